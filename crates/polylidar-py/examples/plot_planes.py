"""Planes and polygons of a point cloud file, drawn with matplotlib.

    python plot_planes.py ../../../../shared/fixtures/synpeb/pc_01.pcd --preset synpeb
    python plot_planes.py depth.png --preset rgbd          # 16-bit depth + depth_metadata.csv
    python plot_planes.py cloud.pcd --preset rgbd --out planes.png

Reads the file with ``polylidar_rs.load`` (PCD, NPY, PLY, OBJ, LAS/LAZ, CSV or a 16-bit
depth PNG with its RealSense ``_metadata.csv``), runs the pipeline on the NumPy array, and
draws the points seen from above with each plane's polygon (shell and holes) on top.
"""

import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import polylidar_rs as pr  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("path", help="a PCD / NPY / PLY / LAS / CSV file or a 16-bit depth PNG")
    parser.add_argument("--preset", default="synpeb", choices=pr.presets())
    parser.add_argument("--out", default="planes.png", help="picture to write")
    args = parser.parse_args()

    data = pr.load(args.path)
    polylidar = pr.Polylidar(args.preset)
    if data["kind"] == "organized":
        cloud = data["points"]
        result = polylidar.extract_organized(cloud)
        points = cloud.reshape(-1, 3)
    elif data["kind"] == "mesh":
        points = data["vertices"]
        result = polylidar.extract_mesh(points, data["triangles"])
    else:
        points = data["points"]
        result = polylidar.extract_points(points)
    polygons = result.postprocessed or result.polygons
    print(f"{len(polygons)} polygons; counts {result.counts}")
    print("ms per stage:", {k: round(v, 2) for k, v in result.timings.items()})

    valid = np.isfinite(points).all(axis=1)
    fig, ax = plt.subplots(figsize=(8, 8))
    ax.scatter(points[valid, 0], points[valid, 1], s=0.2, c="0.75", linewidths=0)
    colours = plt.get_cmap("tab20")
    for i, polygon in enumerate(polygons):
        colour = colours(i % 20)
        shell = np.vstack([polygon.shell, polygon.shell[:1]])
        ax.fill(shell[:, 0], shell[:, 1], color=colour, alpha=0.35, linewidth=0)
        ax.plot(shell[:, 0], shell[:, 1], color=colour, linewidth=1.2)
        for hole in polygon.holes:
            ring = np.vstack([hole, hole[:1]])
            ax.plot(ring[:, 0], ring[:, 1], color="k", linewidth=0.8)
    ax.set_aspect("equal")
    ax.set_title(f"{args.path}: {len(polygons)} polygons ({args.preset})")
    fig.savefig(args.out, dpi=150, bbox_inches="tight")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
