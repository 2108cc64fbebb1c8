"""``lidarblock``: a whole LiDAR block tile by tile on dask.distributed: ground filter (SMRF)
-> roof planes -> LiDAR control points and lines, with buffers and seamless merges."""

from __future__ import annotations

import contextlib
import logging
import math
import os
import shutil
import signal
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..errors import Cancelled, InputError
from .common import cloud_params, cluster_params, lengths_in_cloud_units
from .lidar_block_tiles import (
    ROOF_SCRATCH,
    BlockSettings,
    TileOutcome,
    _scratch_fetch,
    control_tile,
    process_tile,
)
from .runner import JobResult
from .spec import AlgorithmSpec, Fields, Param, Result, Values, options_from

log = logging.getLogger(__name__)

_S = Fields("lidar.ground_filter_params", "SmrfParams")
_R = Fields("lidar.roof_plane_params", "RoofPlaneParams")
_C = Fields("lidar.control_options", "ControlOptions")
#: Exit status of the command line when the block is incomplete (a tile failed).
INCOMPLETE_EXIT = 3
#: The command line shows a progress bar for this job.
CLI_PROGRESS = True
REPORT_NAME = "block_report.json"
#: Most tiles one block may have (each is a task carrying the block's index; a small
#: TILE_SIZE over a large file would give millions).
MAX_TILES = 20000
#: Memory of one worker besides its tile: Python, numpy, dask, laspy and the compiled
#: kernels loaded (a process worker: 200 MB idle, 285.6 MB peak on the 35 231-point AHN3 tile
#: by the block report's peak_rss_mb; rounded).
WORKER_BASE_BYTES = 280e6
#: Bytes per point of a tile and its buffer besides the ground filter's (x, y, z, ids and
#: flags as arrays; the LAS records are counted apart).
TILE_BYTES_PER_POINT = 48

# fmt: off
SPEC = AlgorithmSpec(
    name="lidarblock",
    title="LiDAR block: ground, roof planes and control, tile by tile (dask)",
    group="Blocks",
    group_id="blocks",
    summary="a whole LiDAR block tile by tile on dask.distributed: ground filter, roof planes, "
            "LiDAR control points and lines",
    description="""\
Runs the ground filter (SMRF, Pingel et al. 2013), the roof planes and the LiDAR control of
a whole block, one dask task per tile, on a local dask.distributed cluster (one worker per
core by default) or on an existing cluster (CLUSTER: its scheduler address, e.g.
tcp://10.0.0.5:8786; every worker must have lidarphoto and read the input paths).

Input: a folder of LAS/LAZ tiles, a virtual point cloud (.vpc, as made by PDAL or QGIS), or
one large LAS/LAZ file cut into square tiles of TILE_SIZE read in chunks. A COPC file (Cloud
Optimized Point Cloud) is read by octree node instead: each tile decompresses only the nodes
around its cell and buffer, where a plain LAZ is streamed whole by every tile. Tiles in
different CRSs are refused. Neighbours are found from the headers' bounding boxes.

Buffers: each tile is filtered with the points of its neighbours within 2 x SMRF_WINDOW +
LOW_OUTLIER_RADIUS + 3 cells of its box, so its classes are those of a run on the whole cloud
(except a few points next to buildings within millimetres of the height tolerance: the DTM
filled under objects depends on the tile's grid corner; 9 of 75 256 points in the tests); only
the tile's own points are written. Roof planes are extracted on the tile plus three times
the reach of a point's label (its K_NEIGHBOURS patch and four rings of region-growing
neighbours); planes cut by a tile border are merged when both tiles' region growing put the
same points of the band along the border into them (never two planes one tile kept apart)
and refitted with their covariance, so the block has the planes of a single run; control
points and lines found by several tiles are kept once.

A tile that cannot be read is reported by name and skipped; the rest finishes and the block
is marked incomplete (report "complete": false, result COMPLETE 0, command-line exit
status 3).

## Outputs
OUTPUT_FOLDER (must be new, empty, or a previous block output) receives, all at once when
the block is done: tiles/<tile>.laz (each tile's own points, class 2 ground, 7 low outliers,
other classes kept), block.vpc (the tiles as a virtual point cloud), planes.csv, lcps.csv,
lines.csv (the formats of Extract roof planes and Create LCPs) and block_report.json (per
tile: points, ground, seconds, peak memory, errors). Lengths are in the CRS unit unless
DISTANCE_UNIT is metres.""",
    params=(
        Param("INPUT", "file", "Block: folder of LAS/LAZ tiles, .vpc or one LAS/LAZ file",
              file_filter="LAS/LAZ or virtual point cloud (*.las *.laz *.vpc)",
              help="a folder path is accepted too (its *.las/*.laz); COPC files are read by "
              "octree node"),
        *cloud_params("INPUT")[1:],
        Param("TILE_SIZE", "number", "Tile size (one large file)", 500.0, unit="length",
              minimum=1.0, maximum=1e6, help="side of the square tiles one file is cut into"),
        Param("SMRF_CELL_SIZE", "number", "SMRF cell size", _S.cell_size, unit="length",
              minimum=0.01, maximum=1000.0),
        Param("SMRF_SLOPE", "number", "SMRF terrain slope", _S.slope, unit="rise/run",
              minimum=0.001, maximum=10.0),
        Param("SMRF_WINDOW", "number", "SMRF largest window radius", _S.max_window,
              unit="length", minimum=0.01, maximum=10000.0, advanced=True),
        Param("SMRF_THRESHOLD", "number", "SMRF final height tolerance", _S.threshold,
              unit="length", minimum=0.0, maximum=1000.0, advanced=True),
        Param("SMRF_SCALAR", "number", "SMRF tolerance added per unit of slope", _S.scalar,
              unit="length", minimum=0.0, maximum=1000.0, advanced=True),
        Param("LOW_OUTLIER_RADIUS", "number", "Low outlier radius", _S.low_outlier_radius,
              unit="length", minimum=0.0, maximum=10000.0, advanced=True),
        Param("EPSILON", "number", "Roof planes: point-to-plane tolerance", _R.epsilon,
              unit="length", minimum=0.001, maximum=100.0),
        Param("K_NEIGHBOURS", "integer", "Roof planes: neighbours of the local RANSAC",
              _R.k_neighbours, minimum=6, maximum=200, advanced=True),
        Param("MIN_PLANE_POINTS", "integer", "Roof planes: smallest plane (points)",
              _R.min_plane_points, minimum=3, maximum=1000000, advanced=True),
        Param("DELTA", "number", "Control: adjacency distance delta", _C.delta,
              unit="length", minimum=0.001, maximum=1000.0),
        Param("MIN_BOUNDARY", "number", "Control: minimum common boundary", _C.min_boundary,
              unit="length", minimum=0.0, maximum=10000.0, advanced=True),
        *cluster_params(),
        Param("OUTPUT_FOLDER", "folder_out", "Output folder (tiles, VPC, tables, report)"),
    ),
    results=(
        Result("TILE_COUNT", "number", "Tiles processed"),
        Result("FAILED_TILES", "number", "Tiles that failed"),
        Result("COMPLETE", "number", "1 when every tile was processed, else 0"),
        Result("POINT_COUNT", "number", "Points written"),
        Result("GROUND_COUNT", "number", "Ground points"),
        Result("PLANE_COUNT", "number", "Roof planes"),
        Result("LCP_COUNT", "number", "LiDAR control points"),
        Result("LINE_COUNT", "number", "LiDAR control lines"),
    ),
    tags=("block", "tiles", "dask", "vpc", "ground", "smrf", "roof planes", "lcp", "laz"),
    references=("Pingel et al. (2013)", "Rocklin (2015)"),
)
# fmt: on

_H = ("cell_size", "max_window", "threshold", "scalar", "low_outlier_radius", "low_outlier_height")


# ----------------------------------------------------------------------------- the cluster
#: Signals that stop a run (the command line raises on SIGTERM and SIGHUP; SIGINT is Ctrl+C).
_STOP_SIGNALS = {getattr(signal, n) for n in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, n)}


def _process_workers(v: Values) -> bool:
    """A local cluster of processes (else threads of this process)."""
    # inside QGIS (or qgis_process) a worker process would be started with QGIS's own
    # executable: threads there
    return v.local_cluster == "processes" or (
        v.local_cluster == "auto" and "qgis.core" not in sys.modules
    )


def open_client(v: Values):
    """A dask client: on CLUSTER's scheduler, or on a new LocalCluster (closed with it)."""
    from distributed import Client, LocalCluster

    # the scheduler's and workers' own INFO lines would drown the job's log
    logging.getLogger("distributed").setLevel(logging.WARNING)
    if v.cluster:
        try:
            return Client(v.cluster, timeout="20s"), None
        except (OSError, TimeoutError) as exc:
            raise InputError(
                f"CLUSTER: cannot reach the dask scheduler {v.cluster}: {exc}"
            ) from exc
    n = v.workers or os.cpu_count() or 1
    memory = f"{v.memory_limit}GB" if v.memory_limit > 0 else "auto"
    processes = _process_workers(v)
    made: list[Any] = []

    def start() -> None:
        # the cluster's threads (its event loop, the workers' watchers) inherit this mask:
        # a stop signal then reaches the main thread, which waits below and raises at once
        # (one delivered to another thread would leave it asleep until the start is done)
        if hasattr(signal, "pthread_sigmask"):
            signal.pthread_sigmask(signal.SIG_BLOCK, _STOP_SIGNALS)
        try:
            cluster = LocalCluster(
                n_workers=n,
                threads_per_worker=1,
                memory_limit=memory,
                processes=processes,
                dashboard_address=None,
                silence_logs=logging.ERROR,
            )
            made.append((Client(cluster), cluster))
        except Exception as exc:
            made.append(exc)

    import threading

    starter = threading.Thread(target=start, name="lidarblock cluster start", daemon=True)
    starter.start()
    while starter.is_alive():
        starter.join(0.1)
    if isinstance(made[0], Exception):
        raise made[0]
    return made[0]


def gather(client, futures, progress, should_stop, lo: float, hi: float) -> list[Any]:
    """Wait for ``futures`` (their results in order), reporting progress in [lo, hi]; a stop
    request cancels every task still on the cluster and raises Cancelled."""
    from distributed import wait

    pending = set(futures)
    n = max(len(futures), 1)
    while pending:
        if should_stop is not None and should_stop():
            client.cancel(list(pending), force=True)
            raise Cancelled("stopped: the block's remaining tasks were cancelled")
        try:
            _, pending = wait(pending, timeout=0.5, return_when="FIRST_COMPLETED")
        except TimeoutError:  # nothing finished in this half second
            pass
        if progress is not None:
            progress(lo + (hi - lo) * (len(futures) - len(pending)) / n)
    return client.gather(futures)


def run_block(
    index,
    settings: BlockSettings,
    staging: str,
    client,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
    task: Callable[..., TileOutcome] = process_tile,
) -> dict[str, Any]:
    """Process every tile of ``index`` on ``client`` into ``staging``; merge the planes, build
    the control; the block's results (what run() writes and reports)."""
    import numpy as np

    from ..lidar.block import dedupe_lines, dedupe_points, merge_cut_planes
    from ..lidar.block_cut import second_pass

    os.makedirs(os.path.join(staging, "tiles"), exist_ok=True)
    os.makedirs(os.path.join(staging, ROOF_SCRATCH), exist_ok=True)
    t0 = time.perf_counter()
    # the index travels with each task (a few hundred bytes per tile): nothing is lost
    # with a worker
    futures = [
        client.submit(
            task,
            index,
            i,
            settings,
            staging,
            pure=False,
            key=f"lidarblock-tile-{i}-{os.getpid()}-{time.time_ns()}",
        )
        for i in range(len(index.tiles))
    ]
    outcomes: list[TileOutcome] = gather(client, futures, progress, should_stop, 0.0, 0.85)
    t_tiles = time.perf_counter() - t0
    pieces, bands = [], []
    for o in outcomes:
        if o.ok and o.band is not None:
            bands.append(o.band.shifted(len(pieces)))
        pieces += o.pieces if o.ok else []
    merged = merge_cut_planes(pieces, bands)
    t1 = time.perf_counter()

    def on_cluster(f: Callable[..., Any], args: list[tuple[Any, ...]]) -> list[Any]:
        # one task a window: its points are read and its planes found on a worker
        return gather(
            client, [client.submit(f, *a, pure=False) for a in args], None, should_stop, 0.85, 0.85
        )

    merged = second_pass(
        merged,
        pieces,
        settings.roof_buffer,
        settings.roof,
        _scratch_fetch(os.path.join(staging, ROOF_SCRATCH)),
        on_cluster,
    )
    t_second = time.perf_counter() - t1
    shutil.rmtree(os.path.join(staging, ROOF_SCRATCH), ignore_errors=True)
    planes = [m.plane for m in merged]
    # control around each tile: planes whose points come within the control reach of it
    reach = settings.control.delta + settings.control.max_support_distance
    lo = np.array([m.points[:, :2].min(axis=0) for m in merged]).reshape(-1, 2)
    hi = np.array([m.points[:, :2].max(axis=0) for m in merged]).reshape(-1, 2)
    ctrl = []
    for k, tile in enumerate(index.tiles):
        if not outcomes[k].ok:
            continue
        box = tile.cell or tile.box
        if tile.cell is None:  # a file tile: the half-open box must hold its max corner
            box = (box[0], box[1], np.nextafter(box[2], np.inf), np.nextafter(box[3], np.inf))
        near = np.flatnonzero(
            np.all(lo <= np.array(box[2:]) + reach, axis=1)
            & np.all(hi >= np.array(box[:2]) - reach, axis=1)
        )
        if len(near) < 2:
            continue
        pts = np.concatenate([merged[j].points for j in near])
        ids = np.concatenate([np.full(len(merged[j].points), j, np.int64) for j in near])
        inside = (
            (pts[:, 0] >= box[0] - reach)
            & (pts[:, 0] <= box[2] + reach)
            & (pts[:, 1] >= box[1] - reach)
            & (pts[:, 1] <= box[3] + reach)
        )
        ctrl.append(
            client.submit(
                control_tile,
                box,
                [planes[j] for j in near],
                pts[inside],
                ids[inside],
                settings.control,
                pure=False,
            )
        )
    found = gather(client, ctrl, progress, should_stop, 0.85, 1.0)
    lcps = dedupe_points([p for f in found for p in f[0]], settings.control.delta)
    lines = dedupe_lines([ln for f in found for ln in f[1]])
    return {
        "outcomes": outcomes,
        "planes": planes,
        "lcps": lcps,
        "lines": lines,
        "seconds_tiles": t_tiles,
        "seconds_second_pass": t_second,
        "seconds": time.perf_counter() - t0,
    }


def settings_from(v: Values, info) -> BlockSettings:
    """Science parameters in the cloud's units, the buffers from their rule."""
    import numpy as np

    from ..lidar.block import ground_buffer, roof_buffer
    from ..lidar.control import ControlOptions
    from ..lidar.ground_filter import SmrfParams
    from ..lidar.roof_planes import RoofPlaneParams

    smrf = options_from(SmrfParams, SPEC, v)
    smrf = lengths_in_cloud_units(
        smrf,
        info,
        v.distance_unit,
        ("cell_size", "max_window", "low_outlier_radius"),
        ("threshold", "scalar", "low_outlier_height"),
    )
    roof = options_from(
        RoofPlaneParams, SPEC, v, min_support=min(RoofPlaneParams().min_support, v.k_neighbours)
    )
    roof = lengths_in_cloud_units(roof, info, v.distance_unit, ("epsilon",))
    control = options_from(ControlOptions, SPEC, v)
    control = lengths_in_cloud_units(
        control, info, v.distance_unit, ("delta", "min_boundary", "max_support_distance")
    )
    area = float(np.prod(np.maximum(info.maxs[:2] - info.mins[:2], 1e-9)))
    spacing = math.sqrt(area / max(info.point_count, 1))
    return BlockSettings(
        smrf,
        roof,
        control,
        ground_buffer(smrf),
        roof_buffer(roof.k_neighbours, spacing),
        v.crs or None,
    )


def _check_tiling(v: Values) -> None:
    """One large file: its tiles' count and their size against the buffer each reads around
    it, from the header, before any tile is made (a small TILE_SIZE would make millions, each
    reading many times its own area)."""
    from ..io.pointcloud import read_info

    path = Path(v.input)
    if not (path.is_file() and path.suffix.lower() in (".las", ".laz")):
        return
    info = read_info(path, v.crs or None)
    width, height = (float(d) for d in info.maxs[:2] - info.mins[:2])
    size, unit = float(v.tile_size), info.horizontal_unit
    if size > max(width, height):
        return  # one tile
    # the grid of index_block: cells on multiples of the tile size
    cols, rows = (
        math.floor((float(hi) - math.floor(float(lo) / size) * size) / size) + 1
        for lo, hi in zip(info.mins[:2], info.maxs[:2])
    )
    if cols * rows > MAX_TILES:
        raise InputError(
            f"TILE_SIZE {size:g} {unit}: the file ({width:.4g} x {height:.4g} "
            f"{unit}) would be cut into {cols} x {rows} tiles, more than "
            f"{MAX_TILES}: give a larger TILE_SIZE"
        )
    settings = settings_from(v, info)
    buffer = max(settings.ground_buffer, settings.roof_buffer)
    if size < buffer:
        ratio = ((size + 2 * buffer) / size) ** 2
        raise InputError(
            f"TILE_SIZE {size:g} {unit} is smaller than the buffer each tile reads "
            f"around it ({buffer:.4g} {unit}, from SMRF_WINDOW, "
            f"LOW_OUTLIER_RADIUS and SMRF_CELL_SIZE): each tile would read "
            f"{ratio:.0f} times its own area; give at least {buffer:.4g} {unit}"
        )


def _tile_need(index, settings: BlockSettings) -> tuple[float, str]:
    """Bytes the largest tile takes in a worker (its points with the buffer, at the block's
    mean density, and the ground filter's grid) and the words saying so."""
    import numpy as np

    from .checks import GROUND_FILTER_BYTES_PER_CELL, GROUND_FILTER_BYTES_PER_POINT, size_text

    info = index.info
    lo, hi = info.mins[:2], info.maxs[:2]
    density = index.point_count / float(np.prod(np.maximum(hi - lo, 1e-9)))
    b = max(settings.ground_buffer, settings.roof_buffer)
    per_point = GROUND_FILTER_BYTES_PER_POINT + TILE_BYTES_PER_POINT + info.record_size
    best = (0.0, 0, 0, "")
    for tile in index.tiles:
        box = tile.cell or tile.box
        w = min(box[2] + b, hi[0]) - max(box[0] - b, lo[0])
        h = min(box[3] + b, hi[1]) - max(box[1] - b, lo[1])
        points = min(density * max(w, 0.0) * max(h, 0.0), index.point_count)
        cells = (w / settings.smrf.cell_size + 1) * (h / settings.smrf.cell_size + 1)
        need = points * per_point + max(cells, 0.0) * GROUND_FILTER_BYTES_PER_CELL
        if need > best[0]:
            best = (need, int(points), int(max(cells, 0.0)), tile.name)
    need, points, cells, name = best
    return WORKER_BASE_BYTES + need, (
        f"the largest tile ({name}: about {points} points with its buffer, a grid of {cells} "
        f"cells) and the worker itself ({size_text(WORKER_BASE_BYTES)})"
    )


def _check_cluster_memory(v: Values, index, settings: BlockSettings) -> None:
    """A local cluster's memory against the largest tile, before it starts (a worker below
    what a tile needs is restarted again and again: no error, no end)."""
    from .checks import check_memory, size_text

    if len(index.tiles) > MAX_TILES:
        raise InputError(
            f"INPUT: the block has {len(index.tiles)} tiles, more than "
            f"{MAX_TILES}: split it into several blocks"
        )
    if v.cluster or not index.tiles:
        return  # an existing cluster's workers have their own memory
    need, what = _tile_need(index, settings)
    if v.memory_limit > 0 and need > v.memory_limit * 1e9:
        raise InputError(
            f"MEMORY_LIMIT {v.memory_limit:g} GB: a worker needs about "
            f"{size_text(need)} for {what}: give at least "
            f"{math.ceil(need / 1e8) / 10:g} GB, or 0 (the memory shared among "
            "the workers)"
        )
    n = v.workers or os.cpu_count() or 1
    # thread workers share this process (its own memory counted once)
    total = n * need if _process_workers(v) else need + (n - 1) * (need - WORKER_BASE_BYTES)
    check_memory(
        total,
        f"WORKERS {n}: {n} tiles at once, each {what},",
        "give fewer WORKERS or a smaller TILE_SIZE",
    )


def _stop_workers(cluster) -> None:
    """End a local cluster's worker processes at once (a stop or an error: the graceful
    close waits seconds for each busy worker), so that SIGTERM ends the run within a second."""
    for nanny in list(getattr(cluster, "workers", {}).values()):
        process = getattr(getattr(nanny, "process", None), "process", None)
        pid = getattr(process, "pid", None)
        if pid is None:
            continue  # a thread worker: it ends with this process
        nanny.auto_restart = False
        try:
            os.kill(pid, getattr(signal, "SIGKILL", signal.SIGTERM))
        except OSError:
            pass


def _check_output(folder: Path) -> None:
    if folder.exists() and (
        not folder.is_dir() or (any(folder.iterdir()) and not (folder / REPORT_NAME).exists())
    ):
        raise InputError(
            "OUTPUT_FOLDER must be a new or empty folder, or a previous block "
            "output (with its block_report.json)",
            path=str(folder),
        )


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Index the block, run it on the cluster, write the outputs together."""
    import shutil

    from ..io.atomic import check_outputs
    from ..io.tiles import commit_folder, index_block, staging_folder, write_json

    target = Path(v.output_folder)
    _check_output(target)
    _check_tiling(v)
    index = index_block(v.input, v.crs or None, v.tile_size)
    # the folder is replaced when the block is done: no tile it reads may lie in it
    check_outputs(
        {}, {"INPUT": [v.input, *(t.path for t in index.tiles)]}, folders={"OUTPUT_FOLDER": target}
    )
    info = index.info
    settings = settings_from(v, info)
    _check_cluster_memory(v, index, settings)
    log.info(
        "%d tiles (%s), %d points; buffers: ground %.4g, roof planes %.4g %s",
        len(index.tiles),
        index.kind,
        index.point_count,
        settings.ground_buffer,
        settings.roof_buffer,
        info.horizontal_unit,
    )
    staging = staging_folder(target)
    try:
        block = _on_cluster(v, index, settings, str(staging), progress, should_stop)
        outcomes = block["outcomes"]
        failed = [(o.name, o.error) for o in outcomes if not o.ok] + index.bad
        good = [o for o in outcomes if o.ok and o.n_core > 0]
        _write_tables(staging, block, good, info)
        report = _report(v, index, settings, block, failed, good)
        write_json(staging / REPORT_NAME, report)
        commit_folder(staging, target)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    return _result(target, index, block, report, failed, good)


def _result(target: Path, index, block: dict, report: dict, failed: list, good: list) -> JobResult:
    """The job's result of a committed block: counts, the summary line, the exit status."""
    complete = not failed
    for name, error in failed:
        log.warning("tile %s failed: %s", name, error)
    n_tiles = len(index.tiles) + len(index.bad)
    status = (
        "complete"
        if complete
        else f"INCOMPLETE ({len(failed)} tile(s) failed: " + ", ".join(n for n, _ in failed) + ")"
    )
    return JobResult(
        results={
            "TILE_COUNT": len(good),
            "FAILED_TILES": len(failed),
            "COMPLETE": int(complete),
            "POINT_COUNT": report["point_count"],
            "GROUND_COUNT": report["ground_count"],
            "PLANE_COUNT": len(block["planes"]),
            "LCP_COUNT": len(block["lcps"]),
            "LINE_COUNT": len(block["lines"]),
        },
        lines=[
            f"block {status}: {len(good)} of {n_tiles} tiles, {report['point_count']} "
            f"points, {report['ground_count']} ground, {len(block['planes'])} planes, "
            f"{len(block['lcps'])} LCPs, {len(block['lines'])} lines in "
            f"{block['seconds']:.1f} s -> {target}"
        ],
        data=report,
        exit_code=0 if complete else INCOMPLETE_EXIT,
    )


@contextlib.contextmanager
def cluster_session(v: Values):
    """The dask client of the parameters (:func:`open_client`) for the block inside; a local
    cluster's workers stopped at once when it fails or is cancelled, the client and cluster
    closed in every case."""
    client, cluster = open_client(v)
    try:
        yield client
    except BaseException:
        if cluster is not None:
            _stop_workers(cluster)
        raise
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _on_cluster(v: Values, index, settings, staging: str, progress, should_stop) -> dict:
    """:func:`run_block` on the client of the parameters (:func:`cluster_session`)."""
    with cluster_session(v) as client:
        return run_block(index, settings, staging, client, progress, should_stop)


def _write_tables(staging: Path, block: dict, good: list, info) -> None:
    """The block's virtual point cloud (its good tiles) and its planes, LCPs and lines."""
    from ..io.control import write_lcps_csv, write_lines_csv
    from ..io.planes import write_planes_csv
    from ..io.tiles import write_vpc

    crs_wkt = info.crs.to_wkt() if info.crs is not None else ""
    write_vpc(
        staging / "block.vpc",
        [{"name": o.name, "href": o.href, "count": o.n_core, "bbox": o.bbox} for o in good],
        crs_wkt,
    )
    write_planes_csv(staging / "planes.csv", block["planes"])
    write_lcps_csv(staging / "lcps.csv", block["lcps"])
    write_lines_csv(staging / "lines.csv", block["lines"])


def _report(v: Values, index, settings, block: dict, failed: list, good: list) -> dict:
    """The block's report (REPORT_NAME): the source, buffers, counts, times and every tile."""
    info = index.info
    outcomes = block["outcomes"]
    return {
        "complete": not failed,
        "source": str(v.input),
        "kind": index.kind,
        "copc_tiles": sum(t.copc for t in index.tiles),
        "crs": info.crs.name if info.crs is not None else "",
        "unit": info.horizontal_unit,
        "ground_buffer": settings.ground_buffer,
        "roof_buffer": settings.roof_buffer,
        "failed_tiles": [{"name": n, "error": e} for n, e in failed],
        "point_count": sum(o.n_core for o in good),
        "ground_count": sum(o.n_ground for o in good),
        "plane_count": len(block["planes"]),
        "lcp_count": len(block["lcps"]),
        "line_count": len(block["lines"]),
        "seconds": round(block["seconds"], 3),
        "tasks_s": round(block["seconds_tiles"], 3),
        "second_pass_s": round(block.get("seconds_second_pass", 0.0), 3),
        "tiles": [
            {
                "name": o.name,
                "ok": o.ok,
                "error": o.error,
                "points": o.n_core,
                "points_read": o.n_read,
                "points_decoded": o.n_decoded,
                "ground": o.n_ground,
                "low_outliers": o.n_low,
                "plane_pieces": len(o.pieces),
                "seconds": round(o.seconds, 3),
                "peak_rss_mb": round(o.peak_rss_mb, 1),
                "stage_seconds": o.stages,
                "buffer_incomplete": o.missing,
                "href": o.href,
            }
            for o in outcomes
        ],
    }
