"""What a least-squares adjustment returns: estimates, covariance, statistics, residuals,
the global test and the rejected observations (:mod:`.adjustment` describes the method), and
the check that the rejections are as few as the false alarms of data snooping explain
(:func:`rejection_test`).

Data snooping tests each row of every group kept with the w-test at ``alpha`` and rejects the
worst group while one row exceeds the critical value. When the model is right and there is no
blunder, a group of ``o`` independent rows is rejected with probability
``p = 1 - (1 - alpha)^o`` (at most, when its rows are correlated), so the number of false
rejections among ``n`` groups is a sum of binomials ``B(n_b, p_b)`` over the blocks (a
Poisson-binomial count). A number of rejections whose upper tail ``P(X >= k)`` is below
``level`` is not explained by false alarms: blunders by the handful, or a model that does not
fit the data, whose largest misfits snooping throws away until the rest passes the global
test. Such an adjustment's global test says nothing about the model: the rule flags it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..i18n import Message
from ..i18n import mark as _t
from .schur import BlockCofactor

Array = NDArray[np.float64]
TR_CONTEXT = "Report"


@dataclass
class ChiSquareTest:
    """Two-sided global test of the adjustment.

    Attributes
    ----------
    statistic : float
        ``Omega / sigma0_prior^2`` (``Omega = v'Pv``).
    dof : int
        Degrees of freedom (the redundancy).
    lower, upper : float
        Critical values ``chi2(alpha/2, dof)`` and ``chi2(1 - alpha/2, dof)`` (NaN if dof = 0).
    p_value : float
        Two-sided p-value (NaN if dof = 0).
    passed : bool
        ``lower <= statistic <= upper``; True when there is no redundancy to test.
    alpha : float
        Significance level.
    """

    statistic: float
    dof: int
    lower: float
    upper: float
    p_value: float
    passed: bool
    alpha: float = 0.05


@dataclass
class ResidualTable:
    """Residuals and their statistics for one block.

    Attributes
    ----------
    labels : list of str, shape (G,)
    row_names : list of str, shape (o,)
    observed : ndarray, shape (G, o)
        Observations ``l``.
    v : ndarray, shape (G, o)
        Residuals (adjusted minus observed), in the units of the observations. For rejected
        groups, the misfit predicted from the adjusted parameters.
    w : ndarray, shape (G, o)
        Baarda's standardised residuals (NaN where the redundancy number is about zero or the
        covariance was not computed). For rejected groups, the standardised prediction misfit.
    redundancy_numbers : ndarray, shape (G, o)
        ``diag(Qvv P)``, in [0, 1]; NaN for rejected groups.
    rejected : ndarray of bool, shape (G,)
    """

    labels: list[str]
    row_names: list[str]
    observed: Array
    v: Array
    w: Array
    redundancy_numbers: Array
    rejected: NDArray[np.bool_]


@dataclass
class RejectedObservation:
    """A group rejected by data snooping, identified by its worst row.

    Attributes
    ----------
    block, label, row_name : str
        Where it is.
    w : float
        Its standardised residual when it was rejected.
    iteration : int
        Snooping round (1 for the first rejection).
    """

    block: str
    label: str
    row_name: str
    w: float
    iteration: int


@dataclass
class AdjustmentResult:
    """Estimates and statistics of an adjustment (see the module docstring for the formulas).

    Attributes
    ----------
    x : ndarray, shape (n,)
        Adjusted parameters.
    names : list of str, shape (n,)
    iterations : int
        Linearisations of the last adjustment run.
    converged : bool
    termination : str
        Why the last run stopped: ``"step tolerance"``, ``"function tolerance"``,
        ``"gradient tolerance"``, ``"rounding floor"`` (converged; see
        :class:`AdjustmentOptions`), ``"iteration limit"`` or ``"no decrease"`` (not
        converged).
    trace : list of (int, float, float)
        Per iteration of the last run (0: the start): the iteration, ``v'Pv`` (over the
        groups kept, robust weights included) and the seconds since the run started.
    omega : float
        ``v'Pv`` over the groups kept.
    redundancy : int
        ``rows - n + constraint rows`` (rows of rejected groups excluded).
    sigma0, sigma0_prior : float
        A-posteriori ``sqrt(omega / redundancy)`` (NaN if the redundancy is 0) and a-priori.
    global_test : ChiSquareTest
    cofactor : ndarray, shape (n, n) or None
        ``Qxx``; None when the covariance was not computed.
    covariance, covariance_prior : ndarray, shape (n, n) or None
        ``sigma0^2 Qxx`` and ``sigma0_prior^2 Qxx``.
    std, std_prior : ndarray, shape (n,)
        Standard deviations from ``covariance`` and ``covariance_prior`` (NaN if unknown).
    correlation : ndarray, shape (n, n) or None
    condition_number : float
        Of the Jacobi-scaled normal matrix: eigenvalue ratio (dense analysis) or a 1-norm
        estimate (large sparse systems).
    residuals : dict of str to ResidualTable
    rejected : list of RejectedObservation
    warnings : list of str
    solver : str
        ``"dense"`` or ``"sparse"``.
    n_observations : int
        Condition rows of the groups kept.
    n_constraints : int
        Hard constraint rows.
    outlier_method : str
        How outliers were flagged.
    cofactor_blocks : BlockCofactor or None
        ``Qxx`` in blocks when parameter blocks were eliminated
        (:attr:`AdjustmentOptions.eliminate`); ``cofactor``, ``covariance`` and
        ``correlation`` are then None (use :meth:`covariance_of`).
    """

    x: Array
    names: list[str]
    iterations: int
    converged: bool
    omega: float
    redundancy: int
    sigma0: float
    sigma0_prior: float
    global_test: ChiSquareTest
    cofactor: Array | None
    covariance: Array | None
    covariance_prior: Array | None
    std: Array
    std_prior: Array
    correlation: Array | None
    condition_number: float
    residuals: dict[str, ResidualTable]
    rejected: list[RejectedObservation] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    solver: str = "dense"
    n_observations: int = 0
    n_constraints: int = 0
    outlier_method: str = "none"
    cofactor_blocks: BlockCofactor | None = None
    termination: str = ""
    trace: list[tuple[int, float, float]] = field(default_factory=list)

    def covariance_of(self, index: ArrayLike, prior: bool = False) -> Array:
        """Covariance matrix (k, k) of the parameters ``index`` (a posteriori sigma0, or the
        a-priori one with ``prior``); with eliminated blocks, the parameters must all be
        reduced ones or all belong to one block."""
        idx = np.asarray(index, dtype=np.intp).ravel()
        s2 = self.sigma0_prior**2 if prior else self.sigma0**2
        if self.cofactor is not None:
            return s2 * self.cofactor[np.ix_(idx, idx)]
        if self.cofactor_blocks is not None:
            return s2 * self.cofactor_blocks.block(idx)
        return np.full((idx.size, idx.size), np.nan)

    def correlation_of(self, index: ArrayLike) -> Array:
        """Correlation matrix (k, k) of the parameters ``index`` (see :meth:`covariance_of`)."""
        q = self.covariance_of(index, prior=True)
        s = np.sqrt(np.clip(np.diag(q), 0.0, None))
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.clip(q / np.outer(s, s), -1.0, 1.0)

    def parameter(self, name: str) -> tuple[float, float]:
        """Return ``(value, std)`` of the parameter called ``name`` (KeyError if unknown)."""
        try:
            i = self.names.index(name)
        except ValueError:
            raise KeyError(f"no parameter named {name!r}") from None
        return float(self.x[i]), float(self.std[i])

    def summary(self, max_parameters: int = 200) -> str:
        """Readable text report: test statistics, parameters, residual overview, rejections.

        Parameters
        ----------
        max_parameters : int
            Parameters listed in the table (the rest is counted, not listed).
        """
        t = self.global_test
        lines = [
            "Least-squares adjustment",
            f"  converged: {'yes' if self.converged else 'NO'} after {self.iterations} "
            f"iterations ({self.solver} solver; stopped by: {self.termination or '-'})",
            f"  observations (condition rows): {self.n_observations}, parameters: "
            f"{len(self.x)}, hard constraints: {self.n_constraints}, redundancy: "
            f"{self.redundancy}",
            f"  v'Pv = {self.omega:.6g}",
            f"  sigma0 a posteriori = {self.sigma0:.6g} (a priori {self.sigma0_prior:.6g})",
        ]
        if t.dof > 0:
            lines.append(
                f"  global chi-square test (two-sided, alpha = {t.alpha:g}): statistic "
                f"{t.statistic:.6g}, dof {t.dof}, accepted range [{t.lower:.6g}, "
                f"{t.upper:.6g}], p = {t.p_value:.4g} -> {'PASSED' if t.passed else 'FAILED'}"
            )
        else:
            lines.append("  global chi-square test: not possible (no redundancy)")
        lines.append(
            f"  condition number (Jacobi-scaled normal matrix): {self.condition_number:.3g}"
        )
        lines.append(f"  outlier detection: {self.outlier_method}")
        lines.append("")
        width = max([len("parameter")] + [len(s) for s in self.names[:max_parameters]])
        lines.append(f"  {'parameter':<{width}}  {'value':>18}  {'std':>12}")
        for name, value, s in zip(
            self.names[:max_parameters], self.x[:max_parameters], self.std[:max_parameters]
        ):
            lines.append(f"  {name:<{width}}  {value:>18.10g}  {s:>12.4g}")
        if len(self.names) > max_parameters:
            lines.append(f"  ... and {len(self.names) - max_parameters} more parameters")
        lines.append("")
        lines.append("  residuals per block (RMS of v per row; |w| max over rows kept)")
        for name, table in self.residuals.items():
            kept = ~table.rejected
            rms = (
                np.sqrt(np.mean(table.v[kept] ** 2, axis=0))
                if kept.any()
                else np.full(table.v.shape[1], np.nan)
            )
            parts = ", ".join(f"{r}: {x:.4g}" for r, x in zip(table.row_names, rms))
            head = f"  {name}: {len(table.labels)} groups, {int(table.rejected.sum())} rejected"
            wk = np.abs(table.w[kept])
            if wk.size and np.isfinite(wk).any():
                g, i = np.unravel_index(int(np.nanargmax(wk)), wk.shape)
                label = [lab for lab, k in zip(table.labels, kept) if k][g]
                head += f"; max |w| = {wk[g, i]:.3f} at {label} / {table.row_names[i]}"
            lines.append(head)
            lines.append(f"    RMS v: {parts}")
        if self.rejected:
            lines.append("")
            lines.append("  rejected by data snooping")
            for rej in self.rejected:
                lines.append(
                    f"    round {rej.iteration}: {rej.block} / {rej.label} / {rej.row_name}"
                    f"  w = {rej.w:.3f}"
                )
        if self.warnings:
            lines.append("")
            lines.append("  warnings")
            lines.extend(f"    - {w}" for w in self.warnings)
        return "\n".join(lines)


@dataclass(frozen=True)
class RejectionTest:
    """Whether data snooping rejected more groups than its false alarms explain (see the
    module text).

    Attributes
    ----------
    groups, rejected : int
        Observation groups tested (kept and rejected) and rejected.
    alpha : float
        Significance of snooping's w-test per row.
    level : float
        Significance of this test: rejections with ``P(X >= rejected) < level`` fail it.
    expected : float
        False rejections expected when the model is right.
    bound : int
        The most rejections the false alarms explain at ``level``.
    p_value : float
        ``P(X >= rejected)`` when the model is right.
    """

    groups: int
    rejected: int
    alpha: float
    level: float
    expected: float
    bound: int
    p_value: float

    @property
    def passed(self) -> bool:
        return self.rejected <= self.bound

    def message(self) -> Message:
        """One sentence (translatable) saying what the count means."""
        share = 100.0 * self.rejected / max(self.groups, 1)
        return _t(
            "data snooping rejected {k} of {n} observations ({share:.1f} %); its false alarms "
            "at alpha = {alpha:g} explain at most {bound} ({expected:.2g} expected, P({k} or "
            "more) = {p:.2g}): a model that does not fit the data (parameters missing?) or "
            "many blunders, and the global test of the rest does not show it",
            k=self.rejected,
            n=self.groups,
            share=share,
            alpha=self.alpha,
            bound=self.bound,
            expected=self.expected,
            p=self.p_value,
        )


def rejection_test(
    result: AdjustmentResult,
    alpha: float,
    level: float = 0.001,
    blocks: Sequence[str] | None = None,
) -> RejectionTest:
    """Test the number of groups ``result`` rejected (robust stage and data snooping) against
    the false alarms of a w-test at ``alpha`` per row (``level``: this test's significance;
    ``blocks``: the blocks snooping tested, default all).

    >>> from types import SimpleNamespace as NS
    >>> table = lambda n, k, o: NS(v=np.zeros((n, o)), rejected=np.arange(n) < k)
    >>> r = NS(residuals={"polar": table(162, 15, 3), "control": table(27, 0, 1)})
    >>> t = rejection_test(r, 0.001)
    >>> t.groups, t.rejected, t.bound, round(t.expected, 3), t.passed
    (189, 15, 4, 0.513, False)
    >>> f"{t.p_value:.2g}", rejection_test(
    ...     NS(residuals={"polar": table(162, 2, 3)}), 0.001).passed
    ('1.2e-17', True)
    """
    from scipy import stats  # here: scipy.stats takes seconds to import (QGIS start-up)

    counts = []
    for name, table in result.residuals.items():
        if blocks is not None and name not in blocks:
            continue
        n, o = np.shape(table.v)
        if n:
            counts.append((n, 1.0 - (1.0 - alpha) ** max(o, 1), int(np.sum(table.rejected))))
    groups = sum(c[0] for c in counts)
    k = sum(c[2] for c in counts)
    expected = sum(n * p for n, p, _ in counts)
    # the count distribution up to well past its mean (the tail beyond is far below level)
    top = max(k, math.ceil(expected + 12.0 * math.sqrt(expected) + 30.0))
    pmf = np.zeros(top + 1)
    pmf[0] = 1.0
    for n, p, _ in counts:
        pmf = np.convolve(pmf, stats.binom.pmf(np.arange(min(n, top) + 1), n, p))[: top + 1]
    upper = np.append(np.cumsum(pmf[::-1])[::-1][1:], 0.0)  # upper[b] = P(X > b)
    bound = int(np.argmax(upper < level)) if (upper < level).any() else top
    p_value = 1.0 if k == 0 else float(upper[k - 1])
    return RejectionTest(groups, k, float(alpha), float(level), float(expected), bound, p_value)


def unexplained_rejections(
    result: AdjustmentResult, alpha: float, level: float = 0.001
) -> RejectionTest | None:
    """The :func:`rejection_test` of ``result`` when it fails (more rejections than the false
    alarms of snooping at ``alpha`` per row explain), else None (also when nothing was
    rejected: then scipy is not imported)."""
    if not any(bool(np.any(t.rejected)) for t in result.residuals.values()):
        return None
    test = rejection_test(result, alpha, level)
    return None if test.passed else test
