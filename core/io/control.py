"""CSV tables of LiDAR control: control points (LCPs), control lines and the plane graph.

LCP table, one row per point (lengths in the CRS unit of the cloud, angles in degrees)::

    id,X,Y,Z,sigma_x,sigma_y,sigma_z,cov_xx,cov_xy,cov_xz,cov_yy,cov_yz,cov_zz,
    ellipsoid_a,ellipsoid_b,ellipsoid_c,plane_1,plane_2,plane_3,min_angle_deg,condition

ellipsoid_a >= b >= c are the 1-sigma semi-axes of the error ellipsoid.

Line table, one row per line (start/end clipped to the common support of the two planes;
X0 the line point nearest the centre of their contact; u the unit direction; the covariance is
that of (X0, u), 21 upper-triangle elements in the order x0 y0 z0 ux uy uz)::

    id,plane_1,plane_2,kind,x1,y1,z1,x2,y2,z2,length,x0,y0,z0,ux,uy,uz,
    sigma_perpendicular,sigma_start,sigma_end,dihedral_deg,cov_00,cov_01,...,cov_55

sigma_perpendicular, sigma_start, sigma_end: RMS standard deviation across the line at X0 and
at the two end points (it grows away from X0 with the uncertainty of the direction).

Plane graph, one row per pair of planes whose points touch::

    plane_1,plane_2,adjacent,boundary_length,contact_points,contact_x,contact_y,contact_z
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Union

import numpy as np

from ..errors import InputError
from ..lidar.control import (
    LINE_KINDS,
    LINE_PARAMETERS,
    Adjacency,
    ControlLine,
    ControlPoint,
    error_ellipsoid,
)
from .tables import (
    check_covariance,
    find_column,
    float_column,
    number,
    read_table,
    text_column,
    unique_integer_ids,
    write_csv_atomic,
)

_IU3 = np.triu_indices(3)
_IU6 = np.triu_indices(6)
LCP_COV = tuple(f"cov_{'xyz'[i]}{'xyz'[j]}" for i, j in zip(*_IU3))
#: A 3D point (mapping CRS) and its standard deviations (CRS units), in the point tables.
XYZ_SIGMA_COLUMNS = ("X", "Y", "Z", "sigma_x", "sigma_y", "sigma_z")
LCP_COLUMNS = (
    "id",
    *XYZ_SIGMA_COLUMNS,
    *LCP_COV,
    "ellipsoid_a",
    "ellipsoid_b",
    "ellipsoid_c",
    "plane_1",
    "plane_2",
    "plane_3",
    "min_angle_deg",
    "condition",
)
LINE_COV = tuple(f"cov_{i}{j}" for i, j in zip(*_IU6))
LINE_COLUMNS = (
    "id",
    "plane_1",
    "plane_2",
    "kind",
    "x1",
    "y1",
    "z1",
    "x2",
    "y2",
    "z2",
    "length",
    *LINE_PARAMETERS,
    "sigma_perpendicular",
    "sigma_start",
    "sigma_end",
    "dihedral_deg",
    *LINE_COV,
)
GRAPH_COLUMNS = (
    "plane_1",
    "plane_2",
    "adjacent",
    "boundary_length",
    "contact_points",
    "contact_x",
    "contact_y",
    "contact_z",
)

PathLike = Union[str, Path]


def write_lcps_csv(path: PathLike, points: Sequence[ControlPoint]) -> None:
    rows = []
    for p in points:
        axes, _ = error_ellipsoid(p.covariance)
        rows.append(
            [
                p.id,
                *map(number, p.xyz),
                *map(number, p.sigma),
                *map(number, p.covariance[_IU3]),
                *map(number, axes),
                *p.plane_ids,
                number(p.min_angle_deg),
                number(p.condition),
            ]
        )
    write_csv_atomic(path, LCP_COLUMNS, rows)


def read_lcps_csv(path: PathLike) -> list[ControlPoint]:
    """Read an LCP table; errors name the file, row and column (an id that is not a unique
    integer, a covariance that is not positive semi-definite)."""
    table = read_table(path)
    col = {name: find_column(table, (name.lower(),)) for name in LCP_COLUMNS}
    num = {name: float_column(table, col[name]) for name in LCP_COLUMNS}
    ids = unique_integer_ids(table, num["id"], col["id"])
    out = []
    for k, _row in enumerate(table.line_numbers):
        cov = np.zeros((3, 3))
        cov[_IU3] = [num[c][k] for c in LCP_COV]
        cov = cov + np.triu(cov, 1).T
        check_covariance(cov, table, k, "covariance of (X, Y, Z)")
        out.append(
            ControlPoint(
                id=ids[k],
                xyz=np.array([num["X"][k], num["Y"][k], num["Z"][k]]),
                covariance=cov,
                plane_ids=(int(num["plane_1"][k]), int(num["plane_2"][k]), int(num["plane_3"][k])),
                min_angle_deg=float(num["min_angle_deg"][k]),
                condition=float(num["condition"][k]),
                support_distance=np.full(3, np.nan),
            )
        )
    return out


def write_lines_csv(path: PathLike, lines: Sequence[ControlLine]) -> None:
    rows = [
        [
            ln.id,
            *ln.plane_ids,
            ln.kind,
            *map(number, ln.start),
            *map(number, ln.end),
            number(ln.length),
            *map(number, ln.point),
            *map(number, ln.direction),
            number(ln.sigma_perpendicular),
            *map(number, ln.sigma_ends),
            number(ln.dihedral_deg),
            *map(number, ln.covariance[_IU6]),
        ]
        for ln in lines
    ]
    write_csv_atomic(path, LINE_COLUMNS, rows)


def read_lines_csv(path: PathLike) -> list[ControlLine]:
    """Read a line table; errors name the file, row and column (an id that is not a unique
    integer, an unknown kind, a direction that is not a unit vector, a covariance that is not
    positive semi-definite)."""
    table = read_table(path)
    numeric = [c for c in LINE_COLUMNS if c != "kind"]
    num = {name: float_column(table, find_column(table, (name.lower(),))) for name in numeric}
    kinds = text_column(table, find_column(table, ("kind",)))
    ids = unique_integer_ids(table, num["id"], find_column(table, ("id",)))
    out = []
    for k, row in enumerate(table.line_numbers):
        if kinds[k] not in LINE_KINDS:
            raise InputError(
                f"kind '{kinds[k]}' is not one of {', '.join(LINE_KINDS)}",
                path=table.path,
                row=row,
                column="kind",
            )
        cov = np.zeros((6, 6))
        cov[_IU6] = [num[c][k] for c in LINE_COV]
        cov = cov + np.triu(cov, 1).T
        check_covariance(cov, table, k, "covariance of (X0, u)")
        u = np.array([num["ux"][k], num["uy"][k], num["uz"][k]])
        if abs(np.linalg.norm(u) - 1.0) > 1e-6:
            raise InputError(
                "direction (ux, uy, uz) is not a unit vector", path=table.path, row=row
            )
        out.append(
            ControlLine(
                id=ids[k],
                plane_ids=(int(num["plane_1"][k]), int(num["plane_2"][k])),
                kind=kinds[k],
                start=np.array([num["x1"][k], num["y1"][k], num["z1"][k]]),
                end=np.array([num["x2"][k], num["y2"][k], num["z2"][k]]),
                point=np.array([num["x0"][k], num["y0"][k], num["z0"][k]]),
                direction=u,
                covariance=cov,
                dihedral_deg=float(num["dihedral_deg"][k]),
            )
        )
    return out


def write_graph_csv(path: PathLike, adjacency: Adjacency) -> None:
    rows = [
        [int(a), int(b), int(adj), number(length), int(count), *map(number, centre)]
        for (a, b), adj, length, count, centre in zip(
            adjacency.pairs.tolist(),
            adjacency.adjacent,
            adjacency.boundary_length,
            adjacency.contact_count,
            adjacency.contact_centre,
        )
    ]
    write_csv_atomic(path, GRAPH_COLUMNS, rows)
