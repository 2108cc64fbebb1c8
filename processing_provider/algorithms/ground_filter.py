"""lidarphoto:groundfilter - progressive morphological ground filter of a LAS/LAZ cloud."""

from __future__ import annotations

from qgis.core import (
    QgsProcessingException,
    QgsProcessingOutputNumber,
    QgsProcessingOutputString,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterEnum,
    QgsProcessingParameterFileDestination,
    QgsProcessingParameterNumber,
    QgsProcessingParameterRasterDestination,
)

from ..base import BaseAlgorithm, core_errors
from ..compat import FLAG_ADVANCED

#: (parameter, GroundFilterParams field, label, default, advanced) of the numeric parameters.
_NUMBERS = (
    ("CELL_SIZE", "cell_size", "Cell size (horizontal)", 1.0, False),
    ("MAX_WINDOW", "max_window", "Maximum window size (horizontal)", 20.0, False),
    ("SLOPE", "slope", "Terrain slope (rise/run, dimensionless)", 0.2, False),
    ("INITIAL_DISTANCE", "initial_distance", "Initial elevation threshold (vertical)", 0.3, False),
    ("MAX_DISTANCE", "max_distance", "Maximum elevation threshold (vertical)", 2.5, False),
    ("WINDOW_BASE", "window_base", "Window growth base b (cells)", 1.0, True),
    ("GROUND_THRESHOLD", "ground_threshold", "Final height tolerance (vertical)", 0.3, False),
    ("SLOPE_SCALAR", "slope_scalar", "Tolerance added per unit of slope (vertical)", 1.0, True),
    ("LOW_OUTLIER_HEIGHT", "low_outlier_height", "Low outlier depth (0 = off)", 1.0, True),
    ("LOW_OUTLIER_RADIUS", "low_outlier_radius", "Low outlier radius (horizontal)", 5.0, True),
)
_GROWTH = ("linear", "exponential")
_SHAPES = ("square", "disk")
_NON_GROUND = (None, 1)

_HELP = """<p>Separates ground from objects with the Progressive Morphological Filter \
(Zhang et al. 2003): minimum grid, openings with growing windows and slope-dependent \
elevation thresholds, then each point is ground when its height above the filtered surface \
is within a slope-dependent tolerance (as in SMRF). Low outliers are removed first (class 7); \
only last returns can be ground when the file has return numbers.</p>
<h3>Units</h3><p>With <b>Distance unit</b> = cloud CRS units, every length is in the unit of \
the cloud's CRS (e.g. international feet for Autzen); with metres, they are converted. The log \
and the UNIT output say which unit was used. <b>CRS</b> overrides the file's CRS (needed when \
the file has none).</p>
<h3>Outputs</h3><p>A copy of the cloud (LAS/LAZ by suffix) with every original dimension and \
VLR, class 2 for ground (other classes kept, or set to 1), and the extra dimension \
height_above_ground (float32); optionally the DTM as GeoTIFF.</p>"""


class GroundFilterAlgorithm(BaseAlgorithm):
    """Thin adapter of ``core.ground_filter.run_ground_filter``."""

    INPUT = "INPUT"
    CRS = "CRS"
    DISTANCE_UNIT = "DISTANCE_UNIT"
    GROWTH = "GROWTH"
    WINDOW_SHAPE = "WINDOW_SHAPE"
    LAST_RETURNS_ONLY = "LAST_RETURNS_ONLY"
    NON_GROUND_CLASS = "NON_GROUND_CLASS"
    OUTPUT_CLOUD = "OUTPUT_CLOUD"
    OUTPUT_DTM = "OUTPUT_DTM"

    GROUP = "LiDAR"
    GROUP_ID = "lidar"
    TAGS = ("ground", "dtm", "pmf", "morphological", "las", "laz", "point cloud", "classification")

    def name(self) -> str:
        return "groundfilter"

    def displayName(self) -> str:
        return self.tr("Ground filter (progressive morphological)")

    def shortHelpString(self) -> str:
        return self.tr(_HELP)

    def initAlgorithm(self, config=None):
        self.add_cloud_parameters(self.INPUT)
        for key, _field, label, default, advanced in _NUMBERS:
            param = QgsProcessingParameterNumber(
                key, self.tr(label), QgsProcessingParameterNumber.Type.Double, default, False, 0.0
            )
            if advanced:
                param.setFlags(param.flags() | FLAG_ADVANCED)
            self.addParameter(param)
        for key, label, options in (
            (self.GROWTH, "Window growth", _GROWTH),
            (self.WINDOW_SHAPE, "Window shape", _SHAPES),
        ):
            param = QgsProcessingParameterEnum(key, self.tr(label), list(options), False, 0)
            param.setFlags(param.flags() | FLAG_ADVANCED)
            self.addParameter(param)
        self.addParameter(
            QgsProcessingParameterBoolean(
                self.LAST_RETURNS_ONLY, self.tr("Only last returns can be ground"), True
            )
        )
        self.addParameter(
            QgsProcessingParameterEnum(
                self.NON_GROUND_CLASS,
                self.tr("Non-ground points"),
                [self.tr("keep their class"), self.tr("set to 1 (unclassified)")],
                False,
                0,
            )
        )
        self.addParameter(
            QgsProcessingParameterFileDestination(
                self.OUTPUT_CLOUD,
                self.tr("Classified point cloud"),
                self.tr("LAZ files (*.laz);;LAS files (*.las)"),
            )
        )
        self.addParameter(
            QgsProcessingParameterRasterDestination(
                self.OUTPUT_DTM, self.tr("DTM"), optional=True, createByDefault=False
            )
        )
        for key, label in (
            ("POINT_COUNT", "Number of points"),
            ("GROUND_COUNT", "Number of ground points"),
            ("LOW_OUTLIER_COUNT", "Number of low outliers"),
        ):
            self.addOutput(QgsProcessingOutputNumber(key, self.tr(label)))
        self.addOutput(QgsProcessingOutputString("UNIT", self.tr("Unit of the distances")))

    def processAlgorithm(self, parameters, context, feedback):
        from ...core.lidar.ground_filter import GroundFilterParams, run_ground_filter

        values = {f: self.parameterAsDouble(parameters, key, context) for key, f, *_ in _NUMBERS}
        params = GroundFilterParams(
            **values,
            growth=_GROWTH[self.parameterAsEnum(parameters, self.GROWTH, context)],
            window_shape=_SHAPES[self.parameterAsEnum(parameters, self.WINDOW_SHAPE, context)],
            last_returns_only=self.parameterAsBool(parameters, self.LAST_RETURNS_ONLY, context),
            distance_unit=self.distance_unit(parameters, context),
        )
        out_cloud = self.parameterAsFileOutput(parameters, self.OUTPUT_CLOUD, context)
        out_dtm = self.parameterAsOutputLayer(parameters, self.OUTPUT_DTM, context)
        run = self.run_core(
            run_ground_filter,
            self.parameterAsFile(parameters, self.INPUT, context),
            out_cloud,
            params,
            crs=self.cloud_crs(parameters, context),
            non_ground_class=_NON_GROUND[
                self.parameterAsEnum(parameters, self.NON_GROUND_CLASS, context)
            ],
            feedback=feedback,
        )
        feedback.pushInfo(self.tr("Distances interpreted in: {}").format(run.unit))
        if out_dtm:
            self._write_dtm(out_dtm, run)
        return {
            self.OUTPUT_CLOUD: out_cloud,
            self.OUTPUT_DTM: out_dtm or None,
            "POINT_COUNT": run.point_count,
            "GROUND_COUNT": run.ground_count,
            "LOW_OUTLIER_COUNT": run.low_outlier_count,
            "UNIT": run.unit,
        }

    def _write_dtm(self, path: str, run) -> None:
        """GeoTIFF through GDAL, written next to ``path`` and moved into place when complete."""
        import os
        import tempfile

        from osgeo import gdal

        dtm = run.result.dtm
        fd, tmp = tempfile.mkstemp(suffix=".tif", dir=os.path.dirname(os.path.abspath(path)))
        os.close(fd)
        try:
            with core_errors():
                ds = gdal.GetDriverByName("GTiff").Create(
                    tmp, dtm.shape[1], dtm.shape[0], 1, gdal.GDT_Float32
                )
                if ds is None:
                    raise QgsProcessingException(self.tr("Cannot create {}").format(path))
                ds.SetGeoTransform(run.result.geotransform)
                if run.crs_wkt:
                    ds.SetProjection(run.crs_wkt)
                band = ds.GetRasterBand(1)
                band.SetNoDataValue(run.result.nodata)
                band.WriteArray(dtm)
                band = ds = None  # closes and flushes the file
                os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.remove(tmp)
