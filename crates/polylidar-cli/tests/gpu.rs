//! `--gpu`: the smoothing filters on the GPU give the CPU's polygons on a shared RGB-D
//! frame; a build without the `gpu` feature refuses the flag and says how to get it.
//! The GPU run needs a wgpu adapter (Mesa's lavapipe will do): without one it fails under
//! CI (`CI=true`) and is skipped with a printed reason elsewhere.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

mod common;

use common::polylidar_in as polylidar;

/// `extract` of the TUM frame with preset `rgbd` and `extra` flags, in `dir`, writing
/// `out`.
fn extract_tum(dir: &std::path::Path, out: &str, extra: &[&str]) -> Option<std::process::Output> {
    let frame = test_fixtures::fixture("rgbd/tum_depth.png")?;
    let camera = test_fixtures::fixture("rgbd/camera_primesense.json")?;
    let (frame, camera) = (frame.display().to_string(), camera.display().to_string());
    let mut args = vec![
        "extract",
        &frame,
        "--intrinsics",
        &camera,
        "--depth-scale",
        "5000",
        "--preset",
        "rgbd",
        "-o",
        out,
    ];
    args.extend_from_slice(extra);
    Some(polylidar(dir, &args))
}

/// The polygons' areas (shell minus holes, in the plane of their x and y).
#[cfg(feature = "gpu")]
fn areas(path: &std::path::Path) -> Vec<f64> {
    let text = std::fs::read_to_string(path).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let ring_area = |ring: &serde_json::Value| {
        let p: Vec<[f64; 2]> = ring
            .as_array()
            .unwrap()
            .iter()
            .map(|c| [c[0].as_f64().unwrap(), c[1].as_f64().unwrap()])
            .collect();
        let twice: f64 = p
            .windows(2)
            .map(|w| w[0][0] * w[1][1] - w[1][0] * w[0][1])
            .sum();
        twice.abs() / 2.0
    };
    json["features"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            let rings = f["geometry"]["coordinates"].as_array().unwrap();
            ring_area(&rings[0]) - rings[1..].iter().map(ring_area).sum::<f64>()
        })
        .collect()
}

#[cfg(feature = "gpu")]
#[test]
fn gpu_smoothing_gives_the_cpu_polygons() {
    let dir = common::scratch("gpu", "tum");
    let Some(cpu) = extract_tum(&dir, "cpu.geojson", &[]) else {
        return;
    };
    common::succeeded(&cpu);
    let gpu = extract_tum(&dir, "gpu.geojson", &["--gpu"]).expect("fixtures found above");
    if !gpu.status.success() {
        let stderr = String::from_utf8_lossy(&gpu.stderr);
        assert!(
            stderr.contains("no GPU adapter") && !test_fixtures::in_ci(),
            "--gpu failed{}: {stderr}",
            if test_fixtures::in_ci() {
                " under CI=true"
            } else {
                ""
            }
        );
        test_fixtures::record_skip(&format!("no GPU adapter ({})", stderr.trim()));
        return;
    }
    let stderr = String::from_utf8_lossy(&gpu.stderr);
    assert!(stderr.contains("smoothing on the GPU"), "{stderr}");
    let (on_cpu, on_gpu) = (
        areas(&dir.join("cpu.geojson")),
        areas(&dir.join("gpu.geojson")),
    );
    assert!(!on_cpu.is_empty(), "the CPU run finds polygons");
    assert_eq!(on_gpu.len(), on_cpu.len(), "as many polygons on both");
    for (g, c) in on_gpu.iter().zip(&on_cpu) {
        assert!(
            (g - c).abs() <= 0.01 * c,
            "areas {g} (GPU) and {c} (CPU) differ by over 1 %"
        );
    }
}

#[cfg(feature = "gpu")]
#[test]
fn gpu_on_2d_points_is_reported_and_ignored() {
    let dir = common::scratch("gpu", "shape");
    let out = polylidar(
        &dir,
        &["extract", "--demo", "shape", "--gpu", "-o", "shape.geojson"],
    );
    let stderr = common::succeeded(&out);
    assert!(
        stderr.contains("--gpu does not apply to 2D points; ignored"),
        "{stderr}"
    );
}

#[cfg(not(feature = "gpu"))]
#[test]
fn without_the_feature_gpu_says_how_to_get_it() {
    let dir = common::scratch("gpu", "refused");
    let Some(out) = extract_tum(&dir, "gpu.geojson", &["--gpu"]) else {
        return;
    };
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("--features gpu"), "{stderr}");
}
