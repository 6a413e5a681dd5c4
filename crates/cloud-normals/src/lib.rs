//! Normals for unorganized point clouds, and the neighbourhoods they come from:
//!
//! * [`Neighbours`]: the `k` nearest neighbours of every point, from a uniform grid of
//!   cells searched ring by ring, in parallel (on scans of surfaces faster than a general
//!   k-d tree: the crate README gives the measured figure);
//! * [`estimate_normals`] / [`plane_normal`]: the normal of the plane that fits each
//!   neighbourhood best (principal component analysis: the eigenvector of the smallest
//!   eigenvalue of the covariance, in closed form);
//! * [`orient()`]: normals flipped towards a viewpoint (the sensor) or into the half-space
//!   of a direction (up, for airborne data);
//! * [`voxel_downsample`]: one representative point per voxel, for dense clouds;
//! * [`neighbourhood_noise`]: how noisy the surfaces are, relative to the point spacing,
//!   and [`predict_smoothing_passes`]: the passes of [`smooth_points`] a trained model
//!   gives that noise;
//! * [`spatial_order`]: a Morton order, so that neighbourhood passes over a shuffled cloud
//!   read memory in order.
//!
//! Nothing here depends on the rest of the pipeline; Polylidar's unorganized 3D path uses
//! it to find the planes of a cloud in every direction.
//!
//! ```
//! use cloud_normals::{Neighbours, Orientation, estimate_normals, orient};
//!
//! // A 20 × 20 floor at z = 1, seen from a sensor above it.
//! let points: Vec<[f64; 3]> = (0..400).map(|i| [(i % 20) as f64, (i / 20) as f64, 1.0]).collect();
//! let neighbours = Neighbours::new(&points, 10)?;
//! let mut normals = estimate_normals(&points, &neighbours);
//! orient(&points, &mut normals, Orientation::Towards([5.0, 5.0, 10.0]))?;
//! assert!(normals.iter().all(|n| (n[2] - 1.0).abs() < 1e-9));
//! # Ok::<(), cloud_normals::NormalsError>(())
//! ```

#![deny(rustdoc::broken_intra_doc_links)]

mod error;
mod knn;
mod noise;
mod order;
mod orient;
mod pca;
mod voxel;

pub use error::NormalsError;
pub use knn::Neighbours;
pub use noise::{MAX_AUTO_PASSES, NOISE_SAMPLES, neighbourhood_noise, predict_smoothing_passes};
pub use order::spatial_order;
pub use orient::{Orientation, SIDE_COS, orient};
pub use pca::{estimate_normals, plane_normal, smooth_points};
/// The closed-form eigenvector behind [`plane_normal`], `plane-geom`'s.
pub use plane_geom::smallest_eigenvector;
pub use voxel::{Voxels, voxel_downsample};

#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
