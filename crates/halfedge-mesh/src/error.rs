//! Errors raised while building or checking a [`HalfEdgeMesh`](crate::HalfEdgeMesh).

/// Why a mesh could not be built, or which invariant a mesh breaks.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MeshError {
    /// Fewer points than a triangulation needs.
    #[error("need at least 3 points to triangulate, got {found}")]
    TooFewPoints {
        /// Number of points given.
        found: usize,
    },
    /// A point coordinate is NaN or infinite.
    #[error(
        "point {index} has a non-finite coordinate (NaN or infinity); remove or repair it first"
    )]
    NonFinitePoint {
        /// Index of the offending point.
        index: usize,
    },
    /// A coordinate is so large that the squared distances of the Delaunay tests would
    /// overflow.
    #[error("point {index} has a coordinate of magnitude {value:e}, beyond the supported {max:e}")]
    CoordinateTooLarge {
        /// Index of the offending point.
        index: usize,
        /// The coordinate.
        value: f64,
        /// The largest magnitude accepted.
        max: f64,
    },
    /// The points span no area (all on one line or all equal).
    #[error(
        "all {count} points are collinear or coincide; a triangulation needs points spanning an area"
    )]
    Collinear {
        /// Number of points given.
        count: usize,
    },
    /// More points or triangles than `u32` indices can address.
    #[error("{what} count {count} exceeds the u32 index space")]
    TooLarge {
        /// What overflowed ("points", "triangles").
        what: &'static str,
        /// The count that does not fit.
        count: usize,
    },
    /// A triangle references a vertex that does not exist.
    #[error(
        "triangle {triangle} references vertex {vertex}, but the mesh has only {num_vertices} vertices"
    )]
    IndexOutOfRange {
        /// Triangle index.
        triangle: usize,
        /// The bad vertex index.
        vertex: u32,
        /// Number of vertices.
        num_vertices: usize,
    },
    /// A triangle repeats a vertex, has (numerically) zero area, or is too large to measure.
    #[error(
        "triangle {triangle} {vertices:?} is degenerate ({reason}); pass DegeneratePolicy::Drop to skip such triangles"
    )]
    DegenerateTriangle {
        /// Triangle index.
        triangle: usize,
        /// Its vertex indices.
        vertices: [u32; 3],
        /// "repeated vertex", "zero area" or "too large: …" (its area overflows `f64`).
        reason: &'static str,
    },
    /// A mesh was given without any triangle.
    #[error("the mesh has no triangles")]
    NoTriangles,
    /// Parallel arrays of a mesh disagree in length.
    #[error("{what} has length {found}, expected {expected}")]
    LengthMismatch {
        /// Which array.
        what: &'static str,
        /// Its length.
        found: usize,
        /// The length it must have.
        expected: usize,
    },
    /// A twin link breaks the half-edge invariants.
    #[error("half-edge {halfedge}: {reason}")]
    BadTwin {
        /// The half-edge whose twin is wrong.
        halfedge: u32,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// A vertex used by a triangle is not finite.
    #[error("vertex {vertex} used by triangle {triangle} is not finite")]
    NonFiniteVertex {
        /// Vertex index.
        vertex: u32,
        /// A triangle that uses it.
        triangle: usize,
    },
    /// A triangle normal is not a unit vector.
    #[error("normal of triangle {triangle} is not a finite unit vector")]
    BadNormal {
        /// Triangle index.
        triangle: usize,
    },
    /// The rotation axis for a 2.5D triangulation is not usable.
    #[error("the up vector {up:?} must be finite and non-zero")]
    BadUpVector {
        /// The vector given.
        up: [f64; 3],
    },
}
