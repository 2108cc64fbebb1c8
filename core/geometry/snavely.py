"""Snavely's camera model (Bundler, and the BAL benchmark problems), with analytic Jacobians.

A camera is ``(r, t, f, k1, k2)``: ``P = R(r) X + t`` with ``R(r)`` the rotation of the
Rodrigues vector ``r``, ``p = -P_xy / P_z``, and the projection
``u = f (1 + k1 |p|^2 + k2 |p|^4) p`` (pixels from the image centre, x right, y up).

The derivative of ``R(r) X`` by ``r`` is ``-R [X]x J_r(r)`` with ``J_r`` the right Jacobian
of the rotation group, ``J_r(r) = I - (1 - cos a)/a^2 [r]x + (a - sin a)/a^3 [r]x^2``
(``a = |r|``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .rotations import skew

Array = NDArray[np.float64]

__all__ = ["rodrigues", "snavely_project"]


def _coefficients(a: Array) -> tuple[Array, Array, Array, Array]:
    """sin(a)/a, (1-cos a)/a^2, (a - sin a)/a^3 (series near 0) and a."""
    small = a < 1e-4
    safe = np.where(small, 1.0, a)
    s1 = np.where(small, 1.0 - a * a / 6.0, np.sin(safe) / safe)
    s2 = np.where(small, 0.5 - a * a / 24.0, (1.0 - np.cos(safe)) / safe**2)
    s3 = np.where(small, 1.0 / 6.0 - a * a / 120.0, (safe - np.sin(safe)) / safe**3)
    return s1, s2, s3, a


def rodrigues(r: Array) -> Array:
    """Rotation matrices (N, 3, 3) of Rodrigues vectors (N, 3).

    >>> bool(np.allclose(rodrigues(np.array([[0.0, 0.0, np.pi / 2]]))[0] @ [1, 0, 0], [0, 1, 0]))
    True
    """
    r = np.atleast_2d(np.asarray(r, dtype=np.float64))
    s1, s2, _, _ = _coefficients(np.linalg.norm(r, axis=1))
    K = skew(r)
    return np.eye(3) + s1[:, None, None] * K + s2[:, None, None] * (K @ K)


def snavely_project(
    cameras: Array, points: Array, jacobian: bool = True, compiled: bool = True, joint: bool = False
):
    """Projections (N, 2) of points (N, 3) by cameras (N, 9), and optionally the Jacobians
    ``d u / d camera`` (N, 2, 9) and ``d u / d point`` (N, 2, 3), or with ``joint`` both as
    one (N, 2, 12), camera columns first (the Jacobian of a group (camera, point)).
    ``compiled``: the numba kernel of :mod:`.snavely_numba` when numba is there (the same
    formulas in one loop), else numpy.

    >>> cam = np.array([[0, 0, 0, 0, 0, -10.0, 100.0, 0, 0]])
    >>> snavely_project(cam, np.array([[1.0, 2.0, 0.0]]), jacobian=False).tolist()
    [[10.0, 20.0]]
    """
    c = np.asarray(cameras, dtype=np.float64)
    X = np.asarray(points, dtype=np.float64)
    if compiled and c.shape[0] > 0:
        from .snavely_numba import project

        out = project(c, X, jacobian, joint)
        if out is not None:
            return out
    r, t, f, k1, k2 = c[:, :3], c[:, 3:6], c[:, 6], c[:, 7], c[:, 8]
    R = rodrigues(r)
    P = np.einsum("nij,nj->ni", R, X) + t
    p = -P[:, :2] / P[:, 2:3]
    r2 = np.sum(p * p, axis=1)
    dist = 1.0 + r2 * (k1 + k2 * r2)
    u = (f * dist)[:, None] * p
    if not jacobian:
        return u
    n = c.shape[0]
    # du/dp = f (dist I + p (d dist/dp)'), d dist/dp = (2 k1 + 4 k2 r2) p
    g = (2.0 * k1 + 4.0 * k2 * r2)[:, None] * p
    du_dp = f[:, None, None] * (dist[:, None, None] * np.eye(2) + p[:, :, None] * g[:, None, :])
    iz = 1.0 / P[:, 2]
    dp_dP = np.zeros((n, 2, 3))
    dp_dP[:, 0, 0] = -iz
    dp_dP[:, 1, 1] = -iz
    dp_dP[:, 0, 2] = P[:, 0] * iz * iz
    dp_dP[:, 1, 2] = P[:, 1] * iz * iz
    du_dP = du_dp @ dp_dP
    _, s2, s3, _ = _coefficients(np.linalg.norm(r, axis=1))
    K = skew(r)
    Jr = np.eye(3) - s2[:, None, None] * K + s3[:, None, None] * (K @ K)
    dP_dr = -(R @ skew(X)) @ Jr
    J_cam = np.zeros((n, 2, 9))
    J_cam[:, :, :3] = du_dP @ dP_dr
    J_cam[:, :, 3:6] = du_dP
    J_cam[:, :, 6] = dist[:, None] * p
    J_cam[:, :, 7] = (f * r2)[:, None] * p
    J_cam[:, :, 8] = (f * r2 * r2)[:, None] * p
    J_pt = du_dP @ R
    if joint:
        return u, np.concatenate([J_cam, J_pt], axis=2)
    return u, J_cam, J_pt
