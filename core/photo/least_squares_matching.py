"""Least-squares matching (Gruen 1985): 6 affine + 2 radiometric parameters, many patches at once.

Model, for template pixel (x, y) (pixels from the template's reference point, usually the point
to be matched)::

    f(x, y) - e(x, y) = r0 + r1 g(a0 + a1 x + a2 y, b0 + b1 x + b2 y)

f: template, g: search image (array coordinates: the centre of pixel (i, j) is (j, i)), e:
noise. Gauss-Newton: at each iteration g and its gradient are resampled at the affine
positions (numpy, exact coordinates: OpenCV's remap
quantises them to 1/32 px, which alone would bias the shift by up to 0.016 px), the normal
equations of all K patches are formed as one batched product ``J^T J`` and solved together.
Resampling is bicubic by default (Keys 1981, a = -0.5; the gradient is the derivative of the
same interpolating surface): with bilinear resampling the interpolation error of a textured
patch dominated sigma0 and biased the shift by up to 0.009 px on the synthetic textures of
the tests; ``interpolation="bilinear"`` is kept (numpy only). With numba installed the
bicubic inner loop (sampling and the normal equations of each patch) runs compiled
(:mod:`core.photo.least_squares_matching_numba`, ``backend="auto"``; ``"numpy"`` forces the
vectorised numpy path, which gives the same numbers).

Convergence: the shift update ``|(da0, db0)|`` below ``shift_tol_px`` (default 0.001 px) within
``max_iterations`` (default 30). A posteriori: ``sigma0^2 = v^T v / (n - 8)`` (grey values^2,
n template pixels), covariance ``sigma0^2 N^-1``; the sigmas of (a0, b0) are the sigmas of
the matched position in the search image (pixels). They assume uncorrelated noise in f only;
with noise in both images sigma0 absorbs ``r1^2`` times g's noise, and tests show the sigmas
agree with Monte Carlo within a few percent on textures with some smoothness.

Blunder rejection (status, :data:`STATUS_TEXT`): the template's structure tensor is singular
(``no texture``), the patch left the search window, no convergence, the shift moved farther
than ``max_shift_px`` from its start (a jump to another feature), the correlation between f
and the resampled g at the solution below ``min_correlation``, or the position sigma above
``max_sigma_px``. A rejected patch keeps its numbers (for the report) but must not be used.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..i18n import mark as _t
from . import least_squares_matching_numba as _numba
from .matching_options import LsmOptions

#: catalogue context of this module's ``_t("...")`` sentences (``make i18n``): the reports'
TR_CONTEXT = "Report"

Array = NDArray[np.float64]

__all__ = [
    "STATUS_TEXT",
    "LsmOptions",
    "LsmResult",
    "PointMatch",
    "affine_start",
    "lsm_batch",
    "lsm_in_image",
    "match_point",
]

OK, NO_TEXTURE, LEFT_WINDOW, NOT_CONVERGED, DRIFTED, LOW_CORRELATION, SIGMA_TOO_LARGE = range(7)
#: Status code -> reason.
STATUS_TEXT = (
    _t("ok"),
    _t("no texture"),
    _t("left the search window"),
    _t("not converged"),
    _t("moved too far"),
    _t("low correlation"),
    _t("sigma too large"),
)


@dataclass(frozen=True)
class LsmResult:
    """K matches.

    affine : (K, 2, 3) ``[[a0, a1, a2], [b0, b1, b2]]``: template (x, y) -> search array (col,
        row); ``affine[:, :, 0]`` is the matched position of the template's reference point.
    radiometry : (K, 2) offset r0 and gain r1.
    sigma_px : (K, 2) standard deviations of that position (col, row), pixels.
    cov_px : (K, 2, 2) its covariance, pixels^2.
    sigma0 : (K,) a-posteriori standard deviation of a grey value.
    correlation : (K,) correlation coefficient of f and the resampled g at the solution.
    iterations : (K,) iterations used.
    status : (K,) int8 code into :data:`STATUS_TEXT` (0 = ok).
    """

    affine: Array
    radiometry: Array
    sigma_px: Array
    cov_px: Array
    sigma0: Array
    correlation: Array
    iterations: NDArray[np.int32]
    status: NDArray[np.int8]

    @property
    def position(self) -> Array:
        """(K, 2) matched (col, row) of the reference point, search array coordinates."""
        return self.affine[:, :, 0]

    @property
    def ok(self) -> NDArray[np.bool_]:
        """(K,) accepted matches."""
        return self.status == OK

    def reasons(self) -> list[str]:
        """Reason text per match ("ok" when accepted)."""
        return [STATUS_TEXT[int(s)] for s in self.status]


def affine_start(position: ArrayLike, linear: ArrayLike | None = None) -> Array:
    """(K, 2, 3) start affines from (K, 2) positions and optional (K, 2, 2) linear parts
    (identity by default).

    >>> affine_start([[5.0, 6.0]]).tolist()
    [[[5.0, 1.0, 0.0], [6.0, 0.0, 1.0]]]
    """
    p = np.asarray(position, dtype=np.float64).reshape(-1, 2)
    lin = np.broadcast_to(
        np.eye(2) if linear is None else np.asarray(linear, float), (p.shape[0], 2, 2)
    )
    return np.concatenate([p[:, :, None], lin], axis=2)


def _keys(t: Array) -> tuple[Array, Array]:
    """Keys' (1981) cubic convolution weights (a = -0.5) of the 4 taps at offsets -1, 0, 1, 2
    for fraction ``t`` (any shape), and their derivatives d/dt; stacked on a last axis."""
    t2 = t * t
    t3 = t2 * t
    w = np.stack(
        [
            -0.5 * t3 + t2 - 0.5 * t,
            1.5 * t3 - 2.5 * t2 + 1.0,
            -1.5 * t3 + 2.0 * t2 + 0.5 * t,
            0.5 * t3 - 0.5 * t2,
        ],
        axis=-1,
    )
    d = np.stack(
        [
            -1.5 * t2 + 2.0 * t - 0.5,
            4.5 * t2 - 5.0 * t,
            -4.5 * t2 + 4.0 * t + 0.5,
            1.5 * t2 - t,
        ],
        axis=-1,
    )
    return w, d


def _sample(
    g: Array,
    k: NDArray[np.intp],
    c: Array,
    r: Array,
    cubic: bool,
    grads: tuple[Array, Array] | None = None,
) -> tuple[Array, Array, Array]:
    """Value and gradient (d/dcol, d/drow) of patch k of the (K, H, W) array ``g`` at (c, r).

    Bicubic (Keys): the gradient is the exact derivative of the interpolating surface.
    Bilinear: the gradient is interpolated from ``grads`` (central differences). Coordinates
    outside the usable interior are clamped (the caller flags them).
    """
    h, w = g.shape[1:]
    flat = g.reshape(-1)
    if cubic:
        c = np.clip(c, 1.0, w - 3.000001)
        r = np.clip(r, 1.0, h - 3.000001)
        c0 = c.astype(np.intp)
        r0 = r.astype(np.intp)
        wx, dx = _keys(c - c0)
        wy, dy = _keys(r - r0)
        base = (k * h + r0 - 1) * w + c0 - 1
        offs = (np.arange(4)[:, None] * w + np.arange(4)[None, :]).ravel()
        taps = flat[base[..., None] + offs].reshape(*base.shape, 4, 4)
        along_x = np.einsum("...ij,...j->...i", taps, wx)
        val = np.einsum("...i,...i->...", wy, along_x)
        gcol = np.einsum("...i,...ij,...j->...", wy, taps, dx)
        grow = np.einsum("...i,...i->...", dy, along_x)
        return val, gcol, grow
    c = np.clip(c, 0.0, w - 1.000001)
    r = np.clip(r, 0.0, h - 1.000001)
    c0 = c.astype(np.intp)
    r0 = r.astype(np.intp)
    fc = c - c0
    fr = r - r0
    base = (k * h + r0) * w + c0
    w00 = (1 - fc) * (1 - fr)
    w01 = fc * (1 - fr)
    w10 = (1 - fc) * fr
    w11 = fc * fr
    out = []
    for a in (g, *(grads or (g, g))):
        fl = a.reshape(-1)
        out.append(
            w00 * fl[base] + w01 * fl[base + 1] + w10 * fl[base + w] + w11 * fl[base + w + 1]
        )
    return out[0], out[1], out[2]


def _search_coords(a: Array, x: Array, y: Array) -> tuple[Array, Array]:
    """(K, p) search (col, row) of the template points (x, y) under the affines ``a``."""
    cs = a[:, 0, 0:1] + a[:, 0, 1:2] * x + a[:, 0, 2:3] * y
    rs = a[:, 1, 0:1] + a[:, 1, 1:2] * x + a[:, 1, 2:3] * y
    return cs, rs


def _outside(cs: Array, rs: Array, box: tuple[float, float, float]) -> NDArray[np.bool_]:
    """(K,) patches with a point outside the usable interior ``(lo, hi_col, hi_row)``."""
    lo, hi_c, hi_r = box
    outside = (cs < lo) | (rs < lo) | (cs > hi_c) | (rs > hi_r)
    return cast(NDArray[np.bool_], outside.any(axis=1))  # an array along an axis


def _numpy_normals(
    g: Array,
    idx: NDArray[np.intp],
    a: Array,
    rad: Array,
    fv: Array,
    x: Array,
    y: Array,
    cubic: bool,
    grads: tuple[Array, Array] | None,
    box: tuple[float, float, float],
) -> tuple[Array, Array, NDArray[np.bool_]]:
    """Normal equations (n, 8, 8), right-hand sides (n, 8) and the outside flags of the
    patches ``idx``: six affine and two radiometric parameters (the numba kernel's twin)."""
    cs, rs = _search_coords(a[idx], x, y)
    outside = _outside(cs, rs, box)
    gv, gxv, gyv = _sample(g, idx[:, None], cs, rs, cubic, grads)
    r0 = rad[idx, 0:1]
    r1 = rad[idx, 1:2]
    resid = fv[idx] - (r0 + r1 * gv)
    ux = r1 * gxv
    uy = r1 * gyv
    jac = np.stack([ux, ux * x, ux * y, uy, uy * x, uy * y, np.ones_like(gv), gv], axis=1)
    nn = jac @ jac.transpose(0, 2, 1)
    rhs = np.einsum("kip,kp->ki", jac, resid)
    return nn, rhs, outside


def _solve_normals(nn: Array, rhs: Array, first: bool) -> tuple[Array, NDArray[np.bool_]]:
    """(n, 8) corrections and the (n,) patches whose normal equations could be solved.

    Singular normal equations (a template without texture: zero gain, no gradient) are
    tested on the first iteration (an SVD per patch); later a failed solve is caught.
    """
    det_ok = np.asarray(np.isfinite(nn).all(axis=(1, 2)))  # sampled off the image: not solved
    if first and det_ok.any():
        det_ok[det_ok] = np.linalg.cond(nn[det_ok]) < 1e12
    sol = np.zeros((nn.shape[0], 8))
    if det_ok.any():
        try:
            sol[det_ok] = np.linalg.solve(nn[det_ok], rhs[det_ok][:, :, None])[:, :, 0]
        except np.linalg.LinAlgError:
            for q in np.flatnonzero(det_ok):
                try:
                    sol[q] = np.linalg.solve(nn[q], rhs[q])
                except np.linalg.LinAlgError:
                    det_ok[q] = False
    return sol, det_ok


def _position_covariance(nmat: Array, s0: Array, good: NDArray[np.bool_]) -> Array:
    """(K, 2, 2) covariance of the matched position (pixels^2; NaN where not ``good``)."""
    cov = np.full((nmat.shape[0], 2, 2), np.nan)
    if good.any():
        try:
            q = np.linalg.inv(nmat[good])
        except np.linalg.LinAlgError:
            q = np.linalg.pinv(nmat[good])
        sub = q[:, [0, 3]][:, :, [0, 3]]
        cov[good] = s0[good, None, None] ** 2 * sub
    return cov


def lsm_batch(
    templates: ArrayLike,
    searches: ArrayLike,
    start: ArrayLike,
    reference: tuple[float, float] | None = None,
    options: LsmOptions | None = None,
) -> LsmResult:
    """Least-squares matching of K templates in K search windows (module docstring).

    Parameters
    ----------
    templates : (K, m, n) array_like
        Grey values f.
    searches : (K, H, W) array_like
        Grey values g.
    start : (K, 2, 3) array_like
        Start affines (:func:`affine_start`), template (x, y) -> search (col, row).
    reference : (col, row), optional
        Template array coordinates of the reference point (x = y = 0); the centre
        ``((n - 1) / 2, (m - 1) / 2)`` by default.
    options : LsmOptions, optional

    Returns
    -------
    LsmResult

    Examples
    --------
    >>> import cv2
    >>> rng = np.random.default_rng(3)
    >>> g = cv2.GaussianBlur(rng.normal(0, 40, (64, 64)), (0, 0), 2.0) + 100
    >>> f = g[20:41, 24:45] * 0.5 + 3         # template centre at (34, 30) in g
    >>> res = lsm_batch(f[None], g[None], affine_start([[33.4, 30.5]]))
    >>> res.reasons(), np.round(res.position[0], 3).tolist(), np.round(res.radiometry[0], 3)
    (['ok'], [34.0, 30.0], array([3. , 0.5]))
    """
    opt = options or LsmOptions()
    f = np.asarray(templates, dtype=np.float64)
    g = np.ascontiguousarray(searches, dtype=np.float64)
    if f.ndim == 2:
        f = f[None]
    if g.ndim == 2:
        g = g[None]
    a = np.array(start, dtype=np.float64).reshape(-1, 2, 3)
    k_n, m, n = f.shape
    if g.shape[0] != k_n or a.shape[0] != k_n:
        raise ValueError(f"{k_n} templates need as many search windows and start affines")
    h, w = g.shape[1:]
    cubic = opt.interpolation == "bicubic"
    grads = None if cubic else tuple(np.gradient(g, axis=(1, 2))[::-1])
    box = (1.0, w - 3.0, h - 3.0) if cubic else (0.0, w - 1.0, h - 1.0)
    rc, rr = reference if reference is not None else ((n - 1) / 2.0, (m - 1) / 2.0)
    yy, xx = np.mgrid[0:m, 0:n]
    x = (xx.ravel() - rc).astype(np.float64)
    y = (yy.ravel() - rr).astype(np.float64)
    p = x.size
    fv = f.reshape(k_n, p)
    start_pos = a[:, :, 0].copy()
    rad = np.zeros((k_n, 2))
    status = np.zeros(k_n, dtype=np.int8)
    iters = np.zeros(k_n, dtype=np.int32)
    active = np.ones(k_n, dtype=bool)
    nmat = np.zeros((k_n, 8, 8))
    fast = cubic and opt.backend != "numpy" and _numba.AVAILABLE
    if fast:
        g = np.ascontiguousarray(g)
        fv = np.ascontiguousarray(fv)

    def samples() -> Array:
        """(K, p) g resampled at the template points under the current affines."""
        if fast:
            return _numba.samples(g, a, x, y)
        cs, rs = _search_coords(a, x, y)
        return _sample(g, np.arange(k_n)[:, None], cs, rs, cubic, grads)[0]

    # Radiometric start: the gain and offset that map g's statistics at the start onto f's.
    gv0 = samples()
    sg = gv0.std(axis=1)
    rad[:, 1] = np.where(sg > 0, fv.std(axis=1) / np.where(sg > 0, sg, 1.0), 1.0)
    rad[:, 0] = fv.mean(axis=1) - rad[:, 1] * gv0.mean(axis=1)
    for it in range(1, opt.max_iterations + 1):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        if fast:
            nn, rhs, outside = _numba.normals(g, idx, a, rad, fv, x, y)
        else:
            nn, rhs, outside = _numpy_normals(g, idx, a, rad, fv, x, y, cubic, grads, box)
        sol, det_ok = _solve_normals(nn, rhs, it == 1)
        a[idx, 0, :] += sol[:, 0:3]
        a[idx, 1, :] += sol[:, 3:6]
        rad[idx] += sol[:, 6:8]
        nmat[idx] = nn
        iters[idx] = it
        bad_tex = ~det_ok
        status[idx[bad_tex]] = NO_TEXTURE
        # moved too far wins over having left the window: which of the two a drifting patch
        # reaches first depends only on how large its window was cut
        moved = np.hypot(*(a[idx, :, 0] - start_pos[idx]).T) > opt.max_shift_px
        status[idx[outside & det_ok & ~moved]] = LEFT_WINDOW
        status[idx[moved & det_ok]] = DRIFTED
        done = np.hypot(sol[:, 0], sol[:, 3]) < opt.shift_tol_px
        active[idx[done | bad_tex | outside | moved]] = False
    status[active] = NOT_CONVERGED
    # Final residuals, sigma0, covariance and correlation at the solution.
    status[(status == OK) & _outside(*_search_coords(a, x, y), box)] = LEFT_WINDOW
    gv = samples()
    resid = fv - (rad[:, 0:1] + rad[:, 1:2] * gv)
    s0 = np.sqrt((resid**2).sum(axis=1) / max(p - 8, 1))
    cov = _position_covariance(nmat, s0, status != NO_TEXTURE)
    sig = np.sqrt(np.stack([cov[:, 0, 0], cov[:, 1, 1]], axis=1))
    fc = fv - fv.mean(axis=1, keepdims=True)
    gc = gv - gv.mean(axis=1, keepdims=True)
    den = np.sqrt((fc**2).sum(axis=1) * (gc**2).sum(axis=1))
    corr = np.where(den > 0, (fc * gc).sum(axis=1) / np.where(den > 0, den, 1.0), 0.0)
    ok = status == OK
    status[ok & (corr < opt.min_correlation)] = LOW_CORRELATION
    ok = status == OK
    status[ok & ~(np.where(np.isnan(sig), np.inf, sig).max(axis=1) <= opt.max_sigma_px)] = (
        SIGMA_TOO_LARGE
    )
    return LsmResult(a, rad, sig, cov, s0, corr, iters, status)


def lsm_in_image(
    templates: ArrayLike,
    image: ArrayLike,
    start: ArrayLike,
    reference: tuple[float, float] | None = None,
    options: LsmOptions | None = None,
) -> LsmResult:
    """:func:`lsm_batch` with all K templates matched in one (H, W) image: each gets a window
    cut around its start position, large enough for the template under its own start affine
    plus ``max_shift_px`` and a margin; positions are returned in the image's array
    coordinates. Windows that would leave the image are cut at its border (a patch that
    reaches it is reported as having left the search window). A start whose window would be
    more than twice the median one is matched in a group of its own window size, the others
    share the largest of theirs: a single start affine of a large scale no longer enlarges
    every window of the batch (6 kite images: 3,370 windows of 263 x 263 px, 1.9 GB, for one
    such start, where 37-47 px serve the others).
    """
    opt = options or LsmOptions()
    f = np.asarray(templates, dtype=np.float64)
    if f.ndim == 2:
        f = f[None]
    img = np.asarray(image, dtype=np.float64)
    a = np.array(start, dtype=np.float64).reshape(-1, 2, 3)
    k_n, m, n = f.shape
    rc, rr = reference if reference is not None else ((n - 1) / 2.0, (m - 1) / 2.0)
    corners = np.array([[-rc, -rr], [n - 1 - rc, -rr], [-rc, m - 1 - rr], [n - 1 - rc, m - 1 - rr]])
    reach = np.abs(np.einsum("kij,cj->kci", a[:, :, 1:], corners)).max(axis=1).max(axis=1)
    halves = np.ceil(reach + opt.max_shift_px + 3).astype(np.intp)
    if k_n == 0 or a.shape[0] != k_n:
        return lsm_batch(f, np.zeros((k_n, 1, 1)), a, reference, opt)
    # the usual starts share the largest of their windows (a patch keeps room to drift and be
    # called so); a start needing more than twice the median is matched in its own group
    usual = halves <= 2 * np.median(halves)
    halves[usual] = halves[usual].max()
    border = int(halves.max()) + 1
    pad = np.pad(img, border, mode="constant", constant_values=np.nan)
    out = LsmResult(
        np.zeros((k_n, 2, 3)),
        np.zeros((k_n, 2)),
        np.zeros((k_n, 2)),
        np.zeros((k_n, 2, 2)),
        np.zeros(k_n),
        np.zeros(k_n),
        np.zeros(k_n, np.int32),
        np.zeros(k_n, np.int8),
    )
    for half in np.unique(halves):
        sel = np.flatnonzero(halves == half)
        part = _in_windows(f[sel], pad, border, a[sel], int(half), (rc, rr), reference, opt)
        for name in LsmResult.__dataclass_fields__:
            getattr(out, name)[sel] = getattr(part, name)
    return out


def _in_windows(
    f: Array,
    pad: Array,
    border: int,
    a: Array,
    half: int,
    ref: tuple[float, float],
    reference: tuple[float, float] | None,
    opt: LsmOptions,
) -> LsmResult:
    """:func:`lsm_in_image` for templates of one window size ``2 half + 1``; ``pad``: the image
    padded by ``border`` (>= half + 1) pixels of NaN."""
    k_n, m, n = f.shape
    rc, rr = ref
    size = 2 * half + 1
    origin = np.round(a[:, :, 0]).astype(np.intp) - half
    rows = origin[:, 1, None] + np.arange(size) + border
    cols = origin[:, 0, None] + np.arange(size) + border
    rows = np.clip(rows, 0, pad.shape[0] - 1)
    cols = np.clip(cols, 0, pad.shape[1] - 1)
    wins = pad[rows[:, :, None], cols[:, None, :]]
    nan = np.isnan(wins)
    local = a.copy()
    local[:, :, 0] -= origin
    res = lsm_batch(f, np.where(nan, 0.0, wins), local, reference, opt)
    aff = res.affine.copy()
    aff[:, :, 0] += origin
    status = res.status.copy()
    # A patch whose footprint (at the start or at the solution) touches pixels outside the
    # image was matched against filler: whatever happened next, that is the reason.
    if nan.any():
        yy, xx = np.mgrid[0:m, 0:n]
        x = xx.ravel() - rc
        y = yy.ravel() - rr
        k = np.arange(k_n)[:, None]
        for aff_w in (local, res.affine):
            cs, rs = _search_coords(aff_w, x, y)
            ci = np.clip(np.floor(cs).astype(np.intp), 0, size - 2)
            ri = np.clip(np.floor(rs).astype(np.intp), 0, size - 2)
            touch = (
                nan[k, ri, ci] | nan[k, ri + 1, ci + 1] | nan[k, ri, ci + 1] | nan[k, ri + 1, ci]
            ).any(axis=1)
            status[(status != NO_TEXTURE) & touch] = LEFT_WINDOW
    return LsmResult(
        aff,
        res.radiometry,
        res.sigma_px,
        res.cov_px,
        res.sigma0,
        res.correlation,
        res.iterations,
        status,
    )


@dataclass(frozen=True)
class PointMatch:
    """One point refined by :func:`match_point` (search-window array coordinates).

    col, row : matched position (NaN when refused); sigma_px : (col, row) sigmas, pixels;
    correlation : LSM correlation at the solution; reason : "" when accepted, else why not.
    """

    col: float
    row: float
    sigma_px: tuple[float, float]
    correlation: float
    reason: str

    @property
    def ok(self) -> bool:
        """True when accepted."""
        return not self.reason

    @classmethod
    def refused(cls, reason: str, correlation: float = math.nan) -> PointMatch:
        """A refused match: no position, ``reason`` saying why (``correlation`` where one was
        computed)."""
        return cls(math.nan, math.nan, (math.nan, math.nan), correlation, reason)


def match_point(
    template_window: ArrayLike,
    template_xy: tuple[float, float],
    search_window: ArrayLike,
    start_xy: tuple[float, float],
    half_size: int = 10,
    search_px: int = 6,
    min_ncc: float = 0.6,
    options: LsmOptions | None = None,
) -> PointMatch:
    """Snap ``start_xy`` in ``search_window`` to the match of the patch around ``template_xy``
    of ``template_window`` (both in their windows' array coordinates): NCC within
    ``search_px`` pixels, then least-squares matching (the picking dock's refine action).

    Examples
    --------
    >>> import cv2
    >>> rng = np.random.default_rng(3)
    >>> g = cv2.GaussianBlur(rng.normal(0, 40, (64, 64)), (0, 0), 2.0) + 100
    >>> m = match_point(g, (30.25, 33.5), g[2:, 3:] * 0.8, (29.0, 29.0))
    >>> m.reason, round(m.col, 2), round(m.row, 2)
    ('', 27.25, 31.5)
    """
    from .template_matching import ncc_search

    t = np.asarray(template_window, dtype=np.float64)
    s = np.asarray(search_window, dtype=np.float64)
    c, r = int(np.rint(template_xy[0])), int(np.rint(template_xy[1]))
    h = int(half_size)
    if c - h < 0 or r - h < 0 or c + h >= t.shape[1] or r + h >= t.shape[0]:
        return PointMatch.refused("the template point is too close to its image's border")
    tmpl = t[r - h : r + h + 1, c - h : c + h + 1]
    ref = (template_xy[0] - (c - h), template_xy[1] - (r - h))
    sc, sr = int(np.rint(start_xy[0])), int(np.rint(start_xy[1]))
    reach = h + int(search_px)
    if sc - reach < 0 or sr - reach < 0 or sc + reach >= s.shape[1] or sr + reach >= s.shape[0]:
        return PointMatch.refused("the point is too close to the image's border")
    sub = s[sr - reach : sr + reach + 1, sc - reach : sc + reach + 1]
    m = ncc_search(tmpl, sub)
    if m.peak < min_ncc:
        return PointMatch.refused(f"low correlation (NCC {m.peak:.2f} < {min_ncc:.2f})", m.peak)
    # the NCC centre is the template's centre pixel; the point is at ref from its corner
    start = np.array([sc - reach + m.col - h + ref[0], sr - reach + m.row - h + ref[1]])
    res = lsm_in_image(tmpl[None], s, affine_start(start[None]), reference=ref, options=options)
    reason = "" if res.ok[0] else f"LSM: {res.reasons()[0]}"
    return PointMatch(
        float(res.position[0, 0]),
        float(res.position[0, 1]),
        (float(res.sigma_px[0, 0]), float(res.sigma_px[0, 1])),
        float(res.correlation[0]),
        reason,
    )
