"""Eigen-decomposition of batches of symmetric 3 x 3 matrices by a fixed number of cyclic
Jacobi rotations, vectorised over the batch.

Only IEEE +, -, *, / and sqrt, in an order fixed by the code: no BLAS or LAPACK call, so the
result is the same bit for bit whatever the number of BLAS threads, the BLAS/LAPACK build
or the numpy version (LAPACK's ``eigh`` on Debian's OpenBLAS moved plane parameters by up to
1.8e-14 of their value between 1 and 2 threads). Every matrix of the batch gets the same
``JACOBI_SWEEPS`` sweeps of the rotations (0, 1), (0, 2), (1, 2) (Golub & Van Loan, Matrix
Computations, 4th ed., section 8.5: the symmetric Schur decomposition and the cyclic Jacobi
method), so a matrix's result does not depend on the others in its batch; a rotation whose
off-diagonal element is already zero is skipped. Cyclic Jacobi converges quadratically:
six sweeps take any 3 x 3 matrix to machine precision (checked against LAPACK in
tests/core/test_sym3.py). The compiled roof-plane kernels
(:mod:`core.lidar.roof_planes_numba`) perform the same rotations one matrix at a time, with
the same bits.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError

__all__ = ["JACOBI_SWEEPS", "eigh_sym3", "jacobi_sym3"]

Array = NDArray[np.float64]

#: Jacobi sweeps (3 rotations each) of every 3 x 3 eigen-decomposition.
JACOBI_SWEEPS = 6

_PAIRS = ((0, 1, 2), (0, 2, 1), (1, 2, 0))  # (p, q, the third index r)


def jacobi_sym3(
    a00: Array, a01: Array, a02: Array, a11: Array, a12: Array, a22: Array
) -> tuple[list[Array], list[list[Array]]]:
    """Eigenvalues and eigenvectors, unsorted, of the symmetric 3 x 3 matrices given by their
    upper triangles (each (B,), any unit u): ``(d, v)`` with ``d[k]`` (B,) the k-th eigenvalue
    (u) and ``v[row][k]`` (B,) the row-th component of its unit eigenvector (the k-th column
    of the rotations' product). The inputs are not modified."""
    one, zero = np.ones_like(a00), np.zeros_like(a00)
    v = [
        [one, zero, zero],
        [zero.copy(), one.copy(), zero.copy()],
        [zero.copy(), zero.copy(), one.copy()],
    ]
    a = {(0, 0): a00, (0, 1): a01, (0, 2): a02, (1, 1): a11, (1, 2): a12, (2, 2): a22}
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for _ in range(JACOBI_SWEEPS):
            for p_, q_, r_ in _PAIRS:
                app, aqq, apq = a[p_, p_], a[q_, q_], a[p_, q_]
                rot = apq != 0.0
                theta = (aqq - app) / (2.0 * apq)
                tt = 1.0 / (np.abs(theta) + np.sqrt(theta * theta + 1.0))
                tt = np.where(theta < 0.0, -tt, tt)
                cc = 1.0 / np.sqrt(tt * tt + 1.0)
                ss = tt * cc
                arp, arq = a[min(r_, p_), max(r_, p_)], a[min(r_, q_), max(r_, q_)]
                a[p_, p_] = np.where(rot, app - tt * apq, app)
                a[q_, q_] = np.where(rot, aqq + tt * apq, aqq)
                a[p_, q_] = np.where(rot, 0.0, apq)
                a[min(r_, p_), max(r_, p_)] = np.where(rot, cc * arp - ss * arq, arp)
                a[min(r_, q_), max(r_, q_)] = np.where(rot, ss * arp + cc * arq, arq)
                for row in range(3):
                    vp, vq = v[row][p_], v[row][q_]
                    v[row][p_] = np.where(rot, cc * vp - ss * vq, vp)
                    v[row][q_] = np.where(rot, ss * vp + cc * vq, vq)
    return [a[0, 0], a[1, 1], a[2, 2]], v


def eigh_sym3(matrices: Array) -> tuple[Array, Array]:
    """``numpy.linalg.eigh`` of a batch of symmetric 3 x 3 matrices (B, 3, 3) (only the upper
    triangle is read) by :func:`jacobi_sym3`: eigenvalues (B, 3) ascending and unit
    eigenvectors (B, 3, 3) in the columns (``vec[b, :, k]`` belongs to ``lam[b, k]``), the
    same bits for any BLAS, thread count or numpy version. Ties in the eigenvalues keep
    the columns' order (a stable sort); an eigenvector's sign is the rotations'.

    >>> lam, vec = eigh_sym3(np.array([[[2.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 5.0]]]))
    >>> lam.round(12).tolist(), np.abs(vec[0, :, 0]).round(12).tolist()
    ([[1.0, 3.0, 5.0]], [0.707106781187, 0.707106781187, 0.0])
    """
    m = np.asarray(matrices, dtype=np.float64)
    if m.ndim != 3 or m.shape[1:] != (3, 3):
        raise InputError(f"matrices must have shape (B, 3, 3), got {m.shape}")
    d, v = jacobi_sym3(m[:, 0, 0], m[:, 0, 1], m[:, 0, 2], m[:, 1, 1], m[:, 1, 2], m[:, 2, 2])
    lam = np.column_stack(d)
    vec = np.stack([np.column_stack(row) for row in v], axis=1)  # (B, row, column)
    order = np.argsort(lam, axis=1, kind="stable")
    lam = np.take_along_axis(lam, order, axis=1)
    vec = np.take_along_axis(vec, order[:, None, :], axis=2)
    return lam, vec
