"""``lidaraccuracy``: a LiDAR survey's swath-to-swath, within-swath and absolute vertical
accuracy (ASPRS Positional Accuracy Standards, Ed. 2, 2023)."""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import InputError
from .checks import check_memory
from .common import CSV_FILTER, cluster_params, enum_param, html_out, json_out, table_param
from .runner import JobResult, stages
from .spec import AlgorithmSpec, Fields, Param, Result, Values, options_from

log = logging.getLogger(__name__)

_D = Fields("quality.lidar_accuracy_options", "LidarAccuracyOptions")
_LAS_SUFFIXES = (".las", ".laz")
#: Memory per return: the arrays read (36 B) and the cell fit's sorted copies, offsets,
#: products and residuals (about 20 float64 arrays); rounded up.
BYTES_PER_RETURN = 200
#: (parameter, LidarAccuracyOptions field, label, kind, unit, minimum, maximum, advanced)
_NUMBERS = (
    (
        "CELL_SIZE",
        "cell_size",
        "Cell size (about 2 x point spacing or more)",
        "number",
        "m",
        0.01,
        1000.0,
        False,
    ),
    (
        "MIN_POINTS",
        "min_points",
        "Least returns of one swath in a cell",
        "integer",
        "",
        4,
        100000,
        True,
    ),
    (
        "MAX_SLOPE",
        "max_slope_deg",
        "Largest slope of a smooth cell",
        "number",
        "degrees",
        0.0,
        89.0,
        True,
    ),
    (
        "MAX_RESIDUAL",
        "max_residual",
        "Largest plane-fit rms of a smooth cell",
        "number",
        "m",
        0.0,
        100.0,
        True,
    ),
    (
        "MAX_STEP",
        "max_step",
        "Largest step to a neighbour cell's plane",
        "number",
        "m",
        0.0,
        1000.0,
        True,
    ),
    ("GPS_GAP", "gps_gap_s", "GPS-time gap that starts a new swath", "number", "s", 0.0, 1e9, True),
    (
        "MIN_PAIR_CELLS",
        "min_pair_cells",
        "Least smooth cells of an assessed swath pair",
        "integer",
        "",
        1,
        1e9,
        True,
    ),
    (
        "V_CLASS_CM",
        "v_class_cm",
        "ASPRS vertical class (0 = report the class met)",
        "number",
        "cm",
        0.0,
        10000.0,
        False,
    ),
    (
        "SURVEY_SIGMA_V",
        "survey_sigma_v",
        "Check-point survey sigma in height",
        "number",
        "m",
        0.0,
        100.0,
        False,
    ),
    (
        "TIN_RADIUS",
        "tin_radius",
        "Ground returns within this distance make the TIN",
        "number",
        "m",
        0.1,
        10000.0,
        True,
    ),
)

SPEC = AlgorithmSpec(
    name="lidaraccuracy",
    title="LiDAR swath and vertical accuracy (ASPRS 2023)",
    group="Accuracy",
    group_id="accuracy",
    summary="swath overlap difference, within-swath precision and NVA/VVA of a LiDAR survey",
    description="""\
Tells how good a LiDAR survey itself is, under the ASPRS Positional Accuracy Standards,
Edition 2 (2023): relative accuracy between overlapping swaths, within-swath precision and
absolute vertical accuracy at surveyed check points.

## Swaths
From the LAS point source id (flight line) when the cloud holds more than one, else from gaps
in GPS time longer than GPS gap (the report says which).

## Smooth hard cells
On a north-up grid of Cell size (corners on multiples of it), a cell of a swath is smooth
when it holds at least the least returns of that swath, no vegetation class (3-5), only single
returns (and, with Hard classes, only those classes), the least-squares plane through them has
a slope at most Max slope and a residual rms at most Max residual, and the planes of its
neighbour cells continue it within Max step (edges, walls and rough ground fail).

## Figures
Swath overlap difference dz = h_a - h_b (plane heights at the cell centre) per swath pair and
overall: count, mean, RMSDz, max |dz|, surface-normal RMSD, the share beyond 0.8 and 1.6 times
the class, and the tilt of dz across the overlap (a roll error shows as a cross-track slope).
Within-swath precision per swath: pooled plane residual rms and the cells' Max Diff (range).
Check points (CSV id, e, n, h, group = land cover): dz = LiDAR - check, the LiDAR height
interpolated in a TIN of the ground returns (class 2); NVA (non-vegetated): RMSE_V with the
survey sigma, 1.96 RMSE_V for comparison; VVA (groups such as vegetated, forest, brush, crops):
RMSE and the 95th percentile of |dz|, reported only. Verdicts against a vertical class #-cm:
within-swath Max Diff <= 0.6 #, swath RMSDz <= 0.8 #, swath max <= 1.6 #, NVA RMSE_V <= #
with at least 30 check points (docs/formats.md "LiDAR accuracy").

## Outputs
HTML report, JSON of every figure, a GeoTIFF of dz with one band per swath pair, and the check
points with the LiDAR heights as a check-point table (id, e, n, h, e_ref, n_ref, h_ref, group)
that accuracyreport reads for the NSSDA and PEC-PCD sections.""",
    params=(
        Param(
            "INPUT",
            "files",
            "Point clouds (LAS/LAZ files or folders)",
            suffixes=_LAS_SUFFIXES,
            help="LAS/LAZ files of one survey, or folders of them",
        ),
        table_param(
            "CHECKPOINTS",
            "Check points (CSV: id, e, n, h, group)",
            optional=True,
            help="surveyed check points; group = land cover",
        ),
        enum_param(
            "SWATH_SOURCE",
            "Swaths from",
            _D.swath_source,
            "SWATH_SOURCES",
            labels=("point source id, else GPS time", "point source id", "GPS time gaps"),
        ),
        Param(
            "HARD_CLASSES",
            "string",
            "Hard classes only (e.g. 2,6; empty: any but vegetation)",
            "",
            optional=True,
            help="LAS classes of hard surfaces; a cell holding another "
            "class is not compared (class 1 holds cars that move between flights)",
        ),
        *_D.params(_NUMBERS),
        Param(
            "TILE_SIZE",
            "number",
            "Tile size (0 = one process)",
            0.0,
            unit="m",
            minimum=0.0,
            maximum=1e6,
            help="tiles of this side (rounded up to whole cells) on a dask "
            "cluster, as lidarblock; needs point source ids",
            advanced=True,
        ),
        *cluster_params(advanced=True),
        html_out("OUTPUT_HTML", "LiDAR accuracy report (HTML)", optional=False),
        json_out("OUTPUT_JSON", "LiDAR accuracy figures (JSON)", on_demand=True),
        Param(
            "OUTPUT_RASTER",
            "raster_out",
            "Swath overlap dz (GeoTIFF, a band per pair)",
            optional=True,
            create_by_default=False,
        ),
        Param(
            "OUTPUT_CHECKPOINTS",
            "file_out",
            "Check points with LiDAR heights (CSV)",
            optional=True,
            create_by_default=False,
            file_filter=CSV_FILTER,
        ),
    ),
    results=(
        Result("RMSDZ", "number", "Swath-to-swath RMSDz, all pairs (m)"),
        Result("SMOOTH_CELLS", "number", "Smooth cells compared"),
        Result("NVA_RMSE", "number", "NVA RMSE_V (m; NaN without check points)"),
    ),
    tags=("lidar", "swath", "overlap", "accuracy", "asprs", "nva", "vva", "quality"),
    references=("ASPRS (2023)",),
)


def _classes(text: str) -> tuple[int, ...]:
    """LAS classes from "2,6" or "2 6" (empty: none).

    >>> _classes("2, 6")
    (2, 6)
    """
    parts = text.replace(",", " ").replace(";", " ").split()
    try:
        classes = tuple(int(p) for p in parts)
    except ValueError:
        raise InputError(
            f"HARD_CLASSES must be integers separated by commas, got {text!r}"
        ) from None
    if any(not 0 <= c <= 255 for c in classes):
        raise InputError(f"HARD_CLASSES: classes are 0-255, got {text!r}")
    return classes


def _cloud_files(paths) -> list[str]:
    files: list[str] = []
    for p in paths or ():
        path = Path(p)
        if path.is_dir():
            files += sorted(str(f) for f in path.iterdir() if f.suffix.lower() in _LAS_SUFFIXES)
        else:
            files.append(str(path))
    if not files:
        raise InputError("INPUT holds no LAS/LAZ file")
    return files


def _infos(files: list[str]):
    """The files' headers and their CRS (one CRS for the survey)."""
    from ..io.pointcloud import read_info

    infos = [read_info(f, require_crs=False) for f in files]
    crs = None
    for f, info in zip(files, infos):
        if crs is not None and info.crs is not None and not info.crs.equals(crs):
            raise InputError(f"its CRS differs from {files[0]}'s: one survey, one CRS", path=f)
        crs = crs or info.crs
    return infos, crs


def _header_grid(infos, cell: float):
    """The cells covering the files' header boxes (the same for one process and tiles)."""
    import numpy as np

    from ..quality.lidar_swaths import CellGrid

    lo = np.min([i.mins[:2] for i in infos], axis=0)
    hi = np.max([i.maxs[:2] for i in infos], axis=0)
    return CellGrid.covering(np.array([lo[0], hi[0]]), np.array([lo[1], hi[1]]), cell)


def _read(files: list[str], infos, progress, should_stop):
    """Every file's returns with the fields the check uses (those a file lacks: None)."""
    import numpy as np

    from ..io.pointcloud import read_points
    from ..quality.lidar_accuracy import LidarCloud

    parts: dict[str, list] = {}
    optional = ("classification", "number_of_returns", "point_source_id", "gps_time")
    total = sum(i.point_count for i in infos)
    check_memory(
        total * BYTES_PER_RETURN,
        f"INPUT: {total} returns",
        "use TILE_SIZE (tiles on a dask cluster)",
    )
    for k, (f, info) in enumerate(zip(files, infos)):
        fields = ["x", "y", "z"] + [n for n in optional if n in info.dimensions]
        arrays, _ = read_points(f, fields, require_crs=False, should_stop=should_stop)
        for n in ("x", "y", "z", *optional):
            parts.setdefault(n, []).append(arrays.get(n))
        if progress is not None:
            progress((k + 1) / len(files))
    joined = {}
    for n, arrs in parts.items():
        joined[n] = None if any(a is None for a in arrs) else np.concatenate(arrs)
    if joined["gps_time"] is not None and not np.any(joined["gps_time"]):
        joined["gps_time"] = None
    return LidarCloud(source=", ".join(files), **joined)


def _checkpoints(path: str | None):
    if not path:
        return None
    from ..io.checkpoints import read_point_table
    from ..quality.lidar_accuracy import CheckPointSet

    pts = read_point_table(path)
    return CheckPointSet(tuple(pts.ids), pts.xyz, tuple(pts.groups), str(path))


def _write_checkpoint_table(path: str, report) -> None:
    import csv
    import io

    from ..io.atomic import write_text_atomic

    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["id", "e", "n", "h", "e_ref", "n_ref", "h_ref", "group"])
    cp, f = report.checkpoints, report.vertical
    for i, p, g, dz in zip(cp.ids, cp.xyz, cp.groups, f.dz):
        if dz == dz:  # outside the TIN: no LiDAR height
            w.writerow(
                [
                    i,
                    repr(float(p[0])),
                    repr(float(p[1])),
                    repr(float(p[2] + dz)),
                    repr(float(p[0])),
                    repr(float(p[1])),
                    repr(float(p[2])),
                    g,
                ]
            )
    write_text_atomic(path, buf.getvalue())


@dataclass(frozen=True)
class TilePart:
    """What one tile task returns: its cells' fits, its core returns per swath, the motion
    sums of each swath (n, mean t, x, y; sums of dt dt, dt dx, dt dy) and its ground returns
    within TIN_RADIUS of a check point."""

    fits: Any
    swaths: dict[int, int]
    motion: dict[int, tuple[float, ...]]
    ground: Any


_FIELDS = ("x", "y", "z", "classification", "number_of_returns", "point_source_id", "gps_time")


def accuracy_tile(files, boxes, own, grid, options, check_xy) -> TilePart:
    """One dask task: the returns of ``own`` (half-open box on whole cells) and one cell
    around it from the files whose header box meets it; the fits of the cells centred in it."""
    import numpy as np
    from scipy.spatial import cKDTree

    from ..io.pointcloud import read_info, read_points
    from ..quality.lidar_swaths import fit_cells

    pad = grid.cell
    outer = (own[0] - pad, own[1] - pad, own[2] + pad, own[3] + pad)
    parts: dict[str, list] = {k: [] for k in _FIELDS}
    for f, b in zip(files, boxes):
        if b[0] > outer[2] or b[2] < outer[0] or b[1] > outer[3] or b[3] < outer[1]:
            continue
        info = read_info(f, require_crs=False)
        fields = [k for k in _FIELDS if k in ("x", "y", "z") or k in info.dimensions]
        if "point_source_id" not in fields:
            raise InputError(
                "a tiled run needs the point source ids (TILE_SIZE 0 for GPS time)", path=f
            )
        a, _ = read_points(f, fields, require_crs=False)
        m = (a["x"] >= outer[0]) & (a["x"] <= outer[2]) & (a["y"] >= outer[1])
        m &= a["y"] <= outer[3]
        for k in _FIELDS:
            if k in a:
                parts[k].append(a[k][m])
    a = {k: np.concatenate(v) for k, v in parts.items() if v}
    if "x" not in a or a["x"].size == 0:
        return TilePart(None, {}, {}, np.zeros((0, 3)))
    fits = fit_cells(
        a["x"],
        a["y"],
        a["z"],
        a["point_source_id"],
        grid,
        options,
        a.get("classification"),
        a.get("number_of_returns"),
        own,
    )
    core = (a["x"] >= own[0]) & (a["x"] < own[2]) & (a["y"] >= own[1]) & (a["y"] < own[3])
    ids = a["point_source_id"][core].astype(np.int64)
    swaths = {int(s): int(n) for s, n in zip(*np.unique(ids, return_counts=True))}
    motion = {}
    if "gps_time" in a:
        t, x, y = a["gps_time"][core], a["x"][core], a["y"][core]
        for s in swaths:
            k = ids == s
            tc, xc, yc = t[k] - t[k].mean(), x[k] - x[k].mean(), y[k] - y[k].mean()
            means = (float(t[k].mean()), float(x[k].mean()), float(y[k].mean()))
            motion[s] = (float(k.sum()), *means, float(tc @ tc), float(tc @ xc), float(tc @ yc))
    ground = np.zeros((0, 3))
    if check_xy is not None and len(check_xy) and "classification" in a:
        g = core & np.isin(a["classification"], options.ground_classes)
        xyz = np.column_stack([a["x"][g], a["y"][g], a["z"][g]])
        if len(xyz):
            d = cKDTree(check_xy).query(xyz[:, :2], distance_upper_bound=options.tin_radius)[0]
            ground = xyz[np.isfinite(d)]
    return TilePart(fits, swaths, motion, ground)


def _merge_motion(parts) -> dict[int, float]:
    """Each swath's flight direction (rad from grid east) from the tiles' motion sums
    (pairwise-combined centred sums: no loss of digits to the GPS time's size)."""
    import math

    acc: dict[int, list[float]] = {}
    for part in parts:
        for s, (n, mt, mx, my, stt, stx, sty) in part.motion.items():
            if s not in acc:
                acc[s] = [n, mt, mx, my, stt, stx, sty]
                continue
            na, ta, xa, ya, sa_tt, sa_tx, sa_ty = acc[s]
            tot = na + n
            dt, dx, dy = mt - ta, mx - xa, my - ya
            w = na * n / tot
            acc[s] = [
                tot,
                ta + dt * n / tot,
                xa + dx * n / tot,
                ya + dy * n / tot,
                sa_tt + stt + dt * dt * w,
                sa_tx + stx + dt * dx * w,
                sa_ty + sty + dt * dy * w,
            ]
    return {s: math.atan2(v[6], v[5]) for s, v in acc.items() if v[4] > 0 and (v[5] or v[6])}


def _tiles(grid, tile_size: float) -> list[tuple[float, float, float, float]]:
    """Boxes of whole cells covering the grid, about ``tile_size`` on a side."""
    import math

    k = max(1, math.ceil(tile_size / grid.cell))
    side = k * grid.cell
    out = []
    for j in range(math.ceil(grid.rows / k)):
        for i in range(math.ceil(grid.cols / k)):
            x0 = grid.x0 + i * side
            y1 = grid.y_top - j * side
            out.append((x0, y1 - side, x0 + side, y1))
    return out


def _tile_points(own, pad: float, boxes, infos) -> int:
    """Returns of the files whose header box meets the tile and its one-cell margin."""
    return sum(
        i.point_count
        for b, i in zip(boxes, infos)
        if not (
            b[0] > own[2] + pad or b[2] < own[0] - pad or b[1] > own[3] + pad or b[3] < own[1] - pad
        )
    )


def _run_tiled(v: Values, files, infos, grid, options, checkpoints, progress, should_stop):
    """The cells of every tile on a dask cluster (lidarblock's), joined into one report."""
    import os
    import time

    import numpy as np

    from ..quality.lidar_accuracy import report_from_cells
    from ..quality.lidar_swaths import finish_cells
    from .lidar_block import cluster_session, gather

    if options.swath_source == "gps_time":
        raise InputError("SWATH_SOURCE gps_time needs the whole survey at once: TILE_SIZE 0")
    boxes = [
        (float(i.mins[0]), float(i.mins[1]), float(i.maxs[0]), float(i.maxs[1])) for i in infos
    ]
    tiles = _tiles(grid, v.tile_size)
    if not v.cluster:  # a local cluster: every worker holds the files its tile meets
        most = max(_tile_points(own, grid.cell, boxes, infos) for own in tiles)
        workers = min(v.workers or os.cpu_count() or 1, len(tiles))
        check_memory(
            most * BYTES_PER_RETURN * workers,
            f"TILE_SIZE {v.tile_size:g}: {workers} worker(s), up to {most} returns "
            "each (every file a tile meets is decoded whole)",
            "use smaller files (e.g. lidarblock's tiles) or fewer WORKERS",
        )
    check_xy = None if checkpoints is None else checkpoints.xyz[:, :2]
    with cluster_session(v) as client:
        futures = [
            client.submit(
                accuracy_tile,
                files,
                boxes,
                own,
                grid,
                options,
                check_xy,
                pure=False,
                key=f"lidaraccuracy-{k}-{os.getpid()}-{time.time_ns()}",
            )
            for k, own in enumerate(tiles)
        ]
        parts = [
            p
            for p in gather(client, futures, progress, should_stop, 0.0, 0.9)
            if p.fits is not None
        ]
    if not parts:
        raise InputError("the survey has no points in its header's box")
    cells = finish_cells([p.fits for p in parts], grid, options)
    counts: dict[int, int] = {}
    for p in parts:
        for s, n in p.swaths.items():
            counts[s] = counts.get(s, 0) + n
    ground = np.concatenate([p.ground for p in parts]) if checkpoints is not None else None
    counts = dict(sorted(counts.items()))
    return report_from_cells(
        cells,
        grid,
        options,
        "point_source_id",
        counts,
        _merge_motion(parts),
        checkpoints,
        ground,
        ", ".join(files),
    )


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the clouds (and check points), assess them, write the report and rasters."""
    import math

    from ..errors import stop_if_asked
    from ..quality.lidar_accuracy import assess_lidar
    from ..quality.lidar_accuracy_options import LidarAccuracyOptions

    options = options_from(
        LidarAccuracyOptions, SPEC, v, hard_classes=_classes(v.hard_classes or "")
    )
    if v.output_checkpoints and not v.checkpoints:
        raise InputError("OUTPUT_CHECKPOINTS needs the CHECKPOINTS table")
    files = _cloud_files(v.input)
    infos, crs = _infos(files)
    grid = _header_grid(infos, options.cell_size)
    checkpoints = _checkpoints(v.checkpoints)
    if v.tile_size > 0:
        report = _run_tiled(v, files, infos, grid, options, checkpoints, progress, should_stop)
    else:
        read_p, assess_p = stages(progress, 1, 2)
        cloud = _read(files, infos, read_p, should_stop)
        log.info("%d returns from %s", cloud.x.size, cloud.source)
        report = assess_lidar(cloud, options, checkpoints, assess_p, should_stop, grid)
    stop_if_asked(should_stop, "writing the report")
    bands = [f"{p.swath_a}-{p.swath_b}" for p in report.pairs]
    _write_outputs(out, report, bands, crs)
    nva = report.vertical.nva_rmse_v if report.vertical is not None else math.nan
    lines = [f"swaths from {report.swath_method}: {len(report.swath_counts)}"]
    lines += [
        f"swaths {p.swath_a}-{p.swath_b}: {p.n} cells, RMSDz {p.stats()['rmsdz']:.4f} m"
        for p in report.pairs
    ]
    lines += [f"{x.name}: {x.status} ({x.reason})" for x in report.verdicts]
    results = {
        "RMSDZ": report.overall["rmsdz"],
        "SMOOTH_CELLS": report.overall["n"],
        "NVA_RMSE": nva,
    }
    return JobResult(results=results, lines=lines, data=report)


def _write_outputs(out, report, bands: list[str], crs) -> None:
    """The requested outputs: the swath-pair rasters (one band per pair, ``bands`` their
    names), the check point table, the JSON and the HTML report."""
    import json

    from ..io.atomic import write_text_atomic
    from ..io.raster_write import GeoTiffWriter
    from ..quality.lidar_accuracy import report_dict
    from ..quality.lidar_accuracy_html import render_html
    from ..quality.lidar_swaths import pair_rasters

    if out.requested("OUTPUT_RASTER"):
        from ..io.atomic import atomic_path

        g = report.grid
        check_memory(
            4.0 * max(len(bands), 1) * g.rows * g.cols,
            f"OUTPUT_RASTER: {len(bands)} band(s) of {g.cols} x {g.rows} cells",
            "use a larger CELL_SIZE",
        )
        data = pair_rasters(report.pairs, g)
        with atomic_path(out.path("OUTPUT_RASTER")) as tmp:
            with GeoTiffWriter(
                tmp,
                g.cols,
                g.rows,
                data.shape[0],
                data.dtype,
                g.geotransform(),
                crs,
                nodata=float("nan"),
                metadata={"BANDS": ",".join(bands)},
            ) as w:
                w.write(data)
    if out.requested("OUTPUT_CHECKPOINTS") and report.vertical is not None:
        _write_checkpoint_table(out.path("OUTPUT_CHECKPOINTS"), report)
    if out.requested("OUTPUT_JSON"):
        text = json.dumps(report_dict(report, bands), indent=1, allow_nan=False)
        write_text_atomic(out.path("OUTPUT_JSON"), text)
    if out.requested("OUTPUT_HTML"):
        write_text_atomic(out.path("OUTPUT_HTML"), render_html(report))
