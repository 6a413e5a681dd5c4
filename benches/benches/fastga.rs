//! FastGA benchmarks (Polylidar3D Table 2): integrating normals into a level-4 Gaussian
//! accumulator (5,120 cells) with the paper's learned-index search and with the cell table,
//! against the k-d tree baseline, on
//! one thread and on the rayon pool; peak detection and clustering at level 5; and the
//! triangle normals of the meshed SynPEB cloud pc_01 when `../shared/fixtures` is present.
//!
//! `cargo bench -p polylidar-benches --bench fastga`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use fastga::{
    AsNormal, FastGaConfig, GaussianAccumulator, KdAccumulator, Parallelism, Search, cluster_peaks,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use test_fixtures::random_unit_normals;

fn bench_integrate<N: AsNormal>(c: &mut Criterion, group: &str, normals: &[N], fraction: f64) {
    let mut group = c.benchmark_group(group);
    if normals.len() > 200_000 {
        group.sample_size(20);
    }
    let mut searches = [
        ("learned index", Search::LearnedIndex),
        ("cell table", Search::CellTable),
    ]
    .map(|(label, search)| {
        let ga = GaussianAccumulator::with_search(4, search)
            .unwrap_or_else(|e| unreachable!("level 4: {e}"));
        (label, ga)
    });
    let mut kd = KdAccumulator::new(4).unwrap_or_else(|e| unreachable!("level 4: {e}"));
    for (name, parallelism) in [
        ("1 thread", Parallelism::Sequential),
        ("rayon", Parallelism::Rayon),
    ] {
        for (label, ga) in &mut searches {
            group.bench_function(format!("fastga {label} {name}"), |b| {
                b.iter(|| {
                    ga.clear();
                    black_box(ga.integrate(black_box(normals), fraction, parallelism))
                })
            });
        }
        group.bench_function(format!("kd-tree {name}"), |b| {
            b.iter(|| {
                kd.clear();
                black_box(kd.integrate(black_box(normals), fraction, parallelism))
            })
        });
    }
    group.finish();
}

fn integrate_random(c: &mut Criterion) {
    let normals = random_unit_normals(100_000, 42);
    bench_integrate(c, "integrate 100k random normals, level 4", &normals, 1.0);
}

/// Peak detection and clustering at level 5 on an accumulator holding three noisy planes
/// and uniform clutter (their cost depends on the level, not the number of normals).
fn peaks_level_5(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut normals = random_unit_normals(20_000, 8);
    for plane in [[0.0, 0.0, 1.0], [0.8, 0.6, 0.0], [-0.6, 0.8, 0.0]] {
        for _ in 0..30_000 {
            let p: [f64; 3] =
                std::array::from_fn(|k| plane[k] + 0.03 * rng.random_range(-1.0..1.0));
            let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            normals.push(p.map(|x| x / l));
        }
    }
    let config = FastGaConfig::synpeb();
    let mut ga = GaussianAccumulator::new(5).unwrap_or_else(|e| unreachable!("level 5: {e}"));
    ga.integrate(&normals, 1.0, Parallelism::Sequential)
        .unwrap_or_else(|e| unreachable!("valid fraction: {e}"));
    c.bench_function("peaks + clustering, level 5", |b| {
        b.iter(|| {
            let peaks = ga.find_peaks(config.value_threshold);
            black_box(cluster_peaks(
                &peaks,
                config.cluster_distance,
                config.min_cluster_weight,
            ))
        })
    });
}

/// Triangle normals of SynPEB pc_01 meshed with right-cut triangles (all of them, and the
/// paper's 12 % sample).
fn integrate_pc_01(c: &mut Criterion) {
    let Some(path) = test_fixtures::fixture("synpeb/pc_01.pcd") else {
        return;
    };
    let pcd =
        polylidar_io::read_pcd(&path).unwrap_or_else(|e| unreachable!("readable pc_01.pcd: {e}"));
    let cloud = opc_mesh::OrganizedPointCloud::new(pcd.rows, pcd.cols, pcd.points)
        .unwrap_or_else(|e| unreachable!("organized: {e}"));
    let meshed = cloud
        .mesh(&opc_mesh::OpcMeshOptions::default())
        .unwrap_or_else(|e| unreachable!("meshable: {e}"));
    let normals = meshed
        .mesh
        .triangle_normals()
        .unwrap_or_else(|| unreachable!("normals are computed by default"))
        .to_vec();
    let name = format!(
        "integrate pc_01 triangle normals ({}), level 4",
        normals.len()
    );
    bench_integrate(c, &name, &normals, 1.0);
    bench_integrate(c, &format!("{name}, 12 % sample"), &normals, 0.12);
}

criterion_group!(benches, integrate_random, peaks_level_5, integrate_pc_01);
criterion_main!(benches);
