"""Tests of core.geometry.collinearity: projection, back-projection, analytic Jacobians, OpenCV
peer.

The scene: a 100 mm camera (26000 x 17000 px of 4 µm) about 1000 m above points spread
over +-300 m, tilted by a few degrees, with strong Brown-Conrady coefficients.
"""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.collinearity import (
    EO_NAMES,
    collinearity_jacobians,
    image_rays,
    project,
    project_with_status,
)
from lidarphoto.core.geometry.distortion import BrownConrady, NoDistortion
from lidarphoto.core.geometry.rotations import opk_to_matrix
from numdiff import central_difference
from numpy.testing import assert_allclose

W, H, PS, F = 26000, 17000, 0.004, 100.0
BC = BrownConrady(k1=-5e-5, k2=1e-8, k3=2e-13, p1=2e-6, p2=-1e-6)
CAM = Camera("test", F, PS, W, H, x0_mm=0.012, y0_mm=-0.008, distortion=BC)
CAM_PLAIN = Camera("plain", F, PS, W, H, x0_mm=0.012, y0_mm=-0.008)
EO = np.array([500.0, -200.0, 1000.0, 0.03, -0.05, 0.7])


def scene(n: int = 60, seed: int = 0) -> np.ndarray:
    """Object points (n, 3) near the ground below EO, all inside the image of CAM."""
    rng = np.random.default_rng(seed)
    xy = EO[:2] + rng.uniform(-250.0, 250.0, size=(n, 2))
    return np.column_stack([xy, rng.uniform(-20.0, 60.0, n)])


def column_errors(analytic: np.ndarray, numeric: np.ndarray) -> np.ndarray:
    """Largest error of each column (parameter) relative to the largest entry of the column."""
    scale = np.abs(numeric).max(axis=(0, 1))
    scale[scale == 0] = 1.0
    return np.abs(analytic - numeric).max(axis=(0, 1)) / scale


# Finite-difference steps and why the relative 1e-6 test is safe with them (pixels up to
# 3e4, range ~1000 m, f = 25000 px, eps = 2.2e-16; the lens inversion is polished to rounding
# level, so it adds no noise):
# - positions (m), h = 1e-3: truncation ~ (h / range)^2 = 1e-12 relative; rounding
#   eps 3e4 / h = 7e-9 px/m against derivatives ~ f/range = 25 px/m: 3e-10.
# - angles (rad), h = 1e-6: truncation ~ h^2 = 1e-12; rounding 7e-6 px/rad against
#   ~2.5e4 px/rad: 3e-10.
# - focal and principal point (mm), h = 1e-4: rounding 7e-8 against >= 130 px/mm.
# - k1, k2, k3, p1, p2: steps that move corner points by ~0.01 px; rounding 3e-12/0.01.
POS_STEP, ANGLE_STEP = 1e-3, 1e-6
LENS_STEPS = [1e-4, 1e-4, 1e-4, 1e-9, 1e-13, 1e-17, 1e-9, 1e-9]
REL = 1e-6


# ---------------------------------------------------------------------------- geometry
def test_nadir_camera_east_is_right_and_north_is_up() -> None:
    cam = Camera("nadir", F, PS, W, H)
    eo = [1000.0, 2000.0, 1500.0, 0.0, 0.0, 0.0]
    centre, east, north = project(
        [[1000.0, 2000.0, 500.0], [1100.0, 2000.0, 500.0], [1000.0, 2100.0, 500.0]], eo, cam
    )
    assert_allclose(centre, [W / 2, H / 2], rtol=0, atol=1e-9)
    # 100 m at 1000 m range with f = 100 mm: 10 mm = 2500 px to the right, resp. up.
    assert_allclose(east, [W / 2 + 2500.0, H / 2], rtol=0, atol=1e-9)
    assert_allclose(north, [W / 2, H / 2 - 2500.0], rtol=0, atol=1e-9)


def test_principal_point_offset_moves_the_image() -> None:
    cam = Camera("pp", F, PS, W, H, x0_mm=0.04, y0_mm=0.08)
    px = project([[0.0, 0.0, 0.0]], [0.0, 0.0, 1000.0, 0.0, 0.0, 0.0], cam)
    assert_allclose(px, [cam.principal_point_px], rtol=0, atol=1e-9)
    assert_allclose(px, [[W / 2 + 10.0, H / 2 - 20.0]], rtol=0, atol=1e-9)


def test_points_behind_or_beside_the_camera_are_flagged() -> None:
    eo = [0.0, 0.0, 1000.0, 0.0, 0.0, 0.0]
    pts = [[10.0, 0.0, 0.0], [10.0, 0.0, 2000.0], [10.0, 0.0, 1000.0]]  # below, above, level
    px, in_front, converged = project_with_status(pts, eo, CAM)
    assert in_front.tolist() == [True, False, False]
    assert converged.tolist() == [True, False, False]
    assert np.isfinite(px[0]).all() and np.isnan(px[1:]).all()
    jac = collinearity_jacobians(pts, eo, CAM)
    assert np.isfinite(jac["eo"][0]).all() and np.isnan(jac["eo"][1:]).all()


def test_lens_inversion_failure_gives_nan() -> None:
    # k1 alone: ideal radii beyond 54.4 mm have no measured point (see test_camera).
    cam = Camera("k1", F, PS, W, H, distortion=BrownConrady(k1=-5e-5))
    eo = [0.0, 0.0, 1000.0, 0.0, 0.0, 0.0]
    px, in_front, converged = project_with_status([[700.0, 0.0, 0.0], [100.0, 0.0, 0.0]], eo, cam)
    assert in_front.tolist() == [True, True] and converged.tolist() == [False, True]
    assert np.isnan(px[0]).all() and np.isfinite(px[1]).all()


def test_project_then_back_project() -> None:
    pts = scene(200)
    eos = np.tile(EO, (200, 1))
    eos[:, 3:] += np.random.default_rng(2).normal(0.0, 0.1, size=(200, 3))  # one EO per point
    for cam in (CAM, CAM_PLAIN):
        px = project(pts, eos, cam)
        assert np.isfinite(px).all()
        origins, directions = image_rays(px, eos, cam)
        assert_allclose(np.linalg.norm(directions, axis=1), 1.0, rtol=0, atol=1e-14)
        v = pts - origins
        rng_m = np.linalg.norm(v, axis=1)
        dist = np.linalg.norm(np.cross(v, directions), axis=1)
        # Rounding alone gives ~1e-15 relative; the lens inversion is polished to that level.
        assert (dist / rng_m).max() < 1e-9
        assert np.all(np.einsum("ni,ni->n", v, directions) > 0)  # towards the point, not away


def test_single_eo_equals_per_point_eo_and_translation_invariance() -> None:
    pts = scene(20)
    a = project(pts, EO, CAM)
    assert_allclose(project(pts, np.tile(EO, (20, 1)), CAM), a, rtol=0, atol=0)
    # UTM-sized coordinates: dX is formed first, so only ~1e-9 m of rounding enters,
    # ~3e-8 px at 1000 m with f = 25000 px.
    shift = np.array([500000.0, 7000000.0, 0.0])
    b = project(pts + shift, EO + np.concatenate([shift, np.zeros(3)]), CAM)
    assert_allclose(b, a, rtol=0, atol=1e-6)
    with pytest.raises(ValueError):
        project(pts, np.zeros((3, 6)), CAM)


# ---------------------------------------------------------------------------- Jacobians
@pytest.mark.parametrize("cam", [CAM, CAM_PLAIN], ids=["brown_conrady", "no_distortion"])
def test_jacobians_against_finite_differences(cam: Camera) -> None:
    pts = scene(60)
    out = collinearity_jacobians(pts, EO, cam)
    assert out["converged"].all() and out["in_front"].all()
    assert_allclose(out["pixels"], project(pts, EO, cam), rtol=0, atol=0)
    n, p = len(pts), cam.distortion.n_params
    assert out["eo"].shape == (n, 2, 6)
    assert out["point"].shape == (n, 2, 3)
    assert out["interior"].shape == (n, 2, 3 + p)
    assert out["interior_names"] == cam.interior_names

    eo_steps = [POS_STEP] * 3 + [ANGLE_STEP] * 3
    num_eo = central_difference(lambda e: project(pts, e, cam), EO.copy(), eo_steps)
    err = column_errors(out["eo"], num_eo)
    assert np.all(err <= REL), dict(zip(EO_NAMES, err))

    num_pt = np.empty((n, 2, 3))
    for k in range(3):  # all points at once: each point only moves its own pixel
        step = np.zeros(3)
        step[k] = POS_STEP
        num_pt[:, :, k] = (project(pts + step, EO, cam) - project(pts - step, EO, cam)) / (
            2 * POS_STEP
        )
    assert np.all(column_errors(out["point"], num_pt) <= REL)

    num_io = central_difference(
        lambda q: project(pts, EO, cam.with_interior(q)), cam.interior_params, LENS_STEPS[: 3 + p]
    )
    err = column_errors(out["interior"], num_io)
    assert np.all(err <= REL), dict(zip(cam.interior_names, err))


def test_jacobian_check_is_sensitive_to_the_lens_term() -> None:
    # The implicit-function factor (I + dd/dm)^-1 matters: leaving it out (the Jacobian of
    # the distortion-free camera at the same points) fails the same finite-difference check.
    pts = scene(60)
    wrong = collinearity_jacobians(pts, EO, CAM_PLAIN, wrt=("eo",))["eo"]
    eo_steps = [POS_STEP] * 3 + [ANGLE_STEP] * 3
    num = central_difference(lambda e: project(pts, e, CAM), EO.copy(), eo_steps)
    assert column_errors(wrong, num).max() > 100 * REL


def test_point_jacobian_is_minus_position_jacobian_and_wrt_subset() -> None:
    pts = scene(10)
    out = collinearity_jacobians(pts, EO, CAM, wrt=("eo", "point"))
    assert "interior" not in out
    assert_allclose(out["point"], -out["eo"][:, :, :3], rtol=0, atol=0)
    with pytest.raises(ValueError, match="wrt"):
        collinearity_jacobians(pts, EO, CAM, wrt=("focal",))


def test_distortion_free_interior_jacobian_in_closed_form() -> None:
    # Without distortion: col = (x0 + x_i)/ps + W/2, row = H/2 - (y0 + y_i)/ps, x_i linear in f.
    pts = scene(10)
    out = collinearity_jacobians(pts, EO, Camera("p", F, PS, W, H), wrt=("interior",))
    centred = out["pixels"] - [W / 2, H / 2]
    assert_allclose(out["interior"][:, :, 0], centred / F, rtol=1e-12, atol=0)
    assert_allclose(out["interior"][:, :, 1], np.tile([1 / PS, 0.0], (10, 1)), rtol=0, atol=0)
    assert_allclose(out["interior"][:, :, 2], np.tile([0.0, -1 / PS], (10, 1)), rtol=0, atol=0)


# ---------------------------------------------------------------------------- OpenCV peer
def test_project_agrees_with_opencv_projectpoints() -> None:
    cam = Camera("cv", 35.0, 0.006, 6000, 4000, x0_mm=0.1, y0_mm=-0.07, distortion=NoDistortion())
    rng = np.random.default_rng(11)
    for omega, phi, kappa in [(0.0, 0.0, 0.0), (0.2, -0.15, 2.5), (-0.4, 0.3, -1.0)]:
        eo = np.array([350.0, -120.0, 600.0, omega, phi, kappa])
        m = opk_to_matrix(omega, phi, kappa)
        # Points in front of the camera: along the camera's -z axis in object space.
        rays = np.column_stack([rng.uniform(-0.5, 0.5, (50, 2)), -np.ones(50)])
        pts = eo[:3] + rng.uniform(200.0, 800.0, (50, 1)) * (rays @ m)
        ours = project(pts, eo, cam)

        # OpenCV's camera looks along +z with y down: flip our camera's y and z axes.
        r_cv = np.diag([1.0, -1.0, -1.0]) @ m
        t_cv = -r_cv @ eo[:3]
        rvec, _ = cv2.Rodrigues(r_cv)
        col0, row0 = cam.principal_point_px
        # OpenCV's pixel (0, 0) is the CENTRE of the first pixel; ours is its top-left corner,
        # so the centre of the first pixel is (0.5, 0.5) here: OpenCV coordinates are ours
        # minus 0.5, for the principal point and for the projected points alike.
        k = np.array([[cam.focal_px, 0, col0 - 0.5], [0, cam.focal_px, row0 - 0.5], [0, 0, 1.0]])
        theirs, _ = cv2.projectPoints(pts.reshape(-1, 1, 3), rvec, t_cv, k, None)
        # Both are double-precision evaluations of the same formula: 1e-6 px (design).
        assert_allclose(ours, theirs.reshape(-1, 2) + 0.5, rtol=0, atol=1e-6)
