"""The calls of the original Polylidar3D's Python examples, timed from Python, for
polylidar_rs and — when it is importable — the original `polylidar` / `fastgac` /
`organizedpointfilters` packages; then the Python overhead of polylidar_rs against the
same calls in Rust (examples/python_reference.rs).

    python benches/python_bench.py [--repeats 20] [--no-rust]

Needs the polylidar_rs wheel installed (see crates/polylidar-py/README.md) and, for the
real data, ../shared/fixtures beside the checkout. Prints one table of median
milliseconds and the overhead checks (Python ≤ 3 % over Rust on pc_01 end to end, FastGA
on 100k normals within 10 %); timings on a loaded machine drift, so run it idle.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import polylidar_rs as pr

ROOT = Path(__file__).resolve().parents[1]
FIXTURES = ROOT.parent / "shared" / "fixtures"


def median_ms(fn, repeats):
    fn()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append((time.perf_counter() - start) * 1e3)
    return statistics.median(times)


def random_unit_normals(count, seed):
    rng = np.random.default_rng(seed)
    z = rng.uniform(-1.0, 1.0, count)
    phi = rng.uniform(0.0, 2 * np.pi, count)
    r = np.sqrt(1.0 - z * z)
    return np.ascontiguousarray(np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1))


def points_2d(count, seed=1):
    """Uniform points in a 100 × 100 square with a 40 × 40 hole (the 2D example's kind)."""
    rng = np.random.default_rng(seed)
    pts = rng.uniform(0.0, 100.0, (count * 2, 2))
    keep = ~((np.abs(pts[:, 0] - 50) < 20) & (np.abs(pts[:, 1] - 50) < 20))
    return np.ascontiguousarray(pts[keep][:count])


def ours(repeats):
    rows = []
    pts = points_2d(100_000)
    spacing = 100.0 / np.sqrt(100_000)
    pl_lmax = pr.Polylidar(lmax=4 * spacing, min_triangles=20)
    pl_alpha = pr.Polylidar(alpha=2 * spacing, min_triangles=20)
    rows.append(("2D, 100k points, lmax", median_ms(lambda: pl_lmax.extract_2d(pts), repeats)))
    rows.append(("2D, 100k points, alpha", median_ms(lambda: pl_alpha.extract_2d(pts), repeats)))

    opc = FIXTURES / "realsense" / "rgbd_opc.npy"
    if opc.is_file():
        cloud = np.ascontiguousarray(np.load(opc))
        pl = pr.Polylidar("rgbd")
        fastga = pr.FastGA(level=3, value_threshold=50, cluster_distance=0.28, sample_fraction=0.12)
        staged = pr.Polylidar("rgbd", postprocess=None)

        def stages():
            smooth = pr.laplacian_filter(cloud, lambda_=1.0, kernel=3, iterations=2)
            mesh = pr.mesh_organized(smooth)
            pr.bilateral_filter(smooth, sigma_length=0.1, sigma_angle=0.15, iterations=2)
            normals, _ = fastga.detect(mesh.triangle_normals)
            planes = staged.extract_planes(mesh, normals)
            pr.postprocess(planes.polygons, alpha=0.02, beta_pos=0.005, beta_neg=0.02,
                           min_area=0.1, min_hole_area=0.1)

        rows.append(("RealSense OPC 120x212: stage by stage", median_ms(stages, repeats)))
        rows.append(("RealSense OPC 120x212: extract_organized (rgbd)",
                     median_ms(lambda: pl.extract_organized(cloud), repeats)))
    pc01 = FIXTURES / "synpeb" / "pc_01.pcd"
    pc01_ms = None
    if pc01.is_file():
        cloud = np.ascontiguousarray(pr.load(pc01)["points"])
        pl = pr.Polylidar("synpeb")
        pc01_ms = median_ms(lambda: pl.extract_organized(cloud), repeats)
        rows.append(("SynPEB pc_01 500x500: extract_organized (synpeb)", pc01_ms))
    normals = random_unit_normals(100_000, 42)
    fastga = pr.FastGA(level=4)
    fastga_ms = median_ms(lambda: fastga.detect(normals), repeats * 5)
    rows.append(("FastGA, 100k random normals, level 4 (accumulator kept)", fastga_ms))
    return rows, pc01_ms, fastga_ms, normals


def original(repeats):
    """The original packages' calls, when they are installed."""
    try:
        from polylidar import MatrixDouble, Polylidar3D  # noqa: F401
    except ImportError:
        return None
    rows = []
    pts = points_2d(100_000)
    spacing = 100.0 / np.sqrt(100_000)
    pl = Polylidar3D(lmax=4 * spacing, min_triangles=20)
    mat = MatrixDouble(pts, False)
    rows.append(("2D, 100k points, lmax", median_ms(lambda: pl.extract_planes_and_polygons(mat), repeats)))
    return rows


def rust_reference(repeats, normals):
    """The Rust reference's medians; it times FastGA on the very `normals` timed here."""
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "normals.npy")
        np.save(path, normals)
        cmd = ["cargo", "run", "--quiet", "--release", "-p", "polylidar-benches",
               "--example", "python_reference", "--", str(repeats), path]
        done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    if done.returncode != 0:
        print(f"(Rust reference failed: {done.stderr.strip()[-400:]})", file=sys.stderr)
        return None
    return json.loads(done.stdout.strip().splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--no-rust", action="store_true", help="skip the Rust reference run")
    args = parser.parse_args()

    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"polylidar_rs {pr.__version__}, Python {sys.version.split()[0]}, "
          f"{os.cpu_count()} CPUs, load average {load:.2f}; median ms of {args.repeats} runs")
    rows, pc01_ms, fastga_ms, normals = ours(args.repeats)
    theirs = original(args.repeats)
    theirs_by_name = dict(theirs or [])
    print(f"\n| call | polylidar_rs (ms) | original (ms) |\n| --- | ---: | ---: |")
    for name, ms in rows:
        other = theirs_by_name.get(name)
        print(f"| {name} | {ms:.2f} | {'%.2f' % other if other else '—'} |")
    if theirs is None:
        print("\nThe original packages (polylidar, fastgac, organizedpointfilters) are not "
              "importable here (no wheel for this Python), so only polylidar_rs is timed.")

    if args.no_rust:
        return
    rust = rust_reference(args.repeats, normals)
    if not rust:
        return
    print("\nPython overhead against the same call in Rust (examples/python_reference.rs):")
    checks = [("pc_01 end to end", pc01_ms, rust.get("pc_01_synpeb"), 3.0),
              ("FastGA 100k normals", fastga_ms, rust.get("fastga_100k"), 10.0)]
    for name, py_ms, rust_ms, limit in checks:
        if py_ms is None or rust_ms is None:
            print(f"  {name}: not measured (fixture missing)")
            continue
        over = (py_ms / rust_ms - 1.0) * 100.0
        verdict = "ok" if over <= limit else "OVER"
        print(f"  {name}: Python {py_ms:.2f} ms, Rust {rust_ms:.2f} ms, "
              f"overhead {over:+.1f} % (target ≤ {limit:.0f} %) {verdict}")


if __name__ == "__main__":
    main()
