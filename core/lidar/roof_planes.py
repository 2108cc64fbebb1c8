"""Roof planes from non-ground LiDAR points: local RANSAC, region growing, plane precision.

Method (Pedrosa & dos Santos 2020, section 2.1, made rigorous; every length in the cloud's CRS
unit):

1. **Local RANSAC** (paper's conditions a and b; :mod:`core.lidar.roof_planes_local`). For
   every point, its ``k_neighbours`` nearest neighbours (the point included, ties by the
   sorted order) get ``ransac_iterations`` triplets; the plane with the most neighbours within
   ``epsilon`` wins (the paper's "plane with the largest number of points"). It is refined by
   least squares on its inliers. The point is kept when the plane has at least
   ``min_support`` inliers, the point lies within ``epsilon`` of it and its slope is in
   ``[min_slope_deg, max_slope_deg]`` (vegetation has no supported plane; walls are too
   steep). The triplets are not random draws: one of 256 fixed tables of neighbour ranks
   (``roof_planes_local.triplets``), picked by a hash of the point's coordinates, so a point's
   local plane depends on its neighbours alone, whatever the seed, the batch, the thread count
   or the tile.
2. **Region growing** (:mod:`core.lidar.roof_planes_regions`) from seeds (the best-fitting
   kept point of each voxel of a grid on the map coordinates, its size a power of two from
   the local spacing) in waves over the
   ``GROW_NEIGHBOURS`` nearest neighbours: a kept neighbour joins when it lies within
   ``epsilon`` of the region's current plane and its local normal is within
   ``angle_tolerance_deg`` of the region's.
3. **Clean-up**: components smaller than ``min_plane_points`` are dropped; each region is
   refitted, points farther than ``epsilon`` from it are released; then every point of the
   input (kept or not: ridge and eave points often fail step 1 because their neighbourhood
   straddles two faces) is assigned to the nearest plane among those of its neighbours when it
   lies within ``epsilon`` (``REASSIGN_PASSES`` times, refitting in between); adjacent planes
   that are coplanar (normals within ``angle_tolerance_deg``, each centroid within ``epsilon``
   of the other plane) are merged; regions below ``min_plane_points`` are dropped again.
4. **Fit** of each region by :func:`lidarphoto.core.geometry.planes.fit_plane` (Pathak's weighted
   eigen method on centred coordinates, covariance, sigma_d), ids ordered by decreasing point
   count (ties: first sorted point), and an **outline**: the plane's points rasterised in x, y
   at ``outline_cell`` (default: the median distance to the 4th nearest neighbour, about one
   point spacing), closed morphologically (3x3, OpenCV), the outer contour of the largest
   blob (cv2.findContours) simplified by Douglas-Peucker at half a cell, counter-clockwise in
   x, y, with z on the plane.
   It is a concave hull for display, not a measured building outline.

**Repeatable**: the points are sorted by grid cell and, within a cell, by their coordinates;
every tie goes to the lower sorted index and every sum runs in that order; the local and the
region normals and the final fits (:func:`core.geometry.planes.fit_planes`: sums in point
order, :mod:`core.geometry.sym3`) come from fixed Jacobi rotations (IEEE +, -, *, /, sqrt), not
BLAS or LAPACK, so neither the assignments nor the plane parameters depend on the BLAS/LAPACK
build, its threads or the numpy version. The same point set gives the same planes bit for
bit whatever the order of the points, the seed or the number of threads
(tests/core/test_roof_planes_repeatable.py), and a tile holding a buffer of
:func:`core.lidar.block.roof_buffer` the whole file's local planes and seeds on its core.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError, stop_if_asked
from ..geometry.planes import Plane, fit_plane, fit_planes
from ..i18n import mark as _t
from .roof_plane_params import SELECTION_CHOICES, RoofPlaneParams
from .roof_planes_local import (  # noqa: F401 - _jacobi_normals for the back-end tests
    Array,
    Progress,
    ShouldStop,
    _jacobi_normals,
    _local_planes,
    _spatial_order,
    _use_numba,
)
from .roof_planes_regions import (
    _drop_small,
    _grow,
    _merge_coplanar,
    _reassign,
    _release_far,
)

__all__ = ["SELECTION_CHOICES", "RoofPlaneParams", "RoofPlaneResult", "extract_roof_planes"]

log = logging.getLogger(__name__)

#: catalogue context of this module's ``_t("...")`` sentences (the log and the report)
TR_CONTEXT = "Report"

#: Reassignment passes (each reaches one more ring of unassigned points around a plane).
REASSIGN_PASSES = 3


@dataclass(frozen=True)
class RoofPlaneResult:
    """Planes found and the plane id of every input point.

    Attributes
    ----------
    planes : tuple of Plane
        Ids 0..P-1, by decreasing point count.
    plane_id : ndarray, shape (N,), int32
        Plane of each input point, -1 for none.
    n_candidates : int
        Points kept by the local RANSAC (step 1).
    outline_cell : float
        Raster cell used for the outlines, CRS unit.
    message : str
        Human-readable summary (says so when no plane was found).
    fit_mask : ndarray, shape (N,), bool, optional
        The interior points of the planes (see ``_final_planes``): a plane is fitted to these,
        or to all its points when fewer than half are interior; a merge of plane pieces
        refits by the same rule.
    """

    planes: tuple[Plane, ...]
    plane_id: NDArray[np.int32]
    n_candidates: int
    outline_cell: float
    message: str = ""
    fit_mask: NDArray[np.bool_] | None = None


def _outline(xyz: Array, plane: Plane, cell: float) -> Array:
    """Concave outline (M, 3) of a plane's points: raster mask, closing, outer contour."""
    import cv2

    xy = xyz[:, :2]
    lo = xy.min(axis=0)
    span = xy.max(axis=0) - lo
    cell = max(cell, float(span.max()) / 4000.0, 1e-9)  # bounded raster size
    ij = np.floor((xy - lo) / cell).astype(np.int64) + 2  # 2-cell margin for the closing
    w, h = int(ij[:, 0].max()) + 3, int(ij[:, 1].max()) + 3
    mask = np.zeros((h, w), dtype=np.uint8)
    mask[ij[:, 1], ij[:, 0]] = 255
    mask = cv2.morphologyEx(mask, cv2.MORPH_CLOSE, np.ones((3, 3), np.uint8))
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    if not contours:
        return np.empty((0, 3))
    biggest = max(contours, key=lambda c: (cv2.contourArea(c), len(c)))
    poly = cv2.approxPolyDP(biggest, 0.5, True).reshape(-1, 2).astype(np.float64)
    if len(poly) < 3:
        poly = biggest.reshape(-1, 2).astype(np.float64)
    # cell (i, j) covers [i, i + 1) * cell from lo - 2 cells: its centre is at i + 0.5
    pxy = lo + (poly - 2 + 0.5) * cell
    x, y = pxy[:, 0], pxy[:, 1]
    # shoelace (fsum: exactly rounded, no BLAS dot): clockwise
    if math.fsum((x * np.roll(y, -1) - np.roll(x, -1) * y).tolist()) < 0:
        pxy = pxy[::-1]
    a, b, c = plane.normal
    z = (
        plane.centroid[2]
        - (a * (pxy[:, 0] - plane.centroid[0]) + b * (pxy[:, 1] - plane.centroid[1])) / c
    )
    return np.column_stack([pxy, z])


def extract_roof_planes(
    points: ArrayLike,
    params: RoofPlaneParams | None = None,
    *,
    progress: Progress = None,
    should_stop: ShouldStop = None,
    backend: str = "auto",
) -> RoofPlaneResult:
    """Find roof planes in non-ground points (module docstring: method).

    Parameters
    ----------
    points : array_like, shape (N, 3)
        Non-ground points in a projected CRS (x, y, z in one unit).
    params : RoofPlaneParams, optional
        Lengths in the same unit as the points. Default: ``RoofPlaneParams()`` (metres).
    progress : callable, optional
        Receives the fraction done in [0, 1] after each batch.
    should_stop : callable, optional
        Checked per batch; True raises :class:`Cancelled`.
    backend : {"auto", "numba", "numpy"}
        The neighbour search and local RANSAC compiled with numba
        (:mod:`core.lidar.roof_planes_numba`, optional dependency) or with scipy's cKDTree and
        numpy; "auto" takes numba when it imports. Both give the same planes.

    Returns
    -------
    RoofPlaneResult
        With zero planes (and a message saying so) when nothing planar and roof-like is found;
        that is not an error.

    Raises
    ------
    InputError
        Points of a wrong shape or not finite.
    Cancelled
        When ``should_stop()`` returns True.

    Examples
    --------
    >>> from lidarphoto.core.simulation.town import simulate_town
    >>> town, pts = simulate_town(n_buildings=2, n_trees=0, density=6.0, seed=2)
    >>> res = extract_roof_planes(pts.xyz[pts.classification != 2])
    >>> len(res.planes), len(town.faces)
    (6, 6)
    """
    params = params or RoofPlaneParams()
    xyz = np.asarray(points, dtype=np.float64)
    if xyz.ndim != 2 or xyz.shape[1] != 3:
        raise InputError(f"points must have shape (N, 3), got {xyz.shape}")
    if not np.isfinite(xyz).all():
        raise InputError("points contain NaN or infinite coordinates")
    n = len(xyz)
    empty = np.full(n, -1, dtype=np.int32)
    if n < max(params.min_plane_points, params.k_neighbours):
        msg = _t("no roof plane: only {n} candidate points (fewer than needed for one plane)", n=n)
        log.info(msg)
        return RoofPlaneResult((), empty, 0, params.outline_cell, msg)
    # centred once: map coordinates (1e5-1e6) would cost digits in every product below
    origin = np.floor(xyz.min(axis=0))
    stop_if_asked(should_stop, "extracting roof planes")
    # the work runs on the points sorted by grid cell (neighbours close in memory); the order
    # is part of the method (ties, batches), the same for both back ends
    compiled = _use_numba(backend)
    order, grid = _spatial_order(xyz, origin, params.k_neighbours, compiled)
    q = grid.q
    keep, normals, quality, knn, spacing_of = _local_planes(
        grid, params, backend, progress, should_stop
    )
    del grid
    n_cand = int(keep.sum())
    log.info("local RANSAC kept %d of %d points (%.1f %%)", n_cand, n, 100.0 * n_cand / n)
    labels = _grow(
        q, keep, normals, quality, knn, spacing_of, params, should_stop, compiled, origin
    )
    del normals, quality
    if progress is not None:
        progress(0.8)
    eps = params.epsilon
    labels = _drop_small(_merge_coplanar(q, labels, knn, params, compiled), params.min_plane_points)
    for _ in range(2):
        labels = _drop_small(_release_far(q, labels, eps, compiled), params.min_plane_points)
    for _ in range(REASSIGN_PASSES):
        labels = _drop_small(
            _reassign(q, labels, knn, eps, params.batch_size * 8, should_stop, compiled)[0],
            params.min_plane_points,
        )
    labels = _merge_coplanar(q, labels, knn, params, compiled)
    labels, ambiguous = _reassign(q, labels, knn, eps, params.batch_size * 8, should_stop, compiled)
    labels = _drop_small(labels, params.min_plane_points)
    if progress is not None:
        progress(0.9)
    cell = params.outline_cell or float(np.median(spacing_of))
    # points of the region's interior only: a point with a neighbour outside its plane is at a
    # ridge or an eave (where wall points attach), on one side of the plane
    interior = np.empty(n, dtype=bool)
    for lo in range(0, n, 1 << 20):  # (N, G) comparisons in slices: bounded memory
        hi = min(n, lo + (1 << 20))
        interior[lo:hi] = (labels[knn[lo:hi]] == labels[lo:hi, None]).all(axis=1)
    fit_sorted = keep & ~ambiguous & interior
    del q, knn, interior, ambiguous, spacing_of  # the fits need the points and labels only
    planes, pid_sorted = _final_planes(xyz, order, labels, fit_sorted, cell, progress, should_stop)
    # back to the input's order (the work ran on the sorted points)
    plane_id = np.empty(n, dtype=np.int32)
    plane_id[order] = pid_sorted
    fit_mask = np.zeros(n, dtype=bool)
    fit_mask[order] = fit_sorted & (pid_sorted >= 0)
    if planes:
        msg = _t(
            "{planes} roof planes, {assigned} of {n} points assigned ({kept} kept by the local "
            "RANSAC)",
            planes=len(planes),
            assigned=int((plane_id >= 0).sum()),
            n=n,
            kept=n_cand,
        )
    else:
        msg = _t(
            "no roof plane found among {n} points ({kept} passed the local RANSAC test): the "
            "cloud has no planar, roof-like surfaces with these parameters",
            n=n,
            kept=n_cand,
        )
    log.info(msg)
    return RoofPlaneResult(tuple(planes), plane_id, n_cand, float(cell), msg, fit_mask)


def _final_planes(
    xyz: Array,
    order: NDArray[np.int64],
    labels: NDArray[np.int64],
    fit_mask: NDArray[np.bool_],
    cell: float,
    progress: Progress,
    should_stop: ShouldStop,
) -> tuple[list[Plane], NDArray[np.int32]]:
    """Plane fits (:func:`fit_planes`) + outline per region of the sorted points (``xyz[order]``,
    ``labels`` and ``fit_mask`` in that order); ids by decreasing size (ties: first sorted
    point). Returns the planes and the plane id of every sorted point.

    Only ``fit_mask`` points enter the fit: points kept by the local RANSAC (their whole
    neighbourhood is planar), not within epsilon of a second plane and whose neighbours all
    belong to the same plane (the region's interior). Points at its edge (ridges, hips, eaves,
    and wall points just below the eaves that lie within epsilon) keep their plane id but sit
    on one side of the plane: fitted, they tilted the planes of the synthetic town by 1.2-1.5x
    the variance the covariance reports; without them the normals scatter 1.09x and sigma_d
    1.10x their reported variance over 160 noise draws (tests/core/test_roof_planes.py). A
    region with fewer than half its points in the mask is fitted with all of them. Sums run
    in the sorted order: the planes do not depend on the order of the input.
    """
    n = len(labels)
    plane_id = np.full(n, -1, dtype=np.int32)
    m = np.flatnonzero(labels >= 0)
    if not len(m):
        return [], plane_id
    lab = labels[m]
    counts = np.bincount(lab)
    first = np.full(len(counts), n, dtype=np.int64)
    np.minimum.at(first, lab, m)
    rank_order = np.lexsort((first, -counts))
    rank = np.empty(len(counts), dtype=np.int64)
    rank[rank_order] = np.arange(len(counts))
    pid_m = rank[lab]
    plane_id[m] = pid_m
    pts = xyz[order[m]]  # the plane points only, in the sorted order
    sort = np.argsort(pid_m, kind="stable")
    members = np.split(sort, np.cumsum(counts[rank_order])[:-1])
    clear = np.bincount(pid_m, fit_mask[m], minlength=len(counts))
    use_all = clear < np.maximum(3, counts[rank_order] // 2)
    fit_m = fit_mask[m] | use_all[pid_m]
    fitted = fit_planes(pts, np.where(fit_m, pid_m, -1), len(counts))
    planes = []
    for pid, idx in enumerate(members):
        if pid % 64 == 0:
            stop_if_asked(should_stop, "extracting roof planes")
            if progress is not None:
                progress(0.9 + 0.1 * pid / len(members))
        plane = fitted[pid]
        if plane is None:  # collinear points: fit_plane says why
            plane = fit_plane(pts[idx], plane_id=pid)
        planes.append(plane.with_outline(_outline(pts[idx], plane, cell)))
    return planes, plane_id
