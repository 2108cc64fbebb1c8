"""The pair sums of the reduced camera system (:mod:`.schur`) compiled with numba.

``W V^-1 W'`` is summed over pairs of occurrences of the same eliminated block: for every
pair ``q`` (sorted by its key, a pair of signatures such as two images) the product
``Za[o1[q]]' Zb[o2[q]]`` (``kk1 x kk2`` from ``b`` rows) is added to its key's block. numpy
has to gather both operands of every pair and loop over the keys in Python; the kernel reads
them in place in one loop. The sums are the same (in another order of additions: equal to
rounding). :func:`normal_sums` does the same for the sums of the normal equations of one
observation block (``U``, ``V``, ``g_e`` and ``W``'s per-group products). numba is optional:
both return None without it.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]
Index = NDArray[np.intp]

__all__ = ["normal_sums", "pair_sums"]


def _kernel(Za, Zb, o1, o2, key, out):  # pragma: no cover - compiled
    b = Za.shape[1]
    k1 = Za.shape[2]
    k2 = Zb.shape[2]
    acc = np.zeros((k1, k2))
    last = -1
    for q in range(o1.size):
        k = key[q]
        if k != last:  # pairs come sorted by key: one block in the accumulator at a time
            if last >= 0:
                out[last] += acc
                acc[:, :] = 0.0
            last = k
        a = o1[q]
        c = o2[q]
        for m in range(b):
            for i in range(k1):
                z = Za[a, m, i]
                for j in range(k2):
                    acc[i, j] += z * Zb[c, m, j]
    if last >= 0:
        out[last] += acc


def pair_sums(Za: Array, Zb: Array, o1: Index, o2: Index, key: Index, n_keys: int
              ) -> Array | None:  # fmt: skip
    """Per key ``sum_q Za[o1[q]]' Zb[o2[q]]`` (n_keys, kk1, kk2), or None without numba."""
    from ..compiled import compiled_kernel  # numba imported here: this module stays light

    kernel = compiled_kernel(_kernel)
    if kernel is None:
        return None
    out = np.zeros((n_keys, Za.shape[2], Zb.shape[2]))
    kernel(np.ascontiguousarray(Za), np.ascontiguousarray(Zb), o1, o2, key, out)
    return out


def _normal_kernel(abar, wbar, scale, rc, ec, sig, point, U, V, g_e, T):  # pragma: no cover
    g_n, c_n, k_n = abar.shape
    kr = rc.size
    b = ec.size
    row = np.empty(k_n)
    for g in range(g_n):
        s = sig[g]
        p = point[g]
        for c in range(c_n):
            w = wbar[g, c]
            for i in range(k_n):
                row[i] = abar[g, c, i] * scale[g, i]
            for i in range(kr):
                ri = row[rc[i]]
                for j in range(kr):
                    U[s, i, j] += ri * row[rc[j]]
                for j in range(b):
                    T[g, i, j] += ri * row[ec[j]]
            for i in range(b):
                ei = row[ec[i]]
                g_e[p, i] += w * ei
                for j in range(b):
                    V[p, i, j] += ei * row[ec[j]]


def normal_sums(abar: Array, wbar: Array, scale: Array, rc: Index, ec: Index, sig: Index,
                n_sig: int, point: Index, n_points: int) -> tuple | None:  # fmt: skip
    """For one block whose every group sees one eliminated block in slot order and whose
    reduced columns all vary between groups: ``U`` per signature (n_sig, kr, kr), ``V`` and
    ``g_e`` per eliminated block, ``T = R' E`` per group, from the whitened rows ``abar``
    scaled by ``scale`` (G, k) and the misclosures ``wbar`` (G, c); None without numba."""
    from ..compiled import compiled_kernel  # numba imported here: this module stays light

    kernel = compiled_kernel(_normal_kernel)
    if kernel is None:
        return None
    g, kr, b = abar.shape[0], rc.size, ec.size
    U = np.zeros((n_sig, kr, kr))
    V = np.zeros((n_points, b, b))
    g_e = np.zeros((n_points, b))
    T = np.zeros((g, kr, b))
    kernel(np.ascontiguousarray(abar), np.ascontiguousarray(wbar),
                 np.ascontiguousarray(scale), rc, ec, sig, point, U, V, g_e, T)  # fmt: skip
    return U, V, g_e, T
