"""Write simulated points as a COPC file (Cloud Optimized Point Cloud: a LAZ 1.4 file whose
LAZ chunks are the nodes of an octree) with copclib, the COPC library of Rock Robotic.

copclib writes the format (header, COPC info VLR, LAZ chunks, hierarchy pages); the octree's
content is ours and follows the usual level-of-detail rule of COPC writers: the root's cube is
divided into ``grid`` voxels a side, each node keeps one point per voxel (the first of a fixed
random order) and hands the rest to its children (voxels half as large); a node with at most
``leaf_points`` points keeps them all. Nodes are written in a shuffled order, so the file
order of the points is not the octree's (a reader must take each node's place from its
offset).

Test and benchmark data only: copclib is not a dependency of the plugin (pip install copclib).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .block import BLOCK_EPSG


def _octree(
    xyz: NDArray[np.float64],
    lo: NDArray[np.float64],
    side: float,
    grid: int,
    leaf: int,
    order: NDArray[np.int64],
) -> dict[tuple[int, int, int, int], NDArray[np.int64]]:
    """Point indices per node key (level, x, y, z); ``xyz`` in the cube frame (0..side)."""
    nodes: dict[tuple[int, int, int, int], NDArray[np.int64]] = {}
    todo = [((0, 0, 0, 0), order)]
    while todo:
        key, idx = todo.pop()
        level = key[0]
        if len(idx) <= leaf or level >= 20:
            nodes[key] = np.sort(idx)
            continue
        cell = side / 2**level / grid
        vox = np.floor((xyz[idx] - lo) / cell).astype(np.int64)
        vox = np.clip(vox, 0, grid * 2**level - 1)
        flat = (vox[:, 0] * (grid << level) + vox[:, 1]) * (grid << level) + vox[:, 2]
        _, first = np.unique(flat, return_index=True)
        keep = np.zeros(len(idx), bool)
        keep[first] = True
        nodes[key] = np.sort(idx[keep])
        rest = idx[~keep]
        child = np.clip(
            np.floor((xyz[rest] - lo) / (side / 2 ** (level + 1))).astype(np.int64),
            0,
            2 ** (level + 1) - 1,
        )
        code = (
            (child[:, 0] - 2 * key[1])
            + 2 * (child[:, 1] - 2 * key[2])
            + 4 * (child[:, 2] - 2 * key[3])
        )
        for c in range(8):
            sub = rest[code == c]
            if len(sub):
                k = (
                    level + 1,
                    2 * key[1] + (c & 1),
                    2 * key[2] + ((c >> 1) & 1),
                    2 * key[3] + ((c >> 2) & 1),
                )
                todo.append((k, sub))
    return nodes


def write_copc(
    path: str | Path,
    xyz: NDArray[np.float64],
    gps_time: NDArray[np.float64] | None = None,
    classification: NDArray[Any] | None = None,
    epsg: int | None = BLOCK_EPSG,
    grid: int = 64,
    leaf_points: int = 20_000,
    seed: int = 0,
) -> dict[str, int]:
    """Write points as a COPC file (point format 6, mm scale, single returns, WKT CRS).

    Parameters
    ----------
    path : path
        The .copc.laz file.
    xyz : (N, 3) float
        Coordinates, CRS unit.
    gps_time : (N,) float, optional
        Default: the point's index (its id in the simulated blocks).
    classification : (N,) int, optional
    epsg : int or None
    grid : int
        Voxels per side of a node (the level-of-detail thinning).
    leaf_points : int
        A node with at most this many points keeps them all.
    seed : int
        Order of the points within the thinning and of the nodes in the file.

    Returns
    -------
    dict
        ``nodes`` (count) and ``depth`` (deepest level).
    """
    import copclib
    import laspy
    import pyproj

    xyz = np.asarray(xyz, dtype=np.float64)
    n = len(xyz)
    scale = 0.001
    offset = np.floor(xyz.min(axis=0))
    ixyz = np.round((xyz - offset) / scale).astype(np.int64)
    q = ixyz * scale + offset  # the stored coordinates: nodes hold them
    mins, maxs = q.min(axis=0), q.max(axis=0)
    half = float(np.max(maxs - mins)) / 2.0 + scale
    center = (mins + maxs) / 2.0
    lo = center - half
    rng = np.random.default_rng(seed)
    nodes = _octree(q, lo, 2.0 * half, grid, leaf_points, rng.permutation(n))

    wkt = pyproj.CRS.from_epsg(epsg).to_wkt() if epsg is not None else ""
    cfg = copclib.CopcConfigWriter(
        6, copclib.Vector3(scale, scale, scale), copclib.Vector3(*offset.tolist()), wkt
    )
    cfg.las_header.min = copclib.Vector3(*mins.tolist())
    cfg.las_header.max = copclib.Vector3(*maxs.tolist())
    cfg.copc_info.center_x, cfg.copc_info.center_y, cfg.copc_info.center_z = center.tolist()
    cfg.copc_info.halfsize = half
    cfg.copc_info.spacing = 2.0 * half / grid
    fmt = laspy.PointFormat(6)
    rec = laspy.PackedPointRecord.zeros(n, fmt)
    rec.X, rec.Y, rec.Z = ixyz[:, 0], ixyz[:, 1], ixyz[:, 2]
    rec.return_number = np.ones(n, np.uint8)
    rec.number_of_returns = np.ones(n, np.uint8)
    if classification is not None:
        rec.classification = np.asarray(classification, np.uint8)
    rec.gps_time = np.arange(n, dtype=np.float64) if gps_time is None else gps_time
    writer = copclib.FileWriter(str(path), cfg)
    try:
        keys = list(nodes)
        for k in rng.permutation(len(keys)):
            key = keys[int(k)]
            raw = rec.array[nodes[key]].tobytes()
            writer.AddNode(copclib.VoxelKey(*key), copclib.VectorChar(np.frombuffer(raw, np.int8)))
    finally:
        writer.Close()
    return {"nodes": len(nodes), "depth": max(k[0] for k in nodes)}


def copc_town(
    path: str | Path, density: float = 12.0, seed: int = 0, **kwargs: Any
) -> NDArray[np.float64]:
    """The simulated town of :func:`core.simulation.block.town_tiles` written as one COPC file
    (ids in ``gps_time``: the town's point order). Returns its (N, 3) points."""
    from .town import simulate_town

    _, pts = simulate_town(n_buildings=10, n_trees=8, density=density, seed=seed)
    write_copc(path, pts.xyz, **kwargs)
    return pts.xyz
