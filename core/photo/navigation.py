"""Trajectory import: the INS/GNSS solution interpolated at the camera's exposure times.

A navigation solution (an Applanix SBET, an ASCII export, a generic CSV: core/io) is a list
of records at times ``t_k`` (GPS seconds of week). For each camera event at time ``te`` on
the camera's clock the pose is taken at the trajectory time::

    t = te + time_offset                (the sign convention: trajectory = event + offset)

inside a record interval ``[t_k, t_k+1]`` no longer than ``max_gap_s``:

- position in the Earth-centred frame e (ECEF of the mapping CRS's datum, through pyproj):
  cubic Hermite between the two records, with the records' velocities (rotated from
  north-east-down into e) when the file has them, else velocities from the positions of
  the neighbouring records (three-point differences, second order in the interval);
- attitude: the body-to-ECEF rotation ``R_b^e = R_n^e(lat, lon) R_b^n(roll, pitch,
  heading)`` of both records, spherically interpolated (SLERP of the unit quaternions,
  Shoemake 1985). The frame e does not turn with the aircraft, so a heading through north
  (359 -> 1 degree), the meridian convergence between the records and a wander-azimuth
  solution need no special case: roll, pitch and true heading are read back from
  ``R_n^e(interpolated position)^T R_b^e`` at the interpolated position.

Events outside the trajectory, or in an interval longer than ``max_gap_s``, are refused by
name (file, row, image). Event times in seconds of week are moved by one week when that
brings them into a trajectory that runs through the week's end (its times then go past
604,800 s), so an event file and a trajectory on either side of Sunday 00:00 still match.
"""

from __future__ import annotations

import datetime as _dt
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..geometry.frames import MappingFrame, ned_to_ecef_rotation
from ..geometry.rotations import matrix_to_rph, rph_to_matrix
from .georeference import Trajectory
from .trajectory_options import WEEK_S, TrajectoryImportOptions

__all__ = [
    "CameraEvents",
    "NavSolution",
    "gps_seconds_of_week",
    "interpolate_trajectory",
]

Array = NDArray[np.float64]
#: The GPS time origin: 1980-01-06 00:00:00 (a Sunday), UTC = GPS then.
GPS_EPOCH = _dt.datetime(1980, 1, 6, tzinfo=_dt.timezone.utc)


@dataclass(frozen=True)
class NavSolution:
    """INS/GNSS records, strictly increasing in time.

    time: (N,) seconds (GPS seconds of week). position: (N, 3) latitude, longitude (degrees)
    and ellipsoidal height (m) on the mapping CRS's datum when ``geodetic``, else easting,
    northing, height in the mapping CRS. rph: (N, 3) roll, pitch, true heading, radians
    (body x forward, y right, z down; DESIGN.md). velocity_ned: (N, 3) north, east, down
    m/s, or None. source: the file (for messages); record: what a record is called there
    (``record`` for SBET, ``row`` for tables) and ``numbers`` its 1-based number.
    """

    time: Array
    position: Array
    geodetic: bool
    rph: Array
    velocity_ned: Array | None
    source: str
    record: str
    numbers: NDArray[np.int64]

    def __len__(self) -> int:
        return len(self.time)


@dataclass(frozen=True)
class CameraEvents:
    """Exposure times: ``time`` (N,) GPS seconds of week on the camera's clock; ``rows``
    the line numbers in ``source``; ``group`` flight line or camera (may be empty)."""

    image_id: tuple[str, ...]
    time: Array
    group: tuple[str, ...]
    rows: tuple[int, ...]
    source: str

    def __len__(self) -> int:
        return len(self.image_id)


def gps_seconds_of_week(utc: _dt.datetime, leap_seconds: int) -> float:
    """GPS seconds of week of a UTC date-time, given GPS - UTC in seconds at that date.

    Exact to the microsecond (integer days and seconds, then the fraction).

    >>> gps_seconds_of_week(_dt.datetime(2017, 1, 1, tzinfo=_dt.timezone.utc), 18)
    18.0
    """
    if utc.tzinfo is None:
        raise InputError(f"the date-time {utc.isoformat()} has no time zone (add Z for UTC)")
    d = utc - GPS_EPOCH
    whole = (d.days % 7) * 86400 + d.seconds + int(leap_seconds)
    return float(whole % int(WEEK_S)) + d.microseconds * 1e-6


def interpolate_trajectory(
    nav: NavSolution,
    events: CameraEvents,
    frame: MappingFrame,
    options: TrajectoryImportOptions,
) -> Trajectory:
    """The pose of every event (module docstring), as the trajectory table of
    :mod:`.georeference`: easting, northing, height in the mapping CRS, roll, pitch and true
    heading (radians, heading in [0, 2 pi)), time = the trajectory time (event + offset)."""
    if len(nav) < 2:
        raise InputError(f"the trajectory has {len(nav)} record(s); at least 2 are needed",
                         path=nav.source)  # fmt: skip
    t = _align_week(events.time + options.time_offset_s, nav.time)
    k = _segments(nav, events, t, options.max_gap_s)
    knots = np.unique(np.concatenate([k, k + 1]))
    # positions and velocities in ECEF for the records used (and their neighbours)
    near = np.unique(np.clip(np.concatenate([knots - 1, knots, knots + 1]), 0, len(nav) - 1))
    llh = _geodetic(nav, frame, near)
    xyz = frame.geodetic_to_ecef(llh)
    r_n_e = ned_to_ecef_rotation(llh[:, 0], llh[:, 1])
    at = np.searchsorted(near, knots)
    if nav.velocity_ned is not None:
        vel = np.einsum("kij,kj->ki", r_n_e[at], nav.velocity_ned[knots])
        _check_velocities(nav, knots, xyz[at], vel, options.velocity_tolerance_mps)
    else:
        vel = _three_point_velocity(nav.time[near], xyz, near, len(nav))[at]
    r_b_e = r_n_e[at] @ rph_to_matrix(*nav.rph[knots].T)
    xyz_t, r_b_e_t = _interpolate(nav.time[knots], xyz[at], vel, r_b_e, t)
    llh_t = frame.ecef_to_geodetic(xyz_t)
    r_b_n = np.swapaxes(ned_to_ecef_rotation(llh_t[:, 0], llh_t[:, 1]), -1, -2) @ r_b_e_t
    roll, pitch, heading = matrix_to_rph(r_b_n)
    rph = np.stack([roll, pitch, np.mod(heading, 2.0 * np.pi)], axis=1)
    return Trajectory(events.image_id, t, events.group, frame.geodetic_to_map(llh_t), False, rph)


def _align_week(t: Array, nav_time: Array) -> Array:
    """Each time moved by -1, 0 or +1 week to fall inside the trajectory when one does."""
    lo, hi = nav_time[0], nav_time[-1]
    out = t.copy()
    for shift in (WEEK_S, -WEEK_S):
        moved = t + shift
        use = ((t < lo) | (t > hi)) & (moved >= lo) & (moved <= hi)
        out[use] = moved[use]
    return out


def _segments(nav: NavSolution, events: CameraEvents, t: Array, max_gap_s: float) -> Array:
    """Index k of the record interval [t_k, t_k+1] of every event; refuses events outside
    the trajectory or in a gap longer than ``max_gap_s``."""
    tt = nav.time
    outside = np.flatnonzero((t < tt[0]) | (t > tt[-1]))
    if outside.size:
        j = outside[0]
        raise InputError(
            f"image '{events.image_id[j]}' at trajectory time {t[j]:.6f} s (event + offset) "
            f"is outside the trajectory {nav.source} ({tt[0]:.6f} to {tt[-1]:.6f} s); "
            f"{outside.size} of {len(t)} events are outside: wrong file, time offset or clock?",
            path=events.source, row=events.rows[j],
        )  # fmt: skip
    k = np.clip(np.searchsorted(tt, t, side="right") - 1, 0, len(tt) - 2)
    gap = tt[k + 1] - tt[k]
    wide = np.flatnonzero(gap > max_gap_s)
    if wide.size:
        j = wide[0]
        a, b = int(nav.numbers[k[j]]), int(nav.numbers[k[j] + 1])
        raise InputError(
            f"image '{events.image_id[j]}' at trajectory time {t[j]:.6f} s falls in a gap of "
            f"{gap[j]:.6g} s of the trajectory {nav.source} (between {nav.record}s {a} and "
            f"{b}, {tt[k[j]]:.6f} to {tt[k[j] + 1]:.6f} s), longer than the limit MAX_GAP = "
            f"{max_gap_s:g} s ({wide.size} of {len(t)} events are in such gaps)",
            path=events.source, row=events.rows[j],
        )  # fmt: skip
    return k


def _geodetic(nav: NavSolution, frame: MappingFrame, index: NDArray[np.int64]) -> Array:
    p = nav.position[index]
    return p if nav.geodetic else frame.map_to_geodetic(p)


def _three_point_velocity(t: Array, xyz: Array, index: NDArray[np.int64], n: int) -> Array:
    """d xyz / dt at each record of ``index`` (sorted) from its neighbours (second-order
    differences on unequal intervals), one-sided at the trajectory's ends. ``t`` and ``xyz``
    hold the records of ``index``; a record's neighbours are in it (the caller adds them)."""
    out = np.empty_like(xyz)
    pos = {int(r): i for i, r in enumerate(index)}
    for i, r in enumerate(index):
        lo, hi = pos.get(int(r) - 1), pos.get(int(r) + 1)
        if lo is not None and hi is not None:
            h1, h2 = t[i] - t[lo], t[hi] - t[i]
            out[i] = (h1 * h1 * xyz[hi] - h2 * h2 * xyz[lo] + (h2 * h2 - h1 * h1) * xyz[i]) / (
                h1 * h2 * (h1 + h2)
            )
        else:  # an end of the trajectory
            j = hi if hi is not None else lo
            out[i] = (xyz[j] - xyz[i]) / (t[j] - t[i])
    return out


def _check_velocities(
    nav: NavSolution, knots: NDArray[np.int64], xyz: Array, vel: Array, tol: float
) -> None:
    """Record velocities against the chord of each interval used (a velocity in another frame
    or sign convention would bend the interpolation by centimetres: refuse it)."""
    adjacent = np.flatnonzero(np.diff(knots) == 1)
    if not adjacent.size:
        return
    a, b = adjacent, adjacent + 1
    dt = nav.time[knots[b]] - nav.time[knots[a]]
    chord = (xyz[b] - xyz[a]) / dt[:, None]
    mean = 0.5 * (vel[a] + vel[b])
    off = np.linalg.norm(mean - chord, axis=1)
    bad = np.flatnonzero(off > tol + 5.0 * dt)
    if bad.size:
        j = bad[np.argmax(off[bad])]
        raise InputError(
            f"the velocities of {nav.record}s {int(nav.numbers[knots[a[j]]])} and "
            f"{int(nav.numbers[knots[b[j]]])} differ by {off[j]:.3g} m/s from the motion of "
            f"their positions (chord {np.linalg.norm(chord[j]):.3g} m/s): velocities in another "
            "frame or sign convention?",
            path=nav.source,
        )


def _interpolate(tk: Array, xyz: Array, vel: Array, r_b_e: Array, t: Array) -> tuple[Array, Array]:
    """Cubic Hermite positions and SLERP rotations at ``t`` between the knots ``tk``
    (increasing; the interval of each ``t`` holds two consecutive records).

    The Hermite basis is written out (the same numbers as SciPy's CubicHermiteSpline, tested):
    importing scipy.interpolate alone takes about 1 s, half of a whole hour-long SBET run.
    """
    from scipy.spatial.transform import Rotation, Slerp

    j = np.clip(np.searchsorted(tk, t, side="right") - 1, 0, len(tk) - 2)
    h = (tk[j + 1] - tk[j])[:, None]
    s = (t - tk[j])[:, None] / h
    s2, s3 = s * s, s * s * s
    h00, h10, h01, h11 = 2 * s3 - 3 * s2 + 1, s3 - 2 * s2 + s, 3 * s2 - 2 * s3, s3 - s2
    xyz_t = h00 * xyz[j] + h10 * h * vel[j] + h01 * xyz[j + 1] + h11 * h * vel[j + 1]
    rot = Slerp(tk, Rotation.from_matrix(r_b_e))(t)
    return xyz_t, rot.as_matrix()
