"""lidarblock on one large file: COPC read by octree node vs the chunked read (every grid tile
streams the whole file), on the same points.

Generates one simulated town of a few million points (core/simulation/town.py), writes it as
COPC (copclib, core/simulation/copc.py) and as a plain LAZ (laspy, point format 1), and runs
the whole job (index, reads + buffers, SMRF, tile writing, roof planes, merge, control,
VPC/report) three times on one worker (a thread cluster, so the process CPU time holds the
worker's): the COPC by query, the same COPC file streamed (COPC detection off), the plain LAZ
streamed. Prints wall and CPU time, the points decoded and the read stage per run, and checks
that the three runs classify every point alike.

Usage::

    python bench/bench_copc.py --cells 20 --density 8 --tile 150 --folder /tmp/copc-bench

(copclib is needed to write the COPC: pip install copclib.)
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import shutil
import time
from pathlib import Path

import numpy as np


def _classes(out: Path) -> np.ndarray:
    import laspy

    ids, cls = [], []
    for f in sorted((out / "tiles").glob("*.laz")):
        las = laspy.read(f)
        ids.append(np.asarray(las.gps_time).astype(np.int64))
        cls.append(np.asarray(las.classification))
    ids, cls = np.concatenate(ids), np.concatenate(cls)
    res = np.zeros(len(ids), np.uint8)
    res[ids] = cls
    return res


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--cells", type=int, default=20, help="town cells (30 m) per side")
    ap.add_argument("--density", type=float, default=8.0, help="points per m^2")
    ap.add_argument("--tile", type=float, default=150.0, help="TILE_SIZE (m)")
    ap.add_argument("--folder", default="/tmp/copc-bench")
    args = ap.parse_args()

    from importlib.metadata import version

    import laspy
    from lidarphoto.core.io import tiles as tiles_mod
    from lidarphoto.core.jobs import lidar_block
    from lidarphoto.core.jobs.runner import run_job
    from lidarphoto.core.simulation.block import write_las
    from lidarphoto.core.simulation.copc import write_copc
    from lidarphoto.core.simulation.town import simulate_town

    folder = Path(args.folder)
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    t0 = time.perf_counter()
    nb = int(args.cells**2 * 0.55)
    _, pts = simulate_town(n_buildings=nb, n_trees=args.cells**2 - nb, density=args.density,
                           seed=0)  # fmt: skip
    xyz = pts.xyz
    layout = write_copc(folder / "town.copc.laz", xyz)
    write_las(folder / "town.laz", xyz)
    del pts
    print(f"# {platform.node()} {os.cpu_count()} cores, load {os.getloadavg()}")
    print(f"# laspy {laspy.__version__}, lazrs {version('lazrs')}, copclib {version('copclib')}, "
          f"numpy {np.__version__}")
    print(f"{len(xyz)} points, {np.ptp(xyz[:, :2], axis=0).round(0)} m; COPC "
          f"{(folder / 'town.copc.laz').stat().st_size / 1e6:.1f} MB ({layout['nodes']} nodes, "
          f"depth {layout['depth']}), LAZ {(folder / 'town.laz').stat().st_size / 1e6:.1f} MB; "
          f"generated in {time.perf_counter() - t0:.1f} s")
    runs = {"COPC by query": ("town.copc.laz", True),
            "same COPC streamed": ("town.copc.laz", False),
            "plain LAZ streamed": ("town.laz", True)}  # fmt: skip
    classes = {}
    for name, (file, detect) in runs.items():
        out = folder / name.replace(" ", "_")
        load = os.getloadavg()[0]
        c0 = time.process_time()
        t = time.perf_counter()
        real = tiles_mod.is_copc
        if not detect:
            tiles_mod.is_copc = lambda path: False
        try:
            res = run_job(lidar_block, {"INPUT": str(folder / file), "TILE_SIZE": args.tile,
                                        "OUTPUT_FOLDER": str(out), "WORKERS": 1,
                                        "LOCAL_CLUSTER": "threads"})  # fmt: skip
        finally:
            tiles_mod.is_copc = real
        wall = time.perf_counter() - t
        cpu = time.process_time() - c0
        rep = json.loads((out / "block_report.json").read_text())
        decoded = sum(t["points_decoded"] for t in rep["tiles"])
        kept = sum(t["points_read"] for t in rep["tiles"])
        read = sum(t["stage_seconds"].get("read", 0.0) for t in rep["tiles"])
        rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        classes[name] = _classes(out)
        print(f"{name:20s}: {len(rep['tiles'])} tiles, wall {wall:6.1f} s, CPU {cpu:6.1f} s, "
              f"read stage {read:6.1f} s, decoded {decoded / len(xyz):5.2f} x the file, "
              f"kept {kept / len(xyz):4.2f} x, {res.results['GROUND_COUNT']} ground, "
              f"{res.results['PLANE_COUNT']} planes, {res.results['LCP_COUNT']} LCPs, "
              f"load {load:.1f}, process peak RSS {rss:.0f} MB")
    first = next(iter(classes.values()))
    for name, cls in classes.items():
        print(f"classes equal to the COPC run's ({name}): {bool(np.array_equal(cls, first))}")


if __name__ == "__main__":
    main()
