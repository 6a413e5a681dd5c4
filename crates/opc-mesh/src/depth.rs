//! Back-projection of 16-bit depth images through a pinhole camera model.

use rayon::prelude::*;

use crate::view::strided_shape;
use crate::{OpcError, OrganizedPointCloud};

/// Pinhole camera intrinsics, in pixels (the names RealSense uses).
///
/// Pixel `(u, v)` (column `u`, row `v`) at depth `z` back-projects to
/// `x = (u − ppx) z / fx`, `y = (v − ppy) z / fy`: the camera frame has `x` to the right,
/// `y` down the image and `z` along the optical axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Intrinsics {
    /// Focal length along image columns (pixels), > 0.
    pub fx: f64,
    /// Focal length along image rows (pixels), > 0.
    pub fy: f64,
    /// Principal point column (pixels).
    pub ppx: f64,
    /// Principal point row (pixels).
    pub ppy: f64,
}

impl Intrinsics {
    /// Intrinsics from focal lengths `fx`, `fy` and principal point `ppx`, `ppy`, all in
    /// pixels.
    pub fn new(fx: f64, fy: f64, ppx: f64, ppy: f64) -> Self {
        Self { fx, fy, ppx, ppy }
    }

    fn validate(&self) -> Result<(), OpcError> {
        positive("intrinsics.fx", self.fx)?;
        positive("intrinsics.fy", self.fy)?;
        finite("intrinsics.ppx", self.ppx)?;
        finite("intrinsics.ppy", self.ppy)
    }
}

/// How to turn a depth image into an organized point cloud.
///
/// ```
/// use opc_mesh::{DepthOptions, Intrinsics};
/// let options = DepthOptions::new(Intrinsics::new(615.0, 615.0, 320.0, 240.0))
///     .with_depth_scale(0.001)
///     .with_stride(2)
///     .with_max_depth(4.0);
/// assert_eq!(options.stride, 2);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct DepthOptions {
    /// The camera model.
    pub intrinsics: Intrinsics,
    /// Metres per depth unit, finite and > 0. Default `0.001` (RealSense: 1 mm).
    pub depth_scale: f64,
    /// Keep every `stride`-th row and column (starting with the first), ≥ 1. Default 1.
    pub stride: usize,
    /// Depths beyond this many metres become invalid (NaN), > 0. Default `f64::INFINITY`.
    pub max_depth: f64,
}

impl DepthOptions {
    /// Options for a camera, with the defaults: depth scale 0.001 m, stride 1, no maximum
    /// depth.
    pub fn new(intrinsics: Intrinsics) -> Self {
        Self {
            intrinsics,
            depth_scale: 0.001,
            stride: 1,
            max_depth: f64::INFINITY,
        }
    }

    /// Sets the metres per depth unit.
    pub fn with_depth_scale(mut self, depth_scale: f64) -> Self {
        self.depth_scale = depth_scale;
        self
    }

    /// Sets the row and column stride.
    pub fn with_stride(mut self, stride: usize) -> Self {
        self.stride = stride;
        self
    }

    /// Sets the maximum depth in metres.
    pub fn with_max_depth(mut self, max_depth: f64) -> Self {
        self.max_depth = max_depth;
        self
    }

    fn validate(&self) -> Result<(), OpcError> {
        self.intrinsics.validate()?;
        positive("depth_scale", self.depth_scale)?;
        if self.max_depth.is_nan() || self.max_depth <= 0.0 {
            return Err(OpcError::InvalidParameter {
                name: "max_depth",
                value: self.max_depth.to_string(),
                expected: "> 0 (infinity allowed)",
            });
        }
        Ok(())
    }
}

impl OrganizedPointCloud {
    /// Back-projects a 16-bit depth image of `rows × cols` pixels (row-major) into an
    /// organized cloud: `z = d · depth_scale`, `x = (u − ppx) z / fx`,
    /// `y = (v − ppy) z / fy` for the pixel in column `u`, row `v`. Depth 0 (no
    /// measurement) and depths beyond `max_depth` give NaN points. With a stride `k` the
    /// cloud has `⌈rows / k⌉ × ⌈cols / k⌉` points, point `(i, j)` coming from pixel
    /// `(i k, j k)` with the full-resolution intrinsics.
    ///
    /// ```
    /// use opc_mesh::{DepthOptions, Intrinsics, OrganizedPointCloud};
    /// let depth = [1000u16, 1000, 0, 2000];
    /// let options = DepthOptions::new(Intrinsics::new(2.0, 2.0, 0.0, 0.0));
    /// let cloud = OrganizedPointCloud::from_depth_image(&depth, 2, 2, &options)?;
    /// assert_eq!(cloud.point(0, 1), [0.5, 0.0, 1.0]);
    /// assert!(cloud.point(1, 0)[2].is_nan());
    /// assert_eq!(cloud.point(1, 1), [1.0, 1.0, 2.0]);
    /// # Ok::<(), opc_mesh::OpcError>(())
    /// ```
    ///
    /// # Errors
    /// [`OpcError::InvalidParameter`] for non-positive or non-finite focal lengths or depth
    /// scale, a non-finite principal point, `max_depth ≤ 0` or NaN, or `stride == 0`;
    /// [`OpcError::DepthLengthMismatch`] if `depth.len() != rows * cols`;
    /// [`OpcError::TooSmall`] if fewer than 2 rows or columns remain after the stride.
    pub fn from_depth_image(
        depth: &[u16],
        rows: usize,
        cols: usize,
        options: &DepthOptions,
    ) -> Result<Self, OpcError> {
        options.validate()?;
        if rows.checked_mul(cols) != Some(depth.len()) {
            return Err(OpcError::DepthLengthMismatch {
                rows,
                cols,
                found: depth.len(),
            });
        }
        let stride = options.stride;
        let (out_rows, out_cols) = strided_shape(rows, cols, stride)?;
        let DepthOptions {
            intrinsics: k,
            depth_scale,
            max_depth,
            ..
        } = *options;
        // x / z for every kept column.
        let x_over_z: Vec<f64> = (0..out_cols)
            .map(|j| ((j * stride) as f64 - k.ppx) / k.fx)
            .collect();
        let mut points = vec![[0.0; 3]; out_rows * out_cols];
        points
            .par_chunks_mut(out_cols)
            .enumerate()
            .for_each(|(i, out)| {
                let v = i * stride;
                let y_over_z = (v as f64 - k.ppy) / k.fy;
                let row = &depth[v * cols..][..cols];
                for ((p, &d), &xz) in out
                    .iter_mut()
                    .zip(row.iter().step_by(stride))
                    .zip(&x_over_z)
                {
                    let z = f64::from(d) * depth_scale;
                    *p = if d == 0 || z > max_depth {
                        [f64::NAN; 3]
                    } else {
                        [xz * z, y_over_z * z, z]
                    };
                }
            });
        Self::new(out_rows, out_cols, points)
    }
}

fn positive(name: &'static str, value: f64) -> Result<(), OpcError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(OpcError::InvalidParameter {
            name,
            value: value.to_string(),
            expected: "finite and > 0",
        })
    }
}

fn finite(name: &'static str, value: f64) -> Result<(), OpcError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(OpcError::InvalidParameter {
            name,
            value: value.to_string(),
            expected: "finite",
        })
    }
}
