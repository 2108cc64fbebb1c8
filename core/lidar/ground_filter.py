"""Ground filters on a minimum grid: PMF (Zhang et al. 2003), SMRF (Pingel et al. 2013) and
the cloth simulation filter CSF (Zhang et al. 2016).

Shared steps (all grid work is vectorised with OpenCV/scipy.ndimage; the point work is vectorised
with numpy, or compiled with numba when installed (:mod:`core.lidar.ground_filter_numba`, the same
bits), as are then the openings by larger windows (the same values as OpenCV's, on all cores);
the coordinates come as float64 arrays or as the LAS records' integers, :class:`ScaledXYZ`):

1. **Candidates.** Where the file has return numbers, only last (and single) returns can be
   ground: earlier returns of a multi-return pulse were stopped by something above the ground.
2. **Minimum grid.** The lowest candidate per cell of ``cell_size``; empty cells take the value
   of the nearest filled cell (Euclidean distance transform).
3. **Low outliers.** A point lower than every other cell's minimum within
   ``low_outlier_radius`` by more than ``low_outlier_height`` is a low outlier (multipath or
   range errors: nothing real lies below the ground around it); only cells holding points
   count, so an isolated point with no neighbour in the radius is never one. Low
   outliers are removed before the filter (a single one punches a pit that every opening
   widens and the cloth hangs on), get class 7 (low point, noise) and are never ground. The
   minimum grid is rebuilt without them.

Then one of the methods finds the ground cells (PMF, SMRF) or the ground surface (CSF):

- **PMF** (Zhang et al. 2003): openings (erosion then dilation, square or disk windows counted
  in cells) of the surface with windows ``w_k`` growing linearly (``w_k = 2 k b + 1``) or
  exponentially (``w_k = 2 b^k + 1``) up to ``max_window``. At each step a cell is an object
  cell when the surface minus its opening exceeds ``dh_k``: ``dh_1 = initial_distance``, then
  ``dh_k = slope (w_k - w_{k-1}) c + initial_distance`` capped at ``max_distance``, where ``c``
  is the cell size (applied once: PDAL's filters.pmf applies it twice and counts its windows in
  map units, see PEERS.md) and ``slope`` is converted to the file's z-per-xy units.
- **SMRF** (Pingel et al. 2013): openings with disks of radius ``r = 1, 2, ...`` cells up to
  ``max_window / c`` (the window is a radius, as in the paper and PDAL's filters.smrf); a cell is
  an object cell when the surface minus its opening exceeds ``slope * r * c``, a threshold that
  grows with the window, so steep ground survives the wide windows that remove buildings.
- **CSF** (Zhang et al. 2016): the cloud is turned upside down and a cloth of particles
  ``resolution`` apart falls onto it (Verlet steps with damping 0.01 and gravity 0.2 m per unit
  time squared, ``time_step`` units per step); each particle stops on the height of the point
  nearest to it horizontally (empty cells take the nearest cell's); neighbouring particles are
  pulled together ``rigidness`` times per step (the paper's internal forces, applied to the
  four neighbours in a red-black order so every spring acts once). The run ends after
  ``iterations`` steps or when no particle moved more than 1 % of ``threshold``. Optional
  slope smoothing (``slope_smooth``) pins movable particles next to pinned ones when they lie
  within 0.3 m of their point (the paper's post-processing for steep slopes).

**DTM and points** (PMF, SMRF): the minimum grid with object cells removed, holes filled by a
pull-push pyramid (weighted 2x2 averages down, bilinear up), which interpolates smoothly across
buildings; cells farther than the largest window from any ground cell are nodata. Each
candidate's height above the DTM (bilinear between cell centres) is compared with a
slope-dependent threshold (Pingel et al. 2013): ``|h| <= threshold + scalar * local DTM slope``
is ground. CSF: a point is ground when it lies within ``threshold`` of the cloth (bilinear
between particles); the cloth is the DTM.

Distance parameters are in the cloud's horizontal unit (cell sizes, windows, radii, the cloth
resolution) or its vertical unit (elevation thresholds, ``slope_scalar``/``scalar``,
``low_outlier_height``); the ``groundfilter`` job converts lengths given in metres
(:func:`core.jobs.common.lengths_in_cloud_units`). ``slope`` is always a ratio of real lengths
(rise over run).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError, stop_if_asked, use_compiled
from ..geometry.grid import Grid, fill_holes, fill_nearest
from ..geometry.scaled_xyz import ScaledXYZ
from .ground_filter_csf import _csf_cloth
from .ground_filter_morphology import (
    _estimate_slope,
    _progressive_opening,
    _within,
    pmf_windows,
    smrf_windows,
)
from .ground_filter_params import CsfParams, FilterParams, GroundFilterParams, SmrfParams

LOG = logging.getLogger(__name__)

GROUND_CLASS = 2
UNCLASSIFIED_CLASS = 1
LOW_NOISE_CLASS = 7
NODATA = -9999.0
HEIGHT_FIELD = "height_above_ground"
#: Points per step of the per-point loops: the temporaries of a step (about 30 B per point)
#: stay in the cache and in memory malloc reuses, where 2 M-point steps cost page faults.
_POINT_CHUNK = 262_144
#: Inner radius of the ring of the low-outlier cluster test, as a share of its radius.
LOW_RING = 0.6
#: Passes of the low-outlier tests (a deeper outlier nearby hides a shallower one until it is
#: removed).
LOW_PASSES = 10


class _Points:
    """The filter's view of its points, from float64 arrays or from a :class:`ScaledXYZ`."""

    def __init__(self, x: Any, y: Any, z: Any) -> None:
        if isinstance(x, ScaledXYZ):
            if y is not None or z is not None:
                raise InputError("with ScaledXYZ coordinates, y and z must be None")
            self.scaled: ScaledXYZ | None = x
            self.n = len(x)
        else:
            if y is None or z is None:
                raise InputError("x, y and z must be non-empty arrays of equal length")
            self.scaled = None
            self.xyz = (np.asarray(x), np.asarray(y), np.asarray(z))
            self.n = len(self.xyz[2])
            if len(self.xyz[0]) != self.n or len(self.xyz[1]) != self.n:
                raise InputError("x, y and z must be non-empty arrays of equal length")

    def bounds(self, compiled: bool) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        if self.scaled is not None:
            if compiled:  # one pass over the records instead of six strided reductions
                from .ground_filter_numba import bounds

                return self.scaled.bounds(bounds(self.scaled.chunks))
            return self.scaled.bounds()
        return (
            np.array([float(a.min()) for a in self.xyz]),
            np.array([float(a.max()) for a in self.xyz]),
        )

    def axis(self, k: int) -> NDArray[np.float64]:
        return self.scaled.axis(k) if self.scaled is not None else self.xyz[k]

    def parts(self) -> list[tuple[int, tuple[Any, ...]]]:
        """(first index, (X, Y, Z, scales, offsets)) per chunk (arrays: one part, scale 1)."""
        if self.scaled is None:
            return [(0, (*self.xyz, (1.0, 1.0, 1.0), (0.0, 0.0, 0.0)))]
        out, done = [], 0
        for chunk in self.scaled.chunks:
            out.append((done, (*chunk, self.scaled.scales, self.scaled.offsets)))
            done += len(chunk[0])
        return out

    def blocks(self, should_stop: Callable[[], bool] | None, z: bool = True) -> Any:
        """(slice, x, y, z) blocks of at most ``_POINT_CHUNK`` points, float64 (views of the
        arrays, or computed from the integers as :meth:`ScaledXYZ.axis` does); z None when
        not asked for."""
        for lo, (X, Y, Z, scales, offsets) in self.parts():
            for start in range(0, len(X), _POINT_CHUNK):
                stop_if_asked(should_stop, "filtering the ground")
                s = slice(start, start + _POINT_CHUNK)
                out = []
                for k, a in enumerate((X, Y, Z) if z else (X, Y)):
                    if self.scaled is None:
                        out.append(a[s])
                    else:
                        v = np.multiply(a[s], float(scales[k]))
                        v += float(offsets[k])
                        out.append(v)
                yield (
                    slice(lo + start, lo + start + len(out[0])),
                    out[0],
                    out[1],
                    out[2] if z else None,
                )


@dataclass(frozen=True)
class GroundFilterResult:
    """Result of :func:`ground_filter`.

    Attributes
    ----------
    ground : NDArray[np.bool_]
        (N,) True for ground points.
    low_outlier : NDArray[np.bool_]
        (N,) True for low outliers (never ground).
    height_above_ground : NDArray[np.float32] or None
        (N,) z minus the DTM at the point (vertical unit; NaN where the DTM is nodata); None
        when not asked for (``heights=False``).
    dtm : NDArray[np.float32]
        (rows, cols) ground surface at the cell centres, ``nodata`` where unknown.
    geotransform : tuple of 6 float
        GDAL order, top-left corner of the top-left cell.
    nodata : float
    windows : tuple[int, ...]
        Opening windows used, in cells (empty for CSF).
    thresholds : tuple[float, ...]
        Elevation-difference threshold of each window (vertical unit).
    params : GroundFilterParams, SmrfParams or CsfParams
        The parameters actually used, in the cloud's units.
    unit : str
        Name of the unit the parameters were interpreted in.
    """

    ground: NDArray[np.bool_]
    low_outlier: NDArray[np.bool_]
    height_above_ground: NDArray[np.float32] | None
    dtm: NDArray[np.float32]
    geotransform: tuple[float, float, float, float, float, float]
    nodata: float
    windows: tuple[int, ...]
    thresholds: tuple[float, ...]
    params: FilterParams
    unit: str = "unknown"
    stats: dict[str, Any] = field(default_factory=dict)

    def classify(self, classification: NDArray[Any], reset_non_ground: bool = False) -> None:
        """Write the filter's classes into the cloud's LAS ``classification`` (N,), in place:
        ground 2, low outliers 7; the other points keep their class (``reset_non_ground``:
        all become 1, unclassified), except that a point the file had as ground which the
        filter rejects becomes 1.

        >>> r = GroundFilterResult(np.array([True, False, False]), np.array([False, False, True]),
        ...     None, np.zeros((1, 1), np.float32), (0.0, 1.0, 0.0, 0.0, 0.0, -1.0), NODATA, (), (),
        ...     None)
        >>> cls = np.array([6, 2, 6], np.uint8); r.classify(cls); cls.tolist()
        [2, 1, 7]
        """
        cls = classification
        if reset_non_ground:
            cls[:] = UNCLASSIFIED_CLASS
        else:  # a point the file had as ground but the filter rejects becomes unclassified
            cls[cls == GROUND_CLASS] = UNCLASSIFIED_CLASS  # (those it keeps get 2 again below)
        cls[self.ground] = GROUND_CLASS
        cls[self.low_outlier] = LOW_NOISE_CLASS


def _min_grid(grid: Grid, flat: NDArray[np.int32], z: NDArray[Any]) -> NDArray[np.float32]:
    out = np.full(grid.rows * grid.cols, np.inf, dtype=np.float32)
    np.minimum.at(out, flat, z.astype(np.float32, copy=False))
    return out.reshape(grid.rows, grid.cols)


def _neighbour_min(surface: NDArray[np.float32], radius: int) -> NDArray[np.float32]:
    """Minimum of the other cells within ``radius`` cells (the cell itself excluded)."""
    import cv2

    kernel = np.ones((2 * radius + 1, 2 * radius + 1), np.uint8)
    kernel[radius, radius] = 0
    out = cv2.erode(surface, kernel, borderType=cv2.BORDER_CONSTANT, borderValue=(np.inf,))
    return cast(NDArray[np.float32], out)  # OpenCV keeps the float32 depth


def _low_references(
    zmin: NDArray[np.float32], radius: int, depth: np.float32
) -> tuple[NDArray[np.float32], NDArray[np.float32] | None]:
    """The grid side of the low-outlier test: per cell (flat), the height a point must be
    below to be low (``reference``), and ``around`` (or None) for the cluster test.

    A point is low when lower by more than ``depth`` than every other cell within ``radius``
    cells (a single outlier), or than every cell of the ring from ``LOW_RING`` x ``radius`` to
    ``radius`` when the low cells inside the ring form a blob smaller than the ring's hole (a
    cluster of multipath points, whose cells hide each other from the first test). Only
    cells holding points count (empty ones are +inf), so an outlier's value never stands in
    for a neighbour and a point without real neighbours is never low; a depression wider
    than the ring's hole is never low (its own cells are in the ring), nor is ground between
    objects (the ring holds ground as low as it)."""
    import cv2

    reference = _neighbour_min(zmin, radius).ravel() - depth
    # +inf where a cell has no real neighbour: no point is below it
    reference[~np.isfinite(reference)] = -np.inf
    inner = math.ceil(LOW_RING * radius)
    around = None
    if radius - inner >= 1:
        ellipse = cv2.MORPH_ELLIPSE  # structuring elements are uint8
        ring = cast(NDArray[np.uint8], cv2.getStructuringElement(ellipse, (2 * radius + 1,) * 2))
        hole = cast(NDArray[np.uint8], cv2.getStructuringElement(ellipse, (2 * inner + 1,) * 2))
        ring[radius - inner : radius + inner + 1, radius - inner : radius + inner + 1] &= 1 - hole
        eroded = cv2.erode(zmin, ring, borderType=cv2.BORDER_CONSTANT, borderValue=(np.inf,))
        ring_min = cast(NDArray[np.float32], eroded)
        ring_min -= depth
        pit = (zmin < ring_min) & np.isfinite(ring_min)
        if pit.any():
            blobs = pit.astype(np.uint8)
            _, labels, stats, _ = cv2.connectedComponentsWithStats(blobs, connectivity=8)
            small = stats[:, cv2.CC_STAT_AREA] <= int(hole.sum())
            small[0] = False
            blob = small[labels].ravel()
            # only blob cells count: elsewhere no point is below the ring
            around = np.where(blob, ring_min.ravel(), -np.inf).astype(np.float32)
    return reference, around


def _low_points(
    reference: NDArray[np.float32],
    around: NDArray[np.float32] | None,
    zmin: NDArray[np.float32],
    zc: NDArray[np.float32],
    flat: NDArray[np.int32],
) -> NDArray[np.intp]:
    """Indices of the points below their cell's references (:func:`_low_references`).

    Only a cell whose lowest point (``zmin``, the minimum of ``zc``) is below a reference can
    hold such a point: the points of those cells are found with one boolean look-up per
    point and only they are compared (low outliers are rare), instead of full-size gathers
    and comparisons of every point."""
    lowest = zmin.ravel()
    suspect = lowest < reference
    if around is not None:
        suspect |= lowest < around
    if not suspect.any():
        return np.zeros(0, dtype=np.intp)
    idx = np.flatnonzero(suspect[flat])
    f, z = flat[idx], zc[idx]
    below = z < reference[f]
    if around is not None:
        below |= z < around[f]
    return idx[below]


@dataclass
class _Cells:
    """The points in the grid: each one's cell (flat, int32: the grid has at most 4e8 cells,
    half the memory of int64) and height above the lowest point (float32), the heights that
    count for the minimum grid (``zc``: +inf for a point that is no candidate or low; None
    with the compiled passes, which derive it from ``zr``, the candidates and the low flags
    instead of keeping a copy), and the minimum grid."""

    flat: NDArray[np.int32]
    zr: NDArray[np.float32]
    zc: NDArray[np.float32] | None
    zmin: NDArray[np.float32]


def _minimum_grid(
    points: _Points,
    grid: Grid,
    z0: float,
    candidate: NDArray[np.bool_] | None,
    compiled: bool,
    should_stop: Callable[[], bool] | None,
) -> _Cells:
    """Step 2: the lowest candidate per cell (the module docstring)."""
    n = points.n
    flat = np.empty(n, dtype=np.int32)
    zr = np.empty(n, dtype=np.float32)
    zc: NDArray[np.float32] | None = None
    if compiled:
        from . import ground_filter_numba as nb

        stop_if_asked(should_stop, "filtering the ground")
        zmin = nb.cells_all(points.parts(), grid, z0, candidate, flat, zr)
        zmin = zmin.reshape(grid.rows, grid.cols)
    else:
        for s, bx, by, bz in points.blocks(should_stop):
            flat[s] = grid.flat_index(bx, by)
            zr[s] = bz - z0
        zc = zr if candidate is None else np.where(candidate, zr, np.float32(np.inf))
        zmin = _min_grid(grid, flat, zc)
    if not np.isfinite(zmin).any():
        raise InputError("no ground candidate point (no last return?)")
    return _Cells(flat, zr, zc, zmin)


def _remove_low_outliers(
    cells: _Cells,
    grid: Grid,
    p: FilterParams,
    candidate: NDArray[np.bool_] | None,
    compiled: bool,
    should_stop: Callable[[], bool] | None,
) -> NDArray[np.bool_]:
    """Step 3: the low outliers (N,), removed from ``cells`` (its minimum grid rebuilt without
    them, and their ``zc`` +inf)."""
    low = np.zeros(cells.zr.size, dtype=bool)
    if not p.low_outlier_height > 0:
        return low
    flat, zr = cells.flat, cells.zr
    radius = max(round(p.low_outlier_radius / p.cell_size), 1)
    depth = np.float32(p.low_outlier_height)
    # A few passes: a deeper outlier nearby can hide a shallower one until it is removed.
    for _ in range(LOW_PASSES):
        stop_if_asked(should_stop, "filtering the ground")
        reference, around = _low_references(cells.zmin, radius, depth)
        if compiled:
            from . import ground_filter_numba as nb

            count, rebuilt = nb.low_pass_all(
                flat, zr, candidate, low, reference, around, cells.zmin.size
            )
            if not count:
                break
            cells.zmin = rebuilt.reshape(cells.zmin.shape)
            continue
        assert cells.zc is not None
        new = _low_points(reference, around, cells.zmin, cells.zc, flat)
        if not len(new):
            break
        low[new] = True
        if cells.zc is zr:  # zr is kept for the heights: zc becomes a copy before it changes
            cells.zc = zr.copy()
        cells.zc[new] = np.inf
        cells.zmin = _min_grid(grid, flat, cells.zc)
    return low


@dataclass
class _Surface:
    """The ground surface of a method: the DTM at the cell centres (relative to the lowest
    point), where it is defined (``reach``), each cell's ground threshold, the windows and
    thresholds of the openings (none for CSF), the parameters in cloud units and the
    method's statistics."""

    dtm: NDArray[np.float32]
    reach: NDArray[np.bool_]
    thr_cell: NDArray[np.float32]
    windows: list[int]
    thresholds: list[float]
    params: FilterParams
    stats: dict[str, Any]


def _cloth_surface(
    cells: _Cells,
    grid: Grid,
    points: _Points,
    low: NDArray[np.bool_],
    candidate: NDArray[np.bool_] | None,
    p: CsfParams,
    vertical_unit_to_metre: float,
    should_stop: Callable[[], bool] | None,
) -> _Surface:
    """CSF: the cloth is the DTM, a point within ``threshold`` of it is ground."""
    zc = cells.zc
    if zc is None:  # the compiled passes keep no zc: made here, as the numpy passes have it
        zc = cells.zr.copy()
        zc[low] = np.inf
        if candidate is not None:
            zc[~candidate] = np.inf
    g_xy = 1.0 / vertical_unit_to_metre if vertical_unit_to_metre > 0 else 1.0
    dtm, steps, moved = _csf_cloth(
        grid, cells.flat, points.axis(0), points.axis(1), zc, p, g_xy, should_stop
    )
    reach = np.ones(dtm.shape, dtype=bool)
    thr_cell = np.full(dtm.size, p.threshold, dtype=np.float32)
    stats = {"csf_steps": steps, "csf_last_move": moved}
    return _Surface(dtm, reach, thr_cell, [], [], p, stats)  # no openings in CSF


def _opened_surface(
    cells: _Cells,
    params: FilterParams,
    p: FilterParams,
    xy_per_z: float,
    compiled: bool,
    should_stop: Callable[[], bool] | None,
) -> _Surface:
    """SMRF and PMF: the progressive opening's ground cells, the DTM interpolated across the
    object cells, and the slope-dependent ground threshold per cell. ``params`` as given,
    ``p`` with the slope in cloud units."""
    zmin = cells.zmin
    valid = np.isfinite(zmin)
    stats: dict[str, Any] = {}
    filled = fill_nearest(zmin, valid)
    if p.method == "smrf":
        assert isinstance(p, SmrfParams) and isinstance(params, SmrfParams)
        if params.slope == 0:  # estimated from the cloud
            estimate = _estimate_slope(zmin, valid, p, xy_per_z, should_stop, compiled)
            p = replace(p, slope=estimate * xy_per_z)
            stats["slope_estimated"] = estimate
            LOG.info("ground filter (smrf): terrain slope estimated at %.3f", estimate)
        windows, thresholds = smrf_windows(p)
        shape, final, scalar = "disk", p.threshold, p.scalar
    else:
        assert isinstance(p, GroundFilterParams)
        windows, thresholds = pmf_windows(p)
        shape, final, scalar = p.window_shape, p.ground_threshold, p.slope_scalar
    objects = _progressive_opening(filled, windows, thresholds, shape, should_stop, compiled)
    ground_cells = valid & ~objects
    if not ground_cells.any():
        ground_cells = valid
    dtm = fill_holes(zmin, ground_cells)
    reach = _within(ground_cells, windows[-1] / 2.0 + 1)
    gr, gc = np.gradient(dtm, p.cell_size)
    slope_cell = np.hypot(gr, gc).ravel()
    # the slope term uses the physical slope (rise/run); the scalar is in z units
    thr_cell = (final + scalar * slope_cell / xy_per_z).astype(np.float32)
    return _Surface(dtm, reach, thr_cell, windows, thresholds, p, stats)


def _classify(
    points: _Points,
    grid: Grid,
    cells: _Cells,
    surf: _Surface,
    low: NDArray[np.bool_],
    candidate: NDArray[np.bool_] | None,
    heights: bool,
    compiled: bool,
    report: Callable[[float], None],
    should_stop: Callable[[], bool] | None,
) -> tuple[NDArray[np.bool_], NDArray[np.float32] | None]:
    """Every point's ground flag and (when ``heights``) height above the DTM (NaN where the
    DTM is not defined)."""
    n = points.n
    flat, zr, dtm, thr_cell = cells.flat, cells.zr, surf.dtm, surf.thr_cell
    ground = np.empty(n, dtype=bool)
    hag = np.empty(n, dtype=np.float32) if heights else None
    nodata_flat = ~surf.reach.ravel()
    if compiled:
        from . import ground_filter_numba as nb

        dtm_flat = np.ascontiguousarray(dtm, dtype=np.float32).ravel()
        stop_if_asked(should_stop, "filtering the ground")
        nb.classify_all(
            points.parts(),
            grid,
            flat,
            zr,
            dtm_flat,
            thr_cell,
            low,
            candidate,
            nodata_flat,
            ground,
            hag,
        )
        report(1.0)
    else:
        for s, bx, by, _ in points.blocks(should_stop, z=False):
            h = zr[s] - grid.bilinear(dtm, bx, by)
            f = flat[s]
            g = np.abs(h) <= thr_cell[f]
            g &= ~low[s]
            if candidate is not None:
                g &= candidate[s]
            ground[s] = g
            if hag is not None:
                h[nodata_flat[f]] = np.nan
                hag[s] = h
            report(0.6 + 0.4 * s.stop / n)
    return ground, hag


def _last_returns(params: FilterParams, returns, n_returns) -> NDArray[np.bool_] | None:
    """The ground candidates with ``last_returns_only``: the last returns (``returns`` the
    return numbers, ``n_returns`` the numbers of returns; records of return 0 as single
    returns), or None (every point) without it or without return numbers."""
    candidate: NDArray[np.bool_] | None = None
    if params.last_returns_only and returns is not None and n_returns is not None:
        if np.any(returns > 0):
            candidate = np.asarray(returns) >= np.asarray(n_returns)
            # malformed records (return 0) are treated as single returns
            candidate |= np.asarray(returns) == 0
    return candidate


def _grid(mins, maxs, p: FilterParams, unit: str) -> Grid:
    """The grid of ``p.cell_size`` covering the points' bounds (``mins``, ``maxs``: (3,) arrays,
    ``unit`` their unit's name); InputError naming the parameter beyond 400 million cells."""
    cell = p.cell_size
    grid = Grid.covering(mins[:2], maxs[:2], cell)
    if grid.rows * grid.cols > 400_000_000:
        name = "resolution" if p.method == "csf" else "cell_size"
        raise InputError(
            f"{name} {cell:g} {unit} gives a {grid.rows} x {grid.cols} grid: too fine "
            "for this extent (check the distance unit)",
            column=name,
        )
    return grid


def ground_filter(
    x: NDArray[np.float64] | ScaledXYZ,
    y: NDArray[np.float64] | None = None,
    z: NDArray[np.float64] | None = None,
    params: FilterParams | None = None,
    *,
    return_number: NDArray[Any] | None = None,
    number_of_returns: NDArray[Any] | None = None,
    unit_to_metre: float = 1.0,
    vertical_unit_to_metre: float = 1.0,
    unit: str = "metre",
    heights: bool = True,
    backend: str = "auto",
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> GroundFilterResult:
    """Classify points as ground with SMRF, PMF or CSF (chosen by the type of ``params``).

    Parameters
    ----------
    x, y, z : (N,) float64
        Coordinates in a projected CRS (horizontal unit ``unit``; z in the vertical unit);
        or ``x`` a :class:`ScaledXYZ` (the records' integers, read a block at a time) and
        ``y``, ``z`` None.
    params : SmrfParams, GroundFilterParams (PMF) or CsfParams, optional
        SMRF with its defaults when None.
    return_number, number_of_returns : (N,) integer arrays, optional
        When given and not all zero, only last returns are ground candidates.
    unit_to_metre, vertical_unit_to_metre : float
        Sizes of the horizontal and vertical units in metres (to turn the physical ``slope``
        into z-per-xy units, and CSF's gravity into z units).
    unit : str
        Name of the horizontal unit, reported in the result.
    heights : bool
        Also return every point's height above the DTM (default); False saves its array.
    backend : {"auto", "numba", "numpy"}
        The per-point passes and the larger openings compiled with numba
        (:mod:`core.lidar.ground_filter_numba`, "auto": when installed), or vectorised with
        numpy and OpenCV; both give the same bits.
    progress, should_stop : callable, optional
        Progress fraction in [0, 1]; cancellation (raises Cancelled), checked per step/chunk.

    Returns
    -------
    GroundFilterResult

    Examples
    --------
    >>> xx, yy = np.meshgrid(np.arange(0, 30, 0.5), np.arange(0, 30, 0.5))
    >>> x, y = xx.ravel(), yy.ravel()
    >>> z = np.where((abs(x - 15) < 4) & (abs(y - 15) < 4), 6.0, 0.0)
    >>> [bool(r.ground[z == 0].all()) and not r.ground[z > 0].any()
    ...  for r in (ground_filter(x, y, z, p) for p in (SmrfParams(), GroundFilterParams(),
    ...                                                  CsfParams()))]
    [True, True, True]
    """
    params = SmrfParams() if params is None else params
    params.validate()
    compiled = _use_numba(backend)
    # slope is a ratio of real lengths: z units per xy unit = slope * (xy unit / z unit)
    xy_per_z = 1.0
    if unit_to_metre > 0 and vertical_unit_to_metre > 0:
        xy_per_z = unit_to_metre / vertical_unit_to_metre
    p: FilterParams = params
    if isinstance(params, (GroundFilterParams, SmrfParams)):  # CSF has no slope
        p = replace(params, slope=params.slope * xy_per_z)
    points = _Points(x, y, z)
    n = points.n
    if n == 0:
        raise InputError("x, y and z must be non-empty arrays of equal length")
    report = progress or (lambda _f: None)

    candidate = _last_returns(params, return_number, number_of_returns)
    cell = p.cell_size
    mins, maxs = points.bounds(compiled)
    grid = _grid(mins, maxs, p, unit)
    z0 = float(mins[2])  # float32 grid values relative to the lowest point keep 0.1 mm
    cells = _minimum_grid(points, grid, z0, candidate, compiled, should_stop)
    report(0.3)
    low = _remove_low_outliers(cells, grid, p, candidate, compiled, should_stop)
    stop_if_asked(should_stop, "filtering the ground")
    report(0.45)

    if p.method == "csf":
        assert isinstance(p, CsfParams)
        surf = _cloth_surface(
            cells, grid, points, low, candidate, p, vertical_unit_to_metre, should_stop
        )
    else:
        surf = _opened_surface(cells, params, p, xy_per_z, compiled, should_stop)
    p = surf.params
    report(0.6)

    ground, hag = _classify(
        points, grid, cells, surf, low, candidate, heights, compiled, report, should_stop
    )
    dtm, reach, windows, thresholds = surf.dtm, surf.reach, surf.windows, surf.thresholds
    ground_count, low_count = int(np.count_nonzero(ground)), int(np.count_nonzero(low))
    dtm_out = (dtm.astype(np.float64) + z0).astype(np.float32)
    dtm_out[~reach] = NODATA
    LOG.info(
        "ground filter (%s, %s): %d points, grid %d x %d cells of %g %s, windows %s cells, "
        "thresholds %s; %d ground (%.1f %%), %d low outliers",
        p.method,
        "numba" if compiled else "numpy",
        n,
        grid.rows,
        grid.cols,
        cell,
        unit,
        windows,
        [round(t, 3) for t in thresholds],
        ground_count,
        100.0 * ground_count / n,
        low_count,
    )
    return GroundFilterResult(
        ground=ground,
        low_outlier=low,
        height_above_ground=hag,
        dtm=dtm_out,
        geotransform=grid.geotransform,
        nodata=NODATA,
        windows=tuple(windows),
        thresholds=tuple(thresholds),
        params=p,
        unit=unit,
        stats={"ground_count": ground_count, "low_outlier_count": low_count, **surf.stats},
    )


def _use_numba(backend: str) -> bool:
    """Resolve ground_filter's ``backend`` argument."""
    from .ground_filter_numba import AVAILABLE

    return use_compiled(backend, AVAILABLE)


@dataclass(frozen=True)
class FilterScore:
    """Accuracy of a ground classification (Sithole & Vosselman 2004), fractions in [0, 1].

    Attributes
    ----------
    confusion : NDArray[np.int64]
        (2, 2) ``[[a, b], [c, d]]``: rows reference ground/object, columns filtered
        ground/object.
    type1 : float
        Ground rejected as object: b / (a + b).
    type2 : float
        Object accepted as ground: c / (c + d).
    total : float
        (b + c) / n.
    kappa : float
        Cohen's kappa of the 2 x 2 table.
    agreement : float
        (a + d) / n.
    """

    confusion: NDArray[np.int64]
    type1: float
    type2: float
    total: float
    kappa: float
    agreement: float

    def as_percent(self) -> dict[str, float]:
        """type1, type2, total, kappa and agreement in percent."""
        return {
            "type1": 100 * self.type1,
            "type2": 100 * self.type2,
            "total": 100 * self.total,
            "kappa": 100 * self.kappa,
            "agreement": 100 * self.agreement,
        }


def score_classification(
    predicted_ground: NDArray[np.bool_], reference_ground: NDArray[np.bool_]
) -> FilterScore:
    """Type I, type II and total error and Cohen's kappa of a ground/object classification.

    Parameters
    ----------
    predicted_ground, reference_ground : (N,) bool
        True for ground.

    Returns
    -------
    FilterScore

    Examples
    --------
    >>> s = score_classification(np.array([1, 1, 0, 0, 1], bool), np.array([1, 0, 0, 0, 1], bool))
    >>> s.confusion.tolist(), round(s.type2, 3), s.total
    ([[2, 0], [1, 2]], 0.333, 0.2)
    """
    pred = np.asarray(predicted_ground, dtype=bool)
    ref = np.asarray(reference_ground, dtype=bool)
    if pred.shape != ref.shape or pred.ndim != 1 or pred.size == 0:
        raise InputError("predicted and reference classifications must be (N,) arrays, N > 0")
    a = int(np.count_nonzero(ref & pred))
    b = int(np.count_nonzero(ref & ~pred))
    c = int(np.count_nonzero(~ref & pred))
    d = int(np.count_nonzero(~ref & ~pred))
    e = a + b + c + d
    po = (a + d) / e
    pe = ((a + b) * (a + c) + (c + d) * (b + d)) / (e * e)
    kappa = (po - pe) / (1 - pe) if pe < 1 else 1.0
    return FilterScore(
        confusion=np.array([[a, b], [c, d]], dtype=np.int64),
        type1=b / (a + b) if a + b else 0.0,
        type2=c / (c + d) if c + d else 0.0,
        total=(b + c) / e,
        kappa=kappa,
        agreement=po,
    )
