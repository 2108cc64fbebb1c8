"""lidarphoto:extractroofplanes - roof planes with their precision from a classified LAS/LAZ."""

from __future__ import annotations

from qgis.core import (
    Qgis,
    QgsCoordinateReferenceSystem,
    QgsFeature,
    QgsField,
    QgsFields,
    QgsGeometry,
    QgsLineString,
    QgsPolygon,
    QgsProcessing,
    QgsProcessingException,
    QgsProcessingOutputNumber,
    QgsProcessingOutputString,
    QgsProcessingParameterEnum,
    QgsProcessingParameterFeatureSink,
    QgsProcessingParameterFileDestination,
    QgsProcessingParameterNumber,
    QgsProcessingParameterString,
    QgsWkbTypes,
)

from ..base import BaseAlgorithm, core_errors
from ..compat import (
    FIELD_DOUBLE,
    FIELD_INT,
    FLAG_ADVANCED,
    SINK_FAST_INSERT,
)

if hasattr(Qgis, "WkbType"):  # QGIS >= 3.30
    WKB_POLYGON_Z = Qgis.WkbType.PolygonZ
else:
    WKB_POLYGON_Z = QgsWkbTypes.Type.PolygonZ
if hasattr(Qgis, "ProcessingSourceType"):  # QGIS >= 3.36
    SOURCE_VECTOR_POLYGON = Qgis.ProcessingSourceType.VectorPolygon
else:
    SOURCE_VECTOR_POLYGON = QgsProcessing.SourceType.TypeVectorPolygon

_INT, _DBL = QgsProcessingParameterNumber.Type.Integer, QgsProcessingParameterNumber.Type.Double
#: (parameter, RoofPlaneParams field, label, type, default, minimum, advanced)
_NUMBERS = (
    ("K_NEIGHBOURS", "k_neighbours", "Neighbours K of the local RANSAC", _INT, 20, 6, False),
    ("EPSILON", "epsilon", "Point-to-plane tolerance epsilon (length)", _DBL, 0.15, 0.0, False),
    ("MIN_SUPPORT", "min_support", "Minimum support of a local plane (points)", _INT, 18, 3, False),
    ("RANSAC_ITERATIONS", "ransac_iterations", "RANSAC triplets per point", _INT, 15, 1, True),
    ("MIN_SLOPE", "min_slope_deg", "Minimum slope alpha (degrees)", _DBL, 0.0, 0.0, False),
    ("MAX_SLOPE", "max_slope_deg", "Maximum slope beta (degrees)", _DBL, 70.0, 0.0, False),
    (
        "ANGLE_TOLERANCE",
        "angle_tolerance_deg",
        "Normal angle tolerance (degrees)",
        _DBL,
        10.0,
        0.0,
        True,
    ),
    ("MIN_PLANE_POINTS", "min_plane_points", "Minimum points per plane", _INT, 30, 3, False),
    (
        "OUTLINE_CELL",
        "outline_cell",
        "Outline raster cell (length, 0 = auto)",
        _DBL,
        0.0,
        0.0,
        True,
    ),
    ("SEED", "seed", "Random seed", _INT, 0, 0, True),
)
_SELECTIONS = ("non_ground", "classes", "all")
_TABLE = ("a", "b", "c", "d", "centroid_x", "centroid_y", "centroid_z")

_HELP = """<p>Extracts roof planes from a LiDAR cloud classified by a ground filter \
(paper 000, section 2.1): for every point, RANSAC on its K nearest neighbours with tolerance \
epsilon; the point is kept when the plane has the minimum support, the point lies on it and \
its slope is between alpha and beta (rejects vegetation and walls). Kept points are grown \
into regions (distance to the region's plane and normal angle), small regions dropped, ridge \
and eave points attached to the nearest plane, coplanar neighbours merged. Each plane is \
fitted by the weighted eigen method of Pathak et al. (2010) on centred coordinates, with the \
full covariance of (a, b, c, d) and the standard deviation of d (Khoshelham 2016). The same \
input and seed give the same planes.</p>
<h3>Points</h3><p>Non-ground (class != 2), the listed <b>Classes</b> (e.g. 6), or all points \
(a cloud that is already non-ground). <b>CRS</b> overrides the file's CRS.</p>
<h3>Units</h3><p>With <b>Distance unit</b> = cloud CRS units, epsilon and the outline cell are \
in the unit of the cloud's CRS (international feet for Autzen); with metres they are \
converted. Plane parameters, centroids, rms and sigma_d are always in the CRS unit (the UNIT \
output names it).</p>
<h3>Outputs</h3><p>Plane outlines (PolygonZ, concave hull for display) with every attribute; \
the plane table CSV: id, a, b, c, d (n.p + d = 0, normal up), centroid_x/y/z, n_points, rms, \
sigma_d, slope_deg, aspect_deg (clockwise from grid north, downslope), and the 10 \
upper-triangle covariance elements cov_aa ... cov_dd; optionally a copy of the cloud with the \
int32 extra dimension plane_id (-1 = none). A cloud without roofs gives zero planes and a \
message, not an error.</p>"""


class ExtractRoofPlanesAlgorithm(BaseAlgorithm):
    """Thin adapter of ``core.roof_planes.run_extract_roof_planes``."""

    INPUT = "INPUT"
    CRS = "CRS"
    DISTANCE_UNIT = "DISTANCE_UNIT"
    POINTS = "POINTS"
    CLASSES = "CLASSES"
    OUTPUT = "OUTPUT"
    OUTPUT_CSV = "OUTPUT_CSV"
    OUTPUT_CLOUD = "OUTPUT_CLOUD"

    GROUP = "LiDAR"
    GROUP_ID = "lidar"
    TAGS = ("roof", "plane", "ransac", "building", "las", "laz", "point cloud", "segmentation")

    def name(self) -> str:
        return "extractroofplanes"

    def displayName(self) -> str:
        return self.tr("Extract roof planes")

    def shortHelpString(self) -> str:
        return self.tr(_HELP)

    def initAlgorithm(self, config=None):
        self.add_cloud_parameters(self.INPUT)
        points = [self.tr("non-ground (class != 2)"), self.tr("the classes below"), self.tr("all")]
        self.addParameter(
            QgsProcessingParameterEnum(self.POINTS, self.tr("Points"), points, False, 0)
        )
        self.addParameter(
            QgsProcessingParameterString(
                self.CLASSES, self.tr("Classes (e.g. 6)"), "6", False, True
            )
        )
        for key, _f, label, kind, default, minimum, advanced in _NUMBERS:
            param = QgsProcessingParameterNumber(key, self.tr(label), kind, default, False, minimum)
            if advanced:
                param.setFlags(param.flags() | FLAG_ADVANCED)
            self.addParameter(param)
        self.addParameter(
            QgsProcessingParameterFeatureSink(
                self.OUTPUT, self.tr("Roof planes"), SOURCE_VECTOR_POLYGON
            )
        )
        self.addParameter(
            QgsProcessingParameterFileDestination(
                self.OUTPUT_CSV, self.tr("Plane table (CSV)"), self.tr("CSV files (*.csv)")
            )
        )
        self.addParameter(
            QgsProcessingParameterFileDestination(
                self.OUTPUT_CLOUD,
                self.tr("Point cloud with plane_id"),
                self.tr("LAZ files (*.laz);;LAS files (*.las)"),
                optional=True,
                createByDefault=False,
            )
        )
        self.addOutput(QgsProcessingOutputNumber("PLANE_COUNT", self.tr("Number of planes")))
        self.addOutput(QgsProcessingOutputString("UNIT", self.tr("Unit of the lengths")))

    def processAlgorithm(self, parameters, context, feedback):
        from ...core.geometry.planes import COV_COLUMNS
        from ...core.lidar.roof_planes import RoofPlaneParams, run_extract_roof_planes

        values = {}
        for key, field, _l, kind, *_ in _NUMBERS:
            get = self.parameterAsInt if kind == _INT else self.parameterAsDouble
            values[field] = get(parameters, key, context)
        with core_errors():
            params = RoofPlaneParams(**values)
        out_csv = self.parameterAsFileOutput(parameters, self.OUTPUT_CSV, context)
        out_cloud = self.parameterAsFileOutput(parameters, self.OUTPUT_CLOUD, context)
        run = self.run_core(
            run_extract_roof_planes,
            self.parameterAsFile(parameters, self.INPUT, context),
            params=params,
            units=self.distance_unit(parameters, context),
            selection=_SELECTIONS[self.parameterAsEnum(parameters, self.POINTS, context)],
            classes=self.parameterAsString(parameters, self.CLASSES, context),
            crs=self.cloud_crs(parameters, context),
            output_csv=out_csv,
            output_cloud=out_cloud or None,
            feedback=feedback,
        )
        for message in run.messages:
            feedback.pushInfo(message)
        names = ["id", *_TABLE, "n_points", "rms", "sigma_d", "slope_deg", "aspect_deg"]
        fields = QgsFields()
        for name in [*names, *COV_COLUMNS]:
            fields.append(QgsField(name, FIELD_INT if name in ("id", "n_points") else FIELD_DOUBLE))
        sink_crs = QgsCoordinateReferenceSystem.fromWkt(run.crs_wkt)
        sink, dest_id = self.parameterAsSink(
            parameters, self.OUTPUT, context, fields, WKB_POLYGON_Z, sink_crs
        )
        if sink is None:
            raise QgsProcessingException(self.invalidSinkError(parameters, self.OUTPUT))
        for plane in run.result.planes:
            if feedback.isCanceled():
                break
            feature = QgsFeature(fields)
            if len(plane.outline) >= 3:
                ring = [*plane.outline, plane.outline[0]]
                line = QgsLineString(
                    [float(p[0]) for p in ring],
                    [float(p[1]) for p in ring],
                    [float(p[2]) for p in ring],
                )
                polygon = QgsPolygon()
                polygon.setExteriorRing(line)
                feature.setGeometry(QgsGeometry(polygon))
            table = [*plane.normal, plane.d, *plane.centroid]
            upper = plane.covariance[[0, 0, 0, 0, 1, 1, 1, 2, 2, 3], [0, 1, 2, 3, 1, 2, 3, 2, 3, 3]]
            feature.setAttributes(
                [
                    int(plane.id),
                    *(float(v) for v in table),
                    int(plane.n_points),
                    float(plane.rms),
                    float(plane.sigma_d),
                    float(plane.slope_deg),
                    float(plane.aspect_deg),
                    *(float(v) for v in upper),
                ]
            )
            sink.addFeature(feature, SINK_FAST_INSERT)
        return {
            self.OUTPUT: dest_id,
            self.OUTPUT_CSV: out_csv,
            self.OUTPUT_CLOUD: out_cloud or None,
            "PLANE_COUNT": len(run.result.planes),
            "UNIT": run.unit,
        }
