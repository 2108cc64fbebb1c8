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
from typing import Any, Union

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError, stop_if_asked, use_compiled
from ..geometry.grid import Grid, fill_holes, fill_nearest

LOG = logging.getLogger(__name__)

GROUND_CLASS = 2
UNCLASSIFIED_CLASS = 1
LOW_NOISE_CLASS = 7
NODATA = -9999.0
HEIGHT_FIELD = "height_above_ground"
METHODS = ("smrf", "pmf", "csf")
GROWTH_CHOICES = ("linear", "exponential")
WINDOW_SHAPES = ("square", "disk")
#: Points per step of the per-point loops: the temporaries of a step (about 30 B per point)
#: stay in the cache and in memory malloc reuses, where 2 M-point steps cost page faults.
_POINT_CHUNK = 262_144
#: CSF's constants (Zhang et al. 2016): velocity damping per step, gravity (m per unit time
#: squared), the distance within which slope smoothing pins a particle (m).
#: SMRF's slope estimated from the cloud (SLOPE 0): this percentile of the slope of a first
#: pass's ground surface, clipped to this range (rise/run).
SLOPE_PERCENTILE = 90.0
SLOPE_RANGE = (0.1, 0.7)
#: Inner radius of the ring of the low-outlier cluster test, as a share of its radius.
LOW_RING = 0.6
#: Passes of the low-outlier tests (a deeper outlier nearby hides a shallower one until it is
#: removed).
LOW_PASSES = 10
CSF_DAMPING = 0.01
CSF_GRAVITY_M = 0.2
CSF_SMOOTH_M = 0.3
#: CSF stops when no free particle moved more than this in a step (m), and smooths slopes only
#: in free regions of more particles than this (the authors' package).
CSF_STOP_M = 0.005
CSF_SMOOTH_MIN_REGION = 50


def _check_common(p: Any) -> None:
    for name in ("low_outlier_height", "low_outlier_radius"):
        value = getattr(p, name)
        if not (value >= 0 and math.isfinite(value)):
            raise InputError(f"{name} must be >= 0", column=name)


@dataclass(frozen=True)
class GroundFilterParams:
    """Parameters of the PMF (units: see the module docstring).

    Attributes
    ----------
    cell_size : float
        Side of a grid cell (horizontal unit). Default 1.0.
    max_window : float
        Largest opening window (horizontal unit): about the size of the largest building.
        Default 20.0.
    slope : float
        Terrain slope (rise/run, dimensionless) that the elevation thresholds allow. Default 0.2.
    initial_distance : float
        ``dh0``, elevation threshold of the first opening (vertical unit). Default 0.3.
    max_distance : float
        Cap of the elevation thresholds (vertical unit). Default 2.5.
    growth : str
        ``"linear"`` (w_k = 2 k b + 1) or ``"exponential"`` (w_k = 2 b^k + 1). Default linear.
    window_base : float
        ``b`` of the window series (cells). Default 1.
    window_shape : str
        ``"square"`` or ``"disk"`` opening window. Default square.
    ground_threshold : float
        Final height above the DTM accepted as ground (vertical unit). Default 0.3.
    slope_scalar : float
        Added to ``ground_threshold`` per unit of local DTM slope (vertical unit). Default 1.0.
    low_outlier_height : float
        Depth below the local ground level that makes a point a low outlier (vertical unit);
        0 disables the pre-filter. Default 1.0.
    low_outlier_radius : float
        Half-size of the neighbourhood the point is compared with (horizontal unit).
        Default 5.0.
    last_returns_only : bool
        Only last/single returns can be ground when the file has return numbers. Default True.
    """

    cell_size: float = 1.0
    max_window: float = 20.0
    slope: float = 0.2
    initial_distance: float = 0.3
    max_distance: float = 2.5
    growth: str = "linear"
    window_base: float = 1.0
    window_shape: str = "square"
    ground_threshold: float = 0.3
    slope_scalar: float = 1.0
    low_outlier_height: float = 1.0
    low_outlier_radius: float = 5.0
    last_returns_only: bool = True

    method = "pmf"

    def validate(self) -> None:
        """Raise InputError naming the parameter when a value is out of range."""
        positive = ("cell_size", "max_window", "window_base")
        for name in positive:
            if not getattr(self, name) > 0:
                raise InputError(f"{name} must be > 0", column=name)
        non_negative = (
            "slope",
            "initial_distance",
            "max_distance",
            "ground_threshold",
            "slope_scalar",
        )
        for name in non_negative:
            value = getattr(self, name)
            if not (value >= 0 and math.isfinite(value)):
                raise InputError(f"{name} must be >= 0", column=name)
        _check_common(self)
        if self.growth not in GROWTH_CHOICES:
            raise InputError(f"growth must be one of {GROWTH_CHOICES}", column="growth")
        if self.growth == "exponential" and self.window_base <= 1:
            raise InputError("window_base must be > 1 for exponential growth", column="window_base")
        if self.window_shape not in WINDOW_SHAPES:
            raise InputError(f"window_shape must be one of {WINDOW_SHAPES}", column="window_shape")
        if self.max_window < self.cell_size:
            raise InputError("max_window must be at least one cell", column="max_window")


@dataclass(frozen=True)
class SmrfParams:
    """Parameters of SMRF (Pingel et al. 2013). The defaults are the paper's (and PDAL's,
    :data:`SMRF_PUBLISHED`) except ``threshold``, chosen on AHN3 (README).

    Attributes
    ----------
    cell_size : float
        Side of a grid cell (horizontal unit). Default 1.0 (published 1.0).
    slope : float
        Terrain slope (rise/run) allowed per unit of window radius; 0 estimates it from the
        cloud (the 90th percentile of the ground's slope after a first pass on cells twice
        as large, within 0.1-0.7; it over-estimates under vegetation on steep slopes, see
        README). Default 0.15 (published 0.15).
    max_window : float
        Largest window radius (horizontal unit). Default 18.0 (published 18.0).
    threshold : float
        Final height above the DTM accepted as ground (vertical unit). Default 0.3
        (published 0.5).
    scalar : float
        Added to ``threshold`` per unit of local DTM slope (vertical unit). Default 1.25
        (published 1.25).
    low_outlier_height, low_outlier_radius, last_returns_only
        As in :class:`GroundFilterParams`.
    """

    cell_size: float = 1.0
    slope: float = 0.15
    max_window: float = 18.0
    threshold: float = 0.3
    scalar: float = 1.25
    low_outlier_height: float = 1.0
    low_outlier_radius: float = 5.0
    last_returns_only: bool = True

    method = "smrf"

    def validate(self) -> None:
        """Raise InputError naming the parameter when a value is out of range."""
        for name in ("cell_size", "max_window"):
            if not getattr(self, name) > 0:
                raise InputError(f"{name} must be > 0", column=name)
        for name in ("slope", "threshold", "scalar"):
            value = getattr(self, name)
            if not (value >= 0 and math.isfinite(value)):
                raise InputError(f"{name} must be >= 0", column=name)
        _check_common(self)
        if self.max_window < self.cell_size:
            raise InputError("max_window must be at least one cell", column="max_window")


#: SMRF with the defaults of Pingel et al. (2013) and PDAL's filters.smrf.
SMRF_PUBLISHED = SmrfParams(slope=0.15, max_window=18.0, threshold=0.5, scalar=1.25)


@dataclass(frozen=True)
class CsfParams:
    """Parameters of the cloth simulation filter (Zhang et al. 2016); the defaults are those of
    the authors' package (``cloth-simulation-filter``).

    Attributes
    ----------
    resolution : float
        Distance between cloth particles (horizontal unit). Default 1.0.
    rigidness : int
        1 (steep slopes), 2 (terraces, gentle slopes) or 3 (flat terrain). Default 3.
    time_step : float
        Time step of the simulation (unit time). Default 0.65.
    threshold : float
        Largest distance from the cloth of a ground point (vertical unit). Default 0.5.
    iterations : int
        Largest number of time steps. Default 500.
    slope_smooth : bool
        Post-processing for steep slopes. Default True.
    low_outlier_height, low_outlier_radius, last_returns_only
        As in :class:`GroundFilterParams`.
    """

    resolution: float = 1.0
    rigidness: int = 3
    time_step: float = 0.65
    threshold: float = 0.5
    iterations: int = 500
    slope_smooth: bool = True
    low_outlier_height: float = 1.0
    low_outlier_radius: float = 5.0
    last_returns_only: bool = True

    method = "csf"

    @property
    def cell_size(self) -> float:
        """The grid of the minimum surface and of the cloth (horizontal unit)."""
        return self.resolution

    def validate(self) -> None:
        """Raise InputError naming the parameter when a value is out of range."""
        if not self.resolution > 0:
            raise InputError("resolution must be > 0", column="resolution")
        if self.rigidness not in (1, 2, 3):
            raise InputError("rigidness must be 1, 2 or 3", column="rigidness")
        if not (self.time_step > 0 and math.isfinite(self.time_step)):
            raise InputError("time_step must be > 0", column="time_step")
        if not (self.threshold >= 0 and math.isfinite(self.threshold)):
            raise InputError("threshold must be >= 0", column="threshold")
        if not self.iterations >= 1:
            raise InputError("iterations must be >= 1", column="iterations")
        _check_common(self)


FilterParams = Union[GroundFilterParams, SmrfParams, CsfParams]


@dataclass(frozen=True)
class ScaledXYZ:
    """Coordinates as LAS point records hold them: integers, ``x = X * scale + offset``
    (float64, the LAS rule), in chunks in point order. The filter reads them a block at a time
    instead of float64 x, y, z arrays of every point (240 MB at 10 M points, and the page
    faults of fresh memory).

    Attributes
    ----------
    chunks : sequence of (X, Y, Z)
        (N_k,) integer arrays each (e.g. views of the records' X, Y, Z fields).
    scales, offsets : tuple of 3 float
        Of x, y, z.
    """

    chunks: tuple[tuple[NDArray[Any], NDArray[Any], NDArray[Any]], ...]
    scales: tuple[float, float, float]
    offsets: tuple[float, float, float]

    def __len__(self) -> int:
        return sum(len(c[0]) for c in self.chunks)

    def axis(self, k: int) -> NDArray[np.float64]:
        """Coordinate ``k`` (0 x, 1 y, 2 z) of every point as one float64 array."""
        out = np.empty(len(self), dtype=np.float64)
        done = 0
        for chunk in self.chunks:
            part = out[done : done + len(chunk[k])]
            np.multiply(chunk[k], float(self.scales[k]), out=part)
            part += float(self.offsets[k])
            done += len(part)
        return out

    def bounds(
        self, integers: NDArray[np.int64] | None = None
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(3,) minima and maxima of the scaled coordinates (exactly those of :meth:`axis`:
        rounding is monotonic, so the extreme integers give the extreme coordinates);
        ``integers``: the (3, 2) extreme integers when already known."""
        if integers is None:
            nonempty = [c for c in self.chunks if len(c[0])]
            integers = np.array([[min(int(c[k].min()) for c in nonempty),
                                  max(int(c[k].max()) for c in nonempty)]
                                 for k in range(3)], dtype=np.int64)  # fmt: skip
        ends = integers.astype(np.float64)
        ends *= np.asarray(self.scales, dtype=np.float64)[:, None]
        ends += np.asarray(self.offsets, dtype=np.float64)[:, None]
        return ends.min(axis=1), ends.max(axis=1)


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
        return (np.array([float(a.min()) for a in self.xyz]),
                np.array([float(a.max()) for a in self.xyz]))  # fmt: skip

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
                yield (slice(lo + start, lo + start + len(out[0])), out[0], out[1],
                       out[2] if z else None)  # fmt: skip


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
        return cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (w, w))
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
    return cv2.morphologyEx(surface, cv2.MORPH_OPEN, kernel)


def _min_grid(grid: Grid, flat: NDArray[np.int32], z: NDArray[Any]) -> NDArray[np.float32]:
    out = np.full(grid.rows * grid.cols, np.inf, dtype=np.float32)
    np.minimum.at(out, flat, z.astype(np.float32, copy=False))
    return out.reshape(grid.rows, grid.cols)


def _neighbour_min(surface: NDArray[np.float32], radius: int) -> NDArray[np.float32]:
    """Minimum of the other cells within ``radius`` cells (the cell itself excluded)."""
    import cv2

    kernel = np.ones((2 * radius + 1, 2 * radius + 1), np.uint8)
    kernel[radius, radius] = 0
    return cv2.erode(surface, kernel, borderType=cv2.BORDER_CONSTANT, borderValue=np.inf)


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
        ring = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * radius + 1, 2 * radius + 1))
        hole = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * inner + 1, 2 * inner + 1))
        ring[radius - inner : radius + inner + 1, radius - inner : radius + inner + 1] &= 1 - hole
        ring_min = cv2.erode(zmin, ring, borderType=cv2.BORDER_CONSTANT, borderValue=np.inf)
        ring_min -= depth
        pit = (zmin < ring_min) & np.isfinite(ring_min)
        if pit.any():
            _, labels, stats, _ = cv2.connectedComponentsWithStats(pit.astype(np.uint8), 8)
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
    objects = _progressive_opening(fill_nearest(coarse, ok), windows, thresholds, "disk",
                                   should_stop, compiled)  # fmt: skip
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
    p = replace(params, slope=params.slope * xy_per_z) if hasattr(params, "slope") else params
    points = _Points(x, y, z)
    n = points.n
    if n == 0:
        raise InputError("x, y and z must be non-empty arrays of equal length")
    report = progress or (lambda _f: None)

    candidate: NDArray[np.bool_] | None = None
    if params.last_returns_only and return_number is not None and number_of_returns is not None:
        if np.any(return_number > 0):
            candidate = np.asarray(return_number) >= np.asarray(number_of_returns)
            # malformed records (return 0) are treated as single returns
            candidate |= np.asarray(return_number) == 0
    cell = p.cell_size
    mins, maxs = points.bounds(compiled)
    grid = Grid.covering(mins[:2], maxs[:2], cell)
    if grid.rows * grid.cols > 400_000_000:
        name = "resolution" if p.method == "csf" else "cell_size"
        raise InputError(
            f"{name} {cell:g} {unit} gives a {grid.rows} x {grid.cols} grid: too fine "
            "for this extent (check the distance unit)",
            column=name,
        )
    z0 = float(mins[2])  # float32 grid values relative to the lowest point keep 0.1 mm
    # int32 cell indices (the grid has at most 4e8 cells): half the memory of int64
    flat = np.empty(n, dtype=np.int32)
    zr = np.empty(n, dtype=np.float32)
    # zc: the heights that count for the minimum grid (+inf: not a candidate, or low); the
    # compiled passes derive it from zr, candidate and low instead of keeping a copy
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
    report(0.3)

    low = np.zeros(n, dtype=bool)
    if p.low_outlier_height > 0:
        radius = max(round(p.low_outlier_radius / cell), 1)
        depth = np.float32(p.low_outlier_height)
        # A few passes: a deeper outlier nearby can hide a shallower one until it is removed.
        for _ in range(LOW_PASSES):
            stop_if_asked(should_stop, "filtering the ground")
            reference, around = _low_references(zmin, radius, depth)
            if compiled:
                count, rebuilt = nb.low_pass_all(flat, zr, candidate, low, reference, around,
                                                 zmin.size)  # fmt: skip
                if not count:
                    break
                zmin = rebuilt.reshape(zmin.shape)
                continue
            assert zc is not None
            new = _low_points(reference, around, zmin, zc, flat)
            if not len(new):
                break
            low[new] = True
            if zc is zr:  # zr is kept for the heights: zc becomes a copy before it changes
                zc = zr.copy()
            zc[new] = np.inf
            zmin = _min_grid(grid, flat, zc)
    valid = np.isfinite(zmin)
    stop_if_asked(should_stop, "filtering the ground")
    report(0.45)

    stats: dict[str, Any] = {}
    if p.method == "csf":
        if zc is None:  # the compiled passes keep no zc: made here, as the numpy passes have it
            zc = zr.copy()
            zc[low] = np.inf
            if candidate is not None:
                zc[~candidate] = np.inf
        g_xy = 1.0 / vertical_unit_to_metre if vertical_unit_to_metre > 0 else 1.0
        dtm, steps, moved = _csf_cloth(grid, flat, points.axis(0), points.axis(1), zc, p, g_xy,
                                       should_stop)  # fmt: skip
        windows, thresholds = [], []  # no openings in CSF
        stats["csf_steps"], stats["csf_last_move"] = steps, moved
        reach = np.ones(dtm.shape, dtype=bool)
        thr_cell = np.full(dtm.size, p.threshold, dtype=np.float32)
    else:
        filled = fill_nearest(zmin, valid)
        if p.method == "smrf":
            if params.slope == 0:  # estimated from the cloud
                estimate = _estimate_slope(zmin, valid, p, xy_per_z, should_stop, compiled)
                p = replace(p, slope=estimate * xy_per_z)
                stats["slope_estimated"] = estimate
                LOG.info("ground filter (smrf): terrain slope estimated at %.3f", estimate)
            windows, thresholds = smrf_windows(p)
            shape, final, scalar = "disk", p.threshold, p.scalar
        else:
            windows, thresholds = pmf_windows(p)
            shape, final, scalar = p.window_shape, p.ground_threshold, p.slope_scalar
        objects = _progressive_opening(filled, windows, thresholds, shape, should_stop,
                                       compiled)  # fmt: skip
        ground_cells = valid & ~objects
        if not ground_cells.any():
            ground_cells = valid
        dtm = fill_holes(zmin, ground_cells)
        reach = _within(ground_cells, windows[-1] / 2.0 + 1)
        gr, gc = np.gradient(dtm, cell)
        slope_cell = np.hypot(gr, gc).ravel()
        # the slope term uses the physical slope (rise/run); the scalar is in z units
        thr_cell = (final + scalar * slope_cell / xy_per_z).astype(np.float32)
    report(0.6)

    ground = np.empty(n, dtype=bool)
    hag = np.empty(n, dtype=np.float32) if heights else None
    nodata_flat = ~reach.ravel()
    if compiled:
        dtm_flat = np.ascontiguousarray(dtm, dtype=np.float32).ravel()
        stop_if_asked(should_stop, "filtering the ground")
        nb.classify_all(points.parts(), grid, flat, zr, dtm_flat, thr_cell, low, candidate,
                        nodata_flat, ground, hag)  # fmt: skip
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
        stats={"ground_count": ground_count, "low_outlier_count": low_count, **stats},
    )


def _use_numba(backend: str) -> bool:
    """Resolve ground_filter's ``backend`` argument."""
    from .ground_filter_numba import AVAILABLE

    return use_compiled(backend, AVAILABLE)


def _csf_cloth(
    grid: Grid,
    flat: NDArray[np.int32],
    x: NDArray[np.float64],
    y: NDArray[np.float64],
    zc: NDArray[np.float32],
    p: CsfParams,
    metre: float,
    should_stop: Callable[[], bool] | None,
) -> tuple[NDArray[np.float32], int, float]:
    """The cloth (Zhang et al. 2016) as a ground surface at the cell centres, in the upright
    frame (z relative to the lowest point); also the number of steps and the last largest move.

    ``metre`` is one metre in z units (gravity, the stop criterion and slope smoothing are in
    metres).
    """
    rows, cols = grid.rows, grid.cols
    # Intersection heights: the candidate nearest to each particle (cell centre) horizontally
    # (Zhang et al. 2016, section 2.2); in the inverted frame it is -z.
    usable = np.isfinite(zc)
    f = flat[usable].astype(np.int64)
    cr = f // cols
    cc = f - cr * cols
    dx = x[usable] - (grid.x0 + (cc + 0.5) * grid.cell)
    dy = y[usable] - (grid.y_top - (cr + 0.5) * grid.cell)
    d2 = dx * dx + dy * dy
    nearest = np.full(rows * cols, np.inf)
    np.minimum.at(nearest, f, d2)
    pick = d2 == nearest[f]
    ihv = np.full(rows * cols, np.nan, dtype=np.float64)
    ihv[f[pick]] = -zc[usable][pick].astype(np.float64)
    has = np.isfinite(ihv).reshape(rows, cols)
    ihv = fill_nearest(ihv.reshape(rows, cols), has)  # particles without a point: nearest one

    height = np.full((rows, cols), float(ihv.max()) + 0.05 * metre)  # starts above everything
    previous = height.copy()
    movable = np.ones((rows, cols), dtype=bool)
    fall = CSF_GRAVITY_M * metre * p.time_step**2
    # Internal forces: a free particle moves towards a free neighbour by `both` of their height
    # difference (each moves), towards a pinned one by `one` of it: the closed forms of the
    # paper's half-difference move repeated `rigidness` times with relaxation (the values the
    # authors' package uses: 0.3/0.42/0.468 and 0.3/0.51/0.657 for rigidness 1/2/3). Springs
    # join each particle to its 8 neighbours and to those 2 cells away in the same 8
    # directions, as in the package.
    both = 0.5 * (1.0 - 0.4**p.rigidness)
    one = 1.0 - 0.7**p.rigidness
    pairs = _spring_pairs(rows, cols)
    done, moved = 0, 0.0
    for done in range(1, p.iterations + 1):
        if done % 16 == 0:
            stop_if_asked(should_stop, "filtering the ground")
        new = height + (height - previous) * (1.0 - CSF_DAMPING) - fall
        np.copyto(new, height, where=~movable)
        previous, height = height, new
        for _ in range(2):  # every spring acts from both of its particles
            for a, b in pairs:
                _spring(height, movable, a, b, both, one)
        moved = float(np.abs(height - previous)[movable].max()) if movable.any() else 0.0
        hit = movable & (height < ihv)
        height[hit] = ihv[hit]
        movable &= ~hit
        if 0.0 < moved < CSF_STOP_M * metre or not movable.any():
            break
    if p.slope_smooth:
        _csf_smooth(height, ihv, movable, CSF_SMOOTH_M * metre)
    return (-height).astype(np.float32), done, round(moved, 6)


def _spring_pairs(rows: int, cols: int) -> list[tuple[tuple[slice, slice], tuple[slice, slice]]]:
    """Index pairs (a, b) of views, one per batch of springs that share no particle: for every
    spring direction (dr, dc) of length 1 or 2, the particles split by their row (or column)
    index so that each is in at most one spring of the batch."""
    out = []
    for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1), (0, 2), (2, 0), (2, 2), (2, -2)):
        ca = slice(max(-dc, 0), cols - max(dc, 0))
        cb = slice(max(dc, 0), cols - max(-dc, 0) if dc < 0 else cols)
        step = dr if dr else dc
        n = rows if dr else cols
        for colour in (0, 1):
            for first in range(colour * step, colour * step + step):
                lo = slice(first, n - step, 2 * step)
                hi = slice(first + step, n, 2 * step)
                if dr:
                    out.append(((lo, ca), (hi, cb)))
                else:
                    out.append(((slice(None), lo), (slice(None), hi)))
    return out


def _spring(
    h: NDArray[np.float64],
    movable: NDArray[np.bool_],
    a: tuple[slice, slice],
    b: tuple[slice, slice],
    both: float,
    one: float,
) -> None:
    """Apply one batch of springs between the particles ``h[a]`` and ``h[b]`` (views), in place."""
    ha, hb = h[a], h[b]
    if ha.size == 0:
        return
    ma, mb = movable[a], movable[b]
    diff = hb - ha
    free = ma & mb
    ha += np.where(free, both, np.where(ma, one, 0.0)) * diff
    hb -= np.where(free, both, np.where(mb, one, 0.0)) * diff


def _csf_smooth(
    height: NDArray[np.float64], ihv: NDArray[np.float64], movable: NDArray[np.bool_], near: float
) -> None:
    """Slope post-processing (Zhang et al. 2016), in place: in every connected region of more
    than 50 free particles, those reachable from a pinned particle through neighbours whose
    point heights differ by less than ``near`` are pinned on their points (the cloth left
    hanging over steep ground)."""
    from scipy import ndimage
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    rows, cols = height.shape
    labels, count = ndimage.label(movable)
    if count == 0:
        return
    sizes = np.bincount(labels.ravel())
    big = (sizes > CSF_SMOOTH_MIN_REGION)[labels] & movable
    index = np.arange(rows * cols).reshape(rows, cols)
    heads, tails = [], []
    for sa, sb in (((slice(None), slice(0, -1)), (slice(None), slice(1, None))),
                   ((slice(0, -1), slice(None)), (slice(1, None), slice(None)))):  # fmt: skip
        close = np.abs(ihv[sa] - ihv[sb]) < near
        heads.append(index[sa][close])
        tails.append(index[sb][close])
    u, v = np.concatenate(heads), np.concatenate(tails)
    flat_big = big.ravel()
    pinned = ~movable.ravel()
    # the graph: close neighbours among the big free regions, plus one node for "pinned"
    inside = flat_big[u] & flat_big[v]
    seed_u = flat_big[u] & pinned[v]
    seed_v = flat_big[v] & pinned[u]
    root = rows * cols
    gu = np.concatenate([u[inside], u[seed_u], v[seed_v]])
    gv = np.concatenate([v[inside], np.full(seed_u.sum(), root), np.full(seed_v.sum(), root)])
    graph = coo_matrix((np.ones(len(gu), np.int8), (gu, gv)), shape=(root + 1, root + 1))
    _, comp = connected_components(graph, directed=False)
    reach = (comp[:root] == comp[root]) & flat_big
    flat_h = height.reshape(-1)
    flat_h[reach] = ihv.reshape(-1)[reach]
    movable.reshape(-1)[reach] = False


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
