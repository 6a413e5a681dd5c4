"""polylidar_rs: planes and non-convex polygons with holes from 2D points, point clouds,
depth images and meshes (Polylidar3D in Rust).

NumPy arrays go in without copies when they are float64 and C-contiguous (the Rust
pipeline reads the array's buffer; float32 is converted once); results come back as NumPy
arrays and :class:`Polygon` objects with ``__geo_interface__``. The GIL is released while
Rust works, so several Python threads can run at once, on one shared :class:`Polylidar`
too. Do not modify an array while a call that reads it is running.

Errors: ``TypeError`` for an argument of the wrong type or dtype, ``ValueError`` for a wrong
shape, a non-contiguous array or a bad parameter, :class:`PolylidarError` (a ``ValueError``)
for what the Rust library refuses, with its message.
"""

from os import PathLike
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

FloatArray = npt.NDArray[Union[np.float64, np.float32]]
Intrinsics = Union[Sequence[float], npt.ArrayLike]

class PolylidarError(ValueError):
    """An error of the Rust library: bad parameters, input that cannot be meshed, an
    unreadable file."""

class Polygon:
    """A polygon with holes on a plane; ``shapely.geometry.shape(polygon)`` works."""

    @property
    def shell(self) -> npt.NDArray[np.float64]:
        """Shell coordinates, ``(K, 3)`` (``(K, 2)`` for 2D input), counter-clockwise
        about the normal, not closed."""
    @property
    def holes(self) -> List[npt.NDArray[np.float64]]:
        """Hole coordinates, one ``(K, 3)`` / ``(K, 2)`` array per hole, clockwise."""
    @property
    def shell_indices(self) -> Optional[npt.NDArray[np.uint32]]:
        """Indices of the shell's points into the input (``None`` when post-processed)."""
    @property
    def hole_indices(self) -> Optional[List[npt.NDArray[np.uint32]]]:
        """Indices of each hole's points (``None`` when post-processed)."""
    @property
    def normal(self) -> npt.NDArray[np.float64]:
        """Unit normal ``(3,)`` of the plane."""
    @property
    def offset(self) -> float:
        """``d`` of the plane ``normal · p + d = 0``."""
    @property
    def area(self) -> float:
        """Area in the plane, shell minus holes (input units²)."""
    @property
    def triangles(self) -> Optional[npt.NDArray[np.uint32]]:
        """Mesh triangles of the plane segment (``None`` when post-processed)."""
    @property
    def plane_id(self) -> Optional[int]:
        """Index of the first polygon on the same plane (``None`` when post-processed)."""
    @property
    def group(self) -> Optional[int]:
        """Index of the dominant normal the segment was grown for (3D)."""
    @property
    def source(self) -> Optional[int]:
        """For a post-processed polygon, the extracted polygon it came from."""
    @property
    def __geo_interface__(self) -> Dict[str, Any]:
        """``{"type": "Polygon", "coordinates": (shell, *holes)}`` with closed rings."""

class Mesh:
    """A triangle mesh (half-edge): vertices, triangles, triangle normals."""

    @property
    def vertices(self) -> npt.NDArray[np.float64]:
        """``(N, 3)`` vertex coordinates (a copy)."""
    @property
    def triangles(self) -> npt.NDArray[np.uint32]:
        """``(M, 3)`` vertex indices, counter-clockwise."""
    @property
    def triangle_normals(self) -> Optional[npt.NDArray[np.float64]]:
        """``(M, 3)`` unit normals, or ``None``."""
    @property
    def num_vertices(self) -> int: ...
    @property
    def num_triangles(self) -> int: ...

class Extraction:
    """The result of a pipeline run."""

    @property
    def polygons(self) -> List[Polygon]:
        """The polygons as extracted."""
    @property
    def postprocessed(self) -> List[Polygon]:
        """The post-processed polygons (empty unless the parameters post-process)."""
    @property
    def dominant_normals(self) -> npt.NDArray[np.float64]:
        """3D: the ``(K, 3)`` dominant plane normals the segments were grown for."""
    @property
    def mesh(self) -> Mesh:
        """The triangulation the polygons come from (a copy on each access); ``ValueError``
        once :meth:`Polylidar.recycle` took it."""
    @property
    def counts(self) -> Dict[str, int]:
        """What each stage kept and dropped (``points``, ``triangles``, ``dropped_lmax``,
        ``regions``, ``polygons``, ``holes``, ``dominant_normals``, …)."""
    @property
    def timings(self) -> Dict[str, float]:
        """Milliseconds per stage that ran, in order."""
    def point_labels(self) -> npt.NDArray[np.int32]:
        """The polygon of every input point (``-1``: none); ``(H, W)`` for organized input."""
    def plane_labels(self) -> npt.NDArray[np.int32]:
        """The plane of every input point (``-1``: none), as scored against ground truth."""
    def geojson(self, postprocessed: Optional[bool] = None) -> str:
        """The polygons as a GeoJSON FeatureCollection, as the command line writes it."""
    @property
    def __geo_interface__(self) -> Dict[str, Any]:
        """The FeatureCollection of :meth:`geojson` as a mapping."""
    @property
    def input_address(self) -> int:
        """Address of the buffer the pipeline read: ``array.ctypes.data`` when the input
        array was used in place; 0 for files and meshes."""

class Polylidar:
    """The pipeline for every input kind, built once and reused; thread-safe.

    ``Polylidar(preset=None, **params)``: ``preset`` is one of :func:`presets` (the papers'
    parameters, in metres), ``params`` override it by name: ``alpha``, ``lmax``,
    ``min_triangles``, ``min_hole_vertices``, ``z_thresh``, ``norm_thresh`` (also as the
    original's ``norm_thresh_min``), ``up``, ``min_area``, ``refine``, ``threads`` (also
    ``task_threads``); sections as dicts merged into the preset's (``laplacian``,
    ``bilateral``, ``fastga``, ``postprocess``) or ``None`` to turn one off.
    """

    def __init__(self, preset: Optional[str] = None, **params: Any) -> None: ...
    @property
    def config(self) -> Dict[str, Any]:
        """The parameters in use."""
    def extract_2d(self, points: FloatArray) -> Extraction:
        """Polygons of a 2D point set ``(N, 2)``."""
    def extract_25d(self, points: FloatArray) -> Extraction:
        """Polygons of a 3D cloud ``(N, 3)`` seen along ``up``."""
    def extract_points(self, points: FloatArray) -> Extraction:
        """``(N, 2)``: :meth:`extract_2d`; ``(N, 3)``: :meth:`extract_25d`."""
    def extract_organized(self, cloud: FloatArray) -> Extraction:
        """Planes and polygons of an organized cloud ``(H, W, 3)`` (NaN: invalid)."""
    def recycle(self, extraction: Extraction) -> None:
        """Hands the extraction's mesh back for the next organized frame to be meshed into;
        its ``mesh``, ``point_labels`` and ``plane_labels`` raise ``ValueError`` afterwards."""
    def extract_mesh(self, vertices: FloatArray, triangles: npt.NDArray[np.integer]) -> Extraction:
        """Planes and polygons of a mesh: ``(N, 3)`` vertices, ``(M, 3)`` triangles."""
    def extract_planes(self, mesh: Mesh, dominant_normals: Optional[FloatArray] = None) -> Extraction:
        """Planes and polygons of a :class:`Mesh` for given dominant normals ``(K, 3)``
        (``None``: detect them)."""
    def extract_depth(
        self,
        depth: npt.NDArray[np.uint16],
        intrinsics: Intrinsics,
        depth_scale: float = 0.001,
        stride: int = 1,
        max_depth: Optional[float] = None,
    ) -> Extraction:
        """Planes and polygons of a 16-bit depth image ``(H, W)`` with ``(fx, fy, cx, cy)``
        or a 3 × 3 camera matrix."""
    def extract_file(
        self,
        path: Union[str, PathLike],
        intrinsics: Union[Intrinsics, str, PathLike, None] = None,
        depth_scale: Optional[float] = None,
    ) -> Extraction:
        """Reads a PCD, NPY, PLY, OBJ, LAS/LAZ, CSV or depth PNG file and runs the pipeline
        that fits it. A depth PNG's camera: ``intrinsics`` ``(fx, fy, cx, cy)``, a 3 × 3
        matrix or the path of an Open3D camera JSON / RealSense metadata CSV (default: the
        ``_metadata.csv`` beside it); ``depth_scale`` metres per unit (default: the CSV's,
        else 0.001; TUM: 0.0002)."""
    def stream(
        self,
        paths: Sequence[Union[str, PathLike]],
        intrinsics: Union[Intrinsics, str, PathLike, None] = None,
        depth_scale: Optional[float] = None,
        prefetch: int = 1,
        in_flight: int = 0,
    ) -> List[Tuple[str, Extraction]]:
        """Runs the pipeline over depth frames in order, one pipeline kept across them, the
        next frame decoded on a loader thread and ``in_flight`` frames run at once (0: one
        or two, whichever short trials show to be faster; 1: each alone); the camera as for
        :meth:`extract_file`. Raises on the first frame that fails, naming it."""

class FastGA:
    """Dominant plane normals (Fast Gaussian Accumulator), the accumulator built once."""

    def __init__(
        self,
        level: int = 4,
        value_threshold: float = 15.0,
        cluster_distance: float = 0.1,
        min_cluster_weight: float = 0.15,
        sample_fraction: float = 1.0,
    ) -> None: ...
    def detect(self, normals: FloatArray) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """``(normals (K, 3), weights (K,))`` of unit normals ``(N, 3)``, strongest first."""
    @property
    def level(self) -> int: ...

def laplacian_filter(
    cloud: FloatArray, lambda_: float = 1.0, kernel: int = 3, iterations: int = 1, parallel: bool = True
) -> npt.NDArray[np.float64]:
    """Laplacian vertex smoothing of an organized cloud ``(H, W, 3)``: a new array."""

def bilateral_filter(
    cloud: FloatArray,
    sigma_length: float = 0.1,
    sigma_angle: float = 0.15,
    kernel: int = 3,
    iterations: int = 1,
    parallel: bool = True,
) -> npt.NDArray[np.float32]:
    """Smoothed normals ``(H - 1, W - 1, 2, 3)`` of the cloud's right-cut triangles."""

def mesh_organized(cloud: FloatArray, stride: int = 1) -> Mesh:
    """The right-cut triangle mesh of an organized cloud, with triangle normals."""

def depth_to_cloud(
    depth: npt.NDArray[np.uint16],
    intrinsics: Intrinsics,
    depth_scale: float = 0.001,
    stride: int = 1,
    max_depth: Optional[float] = None,
) -> npt.NDArray[np.float64]:
    """The organized cloud ``(H, W, 3)`` of a 16-bit depth image (NaN: no depth)."""

def postprocess(
    polygons: Sequence[Polygon],
    alpha: float = 0.0,
    beta_pos: float = 0.0,
    beta_neg: float = 0.0,
    min_area: float = 0.0,
    min_hole_area: float = 0.0,
) -> List[Polygon]:
    """Simplify, buffer and filter 3D polygons in their planes (Polylidar3D §8)."""

def load(path: Union[str, PathLike]) -> Dict[str, Any]:
    """Reads a file into arrays: ``{"kind": ..., "points": ...}`` (meshes: ``vertices``,
    ``triangles``)."""

def presets() -> List[str]:
    """The names accepted as ``preset``."""

# Tiles (the Dask front, polylidar_rs.dask): a grid is (x0, y0, size, margin, cols, rows);
# tile results and merges are encoded tile sets (bytes).

def extract_tile(
    points: FloatArray, grid: Tuple[float, float, float, float, int, int], col: int, row: int,
    preset: Optional[str] = None, **params: Any,
) -> bytes:
    """The 2.5D polygons of tile ``(col, row)`` from the points in its window, clipped to
    its core."""

def extract_tile_files(
    paths: Sequence[Union[str, PathLike]], grid: Tuple[float, float, float, float, int, int],
    col: int, row: int, preset: Optional[str] = None, **params: Any,
) -> bytes:
    """As :func:`extract_tile`, reading the window's points from LAS/LAZ files."""

def merge_tiles(
    parts: Sequence[bytes], preset: Optional[str] = None, max_angle_deg: Optional[float] = None,
    max_offset: Optional[float] = None, **params: Any,
) -> bytes:
    """Merges tile results across their seams (one polygon per plane cut by seams)."""

def tile_polygons(data: bytes, with_z: bool = True) -> Dict[str, Any]:
    """``{"wkb", "normal", "offset", "area", "tiles", "cover"}`` of an encoded tile set."""

def tiles_geojson(data: bytes, with_z: bool = True) -> str:
    """An encoded tile set's polygons as a GeoJSON FeatureCollection."""

def las_bounds(path: Union[str, PathLike]) -> Tuple[Tuple[float, float, float], Tuple[float, float, float], int]:
    """A LAS/LAZ file's box and point count, from its header."""

def synth_city(
    out_dir: Union[str, PathLike], points: int = 1_000_000, tile: float = 250.0, seed: int = 1,
    density: float = 8.0, laz: bool = True,
) -> List[str]:
    """Writes the synthetic city (synthscan) as LAS/LAZ tiles with ``.labels.npy`` ground
    truth; the file paths."""
