//! The Polylidar3D pipeline end to end on real frames (issue 5's speed table and issue 6's
//! post-processing benchmark):
//!
//! * `synpeb/pc_01.pcd` with the `synpeb` preset at 1 and 2 threads: the whole pipeline
//!   from the loaded cloud, and per-stage medians (printed) — `planes_polygons` is the
//!   stage the original measures at 26.3 ms, the whole run at 264.5 ms;
//! * `realsense/rgbd_opc.npy` with the `rgbd` preset, the same;
//! * post-processing alone (the `rgbd` preset's α, β, γ, δ) of the polygons of both frames.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use polylidar::{Config, Extraction, OrganizedPointCloud, Polylidar};
use polylidar_io::{InputKind, read_input};
use polypost::{Plane, Polygon3, PostProcessor};

/// Runs for the printed stage medians.
const RUNS: usize = 21;

fn organized(rel: &str) -> Option<OrganizedPointCloud> {
    let path = test_fixtures::fixture(rel)?;
    let InputKind::Cloud(cloud) = read_input(&path).expect("readable fixture") else {
        return None;
    };
    Some(OrganizedPointCloud::new(cloud.rows, cloud.cols, cloud.points).expect("organized"))
}

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

/// Prints the median of every stage over `RUNS` runs.
fn print_stages(name: &str, polylidar: &Polylidar, cloud: &OrganizedPointCloud) {
    let runs: Vec<Extraction> = (0..RUNS)
        .map(|_| polylidar.extract_organized(cloud).expect("extraction"))
        .collect();
    let stages: Vec<String> = runs[0]
        .diagnostics
        .timings
        .stages()
        .iter()
        .map(|(stage, _)| {
            let ms = median(
                runs.iter()
                    .filter_map(|r| r.diagnostics.timings.get(stage))
                    .map(|d| d.as_secs_f64() * 1e3)
                    .collect(),
            );
            format!("{stage} {ms:.2}")
        })
        .collect();
    let total = median(
        runs.iter()
            .map(|r| r.diagnostics.timings.total().as_secs_f64() * 1e3)
            .collect(),
    );
    eprintln!(
        "{name}, {} thread(s): {} polygons; medians of {RUNS} (ms): {}, total {total:.2}",
        polylidar.config().threads,
        runs[0].polygons.len(),
        stages.join(", ")
    );
}

/// The extraction's polygons as polypost inputs with their planes.
fn post_inputs(extraction: &Extraction) -> (Vec<Polygon3>, Vec<Plane>) {
    extraction
        .polygons
        .iter()
        .map(|p| {
            (
                Polygon3::new(p.shell_points.clone(), p.hole_points.clone()),
                Plane::from_normal_and_point(p.plane.normal, p.plane.centroid)
                    .expect("unit normal"),
            )
        })
        .unzip()
}

fn bench(c: &mut Criterion) {
    let frames = [
        ("pc_01", "synpeb/pc_01.pcd", "synpeb"),
        ("rgbd_opc", "realsense/rgbd_opc.npy", "rgbd"),
    ];
    let rgbd = Config::preset("rgbd").expect("preset");
    let post = rgbd.postprocess.expect("the rgbd preset post-processes");
    let processor = PostProcessor::new(post).expect("valid post-processing");

    let mut group = c.benchmark_group("pipeline_3d");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(10));
    for (name, rel, preset) in frames {
        let Some(cloud) = organized(rel) else {
            continue;
        };
        for threads in [1, 2] {
            let config = Config::preset(preset)
                .expect("preset")
                .with_threads(threads);
            let polylidar = Polylidar::new(config).expect("valid preset");
            print_stages(name, &polylidar, &cloud);
            group.bench_function(format!("{name}_{preset}_{threads}_threads"), |b| {
                b.iter(|| {
                    polylidar
                        .extract_organized(black_box(&cloud))
                        .expect("extraction")
                })
            });
        }
        let raw = Polylidar::new(
            Config::preset(preset)
                .expect("preset")
                .with_postprocess(None),
        )
        .expect("valid preset")
        .extract_organized(&cloud)
        .expect("extraction");
        let (polygons, planes) = post_inputs(&raw);
        eprintln!("{name}: post-processing {} polygons", polygons.len());
        group.bench_function(format!("{name}_postprocess_rgbd"), |b| {
            b.iter(|| {
                processor
                    .process_many_3d(black_box(&polygons), &planes)
                    .expect("post")
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
