"""Normalised cross-correlation (NCC) template search with a sub-pixel peak and an adaptive
template size.

Search: OpenCV's ``matchTemplate`` with ``TM_CCOEFF_NORMED`` (the correlation coefficient of
the template and each same-sized window of the search image). The integer peak is refined to
sub-pixel by a separable parabola: through the peak and its two neighbours along the columns,
and independently along the rows (vertex of each parabola). Its accuracy is about 0.1 px,
enough to start least-squares matching (:mod:`core.photo.least_squares_matching`), which
gives the final position.

Distinctness: the second-highest correlation outside a radius of ``exclusion_px`` around the
peak; a peak that another one nearly equals is ambiguous (repetitive texture).

Texture measure and adaptive template size (the rule): for a template ``t`` of n pixels the
expected standard deviation of a least-squares shift is ``sigma_n / sqrt(lambda_min)``, with
``lambda_min`` the smaller eigenvalue of the structure tensor ``sum(grad t grad t^T)``
(Förstner 1986) and ``sigma_n`` the noise of the grey values. ``sigma_n`` is estimated with
Immerkær's (1996) Laplacian-difference operator, floored at ``noise_floor`` (default 2 %) of
the template's standard deviation so that a noise-free (synthetic or smoothed) chip still
needs a real texture. The template grows from ``min_size`` in steps of ``step`` pixels until
the predicted sigma is at most ``target_sigma_px`` (default 0.02 px) and the structure
tensor's eigenvalue ratio ``lambda_min / lambda_max`` is at least ``min_isotropy`` (default
0.05: not a straight edge, which fixes only one direction). If even ``max_size`` fails, the
chip is refused with the reason: ``no texture`` when its grey values barely vary (standard
deviation below ``min_contrast``, default 1e-6 of their mean magnitude, or below three
times the estimated noise), ``edge only`` for a too anisotropic texture, ``weak texture``
otherwise. The defaults were chosen on the synthetic textures of tests/core/test_matching.py.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..i18n import mark as _t
from .matching_options import TextureOptions

#: catalogue context of this module's ``_t("...")`` sentences (``make i18n``): the reports'
TR_CONTEXT = "Report"

Array = NDArray[np.float64]

__all__ = [
    "NccMatch",
    "TemplateSize",
    "TextureOptions",
    "choose_template_size",
    "immerkaer_noise",
    "ncc_search",
    "texture_measure",
]


def immerkaer_noise(image: ArrayLike) -> float:
    """Standard deviation of white noise in ``image`` (Immerkær 1996), grey values.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> img = np.add.outer(np.arange(64.0), np.arange(64.0)) + rng.normal(0, 2.0, (64, 64))
    >>> round(immerkaer_noise(img), 0)
    2.0
    """
    a = np.asarray(image, dtype=np.float64)
    if a.ndim != 2 or min(a.shape) < 3:
        return 0.0
    lap = (
        a[:-2, :-2]
        - 2 * a[:-2, 1:-1]
        + a[:-2, 2:]
        - 2 * a[1:-1, :-2]
        + 4 * a[1:-1, 1:-1]
        - 2 * a[1:-1, 2:]
        + a[2:, :-2]
        - 2 * a[2:, 1:-1]
        + a[2:, 2:]
    )
    h, w = a.shape
    return float(np.sqrt(np.pi / 2.0) * np.abs(lap).sum() / (6.0 * (w - 2) * (h - 2)))


def texture_measure(template: ArrayLike) -> tuple[float, float]:
    """(lambda_min, lambda_max) of the structure tensor ``sum(grad t grad t^T)`` (grey^2/px^2)
    of a template (central differences, border pixels left out).

    Examples
    --------
    >>> x = np.arange(9.0)
    >>> lo, hi = texture_measure(np.add.outer(0 * x, x))  # a ramp: one direction only
    >>> round(lo, 6), round(hi, 1)
    (0.0, 49.0)
    """
    t = np.asarray(template, dtype=np.float64)
    gx = 0.5 * (t[1:-1, 2:] - t[1:-1, :-2])
    gy = 0.5 * (t[2:, 1:-1] - t[:-2, 1:-1])
    sxx, syy, sxy = float((gx * gx).sum()), float((gy * gy).sum()), float((gx * gy).sum())
    half_trace = 0.5 * (sxx + syy)
    root = float(np.hypot(0.5 * (sxx - syy), sxy))
    return max(half_trace - root, 0.0), half_trace + root


@dataclass(frozen=True)
class TemplateSize:
    """Outcome of :func:`choose_template_size`.

    size : odd template side in pixels (the largest tried when refused).
    predicted_sigma_px : expected least-squares shift sigma at that size, pixels.
    noise : grey-value noise used (estimated, floored).
    reason : "" when accepted, else why the chip is refused.
    """

    size: int
    predicted_sigma_px: float
    noise: float
    reason: str

    @property
    def ok(self) -> bool:
        """True when the template has enough texture."""
        return not self.reason


def choose_template_size(
    chip: ArrayLike, centre: tuple[float, float], options: TextureOptions | None = None
) -> TemplateSize:
    """The smallest odd template around ``centre`` (col, row array coordinates of the chip)
    whose texture passes the rule of the module docstring.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> import cv2
    >>> chip = cv2.GaussianBlur(rng.normal(0, 50, (81, 81)), (0, 0), 1.5)
    >>> choose_template_size(chip, (40.0, 40.0)).ok
    True
    >>> choose_template_size(np.full((81, 81), 7.0), (40.0, 40.0)).reason
    'no texture'
    """
    opt = options or TextureOptions()
    a = np.asarray(chip, dtype=np.float64)
    c, r = int(np.rint(centre[0])), int(np.rint(centre[1]))
    largest = 2 * min(c, r, a.shape[1] - 1 - c, a.shape[0] - 1 - r) + 1
    top = min(opt.max_size | 1, largest)
    if top < 5:
        return TemplateSize(max(top, 0), float("inf"), 0.0, "point too close to the chip edge")
    sizes = list(range(min(opt.min_size | 1, top), top + 1, max(2, opt.step & ~1)))
    if sizes[-1] != top:
        sizes.append(top)
    reason, size, pred, noise = "", top, float("inf"), 0.0
    for size in sizes:
        h = size // 2
        t = a[r - h : r + h + 1, c - h : c + h + 1]
        std = float(t.std())
        est = immerkaer_noise(t)
        noise = max(est, opt.noise_floor * std)
        if std <= opt.min_contrast * max(float(np.abs(t).mean()), 1.0) or std < 3.0 * est:
            reason = _t("no texture")
            continue
        lo, hi = texture_measure(t)
        pred = noise / np.sqrt(lo) if lo > 0 else float("inf")
        if hi <= 0 or lo / hi < opt.min_isotropy:
            reason = _t("edge only")
            continue
        if pred > opt.target_sigma_px:
            reason = _t("weak texture")
            continue
        return TemplateSize(size, float(pred), noise, "")
    return TemplateSize(size, float(pred), noise, reason)


@dataclass(frozen=True)
class NccMatch:
    """Best NCC position of a template in a search image.

    col, row : sub-pixel array coordinates in the search image of the template's centre
        pixel ((size - 1) / 2 from its top-left), i.e. where template pixel (i, j) lands at
        (col - (w - 1) / 2 + j, row - (h - 1) / 2 + i).
    peak : correlation coefficient at the integer peak (-1 .. 1).
    second : highest correlation outside ``exclusion_px`` of the peak (-1 when none).
    on_border : the peak lies on the border of the correlation surface (the true
        maximum may be outside the search window).
    """

    col: float
    row: float
    peak: float
    second: float
    on_border: bool


def _vertex(m: float, z: float, p: float) -> float:
    """Offset of the vertex of the parabola through (-1, m), (0, z), (1, p), within +-0.5."""
    den = m - 2.0 * z + p
    if den >= 0.0:
        return 0.0
    return float(np.clip(0.5 * (m - p) / den, -0.5, 0.5))


def ncc_search(template: ArrayLike, search: ArrayLike, exclusion_px: float = 3.0) -> NccMatch:
    """NCC template search with the separable-parabola sub-pixel peak (module docstring).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> img = rng.normal(size=(60, 60))
    >>> m = ncc_search(img[20:31, 30:41], img)
    >>> round(m.col, 2), round(m.row, 2), round(m.peak, 6)
    (35.0, 24.99, 1.0)
    """
    import cv2

    t = np.ascontiguousarray(template, dtype=np.float32)
    s = np.ascontiguousarray(search, dtype=np.float32)
    if s.shape[0] < t.shape[0] or s.shape[1] < t.shape[1]:
        raise ValueError(f"search window {s.shape} smaller than the template {t.shape}")
    cc = cv2.matchTemplate(s, t, cv2.TM_CCOEFF_NORMED).astype(np.float64)
    cc[~np.isfinite(cc)] = -1.0
    r, c = np.unravel_index(int(np.argmax(cc)), cc.shape)
    peak = float(cc[r, c])
    h, w = cc.shape
    border = r in (0, h - 1) or c in (0, w - 1)
    dc = _vertex(cc[r, c - 1], peak, cc[r, c + 1]) if 0 < c < w - 1 else 0.0
    dr = _vertex(cc[r - 1, c], peak, cc[r + 1, c]) if 0 < r < h - 1 else 0.0
    rr, ccol = np.ogrid[:h, :w]
    far = (rr - r) ** 2 + (ccol - c) ** 2 > exclusion_px**2
    second = float(cc[far].max()) if far.any() else -1.0
    half_c, half_r = (t.shape[1] - 1) / 2.0, (t.shape[0] - 1) / 2.0
    return NccMatch(float(c + dc + half_c), float(r + dr + half_r), peak, second, bool(border))
