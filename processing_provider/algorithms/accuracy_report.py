"""lidarphoto:accuracyreport - positional accuracy of check points against published standards."""

from __future__ import annotations

import math

from qgis.core import (
    NULL,
    QgsCoordinateTransform,
    QgsFeature,
    QgsField,
    QgsFields,
    QgsGeometry,
    QgsPoint,
    QgsPointXY,
    QgsProcessingException,
    QgsProcessingOutputNumber,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterCrs,
    QgsProcessingParameterEnum,
    QgsProcessingParameterFeatureSink,
    QgsProcessingParameterFeatureSource,
    QgsProcessingParameterField,
    QgsProcessingParameterFile,
    QgsProcessingParameterFileDestination,
    QgsProcessingParameterNumber,
    QgsProcessingParameterString,
)
from qgis.PyQt.QtCore import QVariant

from ..base import BaseAlgorithm, core_errors
from ..compat import (
    FIELD_DOUBLE,
    FIELD_STRING,
    FILE_BEHAVIOR_FILE,
    FLAG_ADVANCED,
    SINK_FAST_INSERT,
    SOURCE_VECTOR_POINT,
    WKB_POINT_Z,
    WKT_PREFERRED,
)

STANDARDS = ("asprs", "nssda", "pec", "project")
_STANDARD_LABELS = (
    "ASPRS Positional Accuracy Standards, Edition 2 (2023)",
    "NSSDA (FGDC-STD-007.3-1998)",
    "PEC-PCD (Decreto 89.817 / ET-CQDG)",
    "Project threshold (paper 000: 0.40 m, dz of Eq. 18)",
)
OUTLIER_RULES = ("robust", "three_sigma", "none")
_OUTLIER_LABELS = (
    "robust: modified z-score > 3.5 (median/MAD)",
    "three sigma: |d - mean| > 3 s",
    "none",
)
PEC_CLASSES = ("A", "B", "C", "D")
_DOUBLE = QgsProcessingParameterNumber.Type.Double
_FIELD_NUMERIC = QgsProcessingParameterField.DataType.Numeric
_FIELD_ANY = QgsProcessingParameterField.DataType.Any
# QVariant.Int works on 3.22 and is patched to QMetaType.Type on Qt6 builds (flake8 QGS402).
FIELD_INT = QVariant.Int

_HELP = """<p>Compares measured check points with reference coordinates and reports their \
positional accuracy: discrepancies d = measured - reference (dE, dN, dH, horizontal, 3D), \
mean, standard deviation, RMSE, minimum and maximum per component, per group and overall; \
Shapiro-Wilk normality, Student's t test for bias, chi-square test of the standard deviation \
against a declared precision; outlier screening (flagged points are reported, excluded only \
on request); and the verdicts of the ASPRS Positional Accuracy Standards Edition 2 (2023), \
NSSDA (FGDC-STD-007.3-1998), the Brazilian PEC-PCD (classes A-D for a scale) and the \
project threshold of paper 000 (0.40 m planimetric, dz = sqrt(2) H^2 / (B f) sigma_pix).</p>
<h3>Input: one table or two point layers</h3>
<p><b>Check-point table</b> (CSV): id, e, n, h (measured) and e_ref, n_ref, h_ref \
(reference), optional group; metres in one projected CRS (give it as <b>CRS</b>).</p>
<p>Or <b>Measured points</b> and <b>Reference points</b> layers joined by their id fields; \
heights from the geometry Z or a height field. Ids present in only one layer, duplicate ids \
and missing coordinates are errors. Layers in different CRSs are refused unless \
<b>Reproject</b> is checked (the reference layer is then transformed to the measured \
layer's CRS by QGIS, heights unchanged).</p>
<h3>Settings</h3>
<p>Declared precision and check-point survey sigma are per horizontal axis and in height \
(m; 0 = not given). ASPRS classes in cm (0 = report the tightest class met); PEC-PCD scale \
denominator, equidistance (0 = the series' value) and declared class; project thresholds \
(vertical 0 = dz of Eq. 18 from the flight geometry "H m, B m, f mm, pixel um").</p>
<h3>Outputs</h3>
<p>A self-contained HTML report (tables, verdicts, SVG plots), a JSON of every figure, a \
PointZ layer at the reference positions with id, group, dE, dN, dH, dHoriz, d3D, outlier, \
and the RMSE values as numeric outputs.</p>"""


class AccuracyReportAlgorithm(BaseAlgorithm):
    """Thin adapter of ``core.accuracy.run_accuracy_report``."""

    INPUT = "INPUT"
    MEASURED = "MEASURED"
    MEASURED_ID = "MEASURED_ID"
    MEASURED_Z_FIELD = "MEASURED_Z_FIELD"
    REFERENCE = "REFERENCE"
    REFERENCE_ID = "REFERENCE_ID"
    REFERENCE_Z_FIELD = "REFERENCE_Z_FIELD"
    GROUP_FIELD = "GROUP_FIELD"
    CRS = "CRS"
    REPROJECT = "REPROJECT"
    ALPHA = "ALPHA"
    DECLARED_SIGMA_H = "DECLARED_SIGMA_H"
    DECLARED_SIGMA_V = "DECLARED_SIGMA_V"
    SURVEY_SIGMA_H = "SURVEY_SIGMA_H"
    SURVEY_SIGMA_V = "SURVEY_SIGMA_V"
    OUTLIER_RULE = "OUTLIER_RULE"
    EXCLUDE_OUTLIERS = "EXCLUDE_OUTLIERS"
    STANDARDS = "STANDARDS"
    ASPRS_H_CLASS_CM = "ASPRS_H_CLASS_CM"
    ASPRS_V_CLASS_CM = "ASPRS_V_CLASS_CM"
    PEC_SCALE = "PEC_SCALE"
    PEC_EQUIDISTANCE = "PEC_EQUIDISTANCE"
    PEC_CLASS = "PEC_CLASS"
    PROJECT_H_THRESHOLD = "PROJECT_H_THRESHOLD"
    PROJECT_V_THRESHOLD = "PROJECT_V_THRESHOLD"
    FLIGHT_GEOMETRY = "FLIGHT_GEOMETRY"
    OUTPUT = "OUTPUT"
    OUTPUT_HTML = "OUTPUT_HTML"
    OUTPUT_JSON = "OUTPUT_JSON"
    RMSE_OUTPUTS = ("RMSE_E", "RMSE_N", "RMSE_H", "RMSE_HORIZ", "RMSE_3D")

    GROUP = "Quality"
    GROUP_ID = "quality"
    TAGS = ("accuracy", "rmse", "check points", "asprs", "nssda", "pec", "pec-pcd", "quality")

    def name(self) -> str:
        return "accuracyreport"

    def displayName(self) -> str:
        return self.tr("Positional accuracy report")

    def shortHelpString(self) -> str:
        return self.tr(_HELP)

    def _number(self, key, label, default, advanced=False, minimum=0.0):
        p = QgsProcessingParameterNumber(key, self.tr(label), _DOUBLE, default, False, minimum)
        if advanced:
            p.setFlags(p.flags() | FLAG_ADVANCED)
        self.addParameter(p)

    def initAlgorithm(self, config=None):
        self.addParameter(
            QgsProcessingParameterFile(
                self.INPUT,
                self.tr("Check-point table (CSV: id, e, n, h, e_ref, n_ref, h_ref, group)"),
                behavior=FILE_BEHAVIOR_FILE,
                fileFilter=self.tr("CSV files (*.csv *.txt);;All files (*.*)"),
                optional=True,
            )
        )
        for layer, id_key, z_key, what in (
            (self.MEASURED, self.MEASURED_ID, self.MEASURED_Z_FIELD, "Measured"),
            (self.REFERENCE, self.REFERENCE_ID, self.REFERENCE_Z_FIELD, "Reference"),
        ):
            self.addParameter(
                QgsProcessingParameterFeatureSource(
                    layer, self.tr(f"{what} points"), [SOURCE_VECTOR_POINT], optional=True
                )
            )
            self.addParameter(
                QgsProcessingParameterField(
                    id_key, self.tr(f"{what} id field"), None, layer, _FIELD_ANY, optional=True
                )
            )
            self.addParameter(
                QgsProcessingParameterField(
                    z_key,
                    self.tr(f"{what} height field (empty: geometry Z)"),
                    None,
                    layer,
                    _FIELD_NUMERIC,
                    optional=True,
                )
            )
        self.addParameter(
            QgsProcessingParameterField(
                self.GROUP_FIELD,
                self.tr("Group field (flight direction, model, block)"),
                None,
                self.MEASURED,
                _FIELD_ANY,
                optional=True,
            )
        )
        self.addParameter(
            QgsProcessingParameterCrs(
                self.CRS, self.tr("CRS of the check-point table"), None, optional=True
            )
        )
        self.addParameter(
            QgsProcessingParameterBoolean(
                self.REPROJECT, self.tr("Reproject the reference layer to the measured CRS"), False
            )
        )
        self._number(self.ALPHA, "Significance level of the tests", 0.05, minimum=0.0001)
        self._number(self.DECLARED_SIGMA_H, "Declared precision per horizontal axis (m)", 0.0)
        self._number(self.DECLARED_SIGMA_V, "Declared precision in height (m)", 0.0)
        self._number(self.SURVEY_SIGMA_H, "Check-point survey sigma per horizontal axis (m)", 0.0)
        self._number(self.SURVEY_SIGMA_V, "Check-point survey sigma in height (m)", 0.0)
        self.addParameter(
            QgsProcessingParameterEnum(
                self.OUTLIER_RULE, self.tr("Outlier screening"), list(_OUTLIER_LABELS), False, 0
            )
        )
        self.addParameter(
            QgsProcessingParameterBoolean(
                self.EXCLUDE_OUTLIERS,
                self.tr("Exclude flagged outliers from the statistics"),
                False,
            )
        )
        self.addParameter(
            QgsProcessingParameterEnum(
                self.STANDARDS,
                self.tr("Standards"),
                list(_STANDARD_LABELS),
                True,
                list(range(len(STANDARDS))),
            )
        )
        self._number(self.ASPRS_H_CLASS_CM, "ASPRS horizontal class (cm, 0 = tightest met)", 0.0)
        self._number(self.ASPRS_V_CLASS_CM, "ASPRS vertical class (cm, 0 = tightest met)", 0.0)
        self._number(self.PEC_SCALE, "PEC-PCD scale denominator (1:N)", 1000.0, minimum=1.0)
        self._number(self.PEC_EQUIDISTANCE, "PEC-PCD equidistance (m, 0 = series value)", 0.0)
        self.addParameter(
            QgsProcessingParameterEnum(
                self.PEC_CLASS, self.tr("PEC-PCD declared class"), list(PEC_CLASSES), False, 0
            )
        )
        self._number(self.PROJECT_H_THRESHOLD, "Project planimetric threshold (m)", 0.40)
        self._number(self.PROJECT_V_THRESHOLD, "Project vertical threshold (m, 0 = Eq. 18)", 0.0)
        geometry = QgsProcessingParameterString(
            self.FLIGHT_GEOMETRY,
            self.tr("Flight geometry for Eq. 18: H (m), B (m), f (mm), pixel (um)"),
            "1600,452,100.4,6",
        )
        geometry.setFlags(geometry.flags() | FLAG_ADVANCED)
        self.addParameter(geometry)
        self.addParameter(
            QgsProcessingParameterFeatureSink(
                self.OUTPUT, self.tr("Check points with discrepancies"), SOURCE_VECTOR_POINT
            )
        )
        self.addParameter(
            QgsProcessingParameterFileDestination(
                self.OUTPUT_HTML,
                self.tr("Accuracy report (HTML)"),
                self.tr("HTML files (*.html)"),
                optional=True,
                createByDefault=True,
            )
        )
        self.addParameter(
            QgsProcessingParameterFileDestination(
                self.OUTPUT_JSON,
                self.tr("Accuracy figures (JSON)"),
                self.tr("JSON files (*.json)"),
                optional=True,
                createByDefault=False,
            )
        )
        for key in self.RMSE_OUTPUTS:
            self.addOutput(QgsProcessingOutputNumber(key, self.tr(f"{key} (m)")))

    def _layer_points(self, parameters, context, layer_key, id_key, z_key, group_key, to_crs):
        """Read a point layer into a core PointSet (reprojected to ``to_crs`` if given)."""
        from ...core.quality.accuracy import point_set

        source = self.parameterAsSource(parameters, layer_key, context)
        id_field = (self.parameterAsFields(parameters, id_key, context) or [None])[0]
        if id_field is None:
            raise QgsProcessingException(self.tr(f"{layer_key}: choose its id field ({id_key})."))
        z_field = (self.parameterAsFields(parameters, z_key, context) or [None])[0]
        group = (
            (self.parameterAsFields(parameters, group_key, context) or [None])[0]
            if group_key
            else None
        )
        xform = None
        if to_crs is not None and to_crs != source.sourceCrs():
            xform = QgsCoordinateTransform(source.sourceCrs(), to_crs, context.transformContext())
        ids, xyz, groups, fids = [], [], [], []
        for f in source.getFeatures():
            geom = f.geometry()
            p = geom.constGet() if not geom.isNull() else None
            if p is not None and geom.isMultipart():
                p = p.geometryN(0) if p.numGeometries() == 1 else None
            if p is None:
                x = y = z = math.nan
            else:
                x, y, z = p.x(), p.y(), (p.z() if p.is3D() else math.nan)
                if xform is not None:
                    q = xform.transform(QgsPointXY(x, y))
                    x, y = q.x(), q.y()
            if z_field:
                value = f[z_field]
                z = math.nan if value is None or value == NULL else float(value)
            ids.append(f[id_field])
            xyz.append((x, y, z))
            groups.append("" if not group or f[group] == NULL else f[group])
            fids.append(f.id())
        crs = to_crs if to_crs is not None else source.sourceCrs()
        with core_errors():
            return point_set(
                ids,
                xyz,
                groups,
                crs=crs.authid() or crs.toWkt(WKT_PREFERRED) if crs.isValid() else None,
                source=f"{layer_key} ({source.sourceName()})",
                locations=fids,
                location_kind="feature",
            )

    def processAlgorithm(self, parameters, context, feedback):
        from ...core.quality.accuracy import AccuracySettings, join_points, run_accuracy_report

        table = self.parameterAsFile(parameters, self.INPUT, context)
        has_layers = self.parameterAsSource(parameters, self.MEASURED, context) is not None
        if bool(table) == has_layers:
            raise QgsProcessingException(
                self.tr("Give either a check-point table (INPUT) or two point layers.")
            )
        crs = self.parameterAsCrs(parameters, self.CRS, context)
        points = None
        if has_layers:
            if self.parameterAsSource(parameters, self.REFERENCE, context) is None:
                raise QgsProcessingException(self.tr("The reference point layer is missing."))
            measured = self._layer_points(
                parameters,
                context,
                self.MEASURED,
                self.MEASURED_ID,
                self.MEASURED_Z_FIELD,
                self.GROUP_FIELD,
                None,
            )
            crs = self.parameterAsSource(parameters, self.MEASURED, context).sourceCrs()
            reproject = self.parameterAsBoolean(parameters, self.REPROJECT, context)
            reference = self._layer_points(
                parameters,
                context,
                self.REFERENCE,
                self.REFERENCE_ID,
                self.REFERENCE_Z_FIELD,
                None,
                crs if reproject else None,
            )
            with core_errors():
                points = join_points(measured, reference)
        group = (self.parameterAsFields(parameters, self.GROUP_FIELD, context) or [None])[0]
        num = {
            k: self.parameterAsDouble(parameters, k, context)
            for k in (
                self.ALPHA,
                self.DECLARED_SIGMA_H,
                self.DECLARED_SIGMA_V,
                self.SURVEY_SIGMA_H,
                self.SURVEY_SIGMA_V,
                self.ASPRS_H_CLASS_CM,
                self.ASPRS_V_CLASS_CM,
                self.PEC_SCALE,
                self.PEC_EQUIDISTANCE,
                self.PROJECT_H_THRESHOLD,
                self.PROJECT_V_THRESHOLD,
            )
        }
        try:
            geometry = tuple(
                float(v)
                for v in self.parameterAsString(parameters, self.FLIGHT_GEOMETRY, context).split(
                    ","
                )
            )
        except ValueError as exc:
            raise QgsProcessingException(
                self.tr("FLIGHT_GEOMETRY: 4 numbers H,B,f,pixel.")
            ) from exc
        settings = AccuracySettings(
            alpha=num[self.ALPHA],
            declared_sigma_h=num[self.DECLARED_SIGMA_H],
            declared_sigma_v=num[self.DECLARED_SIGMA_V],
            survey_sigma_h=num[self.SURVEY_SIGMA_H],
            survey_sigma_v=num[self.SURVEY_SIGMA_V],
            outlier_rule=OUTLIER_RULES[
                self.parameterAsEnum(parameters, self.OUTLIER_RULE, context)
            ],
            exclude_outliers=self.parameterAsBoolean(parameters, self.EXCLUDE_OUTLIERS, context),
            standards=tuple(
                STANDARDS[i] for i in self.parameterAsEnums(parameters, self.STANDARDS, context)
            ),
            asprs_h_class_cm=num[self.ASPRS_H_CLASS_CM],
            asprs_v_class_cm=num[self.ASPRS_V_CLASS_CM],
            pec_scale=num[self.PEC_SCALE],
            pec_equidistance=num[self.PEC_EQUIDISTANCE],
            pec_class=PEC_CLASSES[self.parameterAsEnum(parameters, self.PEC_CLASS, context)],
            project_h_threshold=num[self.PROJECT_H_THRESHOLD],
            project_v_threshold=num[self.PROJECT_V_THRESHOLD],
            flight_geometry=geometry,
        )
        html = self.parameterAsFileOutput(parameters, self.OUTPUT_HTML, context)
        out_json = self.parameterAsFileOutput(parameters, self.OUTPUT_JSON, context)
        report = self.run_core(
            run_accuracy_report,
            points,
            input_table=table or None,
            group_field=None if has_layers else group,
            crs=(crs.authid() or crs.toWkt(WKT_PREFERRED)) if crs.isValid() else None,
            settings=settings,
            output_html=html or None,
            output_json=out_json or None,
            feedback=feedback,
        )
        return {
            **self._write_layer(parameters, context, report, crs),
            self.OUTPUT_HTML: html or None,
            self.OUTPUT_JSON: out_json or None,
            **report.rmse,
        }

    def _write_layer(self, parameters, context, report, crs):
        fields = QgsFields()
        for name, kind in (("id", FIELD_STRING), ("group", FIELD_STRING)):
            fields.append(QgsField(name, kind))
        for name in ("dE", "dN", "dH", "dHoriz", "d3D"):
            fields.append(QgsField(name, FIELD_DOUBLE))
        fields.append(QgsField("outlier", FIELD_INT))
        sink, dest_id = self.parameterAsSink(
            parameters, self.OUTPUT, context, fields, WKB_POINT_Z, crs
        )
        if sink is None:
            raise QgsProcessingException(self.invalidSinkError(parameters, self.OUTPUT))
        pts, d = report.points, report.discrepancies
        extra = (report.horizontal, report.d3, report.outliers.any)
        for k, point_id in enumerate(pts.ids):
            feature = QgsFeature(fields)
            feature.setGeometry(QgsGeometry(QgsPoint(*(float(v) for v in pts.reference[k]))))
            feature.setAttributes(
                [
                    point_id,
                    pts.groups[k],
                    *(float(v) for v in d[k]),
                    float(extra[0][k]),
                    float(extra[1][k]),
                    int(bool(extra[2][k])),
                ]
            )
            sink.addFeature(feature, SINK_FAST_INSERT)
        return {self.OUTPUT: dest_id}
