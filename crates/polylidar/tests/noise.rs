//! The point-noise estimator and `laplacian.iterations = "auto"`.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

use polylidar::{
    Config, LaplacianConfig, LaplacianIterations, OrganizedPointCloud, Polylidar,
    auto_laplacian_iterations, estimate_noise, estimate_noise_absolute, estimate_noise_correlation,
    predict_laplacian_iterations,
};
use synthscan::{Noise, PinholeCamera, Pose, RoomConfig, Scene};

/// A 120 × 160 depth-camera scan of the default room from above.
fn room_scan(noise: &Noise) -> OrganizedPointCloud {
    let scene = Scene::room(&RoomConfig::default()).expect("room");
    let pose = Pose::look_at([3.0, 0.3, 2.6], [3.2, 3.0, 0.0], [0.0, 0.0, 1.0]).expect("pose");
    let camera = PinholeCamera::new(120, 160, 80.0, 80.0)
        .expect("camera")
        .with_pose(pose);
    let scan = scene.scan(&camera, noise).expect("scan");
    OrganizedPointCloud::new(scan.rows, scan.cols, scan.points).expect("cloud")
}

#[test]
fn estimate_grows_with_tangential_noise() {
    let estimates: Vec<f64> = [0.5, 1.0, 2.0, 4.0]
        .iter()
        .map(|&mdeg| estimate_noise(&room_scan(&Noise::new(0.0, mdeg, 3))).expect("estimate"))
        .collect();
    for pair in estimates.windows(2) {
        assert!(pair[0] < pair[1], "{estimates:?}");
    }
    // Twice the angle, about twice the estimate.
    let ratio = estimates[3] / estimates[2];
    assert!((1.6..2.4).contains(&ratio), "{estimates:?}");
}

#[test]
fn estimate_grows_with_radial_noise_in_both_units() {
    let clouds: Vec<_> = [0.001, 0.004]
        .iter()
        .map(|&sigma| room_scan(&Noise::new(sigma, 0.0, 5)))
        .collect();
    let rel: Vec<f64> = clouds
        .iter()
        .map(|c| estimate_noise(c).expect("estimate"))
        .collect();
    let abs: Vec<f64> = clouds
        .iter()
        .map(|c| estimate_noise_absolute(c).expect("estimate"))
        .collect();
    assert!(rel[0] < rel[1] && abs[0] < abs[1], "{rel:?} {abs:?}");
    // The absolute estimate is of the order of the radial sigma.
    assert!(abs[1] > 0.001 && abs[1] < 0.008, "{abs:?}");
}

#[test]
fn estimate_is_zero_without_noise_and_scale_free() {
    let cloud = room_scan(&Noise::none());
    let e = estimate_noise(&cloud).expect("estimate");
    assert!(e < 1e-6, "{e}");
    // Millimetres instead of metres: the relative estimate does not change.
    let noisy = room_scan(&Noise::new(0.002, 1.0, 1));
    let mm: Vec<[f64; 3]> = noisy
        .points()
        .iter()
        .map(|p| p.map(|v| v * 1000.0))
        .collect();
    let scaled = OrganizedPointCloud::new(noisy.rows(), noisy.cols(), mm).expect("cloud");
    let (a, b) = (
        estimate_noise(&noisy).expect("estimate"),
        estimate_noise(&scaled).expect("estimate"),
    );
    assert!((a - b).abs() <= 1e-9 * a.max(1e-12) + 1e-12, "{a} vs {b}");
    let (a, b) = (
        estimate_noise_absolute(&noisy).expect("estimate"),
        estimate_noise_absolute(&scaled).expect("estimate"),
    );
    assert!((b / a - 1000.0).abs() < 1e-6, "{a} vs {b}");
}

#[test]
fn estimate_handles_holes_and_empty_clouds() {
    let noise = Noise::new(0.0, 2.0, 9);
    let full = room_scan(&noise);
    let reference = estimate_noise(&full).expect("estimate");
    // Knock out every 7th pixel: fewer neighbourhoods qualify, the median barely moves.
    let mut points = full.points().to_vec();
    for p in points.iter_mut().step_by(7) {
        *p = [f64::NAN; 3];
    }
    let holed = OrganizedPointCloud::new(full.rows(), full.cols(), points).expect("cloud");
    let e = estimate_noise(&holed).expect("estimate");
    assert!((e / reference - 1.0).abs() < 0.3, "{e} vs {reference}");

    let nan = OrganizedPointCloud::new(20, 30, vec![[f64::NAN; 3]; 600]).expect("cloud");
    assert_eq!(estimate_noise(&nan), None);
    assert_eq!(estimate_noise_absolute(&nan), None);
    let thin = OrganizedPointCloud::new(2, 30, vec![[0.0, 0.0, 1.0]; 60]).expect("cloud");
    assert_eq!(estimate_noise(&thin), None);
}

#[test]
fn auto_iterations_parse_from_toml_and_round_trip() {
    let config: Config =
        toml::from_str("[laplacian]\nkernel = 5\niterations = \"auto\"\n").expect("toml");
    let laplacian = config.laplacian.expect("laplacian");
    assert_eq!(laplacian.iterations, LaplacianIterations::Auto);
    let text = toml::to_string(&config).expect("serialise");
    assert!(text.contains("iterations = \"auto\""), "{text}");
    assert_eq!(toml::from_str::<Config>(&text).expect("toml"), config);

    let fixed: LaplacianConfig = toml::from_str("iterations = 8").expect("toml");
    assert_eq!(fixed.iterations, LaplacianIterations::Fixed(8));
    let text = toml::to_string(&fixed).expect("serialise");
    assert!(text.contains("iterations = 8"), "{text}");
    assert_eq!(
        toml::from_str::<LaplacianConfig>(&text).expect("toml"),
        fixed
    );

    for bad in [
        "iterations = -1",
        "iterations = \"many\"",
        "iterations = 1.5",
    ] {
        assert!(toml::from_str::<LaplacianConfig>(bad).is_err(), "{bad}");
    }
}

#[test]
fn synpeb_presets_predict_or_fix_the_iterations() {
    let auto = Config::preset("synpeb-auto")
        .and_then(|c| c.laplacian)
        .expect("laplacian");
    assert_eq!(auto.iterations, LaplacianIterations::Auto);
    let fixed = Config::preset("synpeb")
        .and_then(|c| c.laplacian)
        .expect("laplacian");
    assert_eq!(fixed.iterations, LaplacianIterations::Fixed(8));
    assert_eq!(auto.kernel, fixed.kernel);
}

#[test]
fn auto_run_records_its_iterations_and_matches_the_fixed_run() {
    let cloud = room_scan(&Noise::new(0.004, 2.0, 11));
    let base = Config::new()
        .with_lmax(0.15)
        .with_min_triangles(150)
        .with_norm_thresh(0.95)
        .with_z_thresh(0.05)
        .with_threads(2);
    let with = |iterations: LaplacianIterations| {
        base.clone().with_laplacian(Some(
            LaplacianConfig::default()
                .with_kernel(5)
                .with_iterations(iterations),
        ))
    };
    let auto = Polylidar::new(with(LaplacianIterations::Auto))
        .expect("config")
        .extract_organized(&cloud)
        .expect("extraction");
    let expected = auto_laplacian_iterations(&cloud);
    let chosen = auto.diagnostics.counts.laplacian_iterations;
    assert_eq!(chosen, expected);
    assert!(auto.diagnostics.timings.get("laplacian").is_some());

    let fixed = Polylidar::new(with(LaplacianIterations::Fixed(chosen)))
        .expect("config")
        .extract_organized(&cloud)
        .expect("extraction");
    assert_eq!(fixed.diagnostics.counts, auto.diagnostics.counts);
    assert_eq!(fixed.polygons.len(), auto.polygons.len());
    assert_eq!(fixed.point_labels(), auto.point_labels());
    assert_eq!(fixed.mesh.vertices(), auto.mesh.vertices());

    // Without a Laplacian section the count is 0.
    let none = Polylidar::new(base)
        .expect("config")
        .extract_organized(&cloud)
        .expect("extraction");
    assert_eq!(none.diagnostics.counts.laplacian_iterations, 0);
}

/// Noise correlated over several pixels gets more passes than noise of the same
/// fine-scale size drawn per point: the fine estimate alone cannot tell them apart.
#[test]
fn correlated_noise_gets_more_passes() {
    let n = 120;
    let cloud = |z: &dyn Fn(usize, usize) -> f64| {
        let points = (0..n * n)
            .map(|i| {
                let (r, c) = (i / n, i % n);
                [c as f64 * 0.01, r as f64 * 0.01, z(r, c)]
            })
            .collect();
        OrganizedPointCloud::new(n, n, points).expect("cloud")
    };
    // Independent per point: a hash of the pixel in [-1, 1].
    let hash = |r: usize, c: usize| {
        let h = (r as u64 * 73_856_093) ^ (c as u64 * 19_349_663);
        ((h.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 40) as f64 / (1u64 << 24) as f64) * 2.0 - 1.0
    };
    let white = cloud(&|r, c| 0.003 * hash(r, c));
    let ripples = cloud(&|r, c| {
        let t = std::f64::consts::TAU;
        0.004 * ((c as f64 * t / 9.0).sin() + (r as f64 * t / 11.0).cos())
    });
    let (w, rip) = (
        estimate_noise_correlation(&white).expect("white"),
        estimate_noise_correlation(&ripples).expect("ripples"),
    );
    assert!(w < 0.7 && rip > 1.0, "white {w}, ripples {rip}");
    let base = |c: &OrganizedPointCloud| predict_laplacian_iterations(estimate_noise(c).unwrap());
    assert_eq!(auto_laplacian_iterations(&white), base(&white));
    assert!(auto_laplacian_iterations(&ripples) > base(&ripples));
}

#[test]
fn passes_that_grow_with_range_keep_a_far_quantised_wall_whole() {
    // A Kinect-like 640 × 480 frame: depth error σ ∝ z² and disparity steps of 1/8 px
    // cut the back wall (4–5 m away) into terraces. With one pass count for the whole
    // frame (set by its median noise, the near floor's) the terraces stay and the wall
    // breaks into bands too small to keep; with passes growing with range it is found.
    let kind = synthscan::DepthCameraKind::Kinect;
    let (scene, camera) = synthscan::rgbd_like(1, kind).expect("scene");
    let scan = scene.scan_depth(&camera, 1).expect("scan");
    let cloud = OrganizedPointCloud::new(scan.rows, scan.cols, scan.points).expect("cloud");
    let wall = 2;
    let found = |preset: &str| {
        let config = Config::preset(preset).expect("preset").with_threads(2);
        let extraction = Polylidar::new(config)
            .expect("config")
            .extract_organized(&cloud)
            .expect("extraction");
        let labels = extraction.plane_labels();
        let scores = seg_metrics::evaluate(
            cloud.points(),
            &scan.labels,
            &labels,
            &seg_metrics::EvaluateOptions::new(),
        )
        .expect("scores");
        scores.matches.iter().any(|m| m.truth == wall)
    };
    assert!(
        !found("synpeb-auto"),
        "uniform passes were expected to break the wall"
    );
    assert!(found("rgbd-auto"));
}

#[test]
fn range_exponent_is_checked() {
    let mut config = Config::preset("rgbd-auto").expect("preset");
    assert!(config.validate().is_ok());
    for bad in [-0.5, 4.5, f64::NAN] {
        if let Some(l) = config.laplacian.as_mut() {
            l.range_exponent = bad;
        }
        let error = Polylidar::new(config.clone()).expect_err("invalid exponent");
        assert!(error.to_string().contains("range_exponent"), "{error}");
    }
}
