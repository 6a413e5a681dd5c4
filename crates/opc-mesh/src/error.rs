//! Errors of organized point clouds and their meshing.

/// Why an organized point cloud could not be built or meshed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum OpcError {
    /// Fewer than two rows or columns: no cell can form a triangle.
    #[error("an organized cloud needs at least 2 rows and 2 columns, got {rows} × {cols}")]
    TooSmall {
        /// Rows given.
        rows: usize,
        /// Columns given.
        cols: usize,
    },
    /// The number of points is not `rows × cols`.
    #[error("{found} points do not fill {rows} rows × {cols} columns ({} expected)", rows * cols)]
    LengthMismatch {
        /// Rows given.
        rows: usize,
        /// Columns given.
        cols: usize,
        /// Points given.
        found: usize,
    },
    /// The image is too large for `u32` triangle and half-edge indices.
    #[error("{rows} × {cols} points exceed the u32 index space of the mesh")]
    TooLarge {
        /// Rows given.
        rows: usize,
        /// Columns given.
        cols: usize,
    },
}
