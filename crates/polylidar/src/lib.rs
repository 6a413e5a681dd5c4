//! Polylidar in Rust: planes and non-convex polygons with holes from 2D point sets, point
//! clouds, range images and meshes.
//!
//! This facade chains the stages of the workspace into one [`Polylidar`] pipeline, built
//! from a [`Config`] (serde / TOML, or a named [`Config::preset`] from the papers), with
//! one entry point per input kind:
//!
//! * 2D point sets ([`Polylidar::extract_2d`]): the α-complex of the Delaunay triangulation
//!   (or `lmax`, longest edge), region growing over twin half-edges, boundary following
//!   into polygons with holes (the 2D paper);
//! * 3D clouds seen from one direction ([`Polylidar::extract_25d`], "2.5D"): the same on
//!   the cloud triangulated along [`Config::up`], with triangles kept only where their
//!   normal is within `norm_thresh` of `up` — flat roofs and floors from airborne LiDAR;
//! * organized clouds — range images, RGBD frames ([`Polylidar::extract_organized`]) — and
//!   user meshes ([`Polylidar::extract_mesh`], [`Polylidar::extract_planes_from_mesh`]):
//!   Polylidar3D — optional Laplacian and bilateral smoothing, FastGA dominant normals,
//!   parallel planar segmentation with overlapped polygon extraction, each polygon with
//!   its plane, and optional post-processing into valid simplified polygons.
//!
//! * rotating LiDAR frames — KITTI's Velodyne ([`Polylidar::extract_scan`], the `kitti`
//!   presets): beams recovered from the firing order, thinning and beam-neighbour outlier
//!   removal, then the 2.5D path (the ground with obstacles as holes) or the organized 3D
//!   path on the rebuilt range image.
//!
//! Each result carries per-stage [`Counts`] and [`Timings`] so that an empty result can be
//! explained. [`Extraction::planar_meshes`] turns the planes into light, optionally
//! textured triangle meshes ([`planar_mesh`], Ma et al. 2013).
//!
//! ```
//! use polylidar::{Config, Polylidar};
//!
//! let points: Vec<[f64; 2]> = (0..900).map(|i| [(i % 30) as f64, (i / 30) as f64]).collect();
//! let extraction = Polylidar::new(Config::new().with_alpha(1.0))?.extract_2d(&points)?;
//! assert_eq!(extraction.polygons.len(), 1);
//! assert_eq!(extraction.diagnostics.counts.triangles_kept, 29 * 29 * 2);
//! # Ok::<(), polylidar::PolylidarError>(())
//! ```

#![deny(rustdoc::broken_intra_doc_links)]

mod config;
mod decimate;
mod diagnostics;
mod error;
pub mod explain;
#[cfg(feature = "io")]
pub mod io;
mod mesh;
pub mod misses;
pub mod output;
mod pipeline;
mod pipeline3d;
mod polling;
mod preset;
mod reuse;
pub mod scale;
mod scan;
pub mod stream;
pub mod tiles;
pub mod unorganized;

pub use config::{
    BilateralConfig, Config, DominantNormalsConfig, LaplacianConfig, LaplacianIterations,
    MAX_RANGE_EXPONENT, MAX_THREADS_PER_CORE, SmoothingBackend, max_threads, parse_cosine,
};
pub use decimate::{DecimateConfig, DecimateFactor, Decimation, MAX_DECIMATE_FACTOR};
pub use diagnostics::{Counts, Diagnostics, Timings};
pub use error::PolylidarError;
// The stage errors `PolylidarError` wraps, so that a caller can match on them.
pub use cloud_normals::NormalsError;
pub use fastga::FastGaConfig;
pub use fastga::FastGaError;
pub use halfedge_mesh::{HalfEdgeMesh, MeshError};
pub use mesh::PlanarMeshes;
pub use mesh_smooth_gpu::SmoothError;
pub use planeseg::SegmentError;
pub use polyextract::ExtractError;
#[cfg(feature = "io")]
pub use polylidar_io::IoError;
pub use polypost::PostError;
pub use rotating_scan::ScanError;
// Noise estimates and the trained models that turn them into smoothing passes: the
// organized path's in `mesh-smooth-gpu`, beside the Laplacian filter they drive; the
// unorganized path's in `cloud-normals`, beside its point smoothing.
pub use cloud_normals::predict_smoothing_passes;
pub use mesh_smooth_gpu::{
    CORRELATION_STRIDE, MAX_AUTO_ITERATIONS, WHITE_NOISE_RATIO, auto_laplacian_iterations,
    estimate_noise, estimate_noise_absolute, estimate_noise_correlation, passes_by_range,
    predict_laplacian_iterations,
};
pub use opc_mesh::{
    DepthOptions, FillConfig, Intrinsics, OpcError, OrganizedPointCloud, OrganizedPointCloudView,
};
// The stage configurations the facade's `Config` holds as they are (their `serde`
// features give them their TOML form).
pub use pipeline::{
    ExtractedPolygon, Extraction, Plane, PlaneFrame, Polylidar, PostprocessedPolygon,
};
/// Planar simplification and texturing (Ma et al. 2013), re-exported: see
/// [`Extraction::planar_meshes`].
pub use planar_mesh;
pub use polypost::{BufferJoin, PostprocessConfig};
pub use preset::{Preset, UnknownPreset};
pub use rotating_scan::BeamOutlierConfig;
pub use scan::{BeamSource, FieldOfViewConfig, PreparedScan, ScanConfig};
pub use unorganized::UnorganizedConfig;

#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
