"""The statistics of the accuracy report (:mod:`.accuracy`): per component and group, the
Shapiro-Wilk normality test, Student's t test of a zero mean, the chi-square test of a declared
precision, and the screening of outliers (robust modified z-score or three sigma).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import cast

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from .accuracy_options import OUTLIER_RULES

__all__ = [
    "BiasTest",
    "ComponentStatistics",
    "GroupStatistics",
    "NormalityTest",
    "OutlierScreen",
    "PrecisionTest",
    "bias_test",
    "component_statistics",
    "group_statistics",
    "normality_test",
    "precision_test",
    "screen_outliers",
]

#: Components of the discrepancies (docs/formats.md "Accuracy figures"): east, north, up
#: (the height, column h of the tables), then the derived horizontal and 3D lengths.
COMPONENTS = ("E", "N", "U")
HORIZONTAL, THREE_D = "HORIZONTAL", "3D"

_ROBUST_THRESHOLD = 3.5  # Iglewicz & Hoaglin (1993)
_SIGMA_THRESHOLD = 3.0


@dataclass(frozen=True)
class NormalityTest:
    """Shapiro-Wilk: ``normal`` is True when H0 (normal) is not rejected at ``alpha``."""

    statistic: float
    p_value: float
    alpha: float
    normal: bool | None
    message: str


@dataclass(frozen=True)
class BiasTest:
    """Student's t test of H0: mean = 0 (two-sided); ``biased`` True when H0 is rejected."""

    t: float
    critical: float
    p_value: float
    dof: int
    alpha: float
    biased: bool | None
    message: str


@dataclass(frozen=True)
class PrecisionTest:
    """Chi-square test of H0: sigma <= sigma0; ``accepted`` True when s is compatible."""

    sigma0: float
    s: float
    chi2: float
    critical: float
    p_value: float
    dof: int
    alpha: float
    accepted: bool | None
    message: str


def normality_test(x: NDArray[np.float64], alpha: float = 0.05) -> NormalityTest:
    """Shapiro-Wilk test of one component (scipy.stats.shapiro), n >= 3.

    Examples
    --------
    >>> t = normality_test(np.array([148, 154, 158, 160, 161, 162, 166, 170, 182, 195, 236.0]))
    >>> round(t.statistic, 2), t.normal
    (0.79, False)
    """
    from scipy import stats

    x = np.asarray(x, dtype=np.float64)
    if x.size < 3:
        return NormalityTest(
            math.nan, math.nan, alpha, None, f"needs at least 3 points, has {x.size}"
        )
    if np.ptp(x) == 0.0:
        return NormalityTest(math.nan, math.nan, alpha, None, "all values are equal")
    w, p = stats.shapiro(x)
    normal = bool(p > alpha)
    return NormalityTest(
        float(w),
        float(p),
        alpha,
        normal,
        f"W = {w:.4f}, p = {p:.4f} {'>' if normal else '<='} {alpha:g}: "
        + ("normality not rejected" if normal else "normality rejected"),
    )


def bias_test(x: NDArray[np.float64], alpha: float = 0.05) -> BiasTest:
    """Student's t test of a zero mean: ``t = mean / (s / sqrt(n))``, dof n - 1.

    Examples
    --------
    >>> b = bias_test(np.array([0.1, 0.2, 0.3]))
    >>> round(b.t, 4), round(b.critical, 3), b.biased
    (3.4641, 4.303, False)
    """
    from scipy import stats

    x = np.asarray(x, dtype=np.float64)
    n = x.size
    if n < 2:
        return BiasTest(
            math.nan, math.nan, math.nan, 0, alpha, None, f"needs at least 2 points, has {n}"
        )
    mean = float(x.mean())
    s = float(x.std(ddof=1))
    dof = n - 1
    crit = float(stats.t.ppf(1.0 - alpha / 2.0, dof))
    if s == 0.0:
        t = math.inf if mean != 0.0 else 0.0
        p = 0.0 if mean != 0.0 else 1.0
    else:
        t = mean / (s / math.sqrt(n))
        p = float(2.0 * stats.t.sf(abs(t), dof))
    biased = bool(abs(t) > crit)
    return BiasTest(
        t,
        crit,
        p,
        dof,
        alpha,
        biased,
        f"|t| = {abs(t):.3f} {'>' if biased else '<='} t({1 - alpha / 2:g}, {dof}) = {crit:.3f}, "
        f"p = {p:.4f}: " + ("mean differs from zero (bias)" if biased else "no significant bias"),
    )


def precision_test(x: NDArray[np.float64], sigma0: float, alpha: float = 0.05) -> PrecisionTest:
    """Chi-square test of the standard deviation against a declared ``sigma0`` (one-sided).

    ``chi2 = (n - 1) s^2 / sigma0^2`` compared with ``chi2_{1-alpha}(n - 1)``.

    Examples
    --------
    >>> p = precision_test(np.array([0.1, -0.1, 0.2, -0.2]), 0.2)
    >>> round(p.chi2, 4), p.accepted
    (2.5, True)
    """
    from scipy import stats

    x = np.asarray(x, dtype=np.float64)
    n = x.size
    if not (math.isfinite(sigma0) and sigma0 > 0):
        raise InputError(f"the declared precision must be positive, got {sigma0}")
    if n < 2:
        return PrecisionTest(
            sigma0,
            math.nan,
            math.nan,
            math.nan,
            math.nan,
            0,
            alpha,
            None,
            f"needs 2 points, has {n}",
        )
    s = float(x.std(ddof=1))
    dof = n - 1
    chi2 = dof * s**2 / sigma0**2
    crit = float(stats.chi2.ppf(1.0 - alpha, dof))
    p = float(stats.chi2.sf(chi2, dof))
    ok = bool(chi2 <= crit)
    return PrecisionTest(
        sigma0,
        s,
        chi2,
        crit,
        p,
        dof,
        alpha,
        ok,
        f"chi2 = {chi2:.3f} {'<=' if ok else '>'} chi2({1 - alpha:g}, {dof}) = {crit:.3f}: "
        + (
            f"s = {s:.3f} m compatible with {sigma0:g} m"
            if ok
            else f"s = {s:.3f} m worse than {sigma0:g} m"
        ),
    )


# ----------------------------------------------------------------------------- statistics


@dataclass(frozen=True)
class ComponentStatistics:
    """Summary of one component (E, N, H) or of a resultant (horizontal, 3D), metres."""

    name: str
    n: int
    mean: float
    std: float
    rmse: float
    minimum: float
    maximum: float
    normality: NormalityTest | None = None
    bias: BiasTest | None = None
    precision: PrecisionTest | None = None


@dataclass(frozen=True)
class GroupStatistics:
    """Statistics of one group (or of all points): E, N, H, horizontal and 3D."""

    name: str
    n: int
    components: dict[str, ComponentStatistics]

    @property
    def rmse(self) -> dict[str, float]:
        return {k: v.rmse for k, v in self.components.items()}


def component_statistics(
    x: NDArray[np.float64],
    name: str,
    *,
    alpha: float = 0.05,
    sigma0: float | None = None,
    tests: bool = True,
) -> ComponentStatistics:
    """Mean, standard deviation (n - 1), RMSE, min, max and, with ``tests``, the three tests.

    Examples
    --------
    >>> c = component_statistics(np.array([0.3, -0.4]), "E", tests=False)
    >>> round(c.rmse, 4), round(c.mean, 2)
    (0.3536, -0.05)
    """
    x = np.asarray(x, dtype=np.float64)
    n = x.size
    if n == 0:
        return ComponentStatistics(name, 0, math.nan, math.nan, math.nan, math.nan, math.nan)
    return ComponentStatistics(
        name,
        n,
        float(x.mean()),
        float(x.std(ddof=1)) if n > 1 else math.nan,
        float(np.sqrt(np.mean(x * x))),
        float(x.min()),
        float(x.max()),
        normality_test(x, alpha) if tests else None,
        bias_test(x, alpha) if tests else None,
        precision_test(x, sigma0, alpha) if tests and sigma0 else None,
    )


def group_statistics(
    d: NDArray[np.float64],
    name: str,
    *,
    alpha: float = 0.05,
    declared_sigma: Sequence[float] = (0.0, 0.0, 0.0),
) -> GroupStatistics:
    """Statistics of discrepancies ``d`` (N, 3): E, N, H with tests, horizontal and 3D."""
    d = np.asarray(d, dtype=np.float64).reshape(-1, 3)
    comps = {
        c: component_statistics(d[:, k], c, alpha=alpha, sigma0=declared_sigma[k] or None)
        for k, c in enumerate(COMPONENTS)
    }
    comps[HORIZONTAL] = component_statistics(np.hypot(d[:, 0], d[:, 1]), HORIZONTAL, tests=False)
    comps[THREE_D] = component_statistics(np.linalg.norm(d, axis=1), THREE_D, tests=False)
    return GroupStatistics(name, len(d), comps)


@dataclass(frozen=True)
class OutlierScreen:
    """Outlier flags: ``scores`` and ``flags`` (N, 3) per component, ``any`` (N,)."""

    rule: str
    threshold: float
    description: str
    scores: NDArray[np.float64]
    flags: NDArray[np.bool_]

    @property
    def any(self) -> NDArray[np.bool_]:
        return cast(NDArray[np.bool_], self.flags.any(axis=1))  # an array along an axis


def screen_outliers(d: NDArray[np.float64], rule: str = "robust") -> OutlierScreen:
    """Flag outlying discrepancies per component.

    ``robust``: modified z-score ``0.6745 (x - median) / MAD`` beyond 3.5 (Iglewicz &
    Hoaglin 1993; with MAD = 0 the mean absolute deviation times 1.2533 stands in);
    ``three_sigma``: ``|x - mean| / s`` beyond 3 (the outliers inflate s, so this rule misses
    them in small samples); ``none``: nothing flagged.

    Examples
    --------
    >>> d = np.zeros((10, 3)); d[:, 0] = np.linspace(-0.1, 0.1, 10); d[3, 0] = 5.0
    >>> screen_outliers(d).any.nonzero()[0].tolist()
    [3]
    """
    d = np.asarray(d, dtype=np.float64).reshape(-1, 3)
    rule = (rule or "none").strip().lower().replace("-", "_")
    if rule not in OUTLIER_RULES:
        raise InputError(f"unknown outlier rule '{rule}' ({', '.join(OUTLIER_RULES)})")
    if rule == "none" or len(d) < 3:
        zeros = np.zeros_like(d)
        return OutlierScreen(rule, math.inf, "no outlier screening", zeros, zeros.astype(bool))
    with np.errstate(divide="ignore", invalid="ignore"):
        if rule == "robust":
            med = np.median(d, axis=0)
            mad = np.median(np.abs(d - med), axis=0)
            mean_ad = np.mean(np.abs(d - med), axis=0)
            scale = np.where(mad > 0, mad / 0.6745, 1.2533 * mean_ad)
            scores = np.where(scale > 0, (d - med) / scale, 0.0)
            threshold = _ROBUST_THRESHOLD
            text = "robust modified z-score |0.6745 (x - median) / MAD| > 3.5 (Iglewicz & Hoaglin)"
        else:
            s = d.std(axis=0, ddof=1)
            scores = np.where(s > 0, (d - d.mean(axis=0)) / s, 0.0)
            threshold = _SIGMA_THRESHOLD
            text = "three sigma |x - mean| > 3 s"
    flags = np.abs(scores) > threshold
    return OutlierScreen(rule, threshold, text, scores, flags)
