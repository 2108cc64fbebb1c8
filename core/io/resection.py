"""Files of the space resection: control points, 3D control lines, the exterior orientation
with its precision and the residual table.

Control points (CSV, one row per point; lengths in the CRS unit)::

    point_id,X,Y,Z,sx,sy,sz

``sx, sy, sz``: standard deviations of the coordinates (optional, empty or 0: errorless). The
LCP table of ``createlcps`` (``id,X,Y,Z,...,cov_xx..cov_zz``) is read too, with its full
covariance.

Control lines (CSV, one row per 3D line), any of:

- the line table of ``createlcps`` (``id,...,x1..z2,...,x0..uz,...,cov_00..cov_55``): its end
  points, with the covariance of (X0, u) propagated to them;
- a 3D segment table ``id,x1,y1,z1,x2,y2,z2[,sigma_start,sigma_end]``;
- the line table of ``monoplot`` (``target_id,...,sigma_start,sigma_end,wkt`` with a
  ``LINESTRING Z``): its first and last vertex; rows without geometry are skipped.

``sigma_start``, ``sigma_end``: the 3D standard deviation of each end point (the square root
of the trace of its covariance, metres, as ``monoplot`` writes it), taken as isotropic.
Line ids must be unique (``target_id`` for the monoplot table).

Exterior orientation with precision (the EO CSV of :mod:`.orientation` with more columns; every
reader of the EO CSV reads it)::

    image_id,time,group,X,Y,Z,omega_deg,phi_deg,kappa_deg,sigma_X,sigma_Y,sigma_Z,
    sigma_omega_deg,sigma_phi_deg,sigma_kappa_deg,sigma0,redundancy,chi2,chi2_critical,
    chi2_passed,points,lines,rejected,model,start

sigmas a posteriori (metres, degrees); ``chi2`` the global test statistic
``v'Pv / sigma0_prior^2``, ``chi2_critical`` its one-sided critical value at the 5 % level,
``chi2_passed`` 1 when ``chi2 <= chi2_critical``; ``points``, ``lines`` the control points and
lines used, ``rejected`` those rejected by data snooping; ``start`` how the start pose was
found.

Residuals (one row per measured pixel: a control point, a check point or a point measured on
a line)::

    image_id,point_id,type,target_id,vertex,col,row,vx_px,vy_px,distance_px,w,rejected,used

``vx_px, vy_px``: adjusted minus measured pixel (points; points on lines with the
coplanarity model), for check points the projection with the resected orientation minus the
measurement; ``distance_px`` the length of that vector for points, and for a point on a line
its signed distance from the 3D line projected with the resected orientation; ``w`` the
largest |Baarda w| of the point or line; ``rejected`` 1 when data snooping rejected it;
``used`` 0 for check points.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Hashable, Iterable, Sequence
from typing import Any, Union

import numpy as np

from ..errors import InputError
from ..photo.resection_map import LineControl, PointControl, line_control_from_lines
from .control import LCP_COV, read_lines_csv
from .orientation import EO_COLUMNS, EO_SIGMA_COLUMNS
from .tables import (
    check_covariance,
    find_column,
    float_column,
    normalise,
    note_unique,
    number,
    read_table,
    sigma_column,
    text_column,
    unique_ids,
    write_csv_atomic,
)

PathLike = Union[str, "os.PathLike[str]"]

#: The resection's EO table: the EO columns, their standard deviations and the fit's figures.
RESECTION_EO_COLUMNS = (
    *EO_COLUMNS,
    *EO_SIGMA_COLUMNS,
    "sigma0",
    "redundancy",
    "chi2",
    "chi2_critical",
    "chi2_passed",
    "points",
    "lines",
    "rejected",
    "model",
    "start",
)
RESIDUAL_COLUMNS = (
    "image_id",
    "point_id",
    "type",
    "target_id",
    "vertex",
    "col",
    "row",
    "vx_px",
    "vy_px",
    "distance_px",
    "w",
    "rejected",
    "used",
)
_IU3 = np.triu_indices(3)
_WKT = re.compile(r"^\s*LINESTRING\s*Z?\s*\((.*)\)\s*$", re.IGNORECASE)


def read_point_control_csv(path: PathLike) -> PointControl:
    """Read control points (module docstring).

    Raises
    ------
    InputError
        A missing column, a value that is not a finite number, a negative sigma, a repeated
        id, a covariance that is not positive semi-definite; naming file, row and column.
    """
    table = read_table(path)
    names = [normalise(c) for c in table.columns]
    ids = unique_ids(table, find_column(table, ("point_id", "id", "name", "point")))
    xyz = np.column_stack(
        [
            float_column(table, find_column(table, aliases))
            for aliases in (("x", "easting"), ("y", "northing"), ("z", "h", "height"))
        ]
    )
    n = len(ids)
    cov = np.zeros((n, 3, 3))
    if all(c in names for c in LCP_COV):
        vals = [float_column(table, names.index(c)) for c in LCP_COV]
        for k in range(n):
            c = np.zeros((3, 3))
            c[_IU3] = [v[k] for v in vals]
            c = c + np.triu(c, 1).T
            check_covariance(c, table, k, "covariance of (X, Y, Z)")
            cov[k] = c
        return PointControl(ids, xyz, cov)
    for axis, aliases in enumerate(
        (("sx", "sigma_x", "std_x"), ("sy", "sigma_y", "std_y"), ("sz", "sigma_z", "std_z"))
    ):
        s = sigma_column(table, aliases)
        if s is not None:
            cov[:, axis, axis] = s**2
    return PointControl(ids, xyz, cov)


def read_line_control_csv(path: PathLike) -> LineControl:
    """Read 3D control lines in any of the forms of the module docstring.

    Raises
    ------
    InputError
        Missing columns, values that are not finite numbers, a repeated id, a line of zero
        length, a negative sigma, a geometry that is not a ``LINESTRING Z``; naming file, row
        and column.
    """
    table = read_table(path)
    names = [normalise(c) for c in table.columns]
    if "cov_00" in names and "ux" in names:
        return line_control_from_lines(read_lines_csv(os.fspath(path)))
    if "wkt" in names:
        id_col = find_column(table, ("target_id", "line_id", "id"))
        wkt = text_column(table, names.index("wkt"), nonempty=False)
        keep, ends = [], []
        for k, (text, row) in enumerate(zip(wkt, table.line_numbers)):
            if not text.strip():
                continue  # a monoplotted line without geometry (its rays missed the DSM)
            ends.append(_wkt_ends(text, table.path, row))
            keep.append(k)
        ids_all = text_column(table, id_col)
        rows = [table.line_numbers[k] for k in keep]
        ids = _unique([ids_all[k] for k in keep], rows, table, id_col)
        e = np.array(ends, dtype=np.float64).reshape(-1, 2, 3)
        p1, p2 = e[:, 0], e[:, 1]
    else:
        id_col = find_column(table, ("id", "line_id", "target_id"))
        rows = list(table.line_numbers)
        keep = list(range(len(table)))
        ids = _unique(text_column(table, id_col), rows, table, id_col)
        p1, p2 = (
            np.column_stack([float_column(table, find_column(table, (f"{a}{i}",))) for a in "xyz"])
            for i in (1, 2)
        )
    sig = []
    for aliases in (("sigma_start", "sigma_1", "sigma1"), ("sigma_end", "sigma_2", "sigma2")):
        s = sigma_column(table, aliases)
        sig.append(np.zeros(len(keep)) if s is None else s[keep])
    length = np.linalg.norm(p2 - p1, axis=1)
    short = np.flatnonzero(~(length > 1e-3))
    if short.size:
        raise InputError(
            f"line '{ids[short[0]]}' has zero length ({length[short[0]]:.3g}): its "
            "two end points coincide",
            path=table.path,
            row=rows[short[0]],
        )
    cov = np.zeros((len(ids), 6, 6))
    eye = np.eye(3)
    cov[:, :3, :3] = (sig[0] ** 2 / 3.0)[:, None, None] * eye
    cov[:, 3:, 3:] = (sig[1] ** 2 / 3.0)[:, None, None] * eye
    return LineControl(tuple(ids), p1, p2, cov)


def _unique(ids: Sequence[str], rows: Sequence[int], table, col: int) -> tuple[str, ...]:
    first: dict[Hashable, int] = {}
    for value, line_no in zip(ids, rows):
        if not value:
            raise InputError("empty id", path=table.path, row=line_no, column=table.columns[col])
        note_unique(first, value, f"line id '{value}'", table, line_no, col)
    return tuple(ids)


def _wkt_ends(text: str, path: str, row: int) -> tuple[list[float], list[float]]:
    m = _WKT.match(text)
    bad = InputError(
        "the geometry is not a LINESTRING Z of two or more 3D vertices",
        path=path,
        row=row,
        column="wkt",
    )
    if not m:
        raise bad
    try:
        vertices = [[float(v) for v in p.split()] for p in m.group(1).split(",")]
    except ValueError:
        raise bad from None
    if len(vertices) < 2 or any(len(v) != 3 for v in vertices):
        raise bad
    if not all(math.isfinite(c) for v in vertices for c in v):
        raise bad
    return vertices[0], vertices[-1]


def write_eo_sigma_csv(path: PathLike, rows: Iterable[Sequence[Any]]) -> None:
    """Write the EO table with precision; ``rows`` hold the values of
    :data:`RESECTION_EO_COLUMNS` (angles in radians, converted here), in that order."""
    out = []
    for r in rows:
        (
            image,
            time,
            group,
            x,
            y,
            z,
            w,
            p,
            k,
            sx,
            sy,
            sz,
            sw,
            sp,
            sk,
            s0,
            red,
            chi2,
            crit,
            passed,
            npt,
            nln,
            rej,
            model,
            start,
        ) = r
        out.append(
            (
                image,
                number(time),
                group,
                number(x),
                number(y),
                number(z),
                *(number(math.degrees(a)) for a in (w, p, k)),
                *(number(s) for s in (sx, sy, sz)),
                *(number(math.degrees(s)) for s in (sw, sp, sk)),
                number(s0),
                int(red),
                number(chi2),
                number(crit),
                int(bool(passed)),
                int(npt),
                int(nln),
                int(rej),
                model,
                start,
            )
        )
    write_csv_atomic(path, RESECTION_EO_COLUMNS, out)


def write_residuals_csv(path: PathLike, rows: Iterable[Sequence[Any]]) -> None:
    """Write the residual table; ``rows`` hold the values of :data:`RESIDUAL_COLUMNS`."""
    out = []
    for r in rows:
        image, point, kind, target, vertex, col, row, vx, vy, dist, w, rej, used = r
        out.append(
            (
                image,
                point,
                kind,
                target,
                int(vertex),
                number(col),
                number(row),
                number(vx),
                number(vy),
                number(dist),
                number(w),
                int(bool(rej)),
                int(bool(used)),
            )
        )
    write_csv_atomic(path, RESIDUAL_COLUMNS, out)
