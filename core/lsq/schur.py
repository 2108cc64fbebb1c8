"""Reduced normal equations: small independent parameter blocks eliminated by the Schur complement.

Used by :func:`~lidarphoto.core.lsq.adjustment.adjust` when
:attr:`~lidarphoto.core.lsq.model.AdjustmentOptions.eliminate` names ``P`` blocks of ``b``
parameters (the object points of a bundle adjustment, ``b = 3``). Every observation group may
depend on at most one of these blocks, so that the normal matrix, ordered as (reduced
parameters r, eliminated parameters e), is::

    N = [[U, W], [W', V]]       V = diag(V_1, ..., V_P), each V_p of size b x b

and the eliminated parameters leave the reduced system (the reduced camera system of a bundle
adjustment; Brown 1976, Triggs et al. 2000)::

    S = U - W V^-1 W',   S z_r = -n_r + W V^-1 n_e,   z_e = V^-1 (-n_e - W' z_r).

Hard constraints ``C z = -h`` are carried as extra rows of the reduced system: with the
augmented ``U+ = [[U, C_r'], [C_r, 0]]`` and ``W+_p = [W_p; C_e,p]`` the reduced (bordered)
matrix is ``U+ - sum_p W+_p V_p^-1 W+_p'``, which also covers constraints on eliminated
parameters (inner constraints on object points).

Assembly never forms the design matrix: per linearisation the whitened, Jacobi-scaled rows of
each group are split into their reduced part ``R_g`` and eliminated part ``E_g``; ``U`` is
summed per *signature* (groups with the same reduced columns, e.g. one image), ``V_p`` per
block, and ``W V^-1 W'`` from pairs of *occurrences* of the same block: an occurrence is a group
(its columns that vary from group to group, e.g. the exterior orientation) or, for the columns
shared by every group of an observation block (e.g. the interior orientation of its camera),
the sum over the block's groups at one point, so that shared columns cost one product per
point instead of one per pair of rays. Every sum is a sorted segment reduction in bounded
chunks.

The cofactor matrix is returned in blocks (:class:`BlockCofactor`): ``Q_rr`` of the reduced
parameters in full, ``Q_pp`` (b x b) of every eliminated block, and, for the standardised
residuals of each group, the cross block ``Q_rp = -M W+_p V_p^-1`` restricted to the group's
columns (``M`` the inverse of the reduced bordered matrix).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from . import schur_numba as _nb
from .scaling import jacobi_scale, scale_constraints
from .schur_numba import back_substitute, dense_reduced, diag_grad, normal_sums, pair_sums
from .schur_plan import EliminationPlan
from .selected_inverse import banded_inverse, cofactor_sums

Array = NDArray[np.float64]
Index = NDArray[np.intp]

__all__ = ["BlockCofactor", "ReducedNormal", "SingularSystem"]

# Reduced systems up to this size are solved densely (Cholesky / LU); above, sparse LU when
# the reduced matrix is sparse enough.
_DENSE_MAX = 2500
_SPARSE_MAX_DENSITY = 0.1
# The compiled sums of the reduced system (numba, when it imports); False: numpy only. They
# run from _COMPILED_MIN items (pairs, or groups of a block) on: below, numpy is as fast and
# numba's import and cache load (about a second) would not pay.
_COMPILED = True
_COMPILED_MIN = 20000
# From this many reduced parameters on (and without constraints), the cofactor matrix takes
# the entries of the inverse reduced matrix it needs from a band Cholesky factor
# (:mod:`.selected_inverse`) instead of the whole dense inverse.
_SELECTED_MIN = _DENSE_MAX
# Occurrences per chunk of the point-factor products of :meth:`ReducedNormal.reduced_matrix`.
_CHUNK = 65536


class SingularSystem(Exception):
    """A factorisation failed or gave non-finite numbers."""


@dataclass
class ReducedNormal:
    """Jacobi-scaled normal equations of one linearisation, in reduced form.

    ``d`` is the Jacobi scale of all ``n`` parameters (as for the full normal equations);
    everything else is in the scaled variables ``z = D dx``.
    """

    plan: EliminationPlan
    d: Array  # (n,)
    ns: Array  # (n,) scaled gradient A' w (for the step-length test only)
    u_rows: Index  # COO of U+ (reduced block and constraint borders)
    u_cols: Index
    u_vals: Array
    g_r: Array  # (n_r,) reduced gradient
    V: Array  # (P, b, b)
    g_e: Array  # (P, b)
    T: list[Array]  # per occurrence set (O, kk, b)
    hs: Array  # (mc,) scaled constraint values
    mc: int
    dead: NDArray[np.bool_] | None = None  # (P,) blocks without any active observation
    use_sparse: bool = False
    _cache: dict = field(default_factory=dict)

    @property
    def n_red(self) -> int:
        return self.plan.n_r + self.mc

    # -- factorising the point blocks ------------------------------------------------------

    def point_factors(self, lam: float) -> tuple[Array, Array]:
        """(Li, Vinv): inverse Cholesky factors and inverses of ``V_p + lam I``."""
        key = ("vf", lam)
        if key in self._cache:
            return self._cache[key]
        b = self.plan.b
        got = _nb.point_factors(self.V, lam) if _COMPILED and self.plan.P >= _COMPILED_MIN else None
        if isinstance(got, int):
            raise SingularSystem("an eliminated block is singular")
        if got is not None and np.isfinite(got[0]).all() and np.isfinite(got[1]).all():
            self._cache[key] = got
            return got
        Vl = self.V + lam * np.eye(b)
        try:
            L = np.linalg.cholesky(Vl)
        except np.linalg.LinAlgError:
            raise SingularSystem("an eliminated block is singular") from None
        eye = np.broadcast_to(np.eye(b), L.shape)
        Li = np.linalg.solve(L, eye)
        Vinv = np.swapaxes(Li, 1, 2) @ Li
        if not (np.isfinite(Li).all() and np.isfinite(Vinv).all()):
            raise SingularSystem("an eliminated block is singular")
        self._cache[key] = (Li, Vinv)
        return Li, Vinv

    def point_conditions(self) -> Array:
        """Condition number of each Jacobi-scaled point block ``V_p`` (inf when singular)."""
        dg = np.sqrt(np.clip(np.einsum("pii->pi", self.V), 0.0, None))
        dg = np.where(dg > 0, dg, 1.0)
        Vs = self.V / (dg[:, :, None] * dg[:, None, :])
        ev = np.linalg.eigvalsh(Vs)
        with np.errstate(divide="ignore", invalid="ignore"):
            cond = np.where(ev[:, 0] > 0, ev[:, -1] / ev[:, 0], np.inf)
        if self.dead is not None:
            cond[self.dead] = 1.0  # set aside, not adjusted
        return cond

    # -- the reduced system ----------------------------------------------------------------

    def reduced_matrix(self, lam: float) -> sp.csr_matrix:
        """``U+ + lam I_r - sum_p W+_p (V_p + lam I)^-1 W+_p'`` (sparse, symmetric)."""
        key = ("K", lam)
        if key in self._cache:
            return self._cache[key]
        plan = self.plan
        Li, _ = self.point_factors(lam)
        # Z' = Li T' per occurrence, (O, b, kk): rows stack without copies in sum_outer
        Z = [_point_products(Li, s.point, T) for T, s in zip(self.T, plan.sets)]
        rows = [self.u_rows, np.arange(plan.n_r)]
        cols = [self.u_cols, np.arange(plan.n_r)]
        vals = [self.u_vals, np.full(plan.n_r, lam)]
        for pl in plan.pairs:
            a, b = plan.sets[pl.s1], plan.sets[pl.s2]
            Za, Zb = Z[pl.s1], Z[pl.s2]
            o1, o2 = pl.o1, pl.o2
            kk1, kk2 = a.rows.shape[1], b.rows.shape[1]

            kr = pl.key_reducer
            big = _COMPILED and o1.size >= _COMPILED_MIN
            blocks = pair_sums(Za, Zb, o1, o2, kr.item_keys, kr.n_keys) if big else None
            if blocks is None:
                blocks = kr.sum_outer(
                    lambda it, Za=Za, o1=o1: Za[o1[it]],
                    lambda it, Zb=Zb, o2=o2: Zb[o2[it]],
                    kk1,
                    kk2,
                )
            r1 = a.rows[pl.key_sig1]
            r2 = b.rows[pl.key_sig2]
            rr = np.broadcast_to(r1[:, :, None], blocks.shape).ravel()
            cc = np.broadcast_to(r2[:, None, :], blocks.shape).ravel()
            rows.append(rr)
            cols.append(cc)
            vals.append(-blocks.ravel())
            if pl.mirror:
                rows.append(cc)
                cols.append(rr)
                vals.append(-blocks.ravel())
        n = self.n_red
        K = sp.coo_matrix(
            (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)
        ).tocsr()
        K.sum_duplicates()
        self._cache[key] = K
        return K

    def reduced_rhs(self, lam: float) -> Array:
        """``[-g_r; -h] + sum_p W+_p (V_p + lam I)^-1 g_e,p``."""
        _, Vinv = self.point_factors(lam)
        y = np.einsum("pij,pj->pi", Vinv, self.g_e)
        rhs = np.concatenate([-self.g_r, -self.hs])
        for T, s in zip(self.T, self.plan.sets):
            if (
                _COMPILED
                and s.point.size >= _COMPILED_MIN
                and _nb.add_point_rhs(T, y, s.point, s.rows, s.sig, rhs)
            ):
                continue
            contrib = (T @ y[s.point][:, :, None])[:, :, 0]
            rows = s.rows[s.sig]
            rhs += np.bincount(rows.ravel(), weights=contrib.ravel(), minlength=rhs.size)
        return rhs

    def _fused(self) -> bool:
        """Whether :meth:`solve` runs the compiled dense path (:meth:`_dense_system`): one
        occurrence set (e.g. one image block, every camera with its own parameters), a dense
        reduced system, and enough pairs for the compiled code to pay."""
        plan = self.plan
        return bool(
            _COMPILED
            and not self.use_sparse
            and len(plan.sets) == 1
            and sum(pl.o1.size for pl in plan.pairs) >= _COMPILED_MIN
        )

    def _dense_system(self, lam: float) -> tuple[Array, Array, Array] | None:
        """(K, rhs, Li): the dense reduced matrix and right-hand side of :meth:`reduced_matrix`
        and :meth:`reduced_rhs`, built point by point in one compiled pass, and the inverse
        Cholesky factors of ``V_p + lam I``; None without numba."""
        key = ("D", lam)
        if key in self._cache:
            return self._cache[key]
        plan = self.plan
        s = plan.sets[0]
        order, start = s.by_point(plan.P)
        n = self.n_red
        K = np.zeros((n, n))
        rhs = np.concatenate([-self.g_r, -self.hs])
        try:
            out = dense_reduced(
                self.V, lam, self.g_e, self.T[0], order, start, s.sig, s.rows, K, rhs
            )
        except ValueError:
            raise SingularSystem("an eliminated block is singular") from None
        if out is None:
            return None
        K += K.T
        np.add.at(K, (self.u_rows, self.u_cols), self.u_vals)
        K[np.arange(plan.n_r), np.arange(plan.n_r)] += lam
        if lam == 0.0:
            # kept: the observability check and the Gauss-Newton step share it
            self._cache[key] = (K, rhs, out[0])
        return K, rhs, out[0]

    def solve(self, lam: float) -> tuple[Array, Array]:
        """Scaled step ``z`` (n,) and multipliers ``k`` (mc,) of the damped system."""
        dense = self._dense_system(lam) if self._fused() else None
        if dense is not None:
            return self._solve_dense(*dense)
        plan = self.plan
        K = self.reduced_matrix(lam)
        rhs = self.reduced_rhs(lam)
        n_r, mc = plan.n_r, self.mc
        try:
            if self.use_sparse:
                lu = spla.splu(
                    K.tocsc(),
                    permc_spec="MMD_AT_PLUS_A",
                    diag_pivot_thresh=0.0 if mc == 0 else 1.0,
                    options={"SymmetricMode": mc == 0},
                )
                sol = lu.solve(rhs)
            else:
                Kd = K.toarray()
                if mc == 0:
                    cf = sla.cho_factor(Kd, lower=True, check_finite=False)
                    sol = sla.cho_solve(cf, rhs, check_finite=False)
                else:
                    sol = sla.solve(Kd, rhs, assume_a="sym", check_finite=False)
        except (RuntimeError, np.linalg.LinAlgError, ValueError) as exc:
            raise SingularSystem(str(exc)) from None
        if not np.isfinite(sol).all():
            raise SingularSystem("non-finite solution")
        zr, k = sol[:n_r], sol[n_r:]
        _, Vinv = self.point_factors(lam)
        acc = -self.g_e.copy()
        for T, s in zip(self.T, plan.sets):
            big = _COMPILED and s.point.size >= _COMPILED_MIN
            sums = _nb.point_back_sums(sol, s.rows, s.sig, T, s.point, plan.P) if big else None
            if sums is not None:
                acc -= sums
                continue
            zs = sol[s.rows[s.sig]]  # (O, kk)
            contrib = (zs[:, None, :] @ T)[:, 0, :]
            for j in range(plan.b):
                acc[:, j] -= np.bincount(s.point, weights=contrib[:, j], minlength=plan.P)
        ze = np.einsum("pij,pj->pi", Vinv, acc)
        return self._step(zr, ze, k)

    def _step(self, zr: Array, ze: Array, k: Array) -> tuple[Array, Array]:
        """The scaled step of all ``n`` parameters from its reduced and eliminated parts."""
        plan = self.plan
        z = np.empty(plan.n)
        z[plan.reduced] = zr
        z[plan.elim.ravel()] = ze.ravel()
        if not np.isfinite(z).all():
            raise SingularSystem("non-finite solution")
        return z, k

    def _solve_dense(self, K: Array, rhs: Array, Li: Array) -> tuple[Array, Array]:
        """:meth:`solve` on the system of :meth:`_dense_system`."""
        plan = self.plan
        n_r = plan.n_r
        try:
            if self.mc == 0:
                cf = sla.cho_factor(K, lower=True, check_finite=False)
                sol = sla.cho_solve(cf, rhs, check_finite=False)
            else:
                # the border C (no constraint on eliminated blocks here): (S + C'C) is
                # positive definite when the constrained problem is determined, and the
                # multipliers follow from the small Schur complement C (S + C'C)^-1 C'
                S, C = K[:n_r, :n_r], K[n_r:, :n_r]
                r1, r2 = rhs[:n_r], rhs[n_r:]
                cf = sla.cho_factor(S + C.T @ C, lower=True, check_finite=False)
                Y = sla.cho_solve(cf, C.T, check_finite=False)
                zr = sla.cho_solve(cf, r1 + C.T @ r2, check_finite=False)
                k = sla.solve(C @ Y, C @ zr - r2, assume_a="pos", check_finite=False)
                sol = np.concatenate([zr - Y @ k, k])
        except (np.linalg.LinAlgError, ValueError) as exc:
            raise SingularSystem(str(exc)) from None
        if not np.isfinite(sol).all():
            raise SingularSystem("non-finite solution")
        s = plan.sets[0]
        ze = back_substitute(self.g_e, self.T[0], s.point, s.sig, s.rows, sol, Li)
        assert ze is not None  # numba imported for _dense_system
        return self._step(sol[:n_r], ze, sol[n_r:])

    def observability_parts(self) -> tuple[sp.csr_matrix, sp.csr_matrix | None]:
        """(S, C~) at lam = 0: the reduced matrix and the reduced constraint rows."""
        n_r = self.plan.n_r
        dense = self._dense_system(0.0) if self._fused() else None
        if dense is not None:
            Kd = dense[0]
            return sp.csr_matrix(Kd[:n_r, :n_r]), sp.csr_matrix(Kd[n_r:, :n_r]) if self.mc else None
        K = self.reduced_matrix(0.0)
        S = K[:n_r, :n_r].tocsr()
        C = K[n_r:, :n_r].tocsr() if self.mc else None
        return S, C

    # -- cofactor ----------------------------------------------------------------------------

    def cofactor(self) -> BlockCofactor:
        """Blocks of ``Qxx`` in the original units (see :class:`BlockCofactor`).

        ``M``, the inverse of the reduced (bordered) matrix, is needed only where the reduced
        matrix is non-zero (pairs of parameters that share an eliminated block) and on the
        diagonal blocks: without constraints and from :data:`_SELECTED_MIN` reduced parameters
        on, these entries come from a band Cholesky factor (:mod:`.selected_inverse`), never
        from the whole dense inverse; below, or with constraints, ``M`` is inverted densely.
        """
        plan = self.plan
        Ks = self.reduced_matrix(0.0)
        n_r = plan.n_r
        sel = None
        M = None
        if self.mc == 0 and n_r >= _SELECTED_MIN:
            try:
                sel = banded_inverse(Ks)
            except (np.linalg.LinAlgError, ValueError) as exc:
                raise SingularSystem(str(exc)) from None
        if sel is None:
            K = Ks.toarray()
            try:
                if self.mc == 0:
                    cf = sla.cho_factor(K, lower=True, check_finite=False)
                    M = sla.cho_solve(cf, np.eye(K.shape[0]), check_finite=False)
                else:
                    M = sla.inv(K, check_finite=False)
            except (np.linalg.LinAlgError, ValueError) as exc:
                raise SingularSystem(str(exc)) from None
            del K
            M = 0.5 * (M + M.T)

            def take(i: Index, j: Index, M: Array = M) -> Array:
                return M[i, j]
        else:
            take = sel.take
        _, Vinv = self.point_factors(0.0)
        inner, cross = cofactor_sums(plan, self.T, Vinv, take)
        Qpp = Vinv + Vinv @ inner @ Vinv
        Qpp = 0.5 * (Qpp + np.swapaxes(Qpp, 1, 2))
        if self.dead is not None and self.dead.any():
            Qpp[self.dead] = np.nan  # not adjusted: no precision
        d = self.d
        de = d[plan.elim]  # (P, b)
        live = np.ones(plan.P, dtype=bool) if self.dead is None else ~self.dead
        finite = np.isfinite(M).all() if M is not None else sel is not None and sel.finite()
        if not (finite and np.isfinite(Qpp[live]).all()):
            raise SingularSystem("non-finite cofactor matrix")
        return BlockCofactor(
            reduced_index=plan.reduced.copy(),
            eliminated_index=plan.elim.copy(),
            Q_eliminated=Qpp / (de[:, :, None] * de[:, None, :]),
            _plan=plan,
            _take=take,
            _cross=cross,
            _d=d,
        )


@dataclass
class BlockCofactor:
    """The cofactor matrix ``Qxx`` of an adjustment with eliminated blocks, in blocks.

    Attributes
    ----------
    reduced_index : ndarray of int, shape (n_r,)
        Parameters that were not eliminated, in the order of :attr:`Q_reduced`.
    eliminated_index : ndarray of int, shape (P, b)
        The eliminated blocks.
    Q_eliminated : ndarray, shape (P, b, b)
        The cofactor matrix of each block (cross blocks between blocks are not formed).
    """

    reduced_index: Index
    eliminated_index: Index
    Q_eliminated: Array
    _plan: EliminationPlan = field(repr=False)
    _take: Callable[[Index, Index], Array] = field(repr=False)  # entries of the scaled M
    _cross: list[Array] = field(repr=False)
    _d: Array = field(repr=False)

    @property
    def Q_reduced(self) -> Array:
        """The cofactor matrix (n_r, n_r) of the reduced parameters in full (formed on each
        call: for a large reduced system of a large block, from its band factor column by
        column; :meth:`block` forms only what it is asked for)."""
        return self.block(self.reduced_index)

    def diagonal(self) -> Array:
        """``diag(Qxx)`` of all ``n`` parameters."""
        out = np.empty(self._plan.n)
        r = np.arange(self.reduced_index.size)
        dr = self._d[self.reduced_index]
        out[self.reduced_index] = self._take(r, r) / dr**2
        out[self.eliminated_index.ravel()] = np.einsum("pii->pi", self.Q_eliminated).ravel()
        return out

    def block(self, index: ArrayLike) -> Array:
        """``Qxx[index][:, index]`` for parameters that are all reduced, or all of one block.

        Raises
        ------
        InputError
            When the indices mix blocks (cross-covariances between points are not formed).
        """
        idx = np.asarray(index, dtype=np.intp).ravel()
        plan = self._plan
        pts = plan.point_of[idx]
        if (pts < 0).all():
            r = plan.rmap[idx]
            dr = self._d[idx]
            return self._take(r[:, None], r[None, :]) / np.outer(dr, dr)
        if (pts >= 0).all() and np.unique(pts).size == 1:
            p = int(pts[0])
            slots = np.array([int(np.flatnonzero(plan.elim[p] == i)[0]) for i in idx])
            return self.Q_eliminated[p][np.ix_(slots, slots)]
        raise InputError(
            "the cofactor blocks hold the reduced parameters and each eliminated block alone; "
            "the requested parameters span several of them"
        )

    def group_blocks(self, block: int, sel: Index) -> Array:
        """``Qxx`` at the parameter indices of the groups ``sel`` of observation block
        ``block``: (len(sel), k, k), in the original units."""
        plan = self._plan
        bp = plan.plans[block]
        kr, ke = bp.rc.size, bp.ec.size
        k = kr + ke
        g = sel.size
        Q = np.zeros((g, k, k))
        rr = bp.rrows[sel]
        if kr:
            Q[:, bp.rc[:, None], bp.rc[None, :]] = self._take(rr[:, :, None], rr[:, None, :])
        if ke:
            pt = bp.point[sel]
            es = bp.eslot[sel]
            if kr:
                # cross block rows in rc order: varying columns from the group's own
                # occurrence, shared columns from the block's occurrence at the point
                X = np.zeros((g, kr, plan.b))
                if bp.vc.size:
                    occ = np.searchsorted(bp.with_point, sel)
                    X[:, bp.vc, :] = self._cross[bp.vset][occ]
                if bp.cc.size:
                    X[:, bp.cc, :] = self._cross[bp.cset][bp.c_occ[sel]]
                Xe = np.take_along_axis(X, es[:, None, :], axis=2)  # (g, kr, ke)
                Q[:, bp.rc[:, None], bp.ec[None, :]] = Xe
                Q[:, bp.ec[:, None], bp.rc[None, :]] = np.swapaxes(Xe, 1, 2)
        dl = np.concatenate(
            [
                self._d[plan.reduced][rr] if kr else np.zeros((g, 0)),
                self._d[plan.elim[bp.point[sel][:, None], bp.eslot[sel]]]
                if ke
                else np.zeros((g, 0)),
            ],
            axis=1,
        )
        order = np.concatenate([bp.rc, bp.ec])
        dk = np.empty((g, k))
        dk[:, order] = dl
        for i in range(k):  # in place, a row at a time: no other (g, k, k) array
            Q[:, i, :] /= dk[:, i, None] * dk
        if ke:  # the block's own cofactors, already in the original units (the same quotients)
            Q[:, bp.ec[:, None], bp.ec[None, :]] = self.Q_eliminated[
                pt[:, None, None], es[:, :, None], es[:, None, :]
            ]
        return Q


def _point_products(Li: Array, point: Index, T: Array) -> Array:
    """``Li[point] @ T'`` (O, b, kk), in chunks of occurrences (the gathered factors are
    not held for all occurrences at once)."""
    if _COMPILED and T.shape[0] >= _COMPILED_MIN:
        Z = _nb.point_products(Li, point, T)
        if Z is not None:
            return Z
    out = np.empty((T.shape[0], Li.shape[1], T.shape[1]))
    for s in range(0, T.shape[0], _CHUNK):
        sl = slice(s, s + _CHUNK)
        out[sl] = Li[point[sl]] @ np.swapaxes(T[sl], 1, 2)
    return out


def _plain(bp, g: int, b: int) -> bool:
    """A block plan the compiled sums cover: every group sees one eliminated block, its
    columns in slot order, and every reduced column varies between groups."""
    return bool(
        bp.ec.size == b
        and bp.eslot_identity
        and bp.rc.size
        and bp.vc.size == bp.rc.size
        and bp.cset < 0
        and bp.vset >= 0
        and bp.u_reducer is not None
        and bp.v_reducer is not None
        and bp.with_point.size == g
    )


def _columns(A: Array, cols: Index) -> Array:
    """``A[:, :, cols]``, a view when the columns are a contiguous run."""
    if cols.size and (np.diff(cols) == 1).all():
        return A[:, :, int(cols[0]) : int(cols[-1]) + 1]
    return A[:, :, cols]


def _diag_grad(
    blocks: Sequence, lins: Sequence, active: Sequence[NDArray[np.bool_]], n: int
) -> tuple[Array, Array]:
    """The diagonal of the normal matrix and the gradient ``A^T w`` (n,) of the whitened
    linearisations, the active groups only (the Jacobi scale is computed from the diagonal)."""
    diag = np.zeros(n)
    grad = np.zeros(n)
    for bk, bl, a in zip(blocks, lins, active):
        if bk.groups == 0:
            continue
        if (
            _COMPILED
            and bk.groups >= _COMPILED_MIN
            and diag_grad(bl.abar, bl.wbar, a, bk.param_index, diag, grad)
        ):
            continue
        every = bool(a.all())
        A = bl.abar if every else bl.abar * a[:, None, None]
        w = bl.wbar if every else bl.wbar * a[:, None]
        diag += np.bincount(
            bk.param_index.ravel(), weights=np.einsum("gck,gck->gk", A, A).ravel(), minlength=n
        )
        grad += np.bincount(
            bk.param_index.ravel(), weights=np.einsum("gc,gck->gk", w, A).ravel(), minlength=n
        )
    return diag, grad


def build_reduced_normal(
    plan: EliminationPlan,
    blocks: Sequence,
    lins: Sequence,
    active: Sequence[NDArray[np.bool_]],
    C: sp.csr_matrix | None,
    h: Array,
    rowscale: Array | None,
) -> tuple[ReducedNormal, Array | None]:
    """Assemble the reduced system of one linearisation (see the module docstring).

    ``lins`` are the whitened linearisations of the blocks (``abar`` (G, c, k), ``wbar``
    (G, c)); ``C`` the constraint Jacobian (mc, n) and ``h`` its values. Returns the system
    and the constraint row scale (computed on the first call, then reused).
    """
    diag, grad = _diag_grad(blocks, lins, active, plan.n)
    d = jacobi_scale(np.sqrt(np.clip(diag, 0.0, None)), C)
    dinv = 1.0 / d
    mc = 0 if C is None else C.shape[0]
    plan.finish(mc)
    n_r, b, P = plan.n_r, plan.b, plan.P
    urows: list[Index] = []
    ucols: list[Index] = []
    uvals: list[Array] = []
    V = np.zeros((P, b, b))
    g_e = np.zeros((P, b))
    T: list[Array | None] = [None] * len(plan.sets)
    for bk, bl, a, bp in zip(blocks, lins, active, plan.plans):
        g = bk.groups
        if g == 0:
            continue
        every = bool(a.all())
        scale = dinv[bk.param_index]
        if not every:
            scale = a[:, None] * scale
        w = bl.wbar if every else bl.wbar * a[:, None]
        if _COMPILED and g >= _COMPILED_MIN and _plain(bp, g, b):
            sums = normal_sums(
                bl.abar, w, scale, bp.rc, bp.ec, bp.sig, bp.sig_rows.shape[0], bp.point, P
            )
            if sums is not None:
                UR, Vb, gb, T[bp.vset] = sums
                rs = bp.sig_rows
                urows.append(np.broadcast_to(rs[:, :, None], UR.shape).ravel())
                ucols.append(np.broadcast_to(rs[:, None, :], UR.shape).ravel())
                uvals.append(UR.ravel())
                V += Vb
                g_e += gb
                continue
        As = bl.abar * scale[:, None, :]
        R = _columns(As, bp.rc)
        ke = bp.ec.size
        if ke and bp.eslot_identity:
            E = _columns(As, bp.ec)
        elif ke:
            E = np.zeros((g, As.shape[1], b))
            for j in range(ke):
                E[np.arange(g), :, bp.eslot[:, j]] += As[:, :, bp.ec[j]]
        kr = bp.rc.size
        if kr and bp.u_reducer is not None:
            UR = bp.u_reducer.sum_outer(lambda it, R=R: R[it], None, kr, kr)
            rs = bp.sig_rows
            urows.append(np.broadcast_to(rs[:, :, None], UR.shape).ravel())
            ucols.append(np.broadcast_to(rs[:, None, :], UR.shape).ravel())
            uvals.append(UR.ravel())
        if ke and bp.v_reducer is not None:
            wp = bp.with_point
            every = wp.size == g
            Ew, ww = (E, w) if every else (E[wp], w[wp])
            V += bp.v_reducer.sum_outer(lambda it, Ew=Ew: Ew[it], None, b, b)
            g_e += bp.v_reducer.sum(
                lambda it, Ew=Ew, ww=ww: (ww[it][:, None, :] @ Ew[it])[:, 0, :], (b,)
            )
            if kr:
                Rw = R if every else R[wp]
                if bp.vset >= 0:
                    T[bp.vset] = np.swapaxes(Rw[:, :, bp.vc], 1, 2) @ Ew
                if bp.cset >= 0:
                    Rc = Rw[:, :, bp.cc]
                    kc = bp.cc.size
                    T[bp.cset] = bp.c_reducer.sum_outer(
                        lambda it, Rc=Rc: Rc[it], lambda it, Ew=Ew: Ew[it], kc, b
                    )
    # blocks whose every group is set aside (see outliers._cascade) stay where they are:
    # a unit block keeps the reduced system regular and their step zero
    dead = np.einsum("pii->p", V) == 0.0
    if dead.any():
        V[dead] = np.eye(b)
        g_e[dead] = 0.0
    g_r = grad[plan.reduced] * dinv[plan.reduced]
    ns = grad * dinv
    hs = np.zeros(0)
    if C is not None:
        Cs, hs, rowscale = scale_constraints(C, dinv, h, rowscale)
        Cr = Cs[:, plan.reduced].tocoo()
        # the borders of U+: C_r at rows n_r.., and its transpose
        urows += [n_r + Cr.row, Cr.col]
        ucols += [Cr.col, n_r + Cr.row]
        uvals += [Cr.data, Cr.data]
        if plan.kset >= 0:
            cols = plan.elim[plan.sets[plan.kset].point].ravel()  # (Ok * b,)
            Ce = Cs[:, cols].toarray()  # (mc, Ok * b)
            T[plan.kset] = np.ascontiguousarray(
                Ce.reshape(mc, -1, b).transpose(1, 0, 2)
            )  # (Ok, mc, b)
    for i, s in enumerate(plan.sets):
        if T[i] is None:
            T[i] = np.zeros((s.point.size, s.rows.shape[1], b))
    nred = n_r + mc
    red = ReducedNormal(
        plan=plan,
        d=d,
        ns=ns,
        u_rows=np.concatenate(urows) if urows else np.zeros(0, dtype=np.intp),
        u_cols=np.concatenate(ucols) if ucols else np.zeros(0, dtype=np.intp),
        u_vals=np.concatenate(uvals) if uvals else np.zeros(0),
        g_r=g_r,
        V=V,
        g_e=g_e,
        T=T,  # type: ignore[arg-type]
        hs=hs,
        mc=mc,
        dead=dead,
    )
    if nred > _DENSE_MAX:
        try:
            nnz = red.reduced_matrix(0.0).nnz
        except SingularSystem:
            nnz = 0  # diagnosed by the observability check
        red.use_sparse = nnz <= _SPARSE_MAX_DENSITY * nred * nred
    return red, rowscale
