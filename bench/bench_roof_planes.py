"""Benchmark: roof-plane extraction (lidarphoto, this tree), the same before issue 20 (the
``main`` branch's implementation, for "the same planes"), Open3D's segment_plane (looped) and
detect_planar_patches, on the same clouds in the same run, on one core.

    python bench/bench_roof_planes.py [--quick] [--before PKG_DIR] [--out results.json]

Needs the project's core importable as ``lidarphoto`` (PYTHONPATH) and open3d (pip; Debian
libusb-1.0-0) in the same venv. ``--before`` is a folder holding an older ``lidarphoto`` package
(e.g. ``git archive main`` extracted into ``DIR/lidarphoto``); without it the comparison with
the former implementation is skipped. Every child runs with OMP/OpenBLAS/numba on one thread.

Clouds: AHN3 Delft (both crops, 848,942 points) and the same repeated 3 x 4 with 10 m gaps
(10,187,304 points; in memory for the algorithm rows, as a LAZ file for the job row). Non-ground
= producer class != 2. Each measurement runs in a fresh child process, so its peak RSS
(ru_maxrss) is that tool's alone (reading and tiling included; "alg s" excludes them and
numba's one-off compilation, timed apart as "jit s"; "cpu s" is the process's CPU time, the
figure that holds on a shared machine). Quality against the producer classes:
share of building (6) points in planes and share of plane points that are building.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

AHN3 = Path(__file__).resolve().parents[2] / "shared" / "data" / "ahn3-delft"
FILES = [AHN3 / "ahn3_cropped_1.laz", AHN3 / "ahn3_cropped_2.laz"]
ONE_CORE = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
            "NUMBA_NUM_THREADS": "1"}  # fmt: skip


def load(tiles: int):
    import laspy

    xs, cs = [], []
    for f in FILES:
        las = laspy.read(str(f))
        xs.append(np.column_stack([las.x, las.y, las.z]))
        cs.append(np.asarray(las.classification))
    xyz, cls = np.concatenate(xs), np.concatenate(cs)
    if tiles > 1:
        span = xyz.max(axis=0)[:2] - xyz.min(axis=0)[:2] + 10.0
        parts = [xyz + [span[0] * (k % 3), span[1] * (k // 3), 0.0] for k in range(tiles)]
        xyz, cls = np.concatenate(parts), np.tile(cls, tiles)
    return xyz, cls


def write_tiles(path: Path, tiles: int) -> None:
    """The tiled cloud as LAZ (EPSG:7415), as the user would have it on disk."""
    import laspy
    import pyproj

    parts = [laspy.read(str(p)) for p in FILES]
    points = np.concatenate([p.points.array for p in parts])
    header = laspy.LasHeader(point_format=parts[0].header.point_format, version="1.2")
    header.scales, header.offsets = parts[0].header.scales, parts[0].header.offsets
    header.add_crs(pyproj.CRS.from_epsg(7415))
    x, y = points["X"] * header.scales[0], points["Y"] * header.scales[1]
    span = (x.max() - x.min() + 10.0, y.max() - y.min() + 10.0)
    with laspy.open(path, mode="w", header=header) as writer:
        for k in range(tiles):
            block = points.copy()
            block["X"] += round(span[0] * (k % 3) / header.scales[0])
            block["Y"] += round(span[1] * (k // 3) / header.scales[1])
            record = laspy.ScaleAwarePointRecord(block, header.point_format, header.scales,
                                                 header.offsets)  # fmt: skip
            writer.write_points(record)


def quality(cls, pid):
    b = cls == 6
    inside = pid >= 0
    return float(np.mean(inside[b])), float(np.mean(cls[inside] == 6)) if inside.any() else 0.0


def child(tool: str, tiles: int, n_planes: int, save: str) -> dict:
    out: dict = {"tool": tool, "tiles": tiles}
    if tool == "job":  # read LAZ -> planes -> CSV table, what the user waits for
        from lidarphoto.core.jobs import extract_roof_planes as job
        from lidarphoto.core.jobs.runner import run_job
        from lidarphoto.core.lidar.roof_planes import extract_roof_planes

        extract_roof_planes(np.random.default_rng(0).normal(size=(2000, 3)))  # compiled/cached
        with tempfile.TemporaryDirectory() as tmp:
            src = Path(tmp) / "tiles.laz"
            write_tiles(src, tiles)
            t, c = time.perf_counter(), time.process_time()
            res = run_job(job, {"INPUT": str(src), "OUTPUT_CSV": str(Path(tmp) / "planes.csv")})
            out["job_s"], out["job_cpu_s"] = time.perf_counter() - t, time.process_time() - c
        out["planes"] = int(res.results["PLANE_COUNT"])
        out["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        return out
    xyz, cls = load(tiles)
    ng = cls != 2
    pts, c = xyz[ng], cls[ng]
    del xyz
    out.update(points=len(pts))
    if tool in ("lidarphoto", "before"):
        from lidarphoto.core.lidar.roof_planes import extract_roof_planes

        t = time.perf_counter()
        extract_roof_planes(np.random.default_rng(0).normal(size=(2000, 3)))
        out["jit_s"] = time.perf_counter() - t  # numba's compilation (or cache load)
        t, cpu = time.perf_counter(), time.process_time()
        res = extract_roof_planes(pts)
        out["alg_s"], out["cpu_s"] = time.perf_counter() - t, time.process_time() - cpu
        pid = res.plane_id
        out["planes"] = len(res.planes)
        out["median_rms_m"] = float(np.median([p.rms for p in res.planes]))
        # precision at the centroid (sigma_d in map coordinates is mostly the normal's lever)
        out["median_sigma_offset_mm"] = float(
            1000 * np.median([p.rms / np.sqrt(p.n_points) for p in res.planes])
        )
        out["median_sigma_normal_mrad"] = float(
            1000 * np.median([np.sqrt(np.trace(p.covariance[:3, :3])) for p in res.planes])
        )
        if save:
            normals = np.array([p.normal for p in res.planes])
            sig = np.sqrt([np.trace(p.covariance[:3, :3]) for p in res.planes])
            np.savez(save, plane_id=pid, normals=normals, sigma=sig,
                     n=np.array([p.n_points for p in res.planes]))  # fmt: skip
    elif tool == "o3d_segment_plane":
        import open3d as o3d

        pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts - pts.min(axis=0)))
        remaining = np.arange(len(pts))
        pid = np.full(len(pts), -1)
        t, cpu = time.perf_counter(), time.process_time()
        for k in range(n_planes):
            _, inl = pcd.segment_plane(distance_threshold=0.15, ransac_n=3, num_iterations=1000)
            inl = np.asarray(inl)
            pid[remaining[inl]] = k
            keep = np.ones(len(remaining), bool)
            keep[inl] = False
            remaining = remaining[keep]
            pcd = pcd.select_by_index(inl, invert=True)
        out["alg_s"], out["cpu_s"] = time.perf_counter() - t, time.process_time() - cpu
        out["planes"] = int(pid.max() + 1)
    else:
        import open3d as o3d

        pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts - pts.min(axis=0)))
        t, cpu = time.perf_counter(), time.process_time()
        pcd.estimate_normals()
        t1 = time.perf_counter()
        patches = pcd.detect_planar_patches()
        out["alg_s"], out["cpu_s"] = time.perf_counter() - t, time.process_time() - cpu
        out["normals_s"] = t1 - t
        pid = np.full(len(pts), -1)
        for k, box in enumerate(patches):  # a patch's points: those inside its oriented box
            idx = np.asarray(box.get_point_indices_within_bounding_box(pcd.points))
            if len(idx):
                pid[idx[pid[idx] < 0]] = k
        out["planes"] = len(patches)
    out["building_in_planes"], out["plane_pts_building"] = quality(c, pid)
    out["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return out


def run(tool, tiles, n_planes=0, save="", pythonpath=""):
    env = {**os.environ, **ONE_CORE}
    if pythonpath:
        env["PYTHONPATH"] = pythonpath
    t = time.perf_counter()
    r = subprocess.run(
        [sys.executable, __file__, "--child", tool, str(tiles), str(n_planes), save or "-"],
        capture_output=True, text=True, check=False, env=env,
    )  # fmt: skip
    if r.returncode:
        sys.stderr.write(r.stderr[-3000:])
        return {"tool": tool, "tiles": tiles, "error": r.stderr[-300:]}
    res = json.loads(r.stdout.strip().splitlines()[-1])
    res["process_s"] = time.perf_counter() - t
    print(json.dumps(res), file=sys.stderr, flush=True)
    return res


def compare(new_path: str, old_path: str) -> dict:
    """The same planes? Plane counts, and for each former plane the new plane sharing most of
    its points: how many find one (>= 50 % of their points shared) and how far their normals
    differ, in units of the new plane's normal sigma (sqrt of the trace of C_nn)."""
    a, b = np.load(new_path), np.load(old_path)
    pa, pb = a["plane_id"], b["plane_id"]
    both = (pa >= 0) & (pb >= 0)
    na, nb = len(a["n"]), len(b["n"])
    pairs = np.bincount(pb[both].astype(np.int64) * na + pa[both], minlength=na * nb)
    pairs = pairs.reshape(nb, na)
    best = pairs.argmax(axis=1)
    shared = pairs[np.arange(nb), best] / np.maximum(np.bincount(pb[pb >= 0], minlength=nb), 1)
    matched = shared >= 0.5
    dn = np.linalg.norm(a["normals"][best] - b["normals"], axis=1)
    ratio = dn / np.maximum(a["sigma"][best], 1e-12)
    ratio = ratio[matched]
    # points in a plane either way whose new plane is the match of their former plane
    agree = (pb >= 0) & (pa == best[pb]) & matched[pb]
    same = 100 * float(agree.sum() / np.sum((pa >= 0) | (pb >= 0)))
    return {"planes_new": na, "planes_before": nb, "count_diff_pct": 100 * (na - nb) / nb,
            "matched_pct": 100 * float(matched.mean()),
            "normal_diff_over_sigma_median": float(np.median(ratio)),
            "normal_diff_within_1_sigma_pct": 100 * float(np.mean(ratio < 1.0)),
            "normal_diff_within_2_sigma_pct": 100 * float(np.mean(ratio < 2.0)),
            "same_points_pct": same}  # fmt: skip


def main() -> int:
    if sys.argv[1:2] == ["--child"]:
        save = "" if sys.argv[5] == "-" else sys.argv[5]
        print(json.dumps(child(sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), save)))
        return 0
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="AHN3 x1 only")
    ap.add_argument("--before", default="", help="folder holding the former lidarphoto package")
    ap.add_argument("--out", default="")
    ap.add_argument("--o3d-small", action="store_true", help="Open3D on AHN3 x1 too")
    args = ap.parse_args()
    results: dict = {"started": time.strftime("%Y-%m-%d %H:%M"), "load": os.getloadavg()}
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        new, old = str(Path(tmp) / "new.npz"), str(Path(tmp) / "old.npz")
        rows.append(run("lidarphoto", 1, save=new))  # "today" = before, same points
        if args.before:
            rows.append(run("before", 1, save=old, pythonpath=args.before))
            results["same_planes_x1"] = compare(new, old)
        if not args.quick:
            rows.append(run("lidarphoto", 12))
            rows.append(run("job", 12))
        if args.quick or args.o3d_small:
            rows += [run("o3d_segment_plane", 1, 5), run("o3d_detect_planar_patches", 1)]
        if not args.quick:
            rows += [run("o3d_segment_plane", 12, 1), run("o3d_detect_planar_patches", 12)]
    results["rows"] = rows
    results["finished"] = time.strftime("%Y-%m-%d %H:%M")
    text = json.dumps(results, indent=1)
    if args.out:
        Path(args.out).write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
