//! The owned [`OrganizedPointCloud`] and its construction from flat buffers.

use crate::{OpcError, OrganizedPointCloudView};

/// A point cloud laid out as an image: `rows × cols` points in row-major order, `f64` xyz,
/// with NaN coordinates marking invalid pixels (no return, no depth).
///
/// Point `(r, c)` has index `r * cols + c`, which is also its vertex index in the mesh built
/// from the cloud.
///
/// Ways to build one, and what each costs:
///
/// | from | call | copies the points? |
/// | --- | --- | --- |
/// | `Vec<[f64; 3]>` | [`OrganizedPointCloud::new`] | no (moved) |
/// | `Vec<f64>`, `(rows, cols, 3)` layout | [`OrganizedPointCloud::from_flat_vec`] | no, if the capacity is a multiple of 3 |
/// | `&[f64]` (e.g. a numpy `(H, W, 3)` `float64` buffer) | [`OrganizedPointCloudView::from_flat`] | no (borrowed view) |
/// | `&[f64]`, owned result | [`OrganizedPointCloud::from_flat`] | one copy |
/// | 16-bit depth image | [`OrganizedPointCloud::from_depth_image`] | computed |
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
    /// Wraps `rows × cols` points given row by row (no copy).
    ///
    /// # Errors
    /// [`OpcError::TooSmall`] if `rows` or `cols` is below 2, [`OpcError::LengthMismatch`]
    /// if `points.len() != rows * cols`, [`OpcError::TooLarge`] beyond `u32` indices.
    pub fn new(rows: usize, cols: usize, points: Vec<[f64; 3]>) -> Result<Self, OpcError> {
        check_shape(rows, cols, points.len())?;
        Ok(Self { rows, cols, points })
    }

    /// Copies a flat, row-major `(rows, cols, 3)` buffer of coordinates
    /// (`x0, y0, z0, x1, …`). Use [`OrganizedPointCloudView::from_flat`] to borrow it
    /// instead.
    ///
    /// # Errors
    /// [`OpcError::FlatLengthMismatch`] if `flat.len() != rows * cols * 3`, and the errors
    /// of [`Self::new`].
    pub fn from_flat(rows: usize, cols: usize, flat: &[f64]) -> Result<Self, OpcError> {
        Ok(OrganizedPointCloudView::from_flat(rows, cols, flat)?.to_cloud())
    }

    /// Takes a flat, row-major `(rows, cols, 3)` vector of coordinates. The allocation is
    /// reused without copying when its capacity is a multiple of 3 (always the case for a
    /// vector built with exactly `rows * cols * 3` elements); otherwise the points are
    /// copied once.
    ///
    /// ```
    /// use opc_mesh::OrganizedPointCloud;
    /// let flat = vec![0.0, 0.0, 1.0, 1.0, 0.0, 1.0, 0.0, 1.0, 1.0, 1.0, 1.0, 1.0];
    /// let cloud = OrganizedPointCloud::from_flat_vec(2, 2, flat)?;
    /// assert_eq!(cloud.point(1, 1), [1.0, 1.0, 1.0]);
    /// # Ok::<(), opc_mesh::OpcError>(())
    /// ```
    ///
    /// # Errors
    /// As [`Self::from_flat`].
    pub fn from_flat_vec(rows: usize, cols: usize, flat: Vec<f64>) -> Result<Self, OpcError> {
        check_flat(rows, cols, flat.len())?;
        let points = match bytemuck::allocation::try_cast_vec::<f64, [f64; 3]>(flat) {
            Ok(points) => points,
            Err((_, flat)) => flat_points(rows, cols, &flat)?.to_vec(),
        };
        Self::new(rows, cols, points)
    }

    /// Wraps a shape already checked by [`check_shape`].
    pub(crate) fn from_checked(rows: usize, cols: usize, points: Vec<[f64; 3]>) -> Self {
        debug_assert!(check_shape(rows, cols, points.len()).is_ok());
        Self { rows, cols, points }
    }

    /// A borrowed view of this cloud.
    #[inline]
    pub fn view(&self) -> OrganizedPointCloudView<'_> {
        OrganizedPointCloudView::from_checked(self.rows, self.cols, &self.points)
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
        self.view().point(r, c)
    }

    /// Number of valid (finite) points.
    pub fn num_valid(&self) -> usize {
        self.view().num_valid()
    }

    /// Keeps every `stride`-th row and column, starting with the first: the result has
    /// `⌈rows / stride⌉ × ⌈cols / stride⌉` points and point `(r, c)` is point
    /// `(r · stride, c · stride)` of this cloud.
    ///
    /// ```
    /// use opc_mesh::OrganizedPointCloud;
    /// let points: Vec<[f64; 3]> = (0..20).map(|i| [i as f64, 0.0, 1.0]).collect();
    /// let cloud = OrganizedPointCloud::new(4, 5, points)?;
    /// let small = cloud.downsample(2)?;
    /// assert_eq!((small.rows(), small.cols()), (2, 3));
    /// assert_eq!(small.point(1, 2), cloud.point(2, 4));
    /// # Ok::<(), opc_mesh::OpcError>(())
    /// ```
    ///
    /// # Errors
    /// [`OpcError::InvalidParameter`] for `stride == 0`, [`OpcError::TooSmall`] if fewer
    /// than 2 rows or columns remain.
    pub fn downsample(&self, stride: usize) -> Result<Self, OpcError> {
        self.view().downsample(stride)
    }
}

/// Whether a point is valid: all three coordinates finite. Without short-circuits, so
/// that loops calling it stay branch-free and vectorise.
#[inline]
pub fn is_valid(p: &[f64; 3]) -> bool {
    p[0].is_finite() & p[1].is_finite() & p[2].is_finite()
}

/// Checks that `len` points fill a `rows × cols` grid that a mesh can index with `u32`.
pub(crate) fn check_shape(rows: usize, cols: usize, len: usize) -> Result<(), OpcError> {
    if rows < 2 || cols < 2 {
        return Err(OpcError::TooSmall { rows, cols });
    }
    let expected = rows
        .checked_mul(cols)
        .ok_or(OpcError::TooLarge { rows, cols })?;
    if expected > u32::MAX as usize / 2 {
        return Err(OpcError::TooLarge { rows, cols });
    }
    if len != expected {
        return Err(OpcError::LengthMismatch {
            rows,
            cols,
            found: len,
        });
    }
    Ok(())
}

/// Checks that `len` values are `rows × cols × 3` coordinates.
fn check_flat(rows: usize, cols: usize, len: usize) -> Result<(), OpcError> {
    let expected = rows.checked_mul(cols).and_then(|n| n.checked_mul(3));
    if expected != Some(len) {
        return Err(OpcError::FlatLengthMismatch {
            rows,
            cols,
            found: len,
        });
    }
    Ok(())
}

/// Reinterprets a flat coordinate buffer as points, without copying.
pub(crate) fn flat_points(rows: usize, cols: usize, flat: &[f64]) -> Result<&[[f64; 3]], OpcError> {
    check_flat(rows, cols, flat.len())?;
    bytemuck::try_cast_slice(flat).map_err(|_| OpcError::FlatLengthMismatch {
        rows,
        cols,
        found: flat.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(rows: usize, cols: usize) -> Vec<[f64; 3]> {
        (0..rows * cols)
            .map(|i| [(i % cols) as f64, (i / cols) as f64, 1.0 + i as f64])
            .collect()
    }

    #[test]
    fn shape_errors() {
        assert_eq!(
            OrganizedPointCloud::new(1, 5, grid(1, 5)),
            Err(OpcError::TooSmall { rows: 1, cols: 5 })
        );
        assert_eq!(
            OrganizedPointCloud::new(3, 3, grid(2, 4)),
            Err(OpcError::LengthMismatch {
                rows: 3,
                cols: 3,
                found: 8
            })
        );
        assert_eq!(
            OrganizedPointCloud::new(usize::MAX, 2, Vec::new()),
            Err(OpcError::TooLarge {
                rows: usize::MAX,
                cols: 2
            })
        );
        assert_eq!(
            OrganizedPointCloud::from_flat(2, 2, &[0.0; 11]),
            Err(OpcError::FlatLengthMismatch {
                rows: 2,
                cols: 2,
                found: 11
            })
        );
        assert_eq!(
            OrganizedPointCloud::from_flat_vec(usize::MAX, 3, vec![0.0; 6]),
            Err(OpcError::FlatLengthMismatch {
                rows: usize::MAX,
                cols: 3,
                found: 6
            })
        );
    }

    #[test]
    fn flat_constructors_agree_with_new() {
        let points = grid(3, 4);
        let flat: Vec<f64> = points.iter().flatten().copied().collect();
        let expected = OrganizedPointCloud::new(3, 4, points).unwrap();
        assert_eq!(
            OrganizedPointCloud::from_flat(3, 4, &flat).unwrap(),
            expected
        );
        let address = flat.as_ptr() as usize;
        let moved = OrganizedPointCloud::from_flat_vec(3, 4, flat).unwrap();
        assert_eq!(moved, expected);
        assert_eq!(
            moved.points().as_ptr() as usize,
            address,
            "the allocation is reused"
        );
    }

    #[test]
    fn flat_vec_with_odd_capacity_is_copied() {
        let mut flat: Vec<f64> = grid(2, 2).iter().flatten().copied().collect();
        flat.reserve_exact(1);
        if flat.capacity().is_multiple_of(3) {
            flat.reserve_exact(flat.capacity() + 1);
        }
        assert_ne!(flat.capacity() % 3, 0);
        let cloud = OrganizedPointCloud::from_flat_vec(2, 2, flat).unwrap();
        assert_eq!(cloud.points(), grid(2, 2).as_slice());
    }

    #[test]
    fn downsample_picks_every_kth_row_and_column() {
        let cloud = OrganizedPointCloud::new(7, 5, grid(7, 5)).unwrap();
        for stride in 1..=3 {
            let small = cloud.downsample(stride).unwrap();
            assert_eq!(small.rows(), 7usize.div_ceil(stride));
            assert_eq!(small.cols(), 5usize.div_ceil(stride));
            for r in 0..small.rows() {
                for c in 0..small.cols() {
                    assert_eq!(small.point(r, c), cloud.point(r * stride, c * stride));
                }
            }
        }
        assert_eq!(
            cloud.downsample(3).map(|c| (c.rows(), c.cols())),
            Ok((3, 2))
        );
        assert_eq!(
            cloud.downsample(5),
            Err(OpcError::TooSmall { rows: 2, cols: 1 })
        );
        assert!(matches!(
            cloud.downsample(0),
            Err(OpcError::InvalidParameter { name: "stride", .. })
        ));
    }

    #[test]
    fn validity() {
        assert!(is_valid(&[0.0, 1.0, 2.0]));
        assert!(!is_valid(&[0.0, f64::NAN, 2.0]));
        assert!(!is_valid(&[0.0, 1.0, f64::INFINITY]));
        let mut points = grid(2, 3);
        points[4] = [f64::NAN; 3];
        assert_eq!(
            OrganizedPointCloud::new(2, 3, points).unwrap().num_valid(),
            5
        );
    }
}
