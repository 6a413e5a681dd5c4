//! `Cpu` and `CpuParallel` give bit-identical results at any thread count.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

mod common;

use common::{bits, normal_bits, wavy_cloud};
use mesh_smooth_gpu::{Backend, BilateralOptions, LaplacianOptions, SmoothError};
use proptest::prelude::*;

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn laplacian_parallel_is_identical(
        rows in 2usize..48, cols in 2usize..48, seed in any::<u64>(),
        holes in 0.0f64..0.5, half in 1u32..4, iterations in 0u32..4, lambda in -0.5f32..1.5,
    ) {
        let cloud = wavy_cloud(rows, cols, seed, 0.01, holes);
        let options = LaplacianOptions::new()
            .with_kernel(2 * half + 1)
            .with_lambda(lambda)
            .with_iterations(iterations);
        let cpu = mesh_smooth_gpu::laplacian_filter(&cloud, &options.with_backend(Backend::Cpu))
            .expect("valid options");
        for threads in [1, 3, 4] {
            let parallel = pool(threads).install(|| {
                mesh_smooth_gpu::laplacian_filter(&cloud, &options.with_backend(Backend::CpuParallel))
            }).expect("valid options");
            prop_assert_eq!(bits(cpu.points()), bits(parallel.points()));
        }
    }

    #[test]
    fn bilateral_parallel_is_identical(
        rows in 2usize..48, cols in 2usize..48, seed in any::<u64>(),
        holes in 0.0f64..0.5, half in 1u32..3, iterations in 0u32..4,
        sigma_length in 0.01f32..0.5, sigma_angle in 0.05f32..1.0,
    ) {
        let cloud = wavy_cloud(rows, cols, seed, 0.01, holes);
        let options = BilateralOptions::new()
            .with_kernel(2 * half + 1)
            .with_sigma_length(sigma_length)
            .with_sigma_angle(sigma_angle)
            .with_iterations(iterations);
        let cpu = mesh_smooth_gpu::bilateral_filter(&cloud, &options.with_backend(Backend::Cpu))
            .expect("valid options");
        for threads in [1, 3, 4] {
            let parallel = pool(threads).install(|| {
                mesh_smooth_gpu::bilateral_filter(&cloud, &options.with_backend(Backend::CpuParallel))
            }).expect("valid options");
            prop_assert_eq!(normal_bits(cpu.as_slice()), normal_bits(parallel.as_slice()));
        }
    }
}

#[test]
fn invalid_options_are_errors_on_every_backend() {
    let cloud = wavy_cloud(8, 8, 1, 0.0, 0.0);
    for backend in [Backend::Cpu, Backend::CpuParallel, Backend::Gpu] {
        let options = LaplacianOptions::new().with_kernel(4).with_backend(backend);
        assert_eq!(
            mesh_smooth_gpu::laplacian_filter(&cloud, &options),
            Err(SmoothError::InvalidKernel { kernel: 4 })
        );
        let options = BilateralOptions::new()
            .with_sigma_angle(f32::NAN)
            .with_backend(backend);
        assert!(matches!(
            mesh_smooth_gpu::bilateral_filter(&cloud, &options),
            Err(SmoothError::InvalidParameter {
                name: "sigma_angle",
                ..
            })
        ));
    }
}

#[cfg(not(feature = "gpu"))]
#[test]
fn gpu_backend_without_the_feature_is_a_clear_error() {
    let cloud = wavy_cloud(8, 8, 1, 0.0, 0.0);
    let options = LaplacianOptions::new().with_backend(Backend::Gpu);
    assert_eq!(
        mesh_smooth_gpu::laplacian_filter(&cloud, &options),
        Err(SmoothError::GpuFeatureDisabled)
    );
}

#[test]
fn a_reused_cpu_smoother_matches_fresh_calls() {
    use mesh_smooth_gpu::{CpuSmoother, SlotNormals};
    let mut smoother = CpuSmoother::new(Backend::CpuParallel).unwrap();
    let mut normals = SlotNormals::default();
    let laplacian = LaplacianOptions::new().with_kernel(5).with_iterations(3);
    let bilateral = BilateralOptions::new().with_iterations(2);
    for (seed, (rows, cols)) in [(30, 40), (12, 9), (30, 40), (50, 20)]
        .into_iter()
        .enumerate()
    {
        let cloud = wavy_cloud(rows, cols, seed as u64, 0.01, 0.1);
        let fresh = mesh_smooth_gpu::laplacian_filter(&cloud, &laplacian).unwrap();
        let mut reused = cloud.clone();
        smoother
            .laplacian_in_place(&mut reused, &laplacian)
            .unwrap();
        assert_eq!(bits(fresh.points()), bits(reused.points()));
        let fresh = mesh_smooth_gpu::bilateral_filter(&cloud, &bilateral).unwrap();
        smoother
            .bilateral_into(&cloud, &bilateral, &mut normals)
            .unwrap();
        assert_eq!(
            normal_bits(fresh.as_slice()),
            normal_bits(normals.as_slice())
        );
        assert_eq!((normals.cloud_rows(), normals.cloud_cols()), (rows, cols));
    }
    assert!(CpuSmoother::new(Backend::Gpu).is_err());
}
