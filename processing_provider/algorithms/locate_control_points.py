"""lidarphoto:locatecontrolpoints - control points located in images from control chips."""

from __future__ import annotations

from ...core.jobs import locate_control_points
from ..base import BaseAlgorithm


class LocateControlPointsAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.locate_control_points`` (file outputs only)."""

    JOB = locate_control_points
