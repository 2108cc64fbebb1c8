"""Benchmark: orthorectification (lidarphoto:orthorectify) against orthority, on the same images,
orientation and DEM, with the same output grid, resampling and file settings; and the exact case
of tests/core/test_orthophoto.py.

Run (figures in bench/ortho.md)::

    python3 -m venv /tmp/orthority-venv && /tmp/orthority-venv/bin/pip install orthority==0.7.0
    .venv/bin/python bench/bench_ortho.py --orthority-python /tmp/orthority-venv/bin/python
    .venv/bin/python bench/bench_ortho.py --set --orthority-python /tmp/orthority-venv/bin/python
    .venv/bin/python bench/bench_ortho.py --large

orthority (pip package, GPL/AGPL-free peer by Dugal Harris) lives in its own throw-away venv: it
needs ``opencv-python``, which clashes with our ``opencv-python-headless``; each run of either
tool is a fresh process (timing from its first call to the closed file, imports excluded; peak
memory: the process's VmHWM, its largest resident set since it started).

Data: the demo's rendered images (``make demo``: 10 frames of 6000 x 4000 px, 8-bit RGB, LZW,
camera 130 m above the AHN3 Delft tile, GSD 1.67 cm), their true orientation (the images are
rendered with it) and the LiDAR DSM (0.5 m, GeoTIFF). With ``--demo DIR`` missing, the demo's
steps are run into it first.

Equal output: orthority with ``aligned_pixels`` at GSD 1/64 m (0.015625, binary-exact: both
tools put their cells on the same multiples), bilinear resampling of the image and of the DEM,
internal mask, overviews, and our GeoTIFF creation options (tiled 512, DEFLATE level 1 with
predictor 2, pixel interleave, RGB, NUM_THREADS); ours on orthority's exact extent. At
1/64 m a cell is smaller than an image pixel (1.67 cm): no averaged reads on our side.
Agreement where both have data: RMS of the differences (DN) and the shift between the two by
phase correlation on 256 x 256 windows of flat ground (core.quality.registration;
magnitude-weighted, and whitened).
The camera models are first compared point by point (orthority's world_to_pixel against
collinearity in our local ENU frame).
"""

from __future__ import annotations

import argparse
import csv
import datetime
import importlib.util
import json
import math
import os
import platform
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
GSD = 1.0 / 64.0
CRS = "EPSG:28992"
#: our GeoTIFF creation options for orthophotos (core/io/raster.py, COMPRESSION=deflate)
CREATION = {"tiled": True, "blockxsize": 512, "blockysize": 512, "compress": "deflate",
            "zlevel": 1, "predictor": 2, "interleave": "pixel", "photometric": "rgb",
            "bigtiff": "if_safer",
            "num_threads": str(max(1, min(4, os.cpu_count() or 1)))}  # fmt: skip

ORTHORITY = r"""
import json, math, sys, time, warnings
warnings.simplefilter("ignore")
import numpy as np
from orthority.camera import PinholeCamera
from orthority.ortho import Ortho
a = json.loads(sys.argv[1])
cam = PinholeCamera(tuple(a["size"]), a["focal_mm"], sensor_size=tuple(a["sensor_mm"]),
                    cx=a["cx"], cy=a["cy"], xyz=tuple(a["xyz"]), opk=tuple(a["opk"]))
import resource
u0 = resource.getrusage(resource.RUSAGE_SELF)
t0 = time.perf_counter()
o = Ortho(a["image"], a["dem"], cam, crs=a["crs"])
o.process(a["out"], resolution=(a["gsd"], a["gsd"]), interp="bilinear", dem_interp="bilinear",
          write_mask=True, creation_options=a["creation"], build_ovw=True, overwrite=True,
          aligned_pixels=True, compress=a.get("compress"))
t = time.perf_counter() - t0
u1 = resource.getrusage(resource.RUSAGE_SELF)
cpu = u1.ru_utime + u1.ru_stime - u0.ru_utime - u0.ru_stime
pts = np.array(a["points"], float).T
px = cam.world_to_pixel(pts).T
hwm = [int(x.split()[1]) for x in open("/proc/self/status") if x.startswith("VmHWM")][0]
print(json.dumps({"seconds": t, "cpu": cpu, "maxrss_mb": hwm / 1024, "pixels": px.tolist()}))
"""

ORTHORITY_SET = r"""
import json, sys, time, warnings
warnings.simplefilter("ignore")
from orthority.camera import PinholeCamera
from orthority.ortho import Ortho
a = json.loads(sys.argv[1])
import resource
u0 = resource.getrusage(resource.RUSAGE_SELF)
t0 = time.perf_counter()
for im in a["images"]:  # one image after the other, as its command line does
    cam = PinholeCamera(tuple(a["size"]), a["focal_mm"], sensor_size=tuple(a["sensor_mm"]),
                        cx=a["cx"], cy=a["cy"], xyz=tuple(im["xyz"]), opk=tuple(im["opk"]))
    Ortho(im["image"], a["dem"], cam, crs=a["crs"]).process(
        im["out"], resolution=(a["gsd"], a["gsd"]), interp="bilinear", dem_interp="bilinear",
        write_mask=True, creation_options=a["creation"], build_ovw=True, overwrite=True,
        aligned_pixels=True)
t = time.perf_counter() - t0
u1 = resource.getrusage(resource.RUSAGE_SELF)
cpu = u1.ru_utime + u1.ru_stime - u0.ru_utime - u0.ru_stime
hwm = [int(x.split()[1]) for x in open("/proc/self/status") if x.startswith("VmHWM")][0]
print(json.dumps({"seconds": t, "cpu": cpu, "maxrss_mb": hwm / 1024}))
"""

OURS = r"""
import json, sys, time
a = json.loads(sys.argv[1])
from lidarphoto.core.jobs import orthorectify
from lidarphoto.core.jobs.runner import run_job
import lidarphoto.core.photo.orthophoto_numba as k
import numpy as np
if k.AVAILABLE:  # load the compiled kernels from their cache before the clock starts
    k.cell_pixels(0.0, 0.0, 1.0, 0, 0, np.zeros((2, 2), np.float32), 0.0, 0.0, 1.0,
                  np.zeros((2, 2, 6)), 2.0, 1.0, np.zeros((1, 1, 2)), 0.0, 0.0, 1.0,
                  np.zeros(5), np.zeros((0, 0)), np.zeros((0, 0)), np.zeros((0, 0)))
    k.remap_maps(np.zeros((1, 1)), np.zeros((1, 1)), 0, 0)
    from lidarphoto.core.io.raster_overviews import average_level
    for side in (2, 3):  # the overview kernels (2 x 2 and GDAL's fractional windows)
        average_level(np.zeros((1, side, side), np.uint8), np.ones((side, side), bool))
# the imports the job makes on first use (orthority's are made before its clock too)
import cv2  # noqa: F401
import lidarphoto.core.io.atomic  # noqa: F401
import lidarphoto.core.io.camera  # noqa: F401
import lidarphoto.core.io.dsm  # noqa: F401
import lidarphoto.core.io.images  # noqa: F401
import lidarphoto.core.io.orientation  # noqa: F401
from lidarphoto.core.io.raster import raster_backend
raster_backend()
import resource
u0 = resource.getrusage(resource.RUSAGE_SELF)
t0 = time.perf_counter()
r = run_job(orthorectify, a["values"])
t = time.perf_counter() - t0
u1 = resource.getrusage(resource.RUSAGE_SELF)
cpu = u1.ru_utime + u1.ru_stime - u0.ru_utime - u0.ru_stime
hwm = [int(x.split()[1]) for x in open("/proc/self/status") if x.startswith("VmHWM")][0]
print(json.dumps({"seconds": t, "cpu": cpu, "maxrss_mb": hwm / 1024,
                  "occluded": r.results["OCCLUDED_FRACTION"]}))
"""


def _run(python: str, code: str, arg: dict, **extra_env: str) -> dict:
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", **extra_env)
    r = subprocess.run([python, "-c", code, json.dumps(arg)], capture_output=True, text=True,
                       env=env, timeout=900)  # fmt: skip
    if r.returncode:
        raise RuntimeError(r.stderr[-3000:])
    return json.loads(r.stdout.strip().splitlines()[-1])


def _demo(folder: Path) -> None:
    """The demo's LiDAR, flight and rendering steps into ``folder`` (when not there yet)."""
    if (folder / "flight" / "images").is_dir() and (folder / "lidar" / "dsm.tif").is_file():
        return
    spec = importlib.util.spec_from_file_location("lidarphoto_demo", ROOT / "scripts" / "demo.py")
    demo = importlib.util.module_from_spec(spec)
    sys.modules["lidarphoto_demo"] = demo
    spec.loader.exec_module(demo)
    lidar = demo.lidar_step(folder / "lidar")
    sim, _, eo = demo.flight_step(lidar, folder / "flight")
    demo.render_step(lidar, sim, eo, folder / "flight" / "images")


def _local_tm(demo: Path, work: Path, eo, dsm) -> tuple[str, Path, Path]:
    """The EO and the DSM in a transverse Mercator tangent at the tile (scale 1 there, on the
    same Bessel ellipsoid, heights unchanged): the CRS, EO CSV and DSM GeoTIFF. In it a map
    is as Cartesian as the ground can be (orthority's assumption); in RD New the scale is
    0.99994 at Delft."""
    import pyproj
    from lidarphoto.core.geometry.frames import LocalFrame, MappingFrame
    from lidarphoto.core.geometry.surface import reproject_dsm
    from lidarphoto.core.io.dsm import write_dsm
    from lidarphoto.core.io.orientation import write_eo_csv
    from lidarphoto.core.photo.orientation import (
        ExteriorOrientationTable,
        eo_local_to_map,
        eo_map_to_local,
    )

    g = dsm.grid
    rd = MappingFrame.from_user_input(CRS)
    mid = [g.x0 + g.cols * g.cell / 2, g.y_top - g.rows * g.cell / 2, 0.0]
    lat, lon, _ = (float(v) for v in rd.map_to_geodetic(np.array([mid]))[0])
    tm = pyproj.CRS.from_proj4(f"+proj=tmerc +lat_0={lat!r} +lon_0={lon!r} +k=1 +x_0=1000 "
                               "+y_0=1000 +ellps=bessel +units=m +no_defs")  # fmt: skip
    local = LocalFrame.at_map_point(rd, mid)
    c, m = eo_map_to_local(eo.xyz, eo.opk, local)
    local_tm = LocalFrame(MappingFrame(tm), local.origin_llh)
    xyz, opk = eo_local_to_map(c, m, local_tm)
    table = ExteriorOrientationTable(eo.image_id, eo.time, eo.group, xyz, opk, tm.to_wkt())
    write_eo_csv(work / "eo_tm.csv", table)
    write_dsm(work / "dsm_tm.tif", reproject_dsm(dsm, tm, cell=g.cell))
    return tm.to_wkt(), work / "eo_tm.csv", work / "dsm_tm.tif"


def _peer_camera(cam, eo, k: int) -> dict:
    """orthority's pinhole camera for our camera and row k of the EO: its rotation is ours
    (R_c^m = Rx(omega) Ry(phi) Rz(kappa), camera x right, y up, z back), its principal point
    in units of the larger image side from the image centre, rows down."""
    side = max(cam.width_px, cam.height_px)
    return {"size": [cam.width_px, cam.height_px], "focal_mm": cam.focal_mm,
            "sensor_mm": [cam.width_px * cam.pixel_size_mm, cam.height_px * cam.pixel_size_mm],
            "cx": cam.x0_mm / cam.pixel_size_mm / side,
            "cy": -cam.y0_mm / cam.pixel_size_mm / side,
            "xyz": eo.xyz[k].tolist(), "opk": eo.opk[k].tolist()}  # fmt: skip


def _read(path: Path):
    from lidarphoto.core.io.raster import RasterReader

    with RasterReader(path) as src:
        return src.info, src.read(), src.read_mask()


def _agreement(a_path: Path, b_path: Path, dsm) -> dict:
    """RMS difference and phase-correlation shifts (b relative to a) where both have data."""
    from lidarphoto.core.quality.registration import phase_correlation

    ia, a, ma = _read(a_path)
    ib, b, mb = _read(b_path)
    if ia.geotransform != ib.geotransform or a.shape != b.shape:
        raise RuntimeError(f"grids differ: {ia.geotransform} {a.shape} / {ib.geotransform} "
                           f"{b.shape}")  # fmt: skip
    both = ma & mb
    d = a.astype(float)[:, both] - b.astype(float)[:, both]
    gt = ia.geotransform
    xs = gt[0] + (np.arange(ia.width) + 0.5) * gt[1]
    ys = gt[3] + (np.arange(ia.height) + 0.5) * gt[5]
    gx, gy = np.meshgrid(xs, ys)
    z = dsm.height_at(gx.ravel(), gy.ravel()).reshape(gx.shape)
    ground = both & (z < np.nanpercentile(z[both], 40) + 0.3)
    shifts, white = [], []
    size = 256
    for r0 in range(0, ia.height - size, size):
        for c0 in range(0, ia.width - size, size):
            if ground[r0 : r0 + size, c0 : c0 + size].mean() < 0.95:
                continue
            ga = a[:, r0 : r0 + size, c0 : c0 + size].astype(float).mean(axis=0)
            gb = b[:, r0 : r0 + size, c0 : c0 + size].astype(float).mean(axis=0)
            dx, dy, _ = phase_correlation(ga, gb)
            wx, wy, _ = phase_correlation(ga, gb, whiten=True)
            shifts.append(math.hypot(dx, dy))
            white.append(math.hypot(wx, wy))
    return {"cells": int(both.sum()), "rms_dn": float(np.sqrt(np.mean(d**2))),
            "rms_dn_ground": float(np.sqrt(np.mean((a.astype(float)[:, ground]
                                                    - b.astype(float)[:, ground]) ** 2))),
            "windows": len(shifts), "shift_px": shifts, "shift_whitened_px": white}  # fmt: skip


def exact_figures() -> dict:
    """The figures of the exact case (tests/core/test_orthophoto.py)."""
    import cv2
    from lidarphoto.core.quality.registration import phase_correlation

    spec = importlib.util.spec_from_file_location("t_ortho",
                                                  ROOT / "tests" / "core" / "test_orthophoto.py")
    sys.path.insert(0, str(ROOT / "tests" / "core"))
    t = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(t)
    e = t.exact_case()
    out = {}
    for name, region in (("ground", (e["z"] < 3.0) & np.isfinite(e["col"]) & ~e["hidden"]),
                         ("roof", (e["z"] > 7.9) & np.isfinite(e["col"]))):  # fmt: skip
        keep = t._interior(region, 3)
        err = e["gap"][keep] / t.GSD
        out[f"geometry_rms_px_{name}"] = float(np.sqrt(np.mean(err**2)))
        out[f"geometry_max_px_{name}"] = float(err.max())
    gray = np.array([0.299, 0.587, 0.114])
    ortho = np.moveaxis(e["plain"], 0, 2).astype(float) @ gray
    truth = np.nan_to_num(e["truth"]) @ gray
    keep = t._interior(e["plain_valid"] & (e["z"] < 3.0) & ~e["hidden"], 4)
    inner = cv2.erode(keep.astype(np.uint8), np.ones((257, 257), np.uint8), borderValue=0)
    rr, cc = np.argwhere(inner)[len(np.argwhere(inner)) // 2] - 128
    dx, dy, _ = phase_correlation(truth[rr : rr + 256, cc : cc + 256],
                                  ortho[rr : rr + 256, cc : cc + 256])  # fmt: skip
    out["texture_shift_px"] = math.hypot(dx, dy)
    squares = (np.floor(e["gx"] - t.X0) + np.floor(e["gy"] - t.Y0)) % 2
    flat = t._interior(keep & (squares == 0), 3) | t._interior(keep & (squares == 1), 3)
    out["texture_rms_dn_flat"] = float(np.sqrt(np.mean((ortho[flat] - truth[flat]) ** 2)))
    both = e["plain_valid"]
    occluded = both & ~e["true_valid"]
    hidden = e["hidden"] & both
    k = np.ones((3, 3), np.uint8)
    border = cv2.dilate(hidden.astype(np.uint8), k) != cv2.erode(hidden.astype(np.uint8), k)
    sure = both & ~border
    out["hidden_cells"] = int(hidden.sum())
    out["occluded_cells"] = int(occluded.sum())
    out["occlusion_agreement_off_border"] = float(np.mean(occluded[sure] == hidden[sure]))
    out["occlusion_disagreement_cells"] = int((occluded != hidden)[both].sum())
    return out


LARGE = r"""
import json, sys, time
a = json.loads(sys.argv[1])
from lidarphoto.core.jobs import orthorectify
from lidarphoto.core.jobs.runner import run_job
t0 = time.perf_counter()
r = run_job(orthorectify, a["values"])
t = time.perf_counter() - t0
hwm = [int(x.split()[1]) for x in open("/proc/self/status") if x.startswith("VmHWM")][0]
print(json.dumps({"seconds": t, "maxrss_mb": hwm / 1024}))
"""


def _emit(res: dict, path: Path | None) -> int:
    """Print the figures, and write them to ``path`` when given."""
    print(json.dumps(res, indent=1))
    if path:
        path.write_text(json.dumps(res, indent=1), encoding="utf-8")
    return 0


def _cells(folder: Path) -> int:
    from lidarphoto.core.io.raster import RasterReader

    total = 0
    for path in sorted(folder.glob("*.tif")):
        with RasterReader(path) as src:
            total += src.info.width * src.info.height
    return total


def image_set(args) -> dict:
    """The demo's images in one run of each tool (fresh processes, alternating, best of
    ``--repeats``): orthority one image after the other in one process (its command line's
    way), ours one orthorectify job (its default extents: each image's footprint on the
    DSM). Throughput in cells of the files written per second."""
    from lidarphoto.core.io.camera import read_camera_json
    from lidarphoto.core.io.orientation import read_eo_csv

    if not args.orthority_python:
        raise SystemExit("--set needs --orthority-python")
    _demo(args.demo)
    cam = read_camera_json(args.demo / "flight" / "camera.json")
    eo = read_eo_csv(args.demo / "flight" / "eo_true.csv")
    n = min(args.images, len(eo))
    images = [args.demo / "flight" / "images" / f"{i}.tif" for i in eo.image_id[:n]]
    work = Path(tempfile.mkdtemp(prefix="bench_ortho_set_"))
    peer_dir, ours_dir = work / "orthority", work / "ours"
    peer_dir.mkdir()
    base = _peer_camera(cam, eo, 0)
    peer_arg = {**{k: base[k] for k in ("size", "focal_mm", "sensor_mm", "cx", "cy")},
                "dem": str(args.demo / "lidar" / "dsm.tif"), "crs": CRS, "gsd": GSD,
                "creation": CREATION,
                "images": [{"image": str(images[k]), "xyz": eo.xyz[k].tolist(),
                            "opk": eo.opk[k].tolist(),
                            "out": str(peer_dir / f"{eo.image_id[k]}.tif")} for k in range(n)]}
    values = {"CAMERA": str(args.demo / "flight" / "camera.json"),
              "EO": str(args.demo / "flight" / "eo_true.csv"),
              "IMAGES": [str(p) for p in images], "DSM": str(args.demo / "lidar" / "dsm.tif"),
              "CRS": CRS, "GSD": GSD, "RESAMPLING": "bilinear", "TRUE_ORTHO": False,
              "OUTPUT_FOLDER": str(ours_dir)}  # fmt: skip
    load_start = os.getloadavg()[0]
    best = {"orthority": None, "ours": None}
    for _ in range(args.repeats):
        for tool in ("orthority", "ours"):
            if tool == "ours" and ours_dir.exists():
                shutil.rmtree(ours_dir)
            got = (_run(args.orthority_python, ORTHORITY_SET, peer_arg) if tool == "orthority"
                   else _run(sys.executable, OURS, {"values": values}))  # fmt: skip
            if best[tool] is None or got["seconds"] < best[tool]["seconds"]:
                best[tool] = got
    out = {"date": datetime.date.today().isoformat(), "cpus": os.cpu_count(),
           "load_start": load_start, "images": n, "repeats": args.repeats}  # fmt: skip
    for tool, folder in (("orthority", peer_dir), ("ours", ours_dir)):
        cells = _cells(folder)
        out[tool] = {**best[tool], "cells": cells,
                     "mcells_per_s": cells / best[tool]["seconds"] / 1e6,
                     "mcells_per_cpu_s": cells / best[tool]["cpu"] / 1e6}  # fmt: skip
    out["speed_ratio"] = out["ours"]["mcells_per_s"] / out["orthority"]["mcells_per_s"]
    out["cpu_ratio"] = out["ours"]["mcells_per_cpu_s"] / out["orthority"]["mcells_per_cpu_s"]
    out["load_end"] = os.getloadavg()[0]
    shutil.rmtree(work)
    return out


def large_frame(work: Path) -> dict:
    """Memory and time for one 196 Mpx frame (UltraCam XP size, 17310 x 11310, 8-bit RGB,
    tiled): its orthophoto at the image's GSD on a flat DSM, in a fresh process."""
    import pyproj
    from lidarphoto.core.geometry.grid import Grid
    from lidarphoto.core.geometry.surface import Dsm
    from lidarphoto.core.io.camera import write_camera_json
    from lidarphoto.core.io.dsm import write_dsm
    from lidarphoto.core.io.orientation import write_eo_csv
    from lidarphoto.core.io.raster_write import GeoTiffWriter
    from lidarphoto.core.photo.orientation import ExteriorOrientationTable
    from lidarphoto.core.simulation.flight import ultracam_xp

    cam = ultracam_xp()
    w, h = cam.width_px, cam.height_px
    image = work / "large" / "big.tif"
    image.parent.mkdir(parents=True, exist_ok=True)
    with GeoTiffWriter(image, w, h, 3, np.uint8, None, tile=512, photometric="RGB",
                       compress="LZW") as out:  # fmt: skip
        jj = np.arange(512)
        for r0 in range(0, h, 512):
            for c0 in range(0, w, 512):
                cc, rr = np.meshgrid(c0 + jj, r0 + jj)
                band = ((cc // 7 + rr // 11) % 2 * 120 + (cc * 3 + rr) % 97).astype(np.uint8)
                out.write(np.stack([band, band[::-1], band.T])[:, : min(512, h - r0),
                                                                : min(512, w - c0)], c0, r0)
        out.close(overviews=False)
    height = 1000.0  # GSD 6 cm; footprint 1040 x 680 m on a flat DSM of 1 m
    gsd = height * cam.pixel_size_mm / cam.focal_mm
    dsm = Dsm(np.zeros((900, 1300), np.float32), Grid(99350.0, 400450.0, 1.0, 900, 1300),
              pyproj.CRS.from_epsg(28992))  # fmt: skip
    write_dsm(work / "large" / "flat.tif", dsm)
    write_camera_json(work / "large" / "camera.json", cam)
    eo = ExteriorOrientationTable(("big",), np.array([0.0]), ("",),
                                  np.array([[100000.0, 400000.0, height]]),
                                  np.radians([[0.5, -0.3, 90.0]]), CRS)  # fmt: skip
    write_eo_csv(work / "large" / "eo.csv", eo)
    values = {"CAMERA": str(work / "large" / "camera.json"), "EO": str(work / "large" / "eo.csv"),
              "IMAGES": [str(image)], "DSM": str(work / "large" / "flat.tif"), "CRS": CRS,
              "GSD": round(gsd, 3), "OUTPUT_FOLDER": str(work / "large" / "out")}  # fmt: skip
    res = _run(sys.executable, LARGE, {"values": values})
    # GDAL's block cache (5 % of the RAM by default) holds written blocks until it is full
    capped = _run(sys.executable, LARGE, {"values": values}, GDAL_CACHEMAX="256")
    res["seconds_cache_256mb"] = capped["seconds"]
    res["maxrss_mb_cache_256mb"] = capped["maxrss_mb"]
    from lidarphoto.core.io.raster import RasterReader

    with RasterReader(work / "large" / "out" / "big_ortho.tif") as src:
        res["cells"] = src.info.width * src.info.height
    res["image_px"] = w * h
    image.unlink()
    return res


class _Peers:
    """The two tools on one image of the demo, in RD New ("rd") or in a local transverse
    Mercator ("tm"): ``frames[frame]`` is (CRS, EO file, EO table, DSM file, DSM)."""

    def __init__(self, args: argparse.Namespace, cam, frames: dict, images: list[Path]):
        self.args, self.cam, self.frames, self.images = args, cam, frames, images

    def camera_points(self, frame: str, k: int) -> tuple[np.ndarray, np.ndarray]:
        """400 DSM points seen by image k and their pixels by our rigorous chain."""
        from lidarphoto.core.geometry.collinearity import project
        from lidarphoto.core.geometry.rotations import matrix_to_opk
        from lidarphoto.core.photo.orientation import eo_map_to_local
        from lidarphoto.core.photo.orthophoto import OrthoProjector

        crs, _, eo, _, dsm = self.frames[frame]
        proj = OrthoProjector.build(self.cam, eo.xyz[k], eo.opk[k], dsm, crs)
        box = proj.footprint()
        rng = np.random.default_rng(k)
        xy = np.column_stack([rng.uniform(box[0], box[2], 400), rng.uniform(box[1], box[3], 400)])
        pts = np.column_stack([xy, dsm.height_at(xy[:, 0], xy[:, 1])])
        pts = pts[np.isfinite(pts[:, 2])]
        c_loc, m_loc = eo_map_to_local(eo.xyz[k : k + 1], eo.opk[k : k + 1], proj.local)
        px = project(proj.local.map_to_enu(pts), np.r_[c_loc[0], matrix_to_opk(m_loc[0])],
                     self.cam)  # fmt: skip
        return pts, px

    def peer(self, frame: str, k: int, out: Path, own_defaults: bool = False) -> dict:
        """orthority on image k; with our creation options, or with its own lossless default
        (DEFLATE at GDAL's level 6, no predictor, tiled 512)."""
        crs, _, eo, dsm_path, _ = self.frames[frame]
        pts, px = self.camera_points(frame, k)
        arg = {**_peer_camera(self.cam, eo, k), "image": str(self.images[k]),
               "dem": str(dsm_path), "crs": crs, "gsd": GSD,
               "creation": None if own_defaults else CREATION,
               "compress": "deflate" if own_defaults else None, "points": pts.tolist(),
               "out": str(out)}  # fmt: skip
        res = _run(self.args.orthority_python, ORTHORITY, arg)
        # orthority's pixels have their centres at integers (OpenCV's): ours at + 0.5
        diff = np.abs(np.array(res["pixels"]) + 0.5 - px)
        res["camera_max_px"] = float(diff.max())
        return res

    def ours(self, frame: str, k: int, ref: Path, out: Path, true_ortho: bool) -> dict:
        """Our job on the extent of orthority's output ``ref`` (the same cells)."""
        from lidarphoto.core.io.raster import RasterReader

        crs, eo_csv, _, dsm_path, _ = self.frames[frame]
        with RasterReader(ref) as src:
            gt, w, h = src.info.geotransform, src.info.width, src.info.height
        extent = (gt[0], gt[3] - h * GSD + GSD / 2, gt[0] + w * GSD - GSD / 2, gt[3] - GSD / 2)
        values = {"CAMERA": str(self.args.demo / "flight" / "camera.json"), "EO": str(eo_csv),
                  "IMAGES": [str(self.images[k])], "DSM": str(dsm_path), "CRS": crs, "GSD": GSD,
                  "EXTENT": ",".join(repr(v) for v in extent), "RESAMPLING": "bilinear",
                  "TRUE_ORTHO": true_ortho, "OUTPUT_FOLDER": str(out)}  # fmt: skip
        res = _run(sys.executable, OURS, {"values": values})
        res["cells"] = w * h
        return res


def _image_row(p: _Peers, k: int, work: Path) -> dict:
    """Image k: best times of ``--repeats`` alternating runs of each tool, peak memories, the
    camera comparison and the agreement of the outputs, in RD New and in the local TM."""
    name = p.frames["rd"][2].image_id[k]
    best = {"peer": math.inf, "ours": math.inf, "true": math.inf, "own": math.inf}
    cpu = {"peer": math.inf, "ours": math.inf, "true": math.inf, "own": math.inf}
    mem = {"peer": 0.0, "ours": 0.0, "true": 0.0, "own": 0.0}
    ref = work / "rd" / f"{name}_orthority.tif"
    ref.parent.mkdir(exist_ok=True)
    for _ in range(p.args.repeats):  # alternating, in RD New: what the user runs
        res = p.peer("rd", k, ref)
        best["peer"], mem["peer"] = min(best["peer"], res["seconds"]), max(
            mem["peer"], res["maxrss_mb"])  # fmt: skip
        cpu["peer"] = min(cpu["peer"], res["cpu"])
        cam_rd = res["camera_max_px"]
        res = p.peer("rd", k, work / "rd" / f"{name}_orthority_own.tif", own_defaults=True)
        best["own"], cpu["own"] = min(best["own"], res["seconds"]), min(cpu["own"],
                                                                        res["cpu"])  # fmt: skip
        for mode in ("ours", "true"):
            got = p.ours("rd", k, ref, work / "rd" / mode, mode == "true")
            best[mode], mem[mode] = min(best[mode], got["seconds"]), max(
                mem[mode], got["maxrss_mb"])  # fmt: skip
            cpu[mode] = min(cpu[mode], got["cpu"])
            cells = got["cells"]
    agree_rd = _agreement(ref, work / "rd" / "ours" / f"{name}_ortho.tif", p.frames["rd"][4])
    ref_tm = work / "tm" / f"{name}_orthority.tif"
    ref_tm.parent.mkdir(exist_ok=True)
    cam_tm = p.peer("tm", k, ref_tm)["camera_max_px"]
    p.ours("tm", k, ref_tm, work / "tm" / "ours", False)
    agree_tm = _agreement(ref_tm, work / "tm" / "ours" / f"{name}_ortho.tif",
                          p.frames["tm"][4])  # fmt: skip
    row = {"image": name, "cells": cells, "orthority_s": best["peer"],
           "ours_s": best["ours"], "ours_true_s": best["true"],
           "orthority_cpu": cpu["peer"], "ours_cpu": cpu["ours"], "ours_true_cpu": cpu["true"],
           "orthority_own_s": best["own"], "orthority_own_cpu": cpu["own"],
           "orthority_mb": mem["peer"], "ours_mb": mem["ours"], "ours_true_mb": mem["true"],
           "camera_max_px_rd": cam_rd, "camera_max_px_tm": cam_tm,
           **{f"{key}_rd": v for key, v in agree_rd.items()},
           **{f"{key}_tm": v for key, v in agree_tm.items()}}  # fmt: skip
    print(f"{name}: {cells / 1e6:.1f} Mcells; orthority {best['peer']:.2f} s "
          f"({cpu['peer']:.2f} CPU s), ours {best['ours']:.2f} s ({cpu['ours']:.2f}; "
          f"{best['peer'] / best['ours']:.2f}x), true {best['true']:.2f}"
          f" s; cameras differ by {cam_rd:.3f} px (RD) / {cam_tm:.3f} px (TM); shift median "
          f"{np.median(agree_rd['shift_px']):.3f} (RD) / {np.median(agree_tm['shift_px']):.3f}"
          f" (TM) px; RMS {agree_tm['rms_dn']:.2f} DN (TM)", flush=True)  # fmt: skip
    return row


def _summary(rows: list[dict]) -> dict:
    """The figures over all images: throughputs and their ratios, shifts, RMS, memory."""
    cells = sum(r["cells"] for r in rows)
    kinds = ("orthority", "orthority_own", "ours", "ours_true")
    tp = {k: cells / sum(r[f"{k}_s"] for r in rows) / 1e6 for k in kinds}

    def stats(key: str) -> dict:
        v = np.concatenate([r[key] for r in rows])
        return {"median": float(np.median(v)), "p95": float(np.percentile(v, 95)),
                "max": float(v.max()), "windows": int(v.size)}  # fmt: skip

    tp_cpu = {k: cells / sum(r[f"{k}_cpu"] for r in rows) / 1e6 for k in kinds}
    return dict(
        images=len(rows), cells=cells, throughput_mcells_s=tp,
        throughput_mcells_per_cpu_s=tp_cpu, cpu_ratio=tp_cpu["ours"] / tp_cpu["orthority"],
        speed_ratio=tp["ours"] / tp["orthority"], true_ratio=tp["ours_true"] / tp["orthority"],
        speed_ratio_own_defaults=tp["ours"] / tp["orthority_own"],
        shift_px_rd=stats("shift_px_rd"), shift_px_tm=stats("shift_px_tm"),
        shift_whitened_px_tm=stats("shift_whitened_px_tm"),
        rms_dn_rd=float(np.sqrt(np.mean([r["rms_dn_rd"] ** 2 for r in rows]))),
        rms_dn_tm=float(np.sqrt(np.mean([r["rms_dn_tm"] ** 2 for r in rows]))),
        rms_dn_ground_tm=float(np.sqrt(np.mean([r["rms_dn_ground_tm"] ** 2 for r in rows]))),
        camera_max_px_rd=max(r["camera_max_px_rd"] for r in rows),
        camera_max_px_tm=max(r["camera_max_px_tm"] for r in rows),
        memory_mb={k: max(r[f"{k}_mb"] for r in rows) for k in ("orthority", "ours",
                                                               "ours_true")},
        load_end=os.getloadavg()[0], rows=rows,
    )  # fmt: skip


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--orthority-python", default=os.environ.get("ORTHORITY_PYTHON", ""),
                    help="python of a venv with orthority installed")  # fmt: skip
    ap.add_argument("--demo", type=Path, default=ROOT / "demo_output")
    ap.add_argument("--images", type=int, default=10)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--json", type=Path, default=None, help="write the figures here")
    ap.add_argument("--large", action="store_true", help="only the 196 Mpx frame")
    ap.add_argument("--set", action="store_true",
                    help="only the whole set of images in one run of each tool")  # fmt: skip
    args = ap.parse_args()
    if args.set:
        res = image_set(args)
        return _emit(res, args.json)
    if args.large:
        res = large_frame(Path(tempfile.mkdtemp(prefix="bench_ortho_large_")))
        return _emit(res, args.json)

    from lidarphoto.core.io.camera import read_camera_json
    from lidarphoto.core.io.dsm import read_dsm_raster
    from lidarphoto.core.io.orientation import read_eo_csv

    figures: dict = {"date": datetime.date.today().isoformat(), "machine": platform.node(),
                     "cpus": os.cpu_count(), "load_start": os.getloadavg()[0]}  # fmt: skip
    print("exact case ...", flush=True)
    figures["exact"] = exact_figures()
    print(json.dumps(figures["exact"], indent=1))
    if not args.orthority_python:
        print("no --orthority-python: peer comparison skipped")
        return 0
    _demo(args.demo)
    cam = read_camera_json(args.demo / "flight" / "camera.json")
    eo_rd = read_eo_csv(args.demo / "flight" / "eo_true.csv")
    dsm_rd_path = args.demo / "lidar" / "dsm.tif"
    dsm_rd = read_dsm_raster(dsm_rd_path)
    work = Path(tempfile.mkdtemp(prefix="bench_ortho_"))
    tm_wkt, tm_eo_csv, tm_dsm_path = _local_tm(args.demo, work, eo_rd, dsm_rd)
    frames = {
        "rd": (CRS, args.demo / "flight" / "eo_true.csv", eo_rd, dsm_rd_path, dsm_rd),
        "tm": (tm_wkt, tm_eo_csv, read_eo_csv(tm_eo_csv), tm_dsm_path,
               read_dsm_raster(tm_dsm_path)),
    }  # fmt: skip
    images = [args.demo / "flight" / "images" / f"{i}.tif" for i in eo_rd.image_id]
    peers = _Peers(args, cam, frames, images)
    rows = [_image_row(peers, k, work) for k in range(min(args.images, len(eo_rd)))]
    figures.update(_summary(rows))
    print(json.dumps({k: v for k, v in figures.items() if k != "rows"}, indent=1))
    if args.json:
        args.json.write_text(json.dumps(figures, indent=1), encoding="utf-8")
    with open(work / "rows.csv", "w", newline="", encoding="utf-8") as fh:
        keys = [k for k in rows[0] if not isinstance(rows[0][k], list)]
        w_ = csv.DictWriter(fh, keys, extrasaction="ignore")
        w_.writeheader()
        w_.writerows(rows)
    print(f"files in {work}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
