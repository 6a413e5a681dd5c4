//! Planar meshes of one RGB-D frame, for profiling and before/after comparisons:
//! extracts the planes once (`synpeb-auto`), then runs `Extraction::planar_meshes` `RUNS`
//! times on a pool of `THREADS` threads and prints the median wall time and a summary of
//! the output (planes, vertices, triangles, area, texels, a checksum of the textures).
//!
//! ```text
//! cargo run --release -p polylidar-benches --example planar_mesh_frame -- \
//!     ../shared/fixtures/rgbd/icl_living_depth_00000.png [SCALE] [THREADS] [RUNS] [polygon|point] [texture|plain]
//! ```
//!
//! `SCALE` is metres per depth unit (0.001 for ICL, 0.0002 for TUM).

#![allow(clippy::expect_used, clippy::print_stdout)]

use std::time::Instant;

use polylidar::planar_mesh::{Method, SimplifyOptions, TextureOptions};
use polylidar::{Config, DepthOptions, Intrinsics, OrganizedPointCloud, Polylidar};

/// The allocator of the `polylidar` command line.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |k: usize, default: &str| args.get(k).cloned().unwrap_or_else(|| default.into());
    let path =
        std::path::PathBuf::from(arg(0, "../shared/fixtures/rgbd/icl_living_depth_00000.png"));
    let scale: f64 = arg(1, "0.001").parse().expect("a depth scale");
    let threads: usize = arg(2, "1").parse().expect("a thread count");
    let runs: usize = arg(3, "15").parse().expect("a run count");
    let method = match arg(4, "polygon").as_str() {
        "point" => Method::Point,
        _ => Method::Polygon,
    };
    let textured = arg(5, "texture") == "texture";

    let depth = polylidar_io::read_depth_png(&path).expect("a 16-bit depth PNG");
    let color = polylidar_io::color_path_for(&path).expect("the frame's colour picture");
    let color = polylidar_io::read_color_image(color).expect("a readable colour picture");
    let options =
        DepthOptions::new(Intrinsics::new(525.0, 525.0, 319.5, 239.5)).with_depth_scale(scale);
    let cloud =
        OrganizedPointCloud::from_depth_image(&depth.data, depth.height, depth.width, &options)
            .expect("a valid frame");
    let polylidar =
        Polylidar::new(Config::preset("synpeb-auto").expect("a preset")).expect("valid");
    let extraction = polylidar.extract_organized(&cloud).expect("planes");
    if let Ok(dump) = std::env::var("PLANAR_MESH_DUMP") {
        dump_segments(&extraction, &color.rgb, &dump);
    }

    let mut options = SimplifyOptions::new()
        .with_method(method)
        .with_parallel(threads > 1);
    if textured {
        options = options.with_texture(TextureOptions::new());
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool");
    let mut times = Vec::with_capacity(runs);
    let mut last = None;
    for _ in 0..runs {
        let start = Instant::now();
        let m = pool.install(|| {
            extraction
                .planar_meshes(Some(&color.rgb), &options)
                .expect("meshes")
        });
        times.push(start.elapsed().as_secs_f64() * 1e3);
        last = Some(m);
    }
    times.sort_by(f64::total_cmp);
    let m = last.expect("at least one run");
    let (mut vertices, mut triangles, mut area, mut texels, mut sum) = (0, 0, 0.0, 0u64, 0u64);
    for (_, p) in &m.planes {
        vertices += p.vertices.len();
        triangles += p.triangles.len();
        area += p.area();
        if let Some(t) = &p.texture {
            texels += u64::from(t.width) * u64::from(t.height);
            sum = t
                .rgb
                .iter()
                .fold(sum, |s, &b| s.wrapping_mul(31).wrapping_add(u64::from(b)));
        }
    }
    println!(
        "planes {} skipped {} vertices {vertices} triangles {triangles} area {area:.9} texels {texels} checksum {sum:x}",
        m.planes.len(),
        m.skipped.len()
    );
    println!(
        "median {:.2} ms (min {:.2}, max {:.2}) over {runs} runs on {threads} threads",
        times[runs / 2],
        times[0],
        times[runs - 1]
    );
}

/// Writes every polygon's points, colours, shell and holes (little-endian: counts as u32,
/// coordinates as f64, colours as 3 bytes) for `planar-mesh`'s `profile_segments` example.
fn dump_segments(extraction: &polylidar::Extraction, colors: &[[u8; 3]], path: &str) {
    let vertices = extraction.mesh.vertices();
    let mut out = Vec::new();
    let put_u32 = |out: &mut Vec<u8>, v: usize| out.extend((v as u32).to_le_bytes());
    let put_ring = |out: &mut Vec<u8>, ring: &[[f64; 3]]| {
        put_u32(out, ring.len());
        for p in ring {
            for v in p {
                out.extend(v.to_le_bytes());
            }
        }
    };
    let ids = extraction.polygon_vertices();
    put_u32(&mut out, ids.len());
    for (ids, polygon) in ids.iter().zip(&extraction.polygons) {
        let points: Vec<[f64; 3]> = ids.iter().map(|&v| vertices[v as usize]).collect();
        put_ring(&mut out, &points);
        for &v in ids {
            out.extend(colors[v as usize]);
        }
        put_ring(&mut out, &polygon.shell_points);
        put_u32(&mut out, polygon.hole_points.len());
        for hole in &polygon.hole_points {
            put_ring(&mut out, hole);
        }
    }
    std::fs::write(path, out).expect("a writable dump file");
}
