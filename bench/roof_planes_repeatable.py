"""Repeatability of the roof planes (bench/roof_planes.md, "Repeatable planes"): another seed,
the block against the single run, the accuracy on the synthetic town.

    python bench/roof_planes_repeatable.py seeds FILE [--unit U]
    python bench/roof_planes_repeatable.py block FILE TILE_SIZE [--crs EPSG:7415]
    python bench/roof_planes_repeatable.py accuracy [DRAWS]

``seeds``: extraction with seed 0 and 1 on the producer's non-ground points (class != 2) of a
LAS/LAZ file; how many planes of >= 50 points have no counterpart within 0.5 degrees and 2 cm
(``--unit``: CRS units per metre) holding >= 80 % of their points; LCPs of each.
``block``: SMRF on the whole file, the roof planes and control of its non-ground points (the
single run), against the lidarblock job on the same file cut into TILE_SIZE tiles (1 thread
worker); plane tables matched by normal (0.5 degrees), offset (2 cm) and point count (within
20 %). ``accuracy``: the synthetic town of tests/core/test_roof_planes.py drawn DRAWS times
with new noise: how often every face is found once, and the normal and d scatter over their
reported variance. Each prints one JSON line. Run with the tree to measure on PYTHONPATH.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np


def _unmatched(a, b, tol: float) -> tuple[int, int]:
    """Planes of result ``a`` (>= 50 points) without a plane of ``b`` within 0.5 degrees and
    ``tol`` holding >= 80 % of their points (both results on the same points)."""
    big = [p for p in a.planes if p.n_points >= 50]
    bad = 0
    for p in big:
        lab = b.plane_id[a.plane_id == p.id]
        if not (lab >= 0).any():
            bad += 1
            continue
        k = int(np.bincount(lab[lab >= 0]).argmax())
        q = b.planes[k]
        angle = np.degrees(np.arccos(min(1.0, abs(float(p.normal @ q.normal)))))
        off = abs(float(q.distance(p.centroid)[0]))
        bad += not (angle < 0.5 and off < tol and np.mean(lab == k) >= 0.8)
    return len(big), bad


def seeds(path: str, unit: float) -> dict:
    import laspy
    from lidarphoto.core.lidar.control import lidar_control
    from lidarphoto.core.lidar.roof_planes import RoofPlaneParams, extract_roof_planes

    las = laspy.read(path)
    xyz = np.column_stack([las.x, las.y, las.z])[np.asarray(las.classification) != 2]
    res = [extract_roof_planes(xyz, RoofPlaneParams(epsilon=0.15 * unit, seed=s)) for s in (0, 1)]
    big, bad = _unmatched(res[0], res[1], 0.02 * unit)
    lcps = [len(lidar_control(r.planes, xyz, r.plane_id).points) for r in res]
    return {"points": len(xyz), "planes": [len(r.planes) for r in res], "planes_50": big,
            "unmatched": bad, "identical": bool(np.array_equal(res[0].plane_id, res[1].plane_id)),
            "lcps": lcps}  # fmt: skip


def block(path: str, tile: float, crs: str) -> dict:
    import laspy
    from lidarphoto.core.io.planes import read_planes_csv
    from lidarphoto.core.jobs import ground_filter, lidar_block
    from lidarphoto.core.jobs.runner import run_job
    from lidarphoto.core.lidar.control import lidar_control
    from lidarphoto.core.lidar.roof_planes import extract_roof_planes

    tmp = Path(tempfile.mkdtemp())
    run_job(ground_filter, {"INPUT": path, "CRS": crs, "OUTPUT_CLOUD": str(tmp / "g.laz")})
    las = laspy.read(str(tmp / "g.laz"))
    cls = np.asarray(las.classification)
    xyz = np.column_stack([las.x, las.y, las.z])[(cls != 2) & (cls != 7)]
    t = time.process_time()
    ref = extract_roof_planes(xyz)
    ctrl = lidar_control(ref.planes, xyz, ref.plane_id)
    single_cpu = time.process_time() - t
    res = run_job(lidar_block, {"INPUT": path, "CRS": crs, "TILE_SIZE": tile, "WORKERS": 1,
                                "LOCAL_CLUSTER": "threads", "OUTPUT_FOLDER": str(tmp / "b")})
    mine = read_planes_csv(tmp / "b" / "planes.csv")
    normals = np.array([q.normal for q in mine])
    counts = np.array([q.n_points for q in mine], dtype=float)
    big = [p for p in ref.planes if p.n_points >= 50]
    bad = 0
    for p in big:
        angle = np.degrees(np.arccos(np.minimum(1.0, np.abs(normals @ p.normal))))
        off = np.array([abs(float(q.distance(p.centroid)[0])) for q in mine])
        ratio = counts / p.n_points
        bad += not ((angle < 0.5) & (off < 0.02) & (ratio > 0.8) & (ratio < 1.25)).any()
    report = json.loads((tmp / "b" / "block_report.json").read_text())
    return {"tiles": len(report["tiles"]), "planes": [len(ref.planes), len(mine)],
            "planes_50": len(big), "unmatched": bad,
            "lcps": [len(ctrl.points), res.results["LCP_COUNT"]],
            "lines": [len(ctrl.lines), res.results["LINE_COUNT"]],
            "roof_buffer": report["roof_buffer"], "single_planes_control_cpu_s": single_cpu,
            "block_task_cpu_s": sum(t["stage_seconds"].get("cpu", 0.0) for t in report["tiles"])}


def accuracy(draws: int) -> dict:
    from lidarphoto.core.lidar.roof_planes import RoofPlaneParams, extract_roof_planes
    from lidarphoto.core.simulation.town import CLASS_GROUND, make_town, sample_town

    town = make_town(n_buildings=3, roof_types=("gable", "hip", "shed"), n_trees=0, seed=4)
    z2, maha, once = [], [], 0
    for k in range(draws):
        pts = sample_town(town, density=8.0, noise_sigma=0.03, seed=100 + k)
        ng = pts.classification != CLASS_GROUND
        res = extract_roof_planes(pts.xyz[ng], RoofPlaneParams(seed=k))
        fid = pts.face_id[ng]
        face = {}
        for p in res.planes:
            f = fid[res.plane_id == p.id]
            face[p.id] = int(np.bincount(f[f >= 0]).argmax())
        once += sorted(face.values()) == [f.face_id for f in town.faces]
        for p in res.planes:
            truth = town.faces[face[p.id]]
            z2.append(((p.d - truth.d) / p.sigma_d) ** 2)
            u = np.cross(truth.normal, [1.0, 0.0, 0.0])
            u /= np.linalg.norm(u)
            tb = np.column_stack([u, np.cross(truth.normal, u)])
            e = tb.T @ (p.normal - truth.normal)
            maha.append(e @ np.linalg.solve(tb.T @ p.covariance[:3, :3] @ tb, e))
    return {"draws": draws, "every_face_once": once, "planes": len(z2),
            "normal_over_variance": float(np.sum(maha) / (2 * len(maha))),
            "d_over_variance": float(np.mean(z2))}  # fmt: skip


def main() -> int:
    ap = argparse.ArgumentParser()
    sub = ap.add_subparsers(dest="what", required=True)
    s = sub.add_parser("seeds")
    s.add_argument("file")
    s.add_argument("--unit", type=float, default=1.0, help="CRS units per metre")
    b = sub.add_parser("block")
    b.add_argument("file")
    b.add_argument("tile", type=float)
    b.add_argument("--crs", default="EPSG:7415")
    a = sub.add_parser("accuracy")
    a.add_argument("draws", type=int, nargs="?", default=160)
    args = ap.parse_args()
    if args.what == "seeds":
        out = seeds(args.file, args.unit)
    elif args.what == "block":
        out = block(args.file, args.tile, args.crs)
    else:
        out = accuracy(args.draws)
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
