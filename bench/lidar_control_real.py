"""LiDAR control on real clouds (issue 4): ground filter -> roof planes -> LCPs and lines on
AHN3 Delft and Autzen, with counts, sigma distributions and a top-view picture.

Run: .venv/bin/python bench/lidar_control_real.py [out_folder]   (about a minute)
Writes the Markdown table to stdout and ``lidar_control_ahn3.png`` (roof planes coloured,
lines black, LCPs red with their error ellipses enlarged 100 x) into the output folder.
"""

from __future__ import annotations

import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

import cv2
import numpy as np
from lidarphoto.core.io.planes import read_planes_csv
from lidarphoto.core.io.pointcloud import read_points
from lidarphoto.core.jobs import create_lcps, extract_roof_planes, ground_filter
from lidarphoto.core.jobs.runner import run_job
from scipy.ndimage import grey_dilation

SHARED = Path(__file__).resolve().parents[2] / "shared" / "data"
CLOUDS = (
    ("AHN3 Delft tile 1", SHARED / "ahn3-delft" / "ahn3_cropped_1.laz", "EPSG:7415", "crs"),
    ("AHN3 Delft tile 2", SHARED / "ahn3-delft" / "ahn3_cropped_2.laz", "EPSG:7415", "crs"),
    ("Autzen trim (ft)", SHARED / "autzen-trim" / "autzen_trim.laz", None, "metre"),
)


def _reason(text: str) -> str:
    for key in ("nearly parallel", "line rather than a point", "from the points", "same corner",
                "no common boundary", "fewer than"):  # fmt: skip
        if key in text:
            return key
    return text[:30]


def run(name: str, path: Path, crs, unit: str, work: Path):
    t0 = time.perf_counter()
    run_job(ground_filter, {"INPUT": str(path), "OUTPUT_CLOUD": work / "ground.laz", "CRS": crs})
    run_job(extract_roof_planes, {
        "INPUT": str(work / "ground.laz"), "DISTANCE_UNIT": unit, "CRS": crs,
        "OUTPUT_CSV": work / "planes.csv", "OUTPUT_CLOUD": work / "planes.laz",
    })  # fmt: skip
    result, info = run_job(create_lcps, {
        "PLANES": str(work / "planes.csv"), "CLOUD": str(work / "planes.laz"), "CRS": crs,
        "DISTANCE_UNIT": unit,
    }).data  # fmt: skip
    seconds = time.perf_counter() - t0
    planes = read_planes_csv(work / "planes.csv")
    return result, info, planes, seconds


def picture(result, work: Path, out: Path, size_m: float = 70.0, px_per_m: float = 12.0) -> str:
    """Top view of the densest block of LCPs; returns a one-line description."""
    arrays, _ = read_points(work / "planes.laz", ("x", "y", "z", "plane_id"), crs="EPSG:7415")
    xyz = np.column_stack([arrays["x"], arrays["y"]])
    lcp = np.array([p.xyz for p in result.points])
    centre = lcp[np.argmax([np.sum(np.linalg.norm(lcp - p, axis=1) < size_m / 2) for p in lcp])]
    lo = centre[:2] - size_m / 2
    n = int(size_m * px_per_m)
    rng = np.random.default_rng(0)
    colours = rng.integers(90, 235, (int(arrays["plane_id"].max()) + 2, 3)).astype(np.uint8)
    colours[-1] = 255  # background
    inside = np.all((xyz >= lo) & (xyz < lo + size_m), axis=1) & (arrays["plane_id"] >= 0)
    pix = ((xyz[inside] - lo) * px_per_m).astype(int)
    labels = np.full((n, n), -1, np.int32)
    labels[n - 1 - pix[:, 1], pix[:, 0]] = arrays["plane_id"][inside]
    # points are ~0.27 m apart: grow each one to fill its neighbourhood (max label wins)
    labels = grey_dilation(labels, size=(5, 5))
    img = np.ascontiguousarray(colours[labels])

    def to_px(p):
        q = (np.asarray(p[:2]) - lo) * px_per_m
        return int(q[0]), int(n - 1 - q[1])

    shown_lines = 0
    for ln in result.lines:
        a, b = to_px(ln.start), to_px(ln.end)
        if 0 <= a[0] < n and 0 <= a[1] < n:
            cv2.line(img, a, b, (0, 0, 0), 2, cv2.LINE_AA)
            shown_lines += 1
    shown = 0
    for p in result.points:
        c = to_px(p.xyz)
        if not (0 <= c[0] < n and 0 <= c[1] < n):
            continue
        shown += 1
        w, v = np.linalg.eigh(p.covariance[:2, :2])
        axes = (
            int(max(2, 100 * px_per_m * np.sqrt(w[1]))),
            int(max(2, 100 * px_per_m * np.sqrt(w[0]))),
        )
        angle = -np.degrees(np.arctan2(v[1, 1], v[0, 1]))
        cv2.ellipse(img, c, axes, angle, 0, 360, (0, 0, 255), 2, cv2.LINE_AA)
        cv2.drawMarker(img, c, (0, 0, 255), cv2.MARKER_CROSS, 14, 2)
    cv2.imwrite(str(out), img)
    return (f"{size_m:.0f} m x {size_m:.0f} m around ({centre[0]:.1f}, {centre[1]:.1f}): "
            f"{shown} LCPs and {shown_lines} lines drawn")  # fmt: skip


def main() -> None:
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent
    print("| cloud | points | planes | adjacent pairs | LCPs | lines (ridge/hip/valley/other) "
          "| LCP sigma X, Y, Z median [p10-p90] | line sigma across median [p10-p90] "
          "| main rejection reasons | s |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, path, crs, unit in CLOUDS:
        with tempfile.TemporaryDirectory() as tmp:
            work = Path(tmp)
            result, info, planes, seconds = run(name, path, crs, unit, work)
            kinds = Counter(ln.kind for ln in result.lines)
            u = "ft" if "foot" in info.horizontal_unit else "m"
            if result.points:
                s = np.array([p.sigma for p in result.points])
                lcp = (
                    ", ".join(
                        f"{np.median(s[:, k]):.3f} [{np.percentile(s[:, k], 10):.3f}-"
                        f"{np.percentile(s[:, k], 90):.3f}]"
                        for k in range(3)
                    )
                    + f" {u}"
                )
            else:
                lcp = "-"
            if result.lines:
                s = np.array([ln.sigma_perpendicular for ln in result.lines])
                line = (f"{np.median(s):.3f} [{np.percentile(s, 10):.3f}-"
                        f"{np.percentile(s, 90):.3f}] {u}")  # fmt: skip
            else:
                line = "-"
            reasons = Counter(_reason(r.reason) for r in result.rejected).most_common(3)
            print(
                f"| {name} | {info.point_count:,} | {len(planes)} | "
                f"{int(result.adjacency.adjacent.sum())} | {len(result.points)} | "
                f"{len(result.lines)} ({kinds['ridge']}/{kinds['hip']}/{kinds['valley']}/"
                f"{kinds['other']}) | {lcp} | {line} | "
                f"{'; '.join(f'{k} {v}' for k, v in reasons) or '-'} | {seconds:.1f} |",
                flush=True,
            )
            if name == "AHN3 Delft tile 1" and result.points:
                text = picture(result, work, out / "lidar_control_ahn3.png")
                print(f"\npicture ({out / 'lidar_control_ahn3.png'}): {text}\n")


if __name__ == "__main__":
    main()
