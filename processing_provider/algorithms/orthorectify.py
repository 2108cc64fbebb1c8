"""lidarphoto:orthorectify - orthophotos of oriented images on a LiDAR DSM or DTM."""

from __future__ import annotations

from pathlib import Path

from qgis.core import QgsProcessingContext
from qgis.PyQt.QtCore import QCoreApplication

from ...core.jobs import orthorectify
from ..base import BaseAlgorithm
from ..layer_styles import LayerInGroup, style_orthophoto


class OrthorectifyAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.orthorectify``: the orthophotos load into the project."""

    JOB = orthorectify

    def write_layers(self, result, parameters, context, feedback) -> dict:
        """Each orthophoto loads styled, in one group named after the output folder."""
        folder = Path(result.data[0].path).parent.name if result.data else ""
        group = QCoreApplication.translate("LidarPhotoProvider", "Orthophotos ({})").format(folder)
        for ortho in result.data:
            details = QgsProcessingContext.LayerDetails(
                f"{ortho.image_id} orthophoto", context.project(), "OUTPUT_FOLDER"
            )
            details.setPostProcessor(LayerInGroup.create_in(style_orthophoto, group))
            context.addLayerToLoadOnCompletion(ortho.path, details)
        return {}
