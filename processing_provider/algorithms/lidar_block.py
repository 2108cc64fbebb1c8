"""lidarphoto:lidarblock - a LiDAR block tile by tile on dask.distributed."""

from __future__ import annotations

from ...core.dependencies import missing_modules, optional_message
from ...core.jobs import lidar_block
from ..base import BaseAlgorithm


class LidarBlockAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.lidar_block`` (file outputs in a folder; needs ``distributed``)."""

    JOB = lidar_block

    def canExecute(self):
        ok, message = super().canExecute()
        if ok and missing_modules(["distributed"]):
            return False, optional_message(["distributed"])
        return ok, message

    def initAlgorithm(self, config=None):
        super().initAlgorithm(config)
        # a folder of tiles is a valid INPUT too: no file filter, whose extension check
        # (QgsProcessingParameterFile) would refuse a folder's path
        self.parameterDefinition("INPUT").setFileFilter("")
