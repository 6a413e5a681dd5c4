//! The Rust side of `benches/python_bench.py`: the same calls the Python benchmark makes,
//! timed in Rust on the same data, printed as one JSON object of median milliseconds.
//!
//! ```text
//! cargo run --release -p polylidar-benches --example python_reference -- [REPEATS] [NORMALS.npy]
//! ```
//!
//! * `pc_01_synpeb`: `Polylidar::extract_organized` on `../shared/fixtures/synpeb/pc_01.pcd`
//!   with the `synpeb` preset, wall-clock per call (the pipeline object built once);
//! * `fastga_100k`: `FastGa::detect` (clear, integrate, peaks, clustering; level 4,
//!   accumulator built once) on the `(N, 3)` normals of `NORMALS.npy` (the Python side
//!   passes the very array it timed), or else on 100,000 random unit normals
//!   (`random_unit_normals(100_000, 42)`, the criterion bench's input).

use std::time::Instant;

use fastga::{FastGa, FastGaConfig};
use polylidar::{Config, OrganizedPointCloud, Polylidar};
use test_fixtures::random_unit_normals;

/// The allocator of the `polylidar` command and of the Python package, so that both sides
/// allocate alike.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn median_ms(repeats: usize, mut f: impl FnMut()) -> f64 {
    f();
    let mut times: Vec<f64> = (0..repeats)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let repeats: usize = std::env::args().nth(1).map_or(Ok(20), |a| a.parse())?;
    let mut out = Vec::new();
    if let Some(path) = test_fixtures::fixture("synpeb/pc_01.pcd") {
        let cloud = polylidar_io::read_pcd(&path)?;
        let cloud = OrganizedPointCloud::new(cloud.rows, cloud.cols, cloud.points)?;
        let config = Config::preset("synpeb").ok_or("no synpeb preset")?;
        let polylidar = Polylidar::new(config)?;
        let mut failed = None;
        let ms = median_ms(repeats, || {
            if let Err(e) = polylidar.extract_organized(&cloud) {
                failed = Some(e);
            }
        });
        if let Some(e) = failed {
            return Err(e.into());
        }
        out.push(format!("\"pc_01_synpeb\": {ms:.4}"));
    }
    let normals = match std::env::args().nth(2) {
        Some(path) => {
            let array = polylidar_io::read_npy(&path)?;
            if array.shape.len() != 2 || array.shape[1] != 3 {
                return Err(
                    format!("{path}: expected (N, 3) normals, got {:?}", array.shape).into(),
                );
            }
            array.data.as_chunks::<3>().0.to_vec()
        }
        None => random_unit_normals(100_000, 42),
    };
    let mut fastga = FastGa::new(FastGaConfig::default().with_level(4))?;
    let mut failed = None;
    let ms = median_ms(repeats * 5, || {
        if let Err(e) = fastga.detect(&normals) {
            failed = Some(e);
        }
    });
    if let Some(e) = failed {
        return Err(e.into());
    }
    out.push(format!("\"fastga_100k\": {ms:.4}"));
    println!("{{{}}}", out.join(", "));
    Ok(())
}
