"""Benchmark: roof-plane extraction (lidarphoto) vs Open3D segment_plane (looped) and
detect_planar_patches, on the same clouds in the same run.

    /work/bench-venv/bin/python bench/bench_roof_planes.py [--quick]

Needs: the project's core (pip install -e . in the venv), open3d (pip; Debian libusb-1.0-0).
Clouds: AHN3 Delft (both crops, 848,942 points) and AHN3 repeated 3 x 4 with 10 m gaps
(10,187,304 points; built in memory), 4 tiles for the 1 M -> 10 M scaling; non-ground =
producer class != 2. Each measurement runs in a fresh child process, so its peak RSS
(ru_maxrss) is that tool's alone (reading and tiling included; algorithm time excludes them).
Quality against the producer classes: share of building (6) points in planes and share of
plane points that are building. Prints one JSON line per run; bench/roof_planes.md has the
figures of the last run.
"""

from __future__ import annotations

import json
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
AHN3 = Path(__file__).resolve().parents[2] / "shared" / "data" / "ahn3-delft"
FILES = [AHN3 / "ahn3_cropped_1.laz", AHN3 / "ahn3_cropped_2.laz"]


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
    ng = cls != 2
    return xyz, cls, ng


def quality(cls, pid):
    b = cls == 6
    return float(np.mean(pid[b] >= 0)), float(np.mean(cls[pid >= 0] == 6)) if (
        pid >= 0
    ).any() else 0.0


def child(tool: str, tiles: int, n_planes: int) -> dict:
    xyz, cls, ng = load(tiles)
    pts, c = xyz[ng], cls[ng]
    out = {"tool": tool, "tiles": tiles, "points_in": len(xyz), "points": len(pts)}
    if tool == "lidarphoto":
        sys.path.insert(0, str(HERE.parent.parent))
        from lidarphoto.core.lidar.roof_planes import extract_roof_planes

        t = time.perf_counter()
        res = extract_roof_planes(pts)
        out["alg_s"] = time.perf_counter() - t
        pid = res.plane_id
        out["planes"] = len(res.planes)
        out["median_rms_m"] = float(np.median([p.rms for p in res.planes]))
        out["median_sigma_offset_mm"] = float(
            1000 * np.median([p.rms / np.sqrt(p.n_points) for p in res.planes])
        )
        out["extra"] = "precision per plane: covariance, sigma_d"
    elif tool == "o3d_segment_plane":
        import open3d as o3d

        pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts - pts.min(axis=0)))
        remaining = np.arange(len(pts))
        pid = np.full(len(pts), -1)
        t = time.perf_counter()
        for k in range(n_planes):
            if len(remaining) < 100:
                break
            _, inl = pcd.segment_plane(distance_threshold=0.15, ransac_n=3, num_iterations=1000)
            inl = np.asarray(inl)
            pid[remaining[inl]] = k
            mask = np.ones(len(remaining), bool)
            mask[inl] = False
            remaining = remaining[mask]
            pcd = pcd.select_by_index(inl, invert=True)
        out["alg_s"] = time.perf_counter() - t
        out["planes"] = int(pid.max() + 1)
        out["extra"] = f"loop stopped after {n_planes} planes (no precision)"
    else:
        import open3d as o3d

        pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts - pts.min(axis=0)))
        t = time.perf_counter()
        pcd.estimate_normals()
        t1 = time.perf_counter()
        patches = pcd.detect_planar_patches()
        out["alg_s"] = time.perf_counter() - t
        pid = np.full(len(pts), -1)
        # membership: points inside each oriented box and within 0.15 m of its plane
        for k, box in enumerate(patches):
            idx = np.asarray(box.get_point_indices_within_bounding_box(pcd.points))
            if len(idx):
                free = idx[pid[idx] < 0]
                pid[free] = k
        out["planes"] = len(patches)
        out["extra"] = f"normals {t1 - t:.1f} s + patches {out['alg_s'] - (t1 - t):.1f} s"
    out["building_in_planes"], out["plane_pts_building"] = quality(c, pid)
    out["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return out


def run(tool, tiles, n_planes=0):
    r = subprocess.run(
        [sys.executable, __file__, "--child", tool, str(tiles), str(n_planes)],
        capture_output=True,
        text=True,
        check=True,
    )
    res = json.loads(r.stdout.strip().splitlines()[-1])
    print(res, flush=True)
    return res


def main() -> int:
    if sys.argv[1:2] == ["--child"]:
        print(json.dumps(child(sys.argv[2], int(sys.argv[3]), int(sys.argv[4]))))
        return 0
    quick = "--quick" in sys.argv
    rows = [run("lidarphoto", 1), run("lidarphoto", 4)]
    if not quick:
        rows.append(run("lidarphoto", 12))
    rows += [run("o3d_segment_plane", 1, 20), run("o3d_detect_planar_patches", 1)]
    if not quick:
        rows += [run("o3d_segment_plane", 12, 5), run("o3d_detect_planar_patches", 12)]
    print(json.dumps(rows, indent=1))  # the lead copies the figures into roof_planes.md
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
