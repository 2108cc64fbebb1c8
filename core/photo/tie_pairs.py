"""Image pairs for tie points: ground footprints of the images on a plane, their overlap, and
the pairs chosen from footprints, a sequential window or all pairs (the first stage of
:func:`lidarphoto.core.photo.tie_points.tie_points`)."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..geometry.camera import Camera
from ..geometry.collinearity import image_rays

Array = NDArray[np.float64]


def footprints(
    camera: Camera, xyz: Array, opk: Array, height_m: float, max_range_factor: float = 10.0
) -> list[Array]:
    """Ground footprint of each image: its four corners' rays met with Z = ``height_m``
    (a fisheye camera: the convex hull of 64 points per image side, its border being
    curved on the ground, a point outside the projection's field moved in to its edge; a
    ray that cannot reach the plane, e.g. beyond 90 degrees off a nadir axis, is cut as
    below).

    The mapping frame is taken as Cartesian over one image (good enough to choose pairs:
    the footprints are compared with a tolerance, ``min_overlap``). A corner ray that does
    not go down to the plane (oblique views) is cut at ``max_range_factor`` times the
    flying height.

    Parameters
    ----------
    camera : Camera
    xyz : (M, 3) perspective centres, metres; opk : (M, 3) radians
    height_m : float

    Returns
    -------
    list of (4, 2) arrays
        Easting, northing of the corners (image order: top-left, top-right, bottom-right,
        bottom-left); a fisheye camera's: (K, 2), its convex hull counter-clockwise.

    Examples
    --------
    >>> cam = Camera("c", focal_mm=10.0, pixel_size_mm=0.01, width_px=1000, height_px=500)
    >>> fp = footprints(cam, np.array([[0.0, 0.0, 100.0]]), np.zeros((1, 3)), 0.0)
    >>> np.round(fp[0], 6).tolist()
    [[-50.0, 25.0], [50.0, 25.0], [50.0, -25.0], [-50.0, -25.0]]
    """
    w, h = camera.width_px, camera.height_px
    corners = np.array([[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]])
    if not camera.is_perspective:
        corners = _within_field(camera, _border(w, h))
    out = []
    for x, a in zip(np.asarray(xyz, float), np.asarray(opk, float)):
        o, d = image_rays(corners, np.concatenate([x, a]), camera)
        depth = x[2] - height_m
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (height_m - o[:, 2]) / d[:, 2]
        t = np.where((t > 0) & np.isfinite(t), t, np.inf)
        t = np.minimum(t, max_range_factor * abs(depth))
        ground = o[:, :2] + t[:, None] * d[:, :2]
        out.append(ground if camera.is_perspective else _hull(ground))
    return out


#: Points per image side of a fisheye footprint (its border is curved on the ground).
FISHEYE_BORDER_POINTS = 64


def _border(w: int, h: int, n: int = FISHEYE_BORDER_POINTS) -> Array:
    """``4 n`` pixels along the image border, clockwise from the top-left corner."""
    s = np.arange(n) / n
    return np.vstack(
        [
            np.column_stack([s * w, np.zeros(n)]),
            np.column_stack([np.full(n, float(w)), s * h]),
            np.column_stack([(1 - s) * w, np.full(n, float(h))]),
            np.column_stack([np.zeros(n), (1 - s) * h]),
        ]
    )


def _within_field(camera: Camera, px: Array, steps: int = 64) -> Array:
    """Pixels ``px`` of the border, each one outside the projection's field (a circular
    fisheye image's corners) moved towards the principal point until it has a ray (the
    largest of ``steps`` equal fractions of its distance that does)."""
    pp = np.asarray(camera.principal_point_px, np.float64)
    out = np.array(px, np.float64)

    def valid(p: Array) -> NDArray[np.bool_]:
        return np.all(np.isfinite(camera.ray_from_ideal(camera.ideal_from_pixel(p))), axis=1)

    bad = np.flatnonzero(~valid(out))
    for s in np.arange(steps - 1, 0, -1) / steps:
        if bad.size == 0:
            break
        trial = pp + s * (px[bad] - pp)
        ok = valid(trial)
        out[bad[ok]] = trial[ok]
        bad = bad[~ok]
    return out


def _hull(p: Array) -> Array:
    """Convex hull (counter-clockwise, Andrew's monotone chain) of the finite points: the
    footprint of a fisheye image, whose border bulges out towards the corners on the ground
    (a hull slightly larger than the footprint chooses a pair more, never one less).

    >>> _hull(np.array([[0, 0], [2, 0], [1, 0.5], [2, 2], [0, 2], [np.nan, 1]])).tolist()
    [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]
    """
    q = p[np.all(np.isfinite(p), axis=1)]
    q = q[np.lexsort((q[:, 1], q[:, 0]))]
    if len(q) < 3:
        return q

    def half(points: Array) -> list:
        chain: list = []
        for pt in points:
            while (
                len(chain) >= 2
                and (
                    (chain[-1][0] - chain[-2][0]) * (pt[1] - chain[-2][1])
                    - (chain[-1][1] - chain[-2][1]) * (pt[0] - chain[-2][0])
                )
                <= 0
            ):
                chain.pop()
            chain.append(pt)
        return chain

    lower, upper = half(q), half(q[::-1])
    return np.array(lower[:-1] + upper[:-1], dtype=np.float64)


def _clip(subject: Array, clip: Array) -> Array:
    """Sutherland-Hodgman: the part of polygon ``subject`` inside convex ``clip`` (CCW)."""
    out = subject
    n = len(clip)
    for k in range(n):
        if len(out) == 0:
            break
        a, b = clip[k], clip[(k + 1) % n]
        e = b - a
        side = e[0] * (out[:, 1] - a[1]) - e[1] * (out[:, 0] - a[0])  # > 0: inside (left)
        nxt = np.roll(out, -1, axis=0)
        side_n = np.roll(side, -1)
        pts = []
        for p, q, sp, sq in zip(out, nxt, side, side_n):
            if sp >= 0:
                pts.append(p)
            if (sp >= 0) != (sq >= 0):
                pts.append(p + (q - p) * (sp / (sp - sq)))
        out = np.array(pts).reshape(-1, 2)
    return out


def _area(poly: Array) -> float:
    if len(poly) < 3:
        return 0.0
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def polygon_overlap(a: Array, b: Array) -> float:
    """Intersection area of two convex polygons / the smaller one's area (0..1).

    >>> sq = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], float)
    >>> polygon_overlap(sq, sq + [1.0, 0.0]), polygon_overlap(sq, sq + [3.0, 0.0])
    (0.5, 0.0)
    """
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    if _area(a) < 0:
        a = a[::-1]
    if _area(b) < 0:
        b = b[::-1]
    small = min(_area(a), _area(b))
    if small <= 0:
        return 0.0
    return max(0.0, _area(_clip(a, b))) / small


def select_pairs(
    n_images: int,
    mode: str,
    window: int = 5,
    footprint: Sequence[Array | None] | None = None,
    min_overlap: float = 0.05,
) -> tuple[list[tuple[int, int]], dict[tuple[int, int], float]]:
    """Image pairs to match, ``i < j``, and the footprint overlap of each (NaN if unknown).

    ``footprint`` mode: pairs whose footprints overlap by ``min_overlap`` of the smaller one;
    an image without a footprint (no orientation) is paired with every other image.

    >>> select_pairs(4, "sequential", window=2)[0]
    [(0, 1), (0, 2), (1, 2), (1, 3), (2, 3)]
    >>> len(select_pairs(5, "all")[0])
    10
    """
    pairs: list[tuple[int, int]] = []
    overlap: dict[tuple[int, int], float] = {}
    if mode == "all":
        pairs = [(i, j) for i in range(n_images) for j in range(i + 1, n_images)]
    elif mode == "sequential":
        pairs = [
            (i, j)
            for i in range(n_images)
            for j in range(i + 1, min(n_images, i + 1 + max(1, window)))
        ]
    elif mode == "footprints":
        if footprint is None or len(footprint) != n_images:
            raise InputError("footprint pairs need the orientation and camera of the images")
        boxes = np.array([[np.nan] * 4 if f is None else [*f.min(0), *f.max(0)] for f in footprint])
        for i in range(n_images):
            for j in range(i + 1, n_images):
                if footprint[i] is None or footprint[j] is None:
                    pairs.append((i, j))
                    overlap[(i, j)] = math.nan
                    continue
                bi, bj = boxes[i], boxes[j]
                if bi[0] > bj[2] or bj[0] > bi[2] or bi[1] > bj[3] or bj[1] > bi[3]:
                    continue
                ov = polygon_overlap(footprint[i], footprint[j])
                if ov >= min_overlap:
                    pairs.append((i, j))
                    overlap[(i, j)] = ov
    else:
        raise InputError(f"unknown pair mode {mode!r}")
    return pairs, overlap
