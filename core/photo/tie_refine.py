"""Least-squares refinement of tie-point tracks (Gruen 1985): every measurement matched to a
template cut around its track's first measurement, in the full-resolution grey images."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError, stop_if_asked
from .tie_options import TiePointOptions
from .tie_tracks import Tracks

__all__ = ["RefineStats", "refine_tracks"]

Array = NDArray[np.float64]


#: LSM statuses that say the measurement is not the reference's point: dropped. The other
#: failures (no texture, left the window, not converged, sigma too large) say nothing
#: about the keypoint, which is kept as matched.
_BLUNDER_TEXT = ("moved too far", "low correlation")
#: Correspondences a start affine is fitted to (nearest tracks seen in both images).
_START_NEIGHBOURS = 12
#: LSM statuses of a patch it ran on and refused without calling it another point.
_RAN_TEXT = ("no texture", "left the search window", "not converged", "sigma too large")
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


#: the templates of one reference image's open tracks: (sorted track ids, templates (T, s, s),
#: the reference's sub-pixel offset from each template's centre pixel (T, 2), NaN at the border)
_Templates = tuple[NDArray[np.intp], NDArray[np.float32], Array]


@dataclass
class _Work:
    """What the refinement changes, per measurement (row of the tracks), and its tallies."""

    pix: Array
    sigma: Array
    keep: NDArray[np.bool_]
    refined: NDArray[np.bool_]
    failed: NDArray[np.bool_] | None = None  # the LSM ran and refused (not a blunder)
    kept: dict[str, int] = field(default_factory=dict)
    dropped: dict[str, int] = field(default_factory=dict)


def _count(d: dict[str, int], reason: str, m: int = 1) -> None:
    if m:
        d[reason] = d.get(reason, 0) + m


@dataclass(frozen=True)
class _Index:
    """Where the rows of sorted tracks are: per row and per image."""

    first: NDArray[np.bool_]  # (n,) the row is its track's reference
    start: NDArray[np.intp]  # (tracks,) the reference row of each track
    ref_row: NDArray[np.intp]  # (n,) each row's reference row
    last_img: NDArray[np.intp]  # (tracks,) the last image of each track
    by_image: NDArray[np.intp]  # rows sorted by image (stable: by track within an image)
    bounds: NDArray[np.intp]  # image k's rows are by_image[bounds[k]:bounds[k + 1]]

    @classmethod
    def of(cls, t: Tracks, n_images: int) -> _Index:
        n = t.track.size
        first = np.r_[True, t.track[1:] != t.track[:-1]]
        start = np.flatnonzero(first)
        by_image = np.argsort(t.image, kind="stable")
        return cls(
            first,
            start,
            start[t.track],
            t.image[np.r_[start[1:] - 1, n - 1]],
            by_image,
            np.searchsorted(t.image[by_image], np.arange(n_images + 1)),
        )

    def rows(self, k: int) -> NDArray[np.intp]:
        """Image ``k``'s rows, sorted by track."""
        return self.by_image[self.bounds[k] : self.bounds[k + 1]]


def _starts(
    t: Tracks,
    ix: _Index,
    rows_k: NDArray[np.intp],
    targets: NDArray[np.intp],
    store: dict[int, _Templates],
    size: int,
    work: _Work,
) -> tuple[NDArray[np.float32], Array, Array, NDArray[np.bool_]]:
    """For the ``targets`` rows of one image: their templates, start linear parts, template
    offsets and whether they can be matched (a start affine and a template inside)."""
    tracks_k = t.track[rows_k]
    tmpl = np.zeros((targets.size, size, size), np.float32)
    lin = np.zeros((targets.size, 2, 2))
    d_off = np.zeros((targets.size, 2))
    usable = np.zeros(targets.size, bool)
    for r in np.unique(t.image[ix.ref_row[targets]]):
        sel = np.flatnonzero(t.image[ix.ref_row[targets]] == r)
        rows_r = ix.rows(r)
        _, ir, ik = np.intersect1d(
            t.track[rows_r], tracks_k, assume_unique=True, return_indices=True
        )
        pr, pk = t.pixels[rows_r[ir]], t.pixels[rows_k[ik]]
        lin[sel], ok = _start_linear(pr, pk, t.pixels[ix.ref_row[targets[sel]]])
        ids, tp, off = store[int(r)]
        pos = np.searchsorted(ids, t.track[targets[sel]])
        valid = np.isfinite(off[pos, 0])
        tmpl[sel] = tp[pos]
        d_off[sel] = off[pos]
        usable[sel] = ok & valid
        _count(work.kept, "no start affine (fewer than 6 shared tracks)", int(np.sum(~ok)))
        _count(work.kept, "template at the image border", int(np.sum(ok & ~valid)))
    return tmpl, lin, d_off, usable


def _match(
    rows: NDArray[np.intp],
    tmpl: NDArray[np.float32],
    lin: Array,
    d_off: Array,
    img: Array,
    sigma_floor_px: float,
    work: _Work,
) -> None:
    """LSM of the measurements ``rows`` against their templates; moves, keeps or drops them."""
    from .least_squares_matching import STATUS_TEXT, LsmOptions, lsm_in_image

    arr = work.pix[rows] - 0.5
    # the template's centre pixel maps to the keypoint minus the linear part of the
    # reference's sub-pixel offset from that centre
    a0 = arr - np.einsum("qij,qj->qi", lin, d_off)
    st = np.concatenate([a0[:, :, None], lin], axis=2)
    res = lsm_in_image(tmpl, img, st, None, LsmOptions())
    new = res.affine[:, :, 0] + np.einsum("qij,qj->qi", res.affine[:, :, 1:], d_off)
    ok = res.ok
    work.pix[rows[ok]] = new[ok] + 0.5
    s = np.sqrt(0.5 * (res.sigma_px[ok] ** 2).sum(axis=1))
    work.sigma[rows[ok]] = np.maximum(s, sigma_floor_px)
    work.refined[rows[ok]] = True
    for code in np.unique(res.status[~ok]):
        reason = STATUS_TEXT[int(code)]
        m = int(np.sum(res.status == code))
        if reason in _BLUNDER_TEXT:
            work.keep[rows[res.status == code]] = False
            _count(work.dropped, reason, m)
        else:
            if work.failed is not None:
                work.failed[rows[res.status == code]] = True
            _count(work.kept, reason, m)


def _templates(t: Tracks, refs: NDArray[np.intp], img: Array, h: int) -> _Templates:
    """The templates (``2 h + 1`` pixels) around the reference rows ``refs`` of one image."""
    size = 2 * h + 1
    arr = t.pixels[refs] - 0.5
    c = np.rint(arr).astype(np.intp)
    inside = (
        (c[:, 0] >= h)
        & (c[:, 1] >= h)
        & (c[:, 0] < img.shape[1] - h)
        & (c[:, 1] < img.shape[0] - h)
    )
    tp = np.zeros((refs.size, size, size), np.float32)
    if inside.any():
        ci = c[inside]
        rr = ci[:, 1, None, None] + np.arange(-h, h + 1)[None, :, None]
        cc = ci[:, 0, None, None] + np.arange(-h, h + 1)[None, None, :]
        tp[inside] = img[rr, cc]
    off = np.where(inside[:, None], arr - c, np.nan)
    return t.track[refs], tp, off


def _finish(
    t: Tracks, ix: _Index, work: _Work, min_track_length: int, keep_unrefined: bool = True
) -> tuple[Tracks, Array, RefineStats]:
    """Reference sigmas (the median of the refined measurements of the track), the tracks
    left too short dropped, the statistics. ``keep_unrefined`` False: a measurement the LSM
    ran on and refused (``work.failed``) is dropped, its reason moved from ``kept`` to
    ``dropped``."""
    sigma, refined, keep = work.sigma, work.refined, work.keep
    if not keep_unrefined and work.failed is not None:
        for reason in [r for r in work.kept if r in _RAN_TEXT]:
            _count(work.dropped, reason, work.kept.pop(reason))
        keep &= ~work.failed
    tr = np.flatnonzero(refined)
    if tr.size:
        order = np.argsort(t.track[tr], kind="stable")
        tt = t.track[tr][order]
        ss = sigma[tr][order]
        cut = np.flatnonzero(np.r_[True, tt[1:] != tt[:-1]])
        med = np.array([np.median(v) for v in np.split(ss, cut[1:])])
        sigma[ix.start[tt[cut]]] = med
    shift = np.hypot(*(work.pix[refined] - t.pixels[refined]).T)
    # tracks too short after the drops
    length = np.bincount(t.track[keep], minlength=t.n_tracks)
    ok_track = length >= min_track_length
    had = np.bincount(t.track, minlength=t.n_tracks) > 0
    keep &= ok_track[t.track]
    new_id = np.cumsum(ok_track) - 1
    out = Tracks(
        new_id[t.track[keep]].astype(np.intp),
        t.image[keep],
        t.feature[keep],
        work.pix[keep],
        t.rejected_inconsistent,
        t.rejected_short,
    )
    stats = RefineStats(
        int(np.sum(refined & keep)),
        work.kept,
        work.dropped,
        int(np.sum(had & ~ok_track)),
        float(np.median(shift)) if shift.size else math.nan,
    )
    return out, sigma[keep], stats


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
    and its sigma (``refine_keep_unrefined`` False: drops those the LSM ran on). Tracks
    left shorter than ``min_track_length`` are dropped.

    Returns
    -------
    tracks, sigma_px, stats
    """
    t = tracks
    n = t.track.size
    h = int(options.refine_half_px)
    work = _Work(
        t.pixels.copy(),
        np.asarray(sigma_px, float).copy(),
        np.ones(n, bool),
        np.zeros(n, bool),
        None if options.refine_keep_unrefined else np.zeros(n, bool),
    )
    if n == 0:
        return t, work.sigma, RefineStats(0, work.kept, work.dropped, 0, math.nan)
    ix = _Index.of(t, n_images)
    # templates of the open tracks: reference image -> (sorted track ids, templates, offsets)
    store: dict[int, _Templates] = {}
    active = [k for k in range(n_images) if ix.bounds[k + 1] > ix.bounds[k]]
    for done, k in enumerate(active):
        stop_if_asked(should_stop, f"refining tie points (image {k + 1} of {n_images})")
        rows_k = ix.rows(k)
        img = np.asarray(load_image(k))
        if img.ndim != 2:
            raise InputError(f"image {k}: a grey image is needed for the refinement")
        img = img.astype(np.float64)
        targets = rows_k[~ix.first[rows_k]]
        tmpl, lin, d_off, usable = _starts(t, ix, rows_k, targets, store, 2 * h + 1, work)
        idx = np.flatnonzero(usable)
        for c0 in range(0, idx.size, _LSM_CHUNK):
            sel = idx[c0 : c0 + _LSM_CHUNK]
            _match(
                targets[sel],
                tmpl[sel],
                lin[sel],
                d_off[sel],
                img,
                float(options.refine_sigma_floor_px),
                work,
            )
        # this image's own templates (the tracks it is the reference of)
        store[k] = _templates(t, rows_k[ix.first[rows_k]], img, h)
        for r in [r for r, v in store.items() if v[0].size == 0 or ix.last_img[v[0]].max() <= k]:
            del store[r]
        del img
        if progress is not None:
            progress((done + 1) / len(active))
    return _finish(t, ix, work, options.min_track_length, options.refine_keep_unrefined)
