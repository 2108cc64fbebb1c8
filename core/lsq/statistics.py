"""The statistics at the end of an adjustment run: cofactor and covariance matrices, sigma0 and
the global chi-square test, the residuals with their redundancy numbers and Baarda's
standardised residuals (see :mod:`.adjustment`).
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np
from numpy.typing import NDArray
from scipy import special

from ..errors import AdjustmentError
from ..i18n import mark as _t
from .model import AdjustmentOptions
from .observability import _check_observability
from .problem import _Lin, _Obs, _Problem, _structured_times
from .results import AdjustmentResult, ChiSquareTest, ResidualTable
from .schur import ReducedNormal, SingularSystem
from .solve import _Run, _scaled_cofactor

#: catalogue context of this module's ``_t("...")`` sentences (``make i18n``): the reports'
TR_CONTEXT = "Report"

Array = NDArray[np.float64]

# Redundancy numbers below this are "zero": the residual is not testable (w is NaN).
_REDUNDANCY_EPS = 1e-9
# Groups per chunk when the standardised residuals are computed (bounds the k x k cofactor
# blocks held at once).
_RESIDUAL_CHUNK = 20000


def _block_times(b: _Obs, M: Array, sel: NDArray[np.intp]) -> Array:
    """``weight @ M`` for the groups ``sel`` of block ``b`` (M of shape (len(sel), o, n))."""
    if b.inv_sigma is not None:  # diagonal weights
        return (b.inv_sigma[sel] ** 2)[:, :, None] * M
    if b.sparse_rows is None:
        return b.weight[sel] @ M
    return _structured_times(b.weight[sel], b.sparse_rows, M)


def _coupled_rows(
    rows: NDArray[np.intp],
    K: Array,
    ab: Array,
    Q: Array,
    sign: Array,
    P: Array,
    r: Array,
    pqp: Array,
) -> None:
    """``diag(Qvv P)`` and ``diag(P Qvv P)`` of the coupled rows (a line's X0 and u, whose
    weights come from a covariance of rank 4 regularised by 1e-12: their products cancel to
    rounding) recomputed in place from the rows' own block of ``Qvv = K (I -+ ab Q ab') K'``,
    in the order of operations of the whole-matrix formula (only those rows' block is
    formed): so these rows' tests are as before, not the rounding of the factored form."""
    KX = K[:, rows]
    inner = np.eye(ab.shape[1]) + sign * (ab @ Q @ np.swapaxes(ab, 1, 2))
    QX = KX @ inner @ np.swapaxes(KX, 1, 2)
    PX = P[:, rows[:, None], rows[None, :]]
    r[:, rows] = np.einsum("gij,gji->gi", QX, PX)
    pqp[:, rows] = np.einsum("gij,gjk,gki->gi", PX, QX, PX)


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
            abt = np.swapaxes(ab, 1, 2)
            Q = qgg(bi, sel)
            # Kept groups: Q_ww = Pe^-1 - A Qxx A'; rejected: prediction, Pe^-1 + A Qxx A'.
            # Qvv = K (I -+ ab Q ab') K' is never formed (o x o per group): with
            # G = K (I -+ ab Q ab') and PK = P K, diag(Qvv P) = rowsum(G * PK) and
            # diag(P Qvv P) = rowsum(P G * PK), P symmetric.
            sign = np.where(ac, -1.0, 1.0)[:, None, None]
            P = b.weight[sel]
            PK = _block_times(b, K, sel)
            G = K + sign * (((K @ ab) @ Q) @ abt)
            PG = PK + sign * (((PK @ ab) @ Q) @ abt)
            r = np.einsum("gil,gil->gi", G, PK)
            pqp = np.einsum("gil,gil->gi", PG, PK)
            if b.sparse_rows is not None:
                _coupled_rows(b.sparse_rows[1], K, ab, Q, sign, P, r, pqp)
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


def chi2_ppf(q: float, r: float) -> float:
    """Quantile ``q`` of the chi-square distribution with ``r`` degrees of freedom
    (``scipy.stats.chi2.ppf``'s formula, from scipy.special: scipy.stats takes about a second
    to import)."""
    return float(2.0 * special.gammaincinv(r / 2.0, q))


def _global_test(omega: float, r: int, sigma0_prior: float, alpha: float) -> ChiSquareTest:
    t = omega / sigma0_prior**2
    if r <= 0:
        return ChiSquareTest(t, int(r), math.nan, math.nan, math.nan, True, alpha)
    lo = chi2_ppf(alpha / 2, r)
    hi = chi2_ppf(1 - alpha / 2, r)
    p = float(min(1.0, 2 * min(special.chdtr(r, t), special.chdtrc(r, t))))
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
        except (np.linalg.LinAlgError, RuntimeError, SingularSystem):
            raise AdjustmentError("the cofactor matrix could not be computed") from None
        qd = np.clip(blocks.diagonal(), 0.0, None)
        qgg = blocks.group_blocks
    elif want_cov:
        try:
            Qs = _scaled_cofactor(nrm, run.use_sparse)
        except (np.linalg.LinAlgError, RuntimeError, SingularSystem):
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
        termination=run.termination,
        trace=list(run.trace),
    )
