"""Polylidar on a Dask cluster: one task per tile, a tree of merge tasks.

The graph is plain ``dask.delayed``: it runs on any scheduler, and on a
``dask.distributed`` cluster (a ``LocalCluster`` or a scheduler with workers on many
machines) with the dashboard and ``dask.distributed.progress`` showing each tile and merge.
Tile results travel between workers as bytes (the merge needs exact coordinates); a task
whose worker dies is run again by Dask, and a merge refuses a tile that comes twice. See
``docs/dask.md``.

>>> import polylidar_rs.dask as prd                                  # doctest: +SKIP
>>> result = prd.extract_files(paths, tile_size=250, margin=5, preset="rooftop")  # doctest: +SKIP
>>> result.to_geodataframe().plot()                                  # doctest: +SKIP
"""

from __future__ import annotations

from os import fspath
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np

from . import polylidar_rs as _native
from .tiles import Path, TiledResult, TileGrid, files_plan

__all__ = ["tile_graph", "files_graph", "points_graph", "extract_files", "extract_points"]


def read_file_windows(path: str, grid: tuple, tiles: List[Tuple[int, int]]) -> Dict[Tuple[int, int], np.ndarray]:
    """One read task: a LAS/LAZ file's points cut into the windows of ``tiles`` (the tiles
    it feeds), so that each file is decoded once however many windows it meets."""
    points = np.asarray(_native.load(path)["points"], dtype=np.float64)
    points = points[np.isfinite(points).all(axis=1)]
    g = TileGrid((grid[0], grid[1]), grid[2], grid[3], grid[4], grid[5])
    return {tile: g.window_points(points, *tile) for tile in tiles}


def extract_tile_pieces(pieces: Sequence[np.ndarray], grid: tuple, col: int, row: int, preset: Optional[str],
                        params: Dict[str, Any]) -> bytes:
    """One tile task: the tile's polygons from its window's points, in pieces (one per file
    that feeds it, from :func:`read_file_windows`)."""
    points = np.concatenate(pieces) if len(pieces) else np.empty((0, 3))
    return extract_tile_points(points, grid, col, row, preset, params)


def extract_tile_points(points: np.ndarray, grid: tuple, col: int, row: int, preset: Optional[str],
                        params: Dict[str, Any]) -> bytes:
    """One tile task: the tile's polygons from its window's points."""
    # Arrays Dask receives over the network may be unaligned: NumPy copies those.
    points = np.require(points, np.float64, ["C_CONTIGUOUS", "ALIGNED"])
    return _native.extract_tile(points, grid, col, row, preset, **params)


def merge_parts(parts: Sequence[bytes], preset: Optional[str], params: Dict[str, Any],
                tolerance: Dict[str, float]) -> bytes:
    """One merge task: the merge of tile results or of earlier merges."""
    return _native.merge_tiles(list(parts), preset, **tolerance, **params)


def tile_graph(leaves: Sequence[Tuple[Tuple[int, int], Callable[..., bytes], tuple]],
               preset: Optional[str] = None, params: Optional[Dict[str, Any]] = None,
               fan_in: int = 4, tolerance: Optional[Dict[str, float]] = None):
    """The graph: one ``dask.delayed`` task per leaf ``((col, row), function, args)``, then
    merges of ``fan_in`` results at a time up to one; the root ``Delayed`` (its value: the
    encoded merged tile set). Task keys carry a token of everything the graph computes
    from, so two graphs on one client never share a result they should not (fixed keys
    let a second graph reuse the first one's tiles while they were still held)."""
    import dask
    from dask.base import tokenize

    if fan_in < 2:
        raise ValueError(f"fan_in {fan_in} must be at least 2")
    if not leaves:
        raise ValueError("no tile to extract")
    params = dict(params or {})
    tolerance = dict(tolerance or {})
    token = tokenize(leaves, preset, params, tolerance, fan_in)
    level = [
        dask.delayed(function, pure=True)(*args, dask_key_name=f"polylidar-tile-{c}-{r}-{token}")
        for (c, r), function, args in leaves
    ]
    depth = 0
    while len(level) > 1:
        depth += 1
        level = [
            dask.delayed(merge_parts, pure=True)(
                level[i:i + fan_in], preset, params, tolerance,
                dask_key_name=f"polylidar-merge-{depth}-{i // fan_in}-{token}",
            )
            for i in range(0, len(level), fan_in)
        ]
    if depth == 0:
        level = [dask.delayed(merge_parts, pure=True)(level, preset, params, tolerance,
                                                      dask_key_name=f"polylidar-merge-1-0-{token}")]
    return level[0]


def files_graph(paths: Sequence[Path], tile_size: float, margin: float, preset: Optional[str] = None,
                fan_in: int = 4, tolerance: Optional[Dict[str, float]] = None,
                extract: Callable[..., bytes] = extract_tile_pieces, **params):
    """The graph for a set of LAS/LAZ files (see :func:`tile_graph`) and its
    :class:`~polylidar_rs.tiles.TileGrid`: one read task per file
    (:func:`read_file_windows`: decoded once, cut into the windows it meets), one tile task
    per tile on the pieces of its window. ``extract`` is the tile task's function (default
    :func:`extract_tile_pieces`; a wrapper of it can instrument the tiles)."""
    import dask
    from dask.base import tokenize

    grid, plan = files_plan(paths, tile_size, margin)
    g = grid.as_tuple()
    feeds: Dict[str, List[Tuple[int, int]]] = {}
    for tile, files in sorted(plan.items()):
        for f in files:
            feeds.setdefault(f, []).append(tile)
    reads = {
        f: dask.delayed(read_file_windows, pure=True)(
            f, g, tiles, dask_key_name=f"polylidar-read-{i}-{tokenize(f, g, tiles)}")
        for i, (f, tiles) in enumerate(sorted(feeds.items()))
    }
    leaves = [(tile, extract, ([reads[f][tile] for f in files], g, tile[0], tile[1], preset, params))
              for tile, files in sorted(plan.items())]
    return tile_graph(leaves, preset, params, fan_in, tolerance), grid


def points_graph(points: np.ndarray, tile_size: float, margin: float, preset: Optional[str] = None,
                 fan_in: int = 4, tolerance: Optional[Dict[str, float]] = None,
                 extract: Callable[..., bytes] = extract_tile_points, **params):
    """The graph for an ``(N, 3)`` cloud in memory, cut here into the tiles' windows (each
    window's points go into its task)."""
    points = np.ascontiguousarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3 or len(points) == 0:
        raise ValueError(f"points must be a non-empty (N, 3) array, not {points.shape}")
    finite = points[np.isfinite(points).all(axis=1)]
    grid = TileGrid.covering(finite.min(axis=0), finite.max(axis=0), tile_size, margin)
    g = grid.as_tuple()
    leaves = []
    for c, r in grid.tiles():
        window = grid.window_points(finite, c, r)
        if len(window):
            leaves.append(((c, r), extract, (window, g, c, r, preset, params)))
    return tile_graph(leaves, preset, params, fan_in, tolerance), grid


def _run(graph, client) -> TiledResult:
    if client is None:
        return TiledResult(graph.compute())
    return TiledResult(client.compute(graph).result())


def extract_files(paths: Sequence[Path], tile_size: float, margin: float, preset: Optional[str] = None,
                  client=None, fan_in: int = 4, **params) -> TiledResult:
    """Extracts the polygons of LAS/LAZ files in tiles on Dask (``client``, or the default
    scheduler: the active ``dask.distributed`` client if there is one) and merges them."""
    graph, _ = files_graph([fspath(p) for p in paths], tile_size, margin, preset, fan_in, **params)
    return _run(graph, client)


def extract_points(points: np.ndarray, tile_size: float, margin: float, preset: Optional[str] = None,
                   client=None, fan_in: int = 4, **params) -> TiledResult:
    """As :func:`extract_files`, for an ``(N, 3)`` cloud in memory."""
    graph, _ = points_graph(points, tile_size, margin, preset, fan_in, **params)
    return _run(graph, client)
