"""Relative accuracy of a LiDAR survey (ASPRS Ed. 2, 2023, relative accuracy of lidar): the
swaths (flight lines), the smooth hard cells of each swath, the swath overlap difference per
pair of swaths and the within-swath precision (smooth-surface repeatability).

Frames: x, y, z in one projected CRS (the cloud's units, metres for the standard's classes);
the grid is north-up, its corner on multiples of the cell size so that a cell is the same
cell whatever the extent read; a cell holds the returns on its west and north edges (columns
counted from the west, rows from the north). A cell of one swath is *smooth* when it holds at least
``min_points`` returns of that swath, none of a vegetation class, only single returns, and the
least-squares plane ``z = h + gx (x - xc) + gy (y - yc)`` through them (xc, yc: the cell
centre) has a slope at most ``max_slope_deg`` and residual rms at most ``max_residual``. Its
height ``h`` is the plane's height at the centre. The overlap difference of swaths a and b in
a cell smooth in both is ``dz = h_a - h_b``; the within-swath "Max Diff" of a cell is the
range (max - min) of its plane residuals.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from .lidar_accuracy_options import (
    SWATH_MAX_FACTOR,
    SWATH_RMSDZ_FACTOR,
    WITHIN_SWATH_FACTOR,
    LidarAccuracyOptions,
)

__all__ = [
    "CellGrid",
    "PairDifference",
    "SwathCells",
    "SwathPrecision",
    "finish_cells",
    "fit_cells",
    "identify_swaths",
    "overlap_differences",
    "pair_rasters",
    "swath_cells",
    "swath_headings",
    "within_swath_precision",
]

#: Why a cell of a swath is not smooth (the counts the report shows), in the order tested.
REJECTIONS = (
    "few returns",
    "vegetation class",
    "not a hard class",
    "multiple returns",
    "slope",
    "rough",
    "step",
)


def identify_swaths(
    point_source_id: NDArray | None,
    gps_time: NDArray | None,
    source: str = "auto",
    gap_s: float = 10.0,
) -> tuple[NDArray[np.int64], str]:
    """The swath of every point and how it was found.

    ``"point_source_id"``: the LAS point source id (the flight line). ``"gps_time"``: swaths
    are runs of points whose sorted GPS times (s) have no gap longer than ``gap_s``, numbered
    0, 1, ... in time order. ``"auto"``: the point source id when it holds more than one
    value, else the GPS time, else one swath by the id.

    >>> identify_swaths(None, np.array([0.0, 1.0, 50.0, 2.0]))
    (array([0, 0, 1, 0]), 'gps_time')
    """
    ids = None if point_source_id is None else np.asarray(point_source_id).astype(np.int64)
    if source == "auto":
        if ids is not None and np.unique(ids).size > 1:
            source = "point_source_id"
        elif gps_time is not None:
            source = "gps_time"
        elif ids is not None:
            source = "point_source_id"
        else:
            raise InputError("the cloud has neither point source ids nor GPS times")
    if source == "point_source_id":
        if ids is None:
            raise InputError("SWATH_SOURCE is point_source_id but the cloud has no such ids")
        return ids, source
    if source != "gps_time":
        raise InputError(f"unknown swath source {source!r}")
    if gps_time is None:
        raise InputError("SWATH_SOURCE is gps_time but the cloud has no GPS time")
    t = np.asarray(gps_time, dtype=np.float64)
    order = np.argsort(t, kind="stable")
    run = np.concatenate([[0], np.cumsum(np.diff(t[order]) > gap_s)]).astype(np.int64)
    labels = np.empty(t.size, dtype=np.int64)
    labels[order] = run
    return labels, source


@dataclass(frozen=True)
class CellGrid:
    """A north-up grid: top-left corner (x0, y_top), square ``cell``, ``cols`` x ``rows``."""

    x0: float
    y_top: float
    cell: float
    cols: int
    rows: int

    @classmethod
    def covering(cls, x: NDArray, y: NDArray, cell: float) -> CellGrid:
        """The grid of ``cell`` on multiples of the cell size that covers the points."""
        if not cell > 0:
            raise InputError(f"CELL_SIZE must be > 0, got {cell}")
        x0 = math.floor(float(np.min(x)) / cell) * cell
        y_top = (math.floor(float(np.max(y)) / cell) + 1) * cell
        cols = math.floor((float(np.max(x)) - x0) / cell) + 1
        rows = math.floor((y_top - float(np.min(y))) / cell) + 1
        return cls(x0, y_top, float(cell), cols, rows)

    def geotransform(self) -> tuple[float, float, float, float, float, float]:
        """GDAL order: top-left corner, cell, north up."""
        return (self.x0, self.cell, 0.0, self.y_top, 0.0, -self.cell)

    def centres(self, flat: NDArray[np.int64]) -> tuple[NDArray, NDArray]:
        """Centre coordinates of flat cell indices ``row * cols + col``."""
        row, col = np.divmod(np.asarray(flat, dtype=np.int64), self.cols)
        return self.x0 + (col + 0.5) * self.cell, self.y_top - (row + 0.5) * self.cell


@dataclass(frozen=True)
class _CellPlanes:
    """The plane fit ``z = height + gx dx + gy dy`` of (swath, cell) groups about the cell
    centres; heights, residuals and ranges in the cloud's z unit, ``gx``, ``gy`` dimensionless."""

    swath: NDArray[np.int64]
    cell: NDArray[np.int64]
    n: NDArray[np.int64]
    height: NDArray[np.float64]
    gx: NDArray[np.float64]
    gy: NDArray[np.float64]
    rms: NDArray[np.float64]
    ssr: NDArray[np.float64]
    range: NDArray[np.float64]


@dataclass(frozen=True)
class SwathCells(_CellPlanes):
    """The plane fit of every (swath, cell) holding returns, sorted by swath then cell.

    Heights, residuals and ranges in the cloud's z unit; ``gx``, ``gy`` dimensionless.
    """

    smooth: NDArray[np.bool_]
    rejected: dict[str, int] = field(default_factory=dict)

    @property
    def slope_deg(self) -> NDArray[np.float64]:
        return np.degrees(np.arctan(np.hypot(self.gx, self.gy)))


def _group_sums(values: list[NDArray], starts: NDArray) -> list[NDArray]:
    return [np.add.reduceat(v, starts) for v in values]


@dataclass(frozen=True)
class CellFits(_CellPlanes):
    """The plane fits of the (swath, cell) groups of one set of points (a tile or the whole
    cloud) and the per-cell tests passed (``passed[:, k]``: REJECTIONS[k], the neighbour step
    excepted: it needs the neighbours, :func:`finish_cells`)."""

    solvable: NDArray[np.bool_]
    passed: NDArray[np.bool_]


def swath_cells(
    x: NDArray,
    y: NDArray,
    z: NDArray,
    swath: NDArray,
    grid: CellGrid,
    options: LidarAccuracyOptions,
    classification: NDArray | None = None,
    number_of_returns: NDArray | None = None,
) -> SwathCells:
    """Fit a plane to the returns of each swath in each cell and flag the smooth hard cells.

    The points are put in a canonical order (swath, cell, x, y, z) before any sum, so the same
    points give the same figures to the last bit whatever their order in the file.

    >>> g = CellGrid(0.0, 2.0, 1.0, 2, 2)
    >>> xx, yy = np.meshgrid(np.linspace(0.05, 1.95, 10), np.linspace(0.05, 1.95, 10))
    >>> c = swath_cells(xx.ravel(), yy.ravel(), 0.1 * xx.ravel(), np.zeros(100, int), g,
    ...                 LidarAccuracyOptions())
    >>> c.n.tolist(), np.round(c.gx, 12).tolist(), c.smooth.tolist()
    ([25, 25, 25, 25], [0.1, 0.1, 0.1, 0.1], [True, True, True, True])
    """
    fits = fit_cells(x, y, z, swath, grid, options, classification, number_of_returns)
    return finish_cells([fits], grid, options)


def fit_cells(
    x: NDArray,
    y: NDArray,
    z: NDArray,
    swath: NDArray,
    grid: CellGrid,
    options: LidarAccuracyOptions,
    classification: NDArray | None = None,
    number_of_returns: NDArray | None = None,
    own: tuple[float, float, float, float] | None = None,
) -> CellFits:
    """The plane fits and per-cell tests of :func:`swath_cells`; with ``own`` (xmin, ymin,
    xmax, ymax, half-open) only the cells whose centre lies in it (a tile's cells: the points
    given must hold every return of those cells)."""
    x, y, z = (np.asarray(a, dtype=np.float64) for a in (x, y, z))
    keep = np.ones(x.size, dtype=bool)
    cls = None if classification is None else np.asarray(classification)
    if cls is not None and options.ignore_classes:
        keep &= ~np.isin(cls, options.ignore_classes)
    col = np.floor((x - grid.x0) / grid.cell).astype(np.int64)
    row = np.floor((grid.y_top - y) / grid.cell).astype(np.int64)
    keep &= (col >= 0) & (col < grid.cols) & (row >= 0) & (row < grid.rows)
    sw = np.asarray(swath, dtype=np.int64)[keep]
    flat = (row * grid.cols + col)[keep]
    x, y, z = x[keep], y[keep], z[keep]
    ncell = grid.rows * grid.cols
    names, sidx = np.unique(sw, return_inverse=True)
    key = sidx.astype(np.int64) * ncell + flat
    order = np.lexsort((z, y, x, key))
    key = key[order]
    if key.size == 0:
        if own is None:
            raise InputError("no returns inside the grid")
        e, b = np.zeros(0), np.zeros(0, bool)
        i = np.zeros(0, np.int64)
        return CellFits(i, i, i, e, e, e, e, e, e, b, np.zeros((0, len(REJECTIONS) - 1), bool))
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    n = np.diff(np.r_[starts, key.size])
    gkey = key[starts]
    gcell = gkey % ncell
    cx, cy = grid.centres(gcell)
    dx = x[order] - np.repeat(cx, n)
    dy = y[order] - np.repeat(cy, n)
    zz = z[order]
    zmean = np.add.reduceat(zz, starts) / n
    zc = zz - np.repeat(zmean, n)
    sx, sy, sz, sxx, sxy, syy, sxz, syz = _group_sums(
        [dx, dy, zc, dx * dx, dx * dy, dy * dy, dx * zc, dy * zc], starts
    )
    nf = n.astype(np.float64)
    normal = np.stack(
        [np.stack([nf, sx, sy], -1), np.stack([sx, sxx, sxy], -1), np.stack([sy, sxy, syy], -1)],
        -2,
    )
    det = np.linalg.det(normal)
    scale = nf * np.maximum(sxx * syy, 1e-300) * nf
    solvable = (n >= 3) & (np.abs(det) > 1e-9 * scale)
    p = np.zeros((n.size, 3))
    if solvable.any():
        rhs = np.stack([sz, sxz, syz], -1)[solvable]
        p[solvable] = np.linalg.solve(normal[solvable], rhs[..., None])[..., 0]
    resid = zc - (np.repeat(p[:, 0], n) + np.repeat(p[:, 1], n) * dx + np.repeat(p[:, 2], n) * dy)
    ssr = np.add.reduceat(resid * resid, starts)
    rms = np.sqrt(ssr / np.maximum(n - 3, 1))
    rng = np.maximum.reduceat(resid, starts) - np.minimum.reduceat(resid, starts)
    slope = np.degrees(np.arctan(np.hypot(p[:, 1], p[:, 2])))
    # at least 4 returns: a plane through 3 has no residual to judge it by
    tests = [(n >= max(options.min_points, 4)) & solvable]
    if cls is not None and options.vegetation_classes:
        veg = np.isin(cls[keep][order], options.vegetation_classes)
        tests.append(np.add.reduceat(veg.astype(np.int64), starts) == 0)
    else:
        tests.append(np.ones(n.size, dtype=bool))
    if cls is not None and options.hard_classes:
        soft = ~np.isin(cls[keep][order], options.hard_classes)
        tests.append(np.add.reduceat(soft.astype(np.int64), starts) == 0)
    else:
        tests.append(np.ones(n.size, dtype=bool))
    if number_of_returns is not None and options.single_returns:
        multi = np.asarray(number_of_returns)[keep][order] > 1
        tests.append(np.add.reduceat(multi.astype(np.int64), starts) == 0)
    else:
        tests.append(np.ones(n.size, dtype=bool))
    tests.append(slope <= options.max_slope_deg)
    tests.append(rms <= options.max_residual)
    keep_g = np.ones(n.size, dtype=bool)
    if own is not None:
        keep_g = (cx >= own[0]) & (cx < own[2]) & (cy >= own[1]) & (cy < own[3])
    k = keep_g
    return CellFits(
        swath=names[gkey // ncell][k],
        cell=gcell[k],
        n=n.astype(np.int64)[k],
        height=(zmean + p[:, 0])[k],
        gx=p[:, 1][k],
        gy=p[:, 2][k],
        rms=np.where(solvable, rms, np.nan)[k],
        ssr=ssr[k],
        range=rng[k],
        solvable=solvable[k],
        passed=np.column_stack(tests)[k],
    )


def finish_cells(fits: Sequence[CellFits], grid: CellGrid, options: LidarAccuracyOptions):
    """Join the fits of tiles (each cell in one of them), test each cell against its
    neighbours' planes and flag the smooth ones: a :class:`SwathCells` sorted by swath, cell
    (the same whatever the tiling)."""
    parts = list(fits)
    cat = {f: np.concatenate([getattr(p, f) for p in parts]) for f in CellFits.__dataclass_fields__}
    order = np.lexsort((cat["cell"], cat["swath"]))
    c = {f: v[order] for f, v in cat.items()}
    sidx = np.unique(c["swath"], return_inverse=True)[1]
    ncell = grid.rows * grid.cols
    gkey = sidx.astype(np.int64) * ncell + c["cell"]
    if np.any(np.diff(gkey) == 0):
        raise ValueError("a cell was fitted in two tiles")
    step = _continuous(
        gkey, c["cell"], c["height"], c["gx"], c["gy"], c["solvable"], grid, options.max_step
    )
    tests = [*c["passed"].T, step]
    smooth = np.ones(gkey.size, dtype=bool)
    rejected: dict[str, int] = {}
    for name, ok in zip(REJECTIONS, tests):
        rejected[name] = int(np.count_nonzero(smooth & ~ok))
        smooth &= ok
    planes = {f: c[f] for f in _CellPlanes.__dataclass_fields__}
    return SwathCells(**planes, smooth=smooth, rejected=rejected)


def _continuous(
    gkey: NDArray[np.int64],
    gcell: NDArray[np.int64],
    height: NDArray[np.float64],
    gx: NDArray[np.float64],
    gy: NDArray[np.float64],
    solvable: NDArray[np.bool_],
    grid: CellGrid,
    max_step: float,
) -> NDArray[np.bool_]:
    """True where every fitted 4-neighbour cell of the same swath continues the cell's plane
    (its centre height within ``max_step`` of the plane extended to it)."""
    ok = np.ones(gkey.size, dtype=bool)
    row, col = np.divmod(gcell, grid.cols)
    c = grid.cell
    for drow, dcol in ((0, 1), (0, -1), (1, 0), (-1, 0)):
        inside = (
            (col + dcol >= 0)
            & (col + dcol < grid.cols)
            & (row + drow >= 0)
            & (row + drow < grid.rows)
        )
        want = gkey + drow * grid.cols + dcol
        j = np.clip(np.searchsorted(gkey, want), 0, gkey.size - 1)
        found = inside & (gkey[j] == want) & solvable[j]
        # rows grow southwards: one row down is -c in y
        predicted = height + gx * (dcol * c) - gy * (drow * c)
        ok &= ~found | (np.abs(height[j] - predicted) <= max_step)
    return ok


@dataclass(frozen=True)
class SwathPrecision:
    """Within-swath precision of one swath on its smooth cells (z unit).

    ``rms``: pooled rms of the plane residuals, sqrt(sum ssr / sum (n - 3)); ``range_*``: the
    per-cell Max Diff (max - min residual), its median, 95th percentile and maximum.
    """

    swath: int
    cells: int
    rms: float
    range_median: float
    range_p95: float
    range_max: float


def within_swath_precision(cells: SwathCells) -> list[SwathPrecision]:
    """Smooth-surface repeatability per swath (a swath without smooth cells: NaN figures)."""
    out = []
    for s in np.unique(cells.swath):
        m = (cells.swath == s) & cells.smooth
        k = int(np.count_nonzero(m))
        if k == 0:
            out.append(SwathPrecision(int(s), 0, math.nan, math.nan, math.nan, math.nan))
            continue
        dof = float(np.sum(cells.n[m] - 3))
        r = cells.range[m]
        out.append(
            SwathPrecision(
                int(s),
                k,
                math.sqrt(float(np.sum(cells.ssr[m])) / dof) if dof > 0 else math.nan,
                float(np.median(r)),
                float(np.percentile(r, 95.0)),
                float(np.max(r)),
            )
        )
    return out


def swath_headings(swath: NDArray, x: NDArray, y: NDArray, t: NDArray) -> dict[int, float]:
    """Flight direction of each swath (radians, counter-clockwise from grid east) from the
    least-squares velocity of x(t), y(t); swaths whose time span is zero are left out."""
    out: dict[int, float] = {}
    swath = np.asarray(swath)
    for s in np.unique(swath):
        m = swath == s
        tt = np.asarray(t, dtype=np.float64)[m]
        tc = tt - tt.mean()
        den = float(np.dot(tc, tc))
        if den <= 0:
            continue
        vx = float(np.dot(tc, np.asarray(x)[m] - np.mean(np.asarray(x)[m]))) / den
        vy = float(np.dot(tc, np.asarray(y)[m] - np.mean(np.asarray(y)[m]))) / den
        if vx or vy:
            out[int(s)] = math.atan2(vy, vx)
    return out


@dataclass(frozen=True)
class PairDifference:
    """The overlap difference ``dz = h_a - h_b`` of two swaths on their common smooth cells.

    ``tilt``: the plane ``dz = c0 + gx (x - xm) + gy (y - ym)`` fitted to the cells (xm, ym:
    the cells' mean centre) with its standard errors ``tilt_se`` (None with under 3 cells or
    collinear cells); ``cross_track_slope``: the gradient across swath a's flight direction
    (positive to the left of it; None without a heading), dimensionless.
    """

    swath_a: int
    swath_b: int
    cells: NDArray[np.int64]
    x: NDArray[np.float64]
    y: NDArray[np.float64]
    dz: NDArray[np.float64]
    dn: NDArray[np.float64]
    tilt: tuple[float, float, float] | None
    tilt_se: tuple[float, float, float] | None
    cross_track_slope: float | None = None

    @property
    def n(self) -> int:
        return int(self.dz.size)

    def stats(self) -> dict[str, float]:
        """Count, mean, standard deviation, RMSDz, max |dz| and the surface-normal RMSD."""
        return difference_stats(self.dz, self.dn)


def difference_stats(dz: NDArray, dn: NDArray | None = None) -> dict[str, float]:
    """The figures of a set of differences (NaN when empty).

    >>> difference_stats(np.array([0.03, -0.04]))["rmsdz"]
    0.035355339059327376
    """
    dz = np.asarray(dz, dtype=np.float64)
    if dz.size == 0:
        nan = math.nan
        return {"n": 0, "mean": nan, "std": nan, "rmsdz": nan, "max_abs": nan, "rmsd_normal": nan}
    dn = dz if dn is None else np.asarray(dn, dtype=np.float64)
    return {
        "n": int(dz.size),
        "mean": float(np.mean(dz)),
        "std": float(np.std(dz, ddof=1)) if dz.size > 1 else math.nan,
        "rmsdz": float(np.sqrt(np.mean(dz * dz))),
        "max_abs": float(np.max(np.abs(dz))),
        "rmsd_normal": float(np.sqrt(np.mean(dn * dn))),
    }


def _tilt(x: NDArray, y: NDArray, dz: NDArray):
    if dz.size < 4:
        return None, None
    a = np.column_stack([np.ones_like(x), x - x.mean(), y - y.mean()])
    ata = a.T @ a
    if np.linalg.cond(ata) > 1e12:
        return None, None
    p = np.linalg.solve(ata, a.T @ dz)
    r = dz - a @ p
    s2 = float(r @ r) / (dz.size - 3)
    se = np.sqrt(np.diag(np.linalg.inv(ata)) * s2)
    return tuple(float(v) for v in p), tuple(float(v) for v in se)


def overlap_differences(
    cells: SwathCells, grid: CellGrid, headings: dict[int, float] | None = None
) -> list[PairDifference]:
    """The overlap difference of every pair of swaths (a < b) that share smooth cells."""
    smooth = cells.smooth
    swaths = [int(s) for s in np.unique(cells.swath[smooth])]
    by_swath = {}
    for s in swaths:
        m = smooth & (cells.swath == s)
        by_swath[s] = (cells.cell[m], cells.height[m], cells.gx[m], cells.gy[m])
    out = []
    for i, a in enumerate(swaths):
        for b in swaths[i + 1 :]:
            ca, ha, gxa, gya = by_swath[a]
            cb, hb, gxb, gyb = by_swath[b]
            common, ia, ib = np.intersect1d(ca, cb, assume_unique=True, return_indices=True)
            if common.size == 0:
                continue
            dz = ha[ia] - hb[ib]
            gx = 0.5 * (gxa[ia] + gxb[ib])
            gy = 0.5 * (gya[ia] + gyb[ib])
            dn = dz / np.sqrt(1.0 + gx * gx + gy * gy)  # vertical -> along the mean normal
            x, y = grid.centres(common)
            tilt, se = _tilt(x, y, dz)
            cross = None
            if tilt is not None and headings and a in headings:
                h = headings[a]
                cross = -math.sin(h) * tilt[1] + math.cos(h) * tilt[2]
            out.append(PairDifference(a, b, common, x, y, dz, dn, tilt, se, cross))
    return out


def relative_limits(v_class_cm: float) -> dict[str, float]:
    """ASPRS Ed. 2 relative accuracy limits (m) for a vertical class (cm), our reading.

    >>> relative_limits(10.0)["swath_rmsdz"]
    0.08
    """
    c = float(v_class_cm) / 100.0
    return {
        "within_swath_max": round(WITHIN_SWATH_FACTOR * c, 12),
        "swath_rmsdz": round(SWATH_RMSDZ_FACTOR * c, 12),
        "swath_max": round(SWATH_MAX_FACTOR * c, 12),
    }


def pair_rasters(pairs: list[PairDifference], grid: CellGrid) -> NDArray[np.float32]:
    """(pairs, rows, cols) float32: each pair's dz in its cells, NaN elsewhere."""
    out = np.full((max(len(pairs), 1), grid.rows, grid.cols), np.nan, dtype=np.float32)
    for k, p in enumerate(pairs):
        row, col = np.divmod(p.cells, grid.cols)
        out[k, row, col] = p.dz
    return out
