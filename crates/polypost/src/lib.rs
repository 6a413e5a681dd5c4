//! Polygon post-processing for Polylidar3D (paper §8), plane fitting, and polygons that
//! are always valid.
//!
//! Polylidar3D extracts one polygon (shell + holes) per planar segment. Projected onto
//! the segment's plane such a polygon can self-intersect, and it is usually jagged. This
//! crate takes it into the plane's 2D frame ([`PlaneFrame`]) and, in the paper's order,
//!
//! 1. simplifies it with tolerance α (Ramer–Douglas–Peucker, on the rings as they are)
//!    and repairs the result if it is not valid,
//! 2. buffers it outward by β_pos and
//! 3. inward by β_neg (mitre joins by default, as the original's Shapely buffers),
//! 4. drops polygons with area below γ and
//! 5. holes with area below δ,
//!
//! then lifts the result back onto the plane. The repair keeps the non-zero winding
//! region of the shell minus the union of the holes (without α, of the input); every polygon
//! returned passes `geo::Validation`, and inputs that cannot be repaired are reported in
//! [`PostDiagnostics`] instead of returned. Buffering may split a polygon or merge holes, so
//! each input gives zero or more outputs, each tagged with its input's index.
//!
//! Plane fitting ([`fit_plane`]) is least squares by PCA of the covariance, with RMSE of
//! the point-to-plane distances; [`Polygon3::metrics`] gives area, perimeter and bounding
//! box. The paper's parameter presets are [`PostprocessConfig::rgbd`],
//! [`PostprocessConfig::rooftop`], [`PostprocessConfig::kitti`],
//! [`PostprocessConfig::mesh_basement`] and [`PostprocessConfig::mesh_mainfloor`].
//!
//! # Example
//!
//! ```
//! use polypost::{fit_plane, Polygon3, PostProcessor, PostprocessConfig};
//!
//! // A 2 m × 1 m rectangle on the tilted plane z = 0.5 x, with a 0.2 m × 0.2 m hole.
//! let lift = |x: f64, y: f64| [x, y, 0.5 * x];
//! let shell = vec![lift(0.0, 0.0), lift(2.0, 0.0), lift(2.0, 1.0), lift(0.0, 1.0)];
//! let hole = vec![lift(0.9, 0.4), lift(0.9, 0.6), lift(1.1, 0.6), lift(1.1, 0.4)];
//! let plane = fit_plane(&shell).unwrap().plane;
//!
//! // Drop holes under 0.1 m² (δ), keep polygons of at least 0.5 m² (γ).
//! let config = PostprocessConfig::default().with_min_area(0.5).with_min_hole_area(0.1);
//! let out = PostProcessor::new(config).unwrap().process_3d(&Polygon3::new(shell, vec![hole]), &plane);
//!
//! assert_eq!(out.polygons.len(), 1);
//! let polygon = &out.polygons[0].polygon;
//! assert!(polygon.holes.is_empty()); // the 0.047 m² hole is below δ
//! assert!((polygon.metrics().area - 2.0 * 1.25f64.sqrt()).abs() < 1e-9);
//! assert_eq!(out.diagnostics.holes_dropped_by_area, 1);
//! ```
//!
//! # Performance
//!
//! Validity is checked with an exact `O(n log n)` sufficient test (sweep over segment
//! bounding boxes with robust orientation predicates); only polygons it cannot prove valid
//! (e.g. a hole touching the shell at a point) go to `geo`'s `O(n²)` `Validation`.
//! Buffering (through `geo`/`i_overlay`) is the dominant cost.

#![forbid(unsafe_code)]
#![deny(rustdoc::broken_intra_doc_links)]

mod config;
mod diagnostics;
mod error;
mod fit;
mod pipeline;
mod plane;
mod process;
mod simplify;
mod valid;

pub use config::{BufferJoin, PostprocessConfig};
pub use diagnostics::{DropReason, DroppedPolygon, PostDiagnostics};
pub use error::PostError;
pub use fit::{PlaneFit, PlaneFitOptions, fit_plane, fit_plane_indexed, fit_plane_with_options};
pub use plane::{Plane, PlaneFrame};
pub use plane_geom::{Polygon3, PolygonMetrics, ring_area, ring_length};
pub use process::{Output2, Output3, PostProcessor, SourcedPolygon2, SourcedPolygon3};

/// Re-export of the `geo-types` types used in the 2D API.
pub use geo_types::{Coord, LineString, MultiPolygon, Polygon};

/// The README's example, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctest;
