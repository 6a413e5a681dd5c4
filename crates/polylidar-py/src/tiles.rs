//! Tiles for the Dask front (`polylidar_rs.dask`): one tile's extraction and the merge of
//! tile results, passed between processes as bytes (`polylidar::tiles::TileSet`, exact
//! coordinates); polygons out as WKB (GeoPandas: `GeoSeries.from_wkb`) and GeoJSON; the
//! bounds of LAS/LAZ files for tiling plans; the synthetic city of `synthscan` as LAS/LAZ
//! tiles.

use std::path::PathBuf;

use numpy::{PyArray1, PyArray2};
use polylidar::tiles::{self, MergeTolerance, TileGrid, TileId, TileSet};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};

use crate::arrays::{self, POINTS_3D};
use crate::{config, error};

/// A grid as Python passes it: `(x0, y0, size, margin, cols, rows)`.
type GridTuple = (f64, f64, f64, f64, u32, u32);

fn grid_of(g: GridTuple) -> PyResult<TileGrid> {
    TileGrid::new([g.0, g.1], g.2, g.3, g.4, g.5).map_err(|e| error(&e))
}

fn pipeline(
    py: Python<'_>,
    preset: Option<&str>,
    params: Option<&Bound<'_, PyDict>>,
) -> PyResult<polylidar::Polylidar> {
    let config = config::build(py, preset, params)?;
    polylidar::Polylidar::new(config).map_err(|e| error(&e))
}

fn decode(bytes: &[u8]) -> PyResult<TileSet> {
    TileSet::from_bytes(bytes).map_err(|e| error(&e))
}

/// ``extract_tile(points, grid, col, row, preset=None, **params) -> bytes``: the 2.5D
/// polygons of tile ``(col, row)`` of ``grid`` (``(x0, y0, size, margin, cols, rows)``)
/// from the points of ``points`` (``(N, 3)``) in its window, clipped to its core; an
/// encoded tile set for :func:`merge_tiles`.
#[pyfunction]
#[pyo3(signature = (points, grid, col, row, preset = None, **params))]
pub fn extract_tile<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    grid: GridTuple,
    col: u32,
    row: u32,
    preset: Option<&str>,
    params: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyBytes>> {
    let polylidar = pipeline(py, preset, params)?;
    let grid = grid_of(grid)?;
    let p = arrays::points::<3>(points, POINTS_3D, 2)?;
    let slice = p.as_slice();
    let set = py
        .detach(|| tiles::extract_tile(&polylidar, &grid, TileId { col, row }, slice))
        .map_err(|e| error(&e))?;
    Ok(PyBytes::new(py, &set.to_bytes()))
}

/// ``extract_tile_files(paths, grid, col, row, preset=None, **params) -> bytes``: as
/// :func:`extract_tile`, reading the window's points from LAS/LAZ files.
#[pyfunction]
#[pyo3(signature = (paths, grid, col, row, preset = None, **params))]
pub fn extract_tile_files<'py>(
    py: Python<'py>,
    paths: Vec<PathBuf>,
    grid: GridTuple,
    col: u32,
    row: u32,
    preset: Option<&str>,
    params: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyBytes>> {
    let polylidar = pipeline(py, preset, params)?;
    let grid = grid_of(grid)?;
    let tile = TileId { col, row };
    let set = py
        .detach(|| {
            let points = tiles::read_window(&paths, &grid, tile)?;
            tiles::extract_tile(&polylidar, &grid, tile, &points)
        })
        .map_err(|e| error(&e))?;
    Ok(PyBytes::new(py, &set.to_bytes()))
}

/// ``merge_tiles(parts, preset=None, max_angle_deg=None, max_offset=None, **params) ->
/// bytes``: the merge of encoded tile sets (from :func:`extract_tile` or earlier merges);
/// tolerances default to those of the pipeline's parameters.
#[pyfunction]
#[pyo3(signature = (parts, preset = None, max_angle_deg = None, max_offset = None, **params))]
pub fn merge_tiles<'py>(
    py: Python<'py>,
    parts: Vec<Vec<u8>>,
    preset: Option<&str>,
    max_angle_deg: Option<f64>,
    max_offset: Option<f64>,
    params: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyBytes>> {
    let config = config::build(py, preset, params)?;
    let mut tolerance = MergeTolerance::for_config(&config);
    if let Some(a) = max_angle_deg {
        tolerance.max_angle_deg = a;
    }
    if let Some(o) = max_offset {
        tolerance.max_offset = o;
    }
    let merged = py
        .detach(|| {
            let sets = parts
                .iter()
                .map(|b| TileSet::from_bytes(b))
                .collect::<Result<Vec<_>, _>>()?;
            tiles::merge(sets, &tolerance)
        })
        .map_err(|e| error(&e))?;
    Ok(PyBytes::new(py, &merged.to_bytes()))
}

/// ``tile_polygons(data, with_z=True) -> dict``: the polygons of an encoded tile set:
/// ``wkb`` (list of bytes), ``normal`` ``(M, 3)``, ``offset`` and ``area`` ``(M,)``,
/// ``tiles`` (list of lists of ``(col, row)``), and ``cover`` (the tiles the set covers).
#[pyfunction]
#[pyo3(signature = (data, with_z = true))]
pub fn tile_polygons<'py>(
    py: Python<'py>,
    data: &[u8],
    with_z: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let set = decode(data)?;
    let out = PyDict::new(py);
    let wkb = PyList::empty(py);
    for p in &set.polygons {
        wkb.append(PyBytes::new(py, &p.to_wkb(with_z)))?;
    }
    out.set_item("wkb", wkb)?;
    let normals: Vec<Vec<f64>> = set.polygons.iter().map(|p| p.normal.to_vec()).collect();
    let normal = if normals.is_empty() {
        PyArray2::<f64>::zeros(py, [0, 3], false)
    } else {
        PyArray2::from_vec2(py, &normals).map_err(|e| error(&e))?
    };
    out.set_item("normal", normal)?;
    let column =
        |f: fn(&tiles::TilePolygon) -> f64| -> Vec<f64> { set.polygons.iter().map(f).collect() };
    out.set_item("offset", PyArray1::from_vec(py, column(|p| p.offset)))?;
    out.set_item("area", PyArray1::from_vec(py, column(|p| p.area)))?;
    let pairs = |t: &[TileId]| -> Vec<(u32, u32)> { t.iter().map(|t| (t.col, t.row)).collect() };
    let tiles: Vec<Vec<(u32, u32)>> = set.polygons.iter().map(|p| pairs(&p.tiles)).collect();
    out.set_item("tiles", tiles)?;
    out.set_item("cover", pairs(&set.cover))?;
    Ok(out)
}

/// ``tiles_geojson(data, with_z=True) -> str``: an encoded tile set's polygons as a
/// GeoJSON FeatureCollection (properties ``index``, ``normal``, ``offset``, ``area``,
/// ``tiles``).
#[pyfunction]
#[pyo3(signature = (data, with_z = true))]
pub fn tiles_geojson(data: &[u8], with_z: bool) -> PyResult<String> {
    Ok(decode(data)?.to_geojson(with_z))
}

/// ``las_bounds(path) -> ((xmin, ymin, zmin), (xmax, ymax, zmax), count)``: a LAS/LAZ
/// file's box and point count from its header.
#[pyfunction]
pub fn las_bounds(path: PathBuf) -> PyResult<([f64; 3], [f64; 3], u64)> {
    polylidar_io::read_las_bounds(&path).map_err(|e| error(&e))
}

/// ``synth_city(out_dir, points=1_000_000, tile=250.0, seed=1, density=8.0, laz=True) ->
/// list[str]``: writes the synthetic city of ``synthscan`` (flat, gabled and hipped
/// roofs, courtyards, trees; airborne scan pattern) as LAS/LAZ tiles of ``tile`` metres
/// with ``.labels.npy`` ground truth beside each (int32: 0 ground, −1 trees, roof faces
/// ``1 + 4·building + face``); the file paths.
#[pyfunction]
#[pyo3(signature = (out_dir, points = 1_000_000, tile = 250.0, seed = 1, density = 8.0, laz = true))]
pub fn synth_city(
    py: Python<'_>,
    out_dir: PathBuf,
    points: u64,
    tile: f64,
    seed: u64,
    density: f64,
    laz: bool,
) -> PyResult<Vec<PathBuf>> {
    let city = synthscan::City::new(
        synthscan::CityConfig::default()
            .with_points(points)
            .with_density(density)
            .with_seed(seed),
    )
    .map_err(|e| error(&e))?;
    if !(tile.is_finite() && tile > 0.0) {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "tile {tile} must be positive"
        )));
    }
    py.detach(
        || -> Result<Vec<PathBuf>, Box<dyn std::error::Error + Send + Sync>> {
            std::fs::create_dir_all(&out_dir)?;
            let n = (city.side() / tile).ceil() as u32;
            let mut files = Vec::new();
            for r in 0..n {
                for c in 0..n {
                    let t = city.tile([f64::from(c) * tile, f64::from(r) * tile], tile);
                    let name = format!("city_{c:04}_{r:04}");
                    let path = out_dir.join(format!("{name}.{}", if laz { "laz" } else { "las" }));
                    polylidar_io::write_las(
                        &path,
                        &t.points,
                        &t.classification,
                        &[],
                        &polylidar_io::LasWriteOptions::default(),
                    )?;
                    let labels = t
                        .labels
                        .iter()
                        .map(|&l| i32::try_from(l))
                        .collect::<Result<Vec<i32>, _>>()?;
                    polylidar_io::write_npy_i32(
                        out_dir.join(format!("{name}.labels.npy")),
                        &[labels.len()],
                        &labels,
                    )?;
                    files.push(path);
                }
            }
            Ok(files)
        },
    )
    .map_err(|e| error(&*e))
}

/// Adds the tile functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(extract_tile, m)?)?;
    m.add_function(wrap_pyfunction!(extract_tile_files, m)?)?;
    m.add_function(wrap_pyfunction!(merge_tiles, m)?)?;
    m.add_function(wrap_pyfunction!(tile_polygons, m)?)?;
    m.add_function(wrap_pyfunction!(tiles_geojson, m)?)?;
    m.add_function(wrap_pyfunction!(las_bounds, m)?)?;
    m.add_function(wrap_pyfunction!(synth_city, m)?)?;
    Ok(())
}
