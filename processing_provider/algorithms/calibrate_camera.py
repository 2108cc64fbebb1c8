"""lidarphoto:calibratecamera - camera calibration from images of a planar target."""

from __future__ import annotations

from ...core.jobs import calibrate_camera
from ..base import BaseAlgorithm


class CalibrateCameraAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.calibrate_camera`` (file outputs only)."""

    JOB = calibrate_camera
