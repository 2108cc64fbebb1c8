"""``lidarblock``: a whole LiDAR block tile by tile on dask.distributed: ground filter (SMRF)
-> roof planes -> LiDAR control points and lines, with buffers and seamless merges."""

from __future__ import annotations

import logging
import math
import os
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import Cancelled, InputError
from .common import cloud_params, lengths_in_cloud_units
from .runner import JobResult
from .spec import AlgorithmSpec, Fields, Param, Result, Values, options_from

if TYPE_CHECKING:
    from ..lidar.control import ControlOptions
    from ..lidar.ground_filter import SmrfParams
    from ..lidar.roof_planes import RoofPlaneParams

log = logging.getLogger(__name__)

_S = Fields("lidar.ground_filter", "SmrfParams")
_R = Fields("lidar.roof_planes", "RoofPlaneParams")
_C = Fields("lidar.control", "ControlOptions")
#: Exit status of the command line when the block is incomplete (a tile failed).
INCOMPLETE_EXIT = 3
#: The command line shows a progress bar for this job.
CLI_PROGRESS = True
REPORT_NAME = "block_report.json"

# fmt: off
SPEC = AlgorithmSpec(
    name="lidarblock",
    title="LiDAR block: ground, roof planes and control, tile by tile (dask)",
    group="LiDAR",
    group_id="lidar",
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
the tile's own points are written. Roof planes are extracted on the tile plus twice the
radius of a K_NEIGHBOURS patch; planes cut by a tile border are merged (same plane by the
parameter test, adjacent points) and refitted with their covariance from all their points;
control points and lines found by several tiles are kept once.

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
              unit="length", minimum=0.01, maximum=10000.0),
        Param("SMRF_THRESHOLD", "number", "SMRF final height tolerance", _S.threshold,
              unit="length", minimum=0.0, maximum=1000.0),
        Param("SMRF_SCALAR", "number", "SMRF tolerance added per unit of slope", _S.scalar,
              unit="length", minimum=0.0, maximum=1000.0, advanced=True),
        Param("LOW_OUTLIER_RADIUS", "number", "Low outlier radius", _S.low_outlier_radius,
              unit="length", minimum=0.0, maximum=10000.0, advanced=True),
        Param("EPSILON", "number", "Roof planes: point-to-plane tolerance", _R.epsilon,
              unit="length", minimum=0.001, maximum=100.0),
        Param("K_NEIGHBOURS", "integer", "Roof planes: neighbours of the local RANSAC",
              _R.k_neighbours, minimum=6, maximum=200, advanced=True),
        Param("MIN_PLANE_POINTS", "integer", "Roof planes: smallest plane (points)",
              _R.min_plane_points, minimum=3, maximum=1000000),
        Param("DELTA", "number", "Control: adjacency distance delta", _C.delta,
              unit="length", minimum=0.001, maximum=1000.0),
        Param("MIN_BOUNDARY", "number", "Control: minimum common boundary", _C.min_boundary,
              unit="length", minimum=0.0, maximum=10000.0),
        Param("CLUSTER", "string", "dask scheduler address (empty: a local cluster)", "",
              optional=True, help="e.g. tcp://10.0.0.5:8786"),
        Param("WORKERS", "integer", "Local cluster: workers (0 = one per core)", 0,
              minimum=0, maximum=1024),
        Param("MEMORY_LIMIT", "number", "Local cluster: memory limit per worker (0 = RAM / "
              "workers)", 0.0, unit="GB", minimum=0.0, maximum=4096.0),
        Param("LOCAL_CLUSTER", "enum", "Local cluster workers", "auto",
              options=("auto", "processes", "threads"),
              labels=("auto (processes on the command line, threads inside QGIS)",
                      "processes (one per worker)", "threads of this process"),
              advanced=True,
              help="auto: processes on the command line, threads inside QGIS or "
              "qgis_process, where a process cluster would start QGIS's own executable for "
              "each worker"),
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

_H = ("cell_size", "max_window", "threshold", "scalar", "low_outlier_radius",
      "low_outlier_height")  # fmt: skip


@dataclass(frozen=True)
class BlockSettings:
    """What every tile task needs (picklable; lengths in the cloud's units)."""

    smrf: SmrfParams
    roof: RoofPlaneParams
    control: ControlOptions
    ground_buffer: float
    roof_buffer: float
    crs: Any = None


@dataclass
class TileOutcome:
    """What a tile task returns to the client."""

    index: int
    name: str
    ok: bool
    error: str = ""
    n_core: int = 0
    n_read: int = 0
    n_ground: int = 0
    n_low: int = 0
    seconds: float = 0.0
    peak_rss_mb: float = 0.0
    missing: list[str] = field(default_factory=list)
    bbox: tuple[float, ...] = ()
    href: str = ""
    pieces: list[Any] = field(default_factory=list)
    ids_digest: tuple[int, int, int] = (0, 0, 0)
    stages: dict[str, float] = field(default_factory=dict)
    n_decoded: int = 0


def _peak_rss_mb() -> float:
    try:
        import resource

        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    except (ImportError, OSError):  # Windows
        return float("nan")


def process_tile(index, i: int, settings: BlockSettings, staging: str) -> TileOutcome:
    """One dask task: read tile ``i`` and its buffer, filter the ground, write the tile's own
    points, find the roof planes around it; the planes' pieces on its core go back."""
    import numpy as np

    from ..io.pointcloud import write_cloud
    from ..io.tiles import read_buffered
    from ..lidar.block import PlanePiece
    from ..lidar.ground_filter import (
        GROUND_CLASS,
        LOW_NOISE_CLASS,
        UNCLASSIFIED_CLASS,
        ground_filter,
    )
    from ..lidar.roof_planes import extract_roof_planes

    t0 = time.perf_counter()
    c0 = time.process_time()  # the worker's CPU (its decoder threads too): load-independent
    tile = index.tiles[i]
    try:
        buf = read_buffered(index, i, max(settings.ground_buffer, settings.roof_buffer),
                            settings.crs)  # fmt: skip
    except InputError as exc:
        return TileOutcome(i, tile.name, False, str(exc))
    stages = {"read": time.perf_counter() - t0}
    a = buf.arrays
    core = a["core"]
    n_core = int(core.sum())
    if n_core == 0:  # an empty cell of a large file's grid
        return TileOutcome(i, tile.name, True, n_read=len(core), seconds=0.0,
                           n_decoded=buf.decoded)  # fmt: skip
    own = tile.cell or tile.box
    g = settings.ground_buffer
    inside = ((a["x"] >= own[0] - g) & (a["x"] <= own[2] + g) & (a["y"] >= own[1] - g)
              & (a["y"] <= own[3] + g))  # fmt: skip
    info = buf.records.info
    sel = np.flatnonzero(inside)
    res = ground_filter(
        a["x"][sel], a["y"][sel], a["z"][sel], settings.smrf,
        return_number=a["return_number"][sel], number_of_returns=a["number_of_returns"][sel],
        unit_to_metre=info.unit_to_metre, vertical_unit_to_metre=info.vertical_unit_to_metre,
        unit=info.horizontal_unit,
    )  # fmt: skip
    ground = np.zeros(len(core), bool)
    low = np.zeros(len(core), bool)
    ground[sel], low[sel] = res.ground, res.low_outlier
    stages["ground"] = time.perf_counter() - t0 - sum(stages.values())
    cls = a["classification"].copy()
    cls[(cls == GROUND_CLASS) & ~ground] = UNCLASSIFIED_CLASS
    cls[ground] = GROUND_CLASS
    cls[low] = LOW_NOISE_CLASS
    # core points come first in the buffered arrays, in the order of the tile's records
    name = f"{tile.name}.laz"
    write_cloud(tile.path, os.path.join(staging, "tiles", name), classification=cls[:n_core],
                points=buf.records)  # fmt: skip
    stages["write"] = time.perf_counter() - t0 - sum(stages.values())
    xyz = np.column_stack([a["x"], a["y"], a["z"]])
    r = settings.roof_buffer
    near = ((a["x"] >= own[0] - r) & (a["x"] <= own[2] + r) & (a["y"] >= own[1] - r)
            & (a["y"] <= own[3] + r))  # fmt: skip
    near &= (cls != GROUND_CLASS) & (cls != LOW_NOISE_CLASS)
    pieces = []
    if near.sum() >= settings.roof.min_plane_points:
        roofs = extract_roof_planes(xyz[near], settings.roof)
        label = np.full(len(core), -1, np.int32)
        label[near] = roofs.plane_id
        core_label = label[:n_core]
        for plane in roofs.planes:
            pts = xyz[:n_core][core_label == plane.id]
            if len(pts) >= 3:  # a plane only in the buffer belongs to the neighbour
                pieces.append(PlanePiece(i, plane, pts))
    stages["roof_planes"] = time.perf_counter() - t0 - sum(stages.values())
    stages["cpu"] = time.process_time() - c0
    ids = a["id"][:n_core]
    cx = xyz[:n_core]
    return TileOutcome(
        i, tile.name, True, "", n_core, len(core), int(ground[:n_core].sum()),
        int(low[:n_core].sum()), time.perf_counter() - t0, _peak_rss_mb(), buf.missing,
        (*cx.min(axis=0).tolist(), *cx.max(axis=0).tolist()), f"tiles/{name}", pieces,
        (int(ids.min()), int(ids.max()), int(ids.sum())),
        {k: round(t, 3) for k, t in stages.items()}, buf.decoded,
    )  # fmt: skip


def control_tile(box, planes, points, plane_ids, options: ControlOptions):
    """One dask task: LiDAR control of the merged planes around a tile; the LCPs inside the
    tile's box (half-open) and every line (deduplicated later)."""
    from ..lidar.control import lidar_control

    if len(planes) < 2:
        return [], []
    res = lidar_control(planes, points, plane_ids, options)
    lcps = [p for p in res.points
            if box[0] <= p.xyz[0] < box[2] and box[1] <= p.xyz[1] < box[3]]  # fmt: skip
    return lcps, res.lines


# ----------------------------------------------------------------------------- the cluster
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
    # inside QGIS (or qgis_process) a worker process would be started with QGIS's own
    # executable: threads there
    processes = v.local_cluster == "processes" or (
        v.local_cluster == "auto" and "qgis.core" not in sys.modules)
    cluster = LocalCluster(n_workers=n, threads_per_worker=1, memory_limit=memory,
                           processes=processes, dashboard_address=None,
                           silence_logs=logging.ERROR)  # fmt: skip
    return Client(cluster), cluster


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

    os.makedirs(os.path.join(staging, "tiles"), exist_ok=True)
    t0 = time.perf_counter()
    # the index travels with each task (a few hundred bytes per tile): nothing is lost
    # with a worker
    futures = [client.submit(task, index, i, settings, staging, pure=False,
                             key=f"lidarblock-tile-{i}-{os.getpid()}-{time.time_ns()}")
               for i in range(len(index.tiles))]  # fmt: skip
    outcomes: list[TileOutcome] = gather(client, futures, progress, should_stop, 0.0, 0.85)
    t_tiles = time.perf_counter() - t0
    pieces = [p for o in outcomes if o.ok for p in o.pieces]
    roof = settings.roof
    spacing = settings.roof_buffer / (2.0 * math.sqrt(roof.k_neighbours / math.pi))
    merged = merge_cut_planes(pieces, roof.angle_tolerance_deg, roof.epsilon,
                              max(3.0 * spacing, roof.epsilon))  # fmt: skip
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
        near = np.flatnonzero(np.all(lo <= np.array(box[2:]) + reach, axis=1)
                              & np.all(hi >= np.array(box[:2]) - reach, axis=1))  # fmt: skip
        if len(near) < 2:
            continue
        pts = np.concatenate([merged[j].points for j in near])
        ids = np.concatenate([np.full(len(merged[j].points), j, np.int64) for j in near])
        inside = ((pts[:, 0] >= box[0] - reach) & (pts[:, 0] <= box[2] + reach)
                  & (pts[:, 1] >= box[1] - reach) & (pts[:, 1] <= box[3] + reach))  # fmt: skip
        ctrl.append(client.submit(control_tile, box, [planes[j] for j in near], pts[inside],
                                  ids[inside], settings.control, pure=False))  # fmt: skip
    found = gather(client, ctrl, progress, should_stop, 0.85, 1.0)
    lcps = dedupe_points([p for f in found for p in f[0]], settings.control.delta)
    lines = dedupe_lines([ln for f in found for ln in f[1]])
    return {"outcomes": outcomes, "planes": planes, "lcps": lcps, "lines": lines,
            "seconds_tiles": t_tiles, "seconds": time.perf_counter() - t0}  # fmt: skip


def settings_from(v: Values, info) -> BlockSettings:
    """Science parameters in the cloud's units, the buffers from their rule."""
    import numpy as np

    from ..lidar.block import ground_buffer, roof_buffer
    from ..lidar.control import ControlOptions
    from ..lidar.ground_filter import SmrfParams
    from ..lidar.roof_planes import RoofPlaneParams

    smrf = options_from(SmrfParams, SPEC, v)
    smrf = lengths_in_cloud_units(smrf, info, v.distance_unit,
                                  ("cell_size", "max_window", "low_outlier_radius"),
                                  ("threshold", "scalar", "low_outlier_height"))  # fmt: skip
    roof = options_from(RoofPlaneParams, SPEC, v,
                        min_support=min(RoofPlaneParams().min_support, v.k_neighbours))
    roof = lengths_in_cloud_units(roof, info, v.distance_unit, ("epsilon",))
    control = options_from(ControlOptions, SPEC, v)
    control = lengths_in_cloud_units(control, info, v.distance_unit,
                                     ("delta", "min_boundary", "max_support_distance"))  # fmt: skip
    area = float(np.prod(np.maximum(info.maxs[:2] - info.mins[:2], 1e-9)))
    spacing = math.sqrt(area / max(info.point_count, 1))
    return BlockSettings(smrf, roof, control, ground_buffer(smrf),
                         roof_buffer(roof.k_neighbours, spacing), v.crs or None)  # fmt: skip


def _check_output(folder: Path) -> None:
    if folder.exists() and (not folder.is_dir() or (any(folder.iterdir())
                                                    and not (folder / REPORT_NAME).exists())):
        raise InputError("OUTPUT_FOLDER must be a new or empty folder, or a previous block "
                         "output (with its block_report.json)", path=str(folder))  # fmt: skip


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Index the block, run it on the cluster, write the outputs together."""
    from ..io.control import write_lcps_csv, write_lines_csv
    from ..io.planes import write_planes_csv
    from ..io.tiles import commit_folder, index_block, staging_folder, write_json, write_vpc

    target = Path(v.output_folder)
    _check_output(target)
    index = index_block(v.input, v.crs or None, v.tile_size)
    info = index.info
    settings = settings_from(v, info)
    log.info("%d tiles (%s), %d points; buffers: ground %.4g, roof planes %.4g %s",
             len(index.tiles), index.kind, index.point_count, settings.ground_buffer,
             settings.roof_buffer, info.horizontal_unit)  # fmt: skip
    staging = staging_folder(target)
    import shutil

    try:
        client, cluster = open_client(v)
        try:
            block = run_block(index, settings, str(staging), client, progress, should_stop)
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
        outcomes = block["outcomes"]
        failed = [(o.name, o.error) for o in outcomes if not o.ok] + index.bad
        good = [o for o in outcomes if o.ok and o.n_core > 0]
        crs_wkt = info.crs.to_wkt() if info.crs is not None else ""
        write_vpc(staging / "block.vpc",
                  [{"name": o.name, "href": o.href, "count": o.n_core, "bbox": o.bbox}
                   for o in good], crs_wkt)  # fmt: skip
        write_planes_csv(staging / "planes.csv", block["planes"])
        write_lcps_csv(staging / "lcps.csv", block["lcps"])
        write_lines_csv(staging / "lines.csv", block["lines"])
        complete = not failed
        report = {
            "complete": complete,
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
            "tiles": [{"name": o.name, "ok": o.ok, "error": o.error, "points": o.n_core,
                       "points_read": o.n_read, "points_decoded": o.n_decoded,
                       "ground": o.n_ground, "low_outliers": o.n_low,
                       "plane_pieces": len(o.pieces), "seconds": round(o.seconds, 3),
                       "peak_rss_mb": round(o.peak_rss_mb, 1), "stage_seconds": o.stages,
                       "buffer_incomplete": o.missing,
                       "href": o.href}
                      for o in outcomes],
        }  # fmt: skip
        write_json(staging / REPORT_NAME, report)
        commit_folder(staging, target)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    for name, error in failed:
        log.warning("tile %s failed: %s", name, error)
    n_tiles = len(index.tiles) + len(index.bad)
    status = "complete" if complete else f"INCOMPLETE ({len(failed)} tile(s) failed: " + \
        ", ".join(n for n, _ in failed) + ")"
    return JobResult(
        results={
            "TILE_COUNT": len(good), "FAILED_TILES": len(failed), "COMPLETE": int(complete),
            "POINT_COUNT": report["point_count"], "GROUND_COUNT": report["ground_count"],
            "PLANE_COUNT": len(block["planes"]), "LCP_COUNT": len(block["lcps"]),
            "LINE_COUNT": len(block["lines"]),
        },
        lines=[f"block {status}: {len(good)} of {n_tiles} tiles, {report['point_count']} "
               f"points, {report['ground_count']} ground, {len(block['planes'])} planes, "
               f"{len(block['lcps'])} LCPs, {len(block['lines'])} lines in "
               f"{block['seconds']:.1f} s -> {target}"],
        data=report,
        exit_code=0 if complete else INCOMPLETE_EXIT,
    )  # fmt: skip

