"""The morphological ground filters (:mod:`.ground_filter`): the windows and thresholds of PMF
(Zhang et al. 2003) and SMRF (Pingel et al. 2013), the progressive opening they share (OpenCV,
or the compiled kernel for the larger windows), and SMRF's slope estimated from the cloud.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from typing import cast

import numpy as np
from numpy.typing import NDArray

from ..errors import stop_if_asked
from ..geometry.grid import fill_holes, fill_nearest
from .ground_filter_params import SMRF_PUBLISHED, GroundFilterParams, SmrfParams

#: SMRF's slope estimated from the cloud (SLOPE 0): this percentile of the slope of a first
#: pass's ground surface, clipped to this range (rise/run).
SLOPE_PERCENTILE = 90.0
SLOPE_RANGE = (0.1, 0.7)


def pmf_windows(params: GroundFilterParams) -> tuple[list[int], list[float]]:
    """Window sizes (odd cell counts) and their elevation thresholds (Zhang 2003, eq. 4-5).

    ``slope`` must already be in the cloud's z-per-xy units here.

    Examples
    --------
    >>> pmf_windows(GroundFilterParams(cell_size=1, max_window=9, slope=0.5, growth="exponential",
    ...                                window_base=2, initial_distance=0.2, max_distance=3))
    ([3, 5, 9], [0.2, 1.2, 2.2])
    """
    c = params.cell_size
    w_max = math.floor(params.max_window / c)
    w_max = max(w_max if w_max % 2 else w_max - 1, 3)
    windows: list[int] = []
    k = 1 if params.growth == "linear" else 0
    while True:
        if params.growth == "linear":
            w = round(2 * k * params.window_base + 1)
        else:
            w = round(2 * params.window_base**k + 1)
        w += 1 - w % 2  # odd, so the window is centred on its cell
        if w > w_max or (windows and w <= windows[-1]):
            break
        windows.append(w)
        k += 1
    if not windows:
        windows = [3]
    thresholds = [params.initial_distance]
    for prev, w in zip(windows[:-1], windows[1:]):
        dh = params.slope * (w - prev) * c + params.initial_distance
        thresholds.append(min(dh, params.max_distance))
    return windows, [round(t, 12) for t in thresholds]


def smrf_windows(params: SmrfParams) -> tuple[list[int], list[float]]:
    """Disk windows (diameters ``2 r + 1`` in cells, r = 1 .. max_window / c) and their
    thresholds ``slope r c`` (Pingel et al. 2013). ``slope`` in z-per-xy units here.

    Examples
    --------
    >>> smrf_windows(SmrfParams(cell_size=2.0, slope=0.15, max_window=7.0))
    ([3, 5, 7, 9], [0.3, 0.6, 0.9, 1.2])
    """
    radii = range(1, max(math.ceil(params.max_window / params.cell_size - 1e-9), 1) + 1)
    windows = [2 * r + 1 for r in radii]
    thresholds = [round(params.slope * r * params.cell_size, 12) for r in radii]
    return windows, thresholds


def _kernel(w: int, shape: str) -> NDArray[np.uint8]:
    import cv2

    if shape == "disk":
        disk = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (w, w))
        return cast(NDArray[np.uint8], disk)  # structuring elements are uint8
    return np.ones((w, w), np.uint8)


#: Openings by windows of at least this many cells across go to the compiled kernel when
#: numba is there (its cost grows with the window's radius, OpenCV's with its area: OpenCV is
#: cheaper below).
_COMPILED_OPENING_MIN = 7


def _opening(
    surface: NDArray[np.float32], w: int, shape: str, compiled: bool = False
) -> NDArray[np.float32]:
    """Grey-level opening of ``surface`` by the window (``w`` cells across), OpenCV's
    ``morphologyEx``; or, when ``compiled`` (and ``surface`` has no NaN: the caller checks),
    :func:`core.lidar.ground_filter_numba.opening`, the same values at a fraction of the cost
    for the larger windows."""
    import cv2

    kernel = _kernel(w, shape)
    if compiled and w >= _COMPILED_OPENING_MIN:
        from .ground_filter_numba import opening

        opened = opening(surface, kernel)
        if opened is not None:
            return opened
    # cv2's default border for erode/dilate is neutral (ignored), as the filter needs.
    return cast(NDArray[np.float32], cv2.morphologyEx(surface, cv2.MORPH_OPEN, kernel))


def _estimate_slope(
    zmin: NDArray[np.float32],
    valid: NDArray[np.bool_],
    p: SmrfParams,
    xy_per_z: float,
    should_stop: Callable[[], bool] | None,
    compiled: bool = False,
) -> float:
    """SMRF's slope from the cloud itself (rise/run): a first SMRF pass with the published
    slope on cells twice as large (the minimum of each 2 x 2 block: a sixteenth of the work),
    its ground surface, and the 90th percentile of that surface's slope over the cells it
    reaches, clipped to ``SLOPE_RANGE``."""
    rows, cols = zmin.shape
    pad = np.pad(zmin, ((0, rows % 2), (0, cols % 2)), constant_values=np.inf)
    coarse = pad.reshape(pad.shape[0] // 2, 2, pad.shape[1] // 2, 2).min(axis=(1, 3))
    ok = np.isfinite(coarse)
    if ok.sum() < 9:
        return SLOPE_RANGE[0]
    first = replace(p, cell_size=2 * p.cell_size, slope=SMRF_PUBLISHED.slope * xy_per_z)
    windows, thresholds = smrf_windows(first)
    objects = _progressive_opening(
        fill_nearest(coarse, ok), windows, thresholds, "disk", should_stop, compiled
    )
    ground = ok & ~objects
    if not ground.any():
        return SLOPE_RANGE[0]
    surface = fill_holes(coarse, ground)
    reach = _within(ground, windows[-1] / 2.0 + 1)
    gr, gc = np.gradient(surface.astype(np.float64), first.cell_size)
    slope = np.hypot(gr, gc)[reach] / xy_per_z
    return float(np.clip(np.percentile(slope, SLOPE_PERCENTILE), *SLOPE_RANGE))


def _within(cells: NDArray[np.bool_], radius: float) -> NDArray[np.bool_]:
    """Cells whose centre is within ``radius`` cells (Euclidean) of a True cell.

    OpenCV's exact distance transform (Felzenszwalb's, float32) is a third to a sixth of
    scipy's CPU time; the radii here are half-integers (a window of ``w = 2 r + 1`` cells
    gives ``r + 1.5``), which no distance ``sqrt(integer)`` equals, and up to 1000 cells the
    nearest such distance is farther from the radius than float32's rounding, so both give
    the same cells; other radii go to scipy (float64).

    Examples
    --------
    >>> cells = np.zeros((5, 7), bool)
    >>> cells[2, 3] = True
    >>> int(_within(cells, 1.5).sum()), int(_within(cells, 2.5).sum())
    (9, 21)
    """
    import cv2

    if radius > 1000 or (2.0 * radius) % 2.0 != 1.0:
        from scipy import ndimage

        return ndimage.distance_transform_edt(~cells) <= radius
    far = np.logical_not(cells).view(np.uint8)
    dist = cv2.distanceTransform(far, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
    return dist <= radius


def _progressive_opening(
    surface: NDArray[np.float32],
    windows: list[int],
    thresholds: list[float],
    shape: str,
    should_stop: Callable[[], bool] | None,
    compiled: bool = False,
) -> NDArray[np.bool_]:
    """Object cells of the progressive opening (PMF and SMRF share it); ``compiled``: the
    openings by the compiled kernel where it is cheaper (same values)."""
    objects = np.zeros(surface.shape, dtype=bool)
    # the compiled openings give OpenCV's values on grids without NaN (openings add none)
    compiled = compiled and not np.isnan(surface).any()
    for w, dh in zip(windows, thresholds):
        stop_if_asked(should_stop, "filtering the ground")
        opened = _opening(surface, w, shape, compiled)
        objects |= (surface - opened) > dh
        surface = opened
    return objects
