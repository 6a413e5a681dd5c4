//! The facade keeps its GPU smoother across frames: a stream of frames asks wgpu for one
//! adapter, and the GPU path finds the planes the CPU path finds. Runs on any wgpu
//! adapter, Mesa's lavapipe included; without one it fails under CI (`CI=true`) and is
//! skipped with a printed reason elsewhere. Alone in its test binary so that no other test
//! asks for an adapter while the count is read.
#![cfg(feature = "gpu")]
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

mod common;

use polylidar::{Config, OrganizedPointCloud, Polylidar, SmoothingBackend};

/// A 60 × 80 depth-camera-like view of two planes meeting at a ridge, slightly wavy so
/// that the smoothing has something to do; `shift` moves the ridge between frames.
fn ridge(shift: usize) -> OrganizedPointCloud {
    let (rows, cols) = (60, 80);
    let points = (0..rows * cols)
        .map(|i| {
            let (r, c) = ((i / cols) as f64, (i % cols) as f64);
            let x = (c - 40.0 - shift as f64) * 0.01;
            let y = (r - 30.0) * 0.01;
            let wave = 0.0005 * ((r * 0.7).sin() + (c * 1.3).cos());
            [x, y, 1.0 + 0.5 * x.abs() + wave]
        })
        .collect();
    OrganizedPointCloud::new(rows, cols, points).expect("60 × 80 points")
}

fn config(backend: SmoothingBackend) -> Config {
    let mut config = Config::preset("rgbd")
        .expect("rgbd preset")
        .with_smoothing_backend(backend);
    config.min_triangles = 200;
    config
}

#[test]
fn two_frames_ask_for_one_adapter() {
    let gpu = Polylidar::new(config(SmoothingBackend::Gpu)).expect("valid config");
    let before = mesh_smooth_gpu::adapter_requests();
    let Some(first) = common::gpu_run(gpu.extract_organized(&ridge(0)), "first frame") else {
        return;
    };
    let after_first = mesh_smooth_gpu::adapter_requests();
    assert!(
        after_first > before,
        "the first GPU frame asks for an adapter"
    );
    let second = gpu.extract_organized(&ridge(5)).expect("second GPU frame");
    assert_eq!(
        mesh_smooth_gpu::adapter_requests(),
        after_first,
        "the second frame reuses the first one's GPU context"
    );
    let cpu = Polylidar::new(config(SmoothingBackend::CpuParallel)).expect("valid config");
    for (on_gpu, shift) in [(first, 0), (second, 5)] {
        let on_cpu = cpu.extract_organized(&ridge(shift)).expect("CPU run");
        assert_eq!(on_gpu.polygons.len(), 2, "two planes at shift {shift}");
        assert_eq!(on_gpu.polygons.len(), on_cpu.polygons.len());
        for (g, c) in on_gpu.polygons.iter().zip(&on_cpu.polygons) {
            let dot: f64 = (0..3).map(|k| g.plane.normal[k] * c.plane.normal[k]).sum();
            assert!(dot > 0.9999, "GPU and CPU plane normals agree: {dot}");
        }
    }
}
