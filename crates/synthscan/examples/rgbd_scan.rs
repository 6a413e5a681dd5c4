//! Scans `rgbd_like` frames with the four RGB-D cameras and prints, per camera, the valid
//! fraction, the planes seen and how their pixel counts spread, and the scan time.
//!
//! `cargo run --release -p synthscan --example rgbd_scan -- [first seed] [frames]`

use std::time::Instant;

use synthscan::{DepthCameraKind, SceneError, rgbd_like};

fn main() -> Result<(), SceneError> {
    let mut args = std::env::args().skip(1);
    let first = args.next().and_then(|s| s.parse().ok()).unwrap_or(1u64);
    let frames = args.next().and_then(|s| s.parse().ok()).unwrap_or(10u64);
    for kind in DepthCameraKind::ALL {
        let (mut valid, mut seen, mut small, mut large, mut ms) =
            (0.0, 0usize, 0usize, 0usize, 0.0);
        let mut per_frame = Vec::new();
        for seed in first..first + frames {
            let (scene, camera) = rgbd_like(seed, kind)?;
            let t = Instant::now();
            let scan = scene.scan_depth(&camera, seed)?;
            ms += t.elapsed().as_secs_f64() * 1e3;
            let n = (scan.rows * scan.cols) as f64;
            valid += scan.num_valid() as f64 / n;
            // Planes seen, and how many of them cover < 0.1 % or > 1 % of the image.
            let counts = scan.label_counts();
            let planes = counts.iter().filter(|&&c| c > 0).count();
            per_frame.push(planes);
            seen += planes;
            small += counts
                .iter()
                .filter(|&&c| c > 0 && (c as f64) < 1e-3 * n)
                .count();
            large += counts.iter().filter(|&&c| c as f64 > 1e-2 * n).count();
        }
        let f = frames as f64;
        println!(
            "{:15} valid {:.1} %, planes seen {:.1} per frame (min {}, max {}), < 0.1 % of the image: {:.1}, > 1 %: {:.1}; scan {:.1} ms",
            kind.name(),
            100.0 * valid / f,
            seen as f64 / f,
            per_frame.iter().min().unwrap_or(&0),
            per_frame.iter().max().unwrap_or(&0),
            small as f64 / f,
            large as f64 / f,
            ms / f
        );
    }
    Ok(())
}
