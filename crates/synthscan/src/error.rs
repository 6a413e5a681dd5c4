//! The crate's error type.

/// Everything that can go wrong when building, scanning, meshing or sampling a scene.
///
/// Rings are numbered `0` for the outer ring and `1 + h` for hole `h`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// A ring has fewer than three distinct, non-collinear vertices.
    #[error(
        "ring {ring} has {count} usable vertices; a ring needs at least 3 (repeated and collinear vertices are dropped)"
    )]
    TooFewVertices {
        /// Ring number (0 = outer).
        ring: usize,
        /// Vertices left after dropping repeated and collinear ones.
        count: usize,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {vertex} of ring {ring} has a non-finite coordinate")]
    NonFinite {
        /// Ring number (0 = outer).
        ring: usize,
        /// Vertex index in the ring as given.
        vertex: usize,
    },
    /// The outer ring encloses no area, so it defines no plane.
    #[error("the outer ring is degenerate (zero area); give at least three non-collinear vertices")]
    Degenerate,
    /// A vertex lies too far from the plane of the outer ring.
    #[error(
        "vertex {vertex} of ring {ring} lies {distance:e} m from the face's plane (tolerance {tolerance:e} m); all rings of a face must be coplanar"
    )]
    NonPlanar {
        /// Ring number (0 = outer).
        ring: usize,
        /// Vertex index in the ring.
        vertex: usize,
        /// Distance from the plane in metres.
        distance: f64,
        /// Allowed distance in metres.
        tolerance: f64,
    },
    /// Two edges of the face's rings cross or touch.
    #[error(
        "edge {edge_a} of ring {ring_a} and edge {edge_b} of ring {ring_b} intersect; rings must be simple and must not touch each other"
    )]
    RingsIntersect {
        /// Ring of the first edge (0 = outer).
        ring_a: usize,
        /// Edge index in that ring (edge `i` runs from vertex `i` to `i + 1`).
        edge_a: usize,
        /// Ring of the second edge.
        ring_b: usize,
        /// Edge index in that ring.
        edge_b: usize,
    },
    /// A hole is not inside the outer ring, or lies inside another hole.
    #[error("hole {hole} is not inside the outer ring or lies inside another hole")]
    HoleOutside {
        /// Hole index (ring `hole + 1`).
        hole: usize,
    },
    /// A plane label is negative (`-1` means "no plane" in scan results).
    #[error("label {label} is negative; plane labels must be >= 0")]
    NegativeLabel {
        /// The label given.
        label: i32,
    },
    /// Two faces share a label but do not lie on the same plane.
    #[error(
        "face {face} has label {label} but is not on the plane of the first face with that label (normal dot {normal_dot}, offset difference {offset_diff:e} m); faces sharing a label must share one plane and facing side"
    )]
    LabelPlaneMismatch {
        /// Index of the offending face in the scene.
        face: usize,
        /// The shared label.
        label: i32,
        /// Dot product of the two unit normals (1 when parallel and facing the same way).
        normal_dot: f64,
        /// Difference of the plane offsets in metres.
        offset_diff: f64,
    },
    /// A configuration value is out of its valid range.
    #[error("invalid parameter `{name}` = {value}: {reason}")]
    InvalidParameter {
        /// Field or argument name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What a valid value looks like.
        reason: &'static str,
    },
    /// Objects in a builder overlap, touch, or stick out of the room.
    #[error("{what} does not fit: {reason}")]
    Placement {
        /// Which object.
        what: &'static str,
        /// Why it does not fit.
        reason: &'static str,
    },
    /// Random placement could not find room for an object.
    #[error(
        "could not place object {object} of {requested} without overlap after {attempts} attempts; ask for fewer or smaller objects or a larger room"
    )]
    PlacementFailed {
        /// Index of the object that did not fit.
        object: usize,
        /// Objects requested.
        requested: usize,
        /// Attempts made for that object.
        attempts: usize,
    },
    /// The rotation of a pose is not a proper rotation matrix.
    #[error(
        "pose rotation is not orthonormal with determinant +1 (largest deviation {deviation:e})"
    )]
    InvalidPose {
        /// Largest deviation of `RᵀR` from the identity, or of `det R` from 1.
        deviation: f64,
    },
    /// `Pose::look_at` got a degenerate view.
    #[error(
        "look_at needs finite eye, target and up, target != eye, and up not parallel to the viewing direction"
    )]
    InvalidView,
    /// Ear clipping found no ear (only possible for numerically degenerate faces).
    #[error(
        "face {face} could not be triangulated (no ear found with {remaining} vertices left); the face is numerically degenerate"
    )]
    TriangulationFailed {
        /// Index of the face in the scene.
        face: usize,
        /// Vertices of the merged ring left when clipping stopped.
        remaining: usize,
    },
    /// A label filter named no face of the scene.
    #[error("no face has label {label}")]
    UnknownLabel {
        /// The label asked for.
        label: i32,
    },
}

/// Checks that `value` is finite and `> 0`.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64, SceneError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(SceneError::InvalidParameter {
            name,
            value,
            reason: "must be finite and > 0",
        })
    }
}

/// Checks that `value` lies in `range` (so it is not NaN); `reason` says which range.
pub(crate) fn within(
    name: &'static str,
    value: f64,
    range: std::ops::RangeInclusive<f64>,
    reason: &'static str,
) -> Result<f64, SceneError> {
    if range.contains(&value) {
        Ok(value)
    } else {
        Err(SceneError::InvalidParameter {
            name,
            value,
            reason,
        })
    }
}

/// Checks that `value` is finite and `>= 0`.
pub(crate) fn non_negative(name: &'static str, value: f64) -> Result<f64, SceneError> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(SceneError::InvalidParameter {
            name,
            value,
            reason: "must be finite and >= 0",
        })
    }
}

/// Checks that `value` is finite.
pub(crate) fn finite(name: &'static str, value: f64) -> Result<f64, SceneError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(SceneError::InvalidParameter {
            name,
            value,
            reason: "must be finite",
        })
    }
}
