"""Time of writing a scan registered into the common frame (read + transform + write), as
tlscalibration's OUTPUT_FOLDER does: a synthetic LAS/LAZ scan of N points in its scanner frame,
rigid pose only and with the paper's four APs removed per point; peak memory of the process.

Run: python bench/tls_register_clouds.py [N]   (prints a Markdown table for bench/tls.md)
"""

from __future__ import annotations

import math
import resource
import sys
import tempfile
import time
from pathlib import Path

import laspy
import numpy as np
from lidarphoto.core.io.scans import write_registered_scan
from lidarphoto.core.simulation.tls import PAPER_APS
from lidarphoto.core.tls.registration import scanner_to_object


def main(n: int = 2_000_000) -> None:
    rng = np.random.default_rng(0)
    d = Path(tempfile.mkdtemp())
    rho = rng.uniform(1.0, 40.0, n)
    theta = rng.uniform(-math.pi, math.pi, n)
    alpha = rng.uniform(-1.0, 1.4, n)
    xyz = np.column_stack([rho * np.cos(alpha) * np.cos(theta),
                           rho * np.cos(alpha) * np.sin(theta), rho * np.sin(alpha)])  # fmt: skip
    pose = np.array([512.3, 204.8, 11.5, 0.001, -0.002, 1.1])
    names = tuple(PAPER_APS)
    values = [PAPER_APS[k] for k in names]
    print("| scan | points | APs | time (read + transform + write) | Mpoints/s |")
    print("|---|---|---|---|---|")
    for suffix in (".las", ".laz"):
        header = laspy.LasHeader(point_format=1, version="1.2")
        header.scales, header.offsets = np.full(3, 0.0001), np.zeros(3)
        las = laspy.LasData(header)
        las.x, las.y, las.z = xyz[:, 0], xyz[:, 1], xyz[:, 2]
        las.intensity = rng.integers(0, 65535, n).astype(np.uint16)
        src = d / f"scan{suffix}"
        las.write(str(src))
        for label, kw in (("none (rigid)", {}), ("a0, b1, b2, c0", {"names": names,
                                                                    "values": values})):
            def f(p, kw=kw):
                return scanner_to_object(p, pose, **kw)

            t0 = time.perf_counter()
            write_registered_scan(src, d / f"out{suffix}", f)
            dt = time.perf_counter() - t0
            print(f"| {suffix[1:].upper()} | {n:,} | {label} | {dt:.2f} s | {n / dt / 1e6:.2f} |")
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"\npeak resident memory of the process: {peak:.0f} MB (the {n:,} points held "
          "by the benchmark itself included)")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 2_000_000)
