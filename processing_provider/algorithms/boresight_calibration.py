"""lidarphoto:boresightcalibration - boresight from LiDAR roof planes, lines and LCPs."""

from __future__ import annotations

import math

from qgis.core import QgsPoint, QgsProcessingException

from ...core.jobs import boresight_calibration
from ..base import BaseAlgorithm
from ..compat import FIELD_DOUBLE, FIELD_INT, FIELD_STRING, WKB_POINT_Z
from ..layer_styles import style_image_residuals

S, D, N = FIELD_STRING, FIELD_DOUBLE, FIELD_INT
_FIELDS = (
    ("image_id", S), ("point_id", S), ("type", S), ("target_id", S), ("group", S),
    ("col", D), ("row", D), ("vx", D), ("vy", D), ("v", D), ("v_d", D), ("w", D),
    ("rejected", N), ("used", N),
)  # fmt: skip


class BoresightCalibrationAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.boresight_calibration``: residuals as a PointZ layer."""

    JOB = boresight_calibration
    STYLES = (("OUTPUT_RESIDUALS", style_image_residuals),)

    def processAlgorithm(self, parameters, context, feedback):
        from ...core.photo.boresight import BoresightNotObservable

        try:
            return super().processAlgorithm(parameters, context, feedback)
        except QgsProcessingException as exc:
            if isinstance(exc.__cause__, BoresightNotObservable):  # words, not null vectors
                raise QgsProcessingException(" ".join(exc.__cause__.diagnosis)) from exc
            raise

    def write_layers(self, result, parameters, context, feedback) -> dict:
        run = result.data
        sink, dest = self.field_sink(parameters, context, "OUTPUT_RESIDUALS", _FIELDS,
                                     WKB_POINT_Z, run.crs_wkt)  # fmt: skip
        for row in run.residual_rows():
            image, point, kind, target, group, x, y, z, *numbers, rejected, used = row
            if not all(math.isfinite(v) for v in (x, y, z)):
                continue  # no ground position (unknown image or target)
            values = [image, point, kind, target, group, *numbers, rejected, used]
            self.add_feature(sink, _FIELDS, QgsPoint(float(x), float(y), float(z)), values)
        return {"OUTPUT_RESIDUALS": dest}
