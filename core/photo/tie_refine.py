"""Least-squares refinement of tie-point tracks (Gruen 1985): every measurement matched to a
template cut around its track's first measurement, in the full-resolution grey images."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

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
