//! How noisy a cloud's surfaces are, relative to its point spacing.

use plane_geom::symmetric_eigenvalues;

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
    let n = around.len() as f64;
    // Offsets from the first point, for precision far from the origin.
    let origin = points[*around.first()? as usize];
    let mut sum = [0.0f64; 3];
    // xx, yy, zz, xy, xz, yz.
    let mut sq = [0.0f64; 6];
    for &v in around {
        let p = points[v as usize];
        let d = [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]];
        for a in 0..3 {
            sum[a] += d[a];
        }
        sq[0] += d[0] * d[0];
        sq[1] += d[1] * d[1];
        sq[2] += d[2] * d[2];
        sq[3] += d[0] * d[1];
        sq[4] += d[0] * d[2];
        sq[5] += d[1] * d[2];
    }
    let m = sum.map(|s| s / n);
    let covariance = [
        sq[0] / n - m[0] * m[0],
        sq[1] / n - m[1] * m[1],
        sq[2] / n - m[2] * m[2],
        sq[3] / n - m[0] * m[1],
        sq[4] / n - m[0] * m[2],
        sq[5] / n - m[1] * m[2],
    ];
    let [low, middle, high] = symmetric_eigenvalues(covariance);
    let spread = (middle * high).sqrt();
    if !(spread.is_finite() && spread > 0.0 && middle > 1e-12 * high) {
        return None;
    }
    let r = low.max(0.0).sqrt() / spread.sqrt();
    r.is_finite().then_some(r)
}
