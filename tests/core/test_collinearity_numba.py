"""The compiled collinearity kernels (core.geometry.collinearity_numba) against the numpy path
of collinearity_jacobians (the reference), for a perspective camera and every AP family.

The scene: a block of 12 images of a 100 mm camera (26000 x 17000 px of 4 um) at about
1000 m, tilted by up to 3 degrees, 3,000 rays to points on the ground across the format; each
lens family with coefficients of 10 px at the corner. The compiled path must equal the
numpy path to 1e-12 relative (two orders of floating-point additions differ only by rounding:
about 1e-16 relative per operation, a few dozen operations per entry).
"""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.compiled import AVAILABLE
from lidarphoto.core.geometry.ap_families import AP_FAMILIES
from lidarphoto.core.geometry.ap_models import make_ap_model
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.collinearity import collinearity_jacobians
from lidarphoto.core.geometry.collinearity_numba import perspective_jacobians
from lidarphoto.core.geometry.distortion import BrownConrady

pytestmark = pytest.mark.skipif(not AVAILABLE, reason="numba not installed")

W, H, PS, F = 26000, 17000, 0.004, 100.0
REL = 1e-12


def _camera(family: str) -> Camera:
    """The camera with lens family ``family``: each coefficient moves the format's corner
    (52 x 34 mm from the centre) by 0.04 mm (10 px), signs alternating."""
    if family == "conrady_brown":
        lens = BrownConrady(k1=-5e-5, k2=1e-8, k3=2e-13, p1=2e-6, p2=-1e-6)
    else:
        corner = np.array([[0.5 * W * PS, 0.5 * H * PS]])
        names = make_ap_model(family, W * PS, H * PS, F).param_names
        coeffs = {}
        for i, k in enumerate(names):
            unit = make_ap_model(family, W * PS, H * PS, F, **{k: 1.0}).correction(corner)
            coeffs[k] = (-1) ** i * 0.04 / np.max(np.abs(unit))
        lens = make_ap_model(family, W * PS, H * PS, F, **coeffs)
    return Camera(family, F, PS, W, H, x0_mm=0.012, y0_mm=-0.008, distortion=lens)


def _block(n_img: int = 12, n: int = 3000, seed: int = 4):
    rng = np.random.default_rng(seed)
    eo = np.column_stack(
        [
            rng.uniform(-400.0, 400.0, n_img),
            rng.uniform(-300.0, 300.0, n_img),
            rng.uniform(950.0, 1050.0, n_img),
            rng.uniform(-0.05, 0.05, (n_img, 2)),
            rng.uniform(-np.pi, np.pi, n_img),
        ]
    )
    img = rng.integers(0, n_img, n)
    pts = np.column_stack(
        [
            eo[img, 0] + rng.uniform(-450.0, 450.0, n),
            eo[img, 1] + rng.uniform(-280.0, 280.0, n),
            rng.uniform(-20.0, 60.0, n),
        ]
    )
    return pts, eo, img


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    """max |a - b| over max |b| per column of the last axis (a Jacobian column's scale)."""
    scale = np.max(np.abs(b.reshape(-1, b.shape[-1])), axis=0)
    scale[scale == 0.0] = 1.0
    return float(np.max(np.abs(a - b).reshape(-1, b.shape[-1]) / scale))


@pytest.mark.parametrize("family", [*AP_FAMILIES])
def test_compiled_equals_numpy(family):
    cam = _camera(family)
    pts, eo, img = _block()
    wrt = ("eo", "point", "interior")
    ref = collinearity_jacobians(pts, eo, cam, wrt=wrt, image_index=img, compiled=False)
    got = collinearity_jacobians(pts, eo, cam, wrt=wrt, image_index=img)
    assert ref["converged"].all() and ref["in_front"].all()
    # the lens moves the image by pixels: the families are really exercised
    plain = collinearity_jacobians(pts, eo, Camera("p", F, PS, W, H, x0_mm=0.012, y0_mm=-0.008),
                                   wrt=("eo",), image_index=img, compiled=False)  # fmt: skip
    moved = np.max(np.abs(ref["pixels"] - plain["pixels"]))
    assert (moved > 2.0) if family != "none" else (moved == 0.0)
    for key in ("in_front", "converged"):
        assert np.array_equal(got[key], ref[key])
    assert _relative(got["pixels"], ref["pixels"]) <= REL
    for key in ("eo", "point", "interior"):
        assert got[key].shape == ref[key].shape
        assert _relative(got[key], ref[key]) <= REL, key
    assert got["interior_names"] == ref["interior_names"]


def test_invalid_rays_are_nan_as_in_numpy():
    """Rays behind the camera: NaN pixels and Jacobian rows in both paths, others equal."""
    cam = _camera("conrady_brown")
    pts, eo, img = _block(n=400)
    pts[::7, 2] = eo[img[::7], 2] + 50.0  # above the camera: w > 0
    ref = collinearity_jacobians(pts, eo, cam, image_index=img, compiled=False)
    got = collinearity_jacobians(pts, eo, cam, image_index=img)
    bad = ~ref["in_front"]
    assert bad.sum() == len(pts[::7])
    assert np.array_equal(got["in_front"], ref["in_front"])
    for key in ("pixels", "eo", "point", "interior"):
        assert np.array_equal(np.isnan(got[key]), np.isnan(ref[key])), key
        assert np.isnan(got[key][bad]).all()
        assert _relative(got[key][~bad], ref[key][~bad]) <= REL, key


def test_eo_subsets_and_bad_sg():
    cam = _camera("bauer")
    pts, eo, img = _block(n=200)
    ref = collinearity_jacobians(pts, eo, cam, wrt=("point",), image_index=img, compiled=False)
    got = collinearity_jacobians(pts, eo, cam, wrt=("point",), image_index=img)
    assert "eo" not in got and "interior" not in got
    assert _relative(got["point"], ref["point"]) <= REL
    with pytest.raises(ValueError, match="sg must have 1 or 200 rows"):
        perspective_jacobians(pts, eo, np.zeros((12, 3, 3)), np.zeros((12, 3, 3, 3)), img, F,
                              np.zeros((3, 2, 2)), np.ones(200, dtype=bool))  # fmt: skip


@pytest.mark.parametrize("compiled", [True, False])
def test_out_receives_eo_and_point_columns(compiled):
    """``out``: the EO and point Jacobians written in place (both paths), returned as views;
    the columns beyond 9 untouched."""
    cam = _camera("jacobsen")
    pts, eo, img = _block(n=300)
    ref = collinearity_jacobians(pts, eo, cam, image_index=img, compiled=False)
    buf = np.full((300, 2, 11), 7.0)
    got = collinearity_jacobians(pts, eo, cam, wrt=("interior",), image_index=img, out=buf,
                                 compiled=compiled)  # fmt: skip
    assert np.shares_memory(got["eo"], buf) and np.shares_memory(got["point"], buf)
    assert _relative(buf[:, :, :6], ref["eo"]) <= REL
    assert _relative(buf[:, :, 6:9], ref["point"]) <= REL
    assert _relative(got["interior"], ref["interior"]) <= REL
    assert np.all(buf[:, :, 9:] == 7.0)


def test_image_rays_with_image_index_equal_per_ray():
    """image_rays with one EO per image and ``image_index`` (rotations once per image):
    bit for bit the rays of one EO row per pixel."""
    from lidarphoto.core.geometry.collinearity import image_rays

    cam = _camera("conrady_brown")
    pts, eo, img = _block(n=500)
    px = collinearity_jacobians(pts, eo, cam, wrt=(), image_index=img)["pixels"]
    o1, d1 = image_rays(px, eo[img], cam)
    o2, d2 = image_rays(px, eo, cam, image_index=img)
    assert np.array_equal(o1, o2) and np.array_equal(d1, d2)
    # and they pass through the points they were projected from (to 1e-9 of the range)
    t = np.einsum("ni,ni->n", pts - o2, d2)
    assert np.max(np.linalg.norm(o2 + t[:, None] * d2 - pts, axis=1) / t) < 1e-9
