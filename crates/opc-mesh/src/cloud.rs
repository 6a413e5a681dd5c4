//! The [`OrganizedPointCloud`] type.

use crate::OpcError;

/// A point cloud laid out as an image: `rows × cols` points in row-major order, `f64` xyz,
/// with NaN coordinates marking invalid pixels (no return, no depth).
///
/// Point `(r, c)` has index `r * cols + c`, which is also its vertex index in the mesh built
/// from the cloud.
///
/// ```
/// use opc_mesh::OrganizedPointCloud;
/// let points = vec![[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0], [f64::NAN; 3]];
/// let cloud = OrganizedPointCloud::new(2, 2, points)?;
/// assert_eq!(cloud.point(1, 0), [0.0, 1.0, 1.0]);
/// assert_eq!(cloud.num_valid(), 3);
/// # Ok::<(), opc_mesh::OpcError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct OrganizedPointCloud {
    rows: usize,
    cols: usize,
    points: Vec<[f64; 3]>,
}

impl OrganizedPointCloud {
    /// Wraps `rows × cols` points given row by row.
    ///
    /// # Errors
    /// [`OpcError::TooSmall`] if `rows` or `cols` is below 2, [`OpcError::LengthMismatch`]
    /// if `points.len() != rows * cols`, [`OpcError::TooLarge`] beyond `u32` indices.
    pub fn new(rows: usize, cols: usize, points: Vec<[f64; 3]>) -> Result<Self, OpcError> {
        if rows < 2 || cols < 2 {
            return Err(OpcError::TooSmall { rows, cols });
        }
        let expected = rows.checked_mul(cols).ok_or(OpcError::TooLarge { rows, cols })?;
        if expected > u32::MAX as usize / 2 {
            return Err(OpcError::TooLarge { rows, cols });
        }
        if points.len() != expected {
            return Err(OpcError::LengthMismatch {
                rows,
                cols,
                found: points.len(),
            });
        }
        Ok(Self { rows, cols, points })
    }

    /// Number of image rows.
    #[inline]
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Number of image columns.
    #[inline]
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// All points, row-major.
    #[inline]
    pub fn points(&self) -> &[[f64; 3]] {
        &self.points
    }

    /// Mutable access to the points (the shape cannot change).
    #[inline]
    pub fn points_mut(&mut self) -> &mut [[f64; 3]] {
        &mut self.points
    }

    /// Gives the points back.
    pub fn into_points(self) -> Vec<[f64; 3]> {
        self.points
    }

    /// The point at row `r`, column `c`.
    ///
    /// # Panics
    /// If `r >= rows` or `c >= cols`, like slice indexing.
    #[inline]
    pub fn point(&self, r: usize, c: usize) -> [f64; 3] {
        assert!(c < self.cols, "column {c} out of range for {} columns", self.cols);
        self.points[r * self.cols + c]
    }

    /// Number of valid (non-NaN) points.
    pub fn num_valid(&self) -> usize {
        self.points.iter().filter(|p| is_valid(p)).count()
    }
}

/// Whether a point is valid: all three coordinates finite.
#[inline]
pub fn is_valid(p: &[f64; 3]) -> bool {
    p[0].is_finite() && p[1].is_finite() && p[2].is_finite()
}
