//! Algorithm 3 of the paper: S2 id → learned-index window → branchless binary search →
//! neighbour refinement by true angular distance.

use rayon::prelude::*;

use crate::icosahedron::{CELLS_PER_TASK, Icosahedron, NO_NEIGHBOR, dot};
use crate::integrate::BATCH;
use crate::s2id;

/// What the search reads of one cell, packed so one visit touches one or two cache lines.
#[derive(Debug, Clone, Copy)]
struct Cell {
    normal: [f64; 3],
    /// `cos` of half the angle to the nearest 1-ring cell that shares no edge, plus a
    /// rounding margin: in that cap around the normal only the three edge neighbours can be
    /// closer to a query, so a query in the cap that beats them is in this cell.
    certain: f64,
    /// The three cells sharing an edge with this one.
    edges: [u32; 3],
    /// 1-ring neighbours with the sentinel replaced by the cell itself (never an improvement).
    ring: [u32; 12],
}

/// The cell search of one icosahedron.
#[derive(Debug, Clone)]
pub(crate) struct CellSearch {
    /// Top 32 bits of each cell id: the binary search reads these (half the ids'
    /// cache footprint); equal keys only make the starting cell less exact.
    keys: Vec<u32>,
    cells: Vec<Cell>,
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
        let ids = ico.cell_ids();
        let model = LinearModel::fit(ids);
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
        let triangles = ico.triangles();
        let shared = |a: usize, b: usize| {
            triangles[a]
                .iter()
                .filter(|v| triangles[b].contains(v))
                .count()
        };
        // Per cell on its own, in parallel: the same cells in the same order on any pool.
        let cells = ico
            .neighbors()
            .par_iter()
            .enumerate()
            .with_min_len(CELLS_PER_TASK)
            .map(|(i, row)| {
                let ring = row.map(|c| if c == NO_NEIGHBOR { i as u32 } else { c });
                let mut edges = [i as u32; 3];
                let mut k = 0;
                let mut nearest = -1.0f64;
                for &c in ring.iter().filter(|&&c| c as usize != i) {
                    if shared(i, c as usize) == 2 {
                        edges[k] = c;
                        k += 1;
                    } else {
                        nearest = nearest.max(dot(normals[i], normals[c as usize]));
                    }
                }
                debug_assert_eq!(k, 3, "a closed triangle mesh has three edge neighbours");
                Cell {
                    normal: normals[i],
                    // cos(θ/2) = sqrt((1 + cos θ) / 2); the margin covers rounding in the
                    // dots.
                    certain: ((1.0 + nearest) / 2.0).sqrt() + 1e-9,
                    edges,
                    ring,
                }
            })
            .collect();
        // Hilbert levels of the query ids (4 · steps − 2): about two finer than the cells, which
        // starts the ascent as well as the full leaf id does.
        let steps = (ico.level() + 4).div_ceil(4).clamp(1, 8);
        Self {
            keys: ids.iter().map(|&id| key32(id)).collect(),
            cells,
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
        let lo = self.window_start(id);
        let k = lo + lower_bound(&self.keys[lo..lo + self.window], key32(id));
        // Start from the better (by angle) of the two cells around the id on the curve.
        let last = self.cells.len() - 1;
        let (a, b) = (k.saturating_sub(1), k.min(last));
        let (da, db) = (dot(self.cells[a].normal, p), dot(self.cells[b].normal, p));
        let start = std::hint::select_unpredictable(da >= db, a, b);
        if self.is_certain(start, da.max(db), p) {
            start as u32
        } else {
            self.descend(start, da.max(db), p)
        }
    }

    /// [`find`](Self::find) for up to [`BATCH`] normals, stage by stage so that the memory
    /// latencies of the independent searches overlap.
    #[inline(always)]
    pub(crate) fn find_batch(&self, batch: &[[f64; 3]], cells: &mut [u32]) {
        let n = batch.len().min(BATCH);
        let mut base = [0usize; BATCH];
        let mut key = [0u32; BATCH];
        for b in 0..n {
            let id = s2id::cell_id_prefix(batch[b], self.steps);
            base[b] = self.window_start(id);
            key[b] = key32(id);
        }
        // Lower bound in each window, one step for every normal at a time.
        let mut size = self.window;
        while size > 1 {
            let half = size / 2;
            for b in 0..n {
                let probe = base[b] + half;
                base[b] =
                    std::hint::select_unpredictable(self.keys[probe] < key[b], probe, base[b]);
            }
            size -= half;
        }
        // Starting cells, and whether each is already certain (loads overlap across normals).
        let last = self.cells.len() - 1;
        let mut start = [0usize; BATCH];
        let mut start_dot = [0.0f64; BATCH];
        let mut done = [false; BATCH];
        for b in 0..n {
            let k = base[b] + usize::from(self.keys[base[b]] < key[b]);
            let p = batch[b];
            let (lo, hi) = (k.saturating_sub(1), k.min(last));
            let (dl, dh) = (dot(self.cells[lo].normal, p), dot(self.cells[hi].normal, p));
            start[b] = std::hint::select_unpredictable(dl >= dh, lo, hi);
            start_dot[b] = dl.max(dh);
            done[b] = self.is_certain(start[b], start_dot[b], p);
        }
        for b in 0..n {
            cells[b] = if done[b] {
                start[b] as u32
            } else {
                self.descend(start[b], start_dot[b], batch[b])
            };
        }
    }

    /// Whether `p`, with dot product `best_dot` with the normal of `cell`, is in that cell by
    /// the cap and edge-neighbour test (a sufficient condition, without branches).
    #[inline(always)]
    fn is_certain(&self, cell: usize, best_dot: f64, p: [f64; 3]) -> bool {
        let cell = &self.cells[cell];
        let edge = |k: usize| dot(self.cells[cell.edges[k] as usize].normal, p);
        let in_cap = best_dot >= cell.certain * dot(p, p).sqrt();
        in_cap & (best_dot >= edge(0).max(edge(1)).max(edge(2)))
    }

    /// Start of the window of the model that holds the insertion point of `id`.
    #[inline(always)]
    fn window_start(&self, id: u64) -> usize {
        (self.model.predict(id) + self.error_min).clamp(0, self.last_start) as usize
    }

    /// Steepest ascent of `normal · p` over the 1-ring neighbour graph from a cell that failed
    /// [`is_certain`](Self::is_certain). The 1-ring holds every Voronoi neighbour of a cell
    /// normal (checked in the tests), so a cell with no better neighbour is the closest cell
    /// overall; so is one that passes `is_certain`.
    #[inline(always)]
    pub(crate) fn descend(&self, mut best: usize, mut best_dot: f64, p: [f64; 3]) -> u32 {
        loop {
            let mut next = best;
            for &c in &self.cells[best].ring {
                let d = dot(self.cells[c as usize].normal, p);
                if d > best_dot {
                    best_dot = d;
                    next = c as usize;
                }
            }
            if next == best || self.is_certain(next, best_dot, p) {
                return next as u32;
            }
            best = next;
        }
    }
}

/// The top 32 bits of an id, monotone in it.
#[inline(always)]
fn key32(id: u64) -> u32 {
    (id >> 32) as u32
}

/// First position in `ids` whose id is ≥ `id` (`ids.len()` if none), by a branchless binary
/// search: the loop count depends only on the length.
#[inline(always)]
fn lower_bound<T: Ord + Copy>(ids: &[T], id: T) -> usize {
    let mut base = 0;
    let mut size = ids.len();
    if size == 0 {
        return 0;
    }
    while size > 1 {
        let half = size / 2;
        // A conditional move, not a branch: the comparison is a coin flip.
        base = std::hint::select_unpredictable(ids[base + half] < id, base + half, base);
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
