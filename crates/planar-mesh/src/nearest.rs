//! Exact nearest-point queries in the plane for the texture (Alg. 1): the points bucketed
//! in a uniform grid of about two points per cell, searched in the 3 × 3 cells around the
//! query's cell, then ring by ring, until no unvisited cell can hold a nearer point. Building is a counting sort
//! (linear), a query visits a few cells and allocates nothing.

/// Points bucketed by grid cell. Ties are broken towards the smaller point index, so the
/// answer does not depend on the bucketing.
pub(crate) struct PointGrid {
    origin: [f64; 2],
    cell: f64,
    inv_cell: f64,
    cols: usize,
    rows: usize,
    /// Points of cell `c` (row-major) are `sorted[starts[c]..starts[c + 1]]`.
    starts: Vec<u32>,
    /// Point coordinates and original indices, cell after cell.
    sorted: Vec<([f64; 2], u32)>,
}

/// Cells per point at most (the grid is enlarged when the points are spread thin).
const MAX_CELLS_PER_POINT: usize = 4;

impl PointGrid {
    /// Buckets `points` (finite coordinates) in cells of about `per_cell` points each when
    /// they cover `area`; `None` without points.
    pub fn new(points: &[[f64; 2]], area: f64, per_cell: f64) -> Option<Self> {
        if points.is_empty() {
            return None;
        }
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        // Comparisons rather than `min` and `max`, whose NaN handling costs several
        // instructions a point (the points are finite).
        for p in points {
            for k in 0..2 {
                if p[k] < lo[k] {
                    lo[k] = p[k];
                }
                if p[k] > hi[k] {
                    hi[k] = p[k];
                }
            }
        }
        let (w, h) = (hi[0] - lo[0], hi[1] - lo[1]);
        let n = points.len();
        let mut cell = (per_cell * area.max(0.0) / n as f64).sqrt();
        // Never more than a few cells per point, and never a zero-sized cell.
        let floor = ((w * h) / (MAX_CELLS_PER_POINT * n) as f64).sqrt();
        let tiny = (w.max(h) * 1e-9).max(f64::MIN_POSITIVE);
        let cap = MAX_CELLS_PER_POINT * n;
        cell = cell.max(floor).max(tiny).max(w.max(h) / cap as f64);
        if !cell.is_finite() {
            cell = w.max(h).max(1.0);
        }
        let inv_cell = 1.0 / cell;
        let count = |span: f64| ((span * inv_cell) as usize).saturating_add(1);
        // At most `cap + 1` cells per axis (points past the last cell join it).
        let (cols, rows) = (count(w).min(cap + 1), count(h).min(cap + 1));
        let mut grid = Self {
            origin: lo,
            cell,
            inv_cell,
            cols,
            rows,
            starts: vec![0; cols * rows + 1],
            sorted: Vec::with_capacity(n),
        };
        let cells: Vec<u32> = points.iter().map(|p| grid.cell_of(*p) as u32).collect();
        for &c in &cells {
            grid.starts[c as usize + 1] += 1;
        }
        for c in 0..cols * rows {
            grid.starts[c + 1] += grid.starts[c];
        }
        let mut fill = grid.starts.clone();
        grid.sorted.resize(n, ([0.0; 2], 0));
        for (k, (&c, p)) in cells.iter().zip(points).enumerate() {
            let slot = &mut fill[c as usize];
            grid.sorted[*slot as usize] = (*p, k as u32);
            *slot += 1;
        }
        Some(grid)
    }

    /// `(col, row)` of the cell holding `p`, clamped to the grid.
    #[inline]
    fn col_row(&self, p: [f64; 2]) -> (usize, usize) {
        // `as` saturates: below the origin is column or row 0.
        let c = ((p[0] - self.origin[0]) * self.inv_cell) as usize;
        let r = ((p[1] - self.origin[1]) * self.inv_cell) as usize;
        (c.min(self.cols - 1), r.min(self.rows - 1))
    }

    #[inline]
    fn cell_of(&self, p: [f64; 2]) -> usize {
        let (c, r) = self.col_row(p);
        r * self.cols + c
    }

    /// Updates `best` (squared distance, index) with the points of cells `c_lo..=c_hi` of
    /// row `r`, which lie one after the other in `sorted`.
    #[inline]
    fn scan(&self, r: usize, c_lo: usize, c_hi: usize, q: [f64; 2], best: &mut (f64, u32)) {
        let row = r * self.cols;
        let range = self.starts[row + c_lo] as usize..self.starts[row + c_hi + 1] as usize;
        for &(p, k) in &self.sorted[range] {
            let (dx, dy) = (p[0] - q[0], p[1] - q[1]);
            let d = dx * dx + dy * dy;
            if d < best.0 || (d == best.0 && k < best.1) {
                *best = (d, k);
            }
        }
    }

    /// The index of the point nearest to `q` (the smallest index among equally near ones).
    pub fn nearest(&self, q: [f64; 2]) -> u32 {
        let (c0, r0) = self.col_row(q);
        let mut best = (f64::INFINITY, u32::MAX);
        // A hair of slack: a point's cell comes from rounded arithmetic.
        let slack = self.cell * 1e-9;
        // The 3 × 3 cells around the query first (three runs of `sorted`), then ring after
        // ring around them.
        for ring in 1usize.. {
            let (c_lo, c_hi) = (c0.checked_sub(ring), c0 + ring);
            let (r_lo, r_hi) = (r0.checked_sub(ring), r0 + ring);
            let (cs_lo, cs_hi) = (c_lo.unwrap_or(0), c_hi.min(self.cols - 1));
            if ring == 1 {
                for r in r_lo.unwrap_or(0)..=r_hi.min(self.rows - 1) {
                    self.scan(r, cs_lo, cs_hi, q, &mut best);
                }
            } else {
                // Bottom and top rows of the ring, then its left and right columns.
                for r in [r_lo, (r_hi < self.rows).then_some(r_hi)]
                    .into_iter()
                    .flatten()
                {
                    self.scan(r, cs_lo, cs_hi, q, &mut best);
                }
                let rs = r_lo.map_or(0, |r| r + 1)..r_hi.min(self.rows);
                for c in [c_lo, (c_hi < self.cols).then_some(c_hi)]
                    .into_iter()
                    .flatten()
                {
                    for r in rs.clone() {
                        self.scan(r, c, c, q, &mut best);
                    }
                }
            }
            // The nearest unvisited point is at least as far as the block's open sides.
            let mut bound = f64::INFINITY;
            if let Some(c) = c_lo.filter(|&c| c > 0) {
                bound = bound.min(q[0] - (self.origin[0] + c as f64 * self.cell));
            }
            if c_hi + 1 < self.cols {
                bound = bound.min(self.origin[0] + (c_hi + 1) as f64 * self.cell - q[0]);
            }
            if let Some(r) = r_lo.filter(|&r| r > 0) {
                bound = bound.min(q[1] - (self.origin[1] + r as f64 * self.cell));
            }
            if r_hi + 1 < self.rows {
                bound = bound.min(self.origin[1] + (r_hi + 1) as f64 * self.cell - q[1]);
            }
            if bound == f64::INFINITY {
                break;
            }
            let bound = bound - slack;
            if bound > 0.0 && best.0 < bound * bound {
                break;
            }
        }
        best.1
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn brute(points: &[[f64; 2]], q: [f64; 2]) -> u32 {
        let d = |p: &[f64; 2]| (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2);
        let mut best = (f64::INFINITY, u32::MAX);
        for (k, p) in points.iter().enumerate() {
            if d(p) < best.0 {
                best = (d(p), k as u32);
            }
        }
        best.1
    }

    /// A deterministic pseudo-random sequence in [0, 1).
    fn uniform(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn matches_brute_force_on_clustered_points_and_far_queries() {
        let mut s = 7;
        // A dense cluster, a sparse spread and exact duplicates (ties: smallest index).
        let mut points: Vec<[f64; 2]> = (0..400)
            .map(|_| [uniform(&mut s) * 0.1, uniform(&mut s) * 0.1])
            .collect();
        points.extend((0..100).map(|_| [uniform(&mut s) * 5.0 - 2.0, uniform(&mut s) * 3.0]));
        points.extend(points[..50].to_vec());
        for per_cell in [0.5, 2.0, 50.0] {
            let grid = PointGrid::new(&points, 2.0, per_cell).unwrap();
            for _ in 0..2000 {
                let q = [uniform(&mut s) * 9.0 - 4.0, uniform(&mut s) * 7.0 - 2.0];
                assert_eq!(grid.nearest(q), brute(&points, q), "{q:?}");
            }
            for (k, p) in points.iter().enumerate().take(60) {
                assert_eq!(grid.nearest(*p), brute(&points, *p), "point {k}");
            }
        }
    }

    #[test]
    fn ties_on_a_lattice_go_to_the_smallest_index() {
        // Queries at cell centres of a unit lattice are equally near four points.
        let points: Vec<[f64; 2]> = (0..100)
            .map(|k| [f64::from(k % 10), f64::from(k / 10)])
            .collect();
        let grid = PointGrid::new(&points, 81.0, 2.0).unwrap();
        for i in 0..9 {
            for j in 0..9 {
                let q = [f64::from(i) + 0.5, f64::from(j) + 0.5];
                assert_eq!(grid.nearest(q), brute(&points, q));
            }
        }
    }

    #[test]
    fn one_point_and_collinear_points() {
        let grid = PointGrid::new(&[[1.0, 1.0]], 0.0, 2.0).unwrap();
        assert_eq!(grid.nearest([-5.0, 3.0]), 0);
        let line: Vec<[f64; 2]> = (0..50).map(|k| [f64::from(k) * 0.1, 2.0]).collect();
        let grid = PointGrid::new(&line, 0.0, 2.0).unwrap();
        for x in [-1.0, 0.04, 2.26, 7.0] {
            assert_eq!(grid.nearest([x, 0.0]), brute(&line, [x, 0.0]));
        }
        assert!(PointGrid::new(&[], 1.0, 2.0).is_none());
    }
}
