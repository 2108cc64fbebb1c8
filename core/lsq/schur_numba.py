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


def pair_sums(Za: Array, Zb: Array, o1: Index, o2: Index, key: Index, n_keys: int) -> Array | None:
    """Per key ``sum_q Za[o1[q]]' Zb[o2[q]]`` (n_keys, kk1, kk2), or None without numba."""
    from ..compiled import compiled_kernel  # numba imported here: this module stays light

    kernel = compiled_kernel(_kernel)
    if kernel is None:
        return None
    out = np.zeros((n_keys, Za.shape[2], Zb.shape[2]))
    kernel(np.ascontiguousarray(Za), np.ascontiguousarray(Zb), o1, o2, key, out)
    return out


def _normal_kernel(abar, wbar, scale, rc, ec, sig, point, U, V, g_e, T):  # pragma: no cover
    g_n, c_n = abar.shape[0], abar.shape[1]
    kr = rc.size
    b = ec.size
    rr = np.empty(kr)  # the scaled row's reduced and eliminated parts, contiguous
    er = np.empty(b)
    for g in range(g_n):
        s = sig[g]
        p = point[g]
        for c in range(c_n):
            w = wbar[g, c]
            for i in range(kr):
                rr[i] = abar[g, c, rc[i]] * scale[g, rc[i]]
            for i in range(b):
                er[i] = abar[g, c, ec[i]] * scale[g, ec[i]]
            for i in range(kr):
                ri = rr[i]
                for j in range(i, kr):  # the upper triangle (mirrored afterwards)
                    U[s, i, j] += ri * rr[j]
                for j in range(b):
                    T[g, i, j] += ri * er[j]
            for i in range(b):
                ei = er[i]
                g_e[p, i] += w * ei
                for j in range(i, b):
                    V[p, i, j] += ei * er[j]


def normal_sums(
    abar: Array,
    wbar: Array,
    scale: Array,
    rc: Index,
    ec: Index,
    sig: Index,
    n_sig: int,
    point: Index,
    n_points: int,
) -> tuple | None:
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
    kernel(
        np.ascontiguousarray(abar),
        np.ascontiguousarray(wbar),
        np.ascontiguousarray(scale),
        rc,
        ec,
        sig,
        point,
        U,
        V,
        g_e,
        T,
    )
    U += np.swapaxes(np.triu(U, 1), 1, 2)
    V += np.swapaxes(np.triu(V, 1), 1, 2)
    return U, V, g_e, T


def _inverse_factor(V, p, lam, L, Li):  # pragma: no cover - compiled
    """``Li[p]``: the inverse of the lower Cholesky factor ``L`` of ``V[p] + lam I`` (``L``
    a b x b work array); False when that block is not positive definite. Shared by the
    kernels below (``compiled_kernel(..., helpers=(_inverse_factor,))``)."""
    b = V.shape[1]
    for i in range(b):
        for j in range(i + 1):
            s = V[p, i, j] + (lam if i == j else 0.0)
            for m in range(j):
                s -= L[i, m] * L[j, m]
            if i == j:
                if not s > 0.0:
                    return False
                L[i, i] = np.sqrt(s)
            else:
                L[i, j] = s / L[j, j]
    for j in range(b):
        for i in range(b):
            if i < j:
                Li[p, i, j] = 0.0
                continue
            s = 1.0 if i == j else 0.0
            for m in range(j, i):
                s -= L[i, m] * Li[p, m, j]
            Li[p, i, j] = s / L[i, i]
    return True


def _dense_kernel(
    V, lam, g_e, T, order, start, osig, srows, base, K, rhs, Li, y
):  # pragma: no cover - compiled
    P, b = V.shape[0], V.shape[1]
    kk = T.shape[1]
    most = 0
    for p in range(P):
        most = max(most, start[p + 1] - start[p])
    Z = np.empty((most, b, kk))
    acc = np.empty((kk, kk))
    L = np.empty((b, b))
    t = np.empty(b)
    for p in range(P):
        # the inverse Cholesky factor of V_p + lam I (lower triangular)
        if not _inverse_factor(V, p, lam, L, Li):
            return 1
        # y_p = (V_p + lam I)^-1 g_e,p = Li' Li g_e,p
        for i in range(b):
            s = 0.0
            for m in range(i + 1):
                s += Li[p, i, m] * g_e[p, m]
            t[i] = s
        for i in range(b):
            s = 0.0
            for m in range(i, b):
                s += Li[p, m, i] * t[m]
            y[p, i] = s
        n_o = start[p + 1] - start[p]
        for q in range(n_o):
            o = order[start[p] + q]
            rows = srows[osig[o]]
            for a in range(kk):
                s = 0.0
                for m in range(b):
                    s += T[o, a, m] * y[p, m]
                rhs[rows[a]] += s
            # Z = Li T' (b x kk)
            for m in range(b):
                for a in range(kk):
                    s = 0.0
                    for c in range(m + 1):
                        s += Li[p, m, c] * T[o, a, c]
                    Z[q, m, a] = s
        # the pair products -Z_i' Z_j at (rows_i, rows_j) for i <= j, the pairs i == j at
        # half weight: K + K' is then the full sum
        for qi in range(n_o):
            si = osig[order[start[p] + qi]]
            for qj in range(qi, n_o):
                sj = osig[order[start[p] + qj]]
                w = -0.5 if qi == qj else -1.0
                if b == 3 and base[si] >= 0 and base[sj] >= 0:
                    # points with contiguous rows: one row of K at a time
                    bj = base[sj]
                    for a in range(kk):
                        z0, z1, z2 = w * Z[qi, 0, a], w * Z[qi, 1, a], w * Z[qi, 2, a]
                        row = K[base[si] + a]
                        if qi == qj:  # a symmetric block: its upper triangle, doubled
                            z0, z1, z2 = 2.0 * z0, 2.0 * z1, 2.0 * z2
                            row[bj + a] += 0.5 * (
                                z0 * Z[qj, 0, a] + z1 * Z[qj, 1, a] + z2 * Z[qj, 2, a]
                            )
                            for c in range(a + 1, kk):
                                row[bj + c] += (
                                    z0 * Z[qj, 0, c] + z1 * Z[qj, 1, c] + z2 * Z[qj, 2, c]
                                )
                            continue
                        for c in range(kk):
                            row[bj + c] += z0 * Z[qj, 0, c] + z1 * Z[qj, 1, c] + z2 * Z[qj, 2, c]
                    continue
                ri, rj = srows[si], srows[sj]
                acc[:, :] = 0.0
                for m in range(b):
                    for a in range(kk):
                        z = Z[qi, m, a]
                        for c in range(kk):
                            acc[a, c] += z * Z[qj, m, c]
                for a in range(kk):
                    r = ri[a]
                    for c in range(kk):
                        K[r, rj[c]] += w * acc[a, c]
    return 0


def dense_reduced(
    V: Array,
    lam: float,
    g_e: Array,
    T: Array,
    order: Index,
    start: Index,
    osig: Index,
    srows: Index,
    K: Array,
    rhs: Array,
) -> tuple | None:
    """For one occurrence set, in place and point by point (``order``/``start``: the
    occurrences sorted by point, CSR-like): afterwards ``K + K'`` is
    ``-sum_p W_p (V_p + lam I)^-1 W_p'`` (``K`` dense, zero on entry), and
    ``sum_p W_p (V_p + lam I)^-1 g_e,p`` is added to ``rhs``.
    Returns (Li, y): the inverse Cholesky factors of ``V_p + lam I`` (P, b, b) and
    ``(V_p + lam I)^-1 g_e,p`` (P, b); raises SingularSystem's cause as ValueError when a
    point block is not positive definite; None without numba."""
    from ..compiled import compiled_kernel

    kernel = compiled_kernel(_dense_kernel, helpers=(_inverse_factor,))
    if kernel is None:
        return None
    P, b = V.shape[0], V.shape[1]
    Li = np.empty((P, b, b))
    y = np.empty((P, b))
    # the first row of every signature whose rows are one contiguous run, else -1
    kk = srows.shape[1]
    run = (srows == srows[:, :1] + np.arange(kk)).all(axis=1)
    base = np.where(run, srows[:, 0], -1).astype(np.intp)
    bad = kernel(
        np.ascontiguousarray(V),
        float(lam),
        np.ascontiguousarray(g_e),
        np.ascontiguousarray(T),
        order,
        start,
        osig,
        srows,
        base,
        K,
        rhs,
        Li,
        y,
    )
    if bad:
        raise ValueError("an eliminated block is singular")
    return Li, y


def _back_kernel(g_e, T, point, osig, srows, z, Li, ze):  # pragma: no cover - compiled
    P, b = g_e.shape
    kk = T.shape[1]
    acc = np.empty((P, b))
    for p in range(P):
        for m in range(b):
            acc[p, m] = -g_e[p, m]
    for o in range(point.size):
        p = point[o]
        rows = srows[osig[o]]
        for m in range(b):
            s = 0.0
            for a in range(kk):
                s += T[o, a, m] * z[rows[a]]
            acc[p, m] -= s
    t = np.empty(b)
    for p in range(P):
        for i in range(b):
            s = 0.0
            for m in range(i + 1):
                s += Li[p, i, m] * acc[p, m]
            t[i] = s
        for i in range(b):
            s = 0.0
            for m in range(i, b):
                s += Li[p, m, i] * t[m]
            ze[p, i] = s


def back_substitute(
    g_e: Array, T: Array, point: Index, osig: Index, srows: Index, z: Array, Li: Array
) -> Array | None:
    """``z_e,p = (V_p + lam I)^-1 (-g_e,p - W_p' z_r)`` for one occurrence set, with ``Li`` of
    :func:`dense_reduced`; (P, b), or None without numba."""
    from ..compiled import compiled_kernel

    kernel = compiled_kernel(_back_kernel)
    if kernel is None:
        return None
    ze = np.empty(g_e.shape)
    kernel(
        np.ascontiguousarray(g_e),
        np.ascontiguousarray(T),
        point,
        osig,
        srows,
        np.ascontiguousarray(z),
        Li,
        ze,
    )
    return ze


def _diag_grad_kernel(abar, wbar, active, index, diag, grad):  # pragma: no cover - compiled
    g_n, c_n, k_n = abar.shape
    for g in range(g_n):
        if not active[g]:
            continue
        for k in range(k_n):
            d = 0.0
            s = 0.0
            for c in range(c_n):
                a = abar[g, c, k]
                d += a * a
                s += wbar[g, c] * a
            diag[index[g, k]] += d
            grad[index[g, k]] += s


def diag_grad(
    abar: Array, wbar: Array, active: NDArray[np.bool_], index: Index, diag: Array, grad: Array
) -> bool:
    """Add the diagonal ``sum a^2`` and the gradient ``sum w a`` of the normal equations of
    one block's active groups (``abar`` (G, c, k) at the parameters ``index`` (G, k)) to
    ``diag`` and ``grad`` in place; False without numba (nothing added)."""
    from ..compiled import compiled_kernel

    kernel = compiled_kernel(_diag_grad_kernel)
    if kernel is None:
        return False
    kernel(
        np.ascontiguousarray(abar),
        np.ascontiguousarray(wbar),
        np.ascontiguousarray(active),
        np.ascontiguousarray(index),
        diag,
        grad,
    )
    return True


# ----------------------------------------------------------------------------- point blocks
# The per-occurrence products of the sparse path of ReducedNormal (numpy: batched products
# of 3 x 3 by 3 x 6 matrices, each a temporary of all occurrences).


def _factors_kernel(V, lam, Li, Vinv):  # pragma: no cover - compiled
    P, b = V.shape[0], V.shape[1]
    L = np.empty((b, b))
    for p in range(P):
        if not _inverse_factor(V, p, lam, L, Li):
            return p + 1
        for i in range(b):  # Vinv = Li' Li
            for j in range(b):
                s = 0.0
                for m in range(max(i, j), b):
                    s += Li[p, m, i] * Li[p, m, j]
                Vinv[p, i, j] = s
    return 0


def point_factors(V: Array, lam: float) -> tuple[Array, Array] | int | None:
    """(Li, Vinv): the inverse lower Cholesky factors and the inverses of ``V_p + lam I``
    (P, b, b); the 1-based index of the first block that is not positive definite (an int)
    instead; None without numba."""
    from ..compiled import compiled_kernel

    kernel = compiled_kernel(_factors_kernel, helpers=(_inverse_factor,))
    if kernel is None:
        return None
    Li = np.empty_like(V)
    Vinv = np.empty_like(V)
    bad = kernel(np.ascontiguousarray(V), float(lam), Li, Vinv)
    return int(bad) if bad else (Li, Vinv)


def _products_kernel(Li, point, T, Z):  # pragma: no cover - compiled
    b = Li.shape[1]
    kk = T.shape[1]
    for o in range(T.shape[0]):
        p = point[o]
        for m in range(b):
            for a in range(kk):
                s = 0.0
                for c in range(b):
                    s += Li[p, m, c] * T[o, a, c]
                Z[o, m, a] = s


def point_products(Li: Array, point: Index, T: Array) -> Array | None:
    """``Z_o = Li[point[o]] T_o'`` (O, b, kk) per occurrence; None without numba."""
    from ..compiled import compiled_kernel

    kernel = compiled_kernel(_products_kernel)
    if kernel is None:
        return None
    Z = np.empty((T.shape[0], Li.shape[1], T.shape[1]))
    kernel(np.ascontiguousarray(Li), point, np.ascontiguousarray(T), Z)
    return Z


def _rhs_kernel(T, y, point, rows, sig, acc):  # pragma: no cover - compiled
    b = y.shape[1]
    kk = T.shape[1]
    for o in range(T.shape[0]):
        p = point[o]
        r = sig[o]
        for a in range(kk):
            s = 0.0
            for m in range(b):
                s += T[o, a, m] * y[p, m]
            acc[rows[r, a]] += s


def add_point_rhs(T: Array, y: Array, point: Index, rows: Index, sig: Index, rhs: Array) -> bool:
    """``rhs[rows[sig[o]]] += T_o y[point[o]]`` over the occurrences (summed apart, then
    added, as numpy's ``bincount``); False without numba (nothing added)."""
    from ..compiled import compiled_kernel

    kernel = compiled_kernel(_rhs_kernel)
    if kernel is None:
        return False
    acc = np.zeros_like(rhs)
    kernel(np.ascontiguousarray(T), np.ascontiguousarray(y), point,
           np.ascontiguousarray(rows), sig, acc)  # fmt: skip
    rhs += acc
    return True


def _back_sums_kernel(sol, rows, sig, T, point, acc):  # pragma: no cover - compiled
    kk = T.shape[1]
    b = T.shape[2]
    for o in range(T.shape[0]):
        r = sig[o]
        p = point[o]
        for j in range(b):
            s = 0.0
            for a in range(kk):
                s += sol[rows[r, a]] * T[o, a, j]
            acc[p, j] += s


def point_back_sums(sol: Array, rows: Index, sig: Index, T: Array, point: Index, P: int):
    """``sum_o T_o' sol[rows[sig[o]]]`` per point (P, b); None without numba."""
    from ..compiled import compiled_kernel

    kernel = compiled_kernel(_back_sums_kernel)
    if kernel is None:
        return None
    acc = np.zeros((P, T.shape[2]))
    kernel(np.ascontiguousarray(sol), np.ascontiguousarray(rows), sig,
           np.ascontiguousarray(T), point, acc)  # fmt: skip
    return acc
