//! Times `evaluate` on a SynPEB-sized scene: a 500 × 500 organized cloud (250,000 points)
//! with 48 ground-truth planes and a prediction that finds, splits, merges and misses some
//! of them, plus label noise.
//!
//! `cargo run --release -p seg-metrics --example timing [runs]`

use std::time::Instant;

use seg_metrics::{EvaluateOptions, MetricsError, evaluate};

/// A small deterministic generator (SplitMix64), so the example needs no dependencies.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn main() -> Result<(), MetricsError> {
    let runs: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(51);
    let (rows, cols) = (500usize, 500usize);
    let mut rng = SplitMix(2024);
    let mut points = Vec::with_capacity(rows * cols);
    let mut truth = Vec::with_capacity(rows * cols);
    let mut predicted = Vec::with_capacity(rows * cols);
    for r in 0..rows {
        for c in 0..cols {
            // 8 × 6 blocks of planes; a 10-pixel unlabelled border with missing returns.
            if r < 10 || c < 10 {
                points.push([f64::NAN; 3]);
                truth.push(-1);
                predicted.push(-1);
                continue;
            }
            let (br, bc) = ((r - 10) / 82, (c - 10) / 62);
            let plane = (br * 8 + bc) as i32;
            // Plane `plane`: z = a x + b y + d with a, b, d from the id, noise 5 mm.
            let (x, y) = (c as f64 * 0.01, r as f64 * 0.01);
            let (a, b) = (0.1 * (plane % 5) as f64, 0.07 * (plane % 7) as f64);
            let z = a * x + b * y + 0.2 * plane as f64 + 0.005 * (rng.unit() - 0.5);
            points.push([x, y, z]);
            truth.push(10 + 3 * plane);
            let p = match plane % 6 {
                0..=2 => 100 + plane,                                // found
                3 => 500 + 2 * plane + ((c - 10) % 62 >= 31) as i32, // split in two
                4 => 900 + plane / 12, // merged in pairs (4 with 10, 16 with 22, …)
                _ => -1,               // missed
            };
            let p = if plane % 6 == 5 && (r + c) % 97 == 0 {
                2000 + plane
            } else {
                p
            };
            predicted.push(if rng.unit() < 0.02 { -1 } else { p });
        }
    }

    let options = EvaluateOptions::default();
    let mut times = Vec::with_capacity(runs);
    let mut last = None;
    for _ in 0..runs {
        let start = Instant::now();
        let scores = evaluate(&points, &truth, &predicted, &options)?;
        times.push(start.elapsed().as_secs_f64() * 1e3);
        last = Some(scores);
    }
    times.sort_by(f64::total_cmp);
    if let Some(s) = last {
        println!(
            "{} points, {} ground-truth planes, {} predicted: correct {}, over {}, under {}, \
             missed {}, spurious {}; f = {:.1} %, k = {:.1} %, RMSE = {:.2} mm",
            points.len(),
            s.truth_planes,
            s.predicted_planes,
            s.correct,
            s.over_segmented,
            s.under_segmented,
            s.missed,
            s.spurious,
            s.f,
            s.k,
            1e3 * s.rmse.unwrap_or(f64::NAN)
        );
    }
    if !times.is_empty() {
        println!(
            "evaluate: median {:.3} ms, min {:.3} ms, max {:.3} ms over {} runs",
            times[times.len() / 2],
            times[0],
            times[times.len() - 1],
            times.len()
        );
    }
    Ok(())
}
