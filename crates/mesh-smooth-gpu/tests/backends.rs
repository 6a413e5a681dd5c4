//! `CpuSmoother::serial` and `CpuSmoother::new` (the rayon pool) give bit-identical results
//! at any thread count, filtering into a copy or in place.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

mod common;

use common::{bits, normal_bits, wavy_cloud};
use mesh_smooth_gpu::{
    BilateralOptions, CpuSmoother, GpuSmoother, LaplacianOptions, SmoothError, Smoother,
};
use opc_mesh::OrganizedPointCloud;
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
        holes in 0.0f64..0.5, half in 1u32..4, iterations in 0u32..4, lambda in 0.05f32..=1.0,
    ) {
        let cloud = wavy_cloud(rows, cols, seed, 0.01, holes);
        let options = LaplacianOptions::new()
            .with_kernel(2 * half + 1)
            .with_lambda(lambda)
            .with_iterations(iterations);
        let cpu = CpuSmoother::serial().laplacian(&cloud, &options).expect("valid options");
        // The copy is written in one pass of its own: it matches the in-place filter.
        let mut in_place = cloud.clone();
        CpuSmoother::serial().laplacian_in_place(&mut in_place, &options).expect("valid options");
        prop_assert_eq!(bits(cpu.points()), bits(in_place.points()));
        for threads in [1, 3, 4] {
            let parallel = pool(threads)
                .install(|| mesh_smooth_gpu::laplacian_filter(&cloud, &options))
                .expect("valid options");
            prop_assert_eq!(bits(cpu.points()), bits(parallel.points()));
            let mut in_place = cloud.clone();
            pool(threads)
                .install(|| CpuSmoother::new().laplacian_in_place(&mut in_place, &options))
                .expect("valid options");
            prop_assert_eq!(bits(cpu.points()), bits(in_place.points()));
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
        let cpu = CpuSmoother::serial().bilateral(&cloud, &options).expect("valid options");
        for threads in [1, 3, 4] {
            let parallel = pool(threads)
                .install(|| mesh_smooth_gpu::bilateral_filter(&cloud, &options))
                .expect("valid options");
            prop_assert_eq!(normal_bits(cpu.as_slice()), normal_bits(parallel.as_slice()));
        }
    }
}

#[test]
fn invalid_options_are_errors_on_every_backend() {
    let cloud = wavy_cloud(8, 8, 1, 0.0, 0.0);
    let mut smoothers: Vec<Box<dyn Smoother>> = vec![
        Box::new(CpuSmoother::serial()),
        Box::new(CpuSmoother::new()),
    ];
    // Where this build has a GPU adapter; without the feature `new` is an error.
    if let Ok(gpu) = GpuSmoother::new() {
        smoothers.push(Box::new(gpu));
    }
    for smoother in &mut smoothers {
        let options = LaplacianOptions::new().with_kernel(4);
        assert_eq!(
            smoother.laplacian(&cloud, &options),
            Err(SmoothError::InvalidKernel { kernel: 4 })
        );
        let options = BilateralOptions::new().with_sigma_angle(f32::NAN);
        assert!(matches!(
            smoother.bilateral(&cloud, &options),
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
    assert!(matches!(
        GpuSmoother::new(),
        Err(SmoothError::GpuFeatureDisabled)
    ));
}

#[test]
fn a_reused_cpu_smoother_matches_fresh_calls() {
    use mesh_smooth_gpu::SlotNormals;
    let mut smoother = CpuSmoother::new();
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
    assert!(smoother.is_parallel() && !CpuSmoother::serial().is_parallel());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Per-pixel pass counts against uniform runs: pixels with `a` passes take exactly the
    /// uniform `a`-pass values (every pixel moves in the first `a` passes, so they are
    /// computed from the same numbers); pixels with `b` passes far enough from the others
    /// that the frozen ones cannot reach them within `b` passes take the uniform `b`-pass
    /// values; one count everywhere is the uniform filter; 0 leaves a pixel bit for bit.
    /// The counts split the grid by columns, or by rows (whose finished rows the filter
    /// copies whole).
    #[test]
    fn per_pixel_passes_match_uniform_runs(
        rows in 8usize..40, cols in 24usize..60, seed in any::<u64>(), holes in 0.0f64..0.3,
        half in 1u32..3, a in 0u8..3, extra in 1u8..4, split in 0.2f64..0.8,
        threads in 1usize..4, by_rows in any::<bool>(),
    ) {
        let b = a + extra;
        let cloud = wavy_cloud(rows, cols, seed, 0.01, holes);
        let options = LaplacianOptions::new().with_kernel(2 * half + 1).with_lambda(0.8);
        // The coordinate across the split: the column, or the row.
        let across = |i: usize| if by_rows { i / cols } else { i % cols };
        let boundary = (split * if by_rows { rows } else { cols } as f64) as usize;
        let passes: Vec<u8> =
            (0..rows * cols).map(|i| if across(i) < boundary { a } else { b }).collect();
        let mut smoother = CpuSmoother::new();
        let mut mixed = cloud.clone();
        pool(threads)
            .install(|| smoother.laplacian_in_place_per_pixel(&mut mixed, &options, &passes))
            .expect("valid");
        let uniform = |n: u8| {
            mesh_smooth_gpu::laplacian_filter(&cloud, &options.with_iterations(u32::from(n)))
                .expect("valid")
        };
        let (low, high) = (uniform(a), uniform(b));
        // Frozen pixels influence others from the pass after they stop: b − a passes of
        // reach, `half` columns (or rows) each.
        let reach = (usize::from(b - a) + 1) * half as usize;
        for (i, p) in mixed.points().iter().enumerate() {
            let c = across(i);
            let bits_of = |q: &[f64; 3]| q.map(f64::to_bits);
            if c < boundary {
                prop_assert_eq!(bits_of(p), bits_of(&low.points()[i]), "pixel {}", i);
            } else if c >= boundary + reach {
                prop_assert_eq!(bits_of(p), bits_of(&high.points()[i]), "pixel {}", i);
            }
        }
        let mut same = cloud.clone();
        smoother
            .laplacian_in_place_per_pixel(&mut same, &options, &vec![b; rows * cols])
            .expect("valid");
        prop_assert_eq!(bits(same.points()), bits(high.points()));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Per-pixel pass counts on 1–3 threads against their definition, pass by pass: each
    /// pass is one uniform pass of the serial filter over the whole cloud, after which the
    /// pixels whose count it reached take back their points. Counts come per row (so that
    /// whole rows finish early) with some pixels of their own; every pixel is compared,
    /// bit for bit.
    #[test]
    fn per_pixel_passes_follow_their_definition(
        rows in 6usize..48, cols in 6usize..50, seed in any::<u64>(), holes in 0.0f64..0.3,
        half in 1u32..4, threads in 1usize..4,
        row_counts in proptest::collection::vec(0u8..4, 48),
        own in proptest::collection::vec(proptest::option::weighted(0.2, 0u8..4), 2400),
    ) {
        let cloud = wavy_cloud(rows, cols, seed, 0.01, holes);
        let options = LaplacianOptions::new().with_kernel(2 * half + 1).with_lambda(0.8);
        let passes: Vec<u8> =
            (0..rows * cols).map(|i| own[i].unwrap_or(row_counts[i / cols])).collect();
        let mut smoother = CpuSmoother::new();
        let mut got = cloud.clone();
        pool(threads)
            .install(|| smoother.laplacian_in_place_per_pixel(&mut got, &options, &passes))
            .expect("valid");
        // One task over the whole grid: no band split shared with the run checked.
        let mut serial = CpuSmoother::serial();
        let mut want = cloud.clone();
        let one_pass = options.with_iterations(1);
        for pass in 0..passes.iter().copied().max().unwrap_or(0) {
            let next = serial.laplacian(&want, &one_pass).expect("valid");
            let points: Vec<[f64; 3]> = want
                .points()
                .iter()
                .zip(next.points())
                .zip(&passes)
                .map(|((&kept, &moved), &count)| if count > pass { moved } else { kept })
                .collect();
            want = OrganizedPointCloud::new(rows, cols, points).expect("same shape");
        }
        prop_assert_eq!(bits(got.points()), bits(want.points()));
    }
}

#[test]
fn per_pixel_passes_need_one_count_per_point() {
    let mut smoother = CpuSmoother::serial();
    let mut cloud = wavy_cloud(5, 5, 1, 0.01, 0.0);
    let before = bits(cloud.points());
    let error = smoother
        .laplacian_in_place_per_pixel(&mut cloud, &LaplacianOptions::new(), &[1; 24])
        .unwrap_err();
    assert!(matches!(
        error,
        SmoothError::InvalidParameter { name: "passes", .. }
    ));
    assert_eq!(bits(cloud.points()), before);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// `laplacian_smoothed` then `Smoothed::bilateral_into_mesh`, which starts from the
    /// Laplacian's own planes, gives the cloud and the normals of the two filters one
    /// after the other, owned or borrowed, with uniform or per-pixel passes (zero
    /// included: nothing to reuse), on both CPU backends; the planes count the cloud's
    /// valid points.
    #[test]
    fn smoothed_bilateral_matches_the_two_filters(
        rows in 3usize..30, cols in 3usize..30, seed in any::<u64>(), holes in 0.0f64..0.4,
        laplacian_half in 1u32..3, iterations in 0u32..4, per_pixel in any::<bool>(),
        bilateral_half in 1u32..3, owned in any::<bool>(),
    ) {
        let cloud = wavy_cloud(rows, cols, seed, 0.01, holes);
        let laplacian = LaplacianOptions::new()
            .with_kernel(2 * laplacian_half + 1)
            .with_iterations(iterations);
        let bilateral = BilateralOptions::new().with_kernel(2 * bilateral_half + 1);
        let passes: Vec<u8> = (0..rows * cols).map(|i| (i * 7 % 5) as u8).collect();
        let passes = per_pixel.then_some(passes.as_slice());
        let mesh_options = opc_mesh::OpcMeshOptions::new().with_compute_normals(false);
        for mut smoother in [CpuSmoother::serial(), CpuSmoother::new()] {
            let mut expected_cloud = cloud.clone();
            match passes {
                Some(p) => smoother.laplacian_in_place_per_pixel(&mut expected_cloud, &laplacian, p),
                None => smoother.laplacian_in_place(&mut expected_cloud, &laplacian),
            }
            .expect("valid options");
            let Ok(mut expected) = expected_cloud.mesh(&mesh_options) else {
                continue;
            };
            smoother
                .bilateral_into_mesh(&expected_cloud, &bilateral, &mut expected)
                .expect("the same cloud");

            let normal_bits = |n: Option<&[[f64; 3]]>| {
                n.map(|n| n.iter().map(|v| v.map(f64::to_bits)).collect::<Vec<_>>())
            };
            let expected_normals = normal_bits(expected.mesh.triangle_normals());
            // With the cloud.
            let mut smoothed = smooth(&mut smoother, &cloud, owned, &laplacian, passes);
            prop_assert_eq!(bits(smoothed.cloud().points()), bits(expected_cloud.points()));
            let mut got = smoothed.cloud().mesh(&mesh_options).expect("meshed above");
            smoothed.bilateral_into_mesh(&bilateral, &mut got).expect("the same cloud");
            prop_assert_eq!(normal_bits(got.mesh.triangle_normals()), expected_normals.clone());
            // With the cloud moved into its mesh, where a pass left planes.
            let half = laplacian_half as usize;
            let runs = passes.map_or(iterations > 0, |p| p.iter().any(|&n| n > 0))
                && rows > 2 * half
                && cols > 2 * half;
            let parts = smooth(&mut smoother, &cloud, owned, &laplacian, passes).into_parts();
            prop_assert_eq!(parts.is_ok(), runs);
            if let Ok((cloud, mut planes)) = parts {
                prop_assert_eq!(planes.num_valid(), cloud.num_valid());
                let mut got = cloud.into_mesh(&mesh_options).expect("meshed above");
                planes.bilateral_into_mesh(&bilateral, &mut got).expect("the same cloud");
                prop_assert_eq!(normal_bits(got.mesh.triangle_normals()), expected_normals);
            }
        }
    }
}

/// `cloud` through `laplacian_smoothed`, owned or borrowed.
fn smooth<'a>(
    smoother: &'a mut CpuSmoother,
    cloud: &'a opc_mesh::OrganizedPointCloud,
    owned: bool,
    laplacian: &LaplacianOptions,
    passes: Option<&[u8]>,
) -> mesh_smooth_gpu::Smoothed<'a> {
    let input = if owned {
        std::borrow::Cow::Owned(cloud.clone())
    } else {
        std::borrow::Cow::Borrowed(cloud)
    };
    smoother
        .laplacian_smoothed(input, laplacian, passes)
        .expect("valid options")
}
