//! Why a result is empty or nearly so: the stage and the parameter that dropped most of
//! what reached it, with a value suggested by the data.
//!
//! ```
//! use polylidar::explain::explain;
//! use polylidar::{Config, Polylidar};
//!
//! // A 30 × 30 grid of spacing 1 with `lmax` below the spacing: every triangle is dropped.
//! let points: Vec<[f64; 2]> = (0..900).map(|i| [(i % 30) as f64, (i / 30) as f64]).collect();
//! let config = Config::new().with_lmax(0.5);
//! let extraction = Polylidar::new(config.clone())?.extract_2d(&points)?;
//! let explanation = explain(&extraction, &config, Some(1.0));
//! assert!(explanation.empty);
//! let finding = &explanation.findings[0];
//! assert_eq!(finding.parameter, "lmax");
//! assert_eq!(finding.suggested, Some(4.0)); // 4 × the spacing
//! # Ok::<(), polylidar::PolylidarError>(())
//! ```

use crate::output::polygon_area;
use crate::scale::{alpha_for_spacing, lmax_for_spacing};
use crate::{Config, Extraction};

/// A stage that dropped more than half of what reached it.
#[derive(Debug, Clone, PartialEq)]
pub struct Finding {
    /// The stage: `triangle filter`, `region size`, `dominant normals` or
    /// `post-processing`.
    pub stage: &'static str,
    /// The parameter responsible, as named in [`Config`] (TOML; kebab case on the command
    /// line): `norm_thresh`, `lmax`, `alpha`, `min_triangles`,
    /// `fastga.value_threshold`, `postprocess.min_area`.
    pub parameter: &'static str,
    /// What the stage dropped.
    pub dropped: usize,
    /// What reached the stage.
    pub of: usize,
    /// The parameter's value in the run.
    pub current: f64,
    /// A value the data suggests, when there is one.
    pub suggested: Option<f64>,
    /// One sentence on what happened and what to try.
    pub hint: String,
}

/// What [`explain`] found.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Explanation {
    /// No polygon came back (after post-processing, when it ran), or the polygons hold
    /// less than [`NEARLY_EMPTY`] of the mesh's triangles.
    pub empty: bool,
    /// The stages that dropped most of their input, in pipeline order.
    pub findings: Vec<Finding>,
}

/// Share of the mesh's triangles below which a result counts as nearly empty.
pub const NEARLY_EMPTY: f64 = 0.01;

/// The stages of `extraction` (run with `config`) that dropped more than half of what
/// reached them, with suggestions; `spacing` is the input's median nearest-neighbour
/// distance where known (see [`crate::scale`]), used for `lmax` and `alpha`.
///
/// Rules: a triangle test (normal, `lmax`, α) that dropped more than half of the mesh's
/// triangles is reported, with `lmax` = [`lmax_for_spacing`] and α =
/// [`alpha_for_spacing`] suggested (else the value that keeps three quarters of the
/// triangles of the mesh for `lmax`); region and post-processing filters are reported
/// when they left nothing: `min_triangles` with the mean region size suggested,
/// post-processing's `min_area` with half the largest polygon's area; no dominant normal
/// at all is reported with `value_threshold` halved.
pub fn explain(extraction: &Extraction, config: &Config, spacing: Option<f64>) -> Explanation {
    let counts = &extraction.diagnostics.counts;
    let mut findings = Vec::new();
    let total = counts.triangles;
    let most = |dropped: usize, of: usize| of > 0 && 2 * dropped > of;
    if most(counts.dropped_normal, total) {
        let hint = if counts.dominant_normals > 0 {
            "triangles far from every dominant normal; lower norm_thresh to accept more tilt"
        } else {
            "triangles tilted away from `up`: is `up` the direction the data was seen from? \
             Lower norm_thresh to accept more tilt"
        };
        findings.push(Finding {
            stage: "triangle filter",
            parameter: "norm_thresh",
            dropped: counts.dropped_normal,
            of: total,
            current: config.norm_thresh,
            suggested: None,
            hint: hint.to_owned(),
        });
    }
    if most(counts.dropped_lmax, total) {
        let suggested = spacing
            .map(lmax_for_spacing)
            .or_else(|| longest_edge_quantile(extraction, 0.75))
            .filter(|&s| s > config.lmax);
        findings.push(Finding {
            stage: "triangle filter",
            parameter: "lmax",
            dropped: counts.dropped_lmax,
            of: total,
            current: config.lmax,
            suggested,
            hint: "triangles with an edge longer than lmax: it is shorter than the gaps \
                   between neighbouring points (check the units)"
                .to_owned(),
        });
    }
    if most(counts.dropped_alpha, total) {
        findings.push(Finding {
            stage: "triangle filter",
            parameter: "alpha",
            dropped: counts.dropped_alpha,
            of: total,
            current: config.alpha,
            suggested: spacing.map(alpha_for_spacing).filter(|&s| s > config.alpha),
            hint: "triangles with a circumradius above alpha: it is below the point spacing"
                .to_owned(),
        });
    }
    // Only the 3D pipeline loses triangles no test counted: those of no dominant normal.
    let uncounted =
        counts.triangles > counts.dropped_normal + counts.dropped_lmax + counts.dropped_alpha;
    if counts.dominant_normals == 0 && counts.triangles_kept == 0 && uncounted {
        findings.push(Finding {
            stage: "dominant normals",
            parameter: "fastga.value_threshold",
            dropped: counts.triangles,
            of: counts.triangles,
            current: config.fastga.value_threshold,
            suggested: Some(config.fastga.value_threshold / 2.0),
            hint: "FastGA found no dominant normal, so no triangle was assigned to a plane"
                .to_owned(),
        });
    }
    if counts.regions > 0 && counts.regions_too_small == counts.regions {
        let mean = counts.triangles_kept as f64 / counts.regions as f64;
        findings.push(Finding {
            stage: "region size",
            parameter: "min_triangles",
            dropped: counts.regions_too_small,
            of: counts.regions,
            current: config.min_triangles as f64,
            suggested: Some(mean.floor().max(1.0)).filter(|&m| m < config.min_triangles as f64),
            hint: format!(
                "every region has fewer than min_triangles triangles ({} kept triangles in {} \
                 regions, {:.1} on average): the kept triangles do not connect",
                counts.triangles_kept, counts.regions, mean
            ),
        });
    }
    let post = config.postprocess.as_ref();
    if let Some(post) = post
        && !extraction.polygons.is_empty()
        && extraction.postprocessed.is_empty()
    {
        let largest = extraction
            .polygons
            .iter()
            .map(|p| polygon_area(p.plane.normal, &p.shell_points, &p.hole_points))
            .fold(0.0, f64::max);
        findings.push(Finding {
            stage: "post-processing",
            parameter: "postprocess.min_area",
            dropped: extraction.polygons.len(),
            of: extraction.polygons.len(),
            current: post.min_area,
            suggested: Some(largest / 2.0).filter(|&s| s < post.min_area),
            hint: format!(
                "every polygon is smaller than min_area after simplification and buffering \
                 (the largest had area {largest:.3} before)"
            ),
        });
    }
    let returned = if post.is_some() {
        extraction.postprocessed.len()
    } else {
        extraction.polygons.len()
    };
    let in_polygons: usize = extraction.polygons.iter().map(|p| p.triangles.len()).sum();
    let empty = returned == 0 || (in_polygons as f64) < NEARLY_EMPTY * counts.triangles as f64;
    Explanation { empty, findings }
}

/// The `q` quantile of the longest edges of the mesh's triangles with finite vertices.
fn longest_edge_quantile(extraction: &Extraction, q: f64) -> Option<f64> {
    let vertices = extraction.mesh.vertices();
    let mut edges: Vec<f64> = extraction
        .mesh
        .triangles()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| vertices[v as usize]);
            distance(a, b).max(distance(b, c)).max(distance(c, a))
        })
        .filter(|d| d.is_finite())
        .collect();
    if edges.is_empty() {
        return None;
    }
    let k = ((edges.len() - 1) as f64 * q).round() as usize;
    let (_, value, _) = edges.select_nth_unstable_by(k, f64::total_cmp);
    Some(*value)
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Polylidar;

    fn grid(n: usize, spacing: f64) -> Vec<[f64; 2]> {
        (0..n * n)
            .map(|i| [spacing * (i % n) as f64, spacing * (i / n) as f64])
            .collect()
    }

    fn run(config: &Config, points: &[[f64; 2]]) -> Extraction {
        Polylidar::new(config.clone())
            .unwrap()
            .extract_2d(points)
            .unwrap()
    }

    #[test]
    fn a_good_result_has_nothing_to_explain() {
        let config = Config::new().with_lmax(3.0);
        let explanation = explain(&run(&config, &grid(30, 1.0)), &config, Some(1.0));
        assert_eq!(explanation, Explanation::default());
    }

    #[test]
    fn the_suggested_lmax_and_alpha_bring_the_polygon_back() {
        let points = grid(30, 2.0);
        for config in [Config::new().with_lmax(1.0), Config::new().with_alpha(0.5)] {
            let explanation = explain(&run(&config, &points), &config, Some(2.0));
            assert!(explanation.empty);
            let finding = &explanation.findings[0];
            let fixed = match finding.parameter {
                "lmax" => config.clone().with_lmax(finding.suggested.unwrap()),
                "alpha" => config.clone().with_alpha(finding.suggested.unwrap()),
                other => panic!("unexpected parameter {other}"),
            };
            assert_eq!(run(&fixed, &points).polygons.len(), 1);
        }
    }

    #[test]
    fn without_spacing_lmax_comes_from_the_mesh() {
        let points = grid(20, 1.0);
        let config = Config::new().with_lmax(0.9);
        let extraction = run(&config, &points);
        let finding = &explain(&extraction, &config, None).findings[0];
        // Every triangle of the grid has a diagonal as its longest edge.
        assert_eq!(finding.suggested, Some(2f64.sqrt()));
    }

    #[test]
    fn regions_all_too_small_suggest_their_mean_size() {
        let config = Config::new().with_lmax(1.5).with_min_triangles(10_000);
        let extraction = run(&config, &grid(10, 1.0));
        let explanation = explain(&extraction, &config, Some(1.0));
        assert!(explanation.empty);
        let finding = &explanation.findings[0];
        assert_eq!(finding.parameter, "min_triangles");
        assert_eq!(finding.suggested, Some(162.0)); // one region of 9 × 9 × 2 triangles
        let fixed = config.with_min_triangles(162);
        assert_eq!(run(&fixed, &grid(10, 1.0)).polygons.len(), 1);
    }
}
