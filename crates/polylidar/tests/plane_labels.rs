//! The plane of every vertex: polygon members, and with refinement the rim of a plane
//! whose triangles reach over its edge.
#![allow(clippy::unwrap_used)]

use polylidar::{Config, HalfEdgeMesh, Polylidar};

/// A floor of `n × n` cells of 1 cm whose last column of vertices is raised by `raise`: the
/// triangles of the last column tilt by more than any normal test lets through.
fn floor_with_raised_edge(n: usize, raise: f64) -> HalfEdgeMesh {
    let vertices: Vec<[f64; 3]> = (0..(n + 1) * (n + 1))
        .map(|i| {
            let (x, y) = (i % (n + 1), i / (n + 1));
            [
                0.01 * x as f64,
                0.01 * y as f64,
                if x == n { raise } else { 0.0 },
            ]
        })
        .collect();
    let triangles = test_fixtures::grid_triangles(n);
    HalfEdgeMesh::from_triangles(vertices, triangles).unwrap()
}

fn run(z_thresh: f64, refine: bool) -> polylidar::Extraction {
    let config = Config::default()
        .with_refine(refine)
        .with_z_thresh(z_thresh)
        .with_norm_thresh(0.9)
        .with_min_triangles(10);
    Polylidar::new(config)
        .unwrap()
        .extract_planes_from_mesh(
            floor_with_raised_edge(20, 0.02),
            Some(vec![[0.0, 0.0, 1.0]]),
        )
        .unwrap()
}

#[test]
fn rim_vertices_within_half_z_thresh_take_their_plane() {
    let n = 20;
    let on_edge = |v: usize| v % (n + 1) == n;
    let extraction = run(0.1, true);
    assert_eq!(extraction.polygons.len(), 1);
    assert_eq!(extraction.rim_distance, 0.05);
    let polygon = extraction.point_labels();
    let plane = extraction.plane_labels();
    for v in 0..polygon.len() {
        // The raised column is in no polygon; 2 cm off the floor, within 5 cm, so on its
        // plane; every other vertex is a polygon member.
        assert_eq!(polygon[v], if on_edge(v) { -1 } else { 0 }, "vertex {v}");
        assert_eq!(plane[v], 0, "vertex {v}");
    }

    // With z_thresh 3 cm the rim reaches 1.5 cm: the column stays off the plane.
    let tight = run(0.03, true);
    assert_eq!(tight.plane_labels(), tight.point_labels());

    // Without refinement (the paper's algorithm) labels are polygon members only.
    let paper = run(0.1, false);
    assert_eq!(paper.rim_distance, 0.0);
    assert_eq!(paper.plane_labels(), paper.point_labels());
}
