"""lidarphoto:groundfilter - progressive morphological ground filter of a LAS/LAZ cloud."""

from __future__ import annotations

from ...core.jobs import ground_filter
from ..base import BaseAlgorithm
from ..layer_styles import style_dtm


class GroundFilterAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.ground_filter`` (file outputs only)."""

    JOB = ground_filter
    STYLES = (("OUTPUT_DTM", style_dtm),)
