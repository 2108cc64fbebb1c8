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
   nodes are the keypoints of all images; its connected components (union-find) are the
   tracks. A track holding two different keypoints of the same image is inconsistent and is
   dropped whole; tracks shorter than ``min_track_length`` images are dropped.

5. **Refinement** (optional, :func:`refine_tracks`): least-squares matching (Gruen 1985) of
   every measurement of a track against a template cut around the track's reference
   measurement (its first image), in the full-resolution grey images (read again, one at a
   time, in image order: each image once).

Without step 5 the tie points are measured at the keypoint positions.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError, stop_if_asked
from .tie_pairs import select_pairs

Array = NDArray[np.float64]

__all__ = [
    "DETECTORS",
    "PAIR_MODES",
    "RANSAC_METHODS",
    "ImageFeatures",
    "PairMatch",
    "RefineStats",
    "TiePointOptions",
    "TiePointResult",
    "Tracks",
    "build_tracks",
    "detect_features",
    "match_pair",
    "refine_tracks",
    "tie_points",
]

DETECTORS = ("sift", "orb")
#: ``auto``: footprints when an orientation is given, else the sequential window.
PAIR_MODES = ("auto", "footprints", "all", "sequential")
RANSAC_METHODS = ("magsac", "ransac")


@dataclass(frozen=True)
class TiePointOptions:
    """Settings of :func:`tie_points` (units in the names).

    detector : "sift" or "orb"
    max_features : int
        Strongest keypoints kept per image.
    max_dimension_px : int
        Features are detected on the image reduced by the smallest integer factor that
        brings its longer side to at most this; 0 detects at full resolution.
    ratio : float
        Lowe's ratio: best distance / second best must be below it.
    mutual : bool
        Keep a match only if it is also the best in the other direction.
    ransac_px : float
        RANSAC threshold on the distance to the epipolar line, full-resolution pixels.
    ransac_method : "magsac" (MAGSAC++) or "ransac"
    min_inliers : int
        Fewer inliers: the pair is dropped.
    min_track_length : int
        Images a track must span.
    pair_mode : one of :data:`PAIR_MODES`
    window : int
        Sequential mode: each image is matched with the next ``window`` images.
    min_overlap : float
        Footprint mode: overlap / smaller footprint area at least this.
    sigma_px : float
        A-priori sigma written with every measurement, pixels; 0 = 0.5 px times the
        detection reduction factor.
    coherence : float
        Motion coherence: an inlier whose displacement differs from the median displacement
        of its 8 nearest inliers by more than this share of the image diagonal is dropped
        (0: no test). It removes wrong matches that slide along the epipolar line, which
        the fundamental matrix cannot see (aerial strips: all epipolar lines are parallel).
    refine : bool
        Least-squares refinement of the tracks (:func:`refine_tracks`).
    refine_half_px : int
        Half size of the LSM template, full-resolution pixels (template 2 h + 1 square).
    refine_sigma_floor_px : float
        Smallest sigma_px written for a refined measurement (the LSM sigma ignores the
        model errors of the affine patch model, e.g. relief inside the patch).
    """

    detector: str = "sift"
    max_features: int = 4000
    max_dimension_px: int = 3000
    ratio: float = 0.8
    mutual: bool = True
    ransac_px: float = 2.0
    ransac_method: str = "magsac"
    min_inliers: int = 15
    min_track_length: int = 2
    pair_mode: str = "auto"
    window: int = 5
    min_overlap: float = 0.05
    sigma_px: float = 0.0
    coherence: float = 0.03
    refine: bool = False
    refine_half_px: int = 10
    refine_sigma_floor_px: float = 0.02

    def __post_init__(self) -> None:
        if self.detector not in DETECTORS:
            raise InputError(f"detector must be one of {', '.join(DETECTORS)}")
        if self.pair_mode not in PAIR_MODES:
            raise InputError(f"pair mode must be one of {', '.join(PAIR_MODES)}")
        if self.ransac_method not in RANSAC_METHODS:
            raise InputError(f"RANSAC method must be one of {', '.join(RANSAC_METHODS)}")
        if not 0.0 < self.ratio <= 1.0:
            raise InputError(f"ratio must be in (0, 1], got {self.ratio:g}")
        if self.min_track_length < 2:
            raise InputError("a track needs at least 2 images")
        if self.min_inliers < 8:
            raise InputError("the fundamental matrix needs at least 8 inliers")
        if self.refine_half_px < 3:
            raise InputError("the refinement template needs a half size of at least 3 px")


@dataclass(frozen=True)
class ImageFeatures:
    """Keypoints of one image (full-resolution pixels, project convention).

    Attributes
    ----------
    image_id : str
    size_px : (int, int)
        Width and height of the full image.
    factor : int
        Reduction factor of the detection image (1: full resolution).
    pixels : (N, 2) float64
        col, row of each keypoint, pixels of the full image (centre of the first pixel 0.5).
    scale_px : (N,) float32
        Keypoint diameter, full-resolution pixels.
    descriptors : (N, D) uint8
        SIFT (D = 128) or ORB (D = 32 bytes).
    """

    image_id: str
    size_px: tuple[int, int]
    factor: int
    pixels: Array
    scale_px: NDArray[np.float32]
    descriptors: NDArray[np.uint8]

    def __len__(self) -> int:
        return int(self.pixels.shape[0])


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
            return cv2.SIFT_create(nfeatures=int(options.max_features),
                                   enable_precise_upscale=True), 0.0  # fmt: skip
        except TypeError:  # OpenCV < 4.8
            return cv2.SIFT_create(nfeatures=int(options.max_features)), -0.25
    return cv2.ORB_create(nfeatures=int(options.max_features), scaleFactor=1.2, nlevels=8,
                          fastThreshold=10), 0.0  # fmt: skip


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
    detector, shift = _detector(options)
    kps, desc = detector.detectAndCompute(img, None)
    if desc is None or not kps:
        width = 128 if options.detector == "sift" else 32
        return ImageFeatures(image_id, (int(full[0]), int(full[1])), total, np.zeros((0, 2)),
                             np.zeros(0, np.float32), np.zeros((0, width), np.uint8))  # fmt: skip
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
    return ImageFeatures(image_id, (int(full[0]), int(full[1])), total, px[inside],
                         size[inside], np.ascontiguousarray(d8[inside]))  # fmt: skip


# --------------------------------------------------------------------------- matching
@dataclass(frozen=True)
class PairMatch:
    """Result of matching one pair (indices into the two images' keypoints).

    ``status`` is ``ok`` or the reason the pair was dropped; ``residual_px`` is the
    symmetric distance of each inlier to its epipolar lines (full-resolution pixels, the mean
    of the two images' distances).
    """

    i: int
    j: int
    idx_i: NDArray[np.intp]
    idx_j: NDArray[np.intp]
    n_ratio: int
    n_mutual: int
    n_inliers: int
    residual_px: Array
    status: str
    overlap: float = math.nan

    @property
    def kept(self) -> bool:
        return self.status == "ok"


def _knn(a: NDArray, b: NDArray, binary: bool, k: int):
    """(best index, best distance, second distance) of each row of ``a`` in ``b``.

    SIFT: FLANN's randomised k-d trees (Muja & Lowe 2009; 4 trees, 64 checks), an
    approximate search several times faster than brute force at a few thousand features;
    ORB: brute force on the Hamming distance.
    """
    import cv2

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


def match_pair(
    fa: ImageFeatures,
    fb: ImageFeatures,
    options: TiePointOptions,
    i: int = 0,
    j: int = 1,
    overlap: float = math.nan,
) -> PairMatch:
    """Ratio test, mutual check and fundamental-matrix RANSAC between two images.

    The RANSAC works on the project pixel coordinates (full resolution) with a fixed seed
    (OpenCV's), so a run is repeatable.
    """
    import cv2

    empty = np.zeros(0, np.intp)

    def drop(reason: str, nr: int = 0, nm: int = 0) -> PairMatch:
        return PairMatch(i, j, empty, empty, nr, nm, 0, np.zeros(0), reason, overlap)

    if len(fa) < 2 or len(fb) < 2:
        return drop("too few features")
    binary = options.detector == "orb"
    best, d1, d2 = _knn(fa.descriptors, fb.descriptors, binary, 2)
    ok = (best >= 0) & (d1 < options.ratio * d2)
    ia = np.flatnonzero(ok)
    ib = best[ia]
    n_ratio = int(ia.size)
    if options.mutual and ia.size:
        back, _, _ = _knn(fb.descriptors[ib], fa.descriptors, binary, 1)
        keep = back == ia
        ia, ib = ia[keep], ib[keep]
    # a keypoint of b chosen by two of a (possible without the mutual check): drop both
    uniq, counts = np.unique(ib, return_counts=True)
    single = np.isin(ib, uniq[counts == 1])
    ia, ib = ia[single], ib[single]
    n_mutual = int(ia.size)
    if n_mutual < options.min_inliers:
        return drop(f"too few matches ({n_mutual} after the ratio test and mutual check)",
                    n_ratio, n_mutual)  # fmt: skip
    pa, pb = fa.pixels[ia], fb.pixels[ib]
    shift = float(np.median(np.hypot(*(pb - pa).T)))
    if shift < NO_PARALLAX_PX:  # the same view twice: no geometry to find
        return drop(f"no parallax (median shift {shift:.2f} px over {n_mutual} matches)",
                    n_ratio, n_mutual)  # fmt: skip
    method = cv2.USAC_MAGSAC if options.ransac_method == "magsac" else cv2.FM_RANSAC
    cv2.setRNGSeed(12345)
    try:
        f, mask = cv2.findFundamentalMat(pa, pb, method, float(options.ransac_px), 0.999, 10000)
    except cv2.error:
        f, mask = None, None
    if f is None or mask is None or f.shape != (3, 3):
        return drop("no fundamental matrix found (RANSAC failed)", n_ratio, n_mutual)
    inl = mask.ravel().astype(bool)
    res = epipolar_distances(f, pa[inl], pb[inl])
    # MAGSAC's mask is its own weighting: keep the hard threshold as well
    good = np.isfinite(res) & (res <= options.ransac_px)
    sel = np.flatnonzero(inl)[good]
    if options.coherence > 0 and sel.size > _NEIGHBOURS:
        diag = math.hypot(*fa.size_px)
        coherent = _coherent(pa[sel], pb[sel] - pa[sel], options.coherence * diag)
        sel, res = sel[coherent], res[good][coherent]
    else:
        res = res[good]
    n_in = int(sel.size)
    if n_in < options.min_inliers:
        return PairMatch(i, j, empty, empty, n_ratio, n_mutual, n_in, np.zeros(0),
                         f"too few RANSAC inliers ({n_in} < {options.min_inliers})",
                         overlap)  # fmt: skip
    return PairMatch(i, j, ia[sel], ib[sel], n_ratio, n_mutual, n_in, res, "ok", overlap)


_NEIGHBOURS = 8
#: Median shift of the matches (full-resolution pixels) below which a pair is the same view
#: twice (a copy, or a camera that did not move): no parallax, no tie points.
NO_PARALLAX_PX = 0.5


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


# --------------------------------------------------------------------------- tracks
@dataclass(frozen=True)
class Tracks:
    """Tie points: one row per measurement (image, track), sorted by track then image.

    ``track`` numbers the tracks 0..T-1; ``feature`` is the keypoint index in its image.
    ``rejected_inconsistent`` counts the tracks dropped for holding two keypoints of one
    image, ``rejected_short`` those below the minimum length.
    """

    track: NDArray[np.intp]
    image: NDArray[np.intp]
    feature: NDArray[np.intp]
    pixels: Array
    rejected_inconsistent: int
    rejected_short: int

    @property
    def n_tracks(self) -> int:
        return int(self.track.max()) + 1 if self.track.size else 0

    def lengths(self) -> NDArray[np.intp]:
        """Images per track."""
        return np.bincount(self.track, minlength=self.n_tracks)


def build_tracks(
    features: Sequence[ImageFeatures], matches: Sequence[PairMatch], min_track_length: int = 2
) -> Tracks:
    """Merge the kept pairwise matches into tracks (connected components, union-find).

    Examples
    --------
    >>> z = np.zeros((3, 2)); d = np.zeros((3, 128), np.uint8); s = np.ones(3, np.float32)
    >>> fs = [ImageFeatures(n, (10, 10), 1, z, s, d) for n in "abc"]
    >>> e = np.array([0, 1]); r = np.zeros(2)
    >>> m = [PairMatch(0, 1, e, e, 2, 2, 2, r, "ok"), PairMatch(1, 2, e, e[::-1], 2, 2, 2, r, "ok")]
    >>> t = build_tracks(fs, m)  # a0-b0-c1 and a1-b1-c0
    >>> t.n_tracks, t.lengths().tolist(), t.feature.tolist()
    (2, [3, 3], [0, 0, 1, 1, 1, 0])
    >>> m.append(PairMatch(0, 2, e[:1], e[:1], 1, 1, 1, r[:1], "ok"))  # a0-c0: joins both
    >>> t = build_tracks(fs, m); t.n_tracks, t.rejected_inconsistent
    (0, 1)
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    counts = np.array([len(f) for f in features], dtype=np.intp)
    offset = np.concatenate([[0], np.cumsum(counts)])
    kept = [m for m in matches if m.kept and m.idx_i.size]
    empty = np.zeros(0, np.intp)
    if not kept:
        return Tracks(empty, empty, empty, np.zeros((0, 2)), 0, 0)
    a = np.concatenate([offset[m.i] + m.idx_i for m in kept])
    b = np.concatenate([offset[m.j] + m.idx_j for m in kept])
    nodes, inv = np.unique(np.concatenate([a, b]), return_inverse=True)
    n = nodes.size
    ea, eb = inv[: a.size], inv[a.size :]
    graph = coo_matrix((np.ones(ea.size, np.int8), (ea, eb)), shape=(n, n))
    _, comp = connected_components(graph, directed=False)
    img = np.searchsorted(offset, nodes, side="right") - 1
    feat = nodes - offset[img]
    order = np.lexsort((img, comp))
    comp, img, feat, nodes = comp[order], img[order], feat[order], nodes[order]
    # two keypoints of one image in a track: sorted by (track, image), they are neighbours
    dup = (comp[1:] == comp[:-1]) & (img[1:] == img[:-1])
    bad = np.zeros(comp.max() + 1, bool)
    bad[comp[1:][dup]] = True
    length = np.bincount(comp)
    short = (length < min_track_length) & ~bad
    keep_comp = ~bad & ~short
    keep = keep_comp[comp]
    new_id = np.cumsum(keep_comp) - 1
    track = new_id[comp[keep]]
    pix = np.vstack([f.pixels for f in features])[nodes[keep]]
    return Tracks(track.astype(np.intp), img[keep].astype(np.intp), feat[keep].astype(np.intp),
                  pix, int(bad.sum()), int(short.sum()))  # fmt: skip


# --------------------------------------------------------------------------- refinement
#: LSM statuses that say the measurement is not the reference's point: dropped. The other
#: failures (no texture, left the window, not converged, sigma too large) say nothing
#: about the keypoint, which is kept as matched.
_BLUNDER_TEXT = ("moved too far", "low correlation")
#: Correspondences a start affine is fitted to (nearest tracks seen in both images).
_START_NEIGHBOURS = 12
_LSM_CHUNK = 4000


@dataclass(frozen=True)
class RefineStats:
    """What :func:`refine_tracks` did, per measurement other than the references.

    refined : measurements moved to their LSM position.
    kept : reason -> count of measurements left at the keypoint (LSM could not decide).
    dropped : reason -> count of measurements removed (LSM says: another point).
    tracks_dropped : tracks left with fewer than the minimum length.
    shift_median_px : median distance keypoint -> LSM position of the refined ones.
    """

    refined: int
    kept: dict[str, int]
    dropped: dict[str, int]
    tracks_dropped: int
    shift_median_px: float


def _start_linear(pr: Array, pk: Array, query: Array) -> tuple[Array, NDArray[np.bool_]]:
    """Local affine (linear part, (Q, 2, 2)) from image r to image k at ``query`` (positions
    in r), fitted to the nearest correspondences ``pr`` -> ``pk``; False where fewer than 6
    or degenerate (nearly collinear) correspondences are at hand.

    >>> rng = np.random.default_rng(0); pr = rng.random((30, 2)) * 100
    >>> lin, ok = _start_linear(pr, -pr + 7.0, pr[:2])  # turned by 180 degrees
    >>> bool(ok.all()), np.round(lin[0], 9).tolist() == [[-1, 0], [0, -1]]
    (True, True)
    """
    from scipy.spatial import cKDTree

    q = query.shape[0]
    lin = np.broadcast_to(np.eye(2), (q, 2, 2)).copy()
    if pr.shape[0] < 6:
        return lin, np.zeros(q, bool)
    kn = min(_START_NEIGHBOURS, pr.shape[0])
    _, nn = cKDTree(pr).query(query, k=kn)
    a = pr[nn]
    b = pk[nn]
    a = a - a.mean(axis=1, keepdims=True)
    b = b - b.mean(axis=1, keepdims=True)
    saa = np.einsum("qni,qnj->qij", a, a)
    sba = np.einsum("qni,qnj->qij", b, a)
    det = np.linalg.det(saa)
    tr = np.trace(saa, axis1=1, axis2=2)
    ok = det > 1e-3 * tr * tr  # eigenvalue ratio of the spread above ~1e-3
    lin[ok] = sba[ok] @ np.linalg.inv(saa[ok])
    return lin, ok


def refine_tracks(
    tracks: Tracks,
    sigma_px: Array,
    n_images: int,
    load_image: Callable[[int], NDArray],
    options: TiePointOptions,
    *,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> tuple[Tracks, Array, RefineStats]:
    """Least-squares refinement of tie point tracks (Gruen 1985, 6 affine + 2 radiometric).

    Each track's reference is its measurement in its first image (lowest index), kept fixed.
    A template of ``2 refine_half_px + 1`` full-resolution pixels is cut around it and every
    other measurement of the track is matched to it by :func:`lsm_in_image`, starting at its
    keypoint with the local affine between the two images fitted to the 12 nearest tracks
    the two images share (handles rotation, e.g. strips flown in opposite directions, and
    scale). Images are processed in index order, each read once (``load_image(k)``: the
    full-resolution grey image, array coordinates = project pixels - 0.5): an image's
    measurements are matched to the templates of earlier images, then its own templates are
    cut; a template is freed once its track's last image is done, so one image and the
    templates of the open tracks are held at a time.

    Rules: an accepted match moves the measurement and sets its sigma to the LSM position
    sigma (root mean square of col and row) with the floor ``refine_sigma_floor_px``; the
    reference gets the median sigma of its refined measurements. LSM saying the patch is
    another point (moved farther than 3 px from the keypoint, or correlation below 0.7)
    drops the measurement; any other failure (no texture, the template or patch reaches the
    image border, no convergence, sigma above 0.2 px, no start affine) keeps the keypoint
    and its sigma. Tracks left shorter than ``min_track_length`` are dropped.

    Returns
    -------
    tracks, sigma_px, stats
    """
    from .least_squares_matching import STATUS_TEXT, LsmOptions, lsm_in_image

    t = tracks
    n = t.track.size
    h = int(options.refine_half_px)
    size = 2 * h + 1
    lsm_opt = LsmOptions()
    pix = t.pixels.copy()
    sigma = np.asarray(sigma_px, float).copy()
    keep = np.ones(n, bool)
    refined = np.zeros(n, bool)
    kept: dict[str, int] = {}
    dropped: dict[str, int] = {}
    if n == 0:
        return t, sigma, RefineStats(0, kept, dropped, 0, math.nan)
    first = np.r_[True, t.track[1:] != t.track[:-1]]
    start = np.flatnonzero(first)
    ref_row = start[t.track]  # each row's reference row
    last_img = t.image[np.r_[start[1:] - 1, n - 1]]  # per track
    by_image = np.argsort(t.image, kind="stable")
    bounds = np.searchsorted(t.image[by_image], np.arange(n_images + 1))
    # templates of the open tracks: reference image -> (sorted track ids, templates, offsets)
    store: dict[int, tuple[NDArray[np.intp], NDArray[np.float32], Array]] = {}

    def count(d: dict[str, int], reason: str, m: int = 1) -> None:
        if m:
            d[reason] = d.get(reason, 0) + m

    active = [k for k in range(n_images) if bounds[k + 1] > bounds[k]]
    for done, k in enumerate(active):
        stop_if_asked(should_stop, f"refining tie points (image {k + 1} of {n_images})")
        rows_k = by_image[bounds[k] : bounds[k + 1]]  # sorted by track
        img = np.asarray(load_image(k))
        if img.ndim != 2:
            raise InputError(f"image {k}: a grey image is needed for the refinement")
        img = img.astype(np.float64)
        targets = rows_k[~first[rows_k]]
        tracks_k = t.track[rows_k]
        tmpl = np.zeros((targets.size, size, size), np.float32)
        lin = np.zeros((targets.size, 2, 2))
        d_off = np.zeros((targets.size, 2))
        usable = np.zeros(targets.size, bool)
        for r in np.unique(t.image[ref_row[targets]]):
            sel = np.flatnonzero(t.image[ref_row[targets]] == r)
            rows_r = by_image[bounds[r] : bounds[r + 1]]
            _, ir, ik = np.intersect1d(t.track[rows_r], tracks_k, assume_unique=True,
                                       return_indices=True)  # fmt: skip
            pr, pk = t.pixels[rows_r[ir]], t.pixels[rows_k[ik]]
            lin[sel], ok = _start_linear(pr, pk, t.pixels[ref_row[targets[sel]]])
            ids, tp, off = store[int(r)]
            pos = np.searchsorted(ids, t.track[targets[sel]])
            valid = np.isfinite(off[pos, 0])
            tmpl[sel] = tp[pos]
            d_off[sel] = off[pos]
            usable[sel] = ok & valid
            count(kept, "no start affine (fewer than 6 shared tracks)", int(np.sum(~ok)))
            count(kept, "template at the image border", int(np.sum(ok & ~valid)))
        idx = np.flatnonzero(usable)
        for c0 in range(0, idx.size, _LSM_CHUNK):
            sel = idx[c0 : c0 + _LSM_CHUNK]
            rows = targets[sel]
            arr = pix[rows] - 0.5
            # the template's centre pixel maps to the keypoint minus the linear part of the
            # reference's sub-pixel offset from that centre
            a0 = arr - np.einsum("qij,qj->qi", lin[sel], d_off[sel])
            st = np.concatenate([a0[:, :, None], lin[sel]], axis=2)
            res = lsm_in_image(tmpl[sel], img, st, None, lsm_opt)
            new = res.affine[:, :, 0] + np.einsum("qij,qj->qi", res.affine[:, :, 1:], d_off[sel])
            ok = res.ok
            pix[rows[ok]] = new[ok] + 0.5
            s = np.sqrt(0.5 * (res.sigma_px[ok] ** 2).sum(axis=1))
            sigma[rows[ok]] = np.maximum(s, float(options.refine_sigma_floor_px))
            refined[rows[ok]] = True
            for code in np.unique(res.status[~ok]):
                reason = STATUS_TEXT[int(code)]
                m = int(np.sum(res.status == code))
                if reason in _BLUNDER_TEXT:
                    keep[rows[res.status == code]] = False
                    count(dropped, reason, m)
                else:
                    count(kept, reason, m)
        # this image's own templates (the tracks it is the reference of)
        refs = rows_k[first[rows_k]]
        arr = t.pixels[refs] - 0.5
        c = np.rint(arr).astype(np.intp)
        inside = ((c[:, 0] >= h) & (c[:, 1] >= h) & (c[:, 0] < img.shape[1] - h)
                  & (c[:, 1] < img.shape[0] - h))  # fmt: skip
        tp = np.zeros((refs.size, size, size), np.float32)
        if inside.any():
            ci = c[inside]
            rr = ci[:, 1, None, None] + np.arange(-h, h + 1)[None, :, None]
            cc = ci[:, 0, None, None] + np.arange(-h, h + 1)[None, None, :]
            tp[inside] = img[rr, cc]
        off = np.where(inside[:, None], arr - c, np.nan)
        store[k] = (t.track[refs], tp, off)
        for r in [r for r, v in store.items() if v[0].size == 0 or last_img[v[0]].max() <= k]:
            del store[r]
        del img
        if progress is not None:
            progress((done + 1) / len(active))
    # the reference: the median sigma of its refined measurements
    tr = np.flatnonzero(refined)
    if tr.size:
        order = np.argsort(t.track[tr], kind="stable")
        tt = t.track[tr][order]
        ss = sigma[tr][order]
        cut = np.flatnonzero(np.r_[True, tt[1:] != tt[:-1]])
        med = np.array([np.median(v) for v in np.split(ss, cut[1:])])
        sigma[start[tt[cut]]] = med
    shift = np.hypot(*(pix[refined] - t.pixels[refined]).T)
    # tracks too short after the drops
    length = np.bincount(t.track[keep], minlength=t.n_tracks)
    ok_track = length >= options.min_track_length
    had = np.bincount(t.track, minlength=t.n_tracks) > 0
    keep &= ok_track[t.track]
    new_id = np.cumsum(ok_track) - 1
    out = Tracks(new_id[t.track[keep]].astype(np.intp), t.image[keep], t.feature[keep],
                 pix[keep], t.rejected_inconsistent, t.rejected_short)  # fmt: skip
    stats = RefineStats(int(np.sum(refined & keep)), kept, dropped,
                        int(np.sum(had & ~ok_track)),
                        float(np.median(shift)) if shift.size else math.nan)  # fmt: skip
    return out, sigma[keep], stats


# --------------------------------------------------------------------------- the chain
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
    """
    if options.refine and load_image is None:
        raise InputError("the least-squares refinement needs the images (load_image)")
    share = (0.4, 0.8) if options.refine else (0.5, 1.0)
    n = len(image_ids)
    feats: list[ImageFeatures] = []
    for k in range(n):
        stop_if_asked(should_stop, f"detecting features ({image_ids[k]})")
        f = load(k)
        feats.append(f)
        if on_features is not None:
            on_features(f)
        if progress is not None:
            progress(share[0] * (k + 1) / n)
    mode = options.pair_mode
    if mode == "auto":
        mode = "footprints" if footprint is not None else "sequential"
    pairs, overlap = select_pairs(n, mode, options.window, footprint, options.min_overlap)
    results: list[PairMatch] = []
    for m, (i, j) in enumerate(pairs):
        stop_if_asked(should_stop, f"matching {image_ids[i]} with {image_ids[j]}")
        results.append(match_pair(feats[i], feats[j], options, i, j,
                                  overlap.get((i, j), math.nan)))  # fmt: skip
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
        del feats[:]  # the descriptors are not needed any more: free them before the images
        sub = None if progress is None else (lambda x: progress(share[1] + (1 - share[1]) * x))
        tracks, sigma, stats = refine_tracks(tracks, sigma, n, load_image, options,
                                             progress=sub, should_stop=should_stop)  # fmt: skip
        if options.sigma_px > 0:  # the value given wins
            sigma = np.full(tracks.track.size, float(options.sigma_px))
    return TiePointResult(tuple(image_ids), counts, factors, results, tracks, sigma,
                          stats)  # fmt: skip
