//! The 2D and 2.5D Polylidar pipeline: mesh → filter → regions → polygons.

use halfedge_mesh::{HalfEdgeMesh, MeshError, Regions, TriangleFilter};
use plane_geom::vec3::unit;
use polyextract::Extractor;
use rayon::prelude::*;

use crate::polling::install_polled;
use crate::{Config, Counts, Decimation, Diagnostics, PolylidarError, Timings};

/// A polygon with holes extracted from one region: point indices into the input, their
/// coordinates, and the region's triangles.
#[derive(Debug, Clone, PartialEq)]
pub struct ExtractedPolygon {
    /// Shell point indices, counter-clockwise seen from `up` (open ring).
    pub shell: Vec<u32>,
    /// Hole point indices, clockwise (open rings).
    pub holes: Vec<Vec<u32>>,
    /// Shell coordinates (`z = 0` for 2D input).
    pub shell_points: Vec<[f64; 3]>,
    /// Hole coordinates.
    pub hole_points: Vec<Vec<[f64; 3]>>,
    /// The triangles of the region, indices into [`Extraction::mesh`].
    pub triangles: Vec<u32>,
    /// The plane of the region's triangles (`normal · x + offset = 0`): their
    /// area-weighted mean normal through their area-weighted centroid.
    pub plane: Plane,
    /// 3D: the index of the dominant normal the segment was grown for (into
    /// [`Extraction::dominant_normals`]); `None` for a plane that refinement found
    /// without one, and for 2D and 2.5D input.
    pub group: Option<u32>,
    /// The plane this polygon lies on, as the index of the first polygon on it: its own
    /// index, unless refinement ([`crate::Config::refine`]) found that an earlier polygon
    /// lies on the same plane (a wall seen on both sides of an object in front of it).
    pub plane_id: u32,
}

impl ExtractedPolygon {
    /// A polygon from its index rings `(shell, holes)` into `vertices`.
    pub(crate) fn new(
        vertices: &[[f64; 3]],
        (shell, holes): (Vec<u32>, Vec<Vec<u32>>),
        plane: Plane,
        triangles: Vec<u32>,
        group: Option<u32>,
        plane_id: u32,
    ) -> Self {
        let coords = |ring: &[u32]| -> Vec<[f64; 3]> {
            ring.iter().map(|&i| vertices[i as usize]).collect()
        };
        Self {
            shell_points: coords(&shell),
            hole_points: holes.iter().map(|h| coords(h)).collect(),
            shell,
            holes,
            plane,
            triangles,
            group,
            plane_id,
        }
    }
}

/// The geometric plane of `triangles` of `mesh`: the area-weighted mean triangle normal
/// through the area-weighted centroid.
pub(crate) fn triangles_plane(mesh: &HalfEdgeMesh, triangles: &[u32]) -> Plane {
    let (normal, centroid) = planeseg::geometric_plane(mesh, triangles);
    Plane::from_unit_normal(normal, centroid)
}

/// A post-processed polygon (simplified, buffered, filtered; always valid in its plane),
/// lifted back onto the plane of the polygon it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct PostprocessedPolygon {
    /// Index of the source polygon in [`Extraction::polygons`].
    pub source: usize,
    /// Shell coordinates (open ring, counter-clockwise about the plane normal).
    pub shell: Vec<[f64; 3]>,
    /// Hole coordinates (open rings, clockwise).
    pub holes: Vec<Vec<[f64; 3]>>,
}

/// The result of a pipeline run.
#[derive(Debug, Clone)]
pub struct Extraction {
    /// The triangulation the polygons were extracted from (2D with α > 0: the α-complex;
    /// organized clouds: one vertex per pixel, NaN where invalid).
    pub mesh: HalfEdgeMesh,
    /// The polygons, ordered by their region's first triangle (3D: by dominant normal,
    /// then first triangle).
    pub polygons: Vec<ExtractedPolygon>,
    /// The polygons after post-processing, when the config asks for it (else empty).
    pub postprocessed: Vec<PostprocessedPolygon>,
    /// 3D: the dominant plane normals (unit) the segments were grown for; a polygon's
    /// [`ExtractedPolygon::group`] indexes this. Empty for 2D and 2.5D input.
    pub dominant_normals: Vec<[f64; 3]>,
    /// [`Self::plane_labels`] also gives a vertex in no polygon the plane of the one
    /// polygon whose vertices share triangles with it, when it lies within this distance
    /// of that plane (the rim of a plane, whose triangles reach over the edge onto the
    /// next surface); `0` labels polygon vertices only. The 3D pipelines set it to half of
    /// `z_thresh` with [`crate::Config::refine`] (the spread of points within `z_thresh`
    /// of a plane), `0` otherwise; 2D and 2.5D input leave it `0`.
    pub rim_distance: f64,
    /// Organized clouds: the pixels [`crate::Config::fill_missing`] filled (one flag per
    /// vertex; empty when none was). They are in the mesh and the polygons, but their
    /// labels are `-1`: the input had no measurement there.
    pub filled: Vec<bool>,
    /// Unorganized 3D ([`Polylidar::extract_unorganized`]): the polygon of every input
    /// point chosen by fit — of the polygons whose triangles use it, or (for a point in
    /// none) whose plane its neighbours lie on, the one whose plane is nearest; `-1` for
    /// none. [`Self::point_labels`] and [`Self::plane_labels`] follow it. Empty for the
    /// other inputs.
    pub fitted: Vec<i32>,
    /// Organized clouds that [`crate::Config::decimate`] decimated: how the mesh's
    /// coarser grid maps onto the input's pixels (the labels are expanded through it);
    /// `None` at full resolution.
    pub decimation: Option<Decimation>,
    /// Per-stage counts and timings.
    pub diagnostics: Diagnostics,
}

impl Extraction {
    /// The polygon (index into [`Self::polygons`]) of every mesh vertex, `-1` for none: a
    /// vertex takes the polygon of its triangles; when triangles of several polygons meet
    /// at it, the polygon with more triangles wins (the lower index on a tie). For an
    /// organized cloud vertex `r · cols + c` is pixel `(r, c)`, so this is the predicted
    /// plane image, row-major; a decimated cloud ([`Self::decimation`]) gives one label
    /// per input pixel, its block's (`-1` where the input pixel is invalid or lies across
    /// a depth jump from its block's point).
    ///
    /// ```
    /// use polylidar::{Config, Polylidar};
    /// let points: Vec<[f64; 2]> = (0..100).map(|i| [(i % 10) as f64, (i / 10) as f64]).collect();
    /// let extraction = Polylidar::new(Config::new().with_lmax(1.5))?.extract_2d(&points)?;
    /// let labels = extraction.point_labels();
    /// assert_eq!(labels.len(), 100);
    /// assert!(labels.iter().all(|&l| l == 0));
    /// # Ok::<(), polylidar::PolylidarError>(())
    /// ```
    pub fn point_labels(&self) -> Vec<i32> {
        self.per_pixel(self.labels(|index| index as i32))
    }

    /// The vertex `labels` with `-1` for the [`Self::filled`] pixels, expanded onto the
    /// input's pixels when the cloud was decimated ([`Self::decimation`]).
    fn per_pixel(&self, mut labels: Vec<i32>) -> Vec<i32> {
        for (label, _) in labels.iter_mut().zip(&self.filled).filter(|(_, f)| **f) {
            *label = -1;
        }
        match &self.decimation {
            Some(d) => d.expand(&labels),
            None => labels,
        }
    }

    /// The plane of every vertex, `-1` for none: what a plane segmentation is scored on
    /// (Hoover et al.). As [`Self::point_labels`], with each polygon's
    /// [`ExtractedPolygon::plane_id`] in place of its index, and the rim vertices of
    /// [`Self::rim_distance`]. The same as `point_labels` unless refinement ran.
    ///
    /// ```
    /// use polylidar::{Config, Polylidar};
    /// let points: Vec<[f64; 2]> = (0..100).map(|i| [(i % 10) as f64, (i / 10) as f64]).collect();
    /// let extraction = Polylidar::new(Config::new().with_lmax(1.5))?.extract_2d(&points)?;
    /// assert_eq!(extraction.rim_distance, 0.0);
    /// assert_eq!(extraction.plane_labels(), extraction.point_labels());
    /// # Ok::<(), polylidar::PolylidarError>(())
    /// ```
    pub fn plane_labels(&self) -> Vec<i32> {
        let owner = self.labels(|index| index as i32);
        let plane_of = |polygon: i32| self.polygons[polygon as usize].plane_id as i32;
        if self.rim_distance <= 0.0 {
            return self.per_pixel(
                owner
                    .into_iter()
                    .map(|o| if o < 0 { -1 } else { plane_of(o) })
                    .collect(),
            );
        }
        // Per vertex in no polygon: the one polygon its triangles share vertices with
        // (-1: none, -2: several).
        let mut neighbour = vec![-1i32; owner.len()];
        for tri in self.mesh.triangles() {
            for &v in tri {
                if owner[v as usize] >= 0 {
                    continue;
                }
                for &u in tri {
                    let o = owner[u as usize];
                    let n = &mut neighbour[v as usize];
                    if o >= 0 && *n != o {
                        *n = if *n == -1 { o } else { -2 };
                    }
                }
            }
        }
        let vertices = self.mesh.vertices();
        let labels = owner
            .iter()
            .zip(&neighbour)
            .zip(vertices)
            .map(|((&o, &n), p)| {
                if o >= 0 {
                    return plane_of(o);
                }
                if n < 0 {
                    return -1;
                }
                let plane = &self.polygons[n as usize].plane;
                let d = plane.normal[0] * p[0]
                    + plane.normal[1] * p[1]
                    + plane.normal[2] * p[2]
                    + plane.offset;
                if d.abs() <= self.rim_distance {
                    plane_of(n)
                } else {
                    -1
                }
            })
            .collect();
        self.per_pixel(labels)
    }

    /// The label `label(polygon index)` of every vertex, as [`Self::point_labels`] assigns
    /// vertices to polygons.
    fn labels(&self, label: impl Fn(usize) -> i32) -> Vec<i32> {
        if !self.fitted.is_empty() {
            let by = |o: &i32| if *o < 0 { -1 } else { label(*o as usize) };
            return self.fitted.iter().map(by).collect();
        }
        let mut owner = vec![-1i32; self.mesh.num_vertices()];
        let triangles = self.mesh.triangles();
        let size = |l: i32| self.polygons[l as usize].triangles.len();
        for (index, polygon) in self.polygons.iter().enumerate() {
            let own = polygon.triangles.len();
            for &t in &polygon.triangles {
                for v in triangles[t as usize] {
                    let slot = &mut owner[v as usize];
                    // Polygons come in index order, so an equal size keeps the lower index.
                    if *slot < 0 || size(*slot) < own {
                        *slot = index as i32;
                    }
                }
            }
        }
        owner
            .into_iter()
            .map(|o| if o < 0 { -1 } else { label(o as usize) })
            .collect()
    }
}

/// The Polylidar pipeline for every input kind: 2D point sets, 2.5D clouds, organized
/// clouds and meshes.
///
/// Build it once and reuse it frame after frame: it keeps its thread pool, the FastGA
/// accumulator and the smoothers' buffers between runs (results never depend on earlier
/// runs). It is `Sync`; a run takes those out for its length, and a run from another
/// thread at the same time builds its own.
///
/// ```
/// use polylidar::{Config, Polylidar};
///
/// // A 20 × 20 grid with a 4 × 4 hole in the middle.
/// let points: Vec<[f64; 2]> = (0..400)
///     .map(|i| [(i % 20) as f64, (i / 20) as f64])
///     .filter(|p| !(8.0..12.0).contains(&p[0]) || !(8.0..12.0).contains(&p[1]))
///     .collect();
/// let polylidar = Polylidar::new(Config::new().with_lmax(1.5))?;
/// let extraction = polylidar.extract_2d(&points)?;
/// assert_eq!(extraction.polygons.len(), 1);
/// assert_eq!(extraction.polygons[0].holes.len(), 1);
/// # Ok::<(), polylidar::PolylidarError>(())
/// ```
#[derive(Debug)]
pub struct Polylidar {
    config: Config,
    pool: Option<rayon::ThreadPool>,
    /// Kept between 3D runs: the FastGA detector (building its accumulator costs more
    /// than integrating a frame's normals; fastga's README has the figures) and the
    /// smoothers' buffers. A run takes what it uses out of the slot and puts it back
    /// (see [`crate::reuse::Reusable`]).
    pub(crate) reuse: std::sync::Mutex<crate::reuse::Reusable>,
}

impl Polylidar {
    /// Checks the configuration and prepares the worker threads.
    ///
    /// # Errors
    /// [`PolylidarError::Config`] for out-of-range parameters,
    /// [`PolylidarError::ThreadPool`] if the threads cannot start.
    pub fn new(config: Config) -> Result<Self, PolylidarError> {
        config.validate()?;
        let pool = match config.threads {
            0 => None,
            threads => Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .map_err(|e| PolylidarError::ThreadPool {
                        threads,
                        message: e.to_string(),
                    })?,
            ),
        };
        Ok(Self {
            config,
            pool,
            reuse: std::sync::Mutex::default(),
        })
    }

    /// The configuration in use.
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// Extracts polygons from a 2D point set: Delaunay triangulation, α / `lmax`
    /// filtering, region growing, boundary following.
    ///
    /// # Errors
    /// [`PolylidarError::Mesh`] for input that cannot be triangulated (fewer than 3
    /// points, NaN, all collinear), [`PolylidarError::Extract`] if a boundary is broken.
    pub fn extract_2d(&self, points: &[[f64; 2]]) -> Result<Extraction, PolylidarError> {
        self.install(|| {
            let mut timings = Timings::default();
            let alpha = self.config.alpha;
            if alpha > 0.0 {
                // The α-complex is built directly (in parallel strips): the same triangles
                // as Delaunay followed by the α test, without materialising the rest.
                let (mesh, report) =
                    timings.time("mesh", || HalfEdgeMesh::alpha_complex_2d(points, alpha))?;
                let counts = Counts {
                    points: points.len(),
                    duplicate_points: report.duplicate_points,
                    triangles: report.delaunay_triangles,
                    dropped_alpha: report.dropped_alpha,
                    ..Counts::default()
                };
                return self.extract_from_mesh(mesh, None, 0.0, counts, timings, |p| [p[0], p[1]]);
            }
            let (mesh, report) =
                timings.time("mesh", || HalfEdgeMesh::delaunay_2d_with_report(points))?;
            let counts = Counts {
                points: points.len(),
                duplicate_points: report.duplicate_points,
                triangles: mesh.num_triangles(),
                ..Counts::default()
            };
            self.extract_from_mesh(mesh, None, 0.0, counts, timings, |p| [p[0], p[1]])
        })
    }

    /// Extracts polygons from a 3D cloud seen along [`Config::up`] (2.5D): triangulation of
    /// the projected points, the normal test against `up`, α / `lmax` on 3D triangles,
    /// region growing, and boundary following in the plane orthogonal to `up`.
    ///
    /// # Errors
    /// As [`Self::extract_2d`].
    pub fn extract_25d(&self, points: &[[f64; 3]]) -> Result<Extraction, PolylidarError> {
        self.install(|| {
            let mut timings = Timings::default();
            let up = unit(self.config.up).ok_or(MeshError::BadUpVector { up: self.config.up })?;
            let (mesh, report) = timings.time("mesh", || {
                HalfEdgeMesh::delaunay_25d_with_report(points, up)
            })?;
            let counts = Counts {
                points: points.len(),
                duplicate_points: report.duplicate_points,
                triangles: mesh.num_triangles(),
                ..Counts::default()
            };
            let frame = PlaneFrame::new(up).ok_or(MeshError::BadUpVector { up })?;
            let alpha = self.config.alpha;
            self.extract_from_mesh(mesh, Some(up), alpha, counts, timings, |p| frame.project(p))
        })
    }

    /// The threads of the pipeline's pool (rayon's global one with `threads` 0).
    pub(crate) fn threads(&self) -> usize {
        self.pool.as_ref().map_or_else(
            rayon::current_num_threads,
            rayon::ThreadPool::current_num_threads,
        )
    }

    /// Runs `f` in the pipeline's pool (rayon's global one with `threads` 0), a second
    /// worker polling for work while it runs (see [`install_polled`]).
    pub(crate) fn install<T: Send>(&self, f: impl FnOnce() -> T + Send) -> T {
        install_polled(self.pool.as_ref(), f)
    }

    /// Filter (α test with `alpha`, which is 0 when the mesh is already an α-complex),
    /// regions and polygons on a built mesh. `counts.triangles` (and `dropped_alpha` of an
    /// α-complex) are set by the caller.
    fn extract_from_mesh(
        &self,
        mesh: HalfEdgeMesh,
        up: Option<[f64; 3]>,
        alpha: f64,
        mut counts: Counts,
        mut timings: Timings,
        project: impl Fn([f64; 3]) -> [f64; 2] + Sync,
    ) -> Result<Extraction, PolylidarError> {
        let config = &self.config;
        let (regions, kept) = timings.time("regions", || {
            let mut filter = TriangleFilter::new()
                .with_alpha(alpha)
                .with_lmax(config.lmax);
            if let Some(u) = up {
                filter = filter.with_up(u, config.norm_thresh);
            }
            let (keep, dropped) = filter.apply(&mesh);
            counts.dropped_normal = dropped.normal;
            counts.dropped_lmax = dropped.lmax;
            counts.dropped_alpha += dropped.alpha;
            counts.triangles_kept =
                counts.triangles - dropped.normal - dropped.lmax - counts.dropped_alpha;
            let regions = Regions::grow(&mesh, &keep)?;
            let kept: Vec<usize> = (0..regions.len())
                .filter(|&r| regions.region(r).len() >= config.min_triangles.max(1))
                .collect();
            Ok::<_, PolylidarError>((regions, kept))
        })?;
        counts.regions = regions.len();
        counts.regions_too_small = regions.len() - kept.len();

        let vertices = mesh.vertices();
        let results: Vec<Result<(ExtractedPolygon, usize), PolylidarError>> =
            timings.time("polygons", || {
                kept.par_iter()
                    .enumerate()
                    .map_init(Extractor::new, |extractor, (k, &r)| {
                        let triangles = regions.region(r);
                        let label = r as u32;
                        let polygon = extractor
                            .extract(
                                &mesh,
                                triangles,
                                |t| regions.labels()[t as usize] == label,
                                |i| project(vertices[i as usize]),
                            )
                            .map_err(|source| PolylidarError::Extract { region: k, source })?;
                        let before = polygon.holes.len();
                        let holes: Vec<Vec<u32>> = polygon
                            .holes
                            .into_iter()
                            .filter(|h| h.len() >= config.min_hole_vertices)
                            .collect();
                        let plane = triangles_plane(&mesh, triangles);
                        let polygon = ExtractedPolygon::new(
                            vertices,
                            (polygon.shell, holes),
                            plane,
                            triangles.to_vec(),
                            None,
                            k as u32,
                        );
                        Ok((polygon, before))
                    })
                    .collect()
            });
        let mut polygons = Vec::with_capacity(results.len());
        for result in results {
            let (polygon, holes_before) = result?;
            counts.holes += polygon.holes.len();
            counts.holes_too_small += holes_before - polygon.holes.len();
            polygons.push(polygon);
        }
        self.finish(mesh, polygons, (Vec::new(), 0.0), counts, timings)
    }

    /// The extraction of `polygons` found on `mesh`, post-processed as configured.
    pub(crate) fn finish(
        &self,
        mesh: HalfEdgeMesh,
        polygons: Vec<ExtractedPolygon>,
        (dominant_normals, rim_distance): (Vec<[f64; 3]>, f64),
        mut counts: Counts,
        timings: Timings,
    ) -> Result<Extraction, PolylidarError> {
        counts.polygons = polygons.len();
        let mut extraction = Extraction {
            mesh,
            polygons,
            postprocessed: Vec::new(),
            dominant_normals,
            rim_distance,
            filled: Vec::new(),
            fitted: Vec::new(),
            decimation: None,
            diagnostics: Diagnostics { counts, timings },
        };
        self.postprocess(&mut extraction)?;
        Ok(extraction)
    }
}

/// The 2.5D pipeline extracts polygons in the plane orthogonal to `up`, in the frame
/// its triangulation (`HalfEdgeMesh::delaunay_25d`) projects on: for `up = +z` plain
/// `(x, y)`.
///
/// ```
/// use polylidar::PlaneFrame;
/// let frame = PlaneFrame::new([0.0, 0.0, 2.0]).ok_or("zero up")?;
/// assert_eq!(frame.project([3.0, 4.0, 5.0]), [3.0, 4.0]);
/// # Ok::<(), &str>(())
/// ```
pub use plane_geom::PlaneFrame;

/// The plane of an extracted polygon (`normal · x + offset = 0`, a unit normal and a
/// point on it): the workspace's shared type from `plane-geom`.
pub use plane_geom::Plane;
