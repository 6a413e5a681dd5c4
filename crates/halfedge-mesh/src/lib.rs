//! Compact half-edge triangle meshes with `u32` indices, shared by every stage of
//! polylidar-rs.
//!
//! A [`HalfEdgeMesh`] holds `f64` vertices, counter-clockwise `u32` triangles, the twin of
//! every half-edge ([`NO_TWIN`] on borders; half-edge `h` is in triangle `h / 3`) and unit
//! triangle normals. Build one from
//!
//! * a 2D point set: [`HalfEdgeMesh::delaunay_2d`] (sweep-hull, exact orientation and in-circle tests);
//! * the α-complex of a 2D point set, the Delaunay triangles of circumradius at most α:
//!   [`HalfEdgeMesh::alpha_complex_2d`] (parallel over strips, same triangles as
//!   `delaunay_2d` filtered by circumradius, whatever the thread count);
//! * a 3D cloud seen from a direction: [`HalfEdgeMesh::delaunay_25d`] (2.5D);
//! * user triangles: [`HalfEdgeMesh::from_triangles`] and
//!   [`HalfEdgeMesh::from_triangles_with_options`], with the three non-manifold edge
//!   policies of the Polylidar3D paper ([`NonManifoldPolicy`]);
//! * arrays built elsewhere: [`HalfEdgeMesh::from_parts`] (checked).
//!
//! Polylidar's triangle filter ([`TriangleFilter`]: α, `lmax`, angle to an up direction)
//! and region growing ([`Regions`]: edge-connected components of the kept triangles) run
//! on any of them.
//!
//! Every constructor returns a [`MeshError`] naming the problem for bad input (too few
//! points, NaN, collinear points, index out of range, degenerate triangles) and never
//! panics on it. [`HalfEdgeMesh::sanity_check`] verifies all invariants.
//!
//! ```
//! use halfedge_mesh::HalfEdgeMesh;
//!
//! let points: Vec<[f64; 2]> = (0..100)
//!     .map(|i| [(i % 10) as f64 + 0.01 * (i / 10) as f64, (i / 10) as f64])
//!     .collect();
//! let mesh = HalfEdgeMesh::delaunay_2d(&points)?;
//! mesh.sanity_check()?;
//! assert!(mesh.num_triangles() > 150);
//! # Ok::<(), halfedge_mesh::MeshError>(())
//! ```

#![deny(rustdoc::broken_intra_doc_links)]

mod build;
mod delaunay;
mod error;
mod filter;
mod mesh;
mod sweep;

pub use build::{BuildReport, DegeneratePolicy, MeshOptions, NonManifoldPolicy};
pub use delaunay::{DelaunayReport, MAX_COORDINATE};
pub use error::MeshError;
pub use filter::{FilterCounts, NO_REGION, Regions, TriangleFilter};
pub use mesh::{HalfEdgeMesh, MeshParts, NO_TWIN, cross_normal, next_halfedge, prev_halfedge};
pub use sweep::alpha::{AlphaComplexOptions, AlphaComplexReport};

#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
