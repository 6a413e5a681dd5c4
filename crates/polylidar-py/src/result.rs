//! What a run returns to Python: [`Extraction`] with its [`Polygon`]s and [`Mesh`].

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{PoisonError, RwLock, RwLockReadGuard};

use numpy::{PyArray1, PyArrayMethods};
use polylidar::HalfEdgeMesh;
use polylidar::output::{PolygonSet, feature_collection, polygon_area};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyList, PyTuple};

use crate::arrays::{rows_to_array, triangles_to_array};
use crate::config::from_json;

/// A polygon with holes on a plane.
#[pyclass(frozen, module = "polylidar_rs")]
pub struct Polygon {
    /// Shell coordinates (open ring).
    pub shell: Vec<[f64; 3]>,
    /// Hole coordinates (open rings).
    pub holes: Vec<Vec<[f64; 3]>>,
    /// Shell and hole point indices (extracted polygons only).
    pub indices: Option<(Vec<u32>, Vec<Vec<u32>>)>,
    /// Unit normal of the plane.
    pub normal: [f64; 3],
    /// `normal · p + offset = 0`.
    pub offset: f64,
    /// A point on the plane.
    pub centroid: [f64; 3],
    /// Triangles of the plane segment (extracted polygons only).
    pub triangles: Option<Vec<u32>>,
    /// Plane id (extracted) or source polygon (post-processed).
    pub plane_id: Option<u32>,
    /// Index of the source polygon of a post-processed one.
    pub source: Option<usize>,
    /// Dominant normal index of the segment.
    pub group: Option<u32>,
    /// 2 for 2D input (coordinates `[x, y]`), else 3.
    pub dims: usize,
}

fn ring_array<'py>(py: Python<'py>, ring: &[[f64; 3]], dims: usize) -> PyResult<Bound<'py, PyAny>> {
    if dims == 2 {
        rows_to_array(py, ring.iter().map(|p| [p[0], p[1]]).collect::<Vec<_>>())
    } else {
        rows_to_array(py, ring.to_vec())
    }
}

fn ring_tuple<'py>(
    py: Python<'py>,
    ring: &[[f64; 3]],
    dims: usize,
) -> PyResult<Bound<'py, PyTuple>> {
    let coords: Vec<Bound<'py, PyTuple>> = ring
        .iter()
        .chain(ring.first())
        .map(|p| PyTuple::new(py, &p[..dims]))
        .collect::<PyResult<_>>()?;
    PyTuple::new(py, coords)
}

#[pymethods]
impl Polygon {
    /// Shell coordinates, an ``(K, 3)`` float64 array (``(K, 2)`` for 2D input), counter-
    /// clockwise about the normal, not closed.
    #[getter]
    fn shell<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        ring_array(py, &self.shell, self.dims)
    }

    /// Hole coordinates: a list of ``(K, 3)`` (2D input: ``(K, 2)``) arrays, clockwise.
    #[getter]
    fn holes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let rings: Vec<_> = self
            .holes
            .iter()
            .map(|h| ring_array(py, h, self.dims))
            .collect::<PyResult<_>>()?;
        PyList::new(py, rings)
    }

    /// Indices of the shell's points into the input points (mesh vertices), or ``None``
    /// for a post-processed polygon (whose vertices are new).
    #[getter]
    fn shell_indices<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<u32>>> {
        self.indices
            .as_ref()
            .map(|(shell, _)| PyArray1::from_slice(py, shell))
    }

    /// Indices of each hole's points, or ``None`` for a post-processed polygon.
    #[getter]
    fn hole_indices<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyList>>> {
        self.indices
            .as_ref()
            .map(|(_, holes)| PyList::new(py, holes.iter().map(|h| PyArray1::from_slice(py, h))))
            .transpose()
    }

    /// Unit normal of the polygon's plane, an ``(3,)`` float64 array.
    #[getter]
    fn normal<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.normal)
    }

    /// Offset ``d`` of the plane ``normal · p + d = 0``.
    #[getter]
    fn offset(&self) -> f64 {
        self.offset
    }

    /// Area in the polygon's plane: the shell's minus the holes' (input units²).
    #[getter]
    fn area(&self) -> f64 {
        polygon_area(self.normal, &self.shell, &self.holes)
    }

    /// Indices of the mesh triangles of the plane segment (``None`` when post-processed).
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<u32>>> {
        self.triangles.as_ref().map(|t| PyArray1::from_slice(py, t))
    }

    /// The plane the polygon lies on: the index of the first polygon on it (3D with
    /// refinement can find one plane in several pieces). ``None`` when post-processed.
    #[getter]
    fn plane_id(&self) -> Option<u32> {
        self.plane_id
    }

    /// Index of the dominant normal the segment was grown for (3D), else ``None``.
    #[getter]
    fn group(&self) -> Option<u32> {
        self.group
    }

    /// For a post-processed polygon, the index of the extracted polygon it came from.
    #[getter]
    fn source(&self) -> Option<usize> {
        self.source
    }

    /// The polygon as a GeoJSON-like mapping (closed rings, ``[x, y, z]`` coordinates, or
    /// ``[x, y]`` for 2D input): ``shapely.geometry.shape(polygon)`` works.
    #[getter]
    fn __geo_interface__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let mut rings = vec![ring_tuple(py, &self.shell, self.dims)?];
        for hole in &self.holes {
            rings.push(ring_tuple(py, hole, self.dims)?);
        }
        let dict = PyDict::new(py);
        dict.set_item("type", "Polygon")?;
        dict.set_item("coordinates", PyTuple::new(py, rings)?)?;
        Ok(dict)
    }

    fn __repr__(&self) -> String {
        format!(
            "Polygon(shell={} points, holes={}, area={:.4}, normal=[{:.3}, {:.3}, {:.3}])",
            self.shell.len(),
            self.holes.len(),
            self.area(),
            self.normal[0],
            self.normal[1],
            self.normal[2]
        )
    }
}

/// A triangle mesh: vertices, triangles, triangle normals.
#[pyclass(frozen, module = "polylidar_rs")]
pub struct Mesh {
    /// The half-edge mesh.
    pub mesh: HalfEdgeMesh,
    /// Organized meshes: `(rows, cols)` of the cloud, so that vertex `r · cols + c` is pixel
    /// `(r, c)`.
    pub grid: Option<(usize, usize)>,
}

#[pymethods]
impl Mesh {
    /// Vertex coordinates, an ``(N, 3)`` float64 array (a copy).
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        rows_to_array(py, self.mesh.vertices().to_vec())
    }

    /// Triangles, an ``(M, 3)`` uint32 array of vertex indices (counter-clockwise).
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        triangles_to_array(py, self.mesh.triangles().to_vec())
    }

    /// Unit triangle normals, an ``(M, 3)`` float64 array, or ``None`` if not computed.
    #[getter]
    fn triangle_normals<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.mesh
            .triangle_normals()
            .map(|n| rows_to_array(py, n.to_vec()))
            .transpose()
    }

    /// Number of vertices.
    #[getter]
    fn num_vertices(&self) -> usize {
        self.mesh.num_vertices()
    }

    /// Number of triangles.
    #[getter]
    fn num_triangles(&self) -> usize {
        self.mesh.num_triangles()
    }

    fn __repr__(&self) -> String {
        format!(
            "Mesh({} vertices, {} triangles)",
            self.mesh.num_vertices(),
            self.mesh.num_triangles()
        )
    }
}

/// The result of a pipeline run.
#[pyclass(frozen, module = "polylidar_rs")]
pub struct Extraction {
    /// The Rust result; its mesh is taken out by `Polylidar.recycle`.
    inner: RwLock<polylidar::Extraction>,
    /// Whether `Polylidar.recycle` took the mesh.
    recycled: AtomicBool,
    /// 2 for 2D input, else 3.
    pub dims: usize,
    /// `(rows, cols)` of organized input.
    pub grid: Option<(usize, usize)>,
    /// The address of the input buffer the pipeline read.
    pub input_address: usize,
    /// Whether the post-processed polygons are the result (the config has a
    /// `postprocess` section).
    pub postprocess: bool,
    /// The polygons' Python objects, made on first use.
    polygons: PyOnceLock<Py<PyList>>,
    postprocessed: PyOnceLock<Py<PyList>>,
}

impl Extraction {
    /// Wraps a Rust result.
    pub fn new(
        inner: polylidar::Extraction,
        dims: usize,
        grid: Option<(usize, usize)>,
        input_address: usize,
        postprocess: bool,
    ) -> Self {
        Self {
            inner: RwLock::new(inner),
            recycled: AtomicBool::new(false),
            dims,
            grid,
            input_address,
            postprocess,
            polygons: PyOnceLock::new(),
            postprocessed: PyOnceLock::new(),
        }
    }

    /// The Rust result (a panic elsewhere while it was held left nothing half-written: it
    /// is only ever written by `take_mesh`, which swaps the mesh out whole).
    fn read(&self) -> RwLockReadGuard<'_, polylidar::Extraction> {
        self.inner.read().unwrap_or_else(PoisonError::into_inner)
    }

    /// [`Self::read`] for what needs the mesh: an error once `Polylidar.recycle` took it.
    fn read_mesh(&self) -> PyResult<RwLockReadGuard<'_, polylidar::Extraction>> {
        if self.recycled.load(Ordering::Acquire) {
            return Err(recycled_error());
        }
        Ok(self.read())
    }

    /// The mesh, for `Polylidar.recycle`, leaving an empty one; an error the second time.
    pub fn take_mesh(&self) -> PyResult<HalfEdgeMesh> {
        let mut inner = self.inner.write().unwrap_or_else(PoisonError::into_inner);
        if self.recycled.swap(true, Ordering::AcqRel) {
            return Err(recycled_error());
        }
        Ok(std::mem::take(&mut inner.mesh))
    }

    fn labels<'py>(&self, py: Python<'py>, labels: Vec<i32>) -> PyResult<Bound<'py, PyAny>> {
        let array = PyArray1::from_vec(py, labels);
        Ok(match self.grid {
            Some((rows, cols)) => array.reshape([rows, cols])?.into_any(),
            None => array.into_any(),
        })
    }
}

#[pymethods]
impl Extraction {
    /// The polygons as extracted (list of :class:`Polygon`), ordered by dominant normal,
    /// then first triangle.
    #[getter]
    fn polygons(&self, py: Python<'_>) -> PyResult<Py<PyList>> {
        let list = self
            .polygons
            .get_or_try_init(py, || -> PyResult<Py<PyList>> {
                let items: Vec<Polygon> = self
                    .read()
                    .polygons
                    .iter()
                    .map(|p| Polygon {
                        shell: p.shell_points.clone(),
                        holes: p.hole_points.clone(),
                        indices: Some((p.shell.clone(), p.holes.clone())),
                        normal: p.plane.normal,
                        offset: p.plane.offset,
                        centroid: p.plane.centroid,
                        triangles: Some(p.triangles.clone()),
                        plane_id: Some(p.plane_id),
                        source: None,
                        group: p.group,
                        dims: self.dims,
                    })
                    .collect();
                Ok(PyList::new(py, items)?.unbind())
            })?;
        Ok(list.clone_ref(py))
    }

    /// The post-processed polygons (simplified, buffered, filtered; valid in their plane),
    /// empty unless the parameters have a ``postprocess`` section.
    #[getter]
    fn postprocessed(&self, py: Python<'_>) -> PyResult<Py<PyList>> {
        let list = self
            .postprocessed
            .get_or_try_init(py, || -> PyResult<Py<PyList>> {
                let inner = self.read();
                let items: Vec<Polygon> = inner
                    .postprocessed
                    .iter()
                    .map(|p| {
                        let source = &inner.polygons[p.source];
                        Polygon {
                            shell: p.shell.clone(),
                            holes: p.holes.clone(),
                            indices: None,
                            normal: source.plane.normal,
                            offset: source.plane.offset,
                            centroid: source.plane.centroid,
                            triangles: None,
                            plane_id: None,
                            source: Some(p.source),
                            group: source.group,
                            dims: self.dims,
                        }
                    })
                    .collect();
                Ok(PyList::new(py, items)?.unbind())
            })?;
        Ok(list.clone_ref(py))
    }

    /// 3D: the dominant plane normals (``(K, 3)`` float64) the segments were grown for.
    #[getter]
    fn dominant_normals<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        rows_to_array(py, self.read().dominant_normals.clone())
    }

    /// The triangulation the polygons were extracted from (a copy, made on each access);
    /// an error once :meth:`Polylidar.recycle` took it.
    #[getter]
    fn mesh(&self) -> PyResult<Mesh> {
        let inner = self.read_mesh()?;
        Ok(Mesh {
            mesh: inner.mesh.clone(),
            // A decimated cloud's mesh has a vertex per block of pixels.
            grid: match &inner.decimation {
                Some(d) => Some(d.grid()),
                None => self.grid,
            },
        })
    }

    /// What each stage kept and dropped (points, triangles, dropped_lmax, regions,
    /// polygons, holes, dominant_normals, …), a dict of ints.
    #[getter]
    fn counts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let value = serde_json::to_value(self.read().diagnostics.counts)
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
        from_json(py, &value)
    }

    /// Milliseconds per stage that ran, in order (``decimate``, ``mesh``, ``laplacian``,
    /// ``bilateral``, ``fastga``, ``regions``, ``polygons``, ``planes_polygons``,
    /// ``postprocess``), a dict.
    #[getter]
    fn timings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        for (stage, d) in self.read().diagnostics.timings.stages() {
            dict.set_item(*stage, d.as_secs_f64() * 1e3)?;
        }
        Ok(dict)
    }

    /// The polygon (index into :attr:`polygons`) of every input point, ``-1`` for none:
    /// an int32 ``(H, W)`` image for organized input, else ``(N,)``.
    fn point_labels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let inner = self.read_mesh()?;
        let labels = py.detach(|| inner.point_labels());
        self.labels(py, labels)
    }

    /// The plane of every input point, ``-1`` for none (as :meth:`point_labels` with each
    /// polygon's ``plane_id``, plus the rim points refinement assigns): what a plane
    /// segmentation is scored on.
    fn plane_labels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let inner = self.read_mesh()?;
        let labels = py.detach(|| inner.plane_labels());
        self.labels(py, labels)
    }

    /// The polygons as a GeoJSON FeatureCollection string, the same as the command line's
    /// ``-o``: post-processed polygons when the parameters post-process (``postprocessed``
    /// ``None``) or when ``postprocessed=True``, else the extracted ones.
    #[pyo3(signature = (postprocessed = None))]
    fn geojson(&self, py: Python<'_>, postprocessed: Option<bool>) -> String {
        let set = if postprocessed.unwrap_or(self.postprocess) {
            PolygonSet::Postprocessed
        } else {
            PolygonSet::Extracted
        };
        py.detach(|| feature_collection(&self.read(), self.dims == 3, set))
    }

    /// The FeatureCollection of :meth:`geojson` as a mapping.
    #[getter]
    fn __geo_interface__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let text = self.geojson(py, None);
        py.import("json")?.call_method1("loads", (text,))
    }

    /// The address of the buffer the pipeline read the points from: the input array's
    /// own (``array.ctypes.data``) when it was used in place (float64, C-contiguous).
    #[getter]
    fn input_address(&self) -> usize {
        self.input_address
    }

    fn __repr__(&self) -> String {
        let inner = self.read();
        let c = &inner.diagnostics.counts;
        format!(
            "Extraction({} polygons, {} holes, {} post-processed, {:.2} ms)",
            inner.polygons.len(),
            c.holes,
            inner.postprocessed.len(),
            inner.diagnostics.timings.total().as_secs_f64() * 1e3
        )
    }
}

/// What asking a recycled extraction for its mesh raises.
fn recycled_error() -> PyErr {
    pyo3::exceptions::PyValueError::new_err(
        "this extraction's mesh was handed back with Polylidar.recycle",
    )
}
