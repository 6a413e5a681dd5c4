//! The implicit right-cut mesh of an organized cloud. This module is the one place that
//! fixes the cell and triangle convention; every backend follows it.
//!
//! A cloud of `rows × cols` points (point `(r, c)` has index `r · cols + c`) has
//! `(rows − 1) × (cols − 1)` cells. Cell `(r, c)` has the corners
//!
//! ```text
//!   p1 = (r, c)       p2 = (r, c + 1)
//!   p4 = (r + 1, c)   p3 = (r + 1, c + 1)
//! ```
//!
//! and is cut along the diagonal p1–p3 into two triangles (Polylidar3D §4.2, Alg. 1):
//!
//! * `k = 0`, the first triangle: vertices `[p3, p2, p1]`;
//! * `k = 1`, the second triangle: vertices `[p1, p4, p3]`.
//!
//! Its slot (the paper's global id, GID) is `2 · (r · (cols − 1) + c) + k`. A triangle
//! exists only when its three points are valid (finite). Normals are
//! `(b − a) × (c − a)` for the vertex order `[a, b, c]` above, normalised, the same rule as
//! `halfedge_mesh::cross_normal`; centroids are `(a + b + c) / 3`.
//!
//! This is opc-mesh's convention too (`CellTriangle::First` is `k = 0`), so the
//! `TriangleMap` of an `OpcMesh` built from the same cloud maps slots to mesh triangles:
//! [`SlotNormals::apply_to_opc_mesh`] hands filtered normals to such a mesh, and
//! [`SlotNormals::for_triangle_map`] takes any slot → triangle map.

use std::mem::MaybeUninit;

use opc_mesh::OpcMesh;
use rayon::prelude::*;

use crate::SmoothError;

/// Triangles per cell of the implicit mesh.
pub const TRIANGLES_PER_CELL: usize = 2;

/// The sentinel of a slot → triangle map for a slot without a triangle (opc-mesh's).
pub const NO_TRIANGLE: u32 = opc_mesh::NO_TRIANGLE;

/// The slot (global id) of triangle `k ∈ {0, 1}` of cell `(r, c)` in a cloud with `cols`
/// columns.
#[inline]
pub fn slot(cols: usize, r: usize, c: usize, k: usize) -> usize {
    TRIANGLES_PER_CELL * (r * (cols - 1) + c) + k
}

/// Number of slots of the implicit mesh of a `rows × cols` cloud (0 if either is below 2).
#[inline]
pub fn num_slots(rows: usize, cols: usize) -> usize {
    TRIANGLES_PER_CELL * rows.saturating_sub(1) * cols.saturating_sub(1)
}

/// Point indices `[a, b, c]` of triangle `k ∈ {0, 1}` of cell `(r, c)` in a cloud with
/// `cols` columns, in the order that defines its normal.
#[inline]
pub fn slot_vertices(cols: usize, r: usize, c: usize, k: usize) -> [u32; 3] {
    let p1 = (r * cols + c) as u32;
    let p2 = p1 + 1;
    let p4 = p1 + cols as u32;
    let p3 = p4 + 1;
    if k == 0 { [p3, p2, p1] } else { [p1, p4, p3] }
}

/// Unit triangle normals of the implicit mesh, one per slot, as computed (`f32`) by the
/// bilateral filter. A missing triangle (a vertex is NaN) has `[NaN; 3]`.
/// `SlotNormals::default()` is empty (a 0 × 0 cloud), ready for
/// [`CpuSmoother::bilateral_into`](crate::CpuSmoother::bilateral_into).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SlotNormals {
    rows: usize,
    cols: usize,
    normals: Vec<[f32; 3]>,
}

impl SlotNormals {
    #[cfg(any(feature = "gpu", test))]
    pub(crate) fn new(rows: usize, cols: usize, normals: Vec<[f32; 3]>) -> Self {
        debug_assert_eq!(normals.len(), num_slots(rows, cols));
        Self {
            rows,
            cols,
            normals,
        }
    }

    /// Sets the shape and lets `fill` rewrite the normals in place (keeping the allocation).
    pub(crate) fn refill(
        &mut self,
        rows: usize,
        cols: usize,
        fill: impl FnOnce(&mut Vec<[f32; 3]>),
    ) {
        self.rows = rows;
        self.cols = cols;
        fill(&mut self.normals);
        debug_assert_eq!(self.normals.len(), num_slots(rows, cols));
    }

    /// Rows of the cloud the normals belong to.
    pub fn cloud_rows(&self) -> usize {
        self.rows
    }

    /// Columns of the cloud the normals belong to.
    pub fn cloud_cols(&self) -> usize {
        self.cols
    }

    /// One normal per slot, `[NaN; 3]` where the triangle is missing.
    pub fn as_slice(&self) -> &[[f32; 3]] {
        &self.normals
    }

    /// Gives the per-slot normals back.
    pub fn into_vec(self) -> Vec<[f32; 3]> {
        self.normals
    }

    /// The normal in `slot`, or `None` if that triangle is missing or `slot` is out of range.
    pub fn get(&self, slot: usize) -> Option<[f32; 3]> {
        self.normals.get(slot).copied().filter(|n| !n[0].is_nan())
    }

    /// The normal of triangle `k` of cell `(r, c)`, or `None` where it is missing or out of
    /// range.
    pub fn at(&self, r: usize, c: usize, k: usize) -> Option<[f32; 3]> {
        if r + 1 >= self.rows || c + 1 >= self.cols || k >= TRIANGLES_PER_CELL {
            return None;
        }
        self.get(slot(self.cols, r, c, k))
    }

    /// Number of slots whose triangle exists.
    pub fn num_present(&self) -> usize {
        self.normals.iter().filter(|n| !n[0].is_nan()).count()
    }

    /// Replaces the triangle normals of a mesh built from the same cloud by opc-mesh with
    /// these, through its GID → triangle map.
    ///
    /// opc-mesh also leaves out triangles whose `f64` normal is undefined (repeated or
    /// collinear points); their slots are simply not used. A mesh triangle whose `f32`
    /// normal here came out zero (area below `f32` resolution, border or isolated) gets
    /// `[0, 0, 0]`, halfedge-mesh's convention for a zero-area triangle.
    ///
    /// # Errors
    /// [`SmoothError::BadTriangleMap`] if the mesh was built from a cloud of another shape
    /// or maps a triangle this filter found missing (another cloud).
    pub fn apply_to_opc_mesh(&self, opc: &mut OpcMesh) -> Result<(), SmoothError> {
        check_shape(opc, self.rows, self.cols)?;
        let spare = spare_normals(opc);
        let map = opc.triangle_map.as_slice();
        let normals = self.normals_for_map(map, opc.mesh.num_triangles(), spare)?;
        set_mesh_normals(opc, normals)
    }

    /// Normals for `num_triangles` mesh triangles given a slot → triangle map
    /// (`triangle_map[slot]` is the mesh triangle of that slot or [`NO_TRIANGLE`]).
    ///
    /// # Errors
    /// [`SmoothError::BadTriangleMap`] if the map's length is not the number of slots, an
    /// entry is out of range, maps a missing slot, or a triangle is mapped twice or never.
    pub fn for_triangle_map(
        &self,
        triangle_map: &[u32],
        num_triangles: usize,
    ) -> Result<Vec<[f64; 3]>, SmoothError> {
        self.normals_for_map(triangle_map, num_triangles, Vec::new())
    }

    /// [`Self::for_triangle_map`] written into `buffer`'s allocation where it can be.
    fn normals_for_map(
        &self,
        triangle_map: &[u32],
        num_triangles: usize,
        buffer: Vec<[f64; 3]>,
    ) -> Result<Vec<[f64; 3]>, SmoothError> {
        if triangle_map.len() != self.normals.len() {
            return Err(SmoothError::BadTriangleMap {
                slot: triangle_map.len().min(self.normals.len()),
                reason: "the map's length is not the number of slots",
            });
        }
        if let Some(out) = self.in_slot_order(triangle_map, num_triangles, buffer) {
            return Ok(out);
        }
        let mut out = vec![[f64::NAN; 3]; num_triangles];
        let mut filled = 0usize;
        for (slot, (&t, n)) in triangle_map.iter().zip(&self.normals).enumerate() {
            if t == NO_TRIANGLE {
                continue;
            }
            let bad = |reason| Err(SmoothError::BadTriangleMap { slot, reason });
            let Some(target) = out.get_mut(t as usize) else {
                return bad("triangle index out of range");
            };
            if n[0].is_nan() {
                return bad("the slot's triangle is missing from the implicit mesh");
            }
            if !target[0].is_nan() {
                return bad("triangle mapped from two slots");
            }
            *target = to_unit_f64(*n);
            filled += 1;
        }
        if filled != num_triangles {
            return Err(SmoothError::BadTriangleMap {
                slot: triangle_map.len(),
                reason: "some mesh triangles have no slot",
            });
        }
        Ok(out)
    }
}

impl SlotNormals {
    /// [`Self::for_triangle_map`] in two parallel passes when the map numbers the
    /// triangles of present slots 0, 1, 2, … in slot order, as `opc_mesh` builds it (see
    /// [`in_slot_order`]).
    fn in_slot_order(
        &self,
        triangle_map: &[u32],
        num_triangles: usize,
        buffer: Vec<[f64; 3]>,
    ) -> Option<Vec<[f64; 3]>> {
        let gather = |(): &mut (), chunk: usize, map: &[u32], gather: &mut Gather<'_>| {
            let normals = &self.normals[chunk * SLOT_CHUNK..][..map.len()];
            for (&n, &t) in normals.iter().zip(map) {
                gather.slot(to_unit_f64(n), !n[0].is_nan(), t);
            }
        };
        in_slot_order(
            triangle_map,
            num_triangles,
            buffer,
            SLOT_CHUNK,
            || (),
            gather,
        )
    }
}

/// The unit `f64` normals of a mesh's triangles when its map numbers the triangles of
/// present slots 0, 1, 2, … in slot order, as `opc_mesh` builds it: the normals in mesh
/// order are then those of the mapped slots in slot order. `None` when the map is any
/// other, or maps a missing slot (the serial pass of [`SlotNormals::for_triangle_map`]
/// then checks it and names what is wrong).
///
/// Two parallel passes over chunks of `chunk_slots` slots: one counts each chunk's mapped
/// slots; in the other, `gather(state, chunk, map, gather)` hands [`Gather::slot`] every
/// slot of chunk `chunk` (`map` its part of the map) in order, which writes the output.
/// A task's chunks come to it in order and share its `state`, made by `init`. The
/// output reuses `buffer`'s allocation (its contents are dropped).
pub(crate) fn in_slot_order<S>(
    triangle_map: &[u32],
    num_triangles: usize,
    buffer: Vec<[f64; 3]>,
    chunk_slots: usize,
    init: impl Fn() -> S + Sync + Send,
    gather: impl Fn(&mut S, usize, &[u32], &mut Gather<'_>) + Sync + Send,
) -> Option<Vec<[f64; 3]>> {
    let counts: Vec<usize> = triangle_map
        .par_chunks(chunk_slots)
        .map(|map| map.iter().filter(|&&t| t != NO_TRIANGLE).count())
        .collect();
    if counts.iter().sum::<usize>() != num_triangles {
        return None;
    }
    // Written straight into its spare capacity, chunk by chunk, from several threads:
    // no pass that only initialises it. A reused allocation's pages are already mapped.
    let mut out = buffer;
    out.clear();
    out.reserve(num_triangles);
    let mut parts = Vec::with_capacity(counts.len());
    let (mut rest, mut first) = (&mut out.spare_capacity_mut()[..num_triangles], 0);
    for count in counts {
        let (part, tail) = rest.split_at_mut(count);
        parts.push(Gather {
            part,
            first,
            next: 0,
            valid: true,
        });
        (rest, first) = (tail, first + count);
    }
    let valid = parts
        .into_par_iter()
        .zip(triangle_map.par_chunks(chunk_slots))
        .enumerate()
        .map_init(init, |state, (chunk, (mut part, map))| {
            gather(state, chunk, map, &mut part);
            part.valid
        })
        .all(|valid| valid);
    if !valid {
        return None;
    }
    #[allow(unsafe_code)]
    // SAFETY: the parts cover the first `num_triangles` elements of the spare capacity,
    // and every part is valid: each of its mapped slots held the triangle `first + next`
    // as `next` ran from 0 to the part's count (the number of mapped slots its chunk of
    // the map has), and each such slot wrote element `next` (`Gather::slot`, or
    // `Gather::dense_cells` for a run of them). So every element is initialised.
    unsafe {
        out.set_len(num_triangles);
    }
    Some(out)
}

/// One chunk's share of [`in_slot_order`]'s output, filled slot by slot.
pub(crate) struct Gather<'a> {
    /// The unit `f64` normals of the chunk's mapped slots, in order (written as they come).
    part: &'a mut [MaybeUninit<[f64; 3]>],
    /// The triangle of the chunk's first mapped slot.
    first: usize,
    /// Mapped slots seen so far.
    next: usize,
    /// Whether every mapped slot so far is present and holds triangle `first + next`.
    valid: bool,
}

impl Gather<'_> {
    /// The chunk's next slot: its unit normal (see [`to_unit_f64`]), whether its
    /// triangle is `present`, its map entry `t`. The normal is written at `next`, which
    /// moves on when the slot is mapped; a slot mapped to anything but triangle
    /// `first + next`, or mapped but missing, makes the chunk invalid. Branch-free but for
    /// the end of the part (past its last triangle, missing slots are not written): noisy
    /// depth frames mix missing and present slots at random, where branches would mostly
    /// mispredict.
    #[inline(always)]
    pub(crate) fn slot(&mut self, unit: [f64; 3], present: bool, t: u32) {
        let mapped = t != NO_TRIANGLE;
        self.valid &= !mapped | ((t as usize == self.first + self.next) & present);
        if let Some(slot) = self.part.get_mut(self.next) {
            slot.write(unit);
        }
        self.next += usize::from(mapped);
    }

    /// [`Self::slot`] for the slots of a run of cells (two each, in slot order) when
    /// their triangles are all `present` and `map` gives them the next triangles in turn,
    /// as in the dense parts of a depth frame: `cell(i)` gives the unit normals of the
    /// run's cell `i`, which are written without the bookkeeping per slot. `false`, and
    /// nothing written, otherwise (the caller then hands the slots over one by one).
    #[inline(always)]
    pub(crate) fn dense_cells(
        &mut self,
        map: &[u32],
        present: bool,
        cell: impl Fn(usize) -> [[f64; 3]; TRIANGLES_PER_CELL],
    ) -> bool {
        let next = self.first + self.next;
        // Never a missing slot: `NO_TRIANGLE` is no triangle's index.
        let in_turn = map
            .iter()
            .enumerate()
            .fold(true, |ok, (i, &t)| ok & (t as usize == next + i));
        let end = self.next + map.len();
        let Some(part) = self
            .part
            .get_mut(self.next..end)
            .filter(|_| present & in_turn)
        else {
            return false;
        };
        for (i, pair) in part.chunks_exact_mut(TRIANGLES_PER_CELL).enumerate() {
            let units = cell(i);
            for (slot, unit) in pair.iter_mut().zip(units) {
                slot.write(unit);
            }
        }
        self.next = end;
        true
    }
}

/// The allocation of a mesh's normals, to be refilled, when the mesh has none (as
/// `opc_mesh` leaves a mesh built without normals into an earlier mesh's arrays: the
/// earlier normals' allocation, emptied); an empty vector when it has normals, which stay.
pub(crate) fn spare_normals(opc: &mut OpcMesh) -> Vec<[f64; 3]> {
    match opc.mesh.triangle_normals() {
        None => opc.mesh.take_triangle_normals(),
        Some(_) => Vec::new(),
    }
}

/// Checks that a mesh was built from a cloud of `rows × cols` points.
pub(crate) fn check_shape(opc: &OpcMesh, rows: usize, cols: usize) -> Result<(), SmoothError> {
    let map = &opc.triangle_map;
    if map.cell_rows() + 1 != rows || map.cell_cols() + 1 != cols {
        return Err(SmoothError::BadTriangleMap {
            slot: 0,
            reason: "the mesh was built from a cloud of another shape",
        });
    }
    Ok(())
}

/// Hands one normal per mesh triangle to the mesh.
pub(crate) fn set_mesh_normals(
    opc: &mut OpcMesh,
    normals: Vec<[f64; 3]>,
) -> Result<(), SmoothError> {
    opc.mesh
        .set_triangle_normals(normals)
        .map_err(|_| SmoothError::BadTriangleMap {
            slot: 0,
            reason: "the map does not cover the mesh's triangles",
        })
}

/// Slots per task of [`in_slot_order`].
pub(crate) const SLOT_CHUNK: usize = 1 << 15;

/// Normals per block of [`widen_units`].
pub(crate) const UNIT_BLOCK: usize = 256;

/// [`to_unit_f64`] of the first (at most [`UNIT_BLOCK`]) normals `(x[i], y[i], z[i])`,
/// into the x, y, z planes `out`; vectorised where the CPU allows, which a gather that
/// renormalises as it goes is not. The loop takes the series for every normal (it also
/// leaves zero normals zero) and notes whether any other needs the square root; only
/// then is the block done again normal by normal.
#[multiversion::multiversion(targets("x86_64+avx512f+avx512vl+avx512bw+avx512dq", "x86_64+avx2"))]
pub(crate) fn widen_units([x, y, z]: [&[f32]; 3], out: &mut [[f64; UNIT_BLOCK]; 3]) {
    let n = x.len().min(UNIT_BLOCK);
    let (x, y, z) = (&x[..n], &y[..n], &z[..n]);
    let [ox, oy, oz] = out;
    let mut exact = false;
    for i in 0..n {
        let v = [x[i], y[i], z[i]].map(f64::from);
        let len2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        let delta = len2 - 1.0;
        let factor = series(delta);
        [ox[i], oy[i], oz[i]] = v.map(|c| c * factor);
        exact |= (delta.abs() >= SERIES_RANGE) & (len2 > 0.0);
    }
    if exact {
        for i in 0..n {
            [ox[i], oy[i], oz[i]] = to_unit_f64([x[i], y[i], z[i]]);
        }
    }
}

/// How far from 1 the squared length of a normal that [`to_unit_f64`] renormalises by its
/// series may be.
const SERIES_RANGE: f64 = 1e-4;

/// Widens a unit `f32` normal and renormalises it in `f64` (zero stays zero). This runs
/// for every triangle: for a normal of squared length `1 + δ` within 1e-4 of 1 (every
/// filtered normal; `f32` rounding leaves δ near 1e-7), the factor `1/√(1 + δ)` is its
/// series `1 − δ/2 + 3δ²/8`, whose error (below δ³/3, about 1e-22) lies far under the
/// `f64` rounding, with neither square root nor division.
#[inline(always)]
fn to_unit_f64(n: [f32; 3]) -> [f64; 3] {
    let v = n.map(f64::from);
    let len2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    let delta = len2 - 1.0;
    let factor = if delta.abs() < SERIES_RANGE {
        series(delta)
    } else if len2 > 0.0 {
        1.0 / len2.sqrt()
    } else {
        1.0
    };
    v.map(|x| x * factor)
}

/// `1/√(1 + δ)` to second order, `1 − δ/2 + 3δ²/8` (see [`to_unit_f64`]).
#[inline(always)]
fn series(delta: f64) -> f64 {
    1.0 - delta * (0.5 - 0.375 * delta)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slots_follow_the_paper_gid() {
        // 7 × 7 cloud (Fig. 5): GID = 2 (u (N − 1) + v) + k.
        assert_eq!(slot(7, 0, 0, 0), 0);
        assert_eq!(slot(7, 0, 0, 1), 1);
        assert_eq!(slot(7, 1, 2, 1), 2 * (6 + 2) + 1);
        assert_eq!(num_slots(7, 7), 72);
        assert_eq!(num_slots(1, 7), 0);
    }

    #[test]
    fn triangles_share_the_p1_p3_diagonal() {
        let [a0, b0, c0] = slot_vertices(4, 1, 2, 0);
        let [a1, b1, c1] = slot_vertices(4, 1, 2, 1);
        assert_eq!([a0, b0, c0], [11, 7, 6]);
        assert_eq!([a1, b1, c1], [6, 10, 11]);
    }

    #[test]
    fn triangle_map_is_checked() {
        let nan = [f32::NAN; 3];
        let normals = SlotNormals::new(2, 2, vec![[0.0, 0.0, 2.0], nan]);
        assert_eq!(normals.num_present(), 1);
        assert_eq!(
            normals.for_triangle_map(&[0, NO_TRIANGLE], 1),
            Ok(vec![[0.0, 0.0, 1.0]])
        );
        assert!(normals.for_triangle_map(&[0], 1).is_err());
        assert!(normals.for_triangle_map(&[0, 0], 1).is_err());
        assert!(normals.for_triangle_map(&[3, NO_TRIANGLE], 1).is_err());
        assert!(
            normals
                .for_triangle_map(&[NO_TRIANGLE, NO_TRIANGLE], 1)
                .is_err()
        );
        assert_eq!(normals.at(0, 0, 0), Some([0.0, 0.0, 2.0]));
        assert_eq!(normals.at(0, 0, 1), None);
        assert_eq!(normals.at(1, 0, 0), None);
    }

    /// Slot by slot, as the map says: the definition the parallel pass must match.
    fn reference(normals: &SlotNormals, map: &[u32], n: usize) -> Vec<[f64; 3]> {
        let mut out = vec![[f64::NAN; 3]; n];
        for (&t, v) in map.iter().zip(normals.as_slice()) {
            if t != NO_TRIANGLE {
                out[t as usize] = to_unit_f64(*v);
            }
        }
        out
    }

    /// Blocks of unit, zero and NaN normals take the vectorised series; one normal far
    /// from unit length sends its block to the square root. Either way the bits are those
    /// of `to_unit_f64` normal by normal.
    #[test]
    fn widened_blocks_match_one_by_one() {
        let unit = [0.6f32, 0.0, -0.8];
        for odd in [None, Some([3.0f32, 0.0, -4.0]), Some([1e-3, 0.0, 0.0])] {
            let mut normals = vec![unit, [0.0; 3], [f32::NAN; 3], [0.0, 1.0, 0.0]];
            normals.extend(odd);
            let planes: [Vec<f32>; 3] = [0, 1, 2].map(|k| normals.iter().map(|n| n[k]).collect());
            let mut out = [[0.0; UNIT_BLOCK]; 3];
            widen_units(planes.each_ref().map(Vec::as_slice), &mut out);
            for (i, &n) in normals.iter().enumerate() {
                let got = [out[0][i], out[1][i], out[2][i]].map(f64::to_bits);
                assert_eq!(got, to_unit_f64(n).map(f64::to_bits), "{n:?} with {odd:?}");
            }
        }
    }

    /// The series for nearly unit normals gives the exact renormalisation to the last
    /// bit or two; zero stays zero, and far from unit length the exact path runs.
    #[test]
    fn widened_normals_are_unit_in_f64() {
        let exact = |n: [f32; 3]| {
            let v = n.map(f64::from);
            let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            v.map(|x| x / len)
        };
        let mut worst = 0.0f64;
        for i in 0..20_000 {
            let a = i as f32 * 0.618_034;
            let b = i as f32 * 0.013_7;
            let raw = [a.cos() * b.sin(), a.sin() * b.sin(), b.cos()];
            let len = (raw[0] * raw[0] + raw[1] * raw[1] + raw[2] * raw[2]).sqrt();
            let n = raw.map(|x| x / len);
            let got = to_unit_f64(n);
            for (g, w) in got.iter().zip(exact(n)) {
                worst = worst.max((g - w).abs());
            }
            let len2: f64 = got.iter().map(|x| x * x).sum();
            assert!((len2 - 1.0).abs() < 4.0 * f64::EPSILON, "{n:?}");
        }
        assert!(worst <= 2.0 * f64::EPSILON, "worst difference {worst}");
        assert_eq!(to_unit_f64([0.0; 3]), [0.0; 3]);
        let far = to_unit_f64([3.0, 0.0, -4.0]);
        for (g, w) in far.iter().zip([0.6, 0.0, -0.8]) {
            assert!((g - w).abs() <= 2.0 * f64::EPSILON, "{far:?}");
        }
    }

    #[test]
    fn maps_in_slot_order_and_others_give_the_same_normals() {
        // Three chunks and a bit, every fifth slot missing, a missing stretch across a
        // chunk boundary.
        let (rows, cols) = (3, 3 * SLOT_CHUNK / 4 + 5);
        let slots = num_slots(rows, cols);
        let present = |i: usize| i % 5 != 3 && !(SLOT_CHUNK - 9..SLOT_CHUNK + 4).contains(&i);
        let values: Vec<[f32; 3]> = (0..slots)
            .map(|i| match present(i) {
                true => [i as f32, 1.0, -2.0],
                false => [f32::NAN; 3],
            })
            .collect();
        let normals = SlotNormals::new(rows, cols, values);
        let mut next = 0u32;
        let in_order: Vec<u32> = (0..slots)
            .map(|i| match present(i) {
                true => {
                    next += 1;
                    next - 1
                }
                false => NO_TRIANGLE,
            })
            .collect();
        let n = next as usize;
        let want = reference(&normals, &in_order, n);
        assert_eq!(
            normals.in_slot_order(&in_order, n, Vec::new()).as_ref(),
            Some(&want)
        );
        // A reused allocation, longer or shorter, with stale contents: the same normals.
        for stale in [n + 3, n / 2] {
            let buffer = vec![[7.0; 3]; stale];
            assert_eq!(
                normals.in_slot_order(&in_order, n, buffer).as_ref(),
                Some(&want)
            );
        }
        assert_eq!(normals.for_triangle_map(&in_order, n), Ok(want));
        // Triangles numbered backwards: the serial pass.
        let backwards: Vec<u32> = in_order
            .iter()
            .map(|&t| if t == NO_TRIANGLE { t } else { next - 1 - t })
            .collect();
        assert!(normals.in_slot_order(&backwards, n, Vec::new()).is_none());
        assert_eq!(
            normals.for_triangle_map(&backwards, n),
            Ok(reference(&normals, &backwards, n))
        );
        // A number skipped in the second chunk, one too many triangles, a missing slot
        // mapped: errors.
        let mut gap = in_order.clone();
        for t in gap[SLOT_CHUNK + 10..]
            .iter_mut()
            .filter(|t| **t != NO_TRIANGLE)
        {
            *t += 1;
        }
        assert!(normals.for_triangle_map(&gap, n).is_err());
        assert!(normals.for_triangle_map(&in_order, n + 1).is_err());
        let mut missing = in_order.clone();
        missing[SLOT_CHUNK] = next;
        assert!(normals.for_triangle_map(&missing, n + 1).is_err());
    }
}
