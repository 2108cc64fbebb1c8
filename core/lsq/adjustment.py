"""General weighted non-linear least-squares adjustment (Gauss-Markov, Gauss-Helmert, constraints).

Every adjustment of the project (bundle adjustment, boresight and lever-arm calibration, plane
fits, levelling-like datum problems) is written as a set of observation *blocks* handed to
:func:`adjust`. A block holds ``G`` groups of identical shape (an image point is one group of two
rows) so that the models are evaluated batched, with a leading dimension ``G``, and never in a
Python loop over observations.

Method
------
Both kinds of block are treated as Gauss-Helmert condition equations ``g(x, l + v) = 0``:

- a Gauss-Markov block (``l + v = f(x)``) is ``g = f(x) - l`` with ``B = dg/dl = -I``;
- a Gauss-Helmert block provides ``g``, ``A = dg/dx`` and ``B = dg/dl`` itself;
- a-priori parameter values with sigmas (:func:`prior_block`) are Gauss-Markov blocks with the
  identity model.

At the current estimate ``(x, l^ = l + v^)`` the conditions are linearised as
``A dx + B v + w = 0`` with the misclosure ``w = g(x, l^) - B v^``. Minimising ``v' S^-1 v``
(``S`` the covariance of the observations of a group) under these conditions gives, per group,
the equivalent weight ``Pe = (B S B')^-1`` (``c x c``, batched; ``S^-1`` for Gauss-Markov). With
the Cholesky factor ``B S B' = L L'`` every group is whitened, ``A_ = L^-1 A``, ``w_ = L^-1 w``,
and the whitened design matrix of all groups is assembled as one ``scipy.sparse`` matrix from
the parameter indices of the groups. The step solves::

    min || A_ dx + w_ ||^2            subject to  h(x) + H dx = 0   (hard constraints)

through the normal equations ``N = A_' A_`` bordered by the constraint Jacobian (a KKT system
with Lagrange multipliers). All solves run in Jacobi-scaled variables ``z = D dx`` with
``D = sqrt(diag(N))``, so the step length is measured in units of parameter precision. After
the step the residuals follow from ``v = -S B' Pe (A dx + w)``; Gauss-Helmert blocks are
re-linearised at the new ``l^ = l + v``. The cost ``Omega = sum v' S^-1 v`` equals the squared
whitened misclosure ``||w_||^2`` of the linearisation at the new point (exactly so for linear
models), which is what the step acceptance compares.

Each iteration computes the Gauss-Newton step; with ``damping`` it is kept only when it does
not increase the cost, otherwise Levenberg-Marquardt steps ``(N_s + lambda I) z = -n_s``
(Marquardt's scaling: ``lambda diag(N)`` in the original variables) are tried with growing
``lambda`` (doubling factors after each rejection). The next iteration starts from the
``lambda`` that worked, reduced by Nielsen's (1999) rule from the gain ratio (by ten when the
quadratic model predicted the decrease well), and Gauss-Newton is tried again once it falls
below 1e-7 (lowered a hundredfold after each rejected Gauss-Newton step, so that nearly
singular directions keep a little damping). With constraints the merit function is
``Omega + nu ||h||_1`` (an exact penalty, ``nu`` above the multipliers). Convergence is
declared when the Gauss-Newton step is below ``tolerance`` in units of parameter precision,
or at the rounding floor of parameters with large values (such as map coordinates): the
relative change of the cost is below ``tolerance``, the step is below ``sqrt(tolerance)`` and
has stopped shrinking (more than half the previous one).

Observability: before trusting a solve, the Jacobi-scaled ``N + C'C`` (``C`` the constraint rows
normalised in the scaled space) is checked with a dense symmetric eigen-decomposition (up to a
few thousand parameters; above, a sparse LU with a 1-norm condition estimate, falling back to
the dense analysis up to 6000 parameters). A condition number above ``condition_limit`` raises
:class:`~lidarphoto.core.errors.NotObservableError` naming the parameters of the (near) null
space. No numbers from a singular system are ever returned.

Statistics
----------
``Qxx`` is ``N^-1`` (the upper-left block of the inverse bordered matrix with constraints),
``sigma0 = sqrt(Omega / r)`` with the redundancy ``r = rows - n + constraints``, the global test
is the two-sided chi-square test of ``Omega / sigma0_prior^2`` with ``r`` degrees of freedom.
For every group ``Qvv = S B' Pe (Pe^-1 - A Qxx A') Pe B S`` (only the ``k x k`` blocks of ``Qxx``
at the parameter indices of the group are needed), redundancy numbers ``diag(Qvv S^-1)`` and
Baarda's standardised residuals ``w_i = (S^-1 v)_i / (sigma0_prior sqrt((S^-1 Qvv S^-1)_ii))``.
Outliers are flagged by Baarda's data snooping with iterative rejection of whole groups,
optionally preceded by a robust estimator (below).

Eliminated blocks
-----------------
With :attr:`AdjustmentOptions.eliminate` the normal equations are assembled and solved in
reduced form (:mod:`.schur`): the named blocks (object points) are eliminated by the Schur
complement, damping, constraints (also on eliminated parameters), the observability analysis
(of every eliminated block, then of the reduced system ``S + C~'C~``, whose null space is that
of the full system projected on the reduced parameters) and the statistics are the same as
above; ``Qxx`` is formed in blocks (reduced parameters in full, each eliminated block, and the
cross blocks each group needs for its standardised residuals).

Robust estimation
-----------------
With :attr:`AdjustmentOptions.robust` the adjustment first runs as iteratively reweighted
least squares (Huber 1964; the Cauchy weight function): each group gets the weight
``psi(u)/u`` of its standardised misfit ``u = |w_g| / sqrt(c) / s`` (``w_g`` the whitened
misclosure, ``s`` the robust scale: the median of ``u`` over the observation groups divided by
its expected value, but at least 1, the a-priori unit weight that data snooping also uses),
until the weights settle. Groups with ``u`` above the critical value of
data snooping at the robust solution are then set aside (reported as rejected in round 0),
and the ordinary adjustment, with its statistics and data snooping, runs on the rest from the
robust estimate, so that several gross errors cannot mask one another.

Sigmas define the weights ``P = S^-1``; ``sigma0_prior`` is the a-priori standard deviation of
unit weight, so ``Omega / sigma0_prior^2`` is chi-square distributed when the sigmas are right.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Callable, Union

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import ArrayLike, NDArray
from scipy import stats

from ..errors import (
    AdjustmentError,
    ConvergenceError,
    InputError,
    NotObservableError,
    stop_if_asked,
)
from ..i18n import mark as _t
from .model import (
    AdjustmentOptions,
    Constraint,
    GaussHelmertBlock,
    GaussMarkovBlock,
    _PriorModel,
)
from .results import AdjustmentResult, ChiSquareTest, RejectedObservation, ResidualTable
from .schur import EliminationPlan, ReducedNormal, SingularSystem, build_reduced_normal

#: catalogue context of this module's ``_t("...")`` sentences (``make i18n``): the reports'
TR_CONTEXT = "Report"

__all__ = ["adjust"]

Array = NDArray[np.float64]
Block = Union[GaussMarkovBlock, GaussHelmertBlock]

# Largest n for which the observability check is a dense eigen-decomposition every time.
_DENSE_ANALYSIS_MAX_N = 3000
# Largest n for which a failed sparse check is repeated densely to name the parameters.
_DENSE_FALLBACK_MAX_N = 6000
# Automatic choice of the sparse solver: n above this and N at most this dense.
_SPARSE_AUTO_MIN_N = 300
_SPARSE_AUTO_MAX_DENSITY = 0.05
# A parameter takes part in a near-null direction when its component exceeds this share of the
# largest component.
_NULL_COMPONENT_SHARE = 0.1
# Eigenvalues below this many eps (relative to the largest) are an exact null space (the
# rounding error of a zero eigenvalue is a few eps).
_EXACT_NULL_EPS = 50.0
# Redundancy numbers below this are "zero": the residual is not testable (w is NaN).
_REDUNDANCY_EPS = 1e-9
# Column chunk of the sparse computation of Qxx (bounds the memory of the right-hand sides).
_QXX_CHUNK = 512
# Largest lambda of Levenberg-Marquardt before the cost is declared irreducible.
_LAMBDA_MAX = 1e12
# First lambda after a rejected Gauss-Newton step, and the smallest kept before returning to
# Gauss-Newton (in the Jacobi-scaled space, where the diagonal of N is one).
_LAMBDA_START = 1e-3
_LAMBDA_MIN = 1e-7
# Maximum number of names quoted in an error message (the full list is on the exception).
_MAX_NAMES_IN_MESSAGE = 30


# ----------------------------------------------------------------------------- internals


class _NonFiniteError(Exception):
    """A model returned NaN/inf (caught: a rejected step, or reported with context)."""

    def __init__(self, block: str, label: str) -> None:
        super().__init__(f"block '{block}' returned non-finite values (group {label})")
        self.block = block
        self.label = label


# A factorisation failed or gave non-finite numbers (leads to the observability analysis).
_SingularError = SingularSystem
# Groups per chunk when the standardised residuals are computed (bounds the k x k cofactor
# blocks held at once).
_RESIDUAL_CHUNK = 20000
_ROBUST_K = {"huber": 1.5, "cauchy": 2.385}


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

    @property
    def groups(self) -> int:
        return self.observed.shape[0]

    @property
    def o(self) -> int:
        return self.observed.shape[1]

    @property
    def k(self) -> int:
        return self.param_index.shape[1]


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
    try:
        chol = np.linalg.cholesky(cov) if g else np.zeros((0, o, o))
    except np.linalg.LinAlgError:
        bad = np.flatnonzero(np.linalg.eigvalsh(cov)[:, 0] <= 0)
        raise InputError(
            f"{where}: covariance of group {int(bad[0]) if bad.size else '?'} is not "
            "positive definite"
        ) from None
    chol_inv = np.linalg.inv(chol) if g else chol
    weight = np.swapaxes(chol_inv, 1, 2) @ chol_inv
    func = block.model if gm else block.condition
    if isinstance(func, _PriorModel) and block.labels is None:
        labels = [names[i] for i in idx[:, 0]]
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
    )


def _check_finite(block: str, labels: list[str], *arrays: Array) -> None:
    for a in arrays:
        ok = np.isfinite(a.reshape(a.shape[0], -1)).all(axis=1)
        if not ok.all():
            raise _NonFiniteError(block, labels[int(np.flatnonzero(~ok)[0])])


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
        SBt = b.cov @ np.swapaxes(B, 1, 2)  # (G, o, c)
        M = B @ SBt
        try:
            L = np.linalg.cholesky(M)
        except np.linalg.LinAlgError:
            bad = np.flatnonzero(np.linalg.eigvalsh(M)[:, 0] <= 0)
            label = b.labels[int(bad[0])] if bad.size else "?"
            raise AdjustmentError(
                f"{where}: B S B' is singular for group {label}: the conditions of a group "
                "must be independent functions of its observations"
            ) from None
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
        d = np.sqrt(np.where(diag > 0, diag, 0.0))
        if C is not None:
            # Parameters seen only by constraints get the constraint column norm as scale.
            cn = np.sqrt(np.asarray(C.multiply(C).sum(axis=0)).ravel())
            d = np.where(d > 0, d, cn)
        d = np.where(d > 0, d, 1.0)
        dinv = 1.0 / d
        Ns = sp.csr_matrix(sp.diags(dinv) @ N @ sp.diags(dinv))
        ns = dinv * (A.T @ wbar)
        Cs = None
        hs = np.zeros(0)
        if C is not None:
            Cd = sp.csr_matrix(C @ sp.diags(dinv))
            if rowscale is None:
                # Unit rows in the scaled space make C'C commensurate with N_s (unit diagonal).
                rn = np.sqrt(np.asarray(Cd.multiply(Cd).sum(axis=1)).ravel())
                rowscale = np.where(rn > 0, 1.0 / np.where(rn > 0, rn, 1.0), 1.0)
            Cs = sp.csr_matrix(sp.diags(rowscale) @ Cd)
            hs = rowscale * lin.h
        return _Normal(A=A, d=d, Ns=Ns, ns=ns, Cs=Cs, hs=hs), rowscale


# ----------------------------------------------------------------------------- linear algebra


def _dense_ns(nrm: _Normal) -> Array:
    if nrm.dense is None:
        nrm.dense = nrm.Ns.toarray()
    return nrm.dense


def _solve(nrm: _Normal, lam: float, use_sparse: bool) -> tuple[Array, Array]:
    """Scaled (damped) step ``z`` and multipliers ``k`` of the bordered system.

    Solves ``(N_s + lam I) z + C_s' k = -n_s``, ``C_s z = -h_s``. Raises _SingularError when a
    factorisation fails or gives non-finite numbers.
    """
    if isinstance(nrm, ReducedNormal):
        return nrm.solve(lam)
    n = nrm.ns.size
    if use_sparse:
        Nl = (nrm.Ns + lam * sp.identity(n, format="csr")).tocsc()
        try:
            if nrm.Cs is None:
                lu = spla.splu(
                    Nl,
                    permc_spec="MMD_AT_PLUS_A",
                    diag_pivot_thresh=0.0,
                    options={"SymmetricMode": True},
                )
                z = lu.solve(-nrm.ns)
                k = np.zeros(0)
            else:
                K = sp.bmat([[Nl, nrm.Cs.T], [nrm.Cs, None]], format="csc")
                sol = spla.splu(K).solve(np.concatenate([-nrm.ns, -nrm.hs]))
                z, k = sol[:n], sol[n:]
        except RuntimeError as exc:  # SuperLU: "Factor is exactly singular"
            raise _SingularError(str(exc)) from None
    else:
        M = _dense_ns(nrm) + lam * np.eye(n)
        try:
            if nrm.Cs is None:
                cf = sla.cho_factor(M, lower=True, check_finite=False)
                z = sla.cho_solve(cf, -nrm.ns, check_finite=False)
                k = np.zeros(0)
            else:
                # (N + C'C) is positive definite exactly when the constrained problem is
                # determined; the multipliers then follow from the small Schur complement.
                C = nrm.Cs.toarray()
                cf = sla.cho_factor(M + C.T @ C, lower=True, check_finite=False)
                r = -nrm.ns - C.T @ nrm.hs
                Y = sla.cho_solve(cf, C.T, check_finite=False)
                zr = sla.cho_solve(cf, r, check_finite=False)
                S = C @ Y
                k = sla.solve(S, C @ zr + nrm.hs, assume_a="pos", check_finite=False)
                z = zr - Y @ k
        except (np.linalg.LinAlgError, ValueError) as exc:
            raise _SingularError(str(exc)) from None
    if not (np.isfinite(z).all() and np.isfinite(k).all()):
        raise _SingularError("non-finite solution")
    return z, k


def _scaled_cofactor(nrm: _Normal, use_sparse: bool) -> Array:
    """``Q_s = (D Qxx D)``: inverse of ``N_s`` or upper-left block of the bordered inverse."""
    n = nrm.ns.size
    if not use_sparse or n <= _DENSE_ANALYSIS_MAX_N:
        Nd = _dense_ns(nrm)
        if nrm.Cs is None:
            cf = sla.cho_factor(Nd, lower=True, check_finite=False)
            Q = sla.cho_solve(cf, np.eye(n), check_finite=False)
        else:
            C = nrm.Cs.toarray()
            cf = sla.cho_factor(Nd + C.T @ C, lower=True, check_finite=False)
            Minv = sla.cho_solve(cf, np.eye(n), check_finite=False)
            Y = Minv @ C.T
            S = C @ Y
            Q = Minv - Y @ sla.solve(S, Y.T, assume_a="pos", check_finite=False)
    else:
        if nrm.Cs is None:
            lu = spla.splu(
                nrm.Ns.tocsc(),
                permc_spec="MMD_AT_PLUS_A",
                diag_pivot_thresh=0.0,
                options={"SymmetricMode": True},
            )
            mc = 0
        else:
            K = sp.bmat([[nrm.Ns, nrm.Cs.T], [nrm.Cs, None]], format="csc")
            lu = spla.splu(K)
            mc = nrm.Cs.shape[0]
        Q = np.empty((n, n))
        for s in range(0, n, _QXX_CHUNK):
            e = min(n, s + _QXX_CHUNK)
            rhs = np.zeros((n + mc, e - s))
            rhs[np.arange(s, e), np.arange(e - s)] = 1.0
            Q[:, s:e] = lu.solve(rhs)[:n]
    Q = 0.5 * (Q + Q.T)
    if not np.isfinite(Q).all():
        raise _SingularError("non-finite cofactor matrix")
    return Q


def _join_names(names: list[str]) -> str:
    if len(names) <= _MAX_NAMES_IN_MESSAGE:
        return ", ".join(names)
    shown = ", ".join(names[:_MAX_NAMES_IN_MESSAGE])
    return f"{shown} and {len(names) - _MAX_NAMES_IN_MESSAGE} more"


def _dense_analysis(M: Array, scale: Array, names: list[str], limit: float) -> float:
    """Eigen-analysis of the (twice) Jacobi-scaled matrix; raises when it is near-singular.

    ``scale`` maps the eigenvectors back to parameter units (``dx = scale * y``).
    """
    ev = np.linalg.eigvalsh(M)
    lmax = float(ev[-1])
    lmin = float(ev[0])
    cond = lmax / lmin if lmin > 0 else math.inf
    if lmax > 0 and cond <= limit:
        return cond
    eps = np.finfo(float).eps
    vals, vecs = np.linalg.eigh(M)
    if lmax > 0:
        null = vals <= lmax / limit
        exact_null = vals <= lmax * _EXACT_NULL_EPS * eps
    else:
        null = exact_null = np.ones(vals.size, dtype=bool)
    involved = np.zeros(vals.size, dtype=bool)
    if exact_null.any():
        # An exact null space: every parameter in its support takes part. The support is
        # read from basis-independent row norms, above the rounding noise of the eigenvectors
        # (about eps over the relative gap to the next eigenvalue).
        rows = np.linalg.norm(vecs[:, exact_null], axis=1)
        rest = vals[~exact_null]
        gap = rest[0] / lmax if rest.size and lmax > 0 else 1.0
        noise = min(_NULL_COMPONENT_SHARE, max(1e-6, 1e3 * eps / max(gap, eps)))
        involved |= rows > noise * rows.max()
    near = null & ~exact_null
    if near.any():
        # Near-null directions: the parameters with a significant share of each direction.
        V = np.abs(vecs[:, near])
        involved |= (V > _NULL_COMPONENT_SHARE * V.max(axis=0)).any(axis=1)
    who = [names[i] for i in np.flatnonzero(involved)]
    nv = scale[:, None] * vecs[:, null]
    nv /= np.linalg.norm(nv, axis=0)
    exact = bool(exact_null.any())
    if exact:
        msg = (
            f"Not observable: the observations do not determine {_join_names(who)} (they can "
            "move together without changing any observation); add a datum (fix or weight "
            "one of them) or observations that connect them"
        )
    else:
        msg = (
            f"Not observable: the normal matrix is ill-conditioned (condition number "
            f"{cond:.3g} > limit {limit:.3g}); the observations barely determine "
            f"{_join_names(who)} (nearly collinear or badly configured observations); add "
            "observations with a better geometry or weight one of them"
        )
    raise NotObservableError(msg, parameters=who, null_vectors=nv, condition_number=cond)


def _check_observability(
    nrm: _Normal, names: list[str], limit: float, constraint_names: Sequence[str] = ()
) -> float:
    """Condition number of the Jacobi-scaled ``N + C'C``; raises NotObservableError."""
    if isinstance(nrm, ReducedNormal):
        return _check_reduced(nrm, names, limit, constraint_names)
    n = nrm.ns.size
    Ms = nrm.Ns
    if nrm.Cs is not None:
        mc = nrm.Cs.shape[0]
        if mc > n:
            raise AdjustmentError(
                f"{mc} hard constraint rows for {n} parameters: they cannot be independent"
            )
        if mc * n <= 2e7:
            s = np.linalg.svd(nrm.Cs.toarray(), compute_uv=False)
            if s.size and (s[-1] <= s[0] * 1e-8 or s[0] == 0):
                raise AdjustmentError(
                    "The hard constraints are linearly dependent (redundant or contradictory): "
                    + ", ".join(constraint_names)
                )
        Ms = (Ms + nrm.Cs.T @ nrm.Cs).tocsr()
    e = np.sqrt(np.clip(Ms.diagonal(), 0.0, None))
    e = np.where(e > 0, e, 1.0)
    Mss = sp.csr_matrix(sp.diags(1.0 / e) @ Ms @ sp.diags(1.0 / e))
    scale = 1.0 / (nrm.d * e)
    if n <= _DENSE_ANALYSIS_MAX_N:
        return _dense_analysis(Mss.toarray(), scale, names, limit)
    cond = math.inf
    try:
        lu = spla.splu(
            Mss.tocsc(),
            permc_spec="MMD_AT_PLUS_A",
            diag_pivot_thresh=0.0,
            options={"SymmetricMode": True},
        )
        op = spla.LinearOperator((n, n), matvec=lu.solve, rmatvec=lu.solve, dtype=np.float64)
        inv_norm = float(spla.onenormest(op))
        norm1 = float(abs(Mss).sum(axis=0).max())
        if np.isfinite(inv_norm):
            cond = norm1 * inv_norm
    except RuntimeError:
        cond = math.inf
    if cond <= limit:
        return cond
    if n <= _DENSE_FALLBACK_MAX_N:
        return _dense_analysis(Mss.toarray(), scale, names, limit)
    unseen = [names[i] for i in np.flatnonzero(nrm.Ns.diagonal() <= 0)]
    extra = f"; parameters without any observation: {_join_names(unseen)}" if unseen else ""
    raise NotObservableError(
        f"Not observable: the normal matrix of {n} parameters is singular or ill-conditioned "
        f"(condition estimate {cond:.3g} > limit {limit:.3g}) and too large to name the "
        f"parameters involved{extra}; check the datum and the connectivity of the network",
        parameters=unseen,
        condition_number=cond,
    )


def _check_reduced(
    red: ReducedNormal, names: list[str], limit: float, constraint_names: Sequence[str]
) -> float:
    """Observability of a reduced system: each eliminated block, then ``S + C~'C~``."""
    plan = red.plan
    cond_p = red.point_conditions()
    bad = np.flatnonzero(~(cond_p <= limit))
    if bad.size:
        who = [names[i] for i in plan.elim[bad].ravel()]
        worst = float(np.max(cond_p[bad]))
        raise NotObservableError(
            f"Not observable: the observations do not determine {_join_names(who)} "
            f"({bad.size} eliminated block(s), condition number up to {worst:.3g} > limit "
            f"{limit:.3g}); each of them needs observations that fix it on their own (an "
            "object point needs rays from two or more images that intersect at an angle)",
            parameters=who,
            condition_number=worst,
        )
    try:
        S, Ct = red.observability_parts()
    except SingularSystem:
        raise NotObservableError(
            "Not observable: the eliminated blocks are singular", parameters=[]
        ) from None
    sub = _Normal(A=None, d=red.d[plan.reduced], Ns=S, ns=red.g_r, Cs=Ct, hs=red.hs)
    rnames = [names[i] for i in plan.reduced]
    cond = _check_observability(sub, rnames, limit, constraint_names)
    return max(cond, float(np.max(cond_p)) if cond_p.size else 1.0)


# ----------------------------------------------------------------------------- iteration


class _Progress:
    """Monotone progress in [0, 1] over possibly several adjustment runs."""

    def __init__(self, callback: Callable[[float], None] | None) -> None:
        self.callback = callback
        self.last = 0.0
        self.lo, self.hi = 0.0, 1.0

    def span(self, lo: float, hi: float) -> None:
        self.lo, self.hi = lo, hi

    def __call__(self, fraction: float) -> None:
        value = self.lo + (self.hi - self.lo) * min(max(fraction, 0.0), 1.0)
        self.last = max(self.last, min(value, 1.0))
        if self.callback is not None:
            self.callback(self.last)


@dataclass
class _Run:
    lin: _Lin
    nrm: _Normal
    iterations: int
    converged: bool
    use_sparse: bool
    warnings: list[str]


def _apply(problem: _Problem, lin: _Lin, nrm: _Normal, z: Array) -> tuple[Array, list[Array]]:
    """New parameters and residual estimates after the scaled step ``z``."""
    dx = z / nrm.d
    x = lin.x + dx
    vhat = []
    for b, bl in zip(problem.blocks, lin.blocks):
        e = bl.wbar + np.einsum("gck,gk->gc", bl.abar, dx[b.param_index])
        vhat.append(-np.einsum("goc,gc->go", bl.K, e))
    return x, vhat


def _refreshed(
    problem: _Problem, lin: _Lin, active: list[NDArray[np.bool_]], rounds: int = 3
) -> _Lin | None:
    """The linearisation at ``lin.x`` with the residuals of Gauss-Helmert blocks re-solved at
    fixed parameters (a few fixed-point rounds of ``v = -S B' Pe (g - B v)``), whose cost is
    the true cost at ``x``; None without Gauss-Helmert blocks or on non-finite values."""
    if all(b.gauss_markov for b in problem.blocks):
        return None
    for _ in range(rounds):
        vhat = [-np.einsum("goc,gc->go", bl.K, bl.wbar) for bl in lin.blocks]
        try:
            lin = problem.linearize(lin.x, vhat, active)
        except _NonFiniteError:
            return None
    return lin


def _merit(lin: _Lin, nrm_rowscale: Array | None, nu: float) -> float:
    if nrm_rowscale is None or lin.h.size == 0:
        return lin.phi
    return lin.phi + nu * float(np.abs(nrm_rowscale * lin.h).sum())


def _run(
    problem: _Problem,
    x0: Array,
    vhat0: list[Array],
    active: list[NDArray[np.bool_]],
    opts: AdjustmentOptions,
    progress: _Progress,
    should_stop: Callable[[], bool] | None,
    initial: bool,
) -> _Run:
    """One adjustment from ``x0`` with the given groups active."""
    try:
        lin = problem.linearize(x0.copy(), vhat0, active)
    except _NonFiniteError as exc:
        state = "initial values" if initial else "current estimate"
        raise AdjustmentError(f"{exc} at the {state}; check the approximate values") from None
    rowscale: Array | None = None
    use_sparse: bool | None = opts.sparse
    tol = opts.tolerance
    lam_memory = 0.0
    lam_good = _LAMBDA_START  # the last positive damping that reduced the cost
    nu_lm = 2.0  # growth factor of the damping after rejected steps (Nielsen 1999)
    # Damping below which Gauss-Newton is tried again; lowered after each rejected
    # Gauss-Newton step (nearly singular directions, e.g. points far away, need a little
    # damping all the way).
    lam_floor = _LAMBDA_MIN
    nu = 0.0
    prev_step = math.inf
    converged = False
    warnings: list[str] = []
    it = 0
    nrm: _Normal | None = None
    for it in range(1, opts.max_iterations + 1):
        stop_if_asked(should_stop, "adjusting")
        progress((it - 1) / opts.max_iterations)
        nrm, rowscale = problem.normal(lin, active, rowscale)
        if isinstance(nrm, ReducedNormal):
            use_sparse = nrm.use_sparse
        elif use_sparse is None:
            n = problem.n
            use_sparse = n > _SPARSE_AUTO_MIN_N and nrm.Ns.nnz <= _SPARSE_AUTO_MAX_DENSITY * n * n
        if it == 1:
            _check_observability(
                nrm, problem.names, opts.condition_limit, problem.constraint_labels()
            )
        def gauss_newton(nrm=nrm, use_sparse=use_sparse) -> tuple[Array, Array]:
            try:
                return _solve(nrm, 0.0, use_sparse)
            except _SingularError:
                _check_observability(
                    nrm, problem.names, opts.condition_limit, problem.constraint_labels()
                )
                raise AdjustmentError("the normal equations could not be solved") from None

        # While damping is still needed the Gauss-Newton step is not solved for (it would be
        # rejected); it is solved again once the damping has shrunk back to zero, or when no
        # damped step reduces the cost (to tell convergence from a stall).
        if opts.damping and lam_memory > 0:
            z = None
            step = math.inf
        else:
            z, k = gauss_newton()
            step = float(np.abs(z).max()) if z.size else 0.0
            if k.size:
                # Exact-penalty weight above the Lagrange multipliers of min ||.||^2 (= 2 k).
                nu = max(nu, 2.5 * float(np.abs(k).max()))
        if step <= tol:
            x, vhat = _apply(problem, lin, nrm, z)
            try:
                lin = problem.linearize(x, vhat, active)
            except _NonFiniteError as exc:
                raise ConvergenceError(f"{exc} after the final step") from None
            converged = True
            break
        m_old = _merit(lin, rowscale, nu)
        if not opts.damping:
            x, vhat = _apply(problem, lin, nrm, z)
            try:
                new = problem.linearize(x, vhat, active)
            except _NonFiniteError as exc:
                raise ConvergenceError(
                    f"Gauss-Newton diverged: {exc} at iteration {it}; try damping=True"
                ) from None
        else:
            new = None
            # Start from the damping that last worked (0: Gauss-Newton): in a long curved
            # valley (e.g. focal length against flying height) the accepted damping then
            # shrinks by ten per step and the steps grow back to Gauss-Newton, instead of
            # crawling at the smallest damping after every rejected Gauss-Newton step.
            lam = lam_memory
            while True:
                if lam > 0:
                    try:
                        z_try, _ = _solve(nrm, lam, use_sparse)
                    except _SingularError:
                        z_try = None
                else:
                    z_try = z
                if z_try is not None:
                    x, vhat = _apply(problem, lin, nrm, z_try)
                    try:
                        cand = problem.linearize(x, vhat, active)
                    except _NonFiniteError:
                        cand = None
                    # Ties at rounding level are accepted: the cost cannot go lower.
                    m_try = _merit(cand, rowscale, nu) if cand is not None else math.inf
                    if m_try <= m_old * (1 + 1e-13):
                        new = cand
                        factor = 0.1
                        if lam > 0:
                            lam_good = lam
                            # Nielsen's update from the gain ratio: the damping shrinks
                            # little when the quadratic model predicted the decrease badly
                            pred = lam * float(z_try @ z_try) - float(nrm.ns @ z_try)
                            if pred > 0:
                                rho = (m_old - m_try) / pred
                                if rho < 0.9:
                                    factor = max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
                        nu_lm = 2.0
                        lam_memory = lam * factor if lam * factor >= lam_floor else 0.0
                        if lam > 0 and float(np.abs(z_try).max(initial=0.0)) <= math.sqrt(tol):
                            # near the optimum: let the Gauss-Newton step test convergence
                            lam_memory = 0.0
                        break
                # after a rejected Gauss-Newton step go back to the damping that last worked
                if lam == 0:
                    lam = lam_good
                    lam_floor = max(lam_floor * 1e-2, 1e-14)
                else:
                    lam *= nu_lm
                    nu_lm *= 2.0
                if lam > _LAMBDA_MAX:
                    break
            if new is None and z is None:
                z, k = gauss_newton()
                step = float(np.abs(z).max()) if z.size else 0.0
            if new is None:
                if step <= math.sqrt(tol):
                    converged = True
                    break
                fresh = _refreshed(problem, lin, active)
                if fresh is not None and _merit(fresh, rowscale, nu) > m_old * (1 + 1e-12):
                    # The Gauss-Helmert cost of this linearisation (residuals predicted by the
                    # last step) sat below the true cost at x: continue from the consistent one.
                    lin = fresh
                    continue
                warnings.append(
                    _t(
                        "the cost could not be reduced further at iteration {iteration} (step "
                        "{step:.3g} sigma): stopped without convergence",
                        iteration=it,
                        step=step,
                    )
                )
                break
        m_new = _merit(new, rowscale, nu)
        lin = new
        # Rounding floor (large parameter values): the cost no longer changes and the step
        # has stopped shrinking although it is above tolerance.
        if (
            abs(m_old - m_new) <= tol * max(m_old, 1e-300)
            and step <= math.sqrt(tol)
            and step >= 0.5 * prev_step
        ):
            converged = True
            break
        prev_step = step
    if not converged and it >= opts.max_iterations:
        warnings.append(
            _t("no convergence within {n} iterations", n=opts.max_iterations)
        )
    # Final normal equations at the final linearisation point, checked before use.
    nrm, _ = problem.normal(lin, active, rowscale)
    if use_sparse is None:
        use_sparse = False
    return _Run(lin, nrm, it, converged, bool(use_sparse), warnings)


# ----------------------------------------------------------------------------- statistics


def _residual_tables(
    problem: _Problem,
    lin: _Lin,
    active: list[NDArray[np.bool_]],
    qgg: Callable[[int, NDArray[np.intp]], Array] | None,
    sigma0_prior: float,
) -> dict[str, ResidualTable]:
    """Residuals and their tests; ``qgg(block, groups)`` gives the groups' Qxx blocks."""
    tables: dict[str, ResidualTable] = {}
    for bi, (b, bl, a) in enumerate(zip(problem.blocks, lin.blocks, active)):
        g, o = b.groups, b.o
        # Zero-step residuals: for Gauss-Markov f(x) - l, for Gauss-Helmert the v that
        # satisfies the conditions linearised at the final point.
        v = -np.einsum("goc,gc->go", bl.K, bl.wbar)
        w = np.full((g, o), np.nan)
        red = np.full((g, o), np.nan)
        for lo in range(0, g if qgg is not None else 0, _RESIDUAL_CHUNK):
            sel = np.arange(lo, min(g, lo + _RESIDUAL_CHUNK))
            ab, K, ac = bl.abar[sel], bl.K[sel], a[sel]
            S = ab @ qgg(bi, sel) @ np.swapaxes(ab, 1, 2)
            eye = np.eye(S.shape[1])
            # Kept groups: Q_ww = Pe^-1 - A Qxx A'; rejected: prediction, Pe^-1 + A Qxx A'.
            inner = np.where(ac[:, None, None], eye - S, eye + S)
            Qvv = K @ inner @ np.swapaxes(K, 1, 2)
            P = b.weight[sel]
            r = np.einsum("gij,gji->gi", Qvv, P)
            pqp = np.einsum("gij,gjk,gki->gi", P, Qvv, P)
            Pv = np.einsum("gij,gj->gi", P, v[sel])
            with np.errstate(invalid="ignore", divide="ignore"):
                ws = Pv / (sigma0_prior * np.sqrt(np.where(pqp > 0, pqp, np.nan)))
            untestable = ac[:, None] & (r < _REDUNDANCY_EPS)
            w[sel] = np.where(untestable, np.nan, ws)
            red[sel] = np.where(ac[:, None], r, np.nan)
        tables[b.name] = ResidualTable(
            labels=list(b.labels),
            row_names=list(b.row_names),
            observed=b.observed.copy(),
            v=v,
            w=w,
            redundancy_numbers=red,
            rejected=~a.copy(),
        )
    return tables


def _global_test(omega: float, r: int, sigma0_prior: float, alpha: float) -> ChiSquareTest:
    t = omega / sigma0_prior**2
    if r <= 0:
        return ChiSquareTest(t, int(r), math.nan, math.nan, math.nan, True, alpha)
    lo = float(stats.chi2.ppf(alpha / 2, r))
    hi = float(stats.chi2.ppf(1 - alpha / 2, r))
    p = float(min(1.0, 2 * min(stats.chi2.cdf(t, r), stats.chi2.sf(t, r))))
    return ChiSquareTest(t, int(r), lo, hi, p, bool(lo <= t <= hi), alpha)


def _finish(
    problem: _Problem,
    run: _Run,
    active: list[NDArray[np.bool_]],
    opts: AdjustmentOptions,
    want_cov: bool,
) -> AdjustmentResult:
    """Statistics at the end of a run (checks observability at the final point first)."""
    nrm = run.nrm
    cond = _check_observability(
        nrm, problem.names, opts.condition_limit, problem.constraint_labels()
    )
    n = problem.n
    Q = None
    blocks = None
    qd = None
    qgg = None
    if want_cov and isinstance(nrm, ReducedNormal):
        try:
            blocks = nrm.cofactor()
        except (np.linalg.LinAlgError, RuntimeError, _SingularError):
            raise AdjustmentError("the cofactor matrix could not be computed") from None
        qd = np.clip(blocks.diagonal(), 0.0, None)
        qgg = blocks.group_blocks
    elif want_cov:
        try:
            Qs = _scaled_cofactor(nrm, run.use_sparse)
        except (np.linalg.LinAlgError, RuntimeError, _SingularError):
            raise AdjustmentError("the cofactor matrix could not be computed") from None
        Q = Qs / np.outer(nrm.d, nrm.d)
        qd = np.clip(np.diag(Q), 0.0, None)

        def qgg(bi: int, sel: NDArray[np.intp], Q: Array = Q) -> Array:
            idx = problem.blocks[bi].param_index[sel]
            return Q[idx[:, :, None], idx[:, None, :]]
    omega = run.lin.phi
    mc = problem.constraint_rows()
    m = problem.rows(active)
    r = m - n + mc
    sigma0 = math.sqrt(omega / r) if r > 0 else math.nan
    s0p = opts.sigma0_prior
    warnings = list(run.warnings)
    if r == 0:
        warnings.append(_t("no redundancy: sigma0 and the global test are undefined"))
    cov = cov_prior = corr = None
    std = np.full(n, np.nan)
    std_prior = np.full(n, np.nan)
    if qd is not None:
        std_prior = s0p * np.sqrt(qd)
        std = sigma0 * np.sqrt(qd) if r > 0 else np.full(n, np.nan)
    if Q is not None:
        cov_prior = s0p**2 * Q
        cov = sigma0**2 * Q if r > 0 else np.full_like(Q, np.nan)
        sq = np.sqrt(qd)
        with np.errstate(invalid="ignore", divide="ignore"):
            # Parameters fixed exactly by constraints have no correlation (NaN).
            corr = Q / np.outer(sq, sq)
        tiny = sq <= np.sqrt(np.finfo(float).tiny)
        corr[tiny, :] = np.nan
        corr[:, tiny] = np.nan
        corr = np.clip(corr, -1.0, 1.0)
    residuals = _residual_tables(problem, run.lin, active, qgg, s0p)
    return AdjustmentResult(
        x=run.lin.x.copy(),
        names=list(problem.names),
        iterations=run.iterations,
        converged=run.converged,
        omega=omega,
        redundancy=int(r),
        sigma0=sigma0,
        sigma0_prior=s0p,
        global_test=_global_test(omega, r, s0p, opts.alpha),
        cofactor=Q,
        covariance=cov,
        covariance_prior=cov_prior,
        std=std,
        std_prior=std_prior,
        correlation=corr,
        condition_number=float(cond),
        residuals=residuals,
        warnings=warnings,
        solver="sparse" if run.use_sparse else "dense",
        n_observations=int(m),
        n_constraints=int(mc),
        cofactor_blocks=blocks,
    )


def _worst(
    result: AdjustmentResult, blocks: Sequence[str] | None = None
) -> tuple[int, int, int, float] | None:
    """(block number, group, row, w) of the largest |w| among the groups kept (of the named
    blocks only, when given)."""
    best = None
    for bi, (name, table) in enumerate(result.residuals.items()):
        if blocks is not None and name not in blocks:
            continue
        w = np.where(table.rejected[:, None], np.nan, np.abs(table.w))
        if w.size == 0 or not np.isfinite(w).any():
            continue
        flat = int(np.nanargmax(w))
        g, i = np.unravel_index(flat, w.shape)
        if best is None or w[g, i] > best[3]:
            best = (bi, int(g), int(i), float(w[g, i]))
    return best


def _cascade(
    problem: _Problem, active: list[NDArray[np.bool_]]
) -> tuple[list[NDArray[np.bool_]], list[tuple[int, int]]]:
    """With eliminated blocks: an eliminated block (an object point) left with fewer rows
    than parameters by the groups set aside cannot be determined; its remaining groups are set
    aside with it (a tie point of two rays goes when one ray is rejected). Returns the new
    active masks and the (block, group) pairs this added."""
    plan = problem.plan
    if plan is None:
        return active, []
    rows = plan.rows_per_block([b.c for b in problem.blocks], active)
    seen = plan.rows_per_block([b.c for b in problem.blocks], None)
    dead = (rows < plan.b) & (seen > 0)
    if not dead.any():
        return active, []
    out, gone = [], []
    for bi, (a, bp) in enumerate(zip(active, plan.plans)):
        hit = a & (bp.point >= 0) & dead[np.maximum(bp.point, 0)]
        gone += [(bi, int(g)) for g in np.flatnonzero(hit)]
        out.append(a & ~hit)
    return out, gone


def _robust(
    problem: _Problem,
    x: Array,
    vhat: list[Array],
    active: list[NDArray[np.bool_]],
    opts: AdjustmentOptions,
    crit: float,
    reporter: _Progress,
    should_stop: Callable[[], bool] | None,
) -> tuple[Array, list[Array], list[NDArray[np.bool_]], dict]:
    """Iteratively reweighted least squares (see the module docstring).

    Returns the robust estimate, its residual estimates, the groups flagged (standardised
    misfit above ``crit``) and a summary (tuning constant, rounds, scale, misfits per row).
    """
    k = opts.robust_k if opts.robust_k is not None else _ROBUST_K[opts.robust]
    if not k > 0:
        raise InputError(f"robust_k must be > 0, got {k}")
    blocks = problem.blocks
    weights = [np.ones(b.groups) for b in blocks]
    if opts.robust_blocks is None:
        chosen = list(range(len(blocks)))
    else:
        known = [b.name for b in blocks]
        unknown = sorted(set(opts.robust_blocks) - set(known))
        if unknown:
            raise InputError(f"robust_blocks: unknown block(s) {', '.join(unknown)}")
        chosen = [i for i, b in enumerate(blocks) if b.name in opts.robust_blocks]
    # Scale from the observation blocks proper (a-priori parameter values have tiny misfits
    # that would drag the median down); all chosen blocks when there are no others.
    scale_blocks = [i for i in chosen if not isinstance(blocks[i].func, _PriorModel)]
    if not scale_blocks:
        scale_blocks = chosen
    rounds = 0
    scale = 1.0
    u_rows: list[Array] = []
    try:
        for rounds in range(1, opts.robust_iterations + 1):
            problem.weights = weights
            # The first round converges from the approximate values; later rounds start at
            # the previous estimate and take a few steps each (the weights and the estimate
            # converge together).
            short = replace(opts, max_iterations=min(4, opts.max_iterations))
            inner = opts if rounds == 1 else short
            run = _run(problem, x, vhat, active, inner, reporter, should_stop,
                       initial=rounds == 1)  # fmt: skip
            x, vhat = run.lin.x, run.lin.vhat
            # Unweighted whitened misclosures at the estimate (the linearisation holds them
            # multiplied by sqrt(weight)).
            u_rows = [bl.wbar / np.sqrt(w)[:, None] for bl, w in zip(run.lin.blocks, weights)]
            u = [np.sqrt(np.sum(r * r, axis=1) / r.shape[1]) for r in u_rows]
            ref = [math.sqrt(stats.chi2.ppf(0.5, b.c) / b.c) for b in blocks]
            pool = np.concatenate(
                [u[i][active[i]] / ref[i] for i in scale_blocks] or [np.zeros(0)]
            )
            scale = float(np.median(pool)) if pool.size else 1.0
            # never below the a-priori unit weight: measurements that fit as well as their
            # stated sigmas (or better, when those are pessimistic) are not outliers, the same
            # reference as data snooping's
            scale = max(scale, 1.0) if np.isfinite(scale) else 1.0
            new = []
            for i, ui in enumerate(u):
                t = ui / (k * scale)
                if i not in chosen:
                    new.append(np.ones_like(ui))
                elif opts.robust == "huber":
                    new.append(np.where(t <= 1.0, 1.0, 1.0 / np.where(t > 0, t, 1.0)))
                else:
                    new.append(1.0 / (1.0 + t * t))
            change = max((float(np.max(np.abs(a - b))) for a, b in zip(new, weights) if a.size),
                         default=0.0)  # fmt: skip
            weights = new
            if change < 1e-2:
                break
    finally:
        problem.weights = None
    flagged = [
        a & (np.sqrt(np.sum(r * r, axis=1) / r.shape[1]) / scale > crit) & (i in chosen)
        for i, (r, a) in enumerate(zip(u_rows, active))
    ]
    u_std = [r / scale for r in u_rows]
    return x, vhat, flagged, {"k": k, "rounds": rounds, "scale": scale, "u": u_std}


# ----------------------------------------------------------------------------- entry point


def adjust(
    x0: ArrayLike,
    names: Sequence[str],
    blocks: Sequence[Block],
    constraints: Sequence[Constraint] = (),
    options: AdjustmentOptions | None = None,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> AdjustmentResult:
    """Weighted non-linear least-squares adjustment (see the module docstring for the method).

    Parameters
    ----------
    x0 : ndarray, shape (n,)
        Approximate values of the parameters.
    names : sequence of str, shape (n,)
        Unique parameter names (used in reports and error messages).
    blocks : sequence of GaussMarkovBlock or GaussHelmertBlock
        Observations, with unique block names.
    constraints : sequence of Constraint
        Hard constraints ``h(x) = 0``.
    options : AdjustmentOptions, optional
        Defaults to ``AdjustmentOptions()``.
    progress : callable, optional
        ``progress(fraction)`` with a non-decreasing fraction in [0, 1], once per iteration.
    should_stop : callable, optional
        Polled once per iteration; when it returns True, :class:`errors.Cancelled` is raised.

    Returns
    -------
    AdjustmentResult

    Raises
    ------
    InputError
        Inconsistent shapes, names or sigmas.
    NotObservableError
        The normal equations are singular or worse conditioned than ``condition_limit``.
    AdjustmentError
        A model gave non-finite values at the approximate values, dependent constraints, ...
    ConvergenceError
        Plain Gauss-Newton (``damping=False``) diverged to non-finite values.
    Cancelled
        ``should_stop()`` returned True.
    """
    opts = options if options is not None else AdjustmentOptions()
    x = np.array(x0, dtype=np.float64).ravel()
    n = x.size
    name_list = [str(s) for s in names]
    if n == 0:
        raise InputError("the adjustment has no parameters")
    if len(name_list) != n:
        raise InputError(f"{len(name_list)} names for {n} parameters")
    if len(set(name_list)) != n:
        dup = sorted({s for s in name_list if name_list.count(s) > 1})
        raise InputError(f"duplicate parameter names: {', '.join(dup)}")
    if not np.isfinite(x).all():
        raise InputError("x0 contains NaN or inf")
    if opts.max_iterations < 1 or not opts.tolerance > 0 or not opts.sigma0_prior > 0:
        raise InputError("max_iterations >= 1, tolerance > 0 and sigma0_prior > 0 are required")
    obs = [_prepare_block(b, n, name_list) for b in blocks]
    bnames = [b.name for b in obs]
    if len(set(bnames)) != len(bnames):
        raise InputError(f"duplicate block names: {', '.join(bnames)}")
    if not obs:
        raise InputError("the adjustment has no observations")
    cons = []
    for c in constraints:
        where = f"constraint '{c.name}'"
        idx = _as_index(c.param_index, n, where)
        labels = _labels(c.labels, idx.shape[0], lambda i, nm=c.name: f"{nm}[{i}]", where, "labels")
        cons.append(_Con(c.name, idx, c.function, labels, None))
    plan = None
    if opts.eliminate is not None:
        plan = EliminationPlan(n, opts.eliminate, obs, [c.param_index for c in cons])
    problem = _Problem(name_list, obs, cons, plan)
    if opts.robust not in ("none", *_ROBUST_K):
        raise InputError(f"robust must be none, huber or cauchy, got {opts.robust!r}")

    reporter = _Progress(progress)
    want_cov = opts.compute_covariance or opts.snooping
    active = [np.ones(b.groups, dtype=bool) for b in obs]
    vhat = [np.zeros((b.groups, b.o)) for b in obs]
    crit = float(stats.norm.ppf(1 - opts.snooping_alpha / 2))
    rejected: list[RejectedObservation] = []
    extra_warnings: list[str] = []
    robust_text = ""
    initial = True
    robust_run, ok = None, False
    if opts.robust != "none":
        reporter.span(0.0, 0.3)
        x, vhat, flagged, rob = _robust(problem, x, vhat, active, opts, crit, reporter,
                                        should_stop)  # fmt: skip
        initial = False
        robust_text = _t(
            "{method} reweighting (k = {k:g} robust scale units, {rounds} rounds, robust scale "
            "{scale:.3g}), groups with a standardised misfit above {critical:.2f} set aside",
            method=opts.robust.capitalize(),
            k=rob["k"],
            rounds=rob["rounds"],
            scale=rob["scale"],
            critical=crit,
        )
        trial = [a & ~f for a, f in zip(active, flagged)]
        trial, gone = _cascade(problem, trial)
        try:  # the adjustment without the flagged groups: kept as the final run below
            robust_run = _run(problem, x, vhat, trial, opts, reporter, should_stop,
                              initial=False)  # fmt: skip
            ok = True
        except NotObservableError:
            ok = False
            extra_warnings.append(
                _t(
                    "robust estimation: setting aside the {n} groups it flagged would leave the "
                    "adjustment not observable; they are kept",
                    n=int(sum(f.sum() for f in flagged)),
                )
            )
        if ok:
            for bj, gj in gone:
                flagged[bj][gj] = True
            for bi, f in enumerate(flagged):
                for g in np.flatnonzero(f):
                    u = rob["u"][bi][g]
                    rejected.append(
                        RejectedObservation(obs[bi].name, obs[bi].labels[g],
                                            obs[bi].row_names[int(np.argmax(np.abs(u)))],
                                            float(u[int(np.argmax(np.abs(u)))]), 0)
                    )  # fmt: skip
            active = trial
    if opts.snooping:
        reporter.span(0.3 if opts.robust != "none" else 0.0, 0.5)
    elif opts.robust != "none":
        reporter.span(0.3, 1.0)
    if robust_run is not None and ok:
        run = robust_run  # the same adjustment (same start, same active groups): not again
    else:
        run = _run(problem, x, vhat, active, opts, reporter, should_stop, initial=initial)
    result = _finish(problem, run, active, opts, want_cov)
    if not opts.snooping:
        result.outlier_method = (
            _t("{robust}; no data snooping", robust=robust_text)
            if robust_text
            else _t("none (data snooping disabled)")
        )
        result.rejected = rejected
        result.warnings.extend(extra_warnings)
        reporter.span(0.0, 1.0)
        reporter(1.0)
        return result

    if not result.converged:
        extra_warnings.append(_t("data snooping skipped: the adjustment did not converge"))
    else:
        round_no = 0
        while True:
            worst = _worst(result, opts.snooping_blocks)
            if worst is None or worst[3] <= crit:
                break
            if len(rejected) >= opts.max_rejections:
                extra_warnings.append(
                    _t(
                        "data snooping stopped at max_rejections = {n} with |w| = {w:.2f} "
                        "still above {critical:.2f}",
                        n=opts.max_rejections,
                        w=worst[3],
                        critical=crit,
                    )
                )
                break
            round_no += 1
            bi, g, i, wv = worst
            b = obs[bi]
            lo = 1.0 - 0.5**round_no
            reporter.span(lo, lo + 0.5 ** (round_no + 1))
            trial = [a.copy() for a in active]
            trial[bi][g] = False
            trial, gone = _cascade(problem, trial)
            try:
                new_run = _run(
                    problem,
                    result.x,
                    run.lin.vhat,
                    trial,
                    opts,
                    reporter,
                    should_stop,
                    initial=False,
                )
                new_result = _finish(problem, new_run, trial, opts, want_cov)
            except NotObservableError:
                extra_warnings.append(
                    _t(
                        "data snooping stopped: rejecting {block} / {label} (|w| = {w:.2f}) "
                        "would make the adjustment not observable; it is kept",
                        block=b.name,
                        label=b.labels[g],
                        w=wv,
                    )
                )
                break
            if not new_run.converged:
                extra_warnings.append(
                    _t(
                        "data snooping stopped: without {block} / {label} the adjustment did "
                        "not converge; it is kept",
                        block=b.name,
                        label=b.labels[g],
                    )
                )
                break
            signed = float(result.residuals[b.name].w[g, i])
            rejected.append(
                RejectedObservation(b.name, b.labels[g], b.row_names[i], signed, round_no)
            )
            for bj, gj in gone:
                lab = obs[bj].labels[gj]
                rejected.append(
                    RejectedObservation(obs[bj].name, lab, "(with its point)", math.nan, round_no)
                )
            active, run, result = trial, new_run, new_result
        untested = sum(
            int((np.isnan(t.w) & ~t.rejected[:, None]).sum()) for t in result.residuals.values()
        )
        if untested:
            extra_warnings.append(
                _t(
                    "{n} observation rows have a redundancy number of about zero and cannot "
                    "be tested by data snooping",
                    n=untested,
                )
            )
    result.outlier_method = (
        _t(
            "Baarda data snooping (alpha = {alpha:g} per observation, critical |w| = "
            "{critical:.2f}, iterative rejection of whole groups)",
            alpha=opts.snooping_alpha,
            critical=crit,
        )
    )
    if robust_text:
        result.outlier_method = _t(
            "{robust}, then {snooping}", robust=robust_text, snooping=result.outlier_method
        )
    result.rejected = rejected
    result.warnings.extend(extra_warnings)
    reporter.span(0.0, 1.0)
    reporter(1.0)
    return result
