"""Absolute vertical accuracy of a LiDAR ground surface at surveyed check points (ASPRS Ed. 2,
2023): NVA on non-vegetated check points (RMSE, pass/fail against a class) and VVA on
vegetated ones (reported only).

The LiDAR height at a check point is the linear interpolation in a TIN (Delaunay
triangulation, scipy) of the ground returns near it, not the nearest return: check points
rarely fall on a return. Discrepancies are ``dz = h_lidar - h_check`` (measured minus
reference, the toolkit's sign). Figures:

* NVA: count, mean, standard deviation, RMSE_V1 of the dz, RMSE_V = sqrt(RMSE_V1^2 +
  survey_sigma_v^2) (Ed. 2 adds the check-point survey error), and 1.96 RMSE_V, the 95 %
  figure of Ed. 1 / NSSDA (reported for comparison; Ed. 2 states accuracy as RMSE only).
* VVA: count, RMSE, and the 95th percentile of |dz| (Ed. 1's VVA measure; numpy's linear
  interpolation between order statistics, Excel's PERCENTILE.INC).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from .lidar_accuracy_options import LidarAccuracyOptions

__all__ = ["CheckHeights", "VerticalFigures", "ground_tin_heights", "vertical_figures"]


@dataclass(frozen=True)
class CheckHeights:
    """The LiDAR ground height at each check point (NaN outside the TIN) and the distance to
    the nearest ground return (a large one: the TIN bridges a gap there)."""

    lidar_h: NDArray[np.float64]
    nearest: NDArray[np.float64]
    tin_points: int


def ground_tin_heights(
    ground_xyz: NDArray, check_xy: NDArray, radius: float = 10.0
) -> CheckHeights:
    """Interpolate the TIN of the ground returns within ``radius`` of any check point.

    Returns at one (x, y) more than once keep the lowest (a fixed choice, so the surface does
    not depend on the order of the points).

    >>> g = np.array([[0, 0, 1.0], [10, 0, 2.0], [0, 10, 3.0], [10, 10, 4.0]])
    >>> ground_tin_heights(g, np.array([[2.5, 5.0]]), radius=20).lidar_h.round(12).tolist()
    [2.25]
    """
    from scipy.spatial import Delaunay, cKDTree

    g = np.asarray(ground_xyz, dtype=np.float64)
    q = np.asarray(check_xy, dtype=np.float64).reshape(-1, 2)
    if g.ndim != 2 or g.shape[0] < 3:
        raise InputError("fewer than 3 ground returns: no TIN for the check points")
    tree = cKDTree(g[:, :2])
    nearest = tree.query(q)[0]
    near = tree.query_ball_point(q, float(radius))
    idx = np.unique(np.concatenate([np.asarray(i, dtype=np.int64) for i in near] + [[]]))
    idx = idx.astype(np.int64)
    sub = g[idx]
    if sub.shape[0] < 3:
        return CheckHeights(np.full(len(q), np.nan), nearest, int(sub.shape[0]))
    order = np.lexsort((sub[:, 2], sub[:, 1], sub[:, 0]))
    sub = sub[order]
    first = np.r_[True, np.any(np.diff(sub[:, :2], axis=0) != 0, axis=1)]
    sub = sub[first]
    if sub.shape[0] < 3:
        return CheckHeights(np.full(len(q), np.nan), nearest, int(sub.shape[0]))
    try:
        tri = Delaunay(sub[:, :2])
    except Exception as exc:  # qhull: all returns on one line
        raise InputError(f"the ground returns near the check points make no TIN: {exc}") from exc
    return CheckHeights(_interpolate(tri, sub[:, 2], q), nearest, int(sub.shape[0]))


def _barycentric(tri, simplex: NDArray[np.int64], q: NDArray) -> NDArray[np.float64]:
    """(M, 3) barycentric coordinates of q[m] in triangle simplex[m]."""
    v = tri.points[tri.simplices[simplex]]  # (M, 3, 2)
    t = np.stack([v[:, 0] - v[:, 2], v[:, 1] - v[:, 2]], axis=-1)  # columns: edges to v2
    rhs = q - v[:, 2]
    det = t[:, 0, 0] * t[:, 1, 1] - t[:, 0, 1] * t[:, 1, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        b0 = (rhs[:, 0] * t[:, 1, 1] - rhs[:, 1] * t[:, 0, 1]) / det
        b1 = (t[:, 0, 0] * rhs[:, 1] - t[:, 1, 0] * rhs[:, 0]) / det
    return np.column_stack([b0, b1, 1.0 - b0 - b1])


def _interpolate(tri, z: NDArray, q: NDArray, k: int = 12) -> NDArray[np.float64]:
    """Linear interpolation in the TIN at q (NaN outside it).

    scipy's find_simplex first builds the barycentric transform of every triangle (seconds
    for 10^5 triangles), so the containing triangle is searched among those incident to the
    k returns nearest to each point, and only points not found there (rare) go to
    find_simplex. The result is the same triangle either way (ties on a shared edge give
    the same height).
    """
    from scipy.spatial import cKDTree

    flat = tri.simplices.ravel()
    by_vertex = np.argsort(flat, kind="stable")
    owner = by_vertex // 3
    first = np.searchsorted(flat[by_vertex], np.arange(tri.npoints + 1))
    near = cKDTree(tri.points).query(q, k=min(k, tri.npoints))[1].reshape(len(q), -1)
    out = np.full(len(q), np.nan)
    missing = []
    for m in range(len(q)):
        cand = np.unique(np.concatenate([owner[first[v] : first[v + 1]] for v in near[m]]))
        b = _barycentric(tri, cand, np.broadcast_to(q[m], (cand.size, 2)))
        inside = np.flatnonzero(np.all(b >= -1e-12, axis=1))
        if inside.size:
            j = inside[0]
            out[m] = float(b[j] @ z[tri.simplices[cand[j]]])
        else:
            missing.append(m)
    if missing:
        rest = q[missing]
        simplex = tri.find_simplex(rest)
        ok = simplex >= 0
        if ok.any():
            b = _barycentric(tri, simplex[ok], rest[ok])
            out[np.asarray(missing)[ok]] = np.sum(b * z[tri.simplices[simplex[ok]]], axis=1)
    return out


@dataclass(frozen=True)
class VerticalFigures:
    """NVA and VVA figures (m) and which check points went where.

    ``nva_*`` over non-vegetated points, ``vva_*`` over vegetated ones; ``outside``: ids of
    check points outside the TIN (not assessed).
    """

    dz: NDArray[np.float64]
    vegetated: NDArray[np.bool_]
    outside: tuple[str, ...]
    nva_n: int
    nva_mean: float
    nva_std: float
    nva_rmse_v1: float
    nva_rmse_v: float
    nva_95: float
    vva_n: int
    vva_rmse: float
    vva_p95: float


def _is_vegetated(groups, options: LidarAccuracyOptions) -> NDArray[np.bool_]:
    names = {g.strip().lower() for g in options.vegetated_groups}
    return np.array([str(g).strip().lower() in names for g in groups], dtype=bool)


def vertical_figures(
    ids, check_h: NDArray, groups, heights: CheckHeights, options: LidarAccuracyOptions
) -> VerticalFigures:
    """NVA and VVA of the check points (``groups``: their land-cover class).

    >>> h = CheckHeights(np.array([1.1, 0.9, 2.3]), np.zeros(3), 10)
    >>> f = vertical_figures(["a", "b", "c"], np.array([1.0, 1.0, 2.0]), ["open", "open",
    ...     "forest"], h, LidarAccuracyOptions())
    >>> round(f.nva_rmse_v, 12), f.vva_n, round(f.vva_p95, 12)
    (0.1, 1, 0.3)
    """
    check_h = np.asarray(check_h, dtype=np.float64)
    dz = heights.lidar_h - check_h
    inside = np.isfinite(dz)
    veg = _is_vegetated(groups, options)
    outside = tuple(str(i) for i, ok in zip(ids, inside) if not ok)
    nva = dz[inside & ~veg]
    vva = dz[inside & veg]
    nan = math.nan
    rmse1 = float(np.sqrt(np.mean(nva * nva))) if nva.size else nan
    rmse_v = math.hypot(rmse1, float(options.survey_sigma_v)) if nva.size else nan
    return VerticalFigures(
        dz=dz,
        vegetated=veg,
        outside=outside,
        nva_n=int(nva.size),
        nva_mean=float(np.mean(nva)) if nva.size else nan,
        nva_std=float(np.std(nva, ddof=1)) if nva.size > 1 else nan,
        nva_rmse_v1=rmse1,
        nva_rmse_v=rmse_v,
        nva_95=1.96 * rmse_v,
        vva_n=int(vva.size),
        vva_rmse=float(np.sqrt(np.mean(vva * vva))) if vva.size else nan,
        vva_p95=float(np.percentile(np.abs(vva), 95.0)) if vva.size else nan,
    )
