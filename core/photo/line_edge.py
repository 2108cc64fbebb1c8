"""Sub-pixel refinement of a point clicked on a straight edge of an image (the picking dock's
line ends, optional).

The point moves across the edge only (along the line's normal) to the largest grey-value
gradient of the profile across it, averaged over a few profiles along the edge, with the
peak's centre taken as the centroid of its samples above half the maximum. Pixels follow
:mod:`core.photo.picking` (col, row; the centre of the first pixel is (0.5, 0.5)).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.ndimage import map_coordinates

__all__ = ["refine_edge_point"]

Array = NDArray[np.float64]


def refine_edge_point(
    image: ArrayLike,
    origin: ArrayLike,
    pixel: ArrayLike,
    direction: ArrayLike,
    search_px: float = 4.0,
    along_px: float = 3.0,
    step_px: float = 0.25,
) -> Array | None:
    """The point of an edge nearest to ``pixel`` across the edge, or None.

    Parameters
    ----------
    image : (H, W) array_like
        Grey values of a window of the image.
    origin : (2,) array_like
        (col, row) of the window's first pixel's corner in the image (integers: the window's
        pixel (0, 0) covers image pixels col0..col0+1, row0..row0+1).
    pixel : (2,) array_like
        The click, image pixels.
    direction : (2,) array_like
        The edge's direction in the image (any length; e.g. the predicted line's).
    search_px, along_px, step_px : float
        Half length of the profiles across the edge, half length of the stretch of edge
        averaged, sampling step (pixels).

    Returns
    -------
    (2,) ndarray or None
        The refined pixel; None when the gradient's maximum is at the end of the profiles
        (no edge within ``search_px``) or the window does not hold the profiles.

    >>> img = np.zeros((20, 20)); img[:, 10:] = 100.0   # a vertical edge at col 10 (image)
    >>> refine_edge_point(img, (0, 0), (8.3, 9.5), (0, 1)).round(2).tolist()
    [10.0, 9.5]
    """
    a = np.asarray(image, dtype=np.float64)
    d = np.asarray(direction, dtype=np.float64).reshape(2)
    norm = float(np.hypot(*d))
    if a.ndim != 2 or not norm > 0:
        return None
    d = d / norm
    n = np.array([-d[1], d[0]])
    p = np.asarray(pixel, dtype=np.float64).reshape(2) - np.asarray(origin, np.float64)
    t = np.arange(-search_px, search_px + step_px / 2, step_px)
    s = np.arange(-along_px, along_px + 0.5, 1.0)
    pts = p + s[:, None, None] * d + t[None, :, None] * n  # (S, T, 2) window pixels
    idx = pts - 0.5  # array index of the pixel centres
    h, w = a.shape
    if (
        idx[..., 0].min() < 0
        or idx[..., 1].min() < 0
        or idx[..., 0].max() > w - 1
        or (idx[..., 1].max() > h - 1)
    ):
        return None
    grey = map_coordinates(a, [idx[..., 1].ravel(), idx[..., 0].ravel()], order=1)
    profile = grey.reshape(len(s), len(t)).mean(axis=0)
    g = np.abs(np.gradient(profile, step_px))
    k = int(np.argmax(g))
    if k == 0 or k == len(t) - 1 or not g[k] > 0:
        return None
    # the centroid of the gradient's peak (its samples above half the maximum, around it):
    # a sharp step interpolated linearly makes a 1 px plateau, whose centre is the edge
    lo, hi = k, k
    while lo > 0 and g[lo - 1] >= 0.5 * g[k]:
        lo -= 1
    while hi < len(t) - 1 and g[hi + 1] >= 0.5 * g[k]:
        hi += 1
    if lo == 0 or hi == len(t) - 1:
        return None
    w = g[lo : hi + 1] - 0.5 * g[k]
    offset = float(np.sum(w * t[lo : hi + 1]) / np.sum(w)) if w.sum() > 0 else float(t[k])
    return np.asarray(pixel, dtype=np.float64).reshape(2) + offset * n
