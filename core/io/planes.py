"""The plane table (CSV): planes with their precision, one row per plane.

Header::

    id,a,b,c,d,centroid_x,centroid_y,centroid_z,n_points,rms,sigma_d,slope_deg,aspect_deg,
    cov_aa,cov_ab,cov_ac,cov_ad,cov_bb,cov_bc,cov_bd,cov_cc,cov_cd,cov_dd

id (integer, as in the cloud's ``plane_id`` dimension), a b c d (plane parameters; a b c
unitless, d in the CRS unit), centroid (CRS unit), n_points, rms of the point-to-plane residuals
(CRS unit), sigma_d (CRS unit), slope (degrees from horizontal), aspect (degrees clockwise from
grid north of the downslope direction; meaningless for flat planes), and the 10 upper-triangle
elements of the covariance of (a, b, c, d). Paper 000's plane list (id, parameters, centroid,
point count) is the first nine columns. Numbers are written with full round-trip precision.
"""

from __future__ import annotations

from collections.abc import Hashable, Sequence
from pathlib import Path
from typing import Union

import numpy as np

from ..errors import InputError
from ..geometry.planes import Plane
from .tables import (
    check_covariance,
    check_integers,
    find_column,
    float_column,
    note_unique,
    number,
    read_table,
    write_csv_atomic,
)

_PARAMS = "abcd"

#: Upper-triangle covariance column names, row-major: cov_aa, cov_ab, ..., cov_dd.
COV_COLUMNS: tuple[str, ...] = tuple(
    f"cov_{_PARAMS[i]}{_PARAMS[j]}" for i in range(4) for j in range(i, 4)
)

#: The header of the plane table, in order.
PLANE_COLUMNS: tuple[str, ...] = (
    "id",
    "a",
    "b",
    "c",
    "d",
    "centroid_x",
    "centroid_y",
    "centroid_z",
    "n_points",
    "rms",
    "sigma_d",
    "slope_deg",
    "aspect_deg",
    *COV_COLUMNS,
)

_IU = np.triu_indices(4)


def write_planes_csv(path: Union[str, Path], planes: Sequence[Plane]) -> None:
    """Write the plane table (header ``PLANE_COLUMNS``, see the module docstring) atomically.

    Parameters
    ----------
    path : str or Path
        CSV to write; written to a temporary file in the same folder, then moved into place.
    planes : sequence of Plane
        Planes, written in the given order (an empty sequence writes only the header).
    """
    rows = []
    for p in planes:
        rows.append(
            [
                str(int(p.id)),
                *(number(v) for v in p.normal),
                number(p.d),
                *(number(v) for v in p.centroid),
                str(int(p.n_points)),
                number(p.rms),
                number(p.sigma_d),
                number(p.slope_deg),
                number(p.aspect_deg),
                *(number(v) for v in p.covariance[_IU]),
            ]
        )
    write_csv_atomic(path, PLANE_COLUMNS, rows)


def _header_only(path: Union[str, Path]) -> bool:
    """True for a readable table holding the plane header and no data rows (no planes)."""
    try:
        text = Path(path).read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError):
        return False  # read_table reports it
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    return len(lines) == 1 and {c.strip().lower() for c in lines[0].split(",")} >= set(
        PLANE_COLUMNS
    )


def read_planes_csv(path: Union[str, Path]) -> list[Plane]:
    """Read a plane table written by :func:`write_planes_csv` (or by hand, same header).

    Columns are found by name (case-insensitive, any order, extra columns ignored). Every
    column of ``PLANE_COLUMNS`` is required. The normal is checked to be unit length with
    c >= 0; outlines are not part of the table (empty).

    Raises
    ------
    InputError
        Missing file or column, a cell that is not a number (names file, row and column), a
        non-integer id or point count, a duplicate id, a normal that is not unit length, a
        negative rms or sigma_d, fewer than 3 points, or a covariance that is not positive
        semi-definite.
    """
    if _header_only(path):
        return []
    table = read_table(path)
    cols = {
        name: float_column(table, find_column(table, (name,), what=name)) for name in PLANE_COLUMNS
    }
    id_col = find_column(table, ("id",))
    np_col = find_column(table, ("n_points",))
    planes = []
    seen: dict[Hashable, int] = {}
    check_integers(table, cols["id"], id_col)
    check_integers(table, cols["n_points"], np_col)
    for k, row_no in enumerate(table.line_numbers):
        pid = int(cols["id"][k])
        note_unique(seen, pid, f"id {pid}", table, row_no, id_col)
        normal = np.array([cols["a"][k], cols["b"][k], cols["c"][k]])
        if abs(np.linalg.norm(normal) - 1.0) > 1e-6 or normal[2] < 0:
            raise InputError(
                "the normal (a, b, c) must be a unit vector with c >= 0",
                path=table.path,
                row=row_no,
                column="a",
            )
        for name in ("rms", "sigma_d"):
            if not cols[name][k] >= 0:
                raise InputError(
                    f"{name} must be >= 0, got {cols[name][k]:g}",
                    path=table.path,
                    row=row_no,
                    column=name,
                )
        if cols["n_points"][k] < 3:
            raise InputError(
                "a plane needs at least 3 points", path=table.path, row=row_no, column="n_points"
            )
        cov = np.empty((4, 4))
        cov[_IU] = [cols[name][k] for name in COV_COLUMNS]
        cov.T[_IU] = cov[_IU]
        check_covariance(cov, table, k, "covariance of (a, b, c, d)")
        planes.append(
            Plane(
                id=pid,
                normal=normal,
                d=float(cols["d"][k]),
                centroid=np.array([cols[f"centroid_{a}"][k] for a in "xyz"]),
                n_points=int(cols["n_points"][k]),
                rms=float(cols["rms"][k]),
                sigma_d=float(cols["sigma_d"][k]),
                covariance=cov,
                slope_deg=float(cols["slope_deg"][k]),
                aspect_deg=float(cols["aspect_deg"][k]),
            )
        )
    return planes
