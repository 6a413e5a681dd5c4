//! Options of the organized-cloud filters.

use crate::SmoothError;

/// Largest kernel side of either filter: 15 × 15 pixels (the papers use 3 and 5; the work
/// of a pass grows with the square of the side).
pub const MAX_KERNEL: u32 = 15;

/// Most passes of either filter (the papers use 2 to 8; the predicted Laplacian count is
/// at most 16).
pub const MAX_ITERATIONS: u32 = 1000;

/// Options of the Laplacian vertex filter on an organized cloud (Polylidar3D Eq. 1–2).
///
/// `v' = v + λ (Σ w_j v_j / Σ w_j − v)` with `w_j = 1 / (‖v − v_j‖ + ε)` over the
/// `kernel × kernel` pixel neighbourhood of `v` (itself excluded, NaN neighbours skipped),
/// repeated `iterations` times, each iteration reading only the previous one's output.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct LaplacianOptions {
    /// Side of the square pixel neighbourhood: odd, 3 to [`MAX_KERNEL`]. Pixels closer than
    /// `kernel / 2` to the image edge are not filtered. Default 3.
    pub kernel: u32,
    /// Step towards the weighted neighbour mean, in (0, 1]: 1 moves to the mean, smaller
    /// steps part of the way (Polylidar3D Eq. 2). Larger steps overshoot and negative ones
    /// roughen the surface, so both are refused. Default 1.0.
    pub lambda: f32,
    /// Number of passes, 0 to [`MAX_ITERATIONS`]. Default 2.
    pub iterations: u32,
    /// ε of the inverse-distance weights, in the cloud's length unit; finite and > 0.
    /// Default 1e-6.
    pub epsilon: f32,
}

impl Default for LaplacianOptions {
    fn default() -> Self {
        Self {
            kernel: 3,
            lambda: 1.0,
            iterations: 2,
            epsilon: 1e-6,
        }
    }
}

impl LaplacianOptions {
    /// The defaults (kernel 3, λ 1, 2 iterations, ε 1e-6).
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets [`Self::kernel`].
    pub fn with_kernel(mut self, kernel: u32) -> Self {
        self.kernel = kernel;
        self
    }

    /// Sets [`Self::lambda`].
    pub fn with_lambda(mut self, lambda: f32) -> Self {
        self.lambda = lambda;
        self
    }

    /// Sets [`Self::iterations`].
    pub fn with_iterations(mut self, iterations: u32) -> Self {
        self.iterations = iterations;
        self
    }

    /// Sets [`Self::epsilon`].
    pub fn with_epsilon(mut self, epsilon: f32) -> Self {
        self.epsilon = epsilon;
        self
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`SmoothError::InvalidKernel`] or [`SmoothError::InvalidParameter`].
    pub fn validate(&self) -> Result<(), SmoothError> {
        check_kernel(self.kernel)?;
        if !(self.lambda > 0.0 && self.lambda <= 1.0) {
            return Err(invalid("lambda", self.lambda, "must be in (0, 1]"));
        }
        check_iterations(self.iterations)?;
        if !(self.epsilon.is_finite() && self.epsilon > 0.0) {
            return Err(invalid("epsilon", self.epsilon, "must be finite and > 0"));
        }
        Ok(())
    }
}

/// Options of the bilateral normal filter on the implicit mesh of an organized cloud
/// (Polylidar3D Eq. 3–5, after Zheng et al.).
///
/// For each triangle with normal `n` and centroid `c`,
/// `n' = normalize(Σ W_s W_r n_j / Σ W_s W_r)` with `W_s = exp(−‖c − c_j‖² / σ_l²)` and
/// `W_r = exp(−‖n − n_j‖² / σ_a²)`, over both triangles of every cell in the
/// `kernel × kernel` cell neighbourhood except the triangle's own cell, missing triangles
/// skipped; repeated `iterations` times. Centroids stay fixed: only normals change.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct BilateralOptions {
    /// Side of the square cell neighbourhood: odd, 3 to [`MAX_KERNEL`]. Cells closer than
    /// `kernel / 2` to the edge of the cell grid keep their unfiltered normals. Default 3.
    pub kernel: u32,
    /// σ_l, the spatial scale, in the cloud's length unit; finite and > 0. Default 0.1.
    pub sigma_length: f32,
    /// σ_a, the normal-difference scale: a Euclidean distance between unit normals
    /// (0 to 2; 0.1 ≈ 5.7°); finite and > 0. Default 0.1.
    pub sigma_angle: f32,
    /// Number of passes, 0 to [`MAX_ITERATIONS`]; 0 returns the unfiltered normals.
    /// Default 2.
    pub iterations: u32,
}

impl Default for BilateralOptions {
    fn default() -> Self {
        Self {
            kernel: 3,
            sigma_length: 0.1,
            sigma_angle: 0.1,
            iterations: 2,
        }
    }
}

impl BilateralOptions {
    /// The defaults (kernel 3, σ_l 0.1, σ_a 0.1, 2 iterations).
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets [`Self::kernel`].
    pub fn with_kernel(mut self, kernel: u32) -> Self {
        self.kernel = kernel;
        self
    }

    /// Sets [`Self::sigma_length`].
    pub fn with_sigma_length(mut self, sigma_length: f32) -> Self {
        self.sigma_length = sigma_length;
        self
    }

    /// Sets [`Self::sigma_angle`].
    pub fn with_sigma_angle(mut self, sigma_angle: f32) -> Self {
        self.sigma_angle = sigma_angle;
        self
    }

    /// Sets [`Self::iterations`].
    pub fn with_iterations(mut self, iterations: u32) -> Self {
        self.iterations = iterations;
        self
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`SmoothError::InvalidKernel`] or [`SmoothError::InvalidParameter`].
    pub fn validate(&self) -> Result<(), SmoothError> {
        check_kernel(self.kernel)?;
        check_iterations(self.iterations)?;
        check_sigma("sigma_length", self.sigma_length)?;
        check_sigma("sigma_angle", self.sigma_angle)
    }

    /// `1 / σ_l²` and `1 / σ_a²`, the factors every backend multiplies by.
    pub(crate) fn inverse_variances(&self) -> (f32, f32) {
        (
            1.0 / (self.sigma_length * self.sigma_length),
            1.0 / (self.sigma_angle * self.sigma_angle),
        )
    }
}

/// Refuses per-pixel pass counts that are not one per point of `cloud`.
pub(crate) fn check_passes(
    passes: &[u8],
    cloud: &opc_mesh::OrganizedPointCloud,
) -> Result<(), SmoothError> {
    if passes.len() == cloud.points().len() {
        return Ok(());
    }
    Err(SmoothError::InvalidParameter {
        name: "passes",
        value: passes.len() as f64,
        reason: "needs one pass count per point of the cloud",
    })
}

fn check_kernel(kernel: u32) -> Result<(), SmoothError> {
    if kernel < 3 || kernel.is_multiple_of(2) || kernel > MAX_KERNEL {
        return Err(SmoothError::InvalidKernel { kernel });
    }
    Ok(())
}

fn check_iterations(iterations: u32) -> Result<(), SmoothError> {
    if iterations > MAX_ITERATIONS {
        return Err(SmoothError::InvalidParameter {
            name: "iterations",
            value: f64::from(iterations),
            reason: "must be at most 1000 (mesh_smooth_gpu::MAX_ITERATIONS)",
        });
    }
    Ok(())
}

fn check_sigma(name: &'static str, sigma: f32) -> Result<(), SmoothError> {
    let inverse_variance = 1.0 / (sigma * sigma);
    if !(sigma.is_finite() && sigma > 0.0 && inverse_variance.is_finite()) {
        return Err(invalid(
            name,
            sigma,
            "must be finite and > 0 (and not so small that 1/σ² overflows)",
        ));
    }
    Ok(())
}

fn invalid(name: &'static str, value: f32, reason: &'static str) -> SmoothError {
    SmoothError::InvalidParameter {
        name,
        value: f64::from(value),
        reason,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid() {
        assert!(LaplacianOptions::default().validate().is_ok());
        assert!(BilateralOptions::default().validate().is_ok());
    }

    #[test]
    fn bad_kernels_are_rejected() {
        for kernel in [0, 1, 2, 4, 6] {
            assert_eq!(
                LaplacianOptions::new().with_kernel(kernel).validate(),
                Err(SmoothError::InvalidKernel { kernel })
            );
            assert!(
                BilateralOptions::new()
                    .with_kernel(kernel)
                    .validate()
                    .is_err()
            );
        }
        assert!(LaplacianOptions::new().with_kernel(7).validate().is_ok());
        for kernel in [MAX_KERNEL + 2, 101, u32::MAX] {
            assert_eq!(
                LaplacianOptions::new().with_kernel(kernel).validate(),
                Err(SmoothError::InvalidKernel { kernel })
            );
            assert_eq!(
                BilateralOptions::new().with_kernel(kernel).validate(),
                Err(SmoothError::InvalidKernel { kernel })
            );
        }
        assert!(
            LaplacianOptions::new()
                .with_kernel(MAX_KERNEL)
                .validate()
                .is_ok()
        );
    }

    #[test]
    fn lambda_must_be_a_step_in_zero_to_one() {
        for lambda in [
            0.0,
            -1.0,
            1.0001,
            2.0,
            10.0,
            1e30,
            -1e30,
            f32::INFINITY,
            f32::NAN,
        ] {
            let err = LaplacianOptions::new()
                .with_lambda(lambda)
                .validate()
                .unwrap_err();
            assert!(
                matches!(err, SmoothError::InvalidParameter { name: "lambda", .. }),
                "{lambda}: {err}"
            );
        }
        for lambda in [1e-3, 0.5, 1.0] {
            assert!(
                LaplacianOptions::new()
                    .with_lambda(lambda)
                    .validate()
                    .is_ok()
            );
        }
    }

    #[test]
    fn iterations_are_bounded() {
        for iterations in [MAX_ITERATIONS + 1, u32::MAX] {
            assert!(
                LaplacianOptions::new()
                    .with_iterations(iterations)
                    .validate()
                    .is_err()
            );
            assert!(
                BilateralOptions::new()
                    .with_iterations(iterations)
                    .validate()
                    .is_err()
            );
        }
        assert!(
            LaplacianOptions::new()
                .with_iterations(MAX_ITERATIONS)
                .validate()
                .is_ok()
        );
        assert!(
            BilateralOptions::new()
                .with_iterations(0)
                .validate()
                .is_ok()
        );
    }

    #[test]
    fn bad_numbers_are_rejected() {
        assert!(
            LaplacianOptions::new()
                .with_lambda(f32::NAN)
                .validate()
                .is_err()
        );
        assert!(
            LaplacianOptions::new()
                .with_epsilon(0.0)
                .validate()
                .is_err()
        );
        assert!(
            BilateralOptions::new()
                .with_sigma_length(0.0)
                .validate()
                .is_err()
        );
        assert!(
            BilateralOptions::new()
                .with_sigma_angle(-1.0)
                .validate()
                .is_err()
        );
        assert!(
            BilateralOptions::new()
                .with_sigma_angle(1e-30)
                .validate()
                .is_err()
        );
        assert!(
            BilateralOptions::new()
                .with_sigma_length(f32::INFINITY)
                .validate()
                .is_err()
        );
    }
}
