//! Point-noise estimation for organized clouds, and the trained model that turns it into a
//! Laplacian iteration count for [`crate::laplacian_filter`] (`iterations = "auto"`, 3D paper §9.3.2: "a linear regression
//! model to predict the most suitable number of iterations given an estimate of point
//! cloud noise").

use opc_mesh::OrganizedPointCloud;
use plane_geom::{covariance, symmetric_eigenvalues};
use rayon::prelude::*;

/// At most about this many 3 × 3 neighbourhoods are fitted per cloud (a regular grid of
/// them), so the estimate's cost does not grow with the cloud (the crate README gives a
/// timing).
const TARGET_SAMPLES: usize = 8192;

/// Sampled rows per parallel task of the noise estimate (about 90 fits a row at the
/// target sample count on a 4 : 3 image).
const SAMPLE_ROWS_PER_TASK: usize = 8;

/// Intercept of the trained model `iterations ≈ A + B · estimate_noise(cloud)`.
///
/// Obtained by `cargo run --release -p polylidar --example train_laplacian`: for training
/// seeds 0–5 of `synthscan::synpeb_like` at tangential noise 0.5, 1, 2 and 4 mdeg plus
/// radial noise of 1 or 2.5 mm per mdeg (48 frames, relative noise 0.02–0.30), the
/// `synpeb` preset was run with Laplacian iterations 0, 1, 2, 4, 6, 8, 10, 12, the best
/// count per frame picked by the f score (ties: k, then fewer iterations), and a least-
/// squares line fitted through (estimate, best count): RMS residual 0.44 iterations.
/// Rerun that command to regenerate (it prints the fit).
const MODEL_INTERCEPT: f64 = 0.3538;
/// Slope of the trained model (iterations per unit of relative noise); see
/// [`MODEL_INTERCEPT`].
const MODEL_SLOPE: f64 = 6.343;
/// Largest iteration count the model may predict.
pub const MAX_AUTO_ITERATIONS: u32 = 16;

/// A robust estimate of the point noise of an organized cloud, relative to the point
/// spacing (dimensionless): the median, over a regular grid of up to about 8,192 pixels,
/// of the RMS distance of the pixel's 3 × 3 neighbourhood to its least-squares plane,
/// divided by the neighbourhood's in-plane spacing.
///
/// The in-plane spacing is `√(3/2) · (λ₁λ₂)^¼` for the two larger eigenvalues λ₁, λ₂ of the
/// neighbourhood's covariance, which is exactly the grid step on a regular square grid;
/// the RMS distance is `√λ₀` for the smallest eigenvalue. The ratio is about the tangent of
/// the normals' noise angle, so it does not depend on the length unit, the range or the
/// sensor's resolution. Neighbourhoods with an invalid (NaN) point or with collinear
/// points are skipped; the median keeps the neighbourhoods that straddle a plane edge (a
/// minority) from dominating. A noise-free cloud of planes gives (nearly) 0.
///
/// Returns `None` when no 3 × 3 neighbourhood of the sample is fully valid (an all-NaN
/// cloud, or one smaller than 3 × 3).
///
/// Deterministic; the neighbourhoods are fitted in parallel over the rayon pool.
///
/// ```
/// use mesh_smooth_gpu::estimate_noise;
/// use opc_mesh::OrganizedPointCloud;
///
/// // A 40 × 40 tilted plane with a 1 cm grid step, then the same with ±1 mm bumps.
/// let plane = |bump: f64| -> Vec<[f64; 3]> {
///     (0..1600)
///         .map(|i| {
///             let (r, c) = ((i / 40) as f64 * 0.01, (i % 40) as f64 * 0.01);
///             let z = 0.3 * r + if (i / 40 + i % 40) % 2 == 0 { bump } else { -bump };
///             [c, r, z]
///         })
///         .collect()
/// };
/// let flat = OrganizedPointCloud::new(40, 40, plane(0.0))?;
/// assert!(estimate_noise(&flat).unwrap() < 1e-9);
/// let bumpy = OrganizedPointCloud::new(40, 40, plane(0.001))?;
/// let e = estimate_noise(&bumpy).unwrap();
/// assert!(e > 0.05 && e < 0.2, "{e}");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn estimate_noise(cloud: &OrganizedPointCloud) -> Option<f64> {
    median_of(cloud, |fit| fit.relative())
}

/// As [`estimate_noise`], but the median RMS plane distance itself, in the cloud's length
/// unit (metres for most clouds): not scale-aware, so it depends on range and resolution.
pub fn estimate_noise_absolute(cloud: &OrganizedPointCloud) -> Option<f64> {
    median_of(cloud, |fit| fit.residual())
}

/// The Laplacian iteration count the trained linear model predicts for a cloud whose
/// [`estimate_noise`] is `noise`: `round(A + B · noise)` clamped to
/// `0..=`[`MAX_AUTO_ITERATIONS`] (0: no smoothing). The constants come from
/// `cargo run --release -p polylidar --example train_laplacian` on SynPEB-like synthetic
/// scans with the `synpeb` preset's other parameters.
pub fn predict_laplacian_iterations(noise: f64) -> u32 {
    passes(MODEL_INTERCEPT + MODEL_SLOPE * noise)
}

/// `predicted` rounded to a pass count in `0..=`[`MAX_AUTO_ITERATIONS`] (0 when not
/// positive or not finite).
fn passes(predicted: f64) -> u32 {
    if !predicted.is_finite() || predicted <= 0.0 {
        return 0;
    }
    // In 0..=MAX after the clamp, so the cast is exact.
    predicted.round().min(f64::from(MAX_AUTO_ITERATIONS)) as u32
}

/// [`estimate_noise`] of the cloud taken at every [`CORRELATION_STRIDE`]-th row and
/// column, over [`estimate_noise`] of the cloud itself: how the relative noise changes
/// when the neighbourhoods span three times the pixel spacing.
///
/// Noise that is independent from point to point shrinks relative to the wider spacing
/// (on the synthetic range-scanner suite, whose noise is drawn per point, the ratio is
/// about [`WHITE_NOISE_RATIO`]); noise that is correlated over several pixels (surface
/// ripples of a few centimetres' wavelength, as in the real SynPEB frames: pc_01 ≈ 1.0,
/// pc_02 ≈ 1.55) does not shrink, and a few Laplacian passes, each averaging over a
/// k × k kernel, do not remove it. `None` when either estimate is missing or zero.
///
/// ```
/// use mesh_smooth_gpu::estimate_noise_correlation;
/// use opc_mesh::OrganizedPointCloud;
///
/// // Ripples 12 pixels long: correlated noise.
/// let points: Vec<[f64; 3]> = (0..3600)
///     .map(|i| {
///         let (r, c) = ((i / 60) as f64, (i % 60) as f64);
///         [c * 0.01, r * 0.01, 0.002 * (c * std::f64::consts::TAU / 12.0).sin()]
///     })
///     .collect();
/// let cloud = OrganizedPointCloud::new(60, 60, points)?;
/// assert!(estimate_noise_correlation(&cloud).unwrap() > 1.0);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn estimate_noise_correlation(cloud: &OrganizedPointCloud) -> Option<f64> {
    correlation(cloud, estimate_noise(cloud)?)
}

/// [`estimate_noise_correlation`] for a cloud whose [`estimate_noise`] is `fine`.
fn correlation(cloud: &OrganizedPointCloud, fine: f64) -> Option<f64> {
    let coarse = estimate_noise(&cloud.downsample(CORRELATION_STRIDE).ok()?)?;
    let ratio = coarse / fine;
    (ratio.is_finite() && ratio > 0.0).then_some(ratio)
}

/// The stride of the coarse estimate of [`estimate_noise_correlation`].
pub const CORRELATION_STRIDE: usize = 3;

/// [`estimate_noise_correlation`] of clouds whose noise is independent per point,
/// measured on the synthetic range-scanner suite (`synthscan::synpeb_like` with 20 mm of
/// radial noise: 0.69–0.71); below it the correlation does not change the count.
pub const WHITE_NOISE_RATIO: f64 = 0.7;

/// The Laplacian passes `iterations = "auto"` runs on `cloud`:
/// [`predict_laplacian_iterations`] of its [`estimate_noise`], scaled by
/// `(ratio / WHITE_NOISE_RATIO)²` for its [`estimate_noise_correlation`] `ratio` when
/// that is above [`WHITE_NOISE_RATIO`], and clamped to [`MAX_AUTO_ITERATIONS`].
///
/// The linear model was trained on noise drawn per point; correlated noise has longer
/// wavelengths, and diffusion by repeated averaging needs a number of passes that grows
/// with the square of the wavelength to flatten them. Without this, the model chose 1–2
/// passes for the real SynPEB frames (whose planes then came out empty or shattered)
/// where 4–8 find them.
pub fn auto_laplacian_iterations(cloud: &OrganizedPointCloud) -> u32 {
    let Some(noise) = estimate_noise(cloud) else {
        return 0;
    };
    let factor =
        correlation(cloud, noise).map_or(1.0, |ratio| (ratio / WHITE_NOISE_RATIO).max(1.0).powi(2));
    passes((MODEL_INTERCEPT + MODEL_SLOPE * noise) * factor)
}

/// About this many points are sampled for the median range of [`passes_by_range`].
const RANGE_SAMPLES: usize = 16_384;

/// The Laplacian pass count of every point of `cloud` for
/// the facade's `LaplacianConfig::range_exponent` `exponent`:
/// `round(n · (r / r_median)^exponent)` clamped to `1..=max(n, MAX_AUTO_ITERATIONS)` (and
/// to 255), for its range `r` from the origin and the median range `r_median` of a
/// regular sample of the valid points; invalid points get 0. `None` without a valid point
/// at a positive range.
///
/// ```
/// use mesh_smooth_gpu::passes_by_range;
/// use opc_mesh::OrganizedPointCloud;
///
/// // A 2 × 2 cloud at ranges 1, 2, 3 and 4 m: the median (of the sample) is 3 m.
/// let cloud = OrganizedPointCloud::new(2, 2, vec![
///     [0.0, 0.0, 1.0], [0.0, 0.0, 2.0], [0.0, 0.0, 3.0], [0.0, 0.0, 4.0],
/// ])?;
/// assert_eq!(passes_by_range(&cloud, 6, 1.0), Some(vec![2, 4, 6, 8]));
/// assert_eq!(passes_by_range(&cloud, 6, 2.0), Some(vec![1, 3, 6, 11]));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn passes_by_range(cloud: &OrganizedPointCloud, n: u32, exponent: f64) -> Option<Vec<u8>> {
    let points = cloud.points();
    let squared = |p: &[f64; 3]| p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    let step = (points.len() / RANGE_SAMPLES).max(1);
    let mut sample: Vec<f64> = points
        .iter()
        .step_by(step)
        .map(squared)
        .filter(|r2| r2.is_finite() && *r2 > 0.0)
        .collect();
    if sample.is_empty() {
        return None;
    }
    let mid = sample.len() / 2;
    let (_, &mut median, _) = sample.select_nth_unstable_by(mid, f64::total_cmp);
    // round(n (r / r_m)^e) ≥ k  ⇔  r² ≥ r_m² ((k − ½) / n)^(2 / e): the squared range at
    // which each count from 2 up starts.
    let upper = n.max(MAX_AUTO_ITERATIONS).min(u32::from(u8::MAX));
    let starts: Vec<f64> = (2..=upper)
        .map(|k| median * ((f64::from(k) - 0.5) / f64::from(n)).powf(2.0 / exponent))
        .collect();
    let mut passes = vec![0u8; points.len()];
    passes
        .par_chunks_mut(4096)
        .zip(points.par_chunks(4096))
        .for_each(|(out, points)| {
            for (o, p) in out.iter_mut().zip(points) {
                let r2 = squared(p);
                if r2.is_finite() {
                    // At most upper ≤ 255. Counted from the front: most points lie
                    // before the first few starts, where a binary search mispredicts.
                    *o = (1 + starts.iter().take_while(|&&s| s <= r2).count()) as u8;
                }
            }
        });
    Some(passes)
}

/// The eigenvalues λ₀ ≤ λ₁ ≤ λ₂ of one neighbourhood's covariance.
#[derive(Clone, Copy)]
struct Fit {
    eigen: [f64; 3],
}

impl Fit {
    fn residual(self) -> Option<f64> {
        Some(self.eigen[0].max(0.0).sqrt())
    }

    fn relative(self) -> Option<f64> {
        let spread = (self.eigen[1] * self.eigen[2]).sqrt();
        if spread.is_nan() || spread <= 0.0 {
            return None;
        }
        let spacing = (1.5 * spread).sqrt();
        let r = self.eigen[0].max(0.0).sqrt() / spacing;
        r.is_finite().then_some(r)
    }
}

/// The median of `value` over the fitted sample neighbourhoods.
fn median_of(
    cloud: &OrganizedPointCloud,
    value: impl Fn(Fit) -> Option<f64> + Sync,
) -> Option<f64> {
    let (rows, cols) = (cloud.rows(), cloud.cols());
    if rows < 3 || cols < 3 {
        return None;
    }
    let inner = (rows - 2) * (cols - 2);
    // The smallest step s with ⌈(rows−2)/s⌉·⌈(cols−2)/s⌉ ≲ TARGET_SAMPLES.
    let step = ((inner as f64 / TARGET_SAMPLES as f64).sqrt().ceil() as usize).max(1);
    let first = |n: usize| 1 + ((n - 2) % step) / 2;
    let points = cloud.points();
    // The sampled rows in parallel: the median does not depend on the values' order.
    let sampled: Vec<usize> = (first(rows)..rows - 1).step_by(step).collect();
    let value = &value;
    let mut values: Vec<f64> = sampled
        .par_iter()
        .with_min_len(SAMPLE_ROWS_PER_TASK)
        .flat_map_iter(|&r| {
            (first(cols)..cols - 1)
                .step_by(step)
                .filter_map(move |c| fit(points, cols, r, c).and_then(value))
        })
        .collect();
    if values.is_empty() {
        return None;
    }
    let mid = values.len() / 2;
    let (_, m, _) = values.select_nth_unstable_by(mid, f64::total_cmp);
    Some(*m)
}

/// The covariance eigenvalues of the 3 × 3 neighbourhood of pixel `(r, c)` (not on the
/// border), or `None` if a point is invalid.
#[inline]
fn fit(points: &[[f64; 3]], cols: usize, r: usize, c: usize) -> Option<Fit> {
    let centre = points[r * cols + c];
    let window = points[(r - 1) * cols..(r + 2) * cols]
        .chunks_exact(cols)
        .flat_map(|row| &row[c - 1..c + 2])
        .copied();
    // Offsets from the centre point, for precision.
    let a = covariance(centre, window)?;
    Some(Fit {
        eigen: symmetric_eigenvalues(a),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    use rand::{RngExt, SeedableRng};

    /// A 60 × 80 tilted plane with uniform noise of ±1 cm and a few holes.
    fn noisy_cloud() -> OrganizedPointCloud {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let points = (0..60 * 80)
            .map(|i| {
                let (r, c) = ((i / 80) as f64 * 0.02, (i % 80) as f64 * 0.02);
                if rng.random_bool(0.03) {
                    [f64::NAN; 3]
                } else {
                    [c, r, 2.0 + 0.4 * r + rng.random_range(-0.01..0.01)]
                }
            })
            .collect();
        OrganizedPointCloud::new(60, 80, points).unwrap()
    }

    #[test]
    fn estimate_is_the_median_over_every_neighbourhood_on_any_thread_count() {
        let cloud = noisy_cloud();
        // Below the target sample count every inner pixel is sampled.
        let mut all: Vec<f64> = (1..59)
            .flat_map(|r| (1..79).map(move |c| (r, c)))
            .filter_map(|(r, c)| fit(cloud.points(), 80, r, c).and_then(Fit::relative))
            .collect();
        assert!(all.len() > 3000, "{}", all.len());
        all.sort_by(f64::total_cmp);
        let median = all[all.len() / 2];
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            assert_eq!(pool.install(|| estimate_noise(&cloud)), Some(median));
        }
    }

    #[test]
    fn prediction_is_clamped() {
        assert!(predict_laplacian_iterations(1e9) <= MAX_AUTO_ITERATIONS);
        assert_eq!(predict_laplacian_iterations(f64::NAN), 0);
    }
}
