"""Synthetic LiDAR blocks: a simulated town cut into LAS/LAZ tiles, or a large block made
tile by tile (each tile its own small town) without ever holding the block in memory.

Every point's ``gps_time`` is its id in the block (0..N-1, in file order of the tiles sorted
by name), so tests can check that a tiled run neither loses nor duplicates a point.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .town import simulate_town

#: The CRS of the synthetic blocks (Amersfoort / RD New + NAP height, as AHN).
BLOCK_EPSG = 7415


def write_las(
    path: str | Path,
    xyz: NDArray[np.float64],
    classification: NDArray[Any] | None = None,
    gps_time: NDArray[np.float64] | None = None,
    epsg: int | None = BLOCK_EPSG,
) -> None:
    """Write points as LAS/LAZ point format 1 (mm scale), single returns, with the CRS."""
    import laspy
    import pyproj

    header = laspy.LasHeader(point_format=1, version="1.2")
    header.scales = np.array([0.001, 0.001, 0.001])
    header.offsets = np.floor(xyz.min(axis=0)) if len(xyz) else np.zeros(3)
    if epsg is not None:
        header.add_crs(pyproj.CRS.from_epsg(epsg))
    las = laspy.LasData(header)
    las.x, las.y, las.z = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    las.return_number = np.ones(len(xyz), np.uint8)
    las.number_of_returns = np.ones(len(xyz), np.uint8)
    if classification is not None:
        las.classification = classification
    las.gps_time = np.arange(len(xyz), dtype=np.float64) if gps_time is None else gps_time
    las.write(str(path))


def town_tiles(
    folder: str | Path,
    tile_size: float,
    *,
    n_buildings: int = 10,
    n_trees: int = 8,
    density: float = 4.0,
    seed: int = 0,
    suffix: str = ".laz",
    epsg: int | None = BLOCK_EPSG,
    **town_kwargs: Any,
) -> tuple[NDArray[np.float64], NDArray[np.float64], list[Path]]:
    """One simulated town cut into square tiles of ``tile_size`` (grid on multiples of it).

    Returns the whole cloud (N, 3) in id order, the truth classes (N,) and the tile files.
    Ids (``gps_time``) follow the tile files sorted by name.
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    _, pts = simulate_town(
        n_buildings=n_buildings, n_trees=n_trees, density=density, seed=seed, **town_kwargs
    )
    xyz, cls = pts.xyz, pts.classification
    col = np.floor(xyz[:, 0] / tile_size).astype(np.int64)
    row = np.floor(xyz[:, 1] / tile_size).astype(np.int64)
    keys = sorted(set(zip(col.tolist(), row.tolist())))
    names = {k: f"tile_{k[0]}_{k[1]}" for k in keys}
    order = sorted(keys, key=lambda k: names[k])
    out_xyz, out_cls, files = [], [], []
    start = 0
    for k in order:
        m = (col == k[0]) & (row == k[1])
        path = folder / f"{names[k]}{suffix}"
        ids = np.arange(start, start + int(m.sum()), dtype=np.float64)
        write_las(path, xyz[m], None, ids, epsg)
        out_xyz.append(xyz[m])
        out_cls.append(cls[m])
        files.append(path)
        start += int(m.sum())
    return np.concatenate(out_xyz), np.concatenate(out_cls), files


def large_block(
    folder: str | Path,
    n_points: int,
    points_per_tile: int = 2_000_000,
    density: float = 8.0,
    seed: int = 0,
    suffix: str = ".laz",
) -> list[Path]:
    """A block of about ``n_points`` written tile by tile: each tile is a town of its own on
    the tile's square (side from the density), so memory stays that of one tile."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    n_tiles = max(1, math.ceil(n_points / points_per_tile))
    side = math.sqrt(points_per_tile / density)  # metres
    cells = max(int(side // 30.0), 1)  # town cells of 30 m
    cols = math.ceil(math.sqrt(n_tiles))
    files = []
    start = 0
    for t in range(n_tiles):
        c, r = t % cols, t // cols
        origin = (85000.0 + c * cells * 30.0, 447000.0 + r * cells * 30.0)
        nb = int(cells * cells * 0.55)
        _, pts = simulate_town(
            n_buildings=nb,
            n_trees=cells * cells - nb,
            density=density,
            seed=seed + t,
            origin=origin,
        )
        xyz = pts.xyz
        box = (origin[0], origin[1], origin[0] + cells * 30.0, origin[1] + cells * 30.0)
        m = (
            (xyz[:, 0] >= box[0])
            & (xyz[:, 0] < box[2])
            & (xyz[:, 1] >= box[1])
            & (xyz[:, 1] < box[3])
        )
        path = folder / f"tile_{t:05d}{suffix}"
        ids = np.arange(start, start + int(m.sum()), dtype=np.float64)
        write_las(path, xyz[m], None, ids)
        start += int(m.sum())
        files.append(path)
    return files
