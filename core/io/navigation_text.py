"""Navigation solutions as text: the ASCII exports of POSPac and Inertial Explorer, and a
generic CSV of time-stamped positions and attitudes at any rate (docs/formats.md).

Both are tables whose header names the columns (case-insensitive; spaces and hyphens count
as underscores, a unit in brackets is read off the name: ``Roll(deg)``, ``Heading[rad]``)::

    time (gps_time, gpstime, sow, t)           GPS seconds of week
    latitude (lat), longitude (lon, long)      degrees, on the mapping CRS's datum
    or easting (east), northing (north)        metres, in the mapping CRS
    height (h_ell, ellipsoid_height, h, alt)   ellipsoidal metres (or the CRS's heights)
    roll, pitch, heading (yaw, true_heading)   degrees unless the unit says rad
    optional: v_north (vnorth, vn, north_vel), v_east (veast, ve, east_vel) and v_up (vup,
    vu, up_vel) or v_down (vdown, vd): m/s; wander (wander_angle): then the heading is the
    platform heading and the true heading is heading - wander (Applanix).

The ASCII export (:func:`read_nav_ascii`) may start with any preamble (project, datum, lines
of dashes): its data are the lines of numbers, its header the line of names above them
(whitespace- or comma-separated; a line of units such as ``(sec) (deg)`` between them is
read as the columns' units). The generic CSV (:func:`read_nav_csv`) is a table of the
project's common rules (core/io/tables.py). Times must rise strictly down the file.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Union

import numpy as np

from ..errors import InputError
from ..photo.navigation import NavSolution
from .tables import Table, find_column, float_column, read_table, refuse_rows
from .trajectory import HEIGHT_RANGE_M, MAX_TIME_S, velocity_columns

_TIME = ("time", "gps_time", "gpstime", "sow", "gps_sow", "t", "time_sow")
_LAT, _LON = ("latitude", "lat"), ("longitude", "lon", "long")
_EAST, _NORTH = ("easting", "east", "e"), ("northing", "north", "n")
_HEIGHT = (
    "height",
    "h_ell",
    "hell",
    "ellipsoid_height",
    "ellipsoidal_height",
    "h",
    "alt",
    "altitude",
    "z",
)
_ROLL, _PITCH = ("roll",), ("pitch",)
_HEADING = ("heading", "yaw", "true_heading", "azimuth")
_WANDER = ("wander", "wander_angle")
_UNIT = re.compile(r"^(.*?)\s*[(\[]([^)\]]*)[)\]]\s*$")


def read_nav_csv(path: Union[str, Path]) -> NavSolution:
    """Read the generic navigation CSV (module docstring)."""
    table = read_table(path)
    names, units = _split_units(table.columns)
    return _solution(Table(table.path, names, table.rows, table.line_numbers), units)


def read_nav_ascii(path: Union[str, Path]) -> NavSolution:
    """Read a POSPac / Inertial Explorer ASCII export (module docstring)."""
    p = Path(path)
    if not p.is_file():
        raise InputError("file not found", path=str(p))
    try:
        lines = p.read_text(encoding="utf-8-sig", errors="strict").splitlines()
    except UnicodeDecodeError as exc:
        raise InputError(
            f"not a text file ({exc.reason}): an SBET? use FORMAT sbet", path=str(p)
        ) from exc
    first = next((i for i, line in enumerate(lines) if _numbers(line)), None)
    if first is None:
        raise InputError("no line of numbers: not a navigation export", path=str(p))
    width = len(_numbers(lines[first]) or ())
    header_at, unit_cells = _header_above(lines, first, width, str(p))
    names, units = _split_units(_cells(lines[header_at].lstrip("#")))
    if unit_cells is not None:
        units = tuple(u or _bare(c) for u, c in zip(units, unit_cells))
    rows, numbers = [], []
    for i in range(first, len(lines)):
        line = lines[i]
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        cells = _cells(line)
        if len(cells) != width:
            raise InputError(
                f"has {len(cells)} values but the header has {width} columns",
                path=str(p),
                row=i + 1,
            )
        rows.append(tuple(cells))
        numbers.append(i + 1)
    return _solution(Table(str(p), names, tuple(rows), tuple(numbers)), units)


def _cells(line: str) -> tuple[str, ...]:
    """Comma-separated if the line has commas, else whitespace-separated."""
    if "," in line:
        return tuple(c.strip() for c in line.split(","))
    return tuple(line.split())


def _numbers(line: str) -> tuple[str, ...] | None:
    """The cells of a data line: at least 4, three quarters of them numbers (an export may
    carry a date or a clock time as text in columns this reader does not use)."""
    cells = _cells(line)
    if len(cells) < 4:
        return None
    numeric = 0
    for c in cells:
        try:
            float(c)
            numeric += 1
        except ValueError:
            pass
    return cells if numeric * 4 >= 3 * len(cells) else None


def _bare(cell: str) -> str:
    return cell.strip().strip("()[]").strip()


def _header_above(lines: list[str], first: int, width: int, path: str):
    """Line index of the names above the first data line, and the units line if any."""
    above = [
        i for i in range(first) if lines[i].strip() and not set(lines[i].strip()) <= set("-=_ ")
    ]
    units = None
    if above and all(c.startswith(("(", "[")) for c in _cells(lines[above[-1]])):
        cells = _cells(lines[above[-1]])
        if len(cells) == width:
            units = cells
            above = above[:-1]
    if not above or len(_cells(lines[above[-1]].lstrip("#"))) != width:
        raise InputError(
            f"no header line with {width} column names above the first data line "
            f"(names joined by _ or -, or separated by commas)",
            path=path,
            row=first + 1,
        )
    return above[-1], units


def _split_units(columns) -> tuple[tuple[str, ...], tuple[str, ...]]:
    names, units = [], []
    for c in columns:
        m = _UNIT.match(c)
        names.append((m.group(1) if m else c).strip())
        units.append((m.group(2) if m else "").strip().lower())
    return tuple(names), tuple(units)


def _angle_factor(units: tuple[str, ...], col: int) -> float:
    return 1.0 if units[col].startswith("rad") else np.pi / 180.0


def _solution(table: Table, units: tuple[str, ...]) -> NavSolution:
    """The navigation solution of a table with named columns (module docstring)."""
    t_col = find_column(table, _TIME, what="time")
    time = float_column(table, t_col)
    _check_time(table, t_col, time)
    lat_col = find_column(table, _LAT, required=False)
    h_col = find_column(table, _HEIGHT, what="height")
    if lat_col is not None:
        lon_col = find_column(table, _LON, what="longitude")
        pos = np.stack([float_column(table, c) for c in (lat_col, lon_col, h_col)], axis=1)
        for col, values, limit in ((lat_col, pos[:, 0], 90.0), (lon_col, pos[:, 1], 360.0)):
            _check_abs(table, col, values, limit, "degrees")
    else:
        cols = [find_column(table, names, what=names[0]) for names in (_EAST, _NORTH)]
        pos = np.stack([float_column(table, c) for c in (*cols, h_col)], axis=1)
    lo, hi = HEIGHT_RANGE_M
    _check_abs(
        table, h_col, pos[:, 2] - 0.5 * (lo + hi), 0.5 * (hi - lo), "m (a height in another unit?)"
    )
    cols = [find_column(table, names, what=names[0]) for names in (_ROLL, _PITCH, _HEADING)]
    rph = np.stack([float_column(table, c) * _angle_factor(units, c) for c in cols], axis=1)
    w_col = find_column(table, _WANDER, required=False)
    if w_col is not None:
        rph[:, 2] -= float_column(table, w_col) * _angle_factor(units, w_col)
    for col, values, limit in zip(cols, rph.T, (np.pi, np.pi / 2, 4 * np.pi)):
        _check_abs(table, col, values, limit, "radians (degrees expected unless the unit is rad)")
    return NavSolution(
        time,
        pos,
        lat_col is not None,
        rph,
        velocity_columns(table),
        table.path,
        "row",
        np.asarray(table.line_numbers),
    )


def _check_abs(table: Table, col: int, values, limit: float, unit: str) -> None:
    refuse_rows(
        table,
        np.abs(values) > limit,
        col,
        lambda k: f"'{table.rows[k][col]}' is out of range ({unit})",
    )


def _check_time(table: Table, col: int, time: np.ndarray) -> None:
    _check_abs(table, col, time, MAX_TIME_S, "seconds")
    refuse_rows(
        table,
        np.r_[False, np.diff(time) <= 0],
        col,
        lambda k: (
            f"time {time[k]:.6f} s is not later than {time[k - 1]:.6f} s in row "
            f"{table.line_numbers[k - 1]}: the records must rise strictly in time"
        ),
    )
