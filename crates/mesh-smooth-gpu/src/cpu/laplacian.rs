//! The Laplacian vertex filter on `f32` planes, a band of image rows per task.

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
    // The largest count per row: rows whose pixels are all done are copied.
    let row_limits: Vec<u8> = limits.map_or_else(Vec::new, |p| {
        p.chunks_exact(cols)
            .map(|row| row.iter().copied().max().unwrap_or(0))
            .collect()
    });
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
            per_row: &row_limits,
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

/// Which pixels a pass filters when their passes are counted per pixel.
#[derive(Clone, Copy)]
struct Limits<'a> {
    /// Passes per pixel.
    per_pixel: &'a [u8],
    /// The largest count per row: rows whose pixels are all done are copied.
    per_row: &'a [u8],
    /// The pass running.
    pass: u8,
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
    let [ox, oy, oz] = out;
    for r in start..last {
        // Rows within `half` of the bottom are nobody's backward neighbours.
        if shared && r + half < rows {
            pair_inverses(stencil, r, src, ring);
        }
        if r < first {
            continue;
        }
        let at = (r - first) * cols..(r - first + 1) * cols;
        let (ox, oy, oz) = (
            &mut ox[at.clone()],
            &mut oy[at.clone()],
            &mut oz[at.clone()],
        );
        let ow = &mut sums[at];
        let span = r * cols..(r + 1) * cols;
        if let Some(limits) = limits
            && limits.per_row[r] <= limits.pass
        {
            // Every pixel of the row is done: it keeps its last weight sum.
            ox.copy_from_slice(&src.x[span.clone()]);
            oy.copy_from_slice(&src.y[span.clone()]);
            oz.copy_from_slice(&src.z[span]);
            continue;
        }
        // (Called, not taken as a function pointer: only inlined into this function
        // does it get its target features.)
        let row_out = [&mut *ox, &mut *oy, &mut *oz];
        // 32 vector registers (AVX-512) or 16 (AVX2), fixed in each compiled copy: see
        // [`BLOCK`].
        const POINTS: usize = if multiversion::target::target_cfg_f!(target_feature = "avx512f") {
            WIDE_BLOCK
        } else {
            BLOCK
        };
        match half {
            _ if !shared => direct_row(&stencil.grid, r, src, row_out, ow),
            1 => shared_row::<8, POINTS>(stencil, r, src, ring, row_out, ow),
            2 => shared_row::<24, POINTS>(stencil, r, src, ring, row_out, ow),
            _ => shared_row::<48, POINTS>(stencil, r, src, ring, row_out, ow),
        }
        if let Some(limits) = limits {
            for (i, &limit) in limits.per_pixel[span.clone()].iter().enumerate() {
                if limit <= limits.pass {
                    let k = span.start + i;
                    (ox[i], oy[i], oz[i]) = (src.x[k], src.y[k], src.z[k]);
                    if limit == 0 {
                        ow[i] = 0.0;
                    }
                }
            }
        }
    }
}

/// The inverse distances `1 / (d + ε)` between row `r`'s points and those at each
/// forward offset, into the ring; pairs reaching past the grid are skipped.
#[inline(always)]
fn pair_inverses(stencil: &Stencil, r: usize, src: &Source<'_>, ring: &mut [f32]) {
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
        let lo = dc.min(0).unsigned_abs();
        let len = cols - dc.unsigned_abs();
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

/// Writes row `r` of the next pass into `out` and its weight sums into `sums`, from the
/// inverse distances of rows `r − half ..= r` in the ring; the sums of `POINTS` points
/// ([`BLOCK`] or [`WIDE_BLOCK`]) at a time stay in registers while every term is added
/// to them and while the points move ([`finished`]: moving them in a second pass over
/// the written row, as [`direct_row`] does, took the filter 6 % longer at 424 × 240).
#[inline(always)]
fn shared_row<const TERMS: usize, const POINTS: usize>(
    stencil: &Stencil,
    r: usize,
    src: &Source<'_>,
    ring: &[f32],
    out: [&mut [f32]; 3],
    sums: &mut [f32],
) {
    let grid = &stencil.grid;
    let [ox, oy, oz] = out;
    let Some(own) = copy_borders(grid, r, src, [&mut *ox, &mut *oy, &mut *oz], sums) else {
        return;
    };
    let Grid { cols, half, .. } = *grid;
    let len = cols - 2 * half;
    // Per neighbour, in raster order: its x, y, z, mask and the pair's inverse distance.
    // Filled in a loop: `std::array::from_fn` ran out of line, a call per term.
    let mut terms: [[&[f32]; 5]; TERMS] = [[&[]; 5]; TERMS];
    debug_assert_eq!(stencil.offsets.neighbours.len(), TERMS);
    for (nb, term) in stencil.offsets.neighbours.iter().zip(&mut terms) {
        let inverses = if nb.forward {
            stencil.ring_row(r, nb.pair) + half
        } else {
            let row = r.wrapping_add_signed(nb.dr);
            (stencil.ring_row(row, nb.pair) + half).wrapping_add_signed(nb.dc)
        };
        let q = own.wrapping_add_signed(nb.dr * cols as isize + nb.dc);
        let [x, y, z, m] = [src.x, src.y, src.z, src.m].map(|p| span(p, q, len));
        *term = [x, y, z, m, span(ring, inverses, len)];
    }
    let mut planes = [
        &mut ox[half..half + len],
        &mut oy[half..half + len],
        &mut oz[half..half + len],
        &mut sums[half..half + len],
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

/// Copies row `r`'s border pixels (all of a border row) from `src` into `out`, with
/// zero weight sums; `Some(first interior pixel)` unless the row is a border row.
#[inline(always)]
fn copy_borders(
    grid: &Grid,
    r: usize,
    src: &Source<'_>,
    out: [&mut [f32]; 3],
    sums: &mut [f32],
) -> Option<usize> {
    let Grid {
        rows, cols, half, ..
    } = *grid;
    let base = r * cols;
    let border_row = r < half || r + half >= rows;
    for (o, s) in out.into_iter().zip([src.x, src.y, src.z]) {
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
        return None;
    }
    sums[..half].fill(0.0);
    sums[cols - half..].fill(0.0);
    Some(base + half)
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

/// Writes row `r` of the next pass into `out` and its weight sums into `sums`, each
/// neighbour's weight computed where it is used: the filter's definition.
#[inline(always)]
fn direct_row(grid: &Grid, r: usize, src: &Source<'_>, out: [&mut [f32]; 3], sums: &mut [f32]) {
    let [ox, oy, oz] = out;
    let Some(own) = copy_borders(grid, r, src, [&mut *ox, &mut *oy, &mut *oz], sums) else {
        return;
    };
    let Grid {
        cols,
        half,
        epsilon,
        ..
    } = *grid;
    let len = cols - 2 * half;
    let vx = &src.x[own..own + len];
    let vy = &src.y[own..own + len];
    let vz = &src.z[own..own + len];
    let ax = &mut ox[half..half + len];
    let ay = &mut oy[half..half + len];
    let az = &mut oz[half..half + len];
    let aw = &mut sums[half..half + len];
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
            let start = (r + dr - half) * cols + dc;
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
                let mut want = [(); 4].map(|_| vec![0.0; n]);
                let [wx, wy, wz, ww] = &mut want;
                for r in 0..rows {
                    let at = r * cols..(r + 1) * cols;
                    let out = [
                        &mut wx[at.clone()],
                        &mut wy[at.clone()],
                        &mut wz[at.clone()],
                    ];
                    direct_row(&stencil.grid, r, &src, out, &mut ww[at]);
                }
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
}
