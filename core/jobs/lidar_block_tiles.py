"""The tile tasks of ``lidarblock`` (core/jobs/lidar_block.py): what runs on a dask worker
(one tile's ground filter, writing and roof planes; the control around a tile) and the
settings and outcomes they carry."""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from ..errors import InputError

if TYPE_CHECKING:
    from ..lidar.control import ControlOptions
    from ..lidar.ground_filter import SmrfParams
    from ..lidar.roof_planes import RoofPlaneParams

#: Folder of the staging area for the tiles' non-ground points (the roof planes' second pass;
#: removed before the block is committed).
ROOF_SCRATCH = ".roof_points"


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
    band: Any = None  # the roof-plane labels along the border (lidar.block.BandLabels)


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
    from ..lidar.block import tile_planes
    from ..lidar.ground_filter import (
        GROUND_CLASS,
        LOW_NOISE_CLASS,
        UNCLASSIFIED_CLASS,
        ground_filter,
    )

    t0 = time.perf_counter()
    c0 = time.process_time()  # the worker's CPU (its decoder threads too): load-independent
    tile = index.tiles[i]
    try:
        buf = read_buffered(
            index, i, max(settings.ground_buffer, settings.roof_buffer), settings.crs
        )
    except InputError as exc:
        return TileOutcome(i, tile.name, False, str(exc))
    stages = {"read": time.perf_counter() - t0}
    a = buf.arrays
    core = a["core"]
    n_core = int(core.sum())
    if n_core == 0:  # an empty cell of a large file's grid
        return TileOutcome(i, tile.name, True, n_read=len(core), seconds=0.0, n_decoded=buf.decoded)
    own = tile.cell or tile.box
    g = settings.ground_buffer
    inside = (
        (a["x"] >= own[0] - g)
        & (a["x"] <= own[2] + g)
        & (a["y"] >= own[1] - g)
        & (a["y"] <= own[3] + g)
    )
    info = buf.records.info
    sel = np.flatnonzero(inside)
    res = ground_filter(
        a["x"][sel],
        a["y"][sel],
        a["z"][sel],
        settings.smrf,
        return_number=a["return_number"][sel],
        number_of_returns=a["number_of_returns"][sel],
        unit_to_metre=info.unit_to_metre,
        vertical_unit_to_metre=info.vertical_unit_to_metre,
        unit=info.horizontal_unit,
    )
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
    write_cloud(
        tile.path,
        os.path.join(staging, "tiles", name),
        classification=cls[:n_core],
        points=buf.records,
    )
    stages["write"] = time.perf_counter() - t0 - sum(stages.values())
    xyz = np.column_stack([a["x"], a["y"], a["z"]])
    r = settings.roof_buffer
    near = (
        (a["x"] >= own[0] - r)
        & (a["x"] <= own[2] + r)
        & (a["y"] >= own[1] - r)
        & (a["y"] <= own[3] + r)
    )
    near &= (cls != GROUND_CLASS) & (cls != LOW_NOISE_CLASS)
    # the band next to the border, where the tile labels as a whole-file run would
    pieces, band = tile_planes(xyz[near], core[near], a["id"][near], own, r / 2.0, settings.roof, i)
    # the tile's non-ground points, for the second pass of the regions cut by a buffer
    mine = near & core
    np.savez(
        os.path.join(staging, ROOF_SCRATCH, f"{i}.npz"),
        xyz=xyz[mine],
        id=a["id"][mine],
        box=np.asarray(own, dtype=np.float64),
    )
    stages["roof_planes"] = time.perf_counter() - t0 - sum(stages.values())
    stages["cpu"] = time.process_time() - c0
    ids = a["id"][:n_core]
    cx = xyz[:n_core]
    return TileOutcome(
        i,
        tile.name,
        True,
        "",
        n_core,
        len(core),
        int(ground[:n_core].sum()),
        int(low[:n_core].sum()),
        time.perf_counter() - t0,
        _peak_rss_mb(),
        buf.missing,
        (*cx.min(axis=0).tolist(), *cx.max(axis=0).tolist()),
        f"tiles/{name}",
        pieces,
        (int(ids.min()), int(ids.max()), int(ids.sum())),
        {k: round(t, 3) for k, t in stages.items()},
        buf.decoded,
        band,
    )


def control_tile(box, planes, points, plane_ids, options: ControlOptions):
    """One dask task: LiDAR control of the merged planes around a tile; the LCPs inside the
    tile's box (half-open) and every line (deduplicated later)."""
    from ..lidar.control import lidar_control

    if len(planes) < 2:
        return [], []
    res = lidar_control(planes, points, plane_ids, options)
    lcps = [p for p in res.points if box[0] <= p.xyz[0] < box[2] and box[1] <= p.xyz[1] < box[3]]
    return lcps, res.lines


def _scratch_fetch(folder: str) -> Callable[[tuple[float, float, float, float]], Any]:
    """``fetch(box)`` for :func:`core.lidar.block_cut.second_pass`: the non-ground points in
    ``box`` from the tiles' scratch files (``process_tile``), read one tile at a time (those
    whose box meets ``box``), each point from the tile that owns it."""
    import numpy as np

    names = sorted(os.listdir(folder), key=lambda f: int(f.split(".")[0]))

    def fetch(box: tuple[float, float, float, float]) -> tuple[Any, Any]:
        xyz, ids = [np.zeros((0, 3))], [np.zeros(0, np.int64)]
        for name in names:
            with np.load(os.path.join(folder, name)) as f:
                own = f["box"]
                if own[0] > box[2] or own[2] < box[0] or own[1] > box[3] or own[3] < box[1]:
                    continue
                x, i = f["xyz"], f["id"]
            m = (x[:, 0] >= box[0]) & (x[:, 0] < box[2]) & (x[:, 1] >= box[1]) & (x[:, 1] < box[3])
            xyz.append(x[m])
            ids.append(i[m])
        return np.concatenate(xyz), np.concatenate(ids)

    return fetch
