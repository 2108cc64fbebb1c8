"""Control plates and control chips with a nadir FISHEYE ground camera (the source's case:
Berveglieri & Tommaselli 2014), against truth.

Truth: the textured ground patch with and without the plate rendered by
core/simulation/ground_photo.py through an equidistant and an equisolid-angle camera with a
Brown lens (960 x 720 px of 4.5 um, f = 1.6 mm: 97 degrees off the axis in the image corners,
which see the sky; 5 mm ground pixels at 1.8 m) from known poses; the plate's corners
projected with the true pose; the chip's texture rendered as an orthographic view of the
patch.

Tolerances are those of the perspective tests (tests/core/test_control_chips.py), which the
noise gives: 1 DN of Gaussian noise puts the inner corners (plate against plate) within a few
hundredths of a pixel and, on uniform ground, every corner within 4 of its propagated sigmas
(+ the rendering's 1/256 px of area quantisation); the ground texture next to the outer edge
pulls the outer corners by up to about a tenth of a pixel (the stated CORNER_PX = 0.15 px);
the pose within 3 sigmas propagated from CORNER_PX; the chip's point at its known position
within 0.1 chip pixel.
"""

from __future__ import annotations

import csv
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from lidarphoto.core.cli import main as cli_main
from lidarphoto.core.geometry.collinearity import project
from lidarphoto.core.geometry.projection import PROJECTIONS
from lidarphoto.core.io.camera import read_camera_json, write_camera_json
from lidarphoto.core.io.raster import RasterReader
from lidarphoto.core.io.raster_write import GeoTiffWriter
from lidarphoto.core.photo.control_chips import ChipOptions, make_chip, register_sift
from lidarphoto.core.photo.control_plate import (
    PlateGeometry,
    detect_plate,
    photo_azimuth,
    pixels_from_plane,
    plane_from_pixels,
    plane_to_pixel_jacobian,
    resect_plate,
)
from lidarphoto.core.quality.registration import phase_correlation
from lidarphoto.core.simulation.ground_photo import (
    corner_errors,
    ground_camera,
    make_ground_patch,
    render_ground_photo,
    render_ortho,
)

CRS = "EPSG:31983"
POINT = np.array([457_321.25, 7_552_104.75, 431.2])
GSD = 0.01
SIZE = 101
CORNER_PX = 0.15
PLATE = PlateGeometry(outer_m=0.5, inner_m=0.25, height_m=0.0, azimuth_deg=20.0)
EO_PLATE = np.array([0.45, -0.30, 1.80, *np.radians([3.0, -2.0, 25.0])])
EO_FREE = EO_PLATE + np.array([0.004, -0.003, 0.002, *np.radians([1.0, 0.5, 4.0])])




@pytest.fixture(scope="module", params=["equidistant", "equisolid"])
def scene(request):
    cam = ground_camera(request.param)
    # the ground's features as wide in pixels as in the perspective tests (12 mm at 3 mm per
    # pixel there, 20 mm at 5 mm here): the outer corners' texture bias depends on that
    patch = make_ground_patch(feature_m=0.02, seed=3)
    plate_photo = render_ground_photo(patch, cam, EO_PLATE, PLATE, supersample=2, seed=4)
    free_photo = render_ground_photo(patch, cam, EO_FREE, None, supersample=2, seed=5)
    return {"cam": cam, "patch": patch, "plate": plate_photo, "free": free_photo,
            "truth": project(PLATE.corners(), EO_PLATE, cam)}  # fmt: skip




def test_the_fisheye_is_far_from_a_perspectiveground_camera(scene):
    """The same focal length as a perspective camera puts the corners pixels away, and the
    photo's corners look beyond 90 degrees (sky): code treating the camera as perspective
    would fail these tests."""
    cam = scene["cam"]
    persp = dataclasses.replace(cam, projection="perspective")
    moved = np.linalg.norm(project(PLATE.corners(), EO_PLATE, persp) - scene["truth"], axis=1)
    assert moved.max() > 2.0
    assert (scene["plate"][:3, :3] < 5).all()  # the sky in the top-left corner: grey 0


def test_ray_plane_of_a_fisheye():
    """Pixels <-> the ray plane z = -1 round trip, NaN for rays at or beyond 90 degrees (no
    point on that plane), and the plane -> pixel Jacobian (corner sigmas, edge normals)
    against central differences."""
    cam = ground_camera("equidistant")
    rng = np.random.default_rng(2)
    px = rng.uniform([300, 200], [660, 520], (50, 2))
    uv = plane_from_pixels(px, cam)
    np.testing.assert_allclose(pixels_from_plane(uv, cam), px, atol=1e-6)
    # the image corner is 97 degrees off the axis
    assert np.isnan(plane_from_pixels([[1.0, 1.0]], cam)).all()
    jac = plane_to_pixel_jacobian(uv, cam)
    h = 1e-6
    for k in range(2):
        step = np.zeros(2)
        step[k] = h
        num = (pixels_from_plane(uv + step, cam) - pixels_from_plane(uv - step, cam)) / (2 * h)
        np.testing.assert_allclose(jac[:, :, k], num, rtol=1e-5, atol=1e-3)


def test_fisheye_corners_sub_pixel_on_textured_ground(scene):
    det = detect_plate(scene["plate"], scene["cam"], PLATE)
    assert det.found, det.reason
    err = corner_errors(det.corners_px, scene["truth"])
    assert err[4:].max() < 0.06
    assert err.max() < CORNER_PX
    assert (det.edge_points >= 30).all()


def test_fisheye_corners_on_uniform_ground_within_their_sigmas(scene):
    """The sigmas are propagated to pixels through the projection's Jacobian: the errors on
    uniform ground (no texture bias) within 4 of them."""
    flat = dataclasses.replace(scene["patch"], grey=np.full_like(scene["patch"].grey, 120.0))
    photo = render_ground_photo(flat, scene["cam"], EO_PLATE, PLATE, supersample=1, seed=6)
    det = detect_plate(photo, scene["cam"], PLATE)
    assert det.found, det.reason
    err = corner_errors(det.corners_px, scene["truth"])
    assert err.max() < 0.06
    assert (err < 4 * det.sigma_px + 0.02).all(), (err, det.sigma_px)


def test_fisheye_resection_recovers_the_pose(scene):
    det = detect_plate(scene["plate"], scene["cam"], PLATE)
    az = photo_azimuth(EO_PLATE)
    pr = resect_plate(det, scene["cam"], PLATE, az + 30.0, sigma_px=CORNER_PX)
    assert abs(pr.azimuth_misfit_deg + 30.0) < 1.0
    tol = 3.0 * pr.result.std_prior
    err = pr.eo - EO_PLATE
    assert (np.abs(err) < tol).all(), (err, tol)
    assert np.abs(err[:3]).max() < 0.01
    assert pr.redundancy == 10


def test_fisheye_chip_matches_the_orthographic_truth(scene):
    res = make_chip("GCP1", POINT, scene["plate"], scene["free"], scene["cam"], PLATE,
                    ChipOptions(gsd_m=GSD, size_px=SIZE), photo_azimuth(EO_PLATE))  # fmt: skip
    assert res.status == "ok", res.reason
    assert res.source == "free"
    gt = res.geotransform
    local = (gt[0] - POINT[0], gt[1], 0.0, gt[3] - POINT[1], 0.0, gt[5])
    truth = render_ortho(scene["patch"], local, SIZE)
    assert np.isfinite(res.chip).all()
    assert np.corrcoef(res.chip.ravel(), truth.ravel())[0, 1] > 0.95
    dx, dy, _ = phase_correlation(truth, res.chip)
    assert math.hypot(dx, dy) < 0.1  # chip pixels: the surveyed point at its chip position
    assert len(res.sift.ref_px) >= 100
    # the plate-free photo's pose inherits the plate photo's (its ground points come from the
    # plate photo's rays): within 3 sigmas of the plate pose propagated from CORNER_PX (a
    # 5 mm ground pixel makes that about 10 mm and 0.3 deg here)
    pr = resect_plate(res.detection, scene["cam"], PLATE, photo_azimuth(EO_PLATE),
                      sigma_px=CORNER_PX)  # fmt: skip
    assert (np.abs(res.free_eo - EO_FREE) < 3.0 * pr.result.std_prior).all()


def test_fisheye_photos_are_registered_on_their_rays(scene):
    """Why the plate-free photo is registered on the ray planes: there the two photos of the
    ground are related by a homography whatever the lens; between the fisheye photos' pixels
    a homography leaves a model error several times the matching noise."""
    import cv2

    cam = scene["cam"]
    reg = register_sift(scene["plate"], scene["free"], cam)
    assert len(reg.ref_px) >= 100
    ua = plane_from_pixels(reg.ref_px, cam).reshape(-1, 1, 2)
    pred = pixels_from_plane(cv2.perspectiveTransform(ua, reg.homography).reshape(-1, 2), cam)
    on_rays = np.median(np.linalg.norm(pred - reg.moved_px, axis=1))
    h, _ = cv2.findHomography(reg.ref_px, reg.moved_px, 0)
    moved = cv2.perspectiveTransform(reg.ref_px.reshape(-1, 1, 2), h).reshape(-1, 2)
    on_pixels = np.median(np.linalg.norm(moved - reg.moved_px, axis=1))
    assert on_rays < 0.15  # px: SIFT's matching noise
    assert on_pixels > 3.0 * on_rays, (on_rays, on_pixels)


# ------------------------------------------------------------------ the job
def _write_grey(path: Path, img: np.ndarray) -> None:
    u8 = np.clip(np.rint(img), 0, 255).astype(np.uint8)
    with GeoTiffWriter(str(path), u8.shape[1], u8.shape[0], 1, np.uint8, None, None) as w:
        w.write(u8)


def test_job_with_a_fisheye_camera_file(scene, tmp_path):
    photos = tmp_path / "photos"
    photos.mkdir()
    _write_grey(photos / "GCP1_plate.tif", scene["plate"])
    _write_grey(photos / "GCP1_free.tif", scene["free"])
    write_camera_json(tmp_path / "fisheye.json", scene["cam"])
    assert read_camera_json(tmp_path / "fisheye.json", PROJECTIONS) == scene["cam"]
    (tmp_path / "points.csv").write_text(
        f"point_id,X,Y,Z,role\nGCP1,{POINT[0]},{POINT[1]},{POINT[2]},control\n"
    )
    out = tmp_path / "chips"
    args = ["makecontrolchips", "--points", str(tmp_path / "points.csv"), "--crs", CRS,
            "--camera", str(tmp_path / "fisheye.json"), "--photos", str(photos),
            "--outer-side", "0.5", "--inner-side", "0.25", "--plate-azimuth", "20",
            "--photo-azimuth", f"{photo_azimuth(EO_PLATE):.3f}", "--gsd", str(GSD),
            "--chip-size", str(SIZE), "--output-folder", str(out)]  # fmt: skip
    assert cli_main(args) == 0
    with RasterReader(out / "GCP1.tif") as src:
        gt, data = src.info.geotransform, src.read()[0]
    assert gt[0] + SIZE / 2 * gt[1] == pytest.approx(POINT[0], abs=1e-6)
    assert gt[3] + SIZE / 2 * gt[5] == pytest.approx(POINT[1], abs=1e-6)
    local = (gt[0] - POINT[0], gt[1], 0.0, gt[3] - POINT[1], 0.0, gt[5])
    truth = render_ortho(scene["patch"], local, SIZE)
    assert np.corrcoef(data.ravel(), truth.ravel())[0, 1] > 0.95
    dx, dy, _ = phase_correlation(truth, data.astype(np.float32))
    assert math.hypot(dx, dy) < 0.1
    row = next(csv.DictReader((out / "control_chips.csv").open()))
    assert row["status"] == "ok" and row["corners_found"] == "8"
    assert int(row["sift_inliers"]) >= 100
