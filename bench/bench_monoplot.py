"""Benchmark: ray / DSM intersection (core.geometry.raycast.intersect_dsm) against a ray-marching
baseline written with numpy here, on a 10-million-cell DSM made from the real AHN3 Delft crop.

Run (one core, as the figures in bench/monoplot.md)::

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 .venv/bin/python bench/bench_monoplot.py

The DSM: the 0.5 m DSM of tests/data/ahn3/ahn3_delft_crop60.laz (120 x 121 cells, houses and
trees) mirrored into a 3200 x 3125 grid (10 M cells, 1.6 x 1.56 km). The camera: a nadir
frame camera 800 m above the ground (about 1.5 km swath), rays through random pixels.
Timed: ours compiled with numba and vectorised with numpy, each with empty-space skipping
and as a plain DDA, and the baseline; 0.1 M to 3 M rays; median of 3 runs for numba, one run
for the others. ``--hilly``: the same DSM on 150 m hills.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from lidarphoto.core.geometry.grid import Grid
from lidarphoto.core.geometry.raycast import DsmTracer, intersect_dsm
from lidarphoto.core.geometry.surface import Dsm
from lidarphoto.core.io.dsm import dsm_from_las

ROOT = Path(__file__).resolve().parents[1]

AHN3 = ROOT / "tests" / "data" / "ahn3" / "ahn3_delft_crop60.laz"


def big_dsm(rows: int = 3200, cols: int = 3125) -> Dsm:
    """The AHN3 crop's DSM mirrored (so the tiles join without steps) to rows x cols."""
    small = dsm_from_las(AHN3, 0.5, crs="EPSG:28992")
    tile = np.block([[small.heights, small.heights[:, ::-1]],
                     [small.heights[::-1], small.heights[::-1, ::-1]]])  # fmt: skip
    reps = (rows // tile.shape[0] + 1, cols // tile.shape[1] + 1)
    z = np.tile(tile, reps)[:rows, :cols].astype(np.float32)
    return Dsm(z, Grid(small.grid.x0, small.grid.y_top, 0.5, rows, cols), small.crs)


def rays(dsm: Dsm, n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Rays from a camera 800 m above the DSM's centre through random ground targets."""
    rng = np.random.default_rng(seed)
    g = dsm.grid
    cx, cy = g.x0 + g.cols * g.cell / 2, g.y_top - g.rows * g.cell / 2
    centre = np.array([cx, cy, 800.0])
    half = 0.45 * min(g.rows, g.cols) * g.cell
    target = np.column_stack(
        [cx + rng.uniform(-half, half, n), cy + rng.uniform(-half, half, n), np.zeros(n)]
    )
    d = target - centre
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return np.broadcast_to(centre, (n, 3)).copy(), d


def surface_height(dsm: Dsm, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    return dsm.height_at(x, y)


def baseline_march(dsm: Dsm, o: np.ndarray, d: np.ndarray, chunk: int = 65536) -> np.ndarray:
    """Straightforward vectorised ray marching: fixed steps of half a cell (horizontally)
    from where the ray enters the DSM's height range, first step below the surface, then
    30 bisections. Returns the hit points (NaN for misses)."""
    zmin, zmax = dsm.z_range
    out = np.full(o.shape, np.nan)
    for s in range(0, o.shape[0], chunk):
        oo, dd = o[s : s + chunk], d[s : s + chunk]
        horiz = np.hypot(dd[:, 0], dd[:, 1])
        step = 0.5 * dsm.cell / np.maximum(horiz, 1e-12)
        step = np.minimum(step, (zmax - zmin) / 4 / np.maximum(-dd[:, 2], 1e-12))
        t0 = (zmax - oo[:, 2]) / dd[:, 2]
        t1 = (zmin - oo[:, 2]) / dd[:, 2]
        idx = np.arange(oo.shape[0])
        t = t0.copy()
        prev = t0.copy()
        found = np.full(oo.shape[0], np.nan)
        while idx.size:
            p = oo[idx] + t[:, None] * dd[idx]
            below = p[:, 2] <= surface_height(dsm, p[:, 0], p[:, 1])
            # NaN (outside the DSM) compares False: the ray keeps marching until t1
            if below.any():
                lo, hi = prev[below], t[below]
                k = idx[below]
                for _ in range(30):
                    mid = 0.5 * (lo + hi)
                    pm = oo[k] + mid[:, None] * dd[k]
                    under = pm[:, 2] <= surface_height(dsm, pm[:, 0], pm[:, 1])
                    hi = np.where(under, mid, hi)
                    lo = np.where(under, lo, mid)
                found[k] = hi
            keep = ~below & (t < t1[idx])
            idx, prev, t = idx[keep], t[keep], t[keep] + step[idx[keep]]
        out[s : s + chunk] = oo + found[:, None] * dd
    return out


def timed(func, repeat: int = 3):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = func()
        times.append(time.perf_counter() - t0)
    return float(np.median(times)), res


def hilly(dsm: Dsm, relief: float = 150.0) -> Dsm:
    """The same DSM on hills (relief metres, 1 km wavelength): a longer path inside the
    height range, where skipping empty space matters."""
    r, c = np.mgrid[0 : dsm.grid.rows, 0 : dsm.grid.cols] * dsm.grid.cell
    k = 2 * np.pi / 1000.0
    hills = 0.25 * relief * (2 + np.sin(k * c) + np.cos(0.8 * k * r))
    return Dsm((dsm.heights + hills).astype(np.float32), dsm.grid, dsm.crs)


METHODS = (
    ("ours, numba (DDA + skipping)", dict(backend="numba")),
    ("ours, numba (plain DDA)", dict(backend="numba", accelerate=False)),
    ("ours, numpy (DDA + skipping)", dict(backend="numpy")),
    ("ours, numpy (plain DDA)", dict(backend="numpy", accelerate=False)),
)


def table(dsm: Dsm, tracer: DsmTracer, sizes, repeat: int, lift: float = 0.0) -> None:
    """One markdown row per (rays, method); agreement with the first method (1 mm)."""
    print("| rays | method | s (median) | rays/s | hits % | agree with numba (1 mm) % |")
    print("| --- | --- | --- | --- | --- | --- |")
    for n in sizes:
        o, d = rays(dsm, n)
        o[:, 2] += lift
        ref = None
        for name, kw in METHODS:
            rep = repeat if "numba" in name else 1
            t, h = timed(lambda o=o, d=d, kw=kw: intersect_dsm(tracer, o, d, **kw), rep)
            if ref is None:
                ref, agree = h, "-"
            else:
                ok = np.isin(ref.status, (0, 1))
                same = np.abs(h.points - ref.points).max(axis=1) < 1e-3
                agree = f"{100 * same[ok].mean():.3f}"
            hits = 100 * np.isin(h.status, (0, 1)).mean()
            print(f"| {n:,} | {name} | {t:.3f} | {n / t:,.0f} | {hits:.2f} | {agree} |", flush=True)
        if n <= 1_000_000 and (lift == 0.0 or n <= 100_000):
            t, pb = timed(lambda o=o, d=d: baseline_march(dsm, o, d), 1)
            ok = np.isin(ref.status, (0, 1))
            err = np.linalg.norm(pb - ref.points, axis=1)
            print(f"| {n:,} | baseline ray marching (0.5-cell steps) | {t:.3f} | {n / t:,.0f} | "
                  f"{100 * np.isfinite(pb[:, 0]).mean():.2f} | "
                  f"{100 * (err < 1e-3)[ok].mean():.3f} |", flush=True)  # fmt: skip


def main() -> None:
    hills = "--hilly" in sys.argv
    t0 = time.perf_counter()
    dsm = big_dsm()
    if hills:
        dsm = hilly(dsm)
    t_build = time.perf_counter() - t0
    t0 = time.perf_counter()
    tracer = DsmTracer.build(dsm)
    t_tracer = time.perf_counter() - t0
    print(f"DSM {dsm.heights.shape} = {dsm.heights.size / 1e6:.2f} M cells, z {dsm.z_range}")
    print(f"DSM build {t_build:.2f} s, skipping pyramid {t_tracer:.2f} s")
    o, d = rays(dsm, 10)
    t0 = time.perf_counter()
    intersect_dsm(tracer, o, d, backend="numba")  # compiles, or loads numba's cache
    print(f"numba: first call (compile or load the cache) {time.perf_counter() - t0:.2f} s")
    if hills:
        table(dsm, tracer, (100_000, 1_000_000), 1, lift=150.0)
    else:
        table(dsm, tracer, (100_000, 300_000, 1_000_000, 3_000_000), 3)


if __name__ == "__main__":
    main()
