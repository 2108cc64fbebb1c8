"""The compiled grey-level openings (core/lidar/ground_filter_numba.py: erosion and dilation by a
flat disk or square as a union of centred rectangles) against OpenCV's ``erode``, ``dilate`` and
``morphologyEx(MORPH_OPEN)`` with the same kernels: the same bits on random float32 grids with
+inf and -inf cells, odd shapes (one row, one column, grids smaller than the window), every
radius 1-25; and the ground filter's openings through both paths give the same object cells."""

from __future__ import annotations

import os

import cv2
import numpy as np
import pytest
from lidarphoto.core.lidar import ground_filter_morphology as gm
from lidarphoto.core.lidar import ground_filter_numba as compiled
from lidarphoto.core.lidar.ground_filter_params import SmrfParams

if not compiled.AVAILABLE:
    if os.environ.get("LIDARPHOTO_REQUIRE_NUMBA") == "1":  # set by scripts/test.sh
        raise RuntimeError("numba is required by the test environment but does not import")
    pytest.skip("numba is not installed", allow_module_level=True)

SHAPES = [(1, 1), (1, 9), (9, 1), (5, 5), (37, 41), (100, 3), (3, 100), (61, 203)]


def _grid(rng, shape, holes=True):
    a = rng.normal(scale=10.0, size=shape).astype(np.float32)
    if holes:
        a[rng.random(shape) < 0.08] = np.inf
        a[rng.random(shape) < 0.04] = -np.inf
    return a


@pytest.mark.parametrize("shape", SHAPES)
def test_same_bits_as_opencv_every_radius(shape):
    rng = np.random.default_rng(sum(shape))
    for r in range(1, 26):
        a = _grid(rng, shape)
        for form in (cv2.MORPH_ELLIPSE, cv2.MORPH_RECT):
            k = cv2.getStructuringElement(form, (2 * r + 1, 2 * r + 1))
            assert compiled.morph(a, k, dilate=False).tobytes() == cv2.erode(a, k).tobytes()
            assert compiled.morph(a, k, dilate=True).tobytes() == cv2.dilate(a, k).tobytes()
            opened = compiled.opening(a, k)
            assert opened.tobytes() == cv2.morphologyEx(a, cv2.MORPH_OPEN, k).tobytes(), (r, form)


def test_rectangles_rebuild_the_kernel_and_refuse_other_shapes():
    for r in range(1, 26):
        k = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * r + 1, 2 * r + 1))
        ws, ds = compiled.rectangles(k)
        assert np.all(np.diff(ws) > 0) and np.all(np.diff(ds) < 0)
        dy, dx = np.mgrid[-r : r + 1, -r : r + 1]
        union = np.zeros(k.shape, bool)
        for w, d in zip(ws, ds):
            union |= (np.abs(dx) <= w) & (np.abs(dy) <= d)
        np.testing.assert_array_equal(union, k != 0)
    cross_off_centre = np.zeros((5, 5), np.uint8)
    cross_off_centre[2, :] = 1
    cross_off_centre[0, 0] = 1  # not a centred run
    assert compiled.rectangles(cross_off_centre) is None
    ring = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (7, 7))
    ring[3, 3] = 0  # hole at the anchor
    assert compiled.rectangles(ring) is None
    assert compiled.rectangles(np.ones((4, 4), np.uint8)) is None  # even side
    assert compiled.opening(np.zeros((5, 5), np.float32), ring) is None


def test_progressive_opening_same_object_cells_both_paths():
    # a terrain with buildings, as the filter's minimum grid (filled, no NaN)
    rng = np.random.default_rng(3)
    yy, xx = np.mgrid[0:150, 0:170].astype(np.float32)
    surface = 0.05 * xx + 0.02 * yy + rng.normal(scale=0.1, size=xx.shape).astype(np.float32)
    for _ in range(25):
        r0, c0 = rng.integers(0, 140), rng.integers(0, 160)
        surface[r0 : r0 + rng.integers(3, 30), c0 : c0 + rng.integers(3, 30)] += 8.0
    surface = surface.astype(np.float32)
    windows, thresholds = gm.smrf_windows(SmrfParams())
    for shape in ("disk", "square"):
        a = gm._progressive_opening(surface, windows, thresholds, shape, None, compiled=False)
        b = gm._progressive_opening(surface, windows, thresholds, shape, None, compiled=True)
        assert 0 < a.sum() < a.size
        np.testing.assert_array_equal(a, b)
    # NaN cells: the compiled path hands the grid to OpenCV (same result as before)
    holed = surface.copy()
    holed[5:9, 5:9] = np.nan
    a = gm._progressive_opening(holed, windows, thresholds, "disk", None, compiled=False)
    b = gm._progressive_opening(holed, windows, thresholds, "disk", None, compiled=True)
    np.testing.assert_array_equal(a, b)
