"""Fisheye projections, calibration targets and the camera calibration against truth."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from lidarphoto.core.errors import InputError, NotObservableError
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.collinearity import collinearity_jacobians, image_rays, project
from lidarphoto.core.geometry.distortion import BrownConrady
from lidarphoto.core.geometry.projection import (
    PROJECTIONS,
    ideal_from_camera,
    radius_factor,
    ray_from_ideal,
)
from lidarphoto.core.io.camera import read_camera_json, write_camera_json
from lidarphoto.core.photo.calibration_targets import (
    TargetSpec,
    detect_target,
    target_field,
)
from lidarphoto.core.photo.camera_calibration import (
    CalibrationOptions,
    calibrate_camera,
    look_at_eo,
    simulate_views,
)

cv2 = pytest.importorskip("cv2")
SHARED = Path(__file__).resolve().parents[3] / "shared" / "data"
CHARUCO = Path(__file__).resolve().parents[1] / "data" / "charuco"  # copied, Apache-2.0
PS = 0.004  # mm


def _camera(projection: str) -> Camera:
    if projection == "perspective":
        return Camera("t", 1000 * PS, PS, 1280, 960, 0.02, -0.015,
                      BrownConrady(k1=-2e-3, k2=5e-5, p1=1e-4, p2=-5e-5))  # fmt: skip
    return Camera("t", 300 * PS, PS, 1280, 960, 0.02, -0.015,
                  BrownConrady(k1=-1e-3, k2=2e-5, p1=1e-4, p2=-5e-5),
                  projection=projection)  # fmt: skip


def _views(projection: str, n: int = 12, seed: int = 1, parallel: bool = False) -> np.ndarray:
    fld = target_field(TargetSpec("chessboard", 9, 6, 0.05))
    ctr = fld.xyz.mean(0)
    rng = np.random.default_rng(seed)
    eos = []
    for i in range(n):
        az = 2 * np.pi * i / n
        tilt = 0.0 if parallel else np.radians(rng.uniform(15, 40))
        d = (0.6 if projection == "perspective" else 0.35) * (1 + 0.1 * parallel * i)
        c = ctr + d * np.array([np.sin(tilt) * np.cos(az), np.sin(tilt) * np.sin(az),
                                np.cos(tilt)])  # fmt: skip
        tgt = ctr + (0 if projection == "perspective" else rng.uniform(-0.3, 0.3, 3) * [1, 1, 0])
        eos.append(look_at_eo(c, tgt, 0.0 if parallel else rng.uniform(-0.5, 0.5)))
    return np.array(eos)


# ----------------------------------------------------------------------------- projections
@pytest.mark.parametrize("projection", PROJECTIONS)
def test_projection_round_trip_and_radius(projection):
    rng = np.random.default_rng(0)
    lim = 85.0 if projection in ("perspective", "orthographic") else 170.0
    theta = np.radians(rng.uniform(0.0, lim, 200))
    az = rng.uniform(-np.pi, np.pi, 200)
    q = np.column_stack([np.sin(theta) * np.cos(az), np.sin(theta) * np.sin(az), -np.cos(theta)])
    q *= rng.uniform(0.5, 20.0, (200, 1))
    ideal, ok = ideal_from_camera(q, 3.0, projection)
    assert ok.all()
    # r = f g(theta), in the direction of (u, v)
    np.testing.assert_allclose(np.hypot(*ideal.T), 3.0 * radius_factor(theta, projection),
                               rtol=1e-12, atol=1e-12)  # fmt: skip
    ray = ray_from_ideal(ideal, 3.0, projection)
    ray /= np.linalg.norm(ray, axis=1, keepdims=True)
    np.testing.assert_allclose(ray, q / np.linalg.norm(q, axis=1, keepdims=True), atol=1e-12)


def test_equidistant_is_f_theta_and_outside_is_refused():
    theta = np.array([0.0, 0.3, 1.2, 2.5])
    q = np.column_stack([np.sin(theta), np.zeros(4), -np.cos(theta)])
    ideal, ok = ideal_from_camera(q, 2.0, "equidistant")
    assert ok.all() and ideal[:, 0].tolist() == pytest.approx((2.0 * theta).tolist(), abs=1e-15)
    _, ok = ideal_from_camera([[1.0, 0.0, 0.1]], 2.0, "orthographic")  # 95 deg off-axis
    assert not ok[0]
    _, ok = ideal_from_camera([[1.0, 0.0, 0.1]], 2.0, "perspective")  # behind
    assert not ok[0]


@pytest.mark.parametrize("projection", PROJECTIONS)
def test_collinearity_jacobians_match_finite_differences(projection):
    cam = _camera(projection)
    rng = np.random.default_rng(2)
    eo = np.array([0.1, -0.2, 0.5, 0.1, -0.2, 0.3])
    m_obj = np.column_stack([rng.uniform(-0.3, 0.3, 30), rng.uniform(-0.5, 0.1, 30),
                             np.zeros(30)])  # fmt: skip
    out = collinearity_jacobians(m_obj, eo, cam)
    assert np.isfinite(out["pixels"]).all()
    h = 1e-6
    for k in range(6):
        d = np.zeros(6)
        d[k] = h
        num = (project(m_obj, eo + d, cam) - project(m_obj, eo - d, cam)) / (2 * h)
        np.testing.assert_allclose(out["eo"][:, :, k], num, rtol=1e-5, atol=1e-3)
    p = cam.interior_params
    for k in range(p.size):
        d = np.zeros(p.size)
        d[k] = h * max(abs(p[k]), 1e-3)
        num = (project(m_obj, eo, cam.with_interior(p + d))
               - project(m_obj, eo, cam.with_interior(p - d))) / (2 * d[k])  # fmt: skip
        np.testing.assert_allclose(out["interior"][:, :, k], num, rtol=1e-4,
                                   atol=1e-4 * np.abs(num).max())  # fmt: skip
    # back-projection: the rays through the projected pixels pass through the points
    origin, direction = image_rays(out["pixels"], eo, cam)
    to_pt = m_obj - origin
    along = np.sum(to_pt * direction, axis=1)
    miss = np.linalg.norm(to_pt - along[:, None] * direction, axis=1)
    assert (along > 0).all() and miss.max() < 1e-9


def test_equidistant_matches_opencv_fisheye_on_points():
    """OpenCV's fisheye model with D = 0 is the equidistant projection r = f theta."""
    cam = Camera("t", 300 * PS, PS, 1280, 960, 0.02, -0.015, projection="equidistant")
    rng = np.random.default_rng(4)
    theta = np.radians(rng.uniform(0, 89, 100))
    az = rng.uniform(-np.pi, np.pi, 100)
    p_cv = np.column_stack([np.sin(theta) * np.cos(az), np.sin(theta) * np.sin(az), np.cos(theta)])
    f_px = cam.focal_px
    cx, cy = cam.principal_point_px
    k = np.array([[f_px, 0, cx - 0.5], [0, f_px, cy - 0.5], [0, 0, 1.0]])
    cv_px, _ = cv2.fisheye.projectPoints(p_cv[:, None, :], np.zeros(3), np.zeros(3), k,
                                         np.zeros(4))  # fmt: skip
    # OpenCV camera: y down, z forward -> the project's: y up, z back (omega = 180 deg)
    ours = project(p_cv, [0, 0, 0, math.pi, 0, 0], cam) - 0.5
    np.testing.assert_allclose(ours, cv_px.reshape(-1, 2), atol=1e-9)


def test_fisheye_camera_file_round_trip_and_refusal(tmp_path):
    cam = _camera("stereographic")
    path = tmp_path / "fish.json"
    write_camera_json(path, cam)
    assert json.loads(path.read_text())["projection"] == "stereographic"
    assert read_camera_json(path, projections=PROJECTIONS) == cam
    with pytest.raises(InputError, match=r"fish\.json.*stereographic \(fisheye\) projection"):
        read_camera_json(path)
    persp = tmp_path / "persp.json"
    write_camera_json(persp, _camera("perspective"))
    assert "projection" not in json.loads(persp.read_text())  # old files stay identical
    bad = json.loads(path.read_text())
    bad["projection"] = "fisheye"
    path.write_text(json.dumps(bad))
    with pytest.raises(InputError, match="key 'projection': unknown projection 'fisheye'"):
        read_camera_json(path, projections=PROJECTIONS)


# ----------------------------------------------------------------------------- calibration
def _within(res, cam, k_sigma=4.0):
    truth = dict(zip(cam.interior_names, cam.interior_params))
    est = dict(zip(res.camera.interior_names, res.camera.interior_params))
    for name, s in res.sigmas.items():
        assert abs(est[name] - truth[name]) < k_sigma * s, (name, est[name], truth[name], s)


@pytest.mark.parametrize("projection", PROJECTIONS)
def test_calibration_recovers_synthetic_camera(projection):
    cam = _camera(projection)
    fld = target_field(TargetSpec("chessboard", 9, 6, 0.05))
    det = simulate_views(cam, fld, _views(projection), noise_px=0.2, seed=3)
    res = calibrate_camera(fld, det, 1280, 960, PS,
                           CalibrationOptions(projection=projection, sigma_px=0.2))  # fmt: skip
    assert res.camera.projection == projection
    # sigma0 = 1 within the 99.9 % chi-square band of the redundancy
    assert abs(res.sigma0 - 1.0) < 3.3 / math.sqrt(2 * res.redundancy)
    assert res.adjustment.global_test.passed
    _within(res, cam)
    # focal length to better than 0.1 % from 0.2 px noise
    assert abs(res.camera.focal_px - cam.focal_px) < 1e-3 * cam.focal_px
    assert res.correlation.shape == (8, 8)
    assert np.allclose(np.diag(res.correlation), 1.0)
    assert res.view_rms_px.shape == (12,) and (res.view_rms_px < 0.5).all()


def test_calibration_free_field_absorbs_a_bent_target():
    cam = _camera("perspective")
    fld = target_field(TargetSpec("chessboard", 9, 6, 0.05))
    # the real target is bent by up to 3 mm (not flat): the nominal field is wrong
    from dataclasses import replace

    bent = fld.xyz.copy()
    bent[:, 2] = 0.003 * np.sin(np.pi * bent[:, 0] / bent[:, 0].max())
    det = simulate_views(cam, replace(fld, xyz=bent), _views("perspective"), 0.2, seed=5)
    free = calibrate_camera(fld, det, 1280, 960, PS, CalibrationOptions(field="free"))
    fixed = calibrate_camera(fld, det, 1280, 960, PS, CalibrationOptions(field="fixed"))
    assert abs(free.sigma0 - 1.0) < 0.15 and fixed.sigma0 > 2.0
    _within(free, cam)
    np.testing.assert_allclose(free.field_xyz[:, 2], bent[:, 2], atol=6e-4)


def test_monte_carlo_sigma_of_the_focal_length():
    cam = _camera("equidistant")
    fld = target_field(TargetSpec("chessboard", 9, 6, 0.05))
    eos = _views("equidistant")
    f_est, f_sig = [], []
    for s in range(25):
        det = simulate_views(cam, fld, eos, noise_px=0.3, seed=100 + s)
        res = calibrate_camera(fld, det, 1280, 960, PS, CalibrationOptions(
            projection="equidistant", sigma_px=0.3))  # fmt: skip
        f_est.append(res.camera.focal_mm)
        f_sig.append(res.adjustment.std_prior[0])
    mc = float(np.std(f_est, ddof=1))
    # 25 samples: the sample std is within +-40 % of the true one at about 99 %
    assert 0.6 < mc / float(np.mean(f_sig)) < 1.4
    assert abs(np.mean(f_est) - cam.focal_mm) < 4 * mc / 5


def test_parallel_views_do_not_determine_the_focal_length():
    cam = _camera("perspective")
    fld = target_field(TargetSpec("chessboard", 9, 6, 0.05))
    det = simulate_views(cam, fld, _views("perspective", n=5, parallel=True), 0.0)
    with pytest.raises(NotObservableError, match=r"not all parallel") as exc:
        calibrate_camera(fld, det, 1280, 960, PS, CalibrationOptions(
            lens_parameters=(), sigma_px=0.2))  # fmt: skip
    assert "focal_mm" in exc.value.parameters
    with pytest.raises(NotObservableError, match="at least 2 views"):
        calibrate_camera(fld, det[:1], 1280, 960, PS)


# ----------------------------------------------------------------------------- detection
def test_charuco_detection_on_a_rendered_board():
    spec = TargetSpec("charuco", 5, 7, 0.04, 0.02, "DICT_6X6_250")
    fld = target_field(spec)
    board = cv2.aruco.CharucoBoard((5, 7), 0.04, 0.02,
                                   cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_6X6_250))
    img = board.generateImage((500, 700), marginSize=0)  # squares of 100 px
    img = cv2.GaussianBlur(cv2.copyMakeBorder(img, 30, 30, 30, 30, cv2.BORDER_CONSTANT,
                                              value=255), (0, 0), 1.0)  # fmt: skip
    det = detect_target(img, spec)
    assert det.ids.size == fld.ids.size == 24
    # square edges at whole pixels: corners at 30 + 100 k in the project's convention
    truth = 30 + fld.coordinates(det.ids)[:, :2] / 0.04 * 100
    np.testing.assert_allclose(det.pixels, truth, atol=0.02)


def test_chessboard_detection_on_a_rendered_board():
    spec = TargetSpec("chessboard", 7, 5, 0.03)
    sq = 40
    img = np.full((6 * sq + 2 * 60, 8 * sq + 2 * 60), 255, np.uint8)
    for r in range(6):
        for c in range(8):
            if (r + c) % 2 == 0:
                img[60 + r * sq: 60 + (r + 1) * sq, 60 + c * sq: 60 + (c + 1) * sq] = 0
    det = detect_target(cv2.GaussianBlur(img, (0, 0), 1.0), spec)
    assert det.ids.size == 35
    fld = target_field(spec)
    xy = fld.coordinates(det.ids)[:, :2] / 0.03 * sq + 60 + sq
    # the detector may number the corners from either end of a symmetric board
    err = min(np.abs(det.pixels - xy).max(), np.abs(det.pixels - xy[::-1]).max())
    assert err < 0.05


def test_charuco_calibration_on_real_views_matches_opencv():
    """The 4 ChArUco views of OpenCV's tutorial: our adjustment vs cv2.calibrateCamera on the
    same detections (OpenCV's k1 k2 p1 p2 k3 model)."""
    spec = TargetSpec("charuco", 5, 7, 0.04, 0.02, "DICT_6X6_250")
    fld = target_field(spec)
    folder = CHARUCO
    det = [detect_target(cv2.imread(str(p)), spec, p.name)
           for p in sorted(folder.glob("img_*.jpg"))]  # fmt: skip
    assert [d.ids.size for d in det] == [24, 24, 24, 24]
    res = calibrate_camera(fld, det, 640, 480, 0.003, CalibrationOptions(sigma_px=0.2))
    obj = [fld.coordinates(d.ids).astype(np.float32) for d in det]
    img = [(d.pixels - 0.5).astype(np.float32) for d in det]
    rms, k, _, _, _, sd, _, _ = cv2.calibrateCameraExtended(obj, img, (640, 480), None, None)
    sd = sd.ravel()
    # same RMS within 2 % (the two lens models differ: OpenCV distorts ideal points, ours
    # corrects measured ones; OpenCV has fx and fy apart)
    assert abs(res.rms_px - rms) < 0.02 * rms
    # f and the principal point agree within 2 combined sigmas (ours and OpenCV's own)
    ps = 0.003
    cx, cy = res.camera.principal_point_px
    for ours, sig, cv_value, cv_sig in (
        (res.camera.focal_px, res.sigmas["focal_mm"] / ps, 0.5 * (k[0, 0] + k[1, 1]), sd[0]),
        (cx, res.sigmas["x0_mm"] / ps, k[0, 2] + 0.5, sd[2]),
        (cy, res.sigmas["y0_mm"] / ps, k[1, 2] + 0.5, sd[3]),
    ):
        assert abs(ours - cv_value) < 2.0 * math.hypot(sig, cv_sig), (ours, cv_value, sig)


@pytest.mark.skipif(not (SHARED / "fisheye-calibration").is_dir(), reason="shared data absent")
def test_fisheye_calibration_on_real_views_matches_boofcv():
    """BoofCV's 190-degree fisheye chessboard set: our equidistant + Brown model against
    BoofCV's published Mei-model calibration, compared by the projection of rays (the two
    models' parameters do not correspond); acceptance from the data's MANIFEST."""
    from lidarphoto.core.io.calibration import read_image_grey

    spec = TargetSpec("chessboard", 4, 6, 1.0)
    fld = target_field(spec)
    files = sorted((SHARED / "fisheye-calibration" / "chessboard").glob("*.jpg"))
    det = [detect_target(read_image_grey(p), spec, p.name) for p in files]
    assert sum(d.ids.size == 24 for d in det) == 26
    res = calibrate_camera(fld, det, 640, 720, 0.003, CalibrationOptions(
        projection="equidistant", sigma_px=0.2))  # fmt: skip
    assert res.rms_px < 0.5
    cx, cy = res.camera.principal_point_px
    # BoofCV's principal point (pixel centres at integers) + 0.5, within 3 px
    assert abs(cx - 319.68) < 3.0 and abs(cy - 320.22) < 3.0
    th = np.radians(np.linspace(0.0, 90.0, 30))
    ray = np.column_stack([np.sin(th), np.zeros_like(th), np.cos(th)])  # OpenCV frame
    s = ray / np.linalg.norm(ray, axis=1, keepdims=True)
    xi, k1, k2 = 1.1331346732794045, -0.24972089525362837, 0.009672326567075125
    x = s[:, 0] / (s[:, 2] + xi)
    mei = 398.77492706579216 * x * (1 + k1 * x * x + k2 * x**4)
    ours = project(ray, [0, 0, 0, math.pi, 0, 0], res.camera)[:, 0] - cx
    assert np.max(np.abs(ours - mei)) < 3.0


def test_perspective_only_kernels_refuse_a_fisheye_camera():
    """A perspective-only kernel refuses a fisheye camera by name (Camera.require_perspective),
    never treating it as a perspective one. Every algorithm now takes fisheye cameras but the
    resection's straight lines (tests/core/test_bundle_fisheye.py): the bundle adjustment,
    resection from points, monoplotting, orthophotos, tie points, the boresight calibration
    and control location (tests/core/test_*_fisheye.py, test_locate_fisheye.py)."""
    cam = _camera("equisolid")
    who = "the resection from straight lines"
    with pytest.raises(InputError, match=f"equisolid \\(fisheye\\) projection; {who} handles"):
        cam.require_perspective(who)
    _camera("perspective").require_perspective(who)  # no error
