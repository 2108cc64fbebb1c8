"""Forward lens models (OpenCV, COLMAP): exact inversion, Jacobians, and OpenCV's projection."""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.geometry.camera import Camera, camera_from_dict
from lidarphoto.core.geometry.distortion import DISTORTION_MODELS, distortion_from_dict
from lidarphoto.core.geometry.forward_lens import (
    MetashapeLens,
    OpenCVFisheyeLens,
    OpenCVFullLens,
    OpenCVLens,
    ThinPrismFisheyeLens,
    opencv_coefficients,
)
from lidarphoto.core.geometry.projection import ideal_from_camera

F_MM = 4.0  # focal length of the test cameras, mm (1000 px of 4 um)
PS = 0.004

LENSES = {
    "opencv": OpenCVLens(k1=-0.28, k2=0.09, p1=1.2e-3, p2=-8e-4, k3=-0.01,
                         scale_mm=F_MM, aspect=1.003),
    "opencv_full": OpenCVFullLens(k1=0.12, k2=-0.03, p1=-6e-4, p2=9e-4, k3=0.002,
                                  k4=0.35, k5=-0.02, k6=0.004, scale_mm=F_MM, aspect=0.998),
    "opencv_fisheye": OpenCVFisheyeLens(k1=0.03, k2=-0.01, k3=0.002, k4=-3e-4,
                                        scale_mm=F_MM, aspect=1.0),
    "thin_prism_fisheye": ThinPrismFisheyeLens(k1=0.03, k2=-0.01, p1=6e-4, p2=-4e-4, k3=0.002,
                                               k4=-3e-4, sx1=5e-4, sy1=-3e-4, scale_mm=F_MM,
                                               aspect=1.003),
    "metashape": MetashapeLens(k1=-0.2, k2=0.06, k3=-0.01, k4=0.002, p1=-8e-4, p2=1.2e-3,
                               b1=0.8, b2=-0.3, scale_mm=F_MM, aspect=1.0, focal_px=1000.0),
}  # fmt: skip


def _ideal_grid(fisheye: bool) -> np.ndarray:
    # ideal points over a 1600 x 1200 px image (fisheye: to 75 degrees off the axis)
    rng = np.random.default_rng(3)
    half = np.array([3.2, 2.4]) if not fisheye else np.array([5.2, 5.2])
    return rng.uniform(-1, 1, size=(400, 2)) * half


def test_registered_and_round_trip_through_files() -> None:
    for name, lens in LENSES.items():
        assert DISTORTION_MODELS[name] is type(lens)
        assert distortion_from_dict(lens.to_dict()) == lens


@pytest.mark.parametrize("name", list(LENSES))
def test_forward_then_correction_round_trips(name: str) -> None:
    lens = LENSES[name]
    ideal = _ideal_grid(name.endswith("fisheye"))
    measured = lens.distort(ideal)
    back = measured + lens.correction(measured)
    assert np.max(np.abs(back - ideal)) < 1e-9
    # the distortion is not small (so the round trip tests something)
    assert np.max(np.hypot(*(measured - ideal).T)) > 0.05


@pytest.mark.parametrize("name", list(LENSES))
def test_jacobians_against_finite_differences(name: str) -> None:
    lens = LENSES[name]
    m = lens.distort(_ideal_grid(name.endswith("fisheye"))[:40])
    h = 1e-6
    jx = lens.jacobian_xy(m)
    for j in range(2):
        d = np.zeros(2)
        d[j] = h
        fd = (lens.correction(m + d) - lens.correction(m - d)) / (2 * h)
        np.testing.assert_allclose(jx[:, :, j], fd, atol=1e-7)
    jp = lens.jacobian_params(m)
    fwd = lens.forward_jacobian_params(lens.undistort(m))
    for k in range(lens.n_params):
        step = 1e-7
        p = lens.params
        p[k] += step
        hi = lens.with_params(p)
        p[k] -= 2 * step
        lo = lens.with_params(p)
        fd = (hi.correction(m) - lo.correction(m)) / (2 * step)
        np.testing.assert_allclose(jp[:, :, k], fd, atol=1e-6 * max(1.0, np.abs(fd).max()))
        ideal = lens.undistort(m)
        fdf = (hi.forward(ideal) - lo.forward(ideal)) / (2 * step)
        np.testing.assert_allclose(fwd[:, :, k], fdf, atol=1e-6 * max(1.0, np.abs(fdf).max()))


def _camera(lens, projection: str = "perspective") -> Camera:
    return Camera("c", F_MM, PS, 1600, 1200, 0.02, -0.012, lens, projection)


def _cv_points(n: int, max_angle_deg: float) -> np.ndarray:
    rng = np.random.default_rng(5)
    ang = np.radians(rng.uniform(0, max_angle_deg, n))
    az = rng.uniform(0, 2 * np.pi, n)
    rng_m = rng.uniform(2, 50, n)
    return np.column_stack([np.sin(ang) * np.cos(az), np.sin(ang) * np.sin(az),
                            np.cos(ang)]) * rng_m[:, None]  # fmt: skip


def _project_ours(cam: Camera, p_cv: np.ndarray) -> np.ndarray:
    # OpenCV's camera frame (x right, y down, z forward) -> the project's (y up, z back)
    q = p_cv * np.array([1.0, -1.0, -1.0])
    ideal, ok = ideal_from_camera(q, cam.focal_mm, cam.projection)
    assert np.all(ok)
    return cam.pixel_from_ideal(ideal)


@pytest.mark.parametrize("name", ["opencv", "opencv_full"])
def test_projection_matches_cv2_project_points(name: str) -> None:
    cv2 = pytest.importorskip("cv2")
    lens = LENSES[name]
    cam = _camera(lens)
    fx = cam.focal_px
    fy = fx * lens.constants["aspect"]
    cx, cy = cam.principal_point_px
    k = np.array([[fx, 0, cx], [0, fy, cy], [0, 0, 1.0]])
    c = dict(zip(lens.param_names, lens.params))
    dist = np.array([c.get(n, 0.0) for n in ("k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6")])
    pts = _cv_points(300, 38.0)
    ref, _ = cv2.projectPoints(pts, np.zeros(3), np.zeros(3), k, dist)
    ours = _project_ours(cam, pts)
    assert np.max(np.abs(ours - ref.reshape(-1, 2))) < 1e-6


def test_fisheye_projection_matches_cv2_fisheye() -> None:
    cv2 = pytest.importorskip("cv2")
    lens = LENSES["opencv_fisheye"]
    cam = _camera(lens, "equidistant")
    fx = cam.focal_px
    cx, cy = cam.principal_point_px
    k = np.array([[fx, 0, cx], [0, fx, cy], [0, 0, 1.0]])
    pts = _cv_points(300, 80.0).reshape(-1, 1, 3)
    ref, _ = cv2.fisheye.projectPoints(pts, np.zeros(3), np.zeros(3), k, lens.params)
    ours = _project_ours(cam, pts.reshape(-1, 3))
    assert np.max(np.abs(ours - ref.reshape(-1, 2))) < 1e-6


def test_rescaled_coefficients_keep_the_map() -> None:
    """With the focal length changed (self-calibration), the normalised coefficients follow."""
    lens = LENSES["opencv_full"]
    f_new = 4.4
    c = opencv_coefficients(lens, f_new)
    same = OpenCVFullLens(**c, scale_mm=f_new, aspect=lens.constants["aspect"])
    ideal = _ideal_grid(False)
    np.testing.assert_allclose(same.distort(ideal), lens.distort(ideal), atol=1e-12)
    fish = LENSES["opencv_fisheye"]
    same_f = OpenCVFisheyeLens(**opencv_coefficients(fish, f_new), scale_mm=f_new, aspect=1.0)
    np.testing.assert_allclose(same_f.distort(ideal), fish.distort(ideal), atol=1e-12)
    prism = LENSES["thin_prism_fisheye"]
    same_p = ThinPrismFisheyeLens(**opencv_coefficients(prism, f_new), scale_mm=f_new,
                                  aspect=prism.constants["aspect"])  # fmt: skip
    np.testing.assert_allclose(same_p.distort(ideal), prism.distort(ideal), atol=1e-12)


def test_camera_json_reads_a_forward_model() -> None:
    cam = _camera(LENSES["opencv"])
    assert camera_from_dict(cam.to_dict()) == cam


def test_bundle_adjustment_with_a_forward_lens_recovers_the_interior() -> None:
    """A block photographed through an OpenCV lens (held at its known coefficients) gives the
    true focal length and principal point within 3 sigma, and sigma0 passes the chi-square
    test: the forward model works through the bundle's interface."""
    from dataclasses import replace

    from lidarphoto.core.photo.bundle import bundle_adjust
    from lidarphoto.core.photo.bundle_setup import BundleOptions
    from lidarphoto.core.simulation.uav_block import UavBlockConfig, simulate_uav_block
    from scipy import stats

    nominal = UavBlockConfig().camera
    lens = OpenCVLens(k1=-0.09, k2=0.02, p1=4e-4, p2=-3e-4, scale_mm=nominal.focal_mm,
                      aspect=1.002)  # fmt: skip
    blk = simulate_uav_block("none", seed=2, n_tie=300, camera=replace(nominal, distortion=lens))
    corner = np.array([[0.5 * nominal.width_px, 0.5 * nominal.height_px]]) * nominal.pixel_size_mm
    assert np.hypot(*(lens.distort(corner) - corner)[0]) / nominal.pixel_size_mm > 20  # px
    opts = BundleOptions(ap_model="none", robust="none", snooping=False, ap_selection=False)
    res = bundle_adjust([blk.camera], blk.observations, blk.ground, blk.mapping, blk.eo_dg,
                        blk.eo_sigma, options=opts)  # fmt: skip
    assert res.adjustment.converged
    r = res.adjustment.redundancy
    lo, hi = stats.chi2.ppf([0.0005, 0.9995], r) / r
    assert lo < res.sigma0**2 < hi, res.sigma0
    truth = {"focal_mm": blk.true_camera.focal_mm, "x0_mm": blk.true_camera.x0_mm,
             "y0_mm": blk.true_camera.y0_mm}  # fmt: skip
    est = {p.name: p for p in res.interior if p.status == "estimated"}
    assert set(est) == set(truth)
    z = {n: (est[n].value - truth[n]) / est[n].std for n in truth}
    assert all(abs(v) < 3.0 for v in z.values()), z
