//! Planar simplification and texturing after Ma, Whelan, Bondarev, de With and McDonald,
//! "Planar simplification and texturing of dense point cloud maps" (ECMR 2013):
//! each planar segment of a dense cloud becomes a small triangle mesh with a texture.
//!
//! For one segment — its points, optional colours, and its boundary polygon with holes
//! (for example from Polylidar3D) — [`simplify()`] runs the paper's steps:
//!
//! 1. **preprocessing** (§IV-A1): least-squares plane by PCA ([`fit_frame`]) and the
//!    transform into its x-y frame; the polygon serves as the concave hull;
//! 2. **quadtree decimation** (§IV-A2): a square box over the polygon subdivided to a
//!    [`Depth`]; nodes interior, boundary or exterior against the polygon with holes;
//!    interior nodes merged bottom-up; their corners become the interior vertices, every
//!    boundary vertex is kept;
//! 3. **triangulation** ([`Method`]): point-based (§IV-B1, constrained Delaunay triangulation
//!    of all kept vertices, ring edges as constraints) or polygon-based (§IV-B2, two right
//!    triangles per interior node and the band up to the boundary by constrained Delaunay
//!    triangulation, with no T-joints and no duplicate vertices on the band's outline), or
//!    the paper's boundary-only baseline;
//! 4. **texture** (§V, Alg. 1–2, [`TextureOptions`]): a picture of the plane at `r` texels
//!    per unit length (the paper's 100 per metre, or from the point density), every texel
//!    inside the polygon coloured by its nearest point (a uniform grid of the points), and uv
//!    coordinates for every vertex.
//!
//! Planes are independent: [`simplify_all`] runs them on rayon's pool, and [`merge()`] makes
//! one mesh of them with one texture atlas; [`export`] writes OBJ + MTL, PLY and PNG bytes.
//! [`quality`] measures triangle angles and checks the invariants the tests rely on.
//!
//! This crate has no feature flags.
//!
//! ```
//! use planar_mesh::{Method, SimplifyOptions, Segment, TextureOptions, simplify};
//!
//! // A 2 m × 1 m wall sampled every 2 cm, left half red, right half blue, with its outline.
//! let (nx, ny) = (101, 51);
//! let points: Vec<[f64; 3]> = (0..nx * ny)
//!     .map(|k| [(k % nx) as f64 * 0.02, 0.0, (k / nx) as f64 * 0.02])
//!     .collect();
//! let colors: Vec<[u8; 3]> = points
//!     .iter()
//!     .map(|p| if p[0] < 1.0 { [255, 0, 0] } else { [0, 0, 255] })
//!     .collect();
//! let shell = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 0.0, 1.0], [0.0, 0.0, 1.0]];
//! let options = SimplifyOptions::new()
//!     .with_method(Method::Point)
//!     .with_texture(TextureOptions::new());
//! let mesh = simplify(&Segment::new(&points, &shell, &[]).with_colors(&colors), &options)?;
//! let texture = mesh.texture.as_ref().expect("asked for");
//! assert_eq!((texture.width, texture.height), (200, 100)); // 100 texels per metre
//! assert_eq!(mesh.uv.len(), mesh.vertices.len());
//! # Ok::<(), planar_mesh::PlanarMeshError>(())
//! ```

#![forbid(unsafe_code)]
#![deny(rustdoc::broken_intra_doc_links)]

mod cdt;
mod error;
pub mod export;
mod frame;
mod merge;
mod nearest;
mod outline;
mod polygon;
mod quadtree;
pub mod quality;
mod simplify;
mod squares;
mod texture;
mod triangulate;

pub use error::PlanarMeshError;
pub use frame::fit_frame;
pub use merge::{ATLAS_GUTTER, Atlas, MergedMesh, Packing, PlaneRange, merge};
pub use plane_geom::PlaneFrame;
pub use quadtree::{AUTO_CELL_EDGES, MAX_DEPTH};
pub use simplify::{
    Depth, PlaneMesh, PlaneStats, Segment, SimplifyOptions, simplify, simplify_all,
};
pub use texture::{DEFAULT_TEXELS_PER_UNIT, Resolution, Texture, TextureOptions};
pub use triangulate::Method;

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
