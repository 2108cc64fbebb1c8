"""The validated problem of an adjustment: observation blocks and constraints checked and
prepared (covariance factors, weights), their batched evaluation and whitening at one
linearisation point, and the assembly of the Jacobi-scaled normal equations (full, or reduced
by :mod:`.schur`). The method is described in :mod:`.adjustment`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Callable, Union

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray

from ..errors import AdjustmentError, InputError
from .model import GaussHelmertBlock, GaussMarkovBlock, _PriorModel
from .scaling import jacobi_scale, scale_constraints
from .schur import build_reduced_normal
from .schur_plan import EliminationPlan

Array = NDArray[np.float64]
Block = Union[GaussMarkovBlock, GaussHelmertBlock]


class _NonFiniteError(Exception):
    """A model returned NaN/inf (caught: a rejected step, or reported with context)."""

    def __init__(self, block: str, label: str) -> None:
        super().__init__(f"block '{block}' returned non-finite values (group {label})")
        self.block = block
        self.label = label


@dataclass
class _Obs:
    """A validated observation block (Gauss-Markov or Gauss-Helmert)."""

    name: str
    gauss_markov: bool
    observed: Array  # (G, o)
    cov: Array  # (G, o, o)
    weight: Array  # (G, o, o) = cov^-1
    chol: Array  # (G, o, o) lower Cholesky factor of cov
    chol_inv: Array  # (G, o, o)
    param_index: NDArray[np.intp]  # (G, k)
    func: Callable
    labels: list[str]
    row_names: list[str]
    c: int | None  # condition rows per group (known after the first evaluation)
    inv_sigma: Array | None = None  # (G, o) 1/sigma when every cov is diagonal, else None
    # Rows whose covariance has no off-diagonal entry in any group (a line's pixels beside its
    # 6 x 6 (X0, u)), when the others are at most half: products with cov and weight then take
    # those rows as a diagonal scaling and only the rest as a matrix (see :meth:`times_cov`).
    sparse_rows: tuple[NDArray[np.intp], NDArray[np.intp]] | None = None
    # every sigma is one (inv_sigma all ones): the whitening is the identity
    unit_sigma: bool = False

    @property
    def groups(self) -> int:
        return self.observed.shape[0]

    @property
    def o(self) -> int:
        return self.observed.shape[1]

    @property
    def k(self) -> int:
        return self.param_index.shape[1]

    def times_cov(self, M: Array) -> Array:
        """``cov @ M`` for M of shape (G, o, n) (:func:`_structured_times`)."""
        return _structured_times(self.cov, self.sparse_rows, M)


def _structured_times(
    S: Array, sparse_rows: tuple[NDArray[np.intp], NDArray[np.intp]] | None, M: Array
) -> Array:
    """``S @ M`` for S (G, o, o) a covariance or weight matrix and M (G, o, n); with
    ``sparse_rows`` (diagonal rows, coupled rows: :attr:`_Obs.sparse_rows`) the diagonal rows
    are scaled and the coupled ones multiplied by their (coupled x coupled) part only: the two
    parts do not couple, so the product is the same."""
    if sparse_rows is None:
        return S @ M
    diag, dense = sparse_rows
    out = np.empty(M.shape)
    out[:, diag] = S[:, diag, diag][:, :, None] * M[:, diag]
    out[:, dense] = S[:, dense[:, None], dense[None, :]] @ M[:, dense]
    return out


@dataclass
class _Con:
    name: str
    param_index: NDArray[np.intp]
    func: Callable
    labels: list[str]
    c: int | None


@dataclass
class _BlockLin:
    """Whitened linearisation of one block: rows of all groups, rejected ones included."""

    abar: Array  # (G, c, k) = L^-1 A
    wbar: Array  # (G, c) = L^-1 w
    K: Array  # (G, o, c) = S B' L^-T, so that v = -K (A_ dx + w_)


@dataclass
class _Lin:
    x: Array
    vhat: list[Array]
    blocks: list[_BlockLin]
    h: Array  # (mc,)
    H: list[Array]  # per constraint (G, c, k)
    phi: float  # ||w_||^2 over the groups kept


@dataclass
class _Normal:
    """Jacobi-scaled normal equations at one linearisation."""

    A: sp.csr_matrix  # whitened design (m x n), rejected rows zero
    d: Array  # (n,) Jacobi scale sqrt(diag N)
    Ns: sp.csr_matrix  # D^-1 N D^-1
    ns: Array  # D^-1 A_' w_
    Cs: sp.csr_matrix | None  # R C D^-1
    hs: Array  # R h
    dense: Array | None = None  # cached Ns.toarray()


def _as_index(value: ArrayLike, n: int, where: str) -> NDArray[np.intp]:
    idx = np.asarray(value)
    if idx.ndim != 2:
        raise InputError(f"{where}: param_index must have shape (G, k), got {idx.shape}")
    if idx.size and not np.issubdtype(idx.dtype, np.integer):
        raise InputError(f"{where}: param_index must be integers, got {idx.dtype}")
    idx = idx.astype(np.intp)
    if idx.size and (idx.min() < 0 or idx.max() >= n):
        raise InputError(f"{where}: param_index outside 0..{n - 1}")
    return idx


def _labels(
    given: Sequence[str] | None, count: int, default: Callable[[int], str], where: str, what: str
) -> list[str]:
    if given is None:
        return [default(i) for i in range(count)]
    out = [str(s) for s in given]
    if len(out) != count:
        raise InputError(f"{where}: {what} has {len(out)} entries, expected {count}")
    return out


def _prepare_block(block: Block, n: int, names: list[str]) -> _Obs:
    """Validate a block and precompute the constant parts (covariance factors, weights)."""
    where = f"block '{block.name}'"
    gm = isinstance(block, GaussMarkovBlock)
    if not gm and not isinstance(block, GaussHelmertBlock):
        raise InputError(f"{where}: not a GaussMarkovBlock or GaussHelmertBlock")
    obs = np.asarray(block.observed, dtype=np.float64)
    if obs.ndim != 2:
        raise InputError(f"{where}: observed must have shape (G, c), got {obs.shape}")
    g, o = obs.shape
    if not np.isfinite(obs).all():
        raise InputError(f"{where}: observed contains NaN or inf")
    idx = _as_index(block.param_index, n, where)
    if idx.shape[0] != g:
        raise InputError(f"{where}: param_index has {idx.shape[0]} groups, observed has {g}")
    sig = np.asarray(block.sigma, dtype=np.float64)
    if sig.ndim == 3:
        try:
            cov = np.array(np.broadcast_to(sig, (g, o, o)))
        except ValueError:
            raise InputError(f"{where}: sigma of shape {sig.shape} is not (G, c, c)") from None
        if not np.isfinite(cov).all() or not np.allclose(cov, np.swapaxes(cov, 1, 2)):
            raise InputError(f"{where}: covariance matrices must be finite and symmetric")
    else:
        try:
            s = np.broadcast_to(sig, (g, o))
        except ValueError:
            raise InputError(f"{where}: sigma of shape {sig.shape} is not (G, c)") from None
        if not (np.isfinite(s).all() and (s > 0).all()):
            raise InputError(f"{where}: sigma must be finite and > 0")
        cov = np.zeros((g, o, o))
        cov[:, np.arange(o), np.arange(o)] = s**2
    off = cov.copy()
    off[:, np.arange(o), np.arange(o)] = 0.0
    coupled = off.any(axis=(0, 2)) if g else np.zeros(o, dtype=bool)
    sparse_rows = None
    if coupled.any() and 2 * int(coupled.sum()) <= o:
        sparse_rows = (np.flatnonzero(~coupled), np.flatnonzero(coupled))
    # a Gauss-Helmert block's factors from its two parts (a line's 2,000 pixels: no o^3)
    chol, chol_inv, weight = _factors(cov, sparse_rows if not gm else None, where)
    inv_sigma = None if off.any() else np.ascontiguousarray(np.einsum("gii->gi", chol_inv))
    func = block.model if gm else block.condition
    if isinstance(func, _PriorModel) and block.labels is None:
        labels = [names[i] for i in idx[:, 0]]
    elif block.labels is None:  # the default names, without a call per group
        name = block.name
        labels = [f"{name}[{i}]" for i in range(g)]
    else:
        labels = _labels(block.labels, g, lambda i: f"{block.name}[{i}]", where, "labels")
    row_names = _labels(block.row_names, o, str, where, "row_names")
    return _Obs(
        name=block.name,
        gauss_markov=gm,
        observed=obs,
        cov=cov,
        weight=weight,
        chol=chol,
        chol_inv=chol_inv,
        param_index=idx,
        func=func,
        labels=labels,
        row_names=row_names,
        c=o if gm else None,
        inv_sigma=inv_sigma,
        sparse_rows=sparse_rows,
        unit_sigma=inv_sigma is not None and bool((inv_sigma == 1.0).all()),
    )


def _factors(
    cov: Array, sparse_rows: tuple[NDArray[np.intp], NDArray[np.intp]] | None, where: str
) -> tuple[Array, Array, Array]:
    """(lower Cholesky factor, its inverse, the weight matrix) of each group's covariance
    (G, o, o); with ``sparse_rows`` (diagonal rows, coupled rows) from the diagonal and the
    coupled part separately (the same factors: the parts do not couple)."""
    g, o, _ = cov.shape
    if not g:
        return np.zeros((0, o, o)), np.zeros((0, o, o)), np.zeros((0, o, o))
    parts = [np.arange(o)] if sparse_rows is None else [sparse_rows[1]]
    chol = np.zeros_like(cov)
    chol_inv = np.zeros_like(cov)
    weight = np.zeros_like(cov)
    if sparse_rows is not None:
        diag = sparse_rows[0]
        d = cov[:, diag, diag]
        if not (d > 0).all():
            bad = int(np.flatnonzero(~(d > 0).all(axis=1))[0])
            raise InputError(f"{where}: covariance of group {bad} is not positive definite")
        chol[:, diag, diag] = np.sqrt(d)
        chol_inv[:, diag, diag] = 1.0 / np.sqrt(d)
        weight[:, diag, diag] = 1.0 / d
    for rows in parts:
        at = (slice(None), rows[:, None], rows[None, :])
        part = cov[at]
        try:
            L = np.linalg.cholesky(part)
        except np.linalg.LinAlgError:
            bad = np.flatnonzero(np.linalg.eigvalsh(part)[:, 0] <= 0)
            raise InputError(
                f"{where}: covariance of group {int(bad[0]) if bad.size else '?'} is not "
                "positive definite"
            ) from None
        Li = np.linalg.inv(L)
        chol[at], chol_inv[at] = L, Li
        weight[at] = np.swapaxes(Li, 1, 2) @ Li
    return chol, chol_inv, weight


def _check_finite(block: str, labels: list[str], *arrays: Array) -> None:
    for a in arrays:
        if np.isfinite(a.sum()):  # one pass; NaN or inf anywhere makes the sum non-finite
            continue
        ok = np.isfinite(a.reshape(a.shape[0], -1)).all(axis=1)
        if not ok.all():
            raise _NonFiniteError(block, labels[int(np.flatnonzero(~ok)[0])])


#: Conditions per group from which a Gauss-Helmert group with :attr:`_Obs.sparse_rows` is
#: whitened group by group with sparse products (:func:`_whiten_large`).
_LARGE_GROUP = 64


def _singular(where: str, label: str) -> AdjustmentError:
    return AdjustmentError(
        f"{where}: B S B' is singular for group {label}: the conditions of a group "
        "must be independent functions of its observations"
    )


def _whiten_large(b: _Obs, A: Array, B: Array, w: Array, where: str) -> _BlockLin:
    """The whitened linearisation of a Gauss-Helmert block of large groups (a LiDAR line with
    the pixels of its ~1,000 measurements) whose covariance has rows without off-diagonal
    entries (:attr:`_Obs.sparse_rows`): the same ``L = chol(B S B')``, ``abar = L^-1 A``,
    ``wbar = L^-1 w`` and ``K = S B' L^-T`` as the batched path, with the products over the
    diagonal rows taken sparse (B has few entries there: a measurement's pixel enters its own
    condition only) and L inverted as a triangle, per group. Cost per group about
    ``2/3 c^3`` instead of ``~3 c^2 o + 2 c^3``."""
    from scipy.linalg.lapack import dtrtri

    assert b.sparse_rows is not None
    diag, dense = b.sparse_rows
    g, c, k = A.shape
    abar = np.empty((g, c, k))
    wbar = np.empty((g, c))
    K = np.empty((g, b.o, c))
    for gi in range(g):
        s = b.cov[gi, diag, diag]
        SX = b.cov[gi][np.ix_(dense, dense)]
        BD = sp.csr_matrix(B[gi][:, diag])  # (c, diagonal rows)
        BX = B[gi][:, dense]
        SBtD = BD.T.multiply(s[:, None]).tocsr()  # S B' over the diagonal rows, sparse
        SBtX = SX @ BX.T
        M = np.asarray((BD @ SBtD).todense()) + BX @ SBtX
        try:
            L = np.linalg.cholesky(M)
        except np.linalg.LinAlgError:
            raise _singular(where, b.labels[gi]) from None
        Linv, info = dtrtri(L, lower=1)
        if info != 0:
            raise _singular(where, b.labels[gi])
        abar[gi] = Linv @ A[gi]
        wbar[gi] = Linv @ w[gi]
        K[gi, diag] = SBtD @ Linv.T
        K[gi, dense] = SBtX @ Linv.T
    return _BlockLin(abar=abar, wbar=wbar, K=K)


def _shape_error(where: str, what: str, got: tuple, want: tuple) -> InputError:
    return InputError(f"{where}: {what} has shape {got}, expected {want}")


class _Problem:
    """The validated problem: blocks, constraints and the sparse assembly templates."""

    def __init__(
        self,
        names: list[str],
        blocks: list[_Obs],
        constraints: list[_Con],
        plan: EliminationPlan | None = None,
    ) -> None:
        self.names = names
        self.n = len(names)
        self.blocks = blocks
        self.constraints = constraints
        self.plan = plan
        # Robust (IRLS) weights of the groups of each block, or None.
        self.weights: list[Array] | None = None
        self._row_template: tuple[NDArray[np.intp], NDArray[np.intp], int] | None = None
        self._con_template: tuple[NDArray[np.intp], NDArray[np.intp], int] | None = None

    # -- evaluation --------------------------------------------------------------------------

    def _eval_block(self, b: _Obs, x: Array, vhat: Array) -> _BlockLin:
        g, o, k = b.groups, b.o, b.k
        where = f"block '{b.name}'"
        xl = x[b.param_index]
        if b.gauss_markov:
            f, J = b.func(xl)
            f = np.asarray(f, dtype=np.float64)
            J = np.asarray(J, dtype=np.float64)
            if f.shape != (g, o):
                raise _shape_error(where, "model value f", f.shape, (g, o))
            if J.shape != (g, o, k):
                raise _shape_error(where, "model Jacobian J", J.shape, (g, o, k))
            _check_finite(b.name, b.labels, f, J)
            # B = -I: w = f - l does not depend on v^, and L is the Cholesky factor of S.
            if b.inv_sigma is not None:  # uncorrelated observations: L^-1 is diagonal
                fresh = getattr(b.func, "fresh_jacobian", False) and J.flags.writeable
                if b.unit_sigma:  # L = I: a fresh J is taken as it is, another one copied
                    return _BlockLin(abar=J if fresh else J.copy(), wbar=f - b.observed, K=-b.chol)
                if fresh:
                    # the model hands over a new J on every call: whitened in place
                    abar = np.multiply(J, b.inv_sigma[:, :, None], out=J)
                else:
                    abar = J * b.inv_sigma[:, :, None]
                wbar = (f - b.observed) * b.inv_sigma
            else:
                abar = b.chol_inv @ J
                wbar = np.einsum("gij,gj->gi", b.chol_inv, f - b.observed)
            K = -b.chol
            return _BlockLin(abar=abar, wbar=wbar, K=K)
        gv, A, B = b.func(xl, b.observed + vhat)
        gv = np.asarray(gv, dtype=np.float64)
        A = np.asarray(A, dtype=np.float64)
        B = np.asarray(B, dtype=np.float64)
        if gv.ndim != 2 or gv.shape[0] != g:
            raise _shape_error(where, "condition value g", gv.shape, (g, "c"))
        c = gv.shape[1]
        if b.c is None:
            b.c = c
        elif c != b.c:
            raise InputError(f"{where}: the number of conditions changed from {b.c} to {c}")
        if A.shape != (g, c, k):
            raise _shape_error(where, "condition Jacobian A", A.shape, (g, c, k))
        if B.shape != (g, c, o):
            raise _shape_error(where, "condition Jacobian B", B.shape, (g, c, o))
        _check_finite(b.name, b.labels, gv, A, B)
        w = gv - np.einsum("gco,go->gc", B, vhat)
        if b.sparse_rows is not None and c >= _LARGE_GROUP:
            return _whiten_large(b, A, B, w, where)
        SBt = b.times_cov(np.swapaxes(B, 1, 2))  # (G, o, c)
        M = B @ SBt
        try:
            L = np.linalg.cholesky(M)
        except np.linalg.LinAlgError:
            bad = np.flatnonzero(np.linalg.eigvalsh(M)[:, 0] <= 0)
            raise _singular(where, b.labels[int(bad[0])] if bad.size else "?") from None
        Linv = np.linalg.inv(L)
        abar = Linv @ A
        wbar = np.einsum("gij,gj->gi", Linv, w)
        K = SBt @ np.swapaxes(Linv, 1, 2)
        return _BlockLin(abar=abar, wbar=wbar, K=K)

    def _eval_constraint(self, c: _Con, x: Array) -> tuple[Array, Array]:
        g, k = c.param_index.shape
        where = f"constraint '{c.name}'"
        h, H = c.func(x[c.param_index])
        h = np.asarray(h, dtype=np.float64)
        H = np.asarray(H, dtype=np.float64)
        if h.ndim != 2 or h.shape[0] != g:
            raise _shape_error(where, "value h", h.shape, (g, "c"))
        if c.c is None:
            c.c = h.shape[1]
        elif h.shape[1] != c.c:
            raise InputError(f"{where}: the number of rows changed from {c.c} to {h.shape[1]}")
        if H.shape != (g, c.c, k):
            raise _shape_error(where, "Jacobian H", H.shape, (g, c.c, k))
        _check_finite(c.name, c.labels, h, H)
        return h, H

    def linearize(self, x: Array, vhat: list[Array], active: list[NDArray[np.bool_]]) -> _Lin:
        """Evaluate every block and constraint at ``x`` (raises _NonFiniteError)."""
        lins = [self._eval_block(b, x, v) for b, v in zip(self.blocks, vhat)]
        if self.weights is not None:
            for bl, wt in zip(lins, self.weights):
                s = np.sqrt(wt)
                bl.abar = bl.abar * s[:, None, None]
                bl.wbar = bl.wbar * s[:, None]
                bl.K = bl.K / s[:, None, None]
        hs, Hs = [], []
        for c in self.constraints:
            h, H = self._eval_constraint(c, x)
            hs.append(h.ravel())
            Hs.append(H)
        phi = float(sum(np.sum(bl.wbar[a] ** 2) for bl, a in zip(lins, active)))
        h_all = np.concatenate(hs) if hs else np.zeros(0)
        return _Lin(x=x, vhat=vhat, blocks=lins, h=h_all, H=Hs, phi=phi)

    # -- assembly ----------------------------------------------------------------------------

    @staticmethod
    def _template(index_list: list[NDArray[np.intp]], rows_per_group: list[int]) -> tuple:
        """CSR structure of stacked groups: every row of a group holds its k parameters."""
        indices, indptr, start, nnz = [], [np.zeros(1, dtype=np.intp)], 0, 0
        for idx, c in zip(index_list, rows_per_group):
            g, k = idx.shape
            indices.append(np.broadcast_to(idx[:, None, :], (g, c, k)).ravel())
            indptr.append(nnz + k * np.arange(1, g * c + 1, dtype=np.intp))
            nnz += g * c * k
            start += g * c
        ind = np.concatenate(indices) if indices else np.zeros(0, dtype=np.intp)
        return ind, np.concatenate(indptr), start

    def design(self, lin: _Lin, active: list[NDArray[np.bool_]]) -> tuple[sp.csr_matrix, Array]:
        """Whitened design matrix (m, n) and misclosure (m,), rows of rejected groups zero."""
        if self._row_template is None:
            self._row_template = self._template(
                [b.param_index for b in self.blocks], [int(b.c) for b in self.blocks]
            )
        ind, ptr, m = self._row_template
        data = [(bl.abar * a[:, None, None]).ravel() for bl, a in zip(lin.blocks, active)]
        wb = [(bl.wbar * a[:, None]).ravel() for bl, a in zip(lin.blocks, active)]
        A = sp.csr_matrix(
            (np.concatenate(data) if data else np.zeros(0), ind.copy(), ptr.copy()),
            shape=(m, self.n),
        )
        # Repeated indices in a group are legitimate (the columns add up): merge them.
        A.sum_duplicates()
        return A, (np.concatenate(wb) if wb else np.zeros(0))

    def constraint_matrix(self, lin: _Lin) -> sp.csr_matrix | None:
        if not self.constraints:
            return None
        if self._con_template is None:
            self._con_template = self._template(
                [c.param_index for c in self.constraints], [int(c.c) for c in self.constraints]
            )
        ind, ptr, m = self._con_template
        C = sp.csr_matrix(
            (np.concatenate([H.ravel() for H in lin.H]), ind.copy(), ptr.copy()),
            shape=(m, self.n),
        )
        C.sum_duplicates()
        return C

    def rows(self, active: list[NDArray[np.bool_]]) -> int:
        return int(sum(int(b.c) * int(a.sum()) for b, a in zip(self.blocks, active)))

    def constraint_rows(self) -> int:
        return int(sum(int(c.c) * c.param_index.shape[0] for c in self.constraints))

    def constraint_labels(self) -> list[str]:
        return [c.name for c in self.constraints]

    def normal(
        self,
        lin: _Lin,
        active: list[NDArray[np.bool_]],
        rowscale: Array | None,
    ) -> tuple[_Normal, Array | None]:
        """Jacobi-scaled normal equations; returns the constraint row scale it used."""
        if self.plan is not None:
            return build_reduced_normal(
                self.plan,
                self.blocks,
                lin.blocks,
                active,
                self.constraint_matrix(lin),
                lin.h,
                rowscale,
            )
        A, wbar = self.design(lin, active)
        N = (A.T @ A).tocsr()
        diag = N.diagonal()
        C = self.constraint_matrix(lin)
        d = jacobi_scale(np.sqrt(np.where(diag > 0, diag, 0.0)), C)
        dinv = 1.0 / d
        Ns = sp.csr_matrix(sp.diags(dinv) @ N @ sp.diags(dinv))
        ns = dinv * (A.T @ wbar)
        Cs = None
        hs = np.zeros(0)
        if C is not None:
            Cs, hs, rowscale = scale_constraints(C, dinv, lin.h, rowscale)
        return _Normal(A=A, d=d, Ns=Ns, ns=ns, Cs=Cs, hs=hs), rowscale
