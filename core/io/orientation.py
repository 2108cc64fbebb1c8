"""The exterior orientation table: perspective centre and omega-phi-kappa per image.

CSV format (header row, comma separated, one image per row)::

    image_id,time,group,X,Y,Z,omega_deg,phi_deg,kappa_deg

X, Y, Z: perspective centre in the mapping CRS (easting, northing, height; metres).
omega, phi, kappa: degrees, ``M = R3(kappa) R2(phi) R1(omega)`` rotates vectors of the grid
frame at the perspective centre (grid east, grid north, local up) into the camera frame.
``time`` may be empty (NaN) and ``group`` (flight line or direction) may be empty. Lines
starting with ``#`` are comments (a calibration accepted despite failed checks says so there).
"""

from __future__ import annotations

import csv
import io
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Union

import numpy as np

from ..errors import InputError
from ..photo.orientation import ExteriorOrientationTable
from .tables import find_column, float_column, read_table, text_column, unique_ids, write_csv_atomic

EO_COLUMNS = ("image_id", "time", "group", "X", "Y", "Z", "omega_deg", "phi_deg", "kappa_deg")


def _eo_rows(eo: ExteriorOrientationTable) -> Iterator[tuple[str, ...]]:
    deg = np.degrees(eo.opk)
    for image, t, group, (x, y, z), (w, p, k) in zip(
        eo.image_id, eo.time, eo.group, eo.xyz, deg
    ):
        yield (
            image,
            "" if not np.isfinite(t) else f"{t:.6f}",
            group,
            f"{x:.4f}",
            f"{y:.4f}",
            f"{z:.4f}",
            f"{w:.10f}",
            f"{p:.10f}",
            f"{k:.10f}",
        )


def write_eo_csv(
    path: Union[str, Path], eo: ExteriorOrientationTable, comments: Sequence[str] = ()
) -> None:
    """Write the documented CSV atomically (never a half-written file); ``comments`` become
    ``# text`` lines before the header (e.g. a warning)."""
    write_csv_atomic(path, EO_COLUMNS, _eo_rows(eo), comments)


def eo_csv_text(eo: ExteriorOrientationTable) -> str:
    """The same table as text (what the command line prints when no file is given)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(EO_COLUMNS)
    writer.writerows(_eo_rows(eo))
    return buffer.getvalue()


def read_eo_csv(path: Union[str, Path], crs_wkt: str = "") -> ExteriorOrientationTable:
    """Read a table written by :meth:`ExteriorOrientationTable.to_csv` (or made by hand)."""
    table = read_table(path)
    ids = unique_ids(table, find_column(table, ("image_id", "image", "id", "name")))
    t_col = find_column(table, ("time",), required=False)
    g_col = find_column(table, ("group",), required=False)
    xyz = np.stack(
        [float_column(table, find_column(table, (name.lower(),))) for name in ("X", "Y", "Z")],
        axis=1,
    )
    opk = np.stack(
        [
            float_column(table, find_column(table, (f"{name}_deg", name)))
            for name in ("omega", "phi", "kappa")
        ],
        axis=1,
    )
    if t_col is None:
        time = np.full(len(table), np.nan)
    else:
        time = float_column(table, t_col, allow_empty=True)
    group = text_column(table, g_col, nonempty=False) if g_col is not None else ("",) * len(ids)
    if np.any(np.abs(opk[:, 1]) > 90.0):
        row = table.line_numbers[int(np.argmax(np.abs(opk[:, 1]) > 90.0))]
        raise InputError("phi must lie within [-90, 90] degrees", path=table.path, row=row)
    return ExteriorOrientationTable(ids, time, group, xyz, np.radians(opk), crs_wkt)
