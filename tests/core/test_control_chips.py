"""Control plates and control chips against truth (core/photo/control_plate.py,
core/photo/control_chips.py, core/jobs/make_control_chips.py).

Truth: a textured ground patch with and without the plate, rendered by
core/simulation/ground_photo.py through a ground camera with a Brown lens and known poses;
the plate's corners projected with the true pose; the chip's texture rendered directly as an
orthographic view of the patch.
"""

from __future__ import annotations

import csv
import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pyproj
import pytest
from lidarphoto.core.cli import main as cli_main
from lidarphoto.core.geometry.camera import camera_from_dict
from lidarphoto.core.geometry.collinearity import project
from lidarphoto.core.io.camera import write_camera_json
from lidarphoto.core.io.control_chips import CHIP_NODATA
from lidarphoto.core.io.raster import RasterReader
from lidarphoto.core.io.raster_write import GeoTiffWriter
from lidarphoto.core.photo.control_chips import ChipOptions, chip_grid, make_chip
from lidarphoto.core.photo.control_plate import (
    PlateGeometry,
    detect_plate,
    photo_azimuth,
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

CRS = "EPSG:31983"  # SIRGAS 2000 / UTM zone 23S (Presidente Prudente)
POINT = np.array([457_321.25, 7_552_104.75, 431.2])
GSD = 0.01
SIZE = 101
#: Stated accuracy of a plate corner on textured ground (the outer edge's bias, module
#: docstring of control_plate); the pose tolerance is propagated from it.
CORNER_PX = 0.15
PLATE = PlateGeometry(outer_m=0.5, inner_m=0.25, height_m=0.0, azimuth_deg=20.0)
EO_PLATE = np.array([0.45, -0.30, 1.80, *np.radians([3.0, -2.0, 25.0])])
# the plate-free photo: the camera put back on its tripod, slightly turned and moved
EO_FREE = EO_PLATE + np.array([0.004, -0.003, 0.002, *np.radians([1.0, 0.5, 4.0])])


@pytest.fixture(scope="module")
def scene():
    cam = ground_camera()
    patch = make_ground_patch(seed=3)
    plate_photo = render_ground_photo(patch, cam, EO_PLATE, PLATE, supersample=2, seed=4)
    free_photo = render_ground_photo(patch, cam, EO_FREE, None, supersample=2, seed=5)
    return {"cam": cam, "patch": patch, "plate": plate_photo, "free": free_photo,
            "truth": project(PLATE.corners(), EO_PLATE, cam)}  # fmt: skip




def test_lens_is_not_negligible(scene):
    """The Brown term moves the plate's corners by pixels: the detector must remove it."""
    cam = scene["cam"]
    pinhole = dataclasses.replace(cam, distortion=camera_from_dict(
        {"name": "p", "focal_mm": 3.0, "pixel_size_mm": 0.005, "width_px": 960,
         "height_px": 720}).distortion)  # fmt: skip
    moved = np.linalg.norm(project(PLATE.corners(), EO_PLATE, pinhole) - scene["truth"], axis=1)
    assert moved.max() > 2.0


def test_corners_sub_pixel_on_textured_ground(scene):
    det = detect_plate(scene["plate"], scene["cam"], PLATE)
    assert det.found, det.reason
    err = corner_errors(det.corners_px, scene["truth"])
    # inner edges (plate against plate): a few hundredths; outer edges (plate against the
    # ground's texture) pulled by the texture up to about a tenth of a pixel
    assert err[4:].max() < 0.06
    assert err.max() < CORNER_PX
    assert (det.edge_points >= 50).all()


def test_corners_on_uniform_ground_within_their_sigmas(scene):
    """Without texture the corners are unbiased: errors within 4 propagated sigmas (+ the
    rendering's own 1/256 px of area quantisation)."""
    flat = dataclasses.replace(scene["patch"], grey=np.full_like(scene["patch"].grey, 120.0))
    photo = render_ground_photo(flat, scene["cam"], EO_PLATE, PLATE, supersample=1, seed=6)
    det = detect_plate(photo, scene["cam"], PLATE)
    assert det.found, det.reason
    err = corner_errors(det.corners_px, scene["truth"])
    assert err.max() < 0.06
    assert (err < 4 * det.sigma_px + 0.02).all()


def test_resection_recovers_the_pose(scene):
    det = detect_plate(scene["plate"], scene["cam"], PLATE)
    az = photo_azimuth(EO_PLATE)
    pr = resect_plate(det, scene["cam"], PLATE, az + 30.0, sigma_px=CORNER_PX)
    assert abs(pr.azimuth_misfit_deg + 30.0) < 1.0
    # tolerance: 3 sigmas of the pose propagated from the stated corner accuracy
    tol = 3.0 * pr.result.std_prior
    err = pr.eo - EO_PLATE
    assert (np.abs(err) < tol).all(), (err, tol)
    assert np.abs(err[:3]).max() < 0.01  # metres: the figure the README quotes
    assert pr.redundancy == 10


def test_photo_azimuth_picks_the_quarter_turn(scene):
    """A reading 90 degrees off picks another turn: the pose is then 90 degrees off (what the
    azimuth is for); the misfit tells it."""
    det = detect_plate(scene["plate"], scene["cam"], PLATE)
    right = resect_plate(det, scene["cam"], PLATE, photo_azimuth(EO_PLATE))
    wrong = resect_plate(det, scene["cam"], PLATE, photo_azimuth(EO_PLATE) + 90.0)
    assert wrong.turn != right.turn
    dk = math.degrees(wrong.eo[5] - right.eo[5]) % 360.0
    assert min(abs(dk - 90.0), abs(dk - 270.0)) < 1.0


def test_chip_matches_the_orthographic_truth(scene):
    cam = scene["cam"]
    res = make_chip("GCP1", POINT, scene["plate"], scene["free"], cam, PLATE,
                    ChipOptions(gsd_m=GSD, size_px=SIZE), photo_azimuth(EO_PLATE))  # fmt: skip
    assert res.status == "ok", res.reason
    assert res.source == "free"
    # the geotransform puts the point at the chip's centre, (SIZE/2, SIZE/2)
    gt = res.geotransform
    assert gt == chip_grid(POINT[:2], GSD, SIZE)
    assert gt[0] + SIZE / 2 * gt[1] == pytest.approx(POINT[0], abs=1e-9)
    assert gt[3] + SIZE / 2 * gt[5] == pytest.approx(POINT[1], abs=1e-9)
    local = (gt[0] - POINT[0], gt[1], 0.0, gt[3] - POINT[1], 0.0, gt[5])
    truth = render_ortho(scene["patch"], local, SIZE)
    chip = res.chip
    assert np.isfinite(chip).all()
    ncc = np.corrcoef(chip.ravel(), truth.ravel())[0, 1]
    assert ncc > 0.95
    dx, dy, _ = phase_correlation(truth, chip)
    assert math.hypot(dx, dy) < 0.1  # chip pixels: the point's chip position
    # the plate-free photo's pose from the SIFT matches
    assert len(res.sift.ref_px) >= 100
    assert np.abs(res.free_eo[:3] - EO_FREE[:3]).max() < 0.01
    assert np.abs(res.free_eo[3:] - EO_FREE[3:]).max() < math.radians(0.3)


def test_chip_from_the_plate_photo_is_an_option(scene):
    cam = scene["cam"]
    opt = ChipOptions(gsd_m=GSD, size_px=SIZE)
    az = photo_azimuth(EO_PLATE)
    refused = make_chip("GCP1", POINT, scene["plate"], None, cam, PLATE, opt, az)
    assert refused.status == "failed" and "no plate-free photo" in refused.reason
    made = make_chip("GCP1", POINT, scene["plate"], None, cam, PLATE,
                     dataclasses.replace(opt, from_plate_photo=True), az)  # fmt: skip
    assert made.status == "ok" and made.source == "plate"
    assert "plate hides" in made.notes[0]
    # outside the plate (and a cell's margin) the chip is the ground
    gt = made.geotransform
    local = (gt[0] - POINT[0], gt[1], 0.0, gt[3] - POINT[1], 0.0, gt[5])
    truth = render_ortho(scene["patch"], local, SIZE)
    c = (np.arange(SIZE) + 0.5 - SIZE / 2) * GSD
    gx, gy = np.meshgrid(c, -c)
    a = math.radians(PLATE.azimuth_deg)
    u = np.abs(gx * math.sin(a) + gy * math.cos(a))
    v = np.abs(-gx * math.cos(a) + gy * math.sin(a))
    ground = np.maximum(u, v) > PLATE.outer_m / 2 + 2 * GSD
    assert np.corrcoef(made.chip[ground], truth[ground])[0, 1] > 0.95


def test_failures_carry_their_reason(scene):
    cam = scene["cam"]
    opt = ChipOptions(gsd_m=GSD, size_px=SIZE)
    az = photo_azimuth(EO_PLATE)
    no_plate = make_chip("P", POINT, scene["free"], scene["free"], cam, PLATE, opt, az)
    assert no_plate.status == "failed"
    assert no_plate.reason.startswith(("plate not found", "only one square"))
    wrong_ratio = detect_plate(scene["plate"], cam, dataclasses.replace(PLATE, inner_m=0.45))
    assert not wrong_ratio.found and wrong_ratio.reason.startswith("only one square")
    noise = np.random.default_rng(0).uniform(0, 255, scene["free"].shape).astype(np.float32)
    sift = make_chip("P", POINT, scene["plate"], noise, cam, PLATE, opt, az)
    assert sift.status == "failed" and sift.reason.startswith("too few SIFT matches")
    strict = make_chip("P", POINT, scene["plate"], scene["free"], cam, PLATE,
                       dataclasses.replace(opt, max_sigma0=1e-3), az)  # fmt: skip
    assert strict.status == "failed" and strict.reason.startswith("resection sigma0")
    big = make_chip("P", POINT, scene["plate"], scene["free"], cam, PLATE,
                    dataclasses.replace(opt, size_px=401), az)  # fmt: skip
    assert big.status == "failed" and "of the chip" in big.reason


def test_two_plates_are_ambiguous(scene):
    cam = scene["cam"]
    two = np.hstack([scene["plate"], scene["plate"]])
    wide = dataclasses.replace(cam, width_px=2 * cam.width_px)
    det = detect_plate(two, wide, PLATE)
    assert not det.found and det.reason.startswith("ambiguous") and det.candidates == 2


# ------------------------------------------------------------------ the job
def _write_grey(path: Path, img: np.ndarray) -> None:
    u8 = np.clip(np.rint(img), 0, 255).astype(np.uint8)
    with GeoTiffWriter(str(path), u8.shape[1], u8.shape[0], 1, np.uint8, None, None) as w:
        w.write(u8)


@pytest.fixture(scope="module")
def job_files(scene, tmp_path_factory):
    d = tmp_path_factory.mktemp("chips_in")
    photos = d / "photos"
    photos.mkdir()
    _write_grey(photos / "GCP1_plate.tif", scene["plate"])
    _write_grey(photos / "GCP1_free.tif", scene["free"])
    _write_grey(photos / "GCP2_plate.tif", scene["free"])  # no plate in it
    write_camera_json(d / "camera.json", scene["cam"])
    rows = ["point_id,X,Y,Z,role", f"GCP1,{POINT[0]},{POINT[1]},{POINT[2]},control",
            f"GCP2,{POINT[0] + 50},{POINT[1]},{POINT[2]},control",
            f"GCP3,{POINT[0] + 90},{POINT[1]},{POINT[2]},check"]  # fmt: skip
    (d / "points.csv").write_text("\n".join(rows) + "\n")
    return d


def test_job_writes_chips_and_report(scene, job_files, tmp_path):
    d = job_files
    out = tmp_path / "chips"
    az = photo_azimuth(EO_PLATE)
    args = ["makecontrolchips", "--points", str(d / "points.csv"), "--crs", CRS,
            "--camera", str(d / "camera.json"), "--photos", str(d / "photos"),
            "--outer-side", "0.5", "--inner-side", "0.25", "--plate-azimuth", "20",
            "--photo-azimuth", f"{az:.3f}", "--gsd", str(GSD), "--chip-size", str(SIZE),
            "--output-folder", str(out)]  # fmt: skip
    assert cli_main(args) == 0
    assert sorted(p.name for p in out.iterdir()) == ["GCP1.tif", "control_chips.csv",
                                                     "control_chips.json"]  # fmt: skip
    with RasterReader(out / "GCP1.tif") as src:
        info, data = src.info, src.read()[0]
    assert (info.width, info.height, info.bands) == (SIZE, SIZE, 1)
    gt = info.geotransform
    assert gt[0] + SIZE / 2 * gt[1] == pytest.approx(POINT[0], abs=1e-6)
    assert gt[3] + SIZE / 2 * gt[5] == pytest.approx(POINT[1], abs=1e-6)
    assert pyproj.CRS.from_wkt(info.crs_wkt).equals(pyproj.CRS.from_user_input(CRS))
    assert info.nodata == CHIP_NODATA and info.metadata.get("LIDARPHOTO_POINT_ID") == "GCP1"
    local = (gt[0] - POINT[0], gt[1], 0.0, gt[3] - POINT[1], 0.0, gt[5])
    truth = render_ortho(scene["patch"], local, SIZE)
    assert np.corrcoef(data.ravel(), truth.ravel())[0, 1] > 0.95
    rows = {r["point_id"]: r for r in csv.DictReader((out / "control_chips.csv").open())}
    assert rows["GCP1"]["status"] == "ok" and rows["GCP1"]["corners_found"] == "8"
    assert int(rows["GCP1"]["sift_inliers"]) >= 100
    assert float(rows["GCP1"]["resection_sigma0"]) > 0
    assert rows["GCP2"]["status"] == "failed"
    assert rows["GCP2"]["reason"].startswith(("plate not found", "only one square"))
    assert rows["GCP3"]["reason"] == "no plate photo"
    full = {r["point_id"]: r for r in json.loads((out / "control_chips.json").read_text())}
    assert len(full["GCP1"]["corners_px"]) == 8 and len(full["GCP1"]["plate_eo"]) == 6
    assert full["GCP1"]["plate_eo"][0] == pytest.approx(POINT[0] + EO_PLATE[0], abs=0.01)


def test_job_photo_table_and_refusals(scene, job_files, tmp_path):
    d = job_files
    table = d / "photos.csv"
    table.write_text("point_id,plate_photo,free_photo,photo_azimuth_deg\n"
                     f"GCP1,photos/GCP1_plate.tif,,{photo_azimuth(EO_PLATE):.3f}\n")  # fmt: skip
    base = ["makecontrolchips", "--points", str(d / "points.csv"), "--crs", CRS,
            "--camera", str(d / "camera.json"), "--outer-side", "0.5", "--inner-side", "0.25",
            "--plate-azimuth", "20", "--gsd", str(GSD), "--chip-size", str(SIZE)]  # fmt: skip
    out = tmp_path / "a"
    assert cli_main([*base, "--photo-table", str(table), "--from-plate-photo", "true",
                     "--output-folder", str(out)]) == 0  # fmt: skip
    rows = list(csv.DictReader((out / "control_chips.csv").open()))
    assert rows[0]["point_id"] == "GCP1" and rows[0]["source"] == "plate"
    # no photos at all, and a photo missing from the table: refused, nothing written
    out_b = tmp_path / "b"
    assert cli_main([*base, "--output-folder", str(out_b)]) != 0
    bad = d / "bad.csv"
    bad.write_text("point_id,plate_photo\nGCP1,photos/missing.tif\n")
    assert cli_main([*base, "--photo-table", str(bad), "--output-folder", str(out_b)]) != 0
    small = d / "small.csv"
    _write_grey(d / "small.tif", scene["plate"][:100, :100])
    small.write_text("point_id,plate_photo\nGCP1,small.tif\n")
    assert cli_main([*base, "--photo-table", str(small), "--output-folder", str(out_b)]) != 0
    assert not out_b.exists() or not any(out_b.iterdir())
