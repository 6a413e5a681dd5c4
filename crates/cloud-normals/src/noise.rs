//! How noisy a cloud's surfaces are, relative to its point spacing.

use plane_geom::{covariance, symmetric_eigenvalues};

use crate::Neighbours;

/// Neighbourhoods fitted per cloud at most (an even sample of the points), so that the
/// estimate's cost does not grow with the cloud.
pub const NOISE_SAMPLES: usize = 8192;

/// A robust estimate of the point noise of an unorganized cloud relative to its point
/// spacing (dimensionless): the median, over an even sample of at most [`NOISE_SAMPLES`]
/// points, of `√λ₀ / (λ₁λ₂)^¼` for the eigenvalues `λ₀ ≤ λ₁ ≤ λ₂` of the covariance of
/// the point's [`Neighbours`] — the RMS distance of the neighbourhood to its best plane
/// over the geometric mean of its two in-plane spreads.
///
/// The ratio is about the tangent of the normals' noise angle, so it depends neither on
/// the length unit nor on the sampling density (for a given `k`). The median keeps the
/// neighbourhoods that straddle an edge (a minority on scans of planes) from dominating;
/// neighbourhoods on one line or one spot are skipped. A noise-free cloud of planes gives
/// (nearly) 0. `None` when no sampled neighbourhood spans a plane.
///
/// Deterministic and single-threaded.
///
/// ```
/// use cloud_normals::{Neighbours, neighbourhood_noise};
///
/// // A 40 × 40 floor on a 1 cm grid, then the same with ±1 mm bumps.
/// let floor = |bump: f64| -> Vec<[f64; 3]> {
///     (0..1600)
///         .map(|i| {
///             let z = if (i / 40 + i % 40) % 2 == 0 { bump } else { -bump };
///             [0.01 * (i % 40) as f64, 0.01 * (i / 40) as f64, z]
///         })
///         .collect()
/// };
/// let flat = floor(0.0);
/// assert!(neighbourhood_noise(&flat, &Neighbours::new(&flat, 12)?).unwrap() < 1e-6);
/// let bumpy = floor(0.001);
/// let e = neighbourhood_noise(&bumpy, &Neighbours::new(&bumpy, 12)?).unwrap();
/// assert!(e > 0.05 && e < 0.2, "{e}");
/// # Ok::<(), cloud_normals::NormalsError>(())
/// ```
///
/// # Panics
/// If `neighbours` was built for another cloud (an index out of range).
pub fn neighbourhood_noise(points: &[[f64; 3]], neighbours: &Neighbours) -> Option<f64> {
    let step = neighbours.len().div_ceil(NOISE_SAMPLES).max(1);
    let mut values: Vec<f64> = (0..neighbours.len())
        .step_by(step)
        .filter_map(|i| relative_noise(points, neighbours.of(i)))
        .collect();
    if values.is_empty() {
        return None;
    }
    let mid = values.len() / 2;
    Some(*values.select_nth_unstable_by(mid, f64::total_cmp).1)
}

/// `√λ₀ / (λ₁λ₂)^¼` of the covariance of the points `around`; `None` when they span no
/// plane.
fn relative_noise(points: &[[f64; 3]], around: &[u32]) -> Option<f64> {
    // Offsets from the first point, for precision far from the origin.
    let origin = points[*around.first()? as usize];
    let covariance = covariance(origin, around.iter().map(|&v| points[v as usize]))?;
    let [low, middle, high] = symmetric_eigenvalues(covariance);
    let spread = (middle * high).sqrt();
    if !(spread.is_finite() && spread > 0.0 && middle > 1e-12 * high) {
        return None;
    }
    let r = low.max(0.0).sqrt() / spread.sqrt();
    r.is_finite().then_some(r)
}

/// Largest pass count [`predict_smoothing_passes`] predicts.
pub const MAX_AUTO_PASSES: u32 = 16;

/// Intercept of the trained model `passes ≈ A + B · neighbourhood_noise(cloud)` behind
/// the facade's `unorganized.smoothing = "auto"` (passes of [`crate::smooth_points`]).
///
/// Obtained by `cargo run --release -p polylidar --example train_unorganized_smoothing`:
/// seeds 0–3 of `synthscan::synpeb_like` at 1 mdeg of tangential and 0, 5, 10, 20 or
/// 30 mm of radial noise, each scan shuffled into an unorganized cloud, the `room` preset
/// (`norm_thresh` 0.85) run with 0, 1, 2, 4, 6, 8, 10, 12 and 16 passes; per noise level
/// the count with the best mean f (0, 1, 2, 12, 10 passes at mean estimates 0.003, 0.22,
/// 0.39, 0.54, 0.59), and a least-squares line through them: RMS residual 2.5 passes (the
/// f scores of 4 to 12 passes lie within 3 points of each other at 20 and 30 mm, so the
/// best count is loosely determined there). Rerun that command to regenerate (it prints
/// the fit).
const SMOOTHING_INTERCEPT: f64 = -2.0016;
/// Slope of the trained smoothing model (passes per unit of relative noise); see
/// [`SMOOTHING_INTERCEPT`].
const SMOOTHING_SLOPE: f64 = 19.9540;

/// The point-smoothing passes the trained linear model predicts for an unorganized cloud
/// whose [`neighbourhood_noise`] is `noise` (the unorganized path's
/// `smoothing = "auto"`): `round(A + B · noise)` clamped to
/// `0..=`[`MAX_AUTO_PASSES`] (0: no smoothing; 0 too for a `noise` that is not finite).
///
/// ```
/// use cloud_normals::predict_smoothing_passes;
/// assert_eq!(predict_smoothing_passes(0.0), 0);
/// assert!(predict_smoothing_passes(0.5) > predict_smoothing_passes(0.1));
/// ```
pub fn predict_smoothing_passes(noise: f64) -> u32 {
    let predicted = SMOOTHING_INTERCEPT + SMOOTHING_SLOPE * noise;
    if !predicted.is_finite() || predicted <= 0.0 {
        return 0;
    }
    // In 0..=MAX after the clamp, so the cast is exact.
    predicted.round().min(f64::from(MAX_AUTO_PASSES)) as u32
}
