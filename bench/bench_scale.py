"""Scaling of the tiled LiDAR block (lidarblock, core/jobs/lidar_block.py) on dask.distributed.

Generates a synthetic block tile by tile (core/simulation/block.py: each tile a simulated town,
never the whole block in memory), then runs the whole job (index, read + buffers, SMRF, tile
writing, roof planes, plane merge, control, VPC/report) as the user waits for it, on a local
process cluster of 1 and of 2 workers. Prints the per-tile cost (seconds, peak RSS of the
worker) from the block report and the wall time.

Usage::

    python bench/bench_scale.py --points 8e6 --per-tile 1e6 --workers 1 2 --folder /tmp/blk
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import statistics
import time
from pathlib import Path


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--points", type=float, default=4e6)
    ap.add_argument("--per-tile", type=float, default=1e6)
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--folder", default="/tmp/lidarblock-bench")
    ap.add_argument("--keep", action="store_true", help="reuse the tiles if present")
    args = ap.parse_args()

    from lidarphoto.core.jobs import lidar_block
    from lidarphoto.core.jobs.runner import run_job
    from lidarphoto.core.simulation.block import large_block

    folder = Path(args.folder)
    tiles = folder / "tiles"
    t0 = time.perf_counter()
    if not (args.keep and tiles.exists()):
        shutil.rmtree(tiles, ignore_errors=True)
        large_block(tiles, int(args.points), int(args.per_tile))
    t_gen = time.perf_counter() - t0
    size = sum(p.stat().st_size for p in tiles.glob("*.laz"))
    print(f"# {platform.node()} {os.cpu_count()} cores, load {os.getloadavg()}")
    print(f"generated {len(list(tiles.glob('*.laz')))} tiles, {size / 1e6:.1f} MB LAZ, "
          f"{t_gen:.1f} s")
    for n in args.workers:
        out = folder / f"out{n}"
        shutil.rmtree(out, ignore_errors=True)
        load = os.getloadavg()[0]
        t = time.perf_counter()
        res = run_job(lidar_block, {"INPUT": str(tiles), "OUTPUT_FOLDER": str(out),
                                    "WORKERS": n, "LOCAL_CLUSTER": "processes"})
        wall = time.perf_counter() - t
        rep = json.loads((out / "block_report.json").read_text())
        secs = [t["seconds"] for t in rep["tiles"]]
        rss = [t["peak_rss_mb"] for t in rep["tiles"]]
        pts = [t["points"] for t in rep["tiles"]]
        read = [t["points_read"] for t in rep["tiles"]]
        stage = {k: round(sum(t["stage_seconds"].get(k, 0.0) for t in rep["tiles"]), 1)
                 for k in ("read", "ground", "write", "roof_planes", "cpu")}  # fmt: skip
        print(json.dumps({
            "workers": n, "load_before": round(load, 2), "wall_s": round(wall, 1),
            "points": res.results["POINT_COUNT"], "tiles": len(secs),
            "points_per_s": round(res.results["POINT_COUNT"] / wall),
            "tile_s_median": round(statistics.median(secs), 2), "tile_s_max": round(max(secs), 2),
            "tile_points_median": int(statistics.median(pts)),
            "read_over_core": round(sum(read) / max(sum(pts), 1), 3),
            "worker_peak_rss_mb_max": max(rss), "tasks_s": rep["seconds"],
            "stage_s_sum": stage, "merge_control_s": round(rep["seconds"] - rep["tasks_s"], 1)
            if "tasks_s" in rep else None,
            "planes": res.results["PLANE_COUNT"], "lcps": res.results["LCP_COUNT"],
            "lines": res.results["LINE_COUNT"], "complete": rep["complete"],
            "out_mb": round(sum(p.stat().st_size for p in (out / "tiles").glob("*.laz")) / 1e6,
                            1),
        }), flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
