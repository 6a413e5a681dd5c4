//! The k-d tree baseline (feature `kdtree`) against exhaustive search and against the
//! accumulator it is the baseline of.

mod common;

use common::{dot, random_units};
use fastga::{GaussianAccumulator, IntegrateStats, KdAccumulator, Parallelism, Search};
use rayon::prelude::*;

/// Two cells are equally good answers when their normals' dot products with the query differ
/// by at most this (the documented tie rule).
const TIE: f64 = 1e-12;

#[test]
fn levels_0_to_6_match_brute_force() {
    for level in 0..=6u32 {
        let count = if cfg!(debug_assertions) {
            1_000
        } else {
            20_000
        };
        let kd = KdAccumulator::new(level).unwrap();
        let ico = kd.icosahedron();
        let n = ico.normals();
        random_units(u64::from(level) + 7, count)
            .par_iter()
            .for_each(|&p| {
                let (found, best) = (kd.find_cell(p), ico.nearest_cell_brute_force(p));
                assert!(
                    dot(n[found as usize], p) >= dot(n[best as usize], p) - TIE,
                    "level {level} normal {p:?}: k-d tree cell {found}, brute force {best}"
                );
            });
    }
}

/// Random normals hit no ties, so the counts are the same cell by cell.
#[test]
fn integrate_bins_like_the_accumulator_and_brute_force() {
    let normals = random_units(99, 10_000);
    for level in [3, 4] {
        let mut kd = KdAccumulator::new(level).unwrap();
        let mut ga = GaussianAccumulator::with_search(level, Search::LearnedIndex).unwrap();
        kd.integrate(&normals, 1.0, Parallelism::Sequential)
            .unwrap();
        ga.integrate(&normals, 1.0, Parallelism::Sequential)
            .unwrap();
        let mut brute = vec![0u64; kd.icosahedron().cell_count()];
        for &p in &normals {
            brute[kd.icosahedron().nearest_cell_brute_force(p) as usize] += 1;
        }
        assert_eq!(kd.counts(), &brute[..]);
        assert_eq!(kd.counts(), ga.counts());
    }
}

#[test]
fn invalid_normals_are_skipped_and_counted_like_the_accumulator() {
    let s = 1.0 / 3f64.sqrt();
    let normals = [
        [0.0, 0.0, 1.0],
        [f64::NAN, 0.0, 1.0],
        [f64::INFINITY, 0.0, 0.0],
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [0.0, 0.99, 0.0],
        [s, s, s],
        [0.0, 1.0 + 1e-6, 0.0],
    ];
    let expected = IntegrateStats {
        integrated: 3,
        skipped_invalid: 5,
        skipped_by_sampling: 0,
    };
    for parallelism in [Parallelism::Sequential, Parallelism::Rayon] {
        let mut kd = KdAccumulator::new(2).unwrap();
        assert_eq!(kd.integrate(&normals, 1.0, parallelism).unwrap(), expected);
        assert_eq!(kd.counts().iter().sum::<u64>(), 3);
    }
    let mut kd = KdAccumulator::new(2).unwrap();
    assert!(kd.set_unit_tolerance(f64::NAN).is_err());
    assert!(kd.set_unit_tolerance(1.0).is_err());
    assert!(KdAccumulator::new(fastga::MAX_LEVEL + 1).is_err());
}
