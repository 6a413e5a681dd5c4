//! Right-cut meshing against independent oracles: a brute-force cell walk for triangles,
//! the GID map and normals, and halfedge-mesh's sort-based linker for twins.

// Test helpers outside `#[test]` functions may fail loudly too.
#![allow(clippy::expect_used, clippy::unwrap_used)]

use halfedge_mesh::{HalfEdgeMesh, NO_TWIN};
use opc_mesh::{
    CellTriangle, NO_TRIANGLE, OpcError, OpcMesh, OpcMeshOptions, OrganizedPointCloud,
    OrganizedPointCloudView,
};
use proptest::prelude::*;

/// What a brute-force walk over the cells expects.
struct Expected {
    triangles: Vec<[u32; 3]>,
    map: Vec<u32>,
    normals: Vec<[f64; 3]>,
}

fn finite(p: [f64; 3]) -> bool {
    p.iter().all(|c| c.is_finite())
}

/// The unit normal of `[a, b, c]` by the right-hand rule, or `None` if the triangle has no
/// usable normal.
fn brute_normal(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> Option<[f64; 3]> {
    let (ux, uy, uz) = (b[0] - a[0], b[1] - a[1], b[2] - a[2]);
    let (vx, vy, vz) = (c[0] - a[0], c[1] - a[1], c[2] - a[2]);
    let n = [uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx];
    let len2 = n.iter().map(|x| x * x).sum::<f64>();
    (len2.is_finite() && len2 >= f64::MIN_POSITIVE).then(|| n.map(|x| x / len2.sqrt()))
}

/// Walks the cells in GID order: the first triangle of cell (r, c) is
/// `[(r+1, c+1), (r, c+1), (r, c)]`, the second `[(r, c), (r+1, c), (r+1, c+1)]`.
fn brute_force(rows: usize, cols: usize, points: &[[f64; 3]]) -> Expected {
    let idx = |r: usize, c: usize| (r * cols + c) as u32;
    let mut e = Expected {
        triangles: Vec::new(),
        map: Vec::new(),
        normals: Vec::new(),
    };
    for r in 0..rows - 1 {
        for c in 0..cols - 1 {
            let cell = [
                [idx(r + 1, c + 1), idx(r, c + 1), idx(r, c)],
                [idx(r, c), idx(r + 1, c), idx(r + 1, c + 1)],
            ];
            for tri in cell {
                let [a, b, c] = tri.map(|v| points[v as usize]);
                let normal = (finite(a) && finite(b) && finite(c))
                    .then(|| brute_normal(a, b, c))
                    .flatten();
                match normal {
                    Some(n) => {
                        e.map.push(e.triangles.len() as u32);
                        e.triangles.push(tri);
                        e.normals.push(n);
                    }
                    None => e.map.push(NO_TRIANGLE),
                }
            }
        }
    }
    e
}

fn same_points(a: &[[f64; 3]], b: &[[f64; 3]]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(p, q)| (0..3).all(|k| p[k].to_bits() == q[k].to_bits()))
}

/// Whether two meshes are identical (vertices compared bit for bit, NaN included).
fn same_mesh(a: &OpcMesh, b: &OpcMesh) -> bool {
    same_points(a.mesh.vertices(), b.mesh.vertices())
        && a.mesh.triangles() == b.mesh.triangles()
        && a.mesh.halfedges() == b.mesh.halfedges()
        && a.mesh.triangle_normals() == b.mesh.triangle_normals()
        && a.triangle_map == b.triangle_map
}

/// Checks one mesh of `cloud` against every oracle.
fn check_against_oracles(cloud: &OrganizedPointCloud, opc: &OpcMesh) {
    let (rows, cols) = (cloud.rows(), cloud.cols());
    let mesh = &opc.mesh;
    mesh.sanity_check().expect("sanity check");
    let expected = brute_force(rows, cols, cloud.points());
    assert_eq!(mesh.triangles(), expected.triangles.as_slice());
    assert_eq!(opc.triangle_map.as_slice(), expected.map.as_slice());
    assert!(same_points(mesh.vertices(), cloud.points()));

    let normals = mesh.triangle_normals().expect("normals were asked for");
    for (t, (n, m)) in normals.iter().zip(&expected.normals).enumerate() {
        let d = (0..3).map(|k| (n[k] - m[k]).abs()).fold(0.0, f64::max);
        assert!(d < 1e-12, "normal of triangle {t}: {n:?} vs {m:?}");
    }

    let linked = HalfEdgeMesh::from_triangles(cloud.points().to_vec(), expected.triangles)
        .expect("the sort-based linker accepts the brute-force triangles");
    assert_eq!(mesh.halfedges(), linked.halfedges());
}

/// A random cloud: pixel (r, c) near (c, r, z), a hole where the roll is below `holes`.
fn arb_cloud() -> impl Strategy<Value = OrganizedPointCloud> {
    (2usize..14, 2usize..14, 0.0f64..0.7).prop_flat_map(|(rows, cols, holes)| {
        proptest::collection::vec(
            (0.0f64..1.0, -0.3f64..0.3, -0.3f64..0.3, 0.5f64..3.0),
            rows * cols,
        )
        .prop_map(move |pixels| {
            let points = pixels
                .iter()
                .enumerate()
                .map(|(i, &(roll, dx, dy, z))| {
                    if roll < holes {
                        [f64::NAN; 3]
                    } else {
                        [(i % cols) as f64 + dx, (i / cols) as f64 + dy, z]
                    }
                })
                .collect();
            OrganizedPointCloud::new(rows, cols, points).expect("valid shape")
        })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(if cfg!(debug_assertions) { 160 } else { 1000 }))]

    #[test]
    fn right_cut_mesh_matches_oracles(cloud in arb_cloud()) {
        let options = OpcMeshOptions::default();
        let expected_count = brute_force(cloud.rows(), cloud.cols(), cloud.points()).triangles.len();
        match cloud.mesh(&options) {
            Ok(opc) => {
                prop_assert!(expected_count > 0);
                check_against_oracles(&cloud, &opc);
                // Every path gives the same mesh.
                let serial = cloud.mesh(&options.with_parallel(false)).expect("serial");
                prop_assert!(same_mesh(&serial, &opc));
                let view = OrganizedPointCloudView::new(cloud.rows(), cloud.cols(), cloud.points())
                    .expect("view");
                prop_assert!(same_mesh(&view.mesh(&options).expect("view mesh"), &opc));
                let moved = cloud.clone().into_mesh(&options).expect("moved");
                prop_assert!(same_mesh(&moved, &opc));
                // Without normals: the same topology.
                let bare = cloud.mesh(&options.with_compute_normals(false)).expect("bare");
                bare.mesh.sanity_check().expect("sanity check");
                prop_assert_eq!(bare.mesh.triangle_normals(), None);
                prop_assert_eq!(bare.mesh.triangles(), opc.mesh.triangles());
                prop_assert_eq!(bare.mesh.halfedges(), opc.mesh.halfedges());
                prop_assert_eq!(&bare.triangle_map, &opc.triangle_map);
            }
            Err(e) => {
                prop_assert_eq!(expected_count, 0);
                prop_assert_eq!(e, OpcError::NoTriangles {
                    valid_points: cloud.num_valid(),
                    points: cloud.rows() * cloud.cols(),
                });
            }
        }
    }

    #[test]
    fn reusing_an_earlier_mesh_changes_nothing(
        first in arb_cloud(),
        second in arb_cloud(),
        normals in any::<[bool; 2]>(),
        parallel in any::<bool>(),
    ) {
        let options = |n: bool| OpcMeshOptions::new().with_compute_normals(n).with_parallel(parallel);
        let (Ok(previous), Ok(fresh)) = (first.mesh(&options(normals[0])), second.mesh(&options(normals[1]))) else {
            return Ok(());
        };
        let moved_into = first.clone().into_mesh(&options(normals[0])).expect("meshed above");
        let reused = second.mesh_reusing(&options(normals[1]), previous).expect("reused");
        reused.mesh.sanity_check().expect("sanity check");
        prop_assert!(same_mesh(&reused, &fresh));
        // Moving the points in, into the arrays of a mesh that had moved its own in.
        let moved = second.clone().into_mesh_reusing(&options(normals[1]), moved_into).expect("reused");
        moved.mesh.sanity_check().expect("sanity check");
        prop_assert!(same_mesh(&moved, &fresh));
    }

    #[test]
    fn triangle_map_round_trips(cloud in arb_cloud()) {
        let Ok(opc) = cloud.mesh(&OpcMeshOptions::default()) else { return Ok(()) };
        let map = &opc.triangle_map;
        prop_assert_eq!((map.cell_rows(), map.cell_cols()), (cloud.rows() - 1, cloud.cols() - 1));
        let gids = map.triangle_gids();
        prop_assert_eq!(gids.len(), opc.mesh.num_triangles());
        for (t, &gid) in gids.iter().enumerate() {
            prop_assert_eq!(map.get(gid as usize), Some(t as u32));
            let (r, c, k) = map.cell(gid as usize).expect("in range");
            prop_assert_eq!(map.gid(r, c, k), gid as usize);
            prop_assert_eq!(map.triangle(r, c, k), Some(t as u32));
            // The triangle's vertices are the cell's pixels.
            let tri = opc.mesh.triangles()[t];
            let cols = cloud.cols() as u32;
            let p1 = (r as u32) * cols + c as u32;
            let corner = match k {
                CellTriangle::First => p1 + 1,
                CellTriangle::Second => p1 + cols,
            };
            let mut got = tri;
            got.sort_unstable();
            let mut want = [p1, corner, p1 + cols + 1];
            want.sort_unstable();
            prop_assert_eq!(got, want);
        }
        prop_assert_eq!(map.get(map.as_slice().len()), None);
        prop_assert_eq!(map.cell(map.as_slice().len()), None);
    }
}

/// A deterministic cloud with holes, big enough to spread over threads.
fn holey_cloud(rows: usize, cols: usize) -> OrganizedPointCloud {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let points = (0..rows * cols)
        .map(|i| {
            let (r, c) = (i / cols, i % cols);
            let hole = next() < 0.1 || (r / 16 + c / 16) % 7 == 3;
            if hole {
                [f64::NAN; 3]
            } else {
                [c as f64 * 0.01, r as f64 * 0.01, 2.0 + 0.05 * next()]
            }
        })
        .collect();
    OrganizedPointCloud::new(rows, cols, points).expect("valid shape")
}

#[test]
fn identical_at_any_thread_count() {
    let cloud = holey_cloud(97, 131);
    let options = OpcMeshOptions::default();
    let reference = cloud.mesh(&options.with_parallel(false)).expect("serial");
    check_against_oracles(&cloud, &reference);
    for threads in 1..=4 {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool");
        let opc = pool.install(|| cloud.mesh(&options)).expect("parallel");
        assert!(same_mesh(&opc, &reference), "{threads} threads");
    }
}

#[test]
fn same_size_frames_reuse_every_array() {
    let options = OpcMeshOptions::default();
    let mut frame = holey_cloud(60, 80);
    let mut opc = frame.mesh(&options).expect("mesh");
    let addresses = |opc: &OpcMesh| {
        [
            opc.mesh.vertices().as_ptr() as usize,
            opc.mesh.triangles().as_ptr() as usize,
            opc.mesh.halfedges().as_ptr() as usize,
            opc.mesh
                .triangle_normals()
                .map_or(0, |n| n.as_ptr() as usize),
            opc.triangle_map.as_slice().as_ptr() as usize,
        ]
    };
    let before = addresses(&opc);
    for step in 1..4 {
        for p in frame.points_mut() {
            p[2] += 0.01 * step as f64;
        }
        opc = frame.mesh_reusing(&options, opc).expect("reuse");
        check_against_oracles(&frame, &opc);
    }
    assert_eq!(addresses(&opc), before);
}

#[test]
fn full_grid_counts_and_twins() {
    let (rows, cols) = (5, 7);
    let points = (0..rows * cols)
        .map(|i| [(i % cols) as f64, (i / cols) as f64, 1.0])
        .collect();
    let cloud = OrganizedPointCloud::new(rows, cols, points).expect("valid shape");
    let opc = cloud.mesh(&OpcMeshOptions::default()).expect("mesh");
    let cells = (rows - 1) * (cols - 1);
    assert_eq!(opc.mesh.num_triangles(), 2 * cells);
    // Border edges of a full grid: 2 (rows − 1) + 2 (cols − 1).
    let border = opc
        .mesh
        .halfedges()
        .iter()
        .filter(|&&h| h == NO_TWIN)
        .count();
    assert_eq!(border, 2 * (rows - 1) + 2 * (cols - 1));
    // Triangle t is GID t.
    assert!(
        opc.triangle_map
            .as_slice()
            .iter()
            .enumerate()
            .all(|(g, &t)| t == g as u32)
    );
}

#[test]
fn repeated_points_make_no_triangle() {
    // A sensor that reports (0, 0, 0) for "no return" in a 3 × 3 block.
    let mut cloud = holey_cloud(8, 9);
    for r in 2..5 {
        for c in 3..6 {
            cloud.points_mut()[r * 9 + c] = [0.0; 3];
        }
    }
    let opc = cloud.mesh(&OpcMeshOptions::default()).expect("mesh");
    check_against_oracles(&cloud, &opc);
    // The 2 × 2 cells inside the block have no triangle.
    for r in 2..4 {
        for c in 3..5 {
            for k in [CellTriangle::First, CellTriangle::Second] {
                assert_eq!(opc.triangle_map.triangle(r, c, k), None);
            }
        }
    }
}

#[test]
fn no_triangle_errors() {
    let all_nan = OrganizedPointCloud::new(3, 4, vec![[f64::NAN; 3]; 12]).expect("shape");
    let err = all_nan.mesh(&OpcMeshOptions::default()).unwrap_err();
    assert_eq!(
        err,
        OpcError::NoTriangles {
            valid_points: 0,
            points: 12
        }
    );
    assert!(
        err.to_string().contains("none of the 12 points is valid"),
        "{err}"
    );
    // All zero, or coordinates whose normals overflow: valid points, no area; the message
    // says so instead of blaming invalid neighbours.
    for value in [0.0, 1e300] {
        let flat = OrganizedPointCloud::new(3, 3, vec![[value; 3]; 9]).expect("shape");
        let err = flat.mesh(&OpcMeshOptions::default()).unwrap_err();
        let text = err.to_string();
        assert!(text.contains("9 of the 9 points are valid"), "{text}");
        assert!(
            text.contains("coincident") && text.contains("overflows"),
            "{text}"
        );
    }
    // Valid points on a checkerboard never form a triangle.
    let checker: Vec<[f64; 3]> = (0..16)
        .map(|i| {
            if (i % 4 + i / 4) % 2 == 0 {
                [(i % 4) as f64, (i / 4) as f64, 1.0]
            } else {
                [f64::NAN; 3]
            }
        })
        .collect();
    let checker = OrganizedPointCloud::new(4, 4, checker).expect("shape");
    assert_eq!(
        checker.into_mesh(&OpcMeshOptions::default()),
        Err(OpcError::NoTriangles {
            valid_points: 8,
            points: 16
        })
    );
}
