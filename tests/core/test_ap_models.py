"""The additional-parameter families against their own definitions.

Each family's correction is compared with its formula written out here independently (from
the sources named in docs/ap_models.md), for random coefficients at random points; Ebner's set
is checked against the property that defines it (orthogonality on a 3 x 3 grid, to each
other and to the effects of the exterior orientation); the constants are checked against
the property they are chosen for. The generic checks of every registered lens model
(Jacobians by finite differences, inversion, JSON round trip) are in test_camera.py.
"""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.geometry.ap_models import (
    AP_FAMILIES,
    Bauer,
    Brown14,
    Ebner,
    Jacobsen,
    LensK1K2,
    ap_constants,
    make_ap_model,
)
from lidarphoto.core.geometry.camera import camera_from_dict
from lidarphoto.core.geometry.distortion import DISTORTION_MODELS
from numpy.testing import assert_allclose

RNG = np.random.default_rng(11)
XY = RNG.uniform([-3.1, -2.3], [3.1, 2.3], (400, 2))  # a 1/2.3" sensor, mm
X, Y = XY[:, 0], XY[:, 1]
R2 = X * X + Y * Y


def _coefs(n: int, scale: float = 1e-3) -> np.ndarray:
    return RNG.normal(0.0, scale, n)


def test_lens_k1k2_is_the_radial_model():
    k1, k2 = _coefs(2)
    d = LensK1K2(k1=k1, k2=k2).correction(XY)
    assert_allclose(d[:, 0], k1 * X * R2 + k2 * X * R2**2, rtol=1e-13, atol=1e-16)
    assert_allclose(d[:, 1], k1 * Y * R2 + k2 * Y * R2**2, rtol=1e-13, atol=1e-16)


def test_bauer_three_parameters():
    a1, a2, a3 = _coefs(3)
    r0 = 2.2
    d = Bauer(a1=a1, a2=a2, a3=a3, r0_mm=r0).correction(XY)
    assert_allclose(d[:, 0], a1 * X * (R2 - r0**2) + a2 * X, rtol=1e-12, atol=1e-16)
    assert_allclose(d[:, 1], a1 * Y * (R2 - r0**2) - a2 * Y + a3 * X, rtol=1e-12, atol=1e-16)
    # the radial term vanishes on the circle r = r0
    ring = 2.2 * np.column_stack([np.cos(np.linspace(0, 6, 9)), np.sin(np.linspace(0, 6, 9))])
    assert_allclose(Bauer(a1=1e-3, r0_mm=r0).correction(ring), 0.0, atol=1e-15)


def test_jacobsen_four_parameters():
    a1, a2, a3, a4 = _coefs(4)
    r0 = 1.7
    d = Jacobsen(a1=a1, a2=a2, a3=a3, a4=a4, r0_mm=r0).correction(XY)
    assert_allclose(d[:, 0], a1 * X * (R2 - r0**2) + a2 * X + a3 * Y, rtol=1e-12, atol=1e-16)
    assert_allclose(
        d[:, 1], a1 * Y * (R2 - r0**2) - a2 * Y + a3 * X + a4 * X**2, rtol=1e-12, atol=1e-16
    )


def _ebner_written_out(b: np.ndarray, bb: float, x: np.ndarray, y: np.ndarray):
    q = 2.0 * bb * bb / 3.0
    dx = (
        b[0] * x
        + b[1] * y
        - b[2] * (2 * x * x - 2 * q)
        + b[3] * x * y
        + b[4] * (y * y - q)
        + b[6] * x * (y * y - q)
        + b[8] * y * (x * x - q)
        + b[10] * (x * x - q) * (y * y - q)
    )
    dy = (
        -b[0] * y
        + b[1] * x
        + b[2] * x * y
        - b[3] * (2 * y * y - 2 * q)
        + b[5] * (x * x - q)
        + b[7] * y * (x * x - q)
        + b[9] * x * (y * y - q)
        + b[11] * (x * x - q) * (y * y - q)
    )
    return dx, dy


def test_ebner_twelve_parameters():
    b = _coefs(12)
    bb = 1.9
    d = Ebner(b_mm=bb, **{f"b{k + 1}": v for k, v in enumerate(b)}).correction(XY)
    dx, dy = _ebner_written_out(b, bb, X, Y)
    assert_allclose(d[:, 0], dx, rtol=1e-11, atol=1e-15)
    assert_allclose(d[:, 1], dy, rtol=1e-11, atol=1e-15)


def test_ebner_set_is_orthogonal_on_its_grid():
    """Ebner (1976): on the 3 x 3 grid of spacing b the twelve terms are orthogonal to each
    other and to the six effects of the exterior orientation of a vertical image over flat
    ground (shifts, scale, rotation, and the two tilts with their x^2/f, xy/f terms); together
    they span all 18 coordinates of the nine points."""
    b, f = 2.0, 5.0
    g = np.array([(u, v) for v in (-b, 0.0, b) for u in (-b, 0.0, b)])
    basis = Ebner(b_mm=b).jacobian_params(g)  # (9, 2, 12)
    ap = basis.transpose(2, 1, 0).reshape(12, 18)  # one row per parameter: dx of 9, dy of 9
    u, v = g[:, 0], g[:, 1]
    z, o = np.zeros(9), np.ones(9)
    eo = np.array(
        [
            np.r_[o, z],
            np.r_[z, o],  # principal point / X0, Y0 shifts
            np.r_[u, v],  # scale (Z0, principal distance)
            np.r_[-v, u],  # kappa
            np.r_[f + u * u / f, u * v / f],  # phi
            np.r_[u * v / f, f + v * v / f],  # omega
        ]
    )
    gram = ap @ ap.T
    off = gram - np.diag(np.diag(gram))
    assert np.abs(off).max() < 1e-12 * np.abs(np.diag(gram)).max()
    assert np.abs(ap @ eo.T).max() < 1e-12 * np.abs(gram).max()
    assert np.linalg.matrix_rank(np.vstack([ap, eo])) == 18


def test_brown_fourteen_terms():
    a = _coefs(14)
    c = 5.1
    d = Brown14(c_mm=c, **{f"a{k + 1}": v for k, v in enumerate(a)}).correction(XY)
    x2y2 = X * X * Y * Y
    dx = (
        a[0] * X
        + a[1] * Y
        + a[2] * X * Y
        + a[3] * Y * Y
        + a[4] * X * X * Y
        + a[5] * X * Y * Y
        + a[6] * x2y2
        + a[12] * (X / c) * x2y2
        + a[13] * X * R2
    )
    dy = (
        a[7] * X * Y
        + a[8] * X * X
        + a[9] * X * X * Y
        + a[10] * X * Y * Y
        + a[11] * x2y2
        + a[12] * (Y / c) * x2y2
        + a[13] * Y * R2
    )
    assert_allclose(d[:, 0], dx, rtol=1e-11, atol=1e-15)
    assert_allclose(d[:, 1], dy, rtol=1e-11, atol=1e-15)


def test_constants_serve_their_purpose():
    w, h, f = 6.16, 4.62, 5.0
    k = ap_constants(w, h, f)
    # r0: Bauer's radial term orthogonal to a change of principal distance (x, y) over the
    # uniformly covered format (midpoint rule on a fine grid: error ~ 1 / n^2)
    mx = (np.arange(800) + 0.5) / 800 - 0.5
    my = (np.arange(600) + 0.5) / 600 - 0.5
    gx, gy = np.meshgrid(mx * w, my * h)
    r2 = gx**2 + gy**2
    inner = np.mean(r2 * (r2 - k["r0_mm"] ** 2))
    assert abs(inner) < 1e-4 * np.mean(r2 * r2)
    # b: for a square format q(u) = u^2 - 2 b^2 / 3 has zero mean
    ks = ap_constants(4.0, 4.0, f)
    u = ((np.arange(4000) + 0.5) / 4000 - 0.5) * 4.0
    assert abs(np.mean(u * u - 2 * ks["b_mm"] ** 2 / 3)) < 1e-6
    assert k["c_mm"] == f


def test_every_family_is_registered_and_read_from_a_camera_file():
    for option, model in AP_FAMILIES.items():
        assert model in DISTORTION_MODELS, option
        lens = make_ap_model(option, 6.16, 4.62, 5.0)
        # distinct non-zero coefficients: a swapped or misnamed one would not read back equal
        lens = lens.with_params(1e-6 * (1.0 + np.arange(lens.params.size)))
        cam = camera_from_dict(
            {
                "focal_mm": 5.0,
                "pixel_size_mm": 0.00154,
                "width_px": 4000,
                "height_px": 3000,
                "distortion": lens.to_dict(),
            }
        )
        assert cam.distortion == lens
    with pytest.raises(ValueError, match="unknown AP family"):
        make_ap_model("tsai", 6.0, 4.0, 5.0)
