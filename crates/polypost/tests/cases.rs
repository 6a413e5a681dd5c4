//! Hand-made cases with known answers.

#![allow(clippy::unwrap_used)] // helpers outside #[test] fns unwrap known-good configs

use geo::{Area, Validation, wkt};
use polypost::{DropReason, Plane, Polygon, Polygon3, PostError, PostProcessor, PostprocessConfig};

fn processor(config: PostprocessConfig) -> PostProcessor {
    PostProcessor::new(config).unwrap()
}

fn square(x0: f64, y0: f64, side: f64) -> Vec<(f64, f64)> {
    vec![
        (x0, y0),
        (x0 + side, y0),
        (x0 + side, y0 + side),
        (x0, y0 + side),
    ]
}

fn poly(shell: &[(f64, f64)], holes: &[Vec<(f64, f64)>]) -> Polygon<f64> {
    Polygon::new(
        shell.to_vec().into(),
        holes.iter().map(|h| h.clone().into()).collect(),
    )
}

#[test]
fn bow_tie_is_repaired_into_two_triangles() {
    let bow = wkt!(POLYGON((0. 0., 10. 10., 10. 0., 0. 10., 0. 0.)));
    let out = processor(PostprocessConfig::default()).process_2d(&bow);
    assert_eq!(out.polygons.len(), 2);
    let total: f64 = out.polygons.iter().map(|p| p.polygon.unsigned_area()).sum();
    assert!((total - 50.0).abs() < 1e-6, "area {total}");
    assert!(out.polygons.iter().all(|p| p.polygon.is_valid()));
    assert_eq!(out.diagnostics.repaired_inputs, 1);
    assert_eq!(out.diagnostics.output_polygons, 2);
}

#[test]
fn bow_tie_on_a_tilted_plane_is_repaired_and_stays_on_the_plane() {
    let plane = Plane::from_normal_and_point([0.3, -0.2, 0.9], [5.0, 1.0, -2.0]).unwrap();
    let f = plane.frame();
    let shell = [[0.0, 0.0], [2.0, 2.0], [2.0, 0.0], [0.0, 2.0]]
        .map(|q| f.lift(q))
        .to_vec();
    let out = processor(PostprocessConfig::rgbd().with_min_area(0.0))
        .process_3d(&Polygon3::new(shell, vec![]), &plane);
    assert_eq!(out.diagnostics.repaired_inputs, 1);
    assert!(!out.polygons.is_empty());
    for p in &out.polygons {
        for q in p
            .polygon
            .shell
            .iter()
            .chain(p.polygon.holes.iter().flatten())
        {
            assert!(plane.signed_distance(*q).abs() < 1e-9);
        }
    }
}

#[test]
fn valid_polygon_without_steps_passes_unchanged() {
    let shell = square(0.0, 0.0, 4.0);
    let hole = square(1.0, 1.0, 1.0);
    let p = poly(&shell, &[hole]);
    let out = processor(PostprocessConfig::default().with_min_area(14.9)).process_2d(&p);
    assert_eq!(out.polygons.len(), 1);
    let q = &out.polygons[0].polygon;
    assert_eq!(q.unsigned_area(), 15.0);
    assert_eq!(q.interiors().len(), 1);
    assert_eq!(out.diagnostics.repaired_inputs, 0);
    // γ just above the area drops it.
    let out = processor(PostprocessConfig::default().with_min_area(15.1)).process_2d(&p);
    assert!(out.polygons.is_empty());
    assert_eq!(out.diagnostics.dropped_by_area, 1);
}

/// An input whose outward buffer stays below γ is dropped before the inward buffer, once,
/// as is one that reaches γ outward and falls below it inward; one that stays above γ is
/// kept. (A 1 × 1 square grows to 1.21 outward by 0.05 with mitred corners and shrinks to
/// a 0.7 × 0.7 square inward by 0.2.)
#[test]
fn inputs_that_cannot_reach_gamma_are_dropped_once() {
    let p = poly(&square(0.0, 0.0, 1.0), &[]);
    let config = PostprocessConfig::default()
        .with_beta_pos(0.05)
        .with_beta_neg(0.2);
    for min_area in [1.3, 1.15] {
        let out = processor(config.with_min_area(min_area)).process_2d(&p);
        assert!(out.polygons.is_empty(), "γ {min_area}");
        assert_eq!(out.diagnostics.dropped_by_area, 1, "γ {min_area}");
        assert_eq!(out.diagnostics.vanished, 0, "γ {min_area}");
    }
    let out = processor(config.with_min_area(0.45)).process_2d(&p);
    assert_eq!(out.polygons.len(), 1);
    let area = out.polygons[0].polygon.unsigned_area();
    assert!((area - 0.49).abs() < 1e-6, "{area}");
    assert_eq!(out.diagnostics.dropped_by_area, 0);
}

#[test]
fn hole_filter_uses_hole_area() {
    let shell = square(0.0, 0.0, 10.0);
    let small = square(1.0, 1.0, 0.5); // 0.25
    let big = square(5.0, 5.0, 2.0); // 4
    let p = poly(&shell, &[small, big]);
    let out = processor(PostprocessConfig::default().with_min_hole_area(0.3)).process_2d(&p);
    assert_eq!(out.polygons.len(), 1);
    assert_eq!(out.polygons[0].polygon.interiors().len(), 1);
    assert_eq!(out.polygons[0].polygon.unsigned_area(), 96.0);
    assert_eq!(out.diagnostics.holes_dropped_by_area, 1);
}

#[test]
fn positive_buffer_fills_a_small_hole_and_negative_restores_the_outline() {
    let shell = square(0.0, 0.0, 10.0);
    let tiny = square(4.0, 4.0, 0.1);
    let p = poly(&shell, &[tiny]);
    let config = PostprocessConfig::default()
        .with_beta_pos(0.2)
        .with_beta_neg(0.2);
    let out = processor(config).process_2d(&p);
    assert_eq!(out.polygons.len(), 1);
    let q = &out.polygons[0].polygon;
    assert!(
        q.interiors().is_empty(),
        "the 0.1 m hole closes under a 0.2 m buffer"
    );
    assert!(
        (q.unsigned_area() - 100.0).abs() < 0.05,
        "area {}",
        q.unsigned_area()
    );
}

#[test]
fn negative_buffer_splits_a_dumbbell_and_keeps_the_source() {
    // Two 2 m squares joined by a 0.1 m wide corridor.
    let shell = vec![
        (0.0, 0.0),
        (2.0, 0.0),
        (2.0, 0.95),
        (4.0, 0.95),
        (4.0, 0.0),
        (6.0, 0.0),
        (6.0, 2.0),
        (4.0, 2.0),
        (4.0, 1.05),
        (2.0, 1.05),
        (2.0, 2.0),
        (0.0, 2.0),
    ];
    let polys = vec![poly(&square(10.0, 10.0, 1.0), &[]), poly(&shell, &[])];
    let out = processor(PostprocessConfig::default().with_beta_neg(0.1))
        .process_many_2d(&polys)
        .unwrap();
    assert_eq!(out.of_source(0).len(), 1);
    assert_eq!(out.of_source(1).len(), 2);
    assert!(out.polygons.iter().all(|p| p.polygon.is_valid()));
}

#[test]
fn erosion_can_remove_everything() {
    let p = poly(&square(0.0, 0.0, 0.1), &[]);
    let out = processor(PostprocessConfig::default().with_beta_neg(0.1)).process_2d(&p);
    assert!(out.polygons.is_empty());
    assert_eq!(out.diagnostics.vanished, 1);
}

#[test]
fn unusable_inputs_are_dropped_with_reasons() {
    let nan = poly(&[(0.0, 0.0), (1.0, f64::NAN), (0.0, 1.0)], &[]);
    let two = poly(&[(0.0, 0.0), (1.0, 0.0), (1.0, 0.0), (0.0, 0.0)], &[]);
    let line = poly(&[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0)], &[]);
    let ok = poly(&square(0.0, 0.0, 1.0), &[]);
    let out = processor(PostprocessConfig::default())
        .process_many_2d(&[nan, two, line, ok])
        .unwrap();
    let d = &out.diagnostics;
    assert_eq!(d.input_polygons, 4);
    assert_eq!(d.output_polygons, 1);
    assert_eq!(d.dropped_invalid, 3);
    assert_eq!(d.dropped[0].source, 0);
    assert_eq!(d.dropped[0].reason, DropReason::NonFiniteCoordinate);
    assert_eq!(
        d.dropped[1].reason,
        DropReason::DegenerateShell {
            distinct_vertices: 2
        }
    );
    assert_eq!(d.dropped[2].reason, DropReason::NoAreaAfterRepair);
    assert_eq!(out.polygons[0].source, 3);
}

#[test]
fn hole_outside_shell_and_overlapping_holes_are_repaired() {
    let shell = square(0.0, 0.0, 10.0);
    let outside = square(20.0, 20.0, 1.0);
    let a = square(2.0, 2.0, 2.0);
    let b = square(3.0, 3.0, 2.0);
    let p = poly(&shell, &[outside, a, b]);
    let out = processor(PostprocessConfig::default()).process_2d(&p);
    assert_eq!(out.diagnostics.repaired_inputs, 1);
    assert_eq!(out.polygons.len(), 1);
    let q = &out.polygons[0].polygon;
    assert!(q.is_valid());
    // 100 minus the union of the two overlapping 2 × 2 holes (4 + 4 − 1).
    assert!((q.unsigned_area() - 93.0).abs() < 1e-6);
}

#[test]
fn jagged_bow_tie_is_simplified_then_repaired() {
    // A bow tie whose four edges zig-zag by ±1 cm: simplified with α = 5 cm first, the
    // crossing shell is repaired into two triangles of three corners each.
    let corners: [(f64, f64); 4] = [(0.0, 0.0), (10.0, 10.0), (10.0, 0.0), (0.0, 10.0)];
    let mut shell = Vec::new();
    for (k, &(x0, y0)) in corners.iter().enumerate() {
        let (x1, y1) = corners[(k + 1) % 4];
        let (len, steps) = ((x1 - x0).hypot(y1 - y0), 40);
        for i in 0..steps {
            let t = f64::from(i) / f64::from(steps);
            let off = if i % 2 == 1 { 0.01 } else { 0.0 };
            // The unit normal of the edge times the tooth.
            let (nx, ny) = (-(y1 - y0) / len, (x1 - x0) / len);
            shell.push((x0 + t * (x1 - x0) + off * nx, y0 + t * (y1 - y0) + off * ny));
        }
    }
    let out =
        processor(PostprocessConfig::default().with_alpha(0.05)).process_2d(&poly(&shell, &[]));
    assert_eq!(out.diagnostics.repaired_inputs, 1);
    assert_eq!(out.diagnostics.repaired_after_simplify, 0);
    assert_eq!(out.polygons.len(), 2);
    for p in &out.polygons {
        assert!(p.polygon.is_valid());
        assert_eq!(p.polygon.exterior().0.len(), 4, "{:?}", p.polygon);
        assert!((p.polygon.unsigned_area() - 25.0).abs() < 0.2);
    }
}

#[test]
fn valid_input_made_invalid_by_simplification_is_repaired() {
    // A shallow outward bump of the bottom edge holds a hole that dips below y = 0;
    // simplified with α = 0.1 the bump goes and the hole crosses the shell.
    let shell = [
        (0.0, 0.0),
        (4.0, 0.0),
        (5.0, -0.05),
        (6.0, 0.0),
        (10.0, 0.0),
        (10.0, 10.0),
        (0.0, 10.0),
    ];
    let hole = vec![(4.9, -0.02), (4.9, 0.2), (5.1, 0.2), (5.1, -0.02)];
    let p = poly(&shell, &[hole]);
    assert!(p.is_valid());
    let out = processor(PostprocessConfig::default().with_alpha(0.1)).process_2d(&p);
    assert_eq!(out.diagnostics.repaired_inputs, 0);
    assert_eq!(out.diagnostics.repaired_after_simplify, 1);
    assert_eq!(out.polygons.len(), 1);
    let q = &out.polygons[0].polygon;
    assert!(q.is_valid());
    // The 10 × 10 square less the hole's part above y = 0 (0.2 × 0.2), now a notch.
    assert!(
        (q.unsigned_area() - 99.96).abs() < 1e-6,
        "{}",
        q.unsigned_area()
    );
}

#[test]
fn simplification_stays_within_alpha() {
    // A jagged circle: radius 3 m with ±1 cm teeth.
    let n = 400;
    let shell: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / n as f64;
            let r = 3.0 + if i % 2 == 0 { 0.01 } else { -0.01 };
            (r * t.cos(), r * t.sin())
        })
        .collect();
    let alpha = 0.05;
    let p = poly(&shell, &[]);
    let out = processor(PostprocessConfig::default().with_alpha(alpha)).process_2d(&p);
    assert_eq!(out.polygons.len(), 1);
    let q = &out.polygons[0].polygon;
    assert!(
        q.exterior().0.len() < n / 4,
        "{} vertices left",
        q.exterior().0.len()
    );
    // Oracle: distance from every input vertex to the simplified ring.
    use geo::{Distance, Euclidean, Point};
    for &(x, y) in &shell {
        let d = Euclidean.distance(&Point::new(x, y), q.exterior());
        assert!(
            d <= alpha + 1e-9,
            "vertex ({x}, {y}) is {d} from the simplified ring"
        );
    }
}

#[test]
fn bad_config_and_mismatched_batches_are_errors() {
    assert!(matches!(
        PostProcessor::new(PostprocessConfig::default().with_alpha(-1.0)),
        Err(PostError::BadParameter { field: "alpha", .. })
    ));
    let plane = Plane::from_normal_and_point([0.0, 0.0, 1.0], [0.0; 3]).unwrap();
    let r = processor(PostprocessConfig::default())
        .process_many_3d(&[Polygon3::default()], &[plane, plane]);
    assert!(matches!(
        r,
        Err(PostError::LengthMismatch {
            polygons: 1,
            planes: 2
        })
    ));
}

#[test]
fn bad_plane_is_reported() {
    let plane = Plane {
        normal: [0.0, 0.0, 0.0],
        offset: 0.0,
        centroid: [0.0; 3],
    };
    let shell = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let out =
        processor(PostprocessConfig::default()).process_3d(&Polygon3::new(shell, vec![]), &plane);
    assert!(out.polygons.is_empty());
    assert_eq!(out.diagnostics.dropped[0].reason, DropReason::BadPlane);
}

/// A star-shaped ring of `n` vertices around `(x0, 0)`, radius 1 ± 0.3, scaled by `scale`.
fn star(x0: f64, n: usize, scale: f64) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            let r = scale * if i % 2 == 0 { 1.3 } else { 0.7 };
            (x0 + r * a.cos(), r * a.sin())
        })
        .collect()
}

/// Many polygons of very different sizes, processed together on two threads (the largest
/// first): the outputs, in input order with their sources, and the diagnostics are those
/// of each polygon processed alone.
#[test]
fn many_polygons_give_what_each_gives_alone_in_input_order() {
    let sizes = [6, 300, 20, 1200, 8, 50, 800, 3, 400, 12];
    let polygons: Vec<Polygon<f64>> = sizes
        .iter()
        .enumerate()
        .map(|(i, &n)| {
            let x0 = 4.0 * i as f64;
            poly(&star(x0, n, 1.0), &[star(x0, 10, 0.2)])
        })
        .collect();
    let plane = Plane::from_normal_and_point([0.0, 0.0, 1.0], [0.0; 3]).unwrap();
    let lifted: Vec<Polygon3> = polygons
        .iter()
        .map(|p| {
            let ring = |r: &geo::LineString<f64>| r.0.iter().map(|c| [c.x, c.y, 0.0]).collect();
            Polygon3::new(ring(p.exterior()), p.interiors().iter().map(ring).collect())
        })
        .collect();
    let planes = vec![plane; lifted.len()];
    let post = processor(PostprocessConfig::default().with_beta_neg(0.02));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let (flat, lifted_out) = pool.install(|| {
        (
            post.process_many_2d(&polygons).unwrap(),
            post.process_many_3d(&lifted, &planes).unwrap(),
        )
    });
    let mut alone = (polypost::Output2::default(), polypost::Output3::default());
    for (i, (p, q)) in polygons.iter().zip(&lifted).enumerate() {
        let (one, three) = (post.process_2d(p), post.process_3d(q, &plane));
        let source = i as u32;
        alone.0.polygons.extend(
            one.polygons
                .into_iter()
                .map(|o| polypost::SourcedPolygon2 { source, ..o }),
        );
        alone.1.polygons.extend(
            three
                .polygons
                .into_iter()
                .map(|o| polypost::SourcedPolygon3 { source, ..o }),
        );
        alone.0.diagnostics.merge(&one.diagnostics);
        alone.1.diagnostics.merge(&three.diagnostics);
    }
    assert_eq!(flat.polygons.len(), sizes.len());
    assert_eq!(flat.polygons, alone.0.polygons);
    assert_eq!(flat.diagnostics, alone.0.diagnostics);
    assert_eq!(lifted_out.polygons, alone.1.polygons);
    assert_eq!(lifted_out.diagnostics, alone.1.diagnostics);
}
