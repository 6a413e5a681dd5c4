"""Times a tiled extraction of LAS/LAZ tiles on a Dask LocalCluster (docs/bench/dask_scale.md).

Make a synthetic city first (`cargo xtask city --points 100000000 --out city`, or
`polylidar_rs.synth_city`), then::

    python dask_city.py city --workers 2 --tile 250 --margin 4 --preset aerial

It prints one JSON line: the wall time from submitting the graph to the merged result, the
peak resident memory of every worker process, the polygons and the tiles. ``--out`` also
writes the polygons as GeoJSON.
"""

import argparse
import glob
import json
import os
import resource
import time

from dask.distributed import Client, LocalCluster, progress

import polylidar_rs.dask as prd


def peak_rss_mb() -> float:
    """The peak resident memory of the calling process, MB (run on each worker)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", help="folder of .laz/.las tiles")
    parser.add_argument("--workers", type=int, default=2, help="worker processes (one thread each)")
    parser.add_argument("--tile", type=float, default=250.0, help="tile side, in the files' unit")
    parser.add_argument("--margin", type=float, default=4.0, help="overlap margin of the tiles")
    parser.add_argument("--preset", default="aerial", help="rooftop (2.5D) or aerial (3D)")
    parser.add_argument("--fan-in", type=int, default=4, help="results per merge task")
    parser.add_argument("--out", help="write the merged polygons to this GeoJSON file")
    args = parser.parse_args()

    files = sorted(glob.glob(os.path.join(args.folder, "*.laz")) + glob.glob(os.path.join(args.folder, "*.las")))
    if not files:
        raise SystemExit(f"no .laz or .las file in {args.folder}")
    with LocalCluster(n_workers=args.workers, threads_per_worker=1, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        started = time.perf_counter()
        # One pipeline thread per task: the workers are the parallelism.
        graph, grid = prd.files_graph(files, args.tile, args.margin, args.preset, args.fan_in, threads=1)
        future = client.compute(graph)
        progress(future)
        data = future.result()
        wall = time.perf_counter() - started
        peaks = client.run(peak_rss_mb)
    result = prd.TiledResult(data)
    if args.out:
        result.to_geojson(args.out)
    print()
    print(json.dumps({
        "files": len(files),
        "workers": args.workers,
        "tile": args.tile,
        "preset": args.preset,
        "wall_s": round(wall, 1),
        "polygons": len(result),
        "tiles": len(result.cover),
        "peak_worker_mb": sorted(round(v) for v in peaks.values()),
    }))


if __name__ == "__main__":
    main()
