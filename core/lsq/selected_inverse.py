"""Selected entries of the inverse of a sparse symmetric positive definite matrix, without
forming the inverse: a band Cholesky factor and Takahashi's recurrence.

Used for the cofactor matrix of a large reduced camera system (:mod:`.schur`): its statistics
need the blocks of ``S^-1`` where ``S`` itself is non-zero (each image with itself and with
the images it shares points with) and a few small dense blocks (interior orientation), never
the whole inverse (288 MB for 1,000 images, and ``n^3`` operations).

Method
------
The parameters are ordered (permutation ``perm``, positions ``pos``) so that the sparse part
``A`` of ``S`` has a small bandwidth ``w`` (reverse Cuthill-McKee of its graph), with the few
dense rows and columns (parameters coupled to a large share of all others, such as a
camera's interior orientation) last::

    P S P' = [[A, E], [E', F]]         A banded (n_B x n_B, bandwidth w), F small (g x g)

``A = L L'`` (LAPACK's band Cholesky); Takahashi, Fagan & Chen (1973): ``Z = A^-1`` satisfies
``L' Z = L^-1`` whose right side is lower triangular with diagonal ``1 / L_jj``, so, from the
last column on::

    Z_ij = -(1 / L_jj) sum_{k > j} L_kj Z_ki      (i > j, i - j <= w)
    Z_jj = 1 / L_jj^2 - (1 / L_jj) sum_{k > j} L_kj Z_kj

and every ``Z_ki`` it reads lies within the band (``j < k, i <= j + w``): the band of the
inverse, and only it, in ``n_B w^2`` operations. The dense part by its Schur complement
``H = F - E' A^-1 E`` with ``Y = A^-1 E`` (``g`` band solves)::

    S^-1 = [[Z + Y H^-1 Y', -Y H^-1], [-H^-1 Y', H^-1]]      (in the order of perm)

An entry outside the band is found by solving for its column (:meth:`BandedInverse.take`
gathers any entries; columns are solved in chunks).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.sparse.csgraph import reverse_cuthill_mckee

from .schur_plan import _Reducer

if TYPE_CHECKING:
    from .schur_plan import EliminationPlan

Array = NDArray[np.float64]
Index = NDArray[np.intp]

__all__ = ["BandedInverse", "banded_inverse", "cofactor_sums"]

# A parameter is "dense" (ordered last, outside the band) when it is coupled to more than
# this share of all parameters, and to more than _DENSE_MIN_DEGREE of them.
_DENSE_SHARE = 0.1
_DENSE_MIN_DEGREE = 200
# Columns solved at once for entries outside the band (bounds the n x k work array).
_CHUNK = 256
# Occurrences per chunk of the point sums of :func:`cofactor_sums`.
_OCC_CHUNK = 1 << 16


def _takahashi_kernel(Lt, Zt):  # pragma: no cover - compiled
    """Band of ``A^-1`` from the band Cholesky factor: ``Lt[j, d] = L[j + d, j]``,
    ``Zt[j, d] = Z[j + d, j]`` (both (n, w + 1)); Zt is written. For each column j the
    sums over k are one symmetric product of the window ``Z[j+1:j+w+1, j+1:j+w+1]`` (read
    row by row from its lower triangle, contiguously) with ``L[j+1:j+w+1, j]``."""
    n, w1 = Lt.shape
    w = w1 - 1
    z = np.zeros(w1)
    for j in range(n - 1, -1, -1):
        ljj = Lt[j, 0]
        m = min(w, n - 1 - j)
        z[: m + 1] = 0.0
        for c in range(1, m + 1):  # row k = j + c of the window: Z[k + e, k] = Zt[k, e]
            k = j + c
            lc = Lt[j, c]
            zc = lc * Zt[k, 0]
            for e in range(1, m - c + 1):
                zz = Zt[k, e]
                z[c + e] += lc * zz
                zc += Lt[j, c + e] * zz
            z[c] += zc
        s = 0.0
        for a in range(1, m + 1):
            Zt[j, a] = -z[a] / ljj
            s += Lt[j, a] * Zt[j, a]
        Zt[j, 0] = (1.0 / ljj - s) / ljj


class BandedInverse:
    """Entries of ``S^-1`` on demand (see the module docstring); built by
    :func:`banded_inverse`.

    Attributes
    ----------
    n : int
        Order of ``S``.
    bandwidth : int
        ``w`` of the sparse part in the chosen order.
    n_dense : int
        ``g``, the parameters ordered last and treated densely.
    """

    def __init__(
        self,
        perm: Index,
        n_band: int,
        band: sp.coo_matrix,
        Zt: Array,
        Y: Array,
        Hinv: Array,
        E: Array,
    ) -> None:
        self.perm = perm
        self.pos = np.empty_like(perm)
        self.pos[perm] = np.arange(perm.size)
        self.n = int(perm.size)
        self.n_band = n_band
        self.n_dense = self.n - n_band
        # the band part's lower triangle (sparse): its factor is formed again when an entry
        # outside the band is asked for (the factor is as large as Zt, kept only then)
        self._band = band
        self._Lb: Array | None = None  # LAPACK lower band form, (w + 1, n_B)
        self._Zt = Zt  # (n_B, w + 1)
        self.bandwidth = Zt.shape[1] - 1
        self._Y = Y  # (n_B, g) A^-1 E
        self._YH = Y @ Hinv  # (n_B, g)
        self._Hinv = Hinv
        self._E = E  # (n_B, g)

    def finite(self) -> bool:
        """Whether every stored number is finite."""
        return bool(
            np.isfinite(self._Zt).all()
            and np.isfinite(self._YH).all()
            and np.isfinite(self._Hinv).all()
        )

    def diagonal(self) -> Array:
        """``diag(S^-1)`` (n,)."""
        i = np.arange(self.n)
        return self.take(i, i)

    def take(self, rows: NDArray[np.integer], cols: NDArray[np.integer]) -> Array:
        """``S^-1[rows, cols]`` elementwise (broadcast index arrays, original order)."""
        qq = self.pos[np.asarray(rows, dtype=np.intp)]
        pp = self.pos[np.asarray(cols, dtype=np.intp)]
        lo = np.minimum(qq, pp)
        dd = np.abs(qq - pp)
        if not self.n_dense and (dd.size == 0 or dd.max() <= self.bandwidth):
            return self._Zt[lo, dd]  # the common case: all within the band
        r, c = np.broadcast_arrays(qq, pp)
        q, p = r.ravel(), c.ravel()
        out = np.empty(q.size)
        nb, w = self.n_band, self.bandwidth
        qb, pb = q < nb, p < nb
        bb = qb & pb
        lo, hi = np.minimum(q, p), np.maximum(q, p)
        inband = bb & (hi - lo <= w)
        out[inband] = self._Zt[lo[inband], hi[inband] - lo[inband]]
        far = bb & ~inband
        if far.any():
            out[far] = self._far(q[far], p[far])
        if self.n_dense:
            if bb.any():
                out[inband] += np.einsum("ij,ij->i", self._YH[q[inband]], self._Y[p[inband]])
            s = qb & ~pb
            out[s] = -self._YH[q[s], p[s] - nb]
            s = ~qb & pb
            out[s] = -self._YH[p[s], q[s] - nb]
            s = ~qb & ~pb
            out[s] = self._Hinv[q[s] - nb, p[s] - nb]
        return out.reshape(r.shape)

    def _far(self, q: Index, p: Index) -> Array:
        """Entries (permuted positions, both in the band part, outside the band) by solving
        for their columns (the dense part's term included)."""
        cols, where = np.unique(p, return_inverse=True)
        out = np.empty(q.size)
        for start in range(0, cols.size, _CHUNK):
            cc = cols[start : start + _CHUNK]
            X = self._columns(cc)  # (n, k), permuted rows
            sel = (where >= start) & (where < start + cc.size)
            out[sel] = X[q[sel], where[sel] - start]
        return out

    def _columns(self, cc: Index) -> Array:
        """Columns ``cc`` (permuted positions in the band part) of ``P S^-1 P'``, (n, k)."""
        nb = self.n_band
        rhs = np.zeros((nb, cc.size))
        rhs[cc, np.arange(cc.size)] = 1.0
        if self._Lb is None:
            self._Lb = _band_factor(self._band, self.bandwidth)
        yb = sla.cho_solve_banded((self._Lb, True), rhs, check_finite=False)
        if not self.n_dense:
            return yb
        xg = -self._Hinv @ (self._E.T @ yb)
        return np.vstack([yb - self._Y @ xg, xg])


def _band_factor(band: sp.coo_matrix, w: int) -> Array:
    """LAPACK's band Cholesky factor (lower band form, (w + 1, n)) of the symmetric matrix
    whose lower triangle is ``band`` (bandwidth w).

    Raises
    ------
    numpy.linalg.LinAlgError
        When the matrix is not positive definite.
    """
    n = band.shape[0]
    ab = np.zeros((w + 1, n))
    ab[band.row - band.col, band.col] = band.data
    return sla.cholesky_banded(ab, lower=True, check_finite=False) if n else ab


def _order(S: sp.csr_matrix) -> tuple[Index, int]:
    """(perm, n_B): the sparse parameters in reverse Cuthill-McKee order, then the dense."""
    n = S.shape[0]
    deg = np.diff(S.indptr)
    dense = (deg > _DENSE_SHARE * n) & (deg > _DENSE_MIN_DEGREE)
    sparse_idx = np.flatnonzero(~dense)
    sub = S[sparse_idx][:, sparse_idx].tocsr()
    rcm = reverse_cuthill_mckee(sub, symmetric_mode=True) if sparse_idx.size else sparse_idx
    perm = np.concatenate([sparse_idx[rcm], np.flatnonzero(dense)]).astype(np.intp)
    return perm, int(sparse_idx.size)


def banded_inverse(S: sp.spmatrix) -> BandedInverse | None:
    """The :class:`BandedInverse` of the symmetric positive definite ``S`` (n x n, sparse;
    both triangles stored), or None without numba (the recurrence is compiled).

    Raises
    ------
    numpy.linalg.LinAlgError
        When ``S`` (or its dense part's Schur complement) is not positive definite.
    """
    from ..compiled import compiled_kernel  # numba imported here: this module stays light

    kernel = compiled_kernel(_takahashi_kernel)
    if kernel is None:
        return None
    S = sp.csr_matrix(S)
    S.eliminate_zeros()
    perm, nb = _order(S)
    P = S[perm][:, perm].tocoo()
    i, j, v = P.row, P.col, P.data
    low = (i >= j) & (i < nb)
    w = int((i[low] - j[low]).max()) if low.any() else 0
    band = sp.coo_matrix((v[low], (i[low], j[low])), shape=(nb, nb))
    Lb = _band_factor(band, w)
    g = S.shape[0] - nb
    E = np.zeros((nb, g))
    F = np.zeros((g, g))
    eb = (i < nb) & (j >= nb)
    E[i[eb], j[eb] - nb] = v[eb]
    fg = (i >= nb) & (j >= nb)
    F[i[fg] - nb, j[fg] - nb] = v[fg]
    if g:
        Y = sla.cho_solve_banded((Lb, True), E, check_finite=False) if nb else E
        H = F - E.T @ Y
        cf = sla.cho_factor(0.5 * (H + H.T), lower=True, check_finite=False)
        Hinv = sla.cho_solve(cf, np.eye(g), check_finite=False)
        Hinv = 0.5 * (Hinv + Hinv.T)
    else:
        Y, Hinv = np.zeros((nb, 0)), np.zeros((0, 0))
    Lt = np.ascontiguousarray(Lb.T)
    Zt = np.zeros_like(Lt)
    del Lb
    kernel(Lt, Zt)
    del Lt
    return BandedInverse(perm, nb, band, Zt, Y, Hinv, E)


def _add_sums(out: Array, by: Index, n: int, Mk: Array, keys: Index, T: Array, o: Index) -> None:
    """``out[by[i]] += Mk[keys[i]] @ T[o[i]]`` summed over the items i of each ``by`` value,
    chunk by chunk (the order and grouping of ``_Reducer.sum``, added straight into ``out``:
    no array of all the sums is formed; the reducer is dropped after)."""
    red = _Reducer(by, n)
    ends = np.r_[red.starts[1:], red.n_items] if red.starts.size else red.starts
    for a, b in zip(red.bounds[:-1], red.bounds[1:]):
        lo, hi = int(red.starts[a]), int(ends[b - 1])
        it = red.order[lo:hi]
        vals = Mk[keys[it]] @ T[o[it]]
        out[red.keys[a:b]] += np.add.reduceat(vals, red.starts[a:b] - lo, axis=0)


def cofactor_sums(
    plan: EliminationPlan,
    T: Sequence[Array],
    Vinv: Array,
    take: Callable[[Index, Index], Array],
) -> tuple[Array, list[Array]]:
    """(inner, cross): the sums of the eliminated blocks' cofactors (:meth:`.schur.
    ReducedNormal.cofactor`), with ``M`` the inverse reduced matrix (its entries from
    ``take``, scaled variables) and ``T_o`` (kk, b) the reduced-eliminated products of each
    occurrence ``o``::

        A_o = sum_{o' at the block of o} M[rows_o, rows_o'] T_o'          (kk, b)
        inner_p = sum_{o at p} T_o' A_o,    cross_o = -A_o Vinv_p          (b, b), (kk, b)

    so that ``Q_pp = Vinv_p + Vinv_p inner_p Vinv_p`` and ``Q_rp = cross``. The blocks of
    ``M`` are taken once per pair of signatures (e.g. of images), not per pair of
    occurrences; ``A`` is summed in place and turned into ``cross`` chunk by chunk, so one
    array of the size of ``T`` is formed (the peak memory of a large block's covariance), and
    the sums by occurrence are planned here and dropped after (not kept with the plan).
    """
    acc = [np.zeros_like(t) for t in T]
    for pl in plan.pairs:
        a, b = plan.sets[pl.s1], plan.sets[pl.s2]
        r1, r2 = a.rows[pl.key_sig1], b.rows[pl.key_sig2]
        keys = pl.key_reducer.item_keys
        Mf = take(r1[:, :, None], r2[:, None, :])  # (n_keys, kk1, kk2)
        _add_sums(acc[pl.s1], pl.o1, pl.n1, Mf, keys, T[pl.s2], pl.o2)
        if pl.mirror:  # the reverse pairs (o2, o1): the transposed blocks
            Mb = take(r2[:, :, None], r1[:, None, :])
            _add_sums(acc[pl.s2], pl.o2, pl.n2, Mb, keys, T[pl.s1], pl.o1)
    P, b = plan.P, plan.b
    inner = np.zeros((P, b, b))
    flat = np.arange(b * b)
    for t, A, s in zip(T, acc, plan.sets):
        part = np.zeros(P * b * b)  # summed in the occurrences' order, as bincount does
        for lo in range(0, t.shape[0], _OCC_CHUNK):
            sl = slice(lo, lo + _OCC_CHUNK)
            pt = s.point[sl]
            contrib = np.swapaxes(t[sl], 1, 2) @ A[sl]  # (c, b, b)
            np.add.at(part, (pt[:, None] * (b * b) + flat).ravel(), contrib.ravel())
            A[sl] = -(A[sl] @ Vinv[pt])
        inner += part.reshape(P, b, b)
    return inner, acc
