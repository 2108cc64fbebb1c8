"""Ground filter: the Progressive Morphological Filter (Zhang et al. 2003) on a minimum grid.

Steps (all grid work is vectorised with OpenCV/scipy.ndimage, all point work with numpy):

1. **Candidates.** Where the file has return numbers, only last (and single) returns can be
   ground: earlier returns of a multi-return pulse were stopped by something above the ground.
2. **Minimum grid.** The lowest candidate per cell of ``cell_size``; empty cells take the value
   of the nearest filled cell (Euclidean distance transform).
3. **Low outliers.** A point lower than every other cell's minimum within
   ``low_outlier_radius`` by more than ``low_outlier_height`` is a low outlier (multipath or
   range errors: nothing real lies below the ground around it). Low
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
``ground_threshold``, ``slope_scalar``, ``low_outlier_height``), unless
``distance_unit="metre"``: they are then converted with the CRS's unit sizes. ``slope`` is
always a ratio of real lengths (rise over run).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError, stop_if_asked

LOG = logging.getLogger(__name__)

GROUND_CLASS = 2
UNCLASSIFIED_CLASS = 1
LOW_NOISE_CLASS = 7
NODATA = -9999.0
HEIGHT_FIELD = "height_above_ground"
DISTANCE_UNITS = ("crs", "metre")
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
    distance_unit : str
        ``"crs"``: parameters in the cloud's CRS units; ``"metre"``: in metres, converted.
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
    distance_unit: str = "crs"

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
        if self.distance_unit not in DISTANCE_UNITS:
            raise InputError(
                f"distance_unit must be one of {DISTANCE_UNITS}", column="distance_unit"
            )
        if self.max_window < self.cell_size:
            raise InputError("max_window must be at least one cell", column="max_window")

    def in_cloud_units(
        self, unit_to_metre: float, vertical_unit_to_metre: float
    ) -> GroundFilterParams:
        """The same parameters expressed in the cloud's units (``distance_unit="crs"``).

        Parameters
        ----------
        unit_to_metre, vertical_unit_to_metre : float
            Sizes in metres of the cloud's horizontal and vertical units.
        """
        if self.distance_unit == "crs":
            return self
        if not (unit_to_metre > 0 and vertical_unit_to_metre > 0):
            raise InputError("distance_unit 'metre' needs a cloud CRS with known units")
        h = 1.0 / unit_to_metre
        v = 1.0 / vertical_unit_to_metre
        return replace(
            self,
            cell_size=self.cell_size * h,
            max_window=self.max_window * h,
            low_outlier_radius=self.low_outlier_radius * h,
            initial_distance=self.initial_distance * v,
            max_distance=self.max_distance * v,
            ground_threshold=self.ground_threshold * v,
            slope_scalar=self.slope_scalar * v,
            low_outlier_height=self.low_outlier_height * v,
            distance_unit="crs",
        )


@dataclass(frozen=True)
class Grid:
    """A north-up raster: cell (row, col) covers x0 + col c .. and y_top - row c ...

    ``geotransform`` is in GDAL order (x of the top-left corner, c, 0, y of the top-left
    corner, 0, -c).
    """

    x0: float
    y_top: float
    cell: float
    rows: int
    cols: int

    @property
    def geotransform(self) -> tuple[float, float, float, float, float, float]:
        return (self.x0, self.cell, 0.0, self.y_top, 0.0, -self.cell)

    @classmethod
    def covering(cls, mins: Sequence[float], maxs: Sequence[float], cell: float) -> Grid:
        """The grid of ``cell`` aligned on multiples of ``cell`` that covers the box."""
        x0 = math.floor(mins[0] / cell) * cell
        y_top = (math.floor(maxs[1] / cell) + 1) * cell
        cols = math.floor((maxs[0] - x0) / cell) + 1
        rows = math.floor((y_top - mins[1]) / cell) + 1
        return cls(x0, y_top, cell, rows, cols)

    def flat_index(self, x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.int64]:
        """(N,) flat cell index row * cols + col of each point (clipped to the grid)."""
        col = ((x - self.x0) * (1.0 / self.cell)).astype(np.int64)
        row = ((self.y_top - y) * (1.0 / self.cell)).astype(np.int64)
        np.clip(col, 0, self.cols - 1, out=col)
        np.clip(row, 0, self.rows - 1, out=row)
        row *= self.cols
        row += col
        return row

    def bilinear(
        self, surface: NDArray[np.float32], x: NDArray[np.float64], y: NDArray[np.float64]
    ) -> NDArray[np.float32]:
        """(N,) bilinear interpolation of a (rows, cols) surface given at the cell centres."""
        fc = ((x - self.x0) * (1.0 / self.cell) - 0.5).astype(np.float32)
        fr = ((self.y_top - y) * (1.0 / self.cell) - 0.5).astype(np.float32)
        np.clip(fc, 0, self.cols - 1, out=fc)
        np.clip(fr, 0, self.rows - 1, out=fr)
        c0 = np.minimum(fc.astype(np.int64), max(self.cols - 2, 0))
        r0 = np.minimum(fr.astype(np.int64), max(self.rows - 2, 0))
        fc -= c0
        fr -= r0
        flat = surface.ravel()
        i00 = r0 * self.cols + c0
        dc = 1 if self.cols > 1 else 0
        dr = self.cols if self.rows > 1 else 0
        top = flat[i00] * (1 - fc) + flat[i00 + dc] * fc
        bottom = flat[i00 + dr] * (1 - fc) + flat[i00 + dr + dc] * fc
        return top * (1 - fr) + bottom * fr


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


def _fill_nearest(surface: NDArray[np.float32], valid: NDArray[np.bool_]) -> NDArray[np.float32]:
    from scipy import ndimage

    if valid.all():
        return surface
    _, (ri, ci) = ndimage.distance_transform_edt(~valid, return_indices=True)
    return surface[ri, ci]


def _neighbour_min(surface: NDArray[np.float32], radius: int) -> NDArray[np.float32]:
    """Minimum of the other cells within ``radius`` cells (the cell itself excluded)."""
    import cv2

    kernel = np.ones((2 * radius + 1, 2 * radius + 1), np.uint8)
    kernel[radius, radius] = 0
    return cv2.erode(surface, kernel, borderType=cv2.BORDER_CONSTANT, borderValue=np.inf)


def fill_holes(surface: NDArray[np.float32], valid: NDArray[np.bool_]) -> NDArray[np.float32]:
    """Fill the cells where ``valid`` is False by pull-push interpolation.

    Pull: weighted 2x2 averages build a pyramid until a level has no hole. Push: from the
    coarsest level down, holes take the bilinear up-sampling of the level above. The result
    is smooth across holes and exact on valid cells.

    Parameters
    ----------
    surface : (rows, cols) float32
    valid : (rows, cols) bool, at least one True

    Returns
    -------
    (rows, cols) float32

    Examples
    --------
    >>> s = np.array([[1, 0, 3]], np.float32)
    >>> fill_holes(s, s > 0).tolist()
    [[1.0, 1.5, 3.0]]
    """
    import cv2

    if valid.all():
        return surface.astype(np.float32, copy=True)
    if not valid.any():
        raise InputError("no valid cell to interpolate from")
    values = np.where(valid, surface, 0).astype(np.float32)
    weights = valid.astype(np.float32)
    levels = []
    while True:
        levels.append((values, weights))
        if weights.min() > 0 or max(values.shape) == 1:
            break
        r, c = values.shape
        pr, pc = r % 2, c % 2
        if pr or pc:
            values = np.pad(values, ((0, pr), (0, pc)))
            weights = np.pad(weights, ((0, pr), (0, pc)))
        values = values.reshape(values.shape[0] // 2, 2, values.shape[1] // 2, 2).sum(axis=(1, 3))
        weights = weights.reshape(weights.shape[0] // 2, 2, weights.shape[1] // 2, 2).sum(
            axis=(1, 3)
        )
    values, weights = levels[-1]
    est = values / np.maximum(weights, 1e-30)
    if weights.min() <= 0:  # a 1-cell-wide top level with holes: nearest fill
        est = _fill_nearest(est.astype(np.float32), weights > 0)
    for values, weights in reversed(levels[:-1]):
        r, c = values.shape
        up = cv2.resize(
            est.astype(np.float32),
            (2 * est.shape[1], 2 * est.shape[0]),
            interpolation=cv2.INTER_LINEAR,
        )[:r, :c]
        est = np.where(weights > 0, values / np.maximum(weights, 1e-30), up)
    out = np.where(valid, surface, est)
    return out.astype(np.float32)



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
        Sizes of the horizontal and vertical units in metres (for ``distance_unit="metre"``
        and to turn the physical ``slope`` into z-per-xy units).
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
    p = params.in_cloud_units(unit_to_metre, vertical_unit_to_metre)
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
    filled = _fill_nearest(zmin, valid)
    report(0.3)

    low = np.zeros(n, dtype=bool)
    if p.low_outlier_height > 0:
        radius = max(round(p.low_outlier_radius / p.cell_size), 1)
        # A few passes: a deeper outlier nearby can hide a shallower one until it is removed.
        for _ in range(3):
            # empty cells stay +inf here, so an outlier's value never stands in for a neighbour
            reference = _neighbour_min(zmin, radius).ravel() - np.float32(p.low_outlier_height)
            new = zc < reference[flat]
            if not new.any():
                break
            low |= new
            zc = np.where(new, np.inf, zc).astype(np.float32)
            zmin = _min_grid(grid, flat, zc)
        valid = np.isfinite(zmin)
        filled = _fill_nearest(zmin, valid)
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


@dataclass(frozen=True)
class GroundFilterRun:
    """Summary of :func:`run_ground_filter` (the arrays stay in ``result``)."""

    result: GroundFilterResult
    point_count: int
    ground_count: int
    low_outlier_count: int
    unit: str
    crs_wkt: str
    output: str


def run_ground_filter(
    input_path: str,
    output_path: str,
    params: GroundFilterParams | None = None,
    *,
    crs: Any = None,
    non_ground_class: int | None = None,
    chunk_size: int = 1_000_000,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> GroundFilterRun:
    """Read a LAS/LAZ file, filter its ground and write the classified copy.

    The copy keeps every dimension and VLR; ground points get class 2, low outliers class 7,
    the others keep their class (or get ``non_ground_class`` when given; a point the file had
    as ground but the filter rejects becomes 1). The extra dimension ``height_above_ground``
    (float32, vertical unit) is added.

    Parameters
    ----------
    input_path, output_path : str
        Source and destination (``.las``/``.laz``).
    params : GroundFilterParams, optional
    crs : str, int or pyproj.CRS, optional
        Overrides the file's CRS.
    non_ground_class : int, optional
        Class written to every non-ground point (e.g. 1); None keeps the original classes.
    chunk_size, progress, should_stop
        As in :func:`core.pointcloud.read_points`.

    Returns
    -------
    GroundFilterRun
    """
    from ..io.pointcloud import read_points, write_cloud

    params = GroundFilterParams() if params is None else params
    params.validate()

    def sub(lo: float, hi: float) -> Callable[[float], None] | None:
        if progress is None:
            return None
        return lambda f: progress(lo + (hi - lo) * f)

    info_fields = ("x", "y", "z", "classification")
    from ..io.pointcloud import read_info

    info = read_info(input_path, crs)
    fields: tuple[str, ...] = info_fields
    if info.has_return_numbers and params.last_returns_only:
        fields = (*info_fields, "return_number", "number_of_returns")
    arrays, info = read_points(
        input_path, fields, crs, chunk_size, progress=sub(0.0, 0.3), should_stop=should_stop
    )
    LOG.info(
        "%s: %d points, CRS %s, distances in %s (%s)",
        input_path,
        info.point_count,
        info.crs.name if info.crs is not None else "?",
        "metres" if params.distance_unit == "metre" else info.horizontal_unit,
        "converted from metres" if params.distance_unit == "metre" else "the cloud's CRS unit",
    )
    result = ground_filter(
        arrays.pop("x"),
        arrays.pop("y"),
        arrays.pop("z"),
        params,
        return_number=arrays.get("return_number"),
        number_of_returns=arrays.get("number_of_returns"),
        unit_to_metre=info.unit_to_metre,
        vertical_unit_to_metre=info.vertical_unit_to_metre,
        unit=info.horizontal_unit,
        progress=sub(0.3, 0.6),
        should_stop=should_stop,
    )
    cls = arrays.pop("classification").copy()
    if non_ground_class is not None:
        cls[:] = non_ground_class
    else:
        cls[(cls == GROUND_CLASS) & ~result.ground] = UNCLASSIFIED_CLASS
    cls[result.ground] = GROUND_CLASS
    cls[result.low_outlier] = LOW_NOISE_CLASS
    write_cloud(
        input_path,
        output_path,
        classification=cls,
        extra={HEIGHT_FIELD: result.height_above_ground},
        chunk_size=chunk_size,
        progress=sub(0.6, 1.0),
        should_stop=should_stop,
    )
    return GroundFilterRun(
        result=result,
        point_count=info.point_count,
        ground_count=int(result.ground.sum()),
        low_outlier_count=int(result.low_outlier.sum()),
        unit="metre (converted)" if params.distance_unit == "metre" else info.horizontal_unit,
        crs_wkt=info.crs.to_wkt() if info.crs is not None else "",
        output=output_path,
    )


def write_geotiff(
    path: str,
    array: NDArray[np.float32],
    geotransform: Sequence[float],
    nodata: float,
    crs: Any = None,
) -> None:
    """Write a float32 north-up raster as an uncompressed GeoTIFF (no GDAL needed).

    The CRS is written as GeoTIFF keys when it has an EPSG code (the horizontal and vertical
    parts of a compound CRS separately); otherwise its WKT goes into a GDAL ``.aux.xml``
    sidecar. Written to a temporary file and moved into place.

    Parameters
    ----------
    path : str
        Destination ``.tif``.
    array : (rows, cols) float32
    geotransform : 6 floats, GDAL order (top-left corner, square cells, north up)
    nodata : float
    crs : str, int or pyproj.CRS, optional
    """
    import os
    import struct
    import tempfile

    from ..io.pointcloud import parse_crs

    data = np.ascontiguousarray(array, dtype="<f4")
    rows, cols = data.shape
    x0, cx, _, y_top, _, cy = (float(v) for v in geotransform)
    keys = [(1024, 0, 1, 1), (1025, 0, 1, 1)]  # projected model, PixelIsArea
    wkt = ""
    pcrs = parse_crs(crs)
    if pcrs is not None:
        horizontal = pcrs.sub_crs_list[0] if pcrs.is_compound else pcrs
        code = horizontal.to_epsg()
        if code:
            keys.append((3072, 0, 1, code))
            if pcrs.is_compound and len(pcrs.sub_crs_list) > 1:
                vcode = pcrs.sub_crs_list[1].to_epsg()
                if vcode:
                    keys.append((4096, 0, 1, vcode))
        else:
            wkt = pcrs.to_wkt()
    geokeys = [1, 1, 0, len(keys)] + [v for k in keys for v in k]
    nodata_text = f"{nodata:g}\0".encode("ascii")
    # (tag, type, values): types 3 SHORT, 4 LONG, 12 DOUBLE, 2 ASCII
    body = data.tobytes()
    entries: list[tuple[int, int, Any]] = [
        (256, 4, [cols]),
        (257, 4, [rows]),
        (258, 3, [32]),
        (259, 3, [1]),
        (262, 3, [1]),
        (273, 4, [0]),  # strip offset, patched below
        (277, 3, [1]),
        (278, 4, [rows]),
        (279, 4, [len(body)]),
        (284, 3, [1]),
        (339, 3, [3]),
        (33550, 12, [cx, -cy, 0.0]),
        (33922, 12, [0.0, 0.0, 0.0, x0, y_top, 0.0]),
        (34735, 3, geokeys),
        (42113, 2, nodata_text),
    ]
    fmt = {2: "s", 3: "H", 4: "I", 12: "d"}
    ifd_offset = 8
    ifd_size = 2 + 12 * len(entries) + 4
    extra_offset = ifd_offset + ifd_size
    extra = b""
    packed = []
    for tag, typ, values in entries:
        count = len(values)
        raw = values if typ == 2 else struct.pack(f"<{count}{fmt[typ]}", *values)
        packed.append((tag, typ, count, raw))
        if len(raw) > 4:
            extra += raw + (b"\0" if len(raw) % 2 else b"")
    strip_offset = extra_offset + len(extra)
    ifd = struct.pack("<H", len(entries))
    cursor = extra_offset
    for tag, typ, count, raw in packed:
        if tag == 273:
            raw = struct.pack("<I", strip_offset)
        if len(raw) > 4:
            ifd += struct.pack("<HHII", tag, typ, count, cursor)
            cursor += len(raw) + (len(raw) % 2)
        else:
            ifd += struct.pack("<HHI", tag, typ, count) + raw.ljust(4, b"\0")
    ifd += struct.pack("<I", 0)
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".dtm.", suffix=".tif.part", dir=folder)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(b"II*\0" + struct.pack("<I", ifd_offset) + ifd + extra + body)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise
    aux = path + ".aux.xml"
    if wkt:
        from xml.sax.saxutils import escape

        with open(aux, "w", encoding="utf-8") as fh:
            fh.write(f"<PAMDataset>\n  <SRS>{escape(wkt)}</SRS>\n</PAMDataset>\n")
