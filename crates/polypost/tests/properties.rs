//! Property tests: random polygons with holes (valid and deliberately broken), random
//! plane orientations and random parameters. Oracles: `geo::Validation`, the plane
//! equation, and the filter thresholds themselves.

use geo::{Area, Validation};
use polypost::{
    BufferJoin, Coord, DropReason, LineString, Plane, Polygon, Polygon3, PostProcessor,
    PostprocessConfig,
};
use proptest::prelude::*;
use proptest::strategy::ValueTree;

/// Star-shaped ring around `(cx, cy)`: strictly increasing angles, radii in
/// `[r_min, r_max]`; simple by construction.
fn star(cx: f64, cy: f64, radii: &[f64], jitter: &[f64]) -> Vec<Coord<f64>> {
    let n = radii.len();
    (0..n)
        .map(|i| {
            let t = std::f64::consts::TAU * (i as f64 + 0.5 * jitter[i]) / n as f64;
            Coord {
                x: cx + radii[i] * t.cos(),
                y: cy + radii[i] * t.sin(),
            }
        })
        .collect()
}

/// Distance from the origin to the nearest edge of the closed ring `r`.
fn inscribed_radius(r: &[Coord<f64>]) -> f64 {
    (0..r.len())
        .map(|i| {
            let (a, b) = (r[i], r[(i + 1) % r.len()]);
            let (dx, dy) = (b.x - a.x, b.y - a.y);
            let t = (-(a.x * dx + a.y * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
            (a.x + t * dx).hypot(a.y + t * dy)
        })
        .fold(f64::INFINITY, f64::min)
}

#[derive(Debug, Clone)]
struct Shape {
    polygon: Polygon<f64>,
    /// Built valid (shell star-shaped, holes in disjoint discs inside it).
    valid_by_construction: bool,
}

fn ring_params(
    n: std::ops::Range<usize>,
    r: std::ops::Range<f64>,
) -> impl Strategy<Value = (Vec<f64>, Vec<f64>)> {
    n.prop_flat_map(move |n| {
        (
            prop::collection::vec(r.clone(), n),
            prop::collection::vec(0.0..1.0f64, n),
        )
    })
}

/// A star shell of radius 1–4 m with up to 5 star holes in disjoint sectors; `broken`
/// picks a defect: none, shuffled shell (self-intersecting), oversized holes (crossing
/// each other and the shell), a collinear spike.
fn shape() -> impl Strategy<Value = Shape> {
    shape_with(0..4)
}

/// Shapes built valid (defect 0 only).
fn valid_shape() -> impl Strategy<Value = Shape> {
    shape_with(0..1)
}

fn shape_with(defects: std::ops::Range<u8>) -> impl Strategy<Value = Shape> {
    (
        ring_params(3..40, 1.0..4.0),
        prop::collection::vec(ring_params(3..12, 0.2..1.0), 0..5),
        defects,
        prop::collection::vec(any::<prop::sample::Index>(), 40),
    )
        .prop_map(|((radii, jitter), holes, broken, swaps)| {
            let mut shell = star(0.0, 0.0, &radii, &jitter);
            let r_in = inscribed_radius(&shell);
            let k = holes.len().max(1) as f64;
            let center_r = 0.5 * r_in;
            let apart = if k > 1.0 {
                center_r * (std::f64::consts::PI / k).sin()
            } else {
                f64::INFINITY
            };
            let max_hole = apart.min(r_in - center_r) * 0.95;
            let grow = if broken == 2 { 3.0 } else { 1.0 };
            let hole_rings: Vec<_> = holes
                .iter()
                .enumerate()
                .map(|(j, (hr, hj))| {
                    let t = std::f64::consts::TAU * j as f64 / k;
                    let scaled: Vec<f64> = hr.iter().map(|r| r * max_hole * grow).collect();
                    let mut ring = star(center_r * t.cos(), center_r * t.sin(), &scaled, hj);
                    ring.reverse();
                    LineString(ring)
                })
                .collect();
            match broken {
                1 => {
                    let n = shell.len();
                    for s in swaps.chunks(2) {
                        shell.swap(s[0].index(n), s[1].index(n));
                    }
                }
                3 => {
                    // A spike out and back along the same line.
                    let a = shell[0];
                    shell.insert(
                        1,
                        Coord {
                            x: a.x * 1.5,
                            y: a.y * 1.5,
                        },
                    );
                    shell.insert(2, a);
                }
                _ => {}
            }
            Shape {
                polygon: Polygon::new(LineString(shell), hole_rings),
                valid_by_construction: broken == 0,
            }
        })
}

fn config() -> impl Strategy<Value = PostprocessConfig> {
    (
        0.0..0.3f64,
        0.0..0.3f64,
        0.0..0.3f64,
        0.0..6.0f64,
        0.0..0.8f64,
        0u8..4,
    )
        .prop_map(
            |(alpha, beta_pos, beta_neg, min_area, min_hole_area, off)| {
                // Often switch single steps off, to cover the zero paths.
                PostprocessConfig::default()
                    .with_alpha(if off == 0 { 0.0 } else { alpha })
                    .with_beta_pos(if off == 1 { 0.0 } else { beta_pos })
                    .with_beta_neg(if off == 2 { 0.0 } else { beta_neg })
                    .with_min_area(min_area)
                    .with_min_hole_area(min_hole_area)
            },
        )
}

/// Every corner style of the buffers, with angles across their clamped ranges and past them.
fn join() -> impl Strategy<Value = BufferJoin> {
    prop_oneof![
        (0.01..1.2f64).prop_map(|max_angle| BufferJoin::Round { max_angle }),
        (0.01..3.1f64).prop_map(|min_angle| BufferJoin::Miter { min_angle }),
        Just(BufferJoin::Bevel),
    ]
}

fn unit_normal() -> impl Strategy<Value = [f64; 3]> {
    (-1.0..1.0f64, 0.0..std::f64::consts::TAU).prop_map(|(z, phi)| {
        let r = (1.0 - z * z).sqrt();
        [r * phi.cos(), r * phi.sin(), z]
    })
}

fn ring_area_2d(r: &LineString<f64>) -> f64 {
    Polygon::new(r.clone(), vec![]).unsigned_area()
}

/// `PROPTEST_CASES` if set, else a size that keeps the debug suite fast.
fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(if cfg!(debug_assertions) { 64 } else { 512 })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    #[test]
    fn outputs_are_valid_and_filters_hold(s in shape(), cfg in config()) {
        let out = PostProcessor::new(cfg).unwrap().process_2d(&s.polygon);
        let d = &out.diagnostics;
        prop_assert_eq!(d.input_polygons, 1);
        prop_assert_eq!(d.output_polygons as usize, out.polygons.len());
        // The last-resort validity guard never has to fire.
        prop_assert!(
            !d.dropped.iter().any(|x| matches!(x.reason, DropReason::InvalidAfterProcessing { .. })),
            "{:?}", d.dropped
        );
        for p in &out.polygons {
            prop_assert_eq!(p.source, 0);
            prop_assert!(p.polygon.is_valid(), "invalid output {:?}", p.polygon);
            prop_assert!(p.polygon.unsigned_area() >= cfg.min_area);
            for h in p.polygon.interiors() {
                prop_assert!(ring_area_2d(h) >= cfg.min_hole_area * (1.0 - 1e-12));
            }
        }
        if s.valid_by_construction {
            prop_assert!(s.polygon.is_valid());
        }
    }

    /// γ only filters: the parts kept with `min_area` γ are exactly the parts of the run
    /// without it whose area reaches γ (also when γ drops a polygon before processing,
    /// by the bound on what its buffers can reach, whatever the corner style).
    #[test]
    fn min_area_only_filters_parts(
        s in shape(), cfg in config(), min_area in 0.0..60.0f64, join in join(),
    ) {
        let cfg = cfg.with_min_hole_area(0.0).with_buffer_join(join);
        let all = PostProcessor::new(cfg.with_min_area(0.0)).unwrap().process_2d(&s.polygon);
        let kept = PostProcessor::new(cfg.with_min_area(min_area)).unwrap().process_2d(&s.polygon);
        let expected: Vec<&Polygon<f64>> = all
            .polygons
            .iter()
            .map(|p| &p.polygon)
            .filter(|p| p.unsigned_area() >= min_area)
            .collect();
        let got: Vec<&Polygon<f64>> = kept.polygons.iter().map(|p| &p.polygon).collect();
        prop_assert_eq!(got, expected);
    }

    #[test]
    fn without_simplify_or_buffer_valid_polygons_above_gamma_survive(
        s in valid_shape(), min_area in 0.0..20.0f64, min_hole_area in 0.0..0.5f64,
    ) {
        prop_assert!(s.polygon.is_valid());
        let cfg = PostprocessConfig::default().with_min_area(min_area).with_min_hole_area(min_hole_area);
        let out = PostProcessor::new(cfg).unwrap().process_2d(&s.polygon);
        let area = s.polygon.unsigned_area();
        if area >= min_area {
            prop_assert_eq!(out.polygons.len(), 1);
            let q = &out.polygons[0].polygon;
            let kept = s.polygon.interiors().iter().filter(|h| ring_area_2d(h) >= min_hole_area).count();
            prop_assert_eq!(q.interiors().len(), kept);
            let dropped: f64 = s.polygon.interiors().iter().map(ring_area_2d).filter(|&a| a < min_hole_area).sum();
            prop_assert!((q.unsigned_area() - area - dropped).abs() < 1e-9 * area.max(1.0));
        } else {
            prop_assert!(out.polygons.is_empty());
            prop_assert_eq!(out.diagnostics.dropped_by_area, 1);
        }
    }

    #[test]
    fn lifted_points_lie_on_the_plane(
        s in shape(), cfg in config(), normal in unit_normal(),
        origin in prop::array::uniform3(-100.0..100.0f64), noise in 0.0..0.02f64,
    ) {
        let plane = Plane::from_normal_and_point(normal, origin).unwrap();
        let f = plane.frame();
        // Lift the 2D shape onto the plane with a small off-plane wobble.
        let lift = |r: &LineString<f64>| -> Vec<[f64; 3]> {
            r.0.iter().enumerate().map(|(i, c)| {
                let p = f.lift([c.x, c.y]);
                let e = noise * ((i as f64) * 1.7).sin();
                [p[0] + e * normal[0], p[1] + e * normal[1], p[2] + e * normal[2]]
            }).collect()
        };
        let poly3 = Polygon3::new(lift(s.polygon.exterior()), s.polygon.interiors().iter().map(lift).collect());
        let processor = PostProcessor::new(cfg).unwrap();
        let out = processor.process_3d(&poly3, &plane);
        for p in &out.polygons {
            for q in p.polygon.shell.iter().chain(p.polygon.holes.iter().flatten()) {
                prop_assert!(plane.signed_distance(*q).abs() <= 1e-9);
            }
            let m = p.polygon.metrics();
            prop_assert!(m.area >= cfg.min_area * (1.0 - 1e-9) - 1e-9);
        }
        // Same as processing the projection in 2D.
        let flat = Polygon::new(
            LineString(poly3.shell.iter().map(|&p| { let q = f.project(p); Coord { x: q[0], y: q[1] } }).collect()),
            poly3.holes.iter().map(|h| LineString(h.iter().map(|&p| { let q = f.project(p); Coord { x: q[0], y: q[1] } }).collect())).collect(),
        );
        let out2 = processor.process_2d(&flat);
        prop_assert_eq!(out.polygons.len(), out2.polygons.len());
        prop_assert_eq!(&out.diagnostics, &out2.diagnostics);
        for p in &out2.polygons {
            prop_assert!(p.polygon.is_valid());
        }
    }
}

#[test]
fn identical_results_at_any_thread_count() {
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    let shapes: Vec<Polygon<f64>> = (0..40)
        .map(|_| shape().new_tree(&mut runner).unwrap().current().polygon)
        .collect();
    let processor = PostProcessor::new(PostprocessConfig::rgbd().with_min_area(0.5)).unwrap();
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| processor.process_many_2d(&shapes).unwrap())
    };
    let one = run(1);
    assert_eq!(one.diagnostics.input_polygons, 40);
    assert_eq!(one, run(3));
    // And the batch equals the one-by-one results.
    for (i, s) in shapes.iter().enumerate() {
        let single = processor.process_2d(s);
        let batch: Vec<_> = one.of_source(i as u32).iter().map(|p| &p.polygon).collect();
        let alone: Vec<_> = single.polygons.iter().map(|p| &p.polygon).collect();
        assert_eq!(batch, alone);
    }
}
