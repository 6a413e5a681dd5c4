//! The shared geometry vocabulary of polylidar-rs, in the spirit of `geo-types`: the few
//! 3D types and routines every stage needs, written once so that the stages agree to the
//! last bit.
//!
//! - [`vec3`]: helpers on `[f64; 3]` (dot, cross, add, sub, scale, norm, unit);
//! - [`PlaneFrame`]: the orthonormal frame `(e1, e2, normal)` of a plane, with
//!   [`PlaneFrame::project`] (3D → 2D in the plane) and [`PlaneFrame::lift`] (2D → 3D),
//!   built by one documented convention;
//! - [`Plane`]: a unit normal and a point on the plane, signed distances;
//! - [`symmetric_eigen`]: eigenvalues (ascending) and eigenvectors of a symmetric 3 × 3
//!   matrix, e.g. a covariance for a least-squares plane; [`symmetric_eigenvalues`] the
//!   closed-form values-only fast path.
//!
//! Points are `[f64; 3]` so that any crate's points pass without conversion. The crate
//! depends on nothing in the workspace; `fastga` (free of workspace dependencies by
//! design) and `seg-metrics` (whose own plane fit is the independent oracle of its
//! scores) do not use it.

mod eigen;
mod frame;
mod plane;
mod polygon;
pub mod vec3;

pub use eigen::{
    Eigen3, centroid_and_covariance, covariance, smallest_eigenvector, symmetric_eigen,
    symmetric_eigenvalues,
};
pub use frame::PlaneFrame;
pub use plane::Plane;
pub use polygon::{Polygon3, PolygonMetrics, ring_area, ring_length};

/// Why a [`Plane`] could not be built.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PlaneError {
    /// The normal is zero or not finite.
    #[error(
        "plane normal {normal:?} is zero or not finite; a plane needs a finite non-zero normal"
    )]
    BadNormal {
        /// The normal given.
        normal: [f64; 3],
    },
    /// The point on the plane is not finite.
    #[error("plane point {point:?} is not finite")]
    BadPoint {
        /// The point given.
        point: [f64; 3],
    },
}

/// The README's example, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctest;
