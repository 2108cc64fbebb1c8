"""Ground filter: the Progressive Morphological Filter (Zhang et al. 2003) on a minimum grid.

Steps (all grid work is vectorised with OpenCV/scipy.ndimage, all point work with numpy):

1. **Candidates.** Where the file has return numbers, only last (and single) returns can be
   ground: earlier returns of a multi-return pulse were stopped by something above the ground.
2. **Minimum grid.** The lowest candidate per cell of ``cell_size``; empty cells take the value
   of the nearest filled cell (Euclidean distance transform).
3. **Low outliers.** A point lower than every other cell's minimum within
   ``low_outlier_radius`` by more than ``low_outlier_height`` is a low outlier (multipath or
   range errors: nothing real lies below the ground around it); only cells holding points
   count, so an isolated point with no neighbour in the radius is never one. Low
   outliers are removed before the PMF (a single one punches a pit that every opening widens),
   get class 7 (low point, noise) and are never ground. The minimum grid is rebuilt without them.
4. **PMF.** Openings (erosion then dilation, square or disk windows counted in cells) of the
   surface with windows ``w_k`` growing linearly (``w_k = 2 k b + 1``) or exponentially
   (``w_k = 2 b^k + 1``) up to ``max_window``. At each step a cell is an object cell when the
   surface minus its opening exceeds ``dh_k``: ``dh_1 = initial_distance``, then
   ``dh_k = slope (w_k - w_{k-1}) c + initial_distance`` capped at ``max_distance``, where ``c``
   is the cell size (applied once: PDAL's filters.pmf applies it twice and counts its windows in
   map units, see PEERS.md) and ``slope`` is converted to the file's z-per-xy units.
5. **DTM.** The minimum grid with object cells removed; the holes are filled by a pull-push
   pyramid (weighted 2x2 averages down, bilinear up), which interpolates smoothly across
   buildings. Cells farther than ``max_window`` from any ground cell are nodata.
6. **Points.** Each candidate's height above the DTM (bilinear between cell centres) is compared
   with a slope-dependent threshold as in SMRF (Pingel et al. 2013):
   ``|h| <= ground_threshold + slope_scalar * local DTM slope`` is ground.

Distance parameters are in the cloud's horizontal unit (``cell_size``, ``max_window``,
``low_outlier_radius``) or its vertical unit (``initial_distance``, ``max_distance``,
``ground_threshold``, ``slope_scalar``, ``low_outlier_height``); the ``groundfilter`` job
converts lengths given in metres (:func:`core.jobs.common.lengths_in_cloud_units`). ``slope``
is always a ratio of real lengths (rise over run).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError, stop_if_asked
from ..geometry.grid import Grid, fill_holes, fill_nearest

LOG = logging.getLogger(__name__)

GROUND_CLASS = 2
UNCLASSIFIED_CLASS = 1
LOW_NOISE_CLASS = 7
NODATA = -9999.0
HEIGHT_FIELD = "height_above_ground"
GROWTH_CHOICES = ("linear", "exponential")
WINDOW_SHAPES = ("square", "disk")
_POINT_CHUNK = 2_000_000


@dataclass(frozen=True)
class GroundFilterParams:
    """Parameters of :func:`ground_filter` (units: see the module docstring).

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
            "low_outlier_height",
            "low_outlier_radius",
        )
        for name in non_negative:
            value = getattr(self, name)
            if not (value >= 0 and math.isfinite(value)):
                raise InputError(f"{name} must be >= 0", column=name)
        if self.growth not in GROWTH_CHOICES:
            raise InputError(f"growth must be one of {GROWTH_CHOICES}", column="growth")
        if self.growth == "exponential" and self.window_base <= 1:
            raise InputError("window_base must be > 1 for exponential growth", column="window_base")
        if self.window_shape not in WINDOW_SHAPES:
            raise InputError(f"window_shape must be one of {WINDOW_SHAPES}", column="window_shape")
        if self.max_window < self.cell_size:
            raise InputError("max_window must be at least one cell", column="max_window")


@dataclass(frozen=True)
class GroundFilterResult:
    """Result of :func:`ground_filter`.

    Attributes
    ----------
    ground : NDArray[np.bool_]
        (N,) True for ground points.
    low_outlier : NDArray[np.bool_]
        (N,) True for low outliers (never ground).
    height_above_ground : NDArray[np.float32]
        (N,) z minus the DTM at the point (vertical unit; NaN where the DTM is nodata).
    dtm : NDArray[np.float32]
        (rows, cols) ground surface at the cell centres, ``nodata`` where unknown.
    geotransform : tuple of 6 float
        GDAL order, top-left corner of the top-left cell.
    nodata : float
    windows : tuple[int, ...]
        Opening windows used, in cells.
    thresholds : tuple[float, ...]
        Elevation-difference threshold of each window (vertical unit).
    params : GroundFilterParams
        The parameters actually used, in the cloud's units.
    unit : str
        Name of the unit the parameters were interpreted in.
    """

    ground: NDArray[np.bool_]
    low_outlier: NDArray[np.bool_]
    height_above_ground: NDArray[np.float32]
    dtm: NDArray[np.float32]
    geotransform: tuple[float, float, float, float, float, float]
    nodata: float
    windows: tuple[int, ...]
    thresholds: tuple[float, ...]
    params: GroundFilterParams
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


def _kernel(w: int, shape: str) -> NDArray[np.uint8]:
    import cv2

    if shape == "disk":
        return cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (w, w))
    return np.ones((w, w), np.uint8)


def _opening(surface: NDArray[np.float32], w: int, shape: str) -> NDArray[np.float32]:
    import cv2

    # cv2's default border for erode/dilate is neutral (ignored), as the filter needs.
    return cv2.morphologyEx(surface, cv2.MORPH_OPEN, _kernel(w, shape))


def _min_grid(grid: Grid, flat: NDArray[np.int64], z: NDArray[Any]) -> NDArray[np.float32]:
    out = np.full(grid.rows * grid.cols, np.inf, dtype=np.float32)
    np.minimum.at(out, flat, z.astype(np.float32, copy=False))
    return out.reshape(grid.rows, grid.cols)


def _neighbour_min(surface: NDArray[np.float32], radius: int) -> NDArray[np.float32]:
    """Minimum of the other cells within ``radius`` cells (the cell itself excluded)."""
    import cv2

    kernel = np.ones((2 * radius + 1, 2 * radius + 1), np.uint8)
    kernel[radius, radius] = 0
    return cv2.erode(surface, kernel, borderType=cv2.BORDER_CONSTANT, borderValue=np.inf)


def ground_filter(
    x: NDArray[np.float64],
    y: NDArray[np.float64],
    z: NDArray[np.float64],
    params: GroundFilterParams | None = None,
    *,
    return_number: NDArray[Any] | None = None,
    number_of_returns: NDArray[Any] | None = None,
    unit_to_metre: float = 1.0,
    vertical_unit_to_metre: float = 1.0,
    unit: str = "metre",
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> GroundFilterResult:
    """Classify points as ground with the Progressive Morphological Filter.

    Parameters
    ----------
    x, y, z : (N,) float64
        Coordinates in a projected CRS (horizontal unit ``unit``; z in the vertical unit).
    params : GroundFilterParams, optional
        Defaults when None.
    return_number, number_of_returns : (N,) integer arrays, optional
        When given and not all zero, only last returns are ground candidates.
    unit_to_metre, vertical_unit_to_metre : float
        Sizes of the horizontal and vertical units in metres (to turn the physical ``slope``
        into z-per-xy units).
    unit : str
        Name of the horizontal unit, reported in the result.
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
    >>> r = ground_filter(x, y, z)
    >>> bool(r.ground[z == 0].all()), bool(r.ground[z > 0].any())
    (True, False)
    """
    params = GroundFilterParams() if params is None else params
    params.validate()
    p = params
    # slope is a ratio of real lengths: z units per xy unit = slope * (xy unit / z unit)
    xy_per_z = 1.0
    if unit_to_metre > 0 and vertical_unit_to_metre > 0:
        xy_per_z = unit_to_metre / vertical_unit_to_metre
    p = replace(p, slope=params.slope * xy_per_z)
    n = len(z)
    if n == 0 or len(x) != n or len(y) != n:
        raise InputError("x, y and z must be non-empty arrays of equal length")
    report = progress or (lambda _f: None)

    candidate: NDArray[np.bool_] | None = None
    if params.last_returns_only and return_number is not None and number_of_returns is not None:
        if np.any(return_number > 0):
            candidate = np.asarray(return_number) >= np.asarray(number_of_returns)
            # malformed records (return 0) are treated as single returns
            candidate |= np.asarray(return_number) == 0
    mins = (float(x.min()), float(y.min()))
    maxs = (float(x.max()), float(y.max()))
    grid = Grid.covering(mins, maxs, p.cell_size)
    if grid.rows * grid.cols > 400_000_000:
        raise InputError(
            f"cell_size {p.cell_size:g} {unit} gives a {grid.rows} x {grid.cols} grid: too fine "
            "for this extent (check the distance unit)",
            column="cell_size",
        )
    z0 = float(z.min())  # float32 grid values relative to the lowest point keep 0.1 mm
    flat = np.empty(n, dtype=np.int64)
    zr = np.empty(n, dtype=np.float32)
    for start in range(0, n, _POINT_CHUNK):
        stop_if_asked(should_stop, "filtering the ground")
        s = slice(start, start + _POINT_CHUNK)
        flat[s] = grid.flat_index(x[s], y[s])
        zr[s] = z[s] - z0
    report(0.15)
    zc = zr if candidate is None else np.where(candidate, zr, np.inf).astype(np.float32)
    zmin = _min_grid(grid, flat, zc)
    valid = np.isfinite(zmin)
    if not valid.any():
        raise InputError("no ground candidate point (no last return?)")
    filled = fill_nearest(zmin, valid)
    report(0.3)

    low = np.zeros(n, dtype=bool)
    if p.low_outlier_height > 0:
        radius = max(round(p.low_outlier_radius / p.cell_size), 1)
        # A few passes: a deeper outlier nearby can hide a shallower one until it is removed.
        for _ in range(3):
            # empty cells stay +inf here, so an outlier's value never stands in for a neighbour;
            # a point without any real neighbour (+inf) has nothing to be lower than
            reference = _neighbour_min(zmin, radius).ravel() - np.float32(p.low_outlier_height)
            new = (zc < reference[flat]) & np.isfinite(reference[flat])
            if not new.any():
                break
            low |= new
            zc = np.where(new, np.inf, zc).astype(np.float32)
            zmin = _min_grid(grid, flat, zc)
        valid = np.isfinite(zmin)
        filled = fill_nearest(zmin, valid)
    stop_if_asked(should_stop, "filtering the ground")
    report(0.45)

    windows, thresholds = pmf_windows(p)
    surface = filled
    objects = np.zeros(surface.shape, dtype=bool)
    for w, dh in zip(windows, thresholds):
        stop_if_asked(should_stop, "filtering the ground")
        opened = _opening(surface, w, p.window_shape)
        objects |= (surface - opened) > dh
        surface = opened
    ground_cells = valid & ~objects
    if not ground_cells.any():
        ground_cells = valid
    dtm = fill_holes(zmin, ground_cells)
    report(0.6)

    from scipy import ndimage

    dist = ndimage.distance_transform_edt(~ground_cells)
    outside = dist > (windows[-1] / 2.0 + 1)
    gr, gc = np.gradient(dtm, p.cell_size)
    slope_cell = np.hypot(gr, gc).ravel()
    # the slope term uses the physical slope (rise/run); slope_scalar is in z units
    thr_cell = (p.ground_threshold + p.slope_scalar * slope_cell / xy_per_z).astype(np.float32)

    ground = np.empty(n, dtype=bool)
    hag = np.empty(n, dtype=np.float32)
    nodata_flat = outside.ravel()
    for start in range(0, n, _POINT_CHUNK):
        stop_if_asked(should_stop, "filtering the ground")
        s = slice(start, start + _POINT_CHUNK)
        h = zr[s] - grid.bilinear(dtm, x[s], y[s])
        f = flat[s]
        g = np.abs(h) <= thr_cell[f]
        g &= ~low[s]
        if candidate is not None:
            g &= candidate[s]
        h[nodata_flat[f]] = np.nan
        ground[s] = g
        hag[s] = h
        report(0.6 + 0.4 * min(start + _POINT_CHUNK, n) / n)

    dtm_out = (dtm.astype(np.float64) + z0).astype(np.float32)
    dtm_out[outside] = NODATA
    LOG.info(
        "ground filter: %d points, grid %d x %d cells of %g %s, windows %s cells, thresholds %s; "
        "%d ground (%.1f %%), %d low outliers",
        n,
        grid.rows,
        grid.cols,
        p.cell_size,
        unit,
        windows,
        [round(t, 3) for t in thresholds],
        int(ground.sum()),
        100.0 * ground.mean(),
        int(low.sum()),
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
        stats={"ground_count": int(ground.sum()), "low_outlier_count": int(low.sum())},
    )


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
