//! The 2D paper's benchmark: 64,000 points sampled uniformly inside the California shape
//! with holes (`../shared/fixtures/shapes/caholes.geojson`), α = 2·√(area / n).
//!
//! Criterion measures the whole pipeline and the triangulation alone; the stage split
//! (triangulation / filtering + region growing / polygon extraction) is printed as medians
//! of the pipeline's own timings, with the L² error, before the criterion groups run.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use polylidar::output::to_multipolygon;
use polylidar::{Config, HalfEdgeMesh, Polylidar};
use synthscan::shapes::{l2_error, multipolygon_from_geojson, paper_alpha, sample_uniform};

const N: usize = 64_000;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn bench(c: &mut Criterion) {
    let Some(path) = test_fixtures::fixture("shapes/caholes.geojson") else {
        return;
    };
    let truth =
        multipolygon_from_geojson(&std::fs::read_to_string(path).expect("readable fixture"))
            .expect("valid shape");
    let points = sample_uniform(&truth, N, 42).expect("shape has area");
    let alpha = paper_alpha(&truth, N);

    let pipeline = |threads| {
        Polylidar::new(
            Config::new()
                .with_alpha(alpha)
                .with_min_triangles(1)
                .with_threads(threads),
        )
        .expect("valid config")
    };
    for threads in [1, 2] {
        let polylidar = pipeline(threads);
        let runs: Vec<_> = (0..31)
            .map(|_| polylidar.extract_2d(&points).expect("extraction"))
            .collect();
        let stage = |name: &str| {
            median(
                runs.iter()
                    .map(|r| {
                        r.diagnostics
                            .timings
                            .get(name)
                            .map_or(0.0, |d| d.as_secs_f64() * 1e3)
                    })
                    .collect(),
            )
        };
        let total = median(
            runs.iter()
                .map(|r| r.diagnostics.timings.total().as_secs_f64() * 1e3)
                .collect(),
        );
        let error = l2_error(&truth, &to_multipolygon(&runs[0].polygons));
        eprintln!(
            "caholes 64k, {threads} thread(s): mesh {:.2} ms, regions {:.2} ms, polygons {:.2} ms, total {total:.2} ms (medians of 31), L2 {:.2} %",
            stage("mesh"),
            stage("regions"),
            stage("polygons"),
            100.0 * error
        );
    }

    let mut group = c.benchmark_group("extract_2d_caholes_64k");
    group
        .sample_size(30)
        .measurement_time(Duration::from_secs(8));
    for threads in [1, 2] {
        let polylidar = pipeline(threads);
        group.bench_function(format!("pipeline_{threads}_threads"), |b| {
            b.iter(|| polylidar.extract_2d(&points).expect("extraction"))
        });
    }
    group.bench_function("triangulation", |b| {
        b.iter(|| HalfEdgeMesh::delaunay_2d(&points).expect("triangulation"))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
