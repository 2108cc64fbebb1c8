"""Roof planes from non-ground LiDAR points: local RANSAC, region growing, plane precision.

Method (Pedrosa & dos Santos 2020, section 2.1, made rigorous; every length in the cloud's CRS
unit):

1. **Local RANSAC** (paper's conditions a and b). For every point, its ``k_neighbours``
   nearest neighbours (scipy cKDTree, the point included) get ``ransac_iterations`` random
   triplets; the plane with the most neighbours within ``epsilon`` wins (the paper's "plane
   with the largest number of points"). It is refined by least squares on its inliers. The
   point is kept when the plane has at least ``min_support`` inliers, the point lies within
   ``epsilon`` of it and its slope is in ``[min_slope_deg, max_slope_deg]`` (vegetation has no
   supported plane; walls are too steep). Vectorised over batches of points: (B, T) triplets,
   a (B, T, K) distance tensor, batched 3x3 eigen-decompositions. Triplets come from
   ``numpy.random.default_rng([seed, batch])``: the same input and seed give the same planes
   on any run and platform.
2. **Region growing** as connected components: two kept points are connected when one is among
   the other's ``GROW_NEIGHBOURS`` nearest neighbours, their local normals differ by less than
   ``angle_tolerance_deg`` and the neighbour lies within ``epsilon`` of the point's local plane.
   The components of this graph (scipy.sparse.csgraph) are exactly the regions a seeded
   region growing with the same criteria reaches, without its order dependence.
3. **Clean-up**: components smaller than ``min_plane_points`` are dropped; each region is
   refitted, points farther than ``epsilon`` from it are released; then every point of the
   input (kept or not: ridge and eave points often fail step 1 because their neighbourhood
   straddles two faces) is assigned to the nearest plane among those of its neighbours when it
   lies within ``epsilon`` (``REASSIGN_PASSES`` times, refitting in between); adjacent planes
   that are coplanar (normals within ``angle_tolerance_deg``, each centroid within ``epsilon``
   of the other plane) are merged; regions below ``min_plane_points`` are dropped again.
4. **Fit** of each region by :func:`lidarphoto.core.geometry.planes.fit_plane` (Pathak's weighted
   eigen method on centred coordinates, covariance, sigma_d), ids ordered by decreasing point
   count (ties: first point index), and an **outline**: the plane's points rasterised in x, y
   at ``outline_cell`` (default: the median distance to the 4th nearest neighbour, about one
   point spacing), closed morphologically (3x3, OpenCV), the outer contour of the largest
   blob (cv2.findContours) simplified by Douglas-Peucker at half a cell, counter-clockwise in
   x, y, with z on the plane.
   It is a concave hull for display, not a measured building outline.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Any, Callable, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError, stop_if_asked, use_compiled
from ..geometry.planes import Plane, fit_plane, fit_planes, label_moments
from ..i18n import mark as _t

__all__ = ["SELECTION_CHOICES", "RoofPlaneParams", "RoofPlaneResult", "extract_roof_planes"]

log = logging.getLogger(__name__)

#: catalogue context of this module's ``_t("...")`` sentences (the log and the report)
TR_CONTEXT = "Report"

Array = NDArray[np.float64]
Progress = Union[Callable[[float], None], None]
ShouldStop = Union[Callable[[], bool], None]

#: Neighbours (of the k_neighbours) used for region growing, reassignment and adjacency.
GROW_NEIGHBOURS = 10
#: Seed voxel size, in point spacings (median distance to the 4th neighbour).
SEED_VOXEL = 8.0
#: Seeding rounds of the region growing.
SEED_ROUNDS = 4
#: Reassignment passes (each reaches one more ring of unassigned points around a plane).
REASSIGN_PASSES = 3
#: Point selections: non-ground (class != 2), the listed classes, or every point.
SELECTION_CHOICES: tuple[str, ...] = ("non_ground", "classes", "all")


@dataclass(frozen=True)
class RoofPlaneParams:
    """Parameters of :func:`extract_roof_planes`; lengths in the cloud's CRS unit.

    Attributes
    ----------
    k_neighbours : int
        K of the local RANSAC (>= 6).
    epsilon : float
        Point-to-plane tolerance (CRS unit): RANSAC inliers, region growing, assignment.
        About 3 x the range noise plus roof roughness; default 0.15 (metres).
    min_support : int
        Minimum inliers of a local plane (the paper's minimum set size t), <= k_neighbours.
    ransac_iterations : int
        Random triplets per point.
    min_slope_deg, max_slope_deg : float
        The paper's alpha and beta: accepted plane slopes, degrees from horizontal.
    angle_tolerance_deg : float
        Largest angle between local normals within one region, and between merged planes.
    min_plane_points : int
        Smallest plane kept (points).
    outline_cell : float
        Raster cell of the outlines (CRS unit); 0 = automatic (about one point spacing).
    seed : int
        Seed of the RANSAC triplets.
    batch_size : int
        Points per batch (memory about batch_size x ransac_iterations x k_neighbours x 4 bytes;
        progress and cancel are checked per batch). Part of the random stream: keep it fixed
        to reproduce results.
    """

    k_neighbours: int = 20
    epsilon: float = 0.15
    min_support: int = 18
    ransac_iterations: int = 15
    min_slope_deg: float = 0.0
    max_slope_deg: float = 70.0
    angle_tolerance_deg: float = 10.0
    min_plane_points: int = 30
    outline_cell: float = 0.0
    seed: int = 0
    batch_size: int = 8192

    def __post_init__(self) -> None:
        checks = (
            (self.k_neighbours >= 6, "k_neighbours must be >= 6"),
            (self.epsilon > 0, "epsilon must be > 0"),
            (
                3 <= self.min_support <= self.k_neighbours,
                "min_support must be between 3 and k_neighbours",
            ),
            (self.ransac_iterations >= 1, "ransac_iterations must be >= 1"),
            (
                0 <= self.min_slope_deg <= self.max_slope_deg <= 90,
                "slopes must satisfy 0 <= min_slope_deg <= max_slope_deg <= 90",
            ),
            (0 < self.angle_tolerance_deg < 90, "angle_tolerance_deg must be in (0, 90)"),
            (self.min_plane_points >= 3, "min_plane_points must be >= 3"),
            (self.outline_cell >= 0, "outline_cell must be >= 0"),
            (self.batch_size >= 1, "batch_size must be >= 1"),
        )
        for ok, message in checks:
            if not ok:
                raise InputError(message)


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
    """

    planes: tuple[Plane, ...]
    plane_id: NDArray[np.int32]
    n_candidates: int
    outline_cell: float
    message: str = ""



def _eig_normals(cov: NDArray) -> NDArray:
    """Upward unit normals (smallest eigenvectors) of a batch of 3x3 scatter matrices (B,3,3)."""
    _, vec = np.linalg.eigh(cov)
    n = vec[:, :, 0]
    return n * np.where(n[:, 2:3] < 0, -1.0, 1.0)


def _jacobi_normals(
    a00: Array, a01: Array, a02: Array, a11: Array, a12: Array, a22: Array
) -> tuple[Array, Array, Array]:
    """Upward unit normals (smallest eigenvectors) of symmetric 3 x 3 matrices given by their
    upper triangles (each (B,)), by ``JACOBI_SWEEPS`` sweeps of Jacobi rotations: only +, -,
    *, / and sqrt in a fixed order, so the compiled back end (one matrix at a time) gives the
    same bits. Six sweeps converge any 3 x 3 matrix to machine precision."""
    from .roof_planes_numba import JACOBI_SWEEPS

    one, zero = np.ones_like(a00), np.zeros_like(a00)
    v = [[one, zero, zero], [zero.copy(), one.copy(), zero.copy()],
         [zero.copy(), zero.copy(), one.copy()]]  # fmt: skip
    a = {(0, 0): a00, (0, 1): a01, (0, 2): a02, (1, 1): a11, (1, 2): a12, (2, 2): a22}
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for _ in range(JACOBI_SWEEPS):
            for p_, q_, r_ in ((0, 1, 2), (0, 2, 1), (1, 2, 0)):
                app, aqq, apq = a[p_, p_], a[q_, q_], a[p_, q_]
                rot = apq != 0.0
                theta = (aqq - app) / (2.0 * apq)
                tt = 1.0 / (np.abs(theta) + np.sqrt(theta * theta + 1.0))
                tt = np.where(theta < 0.0, -tt, tt)
                cc = 1.0 / np.sqrt(tt * tt + 1.0)
                ss = tt * cc
                arp, arq = a[min(r_, p_), max(r_, p_)], a[min(r_, q_), max(r_, q_)]
                a[p_, p_] = np.where(rot, app - tt * apq, app)
                a[q_, q_] = np.where(rot, aqq + tt * apq, aqq)
                a[p_, q_] = np.where(rot, 0.0, apq)
                a[min(r_, p_), max(r_, p_)] = np.where(rot, cc * arp - ss * arq, arp)
                a[min(r_, q_), max(r_, q_)] = np.where(rot, ss * arp + cc * arq, arq)
                for row in range(3):
                    vp, vq = v[row][p_], v[row][q_]
                    v[row][p_] = np.where(rot, cc * vp - ss * vq, vp)
                    v[row][q_] = np.where(rot, ss * vp + cc * vq, vq)
    d0, d1, d2 = a[0, 0], a[1, 1], a[2, 2]
    first = (d0 <= d1) & (d0 <= d2)
    second = ~first & (d1 <= d2)
    col = np.where(first, 0, np.where(second, 1, 2))
    nx = np.choose(col, [v[0][0], v[0][1], v[0][2]])
    ny = np.choose(col, [v[1][0], v[1][1], v[1][2]])
    nz = np.choose(col, [v[2][0], v[2][1], v[2][2]])
    flip = nz < 0.0
    return np.where(flip, -nx, nx), np.where(flip, -ny, ny), np.where(flip, -nz, nz)


@dataclass(frozen=True)
class PointGrid:
    """Points sorted by the cells of a grid over x, y, for the compiled neighbour search.

    ``q`` (N, 3) the sorted points, ``cell_of`` (N,) their cell (row-major, ``ny`` x ``nx``
    cells of ``cell`` from ``x0``, ``y0``), ``start`` (nx ny + 1,) the first point of each
    cell; ``offsets`` (M, 2) cell offsets in increasing order of ``bound2``, the squared
    smallest distance from a point to a cell that far.
    """

    q: Array
    cell_of: NDArray[np.int64]
    start: NDArray[np.int64]
    nx: int
    ny: int
    x0: float
    y0: float
    cell: float
    offsets: NDArray[np.int64]
    bound2: Array


def _spatial_order(
    xyz: Array, origin: Array, k: int, compiled: bool = False
) -> tuple[NDArray[np.int64], PointGrid]:
    """Order the points by grid cell (stable) and build the grid of the points ``xyz -
    origin``, with cells of about half the typical distance to the K-th neighbour (from the
    area a sample of the points occupies), at most 4 N cells. The order only makes the work
    local (neighbours close in memory): the results do not depend on the cell size."""
    n = len(xyz)
    lo = xyz[:, :2].min(axis=0)
    span = np.maximum(xyz[:, :2].max(axis=0) - lo, 1e-9)
    sample = xyz[:: max(n // 200_000, 1), :2] - lo
    cell = float(np.sqrt(span[0] * span[1] / len(sample)))
    for _ in range(2):  # the area the points occupy, not their box (trees, gaps, tiles)
        cols = int(span[0] / cell) + 1
        ij = (sample[:, 1] // cell) * cols + sample[:, 0] // cell
        occupied = int(np.count_nonzero(np.bincount(ij.astype(np.int64))))
        cell = float(np.sqrt(occupied * cell * cell / len(sample) * max(k, 4) / 4.0))
    # the occupied area was measured with the sample: K/4 of all the points per cell (with
    # the sample's density instead, 6.8 M points got cells 33x too full)
    cell *= float(np.sqrt(len(sample) / n))
    cell = max(cell, float(np.sqrt(span[0] * span[1] / (4.0 * n))), 1e-9)
    nx = int(span[0] / cell) + 1
    ny = int(span[1] / cell) + 1
    # cells of the centred coordinates, as the search computes their bounds
    x0, y0 = lo[0] - origin[0], lo[1] - origin[1]
    key = np.minimum(np.maximum(((xyz[:, 1] - origin[1] - y0) / cell).astype(np.int64), 0),
                     ny - 1)  # fmt: skip
    key *= nx
    key += np.minimum(np.maximum(((xyz[:, 0] - origin[0] - x0) / cell).astype(np.int64), 0),
                      nx - 1)  # fmt: skip
    if compiled:  # a counting sort: the same order as the stable argsort
        from . import roof_planes_numba

        order, start = roof_planes_numba.counting_order(key, nx * ny)
    else:
        order = np.argsort(key, kind="stable")
        start = np.zeros(nx * ny + 1, dtype=np.int64)
        np.cumsum(np.bincount(key, minlength=nx * ny), out=start[1:])
    reach = min(max(nx, ny), 64)
    r = np.arange(-reach, reach + 1)
    gx, gy = np.meshgrid(r, r)
    gx, gy = gx.ravel(), gy.ravel()
    bound = np.hypot(np.maximum(np.abs(gx) - 1, 0), np.maximum(np.abs(gy) - 1, 0)) * cell
    o = np.lexsort((np.abs(gx) + np.abs(gy), bound))
    q = xyz[order]
    q -= origin
    grid = PointGrid(
        q, key[order], start, nx, ny, float(x0), float(y0),
        cell, np.column_stack([gx[o], gy[o]]).astype(np.int64), bound[o] ** 2,
    )  # fmt: skip
    return order, grid


def _knn_numpy(tree: Any, q: Array, lo: int, hi: int, k: int) -> tuple[Array, NDArray]:
    """The K nearest neighbours of q[lo:hi] with ties broken by the lower index, distances
    squared as ``dx dx + dy dy + dz dz`` (the compiled search's rule): (d2 (B, K), idx)."""
    extra = min(4, len(q) - k)
    _, idx = tree.query(q[lo:hi], k=k + extra, workers=1)
    idx = np.asarray(idx, dtype=np.int64).reshape(hi - lo, k + extra)
    diff = q[idx] - q[lo:hi, None, :]
    d2 = diff[..., 0] * diff[..., 0] + diff[..., 1] * diff[..., 1] + diff[..., 2] * diff[..., 2]
    o = np.lexsort((idx, d2), axis=1)
    d2 = np.take_along_axis(d2, o, axis=1)
    idx = np.take_along_axis(idx, o, axis=1)
    if extra:
        # a tie reaching past the extra neighbours (or a rounding difference with the tree's
        # own distance): every point within the k-th distance, then the same rule
        doubt = np.flatnonzero(d2[:, -1] <= d2[:, k - 1] * (1.0 + 1e-9))
        for row in doubt:
            i = lo + row
            near = np.asarray(tree.query_ball_point(q[i], np.sqrt(d2[row, k - 1]) * (1 + 1e-6)))
            dd = q[near] - q[i]
            e2 = dd[:, 0] * dd[:, 0] + dd[:, 1] * dd[:, 1] + dd[:, 2] * dd[:, 2]
            oo = np.lexsort((near, e2))[:k]
            d2[row, :k], idx[row, :k] = e2[oo], near[oo]
    return d2[:, :k], idx[:, :k]


def _ransac_numpy(
    pts: NDArray[np.float32], tri: NDArray[np.int64], params: RoofPlaneParams
) -> tuple[NDArray[np.bool_], NDArray[np.float32], NDArray[np.float32]]:
    """The local RANSAC of a batch (the compiled back end's operations, vectorised): pts
    (B, K, 3) float32 relative to each query point, tri (B, T, 3). Returns keep, normals
    (B, 3), quality (B,)."""
    b, k, _ = pts.shape
    eps = np.float32(params.epsilon)
    rows = np.arange(b)[:, None]
    px, py, pz = pts[..., 0], pts[..., 1], pts[..., 2]
    a0, a1, a2 = tri[..., 0], tri[..., 1], tri[..., 2]
    ax, ay, az = px[rows, a0], py[rows, a0], pz[rows, a0]
    ux, uy, uz = px[rows, a1] - ax, py[rows, a1] - ay, pz[rows, a1] - az
    vx, vy, vz = px[rows, a2] - ax, py[rows, a2] - ay, pz[rows, a2] - az
    nx = uy * vz - uz * vy
    ny = uz * vx - ux * vz
    nz = ux * vy - uy * vx
    length = np.sqrt(nx * nx + ny * ny + nz * nz)
    valid = length > np.float32(1e-12)
    length = np.where(valid, length, np.float32(1.0))
    nx, ny, nz = nx / length, ny / length, nz / length
    off = -(nx * ax + ny * ay + nz * az)  # (B, T)
    d = np.abs(nx[..., None] * px[:, None, :] + ny[..., None] * py[:, None, :]
               + nz[..., None] * pz[:, None, :] + off[..., None])  # (B, T, K)  # fmt: skip
    support = np.count_nonzero(d < eps, axis=2)
    support[~valid] = 0
    best = np.argmax(support, axis=1)
    sel = np.arange(b)
    best_support = support[sel, best]
    inl = d[sel, best] < eps  # (B, K)
    cnt = np.maximum(inl.sum(axis=1), 1)
    w = inl.astype(np.float64)
    p64 = pts.astype(np.float64)
    m = []
    for axis in range(3):  # sums in neighbour order, as the compiled loop
        acc = np.zeros(b)
        for j in range(k):
            acc += w[:, j] * p64[:, j, axis]
        m.append(acc / cnt)
    dev = [(p64[:, :, axis] - m[axis][:, None]) * w for axis in range(3)]
    cov = {}
    for u_, v_ in ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)):
        acc = np.zeros(b)
        for j in range(k):
            acc += dev[u_][:, j] * dev[v_][:, j]
        cov[u_, v_] = acc
    fx, fy, fz = _jacobi_normals(cov[0, 0], cov[0, 1], cov[0, 2], cov[1, 1], cov[1, 2],
                                 cov[2, 2])  # fmt: skip
    dist_point = np.abs(fx * m[0] + fy * m[1] + fz * m[2])  # the query point at the origin
    rr = np.zeros(b)
    for j in range(k):
        res = dev[0][:, j] * fx + dev[1][:, j] * fy + dev[2][:, j] * fz
        rr += res * res
    quality = np.sqrt(rr / cnt)
    cos_lo = math.cos(math.radians(params.max_slope_deg))
    cos_hi = math.cos(math.radians(params.min_slope_deg))
    nzabs = np.abs(fz)
    keep = (
        (best_support >= params.min_support)
        & (dist_point < params.epsilon)
        & (nzabs >= cos_lo - 1e-12)
        & (nzabs <= cos_hi + 1e-12)
    )
    return keep, np.column_stack([fx, fy, fz]).astype(np.float32), quality.astype(np.float32)


def _local_planes(
    grid: PointGrid,
    params: RoofPlaneParams,
    backend: str,
    progress: Progress,
    should_stop: ShouldStop,
) -> tuple[NDArray[np.bool_], NDArray[np.float32], NDArray[np.float32], NDArray[np.int32], float]:
    """Step 1 on the sorted points. Returns keep (N,), local normals (N,3), local rms of the
    refined plane's inliers (N,), the first GROW_NEIGHBOURS neighbours (N, G) and the median
    distance to the 4th neighbour."""
    q = grid.q
    n = len(q)
    k = min(params.k_neighbours, n)
    g = min(GROW_NEIGHBOURS, k)
    t = params.ransac_iterations
    out = {
        "keep": np.zeros(n, dtype=bool),
        "normals": np.zeros((n, 3), dtype=np.float32),
        "quality": np.zeros(n, dtype=np.float32),
        "knn": np.empty((n, g), dtype=np.int32),
        "spacing": np.empty(n, dtype=np.float32),
    }
    compiled = _use_numba(backend)
    tree = None
    if not compiled:
        from scipy.spatial import cKDTree

        tree = cKDTree(q, balanced_tree=False, compact_nodes=False)
    cos_lo = math.cos(math.radians(params.max_slope_deg))
    cos_hi = math.cos(math.radians(params.min_slope_deg))
    bs = params.batch_size
    n_batches = (n + bs - 1) // bs
    for bi in range(n_batches):
        stop_if_asked(should_stop, "extracting roof planes")
        lo, hi = bi * bs, min(n, (bi + 1) * bs)
        rng = np.random.default_rng([params.seed, bi])
        tri = rng.integers(0, k, size=(hi - lo, t, 3))
        if compiled:
            from . import roof_planes_numba

            roof_planes_numba.local_planes(grid, lo, hi, k, g, tri, params.epsilon,
                                           params.min_support, cos_lo, cos_hi, out)  # fmt: skip
        else:
            d2, idx = _knn_numpy(tree, q, lo, hi, k)
            out["knn"][lo:hi] = idx[:, :g]
            out["spacing"][lo:hi] = np.sqrt(d2[:, min(4, k - 1)])
            pts = (q[idx] - q[lo:hi, None, :]).astype(np.float32)
            keep, normals, quality = _ransac_numpy(pts, tri, params)
            out["keep"][lo:hi], out["normals"][lo:hi], out["quality"][lo:hi] = (
                keep, normals, quality
            )
        if progress is not None:
            progress(0.7 * (bi + 1) / n_batches)
    med = float(np.median(out["spacing"])) if n else 0.0
    return out["keep"], out["normals"], out["quality"], out["knn"], med


def _use_numba(backend: str) -> bool:
    """Resolve extract_roof_planes's ``backend`` argument."""
    from .roof_planes_numba import AVAILABLE

    return use_compiled(backend, AVAILABLE)


def _grow(
    q: Array,
    keep: NDArray[np.bool_],
    normals: NDArray[np.float32],
    quality: NDArray[np.float32],
    knn: NDArray[np.int32],
    spacing: float,
    params: RoofPlaneParams,
    should_stop: ShouldStop,
    compiled: bool = False,
) -> NDArray[np.int64]:
    """Step 2: region growing from many seeds at once, in waves; labels (N,), -1 elsewhere.

    Seeds: in every voxel of ``SEED_VOXEL x spacing`` the unlabelled kept point with the best
    local fit (lowest local rms, below epsilon / 2), so that points whose neighbourhood
    straddles a ridge never seed. Each wave, every region's frontier offers its points'
    neighbours; a kept, unlabelled neighbour joins when it lies within epsilon of the region's
    current plane and its local normal is within the angle tolerance of the region's normal (a
    point claimed by several regions goes to the nearest plane). Region planes are refitted
    after every wave from running moments about the seed (no cancellation). Comparing with the
    region's plane, not the neighbour's local normal, is what stops the growth at ridges and
    hips, where local normals blend smoothly from one face to the other. When all regions have
    stopped, the unlabelled candidates seed a new round (small faces next to big ones), up to
    ``SEED_ROUNDS`` rounds. Several seeds on one face give several regions: they are merged
    afterwards (``_merge_coplanar``).
    """
    n = len(q)
    labels = np.full(n, -1, dtype=np.int64)
    good = keep & (quality < 0.5 * params.epsilon)
    voxel = max(SEED_VOXEL * spacing, 1e-9)
    cos_tol = math.cos(math.radians(params.angle_tolerance_deg))
    min_fit = 2 * params.k_neighbours  # below this the seed's local plane is the better one
    reg_n = np.empty((0, 3))
    reg_c = np.empty((0, 3))
    scratch = {"best_d": np.full(n, np.inf), "best_r": np.full(n, -1, dtype=np.int64)}
    for _ in range(SEED_ROUNDS):
        cand_seed = np.flatnonzero(good & (labels < 0))
        if not len(cand_seed):
            break
        key3 = np.floor(q[cand_seed] / voxel).astype(np.int64)
        key3 -= key3.min(axis=0)
        dims = key3.max(axis=0) + 1
        key = (key3[:, 0] * dims[1] + key3[:, 1]) * dims[2] + key3[:, 2]
        order = np.lexsort((cand_seed, quality[cand_seed], key))
        first = np.ones(len(order), dtype=bool)
        first[1:] = key[order][1:] != key[order][:-1]
        seeds = np.sort(cand_seed[order[first]])
        base = len(reg_n)
        n_new = len(seeds)
        labels[seeds] = base + np.arange(n_new)
        origin = q[seeds]
        reg_n = np.concatenate([reg_n, normals[seeds].astype(np.float64)])
        reg_c = np.concatenate([reg_c, origin])
        cnt = np.ones(n_new)
        s1 = np.zeros((n_new, 3))
        s2 = np.zeros((n_new, 3, 3))
        frontier = seeds
        retried = False
        while True:
            stop_if_asked(should_stop, "extracting roof planes")
            if compiled:
                from . import roof_planes_numba

                cand, reg = roof_planes_numba.claims(q, keep, normals, labels, knn, frontier,
                                                     reg_n, reg_c, cos_tol, params.epsilon,
                                                     scratch)  # fmt: skip
            else:
                cand, reg = _claims(q, keep, normals, labels, knn, frontier, reg_n, reg_c,
                                    cos_tol, params.epsilon)  # fmt: skip
            if not len(cand):
                if retried:
                    break
                # stalled: offer every point of this round's regions once more, refitted
                retried = True
                frontier = np.flatnonzero(labels >= base)
                continue
            retried = False
            labels[cand] = reg
            frontier = cand
            # running moments about each seed, then the plane of every region that grew
            r = reg - base
            dev = q[cand] - origin[r]
            cnt += np.bincount(r, minlength=n_new)
            for a in range(3):
                s1[:, a] += np.bincount(r, dev[:, a], minlength=n_new)
                for b in range(a, 3):
                    s2[:, a, b] += np.bincount(r, dev[:, a] * dev[:, b], minlength=n_new)
            grown = np.unique(r)
            grown = grown[cnt[grown] >= min_fit]
            mean = s1[grown] / cnt[grown, None]
            cov = s2[grown] / cnt[grown, None, None] - mean[:, :, None] * mean[:, None, :]
            iu = np.triu_indices(3, 1)
            cov[:, iu[1], iu[0]] = cov[:, iu[0], iu[1]]
            reg_n[base + grown] = _eig_normals(cov)
            reg_c[base + grown] = origin[grown] + mean
    return labels


def _claims(
    q: Array,
    keep: NDArray[np.bool_],
    normals: NDArray[np.float32],
    labels: NDArray[np.int64],
    knn: NDArray[np.int32],
    frontier: NDArray[np.int64],
    reg_n: Array,
    reg_c: Array,
    cos_tol: float,
    eps: float,
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """One wave: unlabelled kept neighbours of the frontier that fit the frontier's region
    (each point once, to the nearest region plane): (points, regions)."""
    g = knn.shape[1]
    cand = knn[frontier].reshape(-1).astype(np.int64)
    reg = np.repeat(labels[frontier], g)
    ok = keep[cand] & (labels[cand] < 0)
    cand, reg = cand[ok], reg[ok]
    dist = np.abs(_dot3(q[cand] - reg_c[reg], reg_n[reg]))
    ok = (dist < eps) & (_dot3(normals[cand].astype(np.float64), reg_n[reg]) > cos_tol)
    cand, reg, dist = cand[ok], reg[ok], dist[ok]
    o = np.lexsort((reg, dist, cand))
    cand, reg = cand[o], reg[o]
    uniq = np.ones(len(cand), dtype=bool)
    uniq[1:] = cand[1:] != cand[:-1]
    return cand[uniq], reg[uniq]


def _dot3(a: Array, b: Array) -> Array:
    """Row-wise dot products of (M, 3) arrays, summed x + y + z in that order (as the compiled
    back end sums them)."""
    return a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1] + a[:, 2] * b[:, 2]


def _drop_small(labels: NDArray[np.int64], min_points: int) -> NDArray[np.int64]:
    """Renumber labels 0..L-1 by first appearance, dropping labels with < min_points."""
    out = np.full(len(labels), -1, dtype=np.int64)
    m = labels >= 0
    if not m.any():
        return out
    uniq, first, inv, counts = np.unique(
        labels[m], return_index=True, return_inverse=True, return_counts=True
    )
    big = counts >= min_points
    order = np.argsort(first[big], kind="stable")
    new = np.full(len(uniq), -1, dtype=np.int64)
    new[np.flatnonzero(big)[order]] = np.arange(big.sum())
    out[m] = new[inv.reshape(-1)]
    return out


def _fit_labels(
    q: Array, labels: NDArray[np.int64], compiled: bool = False
) -> tuple[Array, Array, NDArray]:
    """Least-squares planes of every label at once: normals (L,3), centroids (L,3), counts.

    The sums run in point order in both back ends (numpy's bincount and the compiled loop add
    in the same order), in two passes: no cancellation in the moments."""
    nl = int(labels.max()) + 1 if len(labels) else 0
    if nl <= 0:
        return np.empty((0, 3)), np.empty((0, 3)), np.empty(0)
    if compiled:
        from . import roof_planes_numba

        counts, centroid, six = roof_planes_numba.moments(q, labels, nl)
        cov = np.empty((nl, 3, 3))
        for col, (a, b) in enumerate(_UPPER):
            cov[:, a, b] = cov[:, b, a] = six[:, col]
    else:
        m = labels >= 0
        counts, centroid, cov = label_moments(q[m], labels[m], nl)
    return _eig_normals(cov), centroid, counts


_UPPER = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))


def _release_far(
    q: Array, labels: NDArray[np.int64], eps: float, compiled: bool = False
) -> NDArray[np.int64]:
    """Refit every region and release its points farther than eps from its plane."""
    if not (labels >= 0).any():
        return labels
    normals, centroids, _ = _fit_labels(q, labels, compiled)
    m = np.flatnonzero(labels >= 0)
    lab = labels[m]
    r = np.abs(_dot3(q[m] - centroids[lab], normals[lab]))
    out = labels.copy()
    out[m[r >= eps]] = -1
    return out


def _reassign(
    q: Array,
    labels: NDArray[np.int64],
    knn: NDArray[np.int32],
    eps: float,
    batch: int,
    should_stop: ShouldStop,
    compiled: bool = False,
) -> tuple[NDArray[np.int64], NDArray[np.bool_]]:
    """Assign every point to the nearest plane among its own and its neighbours' (< eps).

    Returns the labels (N,) and ``ambiguous`` (N,): the point also lies within eps of another
    of those planes (ridge and hip points), so it says little about either plane.
    """
    out = np.full(len(q), -1, dtype=np.int64)
    ambiguous = np.zeros(len(q), dtype=bool)
    if not (labels >= 0).any():
        return out, ambiguous
    normals, centroids, _ = _fit_labels(q, labels, compiled)
    for lo in range(0, len(q), batch):
        stop_if_asked(should_stop, "extracting roof planes")
        hi = min(len(q), lo + batch)
        if compiled:
            from . import roof_planes_numba

            roof_planes_numba.reassign(q, labels, knn, centroids, normals, eps, lo, hi, out,
                                       ambiguous)  # fmt: skip
            continue
        cand = np.concatenate([labels[lo:hi, None], labels[knn[lo:hi]]], axis=1)  # (B, G+1)
        valid = cand >= 0
        c = np.where(valid, cand, 0)
        rel = q[lo:hi, None, :] - centroids[c]
        nc = normals[c]
        dist = np.abs(rel[..., 0] * nc[..., 0] + rel[..., 1] * nc[..., 1]
                      + rel[..., 2] * nc[..., 2])  # fmt: skip
        dist[~valid] = np.inf
        best = np.argmin(dist, axis=1)
        rows = np.arange(hi - lo)
        ok = dist[rows, best] < eps
        chosen = cand[rows, best]
        out[lo:hi] = np.where(ok, chosen, -1)
        other = (dist < eps) & (cand != chosen[:, None])
        ambiguous[lo:hi] = ok & other.any(axis=1)
    return out, ambiguous


def _merge_coplanar(
    q: Array,
    labels: NDArray[np.int64],
    knn: NDArray[np.int32],
    params: RoofPlaneParams,
    compiled: bool = False,
) -> NDArray[np.int64]:
    """Merge adjacent regions that are the same plane (e.g. split by a chimney)."""
    m = labels >= 0
    if not m.any():
        return labels
    normals, centroids, _ = _fit_labels(q, labels, compiled)
    nl = len(normals)
    if compiled:
        from . import roof_planes_numba

        keys = roof_planes_numba.label_pairs(labels, knn, nl)
    else:
        parts = []
        step = 1 << 20  # points per batch: the (N, G) label pairs never exist at once
        for lo in range(0, len(labels), step):
            a = np.repeat(labels[lo : lo + step], knn.shape[1])
            b = labels[knn[lo : lo + step].reshape(-1)]
            pair = (a >= 0) & (b >= 0) & (a != b)
            key = np.minimum(a[pair], b[pair]) * nl + np.maximum(a[pair], b[pair])
            parts.append(np.unique(key))
        keys = np.unique(np.concatenate(parts))
    if not len(keys):
        return labels
    pairs = np.column_stack([keys // nl, keys % nl])
    la, lb = pairs[:, 0], pairs[:, 1]
    cos_tol = math.cos(math.radians(params.angle_tolerance_deg))
    same = (normals[la] * normals[lb]).sum(axis=1) > cos_tol
    da = np.abs(((centroids[lb] - centroids[la]) * normals[la]).sum(axis=1))
    db = np.abs(((centroids[la] - centroids[lb]) * normals[lb]).sum(axis=1))
    same &= (da < params.epsilon) & (db < params.epsilon)
    if not same.any():
        return labels
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    graph = coo_matrix(
        (np.ones(int(same.sum()), dtype=np.int8), (la[same], lb[same])), shape=(nl, nl)
    )
    _, comp = connected_components(graph, directed=False)
    out = labels.copy()
    out[m] = comp[labels[m]]
    return out


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
    if np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y) < 0:  # shoelace: clockwise
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
        msg = _t("no roof plane: only {n} candidate points (fewer than needed for one plane)",
                 n=n)  # fmt: skip
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
    keep, normals, quality, knn, spacing = _local_planes(grid, params, backend, progress,
                                                         should_stop)  # fmt: skip
    del grid
    n_cand = int(keep.sum())
    log.info("local RANSAC kept %d of %d points (%.1f %%)", n_cand, n, 100.0 * n_cand / n)
    labels = _grow(q, keep, normals, quality, knn, spacing, params, should_stop, compiled)
    del normals, quality
    if progress is not None:
        progress(0.8)
    eps = params.epsilon
    labels = _drop_small(_merge_coplanar(q, labels, knn, params, compiled),
                         params.min_plane_points)  # fmt: skip
    for _ in range(2):
        labels = _drop_small(_release_far(q, labels, eps, compiled), params.min_plane_points)
    for _ in range(REASSIGN_PASSES):
        labels = _drop_small(
            _reassign(q, labels, knn, eps, params.batch_size * 8, should_stop, compiled)[0],
            params.min_plane_points,
        )
    labels = _merge_coplanar(q, labels, knn, params, compiled)
    labels, ambiguous = _reassign(q, labels, knn, eps, params.batch_size * 8, should_stop,
                                  compiled)  # fmt: skip
    labels = _drop_small(labels, params.min_plane_points)
    if progress is not None:
        progress(0.9)
    cell = params.outline_cell or spacing
    back = np.empty_like(labels)
    back[order] = labels
    fit_mask = np.empty(n, dtype=bool)
    # points of the region's interior only: a point with a neighbour outside its plane is at a
    # ridge or an eave (where wall points attach), on one side of the plane
    interior = np.empty(n, dtype=bool)
    for lo in range(0, n, 1 << 20):  # (N, G) comparisons in slices: bounded memory
        hi = min(n, lo + (1 << 20))
        interior[lo:hi] = (labels[knn[lo:hi]] == labels[lo:hi, None]).all(axis=1)
    fit_mask[order] = keep & ~ambiguous & interior
    planes, plane_id = _final_planes(xyz, back, fit_mask, cell, progress, should_stop)
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
    return RoofPlaneResult(tuple(planes), plane_id, n_cand, float(cell), msg)


def _final_planes(
    xyz: Array,
    labels: NDArray[np.int64],
    fit_mask: NDArray[np.bool_],
    cell: float,
    progress: Progress,
    should_stop: ShouldStop,
) -> tuple[list[Plane], NDArray[np.int32]]:
    """Plane fits (:func:`fit_planes`) + outline per region; ids by decreasing size (ties:
    first point index).

    Only ``fit_mask`` points enter the fit: points kept by the local RANSAC (their whole
    neighbourhood is planar), not within epsilon of a second plane and whose neighbours all
    belong to the same plane (the region's interior). Points at its edge (ridges, hips, eaves,
    and wall points just below the eaves that lie within epsilon) keep their plane id but sit
    on one side of the plane: fitted, they tilted the planes of the synthetic town by 1.2-1.5x
    the variance the covariance reports; without them the normals scatter 1.09x and sigma_d
    1.10x their reported variance over 160 noise draws (tests/core/test_roof_planes.py). A
    region with fewer than half its points in the mask is fitted with all of them.
    """
    plane_id = np.full(len(xyz), -1, dtype=np.int32)
    m = np.flatnonzero(labels >= 0)
    if not len(m):
        return [], plane_id
    lab = labels[m]
    counts = np.bincount(lab)
    first = np.full(len(counts), len(xyz), dtype=np.int64)
    np.minimum.at(first, lab, m)
    order = np.lexsort((first, -counts))
    rank = np.empty(len(counts), dtype=np.int64)
    rank[order] = np.arange(len(counts))
    plane_id[m] = rank[lab]
    sort = np.argsort(plane_id[m], kind="stable")
    members = np.split(m[sort], np.cumsum(counts[order])[:-1])
    pid_m = plane_id[m]
    clear = np.bincount(pid_m, fit_mask[m], minlength=len(counts))
    use_all = clear < np.maximum(3, counts[order] // 2)
    fit_label = np.full(len(xyz), -1, dtype=np.int64)
    fit_label[m] = np.where(fit_mask[m] | use_all[pid_m], pid_m, -1)
    fitted = fit_planes(xyz, fit_label, len(counts))
    planes = []
    for pid, idx in enumerate(members):
        if pid % 64 == 0:
            stop_if_asked(should_stop, "extracting roof planes")
            if progress is not None:
                progress(0.9 + 0.1 * pid / len(members))
        plane = fitted[pid]
        if plane is None:  # collinear points: fit_plane says why
            plane = fit_plane(xyz[idx], plane_id=pid)
        planes.append(plane.with_outline(_outline(xyz[idx], plane, cell)))
    return planes, plane_id
