"""The compiled ray traversal (core/geometry/raycast_numba.py, numba) against the vectorised numpy
one: the same hits, statuses, faces, weights, gradients and incidence angles ray by ray, on the
real AHN3 DSM, on a hilly synthetic DSM, through nodata holes and on degenerate rays.

The numpy traversal itself is checked against brute force and truth in test_monoplot.py."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.geometry import raycast_numba as dda_compiled
from lidarphoto.core.geometry.grid import Grid
from lidarphoto.core.geometry.raycast import DsmTracer, intersect_dsm
from lidarphoto.core.geometry.surface import Dsm
from lidarphoto.core.io.dsm import dsm_from_las

AHN3 = Path(__file__).resolve().parents[1] / "data" / "ahn3" / "ahn3_delft_crop60.laz"

if not dda_compiled.AVAILABLE:
    if os.environ.get("LIDARPHOTO_REQUIRE_NUMBA") == "1":  # set by scripts/test.sh
        raise RuntimeError("numba is required by the test environment but does not import")
    pytest.skip("numba is not installed", allow_module_level=True)


def _compare(tracer: DsmTracer, o: np.ndarray, d: np.ndarray, **kw) -> np.ndarray:
    """Assert both back ends agree; returns the status array."""
    a = intersect_dsm(tracer, o, d, backend="numpy", **kw)
    b = intersect_dsm(tracer, o, d, backend="numba", **kw)
    np.testing.assert_array_equal(a.status, b.status)
    hit = np.isin(a.status, (0, 1))
    np.testing.assert_array_equal(a.quad[hit], b.quad[hit])
    np.testing.assert_array_equal(a.triangle[hit], b.triangle[hit])
    for name in ("points", "t", "weights", "gradient", "incidence_deg"):
        x, y = getattr(a, name), getattr(b, name)
        np.testing.assert_array_equal(np.isnan(x), np.isnan(y), err_msg=name)
        np.testing.assert_allclose(x[hit], y[hit], rtol=1e-12, atol=1e-9, err_msg=name)
    return a.status


@pytest.fixture(scope="module")
def ahn3() -> DsmTracer:
    return DsmTracer.build(dsm_from_las(AHN3, 0.5, crs="EPSG:28992"))


def _camera_rays(dsm: Dsm, n: int, height: float, seed: int, spread: float = 1.3):
    rng = np.random.default_rng(seed)
    g = dsm.grid
    cx, cy = g.x0 + g.cols * g.cell / 2, g.y_top - g.rows * g.cell / 2
    half = spread * 0.5 * g.cols * g.cell  # > 1: some rays miss the tile
    centre = np.array([cx + 7.0, cy - 4.0, height])
    target = np.column_stack(
        [cx + rng.uniform(-half, half, n), cy + rng.uniform(-half, half, n), np.zeros(n)]
    )
    d = target - centre
    return np.repeat(centre[None], n, axis=0), d / np.linalg.norm(d, axis=1, keepdims=True)


@pytest.mark.parametrize("accelerate", [True, False])
@pytest.mark.parametrize("height", [25.0, 150.0])  # oblique (long paths) and near nadir
def test_backends_agree_on_the_real_tile(ahn3, accelerate, height):
    o, d = _camera_rays(ahn3.dsm, 5000, height, seed=int(height))
    status = _compare(ahn3, o, d, accelerate=accelerate, chunk_size=1777)
    assert (status == 0).mean() > 0.5 and (status == 2).any()  # hits and misses both tested
    if height < 50:
        assert (status == 1).any()  # grazing rays at 25 m over 16 m roofs


def test_backends_agree_on_hills_and_through_holes():
    rng = np.random.default_rng(3)
    rows, cols = 300, 260
    r, c = np.mgrid[0:rows, 0:cols]
    z = 40 * np.sin(r / 37.0) * np.cos(c / 23.0) + rng.normal(0, 0.3, (rows, cols))
    z[rng.random((rows, cols)) < 0.002] = np.nan  # isolated nodata cells
    z[120:140, 60:90] = np.nan  # and a hole
    dsm = Dsm(z.astype(np.float32), Grid(1000.0, 5000.0, 1.0, rows, cols))
    tracer = DsmTracer.build(dsm)
    o = np.column_stack([rng.uniform(900, 1360, 4000), rng.uniform(4600, 5100, 4000),
                         rng.uniform(-20, 400, 4000)])  # fmt: skip
    d = rng.normal(size=(4000, 3))
    d[:, 2] = -np.abs(d[:, 2]) * rng.uniform(0.05, 3, 4000)  # down, some nearly horizontal
    status = _compare(tracer, o, d)
    assert {0, 2, 3} <= set(np.unique(status).tolist())
    status = _compare(tracer, o, d, accelerate=False)
    assert (status == 3).sum() > 50


def test_backends_agree_on_degenerate_rays(ahn3):
    dsm = ahn3.dsm
    xc, yc = dsm.centre_origin
    cell = dsm.cell
    o = np.array([
        [xc + 30 * cell, yc - 30 * cell, 100.0],  # vertical
        [xc + 30 * cell, yc - 30 * cell, 100.0],  # straight up
        [xc + 10 * cell, yc - 12 * cell, 100.0],  # along a grid line (v integer, dv = 0)
        [xc + 10.5 * cell, yc - 12 * cell, 8.0],  # horizontal, inside the height range
        [xc + 10.5 * cell, yc - 12 * cell, 60.0],  # horizontal, above everything
        [xc - 50 * cell, yc + 40 * cell, 30.0],  # from outside the footprint, entering
        [xc + 20 * cell, yc - 20 * cell, 5.0],  # camera inside the height range
        [np.nan, yc, 100.0],  # not finite
        [xc, yc, 100.0],  # zero direction
        [xc + 60 * cell, yc - 60 * cell, 100.0],  # through the exact cell centre (vertex)
    ])  # fmt: skip
    d = np.array([
        [0, 0, -1.0], [0, 0, 1.0], [1.0, 0, -0.2], [0.6, -0.8, 0.0], [0.6, -0.8, 0.0],
        [0.7, -0.6, -0.3], [0.3, 0.2, -0.5], [0, 0, -1.0], [0, 0, 0.0], [0, 0, -1.0],
    ])  # fmt: skip
    status = _compare(ahn3, o, d)
    assert status[0] == 0 and status[1] == 2 and status[4] == 2
    assert status[7] == 2 and status[8] == 2 and status[9] == 0
    assert set(status.tolist()) <= {0, 1, 2}


def test_backend_choice(ahn3, monkeypatch):
    o, d = _camera_rays(ahn3.dsm, 50, 100.0, seed=1)
    with pytest.raises(ValueError, match="backend"):
        intersect_dsm(ahn3, o, d, backend="gpu")
    monkeypatch.setattr(dda_compiled, "AVAILABLE", False)
    with pytest.raises(InputError, match="numba is not installed"):
        intersect_dsm(ahn3, o, d, backend="numba")
    fallback = intersect_dsm(ahn3, o, d)  # auto: numpy, the same answer
    monkeypatch.setattr(dda_compiled, "AVAILABLE", True)
    np.testing.assert_allclose(intersect_dsm(ahn3, o, d).points, fallback.points, atol=1e-9)
