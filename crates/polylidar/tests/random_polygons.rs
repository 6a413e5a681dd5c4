//! The 2D paper's random polygon test (§VI): random polygons with and without holes, of
//! high, medium and low convexity, 8,000 points sampled inside, α = 2·√(area / n). Every
//! polygon returned must be valid, and the L² error must stay within a bound per convexity
//! class: 8 % (high, CV ≥ 0.75), 15 % (medium), 30 % (low, CV < 0.55) — the paper's worst
//! cases were 6.1 %, 13.0 % and 25.0 %.

use geo::{Contains, Coord, LineString, MultiPolygon, Polygon, Validation};
use polylidar::output::to_multipolygon;
use polylidar::{Config, Polylidar};
use proptest::prelude::*;
use synthscan::shapes::{convexity, l2_error, sample_uniform};

/// A star-shaped polygon: `radii.len()` vertices at increasing angles, each at a radius in
/// `[min_radius, 1]`, with round holes placed where they fit.
fn star_polygon(
    angles: &[f64],
    radii: &[f64],
    min_radius: f64,
    holes: &[(f64, f64)],
) -> Polygon<f64> {
    let mut angles = angles.to_vec();
    angles.sort_by(f64::total_cmp);
    angles.dedup_by(|a, b| (*a - *b).abs() < 1e-3);
    let shell: LineString<f64> = angles
        .iter()
        .zip(radii)
        .map(|(&t, &r)| {
            let r = min_radius + (1.0 - min_radius) * r;
            Coord {
                x: r * t.cos(),
                y: r * t.sin(),
            }
        })
        .collect();
    let shell_polygon = Polygon::new(shell.clone(), vec![]);
    let mut rings: Vec<(f64, f64, f64)> = Vec::new();
    for &(t, d) in holes {
        let (cx, cy) = (
            0.6 * min_radius * d * t.cos(),
            0.6 * min_radius * d * t.sin(),
        );
        let r = 0.12 * min_radius.max(0.3);
        let fits = (0..16).all(|k| {
            let a = f64::from(k) / 16.0 * std::f64::consts::TAU;
            shell_polygon.contains(&Coord {
                x: cx + 1.5 * r * a.cos(),
                y: cy + 1.5 * r * a.sin(),
            })
        });
        let apart = rings
            .iter()
            .all(|&(x, y, q)| ((x - cx).powi(2) + (y - cy).powi(2)).sqrt() > 1.5 * (q + r));
        if fits && apart {
            rings.push((cx, cy, r));
        }
    }
    let holes = rings
        .iter()
        .map(|&(cx, cy, r)| {
            (0..24)
                .rev()
                .map(|k| {
                    let a = f64::from(k) / 24.0 * std::f64::consts::TAU;
                    Coord {
                        x: cx + r * a.cos(),
                        y: cy + r * a.sin(),
                    }
                })
                .collect()
        })
        .collect();
    Polygon::new(shell, holes)
}

fn arb_polygon() -> impl Strategy<Value = Polygon<f64>> {
    (
        8usize..40,
        prop_oneof![Just(0.8), Just(0.5), Just(0.15)],
        any::<u64>(),
    )
        .prop_flat_map(|(k, min_radius, _)| {
            (
                proptest::collection::vec(0.0..std::f64::consts::TAU, k),
                proptest::collection::vec(0.0f64..1.0, k),
                Just(min_radius),
                proptest::collection::vec((0.0..std::f64::consts::TAU, 0.0f64..1.0), 0..4),
            )
        })
        .prop_map(|(angles, radii, min_radius, holes)| {
            star_polygon(&angles, &radii, min_radius, &holes)
        })
        .prop_filter("a valid truth polygon", |p| {
            p.is_valid() && p.exterior().0.len() >= 4
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(if cfg!(debug_assertions) { 24 } else { 200 }))]

    #[test]
    fn random_polygons_are_valid_and_accurate(truth in arb_polygon(), seed in any::<u64>()) {
        let truth = MultiPolygon::new(vec![truth]);
        let n = 8000;
        let points = sample_uniform(&truth, n, seed).unwrap();
        let alpha = 2.0 * (geo::Area::unsigned_area(&truth) / n as f64).sqrt();
        let extraction = Polylidar::new(Config::new().with_alpha(alpha).with_min_triangles(1)).unwrap().extract_2d(&points).unwrap();
        let found = to_multipolygon(&extraction.polygons);
        for p in &found {
            prop_assert!(p.is_valid(), "{:?}", p.validation_errors());
        }
        let cv = convexity(&truth);
        let bound = if cv >= 0.75 { 0.08 } else if cv >= 0.55 { 0.15 } else { 0.30 };
        let error = l2_error(&truth, &found);
        prop_assert!(error <= bound, "CV {cv:.2}: L2 {error:.3} > {bound}");
    }
}
