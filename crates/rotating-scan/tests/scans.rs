//! Properties against scans generated with known beams and known spurious returns, and
//! the two real HDL-64E frames of `../shared/fixtures/kitti`.

// Test helpers fail loudly by design.
#![allow(clippy::unwrap_used, clippy::panic)]

use std::collections::HashMap;

use proptest::prelude::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rotating_scan::{
    BeamOutlierConfig, ElevationBins, FieldOfView, NO_POINT, RangeImage, Rings, beam_outliers,
};

/// A generated scan: points in firing order and the beam of each.
struct Scan {
    points: Vec<[f64; 3]>,
    beam: Vec<usize>,
}

/// `beams` beams over flat ground 1.7 m below (or a cylinder wall of radius 15 m for the
/// upper beams), `per` azimuth steps from `start_deg`, each sample dropped with
/// probability `drop` and whole stretches dropped from some beams.
fn scan(seed: u64, beams: usize, per: usize, start_deg: f64, drop: f64) -> Scan {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut points = Vec::new();
    let mut beam = Vec::new();
    for b in 0..beams {
        let e = (2.0 - 24.0 * b as f64 / (beams - 1).max(1) as f64).to_radians();
        // A stretch without returns (sky, far away) on some beams.
        let gap_from = rng.random_range(0..per);
        let gap_len = if rng.random_bool(0.3) {
            rng.random_range(0..per * 3 / 4)
        } else {
            0
        };
        for k in 0..per {
            // Every beam starts at the seam (when a beam misses both its last returns and
            // the next beam's first ones, a turn cannot be told from jitter).
            let first = k == 0;
            if !first && ((k + per - gap_from) % per < gap_len || rng.random_bool(drop)) {
                continue;
            }
            let a = (start_deg + 360.0 * (k as f64 + 0.3) / per as f64).to_radians();
            let range = if e < -0.05 {
                1.7 / -e.tan() / e.cos()
            } else {
                15.0 / e.cos()
            };
            let range = range + rng.random_range(-0.01..0.01);
            points.push([
                range * e.cos() * a.cos(),
                range * e.cos() * a.sin(),
                range * e.sin(),
            ]);
            beam.push(b);
        }
    }
    Scan { points, beam }
}

fn beams_of(rings: &Rings, n: usize) -> Vec<Option<u16>> {
    rings.beam_of_points(n)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Firing order gives back the generated beams exactly, wherever the scan starts and
    /// whatever stretches are missing (every beam keeps at least one return here).
    #[test]
    fn firing_order_recovers_the_beams(seed in any::<u64>(), beams in 2usize..40, per in 90usize..600, start in -180.0f64..180.0, drop in 0.0f64..0.3) {
        let s = scan(seed, beams, per, start, drop);
        let present: Vec<usize> = { let mut b = s.beam.clone(); b.dedup(); b };
        prop_assume!(present.len() == beams);
        let rings = Rings::from_firing_order(&s.points).unwrap();
        prop_assert_eq!(rings.len(), beams);
        let got = beams_of(&rings, s.points.len());
        for (i, &b) in s.beam.iter().enumerate() {
            prop_assert_eq!(got[i], Some(b as u16), "point {}", i);
        }
    }

    /// Elevation bins at the generated beam angles give back the beams, each in azimuth
    /// order.
    #[test]
    fn elevation_recovers_the_beams(seed in any::<u64>(), beams in 2usize..64, per in 50usize..300) {
        let s = scan(seed, beams, per, 0.0, 0.1);
        let bins = ElevationBins::uniform(beams, -22.0, 2.0).unwrap();
        let rings = Rings::from_elevation(&s.points, &bins).unwrap();
        let got = beams_of(&rings, s.points.len());
        for (i, &b) in s.beam.iter().enumerate() {
            prop_assert_eq!(got[i], Some(b as u16));
        }
        for ring in rings.iter() {
            let az: Vec<f64> = ring.iter().map(|&i| { let p = s.points[i as usize]; p[1].atan2(p[0]) }).collect();
            prop_assert!(az.windows(2).all(|w| w[0] <= w[1]));
        }
    }

    /// Spurious returns planted on flat surfaces are exactly what is removed: none of the
    /// true samples (1 cm noise), all the planted ones (0.3–3 m off, isolated).
    #[test]
    fn planted_outliers_are_found(seed in any::<u64>(), beams in 2usize..16, per in 200usize..800) {
        let mut s = scan(seed, beams, per, 0.0, 0.0);
        let rings = Rings::from_firing_order(&s.points).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed);
        let mut planted = Vec::new();
        for ring in rings.iter() {
            let mut j = 3 + rng.random_range(0..20);
            while j + 3 < ring.len() {
                let i = ring[j] as usize;
                // Only where the beam's samples are close enough to be one surface.
                let close = (j - 2..j + 2).all(|m| {
                    let (a, b) = (s.points[ring[m] as usize], s.points[ring[m + 1] as usize]);
                    ((a[0]-b[0]).powi(2) + (a[1]-b[1]).powi(2) + (a[2]-b[2]).powi(2)).sqrt() < 0.45
                });
                if !close {
                    j += 5;
                    continue;
                }
                // Closer to the sensor along the ray, or below the road (a reflection).
                let p = s.points[i];
                let f = if rng.random_bool(0.5) { rng.random_range(0.3..0.9) } else { 1.0 };
                let dz = if f == 1.0 { -rng.random_range(0.3..3.0) } else { 0.0 };
                let q = [p[0] * f, p[1] * f, p[2] * f + dz];
                let moved = ((q[0]-p[0]).powi(2) + (q[1]-p[1]).powi(2) + (q[2]-p[2]).powi(2)).sqrt();
                if moved > 0.3 {
                    s.points[i] = q;
                    planted.push(i as u32);
                }
                j += 5 + rng.random_range(0..40);
            }
        }
        let mut found = beam_outliers(&s.points, &rings, &BeamOutlierConfig::default()).unwrap();
        found.sort_unstable();
        planted.sort_unstable();
        prop_assert_eq!(found, planted);
    }

    /// Every point lands in the pixel of its beam and azimuth, or is a collision; each
    /// pixel holds the nearest of its points (a brute-force assignment as the oracle).
    #[test]
    fn range_image_keeps_the_nearest(seed in any::<u64>(), beams in 1usize..10, per in 30usize..300, cols in 16usize..400) {
        let s = scan(seed, beams.max(2), per, 37.0, 0.2);
        let rings = Rings::from_firing_order(&s.points).unwrap();
        let image = RangeImage::build(&s.points, &rings, cols).unwrap();
        let mut nearest: HashMap<usize, (f64, u32)> = HashMap::new();
        for (r, ring) in rings.iter().enumerate() {
            for &i in ring {
                let p = s.points[i as usize];
                let behind = std::f64::consts::PI - p[1].atan2(p[0]);
                let c = ((behind.rem_euclid(std::f64::consts::TAU) * (cols as f64 / std::f64::consts::TAU)) as usize).min(cols - 1);
                let d = p.iter().map(|v| v * v).sum::<f64>();
                let e = nearest.entry(r * cols + c).or_insert((d, i));
                if d < e.0 { *e = (d, i); }
            }
        }
        prop_assert_eq!(image.valid(), nearest.len());
        prop_assert_eq!(image.valid() + image.collisions, s.points.len());
        for (pixel, &src) in image.source.iter().enumerate() {
            match nearest.get(&pixel) {
                Some(&(_, i)) => {
                    prop_assert_eq!(src, i);
                    prop_assert_eq!(image.points[pixel], s.points[i as usize]);
                }
                None => {
                    prop_assert_eq!(src, NO_POINT);
                    prop_assert!(image.points[pixel][0].is_nan());
                }
            }
        }
    }
}

proptest! {
    /// The trigonometry-free window test agrees with angles computed by `atan2`.
    #[test]
    fn field_of_view_matches_angles(lo in -180.0f64..180.0, hi in -180.0f64..180.0, elo in -80.0f64..0.0, ehi in 0.0f64..80.0, x in -50.0f64..50.0, y in -50.0f64..50.0, z in -20.0f64..20.0) {
        let fov = FieldOfView::new([lo, hi], [elo, ehi]).unwrap();
        let a = y.atan2(x).to_degrees();
        let e = z.atan2(x.hypot(y)).to_degrees();
        let width = (hi - lo).rem_euclid(360.0);
        let from_lo = (a - lo).rem_euclid(360.0);
        // Stay clear of the edges, where rounding may go either way.
        let near = |d: f64| d.abs() < 1e-6 || (360.0 - d).abs() < 1e-6;
        prop_assume!(!near(from_lo) && !near(from_lo - width) && (e - elo).abs() > 1e-6 && (e - ehi).abs() > 1e-6);
        let inside = from_lo <= width && elo <= e && e <= ehi;
        prop_assert_eq!(fov.contains(&[x, y, z]), inside);
    }

    /// Beams of every n-th point are the beams of the thinned scan.
    #[test]
    fn thinned_firing_order_is_the_firing_order_of_the_thinned(seed in any::<u64>(), beams in 2usize..20, n in 1usize..5) {
        let s = scan(seed, beams, 400, -30.0, 0.05);
        let every = Rings::from_firing_order_every(&s.points, n).unwrap();
        let kept: Vec<[f64; 3]> = s.points.iter().step_by(n).copied().collect();
        let direct = Rings::from_firing_order(&kept).unwrap();
        prop_assert_eq!(every.len(), direct.len());
        for (a, b) in every.iter().zip(direct.iter()) {
            let a: Vec<u32> = a.iter().map(|&i| i / n as u32).collect();
            prop_assert_eq!(a, b.to_vec());
        }
    }
}

#[test]
fn shuffled_points_are_not_a_firing_order() {
    let s = scan(7, 8, 400, 0.0, 0.0);
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut points = s.points;
    for i in (1..points.len()).rev() {
        points.swap(i, rng.random_range(0..=i));
    }
    let error = Rings::from_firing_order(&points).unwrap_err();
    assert!(error.to_string().contains("not in firing order"), "{error}");
}

/// The real frames: 64 beams, top first; beam elevations learnt from one frame recover
/// most of the other's beams; few outliers on real data.
#[test]
fn real_frames() {
    let mut frames = Vec::new();
    for name in ["kitti/000000.bin", "kitti/000001.bin"] {
        let Some(path) = test_fixtures::fixture(name) else {
            return;
        };
        frames.push(polylidar_io::read_kitti_bin(path).unwrap().points);
    }
    let mut tables = Vec::new();
    for (f, points) in frames.iter().enumerate() {
        let rings = Rings::from_firing_order(points).unwrap();
        assert_eq!(rings.len(), 64, "frame {f}");
        assert_eq!(rings.num_points(), points.len());
        let e = rings.elevations(points);
        assert!(
            e.windows(2).all(|w| w[0] > w[1]),
            "frame {f}: beams top first"
        );
        let outliers = beam_outliers(points, &rings, &BeamOutlierConfig::default()).unwrap();
        println!(
            "frame {f}: {} outliers of {} points",
            outliers.len(),
            points.len()
        );
        assert!(
            outliers.len() * 100 < points.len(),
            "frame {f}: {}",
            outliers.len()
        );
        let image = RangeImage::build(points, &rings, 0).unwrap();
        println!(
            "frame {f}: range image {} × {}, {} valid, {} collisions",
            image.rows,
            image.cols,
            image.valid(),
            image.collisions
        );
        assert_eq!(image.rows, 64);
        assert!(image.valid() * 10 > points.len() * 9, "frame {f}");
        tables.push(e);
    }
    // Elevation with frame 0's beam table, on frame 1, against frame 1's firing order.
    let bins = ElevationBins::from_angles(tables[0].clone()).unwrap();
    let by_order = Rings::from_firing_order(&frames[1])
        .unwrap()
        .beam_of_points(frames[1].len());
    let by_elevation = Rings::from_elevation(&frames[1], &bins)
        .unwrap()
        .beam_of_points(frames[1].len());
    let agree = by_order
        .iter()
        .zip(&by_elevation)
        .filter(|(a, b)| a == b)
        .count();
    let within_one = by_order
        .iter()
        .zip(&by_elevation)
        .filter(|(a, b)| match (a, b) {
            (Some(a), Some(b)) => a.abs_diff(*b) <= 1,
            _ => false,
        })
        .count();
    println!(
        "elevation vs firing order on frame 1: {:.1} % same beam, {:.1} % within one",
        100.0 * agree as f64 / frames[1].len() as f64,
        100.0 * within_one as f64 / frames[1].len() as f64
    );
    // Approximate only: the lasers sit off the sensor's axis, so near points stray.
    assert!(within_one * 10 > frames[1].len() * 7);
}
