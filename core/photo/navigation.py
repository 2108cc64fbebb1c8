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
  heading)`` of both records, interpolated on the sphere of unit quaternions: by default a
  cubic Hermite on the rotation group, ``R(s) = exp(phi(s)) R_k`` with ``phi`` a cubic in the
  rotation vector whose end slopes are the angular velocities at the two records (three-point
  differences of the neighbouring rotations); or SLERP (Shoemake 1985: constant angular
  velocity, exact for it, off by alpha h^2 / 8 under an angular acceleration alpha). The frame
  e does not turn with the aircraft, so a heading through north (359 -> 1 degree), the
  meridian convergence between the records and a wander-azimuth solution need no special
  case: roll, pitch and true heading are read back from ``R_n^e(interpolated position)^T
  R_b^e`` at the interpolated position.

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
    (body x forward, y right, z down; docs/conventions.md, "Frames"). velocity_ned: (N, 3)
    north, east, down m/s, or None. source: the file (for messages); record: what a record
    is called there (``record`` for SBET, ``row`` for tables) and ``numbers`` its 1-based
    number.
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
    heading (radians, heading in [0, 2 pi)), the north-east-down velocity (m/s: the
    derivative of the position's Hermite cubic), time = the trajectory time (event + offset)."""
    from scipy.spatial.transform import Rotation

    if len(nav) < 2:
        raise InputError(
            f"the trajectory has {len(nav)} record(s); at least 2 are needed", path=nav.source
        )
    t = _align_week(events.time + options.time_offset_s, nav.time)
    k = _segments(nav, events, t, options.max_gap_s)
    # the records of the events' intervals and their neighbours (for the rates), in ECEF
    near = np.unique(np.clip(np.concatenate([k - 1, k, k + 1, k + 2]), 0, len(nav) - 1))
    j = np.searchsorted(near, k)  # interval [near[j], near[j + 1]] of each event
    tn = nav.time[near]
    llh = _geodetic(nav, frame, near)
    xyz = frame.geodetic_to_ecef(llh)
    r_n_e = ned_to_ecef_rotation(llh[:, 0], llh[:, 1])
    lo, hi = _neighbours(near, tn, options.max_gap_s)
    if nav.velocity_ned is not None:
        vel = np.einsum("kij,kj->ki", r_n_e, nav.velocity_ned[near])
        _check_velocities(nav, near, np.unique(j), xyz, vel, options.velocity_tolerance_mps)
    else:
        vel = _rates(tn, lambda i: xyz[i] - xyz, lo, hi)
    rot = Rotation.from_matrix(r_n_e @ rph_to_matrix(*nav.rph[near].T))  # R_b^e
    xyz_t = _hermite(tn, xyz, vel, j, t)
    vel_t = _hermite_rate(tn, xyz, vel, j, t)
    if options.attitude == "slerp":
        r_b_e_t = _slerp(tn, rot, j, t)
    else:
        omega = _rates(tn, lambda i: (rot[i] * rot.inv()).as_rotvec(), lo, hi)
        r_b_e_t = _rotation_hermite(tn, rot, omega, j, t)
    llh_t = frame.ecef_to_geodetic(xyz_t)
    r_e_n = np.swapaxes(ned_to_ecef_rotation(llh_t[:, 0], llh_t[:, 1]), -1, -2)
    roll, pitch, heading = matrix_to_rph(r_e_n @ r_b_e_t)
    rph = np.stack([roll, pitch, np.mod(heading, 2.0 * np.pi)], axis=1)
    v_ned = np.einsum("kij,kj->ki", r_e_n, vel_t)
    return Trajectory(
        events.image_id, t, events.group, frame.geodetic_to_map(llh_t), False, rph, v_ned
    )


def _align_week(t: Array, nav_time: Array) -> Array:
    """Each time moved by -1, 0 or +1 week to fall inside the trajectory when one does."""
    lo, hi = nav_time[0], nav_time[-1]
    out = t.copy()
    for shift in (WEEK_S, -WEEK_S):
        moved = t + shift
        use = ((t < lo) | (t > hi)) & (moved >= lo) & (moved <= hi)
        out[use] = moved[use]
    return out


def _segments(
    nav: NavSolution, events: CameraEvents, t: Array, max_gap_s: float
) -> NDArray[np.intp]:
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
            path=events.source,
            row=events.rows[j],
        )
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
            path=events.source,
            row=events.rows[j],
        )
    return k


def _geodetic(nav: NavSolution, frame: MappingFrame, index: NDArray[np.int64]) -> Array:
    p = nav.position[index]
    return p if nav.geodetic else frame.map_to_geodetic(p)


def _neighbours(
    index: NDArray[np.int64], t: Array, max_gap_s: float
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """For each record of ``index`` (sorted record numbers; ``t`` their times), the positions
    in ``index`` of the records before and after it; a missing neighbour (an end of the
    trajectory, or beyond a gap longer than ``max_gap_s``) is the record itself."""
    n = len(index)
    pos = np.arange(n)
    prev, nxt = np.maximum(pos - 1, 0), np.minimum(pos + 1, n - 1)
    ok_lo = (pos > 0) & (index[prev] == index - 1) & (t - t[prev] <= max_gap_s)
    ok_hi = (pos < n - 1) & (index[nxt] == index + 1) & (t[nxt] - t <= max_gap_s)
    return np.where(ok_lo, prev, pos), np.where(ok_hi, nxt, pos)


def _rates(t: Array, diff, lo: NDArray[np.int64], hi: NDArray[np.int64]) -> Array:
    """Time derivative at each record from its neighbours: ``diff(i)`` is the value at the
    records ``i`` minus the value at each record (a vector difference, or the rotation vector
    of a relative rotation). Three-point, second order on unequal intervals: central where
    both neighbours exist, one-sided (the next two records) at the trajectory's ends and gaps."""
    h1, h2 = (t - t[lo])[:, None], (t[hi] - t)[:, None]
    lo2, hi2 = lo[lo], hi[hi]
    g1, g2 = (t[lo] - t[lo2])[:, None], (t[hi2] - t[hi])[:, None]
    d_lo, d_hi, d_lo2, d_hi2 = diff(lo), diff(hi), diff(lo2), diff(hi2)
    with np.errstate(divide="ignore", invalid="ignore"):
        central = (h1 * h1 * d_hi - h2 * h2 * d_lo) / (h1 * h2 * (h1 + h2))
        # one-sided on 0, a, a + b: (d_a (a + b)^2 - d_ab a^2) / (a b (a + b))
        start = (d_hi * (h2 + g2) ** 2 - d_hi2 * h2 * h2) / (h2 * g2 * (h2 + g2))
        end = -(d_lo * (h1 + g1) ** 2 - d_lo2 * h1 * h1) / (h1 * g1 * (h1 + g1))
        start = np.where(g2 > 0, start, d_hi / h2)
        end = np.where(g1 > 0, end, -d_lo / h1)
    return np.where((h1 > 0) & (h2 > 0), central, np.where(h2 > 0, start, end))


def _check_velocities(
    nav: NavSolution,
    near: NDArray[np.int64],
    j: NDArray[np.int64],
    xyz: Array,
    vel: Array,
    tol: float,
) -> None:
    """Record velocities against the chord of each interval used (a velocity in another frame
    or sign convention would bend the interpolation by centimetres: refuse it)."""
    dt = nav.time[near[j + 1]] - nav.time[near[j]]
    chord = (xyz[j + 1] - xyz[j]) / dt[:, None]
    off = np.linalg.norm(0.5 * (vel[j] + vel[j + 1]) - chord, axis=1)
    bad = np.flatnonzero(off > tol + 5.0 * dt)
    if bad.size:
        i = bad[np.argmax(off[bad])]
        raise InputError(
            f"the velocities of {nav.record}s {int(nav.numbers[near[j[i]]])} and "
            f"{int(nav.numbers[near[j[i] + 1]])} differ by {off[i]:.3g} m/s from the motion of "
            f"their positions (chord {np.linalg.norm(chord[i]):.3g} m/s): velocities in another "
            "frame or sign convention?",
            path=nav.source,
        )


def _basis(t_knots: Array, j: NDArray[np.int64], t: Array):
    """Interval lengths h and the cubic Hermite basis h00, h10, h01, h11 at ``t``."""
    h = (t_knots[j + 1] - t_knots[j])[:, None]
    s = (t - t_knots[j])[:, None] / h
    s2, s3 = s * s, s * s * s
    return h, 2 * s3 - 3 * s2 + 1, s3 - 2 * s2 + s, 3 * s2 - 2 * s3, s3 - s2


def _hermite(tk: Array, xyz: Array, vel: Array, j: NDArray[np.int64], t: Array) -> Array:
    """Cubic Hermite positions at ``t`` in the intervals ``[tk[j], tk[j + 1]]``.

    The basis is written out (the same numbers as SciPy's CubicHermiteSpline, tested):
    importing scipy.interpolate alone takes about 1 s, half of a whole hour-long SBET run.
    """
    h, h00, h10, h01, h11 = _basis(tk, j, t)
    return h00 * xyz[j] + h10 * h * vel[j] + h01 * xyz[j + 1] + h11 * h * vel[j + 1]


def _hermite_rate(tk: Array, xyz: Array, vel: Array, j: NDArray[np.int64], t: Array) -> Array:
    """Velocity (m/s) of the cubic Hermite of :func:`_hermite` at ``t``: its derivative."""
    h = (tk[j + 1] - tk[j])[:, None]
    s = (t - tk[j])[:, None] / h
    d00, d01 = 6 * s * s - 6 * s, 6 * s - 6 * s * s
    d10, d11 = 3 * s * s - 4 * s + 1, 3 * s * s - 2 * s
    return (d00 * xyz[j] + d01 * xyz[j + 1]) / h + d10 * vel[j] + d11 * vel[j + 1]


def _slerp(tk: Array, rot, j: NDArray[np.int64], t: Array) -> Array:
    """Spherical linear interpolation (constant angular velocity over each interval)."""
    from scipy.spatial.transform import Rotation

    s = (t - tk[j]) / (tk[j + 1] - tk[j])
    delta = (rot[j + 1] * rot[j].inv()).as_rotvec()
    return (Rotation.from_rotvec(s[:, None] * delta) * rot[j]).as_matrix()


def _rotation_hermite(tk: Array, rot, omega: Array, j: NDArray[np.int64], t: Array) -> Array:
    """Cubic Hermite on the rotation group: ``R(s) = exp(phi(s)) R_j`` with ``phi`` the cubic
    in the rotation vector through 0 and ``log(R_j+1 R_j^T)`` whose slopes are the angular
    velocities ``omega`` (ECEF, rad/s) at both records (the one at the end mapped through the
    inverse left Jacobian of the rotation vector to first order). With constant angular
    velocity it is SLERP; an angular acceleration (a roll manoeuvre) costs SLERP alpha h^2 / 8
    and this a term of third order in h."""
    from scipy.spatial.transform import Rotation

    h, _, h10, h01, h11 = _basis(tk, j, t)
    delta = (rot[j + 1] * rot[j].inv()).as_rotvec()
    w0, w1 = h * omega[j], h * omega[j + 1]
    w1 = w1 - 0.5 * np.cross(delta, w1)
    phi = h10 * w0 + h01 * delta + h11 * w1
    return (Rotation.from_rotvec(phi) * rot[j]).as_matrix()
