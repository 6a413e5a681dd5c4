//! Errors.

/// Why normals or a voxel grid could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum NormalsError {
    /// The cloud has no point.
    #[error("the cloud is empty")]
    Empty,
    /// A coordinate is NaN or infinite.
    #[error("point {index} {point:?} is not finite")]
    NonFinite {
        /// Its index.
        index: usize,
        /// Its coordinates.
        point: [f64; 3],
    },
    /// A neighbourhood needs at least 3 points.
    #[error("k = {k}: a neighbourhood needs at least 3 points")]
    TooFewNeighbours {
        /// The `k` asked for.
        k: usize,
    },
    /// The voxel size is not a finite positive length.
    #[error("voxel size {size} must be a finite length > 0")]
    BadVoxelSize {
        /// The size given.
        size: f64,
    },
    /// The cloud spans more voxels along an axis than 2²¹ (the key packs 21 bits per axis).
    #[error("the cloud spans {cells} voxels of {size} along an axis; at most 2^21 fit")]
    TooManyVoxels {
        /// Voxels along the longest axis.
        cells: f64,
        /// The voxel size.
        size: f64,
    },
    /// More points than `u32` indices can address.
    #[error("{points} points: at most 2^32 - 1 are supported")]
    TooManyPoints {
        /// The count.
        points: usize,
    },
    /// The orientation target is not finite (or a zero direction).
    #[error("orientation {0} is not a finite point or non-zero direction")]
    BadOrientation(String),
}
