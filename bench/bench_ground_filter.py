"""Benchmark of the ground filters (SMRF default, SMRF published, PMF, CSF) against the
cloth-simulation-filter package (run here), laspy's own read + write and PDAL (PEERS.md).

    python bench/bench_ground_filter.py [--quick] [--runs 3] [--out results.json]
    python bench/bench_ground_filter.py --e2e-only --e2e-runs 3 --before <older copy>
    python bench/bench_ground_filter.py --openings   (SMRF's openings alone, Autzen's grid)

Needs the project's core importable as ``lidarphoto`` and, for the peer, the PyPI package
``cloth-simulation-filter`` (module CSF) in the same venv (bench/ground_filter.md says how).
Each (tool, data) measurement runs in its own process so that its peak RSS is its own.
Sections:

1. End to end (LAZ in, LAZ out): ``laspy.read`` + ``LasData.write`` of the file (the floor)
   against the ``groundfilter`` job (read -> classify -> write) in the same run, 10 M points,
   ``--e2e-runs`` times each, alternating: the job as shipped (numba when installed), the job
   with the numpy back end, and with ``--before`` an older copy's job; the classes written
   by every job run must be the same bits (SHA-1 of the classification, asserted).
2. Algorithm alone (points in memory, median of ``--runs``), peak RSS, and agreement with the
   producer's ground class (AHN3).
3. Synthetic terrain classes (core/simulation/terrain.py): total error of every method, of
   SMRF with its published defaults with and without the low-outlier pre-filter (PDAL's SMRF
   has none), and of the CSF package; the default was chosen on these and on AHN3.
4. ISPRS samples 11, 12, 51: validation only (never used to choose), with PDAL's figures.

Data: AHN3 Delft (both crops merged, 0.85 M points), the same repeated 3 x 4 with 10 m gaps
(10.2 M points, built in a temporary folder), Autzen full (10.65 M, international feet; our
lengths given in metres and converted, CSF's x 3.2808 as in PEERS.md).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "data"
AHN3 = [SHARED / "ahn3-delft" / "ahn3_cropped_1.laz", SHARED / "ahn3-delft" / "ahn3_cropped_2.laz"]
AUTZEN = SHARED / "autzen-full" / "autzen-full.laz"
ISPRS = ROOT / "tests" / "data" / "isprs"
FEET = 0.3048
FIELDS = ("x", "y", "z", "classification", "return_number", "number_of_returns")
METHODS = ("smrf", "smrf_published", "pmf", "csf")
#: PEERS.md, PDAL with its defaults: total error % per ISPRS sample; AHN3 x12 figures.
PDAL_ISPRS = {
    "smrf": {"samp11": 9.9, "samp12": 3.15, "samp51": 5.58},
    "pmf": {"samp11": 17.16, "samp12": 5.88, "samp51": 6.95},
    "csf": {"samp11": 38.23, "samp12": 7.53, "samp51": 18.73},
}


def build_ahn3(folder: Path, repeat: tuple[int, int]) -> Path:
    """Both AHN3 crops merged (and repeated nx x ny with 10 m gaps), LAZ with EPSG:7415."""
    import laspy
    import pyproj

    parts = [laspy.read(p) for p in AHN3]
    points = np.concatenate([p.points.array for p in parts])
    header = laspy.LasHeader(point_format=parts[0].header.point_format, version="1.2")
    header.scales = parts[0].header.scales
    header.offsets = parts[0].header.offsets
    header.add_crs(pyproj.CRS.from_epsg(7415))
    x = points["X"] * header.scales[0]
    y = points["Y"] * header.scales[1]
    width = x.max() - x.min() + 10.0
    height = y.max() - y.min() + 10.0
    nx, ny = repeat
    path = folder / f"ahn3_x{nx * ny}.laz"
    with laspy.open(path, mode="w", header=header) as writer:
        for i in range(nx):
            for j in range(ny):
                block = points.copy()
                block["X"] += round(i * width / header.scales[0])
                block["Y"] += round(j * height / header.scales[1])
                writer.write_points(laspy.PackedPointRecord(block, header.point_format))
    return path


def peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _params(method: str):
    from lidarphoto.core.lidar.ground_filter_params import (
        SMRF_PUBLISHED,
        CsfParams,
        GroundFilterParams,
        SmrfParams,
    )

    return {"smrf": SmrfParams(), "smrf_published": SMRF_PUBLISHED, "pmf": GroundFilterParams(),
            "csf": CsfParams()}[method]  # fmt: skip


def _in_units(params, info):
    from lidarphoto.core.jobs.common import lengths_in_cloud_units
    from lidarphoto.core.jobs.ground_filter import HORIZONTAL_LENGTHS, VERTICAL_LENGTHS

    m = params.method
    return lengths_in_cloud_units(params, info, "metre", HORIZONTAL_LENGTHS[m],
                                  VERTICAL_LENGTHS[m])  # fmt: skip


def _csf_package(xyz: np.ndarray, feet: bool) -> tuple[np.ndarray, float]:
    import CSF

    scale = 1.0 / FEET if feet else 1.0
    csf = CSF.CSF()
    csf.params.cloth_resolution *= scale
    csf.params.class_threshold *= scale
    csf.setPointCloud(xyz)
    g, ng = CSF.VecInt(), CSF.VecInt()
    t = time.perf_counter()
    csf.do_filtering(g, ng, exportCloth=False)
    dt = time.perf_counter() - t
    ground = np.zeros(len(xyz), bool)
    ground[np.asarray(g, dtype=np.int64)] = True
    return ground, dt


def worker(task: str, path: str, feet: bool, runs: int) -> dict:
    """One measurement in this process; returns a JSON-able dict."""
    from lidarphoto.core.io.pointcloud import read_points
    from lidarphoto.core.lidar.ground_filter import ground_filter, score_classification

    crs = 7415 if "ahn3" in path else None
    t_wall = time.perf_counter()
    out: dict = {"task": task, "path": path}
    if task == "laspy_io":  # the floor: laspy's own read + write, LAZ to LAZ
        import laspy

        with tempfile.TemporaryDirectory(dir=os.path.dirname(path)) as tmp:
            par = laspy.LazBackend.LazrsParallel  # laspy's default, made explicit
            t, c = time.perf_counter(), time.process_time()
            r0 = resource.getrusage(resource.RUSAGE_SELF)
            las = laspy.read(path, laz_backend=par)
            t1 = time.perf_counter()
            las.write(Path(tmp) / "out.laz", laz_backend=par)
            t2 = time.perf_counter()
            cpu = time.process_time() - c
            r1 = resource.getrusage(resource.RUSAGE_SELF)
        out.update(n=len(las.points), read_s=t1 - t, write_s=t2 - t1, io_s=t2 - t, cpu_s=cpu,
                   user_s=r1.ru_utime - r0.ru_utime, sys_s=r1.ru_stime - r0.ru_stime)  # fmt: skip
    elif task in ("job", "job_numpy"):  # the groundfilter job end to end, LAZ to LAZ
        import cv2  # noqa: F401  (imports the job makes, done before the clock starts as
        import laspy  # laspy is imported before the floor's clock)
        import scipy.ndimage  # noqa: F401
        from lidarphoto.core.jobs import ground_filter as job
        from lidarphoto.core.jobs.runner import run_job

        if task == "job_numpy":  # the numpy back end of the per-point passes (no numba)
            from lidarphoto.core.lidar import ground_filter as gf

            if hasattr(gf, "_use_numba"):
                gf._use_numba = lambda backend: False
        with tempfile.TemporaryDirectory(dir=os.path.dirname(path)) as tmp:
            raw = {"INPUT": path, "OUTPUT_CLOUD": str(Path(tmp) / "out.laz"),
                   "DISTANCE_UNIT": "metre", "CRS": "EPSG:7415" if crs else None}  # fmt: skip
            t, c = time.perf_counter(), time.process_time()
            r0 = resource.getrusage(resource.RUSAGE_SELF)
            res = run_job(job, raw)
            out["io_s"], out["cpu_s"] = time.perf_counter() - t, time.process_time() - c
            r1 = resource.getrusage(resource.RUSAGE_SELF)
            out["user_s"], out["sys_s"] = r1.ru_utime - r0.ru_utime, r1.ru_stime - r0.ru_stime
            # the classes written, for the bit-identity check across runs and versions
            classes = laspy.read(Path(tmp) / "out.laz").classification
            out["classes_sha1"] = hashlib.sha1(np.asarray(classes).tobytes()).hexdigest()
        out.update(n=res.results["POINT_COUNT"], ground=res.results["GROUND_COUNT"])
    elif task.startswith("alg_"):
        method = task[4:]
        t = time.perf_counter()
        arrays, info = read_points(path, FIELDS, crs=crs)
        out["read_s"] = time.perf_counter() - t
        n = len(arrays["x"])
        ref = arrays["classification"] == 2
        if method == "csf_package":
            xyz = np.column_stack([arrays["x"], arrays["y"], arrays["z"]])
            times = []
            for _ in range(runs):
                ground, dt = _csf_package(xyz, feet)
                times.append(dt)
        else:
            params = _in_units(_params(method), info)
            times, cpus = [], []
            for _ in range(runs):
                t, c = time.perf_counter(), time.process_time()
                r = ground_filter(arrays["x"], arrays["y"], arrays["z"], params,
                                  return_number=arrays["return_number"],
                                  number_of_returns=arrays["number_of_returns"],
                                  unit_to_metre=info.unit_to_metre,
                                  vertical_unit_to_metre=info.vertical_unit_to_metre,
                                  unit=info.horizontal_unit)  # fmt: skip
                times.append(time.perf_counter() - t)
                cpus.append(time.process_time() - c)
            ground = r.ground
            out["cpu_s"] = statistics.median(cpus)
        out.update(n=n, alg_s=statistics.median(times), times=times,
                   ground_pct=100.0 * ground.mean())  # fmt: skip
        if ref.any():
            s = score_classification(ground, ref).as_percent()
            out["score"] = {k: round(v, 2) for k, v in s.items()}
    else:
        raise SystemExit(f"unknown task {task}")
    out["wall_s"] = time.perf_counter() - t_wall
    out["peak_rss_mb"] = peak_rss_mb()
    return out


def run_worker(task: str, path: Path, feet: bool = False, runs: int = 1,
               pythonpath: str = "") -> dict:  # fmt: skip
    """One measurement in a new process (``pythonpath``: another copy of the project)."""
    cmd = [sys.executable, __file__, "--worker", task, str(path), str(int(feet)), str(runs)]
    env = {**os.environ, "PYTHONPATH": pythonpath} if pythonpath else None
    load = os.getloadavg()[0]
    t = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True, check=False, env=env)
    if r.returncode:
        sys.stderr.write(r.stderr[-3000:])
        return {"task": task, "path": str(path), "error": r.stderr[-300:]}
    res = json.loads(r.stdout.strip().splitlines()[-1])
    res["process_s"] = time.perf_counter() - t
    res["load_1min"] = [load, os.getloadavg()[0]]  # before and after
    if pythonpath:
        res["task"] = task + "_before"
    print(json.dumps(res), file=sys.stderr, flush=True)
    return res


def synthetic_table() -> dict:
    """Total error (%) per terrain class and method (3 densities each), and the CSF package."""
    from dataclasses import replace

    from lidarphoto.core.lidar.ground_filter import ground_filter, score_classification
    from lidarphoto.core.simulation.terrain import TERRAIN_CLASSES, make_terrain

    configs = {m: _params(m) for m in METHODS}
    configs["smrf_published_no_prefilter"] = replace(_params("smrf_published"),
                                                     low_outlier_height=0)  # fmt: skip
    table: dict = {name: {} for name in [*configs, "csf_package"]}
    agree = []
    for cls in TERRAIN_CLASSES:
        for density, seed in ((0.7, 10), (2.0, 11), (6.0, 12)):
            scene = make_terrain(cls, density=density, seed=seed)
            x, y, z = scene.xyz.T
            for name, params in configs.items():
                g = ground_filter(x, y, z, params).ground
                table[name].setdefault(cls, []).append(
                    100 * score_classification(g, scene.ground).total
                )
                if name == "csf":
                    ours = g
            try:
                g, _ = _csf_package(scene.xyz, False)
                table["csf_package"].setdefault(cls, []).append(
                    100 * score_classification(g, scene.ground).total
                )
                agree.append(float(np.mean(g == ours)))
            except ImportError:
                pass
    out = {name: {cls: float(np.mean(v)) for cls, v in t.items()} for name, t in table.items()}
    out["csf_agreement_pct"] = 100 * float(np.mean(agree)) if agree else None
    return out


def isprs_table() -> dict:
    from lidarphoto.core.io.pointcloud import read_points
    from lidarphoto.core.lidar.ground_filter import ground_filter, score_classification

    out: dict = {}
    for sample in ("samp11", "samp12", "samp51"):
        a, _ = read_points(ISPRS / f"{sample}.laz", ("x", "y", "z", "classification"))
        ref = a["classification"] == 2
        for m in METHODS:
            r = ground_filter(a["x"], a["y"], a["z"], _params(m))
            s = score_classification(r.ground, ref).as_percent()
            out.setdefault(m, {})[sample] = {k: round(v, 2) for k, v in s.items()}
        try:
            g, _ = _csf_package(np.column_stack([a["x"], a["y"], a["z"]]), False)
            s = score_classification(g, ref).as_percent()
            out.setdefault("csf_package", {})[sample] = {k: round(v, 2) for k, v in s.items()}
        except ImportError:
            pass
    return out


def openings_micro(path: Path, feet: bool, repeats: int = 3) -> dict:
    """SMRF's 18 disk openings (default windows) of the file's filled minimum grid: OpenCV's
    morphologyEx against the compiled kernel, CPU and wall time of each of ``repeats`` runs,
    alternating; asserts the same bits."""
    from lidarphoto.core.geometry.grid import Grid, fill_nearest
    from lidarphoto.core.io.pointcloud import read_points
    from lidarphoto.core.lidar import ground_filter as gf
    from lidarphoto.core.lidar import ground_filter_morphology as morphology
    from lidarphoto.core.lidar.ground_filter_params import SmrfParams

    arrays, _ = read_points(str(path), ("x", "y", "z"), crs=None if feet else 7415)
    cell = 1.0 / FEET if feet else 1.0
    x, y, z = arrays["x"], arrays["y"], arrays["z"]
    grid = Grid.covering(np.array([x.min(), y.min()]), np.array([x.max(), y.max()]), cell)
    zmin = gf._min_grid(grid, grid.flat_index(x, y).astype(np.int32), (z - z.min()))
    surface = fill_nearest(zmin, np.isfinite(zmin))
    windows, _ = morphology.smrf_windows(SmrfParams(cell_size=cell, max_window=18.0 * cell))
    out: dict = {"grid": list(surface.shape), "windows": windows}
    results = {}
    morphology._opening(surface, windows[-1], "disk", True)  # numba's start-up, not timed
    for _ in range(repeats):
        for name, use in (("opencv", False), ("compiled", True)):
            s = surface
            t, c = time.perf_counter(), time.process_time()
            for w in windows:
                s = morphology._opening(s, w, "disk", use)
            out.setdefault(name, []).append(
                {"wall_s": time.perf_counter() - t, "cpu_s": time.process_time() - c}
            )
            results[name] = s
    assert results["opencv"].tobytes() == results["compiled"].tobytes()
    out["load_1min"] = os.getloadavg()[0]
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--worker", nargs=4)
    ap.add_argument("--quick", action="store_true", help="AHN3 0.85 M only, no 10 M files")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--out", default="")
    ap.add_argument("--e2e-only", action="store_true", help="section 1 only (10 M files)")
    ap.add_argument("--openings", action="store_true",
                    help="only SMRF's openings of Autzen's grid: OpenCV, compiled")  # fmt: skip
    ap.add_argument("--e2e-runs", type=int, default=3, help="end-to-end runs of each tool")
    ap.add_argument(
        "--before", default="", help="PYTHONPATH of an older copy of the project: its job runs too"
    )
    args = ap.parse_args()
    if args.worker:
        task, path, feet, runs = args.worker
        print(json.dumps(worker(task, path, feet == "1", int(runs))))
        return
    if args.openings:
        print(json.dumps(openings_micro(AUTZEN, True, args.runs), indent=1))
        return
    results: dict = {"started": time.strftime("%Y-%m-%d %H:%M"), "load": os.getloadavg()}
    with tempfile.TemporaryDirectory() as tmp:
        files = [] if args.e2e_only else [("AHN3 Delft 0.85 M", build_ahn3(Path(tmp), (1, 1)),
                                           False)]  # fmt: skip
        if not args.quick:
            files.append(("AHN3 x12 10.2 M", build_ahn3(Path(tmp), (3, 4)), False))
            files.append(("Autzen full 10.65 M (ft)", AUTZEN, True))
        rows = []
        for label, path, feet in files:
            # end to end: the floor and our job, twice each, alternating (the machine is shared)
            for _ in range(args.e2e_runs):
                for task in ("laspy_io", "job", "job_numpy"):
                    rows.append({**run_worker(task, path, feet), "label": label})
                if args.before:
                    rows.append(
                        {**run_worker("job", path, feet, pythonpath=args.before), "label": label}
                    )
            # bit-identical classes: every run of the job, both back ends and the older copy
            hashes = {r.get("classes_sha1") for r in rows
                      if r["label"] == label and r["task"].startswith("job")}  # fmt: skip
            assert len(hashes) == 1 and None not in hashes, f"{label}: classes differ: {hashes}"
            for method in () if args.e2e_only else (*METHODS, "csf_package"):
                runs = 1 if method.startswith("csf") else args.runs
                rows.append({**run_worker(f"alg_{method}", path, feet, runs), "label": label})
        results["rows"] = rows
    if not args.e2e_only:
        results["synthetic"] = synthetic_table()
        results["isprs"] = isprs_table()
    results["finished"] = time.strftime("%Y-%m-%d %H:%M")
    text = json.dumps(results, indent=1)
    if args.out:
        Path(args.out).write_text(text)
    print(text)


if __name__ == "__main__":
    main()
