"""Monoplotting outputs: the point table (X Y Z, sigmas, covariance, status per ray) and the
line table (one 3D line per image line, WKT)."""

from __future__ import annotations

import os
from typing import Union

import numpy as np

from ..photo.monoplot import STATUS_TEXT, MonoplotResult
from .control import XYZ_SIGMA_COLUMNS
from .tables import number, write_csv_atomic

PathLike = Union[str, "os.PathLike[str]"]


POINT_COLUMNS = (
    "image_id",
    "point_id",
    "type",
    "target_id",
    "line",
    "vertex",
    "col",
    "row",
    *XYZ_SIGMA_COLUMNS,
    "cov_xy",
    "cov_xz",
    "cov_yz",
    "status",
    "status_text",
    "method",
    "incidence_deg",
)
LINE_COLUMNS = (
    "line",
    "image_id",
    "target_id",
    "n_vertices",
    "status",
    "status_text",
    "length",
    "sigma_start",
    "sigma_end",
    "wkt",
)


def write_monoplot_points_csv(path: PathLike, r: MonoplotResult) -> None:
    """The point table: one row per ray (observation point or line vertex), atomically."""
    sig = r.sigmas
    out = []
    for k, (img, pid, kind, tgt, li, vi, how) in enumerate(r.rows):
        c = r.covariance[k]
        out.append(
            (
                img,
                pid,
                kind,
                tgt,
                li,
                vi,
                number(r.pixels[k, 0]),
                number(r.pixels[k, 1]),
                *(number(v) for v in r.points[k]),
                *(number(v) for v in sig[k]),
                *(number(v) for v in (c[0, 1], c[0, 2], c[1, 2])),
                int(r.status[k]),
                STATUS_TEXT[int(r.status[k])],
                how,
                number(r.incidence_deg[k]),
            )
        )
    write_csv_atomic(path, POINT_COLUMNS, out)


def write_monoplot_lines_csv(path: PathLike, r: MonoplotResult) -> None:
    """The line table: one row per 3D line, its vertices as WKT, atomically."""
    out = []
    for li, ln in enumerate(r.lines):
        v = ln.vertices[np.isfinite(ln.vertices).all(axis=1)]
        length = float(np.linalg.norm(np.diff(v, axis=0), axis=1).sum()) if len(v) > 1 else 0.0
        xyz = ", ".join(f"{number(x)} {number(y)} {number(z)}" for x, y, z in v)
        wkt = f"LINESTRING Z ({xyz})"
        out.append(
            (
                li,
                ln.image_id,
                ln.target_id,
                len(ln.vertices),
                ln.status,
                STATUS_TEXT[ln.status],
                number(length),
                number(ln.sigma_ends[0]),
                number(ln.sigma_ends[1]),
                wkt if len(v) > 1 else "",
            )
        )
    write_csv_atomic(path, LINE_COLUMNS, out)
