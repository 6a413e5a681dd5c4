//! k nearest neighbours of every point (`cloud_normals::Neighbours`), the largest cost of
//! the unorganized 3D path, and PCA normals from them.
//!
//! Inputs: the Autzen airborne sample (`lidar/autzen_trim.laz`, 110,000 returns, when the
//! fixtures are there) and 250,000 points of a noisy box room (six walls, 2 mm noise), at
//! k = 12 (the `room` preset) and k = 16 (`aerial`), on 1 and 2 threads.

#![allow(clippy::expect_used)]

use std::hint::black_box;

use cloud_normals::{Neighbours, estimate_normals};
use criterion::{Criterion, criterion_group, criterion_main};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// 250,000 points on the six faces of a 4 × 3 × 2.5 m room, shuffled, with 2 mm noise.
fn room() -> Vec<[f64; 3]> {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let size = [4.0, 3.0, 2.5];
    (0..250_000)
        .map(|_| {
            let face = rng.random_range(0..6usize);
            let axis = face % 3;
            let mut p: [f64; 3] = std::array::from_fn(|a| rng.random::<f64>() * size[a]);
            p[axis] = if face < 3 { 0.0 } else { size[axis] };
            p.map(|v| v + 0.002 * (rng.random::<f64>() - 0.5))
        })
        .collect()
}

fn inputs() -> Vec<(&'static str, Vec<[f64; 3]>)> {
    let mut inputs = vec![("room", room())];
    match test_fixtures::fixture("lidar/autzen_trim.laz") {
        Some(path) => {
            let cloud = polylidar_io::read_las(&path).expect("readable fixture");
            inputs.insert(0, ("autzen", cloud.points));
        }
        None => eprintln!("autzen_trim.laz missing: benchmarking the room only"),
    }
    inputs
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("neighbours");
    group.sample_size(10);
    for (name, points) in inputs() {
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("thread pool");
            for k in [12, 16] {
                group.bench_function(format!("{name}/knn_k{k}_t{threads}"), |b| {
                    b.iter(|| pool.install(|| Neighbours::new(black_box(&points), k)))
                });
            }
            let knn = Neighbours::new(&points, 16).expect("finite points");
            group.bench_function(format!("{name}/pca_k16_t{threads}"), |b| {
                b.iter(|| pool.install(|| estimate_normals(black_box(&points), &knn)))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
