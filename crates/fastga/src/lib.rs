//! # fastga — the Fast Gaussian Accumulator
//!
//! Finds the dominant plane normals of a set of unit normals (for example the triangle
//! normals of a mesh), as in §6 of the Polylidar3D paper (Castagno & Atkins, 2020):
//!
//! 1. a **refined icosahedron** ([`Icosahedron`], levels 0–7, `20·4^L` triangle cells) is the
//!    histogram of the sphere; its cells are sorted by their normals' [S2 cell ids](s2id);
//! 2. each normal is binned into the cell with the closest normal ([`GaussianAccumulator`]),
//!    found by **Algorithm 3** ([`Search::LearnedIndex`]: its S2 id, a least-squares line from
//!    id to array index with exact worst-case error bounds, a branchless binary search in that
//!    window, then steepest ascent over the 1-ring neighbour matrix by true angular distance)
//!    or by a **cell table** built from it ([`Search::CellTable`]: the candidate cells of each
//!    S2 cell two levels finer than the icosahedron, faster to query, costlier to build); by
//!    default ([`Search::Adaptive`]) the table is built once the normals integrated have
//!    paid for it;
//! 3. the vertex values (mean of the incident cells) are **unwrapped** into the five-chart
//!    image of Cohen et al. ([`UnwrappedImage`], writable as PNG with the feature `png`) normalised to 0–255, whose
//!    3×3 local maxima above `value_threshold` are the [`Peak`]s;
//! 4. peaks are merged by single-linkage clustering within `cluster_distance` into
//!    [`DominantNormal`]s, and clusters lighter than `min_cluster_weight` are dropped.
//!
//! `KdAccumulator` (feature `kdtree`) is the same accumulator searched with a k-d tree (kiddo),
//! the baseline the paper compares against. The crate depends on no other part of
//! polylidar-rs.
//!
//! ```
//! use fastga::{FastGaConfig, dominant_normals};
//!
//! // Normals of a floor and a wall, plus a few invalid ones that are skipped and counted.
//! let mut normals: Vec<[f64; 3]> = vec![[0.0, 0.0, 1.0]; 3000];
//! normals.extend(vec![[0.0, -1.0, 0.0]; 1000]);
//! normals.push([f64::NAN, 0.0, 0.0]);
//! let found = dominant_normals(&normals, &FastGaConfig::default())?;
//! assert_eq!(found.len(), 2);
//! assert!(found[0].normal[2] > 0.9999); // the floor is the strongest
//! assert!(found[1].normal[1] < -0.9999);
//! # Ok::<(), fastga::FastGaError>(())
//! ```
//!
//! ## Determinism and threads
//! Integration is sequential or runs on the current rayon pool ([`Parallelism`]); counts and
//! the per-cell normal sums are integers, so every result is bit-identical for any thread
//! count. Sampling (`sample_fraction`) picks normals by a hash of their index.
//!
//! ## Cargo features
//! None is on by default: the accumulator itself needs only `rayon` and `thiserror`.
//! - `kdtree`: `KdAccumulator`, the k-d tree baseline (pulls `kiddo`).
//! - `png`: `UnwrappedImage::write_png`, written atomically (a temporary file beside the
//!   target, renamed into place), and `UnwrappedImage::write_png_to` (both pull `png`).

mod accumulator;
mod config;
mod error;
pub mod icosahedron;
mod image;
mod integrate;
#[cfg(feature = "kdtree")]
mod kdtree;
mod peaks;
pub mod s2id;
mod search;
mod table;

pub use accumulator::{DEFAULT_UNIT_TOLERANCE, GaussianAccumulator, Search, TABLE_PAYS_AFTER};
pub use config::{Detection, FastGa, FastGaConfig, dominant_normals};
pub use error::FastGaError;
pub use icosahedron::{Icosahedron, MAX_LEVEL, NO_NEIGHBOR, NORTH_POLE, SOUTH_POLE};
pub use image::UnwrappedImage;
pub use integrate::{AsNormal, IntegrateStats, Parallelism};
#[cfg(feature = "kdtree")]
pub use kdtree::KdAccumulator;
pub use peaks::{DominantNormal, Peak, cluster_peaks};

/// The README's example, compiled and run as a doctest.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
struct ReadmeDoctest;

/// Checks a unit-length tolerance.
fn unit_tolerance_checked(tolerance: f64) -> Result<f64, FastGaError> {
    if (0.0..1.0).contains(&tolerance) {
        Ok(tolerance)
    } else {
        Err(FastGaError::InvalidUnitTolerance(tolerance))
    }
}
