//! Scans SynPEB-like frames at the four SynPEB tangential noise levels and prints timings
//! and plane counts.
//!
//! `cargo run --release -p synthscan --example synpeb_scan -- [seed] [repeats]`

use std::time::Instant;

use synthscan::{Noise, SceneError, synpeb_like};

fn main() -> Result<(), SceneError> {
    let mut args = std::env::args().skip(1);
    let seed = args.next().and_then(|s| s.parse().ok()).unwrap_or(1u64);
    let repeats = args.next().and_then(|s| s.parse().ok()).unwrap_or(5usize);
    let t = Instant::now();
    let (scene, sensor) = synpeb_like(seed)?;
    println!(
        "scene (seed {seed}): {} faces, {} planes, built in {:.2} ms",
        scene.faces().len(),
        scene.ground_truth().len(),
        t.elapsed().as_secs_f64() * 1e3
    );
    for mdeg in [0.0, 0.5, 1.0, 2.0, 4.0] {
        let noise = Noise::new(0.002, mdeg, seed);
        let mut times = Vec::with_capacity(repeats);
        let mut scan = None;
        for _ in 0..repeats.max(1) {
            let t = Instant::now();
            scan = Some(scene.scan(&sensor, &noise)?);
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
        times.sort_by(f64::total_cmp);
        if let Some(scan) = scan {
            let seen = scan.label_counts().iter().filter(|&&c| c > 0).count();
            println!(
                "500x500 scan, tangential {mdeg} mdeg, radial 2 mm: median {:.1} ms over {} runs ({} threads), {} valid points, {seen} planes seen",
                times[times.len() / 2],
                times.len(),
                rayon::current_num_threads(),
                scan.num_valid()
            );
        }
    }
    for max_edge in [f64::INFINITY, 0.1, 0.05] {
        let t = Instant::now();
        let (v, tris, _) = scene.to_mesh(max_edge)?;
        println!(
            "mesh, max_edge {max_edge} m: {} vertices, {} triangles in {:.1} ms",
            v.len(),
            tris.len(),
            t.elapsed().as_secs_f64() * 1e3
        );
    }
    Ok(())
}
