//! Mesh smoothing for Polylidar3D (§5): a Laplacian vertex filter and a bilateral normal
//! filter on organized point clouds, with three backends that agree, plus Laplacian,
//! Taubin and bilateral-normal smoothing for general half-edge meshes.
//!
//! ```
//! use mesh_smooth_gpu::{BilateralOptions, CpuSmoother, LaplacianOptions};
//! use opc_mesh::OrganizedPointCloud;
//!
//! // A 6 × 6 range image of the plane z = 1 with one missing pixel.
//! let mut points: Vec<[f64; 3]> =
//!     (0..36).map(|i| [(i % 6) as f64 * 0.1, (i / 6) as f64 * 0.1, 1.0]).collect();
//! points[14] = [f64::NAN; 3];
//! let cloud = OrganizedPointCloud::new(6, 6, points).expect("36 points");
//!
//! let options = LaplacianOptions::new().with_kernel(3).with_lambda(1.0).with_iterations(2);
//! let smoothed = mesh_smooth_gpu::laplacian_filter(&cloud, &options)?;
//! assert!(smoothed.points()[7][2] - 1.0 < 1e-6); // a plane stays a plane
//!
//! // The same filter on one thread: the backend is the smoother's type.
//! let normals = CpuSmoother::serial().bilateral(&smoothed, &BilateralOptions::new())?;
//! // 25 cells, 2 triangles each; the missing pixel removes 6 of them.
//! assert_eq!(normals.num_present(), 50 - 6);
//! let n = normals.at(2, 3, 0).expect("a present triangle");
//! assert!((n[2].abs() - 1.0).abs() < 1e-6);
//! # Ok::<(), mesh_smooth_gpu::SmoothError>(())
//! ```
//!
//! # Organized clouds
//!
//! [`laplacian_filter`] smooths the points of an [`opc_mesh::OrganizedPointCloud`] over a
//! `kernel × kernel` pixel neighbourhood; [`bilateral_filter`] computes the normals and
//! centroids of the cloud's implicit right-cut mesh and filters the normals, returning
//! [`SlotNormals`] (one per triangle slot; the convention and the mapping to a
//! `HalfEdgeMesh` built by opc-mesh are in [`grid`]). Formulas, border and NaN rules are on
//! [`LaplacianOptions`] and [`BilateralOptions`]. Both compute in `f32`, like the
//! original.
//!
//! # Backends
//!
//! The backend is the smoother's type, and every smoother implements [`Smoother`].
//! [`CpuSmoother::new`] (rows over the rayon pool) and [`CpuSmoother::serial`] (one
//! thread) run the same row kernels and give bit-identical results at any thread count;
//! the free functions [`laplacian_filter`] and [`bilateral_filter`] run the first. The
//! bilateral kernel's weights and sums use fused multiply-adds (`f32::mul_add`, rounded
//! once): one instruction on CPUs with FMA, which the kernel is compiled for, and a
//! slower library call giving the same bits elsewhere.
//! [`GpuSmoother`] runs WGSL
//! compute shaders through wgpu that mirror those kernels operation for operation; GPUs
//! may fuse multiply-adds and use their own `sqrt`, division and `exp`, so results agree
//! with the CPU within `f32` rounding. The tests hold Laplacian points to 1e-5 relative to
//! `1 + |coordinate|` (on lavapipe they are bit-identical) and bilateral unit normals to
//! 1e-4 per component on random clouds with holes; on real data (SynPEB pc_01) all but
//! 0.01 % of the triangles stay within 1e-4 and all within 1e-2. The exceptions are
//! triangles whose normal is unlike all of their neighbours', so that every weight is near
//! `f32` underflow and the result turns with the last bits of `exp` (2 of 498,002 on pc_01,
//! worst 1.9e-3).
//!
//! [`CpuSmoother`] and [`GpuSmoother`] keep their buffers (and the GPU its device and
//! pipelines) across calls: create one and reuse it for a stream of clouds. The free
//! functions create one per call.
//!
//! # General meshes
//!
//! The [`mesh`] module smooths any [`halfedge_mesh::HalfEdgeMesh`]: Laplacian (uniform or
//! inverse-distance weights over 1-ring vertices), Taubin (λ | μ) and bilateral normals
//! over edge-adjacent or vertex-ring triangles, in `f64` with rayon.
//!
//! # Cargo features
//!
//! * `gpu` (default **off**): the wgpu backend behind [`GpuSmoother`]. Without it,
//!   `GpuSmoother::new` returns
//!   [`SmoothError::GpuFeatureDisabled`] (the type still exists, so code using it compiles
//!   either way; `GpuSmoother::from_device` and `adapter_info`, which name wgpu types, need
//!   the feature). Needs a
//!   Vulkan, Metal, DX12 or GL driver at run time; on machines without a GPU, Mesa's
//!   software Vulkan driver (lavapipe, Debian `mesa-vulkan-drivers`) works.

#![deny(rustdoc::broken_intra_doc_links)]

mod cpu;
mod error;
mod filters;
#[cfg(feature = "gpu")]
mod gpu;
#[cfg(not(feature = "gpu"))]
mod gpu_disabled;
pub mod grid;
pub mod mesh;
mod noise;
mod options;

pub use cpu::{CpuSmoother, Smoothed, SmoothedPlanes};
pub use error::SmoothError;
pub use filters::{Smoother, bilateral_filter, laplacian_filter};
#[cfg(feature = "gpu")]
pub use gpu::GpuSmoother;
#[cfg(not(feature = "gpu"))]
pub use gpu_disabled::GpuSmoother;
/// How many times this process has asked wgpu for an adapter (each [`GpuSmoother::new`]
/// asks once, or twice when the primary backends have none and it falls back to all).
/// For tests and diagnostics that check a GPU context is created once and reused; always
/// 0 without the `gpu` feature.
///
/// ```
/// let before = mesh_smooth_gpu::adapter_requests();
/// assert!(mesh_smooth_gpu::adapter_requests() >= before);
/// ```
pub fn adapter_requests() -> u64 {
    #[cfg(feature = "gpu")]
    {
        gpu::adapter_requests()
    }
    #[cfg(not(feature = "gpu"))]
    {
        gpu_disabled::adapter_requests()
    }
}
pub use grid::SlotNormals;
pub use noise::{
    CORRELATION_STRIDE, MAX_AUTO_ITERATIONS, WHITE_NOISE_RATIO, auto_laplacian_iterations,
    estimate_noise, estimate_noise_absolute, estimate_noise_correlation, passes_by_range,
    predict_laplacian_iterations,
};
pub use options::{BilateralOptions, LaplacianOptions, MAX_ITERATIONS, MAX_KERNEL};

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
