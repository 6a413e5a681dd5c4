//! The entry points of the organized-cloud filters, and what every backend offers
//! ([`Smoother`]).

use opc_mesh::OrganizedPointCloud;

use crate::{BilateralOptions, CpuSmoother, LaplacianOptions, SlotNormals, SmoothError};

/// A backend of the organized-cloud filters: the smoother's type is where they run
/// ([`CpuSmoother`] on the rayon pool or one thread, [`GpuSmoother`](crate::GpuSmoother)
/// on wgpu). Each keeps its buffers (the GPU its device and pipelines too) between calls,
/// so keep one for a stream of clouds. All give the same answer, the GPU within `f32`
/// rounding (see the crate docs).
///
/// ```
/// use mesh_smooth_gpu::{BilateralOptions, CpuSmoother, LaplacianOptions, Smoother};
/// use opc_mesh::OrganizedPointCloud;
///
/// /// Smoothed normals of `cloud` on whichever backend `smoother` is.
/// fn normals(smoother: &mut dyn Smoother, cloud: &OrganizedPointCloud) -> usize {
///     let smoothed = smoother.laplacian(cloud, &LaplacianOptions::new()).expect("valid options");
///     smoother.bilateral(&smoothed, &BilateralOptions::new()).expect("valid options").num_present()
/// }
///
/// let points: Vec<[f64; 3]> = (0..100).map(|i| [(i % 10) as f64, (i / 10) as f64, 1.0]).collect();
/// let cloud = OrganizedPointCloud::new(10, 10, points).expect("100 points");
/// assert_eq!(normals(&mut CpuSmoother::new(), &cloud), normals(&mut CpuSmoother::serial(), &cloud));
/// ```
pub trait Smoother {
    /// The Laplacian filter of [`laplacian_filter`] on this backend.
    ///
    /// # Errors
    /// Invalid options, and on the GPU a cloud too large for the device or a GPU failure.
    fn laplacian(
        &mut self,
        cloud: &OrganizedPointCloud,
        options: &LaplacianOptions,
    ) -> Result<OrganizedPointCloud, SmoothError>;

    /// The bilateral normal filter of [`bilateral_filter`] on this backend.
    ///
    /// # Errors
    /// As [`Self::laplacian`].
    fn bilateral(
        &mut self,
        cloud: &OrganizedPointCloud,
        options: &BilateralOptions,
    ) -> Result<SlotNormals, SmoothError>;
}

/// Laplacian vertex filter (Polylidar3D Eq. 1–2) on an organized cloud, on the CPU (the
/// rows spread over the current rayon pool); returns the smoothed cloud. To filter many
/// clouds, keep a [`CpuSmoother`] (or, on the GPU, a [`GpuSmoother`](crate::GpuSmoother))
/// instead: it reuses its buffers.
///
/// Computed in `f32` like the original implementation: filtered points carry `f32`
/// precision. Points that are not filtered — invalid (NaN) ones, those within
/// `kernel / 2` of the image edge, and valid ones without a valid neighbour — are returned
/// bit for bit unchanged.
///
/// # Errors
/// Invalid options ([`LaplacianOptions::validate`]).
pub fn laplacian_filter(
    cloud: &OrganizedPointCloud,
    options: &LaplacianOptions,
) -> Result<OrganizedPointCloud, SmoothError> {
    CpuSmoother::new().laplacian(cloud, options)
}

/// Bilateral normal filter (Polylidar3D Eq. 3–5) on the implicit right-cut mesh of an
/// organized cloud, on the CPU as [`laplacian_filter`]: computes every triangle's normal and centroid (in `f32`), filters the
/// normals and returns them per slot (see [`crate::grid`] for the slot convention and how
/// to hand them to a `HalfEdgeMesh`).
///
/// A present triangle without any contributing neighbour, and every triangle of a cell
/// within `kernel / 2` of the cell grid's edge, keeps its unfiltered normal.
///
/// # Errors
/// Invalid options ([`BilateralOptions::validate`]).
pub fn bilateral_filter(
    cloud: &OrganizedPointCloud,
    options: &BilateralOptions,
) -> Result<SlotNormals, SmoothError> {
    CpuSmoother::new().bilateral(cloud, options)
}
