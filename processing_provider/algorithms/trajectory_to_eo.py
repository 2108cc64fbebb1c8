"""lidarphoto:trajectorytoeo - exterior orientation of each image from an INS/GNSS trajectory."""

from __future__ import annotations

import math

from qgis.core import (
    NULL,
    QgsFeature,
    QgsField,
    QgsFields,
    QgsGeometry,
    QgsPoint,
    QgsProcessingException,
    QgsProcessingOutputNumber,
    QgsProcessingParameterCrs,
    QgsProcessingParameterEnum,
    QgsProcessingParameterFeatureSink,
    QgsProcessingParameterFile,
    QgsProcessingParameterFileDestination,
    QgsProcessingParameterString,
)

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

try:
    from ...core.photo.georeference import MOUNT_CHOICES
except ImportError:  # a third-party package of the core is missing: canExecute() says which
    MOUNT_CHOICES = (
        "image_top_forward",
        "image_right_forward",
        "image_bottom_forward",
        "image_left_forward",
        "custom",
    )

_MOUNT_LABELS = {
    "image_top_forward": "image top towards the flight direction (nose)",
    "image_right_forward": "image right side towards the flight direction",
    "image_bottom_forward": "image bottom towards the flight direction",
    "image_left_forward": "image left side towards the flight direction",
    "custom": "custom matrix (MOUNT_MATRIX)",
}

_FIELDS = ("image_id", "time", "group", "X", "Y", "Z", "omega_deg", "phi_deg", "kappa_deg")
_TEXT_FIELDS = ("image_id", "group")

_HELP = """<p>Computes the exterior orientation (perspective centre and omega, phi, kappa) \
of every image from the INS/GNSS solution at its exposure time (direct georeferencing: \
X_pc = X_ins + R_b^m a_b, R_c^m = R_b^m R_c^b, composed rigorously through the Earth-centred \
frame, so grid convergence and Earth curvature are accounted for).</p>
<h3>Trajectory table (INPUT)</h3>
<p>CSV with a header row (column names are case-insensitive) and one row per image:</p>
<ul><li><b>image_id</b> (unique) and <b>time</b> (seconds);</li>
<li>either <b>easting, northing, height</b> in the mapping CRS, or <b>latitude, longitude, \
height</b> (degrees, on the geodetic datum of the CRS); heights in metres;</li>
<li><b>roll, pitch, heading</b> in degrees; body frame x forward, y right, z down; heading \
clockwise from true north;</li>
<li>optional <b>group</b> (flight line, camera, ...).</li></ul>
<h3>Mounting</h3>
<p><b>Lever arm</b>: "x,y,z", the camera perspective centre in the body frame, metres. \
<b>Camera mount</b>: the nominal camera-to-body rotation; <i>custom</i> uses <b>Mount matrix</b> \
(advanced), 9 numbers row-major R_c^b. <b>Boresight</b>: "domega,dphi,dkappa", the small \
misalignment in degrees about the camera axes x, y, z.</p>
<h3>Outputs</h3>
<p>A PointZ layer in the mapping CRS with image_id, time, group, X, Y, Z, omega_deg, phi_deg, \
kappa_deg (angles relative to the grid frame at each image), optionally the same table as \
CSV, and the number of images.</p>"""


class TrajectoryToEoAlgorithm(BaseAlgorithm):
    """Thin adapter of ``core.trajectory_to_eo.run_trajectory_to_eo``."""

    INPUT = "INPUT"
    CRS = "CRS"
    LEVER_ARM = "LEVER_ARM"
    MOUNT = "MOUNT"
    MOUNT_MATRIX = "MOUNT_MATRIX"
    BORESIGHT = "BORESIGHT"
    OUTPUT = "OUTPUT"
    OUTPUT_CSV = "OUTPUT_CSV"
    IMAGE_COUNT = "IMAGE_COUNT"

    GROUP = "Direct georeferencing"
    GROUP_ID = "georeferencing"
    TAGS = ("trajectory", "ins", "gnss", "imu", "exterior orientation", "omega phi kappa")

    def name(self) -> str:
        return "trajectorytoeo"

    def displayName(self) -> str:
        return self.tr("Trajectory to exterior orientation")

    def shortHelpString(self) -> str:
        return self.tr(_HELP)

    def initAlgorithm(self, config=None):
        self.addParameter(
            QgsProcessingParameterFile(
                self.INPUT,
                self.tr("Trajectory table (CSV)"),
                behavior=FILE_BEHAVIOR_FILE,
                fileFilter=self.tr("CSV files (*.csv *.txt);;All files (*.*)"),
            )
        )
        self.addParameter(
            QgsProcessingParameterCrs(self.CRS, self.tr("Mapping CRS (projected)"), "ProjectCrs")
        )
        self.addParameter(
            QgsProcessingParameterString(
                self.LEVER_ARM, self.tr("Lever arm x,y,z (m, body frame)"), "0,0,0"
            )
        )
        options = [f"{name}: {self.tr(_MOUNT_LABELS.get(name, name))}" for name in MOUNT_CHOICES]
        self.addParameter(
            QgsProcessingParameterEnum(self.MOUNT, self.tr("Camera mount"), options, False, 0)
        )
        matrix = QgsProcessingParameterString(
            self.MOUNT_MATRIX, self.tr("Mount matrix R_c^b (9 numbers, row-major)"), "", False, True
        )
        matrix.setFlags(matrix.flags() | FLAG_ADVANCED)
        self.addParameter(matrix)
        self.addParameter(
            QgsProcessingParameterString(
                self.BORESIGHT, self.tr("Boresight domega,dphi,dkappa (degrees)"), "0,0,0"
            )
        )
        self.addParameter(
            QgsProcessingParameterFeatureSink(
                self.OUTPUT, self.tr("Exterior orientation"), SOURCE_VECTOR_POINT
            )
        )
        self.addParameter(
            QgsProcessingParameterFileDestination(
                self.OUTPUT_CSV,
                self.tr("Exterior orientation table (CSV)"),
                self.tr("CSV files (*.csv)"),
                optional=True,
                createByDefault=False,
            )
        )
        self.addOutput(QgsProcessingOutputNumber(self.IMAGE_COUNT, self.tr("Number of images")))

    def processAlgorithm(self, parameters, context, feedback):
        from ...core.photo.georeference import run_trajectory_to_eo

        crs = self.parameterAsCrs(parameters, self.CRS, context)
        if not crs.isValid():
            raise QgsProcessingException(self.tr("The mapping CRS is missing or invalid."))
        out_csv = self.parameterAsFileOutput(parameters, self.OUTPUT_CSV, context)
        table = self.run_core(
            run_trajectory_to_eo,
            self.parameterAsFile(parameters, self.INPUT, context),
            crs.authid() or crs.toWkt(WKT_PREFERRED),
            lever_arm=self.parameterAsString(parameters, self.LEVER_ARM, context),
            mount=MOUNT_CHOICES[self.parameterAsEnum(parameters, self.MOUNT, context)],
            mount_matrix=self.parameterAsString(parameters, self.MOUNT_MATRIX, context),
            boresight=self.parameterAsString(parameters, self.BORESIGHT, context),
            feedback=feedback,
        )
        if out_csv:
            with core_errors():
                table.to_csv(out_csv)

        fields = QgsFields()
        for name in _FIELDS:
            fields.append(QgsField(name, FIELD_STRING if name in _TEXT_FIELDS else FIELD_DOUBLE))
        sink, dest_id = self.parameterAsSink(
            parameters, self.OUTPUT, context, fields, WKB_POINT_Z, crs
        )
        if sink is None:
            raise QgsProcessingException(self.invalidSinkError(parameters, self.OUTPUT))
        for i, image_id in enumerate(table.image_id):
            if feedback.isCanceled():
                break
            x, y, z = (float(v) for v in table.xyz[i])
            opk = [math.degrees(float(a)) for a in table.opk[i]]
            feature = QgsFeature(fields)
            feature.setGeometry(QgsGeometry(QgsPoint(x, y, z)))
            time = float(table.time[i])  # NaN when the table has no time
            feature.setAttributes(
                [str(image_id), time if math.isfinite(time) else NULL, str(table.group[i]), x, y, z]
                + opk
            )
            sink.addFeature(feature, SINK_FAST_INSERT)
        return {
            self.OUTPUT: dest_id,
            self.OUTPUT_CSV: out_csv or None,
            self.IMAGE_COUNT: len(table.image_id),
        }
