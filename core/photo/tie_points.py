"""Automatic tie points: features, pair selection, matching, tracks.

The chain (one image's features are computed once and kept; the images themselves are not):

1. **Features** (:func:`detect_features`): SIFT (Lowe 2004; OpenCV's with its precise
   upscaling, without which every keypoint is 0.25 detection px off) or ORB (Rublee et al. 2011) on
   the grey image, optionally detected on a reduced image (an integer factor ``f``, 2 x 2 ...
   box averages) whose keypoints are scaled back to full resolution: a keypoint at OpenCV
   position ``x`` (pixel centres at integers) of the reduced image lies at
   ``col = (x + 0.5) * f`` in the project's pixel convention (centre of the first pixel at
   0.5). Descriptors are kept as 8-bit (SIFT's are integers 0..255 in OpenCV; ORB's are
   bytes): 4,000 SIFT features take 0.5 MB per image.
2. **Pairs** (:func:`select_pairs`): with an exterior orientation and a camera, the pairs
   whose ground footprints (the image corners' rays met with the plane Z = mean terrain
   height) overlap by at least ``min_overlap`` of the smaller footprint; otherwise all pairs,
   or each image with the next ``window`` images (a sequential window, the order of the
   file names).
3. **Matching** (:func:`match_pair`): nearest neighbours (SIFT: FLANN k-d trees, Muja & Lowe
   2009; ORB: brute force, Hamming), Lowe's ratio
   test (2004), a mutual check (the match must also be the best one in the other direction),
   then RANSAC on the fundamental matrix (Fischler & Bolles 1981; MAGSAC++ of Barath et al.
   2020 by default), threshold in full-resolution pixels. A pair with fewer than
   ``min_inliers`` inliers is dropped, with its reason.
4. **Tracks** (:func:`build_tracks`): the pairwise matches are the edges of a graph whose
   nodes are the keypoints of all images (keypoints of one image at one position, SIFT's
   orientations of one extremum, are one node); its connected components (union-find) are
   the tracks. A track holding two different keypoints of the same image is inconsistent and is
   dropped whole; tracks shorter than ``min_track_length`` images are dropped.

5. **Refinement** (on by default, ``refine``; :func:`refine_tracks`): least-squares matching
   (Gruen 1985) of every measurement of a track against a template cut around the track's
   reference measurement (its first image), in the full-resolution grey images (read again,
   one at a time, in image order: each image once).

Without step 5 (``refine=False``) the tie points are measured at the keypoint positions.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError, stop_if_asked
from ..geometry.camera import Camera
from .tie_data import ImageFeatures, PairMatch
from .tie_options import DETECTORS, PAIR_MODES, RANSAC_METHODS, TiePointOptions
from .tie_pairs import select_pairs
from .tie_rays import KeypointRays, fit_essential, keypoint_rays, ray_epipolar_px
from .tie_refine import RefineStats, refine_tracks
from .tie_search import (
    DescriptorIndex,
    descriptor_index,
    epipolar_distances,
    root_sift,
    search_neighbours,
)
from .tie_tracks import Tracks, build_tracks

Array = NDArray[np.float64]

__all__ = [
    "DETECTORS",
    "PAIR_MODES",
    "RANSAC_METHODS",
    "DescriptorIndex",
    "ImageFeatures",
    "PairMatch",
    "RefineStats",
    "TiePointOptions",
    "TiePointResult",
    "Tracks",
    "build_tracks",
    "descriptor_index",
    "detect_features",
    "epipolar_distances",
    "match_pair",
    "refine_tracks",
    "root_sift",
    "tie_points",
]


def reduction_factor(width_px: int, height_px: int, max_dimension_px: int) -> int:
    """Smallest integer factor bringing the longer side to at most ``max_dimension_px``.

    >>> reduction_factor(4000, 3000, 3000), reduction_factor(4000, 3000, 0)
    (2, 1)
    """
    if max_dimension_px <= 0:
        return 1
    return max(1, math.ceil(max(width_px, height_px) / max_dimension_px))


def _detector(options: TiePointOptions):
    """The OpenCV detector and the shift (detection pixels) its keypoints need.

    OpenCV's SIFT doubles the image first; by default its doubling is centre-aligned while
    the keypoints are halved as if it were corner-aligned, which puts every keypoint 0.25
    detection pixels right of and below the feature (measured here: 0.5 px between images
    turned by 180 degrees). ``enable_precise_upscale`` (OpenCV >= 4.8) removes the bias;
    with an older OpenCV the keypoints are shifted back by 0.25 px.
    """
    import cv2

    if options.detector == "sift":
        try:
            return cv2.SIFT_create(
                nfeatures=int(options.max_features),
                contrastThreshold=float(options.contrast),
                enable_precise_upscale=True,
            ), 0.0
        except TypeError:  # OpenCV < 4.8
            return cv2.SIFT_create(
                nfeatures=int(options.max_features), contrastThreshold=float(options.contrast)
            ), -0.25
    return cv2.ORB_create(
        nfeatures=int(options.max_features), scaleFactor=1.2, nlevels=8, fastThreshold=10
    ), 0.0


def _detect(img: NDArray, options: TiePointOptions):
    """(keypoints, descriptors, shift in detection px) of one detection image.

    ``keep == "response"``: OpenCV keeps the ``max_features`` strongest (|DoG| response);
    ``keep == "scale"`` (SIFT): every extremum above the contrast threshold is found, the
    ``max_features`` of the largest scale are kept (the strongest first among equal
    scales), and only those are described. Measured on two kite images at 8,192 features:
    3,396 verified matches against 2,436 for the strongest (bench/matching.md).
    """
    if options.detector != "sift" or options.keep == "response":
        detector, shift = _detector(options)
        kps, desc = detector.detectAndCompute(img, None)
        return kps, desc, shift
    detector, shift = _detector(dataclasses.replace(options, max_features=0))
    kps = detector.detect(img, None)
    if len(kps) > options.max_features:
        size = np.array([k.size for k in kps], dtype=np.float64)
        resp = np.array([k.response for k in kps], dtype=np.float64)
        order = np.lexsort((-resp, -size))[: int(options.max_features)]
        kps = [kps[k] for k in np.sort(order)]
    if not kps:
        return kps, None, shift
    kps, desc = detector.compute(img, kps)
    return kps, desc, shift


def detect_features(
    gray: NDArray,
    image_id: str,
    options: TiePointOptions,
    *,
    factor: int = 1,
    size_px: tuple[int, int] | None = None,
) -> ImageFeatures:
    """Detect and describe keypoints of one grey image.

    Parameters
    ----------
    gray : (H, W) uint8
        The image, possibly already reduced by ``factor`` (e.g. decoded at 1/2, 1/4).
    image_id : str
    options : TiePointOptions
        The image is reduced further (box average, an integer factor) until its longer side,
        at full resolution, divided by the total factor is at most ``max_dimension_px``.
    factor : int
        Full-resolution pixels per pixel of ``gray``.
    size_px : (width, height), optional
        The full image's size (default: ``gray``'s times ``factor``).

    Returns
    -------
    ImageFeatures

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> img = (rng.random((64, 64)) * 255).astype(np.uint8)
    >>> import cv2; img = cv2.resize(img, (512, 512), interpolation=cv2.INTER_CUBIC)
    >>> f = detect_features(img, "a", TiePointOptions(max_features=200, max_dimension_px=256))
    >>> f.factor, f.descriptors.dtype.name, 0 < len(f) <= 200
    (2, 'uint8', True)
    """
    import cv2

    img = np.asarray(gray)
    if img.ndim != 2:
        raise InputError(f"image {image_id}: a grey image is needed (got shape {img.shape})")
    if img.dtype != np.uint8:
        img = cv2.normalize(img, None, 0, 255, cv2.NORM_MINMAX).astype(np.uint8)
    h, w = img.shape
    full = size_px or (w * factor, h * factor)
    need = reduction_factor(full[0], full[1], options.max_dimension_px)
    extra = max(1, -(-need // factor))
    if extra > 1:  # an exact box average: crop to a multiple of the factor first
        hh, ww = (h // extra) * extra, (w // extra) * extra
        img = cv2.resize(img[:hh, :ww], (ww // extra, hh // extra), interpolation=cv2.INTER_AREA)
    total = factor * extra
    kps, desc, shift = _detect(img, options)
    if desc is None or not kps:
        width = 128 if options.detector == "sift" else 32
        return ImageFeatures(
            image_id,
            (int(full[0]), int(full[1])),
            total,
            np.zeros((0, 2)),
            np.zeros(0, np.float32),
            np.zeros((0, width), np.uint8),
        )
    xy = np.array([k.pt for k in kps], dtype=np.float64) + shift
    if options.detector == "orb":
        # ORB's pyramid levels are resized centre-aligned but their keypoints are scaled as
        # if corner-aligned: level l (scale 1.2^l) needs 0.5 (scale - 1) px added
        scale = 1.2 ** np.array([k.octave for k in kps], dtype=np.float64)
        xy += 0.5 * (scale - 1.0)[:, None]
    size = np.array([k.size for k in kps], dtype=np.float32) * total
    px = (xy + 0.5) * total
    inside = (px[:, 0] > 0) & (px[:, 1] > 0) & (px[:, 0] < full[0]) & (px[:, 1] < full[1])
    # SIFT descriptors are whole numbers 0..255 in OpenCV: 8 bits keep them exactly
    d8 = np.clip(np.rint(desc), 0, 255).astype(np.uint8) if desc.dtype != np.uint8 else desc
    return ImageFeatures(
        image_id,
        (int(full[0]), int(full[1])),
        total,
        px[inside],
        size[inside],
        np.ascontiguousarray(d8[inside]),
    )


# --------------------------------------------------------------------------- matching
def _knn(a: NDArray, b: NDArray, binary: bool, k: int):
    """(best index, best distance, second distance) of each row of ``a`` in ``b``.

    SIFT: FLANN's randomised k-d trees (Muja & Lowe 2009; 4 trees, 64 checks), an
    approximate search several times faster than brute force at a few thousand features;
    ORB: brute force on the Hamming distance. The trees are drawn from OpenCV's global
    random state, seeded here: otherwise they depend on whatever OpenCV drew before (an
    earlier pair's RANSAC, an earlier run in the process) and a repeated run differs.
    """
    import cv2

    cv2.setRNGSeed(12345)

    if binary:
        matcher = cv2.BFMatcher(cv2.NORM_HAMMING)
        qa, qb = a, b
    else:
        matcher = cv2.FlannBasedMatcher({"algorithm": 1, "trees": 4}, {"checks": 64})
        qa, qb = a.astype(np.float32), b.astype(np.float32)
    if len(qb) < k:
        k = len(qb)
    res = matcher.knnMatch(qa, qb, k=k)
    n = len(res)
    idx = np.full(n, -1, np.intp)
    d1 = np.full(n, np.inf)
    d2 = np.full(n, np.inf)
    for r, m in enumerate(res):
        if m:
            idx[r] = m[0].trainIdx
            d1[r] = m[0].distance
            if len(m) > 1:
                d2[r] = m[1].distance
    return idx, d1, d2


def match_pair(
    fa: ImageFeatures,
    fb: ImageFeatures,
    options: TiePointOptions,
    i: int = 0,
    j: int = 1,
    overlap: float = math.nan,
    rays: tuple[KeypointRays, KeypointRays] | None = None,
    index: tuple[DescriptorIndex | None, DescriptorIndex | None] | None = None,
) -> PairMatch:
    """Ratio test, mutual check and fundamental-matrix RANSAC between two images.

    The RANSAC works on the project pixel coordinates (full resolution) with a fixed seed
    (OpenCV's), so a run is repeatable. ``rays``: the keypoints' camera rays of a fisheye
    camera (:func:`~core.photo.tie_rays.keypoint_rays`): the essential matrix on the rays
    instead, distances in pixels along the epipolar curves (:mod:`core.photo.tie_rays`).
    ``index``: the two images' :func:`descriptor_index` (SIFT), built here when not given;
    :func:`tie_points` builds each image's once. With ``options.preemptive`` the pair is
    first tried on its largest keypoints only (:func:`~core.photo.tie_search.search_neighbours`).
    """
    import cv2

    empty = np.zeros(0, np.intp)

    def drop(reason: str, nr: int = 0, nm: int = 0) -> PairMatch:
        return PairMatch(i, j, empty, empty, nr, nm, 0, np.zeros(0), reason, overlap)

    if len(fa) < 2 or len(fb) < 2:
        return drop("too few features")
    binary = options.detector == "orb"
    guided = options.guided and not binary
    near = dist = np.zeros((0, 0))
    if binary:
        best, d1, d2 = _knn(fa.descriptors, fb.descriptors, True, 2)
    else:
        xa, xb = index if index is not None else (descriptor_index(fa, options), None)
        xb = xb if xb is not None else descriptor_index(fb, options)
        assert xa is not None and xb is not None
        found = search_neighbours(fa, fb, xa, xb, options, rays is None)
        if isinstance(found, str):
            return drop(found)
        near, dist = found
        best, d1, d2 = near[:, 0], dist[:, 0], dist[:, 1]
    ok = (best >= 0) & (d1 < options.ratio * d2)
    ia = np.flatnonzero(ok)
    ib = best[ia]
    n_ratio = int(ia.size)
    if options.mutual and ia.size:
        if binary:
            back = _knn(fb.descriptors[ib], fa.descriptors, True, 1)[0]
        else:
            back = xa.knn(xb.descriptors[ib], 1)[0][:, 0]
        keep = back == ia
        ia, ib = ia[keep], ib[keep]
    # a keypoint of b chosen by two of a (possible without the mutual check): drop both
    uniq, counts = np.unique(ib, return_counts=True)
    single = np.isin(ib, uniq[counts == 1])
    ia, ib = ia[single], ib[single]
    n_mutual = int(ia.size)
    if n_mutual < options.min_inliers:
        return drop(
            f"too few matches ({n_mutual} after the ratio test and mutual check)", n_ratio, n_mutual
        )
    pa, pb = fa.pixels[ia], fb.pixels[ib]
    shift = float(np.median(np.hypot(*(pb - pa).T)))
    if shift < NO_PARALLAX_PX:  # the same view twice: no geometry to find
        return drop(
            f"no parallax (median shift {shift:.2f} px over {n_mutual} matches)", n_ratio, n_mutual
        )
    if rays is None:
        method = cv2.USAC_MAGSAC if options.ransac_method == "magsac" else cv2.FM_RANSAC
        cv2.setRNGSeed(12345)
        try:
            f, mask = cv2.findFundamentalMat(pa, pb, method, float(options.ransac_px), 0.999, 10000)
        except cv2.error:
            f, mask = None, None
        if f is None or mask is None or f.shape != (3, 3):
            return drop("no fundamental matrix found (RANSAC failed)", n_ratio, n_mutual)
        inl = mask.ravel().astype(bool)

        def distance(ka: NDArray[np.intp], kb: NDArray[np.intp]) -> Array:
            return epipolar_distances(f, fa.pixels[ka], fb.pixels[kb])
    else:
        ra, rb = rays
        e = fit_essential(ra, ia, rb, ib, options.ransac_px, options.ransac_method)
        if e is None:
            return drop("no essential matrix found (RANSAC failed)", n_ratio, n_mutual)

        def distance(ka: NDArray[np.intp], kb: NDArray[np.intp]) -> Array:
            return ray_epipolar_px(e, ra, ka, rb, kb)

        with np.errstate(invalid="ignore"):
            inl = distance(ia, ib) <= options.ransac_px
    ka, kb = ia[inl], ib[inl]
    if guided and ka.size >= options.min_inliers:
        ka, kb = _guided(near, dist, distance, options, ka, kb)
    pa, pb = fa.pixels[ka], fb.pixels[kb]
    res = distance(ka, kb)
    # MAGSAC's mask is its own weighting: keep the hard threshold as well
    sel = np.flatnonzero(np.isfinite(res) & (res <= options.ransac_px))
    if options.coherence > 0 and sel.size > _NEIGHBOURS:
        diag = math.hypot(*fa.size_px)
        tol = options.coherence * diag
        sel = sel[_coherent(pa[sel], pb[sel] - _global_map(pa[sel], pb[sel], tol), tol)]
    n_in = int(sel.size)
    if n_in < options.min_inliers:
        return PairMatch(
            i,
            j,
            empty,
            empty,
            n_ratio,
            n_mutual,
            n_in,
            np.zeros(0),
            f"too few RANSAC inliers ({n_in} < {options.min_inliers})",
            overlap,
        )
    return PairMatch(i, j, ka[sel], kb[sel], n_ratio, n_mutual, n_in, res[sel], "ok", overlap)


def _guided(
    idx: NDArray[np.intp],
    dist: Array,
    distance: Callable[[NDArray[np.intp], NDArray[np.intp]], Array],
    options: TiePointOptions,
    ka: NDArray[np.intp],
    kb: NDArray[np.intp],
) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Guided matching along the epipolar lines (``distance(ka, kb)``: the epipolar distance
    of keypoints ``ka`` of a and ``kb`` of b, pixels; ``idx``,
    ``dist``: the descriptor neighbours in b of every keypoint of a, from
    :meth:`DescriptorIndex.knn`):
    each keypoint of a takes its nearest descriptor among the ``GUIDED_K`` nearest of b that lie
    within ``ransac_px`` of its epipolar line, if that one is below ``ratio`` times the next
    such neighbour (or, when it is the only one, the ``GUIDED_K``-th neighbour's distance: a
    bound, so the test is stricter than with the true second). Keypoints of b taken twice
    are dropped; the matches ``ka``, ``kb`` already verified are kept. Returns the keypoint
    indices of all the matches (a one-to-one map)."""
    n, k = idx.shape
    ra = np.repeat(np.arange(n), k)
    valid = idx.ravel() >= 0
    e = np.full(n * k, np.inf)
    e[valid] = distance(ra[valid], idx.ravel()[valid])
    with np.errstate(invalid="ignore"):
        near = (e <= options.ransac_px).reshape(n, k)
    d = np.where(near, dist, np.inf)
    order = np.argsort(d, axis=1, kind="stable")[:, :2]
    first = np.take_along_axis(d, order[:, :1], 1)[:, 0]
    second = np.take_along_axis(d, order[:, 1:2], 1)[:, 0]
    second = np.where(np.isfinite(second), second, dist[:, -1])
    ok = np.isfinite(first) & (first < options.ratio * second)
    ga = np.flatnonzero(ok)
    gb = np.take_along_axis(idx, order[:, :1], 1)[ga, 0]
    prior = np.full(n, -1, np.intp)
    prior[ka] = kb  # the verified match of a keypoint wins over its guided one
    ga, gb = ga[prior[ga] < 0], gb[prior[ga] < 0]
    ga, gb = np.concatenate([ka, ga]), np.concatenate([kb, gb])
    uniq, counts = np.unique(gb, return_counts=True)
    single = np.isin(gb, uniq[counts == 1])
    return ga[single], gb[single]


_NEIGHBOURS = 8
#: Median shift of the matches (full-resolution pixels) below which a pair is the same view
#: twice (a copy, or a camera that did not move): no parallax, no tie points.
NO_PARALLAX_PX = 0.5


def _global_map(pa: Array, pb: Array, tol_px: float) -> Array:
    """``pa`` carried into image b by a homography fitted robustly (RANSAC, ``tol_px``) to
    the matches; ``pa`` itself when none is found. The coherence test compares what is left
    of each displacement: between images turned against each other the displacement itself
    changes by twice the distance between neighbours (180 degrees), which the test must not
    take for incoherence (measured: a quarter of the right matches of such a pair dropped).

    >>> pa = np.random.default_rng(2).random((30, 2)) * 500
    >>> bool(np.allclose(_global_map(pa, 600.0 - pa, 5.0), 600.0 - pa, atol=1e-6))
    True
    """
    import cv2

    cv2.setRNGSeed(12345)
    try:
        h, _ = cv2.findHomography(pa, pb, cv2.RANSAC, float(tol_px))
    except cv2.error:
        h = None
    if h is None or h.shape != (3, 3):
        return pa
    q = np.column_stack([pa, np.ones(len(pa))]) @ h.T
    with np.errstate(divide="ignore", invalid="ignore"):
        out = q[:, :2] / q[:, 2:]
    return np.where(np.isfinite(out), out, pa)


def _coherent(p: Array, d: Array, tol_px: float) -> NDArray[np.bool_]:
    """Matches whose displacement ``d`` agrees within ``tol_px`` with the median
    displacement of their nearest matches (positions ``p`` in the first image).

    >>> p = np.random.default_rng(1).random((40, 2)) * 100
    >>> d = np.tile([5.0, 0.0], (40, 1)); d[3] = [60.0, 0.0]
    >>> np.flatnonzero(~_coherent(p, d, 10.0)).tolist()
    [3]
    """
    from scipy.spatial import cKDTree

    _, nn = cKDTree(p).query(p, k=_NEIGHBOURS + 1)
    med = np.median(d[nn[:, 1:]], axis=1)
    return np.hypot(*(d - med).T) <= tol_px


# --------------------------------------------------------------------------- the chain
#: Images whose descriptor index :func:`tie_points` keeps for their next pairs (at 16,384
#: RootSIFT features about 9 MB each).
_INDEX_CACHE = 16


@dataclass
class TiePointResult:
    """Everything :func:`tie_points` found.

    Attributes
    ----------
    image_ids : tuple of str
    features : list of int
        Keypoints per image.
    factors : list of int
        Detection reduction factor per image.
    pairs : list of PairMatch
        Every pair tried, kept or not (with the reason).
    tracks : Tracks
    sigma_px : ndarray
        A-priori sigma of each measurement of ``tracks``, pixels.
    refinement : RefineStats or None
        What the least-squares refinement did (None: not run).
    """

    image_ids: tuple[str, ...]
    features: list[int]
    factors: list[int]
    pairs: list[PairMatch]
    tracks: Tracks
    sigma_px: Array = field(default_factory=lambda: np.zeros(0))
    refinement: RefineStats | None = None

    def summary(self) -> dict[str, object]:
        """Counts for reports: pairs tried and kept, matches per kept pair (median, min,
        max), tracks by length, measurements, reasons of the dropped pairs."""
        kept = [p for p in self.pairs if p.kept]
        inl = np.array([p.n_inliers for p in kept]) if kept else np.zeros(0, int)
        reasons: dict[str, int] = {}
        for p in self.pairs:
            if not p.kept:
                key = p.status.split(" (")[0]
                reasons[key] = reasons.get(key, 0) + 1
        lengths = self.tracks.lengths()
        by_len = {int(k): int(v) for k, v in zip(*np.unique(lengths, return_counts=True))}
        res = np.concatenate([p.residual_px for p in kept]) if kept else np.zeros(0)
        seen = set(np.unique(self.tracks.image).tolist())
        return {
            "images": len(self.image_ids),
            "pairs_tried": len(self.pairs),
            "pairs_kept": len(kept),
            "inliers_median": float(np.median(inl)) if inl.size else 0.0,
            "inliers_min": int(inl.min()) if inl.size else 0,
            "inliers_max": int(inl.max()) if inl.size else 0,
            "epipolar_median_px": float(np.median(res)) if res.size else math.nan,
            "epipolar_p95_px": float(np.percentile(res, 95)) if res.size else math.nan,
            "tracks": self.tracks.n_tracks,
            "tracks_by_length": by_len,
            "measurements": int(self.tracks.track.size),
            "rejected_inconsistent": self.tracks.rejected_inconsistent,
            "images_without_tie": [i for k, i in enumerate(self.image_ids) if k not in seen],
            "dropped_pairs": reasons,
            "refinement": self.refinement,
        }

    def observations(self, prefix: str = "tp"):
        """The tie points as :class:`~lidarphoto.core.photo.observations.ImageObservations`
        (type ``tie``, point ids ``<prefix>000001`` ..., target_id empty)."""
        from .observations import ImageObservations

        t = self.tracks
        n = t.track.size
        width = max(6, len(str(t.n_tracks)))
        return ImageObservations(
            tuple(self.image_ids[k] for k in t.image),
            tuple(f"{prefix}{k + 1:0{width}d}" for k in t.track),
            t.pixels,
            self.sigma_px if self.sigma_px.size == n else np.full(n, 0.5),
            ("tie",) * n,
            ("",) * n,
        )


def tie_points(
    image_ids: Sequence[str],
    load: Callable[[int], ImageFeatures],
    options: TiePointOptions,
    footprint: Sequence[Array | None] | None = None,
    *,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
    on_features: Callable[[ImageFeatures], None] | None = None,
    load_image: Callable[[int], NDArray] | None = None,
    camera: Camera | None = None,
) -> TiePointResult:
    """The whole chain (module docstring).

    Parameters
    ----------
    image_ids : sequence of str
    load : callable
        ``load(k)`` returns the :class:`ImageFeatures` of image ``k`` (the caller reads the
        image and calls :func:`detect_features`: only the features are kept here).
    options : TiePointOptions
    footprint : sequence of (4, 2) arrays or None, optional
        Ground footprints (:func:`footprints`), for the footprint pair mode.
    progress, should_stop
        Fraction done (features 0..0.5, matching 0.5..1; with the refinement 0..0.4,
        0.4..0.8, refinement 0.8..1); cancellation per image and pair.
    load_image : callable, optional
        ``load_image(k)``: the full-resolution grey image ``k``, for ``options.refine``.
    camera : Camera, optional
        The camera of every image (full-resolution pixels). A fisheye one (any projection
        but ``perspective``) is verified on its rays (:mod:`core.photo.tie_rays`); without a
        camera, or with a perspective one, by the fundamental matrix on the pixels.
    """
    if options.refine and load_image is None:
        raise InputError("the least-squares refinement needs the images (load_image)")
    share = (0.4, 0.8) if options.refine else (0.5, 1.0)
    n = len(image_ids)
    feats: list[ImageFeatures] = []
    fisheye = camera is not None and not camera.is_perspective
    rays: list[KeypointRays] = []
    for k in range(n):
        stop_if_asked(should_stop, f"detecting features ({image_ids[k]})")
        f = load(k)
        feats.append(f)
        if fisheye:
            assert camera is not None
            rays.append(keypoint_rays(camera, f.pixels))
        if on_features is not None:
            on_features(f)
        if progress is not None:
            progress(share[0] * (k + 1) / n)
    mode = options.pair_mode
    if mode == "auto":
        mode = "footprints" if footprint is not None else "sequential"
    pairs, overlap = select_pairs(n, mode, options.window, footprint, options.min_overlap)
    results: list[PairMatch] = []
    cache: dict[int, DescriptorIndex | None] = {}

    def index_of(k: int) -> DescriptorIndex | None:
        if k not in cache:
            if len(cache) >= _INDEX_CACHE:  # the oldest goes first
                del cache[next(iter(cache))]
            cache[k] = descriptor_index(feats[k], options)
        return cache[k]

    for m, (i, j) in enumerate(pairs):
        stop_if_asked(should_stop, f"matching {image_ids[i]} with {image_ids[j]}")
        results.append(
            match_pair(
                feats[i],
                feats[j],
                options,
                i,
                j,
                overlap.get((i, j), math.nan),
                (rays[i], rays[j]) if fisheye else None,
                (index_of(i), index_of(j)),
            )
        )
        if progress is not None:
            progress(share[0] + (share[1] - share[0]) * (m + 1) / max(len(pairs), 1))
    tracks = build_tracks(feats, results, options.min_track_length)
    factors = [f.factor for f in feats]
    counts = [len(f) for f in feats]
    if options.sigma_px > 0:
        sigma = np.full(tracks.track.size, float(options.sigma_px))
    else:
        sigma = 0.5 * np.asarray(factors, float)[tracks.image] if tracks.track.size else np.zeros(0)
    stats = None
    if options.refine:
        # the descriptors are not needed any more: free them before the images
        del feats[:], rays[:]
        cache.clear()
        sub = None if progress is None else (lambda x: progress(share[1] + (1 - share[1]) * x))
        tracks, sigma, stats = refine_tracks(
            tracks, sigma, n, load_image, options, progress=sub, should_stop=should_stop
        )
        if options.sigma_px > 0:  # the value given wins
            sigma = np.full(tracks.track.size, float(options.sigma_px))
    return TiePointResult(tuple(image_ids), counts, factors, results, tracks, sigma, stats)
