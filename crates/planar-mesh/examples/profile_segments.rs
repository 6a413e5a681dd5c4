//! Simplifies segments dumped by `polylidar-benches`' `planar_mesh_frame` example
//! (`PLANAR_MESH_DUMP=FILE`), for profiling this crate alone: `RUNS` runs of
//! [`simplify_all`] on a pool of `THREADS` threads, the median wall time, and a summary
//! of the output (vertices, triangles, area, texels, a checksum of the textures).
//!
//! ```text
//! cargo run --release -p planar-mesh --example profile_segments -- FILE [THREADS] [RUNS] [polygon|point] [texture|plain]
//! ```

#![allow(clippy::expect_used, clippy::print_stdout, clippy::unwrap_used)]

use std::time::Instant;

use planar_mesh::{Method, Segment, SimplifyOptions, TextureOptions, simplify_all};

/// One dumped segment.
struct Dumped {
    points: Vec<[f64; 3]>,
    colors: Vec<[u8; 3]>,
    shell: Vec<[f64; 3]>,
    holes: Vec<Vec<[f64; 3]>>,
}

struct Reader<'a>(&'a [u8]);

impl Reader<'_> {
    fn take(&mut self, n: usize) -> &[u8] {
        let (head, tail) = self.0.split_at(n);
        self.0 = tail;
        head
    }
    fn u32(&mut self) -> usize {
        u32::from_le_bytes(self.take(4).try_into().unwrap()) as usize
    }
    fn ring(&mut self) -> Vec<[f64; 3]> {
        let n = self.u32();
        (0..n)
            .map(|_| std::array::from_fn(|_| f64::from_le_bytes(self.take(8).try_into().unwrap())))
            .collect()
    }
}

fn read(path: &str) -> Vec<Dumped> {
    let bytes = std::fs::read(path).expect("a readable dump");
    let mut r = Reader(&bytes);
    let n = r.u32();
    (0..n)
        .map(|_| {
            let points = r.ring();
            let colors = (0..points.len())
                .map(|_| r.take(3).try_into().unwrap())
                .collect();
            let shell = r.ring();
            let holes = (0..r.u32()).map(|_| r.ring()).collect();
            Dumped {
                points,
                colors,
                shell,
                holes,
            }
        })
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |k: usize, default: &str| args.get(k).cloned().unwrap_or_else(|| default.into());
    let dumped = read(&arg(0, "/tmp/segments.bin"));
    let threads: usize = arg(1, "1").parse().expect("a thread count");
    let runs: usize = arg(2, "15").parse().expect("a run count");
    let method = match arg(3, "polygon").as_str() {
        "point" => Method::Point,
        _ => Method::Polygon,
    };
    let textured = arg(4, "texture") == "texture";
    let segments: Vec<Segment<'_>> = dumped
        .iter()
        .map(|d| Segment::new(&d.points, &d.shell, &d.holes).with_colors(&d.colors))
        .collect();
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
    let mut last = Vec::new();
    for _ in 0..runs {
        let start = Instant::now();
        last = pool.install(|| simplify_all(&segments, &options));
        times.push(start.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    let (mut vertices, mut boundary, mut triangles, mut area, mut texels, mut sum) =
        (0, 0, 0, 0.0, 0u64, 0u64);
    // A checksum of the triangles (their vertex indices, in order) and of the vertices.
    let mut mesh_sum = 0u64;
    let mut failed = 0;
    let (mut largest, mut total) = (0.0f64, 0.0);
    for p in &last {
        let Ok(p) = p else {
            failed += 1;
            continue;
        };
        let seconds = p.stats.decimate_s + p.stats.triangulate_s + p.stats.texture_s;
        largest = largest.max(seconds);
        total += seconds;
        vertices += p.vertices.len();
        boundary += p.stats.boundary_vertices;
        triangles += p.triangles.len();
        area += p.area();
        mesh_sum = p
            .triangles
            .iter()
            .flatten()
            .map(|&v| u64::from(v))
            .chain(p.vertices_2d.iter().flatten().map(|x| x.to_bits()))
            .fold(mesh_sum, |s, v| s.wrapping_mul(31).wrapping_add(v));
        if let Some(t) = &p.texture {
            texels += u64::from(t.width) * u64::from(t.height);
            sum = t
                .rgb
                .iter()
                .fold(sum, |s, &b| s.wrapping_mul(31).wrapping_add(u64::from(b)));
        }
    }
    println!(
        "planes {} failed {failed} vertices {vertices} boundary {boundary} triangles {triangles} area {area:.9} mesh checksum {mesh_sum:x} texels {texels} checksum {sum:x}",
        last.len()
    );
    println!(
        "largest plane {:.0} % of the planes' time (last run)",
        100.0 * largest / total.max(f64::MIN_POSITIVE)
    );
    println!(
        "median {:.2} ms (min {:.2}, max {:.2}) over {runs} runs on {threads} threads",
        times[runs / 2],
        times[0],
        times[runs - 1]
    );
}
