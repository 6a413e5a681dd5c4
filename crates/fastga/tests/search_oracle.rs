//! The accumulators' cell search against exhaustive search over all cell normals.

mod common;

use common::{cross, dot, normalize, random_units, sub};
use fastga::{GaussianAccumulator, Icosahedron, NO_NEIGHBOR, Parallelism, Search};
use rayon::prelude::*;

/// Two cells are equally good answers when their normals' dot products with the query differ
/// by at most this (the documented tie rule).
const TIE: f64 = 1e-12;

/// An accumulator at `level` with each search: Algorithm 3 and the cell table.
fn both_searches(level: u32) -> [GaussianAccumulator; 2] {
    [Search::LearnedIndex, Search::CellTable].map(|search| {
        GaussianAccumulator::with_search(level, search)
            .unwrap_or_else(|e| unreachable!("level {level}: {e}"))
    })
}

fn assert_matches_brute_force(ico: &Icosahedron, found: u32, p: [f64; 3], what: &str) {
    let best = ico.nearest_cell_brute_force(p);
    if found != best {
        let n = ico.normals();
        let (df, db) = (dot(n[found as usize], p), dot(n[best as usize], p));
        assert!(
            df >= db - TIE,
            "{what}: level {} normal {p:?}: found cell {found} (dot {df}), brute force {best} (dot {db})",
            ico.level()
        );
    }
}

/// 1,000,000 random normals at level 4 in release builds; 100,000 in debug builds (the
/// exhaustive oracle costs 5,120 dot products per normal).
#[test]
fn level_4_random_normals_match_brute_force() {
    let count = if cfg!(debug_assertions) {
        100_000
    } else {
        1_000_000
    };
    let searches = both_searches(4);
    let normals = random_units(2020, count);
    let ico = searches[0].icosahedron();
    let n = ico.normals();
    let mismatches: usize = normals
        .par_iter()
        .map(|&p| {
            let best = ico.nearest_cell_brute_force(p);
            let best_dot = dot(n[best as usize], p);
            searches
                .iter()
                .filter(|ga| dot(n[ga.find_cell(p) as usize], p) < best_dot - TIE)
                .count()
        })
        .sum();
    assert_eq!(mismatches, 0, "of {count} normals, both searches");
}

#[test]
fn levels_0_to_6_match_brute_force() {
    for level in 0..=6u32 {
        let count = match (cfg!(debug_assertions), level) {
            (true, 0..=3) => 5_000,
            (true, 4) => 2_000,
            (true, 5) => 1_000,
            (true, _) => 300,
            (false, _) => 20_000,
        };
        let [learned, table] = both_searches(level);
        let normals = random_units(u64::from(level) + 7, count);
        normals.par_iter().for_each(|&p| {
            let ico = learned.icosahedron();
            assert_matches_brute_force(ico, learned.find_cell(p), p, "learned index");
            assert_matches_brute_force(ico, table.find_cell(p), p, "cell table");
        });
    }
}

/// Normals on the S2 cube's face centres (the poles ±z among them), on its edges and corners
/// (face seams), just either side of a seam, and their antipodes.
#[test]
fn poles_seams_and_antipodes_match_brute_force() {
    let mut probes: Vec<[f64; 3]> = Vec::new();
    let e = 1e-12;
    for a in [-1.0, 0.0, 1.0] {
        for b in [-1.0, 0.0, 1.0] {
            for c in [-1.0, 0.0, 1.0] {
                if (a, b, c) != (0.0, 0.0, 0.0) {
                    probes.push(normalize([a, b, c]));
                    probes.push(normalize([a + e, b - e, c]));
                    probes.push(normalize([a - e, b, c + e]));
                }
            }
        }
    }
    // Points along the seams |x| = |y|, |y| = |z|, |z| = |x| of the cube.
    let steps = if cfg!(debug_assertions) { 40 } else { 200 };
    for k in 0..steps {
        let t = -1.0 + 2.0 * f64::from(k) / f64::from(steps - 1);
        for s in [-1.0, 1.0] {
            probes.push(normalize([1.0, s, t]));
            probes.push(normalize([t, 1.0, s]));
            probes.push(normalize([s, t, -1.0]));
        }
    }
    let antipodes: Vec<[f64; 3]> = probes.iter().map(|p| p.map(|x| -x)).collect();
    probes.extend(antipodes);
    for ga in (0..=6).flat_map(both_searches) {
        let level = ga.icosahedron().level();
        let normals = ga.icosahedron().normals();
        for &p in &probes {
            let found = ga.find_cell(p);
            assert_matches_brute_force(ga.icosahedron(), found, p, "seam");

            // The icosahedron is centrally symmetric: the antipode's cell is the opposite one.
            let opposite = ga.find_cell(p.map(|x| -x));
            let (a, b) = (normals[found as usize], normals[opposite as usize]);
            assert!(
                (dot(a, p) + dot(b, p)).abs() < 1e-9,
                "level {level}: {p:?} and its antipode land in non-opposite cells"
            );
        }
    }
}

/// The 1-ring of every cell holds all its Voronoi neighbours, so the steepest ascent of the
/// search cannot stop short of the closest cell: the Voronoi cell restricted to the 1-ring
/// has all its corners inside the true Voronoi cell. Levels 0–3 in debug builds, 0–6 in
/// release builds.
#[test]
fn one_ring_contains_every_voronoi_neighbour() {
    let max_level = if cfg!(debug_assertions) { 3 } else { 6 };
    for level in 0..=max_level {
        let ico = Icosahedron::new(level).unwrap();
        let normals = ico.normals();
        (0..ico.cell_count()).into_par_iter().for_each(|i| {
            let c = normals[i];
            let ring: Vec<[f64; 3]> = ico.neighbors()[i]
                .iter()
                .filter(|&&j| j != NO_NEIGHBOR)
                .map(|&j| normals[j as usize])
                .collect();
            let mut corners = 0;
            for (a, &cj) in ring.iter().enumerate() {
                for &ck in &ring[a + 1..] {
                    let mut v = cross(sub(cj, c), sub(ck, c));
                    if dot(v, v) < 1e-30 {
                        continue;
                    }
                    v = normalize(v);
                    if dot(v, c) < 0.0 {
                        v = v.map(|x| -x);
                    }
                    let own = dot(v, c);
                    if ring.iter().any(|&m| dot(v, m) > own + 1e-12) {
                        continue; // not a corner of the restricted cell
                    }
                    corners += 1;
                    let best = ico.nearest_cell_brute_force(v) as usize;
                    assert!(
                        dot(v, normals[best]) <= own + 1e-12,
                        "level {level} cell {i}: corner {v:?} is closer to cell {best} outside the 1-ring"
                    );
                }
            }
            assert!(corners >= 3, "level {level} cell {i}: {corners} corners");
        });
    }
}

/// `integrate` searches in batches; with either search its counts match exhaustive search
/// and `find_cell` (random normals hit no ties).
#[test]
fn integrate_bins_like_brute_force_and_find_cell() {
    let normals = random_units(99, 10_000);
    for mut ga in [3, 4].into_iter().flat_map(both_searches) {
        ga.integrate(&normals, 1.0, Parallelism::Sequential)
            .unwrap();
        let mut brute = vec![0u64; ga.icosahedron().cell_count()];
        let mut single = vec![0u64; ga.icosahedron().cell_count()];
        for &p in &normals {
            brute[ga.icosahedron().nearest_cell_brute_force(p) as usize] += 1;
            single[ga.find_cell(p) as usize] += 1;
        }
        assert_eq!(ga.counts(), &brute[..]);
        assert_eq!(ga.counts(), &single[..]);
    }
}
