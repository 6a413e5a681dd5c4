"""Shared helpers: fixture paths (skip with a note, or fail under CI=true), the CLI binary,
and small synthetic inputs."""

import os
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[3]
FIXTURES = ROOT.parent / "shared" / "fixtures"


def in_ci() -> bool:
    return os.environ.get("CI", "") not in ("", "false", "0")


def record_skip(request, reason: str) -> None:
    """Skip the test, noting why in the workspace's skip log (POLYLIDAR_SKIP_LOG), or fail
    under CI=true."""
    if in_ci():
        pytest.fail(f"{reason}; CI=true, so this is a failure")
    log = os.environ.get("POLYLIDAR_SKIP_LOG")
    if log:
        with open(log, "a", encoding="utf-8") as f:
            f.write(f"python::{request.node.nodeid}\t{reason}\n")
    pytest.skip(reason)


@pytest.fixture
def fixture(request):
    """fixture("synpeb/pc_01.pcd") -> Path, skipping (failing under CI) when it is missing."""

    def find(relative: str) -> Path:
        path = FIXTURES / relative
        if not path.is_file():
            record_skip(
                request,
                f"fixture {relative} not found at {path} (expected ../shared/fixtures beside the workspace)",
            )
        return path

    return find


@pytest.fixture
def cli(request):
    """The path of the `polylidar` command (POLYLIDAR_CLI, set by .ci/test.sh)."""
    path = os.environ.get("POLYLIDAR_CLI")
    if not path or not Path(path).is_file():
        record_skip(request, "the polylidar command was not built (POLYLIDAR_CLI not set)")
    return path


def grid_with_hole(n: int = 40, hole=(15, 25)) -> np.ndarray:
    """Points of an n × n unit grid with a square hole, (N, 2) float64."""
    lo, hi = hole
    return np.array(
        [(x, y) for x in range(n) for y in range(n) if not (lo <= x < hi and lo <= y < hi)],
        dtype=np.float64,
    )


def box_corner(rows: int = 60, cols: int = 80) -> np.ndarray:
    """An organized (rows, cols, 3) cloud of two planes meeting at a fold: a floor z = 0
    for x < 0 and a 45° ramp z = x beyond, sampled every 2 cm."""
    r, c = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
    x = (c - cols / 2) * 0.02
    y = r * 0.02
    z = np.where(x < 0, 0.0, x)
    return np.ascontiguousarray(np.stack([x, y, z], axis=-1), dtype=np.float64)
