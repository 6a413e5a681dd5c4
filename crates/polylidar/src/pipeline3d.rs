//! The Polylidar3D pipeline: organized clouds and meshes → smoothing → dominant normals →
//! planar segments and polygons → optional post-processing.

use fastga::FastGa;
use halfedge_mesh::{HalfEdgeMesh, MeshOptions};
use std::borrow::Cow;
use std::time::Instant;

use mesh_smooth_gpu::SmoothError;
use opc_mesh::{OpcMesh, OpcMeshOptions, OrganizedPointCloud, OrganizedPointCloudView};
use polypost::{Plane, Polygon3, PostProcessor};

use crate::config::{BilateralConfig, LaplacianConfig, LaplacianIterations, SmoothingBackend};
use crate::reuse;
use crate::{
    Counts, Decimation, ExtractedPolygon, Extraction, Polylidar, PolylidarError,
    PostprocessedPolygon, Timings,
};

impl Polylidar {
    /// Planes and polygons of an organized point cloud (a range image or RGBD frame):
    /// optional Laplacian smoothing, right-cut meshing with triangle normals, optional
    /// bilateral normal smoothing, FastGA dominant normals, planar segmentation with
    /// overlapped polygon extraction, optional post-processing.
    ///
    /// # Errors
    /// Any stage's error: smoothing options or GPU, meshing (no valid triangle),
    /// FastGA options, segmentation, post-processing.
    pub fn extract_organized(
        &self,
        cloud: &OrganizedPointCloud,
    ) -> Result<Extraction, PolylidarError> {
        self.organized(cloud.view(), Some(cloud))
    }

    /// As [`Self::extract_organized`], on a cloud borrowed from someone else's buffer (a
    /// C-contiguous `(H, W, 3)` float64 NumPy array, say): the points are read where they
    /// are. The smoothing filters write their output into a new cloud as they do for owned
    /// input, so with Laplacian smoothing this costs no more than an owned cloud; with
    /// bilateral smoothing alone the points are copied once for the filter.
    ///
    /// ```
    /// use polylidar::{Config, OrganizedPointCloudView, Polylidar};
    /// // A tilted 30 × 30 plane, as a flat row-major buffer.
    /// let flat: Vec<f64> = (0..900)
    ///     .flat_map(|i| {
    ///         let (r, c) = ((i / 30) as f64 * 0.1, (i % 30) as f64 * 0.1);
    ///         [c, r, 2.0 + 0.2 * c]
    ///     })
    ///     .collect();
    /// let view = OrganizedPointCloudView::from_flat(30, 30, &flat)?;
    /// let config = Config::new().with_lmax(0.5).with_z_thresh(0.01).with_min_triangles(50);
    /// let extraction = Polylidar::new(config)?.extract_organized_view(view)?;
    /// assert_eq!(extraction.polygons.len(), 1);
    /// # Ok::<(), polylidar::PolylidarError>(())
    /// ```
    ///
    /// # Errors
    /// As [`Self::extract_organized`].
    pub fn extract_organized_view(
        &self,
        cloud: OrganizedPointCloudView<'_>,
    ) -> Result<Extraction, PolylidarError> {
        self.organized(cloud, None)
    }

    /// Hands a finished extraction back so that the next organized frame is meshed into
    /// its mesh's arrays (triangles and twins; vertices unless both filters run on the
    /// CPU, whose smoothed points move into the mesh; normals where meshing computes them,
    /// that is without the bilateral filter) instead of fresh memory, which would first
    /// have to be allocated and cleared: for a stream of frames of one shape (a 424 × 240
    /// depth frame has about 8 MB of them). Results are the same either way; a mesh of
    /// another shape is grown or cut to fit. The extraction's polygons are dropped with
    /// it.
    ///
    /// ```
    /// use polylidar::{Config, OrganizedPointCloud, Polylidar};
    /// let frame = |z: f64| {
    ///     let points = (0..900).map(|i| [(i % 30) as f64 * 0.1, (i / 30) as f64 * 0.1, z]);
    ///     OrganizedPointCloud::new(30, 30, points.collect())
    /// };
    /// let config = Config::new().with_lmax(0.5).with_z_thresh(0.01).with_min_triangles(50);
    /// let polylidar = Polylidar::new(config)?;
    /// for z in [1.0, 1.1, 1.2] {
    ///     let extraction = polylidar.extract_organized(&frame(z)?)?;
    ///     assert_eq!(extraction.polygons.len(), 1);
    ///     assert_eq!(extraction.mesh.vertices()[0][2], z);
    ///     polylidar.recycle(extraction);
    /// }
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn recycle(&self, extraction: Extraction) {
        self.recycle_mesh(extraction.mesh);
    }

    /// [`Self::recycle`] for the mesh alone (any mesh: only its arrays are reused).
    pub fn recycle_mesh(&self, mesh: HalfEdgeMesh) {
        let left = reuse::lock(&self.reuse).organized.recycle(mesh);
        drop(left);
    }

    /// The organized pipeline on `input`, which is `owned` viewed when the caller owns it.
    fn organized(
        &self,
        input: OrganizedPointCloudView<'_>,
        owned: Option<&OrganizedPointCloud>,
    ) -> Result<Extraction, PolylidarError> {
        self.install(|| {
            let config = self.config();
            let mut timings = Timings::default();
            let mut reuse = reuse::Organized::take_from(&self.reuse);
            let decimated = match &config.decimate {
                Some(d) => timings.time("decimate", || {
                    d.apply(input, || reuse.take_recycled_vertices())
                })?,
                None => None,
            };
            let (mut decimated, decimation) = decimated.unzip();
            // The cloud the filters read (they take an owned cloud): the decimated one,
            // which they then change in place; the caller's cloud, unless missing returns
            // are to be filled in; else a copy of the caller's cloud or view in the
            // recycled mesh's vertex buffer, whose points become the next mesh's
            // vertices. `None` without smoothing or filling, meshing the input itself.
            let mut cloud: Option<Cow<'_, OrganizedPointCloud>> = (config.laplacian.is_some()
                || config.bilateral.is_some()
                || config.fill_missing.is_some())
            .then(|| {
                Ok::<_, PolylidarError>(match (decimated.take(), owned) {
                    (Some(small), _) => Cow::Owned(small),
                    (None, Some(c)) if config.fill_missing.is_none() => Cow::Borrowed(c),
                    _ => Cow::Owned(reuse.copy_of(input)?),
                })
            })
            .transpose()?;
            // What is meshed without filters.
            let input = decimated.as_ref().map_or(input, OrganizedPointCloud::view);
            let mut filled = Vec::new();
            if let (Some(f), Some(c)) = (&config.fill_missing, &mut cloud) {
                filled = timings.time("fill", || c.to_mut().fill_missing(f));
            }
            // The bilateral filter replaces every triangle normal: meshing skips them then.
            let options = OpcMeshOptions::new().with_compute_normals(config.bilateral.is_none());
            let mut laplacian_iterations = 0;
            // The valid points of a smoothed cloud moved into its mesh.
            let mut moved_valid = None;
            let opc = match (&config.laplacian, &config.bilateral, cloud.take()) {
                (Some(l), Some(b), Some(mut c))
                    if l.backend == SmoothingBackend::Gpu && b.backend == SmoothingBackend::Gpu =>
                {
                    let (iterations, opc) =
                        smooth_on_gpu(&mut reuse, l, b, &mut c, &options, &mut timings)?;
                    cloud = Some(c);
                    laplacian_iterations = iterations;
                    opc
                }
                (Some(l), Some(b), Some(c))
                    if l.backend == b.backend && b.backend != SmoothingBackend::Gpu =>
                {
                    let (iterations, opc, smoothed) =
                        smooth_on_cpu(&mut reuse, l, b, c, &options, &mut timings)?;
                    match smoothed {
                        SmoothedCloud::Kept(c) => cloud = Some(c),
                        SmoothedCloud::Moved { valid } => moved_valid = Some(valid),
                    }
                    laplacian_iterations = iterations;
                    opc
                }
                (_, _, taken) => {
                    cloud = taken;
                    if let (Some(l), Some(c)) = (&config.laplacian, &mut cloud) {
                        laplacian_iterations =
                            timings.time("laplacian", || laplacian(&mut reuse, l, c))?;
                    }
                    let storage = reuse.mesh_storage();
                    let mut opc = timings.time("mesh", || match &cloud {
                        Some(c) => c.mesh_reusing(&options, storage),
                        None => input.mesh_reusing(&options, storage),
                    })?;
                    if let (Some(b), Some(c)) = (&config.bilateral, &cloud) {
                        timings.time("bilateral", || {
                            reuse.bilateral(b.backend, c, &b.options(), &mut opc)
                        })?;
                    }
                    opc
                }
            };
            let OpcMesh { mesh, triangle_map } = opc;
            reuse.triangle_map = Some(triangle_map);
            // Put back now: a run at the same time can smooth with it while this one
            // extracts planes.
            drop(reuse);
            let filled_count = filled.iter().filter(|&&f| f).count();
            let grid_points = moved_valid.unwrap_or_else(|| {
                cloud
                    .as_ref()
                    .map_or_else(|| input.num_valid(), |c| c.num_valid())
            }) - filled_count;
            let counts = Counts {
                points: decimation
                    .as_ref()
                    .map_or(grid_points, Decimation::valid_pixels),
                decimated_points: if decimation.is_some() { grid_points } else { 0 },
                laplacian_iterations,
                filled: filled_count,
                ..Counts::default()
            };
            let mut extraction = self.extract_planes(mesh, None, counts, timings)?;
            if filled_count > 0 {
                extraction.filled = filled;
            }
            extraction.decimation = decimation;
            Ok(extraction)
        })
    }

    /// Planes and polygons of a user triangle mesh: half-edge linking (non-manifold edges:
    /// keep the first pair), triangle normals, FastGA dominant normals, planar segmentation
    /// with overlapped polygon extraction, optional post-processing.
    ///
    /// # Errors
    /// As [`Self::extract_organized`], plus [`PolylidarError::Mesh`] for bad triangles
    /// (out-of-range index, NaN vertex, degenerate triangle).
    pub fn extract_mesh(
        &self,
        vertices: Vec<[f64; 3]>,
        triangles: Vec<[u32; 3]>,
    ) -> Result<Extraction, PolylidarError> {
        self.install(|| {
            let mut timings = Timings::default();
            let points = vertices.len();
            let (mesh, _) = timings.time("mesh", || {
                HalfEdgeMesh::from_triangles_with_options(vertices, triangles, MeshOptions::new())
            })?;
            let counts = Counts {
                points,
                ..Counts::default()
            };
            self.extract_planes(mesh, None, counts, timings)
        })
    }

    /// Planes and polygons of a mesh with triangle normals, for the given dominant plane
    /// normals (unit), skipping FastGA; `None` detects them.
    ///
    /// # Errors
    /// As [`Self::extract_organized`].
    pub fn extract_planes_from_mesh(
        &self,
        mesh: HalfEdgeMesh,
        dominant: Option<Vec<[f64; 3]>>,
    ) -> Result<Extraction, PolylidarError> {
        self.install(|| {
            let counts = Counts {
                points: mesh.num_vertices(),
                ..Counts::default()
            };
            self.extract_planes(mesh, dominant, counts, Timings::default())
        })
    }

    /// FastGA (unless `dominant` is given), segmentation and polygons, post-processing.
    pub(crate) fn extract_planes(
        &self,
        mut mesh: HalfEdgeMesh,
        dominant: Option<Vec<[f64; 3]>>,
        mut counts: Counts,
        mut timings: Timings,
    ) -> Result<Extraction, PolylidarError> {
        let config = self.config();
        if mesh.triangle_normals().is_none() {
            mesh.compute_triangle_normals();
        }
        counts.triangles = mesh.num_triangles();
        let dominant = match dominant {
            Some(d) => d,
            None => timings.time("fastga", || self.detect_normals(&mesh))?,
        };
        counts.dominant_normals = dominant.len();
        let segmentation = config.segmentation();
        // Taken out of the shared slot for the run, so that runs at the same time do not
        // wait for each other (each takes its own, see `reuse::Reusable`).
        let mut segmenter = reuse::lock(&self.reuse)
            .segmenter
            .take()
            .unwrap_or_default();
        let found = timings.time("planes_polygons", || {
            segmenter.segment(&mesh, &dominant, &segmentation)
        });
        let left = reuse::lock(&self.reuse).segmenter.put(segmenter);
        drop(left);
        let found = found?;
        let c = found.counts;
        counts.dropped_lmax = c.groups.dropped_lmax;
        counts.dropped_normal = c.groups.dropped_normal;
        counts.triangles_kept = c.groups.grouped;
        counts.regions = c.segments_grown;
        counts.regions_too_small = c.segments_too_small;
        counts.holes = c.holes;
        counts.holes_too_small = c.holes_too_small;
        counts.absorbed = c.absorbed;
        counts.free_planes = c.free_planes;
        counts.merged = c.merged;
        let vertices = mesh.vertices();
        let polygons: Vec<ExtractedPolygon> = found
            .segments
            .into_iter()
            .map(|s| {
                let plane = Plane::from_unit_normal(s.normal, s.centroid);
                let rings = (s.polygon.shell, s.polygon.holes);
                let group = (s.group != planeseg::NO_GROUP).then_some(s.group);
                ExtractedPolygon::new(vertices, rings, plane, s.triangles, group, s.plane)
            })
            .collect();
        let rim_distance = if config.refine && config.z_thresh > 0.0 {
            config.z_thresh / 2.0
        } else {
            0.0
        };
        self.finish(mesh, polygons, (dominant, rim_distance), counts, timings)
    }

    /// Applies the configured post-processing to `extraction.polygons`, if any.
    pub(crate) fn postprocess(&self, extraction: &mut Extraction) -> Result<(), PolylidarError> {
        let Some(p) = self.config().postprocess else {
            return Ok(());
        };
        let processor = PostProcessor::new(p)?;
        let polygons = &extraction.polygons;
        let output = extraction.diagnostics.timings.time("postprocess", || {
            let inputs: Vec<Polygon3> = polygons
                .iter()
                .map(|p| Polygon3::new(p.shell_points.clone(), p.hole_points.clone()))
                .collect();
            let planes: Vec<Plane> = polygons
                .iter()
                .map(|p| Plane::from_normal_and_point(p.plane.normal, p.plane.centroid))
                .collect::<Result<_, _>>()?;
            processor.process_many_3d(&inputs, &planes)
        })?;
        extraction.postprocessed = output
            .polygons
            .into_iter()
            .map(|p| PostprocessedPolygon {
                source: p.source as usize,
                shell: p.polygon.shell,
                holes: p.polygon.holes,
            })
            .collect();
        let counts = &mut extraction.diagnostics.counts;
        counts.postprocessed_polygons = extraction.postprocessed.len();
        counts.postprocess_dropped = output.diagnostics.dropped.len();
        Ok(())
    }
}

impl Polylidar {
    /// Dominant normals of the mesh's triangle normals, with the detector kept between
    /// runs; the sample fraction is raised so that at least `min_samples` normals are
    /// integrated.
    fn detect_normals(&self, mesh: &HalfEdgeMesh) -> Result<Vec<[f64; 3]>, PolylidarError> {
        self.dominant_normals_of(mesh.triangle_normals().unwrap_or(&[]))
    }

    /// FastGA's dominant normals of `normals` (none for none), with the detector kept
    /// between runs and the sample fraction raised as [`crate::DominantNormalsConfig::config_for`] says.
    pub(crate) fn dominant_normals_of(
        &self,
        normals: &[[f64; 3]],
    ) -> Result<Vec<[f64; 3]>, PolylidarError> {
        if normals.is_empty() {
            return Ok(Vec::new());
        }
        let config = self.config().fastga.config_for(normals.len());
        // Taken out for the detection (see `reuse::Reusable`): a run at the same time
        // takes another or builds its own.
        let taken = reuse::lock(&self.reuse).fastga.take();
        let mut fastga = match taken {
            Some(fastga) => fastga,
            None => FastGa::new(config)?,
        };
        let found = fastga
            .set_sample_fraction(config.sample_fraction)
            .and_then(|()| fastga.detect(normals));
        let left = reuse::lock(&self.reuse).fastga.put(fastga);
        drop(left);
        Ok(found?.normals.iter().map(|d| d.normal).collect())
    }
}

/// The Laplacian passes `l` runs on `cloud`: the fixed count, or the one predicted from
/// the cloud's noise (at the median range when the passes grow with range); and the
/// count of each pixel when they grow with range.
fn laplacian_passes(l: &LaplacianConfig, cloud: &OrganizedPointCloud) -> (u32, Option<Vec<u8>>) {
    let iterations = match l.iterations {
        LaplacianIterations::Fixed(n) => n,
        LaplacianIterations::Auto => mesh_smooth_gpu::auto_laplacian_iterations(cloud),
    };
    let passes = (iterations > 0 && l.range_exponent > 0.0)
        .then(|| mesh_smooth_gpu::passes_by_range(cloud, iterations, l.range_exponent))
        .flatten();
    (iterations, passes)
}

/// Both filters on the GPU in one go ([`mesh_smooth_gpu::GpuSmoother::laplacian_then_bilateral`]):
/// the smoothed cloud replaces `cloud` and is meshed on the CPU while the GPU filters the
/// normals, which then replace the mesh's. Records the `laplacian` (until the smoothed
/// cloud is back), `mesh` and `bilateral` (the rest) stages; returns the Laplacian passes
/// and the mesh.
fn smooth_on_gpu(
    reuse: &mut reuse::Organized,
    l: &LaplacianConfig,
    b: &BilateralConfig,
    cloud: &mut Cow<'_, OrganizedPointCloud>,
    options: &OpcMeshOptions,
    timings: &mut Timings,
) -> Result<(u32, OpcMesh), PolylidarError> {
    let start = Instant::now();
    let (iterations, passes) = laplacian_passes(l, cloud);
    let storage = reuse.mesh_storage();
    let (smoothed, (meshed, at, meshing), normals) = reuse.gpu()?.laplacian_then_bilateral(
        cloud,
        &l.options(iterations),
        passes.as_deref(),
        &b.options(),
        |smoothed| {
            let at = start.elapsed();
            let meshed = smoothed.mesh_reusing(options, storage);
            (meshed, at, start.elapsed() - at)
        },
    )?;
    let mut opc = meshed?;
    normals.apply_to_opc_mesh(&mut opc)?;
    *cloud = Cow::Owned(smoothed);
    timings.record("laplacian", at);
    timings.record("mesh", meshing);
    timings.record("bilateral", start.elapsed() - at - meshing);
    Ok((iterations, opc))
}

/// What became of the cloud that [`smooth_on_cpu`] smoothed.
enum SmoothedCloud<'a> {
    /// Still a cloud: when no pass ran, the input (or its copy).
    Kept(Cow<'a, OrganizedPointCloud>),
    /// Moved into the mesh, with this many valid points.
    Moved { valid: usize },
}

/// Both filters on one CPU smoother with meshing in between
/// ([`mesh_smooth_gpu::CpuSmoother::laplacian_smoothed`]: the bilateral filter starts
/// from the Laplacian's `f32` planes, and the smoothed cloud's points move into the mesh
/// instead of being copied). Records the `laplacian`, `mesh` and `bilateral` stages;
/// returns the Laplacian passes, the mesh and what became of the cloud.
fn smooth_on_cpu<'a>(
    reuse: &mut reuse::Organized,
    l: &LaplacianConfig,
    b: &BilateralConfig,
    cloud: Cow<'a, OrganizedPointCloud>,
    options: &OpcMeshOptions,
    timings: &mut Timings,
) -> Result<(u32, OpcMesh, SmoothedCloud<'a>), PolylidarError> {
    let start = Instant::now();
    let (iterations, passes) = laplacian_passes(l, &cloud);
    // A borrowed cloud is filtered into the recycled mesh's vertex buffer: the smoothed
    // points become the mesh's vertices.
    let points = match &cloud {
        Cow::Borrowed(_) if iterations > 0 => reuse.take_recycled_vertices(),
        _ => Vec::new(),
    };
    let storage = reuse.mesh_storage();
    let cloud = if iterations == 0 {
        cloud
    } else {
        let cpu = reuse.cpu(l.backend);
        let smoothing = l.options(iterations);
        let smoothed =
            cpu.laplacian_smoothed_reusing(cloud, &smoothing, passes.as_deref(), points)?;
        match smoothed.into_parts() {
            Ok((smoothed, mut planes)) => {
                timings.record("laplacian", start.elapsed());
                let valid = planes.num_valid();
                let mut opc =
                    timings.time("mesh", || smoothed.into_mesh_reusing(options, storage))?;
                timings.time("bilateral", || {
                    planes.bilateral_into_mesh(&b.options(), &mut opc)
                })?;
                return Ok((iterations, opc, SmoothedCloud::Moved { valid }));
            }
            // No pass ran (per-pixel counts all zero, or a grid within the kernel): the
            // bilateral filter reads the cloud.
            Err(smoothed) => Cow::Owned(smoothed.into_cloud()),
        }
    };
    timings.record("laplacian", start.elapsed());
    let mut opc = timings.time("mesh", || cloud.mesh_reusing(options, storage))?;
    timings.time("bilateral", || {
        reuse.bilateral(b.backend, &cloud, &b.options(), &mut opc)
    })?;
    Ok((iterations, opc, SmoothedCloud::Kept(cloud)))
}

/// Runs the Laplacian filter `l` on `cloud` (in place when it is owned), returning the
/// passes run (see [`laplacian_passes`]).
fn laplacian(
    reuse: &mut reuse::Organized,
    l: &LaplacianConfig,
    cloud: &mut Cow<'_, OrganizedPointCloud>,
) -> Result<u32, SmoothError> {
    let (iterations, passes) = laplacian_passes(l, cloud);
    if iterations == 0 {
        return Ok(0);
    }
    let options = l.options(iterations);
    if let Some(passes) = passes {
        reuse.laplacian_per_pixel(l.backend, cloud.to_mut(), &options, &passes)?;
        return Ok(iterations);
    }
    match cloud {
        Cow::Owned(c) => reuse.laplacian_in_place(l.backend, c, &options)?,
        Cow::Borrowed(c) => {
            let source: &OrganizedPointCloud = c;
            *cloud = Cow::Owned(reuse.laplacian(l.backend, source, &options)?);
        }
    }
    Ok(iterations)
}
