"""Tests of core.geometry.camera and core.geometry.distortion: pixels <-> mm, lens models, camera
files.

Tolerances are derived in the comments next to them. The reference camera is a 100 mm
camera with a 104 x 68 mm frame (26000 x 17000 px of 4 µm), with strong Brown-Conrady
coefficients (they move the frame corner by about 3 mm, i.e. 750 px).
"""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.geometry.camera import Camera, camera_from_dict
from lidarphoto.core.geometry.distortion import (
    DISTORTION_MODELS,
    BrownConrady,
    DistortionInversionError,
    DistortionModel,
    NoDistortion,
    distortion_from_dict,
)
from lidarphoto.core.io.camera import read_camera_json, write_camera_json
from numdiff import central_difference
from numpy.testing import assert_allclose

W, H, PS, F = 26000, 17000, 0.004, 100.0
BC = BrownConrady(k1=-5e-5, k2=1e-8, k3=0.0, p1=2e-6, p2=-1e-6)


def make_camera(distortion: DistortionModel = BC) -> Camera:
    return Camera("test", F, PS, W, H, x0_mm=0.012, y0_mm=-0.008, distortion=distortion)


def frame_grid(cam: Camera, n_cols: int = 41, n_rows: int = 27) -> np.ndarray:
    """Pixel positions (N, 2) covering the whole frame, corners and edges included."""
    cols, rows = np.meshgrid(
        np.linspace(0.0, cam.width_px, n_cols), np.linspace(0.0, cam.height_px, n_rows)
    )
    return np.column_stack([cols.ravel(), rows.ravel()])


def assert_jacobian_close(analytic: np.ndarray, numeric: np.ndarray, rel: float = 1e-6) -> None:
    """Every entry within ``rel`` times the largest entry of its column (parameter)."""
    scale = np.abs(numeric).max(axis=(0, 1))
    scale[scale == 0] = 1.0
    err = np.abs(analytic - numeric).max(axis=(0, 1)) / scale
    assert np.all(err <= rel), f"relative errors per column: {err}"


# ---------------------------------------------------------------------------- pixels <-> mm
def test_first_pixel_centre_and_frame_corners() -> None:
    cam = make_camera()
    got = cam.pixel_to_image([[0.5, 0.5], [0.0, 0.0], [W, H], [W / 2, H / 2], [W - 0.5, H - 0.5]])
    # Multiples of a 4 µm pixel: exact to rounding of numbers below 60 mm (1e-14 mm).
    expected = [
        [-(W / 2 - 0.5) * PS, (H / 2 - 0.5) * PS],
        [-W / 2 * PS, H / 2 * PS],
        [W / 2 * PS, -H / 2 * PS],
        [0.0, 0.0],
        [(W / 2 - 0.5) * PS, -(H / 2 - 0.5) * PS],
    ]
    assert_allclose(got, expected, rtol=0, atol=1e-12)
    # x right, y up: moving right increases x, moving down decreases y.
    d = cam.pixel_to_image([[101.0, 200.0]]) - cam.pixel_to_image([[100.0, 199.0]])
    assert d[0, 0] > 0 and d[0, 1] < 0


def test_pixel_image_round_trip() -> None:
    cam = make_camera()
    rng = np.random.default_rng(1)
    px = rng.uniform([-1000, -1000], [W + 1000, H + 1000], size=(1000, 2))
    # Values up to 3e4 px and 60 mm carry rounding of about 1e-11: 1e-9 has ample margin.
    assert_allclose(cam.image_to_pixel(cam.pixel_to_image(px)), px, rtol=0, atol=1e-9)
    xy = rng.uniform(-60, 60, size=(1000, 2))
    assert_allclose(cam.pixel_to_image(cam.image_to_pixel(xy)), xy, rtol=0, atol=1e-9)


def test_principal_point_and_focal_px() -> None:
    cam = make_camera()
    col, row = cam.principal_point_px
    assert_allclose([col, row], [W / 2 + 0.012 / PS, H / 2 + 0.008 / PS], rtol=0, atol=1e-9)
    assert_allclose(cam.pixel_to_image([[col, row]]), [[0.012, -0.008]], rtol=0, atol=1e-12)
    assert cam.focal_px == pytest.approx(F / PS, rel=1e-15)
    # Without distortion, the ideal centred coordinate of the principal point is 0.
    plain = make_camera(NoDistortion())
    assert_allclose(plain.ideal_from_pixel([[col, row]]), [[0.0, 0.0]], rtol=0, atol=1e-12)


def test_in_frame() -> None:
    cam = make_camera()
    mask = cam.in_frame([[0, 0], [W, H], [-0.1, 5], [5, H + 0.1], [np.nan, 1]])
    assert mask.tolist() == [True, True, False, False, False]


def test_single_point_and_bad_shapes() -> None:
    cam = make_camera()
    assert cam.pixel_to_image([0.5, 0.5]).shape == (1, 2)
    with pytest.raises(ValueError):
        cam.pixel_to_image(np.zeros((4, 3)))


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("focal_mm", -100.0),
        ("focal_mm", 0.0),
        ("focal_mm", float("nan")),
        ("pixel_size_mm", -0.004),
        ("pixel_size_mm", "abc"),
        ("width_px", 0),
        ("height_px", -5),
        ("width_px", 100.5),
        ("x0_mm", float("inf")),
        ("distortion", {"model": "brown_conrady"}),
    ],
)
def test_camera_validation_names_the_field(field: str, value: object) -> None:
    kwargs = dict(name="cam1", focal_mm=F, pixel_size_mm=PS, width_px=W, height_px=H)
    kwargs[field] = value
    with pytest.raises(InputError, match=field):
        Camera(**kwargs)


def test_interior_vector_round_trip() -> None:
    cam = make_camera()
    assert cam.interior_names == ("focal_mm", "x0_mm", "y0_mm", "k1", "k2", "k3", "p1", "p2")
    p = cam.interior_params
    assert_allclose(p, [F, 0.012, -0.008, -5e-5, 1e-8, 0.0, 2e-6, -1e-6], rtol=0, atol=0)
    assert cam.with_interior(p) == cam
    moved = cam.with_interior(p + np.arange(8) * 1e-9)  # index 4 of the vector is k2
    assert moved.distortion.params[1] == pytest.approx(1e-8 + 4e-9, rel=1e-12)
    assert moved.focal_mm == F
    assert make_camera(NoDistortion()).interior_names == ("focal_mm", "x0_mm", "y0_mm")


# ---------------------------------------------------------------------------- lens models
def test_brown_conrady_value_by_hand() -> None:
    # x = 30, y = -40 mm: r2 = 2500; radial = k1 r2 + k2 r2^2 = -0.125 + 0.0625 = -0.0625.
    # dx = 30 (-0.0625) + 2e-6 (2500 + 1800) + 2 (-1e-6) (30) (-40) = -1.875 + 0.0086 + 0.0024
    # dy = -40 (-0.0625) + 2 (2e-6) (30) (-40) + (-1e-6) (2500 + 3200) = 2.5 - 0.0048 - 0.0057
    got = BC.correction([[30.0, -40.0]])
    assert_allclose(got, [[-1.864, 2.4895]], rtol=0, atol=1e-12)
    assert_allclose(BC.undistort([[30.0, -40.0]]), [[28.136, -37.5105]], rtol=0, atol=1e-12)


def test_brown_conrady_round_trip_over_the_frame() -> None:
    cam = make_camera()
    measured = cam.pixel_to_image(frame_grid(cam)) - [cam.x0_mm, cam.y0_mm]
    ideal = BC.undistort(measured)
    tol_mm = 1e-6 * PS  # the design tolerance, 1e-6 px
    back, ok = BC.distort_with_status(ideal, tol_mm=tol_mm)
    assert ok.all()
    # distort(undistort(m)) == m: Newton found the physical root, not another one.
    assert np.abs(back - measured).max() / PS <= 1e-6
    # undistort(distort(i)) == i for ideal points over the (ideal) frame.
    ideal_grid = cam.pixel_to_image(frame_grid(cam, 33, 21)) * 0.9
    again = BC.undistort(BC.distort(ideal_grid, tol_mm=tol_mm))
    assert np.abs(again - ideal_grid).max() / PS <= 1e-6
    # The corrections are large (so the check is not vacuous): about 3 mm (750 px) at the
    # corner, where k1 r^2 = -0.19 and k2 r^4 = +0.15 nearly cancel.
    assert np.abs(ideal - measured).max() > 2.0


def test_pixel_from_ideal_inverts_ideal_from_pixel() -> None:
    cam = make_camera()
    px = frame_grid(cam)
    assert np.abs(cam.pixel_from_ideal(cam.ideal_from_pixel(px)) - px).max() <= 1e-6


def test_inversion_failure_is_flagged() -> None:
    # With k1 = -5e-5 alone, r (1 + k1 r^2) peaks at r = 81.6 mm with value 54.4 mm: an ideal
    # point at 70 mm has no physical measured counterpart. (Newton does find a root of
    # m + d(m) = i at m = (-165, 0) mm, beyond the fold, on the opposite side of the
    # principal point: it must be rejected, not returned.)
    lens = BrownConrady(k1=-5e-5)
    ideal = np.array([[70.0, 0.0], [10.0, 5.0]])
    m, ok = lens.distort_with_status(ideal)
    assert ok.tolist() == [False, True]
    assert np.isnan(m[0]).all() and np.isfinite(m[1]).all()
    with pytest.raises(DistortionInversionError) as info:
        lens.distort(ideal)
    assert info.value.converged.tolist() == [False, True]
    cam = make_camera(lens)
    with pytest.raises(DistortionInversionError):
        cam.pixel_from_ideal(ideal)
    px, ok = cam.pixel_from_ideal_with_status(ideal)
    assert ok.tolist() == [False, True] and np.isnan(px[0]).all()


def _model_examples():
    """Every registered model, with coefficients scaled to move the corner by ~0.05 mm.

    Generic so that models added later are checked without editing this test.
    """
    rng = np.random.default_rng(7)
    corner = np.array([[52.0, 34.0]])
    for name, cls in sorted(DISTORTION_MODELS.items()):
        constants = {c: 10.0 for c in cls.constant_names}
        unit = cls(**constants)
        jp = np.abs(unit.jacobian_params(corner)).max(axis=(0, 1))
        params = rng.choice([-1.0, 1.0], size=len(jp)) * 0.05 / np.maximum(jp, 1e-300)
        yield pytest.param(unit.with_params(params), id=name)


@pytest.mark.parametrize("model", list(_model_examples()))
def test_lens_jacobians_against_finite_differences(model: DistortionModel) -> None:
    rng = np.random.default_rng(3)
    xy = rng.uniform([-52, -34], [52, 34], size=(200, 2))
    n, p = xy.shape[0], model.n_params
    assert model.correction(xy).shape == (n, 2)
    jx = model.jacobian_xy(xy)
    assert jx.shape == (n, 2, 2)
    # Step 1e-4 mm: truncation h^2/6 |d'''| < 1e-11 for corrections of polynomial degree <= 7
    # with these scales; rounding eps |d| / h < 1e-10. Both far below 1e-6 of the entries.
    numeric = np.stack(
        [
            (model.correction(xy + h) - model.correction(xy - h)) / 2e-4
            for h in (np.array([1e-4, 0.0]), np.array([0.0, 1e-4]))
        ],
        axis=-1,
    )
    if np.abs(numeric).max() > 0:
        assert_jacobian_close(jx, numeric)
    else:
        assert_allclose(jx, 0.0, atol=0)
    jp = model.jacobian_params(xy)
    assert jp.shape == (n, 2, p)
    if p:
        # The correction is linear in these coefficients for the models here, and the step
        # moves the correction by ~1e-3 mm, so the rounding error is below 1e-12 relative.
        steps = 1e-3 / np.maximum(np.abs(jp).max(axis=(0, 1)), 1e-300)
        numeric_p = central_difference(
            lambda q: model.with_params(q).correction(xy), model.params, steps
        )
        assert_jacobian_close(jp, numeric_p)


@pytest.mark.parametrize("model", list(_model_examples()))
def test_every_model_round_trips_and_serialises(model: DistortionModel) -> None:
    rng = np.random.default_rng(5)
    ideal = rng.uniform([-52, -34], [52, 34], size=(500, 2))
    m = model.distort(ideal, tol_mm=1e-9)
    assert np.abs(model.undistort(m) - ideal).max() <= 1e-9
    d = model.to_dict()
    assert d["model"] == model.model
    assert distortion_from_dict(json.loads(json.dumps(d))) == model
    assert type(model).from_dict(d) == model
    assert hash(model.with_params(model.params)) == hash(model)


def test_distortion_from_dict_errors() -> None:
    assert distortion_from_dict({}) == NoDistortion()
    assert distortion_from_dict({"model": "brown_conrady", "k1": 1e-5}) == BrownConrady(k1=1e-5)
    with pytest.raises(InputError, match=r"distortion\.model"):
        distortion_from_dict({"model": "tsai"}, source="x.json")
    with pytest.raises(InputError, match=r"distortion\.kk1"):
        distortion_from_dict({"model": "brown_conrady", "kk1": 1e-5})
    with pytest.raises(InputError, match=r"distortion\.k2"):
        distortion_from_dict({"model": "brown_conrady", "k2": "small"})


# ------------------------------------------------------------- lens model vs OpenCV
def _opencv_coefficients(lens: BrownConrady, f: float) -> np.ndarray:
    """Our coefficients expressed in OpenCV's (k1, k2, p1, p2, k3).

    OpenCV works in coordinates normalised by the focal length, with y DOWN, and its model
    maps undistorted -> distorted: x_d = x (1 + k1 r^2 + ...) + 2 p1 x y + p2 (r^2 + 2 x^2).
    With x_n = x/f and y_n = -y/f, our correction d (measured -> ideal) has exactly that form
    with k1 f^2, k2 f^4, k3 f^6, OpenCV p1 = -p2 f and OpenCV p2 = p1 f. So OpenCV's
    "distortion" run on OUR measured point gives OUR ideal point: the two models go in
    opposite directions.
    """
    k1, k2, k3, p1, p2 = lens.params
    return np.array([k1 * f**2, k2 * f**4, -p2 * f, p1 * f, k3 * f**6])


def test_brown_conrady_against_opencv_model() -> None:
    cam = make_camera()
    f, ps = cam.focal_mm, cam.pixel_size_mm
    measured = cam.pixel_to_image(frame_grid(cam)) - [cam.x0_mm, cam.y0_mm]
    ideal = BC.undistort(measured)
    col0, row0 = cam.principal_point_px
    # OpenCV puts the centre of the first pixel at (0, 0), we at (0.5, 0.5): subtract 0.5.
    k = np.array([[f / ps, 0.0, col0 - 0.5], [0.0, f / ps, row0 - 0.5], [0.0, 0.0, 1.0]])
    dist = _opencv_coefficients(BC, f)
    # 1. OpenCV's forward model on our measured points reproduces our ideal points.
    normalised = np.column_stack([measured[:, 0] / f, -measured[:, 1] / f, np.ones(len(ideal))])
    uv, _ = cv2.projectPoints(normalised.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), k, dist)
    ideal_px = cam.image_to_pixel(ideal + np.array([cam.x0_mm, cam.y0_mm])) - 0.5
    # Both are closed-form double evaluations of values below 3e4 px: 1e-6 px is generous.
    assert np.abs(uv.reshape(-1, 2) - ideal_px).max() <= 1e-6
    # 2. OpenCV's iterative inverse of its model, on our ideal points, gives our measured ones
    #    (an independent check of our Newton inversion).
    crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 1000, 1e-15)
    back = cv2.undistortPointsIter(ideal_px.reshape(-1, 1, 2), k, dist, None, None, crit)
    back_mm = back.reshape(-1, 2) * [f, -f]
    ours = BC.distort(ideal, tol_mm=1e-6 * ps)
    assert np.abs(back_mm - ours).max() / ps <= 1e-6
    # 3. Handing our coefficients to OpenCV unconverted is wrong by many pixels: the
    #    conversion above is not a no-op.
    raw = np.array([BC.params[0], BC.params[1], BC.params[3], BC.params[4], BC.params[2]])
    uv_raw, _ = cv2.projectPoints(normalised.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), k, raw)
    assert np.abs(uv_raw.reshape(-1, 2) - ideal_px).max() > 100.0


# ---------------------------------------------------------------------------- camera files
def test_camera_json_round_trip(tmp_path: Path) -> None:
    cam = Camera("UltraCam", 100.5 + 1e-13, 0.0052, 17310, 11310, 0.0123456789, -1 / 3, BC)
    path = tmp_path / "cam.json"
    write_camera_json(path, cam)
    back = read_camera_json(path)
    assert back == cam  # exact: JSON floats are written with repr()
    data = json.loads(path.read_text())
    assert data["distortion"]["model"] == "brown_conrady"
    assert set(data) == {
        "name", "focal_mm", "pixel_size_mm", "width_px", "height_px", "x0_mm", "y0_mm",
        "distortion",
    }  # fmt: skip
    plain = Camera("p", 50.0, 0.01, 100, 80)
    write_camera_json(path, plain)
    assert read_camera_json(path) == plain


def test_camera_json_in_pixels(tmp_path: Path) -> None:
    path = tmp_path / "px.json"
    path.write_text(
        json.dumps(
            {
                "focal_px": 25000,
                "pixel_size_mm": 0.004,
                "width_px": 26000,
                "height_px": 17000,
                "ppx_px": 13010.0,
                "ppy_px": 8480.0,
                "distortion": {"model": "brown_conrady", "k1": -5e-5},
                "description": "comments are allowed",
            }
        )
    )
    cam = read_camera_json(path)
    assert cam.name == "px"  # defaults to the file stem
    assert cam.focal_mm == pytest.approx(100.0, rel=1e-15)
    # ppx 10 px right of the centre -> +0.04 mm; ppy 20 px above the centre -> +0.08 mm.
    assert (cam.x0_mm, cam.y0_mm) == (pytest.approx(0.04), pytest.approx(0.08))
    assert_allclose(cam.principal_point_px, (13010.0, 8480.0), rtol=0, atol=1e-9)
    assert cam.distortion == BrownConrady(k1=-5e-5)


GOOD = {"name": "c", "focal_mm": 100.0, "pixel_size_mm": 0.004, "width_px": 26000,
        "height_px": 17000}  # fmt: skip


@pytest.mark.parametrize(
    ("change", "key"),
    [
        ({"focal_mm": None}, "focal_mm"),  # None = remove the key
        ({"pixel_size_mm": -0.004}, "pixel_size_mm"),
        ({"pixel_size_mm": None}, "pixel_size_mm"),
        ({"width_px": 26000.5}, "width_px"),
        ({"height_px": "17000"}, "height_px"),
        ({"focal_mm": True}, "focal_mm"),
        ({"focal_px": 25000.0}, "focal_px"),  # both focal_mm and focal_px
        ({"focal_mm": None, "focal_px": 0}, "focal_px"),
        ({"x0_mm": [1]}, "x0_mm"),
        ({"distortion": {"model": "tsai", "k1": 0.1}}, "distortion.model"),
        ({"distortion": {"k1": 0.1}}, "distortion.model"),
        ({"distortion": {"model": "brown_conrady", "k4": 0.1}}, "distortion.k4"),
        ({"distortion": "brown"}, "distortion"),
        ({"focal_lenght_mm": 100.0}, "focal_lenght_mm"),
        ({"name": 5}, "name"),
    ],
)
def test_bad_camera_json_names_file_and_key(tmp_path: Path, change: dict, key: str) -> None:
    data = dict(GOOD)
    for k, v in change.items():
        if v is None:
            data.pop(k)
        else:
            data[k] = v
    path = tmp_path / "bad_camera.json"
    path.write_text(json.dumps(data))
    with pytest.raises(InputError) as info:
        read_camera_json(path)
    message = str(info.value)
    assert str(path) in message and f"'{key}'" in message, message
    assert info.value.path == str(path)


def test_unreadable_camera_json(tmp_path: Path) -> None:
    path = tmp_path / "broken.json"
    path.write_text('{"focal_mm": 100.0,\n "pixel_size_mm": }')
    with pytest.raises(InputError, match="line 2"):
        read_camera_json(path)
    path.write_text('{"focal_mm": NaN}')
    with pytest.raises(InputError, match="NaN"):
        read_camera_json(path)
    with pytest.raises(InputError, match=r"missing\.json"):
        read_camera_json(tmp_path / "missing.json")
    with pytest.raises(InputError, match="object"):
        camera_from_dict([1, 2, 3], source="list.json")
