"""Scale bars and measured distances for the bundle adjustment (CSV), and the adjusted bars.

Input, one row per bar (header row; names case-insensitive, aliases in parentheses)::

    point_a (from, a)                 point_id of one end (an adjusted point of the
    point_b (to, b)                   observation table: tie or control, not check)
    distance (d, length)              measured distance, frame units (metres in a mapping
                                      CRS; m or mm in a local engineering frame), > 0
    sigma (sd, sigma_d)               its standard deviation, the same unit, > 0

A bar is a pair of points: the same pair twice (in either order) is refused, as is a bar
from a point to itself. Errors name the file, the row (the header is row 1) and the column.

Output (``OUTPUT_SCALE_BARS``), one row per bar, frame units (``unit`` column)::

    point_a, point_b, distance, sigma   as given
    adjusted, adjusted_sigma            the adjusted distance and its standard deviation
    v                                   residual, adjusted minus measured
    w, redundancy                       Baarda's w-test and the redundancy number
    rejected                            1 when data snooping rejected the bar
    unit                                m or mm (the frame's)
"""

from __future__ import annotations

from pathlib import Path
from typing import Union

import numpy as np

from ..errors import InputError
from ..photo.scale_bars import BarResult, ScaleBars
from .tables import find_column, float_column, number, read_table, text_column, write_csv_atomic

__all__ = ["SCALE_BAR_COLUMNS", "read_scale_bars_csv", "write_scale_bars_csv"]

SCALE_BAR_COLUMNS = (
    "point_a",
    "point_b",
    "distance",
    "sigma",
    "adjusted",
    "adjusted_sigma",
    "v",
    "w",
    "redundancy",
    "rejected",
    "unit",
)


def read_scale_bars_csv(path: Union[str, Path]) -> ScaleBars:
    """Read the bars (format in the module docstring).

    Raises
    ------
    InputError
        Missing columns, non-numeric or non-positive distances and sigmas, a bar from a point
        to itself, a duplicated bar; naming the file, row and column.
    """
    table = read_table(path)
    ca = find_column(table, ("point_a", "from", "a"), what="point_a")
    cb = find_column(table, ("point_b", "to", "b"), what="point_b")
    a, b = text_column(table, ca), text_column(table, cb)
    cols = (
        find_column(table, ("distance", "d", "length"), what="distance"),
        find_column(table, ("sigma", "sd", "sigma_d"), what="sigma"),
    )
    dist, sig = (float_column(table, c) for c in cols)
    seen: dict[frozenset, int] = {}
    for k, row in enumerate(table.line_numbers):
        for col, values, what in zip(cols, (dist, sig), ("distance", "standard deviation")):
            if not values[k] > 0:
                raise InputError(
                    f"a {what} must be > 0, got {values[k]:g}",
                    path=table.path,
                    row=row,
                    column=table.columns[col],
                )
        if a[k] == b[k]:
            raise InputError(f"a bar from point '{a[k]}' to itself", path=table.path, row=row)
        pair = frozenset((a[k], b[k]))
        if pair in seen:
            raise InputError(
                f"the bar {a[k]} - {b[k]} is given twice (also in row {seen[pair]})",
                path=table.path,
                row=row,
            )
        seen[pair] = row
    return ScaleBars(
        a, b, np.asarray(dist), np.asarray(sig), tuple(table.line_numbers), str(table.path)
    )


def write_scale_bars_csv(path: Union[str, Path], res: BarResult, unit: str) -> None:
    """The adjusted bars (format in the module docstring), ``unit`` the frame's."""
    bars = res.bars
    rows = (
        (
            pa,
            pb,
            number(d),
            number(s),
            number(ad),
            number(asg),
            number(v),
            number(w),
            number(r),
            int(rej),
            unit,
        )
        for pa, pb, d, s, ad, asg, v, w, r, rej in zip(
            bars.point_a,
            bars.point_b,
            bars.distance,
            bars.sigma,
            res.adjusted,
            res.sigma,
            res.v,
            res.w,
            res.redundancy,
            res.rejected,
        )
    )
    write_csv_atomic(path, SCALE_BAR_COLUMNS, rows)
