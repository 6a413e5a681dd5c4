//! The length scale of the data: point spacing, lengths derived from it, and unit
//! conversion of a [`Config`].
//!
//! The papers' presets give lengths in metres for data of their own density. On other data
//! a length such as `lmax` below the point spacing keeps no triangle at all, and a file in
//! feet reads every metre as a foot. These helpers measure the data and rescale the
//! parameters:
//!
//! * [`median_spacing_2d`] / [`median_spacing_25d`]: the median nearest-neighbour distance
//!   of a point set (exact: every point's nearest neighbour is one of its Delaunay
//!   neighbours);
//! * [`alpha_for_spacing`] and [`lmax_for_spacing`]: the α and `lmax` that keep the
//!   triangles of a sample of that spacing, holes and gaps of a few spacings excluded;
//! * [`min_triangles_for_extent`]: the smallest region of a 2.5D cloud as a share of the
//!   area it spans, in triangles of its spacing;
//! * [`convert_lengths`]: a configuration with every length multiplied by a factor (and
//!   every area by its square), e.g. a preset in metres for a file in feet.
//!
//! ```
//! use polylidar::scale::{convert_lengths, lmax_for_spacing, median_spacing_2d};
//! use polylidar::{Config, Polylidar};
//!
//! // A 40 × 40 grid with spacing 0.5.
//! let points: Vec<[f64; 2]> = (0..1600)
//!     .map(|i| [0.5 * (i % 40) as f64, 0.5 * (i / 40) as f64])
//!     .collect();
//! let spacing = median_spacing_2d(&points)?;
//! assert!((spacing - 0.5).abs() < 1e-12);
//! let config = Config::new().with_lmax(lmax_for_spacing(spacing));
//! let extraction = Polylidar::new(config)?.extract_2d(&points)?;
//! assert_eq!(extraction.polygons.len(), 1);
//!
//! // The rooftop preset (metres) for a file in international feet.
//! let rooftop = Config::preset("rooftop").unwrap();
//! let in_feet = convert_lengths(&rooftop, 1.0 / 0.3048);
//! assert!((in_feet.lmax - 0.9 / 0.3048).abs() < 1e-12);
//! # Ok::<(), polylidar::PolylidarError>(())
//! ```

use halfedge_mesh::{HalfEdgeMesh, MeshError};

use crate::{Config, PlaneFrame, PolylidarError};

/// [`alpha_for_spacing`] is this many times the median nearest-neighbour spacing.
///
/// A regular grid of spacing `s` needs α ≥ s/√2 (its triangles' circumradius); a uniform
/// random sample of median spacing `s` (mean spacing ≈ 2.1 s) has Delaunay triangles whose
/// circumradii reach a few spacings. The 2D paper's benchmarks use α = 2·√(area / n),
/// which for a uniform sample is ≈ 4.2 times its median nearest-neighbour distance: this
/// factor.
pub const ALPHA_PER_SPACING: f64 = 4.2;

/// [`lmax_for_spacing`] is this many times the median nearest-neighbour spacing: the
/// longest edge of a Delaunay triangle of an airborne scan (scan lines, uneven density)
/// reaches a few spacings; gaps wider than that (between buildings, under trees) split
/// regions.
pub const LMAX_PER_SPACING: f64 = 4.0;

/// The α (largest circumradius) for a sample of median nearest-neighbour distance
/// `spacing`: [`ALPHA_PER_SPACING`] · `spacing`.
pub fn alpha_for_spacing(spacing: f64) -> f64 {
    ALPHA_PER_SPACING * spacing
}

/// The `lmax` (longest triangle edge) for a sample of median nearest-neighbour distance
/// `spacing`: [`LMAX_PER_SPACING`] · `spacing`.
pub fn lmax_for_spacing(spacing: f64) -> f64 {
    LMAX_PER_SPACING * spacing
}

/// [`min_triangles_for_extent`] keeps regions of at least this share of the area the
/// cloud spans (1/10,000: about 6 m² of a 600 × 1,000 m aerial tile, a small roof).
pub const MIN_AREA_SHARE: f64 = 1e-4;

/// The smallest region, in triangles, that covers [`MIN_AREA_SHARE`] of the cloud's extent
/// seen along `up` (its bounding rectangle in the plane orthogonal to `up`), for a sample
/// of median nearest-neighbour distance `spacing` (a triangle of such a sample covers
/// about `spacing² / 2`); and that area. At least `floor` triangles. `None` without a
/// finite, positive spacing or extent, or for a zero or non-finite `up`.
///
/// ```
/// use polylidar::scale::min_triangles_for_extent;
/// // A 1000 × 500 grid of spacing 1: 5·10⁵ square units, 50 of them a region's minimum,
/// // so 100 triangles of half a unit each.
/// let points: Vec<[f64; 3]> = (0..1001 * 501)
///     .map(|i| [(i % 1001) as f64, (i / 1001) as f64, 0.0])
///     .collect();
/// let (triangles, area) = min_triangles_for_extent(&points, [0.0, 0.0, 1.0], 1.0, 20).unwrap();
/// assert_eq!(triangles, 100);
/// assert!((area - 50.0).abs() < 1e-9);
/// ```
pub fn min_triangles_for_extent(
    points: &[[f64; 3]],
    up: [f64; 3],
    spacing: f64,
    floor: usize,
) -> Option<(usize, f64)> {
    let frame = PlaneFrame::new(up)?;
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in points.iter().filter(|p| p.iter().all(|c| c.is_finite())) {
        let q = frame.project(*p);
        for k in 0..2 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    let extent = (hi[0] - lo[0]) * (hi[1] - lo[1]);
    let per_triangle = spacing * spacing / 2.0;
    if !(extent.is_finite() && extent > 0.0 && per_triangle.is_finite() && per_triangle > 0.0) {
        return None;
    }
    let area = MIN_AREA_SHARE * extent;
    let triangles = (area / per_triangle).ceil();
    // Bounded by the point count, so the cast is exact.
    Some((
        (triangles.min(points.len() as f64) as usize).max(floor),
        area,
    ))
}

/// The median over the points of the distance to their nearest neighbour, for a 2D point
/// set. Duplicate points count once.
///
/// # Errors
/// [`PolylidarError::Mesh`] when the points cannot be triangulated (fewer than 3 distinct
/// points, NaN, all collinear).
pub fn median_spacing_2d(points: &[[f64; 2]]) -> Result<f64, PolylidarError> {
    let (mesh, _) = HalfEdgeMesh::delaunay_2d_with_report(points)?;
    Ok(median_nearest(&mesh, |v| [v[0], v[1]]))
}

/// The median over the points of the distance to their nearest neighbour, measured in the
/// plane orthogonal to `up` (the points as the 2.5D pipeline triangulates them). Duplicate
/// points count once.
///
/// # Errors
/// As [`median_spacing_2d`], plus [`PolylidarError::Mesh`] for a zero or non-finite `up`.
pub fn median_spacing_25d(points: &[[f64; 3]], up: [f64; 3]) -> Result<f64, PolylidarError> {
    let (mesh, _) = HalfEdgeMesh::delaunay_25d_with_report(points, up)?;
    let frame = PlaneFrame::new(up).ok_or(MeshError::BadUpVector { up })?;
    Ok(median_nearest(&mesh, |v| frame.project(v)))
}

/// The median of each triangulated vertex's shortest incident edge, in the coordinates
/// `project` gives.
fn median_nearest(mesh: &HalfEdgeMesh, project: impl Fn([f64; 3]) -> [f64; 2]) -> f64 {
    let planar: Vec<[f64; 2]> = mesh.vertices().iter().map(|&v| project(v)).collect();
    let mut nearest = vec![f64::INFINITY; planar.len()];
    for tri in mesh.triangles() {
        for k in 0..3 {
            let (a, b) = (tri[k] as usize, tri[(k + 1) % 3] as usize);
            let d = (planar[a][0] - planar[b][0]).hypot(planar[a][1] - planar[b][1]);
            nearest[a] = nearest[a].min(d);
            nearest[b] = nearest[b].min(d);
        }
    }
    let mut used: Vec<f64> = nearest.into_iter().filter(|d| d.is_finite()).collect();
    let middle = used.len() / 2;
    let (_, median, _) = used.select_nth_unstable_by(middle, f64::total_cmp);
    *median
}

/// `config` with every length multiplied by `factor` and every area by `factor²`: `alpha`,
/// `lmax`, `z_thresh`, the bilateral filter's `sigma_length`, and post-processing's
/// `alpha`, `beta_pos`, `beta_neg` (lengths), `min_area` and `min_hole_area` (areas).
/// Counts, cosines, angles and the FastGA parameters are unit-free and kept.
///
/// To use a preset (metres) on data in another unit, pass the metres per unit's
/// reciprocal: `1 / 0.3048` for international feet, `3937 / 1200` for US survey feet.
pub fn convert_lengths(config: &Config, factor: f64) -> Config {
    let mut out = config.clone();
    out.alpha *= factor;
    out.lmax *= factor;
    out.z_thresh *= factor;
    out.min_area *= factor * factor;
    if let Some(bilateral) = &mut out.bilateral {
        bilateral.sigma_length = (f64::from(bilateral.sigma_length) * factor) as f32;
    }
    if let Some(unorganized) = &mut out.unorganized {
        unorganized.voxel *= factor;
        unorganized.viewpoint = unorganized.viewpoint.map(|v| v.map(|c| c * factor));
    }
    if let Some(post) = &mut out.postprocess {
        post.alpha *= factor;
        post.beta_pos *= factor;
        post.beta_neg *= factor;
        post.min_area *= factor * factor;
        post.min_hole_area *= factor * factor;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// The brute-force median nearest-neighbour distance.
    fn brute_median(points: &[[f64; 2]]) -> f64 {
        let mut nearest: Vec<f64> = points
            .iter()
            .enumerate()
            .map(|(i, p)| {
                points
                    .iter()
                    .enumerate()
                    .filter(|&(j, _)| j != i)
                    .map(|(_, q)| (p[0] - q[0]).hypot(p[1] - q[1]))
                    .fold(f64::INFINITY, f64::min)
            })
            .collect();
        let middle = nearest.len() / 2;
        nearest.select_nth_unstable_by(middle, f64::total_cmp);
        nearest[middle]
    }

    #[test]
    fn spacing_is_the_brute_force_median_nearest_distance() {
        let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(5);
        for n in [3usize, 4, 17, 200, 801] {
            let points: Vec<[f64; 2]> = (0..n)
                .map(|_| [rng.random_range(0.0..10.0), rng.random_range(-3.0..3.0)])
                .collect();
            assert_eq!(median_spacing_2d(&points).unwrap(), brute_median(&points));
        }
    }

    #[test]
    fn spacing_25d_is_measured_across_up() {
        let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(9);
        let flat: Vec<[f64; 2]> = (0..300)
            .map(|_| [rng.random_range(0.0..5.0), rng.random_range(0.0..5.0)])
            .collect();
        // The same points as a wall: y is up, heights go into the spacing's plane no more.
        let wall: Vec<[f64; 3]> = flat
            .iter()
            .map(|p| [p[0], rng.random_range(0.0..100.0), p[1]])
            .collect();
        let spacing = median_spacing_25d(&wall, [0.0, 1.0, 0.0]).unwrap();
        assert!((spacing - brute_median(&flat)).abs() < 1e-12);
    }

    #[test]
    fn spacing_rejects_what_cannot_be_triangulated() {
        assert!(median_spacing_2d(&[[0.0, 0.0], [1.0, 1.0]]).is_err());
        assert!(median_spacing_25d(&[[0.0; 3]; 5], [0.0, 0.0, 0.0]).is_err());
    }

    #[test]
    fn derived_lengths_keep_every_triangle_of_a_jittered_grid() {
        let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(2);
        let points: Vec<[f64; 2]> = (0..2500)
            .map(|i| {
                let jitter = |r: &mut rand::rngs::Xoshiro256PlusPlus| r.random_range(-0.2..0.2);
                [
                    (i % 50) as f64 + jitter(&mut rng),
                    (i / 50) as f64 + jitter(&mut rng),
                ]
            })
            .collect();
        let spacing = median_spacing_2d(&points).unwrap();
        for config in [
            Config::new().with_alpha(alpha_for_spacing(spacing)),
            Config::new().with_lmax(lmax_for_spacing(spacing)),
        ] {
            let counts = crate::Polylidar::new(config)
                .unwrap()
                .extract_2d(&points)
                .unwrap()
                .diagnostics
                .counts;
            assert_eq!(counts.polygons, 1);
            assert_eq!(counts.holes, 0);
        }
    }

    #[test]
    fn converted_lengths_and_areas_scale_by_factor_and_square() {
        let rooftop = Config::preset("rooftop").unwrap();
        let factor = 3937.0 / 1200.0;
        let feet = convert_lengths(&rooftop, factor);
        let (p, q) = (rooftop.postprocess.unwrap(), feet.postprocess.unwrap());
        assert_eq!(feet.lmax, rooftop.lmax * factor);
        assert_eq!(feet.z_thresh, rooftop.z_thresh * factor);
        assert_eq!(q.min_area, p.min_area * factor * factor);
        assert_eq!(q.beta_neg, p.beta_neg * factor);
        assert_eq!(feet.norm_thresh, rooftop.norm_thresh);
        assert_eq!(feet.min_triangles, rooftop.min_triangles);
        let back = convert_lengths(&feet, 1.0 / factor);
        assert!((back.lmax - rooftop.lmax).abs() < 1e-12);
    }
}
