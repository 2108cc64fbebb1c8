"""Step 1 of the roof-plane extraction (:mod:`core.lidar.roof_planes`): the points sorted by
grid cell, their K nearest neighbours and the local RANSAC on a fixed set of triplets, in numpy
(the compiled back end is :mod:`core.lidar.roof_planes_numba`); the eigen-solvers shared by
both.

Nothing here depends on a random draw or on the order of the input points: each point tries
one of a fixed set of triplet tables (:func:`triplets`), chosen by a hash of its coordinates
(:func:`table_of`), the points are sorted by cell and, within a cell,
by their coordinates, and the neighbours of a point are the K nearest with ties broken by that
order. A tile that holds a point's K neighbours gives it the local plane of the whole file.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Any, Callable, Union

import numpy as np
from numpy.typing import NDArray

from ..errors import stop_if_asked, use_compiled
from ..geometry.sym3 import jacobi_sym3

#: core.lidar.roof_planes.RoofPlaneParams (not imported: roof_planes imports this module)
RoofPlaneParams = Any

Array = NDArray[np.float64]
Progress = Union[Callable[[float], None], None]
ShouldStop = Union[Callable[[], bool], None]

#: Neighbours (of the k_neighbours) used for region growing, reassignment and adjacency.
GROW_NEIGHBOURS = 10


def _eig_normals(cov: NDArray, compiled: bool = False) -> NDArray:
    """Upward unit normals (smallest eigenvectors) of a batch of 3x3 scatter matrices (B,3,3).

    By the fixed Jacobi rotations of :func:`_jacobi_normals` (compiled: the same rotations in
    numba, the same bits), not LAPACK: the region growing compares with these normals, so
    they must not depend on the LAPACK build or its threads (Debian's numpy 1.24 links the
    system OpenBLAS). The numpy path costs about 4 % of an extraction (AHN3 crop 1)."""
    if compiled:
        from . import roof_planes_numba

        return roof_planes_numba.normals(cov)
    nx, ny, nz = _jacobi_normals(
        cov[:, 0, 0], cov[:, 0, 1], cov[:, 0, 2], cov[:, 1, 1], cov[:, 1, 2], cov[:, 2, 2]
    )
    return np.column_stack([nx, ny, nz])


def _jacobi_normals(
    a00: Array, a01: Array, a02: Array, a11: Array, a12: Array, a22: Array
) -> tuple[Array, Array, Array]:
    """Upward unit normals (smallest eigenvectors) of symmetric 3 x 3 matrices given by their
    upper triangles (each (B,)), by the fixed Jacobi rotations of
    :func:`core.geometry.sym3.jacobi_sym3`: only +, -, *, / and sqrt in a fixed order, so the
    compiled back end (one matrix at a time) gives the same bits. Ties in the eigenvalues go
    to the lower column."""
    (d0, d1, d2), v = jacobi_sym3(a00, a01, a02, a11, a12, a22)
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
    table: NDArray[np.uint8]


#: Triplet tables; each point tries the one its coordinates pick (:func:`table_of`).
TRIPLET_TABLES = 256


def _spatial_order(
    xyz: Array, origin: Array, k: int, compiled: bool = False
) -> tuple[NDArray[np.int64], PointGrid]:
    """Order the points by grid cell, and within a cell by x, then y, then z, and build the
    grid of the points ``xyz - origin``, with cells of about half the typical distance to the
    K-th neighbour (from the area the points occupy), at most 4 N cells. The order makes the
    work local (neighbours close in memory) and breaks ties: it depends on the point set, not
    on the order of the input (exact duplicates aside, which are the same point)."""
    n = len(xyz)
    lo = xyz[:, :2].min(axis=0)
    span = np.maximum(xyz[:, :2].max(axis=0) - lo, 1e-9)
    table_all = table_of(xyz)
    # a sample of about 200 k points picked by their coordinates' hash (a strided sample
    # would depend on the input order)
    sample = xyz[table_all < max(1, -(-TRIPLET_TABLES * 200_000 // n)), :2] - lo
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
    key = np.minimum(np.maximum(((xyz[:, 1] - origin[1] - y0) / cell).astype(np.int64), 0), ny - 1)
    key *= nx
    key += np.minimum(np.maximum(((xyz[:, 0] - origin[0] - x0) / cell).astype(np.int64), 0), nx - 1)
    if compiled:  # a counting sort, then each cell by coordinates: the lexsort's order
        from . import roof_planes_numba

        order, start = roof_planes_numba.counting_order(key, nx * ny, xyz)
    else:
        order = np.lexsort((xyz[:, 2], xyz[:, 1], xyz[:, 0], key))
        start = np.zeros(nx * ny + 1, dtype=np.int64)
        np.cumsum(np.bincount(key, minlength=nx * ny), out=start[1:])
    reach = min(max(nx, ny), 64)
    r = np.arange(-reach, reach + 1)
    gx, gy = np.meshgrid(r, r)
    gx, gy = gx.ravel(), gy.ravel()
    bound = np.hypot(np.maximum(np.abs(gx) - 1, 0), np.maximum(np.abs(gy) - 1, 0)) * cell
    o = np.lexsort((np.abs(gx) + np.abs(gy), bound))
    q = xyz[order]
    table = table_all[order]
    q -= origin
    grid = PointGrid(
        q,
        key[order],
        start,
        nx,
        ny,
        float(x0),
        float(y0),
        cell,
        np.column_stack([gx[o], gy[o]]).astype(np.int64),
        bound[o] ** 2,
        table,
    )
    return order, grid


def _mix(z: Any) -> Any:
    """SplitMix64's finaliser of a Python int or a uint64 array (which wraps modulo 2**64)."""
    wrap = (lambda v: v & 0xFFFFFFFFFFFFFFFF) if isinstance(z, int) else (lambda v: v)
    z = wrap((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9)
    z = wrap((z ^ (z >> 27)) * 0x94D049BB133111EB)
    return z ^ (z >> 31)


def triplets(k: int, t: int) -> NDArray[np.int64]:
    """The :data:`TRIPLET_TABLES` tables (M, t, 3) of ``t`` triplets of neighbour ranks in
    [0, k) that the local RANSAC tries: distinct ranks, spread like uniform draws, from a fixed
    integer hash (SplitMix64), so the same on any run, machine and numpy version. One table
    for every point tried tables of their own: the LCPs of the AHN3 crop varied from 72 to 81
    with the table; a table per point, picked by its coordinates, averages that out as random
    draws did, and a point's planes still depend on its neighbours only.

    >>> triplets(20, 2)[0].tolist()
    [[1, 18, 0], [1, 19, 0]]
    """
    return _triplets(k, t).copy()  # a fresh array: the cached one is never handed out


@functools.lru_cache(maxsize=8)
def _triplets(k: int, t: int) -> NDArray[np.int64]:
    """:func:`triplets`, computed once per (k, t) in a process (70 ms of Python: a block's
    tiles and second-pass windows in one worker ask for the same tables)."""
    mask = (1 << 64) - 1
    state = 0x9E3779B97F4A7C15 * (k + 1) & mask
    out = np.empty((TRIPLET_TABLES, t, 3), dtype=np.int64)
    for row in range(TRIPLET_TABLES * t):
        picked: list[int] = []
        while len(picked) < min(3, k):
            state = (state + 0x9E3779B97F4A7C15) & mask
            r = _mix(state) % k
            if r not in picked:
                picked.append(r)
        out[row // t, row % t] = (picked * 3)[:3]
    return out


def table_of(xyz: Array) -> NDArray[np.uint8]:
    """The triplet table (0 .. TRIPLET_TABLES - 1) of each point (N,), from the bits of its map
    coordinates (N, 3) float64: the same for the point in any tile, order or run."""
    out = np.empty(len(xyz), dtype=np.uint8)
    for lo in range(0, len(xyz), 1 << 20):  # in slices: the uint64 temporaries stay small
        bits = np.ascontiguousarray(xyz[lo : lo + (1 << 20)], dtype=np.float64).view(np.uint64)
        with np.errstate(over="ignore"):
            h = bits[:, 0] * np.uint64(0x9E3779B97F4A7C15)
            h ^= bits[:, 1] * np.uint64(0xC2B2AE3D27D4EB4F)
            h ^= bits[:, 2] * np.uint64(0x165667B19E3779F9)
            h = _mix(h)
        out[lo : lo + len(h)] = h % np.uint64(TRIPLET_TABLES)
    return out


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
    (B, K, 3) float32 relative to each query point, tri (B, T, 3) the triplets of each point.
    Returns keep, normals (B, 3), quality (B,)."""
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
    d = np.abs(
        nx[..., None] * px[:, None, :]
        + ny[..., None] * py[:, None, :]
        + nz[..., None] * pz[:, None, :]
        + off[..., None]
    )  # (B, T, K)
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
    fx, fy, fz = _jacobi_normals(cov[0, 0], cov[0, 1], cov[0, 2], cov[1, 1], cov[1, 2], cov[2, 2])
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
) -> tuple[
    NDArray[np.bool_],
    NDArray[np.float32],
    NDArray[np.float32],
    NDArray[np.int32],
    NDArray[np.float32],
]:
    """Step 1 on the sorted points. Returns keep (N,), local normals (N,3), local rms of the
    refined plane's inliers (N,), the first GROW_NEIGHBOURS neighbours (N, G) and the
    distance of each point to its 4th neighbour (N,)."""
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
    tri = triplets(k, t)
    bs = params.batch_size
    n_batches = (n + bs - 1) // bs
    for bi in range(n_batches):
        stop_if_asked(should_stop, "extracting roof planes")
        lo, hi = bi * bs, min(n, (bi + 1) * bs)
        if compiled:
            from . import roof_planes_numba

            roof_planes_numba.local_planes(
                grid, lo, hi, k, g, tri, params.epsilon, params.min_support, cos_lo, cos_hi, out
            )
        else:
            d2, idx = _knn_numpy(tree, q, lo, hi, k)
            out["knn"][lo:hi] = idx[:, :g]
            out["spacing"][lo:hi] = np.sqrt(d2[:, min(4, k - 1)])
            pts = (q[idx] - q[lo:hi, None, :]).astype(np.float32)
            keep, normals, quality = _ransac_numpy(pts, tri[grid.table[lo:hi]], params)
            out["keep"][lo:hi], out["normals"][lo:hi], out["quality"][lo:hi] = (
                keep,
                normals,
                quality,
            )
        if progress is not None:
            progress(0.7 * (bi + 1) / n_batches)
    return out["keep"], out["normals"], out["quality"], out["knn"], out["spacing"]


def _use_numba(backend: str) -> bool:
    """Resolve extract_roof_planes's ``backend`` argument."""
    from .roof_planes_numba import AVAILABLE

    return use_compiled(backend, AVAILABLE)
