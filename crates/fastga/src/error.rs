//! The crate's error type.

#[cfg(feature = "png")]
use std::path::PathBuf;

use thiserror::Error;

/// Everything that can go wrong in `fastga`: a parameter out of its range, or an image that
/// cannot be written.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum FastGaError {
    /// The icosahedron refinement level is above [`MAX_LEVEL`](crate::MAX_LEVEL).
    #[error("refinement level {level} is out of range: levels 0 to {max} are supported")]
    LevelOutOfRange {
        /// The level asked for.
        level: u32,
        /// The highest level supported.
        max: u32,
    },
    /// `sample_fraction` is not in (0, 1].
    #[error("sample_fraction {0} is out of range: it must be in (0, 1] (1 keeps every normal)")]
    InvalidSampleFraction(f64),
    /// `value_threshold` is not in [0, 255].
    #[error("value_threshold {0} is out of range: it is on the image's 0-255 scale")]
    InvalidValueThreshold(f64),
    /// `cluster_distance` is negative or not finite.
    #[error(
        "cluster_distance {0} is invalid: it is a Euclidean distance between unit normals, in [0, 2]"
    )]
    InvalidClusterDistance(f64),
    /// `min_cluster_weight` is negative or not finite.
    #[error("min_cluster_weight {0} is invalid: it must be a finite number >= 0")]
    InvalidMinClusterWeight(f64),
    /// `unit_tolerance` is negative or not finite.
    #[error("unit_tolerance {0} is invalid: it must be a finite number in [0, 1)")]
    InvalidUnitTolerance(f64),
    /// The k-d tree baseline could not be built.
    #[cfg(feature = "kdtree")]
    #[error("k-d tree construction failed: {0}")]
    KdTree(String),
    /// The PNG encoder failed.
    #[cfg(feature = "png")]
    #[error("cannot encode the unwrapped image as PNG: {0}")]
    Png(#[from] png::EncodingError),
    /// The PNG file could not be created, written or renamed into place.
    #[cfg(feature = "png")]
    #[error("cannot write the PNG file {path}: {source}")]
    Io {
        /// The file that was being written.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
}
