//! Errors raised by plane fitting and by post-processing configuration.

/// Why a plane could not be fitted or built, or why a configuration was refused.
///
/// Bad *polygons* are not errors: post-processing drops them and records the reason in
/// [`PostDiagnostics`](crate::PostDiagnostics). Errors are reserved for inputs that make the
/// whole call meaningless (a bad configuration, a plane that is not a plane).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PostError {
    /// Plane fitting needs at least three points.
    #[error("plane fitting needs at least 3 points, got {found}")]
    TooFewPoints {
        /// Number of points given.
        found: usize,
    },
    /// A point coordinate is NaN or infinite.
    #[error(
        "point {index} has a non-finite coordinate (NaN or infinity); remove it before fitting"
    )]
    NonFinitePoint {
        /// Index of the offending point (into the slice given, or the index value when
        /// fitting through an index list).
        index: usize,
    },
    /// An index in an index list points past the end of the point array.
    #[error("index {index} is out of range for {len} points")]
    IndexOutOfRange {
        /// The bad index.
        index: u32,
        /// Number of points.
        len: usize,
    },
    /// The points do not determine a plane (they coincide or lie on one line).
    #[error(
        "the {count} points are collinear or coincide, so no plane is determined \
         (second-smallest spread {spread:e} m²); give points that span an area"
    )]
    DegeneratePoints {
        /// Number of points used.
        count: usize,
        /// The middle eigenvalue of the covariance (the spread across the line).
        spread: f64,
    },
    /// A plane could not be built: its normal is zero or not finite, or its point is not
    /// finite.
    #[error(transparent)]
    Plane(#[from] plane_geom::PlaneError),
    /// The points are finite but so far apart that their covariance overflows.
    #[error(
        "the spread of the {count} points overflows (coordinates near the largest f64); scale or centre them before fitting"
    )]
    SpreadOverflow {
        /// Number of points used.
        count: usize,
    },
    /// A configuration field is negative, NaN or infinite.
    #[error(
        "post-processing parameter `{field}` = {value} is invalid: it must be finite and >= 0 ({unit})"
    )]
    BadParameter {
        /// Field name in [`PostprocessConfig`](crate::PostprocessConfig).
        field: &'static str,
        /// The value given.
        value: f64,
        /// Unit and meaning of the field.
        unit: &'static str,
    },
    /// The buffer join angle is outside the range the offsetter accepts.
    #[error("buffer join angle {angle} rad is invalid: it must be finite and > 0")]
    BadJoinAngle {
        /// The angle given.
        angle: f64,
    },
    /// Batch inputs whose lengths disagree.
    #[error("got {polygons} polygons but {planes} planes; give one plane per polygon")]
    LengthMismatch {
        /// Number of polygons.
        polygons: usize,
        /// Number of planes.
        planes: usize,
    },
    /// More polygons than `u32` source indices can address.
    #[error("{count} polygons exceed the u32 index space")]
    TooManyPolygons {
        /// Number of polygons given.
        count: usize,
    },
}
