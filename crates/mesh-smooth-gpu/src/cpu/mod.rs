//! The CPU backends: single-threaded and rayon, sharing one row kernel each so that both
//! give bit-identical results.
//!
//! Data live in flat `f32` planes (structure of arrays): invalid points are stored as zero
//! with a validity mask of 0.0 (1.0 when valid), so the inner loops are branch-free,
//! multiply weights by the mask instead of skipping, and vectorise. Adding an exact zero
//! does not change a sum, so masking gives the same numbers as skipping.

mod bilateral;
mod fast_exp;
mod laplacian;

pub use smoother::{CpuSmoother, Smoothed, SmoothedPlanes};

pub(crate) use fast_exp::exp2_nonpositive;

mod smoother;

use rayon::prelude::*;

/// `a · b + c` rounded once. The bilateral filter's kernels are compiled for CPUs with
/// fused multiply-add, where this is one instruction that does the work of two; elsewhere
/// it is a library call, slower but giving the same bits, so results never depend on the
/// CPU.
#[inline(always)]
pub(crate) fn fma(a: f32, b: f32, c: f32) -> f32 {
    a.mul_add(b, c)
}

/// Rows (or bands of rows) per rayon task at least; the Cpu backend uses one task for
/// everything.
pub(crate) fn min_rows_per_task(parallel: bool) -> usize {
    if parallel { 2 } else { usize::MAX }
}

/// A neighbour's offset in a square kernel, and where the weight it shares with the
/// centre is kept when each pair's weight is computed once (see [`Offsets`]).
#[derive(Clone, Copy)]
pub(crate) struct Neighbour {
    /// Row and column offsets.
    pub dr: isize,
    pub dc: isize,
    /// Index of the forward offset `±(dr, dc)` in [`Offsets::forward`].
    pub pair: usize,
    /// Whether `(dr, dc)` itself is forward: the pair's weight sits at the centre;
    /// otherwise at the neighbour (the pair seen from there points forward).
    pub forward: bool,
}

/// The offsets of a `(2 half + 1)²` kernel. A filter whose pair weights are symmetric
/// computes them once, for the forward offsets of each point, and finds a backward
/// neighbour's weight at that neighbour.
pub(crate) struct Offsets {
    /// The kernel's half-width.
    pub half: usize,
    /// Offsets later in raster order than `(0, 0)`, in raster order.
    pub forward: Vec<(usize, isize)>,
    /// All offsets but `(0, 0)`, in raster order: the order of the sums.
    pub neighbours: Vec<Neighbour>,
}

impl Offsets {
    /// The offsets of the kernel of half-width `half`.
    pub fn new(half: usize) -> Self {
        let h = half as isize;
        let forward: Vec<(usize, isize)> = (0..=h)
            .flat_map(|dr| (-h..=h).map(move |dc| (dr, dc)))
            .filter(|&(dr, dc)| dr > 0 || dc > 0)
            .map(|(dr, dc)| (dr as usize, dc))
            .collect();
        let neighbours = (-h..=h)
            .flat_map(|dr| (-h..=h).map(move |dc| (dr, dc)))
            .filter(|&offset| offset != (0, 0))
            .map(|(dr, dc)| {
                let is_forward = dr > 0 || (dr == 0 && dc > 0);
                let (fr, fc) = if is_forward { (dr, dc) } else { (-dr, -dc) };
                let pair = forward
                    .iter()
                    .position(|&o| o == (fr as usize, fc))
                    .unwrap_or_default();
                Neighbour {
                    dr,
                    dc,
                    pair,
                    forward: is_forward,
                }
            })
            .collect();
        Self {
            half,
            forward,
            neighbours,
        }
    }

    /// Whether the filter shares pair weights through a ring: up to kernel 7, whose sums
    /// keep their terms (at most 96) in an array and whose ring holds at most 4 rows.
    /// Larger kernels compute each weight where it is used.
    pub fn shares_pairs(&self) -> bool {
        self.half <= 3
    }

    /// The rows above a band whose pair weights the band reads: `half` when shared.
    pub fn above(&self) -> usize {
        if self.shares_pairs() { self.half } else { 0 }
    }

    /// Rows of a ring: at least `half + 1`, a power of two so that a row's place in it
    /// is a mask ([`Self::ring_slot`]) and not a division, of which the row kernels took
    /// up to 36 per row (the bilateral stage took 1–2 % longer with them at 424 × 240).
    fn ring_rows(&self) -> usize {
        (self.half + 1).next_power_of_two()
    }

    /// Where row `r`'s weights sit in a ring: which of its [`Self::ring_rows`] rows.
    #[inline(always)]
    pub fn ring_slot(&self, r: usize) -> usize {
        r & (self.ring_rows() - 1)
    }

    /// A ring of [`Self::ring_rows`] rows of `per_row` weights (none without sharing).
    pub fn ring(&self, per_row: usize) -> Ring {
        Ring::new(if self.shares_pairs() {
            self.ring_rows() * per_row
        } else {
            0
        })
    }
}

/// A band kernel's ring of pair weights (at least the last `half + 1` rows' worth), and
/// where the band that filled it last ended: a band starting there finds the rows above
/// it in place and skips recomputing them. Rayon hands a task its bands in order, so only
/// a task's first band computes the rows above it.
pub(crate) struct Ring {
    pub values: Vec<f32>,
    /// The row after the last band's; `usize::MAX` before any band.
    next: usize,
}

/// The rows a band kernel runs: it computes the pair weights of the rows from `start`
/// on and writes the rows from `first` on.
#[derive(Clone, Copy)]
pub(crate) struct Band {
    pub start: usize,
    pub first: usize,
}

impl Ring {
    /// A ring of `len` weights, continuing no band.
    pub fn new(len: usize) -> Self {
        Self {
            values: vec![0.0; len],
            next: usize::MAX,
        }
    }

    /// The rows of the band `first..last` of a kernel that needs the pair weights of the
    /// `above` rows over a band: none when this ring continues the band above.
    pub fn band(&mut self, first: usize, last: usize, above: usize) -> Band {
        let start = if self.next == first {
            first
        } else {
            first.saturating_sub(above)
        };
        self.next = last;
        Band { start, first }
    }
}

/// Writes a row of `len` cells' sums into the `S` planes `out` (each `len` long) in blocks
/// of `N` cells, `block(at)` giving the sums of cells `at..at + N`. A row that does not
/// end on a block boundary ends with a block that overlaps the one before (the same
/// bits where they overlap); a row shorter than a block goes cell by cell (`cell(i)`).
#[inline(always)]
pub(crate) fn row_in_blocks<const S: usize, const N: usize>(
    len: usize,
    out: &mut [&mut [f32]; S],
    block: impl Fn(usize) -> [[f32; N]; S],
    cell: impl Fn(usize) -> [[f32; 1]; S],
) {
    if len < N {
        for i in 0..len {
            for (o, [value]) in out.iter_mut().zip(cell(i)) {
                o[i] = value;
            }
        }
        return;
    }
    let mut at = 0;
    loop {
        let start = at.min(len - N);
        for (o, values) in out.iter_mut().zip(block(start)) {
            o[start..start + N].copy_from_slice(&values);
        }
        at += N;
        if at >= len {
            break;
        }
    }
}

/// The `N` values from `at` on of each of a term's five slices (written out: a closure
/// mapped over the array can stay out of line, without the kernel's target features).
#[inline(always)]
pub(crate) fn term_at<'a, const N: usize>(term: &[&'a [f32]; 5], at: usize) -> [&'a [f32]; 5] {
    let [a, b, c, d, e] = *term;
    [
        span(a, at, N),
        span(b, at, N),
        span(c, at, N),
        span(d, at, N),
        span(e, at, N),
    ]
}

/// `plane[start..start + len]`.
#[inline(always)]
pub(crate) fn span(plane: &[f32], start: usize, len: usize) -> &[f32] {
    &plane[start..start + len]
}

/// An organized cloud as `f32` planes with a validity mask, reused across calls.
#[derive(Default)]
pub(crate) struct Planes {
    pub x: Vec<f32>,
    pub y: Vec<f32>,
    pub z: Vec<f32>,
    /// 1.0 for a valid point, 0.0 for an invalid one (whose coordinates are stored as 0).
    pub m: Vec<f32>,
}

impl Planes {
    /// Fills the planes from `points` (rows of `cols`), rounding to `f32`; keeps the
    /// allocations of earlier calls.
    pub fn fill(&mut self, points: &[[f64; 3]], cols: usize, parallel: bool) {
        let n = points.len();
        for plane in [&mut self.x, &mut self.y, &mut self.z, &mut self.m] {
            plane.resize(n, 0.0);
        }
        fill_planes(
            points,
            cols,
            parallel,
            [&mut self.x, &mut self.y, &mut self.z, &mut self.m],
        );
    }
}

/// Writes `points` (rows of `cols`) into x, y, z planes rounded to `f32` and a validity
/// mask (see [`Planes`]); each plane has one entry per point. Returns the valid points.
pub(crate) fn fill_planes(
    points: &[[f64; 3]],
    cols: usize,
    parallel: bool,
    [x, y, z, m]: [&mut [f32]; 4],
) -> usize {
    (
        x.par_chunks_mut(cols),
        y.par_chunks_mut(cols),
        z.par_chunks_mut(cols),
        m.par_chunks_mut(cols),
        points.par_chunks(cols),
    )
        .into_par_iter()
        .with_min_len(min_rows_per_task(parallel))
        .map(|(x, y, z, m, row)| fill_row(row, [x, y, z, m]))
        .sum()
}

/// One row of [`fill_planes`], returning its valid points; vectorised where the CPU
/// allows.
#[multiversion::multiversion(targets("x86_64+avx512f+avx512vl+avx512bw+avx512dq", "x86_64+avx2"))]
fn fill_row(row: &[[f64; 3]], [x, y, z, m]: [&mut [f32]; 4]) -> usize {
    let len = row.len();
    let (x, y, z, m) = (&mut x[..len], &mut y[..len], &mut z[..len], &mut m[..len]);
    let mut valid_points = 0;
    for (i, p) in row.iter().enumerate() {
        // `opc_mesh::is_valid` written out: called across the crate boundary, it leaves
        // this loop scalar.
        let valid = p[0].is_finite() & p[1].is_finite() & p[2].is_finite();
        x[i] = if valid { p[0] as f32 } else { 0.0 };
        y[i] = if valid { p[1] as f32 } else { 0.0 };
        z[i] = if valid { p[2] as f32 } else { 0.0 };
        m[i] = if valid { 1.0 } else { 0.0 };
        valid_points += usize::from(valid);
    }
    valid_points
}

/// `N` planes of equal length in one allocation, laid out so that their starts differ
/// modulo 4 KiB: plane `k` starts `(FIRST + k)` · 256 bytes past a page multiple of the
/// allocation's start.
///
/// A row kernel streams through all its planes at the same index at once. Planes
/// allocated separately often start at the same offset modulo a large power of two
/// (allocators hand out big blocks page- or segment-aligned), so those streams compete
/// for the same cache sets (the crate README gives what that cost the Laplacian filter).
/// Sets that a kernel reads together take different `FIRST` slots, so that their planes
/// do not meet either when their allocations are aligned alike.
#[derive(Debug, Default)]
pub(crate) struct PlaneSet<const N: usize, const FIRST: usize = 0> {
    data: Vec<f32>,
    len: usize,
}

/// The stagger between consecutive planes of a [`PlaneSet`], in `f32`s (256 bytes).
const STAGGER: usize = 64;

impl<const N: usize, const FIRST: usize> PlaneSet<N, FIRST> {
    /// Distance between plane starts: `len` rounded up to a 4 KiB multiple, plus the
    /// stagger.
    fn stride(len: usize) -> usize {
        len.next_multiple_of(1024) + STAGGER
    }

    /// Where the first plane starts.
    const LEAD: usize = FIRST * STAGGER;

    /// Makes every plane `len` long, keeping the allocation when it is large enough
    /// (contents are overwritten by the caller).
    pub fn resize(&mut self, len: usize) {
        self.data.resize(Self::LEAD + N * Self::stride(len), 0.0);
        self.len = len;
    }

    /// The planes, each `len` long.
    pub fn planes_mut(&mut self) -> [&mut [f32]; N] {
        // `resize` allocated the lead and N strides (nothing before the first call).
        let (stride, len) = (self.stride_now(), self.len);
        let mut rest: &mut [f32] = self.data.get_mut(Self::LEAD..).unwrap_or_default();
        std::array::from_fn(|_| {
            let (plane, tail) = std::mem::take(&mut rest).split_at_mut(stride);
            rest = tail;
            &mut plane[..len]
        })
    }

    /// The planes, each `len` long.
    pub fn planes(&self) -> [&[f32]; N] {
        let (stride, len) = (self.stride_now(), self.len);
        let data = self.data.get(Self::LEAD..).unwrap_or_default();
        std::array::from_fn(|k| &data[k * stride..][..len])
    }

    /// The stride of the current allocation (0 before the first `resize`).
    fn stride_now(&self) -> usize {
        self.data.len().saturating_sub(Self::LEAD) / N
    }
}

#[cfg(test)]
mod tests {
    use super::PlaneSet;

    #[test]
    fn plane_set_planes_are_disjoint_and_start_on_different_cache_sets() {
        assert!(
            PlaneSet::<8>::default()
                .planes_mut()
                .iter()
                .all(|p| p.is_empty())
        );
        let mut set = PlaneSet::<8>::default();
        for len in [1 << 20, 0, 1, 1000, 1024, 4096, 250_000] {
            set.resize(len);
            let planes = set.planes_mut();
            let starts: Vec<usize> = planes.iter().map(|p| p.as_ptr() as usize).collect();
            for (k, plane) in planes.into_iter().enumerate() {
                assert_eq!(plane.len(), len);
                plane.fill(k as f32);
            }
            let planes = set.planes_mut();
            for (k, plane) in planes.iter().enumerate() {
                assert!(
                    plane.iter().all(|&v| v == k as f32),
                    "planes overlap at len {len}"
                );
            }
            let mut offsets: Vec<usize> = starts.iter().map(|s| (s - starts[0]) % 4096).collect();
            offsets.sort_unstable();
            offsets.dedup();
            assert_eq!(offsets.len(), 8, "len {len}: starts {starts:x?}");
        }
    }

    #[test]
    fn plane_sets_with_a_first_slot_start_past_it() {
        let mut set = PlaneSet::<3, 5>::default();
        assert!(set.planes().iter().all(|p| p.is_empty()));
        for len in [1000, 5000, 10] {
            set.resize(len);
            for (k, plane) in set.planes_mut().into_iter().enumerate() {
                plane.fill(k as f32 + 1.0);
            }
            let planes = set.planes();
            let base = set.data.as_ptr() as usize;
            for (k, plane) in planes.iter().enumerate() {
                assert_eq!(plane.len(), len);
                assert!(plane.iter().all(|&v| v == k as f32 + 1.0));
                let offset = (plane.as_ptr() as usize - base) % 4096;
                assert_eq!(offset, (5 + k) * 256, "len {len}, plane {k}");
            }
        }
    }
}
