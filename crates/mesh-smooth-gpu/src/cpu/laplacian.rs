//! The Laplacian vertex filter on `f32` planes, one image row per task.

use opc_mesh::OrganizedPointCloud;
use rayon::prelude::*;

use super::{PlaneSet, fill_planes, min_rows_per_task};
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
    let grid = Grid {
        rows,
        cols,
        half,
        lambda: options.lambda,
        epsilon: options.epsilon,
    };
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
        let [nx, ny, nz] = &mut next;
        (
            nx.par_chunks_mut(cols),
            ny.par_chunks_mut(cols),
            nz.par_chunks_mut(cols),
            weight_sums.par_chunks_mut(cols),
        )
            .into_par_iter()
            .enumerate()
            .with_min_len(min_rows_per_task(parallel))
            .for_each(|(r, (ox, oy, oz, ow))| match limits {
                None => row(&grid, r, &source, [ox, oy, oz], ow),
                Some(limits) => {
                    let pass = pass as u8;
                    let span = r * cols..(r + 1) * cols;
                    if row_limits[r] <= pass {
                        // Every pixel of the row is done: it keeps its last weight sum.
                        ox.copy_from_slice(&source.x[span.clone()]);
                        oy.copy_from_slice(&source.y[span.clone()]);
                        oz.copy_from_slice(&source.z[span]);
                        return;
                    }
                    row(&grid, r, &source, [&mut *ox, &mut *oy, &mut *oz], ow);
                    for (i, &limit) in limits[span.clone()].iter().enumerate() {
                        if limit <= pass {
                            let k = span.start + i;
                            (ox[i], oy[i], oz[i]) = (source.x[k], source.y[k], source.z[k]);
                            if limit == 0 {
                                ow[i] = 0.0;
                            }
                        }
                    }
                }
            });
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

/// Writes row `r` of the next pass into `out` and its weight sums into `sums`.
#[multiversion::multiversion(targets("x86_64+avx512f+avx512vl+avx512bw+avx512dq", "x86_64+avx2"))]
fn row(grid: &Grid, r: usize, src: &Source<'_>, out: [&mut [f32]; 3], sums: &mut [f32]) {
    row_kernel(grid, r, src, out, sums)
}

/// [`row`] for the baseline target or, inlined, for a wider one.
#[inline(always)]
fn row_kernel(grid: &Grid, r: usize, src: &Source<'_>, out: [&mut [f32]; 3], sums: &mut [f32]) {
    let Grid {
        rows,
        cols,
        half,
        lambda,
        epsilon,
    } = *grid;
    let base = r * cols;
    let [ox, oy, oz] = out;
    if r < half || r + half >= rows {
        ox.copy_from_slice(&src.x[base..base + cols]);
        oy.copy_from_slice(&src.y[base..base + cols]);
        oz.copy_from_slice(&src.z[base..base + cols]);
        sums.fill(0.0);
        return;
    }
    let len = cols - 2 * half;
    for (o, s) in [(&mut *ox, src.x), (&mut *oy, src.y), (&mut *oz, src.z)] {
        o[..half].copy_from_slice(&s[base..base + half]);
        o[half + len..].copy_from_slice(&s[base + half + len..base + cols]);
    }
    sums[..half].fill(0.0);
    sums[half + len..].fill(0.0);

    let own = base + half;
    let vx = &src.x[own..own + len];
    let vy = &src.y[own..own + len];
    let vz = &src.z[own..own + len];
    let vm = &src.m[own..own + len];
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
    for i in 0..len {
        if vm[i] > 0.0 && aw[i] > 0.0 {
            ax[i] = vx[i] + lambda * (ax[i] / aw[i] - vx[i]);
            ay[i] = vy[i] + lambda * (ay[i] / aw[i] - vy[i]);
            az[i] = vz[i] + lambda * (az[i] / aw[i] - vz[i]);
        } else {
            ax[i] = vx[i];
            ay[i] = vy[i];
            az[i] = vz[i];
            aw[i] = 0.0;
        }
    }
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;

    /// The row kernel chosen at run time (AVX-512 or AVX2 where the CPU has them) gives the bits of
    /// the kernel as built for the baseline target.
    #[test]
    fn dispatched_row_matches_the_baseline_kernel() {
        let (rows, cols) = (7, 37);
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut plane = || -> Vec<f32> { (0..rows * cols).map(|_| rng.random::<f32>()).collect() };
        let (x, y, z) = (plane(), plane(), plane());
        let m: Vec<f32> = (0..rows * cols).map(|i| f32::from(i % 5 != 0)).collect();
        let src = Source {
            x: &x,
            y: &y,
            z: &z,
            m: &m,
        };
        let grid = Grid {
            rows,
            cols,
            half: 2,
            lambda: 0.7,
            epsilon: 1e-4,
        };
        for r in 0..rows {
            let mut a = [
                vec![0.0; cols],
                vec![0.0; cols],
                vec![0.0; cols],
                vec![0.0; cols],
            ];
            let mut b = a.clone();
            let [ax, ay, az, aw] = &mut a;
            row(&grid, r, &src, [ax, ay, az], aw);
            let [bx, by, bz, bw] = &mut b;
            row_kernel(&grid, r, &src, [bx, by, bz], bw);
            let bits = |v: &[Vec<f32>; 4]| -> Vec<u32> {
                v.iter().flatten().map(|f| f.to_bits()).collect()
            };
            assert_eq!(bits(&a), bits(&b), "row {r}");
        }
    }
}
