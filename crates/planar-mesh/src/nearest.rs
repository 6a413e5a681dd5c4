//! Exact nearest-point queries in the plane for the texture (Alg. 1): the points bucketed
//! in a uniform grid, searched in the query's cell, then ring by ring of cells around it,
//! until no unvisited cell can hold a nearer point. Building is a counting sort (linear), a
//! query visits a few cells and allocates nothing.

/// Points bucketed by grid cell. Ties are broken towards the smaller point index, so the
/// answer does not depend on the bucketing.
pub(crate) struct PointGrid {
    origin: [f64; 2],
    cell: f64,
    inv_cell: f64,
    cols: u32,
    rows: u32,
    /// Points of cell `c` (row-major) are `sorted[starts[c]..starts[c + 1]]`.
    starts: Vec<u32>,
    /// Point coordinates and original indices, cell after cell.
    sorted: Vec<([f64; 2], u32)>,
}

/// Cells per point at most (the grid is enlarged when the points are spread thin).
const MAX_CELLS_PER_POINT: usize = 4;

/// Cells per axis at most, so that cell arithmetic stays in `u32`.
const MAX_CELLS_PER_AXIS: usize = 1 << 30;

impl PointGrid {
    /// Buckets `points` (finite coordinates) in cells of about `per_cell` points each when
    /// they cover `area`; `None` without points.
    pub fn new(points: &[[f64; 2]], area: f64, per_cell: f64) -> Option<Self> {
        let [lo, hi] = bounds(points)?;
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
        Some(Self::bucket(points, hi, lo, cell))
    }

    /// Buckets `points` (finite coordinates) in square cells of side `cell` whose corners
    /// lie on the lattice through `anchor`, so that a query at a cell's centre finds its
    /// answer in that cell alone more often than not. `None` without points, or when the
    /// points would need more than a few cells each.
    pub fn on_lattice(points: &[[f64; 2]], anchor: [f64; 2], cell: f64) -> Option<Self> {
        let [lo, hi] = bounds(points)?;
        if !(cell.is_finite() && cell > 0.0 && anchor.iter().all(|a| a.is_finite())) {
            return None;
        }
        // The lattice corner at the points' lower left (should rounding put it a hair
        // above, the points below join the first row or column, as any point outside).
        let origin = [0, 1].map(|k| anchor[k] + ((lo[k] - anchor[k]) / cell).floor() * cell);
        let cells = [0, 1].map(|k| (hi[k] - origin[k]) / cell + 1.0);
        if cells[0] * cells[1] > (MAX_CELLS_PER_POINT * points.len()) as f64 {
            return None;
        }
        Some(Self::bucket(points, hi, origin, cell))
    }

    /// The counting sort of `points` (up to `hi`) into cells of side `cell` from `origin`
    /// (about their lower left).
    fn bucket(points: &[[f64; 2]], hi: [f64; 2], origin: [f64; 2], cell: f64) -> Self {
        let n = points.len();
        let cap = MAX_CELLS_PER_POINT * n;
        let inv_cell = 1.0 / cell;
        let count = |k: usize| (((hi[k] - origin[k]) * inv_cell) as usize).saturating_add(1);
        // At most `cap + 1` cells per axis (points past the last cell join it).
        let axis = |k: usize| count(k).min(cap + 1).min(MAX_CELLS_PER_AXIS);
        let (cols, rows) = (axis(0), axis(1));
        let mut grid = Self {
            origin,
            cell,
            inv_cell,
            cols: cols as u32,
            rows: rows as u32,
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
        grid
    }

    /// `p` in cells from the origin.
    #[inline]
    fn in_cells(&self, p: [f64; 2]) -> [f64; 2] {
        [
            (p[0] - self.origin[0]) * self.inv_cell,
            (p[1] - self.origin[1]) * self.inv_cell,
        ]
    }

    /// `(col, row)` of the cell at `f` (in cells from the origin), clamped to the grid.
    #[inline]
    fn col_row(&self, f: [f64; 2]) -> (u32, u32) {
        // `as` saturates: below the origin (or NaN) is column or row 0. Into `u32`, which
        // costs a few instructions where `usize` costs a dozen.
        (
            (f[0] as u32).min(self.cols - 1),
            (f[1] as u32).min(self.rows - 1),
        )
    }

    #[inline]
    fn cell_of(&self, p: [f64; 2]) -> usize {
        let (c, r) = self.col_row(self.in_cells(p));
        r as usize * self.cols as usize + c as usize
    }

    /// Updates `best` (squared distance, index) with the points of cells `c_lo..=c_hi` of
    /// row `r`, which lie one after the other in `sorted`.
    #[inline]
    fn scan(&self, r: u32, c_lo: u32, c_hi: u32, q: [f64; 2], best: &mut (f64, u32)) {
        let row = r as usize * self.cols as usize;
        let range = self.starts[row + c_lo as usize] as usize
            ..self.starts[row + c_hi as usize + 1] as usize;
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
        // A hair of slack, in cells: a point's cell comes from rounded arithmetic.
        const SLACK: f64 = 1e-9;
        let f = self.in_cells(q);
        let (c0, r0) = self.col_row(f);
        let mut best = (f64::INFINITY, u32::MAX);
        // The query's cell first, then ring after ring of cells around it.
        self.scan(r0, c0, c0, q, &mut best);
        for ring in 0u32.. {
            if ring > 0 {
                let (c_lo, c_hi) = (c0.checked_sub(ring), c0 + ring);
                let (r_lo, r_hi) = (r0.checked_sub(ring), r0 + ring);
                let (cs_lo, cs_hi) = (c_lo.unwrap_or(0), c_hi.min(self.cols - 1));
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
            // The nearest unvisited point is at least as far as the block's open sides
            // (those with cells beyond them); in cells.
            let (c_lo, c_hi) = (c0.saturating_sub(ring), c0 + ring);
            let (r_lo, r_hi) = (r0.saturating_sub(ring), r0 + ring);
            let mut bound = f64::INFINITY;
            if c_lo > 0 {
                bound = bound.min(f[0] - f64::from(c_lo));
            }
            if c_hi + 1 < self.cols {
                bound = bound.min(f64::from(c_hi + 1) - f[0]);
            }
            if r_lo > 0 {
                bound = bound.min(f[1] - f64::from(r_lo));
            }
            if r_hi + 1 < self.rows {
                bound = bound.min(f64::from(r_hi + 1) - f[1]);
            }
            if bound == f64::INFINITY {
                break;
            }
            let bound = (bound - SLACK) * self.cell;
            if bound > 0.0 && best.0 < bound * bound {
                break;
            }
        }
        best.1
    }
}

/// The lower-left and upper-right corners of `points`' bounding box; `None` without points.
fn bounds(points: &[[f64; 2]]) -> Option<[[f64; 2]; 2]> {
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
    Some([lo, hi])
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
    fn lattice_grids_match_brute_force_wherever_the_anchor_lies() {
        let mut s = 11;
        let mut points: Vec<[f64; 2]> = (0..3000)
            .map(|_| [uniform(&mut s) * 2.0, uniform(&mut s) * 1.5])
            .collect();
        // An outlier far from the rest and a duplicate.
        points.push([2.6, -0.4]);
        points.push(points[10]);
        // Anchors inside, below and beyond the points; cells from a few points each to
        // hundreds.
        for anchor in [[0.0, 0.0], [-1.3, 0.4], [0.7, 2.9]] {
            for cell in [0.03, 0.05, 0.3] {
                let grid = PointGrid::on_lattice(&points, anchor, cell).unwrap();
                for _ in 0..1500 {
                    let q = [uniform(&mut s) * 3.0 - 0.5, uniform(&mut s) * 2.5 - 0.5];
                    assert_eq!(
                        grid.nearest(q),
                        brute(&points, q),
                        "{anchor:?} {cell} {q:?}"
                    );
                }
                // Queries at cell centres, where a search may end in the query's cell.
                for k in 0..200 {
                    let c = f64::from(k % 20) + 0.5;
                    let r = f64::from(k / 20) + 0.5;
                    let q = [anchor[0] + c * cell, anchor[1] + r * cell];
                    assert_eq!(
                        grid.nearest(q),
                        brute(&points, q),
                        "{anchor:?} {cell} {q:?}"
                    );
                }
            }
        }
        // Cells so small that the points would need too many: no grid.
        assert!(PointGrid::on_lattice(&points, [0.0, 0.0], 1e-6).is_none());
        assert!(PointGrid::on_lattice(&[], [0.0, 0.0], 1.0).is_none());
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
