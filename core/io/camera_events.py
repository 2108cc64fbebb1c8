"""The camera event file: the exposure time of every image (docs/formats.md).

CSV with a header row (the common rules of core/io/tables.py)::

    image_id (id, image, name, photo)   text, unique
    time (gps_time, event_time, t)      GPS seconds of week (EVENT_TIME gps), or a UTC
                                        date-time in ISO 8601 (EVENT_TIME utc), e.g.
                                        2026-12-02T06:13:13.123456Z
    group (line, strip, flight_line)    optional

UTC date-times are turned into GPS seconds of week with the stated leap seconds (GPS - UTC,
18 s since 2017-01-01): :func:`~lidarphoto.core.photo.navigation.gps_seconds_of_week`.
"""

from __future__ import annotations

import datetime as _dt
import re
from pathlib import Path
from typing import Union

import numpy as np

from ..errors import InputError
from ..photo.navigation import CameraEvents, gps_seconds_of_week
from ..photo.trajectory_options import EVENT_TIMES, LEAP_SECONDS_SINCE_2017, WEEK_S
from .tables import find_column, float_column, read_table, refuse_rows, text_column, unique_ids

_FRACTION = re.compile(r"(?<=:\d\d)\.(\d+)")


def read_camera_events(
    path: Union[str, Path],
    event_time: str = "gps",
    leap_seconds: int = LEAP_SECONDS_SINCE_2017,
) -> CameraEvents:
    """Read the event file; times in GPS seconds of week (module docstring)."""
    if event_time not in EVENT_TIMES:
        raise InputError(f"EVENT_TIME '{event_time}' is unknown: use {', '.join(EVENT_TIMES)}")
    table = read_table(path)
    ids = unique_ids(table, find_column(table, ("image_id", "id", "image", "name", "photo")))
    t_col = find_column(table, ("time", "gps_time", "event_time", "t"), what="time")
    g_col = find_column(table, ("group", "line", "strip", "flight_line"), required=False)
    group = text_column(table, g_col, nonempty=False) if g_col is not None else ("",) * len(ids)
    where = {"path": table.path, "column": table.columns[t_col]}
    if event_time == "gps":
        time = float_column(table, t_col)
        refuse_rows(
            table,
            (time < 0) | (time >= 2 * WEEK_S),
            t_col,
            lambda k: (
                f"{time[k]:g} s is not a GPS second of week (0 to 604800; a UTC "
                "date-time needs EVENT_TIME utc)"
            ),
        )
    else:
        cells = text_column(table, t_col)
        time = np.array(
            [
                gps_seconds_of_week(_utc(c, table.line_numbers[k], where), leap_seconds)
                for k, c in enumerate(cells)
            ]
        )
    return CameraEvents(ids, time, group, table.line_numbers, table.path)


def _utc(cell: str, row: int, where: dict) -> _dt.datetime:
    text = cell.strip()
    if text.endswith(("Z", "z")):
        text = text[:-1] + "+00:00"
    # Python 3.9 reads 3 or 6 decimals of a second only: pad to microseconds
    text = _FRACTION.sub(lambda m: "." + (m.group(1) + "000000")[:6], text, count=1)
    try:
        value = _dt.datetime.fromisoformat(text)
    except ValueError:
        raise InputError(
            f"'{cell}' is not an ISO 8601 date-time (e.g. 2026-12-02T06:13:13.25Z)",
            row=row,
            **where,
        ) from None
    if value.tzinfo is None:
        raise InputError(f"'{cell}' has no time zone: add Z for UTC", row=row, **where)
    return value.astimezone(_dt.timezone.utc)
