"""lidarphoto:extractroofplanes - roof planes with their precision from a classified LAS/LAZ."""

from __future__ import annotations

from qgis.core import QgsLineString, QgsPolygon

from ...core.jobs import extract_roof_planes
from ..base import BaseAlgorithm
from ..compat import FIELD_DOUBLE, FIELD_INT, WKB_POLYGON_Z
from ..layer_styles import style_planes

_NAMES = (
    "id", "a", "b", "c", "d", "centroid_x", "centroid_y", "centroid_z", "n_points", "rms",
    "sigma_d", "slope_deg", "aspect_deg",
    "cov_aa", "cov_ab", "cov_ac", "cov_ad", "cov_bb", "cov_bc", "cov_bd", "cov_cc", "cov_cd",
    "cov_dd",
)  # fmt: skip
_FIELDS = tuple((n, FIELD_INT if n in ("id", "n_points") else FIELD_DOUBLE) for n in _NAMES)
_UPPER = ([0, 0, 0, 0, 1, 1, 1, 2, 2, 3], [0, 1, 2, 3, 1, 2, 3, 2, 3, 3])


class ExtractRoofPlanesAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.extract_roof_planes``: plane outlines as a PolygonZ layer."""

    JOB = extract_roof_planes
    STYLES = (("OUTPUT", style_planes),)

    def write_layers(self, result, parameters, context, feedback) -> dict:
        run = result.data
        sink, dest = self.field_sink(
            parameters, context, "OUTPUT", _FIELDS, WKB_POLYGON_Z, run.crs_wkt
        )
        for plane in run.result.planes:
            polygon = None
            if len(plane.outline) >= 3:
                ring = [*plane.outline, plane.outline[0]]
                polygon = QgsPolygon()
                polygon.setExteriorRing(
                    QgsLineString([p[0] for p in ring], [p[1] for p in ring], [p[2] for p in ring])
                )
            values = [
                plane.id, *plane.normal, plane.d, *plane.centroid, plane.n_points, plane.rms,
                plane.sigma_d, plane.slope_deg, plane.aspect_deg, *plane.covariance[_UPPER],
            ]  # fmt: skip
            self.add_feature(sink, _FIELDS, polygon, values)
        return {"OUTPUT": dest}
