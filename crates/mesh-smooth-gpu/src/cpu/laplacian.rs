//! The Laplacian vertex filter on `f32` planes, a band of image rows per task.

use std::ops::Range;

use opc_mesh::OrganizedPointCloud;
use rayon::prelude::*;

use super::{
    Band, Offsets, PlaneSet, Ring, fill_planes, min_rows_per_task, row_in_blocks, span, term_at,
};
use crate::LaplacianOptions;

/// Reusable buffers of the Laplacian filter: the planes x, y, z, mask (see
/// [`Planes`](super::Planes)), the next pass's x, y, z, and Σ w of the last pass (> 0
/// exactly where a pixel was filtered), all read or written together by the row kernel.
#[derive(Default)]
pub(crate) struct LaplacianWork {
    planes: PlaneSet<8>,
    /// Whether the last run filtered anything, and then whether its output is in the
    /// second triple x, y, z (an odd number of passes).
    output: Option<bool>,
    /// The valid points of the cloud the last run filtered.
    valid_points: usize,
    /// With per-pixel pass counts, the largest count of each block of [`SKIP_COLUMNS`]
    /// columns of each row (see [`Limits`]).
    block_limits: Vec<u8>,
}

impl LaplacianWork {
    /// Whether the last run filtered anything, and then whether the planes of the cloud it
    /// output are those with the `second` triple x, y, z ([`Self::planes_at`]).
    pub(crate) fn output(&self) -> Option<bool> {
        self.output
    }

    /// The valid points of the cloud the last run filtered (counted as it was read),
    /// when it filtered anything ([`Self::output`]).
    pub(crate) fn valid_points(&self) -> usize {
        self.valid_points
    }

    /// The point planes x, y, z and mask (see [`Planes`](super::Planes)) with the first
    /// or the `second` triple. Those of the last run's [`Self::output`] are bit for bit
    /// the planes [`Planes::fill`](super::Planes::fill) makes of the cloud it output: the
    /// filtered points were widened from them, and every other point was rounded into
    /// them and kept.
    pub(crate) fn planes_at(&self, second: bool) -> [&[f32]; 4] {
        let [x, y, z, m, nx, ny, nz, _] = self.planes.planes();
        if second {
            [nx, ny, nz, m]
        } else {
            [x, y, z, m]
        }
    }
}

/// How many passes each pixel takes part in: all of them, or pixel `i` only in the first
/// `passes[i]` (one entry per point; afterwards it keeps its value and still serves as a
/// neighbour).
#[derive(Clone, Copy)]
pub(crate) enum Passes<'a> {
    Uniform(u32),
    PerPixel(&'a [u8]),
}

/// Filters `cloud` in place on the CPU (`parallel`: over the rayon pool). Options are
/// validated; `options.iterations` is replaced by `passes`, whose per-pixel counts have
/// one entry per point.
pub(crate) fn laplacian_in_place(
    work: &mut LaplacianWork,
    cloud: &mut OrganizedPointCloud,
    options: &LaplacianOptions,
    passes: Passes<'_>,
    parallel: bool,
) {
    let Some(filtered) = filter(work, cloud, options, passes, parallel) else {
        return;
    };
    let cols = cloud.cols();
    cloud
        .points_mut()
        .par_chunks_mut(cols)
        .enumerate()
        .with_min_len(min_rows_per_task(parallel))
        .for_each(|(r, points)| {
            for (p, (q, moved)) in points.iter_mut().zip(filtered.row(r, cols)) {
                if moved {
                    *p = q;
                }
            }
        });
}

/// The filtered copy of `cloud`, as [`laplacian_in_place`] would leave it, written in one
/// pass (the filtered points from the planes, the others from `cloud`) into `out`'s
/// storage (its points are dropped).
pub(crate) fn laplacian_copy(
    work: &mut LaplacianWork,
    cloud: &OrganizedPointCloud,
    options: &LaplacianOptions,
    passes: Passes<'_>,
    parallel: bool,
    mut out: Vec<[f64; 3]>,
) -> Vec<[f64; 3]> {
    let (source, cols) = (cloud.points(), cloud.cols());
    out.clear();
    out.reserve(source.len());
    let Some(filtered) = filter(work, cloud, options, passes, parallel) else {
        out.extend_from_slice(source);
        return out;
    };
    // Written straight into the spare capacity, row by row from several threads, with
    // no pass that only initialises it. A kept point is read only where the filter left
    // it (a branch: a bit-by-bit choice, which reads every one, is slower).
    out.spare_capacity_mut()[..source.len()]
        .par_chunks_mut(cols)
        .zip(source.par_chunks(cols))
        .enumerate()
        .with_min_len(min_rows_per_task(parallel))
        .for_each(|(r, (slots, kept))| {
            for ((slot, &p), (q, moved)) in slots.iter_mut().zip(kept).zip(filtered.row(r, cols)) {
                slot.write(if moved { q } else { p });
            }
        });
    #[allow(unsafe_code)]
    // SAFETY: the rows cover the first `source.len()` elements of the spare capacity
    // (`source` is `rows × cols` points), and every element of every row was written.
    unsafe {
        out.set_len(source.len());
    }
    out
}

/// The filtered points where [`filter`] left them: its last pass's planes.
struct Filtered<'a> {
    x: &'a [f32],
    y: &'a [f32],
    z: &'a [f32],
    /// Σ w of the last pass, > 0 exactly where a pixel was filtered.
    weight_sums: &'a [f32],
}

impl Filtered<'_> {
    /// The points of row `r` (of `cols`) widened, each with whether the filter moved it
    /// (where it did not, the caller keeps the point it had).
    #[inline]
    fn row(&self, r: usize, cols: usize) -> impl Iterator<Item = ([f64; 3], bool)> + '_ {
        let span = r * cols..(r + 1) * cols;
        let (x, y, z) = (
            &self.x[span.clone()],
            &self.y[span.clone()],
            &self.z[span.clone()],
        );
        let w = &self.weight_sums[span];
        x.iter()
            .zip(y)
            .zip(z)
            .zip(w)
            .map(|(((&x, &y), &z), &w)| ([x, y, z].map(f64::from), w > 0.0))
    }
}

/// Runs the passes on `cloud`'s points in `work`'s planes; `None` where nothing is
/// filtered (no pass, or a grid within the kernel).
fn filter<'a>(
    work: &'a mut LaplacianWork,
    cloud: &OrganizedPointCloud,
    options: &LaplacianOptions,
    passes: Passes<'_>,
    parallel: bool,
) -> Option<Filtered<'a>> {
    let (rows, cols) = (cloud.rows(), cloud.cols());
    let half = (options.kernel / 2) as usize;
    let (iterations, limits) = match passes {
        Passes::Uniform(n) => (n, None),
        Passes::PerPixel(p) => (u32::from(p.iter().copied().max().unwrap_or(0)), Some(p)),
    };
    work.output = None;
    if iterations == 0 || rows <= 2 * half || cols <= 2 * half {
        return None;
    }
    work.output = Some(iterations % 2 == 1);
    let blocks = cols.div_ceil(SKIP_COLUMNS);
    if let Some(p) = limits {
        work.block_limits.clear();
        work.block_limits.extend(
            p.chunks_exact(cols)
                .flat_map(|row| row.chunks(SKIP_COLUMNS))
                .map(|block| block.iter().copied().max().unwrap_or(0)),
        );
    }
    let block_limits = &work.block_limits;
    work.planes.resize(cloud.points().len());
    let [x, y, z, m, nx, ny, nz, weight_sums] = work.planes.planes_mut();
    work.valid_points = fill_planes(cloud.points(), cols, parallel, [x, y, z, m]);
    // A pixel is written back if the kernel filtered it in its last pass. Every pass
    // writes every row's sums but for the rows that per-pixel counts skip from the first
    // pass on, which are never written.
    if limits.is_some() {
        weight_sums.fill(0.0);
    }
    let stencil = Stencil {
        grid: Grid {
            rows,
            cols,
            half,
            lambda: options.lambda,
            epsilon: options.epsilon,
        },
        offsets: Offsets::new(half),
    };
    let band = if parallel { BAND_ROWS } else { rows } * cols;
    let m = &*m;
    let mut current = [x, y, z];
    let mut next = [nx, ny, nz];
    for pass in 0..iterations {
        let [cx, cy, cz] = &current;
        let source = Source {
            x: cx,
            y: cy,
            z: cz,
            m,
        };
        let limits = limits.map(|per_pixel| Limits {
            per_pixel,
            per_block: block_limits,
            blocks,
            pass: pass as u8,
        });
        let [nx, ny, nz] = &mut next;
        (
            nx.par_chunks_mut(band),
            ny.par_chunks_mut(band),
            nz.par_chunks_mut(band),
            weight_sums.par_chunks_mut(band),
        )
            .into_par_iter()
            .enumerate()
            .with_min_len(min_rows_per_task(parallel))
            .for_each_init(
                || stencil.ring(),
                |ring, (b, (ox, oy, oz, ow))| {
                    let first = b * band / cols;
                    let part = ring.band(first, first + ow.len() / cols, stencil.offsets.above());
                    let out = [ox, oy, oz];
                    rows_of_band(&stencil, part, &source, &mut ring.values, out, ow, limits);
                },
            );
        std::mem::swap(&mut current, &mut next);
    }
    let [x, y, z] = current;
    Some(Filtered {
        x,
        y,
        z,
        weight_sums,
    })
}

/// The previous pass's planes.
struct Source<'a> {
    x: &'a [f32],
    y: &'a [f32],
    z: &'a [f32],
    m: &'a [f32],
}

struct Grid {
    rows: usize,
    cols: usize,
    half: usize,
    lambda: f32,
    epsilon: f32,
}

/// Rows per band of the parallel backend; a task takes two bands at least. A task's first
/// band first computes the inverse distances of the `half` rows above it (see [`Ring`];
/// results do not depend on it). With 32-row bands a 213 × 160 frame (640 × 480
/// decimated by 3) had too few tasks for two threads: its filter took 0.40 ms instead of
/// 0.24.
const BAND_ROWS: usize = 8;

/// Columns per block of [`Limits::per_block`]. Far pixels take more passes than near
/// ones, and in a depth frame they rarely fill a row: on the TUM frame with `rgbd-auto`
/// (passes 1–16), computing only the blocks of 32 columns that hold a pixel still taking
/// passes, and not the whole row as soon as it holds one, leaves 1.21 instead of 2.07
/// million pixel passes to compute (1.03 million are needed; blocks of 16 columns leave
/// 1.14, of 64 1.29), and took the Laplacian stage from 56 to 32 ms on one thread (AMD
/// EPYC, AVX2).
const SKIP_COLUMNS: usize = 32;

/// Which pixels a pass filters when their passes are counted per pixel.
#[derive(Clone, Copy)]
struct Limits<'a> {
    /// Passes per pixel.
    per_pixel: &'a [u8],
    /// Per row, the largest count of each block of [`SKIP_COLUMNS`] columns, `blocks` a
    /// row: the pass computes the blocks whose pixels are not all done and copies the
    /// others.
    per_block: &'a [u8],
    blocks: usize,
    /// The pass running.
    pass: u8,
}

impl Limits<'_> {
    /// Whether some pixel of block `b` of row `r` takes this pass.
    #[inline]
    fn active(&self, r: usize, b: usize) -> bool {
        self.per_block[r * self.blocks + b] > self.pass
    }

    /// The column ranges of the runs of consecutive blocks for which `active(b)` holds,
    /// in a row of `cols` columns.
    fn runs(
        &self,
        cols: usize,
        active: impl Fn(usize) -> bool,
    ) -> impl Iterator<Item = Range<usize>> {
        let mut b = 0;
        std::iter::from_fn(move || {
            while b < self.blocks && !active(b) {
                b += 1;
            }
            let first = b;
            while b < self.blocks && active(b) {
                b += 1;
            }
            (first < b).then(|| first * SKIP_COLUMNS..(b * SKIP_COLUMNS).min(cols))
        })
    }
}

/// The grid, the kernel's offsets and where the ring keeps the inverse distances.
struct Stencil {
    grid: Grid,
    offsets: Offsets,
}

impl Stencil {
    /// Room for the inverse distances of the ring's rows, at least `half + 1` (none without
    /// sharing).
    fn ring(&self) -> Ring {
        self.offsets
            .ring(self.offsets.forward.len() * self.grid.cols)
    }

    /// Where, in the ring, the inverse distances between the points of row `r` and
    /// those at forward offset `pair` from them start.
    #[inline(always)]
    fn ring_row(&self, r: usize, pair: usize) -> usize {
        (self.offsets.ring_slot(r) * self.offsets.forward.len() + pair) * self.grid.cols
    }
}

/// Writes the rows of `band` from its first on of the next pass into `out` and their
/// weight sums into `sums`, both holding those rows, after the inverse distances of the
/// rows from its start on.
///
/// A pair of points has the same distance seen from either, so `1 / (d + ε)` is computed
/// once per pair, row by row, for the offsets that point forward, into a ring of the
/// last `half + 1` rows; a point finds its backward pairs' in the rows above. That
/// halves the square roots and divisions, which bound the kernel. A neighbour's weight
/// `m / (d + ε)` is then `m · (1 / (d + ε))`, the same number for a mask `m` of 0 or 1,
/// and the sums run over the neighbours in raster order: the bits of [`direct_row`],
/// which kernels too large for the ring use.
///
/// With per-pixel counts (`limits`) a row's blocks whose pixels are all done keep their
/// points and last weight sums, and the ring holds the inverse distances of the columns
/// that the active blocks of its row and the `half` rows below it read: each pixel's
/// result is the same bits as where every block is computed.
#[multiversion::multiversion(targets("x86_64+avx512f+avx512vl+avx512bw+avx512dq", "x86_64+avx2"))]
fn rows_of_band(
    stencil: &Stencil,
    band: Band,
    src: &Source<'_>,
    ring: &mut [f32],
    out: [&mut [f32]; 3],
    sums: &mut [f32],
    limits: Option<Limits<'_>>,
) {
    let Grid {
        rows, cols, half, ..
    } = stencil.grid;
    let Band { start, first } = band;
    let last = first + sums.len() / cols;
    let shared = stencil.offsets.shares_pairs();
    // 32 vector registers (AVX-512) or 16 (AVX2), fixed in each compiled copy: see
    // [`BLOCK`].
    const POINTS: usize = if multiversion::target::target_cfg_f!(target_feature = "avx512f") {
        WIDE_BLOCK
    } else {
        BLOCK
    };
    let [ox, oy, oz] = out;
    for r in start..last {
        // Rows within `half` of the bottom are nobody's backward neighbours.
        if shared && r + half < rows {
            match limits {
                None => pair_inverses(stencil, r, src, ring, 0..cols),
                Some(limits) => {
                    // A point reads its pairs with the points up to `half` columns away.
                    let readers = |b| (r..=r + half).any(|k| limits.active(k, b));
                    for run in limits.runs(cols, readers) {
                        let columns = run.start.saturating_sub(half)..(run.end + half).min(cols);
                        pair_inverses(stencil, r, src, ring, columns);
                    }
                }
            }
        }
        if r < first {
            continue;
        }
        let at = (r - first) * cols..(r - first + 1) * cols;
        let mut row_out = [
            &mut ox[at.clone()],
            &mut oy[at.clone()],
            &mut oz[at.clone()],
        ];
        let ow = &mut sums[at];
        if !copy_borders(&stencil.grid, r, src, &mut row_out, ow) {
            continue;
        }
        let interior = half..cols - half;
        let Some(limits) = limits else {
            filtered_columns::<POINTS>(stencil, r, src, ring, &mut row_out, ow, interior);
            continue;
        };
        let span = r * cols..(r + 1) * cols;
        for b in (0..limits.blocks).filter(|&b| !limits.active(r, b)) {
            let block = b * SKIP_COLUMNS..((b + 1) * SKIP_COLUMNS).min(cols);
            let from = span.start + block.start..span.start + block.end;
            for (o, s) in row_out.iter_mut().zip([src.x, src.y, src.z]) {
                o[block.clone()].copy_from_slice(&s[from.clone()]);
            }
        }
        for run in limits.runs(cols, |b| limits.active(r, b)) {
            let inside = run.start.max(interior.start)..run.end.min(interior.end);
            if !inside.is_empty() {
                filtered_columns::<POINTS>(stencil, r, src, ring, &mut row_out, ow, inside);
            }
            // Pixels done before this pass keep their points.
            let [ox, oy, oz] = &mut row_out;
            for c in run {
                let k = span.start + c;
                let limit = limits.per_pixel[k];
                if limit <= limits.pass {
                    (ox[c], oy[c], oz[c]) = (src.x[k], src.y[k], src.z[k]);
                    if limit == 0 {
                        ow[c] = 0.0;
                    }
                }
            }
        }
    }
}

/// Writes the points of the interior `columns` of row `r` (within `half` of no border)
/// of the next pass into the row planes `out` and their weight sums into `sums`, `POINTS`
/// at a time where the pairs are shared ([`shared_row`]).
#[inline(always)]
fn filtered_columns<const POINTS: usize>(
    stencil: &Stencil,
    r: usize,
    src: &Source<'_>,
    ring: &[f32],
    [ox, oy, oz]: &mut [&mut [f32]; 3],
    sums: &mut [f32],
    columns: Range<usize>,
) {
    let out = [&mut **ox, &mut **oy, &mut **oz];
    // (Called, not taken as a function pointer: only inlined into the row kernel does it
    // get its target features.)
    match stencil.grid.half {
        _ if !stencil.offsets.shares_pairs() => {
            direct_row(&stencil.grid, r, src, out, sums, columns);
        }
        1 => shared_row::<8, POINTS>(stencil, r, src, ring, out, sums, columns),
        2 => shared_row::<24, POINTS>(stencil, r, src, ring, out, sums, columns),
        _ => shared_row::<48, POINTS>(stencil, r, src, ring, out, sums, columns),
    }
}

/// The inverse distances `1 / (d + ε)` between the points of row `r` in `columns` and
/// those at each forward offset, into the ring; pairs reaching past the grid are skipped.
#[inline(always)]
fn pair_inverses(
    stencil: &Stencil,
    r: usize,
    src: &Source<'_>,
    ring: &mut [f32],
    columns: Range<usize>,
) {
    let Grid {
        rows,
        cols,
        epsilon,
        ..
    } = stencil.grid;
    for (pair, &(dr, dc)) in stencil.offsets.forward.iter().enumerate() {
        if r + dr >= rows {
            continue;
        }
        // Points c with c + dc inside the row.
        let lo = dc.min(0).unsigned_abs().max(columns.start);
        let hi = (cols - dc.max(0) as usize).min(columns.end);
        if lo >= hi {
            continue;
        }
        let len = hi - lo;
        let p = r * cols + lo;
        let q = ((r + dr) * cols + lo).wrapping_add_signed(dc);
        let [px, py, pz] = [src.x, src.y, src.z].map(|s| &s[p..p + len]);
        let [qx, qy, qz] = [src.x, src.y, src.z].map(|s| &s[q..q + len]);
        let start = stencil.ring_row(r, pair) + lo;
        let inverses = &mut ring[start..start + len];
        for i in 0..len {
            let dx = px[i] - qx[i];
            let dy = py[i] - qy[i];
            let dz = pz[i] - qz[i];
            inverses[i] = 1.0 / ((dx * dx + dy * dy + dz * dz).sqrt() + epsilon);
        }
    }
}

/// Points whose sums one block of [`shared_row`] keeps in registers across all terms.
/// Four sums a point: 16 points take 8 of AVX2's 16 vector registers (32 points took all
/// 16 and spilled: the Laplacian stage at 424 × 240 took about 5 % longer on one thread,
/// AMD EPYC).
const BLOCK: usize = 16;

/// [`BLOCK`] with AVX-512: 32 points take 8 of its 32 vector registers.
const WIDE_BLOCK: usize = 32;

/// Writes the points of the interior `columns` of row `r` of the next pass into the row
/// planes `out` and their weight sums into `sums`, from the inverse distances of rows
/// `r − half ..= r` in the ring; the sums of `POINTS` points ([`BLOCK`] or
/// [`WIDE_BLOCK`]) at a time stay in registers while every term is added to them and
/// while the points move ([`finished`]: moving them in a second pass over the written
/// row, as [`direct_row`] does, took the filter 6 % longer at 424 × 240).
#[inline(always)]
fn shared_row<const TERMS: usize, const POINTS: usize>(
    stencil: &Stencil,
    r: usize,
    src: &Source<'_>,
    ring: &[f32],
    [ox, oy, oz]: [&mut [f32]; 3],
    sums: &mut [f32],
    columns: Range<usize>,
) {
    let grid = &stencil.grid;
    let cols = grid.cols;
    let own = r * cols + columns.start;
    let len = columns.len();
    // Per neighbour, in raster order: its x, y, z, mask and the pair's inverse distance.
    // Filled in a loop: `std::array::from_fn` ran out of line, a call per term.
    let mut terms: [[&[f32]; 5]; TERMS] = [[&[]; 5]; TERMS];
    debug_assert_eq!(stencil.offsets.neighbours.len(), TERMS);
    for (nb, term) in stencil.offsets.neighbours.iter().zip(&mut terms) {
        let inverses = if nb.forward {
            stencil.ring_row(r, nb.pair) + columns.start
        } else {
            let row = r.wrapping_add_signed(nb.dr);
            (stencil.ring_row(row, nb.pair) + columns.start).wrapping_add_signed(nb.dc)
        };
        let q = own.wrapping_add_signed(nb.dr * cols as isize + nb.dc);
        let [x, y, z, m] = [src.x, src.y, src.z, src.m].map(|p| span(p, q, len));
        *term = [x, y, z, m, span(ring, inverses, len)];
    }
    let mut planes = [
        &mut ox[columns.clone()],
        &mut oy[columns.clone()],
        &mut oz[columns.clone()],
        &mut sums[columns],
    ];
    row_in_blocks(
        len,
        &mut planes,
        #[inline(always)]
        |at| {
            finished(
                grid.lambda,
                term_sums::<POINTS, TERMS>(&terms, at),
                own + at,
                src,
            )
        },
        #[inline(always)]
        |i| finished(grid.lambda, term_sums::<1, TERMS>(&terms, i), own + i, src),
    );
}

/// The sums of the `N` points from `at` on of the terms, each term given as a
/// neighbour's x, y, z, mask and inverse distance: Σ w x, Σ w y, Σ w z and Σ w, added in
/// the order of [`direct_row`].
#[inline(always)]
fn term_sums<const N: usize, const TERMS: usize>(
    terms: &[[&[f32]; 5]; TERMS],
    at: usize,
) -> [[f32; N]; 4] {
    let mut acc = [[0.0f32; N]; 4];
    for term in terms {
        let [qx, qy, qz, qm, inverse] = term_at::<N>(term, at);
        for i in 0..N {
            let w = qm[i] * inverse[i];
            acc[3][i] += w;
            acc[0][i] += w * qx[i];
            acc[1][i] += w * qy[i];
            acc[2][i] += w * qz[i];
        }
    }
    acc
}

/// Copies row `r`'s border pixels (all of a border row) from `src` into the row planes
/// `out`, with zero weight sums; whether the row has interior pixels (is no border row).
#[inline(always)]
fn copy_borders(
    grid: &Grid,
    r: usize,
    src: &Source<'_>,
    out: &mut [&mut [f32]; 3],
    sums: &mut [f32],
) -> bool {
    let Grid {
        rows, cols, half, ..
    } = *grid;
    let base = r * cols;
    let border_row = r < half || r + half >= rows;
    for (o, s) in out.iter_mut().zip([src.x, src.y, src.z]) {
        let s = &s[base..base + cols];
        if border_row {
            o.copy_from_slice(s);
        } else {
            o[..half].copy_from_slice(&s[..half]);
            o[cols - half..].copy_from_slice(&s[cols - half..]);
        }
    }
    if border_row {
        sums.fill(0.0);
        return false;
    }
    sums[..half].fill(0.0);
    sums[cols - half..].fill(0.0);
    true
}

/// Moves the interior points from `own` on by λ towards their neighbours' weighted mean
/// `a / w` (see [`moved`]).
#[inline(always)]
fn finish(
    grid: &Grid,
    own: usize,
    src: &Source<'_>,
    [ax, ay, az]: [&mut [f32]; 3],
    aw: &mut [f32],
) {
    let len = aw.len();
    let vx = &src.x[own..own + len];
    let vy = &src.y[own..own + len];
    let vz = &src.z[own..own + len];
    let vm = &src.m[own..own + len];
    let (ax, ay, az) = (&mut ax[..len], &mut ay[..len], &mut az[..len]);
    for i in 0..len {
        let point = [vx[i], vy[i], vz[i]];
        let sums = [ax[i], ay[i], az[i], aw[i]];
        [ax[i], ay[i], az[i], aw[i]] = moved(grid.lambda, sums, point, vm[i] > 0.0);
    }
}

/// [`finish`] for the sums of one block of `N` points from `at` on (as [`term_sums`]
/// gives them), while they are still in registers.
#[inline(always)]
fn finished<const N: usize>(
    lambda: f32,
    mut sums: [[f32; N]; 4],
    at: usize,
    src: &Source<'_>,
) -> [[f32; N]; 4] {
    let (vx, vy, vz) = (span(src.x, at, N), span(src.y, at, N), span(src.z, at, N));
    let vm = span(src.m, at, N);
    let [ax, ay, az, aw] = &mut sums;
    for i in 0..N {
        let point = [vx[i], vy[i], vz[i]];
        let point_sums = [ax[i], ay[i], az[i], aw[i]];
        [ax[i], ay[i], az[i], aw[i]] = moved(lambda, point_sums, point, vm[i] > 0.0);
    }
    sums
}

/// The point `v` moved by λ towards its neighbours' weighted mean `a / w`, given its
/// sums `[a_x, a_y, a_z, w]`, and then its weight sum; an invalid point (not `valid`), or
/// one without a weighted neighbour, stays, with a zero weight sum.
#[inline(always)]
fn moved(lambda: f32, [ax, ay, az, aw]: [f32; 4], [vx, vy, vz]: [f32; 3], valid: bool) -> [f32; 4] {
    if valid && aw > 0.0 {
        [
            vx + lambda * (ax / aw - vx),
            vy + lambda * (ay / aw - vy),
            vz + lambda * (az / aw - vz),
            aw,
        ]
    } else {
        [vx, vy, vz, 0.0]
    }
}

/// Writes the points of the interior `columns` of row `r` of the next pass into the row
/// planes `out` and their weight sums into `sums`, each neighbour's weight computed where
/// it is used: the filter's definition.
#[inline(always)]
fn direct_row(
    grid: &Grid,
    r: usize,
    src: &Source<'_>,
    [ox, oy, oz]: [&mut [f32]; 3],
    sums: &mut [f32],
    columns: Range<usize>,
) {
    let Grid {
        cols,
        half,
        epsilon,
        ..
    } = *grid;
    let own = r * cols + columns.start;
    let len = columns.len();
    let vx = &src.x[own..own + len];
    let vy = &src.y[own..own + len];
    let vz = &src.z[own..own + len];
    let ax = &mut ox[columns.clone()];
    let ay = &mut oy[columns.clone()];
    let az = &mut oz[columns.clone()];
    let aw = &mut sums[columns.clone()];
    ax.fill(0.0);
    ay.fill(0.0);
    az.fill(0.0);
    aw.fill(0.0);
    let k = 2 * half + 1;
    for dr in 0..k {
        for dc in 0..k {
            if dr == half && dc == half {
                continue;
            }
            let start = (r + dr - half) * cols + columns.start + dc - half;
            let qx = &src.x[start..start + len];
            let qy = &src.y[start..start + len];
            let qz = &src.z[start..start + len];
            let qm = &src.m[start..start + len];
            for i in 0..len {
                let dx = vx[i] - qx[i];
                let dy = vy[i] - qy[i];
                let dz = vz[i] - qz[i];
                let d = (dx * dx + dy * dy + dz * dz).sqrt();
                let w = qm[i] / (d + epsilon);
                aw[i] += w;
                ax[i] += w * qx[i];
                ay[i] += w * qy[i];
                az[i] += w * qz[i];
            }
        }
    }
    finish(grid, own, src, [ax, ay, az], aw);
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;

    /// The next pass by the filter's definition, x, y, z and weight sums: each row's
    /// borders kept, its interior from [`direct_row`].
    fn direct(grid: &Grid, src: &Source<'_>) -> [Vec<f32>; 4] {
        let cols = grid.cols;
        let mut next = [(); 4].map(|_| vec![0.0f32; grid.rows * cols]);
        let [nx, ny, nz, sums] = &mut next;
        for r in 0..grid.rows {
            let at = r * cols..(r + 1) * cols;
            let mut out = [
                &mut nx[at.clone()],
                &mut ny[at.clone()],
                &mut nz[at.clone()],
            ];
            let sums = &mut sums[at];
            if copy_borders(grid, r, src, &mut out, sums) {
                direct_row(grid, r, src, out, sums, grid.half..cols - grid.half);
            }
        }
        next
    }

    /// The band kernel chosen at run time (AVX-512 or AVX2 where the CPU has them), which
    /// shares each pair's inverse distance through the ring up to kernel 7, gives the bits
    /// of the direct kernel as built for the baseline target: for kernels 3 to 9, rows
    /// with whole blocks and a rest, fewer pixels than a block, and bands of any start.
    #[test]
    fn banded_kernel_matches_the_direct_kernel_at_baseline() {
        let rows = 11;
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for half in 1..=4 {
            for cols in [
                2 * half + 5,
                2 * half + BLOCK,
                2 * half + 2 * BLOCK + 3,
                2 * half + 2 * WIDE_BLOCK + 3,
            ] {
                let n = rows * cols;
                let mut plane = || -> Vec<f32> { (0..n).map(|_| rng.random::<f32>()).collect() };
                let (x, y, z) = (plane(), plane(), plane());
                let m: Vec<f32> = (0..n).map(|i| f32::from(i % 5 != 0)).collect();
                // Invalid points are stored as zeros (see `Planes`).
                let zero =
                    |p: Vec<f32>| -> Vec<f32> { p.iter().zip(&m).map(|(v, m)| v * m).collect() };
                let (x, y, z) = (zero(x), zero(y), zero(z));
                let src = Source {
                    x: &x,
                    y: &y,
                    z: &z,
                    m: &m,
                };
                let stencil = Stencil {
                    grid: Grid {
                        rows,
                        cols,
                        half,
                        lambda: 0.7,
                        epsilon: 1e-4,
                    },
                    offsets: Offsets::new(half),
                };
                let want = direct(&stencil.grid, &src);
                // Bands continuing one ring (in order, as a rayon task takes them), and
                // bands each on a ring of stale values.
                let stale = || {
                    let mut ring = stencil.ring();
                    ring.values.fill(f32::NAN);
                    ring
                };
                for (band, shared) in [1, 3, rows]
                    .into_iter()
                    .flat_map(|b| [(b, true), (b, false)])
                {
                    let mut got = [(); 4].map(|_| vec![f32::NAN; n]);
                    let mut ring = stale();
                    let [gx, gy, gz, gw] = &mut got;
                    for (b, (((ox, oy), oz), ow)) in gx
                        .chunks_mut(band * cols)
                        .zip(gy.chunks_mut(band * cols))
                        .zip(gz.chunks_mut(band * cols))
                        .zip(gw.chunks_mut(band * cols))
                        .enumerate()
                    {
                        if !shared {
                            ring = stale();
                        }
                        let first = b * band;
                        let part =
                            ring.band(first, first + ow.len() / cols, stencil.offsets.above());
                        let out = [ox, oy, oz];
                        rows_of_band(&stencil, part, &src, &mut ring.values, out, ow, None);
                    }
                    let bits = |v: &[Vec<f32>; 4]| -> Vec<u32> {
                        v.iter().flatten().map(|f| f.to_bits()).collect()
                    };
                    assert_eq!(
                        bits(&got),
                        bits(&want),
                        "half {half}, cols {cols}, band {band}, shared ring {shared}"
                    );
                }
            }
        }
    }

    /// With per-pixel counts each pixel ends where the filter's definition leaves it
    /// after its own count of passes: [`direct`] over every pixel of every row in every
    /// pass, a pixel keeping its point once its count is reached. Its weight sum is
    /// positive exactly where its last pass moved it. Kernels 3 to 9, on one thread and in
    /// bands, with counts that leave whole blocks and rows done early and some pixels of
    /// one block taking more passes than all their neighbours.
    #[test]
    fn per_pixel_passes_match_the_definition_pass_by_pass() {
        let (rows, cols) = (37, 2 * SKIP_COLUMNS + 11);
        let n = rows * cols;
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for half in 1..=4 {
            let points: Vec<[f64; 3]> = (0..n)
                .map(|i| match i % 7 {
                    3 => [f64::NAN; 3],
                    _ => [rng.random(), rng.random(), 1.0 + rng.random::<f64>()],
                })
                .collect();
            let passes: Vec<u8> = (0..n)
                .map(|i| match (i / cols, i % cols) {
                    (0..10, c) if c < SKIP_COLUMNS => 0,
                    (20..25, c) if c >= 2 * SKIP_COLUMNS => rng.random_range(3..=6),
                    (30.., _) => 1,
                    _ => rng.random_range(0..=2),
                })
                .collect();
            let cloud = OrganizedPointCloud::new(rows, cols, points).unwrap();
            let (lambda, epsilon) = (0.7, 1e-4);
            let grid = Grid {
                rows,
                cols,
                half,
                lambda,
                epsilon,
            };
            let mut want = [(); 4].map(|_| vec![0.0f32; n]);
            let [x, y, z, m] = &mut want;
            fill_planes(cloud.points(), cols, false, [x, y, z, m]);
            let mut moved = vec![false; n];
            for pass in 0..passes.iter().copied().max().unwrap() {
                let [x, y, z, m] = &want;
                let src = Source { x, y, z, m };
                let next = direct(&grid, &src);
                for i in (0..n).filter(|&i| passes[i] > pass) {
                    for k in 0..3 {
                        want[k][i] = next[k][i];
                    }
                    moved[i] = next[3][i] > 0.0;
                }
            }
            let options = LaplacianOptions::new()
                .with_kernel(2 * half as u32 + 1)
                .with_lambda(lambda)
                .with_epsilon(epsilon);
            for parallel in [false, true] {
                let mut work = LaplacianWork::default();
                let got = filter(
                    &mut work,
                    &cloud,
                    &options,
                    Passes::PerPixel(&passes),
                    parallel,
                )
                .unwrap();
                let bits = |p: &[f32]| -> Vec<u32> { p.iter().map(|v| v.to_bits()).collect() };
                for (k, (got, want)) in [got.x, got.y, got.z].into_iter().zip(&want).enumerate() {
                    assert_eq!(
                        bits(got),
                        bits(want),
                        "half {half}, parallel {parallel}, plane {k}"
                    );
                }
                let got_moved: Vec<bool> = got.weight_sums.iter().map(|&w| w > 0.0).collect();
                assert_eq!(got_moved, moved, "half {half}, parallel {parallel}");
            }
        }
    }
}
