//! The entry points of the organized-cloud filters, dispatching on [`Backend`].

use opc_mesh::OrganizedPointCloud;

use crate::{Backend, BilateralOptions, CpuSmoother, LaplacianOptions, SlotNormals, SmoothError};

/// Laplacian vertex filter (Polylidar3D Eq. 1–2) on an organized cloud; returns the
/// smoothed cloud. To filter many clouds, keep a [`CpuSmoother`] (or
/// [`GpuSmoother`](crate::GpuSmoother)) instead: it reuses its buffers.
///
/// Computed in `f32` like the original implementation: filtered points carry `f32`
/// precision. Points that are not filtered — invalid (NaN) ones, those within
/// `kernel / 2` of the image edge, and valid ones without a valid neighbour — are returned
/// bit for bit unchanged.
///
/// # Errors
/// Invalid options ([`LaplacianOptions::validate`]); with [`Backend::Gpu`], the errors of
/// [`GpuSmoother::new`](crate::GpuSmoother::new) and
/// [`GpuSmoother::laplacian`](crate::GpuSmoother::laplacian), or
/// [`SmoothError::GpuFeatureDisabled`] without the `gpu` feature.
pub fn laplacian_filter(
    cloud: &OrganizedPointCloud,
    options: &LaplacianOptions,
) -> Result<OrganizedPointCloud, SmoothError> {
    options.validate()?;
    match options.backend {
        Backend::Cpu | Backend::CpuParallel => {
            CpuSmoother::new(options.backend)?.laplacian(cloud, options)
        }
        Backend::Gpu => gpu_laplacian(cloud, options),
    }
}

/// Bilateral normal filter (Polylidar3D Eq. 3–5) on the implicit right-cut mesh of an
/// organized cloud: computes every triangle's normal and centroid (in `f32`), filters the
/// normals and returns them per slot (see [`crate::grid`] for the slot convention and how
/// to hand them to a `HalfEdgeMesh`).
///
/// A present triangle without any contributing neighbour, and every triangle of a cell
/// within `kernel / 2` of the cell grid's edge, keeps its unfiltered normal.
///
/// # Errors
/// As [`laplacian_filter`], for [`BilateralOptions`].
pub fn bilateral_filter(
    cloud: &OrganizedPointCloud,
    options: &BilateralOptions,
) -> Result<SlotNormals, SmoothError> {
    options.validate()?;
    match options.backend {
        Backend::Cpu | Backend::CpuParallel => {
            CpuSmoother::new(options.backend)?.bilateral(cloud, options)
        }
        Backend::Gpu => gpu_bilateral(cloud, options),
    }
}

fn gpu_laplacian(
    cloud: &OrganizedPointCloud,
    options: &LaplacianOptions,
) -> Result<OrganizedPointCloud, SmoothError> {
    crate::GpuSmoother::new()?.laplacian(cloud, options)
}

fn gpu_bilateral(
    cloud: &OrganizedPointCloud,
    options: &BilateralOptions,
) -> Result<SlotNormals, SmoothError> {
    crate::GpuSmoother::new()?.bilateral(cloud, options)
}
