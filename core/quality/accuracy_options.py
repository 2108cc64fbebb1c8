"""The settings of the positional accuracy report (:mod:`.accuracy`) and the names its
choices take (standards, outlier rules, PEC classes), in a module that imports no numerical
library, so that the command line's help reads them without numpy (tests/core/test_startup.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..errors import InputError
from ..i18n import mark as _t

#: catalogue context of this module's ``_t("...")`` sentences (``make i18n``): the reports'
TR_CONTEXT = "Report"

#: The standards the report judges against (:mod:`.accuracy`).
STANDARD_KEYS = ("asprs", "nssda", "pec", "project")
#: Outlier screening rules (:func:`~.accuracy_statistics.screen_outliers`).
OUTLIER_RULES = ("robust", "three_sigma", "none")
#: PEC-PCD (ET-ADGV/ET-CQDG): planimetric PEC and EP in millimetres at the map scale and
#: altimetric PEC and EP as fractions of the equidistance (contour interval), classes A-D
#: (:mod:`.standards_pec`).
PEC_CLASSES = ("A", "B", "C", "D")
#: Paper 000 (Pedrosa & dos Santos 2020), section 3 (:mod:`.standards_project`).
PAPER_H_THRESHOLD_M = 0.40
PAPER_FLIGHT_GEOMETRY = (1600.0, 452.0, 100.4, 6.0)  # H (m), B (m), f (mm), sigma_pix (um)


@dataclass(frozen=True)
class AccuracySettings:
    """Everything the report depends on besides the points. Lengths in metres.

    ``declared_sigma_h`` / ``survey_sigma_h`` are per horizontal axis (E and N);
    ``flight_geometry`` is (H m, B m, f mm, sigma_pix um) for Eq. 18 of Pedrosa & dos Santos (2020).
    """

    alpha: float = 0.05
    declared_sigma_h: float = 0.0
    declared_sigma_v: float = 0.0
    survey_sigma_h: float = 0.0
    survey_sigma_v: float = 0.0
    outlier_rule: str = "robust"
    exclude_outliers: bool = False
    standards: tuple[str, ...] = STANDARD_KEYS
    asprs_h_class_cm: float = 0.0
    asprs_v_class_cm: float = 0.0
    pec_scale: float = 1000.0
    pec_equidistance: float = 0.0
    pec_class: str = "A"
    project_h_threshold: float = PAPER_H_THRESHOLD_M
    project_v_threshold: float = 0.0
    flight_geometry: tuple[float, float, float, float] = PAPER_FLIGHT_GEOMETRY
    title: str = _t("Positional accuracy report")

    def validated(self) -> AccuracySettings:
        if not (0.0 < self.alpha < 0.5):
            raise InputError(f"the significance level must be in (0, 0.5), got {self.alpha}")
        for name in (
            "declared_sigma_h",
            "declared_sigma_v",
            "survey_sigma_h",
            "survey_sigma_v",
            "asprs_h_class_cm",
            "asprs_v_class_cm",
            "pec_equidistance",
            "project_v_threshold",
        ):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise InputError(f"{name} must be zero or positive, got {value}")
        keys = tuple(k.strip().lower() for k in self.standards if k.strip())
        unknown = [k for k in keys if k not in STANDARD_KEYS]
        if unknown:
            raise InputError(f"unknown standard(s) {unknown} ({', '.join(STANDARD_KEYS)})")
        rule = self.outlier_rule.strip().lower().replace("-", "_")
        if rule not in OUTLIER_RULES:
            raise InputError(f"unknown outlier rule '{self.outlier_rule}'")
        return replace(self, standards=keys, outlier_rule=rule)
