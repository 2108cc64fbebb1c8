"""Rotations: round trips, the documented conventions, and SciPy's Rotation as a peer."""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.geometry import rotations as rot
from lidarphoto.core.photo.mount import MOUNT_PRESETS
from scipy.spatial.transform import Rotation

RNG = np.random.default_rng(7)
N = 500


def _angles(limit_mid: float = np.pi / 2 - 1e-3):
    return (
        RNG.uniform(-np.pi, np.pi, N),
        RNG.uniform(-limit_mid, limit_mid, N),
        RNG.uniform(-np.pi, np.pi, N),
    )


def test_passive_is_transpose_of_active():
    a = RNG.uniform(-3, 3, 10)
    for passive, active in ((rot.r1, rot.rx), (rot.r2, rot.ry), (rot.r3, rot.rz)):
        np.testing.assert_allclose(passive(a), np.swapaxes(active(a), -1, -2), atol=1e-15)
    # R1 of DESIGN.md, written out
    w = 0.3
    expected = [[1, 0, 0], [0, np.cos(w), np.sin(w)], [0, -np.sin(w), np.cos(w)]]
    np.testing.assert_allclose(rot.r1(w), expected, atol=1e-15)


def test_opk_matches_scipy_and_round_trips():
    w, p, k = _angles()
    m = rot.opk_to_matrix(w, p, k)
    # R_c^m = M.T = Rx(w) Ry(p) Rz(k): intrinsic x-y-z Euler angles in SciPy's notation.
    peer = Rotation.from_euler("XYZ", np.stack([w, p, k], axis=1)).as_matrix()
    np.testing.assert_allclose(np.swapaxes(m, -1, -2), peer, atol=1e-14)
    w2, p2, k2 = rot.matrix_to_opk(m)
    np.testing.assert_allclose(np.stack([w2, p2, k2]), np.stack([w, p, k]), atol=1e-9)
    assert rot.is_rotation(m)


def test_rph_matches_scipy_and_round_trips():
    r, p, h = _angles()
    m = rot.rph_to_matrix(r, p, h)
    peer = Rotation.from_euler("ZYX", np.stack([h, p, r], axis=1)).as_matrix()
    np.testing.assert_allclose(m, peer, atol=1e-14)
    r2, p2, h2 = rot.matrix_to_rph(m)
    np.testing.assert_allclose(np.stack([r2, p2, h2]), np.stack([r, p, h]), atol=1e-9)


def test_heading_is_clockwise_from_north():
    # Body x (forward) with heading 90 deg points east in NED: (n, e, d) = (0, 1, 0).
    forward = rot.rph_to_matrix(0.0, 0.0, np.pi / 2) @ np.array([1.0, 0.0, 0.0])
    np.testing.assert_allclose(forward, [0.0, 1.0, 0.0], atol=1e-15)
    # Positive pitch raises the nose: forward gets a negative down component.
    forward = rot.rph_to_matrix(0.0, 0.1, 0.0) @ np.array([1.0, 0.0, 0.0])
    assert forward[2] < 0
    # Positive roll lowers the right wing: body y gets a positive down component.
    right = rot.rph_to_matrix(0.1, 0.0, 0.0) @ np.array([0.0, 1.0, 0.0])
    assert right[2] > 0


def test_opk_derivatives_against_finite_differences():
    w, p, k = 0.2, -0.4, 1.3
    d = rot.opk_derivatives(w, p, k)
    h = 1e-6
    for i in range(3):
        plus = [w, p, k]
        minus = [w, p, k]
        plus[i] += h
        minus[i] -= h
        fd = (rot.opk_to_matrix(*plus) - rot.opk_to_matrix(*minus)) / (2 * h)
        np.testing.assert_allclose(d[i], fd, atol=1e-9)


def test_boresight_exact_and_linear():
    d = np.array([2e-3, -1.5e-3, 4e-3])
    exact = rot.boresight_matrix(*d)
    np.testing.assert_allclose(exact, rot.opk_to_matrix(*d).T, atol=1e-15)
    lin = rot.boresight_matrix_linear(*d)
    # First order: the difference is second order in the angles.
    assert np.max(np.abs(exact - lin)) < np.max(np.abs(d)) ** 2
    np.testing.assert_allclose(rot.skew(d) + np.eye(3), lin, atol=1e-15)


def test_skew_is_cross_product():
    a, b = RNG.normal(size=(2, 5, 3))
    np.testing.assert_allclose(rot.skew(a) @ b[..., None], np.cross(a, b)[..., None])


@pytest.mark.parametrize("name", sorted(MOUNT_PRESETS))
def test_mount_presets_look_down(name):
    r = MOUNT_PRESETS[name]
    assert rot.is_rotation(r)
    # The camera looks along -z_c; in the body frame that is straight down (+z_b).
    np.testing.assert_allclose(r @ np.array([0.0, 0.0, -1.0]), [0.0, 0.0, 1.0])


def test_mount_preset_meaning():
    up = MOUNT_PRESETS["image_top_forward"] @ np.array([0.0, 1.0, 0.0])
    np.testing.assert_allclose(up, [1.0, 0.0, 0.0])  # image top (y_c) -> forward
    right = MOUNT_PRESETS["image_right_forward"] @ np.array([1.0, 0.0, 0.0])
    np.testing.assert_allclose(right, [1.0, 0.0, 0.0])


def test_nearest_rotation_recovers_a_noisy_rotation_and_refuses_the_rest():
    """A rotation with 1e-7 noise on its elements (a file's rounding) comes back orthonormal
    and within a few noise sigmas of the truth; 1e-3 noise, a scaled matrix or a reflection
    is refused (tolerance 1e-5)."""
    rng = np.random.default_rng(7)
    truth = rot.opk_to_matrix(0.3, -0.2, 1.1)
    noisy = truth + rng.normal(0.0, 1e-7, (3, 3))
    r = rot.nearest_rotation(noisy)
    assert rot.is_rotation(r, atol=1e-12)
    assert np.max(np.abs(r - truth)) < 5e-7
    for bad in (truth + rng.normal(0.0, 1e-3, (3, 3)), 1.001 * truth, truth @ np.diag([1, 1, -1])):
        with pytest.raises(ValueError, match="nearest rotation"):
            rot.nearest_rotation(bad)
