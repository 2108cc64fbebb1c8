"""One module per algorithm: its parameter spec and its run(), from which the QGIS toolbox
and the command line are both made (docs/architecture.md, "Adding an algorithm")."""

from . import (
    accuracy_report,
    boresight_calibration,
    create_lcps,
    extract_roof_planes,
    ground_filter,
    monoplot,
    orthomosaic,
    orthorectify,
    trajectory_to_eo,
)

#: Every algorithm, in the order of the toolbox and of ``lidarphoto --help``.
ALGORITHMS = (
    trajectory_to_eo,
    ground_filter,
    create_lcps,
    accuracy_report,
    extract_roof_planes,
    boresight_calibration,
    monoplot,
    orthorectify,
    orthomosaic,
)
