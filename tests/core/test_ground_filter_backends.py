"""The ground filter's per-point passes compiled with numba (core/lidar/ground_filter_numba.py)
against its numpy back end, and the coordinates read from the records' integers
(:class:`ScaledXYZ`) against float64 arrays: the same low outliers, ground flags, heights and
DTM, bit for bit, for every method, on synthetic terrains with low outliers and multiple
returns and on the real AHN3 crop.

Each method is checked against truth in test_ground_filter.py (the default back end there)."""

from __future__ import annotations

import os
import signal
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.geometry.scaled_xyz import ScaledXYZ
from lidarphoto.core.io.pointcloud import read_cloud
from lidarphoto.core.lidar import ground_filter_numba as compiled
from lidarphoto.core.lidar.ground_filter import ground_filter
from lidarphoto.core.lidar.ground_filter_params import CsfParams, GroundFilterParams, SmrfParams
from lidarphoto.core.simulation.terrain import make_terrain

AHN3 = Path(__file__).resolve().parents[1] / "data" / "ahn3" / "ahn3_delft_crop60.laz"

if not compiled.AVAILABLE:
    if os.environ.get("LIDARPHOTO_REQUIRE_NUMBA") == "1":  # set by scripts/test.sh
        raise RuntimeError("numba is required by the test environment but does not import")
    pytest.skip("numba is not installed", allow_module_level=True)

PARAMS = {
    "smrf": SmrfParams(),
    "smrf_slope_estimated": SmrfParams(slope=0.0),
    "pmf": GroundFilterParams(),
    "pmf_disk_exponential": GroundFilterParams(
        growth="exponential", window_base=2.0, window_shape="disk"
    ),
    "csf": CsfParams(iterations=200),
}


def _assert_same(a, b):
    np.testing.assert_array_equal(a.low_outlier, b.low_outlier)
    np.testing.assert_array_equal(a.ground, b.ground)
    np.testing.assert_array_equal(a.dtm, b.dtm)
    if a.height_above_ground is not None and b.height_above_ground is not None:
        # NaN where the DTM is nodata: compared as bits
        assert a.height_above_ground.tobytes() == b.height_above_ground.tobytes()


def _scaled(x, y, z, scale=(0.01, 0.01, 0.001), offset=(1000.0, -2000.0, 3.0), parts=3):
    """The points quantised as LAS records (int32 + scale and offset), in uneven chunks."""
    ints = [np.round((v - o) / s).astype(np.int32) for v, s, o in zip((x, y, z), scale, offset)]
    cuts = np.linspace(0, len(x), parts + 1).astype(int)
    cuts[1] += 17  # chunks of different sizes
    chunks = tuple(tuple(a[lo:hi] for a in ints) for lo, hi in zip(cuts[:-1], cuts[1:]))
    return ScaledXYZ(chunks=chunks, scales=scale, offsets=offset)


def _terrain(name, seed):
    t = make_terrain(name, size=120.0, density=2.0, seed=seed)
    rng = np.random.default_rng(seed)
    n = len(t.ground)
    number = rng.integers(1, 4, n).astype(np.uint8)
    ret = np.minimum(rng.integers(1, 4, n), number).astype(np.uint8)
    ret[t.ground] = number[t.ground]  # ground points are last returns
    return t.xyz[:, 0], t.xyz[:, 1], t.xyz[:, 2], ret, number


_CASES = [(terrain, method) for method in sorted(PARAMS)
          for terrain in ("bridges", "low_outliers", "dense_buildings", "gaps")
          if method != "csf" or terrain == "low_outliers"]  # CSF is slow: one terrain


@pytest.mark.parametrize(("terrain", "method"), _CASES)
def test_numba_and_numpy_back_ends_agree(terrain, method):
    """Every method, with and without return numbers, from arrays and from records."""
    x, y, z, ret, number = _terrain(terrain, 11)
    z = z.copy()
    z[::501] -= 4.0  # extra low outliers: several passes of the low-outlier test
    params = PARAMS[method]
    for returns in ({}, {"return_number": ret, "number_of_returns": number}):
        a = ground_filter(x, y, z, params, backend="numba", **returns)
        b = ground_filter(x, y, z, params, backend="numpy", **returns)
        _assert_same(a, b)
        assert a.low_outlier.any() and a.ground.any() and not a.ground.all()
    xyz = _scaled(x, y, z)
    from_arrays = ground_filter(xyz.axis(0), xyz.axis(1), xyz.axis(2), params, **returns)
    for backend in ("numba", "numpy"):
        _assert_same(ground_filter(xyz, params=params, backend=backend, **returns), from_arrays)


def test_records_of_the_ahn3_crop_give_the_arrays_result():
    """The real tile: ScaledXYZ views of the records, both back ends, heights on and off."""
    cloud = read_cloud(AHN3)
    x, y, z = (cloud.values(k) for k in "xyz")
    returns = {"return_number": cloud.values("return_number"),
               "number_of_returns": cloud.values("number_of_returns")}  # fmt: skip
    ref = ground_filter(x, y, z, backend="numpy", **returns)
    assert 0.2 < ref.ground.mean() < 0.6
    for backend in ("numba", "numpy"):
        r = ground_filter(cloud.scaled_xyz(), backend=backend, **returns)
        _assert_same(r, ref)
        no_heights = ground_filter(cloud.scaled_xyz(), backend=backend, heights=False, **returns)
        assert no_heights.height_above_ground is None
        _assert_same(no_heights, ref)


def test_scaled_coordinates_are_those_of_the_las_rule():
    """axis() is X * scale + offset in float64; bounds() its exact extremes, also with a
    negative scale (the largest integer gives the smallest coordinate)."""
    rng = np.random.default_rng(3)
    ints = [rng.integers(-(2**31), 2**31 - 1, 1000, dtype=np.int64).astype(np.int32)
            for _ in range(3)]  # fmt: skip
    xyz = ScaledXYZ(chunks=(tuple(a[:400] for a in ints), tuple(a[400:] for a in ints)),
                    scales=(0.001, -0.01, 0.0025), offsets=(5e5, 6e6, -10.0))  # fmt: skip
    lo, hi = xyz.bounds()
    assert [a.tolist() for a in xyz.bounds(compiled.bounds(xyz.chunks))] == [
        lo.tolist(),
        hi.tolist(),
    ]
    for k in range(3):
        expected = ints[k] * xyz.scales[k] + xyz.offsets[k]
        assert xyz.axis(k).tobytes() == expected.tobytes()
        assert (lo[k], hi[k]) == (expected.min(), expected.max())
    assert len(xyz) == 1000


def test_every_point_step_gives_the_same_bits_with_numba(monkeypatch):
    """The compiled passes run per chunk of records; the numpy ones per _POINT_CHUNK within
    them: any split gives the same result."""
    from lidarphoto.core.lidar import ground_filter as gf

    x, y, z, *_ = _terrain("low_outliers", 12)
    ref = ground_filter(x, y, z, backend="numpy")
    for parts in (1, 2, 7):
        xyz = _scaled(x, y, z, scale=(1e-4, 1e-4, 1e-4), offset=(0.0, 0.0, 0.0), parts=parts)
        for step in (4096, 1000):
            monkeypatch.setattr(gf, "_POINT_CHUNK", step)
            a = ground_filter(xyz, backend="numpy")
            b = ground_filter(xyz, backend="numba")
            _assert_same(a, b)
        assert a.ground.sum() == pytest.approx(ref.ground.sum(), rel=0.01)


def test_back_end_argument_is_checked(monkeypatch):
    x, y, z, *_ = _terrain("gaps", 10)
    with pytest.raises(InputError, match="backend must be"):
        ground_filter(x, y, z, backend="fortran")
    monkeypatch.setattr(compiled, "AVAILABLE", False)
    with pytest.raises(InputError, match="numba is not installed"):
        ground_filter(x, y, z, backend="numba")
    auto = ground_filter(x, y, z, replace(SmrfParams(), low_outlier_height=0.5))
    assert auto.ground.any()  # "auto" falls back to numpy
    with pytest.raises(InputError, match="y and z must be None"):
        ground_filter(_scaled(x, y, z), y, z)


@pytest.mark.skipif(not hasattr(signal, "pthread_sigmask"), reason="POSIX threads' signal masks")
def test_pool_threads_block_interrupts_but_not_faults():
    """The grid pool's threads leave SIGINT/SIGTERM to the main thread (else Ctrl+C waits for
    a blocking call) and keep the synchronous signals of a crash unblocked (the fault handler
    and the default action still see them)."""
    if not compiled.AVAILABLE:
        pytest.skip("numba not installed: no pool")
    mask = compiled._pool().submit(signal.pthread_sigmask, signal.SIG_BLOCK, []).result()
    assert {signal.SIGINT, signal.SIGTERM} <= mask
    assert not {signal.SIGSEGV, signal.SIGBUS, signal.SIGFPE, signal.SIGABRT} & mask
