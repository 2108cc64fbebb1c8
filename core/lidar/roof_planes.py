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
   blob (cv2.findContours) simplified by Douglas-Peucker at half a cell, with z on the plane.
   It is a concave hull for display, not a measured building outline.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Any, Callable, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError, stop_if_asked
from ..geometry.planes import Plane, fit_plane

__all__ = ["SELECTION_CHOICES", "RoofPlaneParams", "RoofPlaneResult", "extract_roof_planes"]

log = logging.getLogger(__name__)

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


def _local_ransac(
    q: Array,
    tree: Any,
    params: RoofPlaneParams,
    progress: Progress,
    should_stop: ShouldStop,
) -> tuple[NDArray[np.bool_], NDArray[np.float32], Array, NDArray[np.int32], float]:
    """Step 1. Returns keep (N,), local normals (N,3), local rms of the refined plane's inliers
    (N,), the first GROW_NEIGHBOURS neighbours (N, G) and the median 4th-neighbour distance."""
    n = len(q)
    k = min(params.k_neighbours, n)
    g = min(GROW_NEIGHBOURS, k)
    t = params.ransac_iterations
    eps = np.float32(params.epsilon)
    cos_lo = math.cos(math.radians(params.max_slope_deg))
    cos_hi = math.cos(math.radians(params.min_slope_deg))
    keep = np.zeros(n, dtype=bool)
    normals = np.zeros((n, 3), dtype=np.float32)
    quality = np.zeros(n, dtype=np.float32)
    knn = np.empty((n, g), dtype=np.int32)
    spacing = []
    bs = params.batch_size
    n_batches = (n + bs - 1) // bs
    for bi in range(n_batches):
        stop_if_asked(should_stop, "extracting roof planes")
        lo, hi = bi * bs, min(n, (bi + 1) * bs)
        dist, idx = tree.query(q[lo:hi], k=k, workers=-1)
        knn[lo:hi] = idx[:, :g]
        spacing.append(dist[:, min(4, k - 1)])
        # local coordinates, relative to the query point: float32 is exact enough here
        pts = (q[idx] - q[lo:hi, None, :]).astype(np.float32)  # (B, K, 3)
        b = hi - lo
        rng = np.random.default_rng([params.seed, bi])
        tri = rng.integers(0, k, size=(b, t, 3))
        rows = np.arange(b)[:, None]
        p0 = pts[rows, tri[:, :, 0]]
        nrm = np.cross(pts[rows, tri[:, :, 1]] - p0, pts[rows, tri[:, :, 2]] - p0)
        length = np.linalg.norm(nrm, axis=2)
        valid = length > 1e-12
        nrm /= np.where(valid, length, 1.0)[..., None]
        off = -(nrm * p0).sum(axis=2)  # (B, T)
        d = np.abs(np.matmul(nrm, pts.transpose(0, 2, 1)) + off[..., None])  # (B, T, K)
        support = np.count_nonzero(d < eps, axis=2)
        support[~valid] = 0
        best = np.argmax(support, axis=1)
        best_support = support[np.arange(b), best]
        inl = d[np.arange(b), best] < eps  # (B, K)
        cnt = np.maximum(inl.sum(axis=1), 1)
        w = inl.astype(np.float64)
        p64 = pts.astype(np.float64)
        centroid = (w[..., None] * p64).sum(axis=1) / cnt[:, None]
        dev = (p64 - centroid[:, None, :]) * w[..., None]
        normal = _eig_normals(np.einsum("bki,bkj->bij", dev, dev))
        dist_point = np.abs((normal * centroid).sum(axis=1))  # query point at the origin
        res = (dev * normal[:, None, :]).sum(axis=2)  # zero outside the inliers
        quality[lo:hi] = np.sqrt((res * res).sum(axis=1) / cnt)
        nz = np.abs(normal[:, 2])
        ok = (
            (best_support >= params.min_support)
            & (dist_point < params.epsilon)
            & (nz >= cos_lo - 1e-12)
            & (nz <= cos_hi + 1e-12)
        )
        keep[lo:hi] = ok
        normals[lo:hi] = normal
        if progress is not None:
            progress(0.7 * (bi + 1) / n_batches)
    med = float(np.median(np.concatenate(spacing))) if spacing else 0.0
    return keep, normals, quality, knn, med


def _grow(
    q: Array,
    keep: NDArray[np.bool_],
    normals: NDArray[np.float32],
    quality: NDArray[np.float32],
    knn: NDArray[np.int32],
    spacing: float,
    params: RoofPlaneParams,
    should_stop: ShouldStop,
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
            cand, reg = _claims(
                q, keep, normals, labels, knn, frontier, reg_n, reg_c, cos_tol, params.epsilon
            )
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
    dist = np.abs(((q[cand] - reg_c[reg]) * reg_n[reg]).sum(axis=1))
    ok = (dist < eps) & ((normals[cand] * reg_n[reg]).sum(axis=1) > cos_tol)
    cand, reg, dist = cand[ok], reg[ok], dist[ok]
    o = np.lexsort((reg, dist, cand))
    cand, reg = cand[o], reg[o]
    uniq = np.ones(len(cand), dtype=bool)
    uniq[1:] = cand[1:] != cand[:-1]
    return cand[uniq], reg[uniq]


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


def _fit_labels(q: Array, labels: NDArray[np.int64]) -> tuple[Array, Array, NDArray]:
    """Least-squares planes of every label at once: normals (L,3), centroids (L,3), counts."""
    m = labels >= 0
    lab = labels[m]
    nl = int(lab.max()) + 1 if len(lab) else 0
    pts = q[m]
    counts = np.bincount(lab, minlength=nl).astype(np.float64)
    centroid = (
        np.column_stack([np.bincount(lab, pts[:, c], minlength=nl) for c in range(3)])
        / np.maximum(counts, 1)[:, None]
    )
    dev = pts - centroid[lab]  # two passes: no cancellation in the moments
    cov = np.empty((nl, 3, 3))
    for a in range(3):
        for b in range(a, 3):
            cov[:, a, b] = cov[:, b, a] = np.bincount(lab, dev[:, a] * dev[:, b], minlength=nl)
    return _eig_normals(cov) if nl else np.empty((0, 3)), centroid, counts


def _release_far(q: Array, labels: NDArray[np.int64], eps: float) -> NDArray[np.int64]:
    """Refit every region and release its points farther than eps from its plane."""
    if not (labels >= 0).any():
        return labels
    normals, centroids, _ = _fit_labels(q, labels)
    m = np.flatnonzero(labels >= 0)
    lab = labels[m]
    r = np.abs(((q[m] - centroids[lab]) * normals[lab]).sum(axis=1))
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
) -> tuple[NDArray[np.int64], NDArray[np.bool_]]:
    """Assign every point to the nearest plane among its own and its neighbours' (< eps).

    Returns the labels (N,) and ``ambiguous`` (N,): the point also lies within eps of another
    of those planes (ridge and hip points), so it says little about either plane.
    """
    out = np.full(len(q), -1, dtype=np.int64)
    ambiguous = np.zeros(len(q), dtype=bool)
    if not (labels >= 0).any():
        return out, ambiguous
    normals, centroids, _ = _fit_labels(q, labels)
    for lo in range(0, len(q), batch):
        stop_if_asked(should_stop, "extracting roof planes")
        hi = min(len(q), lo + batch)
        cand = np.concatenate([labels[lo:hi, None], labels[knn[lo:hi]]], axis=1)  # (B, G+1)
        valid = cand >= 0
        c = np.where(valid, cand, 0)
        dist = np.abs(((q[lo:hi, None, :] - centroids[c]) * normals[c]).sum(axis=2))
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
) -> NDArray[np.int64]:
    """Merge adjacent regions that are the same plane (e.g. split by a chimney)."""
    m = labels >= 0
    if not m.any():
        return labels
    normals, centroids, _ = _fit_labels(q, labels)
    nl = len(normals)
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
    if cv2.contourArea(poly.astype(np.float32)) < 0:  # keep counter-clockwise in x, y
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
        msg = f"no roof plane: only {n} candidate points (fewer than needed for one plane)"
        log.info(msg)
        return RoofPlaneResult((), empty, 0, params.outline_cell, msg)
    # centred once: map coordinates (1e5-1e6) would cost digits in every product below
    origin = np.floor(xyz.min(axis=0))
    q = xyz - origin
    stop_if_asked(should_stop, "extracting roof planes")
    from scipy.spatial import cKDTree

    tree = cKDTree(q, balanced_tree=False, compact_nodes=False)
    keep, normals, quality, knn, spacing = _local_ransac(q, tree, params, progress, should_stop)
    del tree
    n_cand = int(keep.sum())
    log.info("local RANSAC kept %d of %d points (%.1f %%)", n_cand, n, 100.0 * n_cand / n)
    labels = _grow(q, keep, normals, quality, knn, spacing, params, should_stop)
    del normals, quality
    if progress is not None:
        progress(0.8)
    eps = params.epsilon
    labels = _drop_small(_merge_coplanar(q, labels, knn, params), params.min_plane_points)
    for _ in range(2):
        labels = _drop_small(_release_far(q, labels, eps), params.min_plane_points)
    for _ in range(REASSIGN_PASSES):
        labels = _drop_small(
            _reassign(q, labels, knn, eps, params.batch_size * 8, should_stop)[0],
            params.min_plane_points,
        )
    labels = _merge_coplanar(q, labels, knn, params)
    labels, ambiguous = _reassign(q, labels, knn, eps, params.batch_size * 8, should_stop)
    labels = _drop_small(labels, params.min_plane_points)
    if progress is not None:
        progress(0.9)
    cell = params.outline_cell or spacing
    planes, plane_id = _final_planes(xyz, labels, keep & ~ambiguous, cell, progress, should_stop)
    if planes:
        msg = (
            f"{len(planes)} roof planes, {int((plane_id >= 0).sum())} of {n} points assigned "
            f"({n_cand} kept by the local RANSAC)"
        )
    else:
        msg = (
            f"no roof plane found among {n} points ({n_cand} passed the local RANSAC test): "
            "the cloud has no planar, roof-like surfaces with these parameters"
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
    """fit_plane + outline per region; ids by decreasing size (ties: first point index).

    Only ``fit_mask`` points enter the fit: points kept by the local RANSAC (their whole
    neighbourhood is planar) and not within epsilon of a second plane. Points attached later
    (ridges, hips, eaves, and wall points just below the eaves) keep their plane id but sit
    on one side of the plane near its edge: fitted, they tilted the planes of the synthetic
    town by 1.5x the variance the covariance reports (tests/core/test_roof_planes.py). A
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
    planes = []
    for pid, idx in enumerate(members):
        if pid % 64 == 0:
            stop_if_asked(should_stop, "extracting roof planes")
            if progress is not None:
                progress(0.9 + 0.1 * pid / len(members))
        pts = xyz[idx]
        clear = fit_mask[idx]
        fit_pts = pts[clear] if clear.sum() >= max(3, len(idx) // 2) else pts
        plane = fit_plane(fit_pts, plane_id=pid)
        planes.append(plane.with_outline(_outline(pts, plane, cell)))
    return planes, plane_id
