"""Check-point tables (CSV) for the accuracy report.

Check-point table (CSV, header row; names are case-insensitive, aliases in parentheses)::

    id (point, point_id, name)                          text, unique
    e (easting, x, e_measured, measured_e)              measured position (m)
    n (northing, y, n_measured, measured_n)
    h (height, z, h_measured, measured_h)
    e_ref (easting_ref, x_ref, e_reference, reference_e) reference position (m)
    n_ref (northing_ref, y_ref, n_reference, reference_n)
    h_ref (height_ref, z_ref, h_reference, reference_h)
    group (direction, model, block, strip)              optional

Point table (two of them, joined by id; ``read_point_table``)::

    id, e, n, h [, group]                               with the aliases above
"""

from __future__ import annotations

import os
from typing import Union

import numpy as np

from ..quality.accuracy import CheckPoints, PointSet, check_unique_ids
from .tables import Table, find_column, float_column, normalise, read_table, text_column

PathLike = Union[str, "os.PathLike[str]"]

_ID = ("id", "point", "point_id", "name")

_GROUP = ("group", "direction", "model", "block", "strip")

_MEASURED = (
    ("e", "easting", "x", "e_measured", "measured_e"),
    ("n", "northing", "y", "n_measured", "measured_n"),
    ("h", "height", "z", "h_measured", "measured_h"),
)

_REFERENCE = (
    ("e_ref", "easting_ref", "x_ref", "e_reference", "reference_e"),
    ("n_ref", "northing_ref", "y_ref", "n_reference", "reference_n"),
    ("h_ref", "height_ref", "z_ref", "h_reference", "reference_h"),
)


def _table_ids(table: Table) -> tuple[str, ...]:
    index = find_column(table, _ID, what="the point id")
    values = text_column(table, index)
    check_unique_ids(values, [f"row {n}" for n in table.line_numbers], table.path)
    return values


def _table_groups(table: Table, column: str | None) -> tuple[str, ...]:
    index: int | None
    if column:
        index = find_column(table, (normalise(column),), what=f"the group ({column})")
    else:
        index = find_column(table, _GROUP, required=False)
    if index is None:
        return ("",) * len(table)
    return text_column(table, index, nonempty=False)


def read_checkpoint_table(
    path: PathLike, *, group_column: str | None = None, crs: str | None = None
) -> CheckPoints:
    """Read the one-table format (see the module docstring).

    Errors name the file, the row (header is row 1) and the column.

    Parameters
    ----------
    path : path-like
        CSV file.
    group_column : str, optional
        Column holding the group; default the first of group, direction, model, block, strip.
    crs : str, optional
        CRS of the coordinates (reported only).
    """
    table = read_table(path)
    ids = _table_ids(table)
    measured = np.column_stack(
        [float_column(table, find_column(table, a, what=a[0])) for a in _MEASURED]
    )
    reference = np.column_stack(
        [float_column(table, find_column(table, a, what=a[0])) for a in _REFERENCE]
    )
    groups = _table_groups(table, group_column)
    return CheckPoints(ids, measured, reference, groups, crs or None, str(path))


def read_point_table(
    path: PathLike,
    *,
    id_column: str | None = None,
    z_column: str | None = None,
    group_column: str | None = None,
    crs: str | None = None,
) -> PointSet:
    """Read a point table ``id, e, n, h [, group]`` (aliases as in the module docstring).

    ``id_column`` and ``z_column`` name other columns for the id and the height.
    """
    table = read_table(path)
    if id_column:
        id_index = find_column(table, (normalise(id_column),), what=f"the id ({id_column})")
        ids = text_column(table, id_index)
        check_unique_ids(ids, [f"row {n}" for n in table.line_numbers], table.path)
    else:
        ids = _table_ids(table)
    cols = []
    aliases: tuple[str, ...]
    for k, aliases in enumerate(_MEASURED):
        if k == 2 and z_column:
            aliases = (normalise(z_column),)
        cols.append(float_column(table, find_column(table, aliases, what=aliases[0])))
    groups = _table_groups(table, group_column)
    return PointSet(
        ids, np.column_stack(cols), groups, crs or None, str(path), table.line_numbers, "row"
    )
