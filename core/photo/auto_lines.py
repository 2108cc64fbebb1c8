"""Automatic line observations: image edges found along projected LiDAR ridge, hip and valley
lines (issue 32, step 3).

Each LiDAR line (:class:`core.lidar.control.ControlLine`, mapping CRS) is sampled in 3D and
projected into the image through the project's collinearity chain with the lens model
(:class:`core.photo.picking.PickingScene`), so a curved image of a straight line under
distortion is followed exactly; samples behind the camera or outside the frame are dropped.
At every ``spacing_px`` along the projection, the dock's sub-pixel routine
:func:`core.photo.line_edge.refine_edge_point` moves the sample across the line to the
strongest edge within ``search_px`` (derived from the pose uncertainty by the caller). A
sample is refused when the edge is weak (grey step across it below ``min_contrast``) or
ambiguous (a second gradient peak, away from the chosen one, stronger than ``ambiguity`` of
it). Per line, the signed offsets from the prediction are fitted by a straight function of
the position along the line (a small pose error shifts and turns the projection); samples
more than ``outlier_sigmas`` robust sigmas off the fit are refused and the fit's residual
RMS is each kept point's ``sigma_px`` (a fit whose RMS shows two populations restarts from
its least-median-of-squares line). Lines with fewer than ``min_points`` kept points give
nothing. Per image, a line's segment off the displacement of the image's other segments (its
pose error: :func:`_screen_segments`) is on another edge and is dropped. Pixels follow
docs/conventions.md ("Images"): (col, row), first pixel centre (0.5, 0.5).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.ndimage import map_coordinates

from ..errors import InputError
from ..geometry.camera import Camera
from ..lidar.control import ControlLine
from .auto_boresight_options import AutoLineOptions
from .line_edge import refine_edge_point
from .observations import ImageObservations
from .orientation import ExteriorOrientationTable
from .picking import PickingScene

__all__ = ["REFUSALS", "AutoLineOptions", "line_observations", "line_observations_block"]

#: Why found edge points are refused (the counts of ``refused``): off the straight fit of their
#: line's offsets in the image, or in a segment off the displacement of the image's other lines.
REFUSALS = ("off the line's fit", "segment off the image's other lines")

Array = NDArray[np.float64]


def _grey(image: ArrayLike) -> Array:
    a = np.asarray(image, dtype=np.float64)
    if a.ndim == 3:  # RGB(A): luminance of the first three bands
        a = a[..., :3] @ np.array([0.299, 0.587, 0.114])
    if a.ndim != 2:
        raise InputError(f"image must be (H, W) or (H, W, 3), got shape {a.shape}")
    return a


def _samples(
    scene: PickingScene, image_id: str, line: ControlLine, camera: Camera, opt: AutoLineOptions
) -> tuple[Array, Array, Array]:
    """(pixels (K, 2), unit directions (K, 2), along-line parameter (K,) in 0..1) of the
    in-frame samples of one line, ``spacing_px`` apart in the image (approximately; at most
    ``max_samples`` over the line)."""
    a, b = np.asarray(line.start, float), np.asarray(line.end, float)
    coarse = scene.project(image_id, a + np.linspace(0, 1, 9)[:, None] * (b - a))
    ok = np.isfinite(coarse).all(axis=1)
    if ok.sum() < 2:
        return np.empty((0, 2)), np.empty((0, 2)), np.empty(0)
    span = np.nansum(np.linalg.norm(np.diff(coarse[ok], axis=0), axis=1))
    n = int(np.clip(np.ceil(span / opt.spacing_px), 2, max(2, int(opt.max_samples))))
    t = (np.arange(n) + 0.5) / n
    eps = 0.5 / n
    pts = scene.project(image_id, a + np.concatenate([t, t - eps, t + eps])[:, None] * (b - a))
    px, lo, hi = pts[:n], pts[n : 2 * n], pts[2 * n :]
    d = hi - lo
    norm = np.linalg.norm(d, axis=1)
    good = np.isfinite(px).all(axis=1) & np.isfinite(norm) & (norm > 0)
    good[good] &= camera.in_frame(px[good], opt.margin_px + opt.search_px + opt.along_px)
    return px[good], d[good] / norm[good, None], t[good]


def _edge_checks(
    grey: Array, pix: Array, refined: Array, dirs: Array, opt: AutoLineOptions
) -> NDArray[np.bool_]:
    """Contrast and uniqueness of the edge at each refined point (vectorised profiles)."""
    normal = np.column_stack([-dirs[:, 1], dirs[:, 0]])
    step = 0.25
    t = np.arange(-opt.search_px, opt.search_px + step / 2, step)
    s = np.arange(-opt.along_px, opt.along_px + 0.5, 1.0)
    pts = (
        pix[:, None, None]
        + s[None, :, None, None] * dirs[:, None, None]
        + t[None, None, :, None] * normal[:, None, None]
    )
    idx = pts - 0.5
    g = map_coordinates(grey, [idx[..., 1].ravel(), idx[..., 0].ravel()], order=1, mode="nearest")
    prof = g.reshape(pts.shape[:3]).mean(axis=1)  # (K, T)
    grad = np.abs(np.gradient(prof, step, axis=1))
    # the refined point's position on the profile
    off = np.einsum("ij,ij->i", refined - pix, normal)
    k = np.clip(np.rint((off + opt.search_px) / step).astype(int), 0, len(t) - 1)
    # grey step: 1.5 px either side of the edge (past a 1 px blur)
    side = np.rint(1.5 / step).astype(int)
    lo = np.clip(k - side, 0, len(t) - 1)
    hi = np.clip(k + side, 0, len(t) - 1)
    rows = np.arange(len(k))
    contrast = np.abs(prof[rows, hi] - prof[rows, lo])
    # a second peak: the largest gradient more than 2 px from the chosen edge
    far = np.abs(t[None, :] - off[:, None]) > 2.0
    peak = grad[rows[:, None], np.clip(k[:, None] + np.arange(-2, 3), 0, len(t) - 1)].max(axis=1)
    second = np.where(far, grad, 0.0).max(axis=1)
    return (contrast >= opt.min_contrast) & (second <= opt.ambiguity * peak)


def _lmeds_line(t: Array, off: Array) -> Array:
    """Least-median-of-squares line ``c0 + c1 t`` through two of the samples (every pair, or
    400 drawn ones): the fit of the majority even when nearly half the samples lie on another
    edge (a least-squares start is pulled between the two and its MAD cut keeps both)."""
    n = t.size
    i, j = np.triu_indices(n, 1)
    if i.size > 400:  # deterministic subset of the pairs
        pick = np.random.default_rng(n).choice(i.size, 400, replace=False)
        i, j = i[pick], j[pick]
    dt = t[j] - t[i]
    ok = np.abs(dt) > 1e-12
    if not ok.any():
        return np.array([0.0, float(np.median(off))])
    i, j, dt = i[ok], j[ok], dt[ok]
    c1 = (off[j] - off[i]) / dt
    c0 = off[i] - c1 * t[i]
    res = np.abs(off[None, :] - (c0[:, None] + c1[:, None] * t[None, :]))
    med = np.partition(res, n // 2, axis=1)[:, n // 2]
    best = int(np.argmin(med))
    return np.array([c1[best], c0[best]])


def _refit(
    t: Array, off: Array, keep: NDArray[np.bool_], opt: AutoLineOptions
) -> tuple[NDArray[np.bool_], float]:
    """Least squares ``c0 + c1 t`` on the kept samples and the MAD cut, until no sample leaves
    (at most 5 times): keep mask and residual RMS (px)."""
    rms = 0.0
    for _ in range(5):
        if keep.sum() < max(3, opt.min_points):
            return np.zeros(t.size, bool), 0.0
        coef = np.polyfit(t[keep], off[keep], 1)
        res = off - np.polyval(coef, t)
        mad = 1.4826 * np.median(np.abs(res[keep]))
        rms = float(np.sqrt(np.sum(res[keep] ** 2) / max(keep.sum() - 2, 1)))
        new = np.abs(res) <= opt.outlier_sigmas * max(mad, opt.min_sigma_px)
        if (new == keep).all():
            break
        keep = new
    return keep, rms


def _fit_line(t: Array, off: Array, opt: AutoLineOptions) -> tuple[NDArray[np.bool_], float]:
    """Keep mask and residual RMS (px) of the offsets fitted by ``c0 + c1 t``: least squares
    from all samples with the MAD cut (:func:`_refit`); when its RMS exceeds
    ``outlier_sigmas`` times the robust scale of the least-median-of-squares line
    (:func:`_lmeds_line`; Rousseeuw's scale ``1.4826 (1 + 5 / (n - 2)) sqrt(med r^2)``, at
    least ``min_sigma_px``), a variance ratio chance does not give, the samples are two
    populations (some on another edge, which pulled the least-squares start between them): the
    fit restarts from the samples within ``outlier_sigmas`` scales of that line."""
    if t.size < max(3, opt.min_points):
        return np.zeros(t.size, bool), 0.0
    keep, rms = _refit(t, off, np.ones(t.size, bool), opt)
    coef = _lmeds_line(t, off)
    res = np.abs(off - np.polyval(coef, t))
    n = t.size
    med = float(np.partition(res, n // 2)[n // 2])
    scale = max(1.4826 * (1.0 + 5.0 / max(n - 2, 1)) * med, opt.min_sigma_px)
    if keep.sum() >= max(3, opt.min_points) and rms <= opt.outlier_sigmas * scale:
        return keep, rms
    return _refit(t, off, res <= opt.outlier_sigmas * scale, opt)


#: Fewest segments (lines) in an image for the screen of :func:`_screen_segments`: its model
#: has 4 parameters, and the least median of squares needs a clear majority over them.
_SCREEN_MIN_SEGMENTS = 7


def _screen_segments(
    mid: Array, normal: Array, offset: Array, centre: Array, opt: AutoLineOptions
) -> NDArray[np.bool_]:
    """Keep mask of an image's line segments against the displacement its pose error gives
    every line at once: a small error of the image's orientation moves the image by a shift,
    a rotation and a scale about the frame's centre (pixel displacement ``d + r J (p - c) +
    s (p - c)``, ``J`` the quarter turn), so each segment's fitted offset at its midpoint
    ``p`` across its normal ``n`` is ``n . d + r n . J (p - c) + s n . (p - c)``. The 4
    parameters are fitted by least median of squares over the segments (all 4-subsets, or 500
    drawn), then least squares on the segments within ``segment_sigmas`` robust sigmas
    (Rousseeuw's scale, at least ``segment_min_px``); a segment farther off is on another edge
    in this image and is dropped. Images with fewer than ``_SCREEN_MIN_SEGMENTS`` segments are
    not screened (the majority cannot be told)."""
    n = len(offset)
    keep = np.ones(n, bool)
    if n < _SCREEN_MIN_SEGMENTS:
        return keep
    rel = (mid - centre) / max(float(np.max(np.abs(mid - centre))), 1.0)  # scaled: conditioning
    quarter = np.column_stack([-rel[:, 1], rel[:, 0]])
    a = np.column_stack(
        [normal, np.einsum("ij,ij->i", normal, quarter), np.einsum("ij,ij->i", normal, rel)]
    )
    from itertools import combinations

    subsets = np.array(list(combinations(range(n), 4)))
    if len(subsets) > 500:
        subsets = subsets[np.random.default_rng(n).choice(len(subsets), 500, replace=False)]
    best, best_med = None, np.inf
    for sub in subsets:
        m = a[sub]
        if np.linalg.cond(m) > 1e8:
            continue
        x = np.linalg.solve(m, offset[sub])
        med = float(np.median((offset - a @ x) ** 2))
        if med < best_med:
            best, best_med = x, med
    if best is None:
        return keep
    p = a.shape[1]
    scale = max(1.4826 * (1 + 5.0 / (n - p)) * np.sqrt(best_med), opt.segment_min_px)
    keep = np.abs(offset - a @ best) <= opt.segment_sigmas * scale
    if keep.sum() > p:
        x = np.linalg.lstsq(a[keep], offset[keep], rcond=None)[0]
        res = offset - a @ x
        s = np.sqrt(np.sum(res[keep] ** 2) / (keep.sum() - p))
        keep = np.abs(res) <= opt.segment_sigmas * max(float(s), opt.segment_min_px)
    return keep


def line_observations(
    image: ArrayLike,
    image_id: str,
    camera: Camera,
    eo: ExteriorOrientationTable,
    lines: Sequence[ControlLine],
    options: AutoLineOptions | None = None,
    *,
    scene: PickingScene | None = None,
    refused: dict[str, int] | None = None,
) -> ImageObservations:
    """Line observations of one image (module docstring).

    Parameters
    ----------
    image : (H, W) or (H, W, 3) array_like
        Grey or RGB values of the whole image (the camera's size).
    image_id : str
        The image's row in ``eo``.
    camera : Camera
    eo : ExteriorOrientationTable
        Exterior orientation (mapping CRS) holding ``image_id``: the current estimate.
    lines : sequence of ControlLine
        LiDAR lines, mapping CRS (:mod:`core.lidar.control`).
    options : AutoLineOptions, optional
    scene : PickingScene, optional
        The projection chain, when the caller has built it for the block (else built here).
    refused : dict, optional
        Incremented by the points refused per reason (:data:`REFUSALS`): off their line's
        fit in the image, or in a segment off the image's other lines (:func:`_screen_segments`).

    Returns
    -------
    ImageObservations
        Rows of type ``line``, ``target_id`` the line id, ``point_id``
        ``"<image_id>:L<line id>:<k>"``, pixels (col, row), ``sigma_px`` from the per-line fit.
    """
    opt = options or AutoLineOptions()
    grey = _grey(image)
    if grey.shape != (camera.height_px, camera.width_px):
        raise InputError(
            f"image '{image_id}' is {grey.shape[1]} x {grey.shape[0]} px, the camera "
            f"'{camera.name}' {camera.width_px} x {camera.height_px}"
        )
    sc = scene or PickingScene(eo, camera)
    segments = []  # (line id, kept points, sigma, midpoint, normal, mean offset)
    for line in lines:
        pix, dirs, t = _samples(sc, image_id, line, camera, opt)
        if len(pix) < opt.min_points:
            continue
        found = [
            refine_edge_point(grey, (0, 0), p, d, opt.search_px, opt.along_px)
            for p, d in zip(pix, dirs)
        ]
        hit = np.array([f is not None for f in found], bool)
        if hit.sum() < opt.min_points:
            continue
        refined = np.array([f for f in found if f is not None])
        pix, dirs, t = pix[hit], dirs[hit], t[hit]
        ok = _edge_checks(grey, pix, refined, dirs, opt)
        normal = np.column_stack([-dirs[:, 1], dirs[:, 0]])
        off = np.einsum("ij,ij->i", refined - pix, normal)
        ok &= np.abs(off) < opt.search_px
        if ok.sum() < opt.min_points:
            continue
        keep, rms = _fit_line(t[ok], off[ok], opt)
        if refused is not None:
            refused[REFUSALS[0]] = refused.get(REFUSALS[0], 0) + int((~keep).sum())
        if keep.sum() < opt.min_points:
            continue
        nm = normal[ok][keep].mean(axis=0)
        segments.append(
            (
                str(line.id),
                refined[ok][keep],
                max(rms, opt.min_sigma_px),
                pix[ok][keep].mean(axis=0),
                nm / np.linalg.norm(nm),
                float(off[ok][keep].mean()),
            )
        )
    screen = _screen_segments(
        np.reshape([s[3] for s in segments], (-1, 2)),
        np.reshape([s[4] for s in segments], (-1, 2)),
        np.array([s[5] for s in segments]),
        np.array([camera.width_px, camera.height_px]) / 2.0,
        opt,
    )
    cols: dict[str, list] = {"pid": [], "tid": [], "px": [], "sig": []}
    for (tid, good, sig, *_), kept in zip(segments, screen):
        if not kept:
            if refused is not None:
                refused[REFUSALS[1]] = refused.get(REFUSALS[1], 0) + len(good)
            continue
        for k, p in enumerate(good):
            cols["pid"].append(f"{image_id}:L{tid}:{k}")
            cols["tid"].append(tid)
            cols["px"].append(p)
        cols["sig"].extend([sig] * len(good))
    n = len(cols["pid"])
    return ImageObservations.from_arrays(
        [image_id] * n,
        cols["pid"],
        np.reshape(cols["px"], (n, 2)),
        np.asarray(cols["sig"]),
        ["line"] * n,
        cols["tid"],
    )


def line_observations_block(
    images: Sequence[tuple[str, ArrayLike]],
    camera: Camera,
    eo: ExteriorOrientationTable,
    lines: Sequence[ControlLine],
    options: AutoLineOptions | None = None,
    refused: dict[str, int] | None = None,
) -> ImageObservations:
    """:func:`line_observations` of many images ((image_id, array) pairs, e.g. a generator
    reading them one at a time), with one projection chain for the block; rows concatenated;
    ``refused`` counts the refused points per reason over the block."""
    scene = PickingScene(eo, camera)
    out = ImageObservations.from_arrays([], [], np.empty((0, 2)), [], [], [])
    for image_id, image in images:
        if not scene.has_image(image_id):
            raise InputError(f"image '{image_id}' has no exterior orientation")
        out = out.concat(
            line_observations(
                image, image_id, camera, eo, lines, options, scene=scene, refused=refused
            )
        )
    return out
