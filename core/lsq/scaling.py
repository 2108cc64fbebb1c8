"""Jacobi scaling of the normal equations and of the hard-constraint rows.

Both the full system (:mod:`.problem`) and the reduced one (:mod:`.schur`) solve in the scaled
variables ``z = D dx`` with ``D = sqrt(diag(N))`` (see :mod:`.adjustment`), and bring the
constraint rows to unit length in that space, so that ``C'C`` is commensurate with ``N_s``.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

Array = NDArray[np.float64]


def jacobi_scale(d: Array, C: sp.csr_matrix | None) -> Array:
    """The scale ``D`` from ``d = sqrt(diag N)``: the constraint column norm for parameters seen
    only by constraints, 1 for parameters seen by nothing (the observability check names them).

    >>> C = sp.csr_matrix(np.array([[0.0, 3.0, 0.0]]))
    >>> jacobi_scale(np.array([2.0, 0.0, 0.0]), C).tolist()
    [2.0, 3.0, 1.0]
    """
    if C is not None:
        Cc = sp.csr_matrix(C)
        cn = np.sqrt(np.bincount(Cc.indices, weights=Cc.data**2, minlength=Cc.shape[1]))
        d = np.where(d > 0, d, cn)
    return np.where(d > 0, d, 1.0)


def scale_constraints(
    C: sp.csr_matrix, dinv: Array, h: Array, rowscale: Array | None
) -> tuple[sp.csr_matrix, Array, Array]:
    """``(C_s, h_s, rowscale)``: the constraint Jacobian in the scaled variables with unit rows
    (``R C D^-1``) and its values ``R h``; ``rowscale`` (``R``) is computed when None (the
    first linearisation) and then kept, so that the merit function stays the same.

    >>> Cs, hs, r = scale_constraints(sp.csr_matrix(np.array([[3.0, 4.0]])), np.ones(2),
    ...                               np.array([10.0]), None)
    >>> np.round(Cs.toarray(), 12).tolist(), hs.tolist(), r.tolist()
    ([[0.6, 0.8]], [2.0], [0.2])
    """
    # the products with the diagonal matrices on the stored entries (no sparse products)
    Cd = sp.csr_matrix(C, copy=True)
    Cd.eliminate_zeros()
    Cd.data *= dinv[Cd.indices]
    rows = np.repeat(np.arange(Cd.shape[0]), np.diff(Cd.indptr))
    if rowscale is None:
        rn = np.sqrt(np.bincount(rows, weights=Cd.data**2, minlength=Cd.shape[0]))
        rowscale = np.where(rn > 0, 1.0 / np.where(rn > 0, rn, 1.0), 1.0)
    Cd.data *= rowscale[rows]
    return Cd, rowscale * h, rowscale
