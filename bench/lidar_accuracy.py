"""LiDAR swath-to-swath and within-swath accuracy (ASPRS Ed. 2) of the AHN3 Delft crops: the
figures per swath pair with their smooth-cell counts, each pair's RMSDz recomputed
independently (a numpy ``lstsq`` plane per cell and swath, from the raw returns of the cell),
at three cell sizes.

Run: ``.venv/bin/python bench/lidar_accuracy.py``; prints the tables of bench/lidar_accuracy.md.
The crops are read from ``../shared/data/ahn3-delft`` (not in the repository).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
from lidarphoto.core.jobs.lidar_accuracy import _infos, _read
from lidarphoto.core.quality.lidar_accuracy import assess_lidar
from lidarphoto.core.quality.lidar_accuracy_options import LidarAccuracyOptions

HERE = Path(__file__).resolve().parent
DATA = HERE.parents[1] / "shared" / "data" / "ahn3-delft"
FILES = [str(DATA / "ahn3_cropped_1.laz"), str(DATA / "ahn3_cropped_2.laz")]


def independent_rmsdz(cloud, pair, swath, cell: float) -> tuple[float, float]:
    """RMSDz and max |dz| of ``pair`` from a fresh least-squares plane per cell and swath."""
    half = cell / 2
    order = np.argsort(cloud.x, kind="stable")
    xs = cloud.x[order]
    dz = np.empty(pair.n)
    for k in range(pair.n):
        lo, hi = np.searchsorted(xs, [pair.x[k] - half, pair.x[k] + half])
        idx = order[lo:hi]
        keep = (cloud.y[idx] > pair.y[k] - half) & (cloud.y[idx] <= pair.y[k] + half)
        keep &= (cloud.x[idx] < pair.x[k] + half) & ~np.isin(cloud.classification[idx], (7, 18))
        idx = idx[keep]
        h = []
        for s in (pair.swath_a, pair.swath_b):
            m = idx[swath[idx] == s]
            a = np.column_stack([np.ones(m.size), cloud.x[m] - pair.x[k], cloud.y[m] - pair.y[k]])
            h.append(np.linalg.lstsq(a, cloud.z[m], rcond=None)[0][0])
        dz[k] = h[0] - h[1]
    return float(np.sqrt(np.mean(dz * dz))), float(np.max(np.abs(dz)))


def main() -> int:
    if not all(Path(f).exists() for f in FILES):
        print(f"AHN3 crops not found in {DATA}")
        return 1
    cloud = _read(FILES, _infos(FILES)[0], None, None)
    swath = cloud.point_source_id.astype(np.int64)
    counts = zip(*np.unique(swath, return_counts=True))
    print(f"{cloud.x.size} returns; swaths (point source id): "
          + ", ".join(f"{s} ({n})" for s, n in counts))  # fmt: skip
    for cell, hard in ((1.0, ()), (1.0, (2, 6)), (1.5, ()), (2.0, ())):
        o = LidarAccuracyOptions(cell_size=cell, v_class_cm=10.0, hard_classes=hard)
        t0 = time.perf_counter()
        rep = assess_lidar(cloud, o)
        dt = time.perf_counter() - t0
        c = rep.cells
        print(f"\n### cell {cell:g} m, hard classes {hard or 'any'} ({dt:.1f} s): "
              f"{c.n.size} swath cells fitted, "
              f"{int(c.smooth.sum())} smooth; rejected {c.rejected}")  # fmt: skip
        print(
            "| swaths | cells | mean dz (m) | RMSDz (m) | max abs dz (m) | > 8 cm | > 16 cm "
            "| tilt across a (mm/m) | independent RMSDz (m) | independent max (m) |"
        )
        print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
        for p in rep.pairs:
            st = p.stats()
            a = np.abs(p.dz)
            ind = independent_rmsdz(cloud, p, swath, cell)
            cross = "" if p.cross_track_slope is None else f"{1000 * p.cross_track_slope:.3f}"
            print(f"| {p.swath_a}-{p.swath_b} | {p.n} | {st['mean']:.4f} | {st['rmsdz']:.4f} | "
                  f"{st['max_abs']:.4f} | {np.mean(a > 0.08):.2%} | {np.mean(a > 0.16):.2%} | "
                  f"{cross} | {ind[0]:.4f} | {ind[1]:.4f} |")  # fmt: skip
        o_ = rep.overall
        print(f"| all | {o_['n']} | {o_['mean']:.4f} | {o_['rmsdz']:.4f} | {o_['max_abs']:.4f} "
              f"| {o_.get('share_over_rmsdz_limit', 0):.2%} | "
              f"{o_.get('share_over_max_limit', 0):.2%} | | | |")  # fmt: skip
        print(
            "\n| swath | smooth cells | residual rms (m) | median Max Diff (m) | "
            "95th pct (m) | max (m) |\n| --- | --- | --- | --- | --- | --- |"
        )
        for w in rep.precision:
            print(
                f"| {w.swath} | {w.cells} | {w.rms:.4f} | {w.range_median:.4f} | "
                f"{w.range_p95:.4f} | {w.range_max:.4f} |"
            )
    tiled_check()
    return 0


def tiled_check() -> None:
    """The job in one process and tiled (100 m tiles, 2 thread workers): the same cells/dz."""
    from lidarphoto.core.jobs import lidar_accuracy
    from lidarphoto.core.jobs.runner import run_job

    times, reports = {}, {}
    for name, extra in (("one process", {}),
                        ("tiled 100 m", {"TILE_SIZE": 100.0, "WORKERS": 2,
                                         "LOCAL_CLUSTER": "threads"})):  # fmt: skip
        t0 = time.perf_counter()
        reports[name] = run_job(lidar_accuracy, {"INPUT": FILES, **extra}).data
        times[name] = time.perf_counter() - t0
    a, b = reports.values()
    same = all(np.array_equal(p.dz, q.dz) for p, q in zip(a.pairs, b.pairs, strict=True))
    print(f"\n### tiled run: dz identical to one process: {same}; "
          + ", ".join(f"{k} {t:.1f} s" for k, t in times.items()))  # fmt: skip


if __name__ == "__main__":
    sys.exit(main())
