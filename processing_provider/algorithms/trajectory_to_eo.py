"""lidarphoto:trajectorytoeo - exterior orientation of each image from an INS/GNSS trajectory."""

from __future__ import annotations

import math

from qgis.core import QgsPoint

from ...core.jobs import trajectory_to_eo
from ..base import BaseAlgorithm
from ..compat import FIELD_DOUBLE, FIELD_STRING, WKB_POINT_Z

S, D = FIELD_STRING, FIELD_DOUBLE
_FIELDS = (
    ("image_id", S), ("time", D), ("group", S), ("X", D), ("Y", D), ("Z", D),
    ("omega_deg", D), ("phi_deg", D), ("kappa_deg", D),
)  # fmt: skip


class TrajectoryToEoAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.trajectory_to_eo``: the EO table as a PointZ layer."""

    JOB = trajectory_to_eo

    def write_layers(self, result, parameters, context, feedback) -> dict:
        table = result.data
        sink, dest = self.field_sink(
            parameters, context, "OUTPUT", _FIELDS, WKB_POINT_Z, table.crs_wkt
        )
        for i, image_id in enumerate(table.image_id):
            x, y, z = (float(v) for v in table.xyz[i])
            opk = [math.degrees(float(a)) for a in table.opk[i]]
            values = [image_id, float(table.time[i]), table.group[i], x, y, z, *opk]
            self.add_feature(sink, _FIELDS, QgsPoint(x, y, z), values)
        return {"OUTPUT": dest}
