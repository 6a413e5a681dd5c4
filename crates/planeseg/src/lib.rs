//! Planar segmentation of a half-edge mesh by dominant plane normals (Polylidar3D §7,
//! Alg. 4–5), with each segment's polygon extracted as soon as the segment is complete.
//!
//! 1. **Group assignment** ([`assign_groups`], data-parallel): a triangle whose longest edge
//!    exceeds `lmax` is dropped; otherwise it joins the dominant normal most similar to its
//!    own (largest dot product) if that similarity reaches `norm_thresh`.
//! 2. **Region growing** (one rayon task per dominant normal): edge-connected triangles of
//!    the same group form a segment while their centroids stay within `z_thresh` of the
//!    plane through the seed triangle's centroid orthogonal to the dominant normal.
//!    Segments with at least `min_triangles` triangles are kept, and each spawns its own
//!    polygon extraction task at once, so segmentation and extraction overlap.
//! 3. **Polygon extraction** ([`polyextract`]) in the segment's geometric plane (the
//!    area-weighted mean of its triangle normals); holes with fewer than
//!    `min_hole_vertices` vertices are dropped.
//!
//! 4. **Refinement** (optional, [`SegmentationConfig::refine`]; beyond the paper): the
//!    grown segments absorb neighbouring triangles that fit their plane, the triangles
//!    left over grow into planes that no dominant normal explains, segments of one plane
//!    merge, strips without interior triangles are dropped, and segments that lie on one
//!    plane without touching share [`PlanarSegment::plane`]; polygons are extracted after
//!    it. [`SegmentationConfig::min_area`] then keeps regions below `min_triangles` that
//!    are large (far planes seen by few pixels).
//!
//! Groups are `u32`, so any number of dominant normals works (the original's `u8` labels
//! stop at 254). Results are sorted by (group, seed triangle) and do not depend on the
//! thread count. [`Segmenter`] keeps the working memory between calls, for frame-by-frame
//! use; [`segment`] allocates it per call.
//!
//! ```
//! use halfedge_mesh::HalfEdgeMesh;
//! use planeseg::{SegmentationConfig, segment};
//!
//! // A 10 × 10 floor grid (z = 0) triangulated as a user mesh.
//! let vertices: Vec<[f64; 3]> = (0..121).map(|i| [(i % 11) as f64, (i / 11) as f64, 0.0]).collect();
//! let mut triangles = Vec::new();
//! for r in 0..10u32 {
//!     for c in 0..10u32 {
//!         let v = r * 11 + c;
//!         triangles.extend([[v, v + 1, v + 12], [v, v + 12, v + 11]]);
//!     }
//! }
//! let mesh = HalfEdgeMesh::from_triangles(vertices, triangles)?;
//! let config = SegmentationConfig::new().with_lmax(2.0).with_min_triangles(10);
//! let segmentation = segment(&mesh, &[[0.0, 0.0, 1.0]], &config)?;
//! assert_eq!(segmentation.segments.len(), 1);
//! assert_eq!(segmentation.segments[0].triangles.len(), 200);
//! assert_eq!(segmentation.segments[0].polygon.shell.len(), 40);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![deny(rustdoc::broken_intra_doc_links)]

mod config;
mod groups;
mod grow;
mod prefetch;
mod refine;
mod vec3;

pub use config::SegmentationConfig;
pub use groups::{GroupCounts, NO_GROUP, assign_groups};
pub use grow::{
    PlanarSegment, Segmentation, SegmentationCounts, Segmenter, geometric_plane, segment,
};
pub use refine::{
    ABSORB_COS, ADJACENT_FLOOR, COPLANAR_COS, COPLANAR_FLOOR, MERGE_RMS_GROWTH, MIN_INTERIOR_SHARE,
};

use polyextract::ExtractError;

/// Why a mesh could not be segmented.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SegmentError {
    /// Segmentation needs triangle normals.
    #[error(
        "the mesh has no triangle normals; compute them first (HalfEdgeMesh::compute_triangle_normals)"
    )]
    MissingNormals,
    /// A dominant normal is not a finite unit vector.
    #[error("dominant normal {index} {normal:?} is not a finite unit vector")]
    BadDominantNormal {
        /// Its index.
        index: usize,
        /// Its value.
        normal: [f64; 3],
    },
    /// A configuration value is out of range.
    #[error("invalid segmentation parameter {field} = {value}: {reason}")]
    Config {
        /// The parameter name.
        field: &'static str,
        /// The value given.
        value: f64,
        /// What it must be.
        reason: &'static str,
    },
    /// The boundary of a segment could not be followed.
    #[error("polygon extraction of the segment seeded at triangle {seed} failed: {source}")]
    Extract {
        /// The segment's seed triangle.
        seed: u32,
        /// The extraction error.
        source: ExtractError,
    },
}

#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
