"""``accuracyreport``: positional accuracy of check points against published standards."""

from __future__ import annotations

import logging

from ..errors import InputError
from .common import enum_param, html_out, json_out, table_param
from .runner import JobResult
from .spec import AlgorithmSpec, Fields, Param, Result, Values, options_from

log = logging.getLogger(__name__)

_D = Fields("quality.accuracy_options", "AccuracySettings")
_STANDARD_LABELS = (
    "ASPRS Positional Accuracy Standards, Edition 2 (2023)",
    "NSSDA (FGDC-STD-007.3-1998)",
    "PEC-PCD (Decreto 89.817 / ET-CQDG)",
    "Project threshold (Pedrosa & dos Santos 2020: 0.40 m, dz of Eq. 18)",
)
_OUTLIER_LABELS = (
    "robust: modified z-score > 3.5 (median/MAD)",
    "three sigma: |d - mean| > 3 s",
    "none",
)
#: (parameter, AccuracySettings field, label, unit, minimum, maximum, advanced)
_NUMBERS = (
    ("ALPHA", "alpha", "Significance level of the tests", "", 0.0001, 0.25, True),
    (
        "DECLARED_SIGMA_H",
        "declared_sigma_h",
        "Declared precision per horizontal axis",
        "m",
        0.0,
        100.0,
        True,
    ),
    ("DECLARED_SIGMA_V", "declared_sigma_v", "Declared precision in height", "m", 0.0, 100.0, True),
    (
        "SURVEY_SIGMA_H",
        "survey_sigma_h",
        "Check-point survey sigma per horizontal axis",
        "m",
        0.0,
        100.0,
        True,
    ),
    (
        "SURVEY_SIGMA_V",
        "survey_sigma_v",
        "Check-point survey sigma in height",
        "m",
        0.0,
        100.0,
        True,
    ),
)
_STANDARD_NUMBERS = (
    (
        "ASPRS_H_CLASS_CM",
        "asprs_h_class_cm",
        "ASPRS horizontal class (0 = tightest met)",
        "cm",
        0.0,
        10000.0,
        True,
    ),
    (
        "ASPRS_V_CLASS_CM",
        "asprs_v_class_cm",
        "ASPRS vertical class (0 = tightest met)",
        "cm",
        0.0,
        10000.0,
        True,
    ),
    ("PEC_SCALE", "pec_scale", "PEC-PCD scale denominator (1:N)", "", 1.0, 1e8, True),
    (
        "PEC_EQUIDISTANCE",
        "pec_equidistance",
        "PEC-PCD equidistance (0 = series value)",
        "m",
        0.0,
        1000.0,
        True,
    ),
)
_PROJECT_NUMBERS = (
    (
        "PROJECT_H_THRESHOLD",
        "project_h_threshold",
        "Project planimetric threshold",
        "m",
        0.0,
        1000.0,
        True,
    ),
    (
        "PROJECT_V_THRESHOLD",
        "project_v_threshold",
        "Project vertical threshold (0 = Eq. 18)",
        "m",
        0.0,
        1000.0,
        True,
    ),
)


def _numbers(rows) -> tuple[Param, ...]:
    """The ``number`` parameters of rows ``(parameter, field, label, unit, minimum, maximum,
    advanced)`` of :class:`AccuracySettings`."""
    return _D.params((key, field, label, "number", *rest) for key, field, label, *rest in rows)


def _point_params(what: str) -> tuple[Param, ...]:
    key = what.upper()
    return (
        Param(
            key,
            "points",
            f"{what.capitalize()} points",
            optional=True,
            help=f"{what} point table (CSV: id, e, n, h [, group]) or point layer",
        ),
        Param(
            f"{key}_ID",
            "field",
            f"{what.capitalize()} id field",
            "",
            parent=key,
            optional=True,
            help="id column (default: id)",
            advanced=True,
        ),
        Param(
            f"{key}_Z_FIELD",
            "field",
            f"{what.capitalize()} height field (empty: geometry Z)",
            "",
            parent=key,
            optional=True,
            numeric_field=True,
            advanced=True,
            help="height column (default: h; in QGIS empty takes the geometry's Z)",
        ),
    )


SPEC = AlgorithmSpec(
    name="accuracyreport",
    title="Positional accuracy report",
    group="Accuracy",
    group_id="accuracy",
    summary="check points against ASPRS Ed. 2, NSSDA, PEC-PCD and the project threshold",
    description="""\
Compares measured check points with reference coordinates and reports their positional
accuracy: discrepancies d = measured - reference (dE, dN, dH, horizontal, 3D), mean, standard
deviation, RMSE, minimum and maximum per component, per group and overall; Shapiro-Wilk
normality, Student's t test for bias, chi-square test of the standard deviation against a
declared precision; outlier screening (flagged points are reported, excluded only on
request); and the verdicts of the ASPRS Positional Accuracy Standards Edition 2 (2023),
NSSDA (FGDC-STD-007.3-1998), the Brazilian PEC-PCD (classes A-D for a scale) and the project
threshold of Pedrosa & dos Santos (2020): 0.40 m planimetric, dz = sqrt(2) H^2 / (B f)
sigma_pix.

## Input: one table or two point tables/layers
Check-point table (CSV): id, e, n, h (measured) and e_ref, n_ref, h_ref (reference),
optional group; metres in one projected CRS (give it as CRS).

Or Measured points and Reference points (CSV tables id, e, n, h [, group], or point layers in
QGIS) joined by their ids. Ids present in only one set, duplicate ids and missing coordinates
are errors. Layers in different CRSs are refused unless Reproject is checked (QGIS only: the
reference layer is then transformed to the measured layer's CRS, heights unchanged).

## Settings
Declared precision and check-point survey sigma are per horizontal axis and in height (m;
0 = not given). ASPRS classes in cm (0 = report the tightest class met); PEC-PCD scale
denominator, equidistance (0 = the series' value) and declared class; project thresholds
(vertical 0 = dz of Eq. 18 from the flight geometry "H m, B m, f mm, pixel um").

## Outputs
A self-contained HTML report (tables, verdicts, SVG plots), a JSON of every figure, a PointZ
layer at the reference positions with id, group, dE, dN, dU, dHorizontal, d3D, outlier, and
the RMSE values as numeric outputs RMSE_E, RMSE_N, RMSE_U (height), RMSE_HORIZONTAL, RMSE_3D
(docs/formats.md, "Accuracy figures"; RMSE_H and RMSE_HORIZ, their former names, are kept
for one release).""",
    params=(
        table_param(
            "INPUT",
            "Check-point table (CSV: id, e, n, h, e_ref, n_ref, h_ref, group)",
            optional=True,
        ),
        *_point_params("measured"),
        *_point_params("reference"),
        Param(
            "GROUP_FIELD",
            "field",
            "Group field (flight direction, model, block)",
            "",
            parent="MEASURED",
            optional=True,
            help="group column (default: group)",
        ),
        Param(
            "CRS",
            "crs",
            "CRS of the check-point table",
            optional=True,
            help="CRS of the coordinates (reported only)",
        ),
        Param(
            "REPROJECT",
            "boolean",
            "Reproject the reference layer to the measured CRS",
            False,
            help="QGIS only: point tables carry no CRS",
            advanced=True,
        ),
        *_numbers(_NUMBERS),
        enum_param(
            "OUTLIER_RULE",
            "Outlier screening",
            _D.outlier_rule,
            "OUTLIER_RULES",
            labels=_OUTLIER_LABELS,
            advanced=True,
        ),
        Param(
            "EXCLUDE_OUTLIERS",
            "boolean",
            "Exclude flagged outliers from the statistics",
            _D.exclude_outliers,
            advanced=True,
        ),
        enum_param(
            "STANDARDS",
            "Standards",
            _D.standards,
            "STANDARD_KEYS",
            labels=_STANDARD_LABELS,
            multiple=True,
        ),
        *_numbers(_STANDARD_NUMBERS),
        enum_param(
            "PEC_CLASS", "PEC-PCD declared class", _D.pec_class, "PEC_CLASSES", advanced=True
        ),
        *_numbers(_PROJECT_NUMBERS),
        Param(
            "FLIGHT_GEOMETRY",
            "numbers",
            "Flight geometry for Eq. 18: H, B, f, pixel",
            _D.flight_geometry,
            count=4,
            unit="m, m, mm, um",
            advanced=True,
            minimum=0.001,
            maximum=100000.0,
        ),
        Param("OUTPUT", "sink", "Check points with discrepancies", geometry="point", optional=True),
        html_out("OUTPUT_HTML", "Accuracy report (HTML)"),
        json_out("OUTPUT_JSON", "Accuracy figures (JSON)", on_demand=True),
    ),
    results=(
        *(
            Result(key, "number", f"{key} (m)")
            for key in ("RMSE_E", "RMSE_N", "RMSE_U", "RMSE_HORIZONTAL", "RMSE_3D")
        ),
        # the names of earlier versions, for one release (docs/formats.md)
        Result("RMSE_H", "number", "RMSE_H (m; deprecated: use RMSE_U)"),
        Result("RMSE_HORIZ", "number", "RMSE_HORIZ (m; deprecated: use RMSE_HORIZONTAL)"),
    ),
    tags=("accuracy", "rmse", "check points", "asprs", "nssda", "pec", "pec-pcd", "quality"),
    references=(
        "ASPRS (2023)",
        "FGDC (1998)",
        "Brasil (1984), DSG (2016)",
        "Pedrosa & dos Santos (2020)",
        "Iglewicz & Hoaglin (1993)",
    ),
)


def _points(v: Values):
    """The check points from the table, or the two point sets (paths or the QGIS adapter's
    PointSet objects), joined by id."""
    from ..io.checkpoints import read_checkpoint_table, read_point_table
    from ..quality.accuracy import PointSet, join_points

    has_table = v.input is not None
    has_points = v.measured is not None or v.reference is not None
    if has_table == has_points or (has_points and (v.measured is None or v.reference is None)):
        raise InputError(
            "give either one check-point table (INPUT) or a measured and a reference point "
            "table (MEASURED and REFERENCE)"
        )
    if has_table:
        return read_checkpoint_table(v.input, group_column=v.group_field or None, crs=v.crs)
    if isinstance(v.measured, PointSet) and isinstance(v.reference, PointSet):
        return join_points(v.measured, v.reference)
    if v.reproject:
        raise InputError("REPROJECT needs QGIS (point tables carry no CRS)")
    measured = read_point_table(
        v.measured,
        id_column=v.measured_id or None,
        z_column=v.measured_z_field or None,
        group_column=v.group_field or None,
        crs=v.crs,
    )
    reference = read_point_table(
        v.reference,
        id_column=v.reference_id or None,
        z_column=v.reference_z_field or None,
        crs=v.crs,
    )
    return join_points(measured, reference)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the check points, assess them, write the HTML report and the JSON."""
    import json

    import numpy as np

    from ..errors import stop_if_asked
    from ..geometry.frames import check_points_in_area, parse_crs
    from ..io.atomic import write_text_atomic
    from ..quality.accuracy import AccuracySettings, assess_accuracy
    from ..quality.accuracy_html import render_html
    from ..quality.accuracy_json import report_to_dict, with_deprecated_keys

    settings = options_from(AccuracySettings, SPEC, v)
    points = _points(v)
    log.info("%d check points from %s", len(points), points.source)
    if points.crs:  # coordinates that cannot be in the stated CRS are refused
        check_points_in_area(
            parse_crs(points.crs),
            np.vstack([points.measured, points.reference]),
            what="the check points",
            path=points.source or None,
        )
    report = assess_accuracy(points, settings, progress=progress, should_stop=should_stop)
    stop_if_asked(should_stop, "writing the report")
    if out.requested("OUTPUT_HTML"):
        write_text_atomic(out.path("OUTPUT_HTML"), render_html(report))
    if out.requested("OUTPUT_JSON"):
        text = json.dumps(report_to_dict(report), indent=1, allow_nan=False)
        write_text_atomic(out.path("OUTPUT_JSON"), text)
    if progress is not None:
        progress(1.0)
    lines = [f"{key} {value:.4f}" for key, value in report.rmse.items()]
    if report.contrast is not None:
        n_flag = int(report.outliers.any.sum())
        lines.append(
            f"{n_flag} point(s) flagged as outliers ({report.overall.name} above); "
            f"{report.contrast.name}: "
            + ", ".join(f"{k} {v:.4f}" for k, v in report.rmse_contrast.items())
        )
    lines += [
        f"{res.key}: {verdict.name}: {verdict.status} ({verdict.reason})"
        for res in report.standards
        for verdict in res.verdicts
    ]
    return JobResult(results=with_deprecated_keys(report.rmse), lines=lines, data=report)
