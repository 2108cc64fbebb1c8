"""The lens distortion plots of the calibration and bundle reports against the lens model."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import numpy as np
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.distortion import BrownConrady, NoDistortion
from lidarphoto.core.photo.calibration_targets import TargetSpec, target_field
from lidarphoto.core.photo.camera_calibration import (
    CalibrationOptions,
    calibrate_camera,
    look_at_eo,
    simulate_views,
)
from lidarphoto.core.quality.calibration_html import render_calibration_html
from lidarphoto.core.quality.lens_plots import (
    lens_correction_px,
    lens_distortion_field,
    lens_radial_profile,
)

PS = 0.004  # mm
K1, K2, P1, P2 = -2e-3, 5e-5, 1e-4, -5e-5


def _camera(distortion=None) -> Camera:
    lens = BrownConrady(k1=K1, k2=K2, p1=P1, p2=P2) if distortion is None else distortion
    return Camera("t", 1000 * PS, PS, 1280, 960, 0.02, -0.015, lens)


def _brown_px(cam: Camera, cols_rows: np.ndarray) -> np.ndarray:
    """Brown-Conrady written out from its formula (mm, y up), returned in px with rows down."""
    x = (cols_rows[:, 0] - 640) * PS - cam.x0_mm
    y = (480 - cols_rows[:, 1]) * PS - cam.y0_mm
    r2 = x * x + y * y
    radial = K1 * r2 + K2 * r2 * r2
    dx = x * radial + P1 * (r2 + 2 * x * x) + 2 * P2 * x * y
    dy = y * radial + 2 * P1 * x * y + P2 * (r2 + 2 * y * y)
    return np.column_stack([dx, -dy]) / PS


def test_correction_in_pixels_is_the_model_written_out():
    cam = _camera()
    rng = np.random.default_rng(0)
    cr = rng.uniform([0, 0], [1280, 960], (50, 2))
    got = lens_correction_px(cam, cr)
    assert np.allclose(got, _brown_px(cam, cr), atol=1e-12, rtol=0)
    # barrel correction (k1 < 0) pulls a corner towards the centre: the top-left corner moves
    # right and down
    corner = lens_correction_px(cam, np.array([[0.0, 0.0]]))[0]
    assert corner[0] > 1.0 and corner[1] > 1.0


def test_field_states_the_corner_correction_and_parses():
    cam = _camera()
    svg = lens_distortion_field(cam, title="lens t")
    ET.fromstring(svg)  # well-formed
    corners = np.array([[0, 0], [1280, 0], [0, 960], [1280, 960]], dtype=float)
    truth = np.max(np.hypot(*_brown_px(cam, corners).T))
    stated = float(re.search(r"; ([0-9.]+) px at the corners", svg).group(1))
    assert abs(stated - truth) <= 5e-4 * truth  # 4 significant digits
    assert svg.count("<polygon") > 90  # an arrow in (nearly) every one of the 108 cells


def test_radial_profile_follows_k1_and_k2():
    cam = _camera(BrownConrady(k1=K1, k2=K2))
    svg = lens_radial_profile(cam, title="radial")
    ET.fromstring(svg)
    curves = re.findall(r'<polyline points="([^"]+)"', svg)
    assert len(curves) == 2  # radial and tangential
    radial = np.array([[float(v) for v in p.split(",")] for p in curves[0].split()])
    tangential = np.array([[float(v) for v in p.split(",")] for p in curves[1].split()])
    # no decentring: the tangential part is a flat line, the radial one falls (barrel) from 0
    assert np.ptp(tangential[:, 1]) < 0.2
    assert radial[0, 1] == tangential[0, 1]
    assert radial[-1, 1] > radial[0, 1] + 50  # y grows downwards on the page


def test_calibration_report_shows_the_calibrated_lens():
    cam = _camera()
    fld = target_field(TargetSpec("chessboard", 9, 6, 0.05))
    ctr = fld.xyz.mean(0)
    rng = np.random.default_rng(1)
    eos = []
    for i in range(8):
        az, tilt = 2 * np.pi * i / 8, np.radians(rng.uniform(15, 40))
        c = ctr + 0.6 * np.array([np.sin(tilt) * np.cos(az), np.sin(tilt) * np.sin(az),
                                  np.cos(tilt)])  # fmt: skip
        eos.append(look_at_eo(c, ctr, rng.uniform(-0.5, 0.5)))
    det = simulate_views(cam, fld, np.array(eos), noise_px=0.2, seed=3)
    res = calibrate_camera(fld, det, 1280, 960, PS, CalibrationOptions(sigma_px=0.2))
    page = render_calibration_html(res, {"target": "chessboard"})
    assert "Lens distortion" in page and page.count('class="lens-') == 2
    # the plot is the calibrated camera's lens: its corners as stated, and where the board was
    # seen (the middle 400 x 400 px) the truth's within the calibration's own error: 0.2 px
    # noise on 8 views of 54 corners leave the lens field a few hundredths of a pixel off
    stated = float(re.search(r"; ([0-9.]+) px at the corners", page).group(1))
    corners = np.array([[0, 0], [1280, 0], [0, 960], [1280, 960]], dtype=float)
    plotted = np.max(np.hypot(*lens_correction_px(res.camera, corners).T))
    assert abs(stated - plotted) <= 5e-4 * plotted
    inner = np.random.default_rng(2).uniform([440, 280], [840, 680], (200, 2))
    err = lens_correction_px(res.camera, inner) - _brown_px(cam, inner)
    off = np.hypot(*err.T)
    assert np.median(off) < 0.05 and np.max(off) < 0.2


def test_a_camera_without_lens_model_gets_no_lens_section():
    from types import SimpleNamespace

    from lidarphoto.core.quality.bundle_html import _lens_plots

    plain = SimpleNamespace(cameras={"t": _camera(NoDistortion())})
    assert _lens_plots(plain) == []
    lens = SimpleNamespace(cameras={"t": _camera()})
    assert len(_lens_plots(lens)) == 5  # heading, div, two plots, /div
