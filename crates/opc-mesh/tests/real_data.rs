//! Meshing the shared real data (`../shared/fixtures`): SynPEB `pc_01` (500 × 500 LiDAR
//! scan) and RealSense `rgbd_opc.npy` (120 × 212).
//! Skipped with a note when the data are absent (a failure under `CI=true`).

#![allow(clippy::expect_used, clippy::unwrap_used)]

use halfedge_mesh::HalfEdgeMesh;
use opc_mesh::{OpcMeshOptions, OrganizedPointCloud};

/// Meshes `cloud` and checks it against a brute-force triangle count, the sort-based twin
/// linker and unit normals; returns the share of normals facing the sensor at the origin.
fn check_mesh(cloud: &OrganizedPointCloud) -> f64 {
    let opc = cloud.mesh(&OpcMeshOptions::default()).expect("mesh");
    let mesh = &opc.mesh;
    mesh.sanity_check().expect("sanity check");

    let (rows, cols) = (cloud.rows(), cloud.cols());
    let valid = |r: usize, c: usize| cloud.point(r, c).iter().all(|x| x.is_finite());
    let mut expected = 0;
    for r in 0..rows - 1 {
        for c in 0..cols - 1 {
            let diagonal = valid(r, c) && valid(r + 1, c + 1);
            expected += usize::from(diagonal && valid(r, c + 1));
            expected += usize::from(diagonal && valid(r + 1, c));
        }
    }
    // Real sensors produce no repeated or collinear valid neighbours here.
    assert_eq!(mesh.num_triangles(), expected);

    let linked = HalfEdgeMesh::from_triangles(cloud.points().to_vec(), mesh.triangles().to_vec())
        .expect("the sort-based linker accepts the mesh's triangles");
    assert_eq!(mesh.halfedges(), linked.halfedges());

    let normals = mesh.triangle_normals().expect("normals");
    let facing = mesh
        .triangles()
        .iter()
        .zip(normals)
        .filter(|(tri, n)| {
            let p = mesh.vertices()[tri[0] as usize];
            n[0] * p[0] + n[1] * p[1] + n[2] * p[2] < 0.0
        })
        .count();
    facing as f64 / normals.len() as f64
}

#[test]
fn synpeb_pc_01() {
    let Some(path) = test_fixtures::fixture("synpeb/pc_01.pcd") else {
        return;
    };
    let pcd = polylidar_io::read_pcd(&path).expect("read pc_01");
    assert_eq!((pcd.rows, pcd.cols), (500, 500));
    let full = OrganizedPointCloud::new(pcd.rows, pcd.cols, pcd.points).expect("organized");
    // The full cloud in release builds; every second row and column in debug builds.
    let cloud = if cfg!(debug_assertions) {
        full.downsample(2).expect("downsample")
    } else {
        full
    };
    let facing = check_mesh(&cloud);
    eprintln!("pc_01: {:.1} % of normals face the sensor", 100.0 * facing);
    // SynPEB lays its rows out mirrored with respect to a camera's (x right, y down,
    // z forward) frame, so the right-cut order gives normals that all face away.
    assert!(facing < 0.01, "{facing} of the normals face the sensor");
}

#[test]
fn realsense_rgbd_opc() {
    let Some(path) = test_fixtures::fixture("realsense/rgbd_opc.npy") else {
        return;
    };
    let npy = polylidar_io::read_npy(&path).expect("read rgbd_opc");
    assert_eq!(npy.shape, vec![120, 212, 3]);
    let cloud = OrganizedPointCloud::from_flat_vec(120, 212, npy.data).expect("organized");
    let facing = check_mesh(&cloud);
    eprintln!(
        "rgbd_opc: {:.1} % of normals face the sensor",
        100.0 * facing
    );
    assert!(facing > 0.9, "only {facing} face the sensor");
}
