"""lidarphoto:makecontrolchips - control chips from ground photos of surveyed points."""

from __future__ import annotations

from qgis.core import QgsProcessingContext

from ...core.jobs import make_control_chips
from ..base import BaseAlgorithm


class MakeControlChipsAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.make_control_chips``: the chips load into the project."""

    JOB = make_control_chips

    def write_layers(self, result, parameters, context, feedback) -> dict:
        for row in result.data:
            if row.get("status") == "ok" and row.get("chip"):
                details = QgsProcessingContext.LayerDetails(
                    f"{row['point_id']} control chip", context.project(), "OUTPUT_FOLDER"
                )
                context.addLayerToLoadOnCompletion(row["chip"], details)
        return {}
