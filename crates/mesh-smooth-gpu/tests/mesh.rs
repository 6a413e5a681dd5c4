//! Smoothing of general half-edge meshes against brute-force oracles and known effects.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

use std::collections::BTreeSet;

use halfedge_mesh::HalfEdgeMesh;
use mesh_smooth_gpu::SmoothError;
use mesh_smooth_gpu::mesh::{
    self, MeshBilateralOptions, MeshLaplacianOptions, TaubinOptions, TriangleNeighbourhood,
    Weighting,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// An `n × n` grid of unit spacing with heights `z(x, y)`, two triangles per square.
fn grid(n: usize, z: impl Fn(f64, f64) -> f64) -> HalfEdgeMesh {
    let vertices = (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f64, (i / n) as f64);
            [x, y, z(x, y)]
        })
        .collect();
    let mut triangles = Vec::new();
    for r in 0..n - 1 {
        for c in 0..n - 1 {
            let v = (r * n + c) as u32;
            let (right, up, diag) = (v + 1, v + n as u32, v + n as u32 + 1);
            triangles.push([v, right, diag]);
            triangles.push([v, diag, up]);
        }
    }
    let mut mesh = HalfEdgeMesh::from_triangles(vertices, triangles).expect("valid grid");
    mesh.compute_triangle_normals();
    mesh
}

fn noisy(seed: u64, amplitude: f64) -> impl Fn(f64, f64) -> f64 {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let table: Vec<f64> = (0..10_000)
        .map(|_| amplitude * (rng.random::<f64>() - 0.5))
        .collect();
    move |x, y| table[(y as usize * 97 + x as usize) % table.len()]
}

/// Brute-force Laplacian: neighbours found by scanning every triangle.
fn laplacian_oracle(
    m: &HalfEdgeMesh,
    lambda: f64,
    iterations: u32,
    inverse_distance: bool,
) -> Vec<[f64; 3]> {
    let mut rings = vec![BTreeSet::new(); m.num_vertices()];
    for tri in m.triangles() {
        for i in 0..3 {
            for j in 0..3 {
                if i != j {
                    rings[tri[i] as usize].insert(tri[j]);
                }
            }
        }
    }
    let mut cur = m.vertices().to_vec();
    for _ in 0..iterations {
        let next: Vec<[f64; 3]> = (0..cur.len())
            .map(|v| {
                let p = cur[v];
                if rings[v].is_empty() {
                    return p;
                }
                let (mut s, mut sw) = ([0.0; 3], 0.0);
                for &j in &rings[v] {
                    let q = cur[j as usize];
                    let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2))
                        .sqrt();
                    let w = if inverse_distance {
                        1.0 / (d + 1e-6)
                    } else {
                        1.0
                    };
                    sw += w;
                    for k in 0..3 {
                        s[k] += w * q[k];
                    }
                }
                [0, 1, 2].map(|k| p[k] + lambda * (s[k] / sw - p[k]))
            })
            .collect();
        cur = next;
    }
    cur
}

fn max_diff(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    a.iter()
        .zip(b)
        .flat_map(|(p, q)| (0..3).map(move |k| (p[k] - q[k]).abs()))
        .fold(0.0, f64::max)
}

#[test]
fn laplacian_matches_the_brute_force_oracle() {
    let m = grid(12, noisy(1, 0.3));
    for (weighting, inverse) in [
        (Weighting::Uniform, false),
        (Weighting::InverseDistance, true),
    ] {
        let options = MeshLaplacianOptions::new()
            .with_lambda(0.6)
            .with_iterations(3)
            .with_weighting(weighting);
        let got = mesh::laplacian(&m, &options).expect("valid mesh");
        assert!(max_diff(&got, &laplacian_oracle(&m, 0.6, 3, inverse)) < 1e-12);
    }
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let m = grid(30, noisy(2, 0.3));
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(|| {
                (
                    mesh::taubin(&m, &TaubinOptions::new()).expect("valid mesh"),
                    mesh::bilateral_normals(
                        &m,
                        &MeshBilateralOptions::new()
                            .with_neighbourhood(TriangleNeighbourhood::VertexRing),
                    )
                    .expect("valid mesh"),
                )
            })
    };
    assert_eq!(run(1), run(4));
}

#[test]
fn a_plane_stays_a_plane() {
    let m = grid(10, |x, y| 1.0 + 0.1 * x - 0.2 * y);
    let moved =
        mesh::laplacian(&m, &MeshLaplacianOptions::new().with_iterations(5)).expect("valid mesh");
    for p in &moved {
        assert!((p[2] - (1.0 + 0.1 * p[0] - 0.2 * p[1])).abs() < 1e-12);
    }
    for neighbourhood in [
        TriangleNeighbourhood::EdgeAdjacent,
        TriangleNeighbourhood::VertexRing,
    ] {
        let options = MeshBilateralOptions::new().with_neighbourhood(neighbourhood);
        let normals = mesh::bilateral_normals(&m, &options).expect("valid mesh");
        assert!(max_diff(&normals, m.triangle_normals().expect("normals")) < 1e-12);
    }
}

fn rms_z(points: &[[f64; 3]]) -> f64 {
    (points.iter().map(|p| p[2] * p[2]).sum::<f64>() / points.len() as f64).sqrt()
}

fn area_of_bounds(points: &[[f64; 3]]) -> f64 {
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for p in points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (hi[0] - lo[0]) * (hi[1] - lo[1])
}

#[test]
fn taubin_smooths_with_less_shrinkage_than_laplacian() {
    let m = grid(25, noisy(3, 0.4));
    let lap = mesh::laplacian(
        &m,
        &MeshLaplacianOptions::new()
            .with_lambda(0.5)
            .with_iterations(20)
            .with_weighting(Weighting::Uniform),
    )
    .expect("valid mesh");
    let tau = mesh::taubin(&m, &TaubinOptions::new().with_iterations(10)).expect("valid mesh");
    assert!(rms_z(&tau) < 0.5 * rms_z(m.vertices()));
    assert!(area_of_bounds(&tau) > area_of_bounds(&lap));
}

#[test]
fn pinned_boundary_vertices_stay() {
    let m = grid(8, noisy(4, 0.4));
    let options = MeshLaplacianOptions::new()
        .with_iterations(4)
        .with_pin_boundary(true);
    let out = mesh::laplacian(&m, &options).expect("valid mesh");
    for (i, (p, q)) in m.vertices().iter().zip(&out).enumerate() {
        let (x, y) = (i % 8, i / 8);
        let border = x == 0 || y == 0 || x == 7 || y == 7;
        assert_eq!(border, p == q, "vertex ({x}, {y})");
    }
}

#[test]
fn bilateral_keeps_a_crease_and_denoises_faces() {
    // A roof: two planes at 90° meeting along x = 10, with noise.
    let noise = noisy(5, 0.05);
    let m = grid(21, |x, y| 10.0 - (x - 10.0).abs() + noise(x, y));
    let options = MeshBilateralOptions::new()
        .with_sigma_length(2.0)
        .with_sigma_angle(0.3)
        .with_iterations(3)
        .with_neighbourhood(TriangleNeighbourhood::VertexRing);
    let filtered = mesh::bilateral_normals(&m, &options).expect("valid mesh");
    let s = 1.0 / 2f64.sqrt();
    let error = |normals: &[[f64; 3]]| {
        let mut total = 0.0;
        for (tri, n) in m.triangles().iter().zip(normals) {
            let x = tri
                .iter()
                .map(|&v| m.vertices()[v as usize][0])
                .sum::<f64>()
                / 3.0;
            let truth = if x < 10.0 { [-s, 0.0, s] } else { [s, 0.0, s] };
            total += (n[0] * truth[0] + n[2] * truth[2]).min(1.0).acos();
        }
        total / normals.len() as f64
    };
    let (before, after) = (
        error(m.triangle_normals().expect("normals")),
        error(&filtered),
    );
    assert!(after < 0.5 * before, "mean angle error {before} → {after}");
}

#[test]
fn bad_input_is_an_error() {
    let m = HalfEdgeMesh::from_parts_trusted(
        vec![[0.0; 3], [1.0, 0.0, 0.0], [f64::NAN; 3]],
        vec![[0, 1, 2]],
        vec![u32::MAX; 3],
        Vec::new(),
    );
    assert_eq!(
        mesh::laplacian(&m, &MeshLaplacianOptions::new()),
        Err(SmoothError::NonFiniteVertex {
            vertex: 2,
            triangle: 0
        })
    );
    let m = HalfEdgeMesh::from_parts_trusted(
        vec![[0.0; 3]; 2],
        vec![[0, 1, 5]],
        vec![u32::MAX; 3],
        Vec::new(),
    );
    assert!(matches!(
        mesh::bilateral_normals(&m, &MeshBilateralOptions::new()),
        Err(SmoothError::VertexOutOfRange { vertex: 5, .. })
    ));
    let ok = grid(3, |_, _| 0.0);
    assert!(mesh::taubin(&ok, &TaubinOptions::new().with_steps(0.5, -0.4)).is_err());
    assert!(mesh::taubin(&ok, &TaubinOptions::new().with_steps(-0.5, -0.6)).is_err());
    assert!(mesh::laplacian(&ok, &MeshLaplacianOptions::new().with_lambda(f64::NAN)).is_err());
    assert!(
        mesh::bilateral_normals(&ok, &MeshBilateralOptions::new().with_sigma_angle(0.0)).is_err()
    );
}
