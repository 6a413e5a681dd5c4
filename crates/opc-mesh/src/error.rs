//! Errors of organized point clouds and their meshing.

/// Why an organized point cloud could not be built or meshed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum OpcError {
    /// Fewer than two rows or columns: no cell can form a triangle.
    #[error("an organized cloud needs at least 2 rows and 2 columns, got {rows} × {cols}")]
    TooSmall {
        /// Rows given (after downsampling, where a stride was applied).
        rows: usize,
        /// Columns given (after downsampling, where a stride was applied).
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
    /// A flat `f64` buffer does not hold `rows × cols × 3` values (x, y, z per point).
    #[error(
        "a flat buffer of {found} f64 values does not hold {rows} rows × {cols} columns × 3 \
         coordinates ({} expected); pass a C-contiguous (rows, cols, 3) array",
        rows * cols * 3
    )]
    FlatLengthMismatch {
        /// Rows given.
        rows: usize,
        /// Columns given.
        cols: usize,
        /// Values given.
        found: usize,
    },
    /// A depth image does not hold `rows × cols` pixels.
    #[error("a depth image of {found} pixels does not fill {rows} rows × {cols} columns ({} expected)", rows * cols)]
    DepthLengthMismatch {
        /// Rows given.
        rows: usize,
        /// Columns given.
        cols: usize,
        /// Pixels given.
        found: usize,
    },
    /// The image is too large for `u32` point, triangle and half-edge indices.
    #[error("{rows} × {cols} points exceed the u32 index space of the mesh")]
    TooLarge {
        /// Rows given.
        rows: usize,
        /// Columns given.
        cols: usize,
    },
    /// A parameter is out of its range.
    #[error("{name} = {value} is invalid: it must be {expected}")]
    InvalidParameter {
        /// The parameter's name, as in the options struct.
        name: &'static str,
        /// The value given, as text.
        value: String,
        /// The range it must lie in.
        expected: &'static str,
    },
    /// No cell of the cloud has a triangle with three valid, distinct vertices (for example
    /// a cloud that is all NaN, all zero, or whose coordinates overflow a normal).
    #[error("no triangle can be formed: {}", no_triangles_reason(*.valid_points, *.points))]
    NoTriangles {
        /// Valid (finite) points in the cloud.
        valid_points: usize,
        /// All points in the cloud.
        points: usize,
    },
}

/// Why no triangle could be formed, from the count of valid points.
fn no_triangles_reason(valid: usize, points: usize) -> String {
    if valid == 0 {
        format!(
            "none of the {points} points is valid (every one has a NaN or infinite coordinate, or depth 0)"
        )
    } else if valid < 3 {
        format!("only {valid} of the {points} points are valid; a triangle needs three")
    } else {
        format!(
            "{valid} of the {points} points are valid, but no cell has three valid corners \
             spanning a triangle of non-zero, finite area: the valid points are isolated \
             (no valid right or lower neighbour), coincident (e.g. all zero), collinear, or so \
             large that a triangle's normal overflows (coordinates beyond about 1e150)"
        )
    }
}
