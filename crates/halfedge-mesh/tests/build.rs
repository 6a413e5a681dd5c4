//! Tests of mesh construction: Delaunay against brute force, twin linking against the
//! Delaunay twins, non-manifold policies, and precise errors for bad input.

// Test helpers fail loudly by design.
#![allow(clippy::unwrap_used)]

use halfedge_mesh::{
    BuildReport, DegeneratePolicy, HalfEdgeMesh, MeshError, MeshOptions, NO_TWIN, NonManifoldPolicy,
};
use proptest::prelude::*;

fn orient(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Brute-force empty-circumcircle test (strict, with a tolerance for cocircular points).
fn assert_delaunay(mesh: &HalfEdgeMesh) {
    let v = mesh.vertices();
    for tri in mesh.triangles() {
        let [a, b, c] = tri.map(|i| v[i as usize]);
        assert!(
            orient(a, b, c) > 0.0,
            "triangle {tri:?} is not counter-clockwise"
        );
        for (i, d) in v.iter().enumerate() {
            if tri.contains(&(i as u32)) {
                continue;
            }
            let m = |p: [f64; 3]| {
                [
                    p[0] - d[0],
                    p[1] - d[1],
                    (p[0] - d[0]).powi(2) + (p[1] - d[1]).powi(2),
                ]
            };
            let (a, b, c) = (m(a), m(b), m(c));
            let det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]);
            assert!(
                det <= 1e-7,
                "point {i} lies inside the circumcircle of {tri:?}"
            );
        }
    }
}

fn twin_set(mesh: &HalfEdgeMesh) -> Vec<(u32, u32)> {
    let mut edges: Vec<(u32, u32)> = (0..mesh.halfedges().len() as u32)
        .filter_map(|h| mesh.twin(h).map(|t| (mesh.origin(h), mesh.origin(t))))
        .collect();
    edges.sort_unstable();
    edges
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn delaunay_2d_is_delaunay_and_sane(pts in proptest::collection::vec((-50.0f64..50.0, -50.0f64..50.0), 3..120)) {
        let points: Vec<[f64; 2]> = pts.into_iter().map(|(x, y)| [x, y]).collect();
        match HalfEdgeMesh::delaunay_2d(&points) {
            Ok(mesh) => {
                mesh.sanity_check().unwrap();
                assert_delaunay(&mesh);
                // Relinking the same triangles by sorting must give the same twins.
                let relinked = HalfEdgeMesh::from_triangles(mesh.vertices().to_vec(), mesh.triangles().to_vec()).unwrap();
                prop_assert_eq!(twin_set(&mesh), twin_set(&relinked));
                prop_assert_eq!(mesh.halfedges(), relinked.halfedges());
            }
            Err(MeshError::Collinear { .. }) => {}
            Err(e) => panic!("unexpected error {e}"),
        }
    }

    #[test]
    fn delaunay_25d_matches_2d_on_xy(pts in proptest::collection::vec((-50.0f64..50.0, -50.0f64..50.0, -5.0f64..5.0), 3..80)) {
        let cloud: Vec<[f64; 3]> = pts.iter().map(|&(x, y, z)| [x, y, z]).collect();
        let flat: Vec<[f64; 2]> = pts.iter().map(|&(x, y, _)| [x, y]).collect();
        if let (Ok(a), Ok(b)) = (HalfEdgeMesh::delaunay_25d(&cloud, [0.0, 0.0, 1.0]), HalfEdgeMesh::delaunay_2d(&flat)) {
            a.sanity_check().unwrap();
            prop_assert_eq!(a.triangles(), b.triangles());
            for n in a.triangle_normals().unwrap() {
                prop_assert!(n[2] > 0.0);
            }
        }
    }
}

#[test]
fn delaunay_25d_along_a_tilted_axis() {
    // A grid on the plane x = 2 seen along +x: triangulating on xy would fail (collinear).
    let cloud: Vec<[f64; 3]> = (0..25)
        .map(|i| [2.0, (i % 5) as f64, (i / 5) as f64])
        .collect();
    assert!(matches!(
        HalfEdgeMesh::delaunay_25d(&cloud, [0.0, 0.0, 1.0]),
        Err(MeshError::Collinear { .. })
    ));
    let mesh = HalfEdgeMesh::delaunay_25d(&cloud, [1.0, 0.0, 0.0]).unwrap();
    mesh.sanity_check().unwrap();
    assert_eq!(mesh.num_triangles(), 32);
    for n in mesh.triangle_normals().unwrap() {
        assert!((n[0] - 1.0).abs() < 1e-12, "normal {n:?} should face +x");
    }
}

#[test]
fn delaunay_errors() {
    assert_eq!(
        HalfEdgeMesh::delaunay_2d(&[[0.0, 0.0], [1.0, 1.0]]),
        Err(MeshError::TooFewPoints { found: 2 })
    );
    assert_eq!(
        HalfEdgeMesh::delaunay_2d(&[[0.0, 0.0], [1.0, f64::NAN], [1.0, 0.0]]),
        Err(MeshError::NonFinitePoint { index: 1 })
    );
    assert_eq!(
        HalfEdgeMesh::delaunay_2d(&[[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [3.0, 3.0]]),
        Err(MeshError::Collinear { count: 4 })
    );
    assert_eq!(
        HalfEdgeMesh::delaunay_2d(&[[1.0, 1.0]; 5]),
        Err(MeshError::Collinear { count: 5 })
    );
    assert!(matches!(
        HalfEdgeMesh::delaunay_2d(&[[0.0, 0.0], [1e300, 0.0], [0.0, 1.0]]),
        Err(MeshError::CoordinateTooLarge { index: 1, .. })
    ));
    assert!(matches!(
        HalfEdgeMesh::delaunay_25d(&[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], [0.0; 3]),
        Err(MeshError::BadUpVector { .. })
    ));
}

#[test]
fn duplicates_are_merged_and_reported() {
    let points = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 0.0], [1.0, 1.0]];
    let (mesh, report) = HalfEdgeMesh::delaunay_2d_with_report(&points).unwrap();
    assert_eq!(report.duplicate_points, 1);
    assert_eq!(mesh.num_triangles(), 2);
    assert_eq!(mesh.num_vertices(), 5);
    mesh.sanity_check().unwrap();
}

fn square() -> Vec<[f64; 3]> {
    vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ]
}

#[test]
fn user_triangle_errors_name_the_problem() {
    assert_eq!(
        HalfEdgeMesh::from_triangles(square(), vec![[0, 1, 2], [0, 2, 7]]),
        Err(MeshError::IndexOutOfRange {
            triangle: 1,
            vertex: 7,
            num_vertices: 4
        })
    );
    let mut nan = square();
    nan[2][1] = f64::NAN;
    assert_eq!(
        HalfEdgeMesh::from_triangles(nan, vec![[0, 1, 3], [1, 2, 3]]),
        Err(MeshError::NonFiniteVertex {
            vertex: 2,
            triangle: 1
        })
    );
    assert!(matches!(
        HalfEdgeMesh::from_triangles(square(), vec![[0, 1, 2], [0, 0, 2]]),
        Err(MeshError::DegenerateTriangle {
            triangle: 1,
            reason: "repeated vertex",
            ..
        })
    ));
    let mut line = square();
    line[3] = [2.0, 0.0, 0.0];
    assert!(matches!(
        HalfEdgeMesh::from_triangles(line, vec![[0, 1, 2], [0, 1, 3]]),
        Err(MeshError::DegenerateTriangle {
            triangle: 1,
            reason: "zero area",
            ..
        })
    ));
    // Coordinates whose products overflow: not "zero area" (issue 22).
    let mut huge = square();
    huge[2] = [1e300, 1e300, 0.0];
    match HalfEdgeMesh::from_triangles(huge, vec![[0, 1, 3], [1, 2, 3]]) {
        Err(MeshError::DegenerateTriangle {
            triangle: 1,
            reason,
            ..
        }) => assert!(reason.starts_with("too large"), "{reason}"),
        other => panic!("expected an overflow, got {other:?}"),
    }
    assert_eq!(
        HalfEdgeMesh::from_triangles(square(), vec![]),
        Err(MeshError::NoTriangles)
    );
}

#[test]
fn degenerate_triangles_can_be_dropped() {
    let options = MeshOptions::new().degenerate(DegeneratePolicy::Drop);
    let (mesh, report) = HalfEdgeMesh::from_triangles_with_options(
        square(),
        vec![[0, 1, 2], [1, 1, 2], [0, 2, 3]],
        options,
    )
    .unwrap();
    assert_eq!(mesh.num_triangles(), 2);
    assert_eq!(report.dropped_degenerate, 1);
    assert_eq!(mesh.twin(2), Some(3));
}

/// Three triangles on edge 0–1: a flat pair (0,1,2)+(1,0,3) and a fin (1,0,4) standing up,
/// listed fin first so that "keep first" pairs the wrong two.
fn fin_mesh(policy: NonManifoldPolicy) -> (HalfEdgeMesh, BuildReport) {
    let vertices = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, 1.0, 0.0],
        [0.5, -1.0, 0.0],
        [0.5, -0.1, 1.0],
        [0.5, 0.1, 1.0],
    ];
    let triangles = vec![[0, 1, 5], [0, 1, 2], [1, 0, 3], [1, 0, 4]];
    HalfEdgeMesh::from_triangles_with_options(
        vertices,
        triangles,
        MeshOptions::new().non_manifold(policy),
    )
    .unwrap()
}

#[test]
fn non_manifold_policies() {
    let (first, report) = fin_mesh(NonManifoldPolicy::KeepFirst);
    assert_eq!(report.non_manifold_edges, 1);
    // Half-edge 0 (0→1 of the fin) links to the first opposite one, half-edge 6 (1→0).
    assert_eq!(first.twin(0), Some(6));
    assert_eq!(first.twin(3), None);
    first.sanity_check().unwrap();

    let (similar, _) = fin_mesh(NonManifoldPolicy::MostSimilarNormals);
    // The flat triangles 1 and 2 (normals +z and +z) are paired.
    assert_eq!(similar.twin(3), Some(6));
    assert_eq!(similar.twin(0), None);
    similar.sanity_check().unwrap();

    let (border, report) = fin_mesh(NonManifoldPolicy::AllBorder);
    assert_eq!([0, 3, 6, 9].map(|h| border.twin(h)), [None; 4]);
    assert_eq!(report.border_halfedges, 12);
    border.sanity_check().unwrap();
}

#[test]
fn inconsistent_orientation_stays_border() {
    let (mesh, report) = HalfEdgeMesh::from_triangles_with_options(
        square(),
        vec![[0, 1, 2], [0, 2, 3], [2, 0, 1]],
        MeshOptions::new(),
    )
    .unwrap();
    // Edge 0–2 has three half-edges; edges 0–1 and 1–2 two each, running the same way.
    assert_eq!(report.inconsistent_edges, 2);
    assert_eq!(report.non_manifold_edges, 1);
    mesh.sanity_check().unwrap();
    let (_, report) = HalfEdgeMesh::from_triangles_with_options(
        square(),
        vec![[0, 1, 2], [0, 3, 2]],
        MeshOptions::new(),
    )
    .unwrap();
    assert_eq!(report.inconsistent_edges, 1);
}

#[test]
fn sanity_check_catches_broken_meshes() {
    let mesh = HalfEdgeMesh::from_triangles(square(), vec![[0, 1, 2], [0, 2, 3]]).unwrap();
    let (v, t, mut h, n) = mesh.clone().into_parts();
    h[2] = 0;
    assert!(matches!(
        HalfEdgeMesh::from_parts(v.clone(), t.clone(), h, n.clone()),
        Err(MeshError::BadTwin { .. })
    ));
    let (_, _, mut h, _) = mesh.clone().into_parts();
    h[2] = NO_TWIN;
    assert!(matches!(
        HalfEdgeMesh::from_parts(v.clone(), t.clone(), h, n.clone()),
        Err(MeshError::BadTwin {
            halfedge: 3,
            reason: "twin link is not mutual"
        })
    ));
    assert!(matches!(
        HalfEdgeMesh::from_parts(v.clone(), t.clone(), vec![NO_TWIN; 5], n.clone()),
        Err(MeshError::LengthMismatch {
            what: "halfedges",
            ..
        })
    ));
    let mut bad_normals = n.clone();
    bad_normals[0] = [0.0, 0.0, 2.0];
    assert!(matches!(
        HalfEdgeMesh::from_parts(v, t, mesh.halfedges().to_vec(), bad_normals),
        Err(MeshError::BadNormal { triangle: 0 })
    ));
}

#[test]
fn cocircular_grid_triangulates_cleanly() {
    // Every cell of a regular grid is four cocircular points: the hardest case for an
    // inexact in-circle test. The result must still tile the square exactly.
    let n = 60;
    let points: Vec<[f64; 2]> = (0..n * n)
        .map(|i| [(i % n) as f64 * 0.1, (i / n) as f64 * 0.1])
        .collect();
    let mesh = HalfEdgeMesh::delaunay_2d(&points).unwrap();
    mesh.sanity_check().unwrap();
    assert_eq!(mesh.num_triangles(), 2 * (n - 1) * (n - 1));
    let v = mesh.vertices();
    let area: f64 = mesh
        .triangles()
        .iter()
        .map(|t| 0.5 * orient(v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]))
        .sum();
    let side = (n - 1) as f64 * 0.1;
    assert!((area - side * side).abs() < 1e-9);
    assert!(mesh.triangles().iter().all(|t| orient(
        v[t[0] as usize],
        v[t[1] as usize],
        v[t[2] as usize]
    ) > 0.0));
}
