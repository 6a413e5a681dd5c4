//! Planes in Hessian normal form and the orthonormal 2D frame post-processing works in:
//! the workspace's shared types from `plane-geom`, and its `[f64; 3]` helpers.

pub(crate) use plane_geom::vec3::norm;
pub use plane_geom::{Plane, PlaneFrame};
