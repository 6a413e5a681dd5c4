//! `polylidar_rs`: the Python package of polylidar-rs (PyO3, abi3 for CPython ≥ 3.9).
//!
//! NumPy arrays go in without copies (float64, C-contiguous: the Rust pipeline reads the
//! array's buffer; float32 is converted once), results come out as NumPy arrays and
//! polygon objects with `__geo_interface__`, and the GIL is released while Rust works. The
//! Python API is documented in `polylidar_rs.pyi` and the crate README; this crate is
//! built with maturin (`maturin build --release -m crates/polylidar-py/Cargo.toml`).

mod arrays;
mod config;
mod result;
mod stages;
mod tiles;

use std::path::PathBuf;

use polylidar::io::Input;
use polylidar::{OrganizedPointCloud, OrganizedPointCloudView};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::{CLOUD, Expect, POINTS_2D, POINTS_3D, Points, TRIANGLES, VERTICES};
use crate::result::{Extraction, Mesh, Polygon};

/// The Rust side allocates the large per-frame buffers (mesh, normals, filtered clouds);
/// an allocator that keeps freed memory for reuse saves the page faults glibc's would cost
/// on every frame (see the `polylidar` crate's README, "Frame after frame").
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

pyo3::create_exception!(
    polylidar_rs,
    PolylidarError,
    pyo3::exceptions::PyValueError,
    "An error of the Rust library: bad parameters, input that cannot be meshed, an unreadable file."
);

/// The error as a Python exception, with its causes.
pub(crate) fn error(e: &dyn std::error::Error) -> PyErr {
    let mut message = e.to_string();
    let mut source = e.source();
    while let Some(cause) = source {
        let text = cause.to_string();
        if !message.contains(&text) {
            message.push_str(": ");
            message.push_str(&text);
        }
        source = cause.source();
    }
    PolylidarError::new_err(message)
}

/// The Polylidar pipeline for every input kind, built once from a preset and keyword
/// parameters and reused; safe to share between threads.
#[pyclass(frozen, module = "polylidar_rs")]
struct Polylidar {
    inner: polylidar::Polylidar,
}

impl Polylidar {
    fn wrap(
        &self,
        result: Result<polylidar::Extraction, polylidar::PolylidarError>,
        dims: usize,
        grid: Option<(usize, usize)>,
        address: usize,
    ) -> PyResult<Extraction> {
        let postprocess = self.inner.config().postprocess.is_some();
        result
            .map(|e| Extraction::new(e, dims, grid, address, postprocess))
            .map_err(|e| error(&e))
    }

    fn organized(
        &self,
        py: Python<'_>,
        cloud: &Points<'_, 3>,
        rows: usize,
        cols: usize,
    ) -> PyResult<Extraction> {
        let slice = cloud.as_slice();
        let result = py.detach(|| {
            let view = OrganizedPointCloudView::new(rows, cols, slice)?;
            self.inner.extract_organized_view(view)
        });
        self.wrap(result, 3, Some((rows, cols)), cloud.address())
    }
}

#[pymethods]
impl Polylidar {
    /// ``Polylidar(preset=None, **params)``: the parameters of ``preset`` (``rgbd``,
    /// ``synpeb``, ``synpeb-auto``, ``rooftop``, ``kitti``, ``mesh-basement``,
    /// ``mesh-mainfloor``; default: the library defaults) overridden by keyword.
    #[new]
    #[pyo3(signature = (preset = None, **params))]
    fn new(
        py: Python<'_>,
        preset: Option<&str>,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let config = config::build(py, preset, params)?;
        let inner = polylidar::Polylidar::new(config).map_err(|e| error(&e))?;
        Ok(Self { inner })
    }

    /// The parameters in use, as a dict (the fields of the Rust ``Config``).
    #[getter]
    fn config<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let value = serde_json::to_value(self.inner.config())
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
        config::from_json(py, &value)
    }

    /// Polygons of a 2D point set, ``(N, 2)``: Delaunay triangulation, ``alpha`` /
    /// ``lmax`` filter, regions, boundary following.
    fn extract_2d(&self, py: Python<'_>, points: &Bound<'_, PyAny>) -> PyResult<Extraction> {
        let p = arrays::points::<2>(points, POINTS_2D, 2)?;
        let slice = p.as_slice();
        let result = py.detach(|| self.inner.extract_2d(slice));
        self.wrap(result, 2, None, p.address())
    }

    /// Polygons of a 3D cloud seen along ``up`` (2.5D), ``(N, 3)``: flat roofs and
    /// floors of airborne LiDAR.
    fn extract_25d(&self, py: Python<'_>, points: &Bound<'_, PyAny>) -> PyResult<Extraction> {
        let p = arrays::points::<3>(points, POINTS_3D, 2)?;
        let slice = p.as_slice();
        let result = py.detach(|| self.inner.extract_25d(slice));
        self.wrap(result, 3, None, p.address())
    }

    /// Polygons of points: ``(N, 2)`` runs :meth:`extract_2d`, ``(N, 3)``
    /// :meth:`extract_25d` (the original's ``extract_planes_and_polygons(points)``).
    fn extract_points(&self, py: Python<'_>, points: &Bound<'_, PyAny>) -> PyResult<Extraction> {
        let array = arrays::ndarray(
            points,
            Expect {
                name: "points",
                shape: "(N, 2) or (N, 3)",
            },
            "float64 or float32",
        )?;
        use numpy::PyUntypedArrayMethods;
        match array.shape() {
            [_, 3] => self.extract_25d(py, points),
            _ => self.extract_2d(py, points),
        }
    }

    /// Planes and polygons of an organized cloud ``(H, W, 3)`` (range image, RGB-D frame;
    /// NaN marks invalid pixels): smoothing, meshing, FastGA, segmentation, polygons,
    /// post-processing, as the parameters say.
    fn extract_organized(&self, py: Python<'_>, cloud: &Bound<'_, PyAny>) -> PyResult<Extraction> {
        let p = arrays::points::<3>(cloud, CLOUD, 3)?;
        let (rows, cols) = grid_of(cloud)?;
        self.organized(py, &p, rows, cols)
    }

    /// Hands a finished extraction's mesh back, so that the next organized frame is meshed
    /// into its arrays instead of fresh memory (a stream of frames of one shape; results
    /// are the same). Its polygons stay; its ``mesh``, ``point_labels`` and
    /// ``plane_labels`` raise ``ValueError`` afterwards, as does recycling it again.
    fn recycle(&self, extraction: &Extraction) -> PyResult<()> {
        self.inner.recycle_mesh(extraction.take_mesh()?);
        Ok(())
    }

    /// Planes and polygons of a triangle mesh: ``vertices`` ``(N, 3)`` float, ``triangles``
    /// ``(M, 3)`` integer (counter-clockwise). The mesh is copied into the half-edge mesh.
    fn extract_mesh(
        &self,
        py: Python<'_>,
        vertices: &Bound<'_, PyAny>,
        triangles: &Bound<'_, PyAny>,
    ) -> PyResult<Extraction> {
        let v = arrays::points::<3>(vertices, VERTICES, 2)?;
        let t = arrays::triangles(triangles, TRIANGLES)?;
        let slice = v.as_slice();
        let result = py.detach(|| self.inner.extract_mesh(slice.to_vec(), t));
        self.wrap(result, 3, None, v.address())
    }

    /// Planes and polygons of a :class:`Mesh` (from :func:`mesh_organized` or an earlier
    /// result) for the given dominant normals ``(K, 3)``, skipping FastGA; ``None``
    /// detects them (the original's ``extract_planes_and_polygons_optimized``).
    #[pyo3(signature = (mesh, dominant_normals = None))]
    fn extract_planes(
        &self,
        py: Python<'_>,
        mesh: &Mesh,
        dominant_normals: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Extraction> {
        let dominant = match dominant_normals {
            Some(d) => Some(
                arrays::points::<3>(
                    d,
                    Expect {
                        name: "dominant_normals",
                        shape: "(K, 3)",
                    },
                    2,
                )?
                .as_slice()
                .to_vec(),
            ),
            None => None,
        };
        let copy = mesh.mesh.clone();
        let result = py.detach(|| self.inner.extract_planes_from_mesh(copy, dominant));
        self.wrap(result, 3, mesh.grid, 0)
    }

    /// Planes and polygons of a 16-bit depth image ``(H, W)`` uint16 with pinhole
    /// ``intrinsics`` — ``(fx, fy, cx, cy)`` or a 3 × 3 matrix — ``depth_scale`` metres
    /// per unit (0.001: millimetres), every ``stride``-th pixel, depths beyond
    /// ``max_depth`` metres dropped.
    #[pyo3(signature = (depth, intrinsics, depth_scale = 0.001, stride = 1, max_depth = None))]
    fn extract_depth(
        &self,
        py: Python<'_>,
        depth: &Bound<'_, PyAny>,
        intrinsics: &Bound<'_, PyAny>,
        depth_scale: f64,
        stride: usize,
        max_depth: Option<f64>,
    ) -> PyResult<Extraction> {
        let (cloud, address) =
            stages::depth_cloud(py, depth, intrinsics, depth_scale, stride, max_depth)?;
        let (rows, cols) = (cloud.rows(), cloud.cols());
        let result = py.detach(|| self.inner.extract_organized(&cloud));
        self.wrap(result, 3, Some((rows, cols)), address)
    }

    /// Reads a file (PCD, NPY, PLY, OBJ, LAS/LAZ, CSV, 16-bit depth PNG) and runs the
    /// pipeline that fits it, as the ``polylidar extract`` command does with these
    /// parameters (without its data-derived defaults). A depth PNG's camera: ``intrinsics``
    /// — ``(fx, fy, cx, cy)``, a 3 × 3 matrix, or the path of an Open3D camera JSON or
    /// RealSense metadata CSV — else the RealSense ``_metadata.csv`` beside it;
    /// ``depth_scale`` metres per unit (TUM: 0.0002), else the CSV's, else 0.001.
    #[pyo3(signature = (path, intrinsics = None, depth_scale = None))]
    fn extract_file(
        &self,
        py: Python<'_>,
        path: PathBuf,
        intrinsics: Option<&Bound<'_, PyAny>>,
        depth_scale: Option<f64>,
    ) -> PyResult<Extraction> {
        let camera = stages::depth_camera(intrinsics, depth_scale)?;
        let result = py.detach(|| {
            let limits = polylidar::io::Limits::default();
            let (input, _) = Input::read_with_camera(&path, &camera, &limits)?;
            let grid = input.grid();
            let dims = if input.is_3d() { 3 } else { 2 };
            self.inner.extract(&input).map(|e| (e, grid, dims))
        });
        let (extraction, grid, dims) = result.map_err(|e| error(&e))?;
        Ok(Extraction::new(
            extraction,
            dims,
            grid,
            0,
            self.inner.config().postprocess.is_some(),
        ))
    }

    /// Runs the pipeline over depth frames (16-bit PNGs, or organized clouds) in the
    /// order given, with one pipeline kept across them and the next frame read and
    /// decoded on a loader thread (``prefetch`` frames ahead; 0: in turn) while one runs,
    /// ``in_flight`` frames at once on the pipeline's threads (0: one or two, whichever
    /// short trials as the stream goes show to be faster; 1: each frame alone, soonest).
    /// The camera as for :meth:`extract_file`.
    /// Returns ``[(path, Extraction)]``; raises on the first frame that cannot be read or
    /// run, naming it.
    #[pyo3(signature = (paths, intrinsics = None, depth_scale = None, prefetch = 1, in_flight = 0))]
    fn stream(
        &self,
        py: Python<'_>,
        paths: Vec<PathBuf>,
        intrinsics: Option<&Bound<'_, PyAny>>,
        depth_scale: Option<f64>,
        prefetch: usize,
        in_flight: usize,
    ) -> PyResult<Vec<(String, Extraction)>> {
        let camera = stages::depth_camera(intrinsics, depth_scale)?;
        let sources = paths
            .into_iter()
            .map(|p| (p.display().to_string(), p))
            .collect();
        let load = move |path: PathBuf| {
            let limits = polylidar::io::Limits::default();
            match Input::read_with_camera(&path, &camera, &limits)?.0 {
                Input::Organized(cloud) => {
                    let grid = (cloud.rows(), cloud.cols());
                    Ok((cloud, grid))
                }
                other => Err(polylidar::PolylidarError::Config {
                    field: "frame",
                    value: format!("{} ({})", path.display(), other.kind()),
                    reason: "a stream frame must be a depth image or an organized cloud",
                }),
            }
        };
        let options = polylidar::stream::StreamOptions::default()
            .with_prefetch(prefetch)
            .with_in_flight(in_flight);
        let frames: Vec<_> = py.detach(|| {
            self.inner
                .stream_with(sources, load, options)
                .map(|f| (f.name, f.extraction, f.extra))
                .collect()
        });
        let postprocess = self.inner.config().postprocess.is_some();
        frames
            .into_iter()
            .map(|(name, extraction, grid)| {
                let extraction = extraction
                    .map_err(|e| PolylidarError::new_err(format!("frame {name}: {}", error(&e))))?;
                Ok((name, Extraction::new(extraction, 3, grid, 0, postprocess)))
            })
            .collect()
    }

    fn __repr__(&self) -> String {
        let c = self.inner.config();
        format!(
            "Polylidar(alpha={}, lmax={}, min_triangles={}, min_hole_vertices={}, z_thresh={}, norm_thresh={}, ...)",
            c.alpha, c.lmax, c.min_triangles, c.min_hole_vertices, c.z_thresh, c.norm_thresh
        )
    }
}

/// `(H, W)` of an `(H, W, 3)` array already checked.
fn grid_of(obj: &Bound<'_, PyAny>) -> PyResult<(usize, usize)> {
    use numpy::PyUntypedArrayMethods;
    let array = arrays::ndarray(obj, CLOUD, "float64 or float32")?;
    match array.shape() {
        [rows, cols, 3] => Ok((*rows, *cols)),
        shape => Err(pyo3::exceptions::PyValueError::new_err(format!(
            "cloud must have shape (H, W, 3), got {}",
            arrays::shape_text(shape)
        ))),
    }
}

/// Reads a file into NumPy arrays: a dict with ``kind`` (``points_2d``, ``cloud_2.5d``,
/// ``organized``, ``mesh``) and ``points`` (``(N, 2)``, ``(N, 3)`` or ``(H, W, 3)``;
/// meshes: ``vertices`` and ``triangles``). Depth PNGs come back as organized clouds.
#[pyfunction]
fn load<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let input = py.detach(|| Input::read(&path)).map_err(|e| error(&e))?;
    let dict = PyDict::new(py);
    dict.set_item("kind", input.kind())?;
    match input {
        Input::Points2d(p) => dict.set_item("points", arrays::rows_to_array(py, p)?)?,
        Input::Cloud(p) => dict.set_item("points", arrays::rows_to_array(py, p)?)?,
        Input::Organized(cloud) => {
            let (rows, cols) = (cloud.rows(), cloud.cols());
            let flat = OrganizedPointCloud::into_points(cloud);
            let array = arrays::rows_to_array(py, flat)?;
            dict.set_item("points", array.call_method1("reshape", ((rows, cols, 3),))?)?;
        }
        Input::Mesh {
            vertices,
            triangles,
        } => {
            dict.set_item("vertices", arrays::rows_to_array(py, vertices)?)?;
            dict.set_item("triangles", arrays::triangles_to_array(py, triangles)?)?;
        }
    }
    Ok(dict)
}

/// The names accepted as ``preset``.
#[pyfunction]
fn presets() -> Vec<&'static str> {
    polylidar::Preset::all().iter().map(|p| p.name()).collect()
}

/// The extension module.
#[pymodule]
fn polylidar_rs(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("PolylidarError", m.py().get_type::<PolylidarError>())?;
    m.add_class::<Polylidar>()?;
    tiles::register(m)?;
    m.add_class::<Extraction>()?;
    m.add_class::<Polygon>()?;
    m.add_class::<Mesh>()?;
    m.add_class::<stages::FastGA>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(presets, m)?)?;
    stages::register(m)?;
    Ok(())
}
