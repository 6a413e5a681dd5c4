//! Planar segmentation with overlapped polygon extraction (`planeseg::segment`, the stage
//! the CLI reports as `planes_polygons`) on `synpeb/pc_01.pcd` after the `synpeb` preset's
//! meshing, smoothing and FastGA, at 1 and 2 threads: `segment` (working memory
//! allocated per call) and a `Segmenter` reused across calls, as the pipeline runs it
//! frame after frame. The C++ original takes 26.3 ms for this stage on the same frame
//! and parameters (issue 5).
//!
//! `planeseg_refined`: the same stage with refinement (absorption, free planes,
//! merging), as `rgbd-auto` runs it on the 848 × 480 RealSense frame
//! (`realsense/001_big_depth.png`, its colorized depth mapped to 300–3000 mm as in
//! Table 8), where growing free planes is most of the stage.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use fastga::FastGa;
use halfedge_mesh::HalfEdgeMesh;
use planeseg::{Segmenter, segment};
use polylidar::{Config, DepthOptions, Intrinsics, OrganizedPointCloud, Polylidar};
use polylidar_io::{InputKind, read_input};

fn bench(c: &mut Criterion) {
    let Some(path) = test_fixtures::fixture("synpeb/pc_01.pcd") else {
        return;
    };
    let InputKind::Cloud(cloud) = read_input(&path).expect("readable fixture") else {
        panic!("pc_01.pcd is an organized cloud");
    };
    let cloud = OrganizedPointCloud::new(cloud.rows, cloud.cols, cloud.points).expect("organized");
    let config = Config::preset("synpeb").expect("preset");
    let (mesh, dominant) = mesh_and_dominant(&config, &cloud);
    let segmentation = config.segmentation();
    let found = segment(&mesh, &dominant, &segmentation).expect("segmentation");
    eprintln!(
        "pc_01: {} triangles, {} dominant normals, {} segments",
        mesh.num_triangles(),
        dominant.len(),
        found.segments.len()
    );

    let mut group = c.benchmark_group("planeseg");
    group
        .sample_size(50)
        .measurement_time(Duration::from_secs(8));
    for threads in [1, 2] {
        let pool = pool(threads);
        group.bench_function(format!("segment_pc_01_{threads}_threads"), |b| {
            b.iter(|| {
                pool.install(|| segment(black_box(&mesh), &dominant, &segmentation))
                    .expect("segmentation")
            })
        });
        let mut segmenter = Segmenter::new();
        group.bench_function(format!("segmenter_pc_01_{threads}_threads"), |b| {
            b.iter(|| {
                pool.install(|| segmenter.segment(black_box(&mesh), &dominant, &segmentation))
                    .expect("segmentation")
            })
        });
    }
    group.finish();
}

/// A pool of `threads` threads to run a bench's iterations in.
fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
}

/// The preset's smoothed mesh of `cloud` and FastGA's dominant normals of it, as the
/// pipeline hands them to segmentation.
fn mesh_and_dominant(
    config: &Config,
    cloud: &OrganizedPointCloud,
) -> (HalfEdgeMesh, Vec<[f64; 3]>) {
    let mesh = Polylidar::new(config.clone())
        .expect("valid preset")
        .extract_organized(cloud)
        .expect("extraction")
        .mesh;
    let normals = mesh.triangle_normals().expect("triangle normals");
    let dominant = FastGa::new(config.fastga.config_for(normals.len()))
        .expect("valid FastGA config")
        .detect(normals)
        .expect("detection")
        .normals
        .iter()
        .map(|d| d.normal)
        .collect();
    (mesh, dominant)
}

fn refined(c: &mut Criterion) {
    let (Some(png), Some(csv)) = (
        test_fixtures::fixture("realsense/001_big_depth.png"),
        test_fixtures::fixture("realsense/001_big_depth_metadata.csv"),
    ) else {
        return;
    };
    let picture = polylidar_io::read_colorized_depth_png(&png).expect("readable picture");
    let k = polylidar_io::read_realsense_intrinsics(&csv).expect("readable intrinsics");
    let depth = picture.to_depth_image(300, 3000);
    let options = DepthOptions::new(Intrinsics::new(k.fx, k.fy, k.ppx, k.ppy));
    let cloud =
        OrganizedPointCloud::from_depth_image(&depth.data, depth.height, depth.width, &options)
            .expect("depth frame");
    let config = Config::preset("rgbd-auto").expect("preset");
    let (mesh, dominant) = mesh_and_dominant(&config, &cloud);
    let segmentation = config.segmentation();
    let found = Segmenter::new()
        .segment(&mesh, &dominant, &segmentation)
        .expect("segmentation");
    eprintln!(
        "001_big_depth: {} triangles, {} dominant normals, {} segments, {} free planes",
        mesh.num_triangles(),
        dominant.len(),
        found.segments.len(),
        found.counts.free_planes
    );

    let mut group = c.benchmark_group("planeseg_refined");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(10));
    for threads in [1, 2] {
        let pool = pool(threads);
        let mut segmenter = Segmenter::new();
        group.bench_function(
            format!("segmenter_rgbd_auto_848x480_{threads}_threads"),
            |b| {
                b.iter(|| {
                    pool.install(|| segmenter.segment(black_box(&mesh), &dominant, &segmentation))
                        .expect("segmentation")
                })
            },
        );
    }
    group.finish();
}

criterion_group!(benches, bench, refined);
criterion_main!(benches);
