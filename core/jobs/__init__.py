"""One module per algorithm: its parameter spec and its run(), from which the QGIS toolbox
and the command line are both made (docs/architecture.md, "Adding an algorithm")."""

from . import (
    accuracy_report,
    boresight_calibration,
    bundle_adjustment,
    calibrate_camera,
    create_lcps,
    extract_roof_planes,
    extract_tls_targets,
    ground_filter,
    lidar_block,
    locate_control_points,
    make_control_chips,
    monoplot,
    orthomosaic,
    orthorectify,
    resection,
    tie_points,
    tls_calibration,
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
    bundle_adjustment,
    resection,
    orthorectify,
    orthomosaic,
    tls_calibration,
    extract_tls_targets,
    locate_control_points,
    lidar_block,
    calibrate_camera,
    tie_points,
    make_control_chips,
)
