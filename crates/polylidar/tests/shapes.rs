//! The ground-truth shapes of the 2D paper's concave-hull evaluation
//! (`../shared/fixtures/shapes/`): sample points uniformly inside, extract with
//! α = 2·√(area / n) as in the paper, and compare against the truth.
//!
//! * Every polygon is valid.
//! * The L² error (symmetric difference / true area) is at most `7 / √n`: the α-shape's
//!   boundary error scales with the point spacing, and the paper's curves follow that law
//!   (its CA-with-holes figure is 1.5 % at 64k points; the bound there is 2.8 %).
//! * From 8,000 points on, the polygons and holes found match the truth: random sampling
//!   leaves small voids that become tiny holes, so found polygons and holes count when
//!   their area exceeds 5 α² (twenty times the area per point). Every true island or hole
//!   four times that size must be found, and no more than the truth has. A hole that
//!   lies mostly outside the true shells is a narrow bay whose mouth the α-disc bridges: that is
//!   the α-shape's answer, charged to the L² error, and not counted as a hole here.

use geo::{Area, BooleanOps, Validation};
use polylidar::output::to_multipolygon;
use polylidar::{Config, Polylidar};
use synthscan::shapes::{l2_error, multipolygon_from_geojson, sample_uniform};

struct Case {
    name: &'static str,
    polygons: usize,
    holes: usize,
}

const CASES: [Case; 8] = [
    Case {
        name: "ca",
        polygons: 1,
        holes: 0,
    },
    Case {
        name: "caholes",
        polygons: 1,
        holes: 10,
    },
    Case {
        name: "hi",
        polygons: 9,
        holes: 0,
    },
    Case {
        name: "hiholes",
        polygons: 9,
        holes: 10,
    },
    Case {
        name: "miglove",
        polygons: 1,
        holes: 0,
    },
    Case {
        name: "migloveholes",
        polygons: 1,
        holes: 10,
    },
    Case {
        name: "rectangles",
        polygons: 2,
        holes: 0,
    },
    Case {
        name: "rectanglesholes",
        polygons: 2,
        holes: 10,
    },
];

#[test]
fn shapes_are_recovered() {
    let sizes: &[usize] = if cfg!(debug_assertions) {
        &[2000, 8000, 32000]
    } else {
        &[2000, 4000, 8000, 16000, 32000, 64000]
    };
    for case in &CASES {
        let Some(path) = test_fixtures::fixture(&format!("shapes/{}.geojson", case.name)) else {
            return;
        };
        let truth = multipolygon_from_geojson(&std::fs::read_to_string(path).unwrap()).unwrap();
        let truth_holes: usize = truth.iter().map(|p| p.interiors().len()).sum();
        assert_eq!(
            (truth.0.len(), truth_holes),
            (case.polygons, case.holes),
            "{}",
            case.name
        );
        let shells: geo::MultiPolygon<f64> = truth
            .iter()
            .map(|p| geo::Polygon::new(p.exterior().clone(), vec![]))
            .collect();
        for &n in sizes {
            let points = sample_uniform(&truth, n, 42).unwrap();
            let alpha = 2.0 * (truth.unsigned_area() / n as f64).sqrt();
            let config = Config::new()
                .with_alpha(alpha)
                .with_min_triangles(1)
                .with_min_hole_vertices(3);
            let extraction = Polylidar::new(config).unwrap().extract_2d(&points).unwrap();
            let found = to_multipolygon(&extraction.polygons);
            for p in &found {
                assert!(
                    p.is_valid(),
                    "{} n={n}: {:?}",
                    case.name,
                    p.validation_errors()
                );
            }
            let error = l2_error(&truth, &found);
            let significant = 5.0 * alpha * alpha;
            let polygons = found
                .iter()
                .filter(|p| p.unsigned_area() >= significant)
                .count();
            let holes = found
                .iter()
                .flat_map(|p| p.interiors())
                .map(|h| geo::Polygon::new(h.clone(), vec![]))
                .filter(|h| {
                    let area = h.unsigned_area();
                    area >= significant && shells.intersection(h).unsigned_area() >= 0.5 * area
                })
                .count();
            eprintln!(
                "{:>16} n={n:>5} polygons={polygons} holes={holes} L2={:.2}% (all holes {})",
                case.name,
                100.0 * error,
                extraction.diagnostics.counts.holes
            );
            assert!(
                error <= 7.0 / (n as f64).sqrt(),
                "{} n={n}: L2 {error}",
                case.name
            );
            if n >= 8000 {
                let big = |area: f64| area >= 4.0 * significant;
                let big_polygons = truth
                    .iter()
                    .filter(|p| big(ring_area(p.exterior())))
                    .count();
                let big_holes = truth
                    .iter()
                    .flat_map(|p| p.interiors())
                    .filter(|h| big(ring_area(h)))
                    .count();
                assert!(
                    (big_polygons..=case.polygons).contains(&polygons),
                    "{} n={n}: {polygons} polygons",
                    case.name
                );
                assert!(
                    (big_holes..=case.holes).contains(&holes),
                    "{} n={n}: {holes} holes",
                    case.name
                );
            }
        }
    }
}

fn ring_area(ring: &geo::LineString<f64>) -> f64 {
    geo::Polygon::new(ring.clone(), vec![]).unsigned_area()
}
