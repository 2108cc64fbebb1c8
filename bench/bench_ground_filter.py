"""Benchmark of the ground filter against CSF (run here) and PDAL (figures from PEERS.md).

    /work/bench-venv/bin/python bench/bench_ground_filter.py [--quick] [--csf-runs 1]

Each (tool, file) measurement runs in its own process so that its peak RSS is its own. Data:
AHN3 Delft (both crops merged, 0.85 M points), the same repeated 3 x 4 times with 10 m gaps
(10.2 M points, built in a temporary folder, never committed), Autzen full (10.65 M points,
international feet), and the ISPRS samples for accuracy. Prints a markdown report.
"""

from __future__ import annotations

import argparse
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


def worker(tool: str, path: str, feet: bool, runs: int) -> dict:
    """One measurement in this process; returns a JSON-able dict."""
    from lidarphoto.core.io.pointcloud import read_points, write_cloud
    from lidarphoto.core.jobs.common import lengths_in_cloud_units
    from lidarphoto.core.jobs.ground_filter import HORIZONTAL_LENGTHS, VERTICAL_LENGTHS
    from lidarphoto.core.lidar.ground_filter import (
        GroundFilterParams,
        ground_filter,
        score_classification,
    )

    t_wall = time.perf_counter()
    out: dict = {"tool": tool, "path": path}
    if tool == "laspy":
        import laspy

        times = []
        for _ in range(runs):
            t = time.perf_counter()
            las = laspy.read(path)
            _ = las.x, las.y, las.z
            times.append(time.perf_counter() - t)
            n = len(las.points)
            del las
        out.update(n=n, alg_s=statistics.median(times), times=times)
        t = time.perf_counter()
        arrays, _ = read_points(path, ("x", "y", "z"), crs=7415 if "ahn3" in path else None)
        out["chunked_read_s"] = time.perf_counter() - t
    else:
        crs = 7415 if "ahn3" in path else None
        t = time.perf_counter()
        arrays, info = read_points(path, FIELDS, crs=crs)
        out["read_s"] = time.perf_counter() - t
        n = len(arrays["x"])
        ref = arrays["classification"] == 2
        if tool == "ours":
            params = lengths_in_cloud_units(
                GroundFilterParams(), info, "metre", HORIZONTAL_LENGTHS, VERTICAL_LENGTHS
            )
            times = []
            for _ in range(runs):
                t = time.perf_counter()
                r = ground_filter(
                    arrays["x"],
                    arrays["y"],
                    arrays["z"],
                    params,
                    return_number=arrays["return_number"],
                    number_of_returns=arrays["number_of_returns"],
                    unit_to_metre=info.unit_to_metre,
                    vertical_unit_to_metre=info.vertical_unit_to_metre,
                    unit=info.horizontal_unit,
                )
                times.append(time.perf_counter() - t)
            ground = r.ground
            with tempfile.TemporaryDirectory(dir=os.path.dirname(path)) as tmp:
                cls = arrays["classification"].copy()
                cls[ground] = 2
                t = time.perf_counter()
                write_cloud(
                    path,
                    Path(tmp) / "out.laz",
                    classification=cls,
                    extra={"height_above_ground": r.height_above_ground},
                )
                out["write_s"] = time.perf_counter() - t
        elif tool == "csf":
            import CSF

            scale = 1.0 / FEET if feet else 1.0
            csf = CSF.CSF()
            csf.params.cloth_resolution *= scale
            csf.params.class_threshold *= scale
            xyz = np.column_stack([arrays["x"], arrays["y"], arrays["z"]])
            times = []
            for _ in range(runs):
                csf = CSF.CSF()
                csf.params.cloth_resolution *= scale
                csf.params.class_threshold *= scale
                csf.setPointCloud(xyz)
                g, ng = CSF.VecInt(), CSF.VecInt()
                t = time.perf_counter()
                csf.do_filtering(g, ng, exportCloth=False)
                times.append(time.perf_counter() - t)
            ground = np.zeros(n, bool)
            ground[np.asarray(g, dtype=np.int64)] = True
        else:
            raise SystemExit(f"unknown tool {tool}")
        out.update(n=n, alg_s=statistics.median(times), times=times)
        out["ground_pct"] = 100.0 * ground.mean()
        if ref.any():
            s = score_classification(ground, ref).as_percent()
            out["score"] = {k: round(v, 2) for k, v in s.items()}
            out["ref_ground_pct"] = 100.0 * ref.mean()
    out["wall_s"] = time.perf_counter() - t_wall
    out["peak_rss_mb"] = peak_rss_mb()
    return out


def run_worker(tool: str, path: Path, feet: bool, runs: int) -> dict:
    cmd = [sys.executable, __file__, "--worker", tool, str(path), str(int(feet)), str(runs)]
    r = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if r.returncode:
        sys.stderr.write(r.stderr[-3000:])
        return {"tool": tool, "path": str(path), "error": r.stderr[-300:]}
    return json.loads(r.stdout.strip().splitlines()[-1])


def isprs_table() -> list[str]:
    from lidarphoto.core.io.pointcloud import read_points
    from lidarphoto.core.lidar.ground_filter import ground_filter, score_classification

    smrf = {"samp11": 9.9, "samp12": 3.15, "samp51": 5.58}
    pmf = {"samp11": 17.16, "samp12": 5.88, "samp51": 6.95}
    csf = {"samp11": 38.23, "samp12": 7.53, "samp51": 18.73}
    rows = [
        "| sample | T1 % | T2 % | total % | kappa % | SMRF total % | PDAL PMF total % "
        "| CSF total % |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    totals = []
    for name in smrf:
        a, _ = read_points(ISPRS / f"{name}.laz", ("x", "y", "z", "classification"))
        r = ground_filter(a["x"], a["y"], a["z"])
        s = score_classification(r.ground, a["classification"] == 2).as_percent()
        totals.append(s["total"])
        rows.append(
            f"| {name} | {s['type1']:.2f} | {s['type2']:.2f} | {s['total']:.2f} | "
            f"{s['kappa']:.2f} | {smrf[name]} | {pmf[name]} | {csf[name]} |"
        )
    rows.append(
        f"| mean | | | {np.mean(totals):.2f} | | {np.mean(list(smrf.values())):.2f} | "
        f"{np.mean(list(pmf.values())):.2f} | {np.mean(list(csf.values())):.2f} |"
    )
    return rows


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--worker", nargs=4)
    ap.add_argument("--quick", action="store_true", help="AHN3 0.85 M only")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--csf-runs", type=int, default=1)
    args = ap.parse_args()
    if args.worker:
        tool, path, feet, runs = args.worker
        print(json.dumps(worker(tool, path, feet == "1", int(runs))))
        return
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        files = [("AHN3 Delft 0.85 M", build_ahn3(Path(tmp), (1, 1)), False)]
        if not args.quick:
            files.append(("AHN3 x12 10.2 M", build_ahn3(Path(tmp), (3, 4)), False))
            files.append(("Autzen full 10.65 M (ft)", AUTZEN, True))
        for label, path, feet in files:
            for tool, runs in (("laspy", args.runs), ("ours", args.runs), ("csf", args.csf_runs)):
                r = run_worker(tool, path, feet, runs)
                r["label"] = label
                results.append(r)
                print(json.dumps(r), file=sys.stderr, flush=True)
    print(
        "| tool | data | points | alg s (median) | points/s | read s | wall s | peak RSS MB | "
        "result |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in results:
        if "error" in r:
            print(f"| {r['tool']} | {r['label']} | error | | | | | | {r['error'][:80]} |")
            continue
        score = r.get("score")
        res = f"ground {r.get('ground_pct', 0):.2f} %"
        if score:
            res += (
                f"; agree {score['agreement']} %; T1 {score['type1']} %; T2 {score['type2']} %;"
                f" kappa {score['kappa']} %"
            )
        if r["tool"] == "laspy":
            res = f"chunked read_points x,y,z {r['chunked_read_s']:.2f} s"
        print(
            f"| {r['tool']} | {r['label']} | {r['n']:,} | {r['alg_s']:.3f} | "
            f"{r['n'] / r['alg_s']:,.0f} | {r.get('read_s', r['alg_s']):.2f} | "
            f"{r['wall_s']:.2f} | {r['peak_rss_mb']:.0f} | {res} |"
        )
    print()
    print("\n".join(isprs_table()))


if __name__ == "__main__":
    main()
