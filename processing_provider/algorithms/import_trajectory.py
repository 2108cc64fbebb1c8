"""lidarphoto:importtrajectory - an SBET / ASCII / CSV trajectory interpolated at the camera
events: the perspective centres as a PointZ layer, like trajectorytoeo's."""

from __future__ import annotations

from ...core.jobs import import_trajectory
from .trajectory_to_eo import TrajectoryToEoAlgorithm


class ImportTrajectoryAlgorithm(TrajectoryToEoAlgorithm):
    """Adapter of ``core.jobs.import_trajectory``: the EO table (with the mount applied) as a
    PointZ layer in the mapping CRS; the tables go to their files."""

    JOB = import_trajectory
