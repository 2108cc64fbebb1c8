"""Steps 2 and 3 of the roof-plane extraction (:mod:`core.lidar.roof_planes`): region growing
from seeds on the neighbour graph, release of far points, reassignment to the nearest plane,
merge of coplanar neighbours, the least-squares planes of labels.

Every step is a function of the point set alone: seeds are chosen per voxel of a grid on the
map coordinates (multiples of a power-of-two size), ties go to the lower index of the sorted
points (cell, then coordinates: :mod:`core.lidar.roof_planes_local`), sums run in that order.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import stop_if_asked
from ..geometry.planes import label_moments
from .roof_planes_local import Array, ShouldStop, _eig_normals

#: core.lidar.roof_planes.RoofPlaneParams (not imported: roof_planes imports this module)
RoofPlaneParams = Any

#: Seed voxel size, in point spacings (distance to the 4th neighbour, the median over the point
#: and its GROW_NEIGHBOURS - 1 nearest), rounded to a power of two. With 8 (2 m voxels on AHN3)
#: a dormer or a small hip face of 35-90 points got 3-6 seeds, grew into regions of 13-35
#: points each that the coplanar merge did not join (their fits too rough) and that were all
#: dropped below min_plane_points: AHN3 crop 1 lost those faces and 13 of the 82 LCPs of the
#: former seeded run at their corners (77 LCPs); with 16: 806 planes, 82 LCPs, the town's
#: accuracy unchanged (bench/roof_planes.md).
SEED_VOXEL = 16.0
#: Seeding rounds of the region growing.
SEED_ROUNDS = 4


def _grow(
    q: Array,
    keep: NDArray[np.bool_],
    normals: NDArray[np.float32],
    quality: NDArray[np.float32],
    knn: NDArray[np.int32],
    spacing: NDArray[np.float32],
    params: RoofPlaneParams,
    should_stop: ShouldStop,
    compiled: bool = False,
    origin: Array | None = None,
) -> NDArray[np.int64]:
    """Step 2: region growing from many seeds at once, in waves; labels (N,), -1 elsewhere.

    Seeds: in every voxel of ``SEED_VOXEL x spacing`` rounded to a power of two, on the map
    coordinates ``q + origin`` (so a tile of the cloud has the voxels, and the seeds, of the
    whole file), the unlabelled kept point with the best local fit (lowest local rms, below
    epsilon / 2), so that points whose neighbourhood straddles a ridge never seed. Each wave,
    every region's frontier offers its points' neighbours; a kept, unlabelled neighbour joins
    when it lies within epsilon of the region's current plane and its local normal is within the
    angle tolerance of the region's normal (a point claimed by several regions goes to the
    nearest plane). Region planes are refitted after every wave from running moments about the
    seed (no cancellation). Comparing with the region's plane, not the neighbour's local normal,
    is what stops the growth at ridges and hips, where local normals blend smoothly from one
    face to the other. When all regions have stopped, the unlabelled candidates seed a new round
    (small faces next to big ones), up to ``SEED_ROUNDS`` rounds. Several seeds on one face give
    several regions: they are merged afterwards (``_merge_coplanar``).
    """
    n = len(q)
    labels = np.full(n, -1, dtype=np.int64)
    good = keep & (quality < 0.5 * params.epsilon)
    level = _voxel_level(spacing, knn, good)
    shift = np.zeros(3) if origin is None else np.asarray(origin, dtype=np.float64)
    cos_tol = math.cos(math.radians(params.angle_tolerance_deg))
    min_fit = 2 * params.k_neighbours  # below this the seed's local plane is the better one
    reg_n = np.empty((0, 3))
    reg_c = np.empty((0, 3))
    scratch = {"best_d": np.full(n, np.inf), "best_r": np.full(n, -1, dtype=np.int64)}
    for _ in range(SEED_ROUNDS):
        cand_seed = np.flatnonzero(good & (labels < 0))
        if not len(cand_seed):
            break
        lev = level[cand_seed]
        key3 = np.floor((q[cand_seed] + shift) / np.ldexp(1.0, lev)[:, None]).astype(np.int64)
        order = np.lexsort((cand_seed, quality[cand_seed], key3[:, 2], key3[:, 1], key3[:, 0], lev))
        key = np.column_stack([lev, key3])[order]
        first = np.ones(len(order), dtype=bool)
        first[1:] = (key[1:] != key[:-1]).any(axis=1)
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
            wave = (q, keep, normals, labels, knn, frontier, reg_n, reg_c, cos_tol, params.epsilon)
            if compiled:
                from . import roof_planes_numba

                cand, reg = roof_planes_numba.claims(*wave, scratch)
            else:
                cand, reg = _claims(*wave)
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
            reg_n[base + grown] = _eig_normals(cov, compiled)
            reg_c[base + grown] = origin[grown] + mean
    return labels


def _voxel_level(
    spacing: NDArray[np.float32], knn: NDArray[np.int32], good: NDArray[np.bool_]
) -> NDArray[np.int8]:
    """Per point (of ``good`` ones; 0 elsewhere): the seed voxel's size as a power of two,
    ``2 ** level`` = SEED_VOXEL x the local spacing (the lower median of the 4th-neighbour
    distances of the point and its nearest neighbours). Local, so that a tile and the whole
    file give a point the same voxel (a median over the cloud gave tiles of another density
    voxels twice as large, and other seeds, far from any border)."""
    level = np.zeros(len(spacing), dtype=np.int8)
    idx = np.flatnonzero(good)
    g = knn.shape[1]
    for lo in range(0, len(idx), 1 << 20):  # (B, G) spacings in slices: bounded memory
        part = idx[lo : lo + (1 << 20)]
        local = np.partition(spacing[knn[part]], (g - 1) // 2, axis=1)[:, (g - 1) // 2]
        size = SEED_VOXEL * np.maximum(local.astype(np.float64), 1e-9)
        level[part] = np.round(np.log2(size)).astype(np.int8)
    return level


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
    return _eig_normals(cov, compiled), centroid, counts


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

            roof_planes_numba.reassign(
                q, labels, knn, centroids, normals, eps, lo, hi, out, ambiguous
            )
            continue
        cand = np.concatenate([labels[lo:hi, None], labels[knn[lo:hi]]], axis=1)  # (B, G+1)
        valid = cand >= 0
        c = np.where(valid, cand, 0)
        rel = q[lo:hi, None, :] - centroids[c]
        nc = normals[c]
        dist = np.abs(
            rel[..., 0] * nc[..., 0] + rel[..., 1] * nc[..., 1] + rel[..., 2] * nc[..., 2]
        )
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
