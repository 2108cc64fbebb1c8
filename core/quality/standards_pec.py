"""The Brazilian PEC-PCD (Decreto 89.817 and the ET-ADGV / ET-CQDG): planimetric and
altimetric classes A-D at a map scale (sources: :mod:`.standards`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from .accuracy_options import PEC_CLASSES
from .html_table import TR_CONTEXT  # noqa: F401 - make i18n collects the _t("...") marks
from .standards import _TOL, StandardResult, Verdict, _check_d, _count_verdict, _rmse, _t

__all__ = [
    "PEC_CLASSES",
    "pec_pcd",
    "pec_pcd_limits",
]

#: PEC-PCD (ET-ADGV/ET-CQDG): planimetric PEC and EP in millimetres at the map scale and
#: altimetric PEC and EP as fractions of the equidistance (contour interval), classes A-D.
_PEC_PLANIMETRIC_MM = {"A": (0.28, 0.17), "B": (0.5, 0.3), "C": (0.8, 0.5), "D": (1.0, 0.6)}
_PEC_ALTIMETRIC_EQ = {
    "A": (0.27, 1.0 / 6.0),
    "B": (0.50, 1.0 / 3.0),
    "C": (0.60, 2.0 / 5.0),
    "D": (0.75, 1.0 / 2.0),
}
#: Equidistance (m) of the Brazilian systematic and large-scale mapping for each scale, used
#: when the user gives none (ET-ADGV tables; 1:25 000 and smaller are the classic series).
PEC_DEFAULT_EQUIDISTANCE_M = {
    500: 0.5,
    1000: 1.0,
    2000: 1.0,
    5000: 2.0,
    10000: 5.0,
    25000: 10.0,
    50000: 20.0,
    100000: 50.0,
    250000: 100.0,
}
PEC_FRACTION = 0.90  # Decreto 89.817 art. 8: 90 % of the points within the PEC
PEC_RECOMMENDED_MIN_POINTS = 20  # common practice, not in the Decreto (uncertain)


def _equidistance(scale: float, equidistance: float | None) -> float | None:
    if not (math.isfinite(float(scale)) and float(scale) > 0):
        raise InputError(f"the PEC-PCD scale denominator must be positive, got {scale}")
    if equidistance is not None and not (math.isfinite(equidistance) and equidistance >= 0):
        raise InputError(f"the equidistance must be positive, got {equidistance}")
    if equidistance:
        return float(equidistance)
    return PEC_DEFAULT_EQUIDISTANCE_M.get(round(float(scale)))


def pec_pcd_limits(scale: float, equidistance: float | None = None) -> dict[str, dict[str, float]]:
    """PEC and EP (m) of classes A-D for a map scale ``1:scale`` and an equidistance (m).

    Returns ``{"A": {"pec_h", "ep_h", "pec_v", "ep_v"}, ...}``; the altimetric values are
    NaN when no equidistance is known (none given and the scale is not in
    ``PEC_DEFAULT_EQUIDISTANCE_M``).

    Examples
    --------
    >>> lim = pec_pcd_limits(1000)
    >>> lim["A"]["pec_h"], lim["A"]["ep_h"], lim["B"]["pec_v"]
    (0.28, 0.17, 0.5)
    """
    eq = _equidistance(scale, equidistance)
    scale = float(scale)
    out = {}
    for c in PEC_CLASSES:
        pec_mm, ep_mm = _PEC_PLANIMETRIC_MM[c]
        pec_f, ep_f = _PEC_ALTIMETRIC_EQ[c]
        out[c] = {
            "pec_h": round(pec_mm * scale / 1000.0, 9),
            "ep_h": round(ep_mm * scale / 1000.0, 9),
            "pec_v": pec_f * eq if eq else math.nan,
            "ep_v": ep_f * eq if eq else math.nan,
        }
    return out


def _class_verdict(name: str, share: float, n: int, rms: float, pec: float, ep: float) -> Verdict:
    """One class: met when ``share`` (of the n discrepancies) within its PEC is >= 90 % and
    the RMS (m) within its EP (m). The Decreto sets no minimum sample: the class verdict
    stands, the count verdict warns when the sample is small."""
    ok90 = share >= PEC_FRACTION
    ok_ep = rms <= ep + _TOL
    reason = _t(
        "{share:.1f} % of {n} points within PEC {pec:.3f} m ({share_relation} 90 %); "
        "RMS {rms:.3f} m {rms_relation} EP {ep:.3f} m",
        share=100 * share,
        n=n,
        pec=pec,
        share_relation=">=" if ok90 else "<",
        rms=rms,
        rms_relation="<=" if ok_ep else ">",
        ep=ep,
    )
    return Verdict(name, "pass" if ok90 and ok_ep else "fail", reason, rms, ep)


def _declared(verdicts: list[Verdict], target: str) -> list[Verdict]:
    """The declared class's verdicts (planimetric, altimetric): those of class ``target``."""
    out = []
    for kind in ("planimetric", "altimetric"):
        v = next(x for x in verdicts if x.name == f"Class {target} {kind}")
        out.append(
            Verdict(
                (
                    _t("Declared class {cls} (planimetric)", cls=target)
                    if kind == "planimetric"
                    else _t("Declared class {cls} (altimetric)", cls=target)
                ),
                v.status,
                v.reason,
                v.measured,
                v.limit,
            )
        )
    return out


def pec_pcd(
    d: NDArray[np.float64],
    *,
    scale: float,
    equidistance: float | None = None,
    target_class: str = "A",
) -> StandardResult:
    """Brazilian PEC-PCD (Decreto 89.817/1984 with the ET-ADGV/ET-CQDG classes A-D).

    A class is met when at least 90 % of the discrepancies are within its PEC and the RMS
    error does not exceed its standard error EP (Decreto 89.817 art. 8-9: PEC = 1.6449 EP,
    "erro-padrão, desvio-padrão e erro médio quadrático" taken as equivalent). Planimetry
    uses the resultant ``sqrt(dE^2 + dN^2)`` and its RMS (as ET-CQDG; some authors test each
    axis against EP/sqrt(2) instead); altimetry uses ``|dH|``. The Decreto sets no minimum
    number of points (ET-CQDG sizes samples by lot, ABNT NBR 5425/5426): fewer than 20 points
    is flagged ``insufficient`` by common practice (uncertain), the classes still computed.

    Parameters
    ----------
    d : (N, 3) float
        Discrepancies (m).
    scale : float
        Scale denominator (1:scale).
    equidistance : float, optional
        Contour interval (m) for the altimetric classes; default from the scale's series.
    target_class : {"A", "B", "C", "D"}
        The class the product is declared as; its verdict is the overall one.

    Returns
    -------
    StandardResult

    Examples
    --------
    >>> d = np.zeros((20, 3)); d[:, 0] = 0.1
    >>> [v.status for v in pec_pcd(d, scale=1000).verdicts[1:5]]
    ['pass', 'pass', 'pass', 'pass']
    """
    d = _check_d(d)
    target = str(target_class).strip().upper()
    if target not in PEC_CLASSES:
        raise InputError(f"unknown PEC-PCD class '{target_class}' (A, B, C or D)")
    n = len(d)
    limits = pec_pcd_limits(scale, equidistance)
    horiz = np.hypot(d[:, 0], d[:, 1])
    vert = np.abs(d[:, 2])
    rms_h, rms_v = _rmse(horiz), _rmse(vert)
    verdicts = [
        _count_verdict(
            n,
            PEC_RECOMMENDED_MIN_POINTS,
            _t(
                "{n} check points; fewer than {minimum} makes the 90 % rule weak (common "
                "practice, not in the Decreto)",
                n=n,
                minimum=PEC_RECOMMENDED_MIN_POINTS,
            ),
        )
    ]
    figures: dict[str, float] = {"RMSE_HORIZONTAL": rms_h, "RMSE_U": rms_v}
    best: dict[str, str | None] = {"planimetric": None, "altimetric": None}
    for kind, values, rms, pk, ek in (
        ("planimetric", horiz, rms_h, "pec_h", "ep_h"),
        ("altimetric", vert, rms_v, "pec_v", "ep_v"),
    ):
        for c in PEC_CLASSES:
            pec, ep = limits[c][pk], limits[c][ek]
            name = (
                _t("Class {cls} planimetric", cls=c)
                if kind == "planimetric"
                else _t("Class {cls} altimetric", cls=c)
            )
            if not math.isfinite(pec):
                verdicts.append(
                    Verdict(name, "info", _t("no equidistance given for this scale"), None, None)
                )
                continue
            share = float(np.mean(values <= pec + _TOL))
            verdict = _class_verdict(name, share, n, rms, pec, ep)
            if verdict.status == "pass" and best[kind] is None:
                best[kind] = c
            verdicts.append(verdict)
            figures[f"{kind}_{c}_share_within_pec"] = share
    eq = _equidistance(scale, equidistance)
    figures["equidistance"] = eq if eq else math.nan
    none = _t("none")
    notes = [
        _t(
            "Scale 1:{scale:,.0f}; equidistance {equidistance}. Best class met: planimetric "
            "{planimetric}, altimetric {altimetric}.",
            scale=float(scale),
            equidistance=_t("{value:g} m", value=eq) if eq else _t("not given"),
            planimetric=best["planimetric"] or none,
            altimetric=best["altimetric"] or none,
        ),
        _t(
            "PEC-PCD limits: planimetric A-D 0.28/0.5/0.8/1.0 mm (EP 0.17/0.3/0.5/0.6 mm) at "
            "the map scale; altimetric A-D 0.27/0.50/0.60/0.75 of the equidistance (EP 1/6, "
            "1/3, 2/5, 1/2)."
        ),
    ]
    verdicts += _declared(verdicts, target)
    return StandardResult(
        key="pec",
        title=_t("PEC-PCD (Decreto 89.817 / ET-CQDG), 1:{scale:,.0f}", scale=float(scale)),
        reference=(
            "Decreto 89.817 de 20/06/1984, art. 8-9; PEC-PCD of the ET-ADGV (2011/2016) and "
            "ET-CQDG (2016), DSG - Exército Brasileiro"
        ),
        n_points=n,
        verdicts=tuple(verdicts),
        figures=figures,
        notes=tuple(notes),
    )
