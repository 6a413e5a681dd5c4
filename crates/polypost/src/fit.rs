//! Least-squares plane fitting (PCA of the 3×3 covariance) and its fit error.

use crate::PostError;
use crate::plane::Plane;
use plane_geom::{centroid_and_covariance, symmetric_eigen};

/// Options of [`fit_plane_with_options`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct PlaneFitOptions {
    /// If set, the fitted normal is flipped so that `normal · hint >= 0` (e.g. the
    /// direction towards the sensor, or the segment's dominant normal). Default: none, the
    /// normal's sign is then whatever the eigen-solver returns (deterministic for a given
    /// input).
    pub orient_toward: Option<[f64; 3]>,
}

impl PlaneFitOptions {
    /// Orients the fitted normal towards `hint`.
    pub fn with_orient_toward(mut self, hint: [f64; 3]) -> Self {
        self.orient_toward = Some(hint);
        self
    }
}

/// A fitted plane and how well the points fit it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneFit {
    /// The least-squares plane; its `centroid` is the mean of the points.
    pub plane: Plane,
    /// Root mean square of the point-to-plane distances, in metres.
    pub rmse: f64,
    /// Largest absolute point-to-plane distance, in metres.
    pub max_distance: f64,
    /// Number of points fitted.
    pub point_count: usize,
    /// Eigenvalues of the covariance (mean of outer products of centred points),
    /// ascending, in m². The smallest is the mean squared distance to the plane.
    pub eigenvalues: [f64; 3],
}

/// Fits a plane to `points` by least squares (orthogonal regression).
///
/// The normal is the eigenvector of the smallest eigenvalue of the points' covariance
/// (computed around the mean, two passes, so large coordinate offsets do not cost
/// precision); the plane passes through the mean.
///
/// # Errors
/// [`PostError::TooFewPoints`] for fewer than 3 points, [`PostError::NonFinitePoint`] for a
/// NaN or infinite coordinate, [`PostError::DegeneratePoints`] when the points lie on a
/// line or coincide.
pub fn fit_plane(points: &[[f64; 3]]) -> Result<PlaneFit, PostError> {
    fit_plane_with_options(points, &PlaneFitOptions::default())
}

/// [`fit_plane`] with options (normal orientation).
///
/// # Errors
/// As [`fit_plane`].
pub fn fit_plane_with_options(
    points: &[[f64; 3]],
    options: &PlaneFitOptions,
) -> Result<PlaneFit, PostError> {
    fit_iter(points.len(), || points.iter().copied().enumerate(), options)
}

/// Fits a plane to the points `points[i]` for `i` in `indices` (a segment's members),
/// without copying them.
///
/// # Errors
/// As [`fit_plane`], plus [`PostError::IndexOutOfRange`] for an index past the end of
/// `points` (reported before any fitting).
pub fn fit_plane_indexed(
    points: &[[f64; 3]],
    indices: &[u32],
    options: &PlaneFitOptions,
) -> Result<PlaneFit, PostError> {
    if let Some(&index) = indices.iter().find(|&&i| i as usize >= points.len()) {
        return Err(PostError::IndexOutOfRange {
            index,
            len: points.len(),
        });
    }
    fit_iter(
        indices.len(),
        || indices.iter().map(|&i| (i as usize, points[i as usize])),
        options,
    )
}

fn fit_iter<I, F>(count: usize, iter: F, options: &PlaneFitOptions) -> Result<PlaneFit, PostError>
where
    I: Iterator<Item = (usize, [f64; 3])>,
    F: Fn() -> I,
{
    if count < 3 {
        return Err(PostError::TooFewPoints { found: count });
    }
    let Some((mean, covariance)) = centroid_and_covariance(|| iter().map(|(_, p)| p)) else {
        let index = iter()
            .find(|(_, p)| !p.iter().all(|c| c.is_finite()))
            .map_or(0, |(index, _)| index);
        return Err(PostError::NonFinitePoint { index });
    };
    let eig = symmetric_eigen(covariance).ok_or(PostError::SpreadOverflow { count })?;
    let eigenvalues = eig.values.map(|v| v.max(0.0));
    let scale = eigenvalues[2];
    // The plane is undetermined when the spread across the main direction vanishes.
    if scale == 0.0 || eigenvalues[1] <= scale * 1e-18 {
        return Err(PostError::DegeneratePoints {
            count,
            spread: eigenvalues[1],
        });
    }
    let normal = eig.vectors[0];
    let mut plane =
        Plane::from_normal_and_point(normal, mean).map_err(|_| PostError::DegeneratePoints {
            count,
            spread: eigenvalues[1],
        })?;
    if let Some(hint) = options.orient_toward {
        plane = plane.oriented_toward(hint);
    }
    let mut sq = 0.0;
    let mut max_distance = 0.0f64;
    for (_, p) in iter() {
        let d = plane.signed_distance(p);
        sq += d * d;
        max_distance = max_distance.max(d.abs());
    }
    Ok(PlaneFit {
        plane,
        rmse: (sq * (1.0 / count as f64)).sqrt(),
        max_distance,
        point_count: count,
        eigenvalues,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Standard normal sample by Box–Muller.
    fn gauss(rng: &mut ChaCha8Rng) -> f64 {
        let u1: f64 = rng.random_range(f64::EPSILON..1.0);
        let u2: f64 = rng.random_range(0.0..1.0);
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }

    #[test]
    fn exact_plane_is_recovered() {
        let plane = Plane::from_normal_and_point([1.0, 2.0, 2.0], [3.0, 0.0, 1.0]).unwrap();
        let f = plane.frame();
        let pts: Vec<_> = (0..50)
            .map(|i| f.lift([(i % 7) as f64 * 0.3, (i / 7) as f64 * 0.2]))
            .collect();
        let fit = fit_plane_with_options(
            &pts,
            &PlaneFitOptions::default().with_orient_toward([1.0, 1.0, 1.0]),
        )
        .unwrap();
        for k in 0..3 {
            assert!((fit.plane.normal[k] - plane.normal[k]).abs() < 1e-9);
        }
        assert!(fit.rmse < 1e-12);
        assert!(fit.max_distance < 1e-12);
        assert_eq!(fit.point_count, 50);
    }

    #[test]
    fn noisy_plane_normal_and_rmse_match_the_generator() {
        // Oracle: the generating plane and the noise sigma. With n samples the RMSE
        // estimates sigma with relative standard error about 1/sqrt(2n).
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let sigma = 0.01;
        let truth = Plane::from_normal_and_point([-0.3, 0.8, 0.52], [10.0, -20.0, 5.0]).unwrap();
        let f = truth.frame();
        let n = 20_000;
        let pts: Vec<_> = (0..n)
            .map(|_| {
                let q = [rng.random_range(-2.0..2.0), rng.random_range(-1.0..1.0)];
                let p = f.lift(q);
                let e = sigma * gauss(&mut rng);
                [
                    p[0] + e * truth.normal[0],
                    p[1] + e * truth.normal[1],
                    p[2] + e * truth.normal[2],
                ]
            })
            .collect();
        let fit = fit_plane_with_options(
            &pts,
            &PlaneFitOptions::default().with_orient_toward(truth.normal),
        )
        .unwrap();
        let cos = plane_geom::vec3::dot(fit.plane.normal, truth.normal);
        assert!(
            cos > (0.1f64.to_radians()).cos(),
            "normal off by {} deg",
            cos.acos().to_degrees()
        );
        assert!((fit.rmse - sigma).abs() < 0.03 * sigma, "rmse {}", fit.rmse);
        assert!((fit.eigenvalues[0].sqrt() - fit.rmse).abs() < 1e-9);
    }

    #[test]
    fn indexed_fit_equals_fit_of_gathered_points() {
        let pts: Vec<[f64; 3]> = (0..30)
            .map(|i| {
                let i = i as f64;
                [i.sin() * 3.0, i.cos() * 2.0, 0.1 * i.sin() + 5.0]
            })
            .collect();
        let idx: Vec<u32> = (0..30).filter(|i| i % 3 != 0).collect();
        let gathered: Vec<_> = idx.iter().map(|&i| pts[i as usize]).collect();
        let a = fit_plane_indexed(&pts, &idx, &PlaneFitOptions::default()).unwrap();
        let b = fit_plane(&gathered).unwrap();
        assert_eq!(a, b);
    }

    #[test]
    fn bad_inputs_are_errors() {
        assert!(matches!(
            fit_plane(&[[0.0; 3]; 2]),
            Err(PostError::TooFewPoints { found: 2 })
        ));
        let line: Vec<_> = (0..10).map(|i| [i as f64, 2.0 * i as f64, 0.0]).collect();
        assert!(matches!(
            fit_plane(&line),
            Err(PostError::DegeneratePoints { .. })
        ));
        assert!(matches!(
            fit_plane(&[[1.0; 3]; 5]),
            Err(PostError::DegeneratePoints { .. })
        ));
        let nan = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, f64::NAN, 0.0]];
        assert!(matches!(
            fit_plane(&nan),
            Err(PostError::NonFinitePoint { index: 2 })
        ));
        let ok = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert!(matches!(
            fit_plane_indexed(&ok, &[0, 1, 3], &PlaneFitOptions::default()),
            Err(PostError::IndexOutOfRange { index: 3, len: 3 })
        ));
    }
}
