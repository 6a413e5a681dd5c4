//! 2D Delaunay triangulation of 64,000 points: the delaunator crate, spade's bulk load, our
//! exact sweep (`HalfEdgeMesh::delaunay_2d`) and our parallel α-complex
//! (`HalfEdgeMesh::alpha_complex_2d`) at 1 and 2 threads.
//!
//! Inputs: 64,000 points sampled uniformly inside `shapes/caholes.geojson` (the 2D paper's
//! benchmark, α = 2·√(area / n)) and 64,000 uniform random points in the unit square
//! (α = 2·√(1 / n)).
//!
//! For instruction counts run one case once, without criterion, under callgrind:
//! `DELAUNAY_BENCH_ONCE=<input>/<case> valgrind --tool=callgrind <bench binary>`, e.g.
//! `caholes/ours_serial`; case names are the criterion ids below.

#![allow(clippy::expect_used)]

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use halfedge_mesh::HalfEdgeMesh;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use synthscan::shapes::{multipolygon_from_geojson, paper_alpha, sample_uniform};

const N: usize = 64_000;

/// A benchmark input: points and the α of the paper's benchmark for them.
struct Input {
    name: &'static str,
    points: Vec<[f64; 2]>,
    alpha: f64,
}

fn inputs() -> Vec<Input> {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let uniform = (0..N)
        .map(|_| [rng.random::<f64>(), rng.random::<f64>()])
        .collect();
    let mut inputs = vec![Input {
        name: "uniform",
        points: uniform,
        alpha: 2.0 * (1.0 / N as f64).sqrt(),
    }];
    match test_fixtures::fixture("shapes/caholes.geojson") {
        Some(path) => {
            let text = std::fs::read_to_string(path).expect("readable fixture");
            let shape = multipolygon_from_geojson(&text).expect("valid GeoJSON");
            let points = sample_uniform(&shape, N, 1).expect("shape with area");
            inputs.insert(
                0,
                Input {
                    name: "caholes",
                    alpha: paper_alpha(&shape, N),
                    points,
                },
            );
        }
        None => eprintln!("caholes fixture missing: benchmarking uniform points only"),
    }
    inputs
}

/// Thread pools for the α-complex cases, built once.
struct Pools {
    one: rayon::ThreadPool,
    two: rayon::ThreadPool,
}

type Case = (&'static str, fn(&Input, &Pools) -> usize);

/// Each case returns a count so that its work cannot be optimized away.
const CASES: [Case; 5] = [
    ("delaunator", |input, _| {
        let points: Vec<delaunator::Point> = input
            .points
            .iter()
            .map(|p| delaunator::Point { x: p[0], y: p[1] })
            .collect();
        delaunator::triangulate(&points).triangles.len()
    }),
    ("spade_bulk_load", |input, _| {
        use spade::{DelaunayTriangulation, Point2, Triangulation};
        let points = input
            .points
            .iter()
            .map(|p| Point2::new(p[0], p[1]))
            .collect();
        DelaunayTriangulation::<Point2<f64>>::bulk_load(points)
            .expect("finite points")
            .num_inner_faces()
    }),
    ("ours_serial", |input, _| {
        HalfEdgeMesh::delaunay_2d(&input.points)
            .expect("triangulable")
            .num_triangles()
    }),
    ("ours_alpha_1_thread", |input, pools| {
        alpha_complex(input, &pools.one)
    }),
    ("ours_alpha_2_threads", |input, pools| {
        alpha_complex(input, &pools.two)
    }),
];

fn alpha_complex(input: &Input, pool: &rayon::ThreadPool) -> usize {
    pool.install(|| {
        HalfEdgeMesh::alpha_complex_2d(&input.points, input.alpha)
            .expect("triangulable")
            .0
            .num_triangles()
    })
}

fn bench(c: &mut Criterion) {
    let inputs = inputs();
    let pool = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool")
    };
    let pools = Pools {
        one: pool(1),
        two: pool(2),
    };
    if let Ok(once) = std::env::var("DELAUNAY_BENCH_ONCE") {
        for input in &inputs {
            for (name, run) in CASES {
                if once == format!("{}/{name}", input.name) {
                    println!("{once}: {}", black_box(run(input, &pools)));
                }
            }
        }
        return;
    }
    for input in &inputs {
        let mut group = c.benchmark_group(format!("delaunay_64k/{}", input.name));
        group.sample_size(30);
        for (name, run) in CASES {
            group.bench_function(name, |b| {
                b.iter(|| black_box(run(black_box(input), &pools)))
            });
        }
        group.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
