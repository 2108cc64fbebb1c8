"""Roof planes of a LiDAR block against the single run (issue 33): a cloud's non-ground points
(the producer's classes) cut into n x n equal tiles, each with the buffer of
``core.lidar.block.roof_buffer``, merged (``merge_cut_planes``) with and without the second
pass of the cut regions (``core.lidar.block_cut.second_pass``).

Per case: planes (single, block); planes of >= 50 points matched (a block plane within 0.5
degrees and 2 cm of it, holding >= 80 % of its points); planes reproduced with exactly the
same points; LCPs (single, block); CPU seconds of the block.

    PYTHONPATH=<folder holding lidarphoto> python bench/roof_planes_block.py autzen
    PYTHONPATH=... python bench/roof_planes_block.py ahn3
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
FT = 0.3048  # international foot, m


def load(name: str):
    """Non-ground points, all-point count, unit in metres."""
    import laspy

    files = {"autzen": [DATA / "autzen-trim" / "autzen_trim.laz"],
             "ahn3": [DATA / "ahn3-delft" / f"ahn3_cropped_{k}.laz" for k in (1, 2)]}[name]
    parts = []
    for f in files:
        las = laspy.read(str(f))
        parts.append((np.column_stack([las.x, las.y, las.z]), np.asarray(las.classification)))
    xyz = np.concatenate([p[0] for p in parts])
    ng = np.concatenate([p[1] for p in parts]) != 2
    return xyz[ng], len(xyz), FT if name == "autzen" else 1.0


def compare(xyz, ref, merged, metre: float) -> dict:
    """Matching figures of a block against the single run."""
    from lidarphoto.core.lidar.control import lidar_control

    pid = np.full(len(xyz), -1)
    for k, m in enumerate(merged):
        pid[m.ids] = k
    sizes = np.bincount(ref.plane_id[ref.plane_id >= 0], minlength=len(ref.planes))
    big = np.flatnonzero(sizes >= 50)
    matched = exact = 0
    bad = []
    for p in big:
        m = ref.plane_id == p
        lab = pid[m]
        if not (lab >= 0).any():
            bad.append(int(p))
            continue
        k = int(np.bincount(lab[lab >= 0]).argmax())
        share = float(np.mean(lab == k))
        a, b = ref.planes[p], merged[k].plane
        angle = float(np.degrees(np.arccos(min(1.0, abs(float(a.normal @ b.normal))))))
        off = abs(float(b.distance(a.centroid)[0])) * metre
        ok = angle < 0.5 and off < 0.02 and share >= 0.8
        matched += ok
        exact += bool(share == 1.0 and (pid == k).sum() == m.sum())
        if not ok:
            bad.append((int(p), int(sizes[p]), round(angle, 3), round(off, 4), round(share, 3)))
    whole = lidar_control(ref.planes, xyz, ref.plane_id)
    block = lidar_control([m.plane for m in merged], xyz, pid)
    return {"planes": [len(ref.planes), len(merged)], "big": len(big), "matched": matched,
            "exact": exact, "lcps": [len(whole.points), len(block.points)],
            "lines": [len(whole.lines), len(block.lines)], "unmatched": bad[:12]}  # fmt: skip


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("cloud", choices=["autzen", "ahn3"])
    ap.add_argument("--tiles", type=int, nargs="+", default=[2, 3])
    ap.add_argument("--out", default="")
    a = ap.parse_args()
    from lidarphoto.core.lidar.block import roof_buffer
    from lidarphoto.core.lidar.block_cut import tiled_planes
    from lidarphoto.core.lidar.roof_planes import RoofPlaneParams, extract_roof_planes

    xyz, n_all, metre = load(a.cloud)
    params = RoofPlaneParams(epsilon=0.15 / metre)
    t = time.process_time()
    ref = extract_roof_planes(xyz, params)
    out = {"cloud": a.cloud, "points": len(xyz), "single_cpu_s": time.process_time() - t}
    lo, hi = xyz[:, :2].min(axis=0), xyz[:, :2].max(axis=0)
    spacing = float(np.sqrt(np.prod(hi - lo) / n_all))
    buf = roof_buffer(params.k_neighbours, spacing)
    out["buffer"] = buf
    for n in a.tiles:
        edges = [lo + (hi - lo) * k / n for k in range(n + 1)]
        edges[-1] = np.nextafter(hi, np.inf)
        xs, ys = [float(e[0]) for e in edges], [float(e[1]) for e in edges]
        for whole in (False, True):
            t = time.process_time()
            merged, n_pieces = tiled_planes(xyz, xs, ys, params, buf, whole=whole)
            cpu = time.process_time() - t
            fig = compare(xyz, ref, merged, metre)
            fig.update({"pieces": n_pieces, "cpu_s": round(cpu, 2)})
            out[f"{n}x{n}{' second pass' if whole else ''}"] = fig
            print(n, whole, json.dumps(fig), flush=True)
    if a.out:
        Path(a.out).write_text(json.dumps(out, indent=1))
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
