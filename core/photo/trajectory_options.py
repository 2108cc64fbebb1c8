"""The options of trajectory import (:mod:`.navigation`), kept apart from its pyproj and
SciPy code so that the ``importtrajectory`` spec reads its defaults and choices without
importing them (core/jobs/import_trajectory.py)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import InputError

#: Trajectory file formats: ``auto`` picks by the file's ending (``.out``/``.sbet``: SBET,
#: ``.csv``: the generic CSV, anything else: an ASCII export); docs/formats.md.
TRAJECTORY_FORMATS = ("auto", "sbet", "ascii", "csv")
#: The clock of the camera event times: ``gps`` seconds of the GPS week (the SBET's clock),
#: or ``utc`` date-times (ISO 8601), turned into GPS seconds of week with the stated leap
#: seconds.
EVENT_TIMES = ("gps", "utc")
#: GPS - UTC in seconds since 2017-01-01 (IERS Bulletin C: no leap second announced since).
LEAP_SECONDS_SINCE_2017 = 18
#: Attitude between two records: ``cubic`` (a Hermite cubic on the rotation group with the
#: angular velocities of the neighbouring records) or ``slerp`` (constant angular velocity).
ATTITUDE_METHODS = ("cubic", "slerp")
#: Seconds in a GPS week.
WEEK_S = 604800.0


@dataclass(frozen=True)
class TrajectoryImportOptions:
    """How camera events are placed on a trajectory.

    Attributes
    ----------
    time_offset_s : float
        Camera timing offset, seconds: trajectory time = event time + offset.
    max_gap_s : float
        Longest interval between two trajectory records an event may fall in, seconds;
        an event in a longer gap is refused (the motion between the records is unknown).
    event_time : {"gps", "utc"}
        Clock of the event times (:data:`EVENT_TIMES`).
    leap_seconds : int
        GPS - UTC, seconds, at the events' date (18 since 2017-01-01); used for ``utc``.
    attitude : {"cubic", "slerp"}
        Interpolation of the body-to-ECEF rotation (:data:`ATTITUDE_METHODS`).
    velocity_tolerance_mps : float
        The records' velocities may differ from the chord velocity of their positions by
        this much plus 5 m/s^2 times the record interval (a velocity in another frame or
        convention is refused rather than bending the interpolation).
    """

    time_offset_s: float = 0.0
    max_gap_s: float = 0.1
    event_time: str = "gps"
    leap_seconds: int = LEAP_SECONDS_SINCE_2017
    attitude: str = "cubic"
    velocity_tolerance_mps: float = 0.1

    def __post_init__(self) -> None:
        if not (math.isfinite(self.time_offset_s) and abs(self.time_offset_s) <= 60.0):
            raise InputError(f"TIME_OFFSET must be within +-60 s, got {self.time_offset_s}")
        if not (math.isfinite(self.max_gap_s) and 0.0 < self.max_gap_s <= 60.0):
            raise InputError(f"MAX_GAP must be in (0, 60] s, got {self.max_gap_s}")
        if self.event_time not in EVENT_TIMES:
            raise InputError(
                f"EVENT_TIME '{self.event_time}' is unknown: use {', '.join(EVENT_TIMES)}"
            )
        if not (0 <= self.leap_seconds <= 100 and float(self.leap_seconds).is_integer()):
            raise InputError(f"LEAP_SECONDS must be a whole number 0..100, got {self.leap_seconds}")
        if self.attitude not in ATTITUDE_METHODS:
            raise InputError(
                f"ATTITUDE '{self.attitude}' is unknown: use {', '.join(ATTITUDE_METHODS)}"
            )
        if not (self.velocity_tolerance_mps > 0.0):
            raise InputError("the velocity tolerance must be > 0 m/s")
