//! Organized point clouds (range images, RGBD frames) and their O(n) right-cut half-edge
//! meshing (Polylidar3D §4.2, Alg. 1–2).
//!
//! * [`OrganizedPointCloud`] owns `rows × cols` `f64` points (NaN = invalid pixel);
//!   [`OrganizedPointCloudView`] borrows them from a caller's buffer without copying (a
//!   numpy `(H, W, 3)` `float64` array, for example).
//! * [`OrganizedPointCloud::from_depth_image`] back-projects a 16-bit depth image through
//!   pinhole [`Intrinsics`] ([`DepthOptions`]: depth scale, stride, maximum depth);
//!   [`OrganizedPointCloud::downsample`] keeps every k-th row and column;
//!   [`OrganizedPointCloud::decimate`] merges k × k blocks of pixels into robust means
//!   ([`Decimated`]);
//!   [`OrganizedPointCloud::fill_missing`] puts back isolated missing returns
//!   ([`FillConfig`]).
//! * [`OrganizedPointCloud::mesh`] (or [`OrganizedPointCloud::into_mesh`], which moves the
//!   points into the mesh) builds a [`HalfEdgeMesh`](halfedge_mesh::HalfEdgeMesh) with
//!   twins and, if asked, unit triangle normals, plus the [`TriangleMap`] from the
//!   implicit mesh's global triangle ids to mesh triangles. It runs in parallel with rayon
//!   ([`OpcMeshOptions`]) and gives the same mesh at any thread count.
//!   [`OrganizedPointCloud::mesh_reusing`] writes over an earlier mesh's arrays, for
//!   streams of frames.
//!
//! ```
//! use opc_mesh::{DepthOptions, Intrinsics, OpcMeshOptions, OrganizedPointCloud};
//!
//! // A 4 × 6 depth image of a wall 1.5 m away, with one missing pixel.
//! let mut depth = vec![1500u16; 4 * 6];
//! depth[8] = 0;
//! let camera = DepthOptions::new(Intrinsics::new(300.0, 300.0, 3.0, 2.0));
//! let cloud = OrganizedPointCloud::from_depth_image(&depth, 4, 6, &camera)?;
//! assert_eq!(cloud.num_valid(), 23);
//!
//! let opc = cloud.into_mesh(&OpcMeshOptions::default())?;
//! assert_eq!(opc.mesh.num_triangles(), 2 * 3 * 5 - 6); // a pixel is in up to 6 triangles
//! opc.mesh.sanity_check()?;
//! // Normals face the camera.
//! let normals = opc.mesh.triangle_normals().unwrap_or_default();
//! assert!(normals.iter().all(|n| n[2] < -0.999));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![deny(rustdoc::broken_intra_doc_links)]

mod cloud;
mod decimate;
mod depth;
mod error;
mod fill;
mod mesh;
mod rightcut;
mod triangle_map;
mod view;

pub use cloud::{OrganizedPointCloud, is_valid};
pub use decimate::Decimated;
pub use depth::{DepthOptions, Intrinsics};
pub use error::OpcError;
pub use fill::FillConfig;
pub use mesh::{OpcMesh, OpcMeshOptions};
pub use triangle_map::{CellTriangle, NO_TRIANGLE, TriangleMap};
pub use view::OrganizedPointCloudView;

/// The README's example, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
