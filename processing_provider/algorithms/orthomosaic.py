"""lidarphoto:orthomosaic - orthophotos into one mosaic, with the seamlines as a layer."""

from __future__ import annotations

from qgis.core import QgsGeometry

from ...core.jobs import orthomosaic
from ..base import BaseAlgorithm
from ..compat import FIELD_DOUBLE, FIELD_INT, FIELD_STRING, WKB_MULTIPOLYGON
from ..layer_styles import LayerStyle, style_orthophoto

_FIELDS = (("image_id", FIELD_STRING), ("cells", FIELD_INT), ("area", FIELD_DOUBLE))


class OrthomosaicAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.orthomosaic``: the seamline regions as a polygon layer."""

    JOB = orthomosaic

    def write_layers(self, result, parameters, context, feedback) -> dict:
        res = result.data
        sink, dest = self.field_sink(parameters, context, "OUTPUT_SEAMLINES", _FIELDS,
                                     WKB_MULTIPOLYGON, res.crs_wkt)  # fmt: skip
        for seam in res.seamlines:
            values = [seam.image_id, seam.cells, seam.area]
            self.add_feature(sink, _FIELDS, QgsGeometry.fromWkt(seam.wkt), values)
        for layer_id in (res.path, dest):
            if layer_id and context.willLoadLayerOnCompletion(layer_id):
                context.layerToLoadOnCompletionDetails(layer_id).setPostProcessor(
                    LayerStyle.create(style_orthophoto)
                )
        return {"OUTPUT_SEAMLINES": dest}
