//! Consistent normal orientation.

use plane_geom::vec3::dot;
use rayon::prelude::*;

use crate::NormalsError;

/// Which way normals should point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Orientation {
    /// Towards a viewpoint (the sensor of a scan, a PCD file's `VIEWPOINT`): `n · (v − p) ≥ 0`.
    Towards([f64; 3]),
    /// Into the half-space of a direction (`+z` for airborne data): `n · u ≥ 0`. Normals
    /// nearly orthogonal to it (within [`SIDE_COS`], walls and façades) take the sign
    /// that points them along a fixed horizontal direction at 30° from the first axis
    /// orthogonal to `u`, so that one wall's normals agree with each other.
    Along([f64; 3]),
}

/// [`Orientation::Along`]: below this `|n · u|` a normal counts as orthogonal to `u`.
pub const SIDE_COS: f64 = 0.3;

/// Flips `normals` (one per point of `points`) to the side `orientation` asks for. Zero
/// normals stay zero.
///
/// ```
/// use cloud_normals::{Orientation, orient};
/// let points = [[0.0, 0.0, 0.0], [0.0, 0.0, 5.0]];
/// let mut normals = [[0.0, 0.0, -1.0], [0.0, 0.0, 1.0]];
/// orient(&points, &mut normals, Orientation::Towards([0.0, 0.0, 2.0]))?;
/// assert_eq!(normals, [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]);
/// # Ok::<(), cloud_normals::NormalsError>(())
/// ```
///
/// # Errors
/// [`NormalsError::BadOrientation`] for a non-finite viewpoint or a zero or non-finite
/// direction.
///
/// # Panics
/// If `normals` is longer than `points`.
pub fn orient(
    points: &[[f64; 3]],
    normals: &mut [[f64; 3]],
    orientation: Orientation,
) -> Result<(), NormalsError> {
    let bad = || NormalsError::BadOrientation(format!("{orientation:?}"));
    match orientation {
        Orientation::Towards(v) => {
            if !v.iter().all(|c| c.is_finite()) {
                return Err(bad());
            }
            normals
                .par_iter_mut()
                .zip(points.par_iter())
                .for_each(|(n, p)| {
                    if dot(*n, [v[0] - p[0], v[1] - p[1], v[2] - p[2]]) < 0.0 {
                        *n = n.map(|c| -c);
                    }
                });
        }
        Orientation::Along(u) => {
            let len = dot(u, u).sqrt();
            if !(len.is_finite() && len > 0.0) {
                return Err(bad());
            }
            let u = u.map(|c| c / len);
            let side = side_direction(u);
            normals.par_iter_mut().for_each(|n| {
                let along = dot(*n, u);
                let flip = if along.abs() >= SIDE_COS {
                    along < 0.0
                } else {
                    dot(*n, side) < 0.0
                };
                if flip {
                    *n = n.map(|c| -c);
                }
            });
        }
    }
    Ok(())
}

/// A unit direction orthogonal to unit `u`, 30° from the first of `x`, `y` projected
/// orthogonally to `u` that is not parallel to it.
fn side_direction(u: [f64; 3]) -> [f64; 3] {
    let axis = if u[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let d = dot(axis, u);
    let e1 = unit([axis[0] - d * u[0], axis[1] - d * u[1], axis[2] - d * u[2]]);
    let e2 = [
        u[1] * e1[2] - u[2] * e1[1],
        u[2] * e1[0] - u[0] * e1[2],
        u[0] * e1[1] - u[1] * e1[0],
    ];
    let (s, c) = 30f64.to_radians().sin_cos();
    [
        c * e1[0] + s * e2[0],
        c * e1[1] + s * e2[1],
        c * e1[2] + s * e2[2],
    ]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let len = dot(a, a).sqrt();
    a.map(|c| c / len)
}
