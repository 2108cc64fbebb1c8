"""The descriptor search of the tie-point matching (:func:`~core.photo.tie_points.match_pair`):
RootSIFT, one FLANN index per image searched by all its pairs, the preemptive test of a pair on
its largest keypoints, and the epipolar distance."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .tie_data import ImageFeatures
from .tie_options import TiePointOptions

__all__ = [
    "GUIDED_K",
    "PREEMPTIVE_MIN",
    "DescriptorIndex",
    "descriptor_index",
    "epipolar_distances",
    "root_sift",
    "search_neighbours",
]

Array = NDArray[np.float64]


def root_sift(d: NDArray) -> NDArray[np.float32]:
    """RootSIFT (Arandjelovic & Zisserman 2012): each descriptor divided by its L1 norm and
    square-rooted, so that the Euclidean distance compares them by the Hellinger kernel,
    which separates true from false neighbours better than the Euclidean one (unit length).

    >>> root_sift(np.array([[4, 0, 0, 12]], np.uint8)).astype(float).round(3).tolist()
    [[0.5, 0.0, 0.0, 0.866]]
    """
    x = np.asarray(d, np.float32)
    return np.sqrt(x / np.maximum(x.sum(axis=1, keepdims=True), 1e-12))


class DescriptorIndex:
    """FLANN's randomised k-d trees (4 trees, ``checks`` leaves visited) over one image's
    float descriptors (RootSIFT when asked), built once per image and searched by every pair
    it is in, in both directions (OpenCV's matcher object rebuilt them for every search).
    The trees are drawn from OpenCV's random state seeded here, so a run is repeatable; a
    query's neighbours do not depend on the other queries of the batch.

    >>> d = np.eye(4, 128, dtype=np.float32)
    >>> idx, dist = DescriptorIndex(d).knn(d[[2]] * 0.5, 2)
    >>> idx.tolist(), dist.round(3).tolist()
    ([[2, 0]], [[0.5, 1.118]])
    """

    def __init__(self, descriptors: NDArray, checks: int = 64) -> None:
        import cv2

        self.checks = int(checks)
        self.descriptors = np.ascontiguousarray(descriptors, np.float32)
        cv2.setRNGSeed(12345)
        self._flann = cv2.flann_Index(self.descriptors, {"algorithm": 1, "trees": 4})  # type: ignore[attr-defined]

    def __len__(self) -> int:
        return int(self.descriptors.shape[0])

    def knn(self, query: NDArray, k: int) -> tuple[NDArray[np.intp], Array]:
        """The ``k`` nearest descriptors of every row of ``query``: indices (-1 where fewer
        were found) and Euclidean distances (inf there), each (len(query), k)."""
        k = max(1, min(k, len(self)))
        q = np.ascontiguousarray(query, np.float32)
        if q.shape[0] == 0:
            return np.zeros((0, k), np.intp), np.zeros((0, k))
        idx, d2 = self._flann.knnSearch(q, k, params={"checks": self.checks})
        idx = np.asarray(idx, np.intp).reshape(q.shape[0], k)
        dist = np.sqrt(np.maximum(np.asarray(d2, np.float64).reshape(idx.shape), 0.0))
        bad = (idx < 0) | (idx >= len(self))
        idx[bad] = -1
        dist[bad] = np.inf
        return idx, dist


def descriptor_index(features: ImageFeatures, options: TiePointOptions) -> DescriptorIndex | None:
    """The :class:`DescriptorIndex` of an image's SIFT descriptors (RootSIFT if
    ``options.root_sift``); None for ORB (matched by brute force)."""
    if options.detector == "orb" or len(features) < 2:
        return None
    d = features.descriptors
    return DescriptorIndex(root_sift(d) if options.root_sift else d, options.checks)


def epipolar_distances(f: Array, pa: Array, pb: Array) -> Array:
    """Mean of the distances of b to the epipolar line F a and of a to F^T b, pixels.

    >>> f = np.array([[0, 0, 0], [0, 0, -1], [0, 1, 0.0]])  # a pure sideways shift
    >>> epipolar_distances(f, np.array([[5.0, 3.0]]), np.array([[9.0, 3.5]])).tolist()
    [0.5]
    """
    ha = np.column_stack([pa, np.ones(len(pa))])
    hb = np.column_stack([pb, np.ones(len(pb))])
    la = ha @ f.T  # lines in b
    lb = hb @ f  # lines in a
    num = np.abs(np.sum(hb * la, axis=1))
    with np.errstate(divide="ignore", invalid="ignore"):
        db = num / np.hypot(la[:, 0], la[:, 1])
        da = num / np.hypot(lb[:, 0], lb[:, 1])
    return 0.5 * (da + db)


#: Descriptor neighbours searched per keypoint by the guided matching.
GUIDED_K = 8
#: Fewest keypoints of image a the preemptive test runs on (below it the whole search is
#: cheap, and a small subset too noisy to judge a pair by).
PREEMPTIVE_MIN = 1000


def search_neighbours(
    fa: ImageFeatures,
    fb: ImageFeatures,
    xa: DescriptorIndex,
    xb: DescriptorIndex,
    options: TiePointOptions,
    screen: bool,
) -> tuple[NDArray[np.intp], Array] | str:
    """The descriptor neighbours in b of every keypoint of a (``GUIDED_K`` of them with the
    guided matching, else 2), or the reason the pair is dropped.

    Preemptive test (``options.preemptive`` > 0, ``screen``: pixels verified by the
    fundamental matrix, and at least :data:`PREEMPTIVE_MIN` keypoints in the subset; after
    Wu 2013's preemptive matching): the largest-scale share ``preemptive`` of a's keypoints
    is searched first, ratio test, mutual check and MAGSAC on the fundamental matrix; with
    fewer than ``min_inliers`` inliers the pair is dropped without the rest of the search
    (the large scales repeat best: on 6 kite images at 16,384 features, an eighth of the
    keypoints gave 41-983 inliers in the 9 overlapping pairs, at most 11 in the others).
    Otherwise the rest is searched: the neighbours are those of the whole search, since a
    query's do not depend on the others.
    """
    import cv2

    k = GUIDED_K if options.guided else 2
    n = len(fa)
    m = int(n * options.preemptive)
    if not screen or options.preemptive <= 0 or m < PREEMPTIVE_MIN or m >= n:
        return xb.knn(xa.descriptors, k)
    sub = np.sort(np.argsort(-fa.scale_px, kind="stable")[:m])
    near_s, dist_s = xb.knn(xa.descriptors[sub], k)
    ok = (near_s[:, 0] >= 0) & (dist_s[:, 0] < options.ratio * dist_s[:, 1])
    ra, rb = np.flatnonzero(ok), near_s[ok, 0]
    if options.mutual and ra.size:
        keep = xa.knn(xb.descriptors[rb], 1)[0][:, 0] == sub[ra]
        ra, rb = ra[keep], rb[keep]
    n_in = 0
    if ra.size >= options.min_inliers:
        method = cv2.USAC_MAGSAC if options.ransac_method == "magsac" else cv2.FM_RANSAC
        cv2.setRNGSeed(12345)
        pa, pb = fa.pixels[sub[ra]], fb.pixels[rb]
        try:
            f, mask = cv2.findFundamentalMat(pa, pb, method, float(options.ransac_px), 0.999, 10000)
        except cv2.error:
            f, mask = None, None
        if f is not None and mask is not None and f.shape == (3, 3):
            fm = np.asarray(f, np.float64)
            res = epipolar_distances(fm, pa[mask.ravel() > 0], pb[mask.ravel() > 0])
            n_in = int(np.sum(res <= options.ransac_px))
    if n_in < options.min_inliers:
        return (
            f"too few inliers in the preemptive test ({n_in} < {options.min_inliers} "
            f"from the {m} largest keypoints)"
        )
    rest = np.setdiff1d(np.arange(n), sub, assume_unique=True)
    near_r, dist_r = xb.knn(xa.descriptors[rest], k)
    near = np.empty((n, near_s.shape[1]), np.intp)
    dist = np.empty((n, near_s.shape[1]))
    near[sub], dist[sub], near[rest], dist[rest] = near_s, dist_s, near_r, dist_r
    return near, dist
