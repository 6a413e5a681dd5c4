//! The cell table: a direct-address table over the S2 cells of one level that lists, for each
//! S2 cell, every accumulator cell that can be the closest to a direction inside it.
//!
//! A query needs only the cube face and `(i, j)` of its S2 cell (no Hilbert position, model or
//! binary search; a loop over a batch vectorizes) and the dot products with the candidates:
//! four slots, or a list for the S2 cells with more (around the icosahedron's vertices, where
//! six cells meet). At level 4 the table has 24,576 entries of 8 bytes; 11 % of them have one
//! candidate, 58 % two, 18 % three or four and 12 % more.
//!
//! The candidate lists are exact supersets, built as follows for an S2 cell with centre `q`,
//! corners within angle `r` of `q`, and `c0` the cell closest to `q`, with all corners within
//! angle `f` of `c0`:
//! 1. the cell `c` closest to any `x` in the S2 cell has `∠(c, x) ≤ ∠(c0, x) ≤ f` (the angle
//!    to a point is largest at a corner of a convex spherical polygon), so `∠(c, q) ≤ f + r`;
//!    the cells within any cap around `q` that holds `c0` are connected in the 1-ring graph
//!    (from any of them, the neighbour across the Voronoi edge towards `q` is closer to `q`),
//!    so a breadth-first walk from `c0` over the 1-ring finds them all;
//! 2. a cell is dropped when another beats it at all four corners: the half-space where the
//!    other is closer is convex, and the S2 cell (bounded by great circles) is the convex hull
//!    of its corners.

use rayon::prelude::*;

use crate::icosahedron::{Icosahedron, NO_NEIGHBOR, dot};
use crate::integrate::BATCH;
use crate::s2id;
use crate::search::CellSearch;

/// Candidate cells kept in an entry; unused slots repeat the first candidate.
const SLOTS: usize = 4;

/// S2 levels finer than the icosahedron's: about two S2 cells across an accumulator cell. One
/// level more has half as many entries with more than two candidates but a table four times
/// the size, which misses the cache for as much as it saves (measured at level 4).
const LEVELS_FINER: u32 = 2;

/// The finest S2 level of a table (6·4⁸ entries, 6.3 MB with `u32` slots): at icosahedron
/// level 7 the table is coarser than [`LEVELS_FINER`] and half its entries overflow.
const MAX_TABLE_LEVEL: u32 = 8;

/// Slack subtracted from the walk's dot-product threshold against rounding in the geometry.
const DOT_MARGIN: f64 = 1e-9;

/// A cell is dropped only if another beats it by more than this at every corner.
const DOMINANCE_MARGIN: f64 = 1e-12;

/// A cell index in a table entry: `u16` while the cells fit (levels ≤ 5), which halves the
/// table's cache footprint, else `u32`.
trait Slot: Copy + Send + Sync + PartialEq {
    /// First slot of an entry whose candidates are in [`CellTable::overflow`]: the other
    /// slots hold the list's start (low and high bits) and length.
    const OVERFLOW: Self;
    /// Bits of a slot.
    const BITS: u32;
    fn get(self) -> usize;
    /// `value` truncated to the slot's width.
    fn truncated(value: u64) -> Self;
}

impl Slot for u16 {
    const OVERFLOW: Self = u16::MAX;
    const BITS: u32 = 16;
    #[inline(always)]
    fn get(self) -> usize {
        usize::from(self)
    }
    #[inline(always)]
    fn truncated(value: u64) -> Self {
        value as u16
    }
}

impl Slot for u32 {
    const OVERFLOW: Self = u32::MAX;
    const BITS: u32 = 32;
    #[inline(always)]
    fn get(self) -> usize {
        self as usize
    }
    #[inline(always)]
    fn truncated(value: u64) -> Self {
        value as u32
    }
}

/// The entries of every S2 cell, face by face, row `i` by row, column `j`.
#[derive(Debug, Clone)]
enum Entries {
    Narrow(Vec<[u16; SLOTS]>),
    Wide(Vec<[u32; SLOTS]>),
}

/// The lookup table of one icosahedron.
#[derive(Debug, Clone)]
pub(crate) struct CellTable {
    /// `2^level` S2 cells along each face edge.
    size: u32,
    entries: Entries,
    /// Candidate lists of the entries with more than [`SLOTS`] candidates.
    overflow: Vec<u32>,
    /// The icosahedron's cell normals, compact for the candidate dot products.
    normals: Vec<[f64; 3]>,
}

impl CellTable {
    /// The S2 level of the table of an icosahedron of `level`.
    fn s2_level(level: u32) -> u32 {
        (level + LEVELS_FINER).min(MAX_TABLE_LEVEL)
    }

    /// The number of entries of the table of an icosahedron of `level` (one per S2 cell).
    pub(crate) fn entry_count(level: u32) -> usize {
        6 << (2 * Self::s2_level(level))
    }

    /// Builds the table of `ico`, using `search` to find the closest cells of S2 cell centres.
    pub(crate) fn new(ico: &Icosahedron, search: &CellSearch) -> Self {
        let size = 1u32 << Self::s2_level(ico.level());
        let n = size as usize;
        let rows: Vec<RowCandidates> = (0..6 * n)
            .into_par_iter()
            .map_init(
                || Walk::new(ico.cell_count()),
                |walk, row| {
                    row_candidates(ico, search, walk, (row / n) as u8, (row % n) as u32, size)
                },
            )
            .collect();
        let mut overflow = Vec::new();
        let entries = if ico.cell_count() <= usize::from(u16::MAX) {
            Entries::Narrow(encode(&rows, &mut overflow))
        } else {
            Entries::Wide(encode(&rows, &mut overflow))
        };
        Self {
            size,
            entries,
            overflow,
            normals: ico.normals().to_vec(),
        }
    }

    /// Index of the cell whose normal is closest to `p` (non-zero, finite); ties within
    /// rounding go to the earlier candidate.
    pub(crate) fn find(&self, p: [f64; 3]) -> u32 {
        let mut cell = [0];
        self.find_batch(&[p], &mut cell);
        cell[0]
    }

    /// [`find`](Self::find) for up to [`BATCH`] normals, stage by stage: the S2 cells of the
    /// whole batch first (a loop the compiler vectorizes), then all its table loads, so that
    /// their cache misses overlap, then the candidates' dot products.
    #[inline(always)]
    pub(crate) fn find_batch(&self, batch: &[[f64; 3]], cells: &mut [u32]) {
        let n = batch.len().min(BATCH);
        let mut index = [0usize; BATCH];
        for (i, &p) in index.iter_mut().zip(&batch[..n]) {
            *i = self.entry_index(p);
        }
        match &self.entries {
            Entries::Narrow(entries) => self.resolve(entries, &index[..n], batch, cells),
            Entries::Wide(entries) => self.resolve(entries, &index[..n], batch, cells),
        }
    }

    #[inline(always)]
    fn resolve<S: Slot>(
        &self,
        entries: &[[S; SLOTS]],
        index: &[usize],
        batch: &[[f64; 3]],
        cells: &mut [u32],
    ) {
        let mut loaded = [[S::OVERFLOW; SLOTS]; BATCH];
        for (e, &i) in loaded.iter_mut().zip(index) {
            *e = entries[i];
        }
        for ((cell, entry), &p) in cells.iter_mut().zip(&loaded[..index.len()]).zip(batch) {
            *cell = if entry[0] == S::OVERFLOW {
                self.closest_overflow(entry, p)
            } else {
                self.closest(entry.map(Slot::get), p)
            };
        }
    }

    /// The candidate of `entry` closest to `p`; the earlier one on ties.
    #[inline(always)]
    fn closest(&self, entry: [usize; SLOTS], p: [f64; 3]) -> u32 {
        // A loop, not `entry.map`: that ran out of line, a call per normal.
        let mut d = [0.0; SLOTS];
        for (d, &c) in d.iter_mut().zip(&entry) {
            *d = dot(self.normals[c], p);
        }
        let mut best = entry[0];
        let mut best_dot = d[0];
        for k in 1..SLOTS {
            best = std::hint::select_unpredictable(d[k] > best_dot, entry[k], best);
            best_dot = best_dot.max(d[k]);
        }
        best as u32
    }

    /// The closest of an overflowing entry's candidate list; the earlier one on ties.
    #[cold]
    fn closest_overflow<S: Slot>(&self, entry: &[S; SLOTS], p: [f64; 3]) -> u32 {
        let start = entry[1].get() | entry[2].get() << S::BITS;
        let list = &self.overflow[start..start + entry[3].get()];
        let mut best = list[0];
        let mut best_dot = dot(self.normals[best as usize], p);
        for &c in &list[1..] {
            let d = dot(self.normals[c as usize], p);
            if d > best_dot {
                (best, best_dot) = (c, d);
            }
        }
        best
    }

    /// Position in `entries` of the S2 cell holding `p`: [`s2id::face_uv`] and
    /// [`s2id::uv_to_st`] written with selects instead of table lookups, so that a loop over
    /// a batch vectorizes.
    #[inline(always)]
    fn entry_index(&self, p: [f64; 3]) -> usize {
        let [x, y, z] = p;
        let (ax, ay, az) = (x.abs(), y.abs(), z.abs());
        // The face axis as in `s2id::face`: the largest |component|, ties to x over y over z.
        let is_y = ay > ax;
        let is_z = az > ax.max(ay);
        let w = if is_z {
            z
        } else if is_y {
            y
        } else {
            x
        };
        // Numerators of (u, v) on the positive face of the axis; the negative face swaps them.
        let a = if is_y | is_z { -x } else { y };
        let b = if is_z { -y } else { z };
        let negative = w < 0.0;
        let (u, v) = if negative {
            (b / w, a / w)
        } else {
            (a / w, b / w)
        };
        let axis = if is_z { 2 } else { usize::from(is_y) };
        let face = axis + 3 * usize::from(negative);
        let scale = f64::from(self.size);
        let last = self.size as i32 - 1;
        // s, t ≥ 0, so truncation is the floor; `min` keeps s = 1 inside. (`i32`, not `u32`:
        // SSE2 converts two doubles to `i32` at once.)
        let i = ((s2id::uv_to_st(u) * scale) as i32).min(last) as usize;
        let j = ((s2id::uv_to_st(v) * scale) as i32).min(last) as usize;
        let n = self.size as usize;
        (face * n + i) * n + j
    }
}

/// The candidate lists of one row of S2 cells, concatenated.
#[derive(Default)]
struct RowCandidates {
    cells: Vec<u32>,
    lens: Vec<u8>,
}

/// The candidates of the S2 cells of row `i` of cube face `face`.
fn row_candidates(
    ico: &Icosahedron,
    search: &CellSearch,
    walk: &mut Walk,
    face: u8,
    i: u32,
    size: u32,
) -> RowCandidates {
    let h = 1.0 / f64::from(size);
    let corner = |i: u32, j: u32| s2id::face_st_to_point(face, f64::from(i) * h, f64::from(j) * h);
    let (mut low, mut high) = (corner(i, 0), corner(i + 1, 0));
    let s = (f64::from(i) + 0.5) * h;
    let mut nearest = search.find(s2id::face_st_to_point(face, s, 0.5 * h)) as usize;
    let mut row = RowCandidates::default();
    for j in 0..size {
        let (next_low, next_high) = (corner(i, j + 1), corner(i + 1, j + 1));
        let q = s2id::face_st_to_point(face, s, (f64::from(j) + 0.5) * h);
        // The walk from the previous centre's cell is short: the centres are neighbours.
        nearest = search.descend(nearest, dot(ico.normals()[nearest], q), q) as usize;
        let kept = walk.candidates(ico, nearest, q, &[low, high, next_low, next_high]);
        row.cells.extend_from_slice(kept);
        // A cell has 12 neighbours; `kept` holds a handful of them.
        row.lens.push(kept.len() as u8);
        (low, high) = (next_low, next_high);
    }
    row
}

/// Buffers of the candidate search, reused from one S2 cell to the next.
struct Walk {
    /// Per accumulator cell, the number of the last search that reached it.
    seen: Vec<u32>,
    /// The number of the current search.
    stamp: u32,
    found: Vec<u32>,
    corner_dots: Vec<[f64; 4]>,
    kept: Vec<u32>,
}

impl Walk {
    fn new(cells: usize) -> Self {
        Self {
            seen: vec![0; cells],
            stamp: 0,
            found: Vec::new(),
            corner_dots: Vec::new(),
            kept: Vec::new(),
        }
    }

    /// The candidates of the S2 cell with centre `q` and `corners`, whose closest cell is
    /// `nearest` (see the module docs), `nearest` first.
    fn candidates(
        &mut self,
        ico: &Icosahedron,
        nearest: usize,
        q: [f64; 3],
        corners: &[[f64; 3]; 4],
    ) -> &[u32] {
        let normals = ico.normals();
        // cos r and cos f of the two angles; the reach r + f as a dot-product threshold
        // (cos(r + f), lowered by a rounding margin), or everything once r + f ≥ π.
        let cos_r = corners.iter().map(|&c| dot(c, q)).fold(1.0, f64::min);
        let cos_f = corners
            .iter()
            .map(|&c| dot(c, normals[nearest]))
            .fold(1.0, f64::min);
        let sin = |c: f64| (1.0 - c * c).max(0.0).sqrt();
        let min_dot = if cos_f <= -cos_r {
            -1.0
        } else {
            cos_f * cos_r - sin(cos_f) * sin(cos_r) - DOT_MARGIN
        };
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.seen.fill(0);
            self.stamp = 1;
        }
        self.found.clear();
        self.found.push(nearest as u32);
        self.seen[nearest] = self.stamp;
        let mut next = 0;
        while let Some(&cell) = self.found.get(next) {
            next += 1;
            for &c in &ico.neighbors()[cell as usize] {
                if c == NO_NEIGHBOR || self.seen[c as usize] == self.stamp {
                    continue;
                }
                self.seen[c as usize] = self.stamp;
                if dot(normals[c as usize], q) >= min_dot {
                    self.found.push(c);
                }
            }
        }
        self.corner_dots.clear();
        self.corner_dots.extend(
            self.found
                .iter()
                .map(|&c| corners.map(|x| dot(normals[c as usize], x))),
        );
        let dots = &self.corner_dots;
        let beaten = |a: usize| {
            (0..dots.len()).any(|b| (0..4).all(|k| dots[b][k] - dots[a][k] > DOMINANCE_MARGIN))
        };
        self.kept.clear();
        self.kept.extend(
            (0..self.found.len())
                .filter(|&a| !beaten(a))
                .map(|a| self.found[a]),
        );
        &self.kept
    }
}

/// The entries of `rows` with slots of type `S`; lists longer than [`SLOTS`] go to `overflow`.
fn encode<S: Slot>(rows: &[RowCandidates], overflow: &mut Vec<u32>) -> Vec<[S; SLOTS]> {
    let mut entries = Vec::with_capacity(rows.iter().map(|r| r.lens.len()).sum());
    for row in rows {
        let mut start = 0;
        for &len in &row.lens {
            let list = &row.cells[start..start + usize::from(len)];
            start += usize::from(len);
            if list.len() <= SLOTS {
                entries.push(std::array::from_fn(|k| {
                    S::truncated(u64::from(list[k.min(list.len() - 1)]))
                }));
            } else {
                let at = overflow.len() as u64;
                overflow.extend_from_slice(list);
                let mut entry = [S::OVERFLOW; SLOTS];
                entry[1] = S::truncated(at);
                entry[2] = S::truncated(at >> S::BITS);
                entry[3] = S::truncated(list.len() as u64);
                entries.push(entry);
            }
        }
    }
    entries
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn s2_cell_centres_and_corners_match_brute_force() {
        for level in 0..=5 {
            let ico = Icosahedron::new(level).unwrap();
            let table = CellTable::new(&ico, &CellSearch::new(&ico));
            let h = 1.0 / f64::from(table.size);
            for face in 0..6u8 {
                for i in (0..table.size).step_by(3) {
                    for j in (0..table.size).step_by(5) {
                        for (ds, dt) in [(0.5, 0.5), (1e-9, 1e-9), (0.999_999, 0.3)] {
                            let p = s2id::face_st_to_point(
                                face,
                                (f64::from(i) + ds) * h,
                                (f64::from(j) + dt) * h,
                            );
                            let found = table.find(p) as usize;
                            let best = ico.nearest_cell_brute_force(p) as usize;
                            let n = ico.normals();
                            assert!(
                                dot(n[found], p) >= dot(n[best], p) - 1e-12,
                                "level {level} face {face} ({i}, {j}): {found} vs {best}"
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn most_level_4_entries_have_at_most_four_candidates() {
        let ico = Icosahedron::new(4).unwrap();
        let table = CellTable::new(&ico, &CellSearch::new(&ico));
        let Entries::Narrow(entries) = &table.entries else {
            panic!("5,120 cells fit u16 slots");
        };
        let overflow = entries.iter().filter(|e| e[0] == u16::OVERFLOW).count();
        // 12.4 % when written: the S2 cells around the icosahedron's vertices, where six cells meet.
        assert!(
            overflow * 100 < 15 * entries.len(),
            "{overflow} of {}",
            entries.len()
        );
    }
}
