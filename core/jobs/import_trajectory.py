"""``importtrajectory``: an INS/GNSS solution (SBET, ASCII export, CSV) interpolated at the
camera events, as the trajectory table and the exterior orientation."""

from __future__ import annotations

import logging

from .common import (
    choice_param,
    csv_out,
    enum_param,
    mapping_crs_param,
    mount_from,
    mount_params,
    table_param,
)
from .runner import JobResult
from .spec import AlgorithmSpec, Fields, Param, Result, Values, options_from

log = logging.getLogger(__name__)

_OPTIONS = Fields("photo.trajectory_options", "TrajectoryImportOptions")


NAV_FILTER = "Trajectories (*.out *.sbet *.txt *.asc *.csv *.OUT);;All files (*)"

SPEC = AlgorithmSpec(
    name="importtrajectory",
    title="Import trajectory at camera events",
    group="Aerotriangulation",
    group_id="aerotriangulation",
    summary="SBET / POSPac / Inertial Explorer / CSV trajectory + camera events -> pose per image",
    description="""\
Reads the INS/GNSS solution as delivered (an Applanix SBET, a POSPac or Inertial Explorer
ASCII export, or a generic CSV at any rate) and the camera's event file (image_id, time),
and interpolates the pose of every image at its exposure:

- trajectory time = event time + TIME_OFFSET (the camera's timing offset, seconds);
- position: cubic Hermite in the Earth-centred frame, with the records' velocities when the
  file has them (they are checked against the positions);
- attitude: spherical interpolation of the body-to-Earth-centred rotation (quaternions; a
  cubic on the rotation group with the angular velocities of the neighbouring records, or
  SLERP with ATTITUDE slerp), so a heading through north and the SBET's wander angle (true
  heading = platform heading - wander) need no special case;
- an event outside the trajectory, or in an interval between records longer than MAX_GAP,
  is refused by name, and nothing is written.

## Inputs
INPUT: the trajectory; FORMAT auto picks SBET for .out/.sbet, the generic CSV for .csv and
an ASCII export otherwise (docs/formats.md). Latitude and longitude are on the datum of the
mapping CRS. EVENTS: CSV with image_id, time and optionally group; EVENT_TIME gps (seconds of
the GPS week, the SBET's clock) or utc (ISO 8601 date-times, with LEAP_SECONDS = GPS - UTC,
18 s since 2017).

## Outputs
OUTPUT_TRAJECTORY: the trajectory table that trajectorytoeo and boresightcalibration read
(easting, northing, height in the mapping CRS; roll, pitch, true heading in degrees; the
velocity v_north, v_east, v_up in m/s, which boresightcalibration's timing offset uses; time =
the trajectory time). OUTPUT_EO: the exterior orientation with the mount applied, as
trajectorytoeo computes it. OUTPUT: the perspective centres as a PointZ layer.""",
    params=(
        Param("INPUT", "file", "Trajectory (SBET, ASCII export or CSV)", file_filter=NAV_FILTER),
        choice_param(
            "FORMAT",
            "Trajectory format",
            "photo.trajectory_options",
            "TRAJECTORY_FORMATS",
            help="auto: by the file's ending (.out/.sbet SBET, .csv CSV, else ASCII)",
        ),
        table_param("EVENTS", "Camera events (CSV: image_id, time)"),
        enum_param(
            "EVENT_TIME",
            "Clock of the event times",
            _OPTIONS.event_time,
            "EVENT_TIMES",
            help="gps: GPS seconds of week; utc: ISO 8601 date-times in UTC",
        ),
        Param(
            "LEAP_SECONDS",
            "integer",
            "Leap seconds GPS - UTC",
            _OPTIONS.leap_seconds,
            unit="s",
            minimum=0,
            maximum=100,
            help="GPS - UTC at the events' date (18 since 2017-01-01); used for utc times",
        ),
        Param(
            "TIME_OFFSET",
            "number",
            "Camera timing offset",
            _OPTIONS.time_offset_s,
            unit="s",
            minimum=-60.0,
            maximum=60.0,
            help="trajectory time = event time + offset",
            advanced=True,
        ),
        Param(
            "MAX_GAP",
            "number",
            "Longest record interval",
            _OPTIONS.max_gap_s,
            unit="s",
            minimum=1e-6,
            maximum=60.0,
            help="an event between two records further apart than this is refused",
            advanced=True,
        ),
        enum_param(
            "ATTITUDE",
            "Attitude interpolation",
            _OPTIONS.attitude,
            "ATTITUDE_METHODS",
            advanced=True,
            help="cubic: Hermite cubic on the rotation group with the neighbours' angular "
            "velocities; slerp: constant angular velocity between two records",
        ),
        mapping_crs_param("projected CRS of the outputs (and of a CSV's eastings/northings)"),
        *mount_params(),
        Param("OUTPUT", "sink", "Perspective centres", geometry="point", optional=True),
        csv_out("OUTPUT_TRAJECTORY", "Trajectory table at the events (CSV)", advanced=True),
        csv_out("OUTPUT_EO", "Exterior orientation table (CSV)", on_demand=True),
    ),
    results=(
        Result("IMAGE_COUNT", "number", "Number of images"),
        Result("RECORD_COUNT", "number", "Number of trajectory records"),
    ),
    tags=("trajectory", "sbet", "pospac", "inertial explorer", "ins", "gnss", "camera events"),
    references=("Schwarz et al. (1993)", "Shoemake (1985)"),
)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the trajectory and the events, interpolate every image's pose, write the tables."""
    from ..errors import stop_if_asked
    from ..geometry.frames import MappingFrame
    from ..io.camera_events import read_camera_events
    from ..io.orientation import eo_csv_text, write_eo_csv
    from ..io.trajectory import write_trajectory_csv
    from ..photo.georeference import direct_georeference
    from ..photo.navigation import interpolate_trajectory
    from ..photo.trajectory_options import TrajectoryImportOptions

    frame = MappingFrame.from_user_input(v.crs)
    mount = mount_from(v)
    options = options_from(TrajectoryImportOptions, SPEC, v)
    nav = _read_navigation(v.input, v.format, frame)
    events = read_camera_events(v.events, options.event_time, options.leap_seconds)
    log.info("read %d records from %s and %d events", len(nav), v.input, len(events))
    stop_if_asked(should_stop, "interpolating the trajectory")
    if progress is not None:
        progress(0.5)
    traj = interpolate_trajectory(nav, events, frame, options)
    table = direct_georeference(traj, mount, frame)
    result = JobResult(results={"IMAGE_COUNT": len(traj), "RECORD_COUNT": len(nav)}, data=table)
    for name, write, what in (
        ("OUTPUT_TRAJECTORY", write_trajectory_csv, traj),
        ("OUTPUT_EO", write_eo_csv, table),
    ):
        if out.requested(name):
            write(out.path(name), what)
            result.lines.append(f"{len(traj)} images -> {out.target(name)}")
    if not result.lines:
        result.stdout = eo_csv_text(table)
    if progress is not None:
        progress(1.0)
    return result


def _read_navigation(path: str, fmt: str, frame):
    """The navigation solution of ``path`` in ``fmt`` (``auto``: by the file's ending); a
    CSV's eastings/northings are checked against the CRS's area of use."""
    from pathlib import Path

    from ..geometry.frames import check_points_in_area
    from ..io.navigation_text import read_nav_ascii, read_nav_csv
    from ..io.sbet import read_sbet

    if fmt == "auto":
        suffix = Path(path).suffix.lower()
        fmt = "sbet" if suffix in (".out", ".sbet") else "csv" if suffix == ".csv" else "ascii"
    nav = {"sbet": read_sbet, "ascii": read_nav_ascii, "csv": read_nav_csv}[fmt](path)
    if not nav.geodetic:
        check_points_in_area(frame.crs, nav.position, what="the trajectory", path=path)
    return nav
