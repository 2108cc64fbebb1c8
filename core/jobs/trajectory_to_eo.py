"""``trajectorytoeo``: exterior orientation of each image from an INS/GNSS trajectory."""

from __future__ import annotations

import logging

from .common import csv_out, mapping_crs_param, mount_from, mount_params, table_param
from .runner import JobResult
from .spec import AlgorithmSpec, Param, Result, Values

log = logging.getLogger(__name__)

SPEC = AlgorithmSpec(
    name="trajectorytoeo",
    title="Trajectory to exterior orientation",
    group="Aerotriangulation",
    group_id="aerotriangulation",
    summary="INS/GNSS trajectory + camera mount -> exterior orientation per image",
    description="""\
Computes the exterior orientation (perspective centre and omega, phi, kappa) of every image
from the INS/GNSS solution at its exposure time (direct georeferencing: X_pc = X_ins +
R_b^m a_b, R_c^m = R_b^m R_c^b, composed rigorously through the Earth-centred frame, so grid
convergence and Earth curvature are accounted for).

## Trajectory table (INPUT)
CSV with a header row (column names are case-insensitive) and one row per image:
- image_id (unique) and time (seconds);
- either easting, northing, height in the mapping CRS, or latitude, longitude, height
  (degrees, on the geodetic datum of the CRS); heights in metres;
- roll, pitch, heading in degrees; body frame x forward, y right, z down; heading clockwise
  from true north;
- optional group (flight line, camera, ...).

## Mounting
Lever arm: the camera perspective centre in the body frame, metres. Camera mount: the
nominal camera-to-body rotation; custom uses the mount matrix (9 numbers, row-major R_c^b).
Boresight: the small misalignment in degrees about the camera axes x, y, z.

## Outputs
A PointZ layer in the mapping CRS with image_id, time, group, X, Y, Z, omega_deg, phi_deg,
kappa_deg (angles relative to the grid frame at each image), optionally the same table as
CSV (on the command line, printed when no file is given), and the number of images.""",
    params=(
        table_param("INPUT", "Trajectory table (CSV)"),
        mapping_crs_param("projected CRS of the trajectory's eastings/northings and of the output"),
        *mount_params(),
        Param("OUTPUT", "sink", "Exterior orientation", geometry="point", optional=True),
        csv_out("OUTPUT_CSV", "Exterior orientation table (CSV)", on_demand=True, twin="OUTPUT"),
    ),
    results=(Result("IMAGE_COUNT", "number", "Number of images"),),
    tags=("trajectory", "ins", "gnss", "imu", "exterior orientation", "omega phi kappa"),
    references=("Schwarz et al. (1993)",),
)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the trajectory, georeference every image, write the EO table."""
    from ..errors import stop_if_asked
    from ..geometry.frames import MappingFrame, check_points_in_area
    from ..io.orientation import eo_csv_text, write_eo_csv
    from ..io.trajectory import read_trajectory_csv
    from ..photo.georeference import direct_georeference

    frame = MappingFrame.from_user_input(v.crs)
    mount = mount_from(v)
    traj = read_trajectory_csv(v.input)
    if not traj.geodetic:
        check_points_in_area(frame.crs, traj.position, what="the trajectory", path=v.input)
    log.info("read %d images from %s", len(traj), v.input)
    stop_if_asked(should_stop, "georeferencing")
    if progress is not None:
        progress(0.3)
    table = direct_georeference(traj, mount, frame)
    result = JobResult(results={"IMAGE_COUNT": len(table)}, data=table)
    if out.requested("OUTPUT_CSV"):
        write_eo_csv(out.path("OUTPUT_CSV"), table)
        result.lines.append(f"{len(table)} images -> {out.target('OUTPUT_CSV')}")
    else:
        result.stdout = eo_csv_text(table)
    if progress is not None:
        progress(1.0)
    return result
