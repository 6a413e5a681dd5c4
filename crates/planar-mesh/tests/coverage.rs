//! Known answers for the triangulations, checked against `geo` as the oracle: the
//! triangles cover the polygon exactly, stay inside it, leave the holes empty, use every
//! boundary vertex, repeat no vertex, and (point-based, and on the polygon-based band's
//! outline) have no T-joints.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::Case;
use geo::{Area, Contains};
use planar_mesh::quality::{Defect, defects, signed_area};
use planar_mesh::{Depth, Method, PlaneMesh, Segment, SimplifyOptions, simplify};
use proptest::prelude::*;

fn run(case: &Case, options: &SimplifyOptions) -> PlaneMesh {
    let points = case.points(0.2);
    let (shell, holes) = (case.shell3(), case.holes3());
    simplify(&Segment::new(&points, &shell, &holes), options).unwrap()
}

/// Every check of the module docs, in the case's own 2D coordinates.
fn check(case: &Case, mesh: &PlaneMesh, method: Method, conforming: bool) {
    let truth = case.geo();
    let flat: Vec<[f64; 2]> = mesh.vertices.iter().map(|p| case.flatten(*p)).collect();
    // Area: the triangles' (in the fitted frame, all counter-clockwise) equals the truth's.
    let mut total = 0.0;
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|v| mesh.vertices_2d[v as usize]);
        let area = signed_area(a, b, c);
        assert!(area > 0.0, "triangle {t:?} is not counter-clockwise");
        total += area;
        // None outside, none in a hole: the centroid is inside the polygon.
        let [a, b, c] = t.map(|v| flat[v as usize]);
        let centroid = geo::Point::new((a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0);
        assert!(
            truth.contains(&centroid),
            "{method:?}: triangle {t:?} outside the polygon"
        );
    }
    let expected = truth.unsigned_area();
    assert!(
        ((total - expected) / expected).abs() < 1e-9,
        "{method:?}: triangles cover {total}, the polygon {expected}"
    );
    // Every boundary vertex is a vertex of the mesh.
    for p in case.shell.iter().chain(case.holes.iter().flatten()) {
        assert!(
            flat.iter().any(|q| (q[0] - p[0]).hypot(q[1] - p[1]) < 1e-9),
            "boundary vertex {p:?} missing"
        );
    }
    // No duplicates, no unused vertex, no bad triangle; T-joints as the method allows.
    let interior = mesh.stats.interior_triangles;
    let band_vertices: std::collections::HashSet<u32> = mesh.triangles[interior..]
        .iter()
        .flatten()
        .copied()
        .collect();
    for defect in defects(&mesh.vertices_2d, &mesh.triangles, |_| true) {
        match defect {
            // The polygon-based interior keeps the paper's T-joints between node sizes,
            // but none may touch the band.
            Defect::TJoint { vertex, triangle }
                if method == Method::Polygon
                    && !conforming
                    && triangle < interior
                    && !band_vertices.contains(&vertex) => {}
            other => panic!("{method:?}: {other:?}"),
        }
    }
}

#[test]
fn square_with_square_hole_has_known_area_and_counts() {
    // Shell 0..4 with a 1 × 1 hole: area 15.
    let case = Case {
        shell: vec![[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]],
        holes: vec![vec![[1.0, 1.0], [1.0, 2.0], [2.0, 2.0], [2.0, 1.0]]],
        origin: [0.0, 0.0, 1.0],
        u: [1.0, 0.0, 0.0],
        v: [0.0, 0.0, 1.0],
    };
    for method in [Method::Point, Method::Polygon, Method::Boundary] {
        let mesh = run(
            &case,
            &SimplifyOptions::new()
                .with_method(method)
                .with_depth(Depth::Fixed(4)),
        );
        check(&case, &mesh, method, false);
        assert_eq!(mesh.stats.boundary_vertices, 8);
        if method == Method::Boundary {
            // 8 vertices, one hole: 8 triangles.
            assert_eq!(mesh.triangles.len(), 8);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn triangles_cover_the_polygon_exactly(
        radii in prop::collection::vec(3.0f64..5.0, 5..40),
        holes in prop::collection::vec((3usize..9, 0.2f64..0.6), 0..6),
        tilt in [-2.0f64..2.0, -2.0f64..2.0],
        origin in [-50.0f64..50.0, -50.0f64..50.0, -50.0f64..50.0],
        depth in prop_oneof![Just(Depth::Auto), (2u32..8).prop_map(Depth::Fixed)],
        clearance in prop_oneof![Just(0.0), Just(0.5)],
        conforming in any::<bool>(),
    ) {
        let case = Case::new(&radii, &holes, tilt, origin);
        for method in [Method::Point, Method::Polygon, Method::Boundary] {
            let options = SimplifyOptions::new()
                .with_method(method)
                .with_depth(depth)
                .with_clearance(clearance)
                .with_conforming(conforming);
            let mesh = run(&case, &options);
            check(&case, &mesh, method, conforming);
        }
    }
}
