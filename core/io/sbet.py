"""Applanix SBET (smoothed best estimated trajectory, ``sbet_*.out``): a headerless binary file
of records of 17 little-endian IEEE float64 (136 bytes)::

     0 time               GPS seconds of week, s
     1 latitude           rad        2 longitude        rad       3 ellipsoidal height  m
     4 x velocity         m/s        5 y velocity       m/s       6 z velocity          m/s
     7 roll               rad        8 pitch            rad       9 platform heading    rad
    10 wander angle       rad
    11-13 x, y, z body acceleration  m/s^2
    14-16 x, y, z body angular rate  rad/s

The field order is the one of the POSPac documentation as republished by its users (e.g.
the LiDAR360 manual's "OUT File" appendix) and of PDAL's ``readers.sbet``. Velocities are in
the wander-angle frame, locally level: with a wander angle of 0 its x axis points north, y
west and z up; the platform heading is measured in that frame, so (Applanix):

    true heading = platform heading - wander angle
    v_north = vx cos(a) - vy sin(a),  v_east = -vx sin(a) - vy cos(a),  v_down = -vz

The reader returns roll, pitch, the true heading and north-east-down velocities; the
accelerations and angular rates are not used. A file whose size is not a multiple of 136
bytes, a non-finite value, a latitude or longitude beyond its range, or a time not later
than the record before is refused with the record's number (1-based) and byte offset.
"""

from __future__ import annotations

from pathlib import Path
from typing import Union

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..photo.navigation import NavSolution
from .atomic import atomic_write
from .trajectory import HEIGHT_RANGE_M, MAX_TIME_S

Array = NDArray[np.float64]
#: Bytes per SBET record: 17 float64.
RECORD_BYTES = 136
SBET_FIELDS = (
    "time",
    "latitude",
    "longitude",
    "height",
    "vx",
    "vy",
    "vz",
    "roll",
    "pitch",
    "platform_heading",
    "wander",
    "ax",
    "ay",
    "az",
    "wx",
    "wy",
    "wz",
)


def read_sbet(path: Union[str, Path]) -> NavSolution:
    """Read an SBET file (format in the module docstring), checked record by record."""
    p = Path(path)
    if not p.is_file():
        raise InputError("file not found", path=str(p))
    size = p.stat().st_size
    if size == 0 or size % RECORD_BYTES:
        raise InputError(
            f"{size} bytes is not a whole number of 136-byte SBET records ({size // RECORD_BYTES}"
            f" records and {size % RECORD_BYTES} bytes): a truncated or not an SBET file",
            path=str(p),
        )
    data = np.fromfile(p, dtype="<f8").reshape(-1, 17)
    _check(data, str(p))
    lat, lon = np.degrees(data[:, 1]), np.degrees(data[:, 2])
    wander = data[:, 10]
    c, s = np.cos(wander), np.sin(wander)
    vx, vy, vz = data[:, 4], data[:, 5], data[:, 6]
    v_ned = np.stack([vx * c - vy * s, -vx * s - vy * c, -vz], axis=1)
    heading = np.mod(data[:, 9] - wander, 2.0 * np.pi)
    return NavSolution(
        time=data[:, 0].copy(),
        position=np.stack([lat, lon, data[:, 3]], axis=1),
        geodetic=True,
        rph=np.stack([data[:, 7], data[:, 8], heading], axis=1),
        velocity_ned=v_ned,
        source=str(p),
        record="record",
        numbers=np.arange(1, len(data) + 1),
    )


def _check(data: Array, path: str) -> None:
    def refuse(k: int, what: str) -> None:
        raise InputError(f"record {k + 1} (byte {k * RECORD_BYTES}): {what}", path=path)

    bad = np.flatnonzero(~np.isfinite(data).all(axis=1))
    if bad.size:
        refuse(int(bad[0]), "a value is not finite")
    limits = (
        (0, MAX_TIME_S, "time"),
        (1, np.pi / 2, "latitude"),
        (2, 2 * np.pi, "longitude"),
        (7, np.pi, "roll"),
        (8, np.pi / 2, "pitch"),
        (9, 4 * np.pi, "heading"),
        (10, 4 * np.pi, "wander angle"),
    )
    for col, limit, name in limits:
        bad = np.flatnonzero(np.abs(data[:, col]) > limit)
        if bad.size:
            refuse(
                int(bad[0]),
                f"{name} {data[bad[0], col]:.9g} is beyond +-{limit:.9g} "
                "(radians and seconds expected: not an SBET?)",
            )
    lo, hi = HEIGHT_RANGE_M
    bad = np.flatnonzero((data[:, 3] < lo) | (data[:, 3] > hi))
    if bad.size:
        refuse(int(bad[0]), f"height {data[bad[0], 3]:.9g} m is outside {lo:g} to {hi:g} m")
    step = np.flatnonzero(np.diff(data[:, 0]) <= 0)
    if step.size:
        k = int(step[0]) + 1
        refuse(
            k,
            f"time {data[k, 0]:.6f} s is not later than {data[k - 1, 0]:.6f} s of the "
            "record before (records out of order or repeated)",
        )


def sbet_records(
    time: Array,
    llh_rad: Array,
    velocity_ned: Array,
    rph_true: Array,
    wander: Array,
) -> Array:
    """(N, 17) SBET records from times (s), latitude, longitude (rad) and height (m),
    north-east-down velocities (m/s), roll, pitch, true heading (rad) and wander angles
    (rad), with the conventions of the module docstring; accelerations and rates zero."""
    n = len(time)
    c, s = np.cos(wander), np.sin(wander)
    vn, ve, vd = velocity_ned.T
    out = np.zeros((n, 17))
    out[:, 0] = time
    out[:, 1:4] = llh_rad
    out[:, 4] = vn * c - ve * s
    out[:, 5] = -vn * s - ve * c
    out[:, 6] = -vd
    out[:, 7:9] = rph_true[:, :2]
    out[:, 9] = np.mod(rph_true[:, 2] + wander, 2.0 * np.pi)
    out[:, 10] = wander
    return out


def write_sbet(path: Union[str, Path], records: Array) -> None:
    """Write (N, 17) records as an SBET file, atomically."""
    records = np.ascontiguousarray(records, dtype="<f8")
    if records.ndim != 2 or records.shape[1] != 17:
        raise InputError(f"SBET records must be (N, 17), got {records.shape}", path=str(path))
    with atomic_write(path, "wb") as fh:
        fh.write(records.tobytes())
