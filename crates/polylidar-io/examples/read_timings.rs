//! Median read times of the real fixtures (`cargo run --release -p polylidar-io --example
//! read_timings`); the file is read from disk each time (page cache warm).

use std::time::Instant;

fn median_ms(runs: usize, mut f: impl FnMut()) -> f64 {
    let mut times: Vec<f64> = (0..runs)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[runs / 2]
}

fn main() -> Result<(), polylidar_io::IoError> {
    let runs = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(21);
    // Optional second argument: only fixtures whose name contains it.
    let only = std::env::args().nth(2).unwrap_or_default();
    let fixture = |name: &str| {
        if name.contains(only.as_str()) {
            test_fixtures::fixture(name)
        } else {
            None
        }
    };
    if let Some(p) = fixture("synpeb/pc_01.pcd") {
        let ms = median_ms(runs, || assert!(polylidar_io::read_pcd(&p).is_ok()));
        println!("pc_01.pcd (500×500, binary_compressed): {ms:.2} ms");
        let cloud = polylidar_io::read_pcd(&p)?;
        let opts = polylidar_io::PcdWriteOptions::new(polylidar_io::PcdEncoding::BinaryCompressed)
            .with_scalar(polylidar_io::PcdScalar::F32);
        let ms = median_ms(runs, || {
            assert!(polylidar_io::encode_pcd(&cloud, &opts).is_ok())
        });
        println!("pc_01 encode binary_compressed f32: {ms:.2} ms");
    }
    if let Some(p) = fixture("realsense/rgbd_opc.npy") {
        let ms = median_ms(runs, || assert!(polylidar_io::read_npy(&p).is_ok()));
        println!("rgbd_opc.npy (120×212×3 <f8): {ms:.2} ms");
    }
    if let Some(p) = fixture("lidar/autzen_trim.laz") {
        let ms = median_ms(runs, || assert!(polylidar_io::read_las(&p).is_ok()));
        println!("autzen_trim.laz (110,000 points): {ms:.2} ms");
    }
    if let Some(p) = fixture("lidar/simple.las") {
        let ms = median_ms(runs, || assert!(polylidar_io::read_las(&p).is_ok()));
        println!("simple.las (1,065 points): {ms:.2} ms");
    }
    if let Some(p) = fixture("realsense/001_big_depth.png") {
        let ms = median_ms(runs, || {
            assert!(polylidar_io::read_colorized_depth_png(&p).is_ok())
        });
        println!("001_big_depth.png (848×480 colorized): {ms:.2} ms");
    }
    Ok(())
}
