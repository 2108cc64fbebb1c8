"""lidarphoto:bundleadjustment - aerotriangulation of a block with self-calibration."""

from __future__ import annotations

import math

from qgis.core import QgsPoint

from ...core.jobs import bundle_adjustment
from ..base import BaseAlgorithm
from ..compat import FIELD_DOUBLE, FIELD_INT, FIELD_STRING, WKB_POINT_Z

S, D, N = FIELD_STRING, FIELD_DOUBLE, FIELD_INT
_FIELDS = (
    ("point_id", S), ("role", S), ("sigma_x", D), ("sigma_y", D), ("sigma_z", D),
    ("n_images", N),
)  # fmt: skip


class BundleAdjustmentAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.bundle_adjustment``: the object points as a PointZ layer."""

    JOB = bundle_adjustment

    def write_layers(self, result, parameters, context, feedback) -> dict:
        res = result.data
        sink, dest = self.field_sink(parameters, context, "OUTPUT_POINTS_LAYER", _FIELDS,
                                     WKB_POINT_Z, res.eo.crs_wkt)  # fmt: skip
        for pid, role, xyz, sig, n in zip(res.point_id, res.point_role, res.point_xyz,
                                          res.point_sigma, res.point_images):  # fmt: skip
            if not all(math.isfinite(float(v)) for v in xyz):
                continue
            values = [pid, role, *(float(s) for s in sig), int(n)]
            self.add_feature(sink, _FIELDS, QgsPoint(*(float(v) for v in xyz)), values)
        return {"OUTPUT_POINTS_LAYER": dest}
