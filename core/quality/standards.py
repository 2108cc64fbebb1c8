"""Positional accuracy standards: what they share. One module per standard: ASPRS Ed. 2 (2023)
(:mod:`.standards_asprs`), NSSDA (:mod:`.standards_nssda`), PEC-PCD (:mod:`.standards_pec`)
and the project threshold (:mod:`.standards_project`).

Every function takes the check-point discrepancies ``d`` (N, 3), metres, columns dE, dN, dU,
``d = measured - reference`` in one projected CRS, and returns a :class:`StandardResult`: one
:class:`Verdict` per class or condition with ``status`` ``"pass"``, ``"fail"``,
``"insufficient"`` (too few check points for the standard: the figures are still computed and
shown, the claim is not made) or ``"info"``, and the reason in words.

Sources (figures taken from the documents named; where a figure comes from a secondary source
or is our reading of the text it is marked *uncertain* here and in the report):

* ASPRS Positional Accuracy Standards for Digital Geospatial Data, Edition 2, Version 1.0
  (23 August 2023), section 7 (Table 7.1 horizontal classes "#-cm" with RMSE_H <= #;
  vertical classes "#-cm" with NVA RMSE_V <= #; the check-point survey error added in
  quadrature; three-dimensional accuracy RMSE_3D = sqrt(RMSE_H^2 + RMSE_V^2); at least 30
  check points, at most 120 for large projects; no 95 % confidence figures any more). The
  list of changes from Edition 1 is confirmed by the ASPRS announcement (GPS World,
  6 Dec 2023); the section/table numbers are from our reading of the standard (uncertain).
* FGDC-STD-007.3-1998, Geospatial Positioning Accuracy Standards Part 3: National Standard for
  Spatial Data Accuracy (NSSDA), section 3.2.1 (at least 20 check points) and Appendix 3-A
  (Accuracy_r = 1.7308 RMSE_r when RMSE_x = RMSE_y; 2.4477 * 0.5 (RMSE_x + RMSE_y) when
  0.6 <= RMSE_min / RMSE_max <= 1; Accuracy_z = 1.9600 RMSE_z; errors assumed normal,
  independent, without systematic error).
* Decreto 89.817 de 20/06/1984, art. 8-9 (PEC = 1.6449 EP; 90 % of well-defined points within
  the PEC; the standard error EP not exceeded) and the PEC-PCD of the ET-ADGV / ET-CQDG
  (DSG, Exército Brasileiro, 2011/2016): planimetric classes A-D 0.28/0.5/0.8/1.0 mm at the
  map scale with EP 0.17/0.3/0.5/0.6 mm; altimetric classes A-D 0.27/0.50/0.60/0.75 of the
  equidistance with EP 1/6, 1/3, 2/5, 1/2 of it.
* Project threshold: Pedrosa & dos Santos (2020), section 3, Eq. 18 and Tables 2-5 (0.40 m
  planimetric, twice the LiDAR standard deviation; dz = sqrt(2) H^2 / (B f) sigma_pix =
  0.48 m with H = 1600 m, B = 452 m, f = 100.4 mm, sigma_pix = 6 micrometres).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..i18n import Message
from .html_table import TR_CONTEXT  # noqa: F401 - make i18n collects the _t("...") marks

__all__ = ["StandardResult", "Verdict"]

# Limits are compared with 1e-9 m of slack so that a value equal to the limit (as printed)
# is not refused by the last bit of floating point: "not exceeding" includes equality.
_TOL = 1e-9


def _t(template: str, **values: object) -> Message:
    """Mark a text (a template with named placeholders) for translation (``make i18n``): the
    result is the English sentence and keeps the template and the values, so the results stay
    in English and the report renders them in the user's language."""
    return Message(template, **values)


@dataclass(frozen=True)
class Verdict:
    """One class or condition of a standard.

    ``measured`` and ``limit`` are in metres unless ``unit`` says otherwise.
    """

    name: str
    status: str
    reason: str
    measured: float | None = None
    limit: float | None = None
    unit: str = "m"


@dataclass(frozen=True)
class StandardResult:
    """The verdicts of one standard on one set of discrepancies."""

    key: str
    title: str
    reference: str
    n_points: int
    verdicts: tuple[Verdict, ...]
    figures: dict[str, float] = field(default_factory=dict)
    notes: tuple[str, ...] = ()

    @property
    def enough_points(self) -> bool:
        return not any(v.status == "insufficient" for v in self.verdicts)


def _check_d(d: NDArray[np.float64]) -> NDArray[np.float64]:
    d = np.asarray(d, dtype=np.float64)
    if d.ndim != 2 or d.shape[1] != 3:
        raise InputError(f"discrepancies must have shape (N, 3), got {d.shape}")
    if not np.all(np.isfinite(d)):
        raise InputError("discrepancies contain NaN or infinite values")
    return d


def _rmse(x: NDArray[np.float64]) -> float:
    return float(np.sqrt(np.mean(np.square(x)))) if x.size else math.nan


def _count_verdict(n: int, minimum: int, reason: str) -> Verdict:
    """The check-point count condition of a standard: ``n`` points, at least ``minimum``
    wanted (``reason`` says the standard's rule); short of it, "insufficient"."""
    status = "pass" if n >= minimum else "insufficient"
    return Verdict(_t("Check-point count"), status, reason, float(n), float(minimum), unit="points")


def _status(ok: bool, enough: bool) -> str:
    if not enough:
        return "insufficient"
    return "pass" if ok else "fail"
