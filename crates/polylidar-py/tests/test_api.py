"""The Python API: parameters, NumPy in and out, errors, polygons, stages."""

import json

import numpy as np
import pytest

import polylidar_rs as pr
from conftest import box_corner, grid_with_hole

ORGANIZED = dict(lmax=0.1, z_thresh=0.02, min_triangles=100, norm_thresh=0.95,
                 fastga={"level": 3, "value_threshold": 10, "min_samples": 0, "sample_fraction": 1.0})


def test_2d_polygon_with_hole():
    points = grid_with_hole()
    result = pr.Polylidar(lmax=1.5, min_triangles=10).extract_2d(points)
    assert len(result.polygons) == 1
    polygon = result.polygons[0]
    assert polygon.shell.shape[1] == 2 and polygon.shell.dtype == np.float64
    assert len(polygon.holes) == 1
    # 39 × 39 grid cells minus the hole's 11 × 11 cells, whose four corners keep a
    # half-cell triangle (its diagonal is shorter than lmax)
    assert polygon.area == pytest.approx(39 * 39 - 11 * 11 + 4 * 0.5)
    assert result.counts["polygons"] == 1 and result.counts["points"] == len(points)
    assert set(result.timings) >= {"mesh", "regions", "polygons"}
    assert all(v >= 0 for v in result.timings.values())
    labels = result.point_labels()
    assert labels.shape == (len(points),) and labels.dtype == np.int32
    assert (labels == 0).all()
    # indices point into the input
    np.testing.assert_array_equal(points[polygon.shell_indices], polygon.shell)


def test_input_read_in_place_by_address():
    points = grid_with_hole()
    result = pr.Polylidar(lmax=1.5).extract_2d(points)
    assert result.input_address == points.ctypes.data
    cloud = box_corner()
    result = pr.Polylidar(**ORGANIZED).extract_organized(cloud)
    assert result.input_address == cloud.ctypes.data
    # a read-only array is read in place as well
    cloud.setflags(write=False)
    assert pr.Polylidar(**ORGANIZED).extract_organized(cloud).input_address == cloud.ctypes.data
    # float32 is converted (a copy), with the same polygons
    as32 = grid_with_hole().astype(np.float32)
    r32 = pr.Polylidar(lmax=1.5).extract_2d(as32)
    assert r32.input_address != as32.ctypes.data
    assert len(r32.polygons) == 1


def test_float32_and_float64_agree():
    cloud = box_corner()
    a = pr.Polylidar(**ORGANIZED).extract_organized(cloud)
    b = pr.Polylidar(**ORGANIZED).extract_organized(cloud.astype(np.float32))
    assert len(a.polygons) == len(b.polygons) == 2


def test_unaligned_input_is_read_not_lost():
    # NumPy allows float64 data at any byte offset (Dask hands such arrays to workers);
    # they are copied once, never read as no points.
    points = grid_with_hole()
    raw = np.zeros(points.nbytes + 1, dtype=np.uint8)
    unaligned = np.ndarray(points.shape, dtype=np.float64, buffer=raw, offset=1)
    unaligned[...] = points
    assert not unaligned.flags.aligned
    pl = pr.Polylidar(lmax=1.5, min_triangles=10)
    expected = pl.extract_2d(points)
    got = pl.extract_2d(unaligned)
    assert len(got.polygons) == len(expected.polygons) == 1
    assert np.array_equal(got.polygons[0].shell, expected.polygons[0].shell)


def test_organized_planes_and_labels():
    cloud = box_corner()
    result = pr.Polylidar(**ORGANIZED).extract_organized(cloud)
    assert len(result.polygons) == 2
    normals = sorted(tuple(np.round(np.abs(p.normal), 2)) for p in result.polygons)
    assert normals[0] == pytest.approx((0.0, 0.0, 1.0), abs=0.02)
    assert normals[1] == pytest.approx((0.71, 0.0, 0.71), abs=0.02)
    for p in result.polygons:
        assert p.shell.shape[1] == 3
        # the shell lies on the plane
        assert np.abs(p.shell @ p.normal + p.offset).max() < 1e-6
    labels = result.point_labels()
    assert labels.shape == cloud.shape[:2] and labels.dtype == np.int32
    assert result.dominant_normals.shape[1] == 3
    mesh = result.mesh
    assert mesh.vertices.shape == (cloud.shape[0] * cloud.shape[1], 3)
    assert mesh.triangles.dtype == np.uint32 and mesh.triangle_normals.shape == (mesh.num_triangles, 3)


def test_recycled_extractions_give_the_same_results():
    cloud = box_corner()
    pl = pr.Polylidar(**ORGANIZED)
    fresh = pr.Polylidar(**ORGANIZED).extract_organized(cloud)
    first = pl.extract_organized(cloud)
    pl.recycle(first)
    # The polygons stay; what needs the mesh says it is gone.
    assert len(first.polygons) == len(fresh.polygons)
    for needs_mesh in (lambda: first.mesh, first.point_labels, first.plane_labels):
        with pytest.raises(ValueError, match="recycle"):
            needs_mesh()
    with pytest.raises(ValueError, match="recycle"):
        pl.recycle(first)
    again = pl.extract_organized(cloud)
    assert len(again.polygons) == len(fresh.polygons)
    for a, b in zip(again.polygons, fresh.polygons):
        assert np.array_equal(a.shell, b.shell)
    assert np.array_equal(again.point_labels(), fresh.point_labels())
    assert np.array_equal(again.mesh.triangles, fresh.mesh.triangles)


def test_dtype_errors_name_what_is_expected():
    pl = pr.Polylidar(lmax=1.5)
    with pytest.raises(TypeError, match=r"float64 or float32"):
        pl.extract_2d(np.zeros((10, 2), dtype=np.int64))
    with pytest.raises(TypeError, match=r"numpy.ndarray"):
        pl.extract_2d([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    with pytest.raises(ValueError, match=r"\(N, 2\).*\(10, 3\)"):
        pl.extract_2d(np.zeros((10, 3)))
    with pytest.raises(ValueError, match=r"\(H, W, 3\)"):
        pl.extract_organized(np.zeros((10, 3)))
    with pytest.raises(ValueError, match=r"C-contiguous"):
        pl.extract_2d(np.zeros((10, 4))[:, :2])
    with pytest.raises(ValueError, match=r"C-contiguous"):
        pl.extract_organized(np.zeros((3, 10, 10)).transpose(1, 2, 0))
    with pytest.raises(TypeError, match=r"integer dtype"):
        pl.extract_mesh(np.zeros((3, 3)), np.zeros((1, 3)))
    with pytest.raises(TypeError, match=r"uint16"):
        pl.extract_depth(np.zeros((4, 4), dtype=np.float32), (1, 1, 2, 2))


def test_parameters():
    pl = pr.Polylidar("rgbd", lmax=0.07, norm_thresh_min=0.9, task_threads=2,
                      laplacian={"iterations": 3}, postprocess=None)
    config = pl.config
    assert config["lmax"] == 0.07 and config["norm_thresh"] == 0.9 and config["threads"] == 2
    assert config["laplacian"]["iterations"] == 3 and config["laplacian"]["kernel"] == 3
    assert config["postprocess"] is None
    assert pr.Polylidar(min_triangles=np.int64(7)).config["min_triangles"] == 7
    with pytest.raises(TypeError, match="unexpected keyword argument 'lmaxx'"):
        pr.Polylidar(lmaxx=1.0)
    with pytest.raises(ValueError, match="unknown preset"):
        pr.Polylidar("nope")
    with pytest.raises(ValueError, match="norm_thresh"):
        pr.Polylidar(norm_thresh=0.9, norm_thresh_min=0.8)
    with pytest.raises(ValueError, match="lmax"):
        pr.Polylidar(lmax=-1.0)
    assert "synpeb-auto" in pr.presets()


def test_gpu_smoothing_needs_a_gpu_build():
    gpu = {"laplacian": {"backend": "gpu"}, "bilateral": {"backend": "gpu"}}
    try:
        pl = pr.Polylidar("rgbd", **gpu)
    except ValueError as e:
        assert "`gpu` feature" in str(e), str(e)
    else:
        assert pl.config["laplacian"]["backend"] == "gpu"
        assert pl.config["bilateral"]["backend"] == "gpu"


def test_rust_errors_are_python_exceptions():
    with pytest.raises(pr.PolylidarError, match="point"):
        pr.Polylidar().extract_2d(np.zeros((2, 2)))
    with pytest.raises(pr.PolylidarError, match="no_such_file.pcd"):
        pr.Polylidar().extract_file("no_such_file.pcd")
    with pytest.raises(pr.PolylidarError):
        pr.Polylidar().extract_mesh(np.zeros((3, 3)), np.array([[0, 1, 7]]))
    assert issubclass(pr.PolylidarError, ValueError)


def test_shapely_round_trip():
    shapely = pytest.importorskip("shapely.geometry")
    result = pr.Polylidar(lmax=1.5, min_triangles=10).extract_2d(grid_with_hole())
    polygon = result.polygons[0]
    shape = shapely.shape(polygon)
    assert shape.is_valid
    assert shape.area == pytest.approx(polygon.area)
    assert len(shape.interiors) == 1
    collection = shapely.shape(result.__geo_interface__["features"][0]["geometry"])
    assert collection.equals(shape)
    # 3D polygons keep z
    organized = pr.Polylidar(**ORGANIZED).extract_organized(box_corner())
    shape3d = shapely.shape(organized.polygons[0])
    assert shape3d.has_z


def test_geojson_matches_polygons():
    result = pr.Polylidar(lmax=1.5, min_triangles=10).extract_2d(grid_with_hole())
    collection = json.loads(result.geojson())
    feature = collection["features"][0]
    assert feature["properties"]["area"] == pytest.approx(result.polygons[0].area)
    ring = np.array(feature["geometry"]["coordinates"][0])
    np.testing.assert_allclose(ring[:-1], result.polygons[0].shell)


def test_mesh_input():
    n = 20
    xs, ys = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float))
    vertices = np.stack([xs.ravel(), ys.ravel(), np.zeros(n * n)], axis=1)
    tris = []
    for r in range(n - 1):
        for c in range(n - 1):
            a = r * n + c
            tris += [(a, a + 1, a + n + 1), (a, a + n + 1, a + n)]
    triangles = np.array(tris, dtype=np.int32)
    pl = pr.Polylidar(lmax=2.0, min_triangles=10, z_thresh=0.1,
                      fastga={"level": 3, "value_threshold": 10, "min_samples": 0})
    result = pl.extract_mesh(vertices, triangles)
    assert len(result.polygons) == 1
    assert result.polygons[0].area == pytest.approx((n - 1) ** 2)
    # the same through a Mesh and given dominant normals
    again = pl.extract_planes(result.mesh, np.array([[0.0, 0.0, 1.0]]))
    assert len(again.polygons) == 1


def test_fastga_accumulator_built_once():
    rng = np.random.default_rng(0)
    normals = np.concatenate([np.tile([0.0, 0.0, 1.0], (600, 1)), np.tile([1.0, 0.0, 0.0], (400, 1))])
    normals += rng.normal(scale=0.01, size=normals.shape)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    fastga = pr.FastGA(level=4)
    found, weights = fastga.detect(normals)
    assert found.shape == (2, 3) and weights.shape == (2,)
    assert found[0] @ np.array([0.0, 0.0, 1.0]) > 0.99
    found32, _ = fastga.detect(normals.astype(np.float32))
    np.testing.assert_allclose(found32, found, atol=1e-3)
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        fastga.detect(np.zeros((5, 2)))
    with pytest.raises(pr.PolylidarError):
        pr.FastGA(level=12)


def test_smoothing_meshing_and_depth():
    cloud = box_corner()
    noisy = cloud + np.random.default_rng(1).normal(scale=0.002, size=cloud.shape)
    smooth = pr.laplacian_filter(noisy, iterations=2)
    assert smooth.shape == cloud.shape and smooth.dtype == np.float64
    # smoothing reduces the floor's height noise away from the fold
    assert np.std(smooth[5:-5, 5:30, 2]) < np.std(noisy[5:-5, 5:30, 2])
    normals = pr.bilateral_filter(noisy, iterations=2)
    assert normals.shape == (cloud.shape[0] - 1, cloud.shape[1] - 1, 2, 3)
    assert normals.dtype == np.float32
    mesh = pr.mesh_organized(cloud)
    assert mesh.num_triangles == 2 * (cloud.shape[0] - 1) * (cloud.shape[1] - 1)
    assert pr.mesh_organized(cloud, stride=2).num_vertices == 30 * 40
    depth = np.full((40, 50), 1000, dtype=np.uint16)
    depth[0, 0] = 0
    points = pr.depth_to_cloud(depth, (50.0, 50.0, 25.0, 20.0))
    assert points.shape == (40, 50, 3)
    assert np.isnan(points[0, 0]).all() and points[1, 1, 2] == pytest.approx(1.0)
    matrix = np.array([[50.0, 0, 25.0], [0, 50.0, 20.0], [0, 0, 1]])
    np.testing.assert_array_equal(pr.depth_to_cloud(depth, matrix)[1:], points[1:])
    planes = pr.Polylidar(lmax=0.1, z_thresh=0.02, min_triangles=100,
                          fastga={"level": 3, "min_samples": 0}).extract_depth(depth, matrix)
    assert len(planes.polygons) == 1
    assert planes.input_address == depth.ctypes.data


def test_postprocess_polygons():
    result = pr.Polylidar(**ORGANIZED).extract_organized(box_corner())
    processed = pr.postprocess(result.polygons, alpha=0.01, min_area=0.0)
    assert len(processed) == 2
    assert all(p.source in (0, 1) and p.shell_indices is None for p in processed)
    assert pr.postprocess(result.polygons, min_area=1e6) == []
    with_section = pr.Polylidar(**ORGANIZED, postprocess={"alpha": 0.01}).extract_organized(box_corner())
    assert len(with_section.postprocessed) == 2
    assert json.loads(with_section.geojson())["features"][0]["properties"]["source"] in (0, 1)


def test_decimated_frames_keep_labels_per_pixel():
    # A tilted floor seen by a 64 × 96 camera, decimated 2 × 2: the mesh has a vertex per
    # block, the labels one per input pixel.
    rows, cols = 64, 96
    v, u = np.mgrid[0:rows, 0:cols].astype(np.float64)
    z = 2.0 + 0.01 * v
    cloud = np.ascontiguousarray(np.stack([(u - 48) * z / 100, (v - 32) * z / 100, z], axis=-1))
    common = dict(lmax=0.2, min_triangles=20, z_thresh=0.05, task_threads=2)
    full = pr.Polylidar(**common).extract_organized(cloud)
    half = pr.Polylidar(decimate={"factor": 2}, **common).extract_organized(cloud)
    assert half.mesh.vertices.shape == (rows * cols // 4, 3)
    assert full.mesh.vertices.shape == (rows * cols, 3)
    labels = half.plane_labels()
    assert labels.shape == (rows, cols)
    assert (labels == 0).all() and (full.plane_labels() == 0).all()
    assert half.counts["points"] == rows * cols
    assert half.counts["decimated_points"] == rows * cols // 4
    assert "decimate" in half.timings
    with pytest.raises(ValueError, match="decimate.factor"):
        pr.Polylidar(decimate={"factor": 0})
