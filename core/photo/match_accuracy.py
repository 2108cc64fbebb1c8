"""The accuracy of point matches between two views of a plane, without trusting a published
homography: a robust homography fit and a split-sample (checkerboard) residual.

Fit (:func:`fit_homography`): the 8 parameters of ``H`` (``H[2, 2] = 1``) that minimise the
squared distances in image 2, ``sum |dst - H(src)|^2`` (OpenCV's ``findHomography``: Hartley's
(1997) normalised DLT of the kept matches refined by Levenberg-Marquardt on the geometric
error), the first kept set from its least-median-of-squares search (Rousseeuw 1984), then
the matches farther than ``k`` robust standard deviations of a coordinate (the median
distance / 1.1774, the Rayleigh median; never less than 1e-4 px: OpenCV fits in single
precision, 1e-5 px at 1000 px from the origin) from the current fit left out and the fit
repeated until the set of kept matches no longer changes.

Split sample (:func:`split_sample_residuals`): the image-1 plane is cut into square blocks
coloured like a checkerboard; ``H`` is fitted to the matches of the black blocks and each
match of the white blocks is scored against it, and the other way round. Every match is thus
scored by a fit it did not enter, so a match's own error cannot be absorbed (no circularity):
``r = e + d`` with ``e`` the match error and ``d = H_plane(p) - H_fit(p)`` the model's error
at p (the fit's own noise, lens distortion, a scene not exactly planar), independent of
``e``. For ``e`` centrally symmetric and unimodal (e.g. Gaussian) and any ``d`` independent of
it, ``P(|e + d| <= t) <= P(|e| <= t)`` for every t (Anderson 1955), so the median of ``|r|``
is an upper bound of the median match error: a wrong model only inflates it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

Array = NDArray[np.float64]

__all__ = [
    "apply_homography",
    "checkerboard_halves",
    "fit_homography",
    "fit_smooth_map",
    "homography_difference",
    "split_sample_residuals",
]


def apply_homography(h: ArrayLike, points: ArrayLike) -> Array:
    """(N, 2) images of (N, 2) points (x = column, y = row, pixels) under the 3 x 3 ``h``.

    >>> apply_homography(np.diag([2.0, 2.0, 1.0]), [[1.0, 3.0]]).tolist()
    [[2.0, 6.0]]
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    h = np.asarray(h, dtype=np.float64)
    return (p @ h[:2, :2].T + h[:2, 2]) / (p @ h[2, :2] + h[2, 2])[:, None]


def _opencv_fit(p: Array, q: Array, method: int) -> Array:
    """OpenCV's homography p -> q: ``method`` 0 is the normalised DLT of all the points
    refined by Levenberg-Marquardt on the distances in image 2, ``cv2.LMEDS`` the
    least-median-of-squares search (then the same refinement of its inliers)."""
    h, _ = cv2.findHomography(p, q, method)
    if h is None:
        raise ValueError("no homography fits these matches (degenerate configuration)")
    return h / h[2, 2]


def fit_homography(
    src: ArrayLike,
    dst: ArrayLike,
    k: float = 3.0,
    start: ArrayLike | None = None,
    max_rounds: int = 20,
) -> tuple[Array, NDArray[np.bool_]]:
    """Robust least-squares homography src -> dst (module docstring) and the kept matches.

    Parameters
    ----------
    src, dst : (N, 2) array_like
        Matched points (column, row), pixels, N >= 4.
    k : float
        Rejection threshold in robust standard deviations of one coordinate.
    start : (3, 3) array_like, optional
        A homography close to the answer that decides the first kept set; by default
        OpenCV's least-median-of-squares search (``cv2.LMEDS``, Rousseeuw 1984).

    Returns
    -------
    h : (3, 3) homography, ``h[2, 2] = 1``.
    kept : (N,) bool, the matches of the last fit.

    Examples
    --------
    >>> h = np.array([[1.1, 0.1, 5.0], [-0.05, 0.9, -3.0], [1e-4, 2e-4, 1.0]])
    >>> src = np.random.default_rng(0).uniform(0, 500, (50, 2))
    >>> fit, kept = fit_homography(src, apply_homography(h, src))
    >>> bool(np.allclose(fit, h, rtol=1e-4, atol=1e-7)), int(kept.sum())
    (True, 50)
    """
    p = np.asarray(src, dtype=np.float64).reshape(-1, 2)
    q = np.asarray(dst, dtype=np.float64).reshape(-1, 2)
    if len(p) < 4 or len(q) != len(p):
        raise ValueError("a homography needs at least 4 matched points, as many in both images")
    if start is None:
        start = _opencv_fit(p, q, cv2.LMEDS)
    r = np.hypot(*(q - apply_homography(start, p)).T)
    kept = r <= (np.inf if np.isinf(k) else k * np.median(r) / 1.1774)
    if kept.sum() < 4:
        raise ValueError(
            f"only {int(kept.sum())} of {len(p)} matches agree with the start: "
            "no homography fits them"
        )
    for _ in range(max(1, max_rounds)):
        h = _opencv_fit(p[kept], q[kept], 0)
        r = np.hypot(*(q - apply_homography(h, p)).T)
        # median distance of a 2-D Gaussian error = 1.1774 sigma (Rayleigh)
        new = r <= (np.inf if np.isinf(k) else max(k * np.median(r[kept]) / 1.1774, 1e-4))
        if new.sum() < 4 or np.array_equal(new, kept):
            break
        kept = new
    return h, kept


def checkerboard_halves(points: ArrayLike, block: float) -> NDArray[np.bool_]:
    """(N,) True for points of the "black" blocks of a checkerboard of ``block`` pixels.

    >>> checkerboard_halves([[10, 10], [70, 10], [70, 70]], 64).tolist()
    [True, False, True]
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    return (np.floor(p / block).astype(np.int64).sum(axis=1) % 2) == 0


def _monomials(p: Array, centre: Array, scale: float, degree: int) -> Array:
    """(N, T) monomials x^i y^j, 2 <= i + j <= degree, of centred and scaled coordinates (the
    constant and linear terms are the homography's)."""
    x, y = ((p - centre) / scale).T
    cols = [x**i * y ** (d - i) for d in range(2, degree + 1) for i in range(d + 1)]
    return np.stack(cols, axis=1) if cols else np.zeros((len(p), 0))


def fit_smooth_map(
    src: ArrayLike, dst: ArrayLike, degree: int = 0, k: float = 3.0
) -> tuple[Callable[[ArrayLike], NDArray[np.float64]], NDArray[np.bool_]]:
    """A homography plus, when ``degree >= 2``, a polynomial correction in image 2 of the
    terms of degree 2..``degree`` (a smooth departure from one plane seen by two pinhole
    cameras: lens distortion that differs between the images, a gently curved scene). Robust
    as :func:`fit_homography` (a first kept set at 2 ``k``, then the correction and the
    homography fitted in turn to the kept matches and those farther than ``k`` robust sigmas
    from the whole map left out, until the kept set no longer changes).

    Returns the map (a callable (N, 2) -> (N, 2)) and the kept matches.

    >>> src = np.random.default_rng(0).uniform(0, 400, (200, 2))
    >>> dst = src + 2e-5 * (src - 200) ** 2        # up to 0.8 px of curvature
    >>> h, _ = fit_smooth_map(src, dst)
    >>> f, kept = fit_smooth_map(src, dst, degree=3)
    >>> float(np.abs(h(src) - dst).max()) > 0.05, float(np.abs(f(src) - dst).max()) < 0.005
    (True, True)
    """
    p = np.asarray(src, dtype=np.float64).reshape(-1, 2)
    q = np.asarray(dst, dtype=np.float64).reshape(-1, 2)
    h, kept = fit_homography(p, q, k=k if degree < 2 else 2 * k)
    if degree < 2:
        return (lambda x: apply_homography(h, x)), kept
    centre = p.mean(axis=0)
    scale = float(np.abs(p - centre).max()) or 1.0
    mono_all = _monomials(p, centre, scale, degree)
    coef: NDArray[np.floating[Any]] = np.zeros((mono_all.shape[1], 2))
    # alternate: the correction given H, H given the correction, then the kept set
    for _ in range(20):
        for _ in range(3):
            coef = np.linalg.lstsq(mono_all[kept], (q - apply_homography(h, p))[kept], rcond=None)[
                0
            ]
            h, _ = fit_homography(p[kept], (q - mono_all @ coef)[kept], k=np.inf, start=h)
        r = np.hypot(*(q - apply_homography(h, p) - mono_all @ coef).T)
        new = r <= max(k * np.median(r[kept]) / 1.1774, 1e-4)
        if new.sum() < 4 + mono_all.shape[1] or np.array_equal(new, kept):
            break
        kept = new

    def smooth(x: ArrayLike) -> Array:
        x = np.asarray(x, dtype=np.float64).reshape(-1, 2)
        return apply_homography(h, x) + _monomials(x, centre, scale, degree) @ coef

    return smooth, kept


def split_sample_residuals(
    src: ArrayLike, dst: ArrayLike, block: float = 64.0, k: float = 3.0, degree: int = 0
) -> Array:
    """(N, 2) residuals ``dst - H(src)`` of each match against the homography fitted to the
    matches of the other half of a checkerboard of ``block``-pixel squares in image 1
    (module docstring: the median of their lengths bounds the median match error from
    above). ``degree >= 2`` adds the smooth correction of :func:`fit_smooth_map`.

    >>> h = np.array([[0.9, 0.2, 10.0], [-0.2, 0.9, 130.0], [2e-6, 1e-6, 1.0]])
    >>> src = np.random.default_rng(1).uniform(0, 600, (400, 2))
    >>> dst = apply_homography(h, src) + np.random.default_rng(2).normal(0, 0.1, (400, 2))
    >>> r = split_sample_residuals(src, dst, block=100.0)
    >>> 0.10 < float(np.median(np.hypot(*r.T))) < 0.14   # 1.1774 x 0.1, plus the fit's noise
    True
    """
    p = np.asarray(src, dtype=np.float64).reshape(-1, 2)
    q = np.asarray(dst, dtype=np.float64).reshape(-1, 2)
    black = checkerboard_halves(p, block)
    out = np.full(p.shape, np.nan)
    for fit_on in (black, ~black):
        if fit_on.sum() < 4 or (~fit_on).sum() == 0:
            continue
        f, _ = fit_smooth_map(p[fit_on], q[fit_on], degree=degree, k=k)
        out[~fit_on] = q[~fit_on] - f(p[~fit_on])
    return out


def homography_difference(
    h_a: ArrayLike, h_b: ArrayLike, shape: tuple[int, int], step: float = 10.0
) -> tuple[Array, Array]:
    """Grid of image-1 points (every ``step`` pixels over ``shape`` = (rows, cols)) and the
    (N, 2) differences ``h_a(p) - h_b(p)`` in image 2, pixels.

    >>> g, d = homography_difference(np.eye(3), [[1, 0, 0.5], [0, 1, 0], [0, 0, 1]], (20, 20))
    >>> g.shape, float(np.abs(d[:, 0] + 0.5).max())
    ((4, 2), 0.0)
    """
    rr, cc = np.mgrid[0 : shape[0] : step, 0 : shape[1] : step]
    grid = np.column_stack([cc.ravel(), rr.ravel()]).astype(np.float64)
    return grid, apply_homography(h_a, grid) - apply_homography(h_b, grid)
