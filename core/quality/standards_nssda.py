"""The National Standard for Spatial Data Accuracy (FGDC-STD-007.3-1998): the 95 % accuracies
and the conditions of the standard's formulas (sources: :mod:`.standards`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from .html_table import TR_CONTEXT  # noqa: F401 - make i18n collects the _t("...") marks
from .standards import StandardResult, Verdict, _check_d, _count_verdict, _rmse, _t

__all__ = [
    "NSSDA_HORIZONTAL_FACTOR",
    "NSSDA_MIN_CHECKPOINTS",
    "NSSDA_RADIAL_FACTOR",
    "NSSDA_VERTICAL_FACTOR",
    "bivariate_radius",
    "nssda",
]

#: NSSDA (FGDC-STD-007.3-1998, Appendix 3-A) factors as printed in the standard.
NSSDA_HORIZONTAL_FACTOR = 2.4477  # sqrt(chi2_2(0.95)): 95 % radius of a circular normal / sigma
NSSDA_RADIAL_FACTOR = 1.7308  # 2.4477 / sqrt(2), applied to RMSE_r when RMSE_x = RMSE_y
NSSDA_VERTICAL_FACTOR = 1.9600  # two-sided 95 % point of the standard normal
NSSDA_MIN_CHECKPOINTS = 20


def bivariate_radius(sigma_x: float, sigma_y: float, probability: float = 0.95) -> float:
    """Radius holding ``probability`` of a zero-mean bivariate normal with independent axes.

    This is the quantity NSSDA approximates with 2.4477 * 0.5 (RMSE_x + RMSE_y); it is
    computed here exactly: with ``a >= b`` the two sigmas, ``P(r <= R) = int_-R^R phi(x / a) /
    a * erf(sqrt(R^2 - x^2) / (b sqrt 2)) dx``, integrated over ``x = R sin t`` (a smooth
    integrand, whatever the ratio b / a) and solved for R between the one-dimensional radius
    ``a z`` and ``a sqrt(-2 ln(1 - p))``, which bracket it. Any ratio of the sigmas works (a
    gross blunder in one axis gives b / a of 1e-8), tending to the one-dimensional radius.

    Parameters
    ----------
    sigma_x, sigma_y : float
        Standard deviations of the two axes (m), finite.
    probability : float
        Probability in (0, 1).

    Returns
    -------
    float
        Radius (m).

    Examples
    --------
    >>> round(bivariate_radius(1.0, 1.0), 4)  # circular case: sqrt(-2 ln 0.05)
    2.4477
    >>> round(bivariate_radius(1e6, 0.01), 1)  # a blunder on one axis: 1.96 a
    1959964.0
    """
    from scipy import integrate, optimize, stats

    a, b = sorted((abs(float(sigma_x)), abs(float(sigma_y))), reverse=True)
    if not (math.isfinite(a) and 0.0 < probability < 1.0):
        raise ValueError(f"bivariate_radius: sigmas must be finite, got {sigma_x}, {sigma_y}")
    if a == 0.0:
        return 0.0
    z = float(stats.norm.ppf(0.5 + probability / 2.0))
    rho = b / a
    if rho < 1e-9:  # the second axis changes the radius by about rho^2: one-dimensional
        return a * z
    scale = 1.0 / (rho * math.sqrt(2.0))

    def cdf(radius: float) -> float:
        def integrand(t: float) -> float:
            c = math.cos(t)
            return math.exp(-0.5 * (radius * math.sin(t)) ** 2) * math.erf(radius * c * scale) * c

        value, _ = integrate.quad(
            integrand, 0.0, 0.5 * math.pi, epsabs=1e-13, epsrel=1e-12, limit=200
        )
        return 2.0 * radius * value / math.sqrt(2.0 * math.pi)

    lo, hi = z, math.sqrt(-2.0 * math.log1p(-probability))
    f_lo, f_hi = cdf(lo) - probability, cdf(hi) - probability
    if f_lo >= 0.0:  # at the rounding level of the quadrature
        return a * lo
    if f_hi <= 0.0:
        return a * hi
    return a * float(optimize.brentq(lambda r: cdf(r) - probability, lo, hi, xtol=1e-13))


def nssda(
    d: NDArray[np.float64],
    *,
    normal: Sequence[bool | None] | None = None,
    biased: Sequence[bool | None] | None = None,
) -> StandardResult:
    """National Standard for Spatial Data Accuracy (FGDC-STD-007.3-1998).

    NSSDA sets no thresholds: it reports the accuracy at the 95 % confidence level,
    ``Accuracy_r`` (horizontal radius) and ``Accuracy_z = 1.9600 RMSE_z``. The verdicts are
    its conditions: at least 20 check points (section 3.2.1), errors normal and without
    systematic error (``normal``/``biased`` per component E, N, H from the Shapiro-Wilk and
    Student tests) and, for the horizontal formula, 0.6 <= RMSE_min/RMSE_max <= 1
    (Appendix 3-A, Case 2). Below 0.6 the standard's approximation does not hold and the
    exact 95 % radius of :func:`bivariate_radius` is reported instead.

    Parameters
    ----------
    d : (N, 3) float
        Discrepancies dE, dN, dU (m).
    normal, biased : sequence of 3 bool or None, optional
        Decisions of the normality and bias tests for E, N, H (None: not tested).

    Returns
    -------
    StandardResult

    Examples
    --------
    >>> d = np.tile([[0.1, 0.1, 0.1]], (20, 1))
    >>> round(nssda(d).figures["ACCURACY_U_95"], 4)
    0.196
    """
    d = _check_d(d)
    n = len(d)
    rmse_x, rmse_y, rmse_z = (_rmse(d[:, k]) for k in range(3))
    rmse_r = math.hypot(rmse_x, rmse_y)
    lo, hi = sorted((rmse_x, rmse_y))
    ratio = lo / hi if hi > 0 else 1.0
    acc_case1 = NSSDA_RADIAL_FACTOR * rmse_r
    acc_case2 = NSSDA_HORIZONTAL_FACTOR * 0.5 * (rmse_x + rmse_y)
    exact = bivariate_radius(rmse_x, rmse_y, 0.95)
    approx_ok = ratio >= 0.6
    acc_r = acc_case2 if approx_ok else exact
    acc_z = NSSDA_VERTICAL_FACTOR * rmse_z
    enough = n >= NSSDA_MIN_CHECKPOINTS
    verdicts = [
        _count_verdict(
            n,
            NSSDA_MIN_CHECKPOINTS,
            _t(
                "{n} check points; NSSDA requires at least {minimum}",
                n=n,
                minimum=NSSDA_MIN_CHECKPOINTS,
            ),
        ),
        Verdict(
            _t("Horizontal approximation condition"),
            "pass" if approx_ok else "fail",
            (
                _t(
                    "RMSE_min/RMSE_max = {ratio:.3f} >= 0.6: Accuracy_r = 2.4477 x 0.5 "
                    "(RMSE_x + RMSE_y)",
                    ratio=ratio,
                )
                if approx_ok
                else _t(
                    "RMSE_min/RMSE_max = {ratio:.3f} < 0.6: the NSSDA approximation does "
                    "not hold; exact 95 % radius used",
                    ratio=ratio,
                )
            ),
            ratio,
            0.6,
            unit="ratio",
        ),
    ]
    verdicts += _assumption_verdicts(normal, biased)
    tail = (
        ""
        if enough
        else _t(" (only {n} of {minimum} check points)", n=n, minimum=NSSDA_MIN_CHECKPOINTS)
    )
    verdicts.append(
        Verdict(
            _t("Horizontal accuracy (95 %)"),
            "info" if enough else "insufficient",
            _t(
                "Tested {value:.3f} m horizontal accuracy at 95 % confidence level{few}",
                value=acc_r,
                few=tail,
            ),
            acc_r,
            None,
        )
    )
    verdicts.append(
        Verdict(
            _t("Vertical accuracy (95 %)"),
            "info" if enough else "insufficient",
            _t(
                "Tested {value:.3f} m vertical accuracy at 95 % confidence level{few}",
                value=acc_z,
                few=tail,
            ),
            acc_z,
            None,
        )
    )
    return StandardResult(
        key="nssda",
        title="NSSDA (FGDC-STD-007.3-1998)",
        reference=(
            "FGDC-STD-007.3-1998 Geospatial Positioning Accuracy Standards, Part 3: National "
            "Standard for Spatial Data Accuracy, section 3.2 and Appendix 3-A"
        ),
        n_points=n,
        verdicts=tuple(verdicts),
        figures={
            # docs/formats.md "Accuracy figures": NSSDA symbol in the comment
            "RMSE_E": rmse_x,  # RMSE_x
            "RMSE_N": rmse_y,  # RMSE_y
            "RMSE_HORIZONTAL": rmse_r,  # RMSE_r
            "RMSE_U": rmse_z,  # RMSE_z
            "ratio_min_max": ratio,
            "ACCURACY_HORIZONTAL_95": acc_r,  # Accuracy_r
            "ACCURACY_HORIZONTAL_95_CASE1": acc_case1,
            "ACCURACY_HORIZONTAL_95_CASE2": acc_case2,
            "ACCURACY_HORIZONTAL_95_EXACT": exact,
            "ACCURACY_U_95": acc_z,  # Accuracy_z
        },
        notes=(
            _t(
                "Accuracy_r = 1.7308 RMSE_r holds for RMSE_x = RMSE_y; the Case 2 formula "
                "2.4477 x 0.5 (RMSE_x + RMSE_y) is used for 0.6 <= ratio <= 1; the exact 95 % "
                "radius of the bivariate normal is also given."
            ),
        ),
    )


def _assumption_verdicts(
    normal: Sequence[bool | None] | None, biased: Sequence[bool | None] | None
) -> list[Verdict]:
    """NSSDA's assumptions as verdicts: errors normal and without systematic error, from the
    decisions of the tests per component E, N, H (None: not tested)."""
    out: list[Verdict] = []
    names = ("E", "N", "U")
    for name, decisions, bad in (
        (_t("Assumption: normal distribution (Shapiro-Wilk)"), normal, False),
        (_t("Assumption: no systematic error (Student t)"), biased, True),
    ):
        if decisions is None:
            continue
        untested = [c for c, v in zip(names, decisions) if v is None]
        failed = [c for c, v in zip(names, decisions) if v is not None and bool(v) == bad]
        status = "fail" if failed else ("insufficient" if untested else "pass")
        reason = (
            _t("rejected for {components}", components=", ".join(failed))
            if failed
            else (
                _t("not testable for {components}", components=", ".join(untested))
                if untested
                else _t("accepted for E, N, H")
            )
        )
        out.append(Verdict(name, status, reason))
    return out
