//! [`CpuSmoother`]: the CPU backend, with buffers kept across calls.

use std::borrow::Cow;

use opc_mesh::{OpcMesh, OrganizedPointCloud};

use super::bilateral::{
    BilateralWork, bilateral, bilateral_into_mesh, bilateral_of_planes_into_mesh,
};
use super::laplacian::{LaplacianWork, Passes, laplacian_copy, laplacian_in_place};
use crate::{BilateralOptions, LaplacianOptions, SlotNormals, SmoothError, Smoother};

/// The CPU backend, on the current rayon thread pool ([`CpuSmoother::new`]) or on one
/// thread ([`CpuSmoother::serial`]), bit for bit the same either way, with its working buffers (`f32` planes, ping-pong buffers, triangle
/// normals and centroids) kept across calls, so that filtering a stream of clouds of one
/// shape allocates nothing after the first call (fresh memory costs page faults: on a
/// 500 × 500 cloud they were a third of a single Laplacian pass).
///
/// The free functions [`crate::laplacian_filter`] and [`crate::bilateral_filter`] create
/// one per call.
///
/// ```
/// use mesh_smooth_gpu::{BilateralOptions, CpuSmoother, LaplacianOptions, SlotNormals};
/// use opc_mesh::{OpcMesh, OrganizedPointCloud};
///
/// let mut smoother = CpuSmoother::new();
/// let mut normals = SlotNormals::default();
/// for frame in 0..3 {
///     let points: Vec<[f64; 3]> =
///         (0..100).map(|i| [(i % 10) as f64, (i / 10) as f64, frame as f64]).collect();
///     let mut cloud = OrganizedPointCloud::new(10, 10, points).expect("100 points");
///     smoother.laplacian_in_place(&mut cloud, &LaplacianOptions::new())?;
///     smoother.bilateral_into(&cloud, &BilateralOptions::new(), &mut normals)?;
///     assert_eq!(normals.num_present(), 2 * 9 * 9);
/// }
/// # Ok::<(), mesh_smooth_gpu::SmoothError>(())
/// ```
pub struct CpuSmoother {
    parallel: bool,
    laplacian: LaplacianWork,
    bilateral: BilateralWork,
}

impl std::fmt::Debug for CpuSmoother {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CpuSmoother")
            .field("parallel", &self.parallel)
            .finish_non_exhaustive()
    }
}

impl CpuSmoother {
    /// A smoother whose rows are spread over the current rayon thread pool (its size is
    /// the thread count; run inside `ThreadPool::install` to choose it).
    pub fn new() -> Self {
        Self {
            parallel: true,
            laplacian: LaplacianWork::default(),
            bilateral: BilateralWork::default(),
        }
    }

    /// A smoother that runs on the calling thread only.
    pub fn serial() -> Self {
        Self {
            parallel: false,
            ..Self::new()
        }
    }

    /// Whether rows are spread over the rayon pool ([`Self::new`]) or not
    /// ([`Self::serial`]).
    pub fn is_parallel(&self) -> bool {
        self.parallel
    }

    /// The Laplacian filter of [`crate::laplacian_filter`], returning a new cloud.
    ///
    /// # Errors
    /// Invalid options.
    pub fn laplacian(
        &mut self,
        cloud: &OrganizedPointCloud,
        options: &LaplacianOptions,
    ) -> Result<OrganizedPointCloud, SmoothError> {
        let smoothed = self.laplacian_smoothed(Cow::Borrowed(cloud), options, None)?;
        Ok(smoothed.into_cloud())
    }

    /// The Laplacian filter, overwriting the filtered points of `cloud`.
    ///
    /// # Errors
    /// Invalid options (the cloud is then unchanged).
    pub fn laplacian_in_place(
        &mut self,
        cloud: &mut OrganizedPointCloud,
        options: &LaplacianOptions,
    ) -> Result<(), SmoothError> {
        options.validate()?;
        let passes = Passes::Uniform(options.iterations);
        laplacian_in_place(&mut self.laplacian, cloud, options, passes, self.parallel);
        Ok(())
    }

    /// The Laplacian filter with a pass count per pixel: pixel `i` moves in the first
    /// `passes[i]` passes only (0: not at all) and keeps its place afterwards, still
    /// weighing in its neighbours' means; `options.iterations` is ignored (the largest
    /// count is run). Blocks of 32 columns whose pixels are all done are skipped. For
    /// noise that differs across the image, such as an RGB-D camera's depth error growing
    /// with range.
    ///
    /// Every pixel with the same count `n` gives exactly [`Self::laplacian_in_place`] with
    /// `n` iterations.
    ///
    /// ```
    /// use mesh_smooth_gpu::{CpuSmoother, LaplacianOptions};
    /// use opc_mesh::{OpcMesh, OrganizedPointCloud};
    ///
    /// let points: Vec<[f64; 3]> =
    ///     (0..100).map(|i| [(i % 10) as f64, (i / 10) as f64, (i % 3) as f64 * 0.1]).collect();
    /// let mut cloud = OrganizedPointCloud::new(10, 10, points.clone())?;
    /// // The left half stays as it is, the right half takes four passes.
    /// let passes: Vec<u8> = (0..100).map(|i| if i % 10 < 5 { 0 } else { 4 }).collect();
    /// let mut smoother = CpuSmoother::serial();
    /// smoother.laplacian_in_place_per_pixel(&mut cloud, &LaplacianOptions::new(), &passes)?;
    /// assert_eq!(cloud.points()[13], points[13]);
    /// assert_ne!(cloud.points()[17], points[17]);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// Invalid options, or `passes` not one entry per point (the cloud is then unchanged).
    pub fn laplacian_in_place_per_pixel(
        &mut self,
        cloud: &mut OrganizedPointCloud,
        options: &LaplacianOptions,
        passes: &[u8],
    ) -> Result<(), SmoothError> {
        options.validate()?;
        crate::options::check_passes(passes, cloud)?;
        let passes = Passes::PerPixel(passes);
        laplacian_in_place(&mut self.laplacian, cloud, options, passes, self.parallel);
        Ok(())
    }

    /// The bilateral filter of [`crate::bilateral_filter`].
    ///
    /// # Errors
    /// Invalid options.
    pub fn bilateral(
        &mut self,
        cloud: &OrganizedPointCloud,
        options: &BilateralOptions,
    ) -> Result<SlotNormals, SmoothError> {
        let mut out = SlotNormals::default();
        self.bilateral_into(cloud, options, &mut out)?;
        Ok(out)
    }

    /// The bilateral filter, writing into `out` and reusing its allocation.
    ///
    /// # Errors
    /// Invalid options (`out` is then unchanged).
    pub fn bilateral_into(
        &mut self,
        cloud: &OrganizedPointCloud,
        options: &BilateralOptions,
        out: &mut SlotNormals,
    ) -> Result<(), SmoothError> {
        options.validate()?;
        out.refill(cloud.rows(), cloud.cols(), |normals| {
            bilateral(&mut self.bilateral, cloud, options, self.parallel).write_slots(normals);
        });
        Ok(())
    }

    /// The bilateral filter, replacing the triangle normals of a mesh built from the same
    /// cloud by opc-mesh: [`Self::bilateral_into`] then
    /// [`SlotNormals::apply_to_opc_mesh`], with the same results and errors, but without
    /// the per-slot copy in between when the mesh's triangle map is in slot order (as
    /// opc-mesh builds it).
    ///
    /// ```
    /// use mesh_smooth_gpu::{BilateralOptions, CpuSmoother};
    /// use opc_mesh::{OpcMeshOptions, OrganizedPointCloud};
    ///
    /// let points: Vec<[f64; 3]> =
    ///     (0..100).map(|i| [(i % 10) as f64, (i / 10) as f64, 0.01 * (i % 3) as f64]).collect();
    /// let cloud = OrganizedPointCloud::new(10, 10, points)?;
    /// let options = OpcMeshOptions::new().with_compute_normals(false);
    /// let mut opc = cloud.mesh(&options)?;
    /// assert!(opc.mesh.triangle_normals().is_none());
    /// let mut smoother = CpuSmoother::new();
    /// smoother.bilateral_into_mesh(&cloud, &BilateralOptions::new(), &mut opc)?;
    ///
    /// // The same normals as through `SlotNormals`.
    /// let mut other = cloud.mesh(&options)?;
    /// smoother.bilateral(&cloud, &BilateralOptions::new())?.apply_to_opc_mesh(&mut other)?;
    /// assert_eq!(opc.mesh.triangle_normals(), other.mesh.triangle_normals());
    /// assert_eq!(opc.mesh.triangle_normals().map(<[_]>::len), Some(opc.mesh.num_triangles()));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// Invalid options, or a mesh of another cloud ([`SmoothError::BadTriangleMap`]); the
    /// mesh is then unchanged.
    pub fn bilateral_into_mesh(
        &mut self,
        cloud: &OrganizedPointCloud,
        options: &BilateralOptions,
        opc: &mut OpcMesh,
    ) -> Result<(), SmoothError> {
        options.validate()?;
        crate::grid::check_shape(opc, cloud.rows(), cloud.cols())?;
        bilateral_into_mesh(&mut self.bilateral, cloud, options, self.parallel, opc)
    }

    /// The Laplacian filter of `cloud` (in place when it is owned, into a copy when it is
    /// borrowed, as [`Self::laplacian_in_place`] and [`Self::laplacian`]; with `passes`,
    /// one count per point, as [`Self::laplacian_in_place_per_pixel`]), kept with this
    /// smoother for the bilateral filter that follows: meshing the smoothed cloud and then
    /// filtering its normals through [`Smoothed`] (or, once the cloud has moved into its
    /// mesh, through [`SmoothedPlanes`]) gives the results of
    /// [`Self::bilateral_into_mesh`] on it, without converting the cloud to `f32` once
    /// more. The pipeline's way through a frame.
    ///
    /// ```
    /// use std::borrow::Cow;
    /// use mesh_smooth_gpu::{BilateralOptions, CpuSmoother, LaplacianOptions};
    /// use opc_mesh::{OpcMeshOptions, OrganizedPointCloud};
    ///
    /// let points: Vec<[f64; 3]> =
    ///     (0..100).map(|i| [(i % 10) as f64, (i / 10) as f64, 0.01 * (i % 3) as f64]).collect();
    /// let cloud = OrganizedPointCloud::new(10, 10, points)?;
    /// let mut smoother = CpuSmoother::new();
    /// let mut smoothed =
    ///     smoother.laplacian_smoothed(Cow::Borrowed(&cloud), &LaplacianOptions::new(), None)?;
    /// let options = OpcMeshOptions::new().with_compute_normals(false);
    /// let mut opc = smoothed.cloud().mesh(&options)?;
    /// smoothed.bilateral_into_mesh(&BilateralOptions::new(), &mut opc)?;
    /// let smoothed = smoothed.into_cloud();
    ///
    /// // What the two filters give one after the other.
    /// let mut other = smoother.laplacian(&cloud, &LaplacianOptions::new())?.mesh(&options)?;
    /// smoother.bilateral_into_mesh(&smoothed, &BilateralOptions::new(), &mut other)?;
    /// assert_eq!(opc.mesh.triangle_normals(), other.mesh.triangle_normals());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// Invalid options, or `passes` not one entry per point.
    pub fn laplacian_smoothed(
        &mut self,
        cloud: Cow<'_, OrganizedPointCloud>,
        options: &LaplacianOptions,
        passes: Option<&[u8]>,
    ) -> Result<Smoothed<'_>, SmoothError> {
        self.laplacian_smoothed_reusing(cloud, options, passes, Vec::new())
    }

    /// [`Self::laplacian_smoothed`], writing the copy of a borrowed cloud into the storage
    /// of `points` (whose points are dropped): a stream of frames hands in the last
    /// frame's buffer (its mesh's vertices, say) and the copy then touches no fresh
    /// memory. An owned cloud is filtered in place, and `points` dropped.
    ///
    /// ```
    /// use std::borrow::Cow;
    /// use mesh_smooth_gpu::{CpuSmoother, LaplacianOptions};
    /// use opc_mesh::OrganizedPointCloud;
    ///
    /// let points: Vec<[f64; 3]> =
    ///     (0..100).map(|i| [(i % 10) as f64, (i / 10) as f64, 0.01 * (i % 3) as f64]).collect();
    /// let cloud = OrganizedPointCloud::new(10, 10, points)?;
    /// let (options, mut smoother) = (LaplacianOptions::new(), CpuSmoother::new());
    /// let buffer: Vec<[f64; 3]> = Vec::with_capacity(250);
    /// let at = buffer.as_ptr();
    /// let smoothed = smoother
    ///     .laplacian_smoothed_reusing(Cow::Borrowed(&cloud), &options, None, buffer)?
    ///     .into_cloud();
    /// assert_eq!(smoothed.points().as_ptr(), at);
    /// assert_eq!(smoothed, smoother.laplacian(&cloud, &options)?);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// As [`Self::laplacian_smoothed`].
    pub fn laplacian_smoothed_reusing(
        &mut self,
        cloud: Cow<'_, OrganizedPointCloud>,
        options: &LaplacianOptions,
        passes: Option<&[u8]>,
        points: Vec<[f64; 3]>,
    ) -> Result<Smoothed<'_>, SmoothError> {
        options.validate()?;
        if let Some(passes) = passes {
            crate::options::check_passes(passes, &cloud)?;
        }
        let passes = passes.map_or(Passes::Uniform(options.iterations), Passes::PerPixel);
        let work = &mut self.laplacian;
        let cloud = match cloud {
            Cow::Owned(mut cloud) => {
                laplacian_in_place(work, &mut cloud, options, passes, self.parallel);
                cloud
            }
            Cow::Borrowed(cloud) => {
                let points = laplacian_copy(work, cloud, options, passes, self.parallel, points);
                OrganizedPointCloud::new(cloud.rows(), cloud.cols(), points)?
            }
        };
        Ok(Smoothed {
            smoother: self,
            cloud,
        })
    }
}

/// A cloud smoothed by [`CpuSmoother::laplacian_smoothed`], held with the smoother that
/// keeps its `f32` planes: nothing can change the cloud meanwhile, so the bilateral
/// filter starts from those planes.
pub struct Smoothed<'a> {
    smoother: &'a mut CpuSmoother,
    cloud: OrganizedPointCloud,
}

impl std::fmt::Debug for Smoothed<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Smoothed")
            .field("rows", &self.cloud.rows())
            .field("cols", &self.cloud.cols())
            .finish_non_exhaustive()
    }
}

impl<'a> Smoothed<'a> {
    /// The smoothed cloud.
    pub fn cloud(&self) -> &OrganizedPointCloud {
        &self.cloud
    }

    /// Gives the smoothed cloud back.
    pub fn into_cloud(self) -> OrganizedPointCloud {
        self.cloud
    }

    /// The smoothed cloud, free to be moved into its mesh
    /// (`OrganizedPointCloud::into_mesh_reusing`), and its planes for the bilateral
    /// filter; `Err(self)` when the Laplacian filter ran no pass (none asked for, or a
    /// grid within its kernel), which leaves no planes: the bilateral filter then needs
    /// the cloud.
    ///
    /// # Errors
    /// `self` back when there are no planes.
    pub fn into_parts(self) -> Result<(OrganizedPointCloud, SmoothedPlanes<'a>), Self> {
        let Some(second) = self.smoother.laplacian.output() else {
            return Err(self);
        };
        let planes = SmoothedPlanes {
            rows: self.cloud.rows(),
            cols: self.cloud.cols(),
            second,
            valid_points: self.smoother.laplacian.valid_points(),
            smoother: self.smoother,
        };
        Ok((self.cloud, planes))
    }

    /// [`CpuSmoother::bilateral_into_mesh`] on the smoothed cloud.
    ///
    /// # Errors
    /// As [`CpuSmoother::bilateral_into_mesh`].
    pub fn bilateral_into_mesh(
        &mut self,
        options: &BilateralOptions,
        opc: &mut OpcMesh,
    ) -> Result<(), SmoothError> {
        let (rows, cols) = (self.cloud.rows(), self.cloud.cols());
        match self.smoother.laplacian.output() {
            Some(second) => planes_bilateral(self.smoother, second, rows, cols, options, opc),
            None => self.smoother.bilateral_into_mesh(&self.cloud, options, opc),
        }
    }
}

/// The planes of a cloud smoothed by [`CpuSmoother::laplacian_smoothed`] once the cloud
/// has gone ([`Smoothed::into_parts`]), for the bilateral filter.
pub struct SmoothedPlanes<'a> {
    smoother: &'a mut CpuSmoother,
    rows: usize,
    cols: usize,
    /// Which triple of the Laplacian's planes holds the smoothed points.
    second: bool,
    valid_points: usize,
}

impl std::fmt::Debug for SmoothedPlanes<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SmoothedPlanes")
            .field("rows", &self.rows)
            .field("cols", &self.cols)
            .finish_non_exhaustive()
    }
}

impl SmoothedPlanes<'_> {
    /// The smoothed cloud's valid points, [`OrganizedPointCloud::num_valid`] (the filter
    /// keeps them valid), counted as the Laplacian filter read the cloud: the cloud
    /// itself may have moved into its mesh.
    pub fn num_valid(&self) -> usize {
        self.valid_points
    }

    /// [`CpuSmoother::bilateral_into_mesh`] on the smoothed cloud, into its mesh.
    ///
    /// # Errors
    /// As [`CpuSmoother::bilateral_into_mesh`].
    pub fn bilateral_into_mesh(
        &mut self,
        options: &BilateralOptions,
        opc: &mut OpcMesh,
    ) -> Result<(), SmoothError> {
        let Self {
            rows, cols, second, ..
        } = *self;
        planes_bilateral(self.smoother, second, rows, cols, options, opc)
    }
}

/// The bilateral filter of a `rows × cols` cloud from the planes of the smoother's last
/// Laplacian run (the first or the `second` triple), into a mesh of that cloud.
fn planes_bilateral(
    smoother: &mut CpuSmoother,
    second: bool,
    rows: usize,
    cols: usize,
    options: &BilateralOptions,
    opc: &mut OpcMesh,
) -> Result<(), SmoothError> {
    options.validate()?;
    crate::grid::check_shape(opc, rows, cols)?;
    let CpuSmoother {
        parallel,
        laplacian,
        bilateral: work,
    } = smoother;
    let points = laplacian.planes_at(second);
    bilateral_of_planes_into_mesh(
        &mut work.passes,
        points,
        rows,
        cols,
        options,
        *parallel,
        opc,
    )
}

impl Default for CpuSmoother {
    /// [`CpuSmoother::new`].
    fn default() -> Self {
        Self::new()
    }
}

impl Smoother for CpuSmoother {
    fn laplacian(
        &mut self,
        cloud: &OrganizedPointCloud,
        options: &LaplacianOptions,
    ) -> Result<OrganizedPointCloud, SmoothError> {
        CpuSmoother::laplacian(self, cloud, options)
    }

    fn bilateral(
        &mut self,
        cloud: &OrganizedPointCloud,
        options: &BilateralOptions,
    ) -> Result<SlotNormals, SmoothError> {
        CpuSmoother::bilateral(self, cloud, options)
    }
}
