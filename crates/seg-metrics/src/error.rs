//! Why a segmentation could not be scored.

use std::fmt;

/// Which of the two label arrays a problem was found in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Labels {
    /// The ground-truth labels (`truth`).
    Truth,
    /// The predicted labels (`predicted`).
    Predicted,
}

impl fmt::Display for Labels {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Labels::Truth => "ground-truth",
            Labels::Predicted => "predicted",
        })
    }
}

/// Why [`evaluate`](crate::evaluate()) refused its input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MetricsError {
    /// The three inputs must describe the same points, one entry per point.
    #[error(
        "input lengths differ: {points} points, {truth} ground-truth labels and {predicted} \
         predicted labels; give exactly one label of each kind per point"
    )]
    LengthMismatch {
        /// Number of points.
        points: usize,
        /// Number of ground-truth labels.
        truth: usize,
        /// Number of predicted labels.
        predicted: usize,
    },
    /// A label below −1. Labels are −1 ("no plane") or a non-negative plane id.
    #[error(
        "{labels} label {label} of point {index} is invalid: use -1 for \"no plane\" and a \
         non-negative id for a plane"
    )]
    InvalidLabel {
        /// The label array holding the bad label.
        labels: Labels,
        /// The point's index.
        index: usize,
        /// The offending label.
        label: i32,
    },
    /// A point with a NaN or infinite coordinate carries a label. Such points (missing
    /// returns of a range image) may only appear with −1 in both label arrays.
    #[error(
        "point {index} has a non-finite coordinate but is labelled (ground truth {truth}, \
         predicted {predicted}); label invalid points -1 in both arrays"
    )]
    NonFinitePoint {
        /// The point's index.
        index: usize,
        /// Its ground-truth label.
        truth: i32,
        /// Its predicted label.
        predicted: i32,
    },
    /// The overlap threshold `T` must lie in (0.5, 1]: above one half, every region has at
    /// most one partner it overlaps by `T`, which the classification relies on.
    #[error("overlap threshold {overlap} is outside (0.5, 1]; the usual value is 0.8")]
    InvalidOverlap {
        /// The rejected threshold.
        overlap: f64,
    },
}
