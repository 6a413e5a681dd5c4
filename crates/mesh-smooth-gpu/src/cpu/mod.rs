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

pub use smoother::CpuSmoother;

pub(crate) use fast_exp::exp_neg;

mod smoother;

use rayon::prelude::*;

/// Rows per rayon task at least; the Cpu backend uses one task for everything.
pub(crate) fn min_rows_per_task(parallel: bool) -> usize {
    if parallel { 2 } else { usize::MAX }
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
        (
            self.x.par_chunks_mut(cols),
            self.y.par_chunks_mut(cols),
            self.z.par_chunks_mut(cols),
            self.m.par_chunks_mut(cols),
            points.par_chunks(cols),
        )
            .into_par_iter()
            .with_min_len(min_rows_per_task(parallel))
            .for_each(|(x, y, z, m, row)| {
                for (i, p) in row.iter().enumerate() {
                    let valid = opc_mesh::is_valid(p);
                    x[i] = if valid { p[0] as f32 } else { 0.0 };
                    y[i] = if valid { p[1] as f32 } else { 0.0 };
                    z[i] = if valid { p[2] as f32 } else { 0.0 };
                    m[i] = if valid { 1.0 } else { 0.0 };
                }
            });
    }
}

/// Resizes every plane of `planes` to `n` (contents are overwritten by the caller).
pub(crate) fn resize_all<const N: usize>(planes: &mut [Vec<f32>; N], n: usize) {
    for plane in planes {
        plane.resize(n, 0.0);
    }
}
