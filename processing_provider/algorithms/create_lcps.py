"""lidarphoto:createlcps - LiDAR control points and lines from intersecting roof planes."""

from __future__ import annotations

from qgis.core import (
    QgsCoordinateReferenceSystem,
    QgsLineString,
    QgsPoint,
    QgsProcessingOutputNumber,
    QgsProcessingParameterFeatureSink,
    QgsProcessingParameterFile,
    QgsProcessingParameterFileDestination,
    QgsProcessingParameterNumber,
    QgsProcessingParameterString,
)

from ..base import BaseAlgorithm
from ..compat import (
    FIELD_DOUBLE,
    FIELD_INT,
    FIELD_STRING,
    FILE_BEHAVIOR_FILE,
    FLAG_ADVANCED,
    NUMBER_DOUBLE,
    SOURCE_VECTOR_LINE,
    SOURCE_VECTOR_POINT,
    WKB_LINESTRING_Z,
    WKB_POINT_Z,
)

_POINT_FIELDS = (
    ("id", FIELD_INT), ("sigma_x", FIELD_DOUBLE), ("sigma_y", FIELD_DOUBLE),
    ("sigma_z", FIELD_DOUBLE), ("ellipsoid_a", FIELD_DOUBLE), ("ellipsoid_b", FIELD_DOUBLE),
    ("ellipsoid_c", FIELD_DOUBLE), ("plane_1", FIELD_INT), ("plane_2", FIELD_INT),
    ("plane_3", FIELD_INT), ("min_angle_deg", FIELD_DOUBLE), ("condition", FIELD_DOUBLE),
)  # fmt: skip
_LINE_FIELDS = (
    ("id", FIELD_INT), ("plane_1", FIELD_INT), ("plane_2", FIELD_INT),
    ("kind", FIELD_STRING), ("length", FIELD_DOUBLE), ("sigma_perpendicular", FIELD_DOUBLE),
    ("sigma_start", FIELD_DOUBLE), ("sigma_end", FIELD_DOUBLE), ("dihedral_deg", FIELD_DOUBLE),
)  # fmt: skip

_HELP = """<p>Intersects roof planes found by <i>Extract roof planes</i>: three planes meeting \
at a roof corner give a <b>LiDAR control point</b> (LCP), two adjacent planes give a \
<b>3D line</b> (ridge, hip, valley or other), each with a covariance propagated from the \
plane fits.</p>
<p><b>Planes</b>: the plane table CSV; <b>Cloud</b>: the LAS/LAZ written by the same algorithm \
(with its <i>plane_id</i> dimension). Two planes are <i>adjacent</i> when their points come within \
<b>delta</b> of each other along a common boundary at least <b>min boundary</b> long. A corner \
is kept only when every pair of its normals differ by at least <b>min angle</b>, the 3x3 system \
is well conditioned (<b>max condition</b>) and the point lies within <b>max support distance</b> \
of the points of each plane; where more than three planes meet (a pyramid apex) the most precise \
triple is kept. Lines are clipped to the common support of the two planes.</p>
<p>Distances are in the cloud's CRS unit (e.g. feet for a CRS in feet) unless <b>distance \
unit</b> is metres; the outputs are in the CRS unit. Optionally give your own plane-id \
<b>triples</b> ("1,2,3; 4,5,6") or <b>pairs</b> ("1,2; 2,3") instead of the automatic ones. \
Rejected candidates are listed in the log with the reason.</p>"""


class CreateLcpsAlgorithm(BaseAlgorithm):
    """Thin adapter of ``core.lidar_control.run_create_lcps``."""

    PLANES = "PLANES"
    CLOUD = "CLOUD"
    CRS = "CRS"
    DISTANCE_UNIT = "DISTANCE_UNIT"
    DELTA = "DELTA"
    MIN_BOUNDARY = "MIN_BOUNDARY"
    MIN_ANGLE = "MIN_ANGLE"
    MAX_CONDITION = "MAX_CONDITION"
    MAX_SUPPORT = "MAX_SUPPORT"
    TRIPLES = "TRIPLES"
    PAIRS = "PAIRS"
    OUTPUT_POINTS = "OUTPUT_POINTS"
    OUTPUT_LINES = "OUTPUT_LINES"
    POINTS_CSV = "POINTS_CSV"
    LINES_CSV = "LINES_CSV"
    GRAPH_CSV = "GRAPH_CSV"

    GROUP = "LiDAR"
    GROUP_ID = "lidar"
    TAGS = ("lcp", "control point", "roof", "ridge", "plane intersection", "covariance")

    def name(self) -> str:
        return "createlcps"

    def displayName(self) -> str:
        return self.tr("Create LiDAR control points and lines")

    def shortHelpString(self) -> str:
        return self.tr(_HELP)

    def initAlgorithm(self, config=None):
        self.addParameter(
            QgsProcessingParameterFile(
                self.PLANES, self.tr("Plane table (CSV)"), behavior=FILE_BEHAVIOR_FILE,
                fileFilter=self.tr("CSV files (*.csv);;All files (*.*)"),
            )
        )  # fmt: skip
        self.add_cloud_parameters(self.CLOUD, "Cloud with plane ids (LAS/LAZ)")
        for key, label, default in (
            (self.DELTA, "Adjacency distance delta", 1.0),
            (self.MIN_BOUNDARY, "Minimum common boundary", 2.0),
            (self.MAX_SUPPORT, "Maximum distance of a corner from each plane's points", 2.0),
        ):
            self.addParameter(
                QgsProcessingParameterNumber(key, self.tr(label), NUMBER_DOUBLE, default, False, 0)
            )
        self.addParameter(
            QgsProcessingParameterNumber(
                self.MIN_ANGLE, self.tr("Minimum angle between normals (degrees)"),
                NUMBER_DOUBLE, 10.0, False, 0.0, 90.0,
            )
        )  # fmt: skip
        self.addParameter(
            QgsProcessingParameterNumber(
                self.MAX_CONDITION, self.tr("Maximum condition number"), NUMBER_DOUBLE, 50.0,
                False, 1.0,
            )
        )  # fmt: skip
        for key, label in ((self.TRIPLES, "Plane triples"), (self.PAIRS, "Plane pairs")):
            param = QgsProcessingParameterString(key, self.tr(label), "", False, True)
            param.setFlags(param.flags() | FLAG_ADVANCED)
            self.addParameter(param)
        self.addParameter(
            QgsProcessingParameterFeatureSink(
                self.OUTPUT_POINTS, self.tr("LiDAR control points"), SOURCE_VECTOR_POINT
            )
        )
        self.addParameter(
            QgsProcessingParameterFeatureSink(
                self.OUTPUT_LINES, self.tr("LiDAR control lines"), SOURCE_VECTOR_LINE
            )
        )
        for key, label in (
            (self.POINTS_CSV, "Control point table (CSV)"),
            (self.LINES_CSV, "Control line table (CSV)"),
            (self.GRAPH_CSV, "Plane adjacency graph (CSV)"),
        ):
            self.addParameter(
                QgsProcessingParameterFileDestination(
                    key, self.tr(label), self.tr("CSV files (*.csv)"), optional=True,
                    createByDefault=False,
                )
            )  # fmt: skip
        self.addOutput(QgsProcessingOutputNumber("LCP_COUNT", self.tr("Number of LCPs")))
        self.addOutput(QgsProcessingOutputNumber("LINE_COUNT", self.tr("Number of lines")))

    def processAlgorithm(self, parameters, context, feedback):
        from ...core.lidar.control import ControlOptions, error_ellipsoid, run_create_lcps

        options = ControlOptions(
            delta=self.parameterAsDouble(parameters, self.DELTA, context),
            min_boundary=self.parameterAsDouble(parameters, self.MIN_BOUNDARY, context),
            min_angle_deg=self.parameterAsDouble(parameters, self.MIN_ANGLE, context),
            max_condition=self.parameterAsDouble(parameters, self.MAX_CONDITION, context),
            max_support_distance=self.parameterAsDouble(parameters, self.MAX_SUPPORT, context),
        )
        csvs = {k: self.parameterAsFileOutput(parameters, k, context) or None
                for k in (self.POINTS_CSV, self.LINES_CSV, self.GRAPH_CSV)}  # fmt: skip
        result, info = self.run_core(
            run_create_lcps,
            self.parameterAsFile(parameters, self.PLANES, context),
            self.parameterAsFile(parameters, self.CLOUD, context),
            crs=self.cloud_crs(parameters, context),
            options=options,
            triples=self.parameterAsString(parameters, self.TRIPLES, context),
            pairs=self.parameterAsString(parameters, self.PAIRS, context),
            points_csv=csvs[self.POINTS_CSV],
            lines_csv=csvs[self.LINES_CSV],
            graph_csv=csvs[self.GRAPH_CSV],
            distance_unit=self.distance_unit(parameters, context),
            feedback=feedback,
        )
        for rejection in result.rejected:
            feedback.pushInfo(f"planes {rejection.plane_ids}: {rejection.reason}")
        feedback.pushInfo(
            f"{len(result.points)} control points, {len(result.lines)} lines "
            f"(units: {info.horizontal_unit})"
        )
        layer_crs = QgsCoordinateReferenceSystem.fromWkt(info.crs.to_wkt()) if info.crs else None
        point_sink, point_id = self.field_sink(
            parameters, context, self.OUTPUT_POINTS, _POINT_FIELDS, WKB_POINT_Z, layer_crs
        )
        for p in result.points:
            axes, _ = error_ellipsoid(p.covariance)
            values = [p.id, *p.sigma, *axes, *p.plane_ids, p.min_angle_deg, p.condition]
            self.add_feature(point_sink, _POINT_FIELDS, QgsPoint(*map(float, p.xyz)), values)
        line_sink, line_id = self.field_sink(
            parameters, context, self.OUTPUT_LINES, _LINE_FIELDS, WKB_LINESTRING_Z, layer_crs
        )
        for ln in result.lines:
            geometry = QgsLineString(
                [QgsPoint(*map(float, ln.start)), QgsPoint(*map(float, ln.end))]
            )
            values = [ln.id, *ln.plane_ids, ln.kind, ln.length, ln.sigma_perpendicular,
                      *ln.sigma_ends, ln.dihedral_deg]  # fmt: skip
            self.add_feature(line_sink, _LINE_FIELDS, geometry, values)
        return {
            self.OUTPUT_POINTS: point_id,
            self.OUTPUT_LINES: line_id,
            **csvs,
            "LCP_COUNT": len(result.points),
            "LINE_COUNT": len(result.lines),
        }
