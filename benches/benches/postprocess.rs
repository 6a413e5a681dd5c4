//! Polygon post-processing (polypost) on synthetic polygons shaped like Polylidar3D's
//! output: RealSense-like frames (a handful of jagged polygons, 100–400 vertices, small
//! holes, metres) and larger SynPEB pc_01-like scenes, both with the paper's rgbd preset.
//!
//! The inputs are generated here with a fixed seed, so that the stage can be measured on
//! many polygon shapes: star-shaped shells whose boundary vertices are about 1.5 cm apart
//! with ±6 mm radial jitter (the staircase of boundary-following on a ~1 cm mesh), small
//! jagged holes, on random planes with ±3 mm off-plane noise. The polygons the pipeline
//! extracts from `realsense/rgbd_opc.npy` and `synpeb/pc_01.pcd` are post-processed in the
//! `pipeline_3d` bench.

use criterion::{Criterion, criterion_group, criterion_main};
use polypost::{Plane, Polygon3, PostProcessor, PostprocessConfig};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;

/// A jagged closed ring around `(cx, cy)` in the frame of `plane`: mean radius `r`,
/// vertices about `spacing` apart, radial jitter `jitter`, off-plane noise `noise`.
fn jagged_ring(
    rng: &mut ChaCha8Rng,
    plane: &Plane,
    centre: [f64; 2],
    r: f64,
    spacing: f64,
    jitter: f64,
    noise: f64,
) -> Vec<[f64; 3]> {
    let frame = plane.frame();
    let n = ((std::f64::consts::TAU * r / spacing).ceil() as usize).max(8);
    // Low-frequency shape: a few random harmonics, so shells are not circles.
    let harmonics: Vec<(f64, f64)> = (2..5)
        .map(|_| {
            (
                rng.random_range(0.0..0.12),
                rng.random_range(0.0..std::f64::consts::TAU),
            )
        })
        .collect();
    (0..n)
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / n as f64;
            let wobble: f64 = harmonics
                .iter()
                .enumerate()
                .map(|(k, (a, ph))| a * ((k as f64 + 2.0) * t + ph).sin())
                .sum();
            let rr = r * (1.0 + wobble) + rng.random_range(-jitter..jitter);
            let p = frame.lift([centre[0] + rr * t.cos(), centre[1] + rr * t.sin()]);
            let e = rng.random_range(-noise..noise);
            [
                p[0] + e * plane.normal[0],
                p[1] + e * plane.normal[1],
                p[2] + e * plane.normal[2],
            ]
        })
        .collect()
}

/// `count` polygons with shell radius in `radius`, `holes` small holes each.
fn scene(seed: u64, count: usize, radius: (f64, f64), holes: usize) -> (Vec<Polygon3>, Vec<Plane>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut polygons = Vec::with_capacity(count);
    let mut planes = Vec::with_capacity(count);
    for _ in 0..count {
        let normal = [
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(0.2..1.0),
        ];
        let origin = [
            rng.random_range(-2.0..2.0),
            rng.random_range(-2.0..2.0),
            rng.random_range(1.0..4.0),
        ];
        let Ok(plane) = Plane::from_normal_and_point(normal, origin) else {
            continue;
        };
        let r = rng.random_range(radius.0..radius.1);
        let shell = jagged_ring(&mut rng, &plane, [0.0, 0.0], r, 0.015, 0.006, 0.003);
        let hole_rings = (0..holes)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / holes as f64;
                let hr = rng.random_range(0.03..0.12);
                let c = [0.45 * r * t.cos(), 0.45 * r * t.sin()];
                let mut ring = jagged_ring(&mut rng, &plane, c, hr, 0.015, 0.004, 0.003);
                ring.reverse();
                ring
            })
            .collect();
        polygons.push(Polygon3::new(shell, hole_rings));
        planes.push(plane);
    }
    (polygons, planes)
}

fn bench_postprocess(c: &mut Criterion) {
    let Ok(processor) = PostProcessor::new(PostprocessConfig::rgbd()) else {
        return;
    };
    // RealSense-like frame: 5 polygons, radius 0.25–0.9 m (≈100–400 vertices), 3 holes.
    let rgbd = scene(1, 5, (0.25, 0.9), 3);
    // pc_01-like scene: 30 polygons, radius 0.5–2.5 m (≈200–1000 vertices), 4 holes.
    let pc01 = scene(2, 30, (0.5, 2.5), 4);
    for (name, (polys, planes)) in [("rgbd_like_5", &rgbd), ("pc01_like_30", &pc01)] {
        let verts: usize = polys.iter().map(|p| p.metrics().vertex_count).sum();
        let out = processor.process_many_3d(polys, planes);
        if let Ok(out) = &out {
            eprintln!(
                "{name}: {} polygons, {verts} vertices in; {} polygons, {} vertices out; {:?}",
                polys.len(),
                out.polygons.len(),
                out.polygons
                    .iter()
                    .map(|p| p.polygon.metrics().vertex_count)
                    .sum::<usize>(),
                out.diagnostics
            );
        }
        let mut group = c.benchmark_group(format!("postprocess/{name}"));
        group.bench_function("sequential", |b| {
            b.iter(|| {
                for (p, plane) in polys.iter().zip(planes) {
                    black_box(processor.process_3d(black_box(p), plane));
                }
            })
        });
        group.bench_function("many_all_threads", |b| {
            b.iter(|| black_box(processor.process_many_3d(polys, planes)))
        });
        group.finish();
    }
}

criterion_group!(benches, bench_postprocess);
criterion_main!(benches);
