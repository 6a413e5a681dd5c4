//! The pipeline's stages on their own: FastGA dominant normals, Laplacian and bilateral
//! smoothing, organized meshing, depth images, post-processing.

use std::sync::{Mutex, PoisonError};

use fastga::{FastGa, FastGaConfig};
use mesh_smooth_gpu::{BilateralOptions, CpuSmoother, LaplacianOptions};
use numpy::{PyArray1, PyUntypedArrayMethods};
use polylidar::{DepthOptions, Intrinsics, OrganizedPointCloud, OrganizedPointCloudView};
use polypost::{Plane, Polygon3, PostProcessor, PostprocessConfig};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::arrays::{self, CLOUD, DEPTH, NORMALS, Points, rows_to_array, rows_to_array_f32};
use crate::error;
use crate::result::{Mesh, Polygon};

/// The `(H, W, 3)` cloud argument and its grid.
fn cloud<'py>(obj: &Bound<'py, PyAny>) -> PyResult<(Points<'py, 3>, usize, usize)> {
    let points = arrays::points::<3>(obj, CLOUD, 3)?;
    let shape = arrays::ndarray(obj, CLOUD, "float64 or float32")?
        .shape()
        .to_vec();
    Ok((points, shape[0], shape[1]))
}

/// Dominant plane normals of unit normals (FastGA): the Gaussian accumulator is built
/// once, in the constructor, and reused by every :meth:`detect`; safe to share between
/// threads (calls take turns).
#[pyclass(frozen, module = "polylidar_rs", name = "FastGA")]
pub struct FastGA {
    inner: Mutex<FastGa>,
}

#[pymethods]
impl FastGA {
    /// ``FastGA(level=4, value_threshold=15, cluster_distance=0.1,
    /// min_cluster_weight=0.15, sample_fraction=1.0)``: icosahedron refinement level
    /// (0–7), smallest peak on the 0–255 image scale (the paper's v_min), peaks closer
    /// than this merge (d_peak), lighter clusters are dropped, fraction of the normals
    /// integrated.
    #[new]
    #[pyo3(signature = (level = 4, value_threshold = 15.0, cluster_distance = 0.1, min_cluster_weight = 0.15, sample_fraction = 1.0))]
    fn new(
        level: u32,
        value_threshold: f64,
        cluster_distance: f64,
        min_cluster_weight: f64,
        sample_fraction: f64,
    ) -> PyResult<Self> {
        let config = FastGaConfig::default()
            .with_level(level)
            .with_value_threshold(value_threshold)
            .with_cluster_distance(cluster_distance)
            .with_min_cluster_weight(min_cluster_weight)
            .with_sample_fraction(sample_fraction);
        let inner = FastGa::new(config).map_err(|e| error(&e))?;
        Ok(Self {
            inner: Mutex::new(inner),
        })
    }

    /// The dominant normals of ``normals`` (``(N, 3)`` float64 or float32 unit vectors,
    /// read in place): ``(normals, weights)``, a ``(K, 3)`` float64 array strongest first
    /// and their ``(K,)`` normalised weights.
    fn detect<'py>(
        &self,
        py: Python<'py>,
        normals: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyArray1<f64>>)> {
        let array = arrays::ndarray(normals, NORMALS, "float64 or float32")?;
        arrays::check_shape(array, NORMALS, 2, &[3])?;
        let found = if let Ok(a) = arrays::exact::<f32>(normals, NORMALS, "float32", 2, &[3]) {
            let slice = a.as_slice().map_or(&[][..], |s| s.as_chunks::<3>().0);
            py.detach(|| self.lock().detect(slice))
        } else {
            let a = arrays::points::<3>(normals, NORMALS, 2)?;
            let slice = a.as_slice();
            py.detach(|| self.lock().detect(slice))
        }
        .map_err(|e| error(&e))?;
        let weights: Vec<f64> = found.normals.iter().map(|d| d.weight).collect();
        let normals: Vec<[f64; 3]> = found.normals.iter().map(|d| d.normal).collect();
        Ok((rows_to_array(py, normals)?, PyArray1::from_vec(py, weights)))
    }

    /// The icosahedron refinement level.
    #[getter]
    fn level(&self) -> u32 {
        self.lock().config().level
    }

    fn __repr__(&self) -> String {
        let inner = self.lock();
        let c = inner.config();
        format!(
            "FastGA(level={}, value_threshold={}, cluster_distance={}, min_cluster_weight={}, sample_fraction={})",
            c.level, c.value_threshold, c.cluster_distance, c.min_cluster_weight, c.sample_fraction
        )
    }
}

impl FastGA {
    fn lock(&self) -> std::sync::MutexGuard<'_, FastGa> {
        // A detect that panicked left nothing the next call's clear does not overwrite.
        self.inner.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// The CPU smoother: rows over the rayon pool, or one thread.
fn smoother(parallel: bool) -> CpuSmoother {
    if parallel {
        CpuSmoother::new()
    } else {
        CpuSmoother::serial()
    }
}

/// Laplacian vertex smoothing of an organized cloud ``(H, W, 3)`` (Polylidar3D Eq. 1–2,
/// computed in float32 like the original): a new ``(H, W, 3)`` float64 array.
#[pyfunction]
#[pyo3(signature = (cloud, lambda_ = 1.0, kernel = 3, iterations = 1, parallel = true))]
fn laplacian_filter<'py>(
    py: Python<'py>,
    cloud: &Bound<'py, PyAny>,
    lambda_: f32,
    kernel: u32,
    iterations: u32,
    parallel: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let (points, rows, cols) = self::cloud(cloud)?;
    let slice = points.as_slice();
    let options = LaplacianOptions::new()
        .with_lambda(lambda_)
        .with_kernel(kernel)
        .with_iterations(iterations);
    let out = py
        .detach(
            || -> Result<OrganizedPointCloud, polylidar::PolylidarError> {
                // The copy is the output array: the filter runs in place on it.
                let mut out = OrganizedPointCloudView::new(rows, cols, slice)?.to_cloud();
                smoother(parallel).laplacian_in_place(&mut out, &options)?;
                Ok(out)
            },
        )
        .map_err(|e| error(&e))?;
    rows_to_array(py, out.into_points())?.call_method1("reshape", ((rows, cols, 3),))
}

/// Bilateral normal smoothing (Polylidar3D Eq. 3–5) of the right-cut mesh of an organized
/// cloud ``(H, W, 3)``: the smoothed unit normal of every cell triangle, a float32
/// ``(H - 1, W - 1, 2, 3)`` array, NaN where a triangle is missing (an invalid vertex).
#[pyfunction]
#[pyo3(signature = (cloud, sigma_length = 0.1, sigma_angle = 0.15, kernel = 3, iterations = 1, parallel = true))]
fn bilateral_filter<'py>(
    py: Python<'py>,
    cloud: &Bound<'py, PyAny>,
    sigma_length: f32,
    sigma_angle: f32,
    kernel: u32,
    iterations: u32,
    parallel: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let (points, rows, cols) = self::cloud(cloud)?;
    let slice = points.as_slice();
    let options = BilateralOptions::new()
        .with_sigma_length(sigma_length)
        .with_sigma_angle(sigma_angle)
        .with_kernel(kernel)
        .with_iterations(iterations);
    let normals = py
        .detach(|| -> Result<Vec<[f32; 3]>, polylidar::PolylidarError> {
            let owned = OrganizedPointCloudView::new(rows, cols, slice)?.to_cloud();
            Ok(smoother(parallel).bilateral(&owned, &options)?.into_vec())
        })
        .map_err(|e| error(&e))?;
    let cells = (rows.saturating_sub(1), cols.saturating_sub(1));
    rows_to_array_f32(py, normals)?.call_method1("reshape", ((cells.0, cells.1, 2, 3),))
}

/// The right-cut triangle mesh of an organized cloud ``(H, W, 3)`` (Polylidar3D Alg. 1–2)
/// with unit triangle normals; vertex ``r * W + c`` is pixel ``(r, c)``, NaN included.
/// ``stride`` keeps every ``stride``-th row and column first.
#[pyfunction]
#[pyo3(signature = (cloud, stride = 1))]
fn mesh_organized(py: Python<'_>, cloud: &Bound<'_, PyAny>, stride: usize) -> PyResult<Mesh> {
    let (points, rows, cols) = self::cloud(cloud)?;
    let slice = points.as_slice();
    let (mesh, grid) = py
        .detach(|| -> Result<_, polylidar::PolylidarError> {
            let view = OrganizedPointCloudView::new(rows, cols, slice)?;
            let options = opc_options();
            if stride > 1 {
                let small = view.downsample(stride)?;
                let grid = (small.rows(), small.cols());
                Ok((small.into_mesh(&options)?.mesh, grid))
            } else {
                Ok((view.mesh(&options)?.mesh, (rows, cols)))
            }
        })
        .map_err(|e| error(&e))?;
    Ok(Mesh {
        mesh,
        grid: Some(grid),
    })
}

fn opc_options() -> opc_mesh::OpcMeshOptions {
    opc_mesh::OpcMeshOptions::new().with_compute_normals(true)
}

/// An organized cloud ``(H, W, 3)`` float64 back-projected from a 16-bit depth image
/// ``(H, W)`` with ``intrinsics`` ``(fx, fy, cx, cy)`` or a 3 × 3 matrix (NaN where the
/// depth is 0 or beyond ``max_depth`` metres).
#[pyfunction]
#[pyo3(signature = (depth, intrinsics, depth_scale = 0.001, stride = 1, max_depth = None))]
fn depth_to_cloud<'py>(
    py: Python<'py>,
    depth: &Bound<'py, PyAny>,
    intrinsics: &Bound<'py, PyAny>,
    depth_scale: f64,
    stride: usize,
    max_depth: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let (cloud, _) = depth_cloud(py, depth, intrinsics, depth_scale, stride, max_depth)?;
    let (rows, cols) = (cloud.rows(), cloud.cols());
    rows_to_array(py, cloud.into_points())?.call_method1("reshape", ((rows, cols, 3),))
}

/// The organized cloud of a depth image argument, and the address of the depth buffer
/// it was read from (in place).
pub fn depth_cloud(
    py: Python<'_>,
    depth: &Bound<'_, PyAny>,
    intrinsics: &Bound<'_, PyAny>,
    depth_scale: f64,
    stride: usize,
    max_depth: Option<f64>,
) -> PyResult<(OrganizedPointCloud, usize)> {
    let image = arrays::exact::<u16>(depth, DEPTH, "uint16", 2, &[])?;
    let shape = image.shape().to_vec();
    let camera = camera(intrinsics)?;
    let mut options = DepthOptions::new(camera)
        .with_depth_scale(depth_scale)
        .with_stride(stride);
    if let Some(max) = max_depth {
        options = options.with_max_depth(max);
    }
    let data = image
        .as_slice()
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let address = data.as_ptr() as usize;
    py.detach(|| OrganizedPointCloud::from_depth_image(data, shape[0], shape[1], &options))
        .map(|cloud| (cloud, address))
        .map_err(|e| error(&e))
}

/// The depth camera of `intrinsics` — `(fx, fy, cx, cy)`, a 3 × 3 matrix, or the path of
/// a camera file (Open3D JSON, RealSense CSV); `None`: the RealSense CSV beside the image
/// — and `depth_scale` metres per unit (`None`: the file's, else 0.001).
pub fn depth_camera(
    intrinsics: Option<&Bound<'_, PyAny>>,
    depth_scale: Option<f64>,
) -> PyResult<polylidar::io::DepthCamera> {
    use polylidar::io::{CameraSource, DepthCamera};
    let source = match intrinsics {
        None => CameraSource::Beside,
        Some(obj)
            if obj.is_instance_of::<pyo3::types::PyString>() || obj.hasattr("__fspath__")? =>
        {
            CameraSource::File(obj.extract::<std::path::PathBuf>()?)
        }
        Some(obj) => CameraSource::Pinhole(camera(obj)?),
    };
    let camera = DepthCamera::new(source);
    Ok(match depth_scale {
        Some(scale) if scale.is_finite() && scale > 0.0 => camera.with_units_per_metre(1.0 / scale),
        Some(scale) => {
            return Err(PyValueError::new_err(format!(
                "depth_scale {scale}: metres per depth unit, finite and > 0"
            )));
        }
        None => camera,
    })
}

/// Pinhole intrinsics from `(fx, fy, cx, cy)` or a 3 × 3 camera matrix.
fn camera(obj: &Bound<'_, PyAny>) -> PyResult<Intrinsics> {
    let flat: Vec<f64> = match obj.extract::<Vec<f64>>() {
        Ok(v) => v,
        Err(_) => obj
            .py()
            .import("numpy")?
            .call_method1("asarray", (obj, "float64"))
            .and_then(|a| a.call_method0("ravel"))
            .and_then(|a| a.call_method0("tolist"))
            .and_then(|l| l.extract())
            .map_err(|_| intrinsics_error())?,
    };
    match flat.as_slice() {
        [fx, fy, cx, cy] => Ok(Intrinsics::new(*fx, *fy, *cx, *cy)),
        [fx, _, cx, _, fy, cy, _, _, _] => Ok(Intrinsics::new(*fx, *fy, *cx, *cy)),
        _ => Err(intrinsics_error()),
    }
}

fn intrinsics_error() -> PyErr {
    PyValueError::new_err(
        "intrinsics must be (fx, fy, cx, cy) or a 3 x 3 camera matrix [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]",
    )
}

/// Post-processing of 3D polygons (Polylidar3D §8): each polygon is projected to its
/// plane, simplified (``alpha``), buffered out (``beta_pos``) and in (``beta_neg``),
/// dropped below ``min_area`` or with holes below ``min_hole_area`` dropped, and lifted
/// back; a polygon can split into several or vanish. Lengths in the input's unit.
#[pyfunction]
#[pyo3(signature = (polygons, alpha = 0.0, beta_pos = 0.0, beta_neg = 0.0, min_area = 0.0, min_hole_area = 0.0))]
fn postprocess(
    py: Python<'_>,
    polygons: Vec<PyRef<'_, Polygon>>,
    alpha: f64,
    beta_pos: f64,
    beta_neg: f64,
    min_area: f64,
    min_hole_area: f64,
) -> PyResult<Vec<Polygon>> {
    let config = PostprocessConfig::default()
        .with_alpha(alpha)
        .with_beta_pos(beta_pos)
        .with_beta_neg(beta_neg)
        .with_min_area(min_area)
        .with_min_hole_area(min_hole_area);
    let inputs: Vec<Polygon3> = polygons
        .iter()
        .map(|p| Polygon3::new(p.shell.clone(), p.holes.clone()))
        .collect();
    let planes: Vec<Plane> = polygons
        .iter()
        .map(|p| Plane::from_normal_and_point(p.normal, p.centroid))
        .collect::<Result<_, _>>()
        .map_err(|e| error(&e))?;
    let output = py
        .detach(|| -> Result<_, polypost::PostError> {
            PostProcessor::new(config)?.process_many_3d(&inputs, &planes)
        })
        .map_err(|e| error(&e))?;
    Ok(output
        .polygons
        .into_iter()
        .map(|p| {
            let source = &polygons[p.source as usize];
            Polygon {
                shell: p.polygon.shell,
                holes: p.polygon.holes,
                indices: None,
                normal: source.normal,
                offset: source.offset,
                centroid: source.centroid,
                triangles: None,
                plane_id: None,
                source: Some(p.source as usize),
                group: source.group,
                dims: source.dims,
            }
        })
        .collect())
}

/// Adds the stage functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(laplacian_filter, m)?)?;
    m.add_function(wrap_pyfunction!(bilateral_filter, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_organized, m)?)?;
    m.add_function(wrap_pyfunction!(depth_to_cloud, m)?)?;
    m.add_function(wrap_pyfunction!(postprocess, m)?)?;
    Ok(())
}
