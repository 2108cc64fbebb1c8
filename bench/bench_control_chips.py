"""Control plates and chips on synthetic ground photos: our corners against OpenCV's
cornerSubPix (the peer, started 1 px off the truth), the plate photo's pose, the chip against
the orthographic truth, and the time of the whole job per point (read + compute + write).

Run: python -m lidarphoto.bench.bench_control_chips [projection ...] (or the file with the
package on the path; default: perspective, equidistant, equisolid); writes nothing but a
temporary folder. Figures in bench/control_chips.md.

Cameras: perspective 960 x 720 px, f = 3 mm, 5 um pixels, Brown k1 (3 mm ground pixels at
1.8 m, ground features of 12 mm); fisheye (the source's nadir fisheye) 960 x 720 px, f = 1.6
mm, 4.5 um pixels, Brown k1 k2, 97 degrees off the axis in the corners (5 mm ground pixels,
ground features of 20 mm: as wide in pixels as the perspective case's).
"""

from __future__ import annotations

import dataclasses
import math
import platform
import resource
import sys
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np
from lidarphoto.core.geometry.collinearity import project
from lidarphoto.core.io.camera import write_camera_json
from lidarphoto.core.io.raster_write import GeoTiffWriter
from lidarphoto.core.jobs import make_control_chips as job
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.photo.control_chips import ChipOptions, make_chip
from lidarphoto.core.photo.control_plate import (
    PlateGeometry,
    detect_plate,
    photo_azimuth,
    resect_plate,
)
from lidarphoto.core.quality.registration import phase_correlation
from lidarphoto.core.simulation.ground_photo import (
    corner_errors,
    ground_camera,
    make_ground_patch,
    render_ground_photo,
    render_ortho,
)

PLATE = PlateGeometry(0.5, 0.25, 0.0, 20.0)
POINT = np.array([457_321.25, 7_552_104.75, 431.2])
GSD, SIZE = 0.01, 101






def main(seeds: int = 4, projection: str = "perspective") -> None:
    cam = ground_camera(projection)
    feature_m = 0.012 if projection == "perspective" else 0.02
    rng = np.random.default_rng(0)
    ours, peer, pose_m, pose_deg, ncc, off, t_job, cpu_job = [], [], [], [], [], [], [], []
    flat = []
    for seed in range(seeds):
        eo = np.array([0.45 + 0.1 * rng.standard_normal(), -0.3 + 0.1 * rng.standard_normal(),
                       1.8 + 0.1 * rng.standard_normal(),
                       *np.radians([3 * rng.standard_normal(), 3 * rng.standard_normal(),
                                    360 * rng.uniform()])])  # fmt: skip
        free_eo = eo + np.array([0.004, -0.003, 0.002, *np.radians([1.0, 0.5, 4.0])])
        patch = make_ground_patch(feature_m=feature_m, seed=10 + seed)
        a = render_ground_photo(patch, cam, eo, PLATE, supersample=2, seed=2 * seed)
        b = render_ground_photo(patch, cam, free_eo, None, supersample=2, seed=2 * seed + 1)
        truth = project(PLATE.corners(), eo, cam)
        det = detect_plate(a, cam, PLATE)
        ours.append(corner_errors(det.corners_px, truth))
        # the same pose on uniform ground: the corners without the texture's bias
        flat_patch = dataclasses.replace(patch, grey=np.full_like(patch.grey, 120.0))
        flat_photo = render_ground_photo(flat_patch, cam, eo, PLATE, supersample=2, seed=99)
        flat.append(corner_errors(detect_plate(flat_photo, cam, PLATE).corners_px, truth))
        start = (truth + rng.uniform(-1, 1, truth.shape) - 0.5).astype(np.float32)
        sub = cv2.cornerSubPix(
            a,
            start.reshape(-1, 1, 2).copy(),
            (5, 5),
            (-1, -1),
            (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 40, 1e-3),
        )
        peer.append(np.linalg.norm(sub.reshape(-1, 2) + 0.5 - truth, axis=1))
        pr = resect_plate(det, cam, PLATE, photo_azimuth(eo) + 20.0)
        pose_m.append(np.abs(pr.eo[:3] - eo[:3]).max())
        d_ang = np.angle(np.exp(1j * (pr.eo[3:] - eo[3:])))  # wrapped to +-pi
        pose_deg.append(math.degrees(np.abs(d_ang).max()))
        res = make_chip("P", POINT, a, b, cam, PLATE, ChipOptions(gsd_m=GSD, size_px=SIZE),
                        photo_azimuth(eo))  # fmt: skip
        gt = res.geotransform
        local = (gt[0] - POINT[0], GSD, 0.0, gt[3] - POINT[1], 0.0, -GSD)
        tr = render_ortho(patch, local, SIZE)
        ncc.append(np.corrcoef(res.chip.ravel(), tr.ravel())[0, 1])
        dx, dy, _ = phase_correlation(tr, res.chip)
        off.append(math.hypot(dx, dy))
        with tempfile.TemporaryDirectory() as tmp:
            d = Path(tmp)
            for name, img in (("P_plate", a), ("P_free", b)):
                u8 = np.clip(np.rint(img), 0, 255).astype(np.uint8)
                with GeoTiffWriter(str(d / f"{name}.tif"), 960, 720, 1, np.uint8, None,
                                   None) as w:  # fmt: skip
                    w.write(u8)
            write_camera_json(d / "camera.json", cam)
            (d / "pts.csv").write_text(f"point_id,X,Y,Z,role\nP,{POINT[0]},{POINT[1]},"
                                       f"{POINT[2]},control\n")  # fmt: skip
            t0, c0 = time.perf_counter(), time.process_time()
            run_job(job, {"POINTS": str(d / "pts.csv"), "CRS": "EPSG:31983",
                          "CAMERA": str(d / "camera.json"), "PHOTOS": [str(d)],
                          "OUTER_SIDE": 0.5, "INNER_SIDE": 0.25, "PLATE_AZIMUTH": 20.0,
                          "PHOTO_AZIMUTH": photo_azimuth(eo), "GSD": GSD, "CHIP_SIZE": SIZE,
                          "OUTPUT_FOLDER": str(d / "out")})  # fmt: skip
            t_job.append(time.perf_counter() - t0)
            cpu_job.append(time.process_time() - c0)
    ours_a, peer_a = np.array(ours), np.array(peer)
    print(
        f"python {sys.version.split()[0]}, numpy {np.__version__}, OpenCV {cv2.__version__}, "
        f"{platform.machine()}; {projection} camera, {seeds} synthetic points (960 x 720 px, "
        "Brown lens, 1 DN noise)"
    )
    for name, e in (("ours", ours_a), ("cv2.cornerSubPix", peer_a),
                    ("ours, uniform ground", np.array(flat))):  # fmt: skip
        print(
            f"corner error {name:20s}: outer RMS {np.sqrt(np.mean(e[:, :4] ** 2)):.3f} px, "
            f"max {e[:, :4].max():.3f}; inner RMS {np.sqrt(np.mean(e[:, 4:] ** 2)):.3f} px, "
            f"max {e[:, 4:].max():.3f}"
        )
    print(
        f"plate photo pose: max position error {1000 * max(pose_m):.1f} mm, "
        f"max angle error {max(pose_deg):.3f} deg"
    )
    print(f"chip vs orthographic truth: NCC min {min(ncc):.4f}, offset max {max(off):.3f} px")
    print(
        f"job (read 2 photos + detect + resect + SIFT + rectify + write): "
        f"median {np.median(t_job):.2f} s wall, {np.median(cpu_job):.2f} s CPU per point; "
        f"peak RSS of the process "
        f"{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB"
    )


if __name__ == "__main__":
    for name in sys.argv[1:] or ("perspective", "equidistant", "equisolid"):
        main(projection=name)
