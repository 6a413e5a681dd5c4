"""The Dask front on a LocalCluster of 2 worker processes: the tiled result equals one run
on the whole cloud, a roof across four tiles is one polygon, and a worker killed in the
middle of a run is replaced by Dask with nothing lost or counted twice."""

import functools
import os

import numpy as np
import pytest

import polylidar_rs as pr
from conftest import record_skip

shapely = pytest.importorskip("shapely")


@pytest.fixture(scope="module")
def client(request):
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        record_skip(request, "dask.distributed is not installed (pip install polylidar-rs[dask])")
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           dashboard_address=":0", silence_logs=40)
    with Client(cluster) as c:
        yield c
    cluster.close()


@pytest.fixture(scope="module")
def city(tmp_path_factory):
    """A small synthetic city (about 160,000 returns, 141 m a side) as 9 LAZ files of
    50 m."""
    out = tmp_path_factory.mktemp("city")
    return [str(p) for p in pr.synth_city(str(out), points=160_000, tile=50.0, seed=4)]


@pytest.fixture(scope="module")
def tiled(client, city):
    """The city in 3 × 3 tiles of 50 m on the cluster."""
    import polylidar_rs.dask as prd

    return prd.extract_files(city, tile_size=50.0, margin=4.0, preset="rooftop", client=client)


def shapes(result):
    return [shapely.from_wkb(w) for w in result.polygons(with_z=False)["wkb"]]


def relative_difference(a, b):
    ua, ub = shapely.union_all(a), shapely.union_all(b)
    return ua.symmetric_difference(ub).area / ua.area


def single_run(paths, **params):
    """One tile covering the whole cloud: the pipeline on every point at once."""
    import polylidar_rs.dask as prd

    grid, _ = prd.files_plan(paths, 1e6, 0.0)
    data = pr.extract_tile_files(list(paths), grid.as_tuple(), 0, 0, "rooftop", **params)
    return prd.TiledResult(pr.merge_tiles([data], "rooftop", **params))


def test_tiled_city_equals_the_single_run(city, tiled):
    single = single_run(city)
    a, b = shapes(single), shapes(tiled)
    assert len(a) >= 4
    assert len(a) == len(b)
    assert all(p.is_valid for p in b)
    assert relative_difference(a, b) < 1e-6
    assert sum(len(p.interiors) for p in a) == sum(len(p.interiors) for p in b)
    cover = tiled.cover
    assert len(cover) == len(set(cover)) == 9
    # GeoJSON of the same polygons.
    import json

    features = json.loads(tiled.to_geojson())["features"]
    assert len(features) == len(b)
    assert len(features[0]["geometry"]["coordinates"][0][0]) == 3


def roof_faces_found(result, city):
    """The share of the city's roof faces of which one polygon holds at least 80 % of the
    returns (xy inside it, within 1 m of its plane): Table 10's f on roof faces."""
    points = np.concatenate([np.asarray(pr.load(p)["points"]) for p in city])
    labels = np.concatenate([np.load(p.rsplit(".", 1)[0] + ".labels.npy") for p in city])
    roof = labels >= 1
    points, labels = points[roof], labels[roof]
    p = result.polygons(with_z=False)
    best = {}
    for wkb, n, d in zip(p["wkb"], p["normal"], p["offset"]):
        inside = shapely.contains_xy(shapely.from_wkb(wkb), points[:, 0], points[:, 1])
        z = -(n[0] * points[:, 0] + n[1] * points[:, 1] + d) / n[2]
        held = inside & (np.abs(points[:, 2] - z) <= 1.0)
        faces, counts = np.unique(labels[held], return_counts=True)
        for face, count in zip(faces, counts):
            best[face] = max(best.get(face, 0), count)
    faces, sizes = np.unique(labels, return_counts=True)
    found = [f for f, n in zip(faces, sizes) if best.get(f, 0) >= 0.8 * n]
    return len(found) / len(faces), found


def test_pitched_roofs_come_through_on_the_aerial_preset(client, city, tiled):
    """`aerial` runs each tile on the unorganized 3D path: the gabled and hipped faces that
    the 2.5D `rooftop` preset leaves out come out as polygons, across the seams."""
    import polylidar_rs.dask as prd

    aerial = prd.extract_files(city, tile_size=50.0, margin=4.0, preset="aerial", client=client)
    assert all(shapely.from_wkb(w).is_valid for w in aerial.polygons(with_z=False)["wkb"])
    f_aerial, found = roof_faces_found(aerial, city)
    f_rooftop, _ = roof_faces_found(tiled, city)
    assert f_aerial >= 0.9, (f_aerial, f_rooftop)
    assert f_aerial > f_rooftop
    # Faces 1-3 of a building (labels 1 + 4 b + f) only exist on gabled and hipped roofs.
    assert any((face - 1) % 4 > 0 for face in found)


def roof_scene():
    """Ground at 0 with a 30 × 24 m flat roof at 8 m whose middle is the corner (50, 50)
    of four 25 m tiles, and a courtyard on the seam x = 50; jittered grid of 0.4 m."""
    rng = np.random.default_rng(7)
    g = np.arange(0, 100, 0.4)
    x, y = np.meshgrid(g, g)
    x = x.ravel() + rng.uniform(0, 0.12, x.size)
    y = y.ravel() + rng.uniform(0, 0.12, y.size)
    roof = (x >= 35) & (x < 65) & (y >= 38) & (y < 62)
    court = (x >= 46) & (x < 54) & (y >= 44) & (y < 48)
    z = np.where(roof & ~court, 8.0, 0.0) + rng.normal(0, 0.01, x.size)
    return np.column_stack([x, y, z])


def test_roof_across_four_tiles_is_one_polygon(client):
    import polylidar_rs.dask as prd

    params = dict(lmax=1.2, min_triangles=50, min_hole_vertices=6, norm_thresh=0.94)
    result = prd.extract_points(roof_scene(), tile_size=25.0, margin=3.0, client=client, **params)
    p = result.polygons(with_z=False)
    centre = shapely.Point(40.0, 55.0)
    roofs = [i for i, w in enumerate(p["wkb"]) if shapely.from_wkb(w).contains(centre)]
    assert len(roofs) == 1
    i = roofs[0]
    assert sorted(map(tuple, p["tiles"][i])) == [(1, 1), (1, 2), (2, 1), (2, 2)]
    roof = shapely.from_wkb(p["wkb"][i])
    assert len(roof.interiors) == 1, "the courtyard on the seam"
    assert roof.is_valid
    assert abs(p["normal"][i][2] - 1.0) < 1e-3


def flaky_extract(marker, *args):
    """The tile task, killing its worker process the first time any tile runs."""
    import polylidar_rs.dask as prd

    if not os.path.exists(marker):
        with open(marker, "w") as f:
            f.write(str(os.getpid()))
        os._exit(1)
    return prd.extract_tile_pieces(*args)


def test_killed_worker_is_retried_and_nothing_is_lost(client, city, tiled, tmp_path):
    import polylidar_rs.dask as prd

    marker = str(tmp_path / "killed")
    graph, grid = prd.files_graph(city, 50.0, 4.0, "rooftop",
                                  extract=functools.partial(flaky_extract, marker))
    future = client.compute(graph)
    result = prd.TiledResult(future.result(timeout=300))
    assert os.path.exists(marker), "a worker was killed"
    cover = result.cover
    assert len(cover) == len(set(cover)) == grid.cols * grid.rows
    assert len(result) == len(tiled)
    assert relative_difference(shapes(tiled), shapes(result)) < 1e-9


def test_graphs_share_only_identical_tasks(city):
    """Keys follow what a task computes: the same inputs give the same keys (dask may reuse
    the work), a different tile function or preset never reuses another graph's tiles or
    merges (fixed names did, while the first graph's results were held)."""
    import polylidar_rs.dask as prd

    a, _ = prd.files_graph(city, 50.0, 4.0, "rooftop")
    again, _ = prd.files_graph(city, 50.0, 4.0, "rooftop")
    assert a.key == again.key
    other_function, _ = prd.files_graph(city, 50.0, 4.0, "rooftop",
                                        extract=functools.partial(flaky_extract, "unused"))
    other_preset, _ = prd.files_graph(city, 50.0, 4.0, "kitti")
    for b in (other_function, other_preset):
        shared = set(a.dask) & set(b.dask)
        assert shared, "the same files are read by the same tasks"
        assert not any(str(k).startswith(("polylidar-tile", "polylidar-merge")) for k in shared)


def test_merge_refuses_a_tile_twice():
    grid = (0.0, 0.0, 10.0, 1.0, 2, 2)
    points = np.column_stack([np.random.default_rng(1).uniform(0, 10, (500, 2)), np.zeros(500)])
    part = pr.extract_tile(points, grid, 0, 0, lmax=2.0, min_triangles=5)
    with pytest.raises(pr.PolylidarError, match="two of the merged"):
        pr.merge_tiles([part, part])
    with pytest.raises(pr.PolylidarError):
        pr.merge_tiles([b"not a tile set"])
