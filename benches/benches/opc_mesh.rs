//! Right-cut meshing of organized point clouds with triangle normals (Polylidar3D §4.2).
//!
//! Clouds: SynPEB `pc_01` (500 × 500) and RealSense `rgbd_opc` (120 × 212) from
//! `../shared/fixtures` when present, and a synthetic 500 × 500 range image with NaN holes.
//! Cases: `serial` (`OpcMeshOptions::parallel = false`), `threads_1` and `threads_2` (a
//! rayon pool of that size per case), all from a borrowed cloud whose points are copied
//! into the mesh; at 2 threads also `reusing` (writing over the previous iteration's mesh
//! with `mesh_reusing`, as for a stream of frames), `moved` (`into_mesh`, no copy of the
//! points) and `no_normals`. Group `decimate`: `OrganizedPointCloud::decimate` by 2 (the
//! `rgbd` preset's first stage at 640 × 480) on 1 and 2 threads, by 3 and 4 (to the
//! paper's 212 columns from 640 and 848) on 2.
//!
//! `cargo bench -p polylidar-benches --bench opc_mesh`

use std::hint::black_box;

use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use opc_mesh::{OpcMeshOptions, OrganizedPointCloud};

/// A 500 × 500 range image of a room-like scene seen from the centre: a spherical grid of
/// rays hitting planes, with 1 cm of noise, 8 % random dropouts and a few missing blobs.
fn synthetic(rows: usize, cols: usize) -> OrganizedPointCloud {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let points = (0..rows * cols)
        .map(|i| {
            let (r, c) = (i / cols, i % cols);
            let blob = ((r / 40) * 7 + (c / 40) * 3) % 13 == 0;
            if blob || uniform() < 0.08 {
                return [f64::NAN; 3];
            }
            let azimuth = (c as f64 / cols as f64 - 0.5) * 1.6;
            let elevation = (r as f64 / rows as f64 - 0.5) * 1.2;
            let ray = [
                azimuth.sin(),
                elevation.sin(),
                azimuth.cos() * elevation.cos(),
            ];
            // The nearest of a back wall (z = 4), a floor (y = 1.2) and a side wall (x = 2.5).
            let hits = [4.0 / ray[2], 1.2 / ray[1], 2.5 / ray[0]];
            let t = hits
                .into_iter()
                .filter(|t| *t > 0.0)
                .fold(f64::INFINITY, f64::min)
                + 0.01 * (uniform() - 0.5);
            ray.map(|x| x * t)
        })
        .collect();
    OrganizedPointCloud::new(rows, cols, points).unwrap_or_else(|e| unreachable!("{e}"))
}

/// SynPEB `pc_01`, if present.
fn pc_01() -> Option<OrganizedPointCloud> {
    let path = test_fixtures::fixture("synpeb/pc_01.pcd")?;
    let pcd = polylidar_io::read_pcd(path).unwrap_or_else(|e| unreachable!("pc_01: {e}"));
    Some(
        OrganizedPointCloud::new(pcd.rows, pcd.cols, pcd.points)
            .unwrap_or_else(|e| unreachable!("pc_01: {e}")),
    )
}

/// RealSense `rgbd_opc`, if present.
fn rgbd_opc() -> Option<OrganizedPointCloud> {
    let path = test_fixtures::fixture("realsense/rgbd_opc.npy")?;
    let npy = polylidar_io::read_npy(path).unwrap_or_else(|e| unreachable!("rgbd_opc: {e}"));
    let (rows, cols) = (npy.shape[0], npy.shape[1]);
    Some(
        OrganizedPointCloud::from_flat_vec(rows, cols, npy.data)
            .unwrap_or_else(|e| unreachable!("rgbd_opc: {e}")),
    )
}

fn clouds() -> Vec<(&'static str, OrganizedPointCloud)> {
    let mut clouds = Vec::new();
    clouds.extend(pc_01().map(|c| ("pc_01", c)));
    clouds.extend(rgbd_opc().map(|c| ("rgbd_opc", c)));
    clouds.push(("synthetic_500x500", synthetic(500, 500)));
    clouds
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap_or_else(|e| unreachable!("cannot start {threads} threads: {e}"))
}

fn bench_mesh(c: &mut Criterion) {
    let parallel = OpcMeshOptions::default();
    let serial = parallel.with_parallel(false);
    let bare = parallel.with_compute_normals(false);
    let (one, two) = (pool(1), pool(2));
    let mut group = c.benchmark_group("opc_mesh");
    for (name, cloud) in clouds() {
        group.bench_with_input(BenchmarkId::new(name, "serial"), &cloud, |b, cloud| {
            b.iter(|| cloud.mesh(black_box(&serial)))
        });
        for (threads, pool) in [(1, &one), (2, &two)] {
            let case = format!("threads_{threads}");
            group.bench_with_input(BenchmarkId::new(name, case), &cloud, |b, cloud| {
                b.iter(|| pool.install(|| cloud.mesh(black_box(&parallel))))
            });
        }
        group.bench_with_input(
            BenchmarkId::new(name, "threads_2_reusing"),
            &cloud,
            |b, cloud| {
                let mut slot = cloud.mesh(&parallel).ok();
                b.iter(|| {
                    if let Some(previous) = slot.take() {
                        slot =
                            two.install(|| cloud.mesh_reusing(black_box(&parallel), previous).ok());
                    }
                })
            },
        );
        group.bench_with_input(
            BenchmarkId::new(name, "threads_2_moved"),
            &cloud,
            |b, cloud| {
                b.iter_batched(
                    || cloud.clone(),
                    |cloud| two.install(|| cloud.into_mesh(black_box(&parallel))),
                    BatchSize::LargeInput,
                )
            },
        );
        group.bench_with_input(
            BenchmarkId::new(name, "threads_2_no_normals"),
            &cloud,
            |b, cloud| b.iter(|| two.install(|| cloud.mesh(black_box(&bare)))),
        );
    }
    group.finish();
}

fn bench_decimate(c: &mut Criterion) {
    let (one, two) = (pool(1), pool(2));
    let mut group = c.benchmark_group("decimate");
    for (name, cloud) in clouds() {
        for (factor, threads, pool) in [(2, 1, &one), (2, 2, &two), (3, 2, &two), (4, 2, &two)] {
            let case = format!("by_{factor}_threads_{threads}");
            group.bench_with_input(BenchmarkId::new(name, case), &cloud, |b, cloud| {
                b.iter(|| pool.install(|| cloud.decimate(black_box(factor), 0.02)))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench_mesh, bench_decimate);
criterion_main!(benches);
