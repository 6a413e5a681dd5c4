//! k nearest neighbours of every point of a cloud, on a uniform grid of cubic cells: the
//! queries of one cell share the points of the 3 × 3 × 3 block of cells around it,
//! gathered once (for points on surfaces this is several times faster than a general k-d
//! tree); a query whose k-th neighbour may lie beyond the block goes on ring by ring.

use rayon::prelude::*;

use crate::NormalsError;

/// Bits per axis of a cell key.
const BITS: u32 = 21;

/// The `k` nearest neighbours of every point, stored flat: the neighbours of point `i` are
/// `indices[i * k .. (i + 1) * k]`, nearest first (ties: lower index first), the point
/// itself included (first, unless an equal point with a lower index comes first). With
/// fewer than `k` points, `k` is the count.
#[derive(Debug, Clone, PartialEq)]
pub struct Neighbours {
    k: usize,
    indices: Vec<u32>,
}

impl Neighbours {
    /// The `k` nearest neighbours of each of `points` (the point itself counts as one).
    ///
    /// ```
    /// use cloud_normals::Neighbours;
    /// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [5.0, 0.0, 0.0], [1.5, 0.0, 0.0]];
    /// let knn = Neighbours::new(&points, 2)?;
    /// assert_eq!(knn.of(0), [0, 1]);
    /// assert_eq!(knn.of(2), [2, 3]);
    /// # Ok::<(), cloud_normals::NormalsError>(())
    /// ```
    ///
    /// # Errors
    /// [`NormalsError::Empty`], [`NormalsError::NonFinite`], [`NormalsError::TooManyPoints`],
    /// and [`NormalsError::TooFewNeighbours`] for `k = 0`.
    pub fn new(points: &[[f64; 3]], k: usize) -> Result<Self, NormalsError> {
        check_points(points)?;
        let k = k.min(points.len());
        if k == 0 {
            return Err(NormalsError::TooFewNeighbours { k });
        }
        let grid = Grid::new(points, k);
        // Cell by cell: the queries of one cell share the candidates of the 3 × 3 × 3
        // block around it, gathered once; rows come out in the grid's order.
        let cells = grid.keys.len();
        let per_chunk = (cells / 64).clamp(1, CELLS_PER_CHUNK);
        let mut sorted_rows = vec![0u32; points.len() * k];
        let mut rows_left: &mut [u32] = &mut sorted_rows;
        let mut chunks: Vec<(usize, usize, &mut [u32])> = Vec::new();
        let mut cell = 0;
        while cell < cells {
            let end = (cell + per_chunk).min(cells);
            let count = (grid.starts[end] - grid.starts[cell]) as usize;
            let (mine, rest) = rows_left.split_at_mut(count * k);
            chunks.push((cell, end, mine));
            rows_left = rest;
            cell = end;
        }
        chunks.into_par_iter().for_each(|(first, end, out)| {
            let mut scratch = Scratch::default();
            let mut at = 0;
            for c in first..end {
                grid.block(c, &mut scratch);
                for s in grid.starts[c] as usize..grid.starts[c + 1] as usize {
                    grid.nearest_in_block(s, c, k, &mut scratch);
                    for (slot, &(_, i)) in out[at..at + k].iter_mut().zip(&scratch.best) {
                        *slot = i;
                    }
                    at += k;
                }
            }
        });
        // Back to the input order.
        let mut indices = vec![0u32; points.len() * k];
        indices
            .par_chunks_mut(k)
            .zip(grid.rank.par_iter())
            .for_each(|(row, &s)| {
                row.copy_from_slice(&sorted_rows[s as usize * k..(s as usize + 1) * k]);
            });
        Ok(Self { k, indices })
    }

    /// Neighbours per point.
    pub fn k(&self) -> usize {
        self.k
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.indices.len().checked_div(self.k).unwrap_or(0)
    }

    /// Whether there is no point.
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    /// The neighbours of point `i`, nearest first.
    ///
    /// # Panics
    /// If `i` is not a point index.
    #[inline]
    pub fn of(&self, i: usize) -> &[u32] {
        &self.indices[i * self.k..(i + 1) * self.k]
    }

    /// All neighbour lists, flat (`k` per point).
    pub fn as_flat(&self) -> &[u32] {
        &self.indices
    }
}

/// Cells per parallel work item at most.
const CELLS_PER_CHUNK: usize = 512;

/// Per-thread buffers of the search.
#[derive(Default)]
struct Scratch {
    /// The points of the current block: coordinates and input index.
    candidates: Vec<([f64; 3], u32)>,
    /// Squared distance and index, the `k` nearest first after a query.
    best: Vec<(f64, u32)>,
}

/// Checks that the cloud is non-empty, finite and addressable with `u32` indices.
pub(crate) fn check_points(points: &[[f64; 3]]) -> Result<(), NormalsError> {
    if points.is_empty() {
        return Err(NormalsError::Empty);
    }
    if points.len() >= u32::MAX as usize {
        return Err(NormalsError::TooManyPoints {
            points: points.len(),
        });
    }
    if let Some((index, point)) = points
        .iter()
        .enumerate()
        .find(|(_, p)| !p.iter().all(|c| c.is_finite()))
    {
        return Err(NormalsError::NonFinite {
            index,
            point: *point,
        });
    }
    Ok(())
}

/// Points sorted by cubic cell: cell `keys[c]` holds `order[starts[c]..starts[c + 1]]`.
struct Grid {
    min: [f64; 3],
    size: f64,
    keys: Vec<u64>,
    starts: Vec<u32>,
    order: Vec<u32>,
    /// The points in `order`.
    sorted: Vec<[f64; 3]>,
    /// Per input point, its position in `order`.
    rank: Vec<u32>,
    /// Cells along each axis.
    cells: [i64; 3],
}

impl Grid {
    /// A grid whose occupied cells hold about `k` points on average (cells sized for a
    /// surface sample: occupancy grows with the square of the size).
    fn new(points: &[[f64; 3]], k: usize) -> Self {
        let mut min = [f64::INFINITY; 3];
        let mut max = [f64::NEG_INFINITY; 3];
        for p in points {
            for a in 0..3 {
                min[a] = min[a].min(p[a]);
                max[a] = max[a].max(p[a]);
            }
        }
        let extent = (0..3).map(|a| max[a] - min[a]).fold(0.0, f64::max);
        let floor = extent / f64::from(1u32 << BITS) * 2.0;
        let mut size = (extent / (points.len() as f64).sqrt() * (k as f64).sqrt()).max(floor);
        if !(size.is_finite() && size > 0.0) {
            size = 1.0;
        }
        let mut grid = Self::with_size(points, min, max, size);
        // Twice: scans are denser near the sensor, and the occupancy a point sees
        // (weighted by points, Σ n² / N) is what a query pays for.
        for _ in 0..2 {
            let seen = grid
                .starts
                .windows(2)
                .map(|w| f64::from(w[1] - w[0]).powi(2))
                .sum::<f64>()
                / points.len() as f64;
            let better = (grid.size * (k as f64 / seen).sqrt()).max(floor);
            if !(better.is_finite() && better > 0.0) || (0.8..1.25).contains(&(better / grid.size))
            {
                break;
            }
            grid = Self::with_size(points, min, max, better);
        }
        grid
    }

    fn with_size(points: &[[f64; 3]], min: [f64; 3], max: [f64; 3], size: f64) -> Self {
        let cells: [i64; 3] = std::array::from_fn(|a| ((max[a] - min[a]) / size) as i64 + 1);
        let mut keyed: Vec<(u64, u32)> = points
            .par_iter()
            .enumerate()
            .map(|(i, p)| (key(cell_of(p, min, size, cells)), i as u32))
            .collect();
        keyed.par_sort_unstable();
        let mut keys = Vec::new();
        let mut starts = Vec::new();
        for (at, &(key, _)) in keyed.iter().enumerate() {
            if keys.last() != Some(&key) {
                keys.push(key);
                starts.push(at as u32);
            }
        }
        starts.push(keyed.len() as u32);
        let mut rank = vec![0u32; points.len()];
        for (at, &(_, i)) in keyed.iter().enumerate() {
            rank[i as usize] = at as u32;
        }
        Self {
            rank,
            min,
            size,
            keys,
            starts,
            sorted: keyed.iter().map(|&(_, i)| points[i as usize]).collect(),
            order: keyed.into_iter().map(|(_, i)| i).collect(),
            cells,
        }
    }

    /// The candidates of the 3 × 3 × 3 block of cells around occupied cell `c`.
    fn block(&self, c: usize, scratch: &mut Scratch) {
        scratch.candidates.clear();
        let [x, y, z] = unkey(self.keys[c]);
        for x in (x - 1).max(0)..=(x + 1).min(self.cells[0] - 1) {
            for y in (y - 1).max(0)..=(y + 1).min(self.cells[1] - 1) {
                // The column's cells z − 1 ..= z + 1 are consecutive keys.
                let low = key([x, y, (z - 1).max(0)]);
                let high = key([x, y, (z + 1).min(self.cells[2] - 1)]);
                let mut at = self.keys.partition_point(|&key| key < low);
                while at < self.keys.len() && self.keys[at] <= high {
                    let cell = self.starts[at] as usize..self.starts[at + 1] as usize;
                    scratch.candidates.extend(
                        self.sorted[cell.clone()]
                            .iter()
                            .copied()
                            .zip(self.order[cell].iter().copied()),
                    );
                    at += 1;
                }
            }
        }
    }

    /// The `k` nearest points to sorted point `s` (in occupied cell `c`, whose block's
    /// candidates `scratch` holds) into `scratch.best`, nearest first (ties: lower index).
    fn nearest_in_block(&self, s: usize, c: usize, k: usize, scratch: &mut Scratch) {
        let p = self.sorted[s];
        let best = &mut scratch.best;
        best.clear();
        for &(q, i) in &scratch.candidates {
            let d = (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2);
            keep(best, k, d, i);
        }
        // The block holds rings 0 and 1; the k best of them stay the candidates there.
        self.nearest(p, unkey(self.keys[c]), k, best, 2);
    }

    /// How far `p` lies inside its cell `c` (distance to the nearest face).
    fn margin(&self, p: [f64; 3], c: [i64; 3]) -> f64 {
        (0..3)
            .map(|a| {
                let low = self.min[a] + c[a] as f64 * self.size;
                (p[a] - low).min(low + self.size - p[a])
            })
            .fold(f64::INFINITY, f64::min)
            .max(0.0)
    }

    /// The `k` nearest points to `p` (in cell `c`) into `best` as `(squared distance,
    /// index)`, nearest first, searching ring after ring of cells from `ring` on; `best`
    /// holds the `k` nearest (or all) of the rings before, sorted.
    fn nearest(&self, p: [f64; 3], c: [i64; 3], k: usize, best: &mut Vec<(f64, u32)>, ring: i64) {
        let margin = self.margin(p, c);
        let reach = self.cells.iter().copied().max().unwrap_or(1);
        let mut ring = ring;
        loop {
            // Every point within `(ring − 1) · size` plus the margin of `p` has been seen.
            let covered = (ring - 1) as f64 * self.size + margin;
            if (best.len() == k && best[k - 1].0 <= covered * covered) || ring > reach {
                return;
            }
            self.visit_shell(c, ring, |i, q| {
                let d = (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2);
                keep(best, k, d, i);
            });
            ring += 1;
        }
    }

    /// Calls `f` (index, coordinates) on every point of the cells at Chebyshev distance `ring` from `c`.
    fn visit_shell(&self, c: [i64; 3], ring: i64, mut f: impl FnMut(u32, [f64; 3])) {
        let range = |a: usize| (c[a] - ring).max(0)..=(c[a] + ring).min(self.cells[a] - 1);
        for x in range(0) {
            for y in range(1) {
                let edge = (x - c[0]).abs() == ring || (y - c[1]).abs() == ring;
                for z in range(2) {
                    if !edge && (z - c[2]).abs() != ring {
                        continue;
                    }
                    if let Ok(at) = self.keys.binary_search(&key([x, y, z])) {
                        let cell = self.starts[at] as usize..self.starts[at + 1] as usize;
                        for (&i, &q) in self.order[cell.clone()].iter().zip(&self.sorted[cell]) {
                            f(i, q);
                        }
                    }
                }
            }
        }
    }
}

/// Puts candidate `(d, i)` into `best` (sorted by squared distance, then index; at most
/// `k`) if it is among the `k` nearest so far.
#[inline]
fn keep(best: &mut Vec<(f64, u32)>, k: usize, d: f64, i: u32) {
    let before = |e: &(f64, u32)| e.0 < d || (e.0 == d && e.1 < i);
    if best.len() == k {
        if best.last().is_none_or(before) {
            return;
        }
        best.pop();
    }
    let mut at = best.len();
    while at > 0 && !before(&best[at - 1]) {
        at -= 1;
    }
    best.insert(at, (d, i));
}

fn cell_of(p: &[f64; 3], min: [f64; 3], size: f64, cells: [i64; 3]) -> [i64; 3] {
    std::array::from_fn(|a| (((p[a] - min[a]) / size) as i64).clamp(0, cells[a] - 1))
}

fn key(c: [i64; 3]) -> u64 {
    ((c[0] as u64) << (2 * BITS)) | ((c[1] as u64) << BITS) | c[2] as u64
}

fn unkey(key: u64) -> [i64; 3] {
    let mask = (1u64 << BITS) - 1;
    [
        (key >> (2 * BITS)) as i64,
        ((key >> BITS) & mask) as i64,
        (key & mask) as i64,
    ]
}
