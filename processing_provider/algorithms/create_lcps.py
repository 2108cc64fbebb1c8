"""lidarphoto:createlcps - LiDAR control points and lines from intersecting roof planes."""

from __future__ import annotations

from qgis.core import QgsLineString, QgsPoint

from ...core.jobs import create_lcps
from ..base import BaseAlgorithm
from ..compat import FIELD_DOUBLE, FIELD_INT, FIELD_STRING, WKB_LINESTRING_Z, WKB_POINT_Z
from ..layer_styles import style_control_lines, style_lcps

N, D, S = FIELD_INT, FIELD_DOUBLE, FIELD_STRING
_POINT_FIELDS = (
    ("id", N), ("sigma_x", D), ("sigma_y", D), ("sigma_z", D), ("ellipsoid_a", D),
    ("ellipsoid_b", D), ("ellipsoid_c", D), ("plane_1", N), ("plane_2", N), ("plane_3", N),
    ("min_angle_deg", D), ("condition", D),
)  # fmt: skip
_LINE_FIELDS = (
    ("id", N), ("plane_1", N), ("plane_2", N), ("kind", S), ("length", D),
    ("sigma_perpendicular", D), ("sigma_start", D), ("sigma_end", D), ("dihedral_deg", D),
)  # fmt: skip


class CreateLcpsAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.create_lcps``: control points and lines as layers."""

    JOB = create_lcps
    STYLES = (("OUTPUT_POINTS", style_lcps), ("OUTPUT_LINES", style_control_lines))

    def write_layers(self, result, parameters, context, feedback) -> dict:
        from ...core.lidar.control import error_ellipsoid

        control, info = result.data
        crs = info.crs.to_wkt() if info.crs else None
        points, point_id = self.field_sink(
            parameters, context, "OUTPUT_POINTS", _POINT_FIELDS, WKB_POINT_Z, crs
        )
        for p in control.points:
            axes, _ = error_ellipsoid(p.covariance)
            values = [p.id, *p.sigma, *axes, *p.plane_ids, p.min_angle_deg, p.condition]
            self.add_feature(points, _POINT_FIELDS, QgsPoint(*map(float, p.xyz)), values)
        lines, line_id = self.field_sink(
            parameters, context, "OUTPUT_LINES", _LINE_FIELDS, WKB_LINESTRING_Z, crs
        )
        for ln in control.lines:
            geometry = QgsLineString(
                [QgsPoint(*map(float, ln.start)), QgsPoint(*map(float, ln.end))]
            )
            values = [ln.id, *ln.plane_ids, ln.kind, ln.length, ln.sigma_perpendicular,
                      *ln.sigma_ends, ln.dihedral_deg]  # fmt: skip
            self.add_feature(lines, _LINE_FIELDS, geometry, values)
        return {"OUTPUT_POINTS": point_id, "OUTPUT_LINES": line_id}
