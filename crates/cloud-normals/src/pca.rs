//! Normals by principal component analysis of each point's neighbourhood: the
//! eigenvector of the smallest eigenvalue of the neighbours' covariance.

use plane_geom::smallest_eigenvector;
use rayon::prelude::*;

use crate::Neighbours;

/// Points per parallel work item.
const CHUNK: usize = 4096;

/// The normal of the best-fitting plane through `points` (unit, sign arbitrary) and the
/// surface variation `λ₀ / (λ₀ + λ₁ + λ₂)` of their covariance (0 on a plane, 1/3 for
/// isotropic scatter); `None` for fewer than 3 points, or points on one line or one spot.
///
/// ```
/// use cloud_normals::plane_normal;
/// let square = [[0.0, 0.0, 2.0], [1.0, 0.0, 2.0], [0.0, 1.0, 2.0], [1.0, 1.0, 2.0]];
/// let (normal, variation) = plane_normal(square.iter().copied()).unwrap();
/// assert!((normal[2].abs() - 1.0).abs() < 1e-12);
/// assert!(variation < 1e-12);
/// ```
pub fn plane_normal(points: impl Iterator<Item = [f64; 3]> + Clone) -> Option<([f64; 3], f64)> {
    let mut n = 0usize;
    let mut mean = [0.0; 3];
    for p in points.clone() {
        n += 1;
        for a in 0..3 {
            mean[a] += p[a];
        }
    }
    if n < 3 {
        return None;
    }
    let mean = mean.map(|m| m / n as f64);
    // The covariance's entries: xx, yy, zz, xy, xz, yz.
    let mut c = [0.0; 6];
    for p in points {
        let d = [p[0] - mean[0], p[1] - mean[1], p[2] - mean[2]];
        c[0] += d[0] * d[0];
        c[3] += d[0] * d[1];
        c[4] += d[0] * d[2];
        c[1] += d[1] * d[1];
        c[5] += d[1] * d[2];
        c[2] += d[2] * d[2];
    }
    smallest_eigenvector(c)
}

/// PCA normals of every point from its [`Neighbours`] (unit, sign arbitrary until
/// [`crate::orient()`]); `[0, 0, 0]` where the neighbourhood has no unique plane (collinear
/// or coincident neighbours). Computed in parallel; the result does not depend on the
/// thread count.
///
/// ```
/// use cloud_normals::{Neighbours, estimate_normals};
/// let points: Vec<[f64; 3]> = (0..100).map(|i| [(i % 10) as f64, 0.0, (i / 10) as f64]).collect();
/// let normals = estimate_normals(&points, &Neighbours::new(&points, 8)?);
/// assert!(normals.iter().all(|n| (n[1].abs() - 1.0).abs() < 1e-9));
/// # Ok::<(), cloud_normals::NormalsError>(())
/// ```
///
/// # Panics
/// If `neighbours` was built for another cloud (an index out of range).
pub fn estimate_normals(points: &[[f64; 3]], neighbours: &Neighbours) -> Vec<[f64; 3]> {
    let mut normals = vec![[0.0; 3]; neighbours.len()];
    normals
        .par_chunks_mut(CHUNK)
        .enumerate()
        .for_each(|(chunk, out)| {
            for (j, normal) in out.iter_mut().enumerate() {
                let around = neighbours.of(chunk * CHUNK + j);
                let found = plane_normal(around.iter().map(|&v| points[v as usize]));
                *normal = found.map_or([0.0; 3], |(n, _)| n);
            }
        });
    normals
}

/// `passes` of Laplacian smoothing on the neighbour graph: each point moves to the mean of
/// its [`Neighbours`] (itself included), all at once per pass. Reduces noise about `√k`
/// times a pass on a flat surface (edges and corners round off by about a neighbourhood's
/// radius); the neighbour lists stay those of the input points.
///
/// ```
/// use cloud_normals::{Neighbours, smooth_points};
/// let points: Vec<[f64; 3]> = (0..100).map(|i| [(i % 10) as f64, (i / 10) as f64, 0.0]).collect();
/// let smoothed = smooth_points(&points, &Neighbours::new(&points, 5)?, 2);
/// assert!(smoothed.iter().all(|p| p[2] == 0.0));
/// # Ok::<(), cloud_normals::NormalsError>(())
/// ```
///
/// # Panics
/// If `neighbours` was built for another cloud (an index out of range).
pub fn smooth_points(points: &[[f64; 3]], neighbours: &Neighbours, passes: u32) -> Vec<[f64; 3]> {
    let mut current = points.to_vec();
    let mut next = vec![[0.0; 3]; points.len()];
    for _ in 0..passes {
        next.par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(chunk, out)| {
                for (j, p) in out.iter_mut().enumerate() {
                    let around = neighbours.of(chunk * CHUNK + j);
                    let mut sum = [0.0; 3];
                    for &v in around {
                        let q = current[v as usize];
                        for a in 0..3 {
                            sum[a] += q[a];
                        }
                    }
                    *p = sum.map(|s| s / around.len() as f64);
                }
            });
        std::mem::swap(&mut current, &mut next);
    }
    current
}
