"""Snavely's camera model (:mod:`.snavely`) compiled with numba: one loop over the
observations computing the projection and its Jacobians with scalars (no per-observation
3 x 3 temporaries), for the BAL benchmark problems. The same formulas as the numpy code;
tests/core/test_snavely.py compares the two.

numba is optional: :func:`project` returns None without it (the caller uses numpy).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

__all__ = ["project"]


def _kernel(c, X, u, jc, jp, want_jac):  # pragma: no cover - compiled
    n = c.shape[0]
    R = np.empty((3, 3))
    K = np.empty((3, 3))
    K2 = np.empty((3, 3))
    Jr = np.empty((3, 3))
    A = np.empty((3, 3))
    B = np.empty((2, 3))
    for i in range(n):
        r0, r1, r2 = c[i, 0], c[i, 1], c[i, 2]
        a = math.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
        if a < 1e-4:
            s1 = 1.0 - a * a / 6.0
            s2 = 0.5 - a * a / 24.0
            s3 = 1.0 / 6.0 - a * a / 120.0
        else:
            s1 = math.sin(a) / a
            s2 = (1.0 - math.cos(a)) / (a * a)
            s3 = (a - math.sin(a)) / (a * a * a)
        K[0, 0], K[0, 1], K[0, 2] = 0.0, -r2, r1
        K[1, 0], K[1, 1], K[1, 2] = r2, 0.0, -r0
        K[2, 0], K[2, 1], K[2, 2] = -r1, r0, 0.0
        for j in range(3):
            for k in range(3):
                K2[j, k] = K[j, 0] * K[0, k] + K[j, 1] * K[1, k] + K[j, 2] * K[2, k]
                e = 1.0 if j == k else 0.0
                R[j, k] = e + s1 * K[j, k] + s2 * K2[j, k]
                Jr[j, k] = e - s2 * K[j, k] + s3 * K2[j, k]
        x0, x1, x2 = X[i, 0], X[i, 1], X[i, 2]
        P0 = R[0, 0] * x0 + R[0, 1] * x1 + R[0, 2] * x2 + c[i, 3]
        P1 = R[1, 0] * x0 + R[1, 1] * x1 + R[1, 2] * x2 + c[i, 4]
        P2 = R[2, 0] * x0 + R[2, 1] * x1 + R[2, 2] * x2 + c[i, 5]
        iz = 1.0 / P2
        px = -P0 * iz
        py = -P1 * iz
        f, k1, k2 = c[i, 6], c[i, 7], c[i, 8]
        rr = px * px + py * py
        dist = 1.0 + rr * (k1 + k2 * rr)
        u[i, 0] = f * dist * px
        u[i, 1] = f * dist * py
        if not want_jac:
            continue
        gs = 2.0 * k1 + 4.0 * k2 * rr
        # du/dp = f (dist I + p g'), g = gs p
        d00 = f * (dist + px * gs * px)
        d01 = f * (px * gs * py)
        d10 = f * (py * gs * px)
        d11 = f * (dist + py * gs * py)
        # du/dP = du/dp dp/dP with dp/dP = [[-iz, 0, P0 iz^2], [0, -iz, P1 iz^2]]
        q0 = P0 * iz * iz
        q1 = P1 * iz * iz
        B[0, 0] = -d00 * iz
        B[0, 1] = -d01 * iz
        B[0, 2] = d00 * q0 + d01 * q1
        B[1, 0] = -d10 * iz
        B[1, 1] = -d11 * iz
        B[1, 2] = d10 * q0 + d11 * q1
        # dP/dr = -(R [X]x) Jr
        for j in range(3):
            # (R [X]x)[j] = R[j] x-product row: [X]x = [[0,-x2,x1],[x2,0,-x0],[-x1,x0,0]]
            m0 = R[j, 1] * x2 - R[j, 2] * x1
            m1 = -R[j, 0] * x2 + R[j, 2] * x0
            m2 = R[j, 0] * x1 - R[j, 1] * x0
            for k in range(3):
                A[j, k] = -(m0 * Jr[0, k] + m1 * Jr[1, k] + m2 * Jr[2, k])
        for j in range(2):
            for k in range(3):
                jc[i, j, k] = B[j, 0] * A[0, k] + B[j, 1] * A[1, k] + B[j, 2] * A[2, k]
                jc[i, j, 3 + k] = B[j, k]
                jp[i, j, k] = B[j, 0] * R[0, k] + B[j, 1] * R[1, k] + B[j, 2] * R[2, k]
        jc[i, 0, 6] = dist * px
        jc[i, 1, 6] = dist * py
        jc[i, 0, 7] = f * rr * px
        jc[i, 1, 7] = f * rr * py
        jc[i, 0, 8] = f * rr * rr * px
        jc[i, 1, 8] = f * rr * rr * py


def project(
    cameras: Array, points: Array, jacobian: bool, joint: bool = False
) -> tuple | Array | None:
    """``snavely_project`` compiled (None without numba); ``joint``: the Jacobians as one
    array (n, 2, 12), camera columns first, written in place (no concatenation)."""
    from ..compiled import compiled_kernel  # numba imported here: this module stays light

    kernel = compiled_kernel(_kernel)
    if kernel is None:
        return None
    c = np.ascontiguousarray(cameras, dtype=np.float64)
    X = np.ascontiguousarray(points, dtype=np.float64)
    n = c.shape[0]
    u = np.empty((n, 2))
    if jacobian and joint:
        J = np.empty((n, 2, 12))
        kernel(c, X, u, J[:, :, :9], J[:, :, 9:], True)
        return u, J
    jc = np.empty((n, 2, 9) if jacobian else (0, 2, 9))
    jp = np.empty((n, 2, 3) if jacobian else (0, 2, 3))
    kernel(c, X, u, jc, jp, bool(jacobian))
    return (u, jc, jp) if jacobian else u
