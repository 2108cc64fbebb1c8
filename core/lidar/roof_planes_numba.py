"""The local planes of the roof-plane extraction compiled with numba: the same K nearest
neighbours and the same local RANSAC as the numpy back end of :mod:`core.lidar.roof_planes`,
one point after the other, without the (B, T, K) tensors.

numba is an optional dependency: :data:`AVAILABLE` tells whether it imports, and
:func:`core.lidar.roof_planes.extract_roof_planes` falls back to numpy (scipy's cKDTree and the
vectorised RANSAC) without it. Both back ends give the same result bit for bit: the
neighbours are the K nearest with ties broken by the lower index (distances computed as
``dx dx + dy dy + dz dz`` in that order), every RANSAC quantity is computed with the same
operations in the same order and precision (float32 for the triplet planes, float64 for the
refit, sums in neighbour order), and the refit's normal comes from the same fixed Jacobi
rotations (:func:`core.lidar.roof_planes._jacobi_normals`), not from LAPACK;
tests/core/test_roof_plane_backends.py compares them point by point.

The neighbour search walks a grid of ``cell`` (CRS unit) over x, y in which the points are
sorted by cell: from the point's cell outwards, in the order of the smallest possible distance
of each cell (``offsets``), keeping the K best (d^2, index) pairs in a sorted list, and stops
when the next cell cannot hold a nearer point.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ..compiled import Kernels
from ..geometry.sym3 import JACOBI_SWEEPS  # the numpy back end's sweeps

try:  # pragma: no cover - depends on the environment
    import numba

    AVAILABLE = True
except Exception:  # ImportError, or a numba built against another numpy
    numba = None
    AVAILABLE = False

__all__ = ["AVAILABLE", "local_planes"]

#: Previous points whose k-th distance bounds the next point's (the search's first cut).
LAST = 4
#: Relative margin of the cell pruning.
SLACK = 1.0 + 1e-9


def _jit_helper(func: Callable[..., Any]) -> Callable[..., Any]:
    """numba.njit for a small function the kernels call (compiled into each calling kernel
    and its cache entry); the plain function without numba, where no kernel runs."""
    return numba.njit(nogil=True, inline="always")(func) if AVAILABLE else func


@_jit_helper
def _sq_dist(qs, s, px, py, pz):
    """Squared distance of point ``s`` of ``qs`` to (px, py, pz): dx dx + dy dy + dz dz in
    that order (the numpy back end's)."""
    dx = qs[s, 0] - px
    dy = qs[s, 1] - py
    dz = qs[s, 2] - pz
    return dx * dx + dy * dy + dz * dz


@_jit_helper
def _deviation(px32, py32, pz32, inl, j, mx, my, mz):
    """Neighbour j's deviation from the inliers' mean (float64), zero when it is no inlier."""
    w = 1.0 if inl[j] else 0.0
    ex = (np.float64(px32[j]) - mx) * w
    ey = (np.float64(py32[j]) - my) * w
    ez = (np.float64(pz32[j]) - mz) * w
    return ex, ey, ez


@_jit_helper
def _rotate(c, s, a, b):
    """The Jacobi rotation (c, s) of the pair (a, b): (c a - s b, s a + c b)."""
    return c * a - s * b, s * a + c * b


@_jit_helper
def _rotate_columns(c, s, a0, b0, a1, b1, a2, b2):
    """The Jacobi rotation (c, s) of two columns (a, b) of the 3 x 3 eigenvectors, row by row."""
    a0, b0 = _rotate(c, s, a0, b0)
    a1, b1 = _rotate(c, s, a1, b1)
    a2, b2 = _rotate(c, s, a2, b2)
    return a0, b0, a1, b1, a2, b2


@_jit_helper
def _plane_dist(q, i, centre, normal, c):
    """Distance of point i of q to plane c (row c of ``centre`` and ``normal``)."""
    return abs(
        (q[i, 0] - centre[c, 0]) * normal[c, 0]
        + (q[i, 1] - centre[c, 1]) * normal[c, 1]
        + (q[i, 2] - centre[c, 2]) * normal[c, 2]
    )


@_jit_helper
def _first_cut(qs, last_r, last_i, px, py, pz):
    """Squared bound on the k-th distance of (px, py, pz): a point's k-th distance is at most
    a previous point's plus their distance (the search's first cut; inf for none)."""
    cut = np.inf
    for u in range(LAST):
        if last_r[u] < np.inf:
            rr = last_r[u] + np.sqrt(_sq_dist(qs, last_i[u], px, py, pz))
            rr = rr * rr * (1.0 + 1e-9)  # above any rounding of the squares below
            if rr < cut:
                cut = rr
    return cut


@_jit_helper
def _nearest(qs, cell_of, start, nx, ny, x0, y0, h, offs, bound2, i, k, cut, bd, bi):
    """The k nearest neighbours of point i of ``qs`` into (bd, bi), ascending (d^2, index):
    the points of the cells in the offsets' order, then, if fewer than k were within the
    offsets' reach, every point (one pass, from an empty list). The insertion stays inline in
    the loop (as a helper of its own the local planes took 5 % longer)."""
    no = offs.shape[0]
    px = qs[i, 0]
    py = qs[i, 1]
    pz = qs[i, 2]
    c = cell_of[i]
    cy = c // nx
    cx = c - cy * nx
    m = 0
    o = 0
    every = False
    while True:
        # the cell bounds carry rounding of about 1e-16 of the coordinates: prune with a
        # margin, so that a tie at the k-th distance is never cut off
        if o < no and not bound2[o] > cut * SLACK:
            gx = cx + offs[o, 0]
            gy = cy + offs[o, 1]
            o += 1
            if gx < 0 or gy < 0 or gx >= nx or gy >= ny:
                continue
            cc = gy * nx + gx
            a = start[cc]
            b = start[cc + 1]
            if a == b:
                continue
            if cut < np.inf:
                lx = x0 + gx * h
                ly = y0 + gy * h
                ex = max(lx - px, 0.0, px - lx - h)
                ey = max(ly - py, 0.0, py - ly - h)
                if ex * ex + ey * ey > cut * SLACK:
                    continue
        elif m < k and not every:
            every = True
            o = no
            m = 0
            cut = np.inf
            a = 0
            b = qs.shape[0]
        else:
            break
        for s in range(a, b):
            d2 = _sq_dist(qs, s, px, py, pz)
            if d2 > cut:
                continue
            if m < k:
                t = m
                m += 1
            elif d2 < bd[k - 1] or (d2 == bd[k - 1] and s < bi[k - 1]):
                t = k - 1
            else:
                continue
            while t > 0 and (bd[t - 1] > d2 or (bd[t - 1] == d2 and bi[t - 1] > s)):
                bd[t] = bd[t - 1]
                bi[t] = bi[t - 1]
                t -= 1
            bd[t] = d2
            bi[t] = s
            if m == k and bd[k - 1] < cut:
                cut = bd[k - 1]


@_jit_helper
def _best_triplet(px32, py32, pz32, k, tri, tab, eps32, tiny32):
    """RANSAC over the triplets of table ``tab`` (float32, relative to the point): the most
    supported plane (support, nx, ny, nz, offset); the first of equal supports wins."""
    best_support = -1
    bnx = np.float32(0.0)
    bny = np.float32(0.0)
    bnz = np.float32(0.0)
    boff = np.float32(0.0)
    for t in range(tri.shape[1]):
        a0 = tri[tab, t, 0]
        a1 = tri[tab, t, 1]
        a2 = tri[tab, t, 2]
        ax, ay, az = px32[a0], py32[a0], pz32[a0]
        ux = px32[a1] - ax
        uy = py32[a1] - ay
        uz = pz32[a1] - az
        vx = px32[a2] - ax
        vy = py32[a2] - ay
        vz = pz32[a2] - az
        nx_ = uy * vz - uz * vy
        ny_ = uz * vx - ux * vz
        nz_ = ux * vy - uy * vx
        length = np.sqrt(nx_ * nx_ + ny_ * ny_ + nz_ * nz_)
        valid = length > tiny32
        if not valid:
            length = np.float32(1.0)
        nx_ = nx_ / length
        ny_ = ny_ / length
        nz_ = nz_ / length
        off = -(nx_ * ax + ny_ * ay + nz_ * az)
        support = 0
        if valid:
            for j in range(k):
                d = abs(nx_ * px32[j] + ny_ * py32[j] + nz_ * pz32[j] + off)
                if d < eps32:
                    support += 1
        if support > best_support:
            best_support = support
            bnx, bny, bnz, boff = nx_, ny_, nz_, off
    return best_support, bnx, bny, bnz, boff


@_jit_helper
def _inlier_moments(px32, py32, pz32, inl, k, cnt):
    """Mean (float64) of the inliers and the upper triangle of their scatter about it, summed
    in neighbour order."""
    sx = 0.0
    sy = 0.0
    sz = 0.0
    for j in range(k):
        w = 1.0 if inl[j] else 0.0
        sx += w * np.float64(px32[j])
        sy += w * np.float64(py32[j])
        sz += w * np.float64(pz32[j])
    mx = sx / cnt
    my = sy / cnt
    mz = sz / cnt
    a00 = 0.0
    a01 = 0.0
    a02 = 0.0
    a11 = 0.0
    a12 = 0.0
    a22 = 0.0
    for j in range(k):
        ex, ey, ez = _deviation(px32, py32, pz32, inl, j, mx, my, mz)
        a00 += ex * ex
        a01 += ex * ey
        a02 += ex * ez
        a11 += ey * ey
        a12 += ey * ez
        a22 += ez * ez
    return mx, my, mz, a00, a01, a02, a11, a12, a22


@_jit_helper
def _jacobi_normal(a00, a01, a02, a11, a12, a22):
    """Upward unit normal (smallest eigenvector) of a symmetric 3 x 3 by JACOBI_SWEEPS sweeps
    of rotations (the numpy back end's _jacobi_normals, scalar)."""
    v00, v01, v02 = 1.0, 0.0, 0.0
    v10, v11, v12 = 0.0, 1.0, 0.0
    v20, v21, v22 = 0.0, 0.0, 1.0
    for _ in range(JACOBI_SWEEPS):
        for rot in range(3):
            if rot == 0:
                app, aqq, apq = a00, a11, a01
            elif rot == 1:
                app, aqq, apq = a00, a22, a02
            else:
                app, aqq, apq = a11, a22, a12
            if apq == 0.0:
                continue
            theta = (aqq - app) / (2.0 * apq)
            tt = 1.0 / (abs(theta) + np.sqrt(theta * theta + 1.0))
            if theta < 0.0:
                tt = -tt
            cc_ = 1.0 / np.sqrt(tt * tt + 1.0)
            ss = tt * cc_
            napp = app - tt * apq
            naqq = aqq + tt * apq
            if rot == 0:  # p = 0, q = 1, r = 2
                a00, a11, a01 = napp, naqq, 0.0
                a02, a12 = _rotate(cc_, ss, a02, a12)
                v00, v01, v10, v11, v20, v21 = _rotate_columns(
                    cc_, ss, v00, v01, v10, v11, v20, v21
                )
            elif rot == 1:  # p = 0, q = 2, r = 1
                a00, a22, a02 = napp, naqq, 0.0
                a01, a12 = _rotate(cc_, ss, a01, a12)
                v00, v02, v10, v12, v20, v22 = _rotate_columns(
                    cc_, ss, v00, v02, v10, v12, v20, v22
                )
            else:  # p = 1, q = 2, r = 0
                a11, a22, a12 = napp, naqq, 0.0
                a01, a02 = _rotate(cc_, ss, a01, a02)
                v01, v02, v11, v12, v21, v22 = _rotate_columns(
                    cc_, ss, v01, v02, v11, v12, v21, v22
                )
    if a00 <= a11 and a00 <= a22:
        nx_, ny_, nz_ = v00, v10, v20
    elif a11 <= a22:
        nx_, ny_, nz_ = v01, v11, v21
    else:
        nx_, ny_, nz_ = v02, v12, v22
    if nz_ < 0.0:
        nx_, ny_, nz_ = -nx_, -ny_, -nz_
    return nx_, ny_, nz_


def _normals_kernel(cov, out):
    """Upward normals (B, 3) of the 3 x 3 matrices ``cov`` (B, 3, 3) by :func:`_jacobi_normal`
    (roof_planes_local._eig_normals' compiled path; the same bits as its numpy path)."""
    for b in range(cov.shape[0]):
        out[b, 0], out[b, 1], out[b, 2] = _jacobi_normal(
            cov[b, 0, 0], cov[b, 0, 1], cov[b, 0, 2], cov[b, 1, 1], cov[b, 1, 2], cov[b, 2, 2]
        )


def _local_planes_kernel(
    qs,
    cell_of,
    start,
    nx,
    ny,
    x0,
    y0,
    h,
    offs,
    bound2,
    lo,
    hi,
    k,
    g,
    tri,
    table,
    eps,
    min_support,
    cos_lo,
    cos_hi,
    keep,
    normals,
    quality,
    knn,
    spacing,
):
    """Points lo .. hi-1 of ``qs`` (sorted by grid cell): K nearest neighbours and the local
    RANSAC; outputs at [i - lo] (keep, normals, quality, knn (first g), spacing)."""
    bd = np.empty(k)
    bi = np.empty(k, np.int64)
    px32 = np.empty(k, np.float32)
    py32 = np.empty(k, np.float32)
    pz32 = np.empty(k, np.float32)
    inl = np.empty(k, np.bool_)
    eps32 = np.float32(eps)
    tiny32 = np.float32(1e-12)
    last_r = np.full(max(LAST, 1), np.inf)
    last_i = np.zeros(max(LAST, 1), np.int64)
    for i in range(lo, hi):
        px = qs[i, 0]
        py = qs[i, 1]
        pz = qs[i, 2]
        cut = _first_cut(qs, last_r, last_i, px, py, pz)
        _nearest(qs, cell_of, start, nx, ny, x0, y0, h, offs, bound2, i, k, cut, bd, bi)
        slot = i % max(LAST, 1)
        last_r[slot] = np.sqrt(bd[k - 1])
        last_i[slot] = i
        r = i - lo
        for t in range(g):
            knn[r, t] = bi[t]
        spacing[r] = np.sqrt(bd[min(4, k - 1)])
        # --- local RANSAC on the K neighbours, relative to the point (float32)
        for j in range(k):
            s = bi[j]
            px32[j] = np.float32(qs[s, 0] - px)
            py32[j] = np.float32(qs[s, 1] - py)
            pz32[j] = np.float32(qs[s, 2] - pz)
        best_support, bnx, bny, bnz, boff = _best_triplet(
            px32, py32, pz32, k, tri, table[i], eps32, tiny32
        )
        cnt = 0
        for j in range(k):
            d = abs(bnx * px32[j] + bny * py32[j] + bnz * pz32[j] + boff)
            inl[j] = d < eps32
            if inl[j]:
                cnt += 1
        cnt = max(cnt, 1)
        # refit on the inliers (float64, sums in neighbour order)
        mx, my, mz, a00, a01, a02, a11, a12, a22 = _inlier_moments(px32, py32, pz32, inl, k, cnt)
        nx_, ny_, nz_ = _jacobi_normal(a00, a01, a02, a11, a12, a22)
        dist_point = abs(nx_ * mx + ny_ * my + nz_ * mz)
        rr = 0.0
        for j in range(k):
            ex, ey, ez = _deviation(px32, py32, pz32, inl, j, mx, my, mz)
            res = ex * nx_ + ey * ny_ + ez * nz_
            rr += res * res
        quality[r] = np.sqrt(rr / cnt)
        nz_abs = abs(nz_)
        keep[r] = (
            best_support >= min_support
            and dist_point < eps
            and nz_abs >= cos_lo - 1e-12
            and nz_abs <= cos_hi + 1e-12
        )
        normals[r, 0] = nx_
        normals[r, 1] = ny_
        normals[r, 2] = nz_


def _claims_kernel(
    q,
    keep,
    normals,
    labels,
    knn,
    frontier,
    reg_n,
    reg_c,
    cos_tol,
    eps,
    best_d,
    best_r,
    out_cand,
    out_reg,
):
    """One wave of the region growing (roof_planes._claims): the unlabelled kept neighbours of
    the frontier that fit their region, each to the nearest region plane (ties: the lower
    region); returns their number m, out_cand[:m] sorted, out_reg[:m]. best_d / best_r are
    scratch arrays (inf / -1) restored before returning."""
    g = knn.shape[1]
    m = 0
    for f in range(frontier.shape[0]):
        i = frontier[f]
        reg = labels[i]
        for t in range(g):
            j = knn[i, t]
            if not keep[j] or labels[j] >= 0:
                continue
            dist = _plane_dist(q, j, reg_c, reg_n, reg)
            if not dist < eps:
                continue
            cosang = (
                np.float64(normals[j, 0]) * reg_n[reg, 0]
                + np.float64(normals[j, 1]) * reg_n[reg, 1]
                + np.float64(normals[j, 2]) * reg_n[reg, 2]
            )
            if not cosang > cos_tol:
                continue
            if best_r[j] < 0:
                out_cand[m] = j
                m += 1
                best_d[j] = dist
                best_r[j] = reg
            elif dist < best_d[j] or (dist == best_d[j] and reg < best_r[j]):
                best_d[j] = dist
                best_r[j] = reg
    cand = np.sort(out_cand[:m])
    for t in range(m):
        j = cand[t]
        out_cand[t] = j
        out_reg[t] = best_r[j]
        best_d[j] = np.inf
        best_r[j] = -1
    return m


def _reassign_kernel(q, labels, knn, centroids, normals, eps, lo, hi, out, ambiguous):
    """Points lo .. hi-1 to the nearest plane among their own and their neighbours' labels,
    within eps (roof_planes._reassign); ``ambiguous`` when another of those planes is within
    eps too."""
    g = knn.shape[1]
    for i in range(lo, hi):
        best = np.inf
        chosen = -1
        for t in range(g + 1):
            c = labels[i] if t == 0 else labels[knn[i, t - 1]]
            if c < 0:
                continue
            d = _plane_dist(q, i, centroids, normals, c)
            if d < best:
                best = d
                chosen = c
        if chosen >= 0 and best < eps:
            out[i] = chosen
            other = False
            for t in range(g + 1):
                c = labels[i] if t == 0 else labels[knn[i, t - 1]]
                if c < 0 or c == chosen:
                    continue
                d = _plane_dist(q, i, centroids, normals, c)
                if d < eps:
                    other = True
                    break
            ambiguous[i] = other
        else:
            out[i] = -1
            ambiguous[i] = False


def _pairs_kernel(labels, knn, nl, out):
    """Keys min * nl + max of the label pairs of neighbouring points with different labels
    (roof_planes._merge_coplanar); returns how many were written (with repeats)."""
    g = knn.shape[1]
    m = 0
    for i in range(labels.shape[0]):
        a = labels[i]
        if a < 0:
            continue
        for t in range(g):
            b = labels[knn[i, t]]
            if b < 0 or b == a:
                continue
            out[m] = min(a, b) * nl + max(a, b)
            m += 1
    return m


def _order_kernel(key, nbins, xyz, start, order):
    """Counting sort: ``order`` lists the indices by key, and within a key by x, then y, then
    z, then index (numpy's lexsort of (z, y, x, key)); ``start`` (nbins + 1) the first
    position of each key. A cell holds a few points: insertion sort."""
    for i in range(key.shape[0]):
        start[key[i] + 1] += 1
    for b in range(nbins):
        start[b + 1] += start[b]
    fill = start[:-1].copy()
    for i in range(key.shape[0]):
        order[fill[key[i]]] = i
        fill[key[i]] += 1
    for b in range(nbins):
        for u in range(start[b] + 1, start[b + 1]):
            i = order[u]
            t = u
            while t > start[b]:
                j = order[t - 1]
                if xyz[j, 0] < xyz[i, 0] or (
                    xyz[j, 0] == xyz[i, 0]
                    and (
                        xyz[j, 1] < xyz[i, 1] or (xyz[j, 1] == xyz[i, 1] and xyz[j, 2] <= xyz[i, 2])
                    )
                ):
                    break
                order[t] = j
                t -= 1
            order[t] = i


def _moments_kernel(q, labels, nl, counts, centroid, cov):
    """Per label: count, centroid, and the scatter of the deviations from it (upper triangle
    xx xy xz yy yz zz): the sums of roof_planes._fit_labels, in index order, two passes."""
    for i in range(q.shape[0]):
        c = labels[i]
        if c < 0:
            continue
        counts[c] += 1.0
        centroid[c, 0] += q[i, 0]
        centroid[c, 1] += q[i, 1]
        centroid[c, 2] += q[i, 2]
    for c in range(nl):
        d = max(counts[c], 1.0)
        centroid[c, 0] = centroid[c, 0] / d
        centroid[c, 1] = centroid[c, 1] / d
        centroid[c, 2] = centroid[c, 2] / d
    for i in range(q.shape[0]):
        c = labels[i]
        if c < 0:
            continue
        ex = q[i, 0] - centroid[c, 0]
        ey = q[i, 1] - centroid[c, 1]
        ez = q[i, 2] - centroid[c, 2]
        cov[c, 0] += ex * ex
        cov[c, 1] += ex * ey
        cov[c, 2] += ex * ez
        cov[c, 3] += ey * ey
        cov[c, 4] += ey * ez
        cov[c, 5] += ez * ez


#: The jitted functions (each compiled at its first call, cached: core/compiled.py; the
#: helpers a kernel calls are compiled into its cache entry).
_compiled = Kernels(
    {
        "local_planes": _local_planes_kernel,
        "claims": _claims_kernel,
        "reassign": _reassign_kernel,
        "pairs": _pairs_kernel,
        "order": _order_kernel,
        "moments": _moments_kernel,
        "normals": _normals_kernel,
    }
)


def local_planes(
    grid: Any,
    lo: int,
    hi: int,
    k: int,
    g: int,
    tri: np.ndarray,
    eps: float,
    min_support: int,
    cos_lo: float,
    cos_hi: float,
    out: dict[str, np.ndarray],
) -> None:
    """Neighbours and local RANSAC of points ``lo .. hi-1`` of ``grid`` (a
    :class:`core.lidar.roof_planes.PointGrid`) into ``out[name][lo:hi]`` (keep, normals,
    quality, knn, spacing)."""
    if not AVAILABLE:
        raise RuntimeError("numba is not installed")
    _compiled("local_planes")(
        grid.q,
        grid.cell_of,
        grid.start,
        grid.nx,
        grid.ny,
        grid.x0,
        grid.y0,
        grid.cell,
        grid.offsets,
        grid.bound2,
        lo,
        hi,
        k,
        g,
        tri,
        grid.table,
        float(eps),
        int(min_support),
        float(cos_lo),
        float(cos_hi),
        out["keep"][lo:hi],
        out["normals"][lo:hi],
        out["quality"][lo:hi],
        out["knn"][lo:hi],
        out["spacing"][lo:hi],
    )


def claims(
    q: np.ndarray,
    keep: np.ndarray,
    normals: np.ndarray,
    labels: np.ndarray,
    knn: np.ndarray,
    frontier: np.ndarray,
    reg_n: np.ndarray,
    reg_c: np.ndarray,
    cos_tol: float,
    eps: float,
    scratch: dict[str, np.ndarray],
) -> tuple[np.ndarray, np.ndarray]:
    """One wave of the region growing (see roof_planes._claims): (points, regions)."""
    size = min(len(frontier) * knn.shape[1], len(q))
    cand = np.empty(size, dtype=np.int64)
    reg = np.empty(size, dtype=np.int64)
    m = _compiled("claims")(
        q,
        keep,
        normals,
        labels,
        knn,
        frontier.astype(np.int64),
        reg_n,
        reg_c,
        float(cos_tol),
        float(eps),
        scratch["best_d"],
        scratch["best_r"],
        cand,
        reg,
    )
    return cand[:m], reg[:m]


def reassign(
    q: np.ndarray,
    labels: np.ndarray,
    knn: np.ndarray,
    centroids: np.ndarray,
    normals: np.ndarray,
    eps: float,
    lo: int,
    hi: int,
    out: np.ndarray,
    ambiguous: np.ndarray,
) -> None:
    """Points lo .. hi-1 of roof_planes._reassign into out / ambiguous."""
    _compiled("reassign")(q, labels, knn, centroids, normals, float(eps), lo, hi, out, ambiguous)


def label_pairs(labels: np.ndarray, knn: np.ndarray, nl: int) -> np.ndarray:
    """The distinct keys min * nl + max of neighbouring labels (roof_planes._merge_coplanar)."""
    boundary = labels >= 0
    out = np.empty(int(boundary.sum()) * knn.shape[1] + 1, dtype=np.int64)
    m = _compiled("pairs")(labels, knn, int(nl), out)
    return np.unique(out[:m])


def counting_order(key: np.ndarray, nbins: int, xyz: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(order, start) of a counting sort of ``key`` in [0, nbins), each key's points by their
    coordinates ``xyz`` (N, 3): numpy's lexsort of (z, y, x, key)."""
    start = np.zeros(nbins + 1, dtype=np.int64)
    order = np.empty(len(key), dtype=np.int64)
    _compiled("order")(
        key.astype(np.int64, copy=False),
        int(nbins),
        np.ascontiguousarray(xyz, dtype=np.float64),
        start,
        order,
    )
    return order, start


def normals(cov: np.ndarray) -> np.ndarray:
    """Upward unit normals (B, 3) of symmetric 3 x 3 matrices (B, 3, 3), Jacobi rotations."""
    out = np.empty((cov.shape[0], 3))
    _compiled("normals")(np.ascontiguousarray(cov, dtype=np.float64), out)
    return out


def moments(q: np.ndarray, labels: np.ndarray, nl: int) -> tuple[np.ndarray, ...]:
    """Counts (nl,), centroids (nl, 3), scatter upper triangles (nl, 6) per label."""
    counts = np.zeros(nl)
    centroid = np.zeros((nl, 3))
    cov = np.zeros((nl, 6))
    _compiled("moments")(q, labels.astype(np.int64, copy=False), int(nl), counts, centroid, cov)
    return counts, centroid, cov
