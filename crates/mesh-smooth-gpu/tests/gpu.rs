//! The GPU backend against the CPU one. Runs on any wgpu adapter, Mesa's lavapipe
//! included. Without an adapter these tests fail under CI (`CI=true`) and are skipped with
//! a printed reason elsewhere.
#![cfg(feature = "gpu")]
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

mod common;

use common::{max_normal_difference, max_relative_difference, wavy_cloud};
use mesh_smooth_gpu::{
    BilateralOptions, CpuSmoother, GpuSmoother, LaplacianOptions, SmoothError, Smoother,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Laplacian points: |gpu − cpu| ≤ this × (1 + |coordinate|).
const LAPLACIAN_TOLERANCE: f64 = 1e-5;
/// Bilateral unit normals: component-wise |gpu − cpu| ≤ this (on real data: for all but
/// [`ILL_CONDITIONED_FRACTION`] of the triangles).
const BILATERAL_TOLERANCE: f64 = 1e-4;
/// Triangles whose every neighbour weight is near `f32` underflow (a normal unlike all its
/// neighbours') turn with the last bits of `exp`; on real data this fraction of them may
/// differ by more than [`BILATERAL_TOLERANCE`], but by at most [`ILL_CONDITIONED_TOLERANCE`].
const ILL_CONDITIONED_FRACTION: f64 = 1e-4;
/// See [`ILL_CONDITIONED_FRACTION`].
const ILL_CONDITIONED_TOLERANCE: f64 = 1e-2;

/// The GPU, or `None` (skip) outside CI when there is none.
fn gpu() -> Option<GpuSmoother> {
    match GpuSmoother::new() {
        Ok(gpu) => {
            eprintln!("GPU adapter: {}", gpu.adapter_summary());
            Some(gpu)
        }
        Err(e @ (SmoothError::NoAdapter { .. } | SmoothError::RequestDevice { .. })) => {
            assert!(
                !test_fixtures::in_ci(),
                "no usable GPU adapter under CI=true: {e}; run .ci/install-gpu-deps.sh"
            );
            test_fixtures::record_skip(&format!("no GPU adapter ({e})"));
            None
        }
        Err(e) => panic!("unexpected error creating the GPU smoother: {e}"),
    }
}

#[test]
fn laplacian_matches_cpu_on_random_clouds() {
    let Some(mut gpu) = gpu() else { return };
    for (seed, (rows, cols)) in [(40, 57), (3, 3), (2, 9), (64, 31), (97, 120)]
        .into_iter()
        .enumerate()
    {
        let cloud = wavy_cloud(rows, cols, seed as u64, 0.01, 0.08);
        for kernel in [3, 5, 7] {
            for iterations in [0, 1, 2, 5] {
                let options = LaplacianOptions::new()
                    .with_kernel(kernel)
                    .with_lambda(0.8)
                    .with_iterations(iterations);
                let cpu = CpuSmoother::serial()
                    .laplacian(&cloud, &options)
                    .expect("valid options");
                let on_gpu = gpu.laplacian(&cloud, &options).expect("GPU run");
                let diff = max_relative_difference(on_gpu.points(), cpu.points());
                assert!(
                    diff <= LAPLACIAN_TOLERANCE,
                    "{rows}×{cols} kernel {kernel} it {iterations}: difference {diff}"
                );
            }
        }
    }
}

#[test]
fn per_pixel_laplacian_matches_cpu_on_random_clouds() {
    let Some(mut gpu) = gpu() else { return };
    for (seed, (rows, cols)) in [(40, 57), (3, 3), (64, 31), (97, 120)]
        .into_iter()
        .enumerate()
    {
        let cloud = wavy_cloud(rows, cols, 50 + seed as u64, 0.01, 0.08);
        let mut rng = ChaCha8Rng::seed_from_u64(seed as u64);
        for max_passes in [0u8, 1, 4, 9] {
            let passes: Vec<u8> = (0..rows * cols)
                .map(|_| rng.random_range(0..=max_passes))
                .collect();
            for kernel in [3, 5] {
                let options = LaplacianOptions::new().with_kernel(kernel).with_lambda(0.8);
                let mut cpu = cloud.clone();
                CpuSmoother::serial()
                    .laplacian_in_place_per_pixel(&mut cpu, &options, &passes)
                    .expect("valid options");
                let on_gpu = gpu
                    .laplacian_per_pixel(&cloud, &options, &passes)
                    .expect("GPU run");
                let diff = max_relative_difference(on_gpu.points(), cpu.points());
                assert!(
                    diff <= LAPLACIAN_TOLERANCE,
                    "{rows}×{cols} kernel {kernel} up to {max_passes} passes: difference {diff}"
                );
                // Points with no pass keep their f64 coordinates exactly.
                for (i, (&n, (g, c))) in passes
                    .iter()
                    .zip(on_gpu.points().iter().zip(cloud.points()))
                    .enumerate()
                {
                    if n == 0 && opc_mesh::is_valid(c) {
                        assert_eq!(g, c, "point {i} has no pass but moved");
                    }
                }
            }
        }
    }
    let cloud = wavy_cloud(10, 10, 1, 0.01, 0.0);
    let error = gpu
        .laplacian_per_pixel(&cloud, &LaplacianOptions::new(), &[1; 99])
        .expect_err("99 counts for 100 points");
    assert!(matches!(
        error,
        SmoothError::InvalidParameter { name: "passes", .. }
    ));
}

#[test]
fn laplacian_then_bilateral_is_the_two_calls_in_one() {
    let Some(mut gpu) = gpu() else { return };
    let normal_bits =
        |n: &[[f32; 3]]| -> Vec<[u32; 3]> { n.iter().map(|v| v.map(f32::to_bits)).collect() };
    for (seed, (rows, cols)) in [(40, 57), (3, 3), (64, 31)].into_iter().enumerate() {
        let cloud = wavy_cloud(rows, cols, 70 + seed as u64, 0.01, 0.08);
        let mut rng = ChaCha8Rng::seed_from_u64(seed as u64);
        let passes: Vec<u8> = (0..rows * cols).map(|_| rng.random_range(0..=5)).collect();
        for iterations in [0, 1, 2, 3] {
            let laplacian = LaplacianOptions::new().with_iterations(iterations);
            let bilateral = BilateralOptions::new().with_iterations(2);
            for per_pixel in [None, Some(passes.as_slice())] {
                let smoothed = match per_pixel {
                    Some(p) => gpu.laplacian_per_pixel(&cloud, &laplacian, p),
                    None => gpu.laplacian(&cloud, &laplacian),
                }
                .expect("GPU run");
                let normals = gpu.bilateral(&smoothed, &bilateral).expect("GPU run");
                let (fused, seen, fused_normals) = gpu
                    .laplacian_then_bilateral(&cloud, &laplacian, per_pixel, &bilateral, |c| {
                        common::bits(c.points())
                    })
                    .expect("GPU run");
                let what = format!(
                    "{rows}×{cols}, {iterations} it, per pixel {}",
                    per_pixel.is_some()
                );
                assert_eq!(
                    common::bits(fused.points()),
                    common::bits(smoothed.points()),
                    "{what}"
                );
                assert_eq!(
                    seen,
                    common::bits(smoothed.points()),
                    "{what}: `between` sees it"
                );
                assert_eq!(
                    normal_bits(fused_normals.as_slice()),
                    normal_bits(normals.as_slice()),
                    "{what}"
                );
            }
        }
    }
}

#[test]
fn bilateral_matches_cpu_on_random_clouds() {
    let Some(mut gpu) = gpu() else { return };
    for (seed, (rows, cols)) in [(40, 57), (2, 2), (3, 8), (64, 31), (97, 120)]
        .into_iter()
        .enumerate()
    {
        let cloud = wavy_cloud(rows, cols, 100 + seed as u64, 0.004, 0.08);
        for kernel in [3, 5] {
            for iterations in [0, 1, 2, 5] {
                let options = BilateralOptions::new()
                    .with_kernel(kernel)
                    .with_sigma_length(0.1)
                    .with_sigma_angle(0.3)
                    .with_iterations(iterations);
                let cpu = CpuSmoother::serial()
                    .bilateral(&cloud, &options)
                    .expect("valid options");
                let on_gpu = gpu.bilateral(&cloud, &options).expect("GPU run");
                let diff = max_normal_difference(on_gpu.as_slice(), cpu.as_slice());
                assert!(
                    diff <= BILATERAL_TOLERANCE,
                    "{rows}×{cols} kernel {kernel} it {iterations}: difference {diff}"
                );
            }
        }
    }
}

#[test]
fn smoother_is_reused_across_shapes_and_filters() {
    let Some(mut gpu) = gpu() else { return };
    let small = wavy_cloud(20, 30, 7, 0.01, 0.05);
    let large = wavy_cloud(50, 40, 8, 0.01, 0.05);
    let options = LaplacianOptions::new();
    let first = gpu.laplacian(&small, &options).expect("GPU run");
    gpu.bilateral(&large, &BilateralOptions::new())
        .expect("GPU run");
    gpu.laplacian(&large, &options).expect("GPU run");
    let again = gpu.laplacian(&small, &options).expect("GPU run");
    assert_eq!(common::bits(first.points()), common::bits(again.points()));
}

#[test]
fn the_gpu_is_a_smoother_like_the_cpu() {
    let Some(gpu) = gpu() else { return };
    let cloud = wavy_cloud(16, 16, 9, 0.01, 0.05);
    let options = BilateralOptions::new();
    let mut smoothers: [Box<dyn Smoother>; 2] = [Box::new(gpu), Box::new(CpuSmoother::new())];
    let [on_gpu, on_cpu] = smoothers
        .each_mut()
        .map(|s| s.bilateral(&cloud, &options).expect("valid options"));
    assert_eq!(on_gpu.as_slice().len(), 2 * 15 * 15);
    let diff = max_normal_difference(on_gpu.as_slice(), on_cpu.as_slice());
    assert!(diff <= BILATERAL_TOLERANCE, "difference {diff}");
}

/// The SynPEB cloud pc_01 (500 × 500, NaN where the simulated scan has no return).
fn pc_01() -> Option<opc_mesh::OrganizedPointCloud> {
    let path = test_fixtures::fixture("synpeb/pc_01.pcd")?;
    let pcd = polylidar_io::read_pcd(&path).expect("readable pc_01.pcd");
    Some(opc_mesh::OrganizedPointCloud::new(pcd.rows, pcd.cols, pcd.points).expect("organized"))
}

#[test]
fn gpu_matches_cpu_on_pc_01() {
    let Some(cloud) = pc_01() else { return };
    let Some(mut gpu) = gpu() else { return };
    let laplacian = LaplacianOptions::new().with_kernel(3).with_iterations(5);
    let cpu = mesh_smooth_gpu::laplacian_filter(&cloud, &laplacian).expect("valid options");
    let on_gpu = gpu.laplacian(&cloud, &laplacian).expect("GPU run");
    let diff = max_relative_difference(on_gpu.points(), cpu.points());
    eprintln!("pc_01 Laplacian k3 5 it: max relative difference {diff:e}");
    assert!(diff <= LAPLACIAN_TOLERANCE);

    let bilateral = BilateralOptions::new().with_kernel(3).with_iterations(2);
    let cpu = mesh_smooth_gpu::bilateral_filter(&cloud, &bilateral).expect("valid options");
    let on_gpu = gpu.bilateral(&cloud, &bilateral).expect("GPU run");
    let diff = max_normal_difference(on_gpu.as_slice(), cpu.as_slice());
    let beyond = on_gpu
        .as_slice()
        .iter()
        .zip(cpu.as_slice())
        .filter(|(g, c)| (0..3).any(|k| f64::from((g[k] - c[k]).abs()) > BILATERAL_TOLERANCE))
        .count();
    let fraction = beyond as f64 / cpu.num_present() as f64;
    eprintln!(
        "pc_01 bilateral k3 2 it: max normal difference {diff:e}; {beyond} of {} triangles beyond {BILATERAL_TOLERANCE:e}",
        cpu.num_present()
    );
    assert!(diff <= ILL_CONDITIONED_TOLERANCE);
    assert!(fraction <= ILL_CONDITIONED_FRACTION);
}
