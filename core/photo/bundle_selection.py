"""The automatic selection of additional parameters (APs): which AP may be dropped, judged
with its correlations.

A correlation alone is never a reason to drop a parameter: on a strong convergent network
the radial terms k1, k2, k3 correlate at 0.9 and more and are all significant. An AP is a
candidate for dropping only when its own t-test (value over its a-posteriori standard
deviation, against Student's t with the redundancy as degrees of freedom; the test of
``x_j = 0`` with every other parameter free) finds it insignificant. When other insignificant
APs of the same camera correlate with it above ``max_correlation``, the correlation may hide
a common signal (each term alone insignificant, the group not): the group is tested jointly,
``F = x_G' C_GG^-1 x_G / |G|`` against Fisher's F with (|G|, redundancy) degrees of freedom
(``C`` the a-posteriori covariance), and the AP is kept when the group is significant. The
selection drops the droppable AP with the smallest t, re-adjusts and decides again, so the
other members of a group are tested anew without it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

from ..i18n import mark as _t

#: catalogue context of this module's ``_t("...")`` sentences (``make i18n``): the reports'
TR_CONTEXT = "Report"


@dataclass(frozen=True)
class ApDecision:
    """The significance decision of one free AP of one camera.

    Attributes
    ----------
    camera : int
        Camera number (order of the run's cameras).
    position : int
        Position of the AP among the camera's interior parameters (``interior_names``).
    name : str
    t, t_critical : float
        Its t statistic and the two-sided critical value.
    group : tuple of str
        The other insignificant APs correlated with it above the limit (tested jointly).
    F, F_critical : float
        The joint test of the AP and ``group`` (NaN without a group).
    drop : bool
        Insignificant alone and, with a group, jointly.
    reason : str
        The decision with its statistics (for the report).
    """

    camera: int
    position: int
    name: str
    t: float
    t_critical: float
    group: tuple[str, ...]
    F: float
    F_critical: float
    drop: bool
    reason: str


def _joint_f(x: np.ndarray, cov: np.ndarray) -> float:
    """``x' C^-1 x / k`` (NaN when C is singular or not finite)."""
    if not np.isfinite(cov).all():
        return math.nan
    try:
        return float(x @ np.linalg.solve(cov, x)) / x.size
    except np.linalg.LinAlgError:
        return math.nan


def ap_decisions(
    result, interior, free, cameras, alpha: float, max_correlation: float
) -> list[ApDecision]:
    """The decision for every free AP of every camera (see the module docstring).

    ``result`` is the :class:`~lidarphoto.core.lsq.results.AdjustmentResult`; ``interior[c]``
    the parameter indices of camera ``c``'s free interior parameters, ``free[c]`` their
    positions among its interior parameters (``>= 3``: an AP), ``cameras[c]`` the camera.
    """
    r = max(int(result.redundancy), 1)
    tcrit = float(stats.t.ppf(1 - alpha / 2, r))
    out: list[ApDecision] = []
    for c, cam in enumerate(cameras):
        idx = np.asarray(interior[c], dtype=np.intp)
        pos = np.asarray(free[c], dtype=np.intp)
        if not idx.size:
            continue
        names = cam.interior_names
        x = result.x[idx]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.abs(x) / result.std[idx]
        corr = result.correlation_of(idx)
        aps = [k for k in range(idx.size) if pos[k] >= 3]
        weak = [k for k in aps if t[k] <= tcrit]  # NaN (no covariance) is never weak
        for k in aps:
            nm = names[pos[k]]
            if not t[k] <= tcrit:
                reason = (
                    _t("significant (t = {t:.2f} > {critical:.2f})", t=t[k], critical=tcrit)
                    if np.isfinite(t[k])
                    else _t("not tested (no standard deviation)")
                )
                out.append(
                    ApDecision(
                        c,
                        int(pos[k]),
                        nm,
                        float(t[k]),
                        tcrit,
                        (),
                        math.nan,
                        math.nan,
                        False,
                        reason,
                    )
                )
                continue
            group = [j for j in weak if j != k and abs(corr[k, j]) > max_correlation]
            gnames = tuple(names[pos[j]] for j in group)
            if not group:
                reason = _t(
                    "insignificant (t = {t:.2f} <= {critical:.2f}, alpha {alpha:g})",
                    t=t[k],
                    critical=tcrit,
                    alpha=alpha,
                )
                out.append(
                    ApDecision(
                        c, int(pos[k]), nm, float(t[k]), tcrit, (), math.nan, math.nan, True, reason
                    )
                )
                continue
            sel = np.array([k, *group])
            f = _joint_f(x[sel], result.covariance_of(idx[sel]))
            fcrit = float(stats.f.ppf(1 - alpha, sel.size, r))
            others = ", ".join(gnames)
            drop = bool(f <= fcrit)  # NaN: kept
            joint = {"t": t[k], "critical": tcrit, "others": others, "f": f, "fcritical": fcrit}
            if drop:
                reason = _t(
                    "insignificant (t = {t:.2f} <= {critical:.2f}, alpha {alpha:g}), also "
                    "jointly with {others} (F = {f:.2f} <= {fcritical:.2f})",
                    alpha=alpha,
                    **joint,
                )
            else:
                reason = _t(
                    "kept: insignificant alone (t = {t:.2f} <= {critical:.2f}) but jointly "
                    "significant with {others} (F = {f:.2f} > {fcritical:.2f})",
                    **joint,
                )
            out.append(
                ApDecision(c, int(pos[k]), nm, float(t[k]), tcrit, gnames, f, fcrit, drop, reason)
            )
    return out


def drop_candidate(decisions: list[ApDecision]) -> ApDecision | None:
    """The droppable AP with the smallest t (over every camera), or None."""
    droppable = [d for d in decisions if d.drop]
    return min(droppable, key=lambda d: d.t) if droppable else None
