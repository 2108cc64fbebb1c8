"""lidarphoto:orthorectify - orthophotos of oriented images on a LiDAR DSM or DTM."""

from __future__ import annotations

from qgis.core import QgsProcessingContext

from ...core.jobs import orthorectify
from ..base import BaseAlgorithm
from ..layer_styles import LayerStyle, style_orthophoto


class OrthorectifyAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.orthorectify``: the orthophotos load into the project."""

    JOB = orthorectify

    def write_layers(self, result, parameters, context, feedback) -> dict:
        for ortho in result.data:
            details = QgsProcessingContext.LayerDetails(
                f"{ortho.image_id} orthophoto", context.project(), "OUTPUT_FOLDER"
            )
            details.setPostProcessor(LayerStyle.create(style_orthophoto))
            context.addLayerToLoadOnCompletion(ortho.path, details)
        return {}
