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

pub(crate) use bilateral::bilateral;
pub(crate) use fast_exp::exp_neg;
pub(crate) use laplacian::laplacian;

use rayon::prelude::*;

/// Rows per rayon task at least; the Cpu backend uses one task for everything.
pub(crate) fn min_rows_per_task(parallel: bool) -> usize {
    if parallel { 2 } else { usize::MAX }
}

/// An organized cloud as `f32` planes with a validity mask.
pub(crate) struct Planes {
    pub x: Vec<f32>,
    pub y: Vec<f32>,
    pub z: Vec<f32>,
    /// 1.0 for a valid point, 0.0 for an invalid one (whose coordinates are stored as 0).
    pub m: Vec<f32>,
}

impl Planes {
    /// Splits `points` (rows of `cols`) into planes, rounding to `f32`.
    pub fn from_points(points: &[[f64; 3]], cols: usize, parallel: bool) -> Self {
        let n = points.len();
        let mut planes = Self {
            x: vec![0.0; n],
            y: vec![0.0; n],
            z: vec![0.0; n],
            m: vec![0.0; n],
        };
        (
            planes.x.par_chunks_mut(cols),
            planes.y.par_chunks_mut(cols),
            planes.z.par_chunks_mut(cols),
            planes.m.par_chunks_mut(cols),
            points.par_chunks(cols),
        )
            .into_par_iter()
            .with_min_len(min_rows_per_task(parallel))
            .for_each(|(x, y, z, m, row)| {
                for (i, p) in row.iter().enumerate() {
                    if opc_mesh::is_valid(p) {
                        x[i] = p[0] as f32;
                        y[i] = p[1] as f32;
                        z[i] = p[2] as f32;
                        m[i] = 1.0;
                    }
                }
            });
        planes
    }
}
