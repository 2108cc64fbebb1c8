"""The rigorous resection (core/photo/resection.py) with a fisheye camera, against truth.

Truth: control points projected through each fisheye projection of core/geometry/projection.py
(with a Brown lens) from a known pose, some of them more than 90 degrees off the axis (walls
above a nadir camera: the model must be the projection itself, not an undistorted perspective
image); Gaussian noise of known sigma on the pixels. The recovered pose must be exact without
noise, within 4 of its reported sigmas with noise, and the reported sigmas must agree with the
scatter of a Monte Carlo run. Straight lines stay perspective-only: with a fisheye camera
they must be refused, naming it.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.collinearity import project
from lidarphoto.core.geometry.distortion import BrownConrady
from lidarphoto.core.geometry.projection import FISHEYE_PROJECTIONS
from lidarphoto.core.io.camera import write_camera_json
from lidarphoto.core.jobs import resection as resection_job
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.photo.pose_start import initial_pose_pnp
from lidarphoto.core.photo.resection import ResectionData, ResectionOptions, resect
from lidarphoto.core.simulation.resection import make_scene, write_scene_files

EO = np.array([0.3, -0.2, 2.0, *np.radians([4.0, -3.0, 35.0])])
SIGMA_PX = 0.3


def _camera(projection: str) -> Camera:
    return Camera("fish", 1.6, 0.004, 2600, 2600, 0.01, -0.008,
                  BrownConrady(k1=2e-3, k2=-1e-4, p1=5e-5), projection=projection)  # fmt: skip


def _points(projection: str) -> np.ndarray:
    """Ground points around the nadir camera and, except for the orthographic projection
    (which ends at 90 degrees), points on walls above the camera, beyond 90 degrees."""
    rng = np.random.default_rng(4)
    ground = np.column_stack([rng.uniform(-3, 3, (14, 2)), rng.uniform(0.0, 0.3, 14)])
    az = np.linspace(0, 2 * np.pi, 6, endpoint=False)
    wall = np.column_stack([3.0 * np.cos(az), 3.0 * np.sin(az), np.full(6, 3.0)])
    return ground if projection == "orthographic" else np.vstack([ground, wall])


def _angles_off_axis(pts: np.ndarray, eo: np.ndarray) -> np.ndarray:
    from lidarphoto.core.geometry.rotations import opk_to_matrix

    q = (pts - eo[:3]) @ opk_to_matrix(*eo[3:]).T
    return np.degrees(np.arctan2(np.hypot(q[:, 0], q[:, 1]), -q[:, 2]))


@pytest.mark.parametrize("projection", FISHEYE_PROJECTIONS)
def test_noise_free_fisheye_resection_is_exact(projection):
    cam = _camera(projection)
    pts = _points(projection)
    px = project(pts, EO, cam)
    assert np.isfinite(px).all() and cam.in_frame(px).all()
    theta = _angles_off_axis(pts, EO)
    if projection != "orthographic":
        assert theta.max() > 100.0  # the walls are behind the image plane of a perspective
    data = ResectionData(tuple(map(str, range(len(pts)))), px, SIGMA_PX, pts)
    # no start pose: the global search and OpenCV's PnP on the normalised rays in front
    res = resect(data, cam)
    np.testing.assert_allclose(res.eo, EO, atol=1e-8)
    assert res.redundancy == 2 * len(pts) - 6
    # OpenCV's start alone (rays beyond 90 degrees left out) lands near the truth
    start = initial_pose_pnp(px, pts, cam)
    np.testing.assert_allclose(start, EO, atol=1e-6)
    # f, x0, y0 refined too (the projection's ideal point is linear in f): from a camera 2 %
    # and 0.05 mm off, the truth again
    if projection != "orthographic":  # ground points only: f and the height trade off
        off = dataclasses.replace(cam, focal_mm=1.02 * cam.focal_mm, x0_mm=cam.x0_mm + 0.05,
                                  y0_mm=cam.y0_mm - 0.05)  # fmt: skip
        res = resect(data, off, ResectionOptions(estimate_interior=True), eo0=EO)
        np.testing.assert_allclose(res.interior, [cam.focal_mm, cam.x0_mm, cam.y0_mm],
                                   atol=1e-9)  # fmt: skip
        np.testing.assert_allclose(res.eo, EO, atol=1e-8)


@pytest.mark.parametrize("projection", ["equidistant", "equisolid"])
def test_fisheye_resection_sigmas_agree_with_monte_carlo(projection):
    """200 noisy resections: the scatter of each parameter within 20 % of the reported
    a-priori sigma (the relative sampling error of a standard deviation from 200 draws is
    5 %), the mean within 4 sigma / sqrt(200) of the truth, and each run within 4 sigma."""
    cam = _camera(projection)
    pts = _points(projection)
    px = project(pts, EO, cam)
    rng = np.random.default_rng(11)
    est, std = [], None
    for _ in range(200):
        noisy = px + rng.normal(0.0, SIGMA_PX, px.shape)
        data = ResectionData(tuple(map(str, range(len(pts)))), noisy, SIGMA_PX, pts)
        res = resect(data, cam, ResectionOptions(snooping=False), eo0=EO)
        assert (np.abs(res.eo - EO) < 4.0 * res.std_prior + 1e-12).all()
        est.append(res.eo)
        std = res.std_prior
    est = np.array(est)
    scatter = est.std(axis=0, ddof=1)
    assert (np.abs(scatter / std - 1.0) < 0.2).all(), (scatter, std)
    assert (np.abs(est.mean(axis=0) - EO) < 4.0 * std / np.sqrt(len(est))).all()


def test_lines_with_a_fisheye_camera_are_refused_by_name():
    cam = _camera("equidistant")
    pts = _points("equidistant")[:4]
    p1 = np.array([[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0]])
    p2 = np.array([[1.0, -1.0, 0.0], [1.0, 1.0, 0.0]])
    lines = tuple(project(np.vstack([a, b]), EO, cam) for a, b in zip(p1, p2))
    data = ResectionData(("a", "b", "c", "d"), project(pts, EO, cam), 0.5, pts, None,
                         ("1", "2"), lines, (0.5, 0.5), p1, p2, None)  # fmt: skip
    with pytest.raises(InputError, match=r"'fish' has the equidistant \(fisheye\).*straight "
                       r"lines"):  # fmt: skip
        resect(data, cam)


def test_resection_algorithm_refuses_lines_with_a_fisheye_camera(tmp_path):
    """The ``resection`` algorithm takes a fisheye camera for control points
    (tests/core/test_bundle_fisheye.py) but not its line rows: the observation file holds
    lines, so the camera is refused, naming its file."""
    scene = make_scene(51, point_sigma_m=0.03)
    data = scene.observe(np.random.default_rng(7))
    files = write_scene_files(tmp_path, scene, data, "EPSG:32632")
    fish = tmp_path / "fisheye_camera.json"
    write_camera_json(fish, dataclasses.replace(scene.camera, projection="equisolid"))
    v = {"CAMERA": str(fish), "OBSERVATIONS": str(files["observations"]),
         "CONTROL_POINTS": str(files["control_points"]), "CRS": "EPSG:32632",
         "OUTPUT_EO": str(tmp_path / "eo.csv")}  # fmt: skip
    with pytest.raises(InputError, match=r"fisheye_camera\.json.*equisolid \(fisheye\)"):
        run_job(resection_job, v)
    assert not (tmp_path / "eo.csv").exists()


def test_equidistant_resection_agrees_with_opencv_fisheye_solvepnp():
    """Peer: OpenCV's fisheye.solvePnP (Kannala-Brandt model, which with zero coefficients is
    the equidistant projection r = f theta) on the same pixels. Noise-free both give the true
    pose; with 0.3 px noise they differ by less than half our sigma (OpenCV minimises in its
    undistorted normalised plane, we in pixels: the same estimate up to the weighting)."""
    import cv2

    cam = Camera("kb", 1.6, 0.004, 2600, 2600, 0.01, -0.008, projection="equidistant")
    rng = np.random.default_rng(5)
    pts = np.column_stack([rng.uniform(-1.5, 1.5, (16, 2)), rng.uniform(0.0, 0.3, 16)])
    assert _angles_off_axis(pts, EO).max() < 60.0
    cx, cy = (c - 0.5 for c in cam.principal_point_px)  # OpenCV: first pixel's centre at 0
    k = np.array([[cam.focal_px, 0.0, cx], [0.0, cam.focal_px, cy], [0.0, 0.0, 1.0]])
    flip = np.diag([1.0, -1.0, -1.0])  # OpenCV's camera: +z forward, y down

    def opencv_pose(px: np.ndarray) -> np.ndarray:
        from lidarphoto.core.geometry.rotations import matrix_to_opk

        ok, rvec, tvec = cv2.fisheye.solvePnP(pts.reshape(-1, 1, 3), (px - 0.5).reshape(-1, 1, 2),
                                              k, np.zeros(4))  # fmt: skip
        assert ok
        r = cv2.Rodrigues(rvec)[0]
        return np.array([*(-r.T @ tvec.ravel()), *matrix_to_opk(flip @ r)])

    exact = project(pts, EO, cam)
    np.testing.assert_allclose(opencv_pose(exact), EO, atol=1e-6)
    ids = tuple(map(str, range(len(pts))))
    np.testing.assert_allclose(resect(ResectionData(ids, exact, SIGMA_PX, pts), cam).eo, EO,
                               atol=1e-8)  # fmt: skip
    noisy = exact + rng.normal(0.0, SIGMA_PX, exact.shape)
    ours = resect(ResectionData(ids, noisy, SIGMA_PX, pts), cam, ResectionOptions(snooping=False))
    peer = opencv_pose(noisy)
    ratio = np.abs(ours.eo - peer) / ours.std_prior
    print("ours - OpenCV fisheye.solvePnP, in sigmas:", ratio.round(3))
    assert (ratio < 0.5).all(), ratio  # measured 0.07-0.24
