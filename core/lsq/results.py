"""What a least-squares adjustment returns: estimates, covariance, statistics, residuals,
the global test and the rejected observations (:mod:`.adjustment` describes the method)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .schur import BlockCofactor

Array = NDArray[np.float64]


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
            f"iterations ({self.solver} solver)",
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
