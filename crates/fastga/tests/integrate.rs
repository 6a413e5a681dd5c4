//! Integration: input types, validity filter, sampling, and results independent of threads.

mod common;

use common::{dot, random_units};
use std::sync::OnceLock;

use fastga::{GaussianAccumulator, IntegrateStats, Parallelism, Search};
use proptest::prelude::*;

/// Accumulators at levels 0–4 with each search, built once for all proptest cases.
fn accumulators() -> &'static [GaussianAccumulator] {
    static ALL: OnceLock<Vec<GaussianAccumulator>> = OnceLock::new();
    ALL.get_or_init(|| {
        (0..=4)
            .flat_map(|level| {
                [Search::LearnedIndex, Search::CellTable].map(|search| {
                    GaussianAccumulator::with_search(level, search)
                        .unwrap_or_else(|e| unreachable!("level {level}: {e}"))
                })
            })
            .collect()
    })
}

fn snapshot(ga: &GaussianAccumulator) -> (Vec<u64>, Vec<[f64; 3]>) {
    let sums = (0..ga.icosahedron().cell_count() as u32)
        .map(|c| ga.cell_normal_sum(c))
        .collect();
    (ga.counts().to_vec(), sums)
}

#[test]
fn results_are_identical_for_any_thread_count() {
    let normals = random_units(11, 60_000);
    let mut reference = GaussianAccumulator::new(4).unwrap();
    let expected_stats = reference
        .integrate(&normals, 0.3, Parallelism::Sequential)
        .unwrap();
    let expected = snapshot(&reference);
    for threads in 1..=4 {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut ga = GaussianAccumulator::new(4).unwrap();
        let stats = pool.install(|| ga.integrate(&normals, 0.3, Parallelism::Rayon).unwrap());
        assert_eq!(stats, expected_stats, "{threads} threads");
        assert_eq!(snapshot(&ga), expected, "{threads} threads");
    }
}

#[test]
fn construction_is_identical_for_any_thread_count() {
    // Level 5 (20,480 cells) is built in parallel tasks: the cells, their order, their
    // neighbours and the search must not depend on the pool.
    let queries = random_units(13, 20_000);
    let build = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| GaussianAccumulator::new(5).unwrap())
    };
    let reference = build(1);
    let ico = reference.icosahedron();
    let cells: Vec<u32> = queries.iter().map(|&p| reference.find_cell(p)).collect();
    for threads in 2..=4 {
        let ga = build(threads);
        let other = ga.icosahedron();
        assert_eq!(other.cell_ids(), ico.cell_ids(), "{threads} threads");
        assert_eq!(other.triangles(), ico.triangles(), "{threads} threads");
        assert_eq!(other.normals(), ico.normals(), "{threads} threads");
        assert_eq!(other.neighbors(), ico.neighbors(), "{threads} threads");
        assert_eq!(ga.model_error_bounds(), reference.model_error_bounds());
        let found: Vec<u32> = queries.iter().map(|&p| ga.find_cell(p)).collect();
        assert_eq!(found, cells, "{threads} threads");
    }
}

#[test]
fn f32_input_bins_like_its_f64_conversion() {
    let normals: Vec<[f32; 3]> = random_units(12, 20_000)
        .iter()
        .map(|p| p.map(|x| x as f32))
        .collect();
    let widened: Vec<[f64; 3]> = normals.iter().map(|p| p.map(f64::from)).collect();
    let mut a = GaussianAccumulator::new(3).unwrap();
    let mut b = GaussianAccumulator::new(3).unwrap();
    let sa = a.integrate(&normals, 1.0, Parallelism::Rayon).unwrap();
    let sb = b.integrate(&widened, 1.0, Parallelism::Rayon).unwrap();
    assert_eq!(sa, sb);
    assert_eq!(sa.integrated, 20_000);
    assert_eq!(snapshot(&a), snapshot(&b));
}

#[test]
fn invalid_normals_are_skipped_and_counted() {
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
    for parallelism in [Parallelism::Sequential, Parallelism::Rayon] {
        let mut ga = GaussianAccumulator::new(2).unwrap();
        let stats = ga.integrate(&normals, 1.0, parallelism).unwrap();
        assert_eq!(
            stats,
            IntegrateStats {
                integrated: 3,
                skipped_invalid: 5,
                skipped_by_sampling: 0
            }
        );
        assert_eq!(ga.total(), 3);
    }
    let mut strict = GaussianAccumulator::new(2).unwrap();
    strict.set_unit_tolerance(0.0).unwrap();
    assert!(strict.set_unit_tolerance(f64::NAN).is_err());
    assert!(strict.set_unit_tolerance(1.0).is_err());
}

#[test]
fn sampling_is_deterministic_and_counts_add_up() {
    let normals = random_units(13, 50_000);
    let mut ga = GaussianAccumulator::new(3).unwrap();
    let first = ga
        .integrate(&normals, 0.12, Parallelism::Sequential)
        .unwrap();
    let counts = ga.counts().to_vec();
    assert_eq!(first.integrated + first.skipped_by_sampling, 50_000);
    let kept = first.integrated as f64 / 50_000.0;
    assert!((kept - 0.12).abs() < 0.01, "kept {kept}");
    ga.clear();
    assert_eq!(ga.total(), 0);
    let second = ga.integrate(&normals, 0.12, Parallelism::Rayon).unwrap();
    assert_eq!(first, second);
    assert_eq!(ga.counts(), &counts[..]);
    assert!(ga.integrate(&normals, 0.0, Parallelism::Rayon).is_err());
    assert!(ga.integrate(&normals, 1.01, Parallelism::Rayon).is_err());
}

/// An accumulator reused over inputs of changing length and sample fraction (a stream of
/// frames) bins what a fresh one bins for each input: the sample it keeps between calls
/// is that of the input at hand.
#[test]
fn a_reused_accumulator_samples_each_input_as_a_fresh_one() {
    let normals = random_units(17, 60_000);
    let mut reused = GaussianAccumulator::with_search(3, Search::LearnedIndex).unwrap();
    for (len, fraction) in [
        (40_000, 0.12),
        (25_000, 0.12),
        (59_999, 0.12),
        (59_999, 0.3),
        (8_193, 0.12),
        (10, 0.12),
    ] {
        reused.clear();
        let stats = reused
            .integrate(&normals[..len], fraction, Parallelism::Rayon)
            .unwrap();
        let mut fresh = GaussianAccumulator::with_search(3, Search::LearnedIndex).unwrap();
        let expected = fresh
            .integrate(&normals[..len], fraction, Parallelism::Sequential)
            .unwrap();
        assert_eq!(stats, expected, "{len} at {fraction}");
        assert_eq!(snapshot(&reused), snapshot(&fresh), "{len} at {fraction}");
    }
}

#[test]
fn cell_means_are_the_mean_of_their_normals() {
    let normals = random_units(14, 5_000);
    let mut ga = GaussianAccumulator::new(1).unwrap();
    ga.integrate(&normals, 1.0, Parallelism::Rayon).unwrap();
    for cell in 0..ga.icosahedron().cell_count() as u32 {
        let mut sum = [0.0; 3];
        for p in normals.iter().filter(|&&p| ga.find_cell(p) == cell) {
            for k in 0..3 {
                sum[k] += p[k];
            }
        }
        let ours = ga.cell_normal_sum(cell);
        for k in 0..3 {
            assert!((ours[k] - sum[k]).abs() < 1e-6);
        }
        if let Some(mean) = ga.cell_mean_normal(cell) {
            assert!((dot(mean, mean) - 1.0).abs() < 1e-12);
        }
    }
}

#[test]
fn empty_input_is_fine() {
    let mut ga = GaussianAccumulator::new(0).unwrap();
    let none: [[f64; 3]; 0] = [];
    for parallelism in [Parallelism::Sequential, Parallelism::Rayon] {
        let stats = ga.integrate(&none, 1.0, parallelism).unwrap();
        assert_eq!(stats, IntegrateStats::default());
    }
    assert!(ga.find_peaks(0.0).is_empty());
    assert!(ga.unwrapped_image().values().iter().all(|&v| v == 0.0));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]
    /// Either search finds the closest cell (up to 1e-12 ties) for any non-zero direction, at
    /// any scale; the direction is what counts.
    #[test]
    fn find_cell_is_exhaustive_search(
        x in -1.0f64..1.0, y in -1.0f64..1.0, z in -1.0f64..1.0,
        scale in 1e-3f64..1e3, which in 0usize..10,
    ) {
        prop_assume!(x * x + y * y + z * z > 1e-9);
        let ga = &accumulators()[which];
        let p = [x * scale, y * scale, z * scale];
        let found = ga.find_cell(p);
        let best = ga.icosahedron().nearest_cell_brute_force(p);
        let n = ga.icosahedron().normals();
        let norm = dot(p, p).sqrt();
        prop_assert!(dot(n[found as usize], p) / norm >= dot(n[best as usize], p) / norm - 1e-12);
    }
}

/// `Search::Adaptive` uses the learned index until the normals integrated, counting the call
/// at hand, reach `TABLE_PAYS_AFTER` per table entry (6·4^(level + 2)), then builds the
/// table; its counts and sums stay those of the two fixed searches before and after.
#[test]
fn adaptive_search_builds_the_table_once_it_pays_and_bins_alike() {
    let level = 1;
    let entries = 6u64 << (2 * (level + 2));
    let threshold = fastga::TABLE_PAYS_AFTER * entries;
    let normals = random_units(21, threshold as usize / 2 + 1);
    let mut adaptive = GaussianAccumulator::new(level).unwrap();
    let mut table = GaussianAccumulator::with_search(level, Search::CellTable).unwrap();
    let mut learned = GaussianAccumulator::with_search(level, Search::LearnedIndex).unwrap();
    assert_eq!(adaptive.search(), Search::Adaptive);
    assert!(!adaptive.uses_table() && table.uses_table() && !learned.uses_table());
    for call in 0..3 {
        for ga in [&mut adaptive, &mut table, &mut learned] {
            ga.integrate(&normals, 1.0, Parallelism::Sequential)
                .unwrap();
        }
        // Calls 0 and 1 integrate half the threshold and one more each: the second reaches it
        // and builds the table first.
        assert_eq!(adaptive.uses_table(), call >= 1, "call {call}");
        assert_eq!(snapshot(&adaptive), snapshot(&table), "call {call}");
        assert_eq!(snapshot(&adaptive), snapshot(&learned), "call {call}");
    }
    // One call that alone reaches the threshold builds the table at once.
    let mut once = GaussianAccumulator::new(level).unwrap();
    let many = random_units(22, threshold as usize);
    once.integrate(&many, 1.0, Parallelism::Sequential).unwrap();
    assert!(once.uses_table());
    // A sample counts as the normals it keeps.
    let mut sampled = GaussianAccumulator::new(level).unwrap();
    sampled
        .integrate(&many, 0.5, Parallelism::Sequential)
        .unwrap();
    assert!(!sampled.uses_table());
}
