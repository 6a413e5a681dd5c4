//! [`OrganizedPointCloudView`]: an organized cloud borrowed from someone else's buffer.

use rayon::prelude::*;

use crate::cloud::{check_shape, flat_points};
use crate::{OpcError, OrganizedPointCloud};

/// Points per task of [`OrganizedPointCloudView::num_valid`].
const COUNT_CHUNK: usize = 1 << 14;

/// An organized point cloud borrowed from a caller's buffer: the same layout and rules as
/// [`OrganizedPointCloud`] (`rows × cols` row-major `f64` xyz, NaN = invalid) without
/// owning the points.
///
/// This is the zero-copy entry for data that lives elsewhere, such as a C-contiguous numpy
/// `(H, W, 3)` `float64` array: its buffer is a `&[f64]` of `H · W · 3` values, which
/// [`Self::from_flat`] reinterprets as `H · W` points in place. Meshing a view
/// ([`Self::mesh`]) copies the points once, into the mesh's vertex array, because a
/// [`HalfEdgeMesh`](halfedge_mesh::HalfEdgeMesh) owns its vertices; mesh an owned cloud
/// with [`OrganizedPointCloud::into_mesh`] to avoid even that copy.
///
/// ```
/// use opc_mesh::OrganizedPointCloudView;
/// // As a numpy (2, 3, 3) float64 array would hand it over.
/// let flat: Vec<f64> = (0..18).map(|i| i as f64).collect();
/// let view = OrganizedPointCloudView::from_flat(2, 3, &flat)?;
/// assert_eq!(view.point(1, 2), [15.0, 16.0, 17.0]);
/// assert_eq!(view.points().as_ptr().cast::<f64>(), flat.as_ptr()); // no copy
/// # Ok::<(), opc_mesh::OpcError>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrganizedPointCloudView<'a> {
    rows: usize,
    cols: usize,
    points: &'a [[f64; 3]],
}

impl<'a> OrganizedPointCloudView<'a> {
    /// Borrows `rows × cols` points given row by row.
    ///
    /// # Errors
    /// As [`OrganizedPointCloud::new`].
    pub fn new(rows: usize, cols: usize, points: &'a [[f64; 3]]) -> Result<Self, OpcError> {
        check_shape(rows, cols, points.len())?;
        Ok(Self::from_checked(rows, cols, points))
    }

    /// Borrows a flat, row-major `(rows, cols, 3)` buffer of coordinates
    /// (`x0, y0, z0, x1, …`) without copying it.
    ///
    /// # Errors
    /// [`OpcError::FlatLengthMismatch`] if `flat.len() != rows * cols * 3`, and the errors
    /// of [`OrganizedPointCloud::new`].
    pub fn from_flat(rows: usize, cols: usize, flat: &'a [f64]) -> Result<Self, OpcError> {
        Self::new(rows, cols, flat_points(rows, cols, flat)?)
    }

    /// Wraps a shape already checked by [`check_shape`].
    pub(crate) fn from_checked(rows: usize, cols: usize, points: &'a [[f64; 3]]) -> Self {
        Self { rows, cols, points }
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
    pub fn points(&self) -> &'a [[f64; 3]] {
        self.points
    }

    /// The point at row `r`, column `c`.
    ///
    /// # Panics
    /// If `r >= rows` or `c >= cols`, like slice indexing.
    #[inline]
    pub fn point(&self, r: usize, c: usize) -> [f64; 3] {
        assert!(
            c < self.cols,
            "column {c} out of range for {} columns",
            self.cols
        );
        self.points[r * self.cols + c]
    }

    /// Number of valid (finite) points.
    pub fn num_valid(&self) -> usize {
        // Branch-free within a chunk (`&` instead of [`crate::is_valid`]'s `&&`), so that it
        // vectorises.
        self.points
            .par_chunks(COUNT_CHUNK)
            .map(|chunk| {
                chunk
                    .iter()
                    .map(|p| usize::from(p[0].is_finite() & p[1].is_finite() & p[2].is_finite()))
                    .sum::<usize>()
            })
            .sum()
    }

    /// Copies the points into an owned cloud.
    pub fn to_cloud(&self) -> OrganizedPointCloud {
        OrganizedPointCloud::from_checked(self.rows, self.cols, self.points.to_vec())
    }

    /// Keeps every `stride`-th row and column into an owned cloud; see
    /// [`OrganizedPointCloud::downsample`].
    ///
    /// # Errors
    /// As [`OrganizedPointCloud::downsample`].
    pub fn downsample(&self, stride: usize) -> Result<OrganizedPointCloud, OpcError> {
        let (rows, cols) = strided_shape(self.rows, self.cols, stride)?;
        let mut points = vec![[0.0; 3]; rows * cols];
        points
            .par_chunks_mut(cols)
            .enumerate()
            .for_each(|(r, out)| {
                let row = &self.points[r * stride * self.cols..][..self.cols];
                for (o, p) in out.iter_mut().zip(row.iter().step_by(stride)) {
                    *o = *p;
                }
            });
        OrganizedPointCloud::new(rows, cols, points)
    }
}

/// The shape left by keeping every `stride`-th row and column.
pub(crate) fn strided_shape(
    rows: usize,
    cols: usize,
    stride: usize,
) -> Result<(usize, usize), OpcError> {
    if stride == 0 {
        return Err(OpcError::InvalidParameter {
            name: "stride",
            value: "0".into(),
            expected: "at least 1",
        });
    }
    let shape = (rows.div_ceil(stride), cols.div_ceil(stride));
    if shape.0 < 2 || shape.1 < 2 {
        return Err(OpcError::TooSmall {
            rows: shape.0,
            cols: shape.1,
        });
    }
    Ok(shape)
}
