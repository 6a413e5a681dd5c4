//! Planar segmentation with overlapped polygon extraction (`planeseg::segment`, the stage
//! the CLI reports as `planes_polygons`) on `synpeb/pc_01.pcd` after the `synpeb` preset's
//! meshing, smoothing and FastGA, at 1 and 2 threads: `segment` (working memory
//! allocated per call) and a `Segmenter` reused across calls, as the pipeline runs it
//! frame after frame. The C++ original takes 26.3 ms for this stage on the same frame
//! and parameters (issue 5).
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use fastga::FastGa;
use planeseg::{Segmenter, segment};
use polylidar::{Config, OrganizedPointCloud, Polylidar};
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
    let mesh = Polylidar::new(config.clone())
        .expect("valid preset")
        .extract_organized(&cloud)
        .expect("extraction")
        .mesh;
    let normals = mesh.triangle_normals().expect("triangle normals");
    let dominant: Vec<[f64; 3]> = FastGa::new(config.fastga.config_for(normals.len()))
        .expect("valid FastGA config")
        .detect(normals)
        .expect("detection")
        .normals
        .iter()
        .map(|d| d.normal)
        .collect();
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
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool");
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

criterion_group!(benches, bench);
criterion_main!(benches);
