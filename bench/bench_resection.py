"""Space resection from points and lines against OpenCV and PoseLib, Monte Carlo, start
without approximate values and convergence from kappa errors (bench/resection.md).

    PYTHONPATH=<plugin parent>:<poselib folder> python bench/bench_resection.py

PoseLib (pip ``poselib``) is a benchmark-only peer: install it in a throw-away virtualenv and put
its package on the path; without it its columns are skipped. Synthetic scenes of
core/simulation/resection.py (100 mm camera, 6000 x 4000 px of 10 um, 800 m above a block of
roofs; 12 control points with 3 cm sigma, 24 LiDAR lines with 5 cm across; 0.5 px).
"""

from __future__ import annotations

import argparse
import math
import platform
import time
import warnings

import cv2
import numpy as np
from lidarphoto.core.geometry.rotations import opk_to_matrix
from lidarphoto.core.photo.resection import ResectionOptions, resect
from lidarphoto.core.simulation.resection import make_scene

try:
    import poselib
except ImportError:  # the bench still runs, without that peer
    poselib = None

D = np.diag([1.0, -1.0, -1.0])  # photogrammetric camera (z backwards, y up) -> OpenCV's


def _wrap(d):
    d = np.asarray(d, dtype=float).copy()
    d[..., 3:] = (d[..., 3:] + np.pi) % (2 * np.pi) - np.pi
    return d


def _cv_pixels(px, cam):
    """Pixels of an ideal (distortion-free, centred) pinhole with the camera's focal length in
    pixels; our image coordinates (mm, y up) mapped to them, so the peers see the same rays."""
    xy = cam.ideal_from_pixel(np.asarray(px, dtype=float))
    f = cam.focal_mm / cam.pixel_size_mm
    k = np.array([[f, 0, cam.width_px / 2], [0, f, cam.height_px / 2], [0, 0, 1.0]])
    uv = np.column_stack([xy[:, 0], -xy[:, 1]]) / cam.pixel_size_mm + k[:2, 2]
    return uv, k


def _pose_from_cv(rot, t):
    """(X0, Y0, Z0, rotation matrix M of the photogrammetric camera) from OpenCV's R, t."""
    m = D @ rot
    return -rot.T @ t, m


def _compare(ours_eo, centre, m):
    """Position difference (m) and rotation angle between the two poses (rad)."""
    m_ours = opk_to_matrix(*ours_eo[3:])
    dr = m_ours @ m.T
    ang = math.acos(max(-1.0, min(1.0, (np.trace(dr) - 1) / 2)))
    return ours_eo[:3] - centre, ang


def opencv_pose(data, cam):
    uv, k = _cv_pixels(data.pixels, cam)
    _ok, rvec, tvec = cv2.solvePnP(data.xyz, uv, k, None, flags=cv2.SOLVEPNP_SQPNP)
    rvec, tvec = cv2.solvePnPRefineLM(data.xyz, uv, k, None, rvec, tvec)
    rot = cv2.Rodrigues(rvec)[0]
    return _pose_from_cv(rot, tvec.ravel())


def poselib_pose(data, cam, points=True, lines=True):
    f = cam.focal_mm / cam.pixel_size_mm
    camera = {"model": "PINHOLE", "width": cam.width_px, "height": cam.height_px,
              "params": [f, f, cam.width_px / 2, cam.height_px / 2]}  # fmt: skip
    ransac = {"max_reproj_error": 3.0, "max_epipolar_error": 3.0}
    bundle = {"loss_type": "TRIVIAL"}
    if points and not lines:
        uv, _ = _cv_pixels(data.pixels, cam)
        pose, _ = poselib.estimate_absolute_pose(uv, data.xyz, camera, ransac, bundle)
    else:
        uv = _cv_pixels(data.pixels, cam)[0] if points else np.empty((0, 2))
        xyz = data.xyz if points else np.empty((0, 3))
        a = np.array([_cv_pixels(v[:1], cam)[0][0] for v in data.line_pixels])
        b = np.array([_cv_pixels(v[-1:], cam)[0][0] for v in data.line_pixels])
        pose, _info = poselib.estimate_absolute_pose_pnpl(uv, xyz, a, b, data.line_p1,
                                                          data.line_p2, camera, ransac, bundle)
    return _pose_from_cv(pose.R, np.asarray(pose.t))


def monte_carlo(n: int, seed: int = 2024) -> list[str]:
    scene = make_scene(11, line_sigma_m=0.05, point_sigma_m=0.03)
    rng = np.random.default_rng(seed)
    out = ["| data | parameter | RMSE | mean reported sigma | RMSE / sigma | OpenCV RMSE | "
           "PoseLib RMSE |", "|---|---|---|---|---|---|---|"]  # fmt: skip
    timing = {}
    agree = {}
    for what, kw in (("points", dict(points=True, lines=False)),
                     ("lines", dict(points=False, lines=True)),
                     ("mixed", dict(points=True, lines=True))):  # fmt: skip
        err, sig, s0, e_cv, e_pl, t_ours, t_cv, t_pl, d_peer = [], [], [], [], [], [], [], [], []
        for _ in range(n):
            data = scene.observe(rng, 0.5, **kw)
            t0 = time.perf_counter()
            res = resect(data, scene.camera, ResectionOptions(snooping=False))
            t_ours.append(time.perf_counter() - t0)
            err.append(_wrap(res.eo - scene.eo))
            sig.append(res.std_prior)
            s0.append(res.sigma0)
            if what == "points":
                t0 = time.perf_counter()
                c, m = opencv_pose(data, scene.camera)
                t_cv.append(time.perf_counter() - t0)
                e_cv.append(_compare(scene.eo, c, m))
            if poselib is not None:
                t0 = time.perf_counter()
                c, m = poselib_pose(data, scene.camera, kw["points"], kw["lines"])
                t_pl.append(time.perf_counter() - t0)
                e_pl.append(_compare(scene.eo, c, m))
                dp, da = _compare(res.eo, c, m)
                d_peer.append(np.r_[np.abs(dp) / res.std[:3], da])
        err, sig = np.array(err), np.array(sig)
        rmse = np.sqrt(np.mean(err**2, axis=0))
        msig = np.mean(sig, axis=0)
        names = ("X0 m", "Y0 m", "Z0 m", "omega mdeg", "phi mdeg", "kappa mdeg")
        scale = np.r_[1, 1, 1, [1000 * 180 / math.pi] * 3]

        def peer(e, j):
            if not e or j >= 3:
                return "-"
            return f"{np.sqrt(np.mean([x[0][j] ** 2 for x in e])):.3f}"

        for j in range(6):
            out.append(f"| {what} | {names[j]} | {rmse[j] * scale[j]:.3f} | "
                       f"{msig[j] * scale[j]:.3f} | {rmse[j] / msig[j]:.3f} | "
                       f"{peer(e_cv, j)} | {peer(e_pl, j)} |")  # fmt: skip
        rot_err = [math.degrees(_compare(scene.eo + e, scene.eo[:3], opk_to_matrix(
            *scene.eo[3:]))[1]) * 1000 for e in err]  # fmt: skip
        out.append(f"| {what} | rotation angle mdeg (RMS) | "
                   f"{np.sqrt(np.mean(np.square(rot_err))):.2f} | | | "
                   f"{_rms_angle(e_cv)} | {_rms_angle(e_pl)} |")  # fmt: skip
        timing[what] = (np.median(t_ours) * 1e3, np.median(t_cv) * 1e3 if t_cv else math.nan,
                        np.median(t_pl) * 1e3 if t_pl else math.nan,
                        float(np.mean(np.square(s0))))  # fmt: skip
        if d_peer:
            d = np.array(d_peer)
            agree[what] = (np.max(d[:, :3]), np.degrees(np.max(d[:, 3])) * 1000)
    out.append("")
    out.append("| data | ours ms (median) | OpenCV ms | PoseLib ms | mean sigma0^2 |")
    out.append("|---|---|---|---|---|")
    for what, (a, b, c, s) in timing.items():
        out.append(f"| {what} | {a:.1f} | {b:.2f} | {c:.2f} | {s:.3f} |")
    if agree:
        out.append("")
        out.append("Largest difference ours - PoseLib over the draws: position in units of our "
                   "sigma, rotation angle in millidegrees: " + "; ".join(
                       f"{k} {a:.3f} sigma, {b:.3f} mdeg" for k, (a, b) in agree.items()))
    return out


def _rms_angle(e) -> str:
    if not e:
        return "-"
    return f"{np.degrees(np.sqrt(np.mean([x[1] ** 2 for x in e]))) * 1000:.2f}"


def start_anywhere(n: int, seed: int = 31) -> list[str]:
    """No approximate values: kappa anywhere, tilts to 20 degrees, 300-2000 m, few data."""
    rng = np.random.default_rng(seed)
    counts = {w: [0, 0, 0] for w in ("points", "lines", "mixed")}
    for trial in range(n):
        eo = np.array([rng.uniform(-50, 50), rng.uniform(-50, 50), 0.0,
                       rng.uniform(-0.35, 0.35), rng.uniform(-0.35, 0.35),
                       rng.uniform(-np.pi, np.pi)])  # fmt: skip
        eo[2] = rng.uniform(300, 2000)
        scene = make_scene(100 + trial, height_m=eo[2], eo=eo, n_points=6, n_lines=8)
        for what in counts:
            data = scene.observe(rng, 0.5, points=what != "lines", lines=what != "points")
            try:
                res = resect(data, scene.camera)
                ok = bool(np.all(np.abs(_wrap(res.eo - scene.eo)) < 5.0 * res.std))
            except Exception:  # a failure is counted, not fatal
                ok = False
            counts[what][0] += ok
            if poselib is not None:
                try:
                    c, m = poselib_pose(data, scene.camera, what != "lines", what != "points")
                    dp, _da = _compare(scene.eo, c, m)
                    res_ok = bool(np.all(np.abs(dp) < 5.0 * res.std[:3] + 0.01))
                    counts[what][1] += res_ok
                except Exception:
                    pass
            counts[what][2] += 1
    out = ["| data (6 points / 8 lines) | ours: recovered | PoseLib: recovered | images |",
           "|---|---|---|---|"]  # fmt: skip
    for what, (a, b, k) in counts.items():
        out.append(f"| {what} | {a} | {b if poselib is not None else '-'} | {k} |")
    return out


def kappa_regions(step: int = 5) -> list[str]:
    warnings.simplefilter("ignore", RuntimeWarning)
    scene = make_scene(1)
    data = scene.observe(np.random.default_rng(5), points=False)
    out = ["| line model | parametrisation | damping | converges from kappa errors up to "
           "(degrees, both signs) | first failure |", "|---|---|---|---|---|"]  # fmt: skip
    for model, par, damp in (("coplanarity", "auto", True), ("coplanarity", "auto", False),
                             ("equivalent_planes", "auto", True),
                             ("equivalent_planes", "auto", False),
                             ("equivalent_planes", "horizontal", True),
                             ("equivalent_planes", "vertical", True)):  # fmt: skip
        opts = ResectionOptions(model=model, parametrisation=par, snooping=False,
                                damping=damp, max_iterations=100)  # fmt: skip
        ref = resect(data, scene.camera, opts, eo0=scene.eo)
        last, fail = 0, None
        for dk in range(step, 181, step):
            good = True
            for sign in (1, -1):
                e0 = ref.eo.copy()
                e0[5] += sign * math.radians(dk)
                try:
                    res = resect(data, scene.camera, opts, eo0=e0)
                    good &= bool(np.all(np.abs(_wrap(res.eo - ref.eo)) < 0.05 * ref.std))
                except Exception:
                    good = False
            if not good:
                fail = dk
                break
            last = dk
        out.append(f"| {model} | {par} | {'yes' if damp else 'no'} | {last} | "
                   f"{fail if fail is not None else 'none up to 180'} |")
    return out


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--draws", type=int, default=300)
    ap.add_argument("--starts", type=int, default=60)
    ap.add_argument("--skip-kappa", action="store_true")
    a = ap.parse_args()
    print(f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; {platform.processor() or platform.machine()}"  # noqa: E501
          f"; Python {platform.python_version()}, numpy {np.__version__}, OpenCV "
          f"{cv2.__version__}, PoseLib {getattr(poselib, '__version__', 'absent')}")
    t = time.perf_counter()
    print("\n## Monte Carlo and peers\n")
    print("\n".join(monte_carlo(a.draws)))
    print(f"\n({time.perf_counter() - t:.0f} s)\n\n## Start without approximate values\n")
    print("\n".join(start_anywhere(a.starts)))
    if not a.skip_kappa:
        print("\n## Convergence from kappa errors\n")
        print("\n".join(kappa_regions()))
    print(f"\ntotal {time.perf_counter() - t:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
