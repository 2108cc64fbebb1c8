"""Straight lines in single-image orientation: image vectors, the coplanarity of an image point
with a 3D line, and the equivalent-planes model, with analytic Jacobians.

Frames and symbols (docs/conventions.md): the camera frame has x right, y up, z toward the
viewer; an image point is the camera-frame vector ``p = (x, y, -f)`` with ``(x, y)`` its ideal
coordinates (centred on the principal point, lens correction applied, mm). A 3D line is given
by two of its points ``P1, P2`` (object frame, metres); with the exterior orientation
``(X0, Y0, Z0, omega, phi, kappa)`` and ``M = R3(kappa) R2(phi) R1(omega)`` their camera-frame
vectors are ``a = M (P1 - C)`` and ``b = M (P2 - C)``. The interpretation plane of the 3D line
(through the perspective centre and the line) has the camera-frame normal ``N = a x b``; its
trace in the image plane ``z = -f`` is the projected line ``N1 x + N2 y - f N3 = 0``.

Models of a line correspondence (image points ``p_j`` measured on the image of the 3D line):

- **coplanarity** (parametrisation-free): every image point lies on the projected line,
  ``d_j = (N . p_j) / sqrt(N1^2 + N2^2) = 0``; ``d_j`` is the perpendicular distance of the
  image point from the projected line in the image plane (mm), whatever the line's direction.
- **equivalent planes** (Tommaselli & Tozzi 1996, as used by dos Santos, Dal Poz & Dalmolin
  2010): the image line ``y = a x + b`` ("horizontal", ``|a| <= 1``) or ``x = a* y + b*``
  ("vertical") has the interpretation-plane normal ``(-a, 1, b/f)`` or ``(1, -a*, b*/f)``;
  equating it with the direction of ``N`` gives ``a = -N1/N2, b = f N3/N2`` and
  ``a* = -N2/N1, b* = f N3/N1`` (derived here from the normal of the plane through the
  perspective centre and the image line; the source text gives the model by reference only).
  The parametrisation is chosen once from the measured line; each becomes singular when the
  predicted line turns perpendicular to it (``N2 = 0`` or ``N1 = 0``).

All functions are vectorised over lines (leading dimension ``G``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .camera import Camera
from .rotations import opk_derivatives, opk_to_matrix, skew

Array = NDArray[np.float64]

__all__ = [
    "HORIZONTAL",
    "VERTICAL",
    "camera_vectors",
    "coplanarity",
    "equivalent_planes_image",
    "equivalent_planes_model",
    "image_vectors",
    "parametrisation",
]

#: Equivalent-planes parametrisation codes: ``y = a x + b`` and ``x = a* y + b*``.
HORIZONTAL = 0
VERTICAL = 1


def image_vectors(
    pixels: ArrayLike,
    camera: Camera,
    interior: ArrayLike | None = None,
) -> tuple[Array, Array, Array]:
    """Camera-frame vectors ``p = (x, y, -f)`` of measured pixels, and their Jacobians.

    Parameters
    ----------
    pixels : (..., 2) array_like
        Measured (col, row), pixels.
    camera : Camera
        Pixel size, image size and lens correction (held fixed).
    interior : (3,) array_like, optional
        ``(focal_mm, x0_mm, y0_mm)`` replacing the camera's (when they are adjusted).

    Returns
    -------
    p : (..., 3) ndarray
        mm.
    dp_dpixel : (..., 3, 2) ndarray
        mm per pixel (the third row is zero).
    dp_dinterior : (..., 3, 3) ndarray
        Derivatives with respect to ``(focal_mm, x0_mm, y0_mm)``.

    Examples
    --------
    >>> cam = Camera("c", focal_mm=100.0, pixel_size_mm=0.01, width_px=1000, height_px=800)
    >>> image_vectors([[600.0, 400.0]], cam)[0].tolist()
    [[1.0, 0.0, -100.0]]
    """
    px = np.asarray(pixels, dtype=np.float64)
    shape = px.shape[:-1]
    flat = px.reshape(-1, 2)
    f, x0, y0 = (
        (camera.focal_mm, camera.x0_mm, camera.y0_mm)
        if interior is None
        else (float(v) for v in np.asarray(interior, dtype=np.float64).reshape(3))
    )
    centred = camera.pixel_to_image(flat) - np.array([x0, y0])
    lens = camera.distortion
    ideal = centred + lens.correction(centred)
    g = np.eye(2) + lens.jacobian_xy(centred)  # d ideal / d centred
    ps = camera.pixel_size_mm
    n = flat.shape[0]
    p = np.column_stack([ideal, np.full(n, -f)])
    dpix = np.zeros((n, 3, 2))
    dpix[:, :2, 0] = g[:, :, 0] * ps
    dpix[:, :2, 1] = -g[:, :, 1] * ps
    dio = np.zeros((n, 3, 3))
    dio[:, 2, 0] = -1.0
    dio[:, :2, 1:] = -g
    return p.reshape(*shape, 3), dpix.reshape(*shape, 3, 2), dio.reshape(*shape, 3, 3)


def camera_vectors(points: ArrayLike, eo: ArrayLike) -> tuple[Array, Array, Array]:
    """``q = M (P - C)`` of object points and its Jacobians.

    Parameters
    ----------
    points : (G, 3) array_like
        Object points, metres.
    eo : (6,) or (G, 6) array_like
        ``(X0, Y0, Z0, omega, phi, kappa)``, metres and radians.

    Returns
    -------
    q : (G, 3) ndarray
    dq_deo : (G, 3, 6) ndarray
    dq_dpoint : (G, 3, 3) ndarray
        ``M``.

    Examples
    --------
    >>> camera_vectors([[1.0, 2.0, 0.0]], [0.0, 0.0, 10.0, 0.0, 0.0, 0.0])[0].tolist()
    [[1.0, 2.0, -10.0]]
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    e = np.broadcast_to(np.asarray(eo, dtype=np.float64).reshape(-1, 6), (pts.shape[0], 6))
    m = opk_to_matrix(e[:, 3], e[:, 4], e[:, 5])
    d = pts - e[:, :3]
    q = np.einsum("gij,gj->gi", m, d)
    dm = opk_derivatives(e[:, 3], e[:, 4], e[:, 5])  # (G, 3 angles, 3, 3)
    jac = np.empty((pts.shape[0], 3, 6))
    jac[:, :, :3] = -m
    jac[:, :, 3:] = np.einsum("gkij,gj->gik", dm, d)
    return q, jac, m


def _normal(a: Array, b: Array) -> tuple[Array, Array, Array]:
    """``N = a x b`` and its Jacobians ``dN/da = -[b]x``, ``dN/db = [a]x``."""
    return np.cross(a, b), -skew(b), skew(a)


def coplanarity(p: ArrayLike, a: ArrayLike, b: ArrayLike) -> tuple[Array, Array, Array, Array]:
    """Distances of image points from the projected 3D line, and their Jacobians.

    Parameters
    ----------
    p : (G, K, 3) array_like
        Camera-frame vectors of K image points measured on each of G lines, mm.
    a, b : (G, 3) array_like
        Camera-frame vectors of two points of each 3D line (``M (P - C)``), metres.

    Returns
    -------
    d : (G, K) ndarray
        Signed perpendicular distance of each image point from the projected line, mm (the
        sign depends on the order of the two points).
    dd_dp : (G, K, 3) ndarray
    dd_da, dd_db : (G, K, 3) ndarray

    Examples
    --------
    A line 10 m to the right of a nadir camera 100 m up, f = 100 mm: it images 10 mm right of
    the centre, so an image point at x = 12 mm lies 2 mm from it.

    >>> a, b = [[10.0, 0.0, -100.0]], [[10.0, 5.0, -100.0]]
    >>> round(float(abs(coplanarity([[[12.0, 3.0, -100.0]]], a, b)[0][0, 0])), 9)
    2.0
    """
    pv = np.asarray(p, dtype=np.float64)
    av = np.asarray(a, dtype=np.float64)
    bv = np.asarray(b, dtype=np.float64)
    n, dn_da, dn_db = _normal(av, bv)
    h = np.hypot(n[:, 0], n[:, 1])  # (G,)
    s = np.einsum("gkc,gc->gk", pv, n)  # N . p
    d = s / h[:, None]
    # d d / d N = p / h - s (N1, N2, 0) / h^3
    nxy = n.copy()
    nxy[:, 2] = 0.0
    dd_dn = pv / h[:, None, None] - (s / h[:, None] ** 3)[:, :, None] * nxy[:, None, :]
    dd_dp = np.broadcast_to((n / h[:, None])[:, None, :], pv.shape).copy()
    dd_da = np.einsum("gkc,gcj->gkj", dd_dn, dn_da)
    dd_db = np.einsum("gkc,gcj->gkj", dd_dn, dn_db)
    return d, dd_dp, dd_da, dd_db


def parametrisation(p: ArrayLike) -> NDArray[np.int8]:
    """The equivalent-planes parametrisation of measured image lines.

    HORIZONTAL (``y = a x + b``) when the line from the first to the last point makes at most
    45 degrees with the image x axis (``|a| <= 1``), VERTICAL (``x = a* y + b*``) otherwise:
    the source's rule (45 < theta < 135 or 225 < theta < 315 degrees -> horizontal) with theta
    read as the direction of the line's normal.

    Parameters
    ----------
    p : (G, K, 3) array_like
        Camera-frame vectors of the image points of each line, mm.

    Returns
    -------
    (G,) ndarray of int8

    Examples
    --------
    >>> parametrisation([[[0, 0, -1], [3, 1, -1]], [[0, 0, -1], [1, 3, -1]]]).tolist()
    [0, 1]
    """
    pv = np.asarray(p, dtype=np.float64)
    d = pv[:, -1, :2] - pv[:, 0, :2]
    return np.where(np.abs(d[:, 1]) <= np.abs(d[:, 0]), HORIZONTAL, VERTICAL).astype(np.int8)


def equivalent_planes_image(p: ArrayLike, kind: ArrayLike) -> tuple[Array, Array]:
    """Line parameters ``(a, b)`` (or ``(a*, b*)``) of measured image lines, and their Jacobian.

    With two points the line through them; with more, the least-squares line of the chosen
    form (``y`` on ``x`` for HORIZONTAL, ``x`` on ``y`` for VERTICAL).

    Parameters
    ----------
    p : (G, K, 3) array_like
        Camera-frame vectors ``(x, y, -f)`` of K >= 2 points per line, mm.
    kind : (G,) array_like of int
        HORIZONTAL or VERTICAL per line.

    Returns
    -------
    ab : (G, 2) ndarray
        ``a`` (dimensionless) and ``b`` (mm).
    dab_dp : (G, 2, K, 3) ndarray
        Derivatives with respect to the points (zero for their third component).

    Examples
    --------
    >>> ab, _ = equivalent_planes_image([[[0.0, 1.0, -1.0], [2.0, 2.0, -1.0]]], [0])
    >>> ab.tolist()
    [[0.5, 1.0]]
    """
    pv = np.asarray(p, dtype=np.float64)
    vert = np.asarray(kind).reshape(-1) == VERTICAL
    k = pv.shape[1]
    u = np.where(vert[:, None], pv[:, :, 1], pv[:, :, 0])  # regressor
    w = np.where(vert[:, None], pv[:, :, 0], pv[:, :, 1])  # regressand
    du = u - u.mean(axis=1, keepdims=True)
    dw = w - w.mean(axis=1, keepdims=True)
    suu = np.sum(du * du, axis=1)
    a = np.sum(du * dw, axis=1) / suu
    ubar = u.mean(axis=1)
    b = w.mean(axis=1) - a * ubar
    da_dw = du / suu[:, None]
    da_du = (dw - 2.0 * a[:, None] * du) / suu[:, None]
    db_dw = 1.0 / k - ubar[:, None] * da_dw
    db_du = -a[:, None] / k - ubar[:, None] * da_du
    jac = np.zeros((pv.shape[0], 2, k, 3))
    iu = np.where(vert, 1, 0)
    iw = 1 - iu
    g = np.arange(pv.shape[0])
    jac[g, 0, :, iu[g]] = da_du
    jac[g, 0, :, iw[g]] = da_dw
    jac[g, 1, :, iu[g]] = db_du
    jac[g, 1, :, iw[g]] = db_dw
    return np.column_stack([a, b]), jac


def equivalent_planes_model(
    a: ArrayLike, b: ArrayLike, focal_mm: float, kind: ArrayLike
) -> tuple[Array, Array, Array, Array]:
    """Predicted ``(a, b)`` (or ``(a*, b*)``) of the image of 3D lines, and their Jacobians.

    Parameters
    ----------
    a, b : (G, 3) array_like
        Camera-frame vectors of two points of each 3D line (``M (P - C)``).
    focal_mm : float
        Principal distance.
    kind : (G,) array_like of int
        HORIZONTAL (``a = -N1/N2, b = f N3/N2``) or VERTICAL (``a* = -N2/N1, b* = f N3/N1``).

    Returns
    -------
    ab : (G, 2) ndarray
    dab_da, dab_db : (G, 2, 3) ndarray
    dab_df : (G, 2) ndarray

    Examples
    --------
    The 3D line x = 10 m, 100 m below a nadir camera with f = 100 mm, images as x = 10 mm:
    vertical, ``a* = 0``, ``b* = 10``.

    >>> ab = equivalent_planes_model([[10.0, 0, -100]], [[10.0, 5, -100]], 100.0, [1])[0]
    >>> [round(float(v), 9) + 0.0 for v in ab[0]]
    [0.0, 10.0]
    """
    av = np.asarray(a, dtype=np.float64)
    bv = np.asarray(b, dtype=np.float64)
    vert = np.asarray(kind).reshape(-1) == VERTICAL
    n, dn_da, dn_db = _normal(av, bv)
    # the denominator component: N2 (horizontal) or N1 (vertical); the numerator of a: N1 / N2
    den = np.where(vert, n[:, 0], n[:, 1])
    num = np.where(vert, n[:, 1], n[:, 0])
    f = float(focal_mm)
    ab = np.column_stack([-num / den, f * n[:, 2] / den])
    g = n.shape[0]
    dab_dn = np.zeros((g, 2, 3))
    i_num = np.where(vert, 1, 0)
    i_den = 1 - i_num
    rows = np.arange(g)
    dab_dn[rows, 0, i_num] = -1.0 / den
    dab_dn[rows, 0, i_den] = num / den**2
    dab_dn[rows, 1, i_den] = -f * n[:, 2] / den**2
    dab_dn[rows, 1, 2] = f / den
    dab_df = np.column_stack([np.zeros(g), n[:, 2] / den])
    return ab, dab_dn @ dn_da, dab_dn @ dn_db, dab_df
