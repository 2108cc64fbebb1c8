"""Polar observations of a terrestrial laser scanner: range, horizontal direction, vertical angle.

Scanner frame s: x and y span the plane perpendicular to the scanner's vertical (primary)
axis, z along it (up when the scanner is levelled); right-handed. A point ``d = (dx, dy, dz)``
in that frame is observed as (Carvalho, Correa & dos Santos, Eqs. 2-4)::

    range       rho   = |d|                                   metres
    horizontal  theta = atan2(dy, dx)                         radians, counter-clockwise from x
    vertical    alpha = atan2(dz, sqrt(dx^2 + dy^2))          radians, elevation above the
                                                              xy plane, in [-pi/2, pi/2]

Two faces: a scanner that turns its vertical circle past the zenith (a panoramic scanner
sweeping its mirror through 360 degrees, or a total-station-like instrument in face II) sees
the same point at ``theta + pi`` and ``pi - alpha``. Those *instrument* angles are what it
records, with ``alpha`` then in (pi/2, 3 pi/2): :func:`instrument_angles` turns the geometric
angles into them, and a vertical angle beyond +-90 degrees in a table marks face II.

All functions are vectorised over a leading dimension (N, ...).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "FACE_TWO_LIMIT",
    "cartesian_to_polar",
    "face_of",
    "instrument_angles",
    "polar_covariance",
    "polar_jacobian",
    "polar_to_cartesian",
    "wrap_angle",
]

Array = NDArray[np.float64]
#: A vertical angle (elevation) above this, in radians, is a face-II observation.
FACE_TWO_LIMIT = math.pi / 2


def wrap_angle(a: ArrayLike) -> Array:
    """Angles reduced to [-pi, pi).

    >>> float(wrap_angle(3 * math.pi / 2))
    -1.5707963267948966
    """
    return (np.asarray(a, dtype=np.float64) + math.pi) % (2 * math.pi) - math.pi


def cartesian_to_polar(d: ArrayLike) -> Array:
    """(N, 3) scanner-frame points -> (N, 3) geometric (rho, theta, alpha), theta in (-pi, pi].

    >>> np.round(cartesian_to_polar([[0.0, 3.0, 4.0]]), 6).tolist()
    [[5.0, 1.570796, 0.927295]]
    """
    d = np.asarray(d, dtype=np.float64)
    h = np.hypot(d[..., 0], d[..., 1])
    rho = np.sqrt(h * h + d[..., 2] ** 2)
    theta = np.arctan2(d[..., 1], d[..., 0])
    alpha = np.arctan2(d[..., 2], h)
    return np.stack([rho, theta, alpha], axis=-1)


def face_of(alpha: ArrayLike) -> NDArray[np.bool_]:
    """True where a recorded vertical angle (radians, elevation) is a face-II reading
    (beyond +-90 degrees after reduction to [-pi/2, 3 pi/2)).

    >>> face_of(np.radians([10.0, 100.0, 250.0, -80.0])).tolist()
    [False, True, True, False]
    """
    a = (np.asarray(alpha, dtype=np.float64) + math.pi / 2) % (2 * math.pi) - math.pi / 2
    return a > FACE_TWO_LIMIT


def instrument_angles(
    theta: ArrayLike, alpha: ArrayLike, face_two: ArrayLike
) -> tuple[Array, Array, Array]:
    """Geometric angles -> the angles the instrument records in its face, and
    ``d alpha_instrument / d alpha`` (+1 in face I, -1 in face II).

    Face I: ``(theta, alpha)``; face II: ``(theta + pi, pi - alpha)``.

    >>> t, a, s = instrument_angles(0.5, 0.2, True)
    >>> round(float(t), 6), round(float(a), 6), float(s)
    (3.641593, 2.941593, -1.0)
    """
    theta = np.asarray(theta, dtype=np.float64)
    alpha = np.asarray(alpha, dtype=np.float64)
    two = np.asarray(face_two, dtype=bool)
    t = np.where(two, theta + math.pi, theta)
    a = np.where(two, math.pi - alpha, alpha)
    return t, a, np.where(two, -1.0, 1.0)


def polar_to_cartesian(polar: ArrayLike) -> Array:
    """(N, 3) recorded (rho, theta, alpha), either face -> (N, 3) scanner-frame points.

    A face-II reading ``(theta + pi, pi - alpha)`` gives the same point as ``(theta, alpha)``
    because ``cos(pi - alpha) = -cos(alpha)``: no face flag is needed in this direction.

    >>> np.round(polar_to_cartesian([[5.0, math.pi / 2, math.atan2(4, 3)]]), 9).tolist()
    [[0.0, 3.0, 4.0]]
    """
    p = np.asarray(polar, dtype=np.float64)
    rho, theta, alpha = p[..., 0], p[..., 1], p[..., 2]
    ca = np.cos(alpha)
    return np.stack(
        [rho * ca * np.cos(theta), rho * ca * np.sin(theta), rho * np.sin(alpha)], axis=-1
    )


def polar_jacobian(d: ArrayLike) -> Array:
    """(N, 3, 3) ``d (rho, theta, alpha) / d (dx, dy, dz)`` of the geometric angles.

    Undefined on the vertical axis (dx = dy = 0), where theta is not defined.
    """
    d = np.asarray(d, dtype=np.float64)
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    h2 = x * x + y * y
    h = np.sqrt(h2)
    r2 = h2 + z * z
    r = np.sqrt(r2)
    out = np.zeros((*d.shape[:-1], 3, 3))
    out[..., 0, 0], out[..., 0, 1], out[..., 0, 2] = x / r, y / r, z / r
    out[..., 1, 0], out[..., 1, 1] = -y / h2, x / h2
    out[..., 2, 0] = -x * z / (r2 * h)
    out[..., 2, 1] = -y * z / (r2 * h)
    out[..., 2, 2] = h / r2
    return out


def polar_covariance(d: ArrayLike, cov: ArrayLike) -> tuple[Array, Array]:
    """Scanner-frame points with (N, 3, 3) covariances -> face-I polar observations and their
    propagated covariance (first order: ``J cov J'``).

    Returns
    -------
    polar : ndarray, shape (N, 3)
        (rho, theta, alpha) in metres and radians.
    cov_polar : ndarray, shape (N, 3, 3)

    >>> p, c = polar_covariance([[10.0, 0.0, 0.0]], np.diag([1e-6, 4e-6, 9e-6])[None])
    >>> np.round(np.sqrt(np.diag(c[0])) * [1, 10, 10], 6).tolist()
    [0.001, 0.002, 0.003]
    """
    d = np.asarray(d, dtype=np.float64)
    j = polar_jacobian(d)
    c = np.asarray(cov, dtype=np.float64)
    return cartesian_to_polar(d), j @ c @ np.swapaxes(j, -1, -2)
