//! The crate's error type.

use thiserror::Error;

/// What can go wrong with a rotating scan: a bad parameter, or points that do not make a
/// scan.
#[derive(Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum ScanError {
    /// A parameter is out of its range.
    #[error("{field} = {value} is out of range: {reason}")]
    Parameter {
        /// The parameter's name.
        field: &'static str,
        /// Its value, as text.
        value: String,
        /// The allowed range.
        reason: &'static str,
    },
    /// A point has a NaN or infinite coordinate.
    #[error("point {index} has a non-finite coordinate {point:?}")]
    NonFinite {
        /// Index of the point.
        index: usize,
        /// Its coordinates.
        point: [f64; 3],
    },
    /// Firing order gave far more beams than a rotating LiDAR has: the points are not in
    /// the order the sensor fired (shuffled, sorted or merged frames).
    #[error(
        "the points are not in firing order: their azimuth turns {found} times (at most \
         {max} beams expected); recover the beams from elevation instead"
    )]
    NotFiringOrder {
        /// Beams found.
        found: usize,
        /// The most allowed.
        max: usize,
    },
    /// A ring refers to a point that does not exist.
    #[error("ring member {index} is out of range ({points} points)")]
    MemberOutOfRange {
        /// The index found.
        index: u32,
        /// Number of points.
        points: usize,
    },
}
