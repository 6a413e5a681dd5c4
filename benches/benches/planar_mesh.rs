//! Planar simplification and texturing (Ma et al. 2013) of every plane of a 640 × 480
//! RGB-D frame, after plane extraction: `Extraction::planar_meshes` for the point- and
//! polygon-based triangulations, with and without texture, at 1 and 2 threads. The issue's
//! target: all planes simplified and textured in at most 15 ms on 2 threads.
//!
//! Input: `rgbd/icl_living_depth_00000.png` with its colour JPEG from
//! `../shared/fixtures` (PrimeSense intrinsics, depth in mm), planes by the `synpeb-auto`
//! preset. Missing fixtures skip the bench with a note (fail under CI).

#![allow(clippy::expect_used)]

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use polylidar::planar_mesh::{Method, SimplifyOptions, TextureOptions};
use polylidar::{Config, DepthOptions, Extraction, Intrinsics, OrganizedPointCloud, Polylidar};

/// The allocator of the `polylidar` command line (see its `main.rs`), so that the bench
/// times what the command runs.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn frame() -> Option<(Extraction, Vec<[u8; 3]>)> {
    let depth = test_fixtures::fixture("rgbd/icl_living_depth_00000.png")?;
    let color = polylidar_io::color_path_for(&depth).expect("the frame's colour JPEG");
    let color = polylidar_io::read_color_image(color).expect("a readable JPEG");
    let image = polylidar_io::read_depth_png(&depth).expect("a 16-bit depth PNG");
    let options = DepthOptions::new(Intrinsics::new(525.0, 525.0, 319.5, 239.5));
    let cloud =
        OrganizedPointCloud::from_depth_image(&image.data, image.height, image.width, &options)
            .expect("a valid frame");
    let polylidar =
        Polylidar::new(Config::preset("synpeb-auto").expect("a preset")).expect("valid");
    let extraction = polylidar.extract_organized(&cloud).expect("planes");
    Some((extraction, color.rgb))
}

fn bench(c: &mut Criterion) {
    let Some((extraction, colors)) = frame() else {
        test_fixtures::record_skip("planar_mesh bench: rgbd/icl_living_depth_00000.png missing");
        return;
    };
    let mut group = c.benchmark_group("planar_mesh_icl_640x480");
    group.sample_size(20);
    for threads in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool");
        for (name, method) in [("point", Method::Point), ("polygon", Method::Polygon)] {
            for textured in [false, true] {
                let mut options = SimplifyOptions::new()
                    .with_method(method)
                    .with_parallel(threads > 1);
                if textured {
                    options = options.with_texture(TextureOptions::new());
                }
                let id = format!(
                    "{name}{}_{threads}t",
                    if textured { "_texture" } else { "" }
                );
                group.bench_function(id, |b| {
                    b.iter(|| {
                        pool.install(|| {
                            black_box(
                                extraction
                                    .planar_meshes(Some(&colors), &options)
                                    .expect("meshes"),
                            )
                        })
                    });
                });
            }
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
