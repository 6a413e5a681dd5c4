"""City-scale clouds in square tiles: the plan (which tiles, which files feed each) and
the merged result, independent of the scheduler that runs the tiles.

A :class:`TileGrid` cuts the xy plane into squares of ``size`` (the *cores*), each
extracted on its *window* (the core grown by ``margin``) and clipped back to its core; the
tiles' results are merged across the seams by :func:`polylidar_rs.merge_tiles`. See
``docs/dask.md``.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from os import PathLike, fspath
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import polylidar_rs as _native

Path = Union[str, "PathLike[str]"]


@dataclass(frozen=True)
class TileGrid:
    """Squares of side ``size`` from ``origin`` (``cols × rows`` of them); windows grown by
    ``margin`` (a few ``lmax``: the triangles along the seams are then the whole cloud's).
    """

    origin: Tuple[float, float]
    size: float
    margin: float
    cols: int
    rows: int

    @classmethod
    def covering(cls, lo: Sequence[float], hi: Sequence[float], size: float, margin: float) -> "TileGrid":
        """The grid of squares of ``size`` from ``lo`` that covers the box ``lo``–``hi``."""
        if not (size > 0 and math.isfinite(size)):
            raise ValueError(f"tile size {size} must be positive")
        cols = int(math.floor((hi[0] - lo[0]) / size)) + 1
        rows = int(math.floor((hi[1] - lo[1]) / size)) + 1
        return cls((float(lo[0]), float(lo[1])), float(size), float(margin), cols, rows)

    def as_tuple(self) -> Tuple[float, float, float, float, int, int]:
        """``(x0, y0, size, margin, cols, rows)``, as the native functions take it."""
        return (self.origin[0], self.origin[1], self.size, self.margin, self.cols, self.rows)

    def tiles(self) -> List[Tuple[int, int]]:
        """Every tile ``(col, row)``, row by row."""
        return [(c, r) for r in range(self.rows) for c in range(self.cols)]

    def window(self, col: int, row: int) -> Tuple[float, float, float, float]:
        """The window ``(xmin, ymin, xmax, ymax)`` of tile ``(col, row)``."""
        x0 = self.origin[0] + col * self.size - self.margin
        y0 = self.origin[1] + row * self.size - self.margin
        return (x0, y0, x0 + self.size + 2 * self.margin, y0 + self.size + 2 * self.margin)

    def window_points(self, points: np.ndarray, col: int, row: int) -> np.ndarray:
        """The rows of ``points`` ``(N, 3)`` inside the window of ``(col, row)``."""
        x0, y0, x1, y1 = self.window(col, row)
        inside = (points[:, 0] >= x0) & (points[:, 0] <= x1) & (points[:, 1] >= y0) & (points[:, 1] <= y1)
        return np.ascontiguousarray(points[inside], dtype=np.float64)


def files_plan(paths: Sequence[Path], size: float, margin: float) -> Tuple[TileGrid, Dict[Tuple[int, int], List[str]]]:
    """The grid covering LAS/LAZ files (their header boxes) and, for every tile, the
    files whose box meets its window; tiles no file meets are left out."""
    paths = [fspath(p) for p in paths]
    if not paths:
        raise ValueError("no input files")
    boxes = [_native.las_bounds(p) for p in paths]
    lo = (min(b[0][0] for b in boxes), min(b[0][1] for b in boxes))
    hi = (max(b[1][0] for b in boxes), max(b[1][1] for b in boxes))
    grid = TileGrid.covering(lo, hi, size, margin)
    plan: Dict[Tuple[int, int], List[str]] = {}
    for tile in grid.tiles():
        x0, y0, x1, y1 = grid.window(*tile)
        feeding = [p for p, (bmin, bmax, n) in zip(paths, boxes)
                   if n > 0 and bmin[0] <= x1 and bmax[0] >= x0 and bmin[1] <= y1 and bmax[1] >= y0]
        if feeding:
            plan[tile] = feeding
    return grid, plan


class TiledResult:
    """The merged polygons of a tiled run (an encoded tile set): WKB for GeoPandas,
    GeoJSON, GeoParquet."""

    def __init__(self, data: bytes):
        self.data = bytes(data)
        self._polygons: Optional[Dict[str, Any]] = None

    def polygons(self, with_z: bool = True) -> Dict[str, Any]:
        """``{"wkb", "normal", "offset", "area", "tiles", "cover"}``
        (see :func:`polylidar_rs.tile_polygons`)."""
        if with_z:
            if self._polygons is None:
                self._polygons = _native.tile_polygons(self.data, True)
            return self._polygons
        return _native.tile_polygons(self.data, False)

    def __len__(self) -> int:
        return len(self.polygons()["wkb"])

    @property
    def cover(self) -> List[Tuple[int, int]]:
        """The tiles whose results are in (each once)."""
        return [tuple(t) for t in self.polygons()["cover"]]

    def to_geojson(self, path: Optional[Path] = None, with_z: bool = True) -> str:
        """A GeoJSON FeatureCollection (written to ``path`` when given)."""
        text = _native.tiles_geojson(self.data, with_z)
        if path is not None:
            with open(fspath(path), "w", encoding="utf-8") as f:
                f.write(text)
        return text

    def to_geodataframe(self, crs: Any = None, with_z: bool = True):
        """A ``geopandas.GeoDataFrame`` (needs geopandas): one row per polygon with its
        plane (``nx``, ``ny``, ``nz``, ``offset``), ``area`` and ``tiles`` (JSON)."""
        import geopandas  # optional dependency: pip install polylidar-rs[geo]

        p = self.polygons(with_z)
        normal = np.asarray(p["normal"]).reshape(-1, 3)
        return geopandas.GeoDataFrame(
            {
                "nx": normal[:, 0], "ny": normal[:, 1], "nz": normal[:, 2],
                "offset": p["offset"], "area": p["area"],
                "tiles": [json.dumps([list(t) for t in ts]) for ts in p["tiles"]],
            },
            geometry=geopandas.GeoSeries.from_wkb(p["wkb"], crs=crs),
        )

    def to_parquet(self, path: Path, crs: Any = None) -> None:
        """GeoParquet (needs geopandas and pyarrow)."""
        self.to_geodataframe(crs).to_parquet(fspath(path))
