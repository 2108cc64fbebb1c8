"""lidarphoto:groundfilter - ground filter of a LAS/LAZ cloud (SMRF, PMF or cloth simulation)."""

from __future__ import annotations

from ...core.jobs import ground_filter
from ..base import BaseAlgorithm
from ..layer_styles import style_dtm


class GroundFilterAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.ground_filter``: file outputs, the DTM styled when QGIS loads it."""

    JOB = ground_filter
    STYLES = (("OUTPUT_DTM", style_dtm),)
