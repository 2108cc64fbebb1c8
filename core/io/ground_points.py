"""Ground points for the bundle adjustment: surveyed control and check points (CSV).

One row per point (header row; names case-insensitive, aliases in parentheses)::

    point_id (id, point, name)        text, unique; the point_id of the image observations
    X (E, easting, x)                 mapping CRS, metres
    Y (N, northing, y)
    Z (H, height, z)                  height as the mapping CRS defines it (ellipsoidal for a
                                      2D projected CRS)
    sx (sigma_x, sigma_e, s_x)        standard deviations, metres, > 0; optional (empty or
    sy (sigma_y, sigma_n, s_y)        missing: 0.02 m)
    sz (sigma_z, sigma_h, s_z)
    role (type, use)                  control (in the adjustment, weighted by its sigmas) or
                                      check (kept out of the adjustment, reported)

Errors name the file, the row (the header is row 1) and the column.
"""

from __future__ import annotations

from pathlib import Path
from typing import Union

import numpy as np

from ..photo.bundle_setup import DEFAULT_CONTROL_SIGMA_M, ROLES, GroundPoints
from . import tables
from .tables import (
    find_column,
    float_column,
    read_table,
    refuse_rows,
    text_column,
    write_csv_atomic,
)

__all__ = ["GROUND_POINT_COLUMNS", "read_ground_points_csv", "write_ground_points_csv"]

GROUND_POINT_COLUMNS = ("point_id", "X", "Y", "Z", "sx", "sy", "sz", "role")

_XYZ = (("x", "e", "easting"), ("y", "n", "northing"), ("z", "h", "height"))
_SIG = (
    ("sx", "sigma_x", "sigma_e", "s_x"),
    ("sy", "sigma_y", "sigma_n", "s_y"),
    ("sz", "sigma_z", "sigma_h", "s_z"),
)


def read_ground_points_csv(path: Union[str, Path]) -> GroundPoints:
    """Read the table (format in the module docstring).

    Raises
    ------
    InputError
        Missing columns, non-numeric values, sigmas <= 0, unknown roles, duplicated ids;
        naming the file, row and column.
    """
    table = read_table(path)
    ids = text_column(table, find_column(table, ("point_id", "id", "point", "name")))
    xyz = np.column_stack([float_column(table, find_column(table, a, what=a[0])) for a in _XYZ])
    sig = np.full((len(table), 3), DEFAULT_CONTROL_SIGMA_M)
    for k, aliases in enumerate(_SIG):
        col = find_column(table, aliases, required=False)
        if col is None:
            continue
        v = float_column(table, col, allow_empty=True)
        _check_positive(table, v, col)
        sig[:, k] = np.where(np.isnan(v), DEFAULT_CONTROL_SIGMA_M, v)
    r_col = find_column(table, ("role", "type", "use"))
    roles = tables.choice_column(table, r_col, ROLES, "a role")
    return GroundPoints(ids, xyz, sig, roles, table.line_numbers, table.path)


def _check_positive(table: tables.Table, sigma: np.ndarray, index: int) -> None:
    """Standard deviations (column ``index``; empty cells NaN) that are > 0."""
    refuse_rows(
        table, sigma <= 0, index, lambda k: f"a standard deviation must be > 0, got {sigma[k]}"
    )


def write_ground_points_csv(path: Union[str, Path], ground: GroundPoints) -> None:
    """Write the table atomically."""
    rows = (
        (p, *(repr(float(v)) for v in x), *(repr(float(v)) for v in s), r)
        for p, x, s, r in zip(ground.point_id, ground.xyz, ground.sigma, ground.role)
    )
    write_csv_atomic(path, GROUND_POINT_COLUMNS, rows)
