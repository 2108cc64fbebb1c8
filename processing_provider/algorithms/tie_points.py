"""lidarphoto:tiepoints - automatic tie points of a block of images."""

from __future__ import annotations

from ...core.jobs import tie_points
from ..base import BaseAlgorithm


class TiePointsAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.tie_points`` (file outputs only)."""

    JOB = tie_points
