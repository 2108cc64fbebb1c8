"""Central projections of a camera: perspective and the four fisheye models.

A camera-frame vector ``q = (u, v, w)`` (x right, y up, the camera looks along -z) makes the
angle ``theta = atan2(hypot(u, v), -w)`` with the optical axis. Each projection maps it to an
ideal, centred image point at the radial distance ``r = f g(theta)`` from the principal point,
in the direction of ``(u, v)`` (Schneider, Schwalbe & Maas 2009; Abraham & Foerstner 2005):

=================  =====================  ====================  =======================
projection         ``r``                  ``theta`` from ``r``  valid for
=================  =====================  ====================  =======================
perspective        ``f tan(theta)``       ``atan(r / f)``       ``theta < 90 deg``
equidistant        ``f theta``            ``r / f``             ``theta < 180 deg``
equisolid          ``2 f sin(theta/2)``   ``2 asin(r / 2f)``    ``theta < 180 deg``
orthographic       ``f sin(theta)``       ``asin(r / f)``       ``theta <= 90 deg``
stereographic      ``2 f tan(theta/2)``   ``2 atan(r / 2f)``    ``theta < 180 deg``
=================  =====================  ====================  =======================

The lens correction of :mod:`core.geometry.distortion` (e.g. Brown-Conrady) is added to every
projection in the same way: ``ideal = measured + d(measured)``. For the perspective projection
the ideal point is computed as ``-f (u, v) / w``, exactly as before this module existed.

>>> import numpy as np
>>> q = np.array([[np.sin(0.5), 0.0, -np.cos(0.5)]])          # 0.5 rad off-axis
>>> ideal_from_camera(q, 10.0, "equidistant")[0].round(12).tolist()   # r = f theta
[[5.0, 0.0]]
>>> ray_from_ideal([[5.0, 0.0]], 10.0, "equidistant").round(12).tolist()
[[0.479425538604, 0.0, -0.87758256189]]
"""

from __future__ import annotations

from typing import Literal, Tuple, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .projection_names import FISHEYE_PROJECTIONS, PROJECTIONS

Array = NDArray[np.float64]


# Largest off-axis angle of each projection, radians (exclusive except orthographic).
_THETA_MAX = {
    "perspective": 0.5 * np.pi,
    "equidistant": np.pi,
    "equisolid": np.pi,
    "orthographic": 0.5 * np.pi,
    "stereographic": np.pi,
}

__all__ = [
    "FISHEYE_PROJECTIONS",
    "PROJECTIONS",
    "ideal_from_camera",
    "radius_derivative",
    "radius_factor",
    "ray_from_ideal",
    "theta_from_radius",
]


def _check(projection: str) -> None:
    if projection not in PROJECTIONS:
        raise ValueError(f"unknown projection {projection!r} (known: {', '.join(PROJECTIONS)})")


def radius_factor(theta: ArrayLike, projection: str) -> Array:
    """``g(theta) = r / f`` of a projection (dimensionless), ``theta`` in radians."""
    _check(projection)
    t = np.asarray(theta, dtype=np.float64)
    if projection == "perspective":
        return np.tan(t)
    if projection == "equidistant":
        return t.copy()
    if projection == "equisolid":
        return 2.0 * np.sin(0.5 * t)
    if projection == "orthographic":
        return np.sin(t)
    return 2.0 * np.tan(0.5 * t)


def radius_derivative(theta: ArrayLike, projection: str) -> Array:
    """``dg / dtheta`` of :func:`radius_factor`, per radian."""
    _check(projection)
    t = np.asarray(theta, dtype=np.float64)
    if projection == "perspective":
        return 1.0 / np.cos(t) ** 2
    if projection == "equidistant":
        return np.ones_like(t)
    if projection == "equisolid":
        return np.cos(0.5 * t)
    if projection == "orthographic":
        return np.cos(t)
    return 1.0 / np.cos(0.5 * t) ** 2


def theta_from_radius(r_over_f: ArrayLike, projection: str) -> Array:
    """Off-axis angle (radians) of a radial distance ``r / f``; NaN outside the projection."""
    _check(projection)
    s = np.asarray(r_over_f, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        if projection == "perspective":
            t = np.arctan(s)
        elif projection == "equidistant":
            t = s.copy()
        elif projection == "equisolid":
            t = 2.0 * np.arcsin(0.5 * s)
        elif projection == "orthographic":
            t = np.arcsin(s)
        else:
            t = 2.0 * np.arctan(0.5 * s)
    t = np.where((s >= 0) & (t <= _THETA_MAX[projection]), t, np.nan)
    return t


@overload
def ideal_from_camera(
    q: ArrayLike, focal_mm: float, projection: str, jacobian: Literal[False] = False
) -> Tuple[Array, NDArray[np.bool_]]: ...


@overload
def ideal_from_camera(
    q: ArrayLike, focal_mm: float, projection: str, jacobian: Literal[True]
) -> Tuple[Array, NDArray[np.bool_], Array]: ...


def ideal_from_camera(
    q: ArrayLike, focal_mm: float, projection: str, jacobian: bool = False
) -> Tuple[Array, NDArray[np.bool_]] | Tuple[Array, NDArray[np.bool_], Array]:
    """Ideal centred image coordinates (N, 2) mm of camera-frame vectors ``q`` (N, 3).

    Returns ``(ideal, valid)`` and, with ``jacobian``, ``d ideal / d q`` (N, 2, 3) mm per
    unit of ``q``. ``valid`` is False (and the rows NaN) where the angle off the axis is
    outside the projection (behind the camera for the perspective one).
    """
    _check(projection)
    qq = np.asarray(q, dtype=np.float64).reshape(-1, 3)
    u, v, w = qq[:, 0], qq[:, 1], qq[:, 2]
    n = qq.shape[0]
    f = float(focal_mm)
    jac = np.zeros((n, 2, 3))
    if projection == "perspective":
        valid = w < 0.0
        with np.errstate(divide="ignore", invalid="ignore"):
            ideal = -f * qq[:, :2] / w[:, np.newaxis]
            if jacobian:
                jac[:, 0, 0] = -f / w
                jac[:, 1, 1] = -f / w
                jac[:, 0, 2] = f * u / (w * w)
                jac[:, 1, 2] = f * v / (w * w)
    else:
        rho = np.hypot(u, v)
        theta = np.arctan2(rho, -w)
        lim = _THETA_MAX[projection]
        valid = (theta <= lim) if projection == "orthographic" else (theta < lim)
        valid &= np.isfinite(theta) & ((rho > 0) | (w < 0))
        g = radius_factor(theta, projection)
        # Near the axis g(theta) / rho -> 1 / -w (every fisheye g has g'(0) = 1): the
        # perspective limit avoids 0 / 0.
        axis = rho <= 1e-12 * np.abs(w)
        with np.errstate(divide="ignore", invalid="ignore"):
            scale = np.where(axis, -1.0 / w, g / rho)
        ideal = f * scale[:, np.newaxis] * qq[:, :2]
        if jacobian:
            n2 = rho * rho + w * w
            gp = radius_derivative(theta, projection)
            with np.errstate(divide="ignore", invalid="ignore"):
                # d theta / d rho = -w / n2, d theta / d w = rho / n2, d rho / du = u / rho
                ds_drho = gp * (-w / n2) / rho - g / (rho * rho)
                ds_dw = gp * (rho / n2) / rho
                for i, c in enumerate((u, v)):
                    for j, d in enumerate((u, v)):
                        jac[:, i, j] = f * ((scale if i == j else 0.0) + c * ds_drho * d / rho)
                    jac[:, i, 2] = f * c * ds_dw
            # on the axis: the perspective Jacobian (the fisheye one tends to it)
            if axis.any():
                wa = w[axis]
                jac[axis] = 0.0
                jac[axis, 0, 0] = -f / wa
                jac[axis, 1, 1] = -f / wa
                jac[axis, 0, 2] = f * u[axis] / (wa * wa)
                jac[axis, 1, 2] = f * v[axis] / (wa * wa)
    ideal = np.where(valid[:, np.newaxis], ideal, np.nan)
    if jacobian:
        jac[~valid] = np.nan
        return ideal, valid, jac
    return ideal, valid


def ray_from_ideal(xy_ideal: ArrayLike, focal_mm: float, projection: str) -> Array:
    """Camera-frame ray directions (N, 3) of ideal centred image points (N, 2) mm.

    Perspective: ``(x, y, -f)`` (not normalised, as the collinearity equations use it);
    fisheye: the unit vector at ``theta(r)`` off the axis, NaN where ``r`` is outside the
    projection's image.
    """
    _check(projection)
    xy = np.asarray(xy_ideal, dtype=np.float64).reshape(-1, 2)
    f = float(focal_mm)
    if projection == "perspective":
        return np.column_stack([xy, np.full(xy.shape[0], -f)])
    r = np.hypot(xy[:, 0], xy[:, 1])
    theta = theta_from_radius(r / f, projection)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(r > 0, np.sin(theta) / r, 1.0 / f)
    return np.column_stack([xy * s[:, np.newaxis], -np.cos(theta)])
