//! The organized-cloud filters against independent answers: brute-force `f64` oracles,
//! fixed points, a hand-computed example and known effects on noisy planes.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

mod common;

use common::{bilateral_oracle, bits, laplacian_oracle, planar_grid, wavy_cloud};
use mesh_smooth_gpu::{BilateralOptions, CpuSmoother, LaplacianOptions};
use opc_mesh::{OpcMeshOptions, OrganizedPointCloud};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Both CPU backends: one thread, the rayon pool.
fn cpu_backends() -> [CpuSmoother; 2] {
    [CpuSmoother::serial(), CpuSmoother::new()]
}

fn laplacian(cloud: &OrganizedPointCloud, options: LaplacianOptions) -> OrganizedPointCloud {
    mesh_smooth_gpu::laplacian_filter(cloud, &options).expect("valid options")
}

fn bilateral(cloud: &OrganizedPointCloud, options: BilateralOptions) -> Vec<[f32; 3]> {
    mesh_smooth_gpu::bilateral_filter(cloud, &options)
        .expect("valid options")
        .into_vec()
}

fn laplacian_on(
    smoother: &mut CpuSmoother,
    cloud: &OrganizedPointCloud,
    options: LaplacianOptions,
) -> OrganizedPointCloud {
    smoother.laplacian(cloud, &options).expect("valid options")
}

fn bilateral_on(
    smoother: &mut CpuSmoother,
    cloud: &OrganizedPointCloud,
    options: BilateralOptions,
) -> Vec<[f32; 3]> {
    smoother
        .bilateral(cloud, &options)
        .expect("valid options")
        .into_vec()
}

#[test]
fn planar_grid_is_a_fixed_point_of_the_laplacian() {
    let cloud = planar_grid(20, 25);
    for mut smoother in cpu_backends() {
        for kernel in [3, 5, 7] {
            let options = LaplacianOptions::new()
                .with_kernel(kernel)
                .with_iterations(4);
            let out = laplacian_on(&mut smoother, &cloud, options);
            let diff = common::max_relative_difference(out.points(), cloud.points());
            assert!(diff < 1e-6, "kernel {kernel}: moved by {diff}");
        }
    }
}

#[test]
fn planar_grid_is_a_fixed_point_of_the_bilateral_filter() {
    let cloud = planar_grid(20, 25);
    // z = 1 + 0.1 x + 0.2 y; with x along columns and y along rows the right-cut triangles
    // face −(−0.1, −0.2, 1).
    let len = (0.01f64 + 0.04 + 1.0).sqrt();
    let truth = [0.1 / len, 0.2 / len, -1.0 / len];
    for mut smoother in cpu_backends() {
        for kernel in [3, 5] {
            let options = BilateralOptions::new()
                .with_kernel(kernel)
                .with_iterations(3);
            for n in bilateral_on(&mut smoother, &cloud, options) {
                for k in 0..3 {
                    assert!(
                        (f64::from(n[k]) - truth[k]).abs() < 1e-5,
                        "{n:?} vs {truth:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn hand_computed_3x3_with_a_missing_corner() {
    // Centre (0, 0, 1) over a flat ring at z = 0; pixel (2, 2) = (1, 1, 0) missing.
    let mut points = Vec::new();
    for y in [-1.0, 0.0, 1.0] {
        for x in [-1.0, 0.0, 1.0] {
            points.push([x, y, 0.0]);
        }
    }
    points[4] = [0.0, 0.0, 1.0];
    points[8] = [f64::NAN; 3];
    let cloud = OrganizedPointCloud::new(3, 3, points.clone()).expect("9 points");
    // Edge neighbours at distance √2, the three corners left at √3:
    // Σw = 4 w2 + 3 w3, Σw x = Σw y = −w3, Σw z = 0.
    let eps = 1e-6f64;
    let (w2, w3) = (1.0 / (2f64.sqrt() + eps), 1.0 / (3f64.sqrt() + eps));
    let sum = 4.0 * w2 + 3.0 * w3;
    let lambda = 0.5;
    let expected = [lambda * (-w3 / sum), lambda * (-w3 / sum), 1.0 - lambda];
    for mut smoother in cpu_backends() {
        let options = LaplacianOptions::new()
            .with_lambda(lambda as f32)
            .with_iterations(1)
            .with_epsilon(eps as f32);
        let out = laplacian_on(&mut smoother, &cloud, options);
        for (got, want) in out.points()[4].iter().zip(expected) {
            assert!((got - want).abs() < 1e-6, "{:?}", out.points()[4]);
        }
        // Every other pixel is on the border: untouched, the NaN stays NaN.
        for i in (0..9).filter(|&i| i != 4) {
            assert_eq!(bits(&out.points()[i..=i]), bits(&points[i..=i]));
        }
    }
}

#[test]
fn laplacian_matches_the_f64_oracle() {
    for seed in 0..6 {
        let cloud = wavy_cloud(23 + seed as usize, 31, seed, 0.01, 0.15);
        for kernel in [3, 5] {
            let oracle = laplacian_oracle(&cloud, kernel, 0.7, 3, 1e-6);
            for mut smoother in cpu_backends() {
                let options = LaplacianOptions::new()
                    .with_kernel(kernel as u32)
                    .with_lambda(0.7)
                    .with_iterations(3);
                let out = laplacian_on(&mut smoother, &cloud, options);
                let diff = common::max_relative_difference(out.points(), &oracle);
                assert!(diff < 2e-6, "seed {seed} kernel {kernel}: {diff}");
            }
        }
    }
}

#[test]
fn bilateral_matches_the_f64_oracle() {
    for seed in 0..6 {
        let cloud = wavy_cloud(21 + seed as usize, 27, 50 + seed, 0.004, 0.15);
        // 9 computes each weight where it is used; the others share them.
        for kernel in [3, 5, 9] {
            let oracle = bilateral_oracle(&cloud, kernel, 0.1, 0.3, 2);
            for mut smoother in cpu_backends() {
                let options = BilateralOptions::new()
                    .with_kernel(kernel as u32)
                    .with_sigma_length(0.1)
                    .with_sigma_angle(0.3)
                    .with_iterations(2);
                let out = bilateral_on(&mut smoother, &cloud, options);
                for (slot, (got, want)) in out.iter().zip(&oracle).enumerate() {
                    match want {
                        None => assert!(got[0].is_nan(), "slot {slot} should be missing"),
                        Some(want) => {
                            for k in 0..3 {
                                let d = (f64::from(got[k]) - want[k]).abs();
                                assert!(d < 2e-5, "seed {seed} slot {slot}: {got:?} vs {want:?}");
                            }
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn border_and_invalid_pixels_are_unchanged() {
    let cloud = wavy_cloud(30, 40, 3, 0.01, 0.2);
    let options = LaplacianOptions::new().with_kernel(5).with_iterations(3);
    let out = laplacian(&cloud, options);
    let (rows, cols) = (cloud.rows(), cloud.cols());
    let mut moved = 0;
    for r in 0..rows {
        for c in 0..cols {
            let i = r * cols + c;
            let (before, after) = (cloud.points()[i], out.points()[i]);
            let border = r < 2 || c < 2 || r + 2 >= rows || c + 2 >= cols;
            if border || before[0].is_nan() {
                assert_eq!(bits(&[before]), bits(&[after]), "pixel ({r}, {c})");
            } else if before != after {
                moved += 1;
            }
        }
    }
    assert!(moved > 500, "only {moved} interior pixels moved");
}

#[test]
fn a_pixel_whose_neighbours_are_all_missing_is_unchanged() {
    let mut points: Vec<[f64; 3]> = planar_grid(5, 5).points().to_vec();
    points[12] = [0.3, 0.3, 7.0];
    for i in [6, 7, 8, 11, 13, 16, 17, 18] {
        points[i] = [f64::NAN; 3];
    }
    let cloud = OrganizedPointCloud::new(5, 5, points).expect("25 points");
    let out = laplacian(&cloud, LaplacianOptions::new());
    assert_eq!(bits(out.points()), bits(cloud.points()));
}

#[test]
fn bilateral_border_cells_keep_their_normals() {
    let cloud = wavy_cloud(20, 24, 4, 0.01, 0.1);
    let raw = bilateral(&cloud, BilateralOptions::new().with_iterations(0));
    let filtered = bilateral(
        &cloud,
        BilateralOptions::new().with_kernel(5).with_iterations(2),
    );
    let (cr, cc) = (19, 23);
    for r in 0..cr {
        for c in 0..cc {
            let border = r < 2 || c < 2 || r + 2 >= cr || c + 2 >= cc;
            for k in 0..2 {
                let s = mesh_smooth_gpu::grid::slot(24, r, c, k);
                if border {
                    assert_eq!(
                        common::normal_bits(&[raw[s]]),
                        common::normal_bits(&[filtered[s]])
                    );
                }
            }
        }
    }
}

/// A noisy range image of the plane z = 2 (noise along z only).
fn noisy_plane(seed: u64, noise: f64) -> OrganizedPointCloud {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let points = (0..60 * 60)
        .map(|i| {
            let (x, y) = ((i % 60) as f64 * 0.02, (i / 60) as f64 * 0.02);
            [x, y, 2.0 + noise * (rng.random::<f64>() - 0.5)]
        })
        .collect();
    OrganizedPointCloud::new(60, 60, points).expect("60 × 60 points")
}

fn mean_angle_to_z(normals: &[[f32; 3]]) -> f64 {
    let present: Vec<f64> = normals
        .iter()
        .filter(|n| !n[0].is_nan())
        .map(|n| f64::from(n[2].abs()).min(1.0).acos())
        .collect();
    present.iter().sum::<f64>() / present.len() as f64
}

#[test]
fn bilateral_brings_a_noisy_planes_normals_closer_to_the_truth() {
    let cloud = noisy_plane(11, 0.004);
    let raw = bilateral(&cloud, BilateralOptions::new().with_iterations(0));
    let options = BilateralOptions::new()
        .with_sigma_length(0.1)
        .with_sigma_angle(0.5)
        .with_iterations(2);
    let filtered = bilateral(&cloud, options);
    let (before, after) = (mean_angle_to_z(&raw), mean_angle_to_z(&filtered));
    assert!(after < 0.6 * before, "mean angle {before} → {after}");
}

#[test]
fn laplacian_flattens_a_noisy_plane() {
    let cloud = noisy_plane(12, 0.01);
    let rms = |c: &OrganizedPointCloud| {
        let inner: Vec<f64> = (2..58)
            .flat_map(|r| (2..58).map(move |c| r * 60 + c))
            .map(|i| c.points()[i][2] - 2.0)
            .collect();
        (inner.iter().map(|d| d * d).sum::<f64>() / inner.len() as f64).sqrt()
    };
    let out = laplacian(&cloud, LaplacianOptions::new().with_iterations(3));
    assert!(
        rms(&out) < 0.5 * rms(&cloud),
        "{} → {}",
        rms(&cloud),
        rms(&out)
    );
}

#[test]
fn slot_normals_match_opc_mesh_and_plug_into_its_mesh() {
    let cloud = wavy_cloud(25, 30, 21, 0.005, 0.1);
    let mut opc = cloud
        .mesh(&OpcMeshOptions::default())
        .expect("meshable cloud");
    let raw =
        mesh_smooth_gpu::bilateral_filter(&cloud, &BilateralOptions::new().with_iterations(0))
            .expect("valid options");
    // Same triangles, same orientation: f32 normals equal opc-mesh's f64 ones up to the
    // f32 rounding of the points (2.4e-7 at z ≈ 2 over 0.02 spacing ≈ 1e-5).
    let mesh_normals = opc
        .mesh
        .triangle_normals()
        .expect("normals computed")
        .to_vec();
    let mut worst = 0.0f64;
    for (slot, &t) in opc.triangle_map.as_slice().iter().enumerate() {
        if t == opc_mesh::NO_TRIANGLE {
            continue;
        }
        let n = raw.get(slot).expect("a meshed slot is present");
        for k in 0..3 {
            worst = worst.max((f64::from(n[k]) - mesh_normals[t as usize][k]).abs());
        }
    }
    assert!(
        worst < 1e-4,
        "f32 normals differ from opc-mesh's by {worst}"
    );
    let filtered =
        mesh_smooth_gpu::bilateral_filter(&cloud, &BilateralOptions::new()).expect("valid options");
    filtered.apply_to_opc_mesh(&mut opc).expect("same cloud");
    opc.mesh
        .sanity_check()
        .expect("valid mesh with unit normals");
    let t = opc.triangle_map.as_slice()[600];
    assert_ne!(t, opc_mesh::NO_TRIANGLE);
    let n = filtered.get(600).expect("present");
    assert!(
        (f64::from(n[2]) - opc.mesh.triangle_normals().expect("normals")[t as usize][2]).abs()
            < 1e-6
    );

    let other = wavy_cloud(25, 31, 21, 0.005, 0.1);
    let mut other_mesh = other
        .mesh(&OpcMeshOptions::default())
        .expect("meshable cloud");
    assert!(filtered.apply_to_opc_mesh(&mut other_mesh).is_err());
}

/// Into a mesh, the last pass goes row by row straight into mesh order; that gives the
/// bits of the filter's slot normals set on the mesh, for grids that end inside a band
/// and on a band's edge, grids narrower than a row block, every kernel (7 the largest
/// that shares weights, 9 computed directly), zero to three passes and both CPU
/// backends.
#[test]
fn bilateral_into_mesh_matches_slot_normals_for_every_kernel_and_pass_count() {
    for (rows, cols, seed) in [(30, 41, 1), (17, 12, 2), (41, 70, 3), (12, 9, 4)] {
        let cloud = wavy_cloud(rows, cols, seed, 0.005, 0.1);
        let mesh_options = OpcMeshOptions::new().with_compute_normals(false);
        for kernel in [3, 5, 7, 9] {
            for iterations in 0..=3 {
                let options = BilateralOptions::new()
                    .with_kernel(kernel)
                    .with_iterations(iterations);
                for mut smoother in cpu_backends() {
                    let mut direct = cloud.mesh(&mesh_options).expect("meshable cloud");
                    smoother
                        .bilateral_into_mesh(&cloud, &options, &mut direct)
                        .expect("same cloud");
                    let mut through_slots = cloud.mesh(&mesh_options).expect("meshable cloud");
                    smoother
                        .bilateral(&cloud, &options)
                        .expect("valid options")
                        .apply_to_opc_mesh(&mut through_slots)
                        .expect("same cloud");
                    let bits = |m: &opc_mesh::OpcMesh| -> Vec<u64> {
                        let normals = m.mesh.triangle_normals().expect("normals set");
                        normals.iter().flatten().map(|v| v.to_bits()).collect()
                    };
                    assert_eq!(
                        bits(&direct),
                        bits(&through_slots),
                        "{rows} × {cols}, kernel {kernel}, {iterations} passes"
                    );
                }
            }
        }
    }
}

/// `bilateral_into_mesh` gives the normals of `bilateral` then `apply_to_opc_mesh`, on a
/// cloud with holes and on both CPU backends, and refuses what `apply_to_opc_mesh`
/// refuses (a mesh of another shape, or of a cloud with other holes) with the same error,
/// leaving the mesh as it was.
#[test]
fn bilateral_into_mesh_matches_slot_normals_and_checks_the_mesh() {
    let full = wavy_cloud(25, 30, 22, 0.005, 0.1);
    let mut points = full.points().to_vec();
    for p in points.iter_mut().step_by(37) {
        *p = [f64::NAN; 3];
    }
    let cloud = OrganizedPointCloud::new(25, 30, points).expect("25 × 30 points");
    let options = BilateralOptions::new();
    let mesh_options = OpcMeshOptions::new().with_compute_normals(false);
    let mesh = |c: &OrganizedPointCloud| c.mesh(&mesh_options).expect("meshable cloud");
    for mut smoother in cpu_backends() {
        let mut direct = mesh(&cloud);
        smoother
            .bilateral_into_mesh(&cloud, &options, &mut direct)
            .expect("same cloud");
        let mut through_slots = mesh(&cloud);
        smoother
            .bilateral(&cloud, &options)
            .expect("valid options")
            .apply_to_opc_mesh(&mut through_slots)
            .expect("same cloud");
        let normals = direct.mesh.triangle_normals().expect("normals set");
        assert_eq!(Some(normals), through_slots.mesh.triangle_normals());
        assert_eq!(normals.len(), direct.mesh.num_triangles());

        for other in [wavy_cloud(25, 31, 22, 0.005, 0.1), full.clone()] {
            let mut other_mesh = mesh(&other);
            let error = smoother
                .bilateral_into_mesh(&cloud, &options, &mut other_mesh)
                .expect_err("a mesh of another cloud");
            assert!(other_mesh.mesh.triangle_normals().is_none());
            let expected = smoother
                .bilateral(&cloud, &options)
                .expect("valid options")
                .apply_to_opc_mesh(&mut other_mesh)
                .expect_err("a mesh of another cloud");
            assert_eq!(error, expected);
        }
    }
}
