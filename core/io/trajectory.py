"""The trajectory table: the INS/GNSS solution at each image's exposure time.

CSV with a header row (names are case-insensitive, aliases in parentheses)::

    image_id (id, image, name, photo)      text, unique
    time (gps_time, t)                     optional, seconds (GPS week or standard time, UNIX
                                           time...); rising down the table within a group
    group (line, strip, flight_line)       optional, flight line or direction
    easting (e, x), northing (n, y), height (h, z, alt)         in the mapping CRS, or
    latitude (lat), longitude (lon, long), height (h, z, alt)   degrees on the CRS's datum
    roll, pitch, heading (yaw)             degrees; body x forward, y right, z down;
                                           heading clockwise from true north
    v_north (vnorth, vn, north_vel, vel_north), v_east (veast, ve, east_vel, vel_east) and
    v_up (vup, vu, up_vel, vel_up) or v_down (vdown, vd, down_vel)
                                           optional, all three or none: velocity at the
                                           exposure, m/s, local level at the image (true
                                           north); the boresight's timing offset uses it

Values outside their physical range are refused with the row: a time beyond
:data:`MAX_TIME_S` (another unit, or garbage), a time earlier than the row before it in the
same group (rows mixed up; equal times are allowed: cameras that fire together), a height
outside :data:`HEIGHT_RANGE_M` (another unit), angles beyond their half or full turn.
"""

from __future__ import annotations

from pathlib import Path
from typing import Union

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..photo.georeference import Trajectory
from .tables import (
    Table,
    find_column,
    float_column,
    read_table,
    refuse_rows,
    text_column,
    unique_ids,
    write_csv_atomic,
)

Array = NDArray[np.float64]
#: Largest plausible |time| (s): about 300 years, beyond every GPS or UNIX time in seconds.
MAX_TIME_S = 1e10
#: Plausible heights of a sensor (m): below the Dead Sea's shore with the geoid's
#: undulation, above any survey aircraft.
HEIGHT_RANGE_M = (-1000.0, 30000.0)
_VN = ("v_north", "vnorth", "vn", "north_vel", "vel_north")
_VE = ("v_east", "veast", "ve", "east_vel", "vel_east")
_VU, _VD = ("v_up", "vup", "vu", "up_vel", "vel_up"), ("v_down", "vdown", "vd", "down_vel")
#: Largest plausible |velocity| of a sensor, m/s (a jet at Mach 1; beyond it another unit).
MAX_SPEED_MPS = 340.0


def read_trajectory_csv(path: Union[str, Path]) -> Trajectory:
    """Read the trajectory table (format in the module docstring)."""
    table = read_table(path)
    ids = unique_ids(table, find_column(table, ("image_id", "id", "image", "name", "photo")))
    t_col = find_column(table, ("time", "gps_time", "t"), required=False)
    g_col = find_column(table, ("group", "line", "strip", "flight_line"), required=False)
    group = text_column(table, g_col, nonempty=False) if g_col is not None else ("",) * len(ids)
    time = np.full(len(ids), np.nan)
    if t_col is not None:
        time = float_column(table, t_col, allow_empty=True)
        _check_times(table, t_col, time, group)
    lat_col = find_column(table, ("latitude", "lat"), required=False)
    e_col = find_column(table, ("easting", "e", "x"), required=False)
    if (lat_col is None) == (e_col is None):
        raise InputError(
            "give either easting/northing/height or latitude/longitude/height columns "
            f"(found: {', '.join(table.columns)})",
            path=table.path,
        )
    h_col = find_column(table, ("height", "h", "z", "alt", "altitude"), what="height")
    if lat_col is not None:
        lon_col = find_column(table, ("longitude", "lon", "long"), what="longitude")
        position = np.stack([float_column(table, c) for c in (lat_col, lon_col, h_col)], axis=1)
        _check_range(table, lat_col, position[:, 0], 90.0)
        _check_range(table, lon_col, position[:, 1], 180.0)
    else:
        n_col = find_column(table, ("northing", "n", "y"), what="northing")
        position = np.stack([float_column(table, c) for c in (e_col, n_col, h_col)], axis=1)
    _check_heights(table, h_col, position[:, 2])
    cols = [find_column(table, names) for names in (("roll",), ("pitch",), ("heading", "yaw"))]
    rph_deg = np.stack([float_column(table, c) for c in cols], axis=1)
    _check_range(table, cols[0], rph_deg[:, 0], 180.0)
    _check_range(table, cols[1], rph_deg[:, 1], 90.0)
    _check_range(table, cols[2], rph_deg[:, 2], 360.0)
    vel = velocity_columns(table)
    return Trajectory(ids, time, group, position, lat_col is not None, np.radians(rph_deg), vel)


def velocity_columns(table: Table) -> Array | None:
    """North, east, down velocities (N, 3) m/s from the v_north, v_east and v_up or v_down
    columns (aliases in the module docstring), or None without any; some but not all, or a
    speed beyond :data:`MAX_SPEED_MPS`, is refused with the row."""
    vn, ve = (find_column(table, names, required=False) for names in (_VN, _VE))
    vu, vd = (find_column(table, names, required=False) for names in (_VU, _VD))
    if vn is None and ve is None and vu is None and vd is None:
        return None
    if vn is None or ve is None or (vu is None and vd is None):
        raise InputError(
            "give all three velocity columns (v_north, v_east and v_up or v_down) or none",
            path=table.path,
        )
    if vu is not None:
        down = -float_column(table, vu)
    else:
        assert vd is not None  # refused above
        down = float_column(table, vd)
    vel = np.stack([float_column(table, vn), float_column(table, ve), down], axis=1)
    check_speeds(table, vel, vn)
    return vel


def check_speeds(table: Table, vel: Array, column: int) -> None:
    """Refuse a speed (|vel| of a row, m/s) beyond :data:`MAX_SPEED_MPS`, naming the row and
    ``column`` (the first velocity column)."""
    fast = np.flatnonzero(np.linalg.norm(vel, axis=1) > MAX_SPEED_MPS)
    if fast.size:
        raise InputError(
            f"a speed of {np.linalg.norm(vel[fast[0]]):.4g} m/s is beyond the plausible "
            f"{MAX_SPEED_MPS:g} m/s of a sensor (velocities in another unit?)",
            path=table.path,
            row=table.line_numbers[fast[0]],
            column=table.columns[column],
        )


def _check_range(table, column: int, values: Array, limit: float) -> None:
    refuse_rows(
        table,
        np.abs(values) > limit,
        column,
        lambda k: f"{values[k]} is outside [-{limit:g}, {limit:g}] degrees",
    )


def _check_times(table, column: int, time: Array, group: tuple[str, ...]) -> None:
    """Times within +-MAX_TIME_S, and never earlier than the row before in the same group."""
    where = {"path": table.path, "column": table.columns[column]}
    refuse_rows(
        table,
        np.abs(time) > MAX_TIME_S,
        column,
        lambda k: (
            f"{time[k]:g} s is beyond the plausible +-{MAX_TIME_S:g} s of a time in "
            "seconds (GPS week or standard time, UNIX time): another unit, or not a time"
        ),
    )
    last: dict[str, int] = {}
    for k, (t, g) in enumerate(zip(time, group)):
        if np.isnan(t):
            continue
        j = last.get(g)
        if j is not None and t < time[j]:
            in_group = f" of group '{g}'" if g else ""
            raise InputError(
                f"time {t:.12g} s is earlier than {time[j]:.12g} s in row "
                f"{table.line_numbers[j]}{in_group}: the rows are not in time order (rows "
                "mixed up? sort the table by time)",
                row=table.line_numbers[k],
                **where,
            )
        last[g] = k


def _check_heights(table, column: int, height: Array) -> None:
    lo, hi = HEIGHT_RANGE_M
    refuse_rows(
        table,
        (height < lo) | (height > hi),
        column,
        lambda k: (
            f"{height[k]:g} m is outside the plausible heights {lo:g} to {hi:g} m of a "
            "sensor (a height in another unit?)"
        ),
    )


TRAJECTORY_COLUMNS = (
    "image_id",
    "time",
    "group",
    "easting",
    "northing",
    "height",
    "roll",
    "pitch",
    "heading",
)


#: The velocity columns written when the trajectory has velocities (m/s, up positive).
VELOCITY_COLUMNS = ("v_north", "v_east", "v_up")


def write_trajectory_csv(path: Union[str, Path], trajectory: Trajectory) -> None:
    """Write a projected trajectory (easting, northing, height; angles in degrees; the
    velocities as v_north, v_east, v_up when it has them), atomically; numbers with full
    round-trip precision."""
    if trajectory.geodetic:
        raise InputError("only a trajectory in map coordinates can be written")
    deg = np.degrees(trajectory.rph)
    t = trajectory
    columns = TRAJECTORY_COLUMNS
    extra: Array = np.empty((len(t), 0))
    if t.velocity_ned is not None:
        columns = (*columns, *VELOCITY_COLUMNS)
        extra = np.asarray(t.velocity_ned, dtype=np.float64) * [1.0, 1.0, -1.0]
    write_csv_atomic(
        path,
        columns,
        [
            (i, repr(float(tt)), g, *(repr(float(v)) for v in (*p, *a, *e)))
            for i, tt, g, p, a, e in zip(t.image_id, t.time, t.group, t.position, deg, extra)
        ],
    )
