"""Rotation matrices and the angle sets of the project (see docs/conventions.md).

All functions are vectorised: angles may be scalars or arrays of any shape ``S``; matrices
then have shape ``S + (3, 3)``. Angles are in radians.

Conventions
-----------
- ``r1, r2, r3`` are the *passive* (frame) rotations of photogrammetry::

      R1(w) = [[1, 0, 0], [0, cos w, sin w], [0, -sin w, cos w]]

  and ``rx, ry, rz`` the *active* ones (``rx(a) == r1(a).T``).
- Omega-phi-kappa: ``M = R3(kappa) R2(phi) R1(omega)`` rotates object-space vectors into the
  camera frame; the camera-to-mapping rotation is ``R_c^m = M.T = Rx(omega) Ry(phi) Rz(kappa)``.
- Roll-pitch-heading: ``R_b^n = Rz(heading) Ry(pitch) Rx(roll)`` maps body vectors (x forward,
  y right, z down) into the local north-east-down frame.
- Boresight: ``R_c^b = R_nominal @ dR`` with ``dR = Rx(dw) Ry(dp) Rz(dk)``: small rotations about
  the camera axes x, y, z (the same form as ``R_c^m`` in omega-phi-kappa).
"""

from __future__ import annotations

from typing import Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

Array = NDArray[np.float64]
Angle = Union[float, ArrayLike]


def _basic(a: Angle, axis: int, passive: bool) -> Array:
    a = np.asarray(a, dtype=np.float64)
    c, s = np.cos(a), np.sin(a)
    if passive:
        s = -s
    out = np.zeros((*a.shape, 3, 3))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    out[..., axis, axis] = 1.0
    out[..., i, i] = c
    out[..., j, j] = c
    out[..., i, j] = -s
    out[..., j, i] = s
    return out


def rx(a: Angle) -> Array:
    """Active rotation by ``a`` about x (right-handed, counter-clockwise seen from +x)."""
    return _basic(a, 0, passive=False)


def ry(a: Angle) -> Array:
    """Active rotation by ``a`` about y."""
    return _basic(a, 1, passive=False)


def rz(a: Angle) -> Array:
    """Active rotation by ``a`` about z."""
    return _basic(a, 2, passive=False)


def r1(a: Angle) -> Array:
    """Passive rotation R1 of photogrammetry (``rx(a).T``)."""
    return _basic(a, 0, passive=True)


def r2(a: Angle) -> Array:
    """Passive rotation R2 (``ry(a).T``)."""
    return _basic(a, 1, passive=True)


def r3(a: Angle) -> Array:
    """Passive rotation R3 (``rz(a).T``)."""
    return _basic(a, 2, passive=True)


def opk_to_matrix(omega: Angle, phi: Angle, kappa: Angle) -> Array:
    """World-to-camera rotation ``M = R3(kappa) R2(phi) R1(omega)``.

    >>> bool(np.allclose(opk_to_matrix(0.0, 0.0, 0.0), np.eye(3)))
    True
    """
    return r3(kappa) @ r2(phi) @ r1(omega)


def matrix_to_opk(m: ArrayLike) -> tuple[Array, Array, Array]:
    """Inverse of :func:`opk_to_matrix`: (omega, phi, kappa) with phi in [-pi/2, pi/2]."""
    m = np.asarray(m, dtype=np.float64)
    # R_c^m = M.T = Rx Ry Rz: its row 0 is (cp ck, -cp sk, sp), column 2 is (sp, -sw cp, cw cp).
    phi = np.arctan2(m[..., 2, 0], np.hypot(m[..., 0, 0], m[..., 1, 0]))
    omega = np.arctan2(-m[..., 2, 1], m[..., 2, 2])
    kappa = np.arctan2(-m[..., 1, 0], m[..., 0, 0])
    return omega, phi, kappa


def opk_derivatives(omega: Angle, phi: Angle, kappa: Angle) -> Array:
    """Derivatives of ``M`` with respect to (omega, phi, kappa), shape ``S + (3, 3, 3)``.

    ``out[..., 0, :, :]`` is dM/domega, and so on.
    """
    a1, a2, a3 = r1(omega), r2(phi), r3(kappa)
    # dR1(w)/dw = R1(w) @ K1 with K1 the generator of the passive rotation about x.
    k1 = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
    k2 = np.array([[0.0, 0.0, -1.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    k3 = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    d_omega = a3 @ a2 @ (a1 @ k1)
    d_phi = a3 @ (a2 @ k2) @ a1
    d_kappa = (a3 @ k3) @ a2 @ a1
    return np.stack([d_omega, d_phi, d_kappa], axis=-3)


def rph_to_matrix(roll: Angle, pitch: Angle, heading: Angle) -> Array:
    """Body-to-NED rotation ``R_b^n = Rz(heading) Ry(pitch) Rx(roll)``."""
    return rz(heading) @ ry(pitch) @ rx(roll)


def matrix_to_rph(r: ArrayLike) -> tuple[Array, Array, Array]:
    """Inverse of :func:`rph_to_matrix`: (roll, pitch, heading), heading in (-pi, pi]."""
    r = np.asarray(r, dtype=np.float64)
    pitch = np.arctan2(-r[..., 2, 0], np.hypot(r[..., 0, 0], r[..., 1, 0]))
    roll = np.arctan2(r[..., 2, 1], r[..., 2, 2])
    heading = np.arctan2(r[..., 1, 0], r[..., 0, 0])
    return roll, pitch, heading


def boresight_matrix(d_omega: Angle, d_phi: Angle, d_kappa: Angle) -> Array:
    """Exact misalignment ``dR = Rx(dw) Ry(dp) Rz(dk)`` about the camera axes."""
    return rx(d_omega) @ ry(d_phi) @ rz(d_kappa)


def boresight_matrix_linear(d_omega: Angle, d_phi: Angle, d_kappa: Angle) -> Array:
    """First-order form of :func:`boresight_matrix`: ``I + [d]x`` (not orthonormal)."""
    dw, dp, dk = (np.asarray(v, dtype=np.float64) for v in (d_omega, d_phi, d_kappa))
    dw, dp, dk = np.broadcast_arrays(dw, dp, dk)
    out = np.zeros((*dw.shape, 3, 3))
    out[..., 0, 0] = out[..., 1, 1] = out[..., 2, 2] = 1.0
    out[..., 0, 1], out[..., 0, 2] = -dk, dp
    out[..., 1, 0], out[..., 1, 2] = dk, -dw
    out[..., 2, 0], out[..., 2, 1] = -dp, dw
    return out


def skew(v: ArrayLike) -> Array:
    """Cross-product matrix ``[v]x`` such that ``skew(v) @ u == cross(v, u)``."""
    v = np.asarray(v, dtype=np.float64)
    out = np.zeros((*v.shape[:-1], 3, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def nearest_rotation(m: ArrayLike, tol: float = 1e-5) -> Array:
    """The rotation nearest the (3, 3) matrix ``m`` (its orthogonal polar factor, by SVD);
    ValueError, saying why, unless ``m`` is a rotation within ``tol``: every singular value
    within ``tol`` of 1, no reflection, and every element within ``tol`` of the rotation.

    >>> bool(np.allclose(nearest_rotation(np.diag([1.0, 1.0, 1.0 + 1e-7])), np.eye(3)))
    True
    """
    a = np.asarray(m, dtype=np.float64)
    u, s, vt = np.linalg.svd(a)
    r = u @ vt
    off = float(np.max(np.abs(r - a)))
    if np.linalg.det(r) < 0 or np.max(np.abs(s - 1.0)) > tol or off > tol:
        raise ValueError(
            f"singular values {s.round(6)}, det {np.linalg.det(a):.6f}, {off:.2e} from the "
            f"nearest rotation (tolerance {tol:g})"
        )
    return r


def is_rotation(r: ArrayLike, atol: float = 1e-9) -> bool:
    """True when every matrix in ``r`` is orthonormal with determinant +1."""
    r = np.asarray(r, dtype=np.float64)
    eye = np.broadcast_to(np.eye(3), r.shape)
    return bool(
        np.allclose(np.swapaxes(r, -1, -2) @ r, eye, atol=atol)
        and np.allclose(np.linalg.det(r), 1.0, atol=atol)
    )
