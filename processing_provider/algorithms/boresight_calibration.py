"""lidarphoto:boresightcalibration - boresight from LiDAR roof planes, lines and control points."""

from __future__ import annotations

import math

from qgis.core import (
    NULL,
    QgsCoordinateReferenceSystem,
    QgsFeature,
    QgsField,
    QgsFields,
    QgsGeometry,
    QgsPoint,
    QgsProcessingException,
    QgsProcessingOutputNumber,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterCrs,
    QgsProcessingParameterEnum,
    QgsProcessingParameterFeatureSink,
    QgsProcessingParameterFile,
    QgsProcessingParameterFileDestination,
    QgsProcessingParameterString,
)

from ..base import BaseAlgorithm
from ..compat import (
    FIELD_DOUBLE,
    FIELD_INT,
    FIELD_STRING,
    FILE_BEHAVIOR_FILE,
    FLAG_ADVANCED,
    SINK_FAST_INSERT,
    SOURCE_VECTOR_POINT,
    WKB_POINT_Z,
    WKT_PREFERRED,
)
from .trajectory_to_eo import _MOUNT_LABELS, MOUNT_CHOICES

_GROUPINGS = ("single", "group", "direction")  # core.boresight_run.GROUPINGS
_TYPES = ("tie", "line", "lcp", "paper")  # core.boresight_run.CONTROL_TYPES
try:
    from ...core.photo.boresight import INS_GRADES

    _GRADE_LABELS = {k: g.name for k, g in INS_GRADES.items()}
except ImportError:  # a third-party package of the core is missing: canExecute() says which
    _GRADE_LABELS = {"pos_av_310": "Applanix POS AV 310"}
_GRADES = (*_GRADE_LABELS, "custom")
_FIELDS = (
    ("image_id", FIELD_STRING),
    ("point_id", FIELD_STRING),
    ("type", FIELD_STRING),
    ("target_id", FIELD_STRING),
    ("group", FIELD_STRING),
    ("col", FIELD_DOUBLE),
    ("row", FIELD_DOUBLE),
    ("vx", FIELD_DOUBLE),
    ("vy", FIELD_DOUBLE),
    ("v", FIELD_DOUBLE),
    ("v_d", FIELD_DOUBLE),
    ("w", FIELD_DOUBLE),
    ("rejected", FIELD_INT),
    ("used", FIELD_INT),
)

_HELP = """<p>Estimates the angular misalignment (<b>boresight</b>) between the camera and the \
INS, per group of images, from image points on roofs whose geometry comes from LiDAR: \
plane-constrained <b>tie</b> points (a roof point in two or more images lying on its LiDAR \
plane), points on LiDAR ridge/hip <b>lines</b> (coplanarity, one image suffices), LiDAR \
control points (<b>lcp</b>, three-plane corners) and the single-image <b>paper</b> model of \
Rodrigues et al. (its Eqs. 12-17; needs the cloud with plane ids). INS positions and attitudes \
are weighted observations (the <b>INS grade</b>); optionally the lever arm and the interior \
orientation are estimated. The adjustment runs in a local east-north-up frame with the \
rigorous navigation frame of each image.</p>
<p><b>Inputs</b>: camera JSON, trajectory CSV (as <i>Trajectory to exterior orientation</i>), \
the mount with the <i>initial</i> boresight (degrees), the image observation CSV \
(image_id, point_id, col, row, sigma_px, type, target_id), and the plane / line / LCP tables \
of <i>Extract roof planes</i> and <i>Create LiDAR control points</i>.</p>
<p><b>Grouping</b>: one boresight for all images, one per value of the trajectory's group \
column (flight line, direction or session) or one per heading octant.</p>
<p><b>Outputs</b>: the results table (one row per group: angles in degrees and arc-seconds, \
standard deviations in arc-seconds), a point layer of every image observation at its ground \
position with its pixel residual (vx, vy, |v|), Baarda's w and the snooping flag, the updated \
exterior orientations (CSV) and an HTML summary. A set-up where a parameter cannot be \
determined stops with a diagnosis saying which flight pattern or control would fix it.</p>"""


class BoresightCalibrationAlgorithm(BaseAlgorithm):
    """Thin adapter of ``core.boresight_run.run_boresight_calibration``."""

    GROUP = "Calibration"
    GROUP_ID = "calibration"
    TAGS = ("boresight", "misalignment", "ins", "imu", "calibration", "roof planes", "lever arm")

    def name(self) -> str:
        return "boresightcalibration"

    def displayName(self) -> str:
        return self.tr("Boresight calibration")

    def shortHelpString(self) -> str:
        return self.tr(_HELP)

    def initAlgorithm(self, config=None):
        def file(key, label, filt, optional=False):
            self.addParameter(
                QgsProcessingParameterFile(
                    key,
                    self.tr(label),
                    behavior=FILE_BEHAVIOR_FILE,
                    fileFilter=self.tr(filt),
                    optional=optional,
                )
            )

        def advanced(param):
            param.setFlags(param.flags() | FLAG_ADVANCED)
            self.addParameter(param)

        csv = "CSV files (*.csv *.txt);;All files (*.*)"
        file("CAMERA", "Camera (JSON)", "JSON files (*.json);;All files (*.*)")
        file("TRAJECTORY", "Trajectory table (CSV)", csv)
        self.addParameter(QgsProcessingParameterCrs("CRS", self.tr("Mapping CRS"), "ProjectCrs"))
        self.addParameter(
            QgsProcessingParameterString(
                "LEVER_ARM", self.tr("Lever arm x,y,z (m, body frame)"), "0,0,0"
            )
        )
        mounts = [f"{m}: {self.tr(_MOUNT_LABELS.get(m, m))}" for m in MOUNT_CHOICES]
        self.addParameter(
            QgsProcessingParameterEnum("MOUNT", self.tr("Camera mount"), mounts, False, 0)
        )
        advanced(
            QgsProcessingParameterString(
                "MOUNT_MATRIX",
                self.tr("Mount matrix R_c^b (9 numbers, row-major)"),
                "",
                False,
                True,
            )
        )
        self.addParameter(
            QgsProcessingParameterString(
                "BORESIGHT", self.tr("Initial boresight domega,dphi,dkappa (degrees)"), "0,0,0"
            )
        )
        file("OBSERVATIONS", "Image observations (CSV)", csv)
        file("PLANES", "Plane table (CSV)", csv, True)
        file("LINES", "Line table (CSV)", csv, True)
        file("LCPS", "LiDAR control point table (CSV)", csv, True)
        file(
            "CLOUD",
            "Cloud with plane ids (LAS/LAZ, paper mode only)",
            "LAS/LAZ files (*.las *.laz);;All files (*.*)",
            True,
        )
        groupings = [
            self.tr("one boresight for all images"),
            self.tr("one per trajectory group (flight line, direction, session)"),
            self.tr("one per heading direction (octant)"),
        ]
        self.addParameter(
            QgsProcessingParameterEnum("GROUPING", self.tr("Boresight groups"), groupings, False, 1)
        )
        self.addParameter(
            QgsProcessingParameterEnum(
                "CONTROL_TYPES", self.tr("Control types"), list(_TYPES), True, [0, 1, 2, 3]
            )
        )
        self.addParameter(
            QgsProcessingParameterBoolean(
                "ESTIMATE_LEVER_ARM", self.tr("Estimate the lever arm"), False
            )
        )
        self.addParameter(
            QgsProcessingParameterBoolean(
                "ESTIMATE_INTERIOR", self.tr("Estimate focal length and principal point"), False
            )
        )
        grades = [*_GRADE_LABELS.values(), self.tr("custom (INS sigmas)")]
        self.addParameter(
            QgsProcessingParameterEnum("INS_GRADE", self.tr("INS grade"), grades, False, 0)
        )
        advanced(
            QgsProcessingParameterString(
                "INS_SIGMAS",
                self.tr("Custom INS sigmas: horizontal m, vertical m, roll/pitch deg, heading deg"),
                "0.02,0.05,0.015,0.035",
                False,
                True,
            )
        )
        self.addParameter(
            QgsProcessingParameterBoolean("SNOOPING", self.tr("Data snooping (Baarda)"), True)
        )
        self.addParameter(
            QgsProcessingParameterFileDestination(
                "OUTPUT_TABLE", self.tr("Boresight per group (CSV)"), self.tr("CSV files (*.csv)")
            )
        )
        self.addParameter(
            QgsProcessingParameterFeatureSink(
                "OUTPUT_RESIDUALS", self.tr("Image residuals"), SOURCE_VECTOR_POINT
            )
        )
        self.addParameter(
            QgsProcessingParameterFileDestination(
                "RESIDUALS_CSV",
                self.tr("Image residuals (CSV)"),
                self.tr("CSV files (*.csv)"),
                optional=True,
                createByDefault=False,
            )
        )
        self.addParameter(
            QgsProcessingParameterFileDestination(
                "OUTPUT_EO",
                self.tr("Updated exterior orientation (CSV)"),
                self.tr("CSV files (*.csv)"),
            )
        )
        self.addParameter(
            QgsProcessingParameterFileDestination(
                "OUTPUT_HTML", self.tr("Summary (HTML)"), self.tr("HTML files (*.html)")
            )
        )
        self.addOutput(QgsProcessingOutputNumber("SIGMA0", self.tr("Sigma0 a-posteriori")))

    def processAlgorithm(self, parameters, context, feedback):
        from ...core.jobs.boresight_calibration import run_boresight_calibration
        from ...core.photo.boresight import BoresightNotObservable

        crs = self.parameterAsCrs(parameters, "CRS", context)
        if not crs.isValid():
            raise QgsProcessingException(self.tr("The mapping CRS is missing or invalid."))
        files = {
            k: self.parameterAsFile(parameters, k, context) or None
            for k in ("PLANES", "LINES", "LCPS", "CLOUD")
        }
        outs = {
            k: self.parameterAsFileOutput(parameters, k, context) or None
            for k in ("OUTPUT_TABLE", "RESIDUALS_CSV", "OUTPUT_EO", "OUTPUT_HTML")
        }
        types = self.parameterAsEnums(parameters, "CONTROL_TYPES", context)
        try:
            run = self.run_core(
                run_boresight_calibration,
                self.parameterAsFile(parameters, "CAMERA", context),
                self.parameterAsFile(parameters, "TRAJECTORY", context),
                crs.authid() or crs.toWkt(WKT_PREFERRED),
                self.parameterAsFile(parameters, "OBSERVATIONS", context),
                lever_arm=self.parameterAsString(parameters, "LEVER_ARM", context),
                mount=MOUNT_CHOICES[self.parameterAsEnum(parameters, "MOUNT", context)],
                mount_matrix=self.parameterAsString(parameters, "MOUNT_MATRIX", context),
                boresight=self.parameterAsString(parameters, "BORESIGHT", context),
                planes=files["PLANES"],
                lines=files["LINES"],
                lcps=files["LCPS"],
                cloud=files["CLOUD"],
                grouping=_GROUPINGS[self.parameterAsEnum(parameters, "GROUPING", context)],
                estimate_lever_arm=self.parameterAsBoolean(
                    parameters, "ESTIMATE_LEVER_ARM", context
                ),
                estimate_interior=self.parameterAsBoolean(parameters, "ESTIMATE_INTERIOR", context),
                ins_grade=_GRADES[self.parameterAsEnum(parameters, "INS_GRADE", context)],
                ins_sigmas=self.parameterAsString(parameters, "INS_SIGMAS", context),
                control_types=[_TYPES[i] for i in types],
                snooping=self.parameterAsBoolean(parameters, "SNOOPING", context),
                output_table=outs["OUTPUT_TABLE"],
                output_eo=outs["OUTPUT_EO"],
                output_html=outs["OUTPUT_HTML"],
                residuals_csv=outs["RESIDUALS_CSV"],
                feedback=feedback,
            )
        except QgsProcessingException as exc:
            cause = exc.__cause__
            if isinstance(cause, BoresightNotObservable):  # words, not the null vectors
                raise QgsProcessingException(" ".join(cause.diagnosis)) from cause
            raise
        for row in run.result.table_rows():
            feedback.pushInfo(
                f"{row['group']} {row['parameter']}: {row['value_deg']:.6f} deg "
                f'({row["value_arcsec"]:.1f}" +- {row["std_arcsec"]:.1f}")'
            )
        fields = QgsFields()
        for name, kind in _FIELDS:
            fields.append(QgsField(name, kind))
        sink, sink_id = self.parameterAsSink(
            parameters,
            "OUTPUT_RESIDUALS",
            context,
            fields,
            WKB_POINT_Z,
            QgsCoordinateReferenceSystem.fromWkt(run.crs_wkt),
        )
        if sink is None:
            raise QgsProcessingException(self.invalidSinkError(parameters, "OUTPUT_RESIDUALS"))
        for row in run.residual_rows():
            image, point, kind, target, group, x, y, z, *numbers, rejected, used = row
            if not all(math.isfinite(v) for v in (x, y, z)):
                continue  # no ground position (unknown image or target)
            feature = QgsFeature(fields)
            feature.setGeometry(QgsGeometry(QgsPoint(float(x), float(y), float(z))))
            values = [float(v) if math.isfinite(v) else NULL for v in numbers]
            feature.setAttributes([image, point, kind, target, group, *values, rejected, used])
            sink.addFeature(feature, SINK_FAST_INSERT)
        return {**outs, "OUTPUT_RESIDUALS": sink_id, "SIGMA0": run.result.sigma0}
