//! The bilateral normal filter on the implicit right-cut mesh, `f32` planes per triangle
//! type, one cell row per task.

use opc_mesh::OrganizedPointCloud;
use rayon::prelude::*;

use super::{Planes, exp_neg, min_rows_per_task, resize_all};
use crate::{BilateralOptions, grid::TRIANGLES_PER_CELL};

/// xyz planes.
type Xyz = [Vec<f32>; 3];

/// Normals, centroids and masks of the triangles of one type `k` (see [`crate::grid`]),
/// indexed by cell `r · (cols − 1) + c`. Missing triangles hold zeros and mask 0.0.
#[derive(Default)]
struct TypePlanes {
    normal: Xyz,
    centroid: Xyz,
    mask: Vec<f32>,
}

/// Reusable buffers of the bilateral filter.
#[derive(Default)]
pub(crate) struct BilateralWork {
    planes: Planes,
    types: [TypePlanes; 2],
    current: [Xyz; 2],
    next: [Xyz; 2],
}

/// Computes normals and centroids, filters the normals and writes them per slot into
/// `out` (resized). Options are validated.
pub(crate) fn bilateral_into(
    work: &mut BilateralWork,
    cloud: &OrganizedPointCloud,
    options: &BilateralOptions,
    parallel: bool,
    out: &mut Vec<[f32; 3]>,
) {
    let (rows, cols) = (cloud.rows(), cloud.cols());
    let BilateralWork {
        planes,
        types,
        current,
        next,
    } = work;
    planes.fill(cloud.points(), cols, parallel);
    for (k, planes_k) in types.iter_mut().enumerate() {
        planes_k.compute(planes, rows, cols, k, parallel);
    }
    let cells = Cells {
        rows: rows - 1,
        cols: cols - 1,
        half: (options.kernel / 2) as usize,
    };
    let num_cells = cells.rows * cells.cols;
    for (cur, t) in current.iter_mut().zip(types.iter()) {
        for (c, n) in cur.iter_mut().zip(&t.normal) {
            c.clear();
            c.extend_from_slice(n);
        }
    }
    if cells.rows > 2 * cells.half && cells.cols > 2 * cells.half && options.iterations > 0 {
        let (inv_var_length, inv_var_angle) = options.inverse_variances();
        let filter = Filter {
            cells,
            inv_var_length,
            inv_var_angle,
        };
        for planes_k in next.iter_mut() {
            resize_all(planes_k, num_cells);
        }
        let types = &*types;
        for _ in 0..options.iterations {
            let [[n0x, n0y, n0z], [n1x, n1y, n1z]] = &mut *next;
            let cc = cells.cols;
            let previous = &*current;
            (
                n0x.par_chunks_mut(cc),
                n0y.par_chunks_mut(cc),
                n0z.par_chunks_mut(cc),
                n1x.par_chunks_mut(cc),
                n1y.par_chunks_mut(cc),
                n1z.par_chunks_mut(cc),
            )
                .into_par_iter()
                .enumerate()
                .with_min_len(min_rows_per_task(parallel))
                .for_each(|(r, (a, b, c, d, e, f))| {
                    row(&filter, r, previous, types, [[a, b, c], [d, e, f]]);
                });
            std::mem::swap(current, next);
        }
    }
    out.resize(TRIANGLES_PER_CELL * num_cells, [0.0; 3]);
    let (types, current) = (&*types, &*current);
    out.par_chunks_mut(TRIANGLES_PER_CELL * cells.cols)
        .enumerate()
        .with_min_len(min_rows_per_task(parallel))
        .for_each(|(r, out)| {
            for (j, pair) in out.chunks_exact_mut(TRIANGLES_PER_CELL).enumerate() {
                let cell = r * cells.cols + j;
                for (k, slot) in pair.iter_mut().enumerate() {
                    *slot = if types[k].mask[cell] > 0.0 {
                        let [x, y, z] = &current[k];
                        [x[cell], y[cell], z[cell]]
                    } else {
                        [f32::NAN; 3]
                    };
                }
            }
        });
}

impl TypePlanes {
    /// Normals and centroids of the type-`k` triangles of every cell.
    fn compute(&mut self, planes: &Planes, rows: usize, cols: usize, k: usize, parallel: bool) {
        let (cr, cc) = (rows - 1, cols - 1);
        resize_all(&mut self.normal, cr * cc);
        resize_all(&mut self.centroid, cr * cc);
        self.mask.resize(cr * cc, 0.0);
        let [nx, ny, nz] = &mut self.normal;
        let [cx, cy, cz] = &mut self.centroid;
        (
            nx.par_chunks_mut(cc),
            ny.par_chunks_mut(cc),
            nz.par_chunks_mut(cc),
            cx.par_chunks_mut(cc),
            cy.par_chunks_mut(cc),
            cz.par_chunks_mut(cc),
            self.mask.par_chunks_mut(cc),
        )
            .into_par_iter()
            .enumerate()
            .with_min_len(min_rows_per_task(parallel))
            .for_each(|(r, (nx, ny, nz, cx, cy, cz, m))| {
                let top = r * cols;
                let bottom = top + cols;
                let corner = |plane, start| span(plane, start, cc);
                // p1 = (r, c), p2 = (r, c + 1), p3 = (r + 1, c + 1), p4 = (r + 1, c);
                // type 0 is [p3, p2, p1], type 1 is [p1, p4, p3].
                let (a, b, c) = if k == 0 {
                    (bottom + 1, top + 1, top)
                } else {
                    (top, bottom, bottom + 1)
                };
                let (ax, ay, az, am) = (
                    corner(&planes.x, a),
                    corner(&planes.y, a),
                    corner(&planes.z, a),
                    corner(&planes.m, a),
                );
                let (bx, by, bz, bm) = (
                    corner(&planes.x, b),
                    corner(&planes.y, b),
                    corner(&planes.z, b),
                    corner(&planes.m, b),
                );
                let (qx, qy, qz, qm) = (
                    corner(&planes.x, c),
                    corner(&planes.y, c),
                    corner(&planes.z, c),
                    corner(&planes.m, c),
                );
                for i in 0..cc {
                    let valid = am[i] * bm[i] * qm[i] > 0.0;
                    let (ux, uy, uz) = (bx[i] - ax[i], by[i] - ay[i], bz[i] - az[i]);
                    let (vx, vy, vz) = (qx[i] - ax[i], qy[i] - ay[i], qz[i] - az[i]);
                    let px = uy * vz - uz * vy;
                    let py = uz * vx - ux * vz;
                    let pz = ux * vy - uy * vx;
                    let len = (px * px + py * py + pz * pz).sqrt();
                    let unit = valid && len > 0.0;
                    nx[i] = if unit { px / len } else { 0.0 };
                    ny[i] = if unit { py / len } else { 0.0 };
                    nz[i] = if unit { pz / len } else { 0.0 };
                    cx[i] = if valid {
                        (ax[i] + bx[i] + qx[i]) / 3.0
                    } else {
                        0.0
                    };
                    cy[i] = if valid {
                        (ay[i] + by[i] + qy[i]) / 3.0
                    } else {
                        0.0
                    };
                    cz[i] = if valid {
                        (az[i] + bz[i] + qz[i]) / 3.0
                    } else {
                        0.0
                    };
                    m[i] = if valid { 1.0 } else { 0.0 };
                }
            });
    }
}

/// The cell grid and the kernel half-width.
#[derive(Clone, Copy)]
struct Cells {
    rows: usize,
    cols: usize,
    half: usize,
}

struct Filter {
    cells: Cells,
    inv_var_length: f32,
    inv_var_angle: f32,
}

/// Writes cell row `r` of the next pass (both triangle types) into `out`.
#[multiversion::multiversion(targets("x86_64+avx2"))]
fn row(
    filter: &Filter,
    r: usize,
    normals: &[Xyz; 2],
    types: &[TypePlanes; 2],
    out: [[&mut [f32]; 3]; 2],
) {
    row_kernel(filter, r, normals, types, out)
}

/// [`row`] for the baseline target or, inlined, for a wider one.
#[inline(always)]
fn row_kernel(
    filter: &Filter,
    r: usize,
    normals: &[Xyz; 2],
    types: &[TypePlanes; 2],
    mut out: [[&mut [f32]; 3]; 2],
) {
    let Cells { rows, cols, half } = filter.cells;
    let base = r * cols;
    let border_row = r < half || r + half >= rows;
    let len = cols - 2 * half;
    for (ko, planes) in out.iter_mut().enumerate() {
        for (o, n) in planes.iter_mut().zip(&normals[ko]) {
            if border_row {
                o.copy_from_slice(&n[base..base + cols]);
            } else {
                o[..half].copy_from_slice(&n[base..base + half]);
                o[half + len..].copy_from_slice(&n[base + half + len..base + cols]);
            }
        }
    }
    if border_row {
        return;
    }
    let own = base + half;
    for (ko, [ax, ay, az]) in out_interior(out, half, len).into_iter().enumerate() {
        let [nx, ny, nz] = &normals[ko];
        let [cx, cy, cz] = &types[ko].centroid;
        let (nx, ny, nz) = (
            &nx[own..own + len],
            &ny[own..own + len],
            &nz[own..own + len],
        );
        let (cx, cy, cz) = (
            &cx[own..own + len],
            &cy[own..own + len],
            &cz[own..own + len],
        );
        let om = &types[ko].mask[own..own + len];
        ax.fill(0.0);
        ay.fill(0.0);
        az.fill(0.0);
        let k = 2 * half + 1;
        for dr in 0..k {
            for dc in 0..k {
                if dr == half && dc == half {
                    continue;
                }
                let start = (r + dr - half) * cols + dc;
                for kn in 0..TRIANGLES_PER_CELL {
                    let [qnx, qny, qnz] = &normals[kn];
                    let [qcx, qcy, qcz] = &types[kn].centroid;
                    let qnx = &qnx[start..start + len];
                    let qny = &qny[start..start + len];
                    let qnz = &qnz[start..start + len];
                    let qcx = &qcx[start..start + len];
                    let qcy = &qcy[start..start + len];
                    let qcz = &qcz[start..start + len];
                    let qm = &types[kn].mask[start..start + len];
                    for i in 0..len {
                        let (ex, ey, ez) = (cx[i] - qcx[i], cy[i] - qcy[i], cz[i] - qcz[i]);
                        let (fx, fy, fz) = (nx[i] - qnx[i], ny[i] - qny[i], nz[i] - qnz[i]);
                        let e = (ex * ex + ey * ey + ez * ez) * filter.inv_var_length
                            + (fx * fx + fy * fy + fz * fz) * filter.inv_var_angle;
                        let w = qm[i] * exp_neg(e);
                        ax[i] += w * qnx[i];
                        ay[i] += w * qny[i];
                        az[i] += w * qnz[i];
                    }
                }
            }
        }
        for i in 0..len {
            let s = (ax[i] * ax[i] + ay[i] * ay[i] + az[i] * az[i]).sqrt();
            let (x, y, z) = if om[i] > 0.0 && s > 0.0 {
                (ax[i] / s, ay[i] / s, az[i] / s)
            } else {
                (nx[i], ny[i], nz[i])
            };
            ax[i] = x;
            ay[i] = y;
            az[i] = z;
        }
    }
}

/// The interior columns `[half, half + len)` of each output row.
fn out_interior(out: [[&mut [f32]; 3]; 2], half: usize, len: usize) -> [[&mut [f32]; 3]; 2] {
    out.map(|planes| planes.map(|o| &mut o[half..half + len]))
}

/// `plane[start..start + len]`.
#[inline]
fn span(plane: &[f32], start: usize, len: usize) -> &[f32] {
    &plane[start..start + len]
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;

    /// The row kernel chosen at run time (AVX2 where the CPU has it) gives the bits of
    /// the kernel as built for the baseline target.
    #[test]
    fn dispatched_row_matches_the_baseline_kernel() {
        let cells = Cells {
            rows: 6,
            cols: 29,
            half: 1,
        };
        let n = cells.rows * cells.cols;
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut xyz =
            || -> Xyz { [0, 1, 2].map(|_| (0..n).map(|_| rng.random::<f32>() - 0.5).collect()) };
        let normals = [xyz(), xyz()];
        let types = [0, 1].map(|k| TypePlanes {
            normal: [vec![0.0; n], vec![0.0; n], vec![0.0; n]],
            centroid: [0, 1, 2].map(|a| (0..n).map(|i| (i * (a + 2) + k) as f32 * 0.01).collect()),
            mask: (0..n).map(|i| f32::from((i + k) % 7 != 0)).collect(),
        });
        let filter = Filter {
            cells,
            inv_var_length: 30.0,
            inv_var_angle: 4.0,
        };
        let bits = |v: &[[Vec<f32>; 3]; 2]| -> Vec<u32> {
            v.iter().flatten().flatten().map(|f| f.to_bits()).collect()
        };
        for r in 0..cells.rows {
            let empty = || [0, 1, 2].map(|_| vec![0.0; cells.cols]);
            let (mut a, mut b) = ([empty(), empty()], [empty(), empty()]);
            let [[a0, a1, a2], [a3, a4, a5]] = &mut a;
            row(&filter, r, &normals, &types, [[a0, a1, a2], [a3, a4, a5]]);
            let [[b0, b1, b2], [b3, b4, b5]] = &mut b;
            row_kernel(&filter, r, &normals, &types, [[b0, b1, b2], [b3, b4, b5]]);
            assert_eq!(bits(&a), bits(&b), "row {r}");
        }
    }
}
