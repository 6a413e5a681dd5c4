"""The same polygons as the command line on the shared fixtures, and one object used from
several Python threads."""

import json
import subprocess
import threading

import numpy as np
import pytest

import polylidar_rs as pr
from conftest import box_corner, grid_with_hole


def features(text: str):
    return json.loads(text)["features"]


def assert_same_features(ours, theirs):
    assert len(ours) == len(theirs) > 0
    for a, b in zip(ours, theirs):
        assert a["properties"]["triangles"] == b["properties"]["triangles"]
        assert a["properties"]["area"] == pytest.approx(b["properties"]["area"], rel=1e-9)
        rings_a, rings_b = a["geometry"]["coordinates"], b["geometry"]["coordinates"]
        assert len(rings_a) == len(rings_b)
        for ra, rb in zip(rings_a, rings_b):
            np.testing.assert_allclose(np.array(ra), np.array(rb), rtol=0, atol=1e-9)


@pytest.mark.parametrize(
    "relative, preset",
    [("realsense/rgbd_opc.npy", "rgbd"), ("synpeb/pc_01.pcd", "synpeb"), ("lidar/unreal_lidar.npy", "kitti")],
)
def test_same_polygons_as_the_cli(fixture, cli, tmp_path, relative, preset):
    path = fixture(relative)
    out = tmp_path / "cli.geojson"
    subprocess.run([cli, "extract", str(path), "--preset", preset, "-o", str(out)],
                   check=True, capture_output=True)
    cli_features = features(out.read_text())
    pl = pr.Polylidar(preset)
    # through the file reader shared with the CLI …
    from_file = pl.extract_file(path)
    assert_same_features(features(from_file.geojson()), cli_features)
    # … and through a NumPy array read in place
    cloud = np.ascontiguousarray(pr.load(path)["points"])
    from_array = pl.extract_organized(cloud)
    assert from_array.input_address == cloud.ctypes.data
    assert_same_features(features(from_array.geojson()), cli_features)
    assert len(from_array.polygons) == from_array.counts["polygons"]


def test_load_kinds(fixture):
    pcd = pr.load(fixture("synpeb/pc_01.pcd"))
    assert pcd["kind"] == "organized" and pcd["points"].shape == (500, 500, 3)
    las = pr.load(fixture("lidar/simple.las"))
    assert las["kind"] == "cloud_2.5d" and las["points"].shape == (1065, 3)


def test_depth_png_like_the_cli(fixture, cli, tmp_path):
    png = fixture("rgbd/icl_living_depth_00000.png")
    # the CLI reads a depth PNG with a RealSense _metadata.csv beside it
    depth_dir = tmp_path / "depth"
    depth_dir.mkdir()
    target = depth_dir / "frame.png"
    target.write_bytes(png.read_bytes())
    (depth_dir / "frame_metadata.csv").write_text(
        "Type,Depth\nFx,525\nFy,525\nPPx,319.5\nPPy,239.5\nResolution x,640\nResolution y,480\n"
        "Depth Units,0.001\n"
    )
    out = tmp_path / "cli.geojson"
    subprocess.run([cli, "extract", str(target), "--preset", "rgbd", "-o", str(out)],
                   check=True, capture_output=True)
    result = pr.Polylidar("rgbd").extract_file(target)
    assert_same_features(features(result.geojson()), features(out.read_text()))


def run_threads(work, count=4):
    results, errors = [None] * count, []

    def run(i):
        try:
            results[i] = work()
        except Exception as e:  # pragma: no cover - reported below
            errors.append(e)

    threads = [threading.Thread(target=run, args=(i,)) for i in range(count)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    return results


def test_one_object_from_several_threads():
    cloud = box_corner(120, 160)
    points = grid_with_hole(60, (20, 35))
    pl = pr.Polylidar(lmax=1.5, z_thresh=0.02, min_triangles=100,
                      fastga={"level": 3, "value_threshold": 10, "min_samples": 0})
    expected_3d = pl.extract_organized(cloud).geojson()
    expected_2d = pl.extract_2d(points).geojson()

    def work():
        out = []
        for _ in range(5):
            out.append(pl.extract_organized(cloud).geojson())
            out.append(pl.extract_2d(points).geojson())
        return out

    for out in run_threads(work):
        assert out == [expected_3d, expected_2d] * 5


def test_fastga_from_several_threads():
    rng = np.random.default_rng(3)
    normals = rng.normal(size=(20000, 3))
    normals[:12000] = [0.0, 0.0, 1.0]
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    fastga = pr.FastGA(level=4)
    expected = fastga.detect(normals)[0]
    for found in run_threads(lambda: [fastga.detect(normals)[0] for _ in range(5)]):
        for f in found:
            np.testing.assert_array_equal(f, expected)


def test_threads_run_at_once():
    """The GIL is released: a pure-Python thread keeps running while Rust works."""
    cloud = np.ascontiguousarray(np.tile(box_corner(200, 200), (2, 2, 1)))
    pl = pr.Polylidar(lmax=1.5, z_thresh=0.02, min_triangles=100,
                      fastga={"level": 3, "min_samples": 0})
    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(1)
            done.wait(0.001)

    t = threading.Thread(target=tick)
    t.start()
    try:
        before = len(ticks)
        for _ in range(3):
            pl.extract_organized(cloud)
        during = len(ticks) - before
    finally:
        done.set()
        t.join()
    assert during > 0


def test_depth_cameras_and_stream(fixture, tmp_path):
    icl = fixture("rgbd/icl_living_depth_00000.png")
    tum = fixture("rgbd/tum_depth.png")
    camera = fixture("rgbd/camera_primesense.json")
    pl = pr.Polylidar("rgbd")
    # An Open3D camera JSON (ICL) and numbers (TUM, 5000 units per metre) give the polygons
    # of a RealSense CSV beside the frame.
    results = {}
    for png, scale, intrinsics in [(icl, 0.001, camera), (tum, 0.0002, (525, 525, 319.5, 239.5))]:
        beside = tmp_path / f"beside_{png.stem}" / "frame.png"
        beside.parent.mkdir()
        beside.write_bytes(png.read_bytes())
        (beside.parent / "frame_metadata.csv").write_text(
            "Fx,525\nFy,525\nPPx,319.5\nPPy,239.5\nResolution x,640\nResolution y,480\n"
            f"Depth Units,{scale}\n"
        )
        expected = features(pl.extract_file(beside).geojson())
        given = pl.extract_file(png, intrinsics=intrinsics, depth_scale=scale)
        assert_same_features(features(given.geojson()), expected)
        results[png] = expected
    # A stream gives the frame's result alone, with frames in flight or one at a time.
    [(name, streamed)] = pl.stream([icl], intrinsics=str(camera))
    assert name == str(icl)
    assert_same_features(features(streamed.geojson()), results[icl])
    assert streamed.point_labels().shape == (480, 640)
    for in_flight in (0, 1, 2):
        frames = pl.stream([icl, icl, icl], intrinsics=str(camera), in_flight=in_flight)
        assert [n for n, _ in frames] == [str(icl)] * 3
        for _, e in frames:
            assert_same_features(features(e.geojson()), results[icl])
    # No intrinsics: the error says so.
    lonely = tmp_path / "lonely.png"
    lonely.write_bytes(icl.read_bytes())
    with pytest.raises(pr.PolylidarError, match="no camera intrinsics"):
        pl.extract_file(lonely)
    with pytest.raises(pr.PolylidarError, match="lonely.png"):
        pl.stream([lonely])
