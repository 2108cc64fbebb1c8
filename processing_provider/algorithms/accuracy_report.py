"""lidarphoto:accuracyreport - positional accuracy of check points against published standards."""

from __future__ import annotations

import math

from qgis.core import (
    NULL,
    QgsCoordinateTransform,
    QgsPoint,
    QgsPointXY,
    QgsProcessingException,
)

from ...core.jobs import accuracy_report
from ..base import BaseAlgorithm, core_errors
from ..compat import FIELD_DOUBLE, FIELD_INT, FIELD_STRING, WKB_POINT_Z, WKT_PREFERRED
from ..layer_styles import style_discrepancies

S, D = FIELD_STRING, FIELD_DOUBLE
_FIELDS = (
    ("id", S), ("group", S), ("dE", D), ("dN", D), ("dU", D), ("dHorizontal", D), ("d3D", D),
    ("outlier", FIELD_INT),
)  # fmt: skip


class AccuracyReportAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.accuracy_report``: point layers in, check points out as a layer."""

    JOB = accuracy_report
    STYLES = (("OUTPUT", style_discrepancies),)

    def prepare(self, raw, parameters, context, feedback):
        """Two point layers become core PointSets (the reference reprojected on request)."""
        if raw["MEASURED"] is None or raw["REFERENCE"] is None:
            return raw
        measured = self._layer_points(parameters, context, "MEASURED", "GROUP_FIELD", None)
        to_crs = raw["MEASURED"].sourceCrs() if raw["REPROJECT"] else None
        reference = self._layer_points(parameters, context, "REFERENCE", None, to_crs)
        return {**raw, "MEASURED": measured, "REFERENCE": reference, "REPROJECT": False}

    def _layer_points(self, parameters, context, key, group_key, to_crs):
        """A point layer as a core PointSet (reprojected to ``to_crs`` if given)."""
        from ...core.quality.accuracy import point_set

        source = self.parameterAsSource(parameters, key, context)
        id_field = (self.parameterAsFields(parameters, f"{key}_ID", context) or [None])[0]
        if id_field is None:
            raise QgsProcessingException(self.tr("{0}: choose its id field ({0}_ID).").format(key))
        z_field = (self.parameterAsFields(parameters, f"{key}_Z_FIELD", context) or [None])[0]
        group = None
        if group_key:
            group = (self.parameterAsFields(parameters, group_key, context) or [None])[0]
        xform = None
        if to_crs is not None and to_crs != source.sourceCrs():
            xform = QgsCoordinateTransform(source.sourceCrs(), to_crs, context.transformContext())
        ids, xyz, groups, fids = [], [], [], []
        for f in source.getFeatures():
            geom = f.geometry()
            p = geom.constGet() if not geom.isNull() else None
            if p is not None and geom.isMultipart():
                p = p.geometryN(0) if p.numGeometries() == 1 else None
            if p is None:
                x = y = z = math.nan
            else:
                x, y, z = p.x(), p.y(), (p.z() if p.is3D() else math.nan)
                if xform is not None:
                    q = xform.transform(QgsPointXY(x, y))
                    x, y = q.x(), q.y()
            if z_field:
                value = f[z_field]
                z = math.nan if value is None or value == NULL else float(value)
            ids.append(f[id_field])
            xyz.append((x, y, z))
            groups.append("" if not group or f[group] == NULL else f[group])
            fids.append(f.id())
        crs = to_crs if to_crs is not None else source.sourceCrs()
        with core_errors():
            return point_set(
                ids, xyz, groups,
                crs=(crs.authid() or crs.toWkt(WKT_PREFERRED)) if crs.isValid() else None,
                source=f"{key} ({source.sourceName()})", locations=fids, location_kind="feature",
            )  # fmt: skip

    def write_layers(self, result, parameters, context, feedback) -> dict:
        report = result.data
        source = self.parameterAsSource(parameters, "MEASURED", context)
        crs = source.sourceCrs() if source is not None else self.parameterAsCrs(
            parameters, "CRS", context
        )  # fmt: skip
        sink, dest = self.field_sink(parameters, context, "OUTPUT", _FIELDS, WKB_POINT_Z, crs)
        pts, d = report.points, report.discrepancies
        for k, point_id in enumerate(pts.ids):
            values = [point_id, pts.groups[k], *d[k], report.horizontal[k], report.d3[k],
                      int(bool(report.outliers.any[k]))]  # fmt: skip
            self.add_feature(sink, _FIELDS, QgsPoint(*map(float, pts.reference[k])), values)
        return {"OUTPUT": dest}
