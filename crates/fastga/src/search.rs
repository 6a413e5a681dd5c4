//! Algorithm 3 of the paper: S2 id → learned-index window → branchless binary search →
//! neighbour refinement by true angular distance.

use crate::icosahedron::{Icosahedron, NO_NEIGHBOR, dot};
use crate::s2id;

/// The cell search of one icosahedron.
#[derive(Debug, Clone)]
pub(crate) struct CellSearch {
    ids: Vec<u64>,
    normals: Vec<[f64; 3]>,
    /// 1-ring neighbours with the sentinel replaced by the cell itself (never an improvement).
    ring: Vec<[u32; 12]>,
    /// Per cell, `cos` of half the angle to the nearest other cell normal (less a rounding
    /// margin): a query whose dot product with the cell normal reaches it is inside the
    /// cell's inscribed cap, so no other cell can be closer.
    certain: Vec<f64>,
    /// Lookup steps of the query ids (see [`s2id::cell_id_prefix`]).
    steps: u32,
    model: LinearModel,
    /// Smallest `k - predict(id_k)` over the cells.
    error_min: i64,
    /// Largest `k - predict(id_k)` over the cells.
    error_max: i64,
    /// Number of ids the binary search looks at.
    window: usize,
    /// Largest start of the window.
    last_start: i64,
}

/// Least-squares line from cell id to array index, evaluated in a fixed, monotone way.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LinearModel {
    id_mean: f64,
    index_mean: f64,
    slope: f64,
}

impl LinearModel {
    fn fit(ids: &[u64]) -> Self {
        let n = ids.len() as f64;
        let id_mean = ids.iter().map(|&id| key(id)).sum::<f64>() / n;
        let index_mean = (n - 1.0) / 2.0;
        let (mut sxy, mut sxx) = (0.0, 0.0);
        for (k, &id) in ids.iter().enumerate() {
            let dx = key(id) - id_mean;
            sxy += dx * (k as f64 - index_mean);
            sxx += dx * dx;
        }
        // Sorted distinct ids give a positive slope; a single cell gets a flat line.
        let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
        Self {
            id_mean,
            index_mean,
            slope,
        }
    }

    /// The predicted index, truncated: non-decreasing in `id` (every step is monotone), which
    /// the error bounds rely on.
    #[inline(always)]
    fn predict(self, id: u64) -> i64 {
        ((key(id) - self.id_mean) * self.slope + self.index_mean) as i64
    }
}

/// An id as a float, monotone in the id: halved first so that it fits an `i64`, whose
/// conversion to `f64` is a single instruction (unlike `u64`'s).
#[inline(always)]
fn key(id: u64) -> f64 {
    ((id >> 1) as i64) as f64
}

impl CellSearch {
    pub(crate) fn new(ico: &Icosahedron) -> Self {
        let ids = ico.cell_ids().to_vec();
        let model = LinearModel::fit(&ids);
        let (mut error_min, mut error_max) = (i64::MAX, i64::MIN);
        for (k, &id) in ids.iter().enumerate() {
            let e = k as i64 - model.predict(id);
            error_min = error_min.min(e);
            error_max = error_max.max(e);
        }
        // For a query id between cell ids k and k+1 the insertion point k+1 lies in
        // predict + [error_min, error_max + 1]: error_max - error_min + 2 candidate positions,
        // which a lower-bound search over one id fewer covers.
        let window = ((error_max - error_min + 1) as usize).min(ids.len());
        let last_start = (ids.len() - window) as i64;
        let normals = ico.normals();
        let ring: Vec<[u32; 12]> = ico
            .neighbors()
            .iter()
            .enumerate()
            .map(|(i, row)| row.map(|c| if c == NO_NEIGHBOR { i as u32 } else { c }))
            .collect();
        // The nearest other cell normal is a Voronoi neighbour, hence in the 1-ring.
        let certain = ring
            .iter()
            .enumerate()
            .map(|(i, row)| {
                let nearest = row
                    .iter()
                    .filter(|&&c| c as usize != i)
                    .map(|&c| dot(normals[i], normals[c as usize]))
                    .fold(-1.0, f64::max);
                // cos(θ/2) = sqrt((1 + cos θ) / 2); the margin covers rounding in the dots.
                ((1.0 + nearest) / 2.0).sqrt() + 1e-9
            })
            .collect();
        // Hilbert levels of the query ids (4 · steps − 2): about two finer than the cells, which
        // starts the ascent as well as the full leaf id does.
        let steps = (ico.level() + 4).div_ceil(4).clamp(1, 8);
        Self {
            ids,
            normals: normals.to_vec(),
            ring,
            certain,
            steps,
            model,
            error_min,
            error_max,
            window,
            last_start,
        }
    }

    /// The worst-case model errors `(min, max)` of `index - predicted index` over the cells.
    pub(crate) fn error_bounds(&self) -> (i64, i64) {
        (self.error_min, self.error_max)
    }

    /// Index of the cell whose normal is closest to `p` (non-zero, finite).
    #[inline(always)]
    pub(crate) fn find(&self, p: [f64; 3]) -> u32 {
        let id = s2id::cell_id_prefix(p, self.steps);
        let k = self.insertion_point(id);
        // Start from the better (by angle) of the two cells around the id on the curve.
        let last = self.ids.len() - 1;
        let (a, b) = (k.saturating_sub(1), k.min(last));
        let (da, db) = (dot(self.normals[a], p), dot(self.normals[b], p));
        if da >= db {
            self.descend(a, da, p)
        } else {
            self.descend(b, db, p)
        }
    }

    /// Position of the first cell id ≥ `id`, found in the model's window.
    #[inline(always)]
    pub(crate) fn insertion_point(&self, id: u64) -> usize {
        let lo = (self.model.predict(id) + self.error_min).clamp(0, self.last_start) as usize;
        lo + lower_bound(&self.ids[lo..lo + self.window], id)
    }

    /// Steepest ascent of `normal · p` over the 1-ring neighbour graph. The 1-ring holds every
    /// Voronoi neighbour of a cell normal (checked in the tests), so a cell with no better
    /// neighbour is the closest cell overall; a cell whose inscribed cap holds `p` is too.
    #[inline(always)]
    fn descend(&self, mut best: usize, mut best_dot: f64, p: [f64; 3]) -> u32 {
        let norm = dot(p, p).sqrt();
        loop {
            if best_dot >= self.certain[best] * norm {
                return best as u32;
            }
            let mut next = best;
            for &c in &self.ring[best] {
                let d = dot(self.normals[c as usize], p);
                if d > best_dot {
                    best_dot = d;
                    next = c as usize;
                }
            }
            if next == best {
                return best as u32;
            }
            best = next;
        }
    }
}

/// First position in `ids` whose id is ≥ `id` (`ids.len()` if none), by a branchless binary
/// search: the loop count depends only on the length.
#[inline(always)]
fn lower_bound(ids: &[u64], id: u64) -> usize {
    let mut base = 0;
    let mut size = ids.len();
    if size == 0 {
        return 0;
    }
    while size > 1 {
        let half = size / 2;
        let mid = base + half;
        base = if ids[mid] < id { mid } else { base };
        size -= half;
    }
    base + usize::from(ids[base] < id)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lower_bound_matches_partition_point() {
        let ids: Vec<u64> = (0..37).map(|k| 10 * k + 5).collect();
        for len in 0..ids.len() {
            let slice = &ids[..len];
            for q in 0..400 {
                assert_eq!(
                    lower_bound(slice, q),
                    slice.partition_point(|&x| x < q),
                    "len {len} q {q}"
                );
            }
        }
    }

    #[test]
    fn window_contains_the_insertion_point_for_every_id_between_cells() {
        for level in 0..=5 {
            let ico = Icosahedron::new(level).unwrap();
            let search = CellSearch::new(&ico);
            let ids = ico.cell_ids();
            let mut probes = vec![0, u64::MAX];
            for w in ids.windows(2) {
                probes.extend([w[0], w[0] + 1, w[0] + (w[1] - w[0]) / 2, w[1] - 1]);
            }
            for q in probes {
                let lo = (search.model.predict(q) + search.error_min).clamp(0, search.last_start)
                    as usize;
                let truth = ids.partition_point(|&x| x < q);
                assert!(
                    (lo..=lo + search.window).contains(&truth),
                    "level {level}: id {q} insertion point {truth} outside [{lo}, {}]",
                    lo + search.window
                );
            }
        }
    }

    #[test]
    fn level_4_window_is_small() {
        let search = CellSearch::new(&Icosahedron::new(4).unwrap());
        let (lo, hi) = search.error_bounds();
        assert!(hi - lo < 128, "bounds {lo}..{hi}");
    }
}
