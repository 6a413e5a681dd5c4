"""polylidar_rs: planes and polygons with holes from 2D points, point clouds, depth images
and meshes (Polylidar3D in Rust), with NumPy in and out.

The native extension is ``polylidar_rs.polylidar_rs``; everything it defines is here.
``polylidar_rs.tiles`` plans city-scale clouds in square tiles and
``polylidar_rs.dask`` runs them on a Dask cluster (``pip install polylidar-rs[dask]``).
"""

from .polylidar_rs import *  # noqa: F401,F403
from .polylidar_rs import __version__  # noqa: F401
