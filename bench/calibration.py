"""Camera calibration: our self-calibrating bundle against OpenCV (and BoofCV's published
fisheye calibration) on the same detections of real target images.

Usage: ``python bench/calibration.py`` (reads ../shared/data relative to the repository).
Prints the Markdown rows of bench/matching.md, section "Camera calibration".
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import cv2
import numpy as np
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.collinearity import project
from lidarphoto.core.io.calibration import read_image_grey
from lidarphoto.core.photo.calibration_targets import TargetSpec, detect_target, target_field
from lidarphoto.core.photo.camera_calibration import CalibrationOptions, calibrate_camera

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
PS = 0.003  # mm; only scales the mm values


def _ours(fld, det, size, projection):
    t = time.perf_counter()
    res = calibrate_camera(fld, det, size[0], size[1], PS, CalibrationOptions(
        projection=projection, sigma_px=0.2))  # fmt: skip
    dt = time.perf_counter() - t
    cam = res.camera
    s = res.sigmas
    ks = ", ".join(f"{n} {v:.3g}±{s[n]:.2g}" for n, v in
                   zip(cam.interior_names[3:], cam.interior_params[3:]))  # fmt: skip
    cx, cy = cam.principal_point_px
    return res, (f"ours {projection}", res.rms_px, f"{cam.focal_px:.2f} ± {s['focal_mm'] / PS:.2f}",
                 f"{cx:.2f} ± {s['x0_mm'] / PS:.2f}, {cy:.2f} ± {s['y0_mm'] / PS:.2f}",
                 f"σ0 {res.sigma0:.2f}; {ks} (mm⁻ⁿ)", dt)  # fmt: skip


def _row(r):
    name, rms, f, pp, ks, dt = r
    return f"| {name} | {rms:.3f} | {f} | {pp} | {ks} | {dt * 1000:.0f} ms |"


def _map_diff(cam: Camera, cv_project, max_theta_deg: float) -> float:
    """Largest pixel difference of the two models' projections of rays up to max_theta."""
    th = np.radians(np.linspace(0.0, max_theta_deg, 40))
    az = np.linspace(-np.pi, np.pi, 24, endpoint=False)
    t, a = np.meshgrid(th, az)
    ray_cv = np.column_stack([np.sin(t.ravel()) * np.cos(a.ravel()),
                              np.sin(t.ravel()) * np.sin(a.ravel()), np.cos(t.ravel())])
    ours = project(ray_cv, [0, 0, 0, math.pi, 0, 0], cam)  # OpenCV frame -> ours
    theirs = cv_project(ray_cv) + 0.5  # pixel centres at integers -> the project's
    ok = np.isfinite(ours).all(axis=1) & cam.in_frame(np.nan_to_num(ours, nan=-1))
    return float(np.max(np.linalg.norm(ours[ok] - theirs[ok], axis=1)))


def charuco() -> list[str]:
    spec = TargetSpec("charuco", 5, 7, 0.04, 0.02, "DICT_6X6_250")
    fld = target_field(spec)
    files = sorted((DATA / "aruco-markers" / "charuco-calibration").glob("img_*.jpg"))
    det = [detect_target(read_image_grey(p), spec, p.name) for p in files]
    _, ours = _ours(fld, det, (640, 480), "perspective")
    obj = [fld.coordinates(d.ids).astype(np.float32) for d in det]
    img = [(d.pixels - 0.5).astype(np.float32) for d in det]
    t = time.perf_counter()
    rms, k, dist, _, _, sd_int, _, _ = cv2.calibrateCameraExtended(obj, img, (640, 480), None,
                                                                    None)  # fmt: skip
    dt = time.perf_counter() - t
    sd = sd_int.ravel()
    d = dist.ravel()
    cv_row = ("OpenCV calibrateCamera (k1 k2 p1 p2 k3)", rms,
              f"{k[0, 0]:.2f} ± {sd[0]:.2f} / {k[1, 1]:.2f} ± {sd[1]:.2f}",
              f"{k[0, 2] + 0.5:.2f} ± {sd[2]:.2f}, {k[1, 2] + 0.5:.2f} ± {sd[3]:.2f}",
              f"k1 {d[0]:.3g}, k2 {d[1]:.3g}, p1 {d[2]:.2g}, p2 {d[3]:.2g}, k3 {d[4]:.3g} "
              "(normalised, ideal → distorted)", dt)  # fmt: skip

    return [_row(ours), _row(cv_row)]


def _mei(rays, fx, fy, cx, cy, xi, k1, k2):
    s = rays / np.linalg.norm(rays, axis=1, keepdims=True)
    x, y = s[:, 0] / (s[:, 2] + xi), s[:, 1] / (s[:, 2] + xi)
    r2 = x * x + y * y
    f = 1 + k1 * r2 + k2 * r2 * r2
    return np.column_stack([fx * x * f + cx, fy * y * f + cy])


def fisheye() -> list[str]:
    spec = TargetSpec("chessboard", 4, 6, 1.0)  # 5 x 7 squares, unit squares (BoofCV)
    fld = target_field(spec)
    files = sorted((DATA / "fisheye-calibration" / "chessboard").glob("*.jpg"),
                   key=lambda p: int(p.stem))  # fmt: skip
    det = [detect_target(read_image_grey(p), spec, p.name) for p in files]
    found = sum(d.ids.size > 0 for d in det)
    rows = [f"| detections | {found} of {len(files)} images | | | | |"]
    boof = dict(fx=398.77492706579216, fy=398.7685638672075, cx=319.17879590584187,
                cy=319.71743712432686, xi=1.1331346732794045, k1=-0.24972089525362837,
                k2=0.009672326567075125)  # fmt: skip
    for proj in ("equidistant", "equisolid", "stereographic", "orthographic"):
        try:
            res, ours = _ours(fld, det, (640, 720), proj)
        except Exception as exc:
            rows.append(f"| ours {proj} | failed: {type(exc).__name__}: "
                        f"{str(exc)[:120]} | | | | |")  # fmt: skip
            continue
        diff = _map_diff(res.camera, lambda r: _mei(r, **boof), 90.0)
        name, rms, f, pp, ks, dt = ours
        rows.append(_row((name, rms, f, pp, ks + f"; vs BoofCV (Mei) projection, rays to 90°: "
                          f"max {diff:.1f} px", dt)))  # fmt: skip
    obj = [fld.coordinates(d.ids).astype(np.float64).reshape(-1, 1, 3) for d in det if d.ids.size]
    img = [(d.pixels - 0.5).reshape(-1, 1, 2) for d in det if d.ids.size]
    t = time.perf_counter()
    try:
        rms, k, dist, _, _ = cv2.fisheye.calibrate(
            obj, img, (640, 720), None, None,
            flags=cv2.fisheye.CALIB_RECOMPUTE_EXTRINSIC | cv2.fisheye.CALIB_FIX_SKEW,
            criteria=(cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 100, 1e-9))  # fmt: skip
        rows.append(_row(("OpenCV fisheye.calibrate (equidistant, θ polynomial)", rms,
                          f"{k[0, 0]:.2f} / {k[1, 1]:.2f}",
                          f"{k[0, 2] + 0.5:.2f}, {k[1, 2] + 0.5:.2f}",
                          "k1..k4 " + ", ".join(f"{x:.3g}" for x in dist.ravel()),
                          time.perf_counter() - t)))  # fmt: skip
    except cv2.error as exc:
        rows.append(f"| OpenCV fisheye.calibrate | failed: {str(exc).splitlines()[-1][:100]} "
                    "| | | | |")  # fmt: skip
    rows.append(f"| BoofCV (Mei, published) | not stated | {boof['fx']:.2f} / {boof['fy']:.2f} "
                f"(xi {boof['xi']:.3f}) | {boof['cx'] + 0.5:.2f}, {boof['cy'] + 0.5:.2f} | "
                f"k1 {boof['k1']:.4f}, k2 {boof['k2']:.4f} | |")  # fmt: skip
    return rows


if __name__ == "__main__":
    head = ("| method | RMS (px) | f (px) ± σ | principal point (px) ± σ | lens, statistics | "
            "time |\n|---|---|---|---|---|---|")  # fmt: skip
    print("ChArUco, 4 views (aruco-markers/charuco-calibration), 640 x 480\n")
    print(head)
    print("\n".join(charuco()))
    print("\nFisheye chessboard, BoofCV (fisheye-calibration), 640 x 720\n")
    print(head)
    print("\n".join(fisheye()))
