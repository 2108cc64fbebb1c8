"""The table of the TLS additional parameters (:mod:`.aps` holds their design): names,
components, formulas, report units, and the named sets, in a module that imports no numerical
library, so that the calibration's options and its help read them without numpy
(tests/core/test_startup.py)."""

from __future__ import annotations

import math
from dataclasses import dataclass

ARCSEC = math.pi / (180.0 * 3600.0)
RANGE, HORIZONTAL, VERTICAL = 0, 1, 2


@dataclass(frozen=True)
class ApTerm:
    """One additional parameter.

    Attributes
    ----------
    name : str
        ``a0`` ... ``c3``.
    component : int
        0 range, 1 horizontal direction, 2 vertical angle.
    formula : str
        The correction it adds, e.g. ``"b1 sec(alpha)"``.
    cause : str
        The physical error it models.
    report_unit : str
        ``"mm"``, ``"ppm"`` or ``"arcsec"``.
    report_scale : float
        Internal value (m, 1 or rad) times this is the reported value.
    """

    name: str
    component: int
    formula: str
    cause: str
    report_unit: str
    report_scale: float


_MM, _PPM = 1000.0, 1e6
_AS = 1.0 / ARCSEC
AP_TERMS: dict[str, ApTerm] = {
    t.name: t
    for t in (
        ApTerm("a0", RANGE, "a0", "rangefinder offset", "mm", _MM),
        ApTerm("a1", RANGE, "a1 rho", "range scale error", "ppm", _PPM),
        ApTerm("a2", RANGE, "a2 sin(4 pi rho / U)", "cyclic range error (sine)", "mm", _MM),
        ApTerm("a3", RANGE, "a3 cos(4 pi rho / U)", "cyclic range error (cosine)", "mm", _MM),
        ApTerm("b1", HORIZONTAL, "b1 sec(alpha)", "collimation axis error", "arcsec", _AS),
        ApTerm("b2", HORIZONTAL, "b2 tan(alpha)", "trunnion axis error", "arcsec", _AS),
        ApTerm(
            "b3",
            HORIZONTAL,
            "b3 sin(theta)",
            "horizontal circle eccentricity (sine)",
            "arcsec",
            _AS,
        ),
        ApTerm(
            "b4",
            HORIZONTAL,
            "b4 cos(theta)",
            "horizontal circle eccentricity (cosine)",
            "arcsec",
            _AS,
        ),
        ApTerm(
            "b5",
            HORIZONTAL,
            "b5 sin(2 theta)",
            "non-orthogonality of the horizontal encoder (sine)",
            "arcsec",
            _AS,
        ),
        ApTerm(
            "b6",
            HORIZONTAL,
            "b6 cos(2 theta)",
            "non-orthogonality of the horizontal encoder (cosine)",
            "arcsec",
            _AS,
        ),
        ApTerm("c0", VERTICAL, "c0", "vertical circle index error", "arcsec", _AS),
        ApTerm("c1", VERTICAL, "c1 alpha", "vertical encoder scale error", "arcsec", _AS),
        ApTerm(
            "c2", VERTICAL, "c2 sin(alpha)", "vertical circle eccentricity (sine)", "arcsec", _AS
        ),
        ApTerm(
            "c3", VERTICAL, "c3 cos(alpha)", "vertical circle eccentricity (cosine)", "arcsec", _AS
        ),
    )
}

#: Named AP sets: none (registration only), the paper's four, Lichti's (2007) physical set.
AP_SETS: dict[str, tuple[str, ...]] = {
    "none": (),
    "paper": ("a0", "b1", "b2", "c0"),
    "extended": tuple(AP_TERMS),
}
