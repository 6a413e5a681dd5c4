//! Times one filter workload on SynPEB pc_01 (or a synthetic 500 × 500 cloud) for
//! profiling: `cargo run --release -p mesh-smooth-gpu --example time_filters -- \
//! laplacian|bilateral cpu|parallel [calls]`. Under `perf stat -e task-clock` the CPU
//! time per call is task-clock / calls, independent of other load on the machine.

use std::time::Instant;

use mesh_smooth_gpu::{BilateralOptions, CpuSmoother, LaplacianOptions};
use opc_mesh::OrganizedPointCloud;

fn cloud() -> Result<OrganizedPointCloud, opc_mesh::OpcError> {
    let from_file = test_fixtures::fixture("synpeb/pc_01.pcd")
        .and_then(|path| polylidar_io::read_pcd(path).ok())
        .and_then(|pcd| OrganizedPointCloud::new(pcd.rows, pcd.cols, pcd.points).ok());
    if let Some(cloud) = from_file {
        return Ok(cloud);
    }
    let points: Vec<[f64; 3]> = (0..500 * 500)
        .map(|i| {
            let (x, y) = ((i % 500) as f64 * 0.01, (i / 500) as f64 * 0.01);
            if i % 17 == 0 {
                [f64::NAN; 3]
            } else {
                [x, y, 3.0 + 0.2 * (5.0 * x).sin()]
            }
        })
        .collect();
    OrganizedPointCloud::new(500, 500, points)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let filter = args.get(1).map_or("laplacian", String::as_str);
    let backend = args.get(2).map_or("parallel", String::as_str);
    let calls: u32 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(20);
    let cloud = cloud()?;
    let mut smoother = match backend {
        "cpu" => CpuSmoother::serial(),
        _ => CpuSmoother::new(),
    };
    let start = Instant::now();
    for _ in 0..calls {
        if filter == "bilateral" {
            let options = BilateralOptions::new().with_kernel(3).with_iterations(2);
            std::hint::black_box(smoother.bilateral(&cloud, &options)?);
        } else {
            let options = LaplacianOptions::new()
                .with_kernel(5)
                .with_lambda(1.0)
                .with_iterations(8);
            std::hint::black_box(smoother.laplacian(&cloud, &options)?);
        }
    }
    let ms = start.elapsed().as_secs_f64() * 1e3 / f64::from(calls);
    println!("{filter} {backend}: {ms:.1} ms wall per call over {calls} calls");
    Ok(())
}
