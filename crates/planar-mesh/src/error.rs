//! Errors of the planar simplification.

/// Why a planar segment could not be simplified, meshed or textured.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PlanarMeshError {
    /// The segment has fewer than three points: there is no plane to fit.
    #[error("a planar segment needs at least 3 points, this one has {0}")]
    TooFewPoints(usize),
    /// A point or polygon vertex has a NaN or infinite coordinate.
    #[error("{what} {index} has a non-finite coordinate {value:?}")]
    NonFinite {
        /// `"point"`, `"shell vertex"` or `"hole vertex"`.
        what: &'static str,
        /// Its index.
        index: usize,
        /// Its coordinates.
        value: [f64; 3],
    },
    /// The points do not span a plane (all on one line or one point).
    #[error("the segment's points are collinear or coincide: no plane to fit")]
    Degenerate,
    /// The shell has fewer than three distinct vertices, or no area in the plane.
    #[error(
        "the shell has {vertices} distinct vertices and area {area:e} in the plane: no polygon"
    )]
    EmptyShell {
        /// Distinct shell vertices.
        vertices: usize,
        /// Its area in the fitted plane.
        area: f64,
    },
    /// There are colours, but not one per point.
    #[error("{colors} colours for {points} points")]
    ColorCount {
        /// Colours given.
        colors: usize,
        /// Points given.
        points: usize,
    },
    /// A texture was asked for a segment without colours.
    #[error("a texture needs one colour per point; this segment has none")]
    NoColors,
    /// An option is out of its range.
    #[error("option `{name}` is {value}: {expected}")]
    BadOption {
        /// The option.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The allowed range.
        expected: &'static str,
    },
    /// The constrained Delaunay triangulation rejected a vertex (out of `spade`'s range).
    #[error("constrained Delaunay triangulation: {0}")]
    Triangulation(String),
    /// A PNG could not be encoded.
    #[error("PNG encoding: {0}")]
    Png(String),
}
