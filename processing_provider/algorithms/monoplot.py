"""lidarphoto:monoplot - 3D points and lines from one oriented image and a LiDAR DSM."""

from __future__ import annotations

import math

from qgis.core import QgsLineString, QgsPoint

from ...core.jobs import monoplot
from ..base import BaseAlgorithm
from ..compat import FIELD_DOUBLE, FIELD_INT, FIELD_STRING, WKB_LINESTRING_Z, WKB_POINT_Z

S, D, N = FIELD_STRING, FIELD_DOUBLE, FIELD_INT
_POINT_FIELDS = (
    ("image_id", S), ("point_id", S), ("type", S), ("target_id", S), ("line", N),
    ("vertex", N), ("col", D), ("row", D), ("sigma_x", D), ("sigma_y", D), ("sigma_z", D),
    ("status", N), ("status_text", S), ("method", S), ("incidence_deg", D),
)  # fmt: skip
_LINE_FIELDS = (
    ("line", N), ("image_id", S), ("target_id", S), ("n_vertices", N), ("status", N),
    ("status_text", S), ("length", D), ("sigma_start", D), ("sigma_end", D),
)  # fmt: skip


class MonoplotAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.monoplot``: points and lines as layers."""

    JOB = monoplot

    def write_layers(self, result, parameters, context, feedback) -> dict:
        from ...core.photo.monoplot import STATUS_TEXT

        res = result.data
        points, pid = self.field_sink(parameters, context, "OUTPUT_POINTS", _POINT_FIELDS,
                                      WKB_POINT_Z, res.crs_wkt)  # fmt: skip
        sig = res.sigmas
        for k, (img, pt, kind, tgt, li, vi, how) in enumerate(res.rows):
            p = res.points[k]
            geom = QgsPoint(*map(float, p)) if all(map(math.isfinite, p)) else None
            st = int(res.status[k])
            values = [img, pt, kind, tgt, li, vi, *res.pixels[k], *sig[k], st, STATUS_TEXT[st],
                      how, res.incidence_deg[k]]  # fmt: skip
            self.add_feature(points, _POINT_FIELDS, geom, values)
        lines, lid = self.field_sink(parameters, context, "OUTPUT_LINES", _LINE_FIELDS,
                                     WKB_LINESTRING_Z, res.crs_wkt)  # fmt: skip
        for li, ln in enumerate(res.lines):
            v = [QgsPoint(*map(float, p)) for p in ln.vertices if all(map(math.isfinite, p))]
            length = sum(a.distance3D(b) for a, b in zip(v[:-1], v[1:]))
            values = [li, ln.image_id, ln.target_id, len(ln.vertices), ln.status,
                      STATUS_TEXT[ln.status], length, *ln.sigma_ends]  # fmt: skip
            self.add_feature(lines, _LINE_FIELDS, QgsLineString(v) if len(v) > 1 else None,
                             values)  # fmt: skip
        return {"OUTPUT_POINTS": pid, "OUTPUT_LINES": lid}
