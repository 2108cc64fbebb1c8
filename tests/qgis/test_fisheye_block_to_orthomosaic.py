"""A fisheye UAV block from its images to an orthomosaic in real QGIS (processing.run):
lidarphoto:tiepoints -> lidarphoto:bundleadjustment -> lidarphoto:orthorectify ->
lidarphoto:orthomosaic.

Data: the six-image block of tests/core/test_tie_points_fisheye.py (two strips of three at
188 m, 1000 x 750 px of 6.16 um, an equisolid 3.6 mm fisheye with its principal point off the
centre and Brown k1: the image corners 62-65 degrees off the axis), rendered from its textured
terrain through the fisheye's own rays (core/simulation/textured_block.py, 2 grey values of
noise); the EO the block's direct georeferencing (5 m, 1 degree off, with those sigmas); its
16 control and 5 check points surveyed (1 / 1.5 cm) and measured in the images as their true
projections with 0.5 px noise (a surveyor's clicks); the DSM the block's terrain every 0.5 m.

Truth: the true EO and camera (the rendering's), the check points' true coordinates, and the
ground texture itself against the orthomosaic. Tolerances: the adjusted EO, interior and the
check points within 4 of their reported sigmas of the truth; the mosaic's ground within a
tenth of a cell (5 cm at 0.5 m) of the texture by phase correlation, where the same chain on
the direct-georeferencing EO is off by metres.
"""

from __future__ import annotations

import csv
import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import processing
import pyproj
import pytest
from lidarphoto.core.geometry.camera import Camera, camera_from_dict
from lidarphoto.core.geometry.grid import Grid
from lidarphoto.core.geometry.surface import Dsm
from lidarphoto.core.io.camera import write_camera_json
from lidarphoto.core.io.dsm import write_dsm
from lidarphoto.core.io.ground_points import write_ground_points_csv
from lidarphoto.core.io.observations import read_observations_csv, write_observations_csv
from lidarphoto.core.io.orientation import read_eo_csv, write_eo_csv_with_sigmas
from lidarphoto.core.io.raster import RasterReader
from lidarphoto.core.photo.observations import ImageObservations
from lidarphoto.core.photo.picking import PickingScene
from lidarphoto.core.quality.registration import phase_correlation
from lidarphoto.core.simulation.textured_block import TexturedBlock, make_texture, render_view
from lidarphoto.core.simulation.uav_block import simulate_uav_block
from scipy.ndimage import map_coordinates

cv2 = pytest.importorskip("cv2")

#: the perspective camera the block is flown for (its overlaps), and the fisheye it is seen by
SMALL = Camera("small", focal_mm=5.0, pixel_size_mm=0.00616, width_px=1000, height_px=750)
FISHEYE = camera_from_dict({"name": "fish", "focal_mm": 3.6, "pixel_size_mm": 0.00616,
                            "width_px": 1000, "height_px": 750, "projection": "equisolid",
                            "x0_mm": 0.03, "y0_mm": -0.02,
                            "distortion": {"model": "brown_conrady", "k1": 2e-3}})  # fmt: skip
GSD = 0.5


@pytest.fixture(scope="module")
def fisheye_uav(tmp_path_factory):
    """The block's files: images, camera, direct-georeferencing EO, ground points, the
    control measurements, DSM; and the truth (block, texture)."""
    out = tmp_path_factory.mktemp("fisheye_uav")
    blk = simulate_uav_block("none", seed=3, n_tie=50, camera=SMALL, strips=(3, 3))
    blk = dataclasses.replace(blk, camera=FISHEYE, true_camera=FISHEYE)
    tb = TexturedBlock.of(blk)
    tex = make_texture(tb.extent(), 0.3, seed=1)
    (out / "images").mkdir()
    ids = list(blk.eo_true.image_id)
    for k, name in enumerate(ids):
        cv2.imwrite(str(out / "images" / f"{name}.png"),
                    render_view(tb, tex, k, step_px=4, noise_dn=2.0))  # fmt: skip
    crs = blk.config.crs
    write_camera_json(out / "camera.json", FISHEYE)
    write_eo_csv_with_sigmas(out / "eo_dg.csv", blk.eo_dg, blk.eo_sigma)
    write_ground_points_csv(out / "ground.csv", blk.ground)
    # the targets clicked: true projections (the rendering's chain) with 0.5 px noise, the
    # control points as ties of known ground (as the block's own), the check points "check"
    scene = PickingScene(blk.eo_true, FISHEYE, crs)
    role = dict(zip(blk.ground.point_id, blk.ground.role))
    rng = np.random.default_rng(7)
    img, pid, px = [], [], []
    for name in ids:
        p = scene.project(name, blk.ground_true)
        seen = np.isfinite(p).all(axis=1) & FISHEYE.in_frame(p, 20.0)
        img += [name] * int(seen.sum())
        pid += list(np.asarray(blk.ground.point_id)[seen])
        px.append(p[seen] + rng.normal(0.0, 0.5, p[seen].shape))
    types = ["check" if role[p] == "check" else "tie" for p in pid]
    targets = ImageObservations.from_arrays(img, pid, np.vstack(px), np.full(len(img), 0.5),
                                            types, [""] * len(img))  # fmt: skip
    xmin, ymin, xmax, ymax = tb.extent(0.0)
    cols, rows = int((xmax - xmin) / 0.5), int((ymax - ymin) / 0.5)
    gx, gy = np.meshgrid(xmin + (np.arange(cols) + 0.5) * 0.5, ymax - (np.arange(rows) + 0.5) * 0.5)
    z = blk.terrain(gx.ravel(), gy.ravel()).reshape(gx.shape).astype(np.float32)
    write_dsm(out / "dsm.tif", Dsm(z, Grid(xmin, ymax, 0.5, rows, cols),
                                   pyproj.CRS.from_user_input(crs)))  # fmt: skip
    return {"out": out, "blk": blk, "tex": tex, "targets": targets, "crs": crs}


def read_csv_rows(path: Path) -> list[dict]:
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def _mosaic_shift(path: Path, tex) -> tuple[float, float, float]:
    """(dx, dy) cells and the peak of the phase correlation between the mosaic's central
    256 x 256 cells (all covered) and the texture sampled at their centres."""
    with RasterReader(path) as src:
        gt, data, mask = src.info.geotransform, src.read(), src.read_mask()
    mos = np.asarray(data, dtype=np.float64).reshape(-1, *mask.shape)[0]
    rr, cc = np.nonzero(mask)
    rc, ccen = (rr.min() + rr.max()) // 2, (cc.min() + cc.max()) // 2
    sl = (slice(rc - 128, rc + 128), slice(ccen - 128, ccen + 128))
    assert mask[sl].all()
    x = gt[0] + (np.arange(mask.shape[1])[sl[1]] + 0.5) * gt[1]
    y = gt[3] + (np.arange(mask.shape[0])[sl[0]] + 0.5) * gt[5]
    mx, my = np.meshgrid(x, y)
    u, v = (mx - tex.x0) / tex.cell - 0.5, (tex.y_top - my) / tex.cell - 0.5
    truth = map_coordinates(tex.values.astype(np.float64), [v.ravel(), u.ravel()], order=1)
    return phase_correlation(truth.reshape(mx.shape), mos[sl])


def _ortho_mosaic(out: Path, camera: Path, eo: Path, crs: str, name: str) -> Path:
    res = processing.run("lidarphoto:orthorectify", {
        "CAMERA": str(camera), "EO": str(eo), "IMAGES": [str(out / "images")],
        "DSM": str(out / "dsm.tif"), "CRS": crs, "GSD": GSD,
        "OUTPUT_FOLDER": str(out / f"orthos_{name}")})  # fmt: skip
    assert res["IMAGE_COUNT"] == 6
    mosaic = out / f"mosaic_{name}.tif"
    processing.run("lidarphoto:orthomosaic", {"ORTHOPHOTOS": [str(out / f"orthos_{name}")],
                                              "OUTPUT": str(mosaic)})  # fmt: skip
    return mosaic


def test_fisheye_block_from_images_to_orthomosaic(provider, fisheye_uav, tmp_path):
    """tiepoints on the fisheye images (pairs from the footprints: all 15 kept), the targets
    added, bundleadjustment (the interior self-calibrated), orthorectify and orthomosaic on
    the adjusted camera and EO. Measured: 1,699 tracks, sigma0 0.95; the EO within 2.1 and
    the check points within 2.0 of their sigmas; the mosaic 0.01 cells from the texture, the
    direct-georeferencing EO's mosaic 8 m off (15.9 cells); 23 s CPU in all."""
    d, blk = fisheye_uav, fisheye_uav["blk"]
    out, crs = d["out"], d["crs"]
    tie = processing.run("lidarphoto:tiepoints", {
        "IMAGES": [str(out / "images")], "EO": str(out / "eo_dg.csv"),
        "CAMERA": str(out / "camera.json"), "HEIGHT": blk.config.ground_height_m,
        "MAX_FEATURES": 1500, "OUTPUT_OBSERVATIONS": str(tmp_path / "tie.csv")})  # fmt: skip
    assert tie["PAIRS_TRIED"] == tie["PAIRS_KEPT"] == 15 and tie["TRACK_COUNT"] > 1000
    ties = read_observations_csv(tmp_path / "tie.csv")
    assert not set(ties.point_id) & set(blk.ground.point_id)
    write_observations_csv(tmp_path / "obs.csv", ties.concat(d["targets"]))
    adj = processing.run("lidarphoto:bundleadjustment", {
        "CAMERA": str(out / "camera.json"), "OBSERVATIONS": str(tmp_path / "obs.csv"),
        "GROUND_POINTS": str(out / "ground.csv"), "EO": str(out / "eo_dg.csv"), "CRS": crs,
        "OUTPUT_EO": str(tmp_path / "eo.csv"), "OUTPUT_CAMERA": str(tmp_path / "camera.json"),
        "OUTPUT_CHECK_CSV": str(tmp_path / "check.csv")})  # fmt: skip
    assert 0.7 < adj["SIGMA0"] < 1.3, adj["SIGMA0"]
    eo = read_eo_csv(tmp_path / "eo.csv")
    assert list(eo.image_id) == list(blk.eo_true.image_id)
    rows = read_csv_rows(tmp_path / "eo.csv")
    sig = np.array([[float(r[f"sigma_{k}"]) for k in ("X", "Y", "Z")] for r in rows])
    sig_a = np.radians([[float(r[f"sigma_{k}_deg"]) for k in ("omega", "phi", "kappa")]
                        for r in rows])  # fmt: skip
    dpos = (eo.xyz - blk.eo_true.xyz) / sig
    dang = ((eo.opk - blk.eo_true.opk + np.pi) % (2 * np.pi) - np.pi) / sig_a
    assert np.abs(dpos).max() < 4 and np.abs(dang).max() < 4, (dpos, dang)
    cam = json.loads((tmp_path / "camera.json").read_text())
    for key, true in (("focal_mm", 3.6), ("x0_mm", 0.03), ("y0_mm", -0.02)):
        assert abs(cam[key] - true) < 4 * cam["sigmas"][key], (key, cam[key], true)
    check = read_csv_rows(tmp_path / "check.csv")
    truth = dict(zip(blk.ground.point_id, blk.ground_true))
    assert len(check) >= 4
    worst_check = 0.0
    for r in check:
        t = truth[r["id"]]
        for k, axis in enumerate("enh"):
            ratio = abs(float(r[axis]) - t[k]) / float(r[f"sigma_{axis}"])
            worst_check = max(worst_check, ratio)
    assert worst_check < 4, worst_check

    mosaic = _ortho_mosaic(out, tmp_path / "camera.json", tmp_path / "eo.csv", crs, "adj")
    dx, dy, peak = _mosaic_shift(mosaic, d["tex"])
    assert math.hypot(dx, dy) < 0.1 and peak > 0.9, (dx, dy, peak)
    # the control: the same chain on the direct-georeferencing EO
    dg = _ortho_mosaic(out, out / "camera.json", out / "eo_dg.csv", crs, "dg")
    gx, gy, gpeak = _mosaic_shift(dg, d["tex"])
    assert math.hypot(gx, gy) * GSD > 1.0 or gpeak < 0.5, (gx, gy, gpeak)
    print(
        f"\nfisheye block: {tie['TRACK_COUNT']} tracks, sigma0 {adj['SIGMA0']:.3f}, EO within "
        f"{max(np.abs(dpos).max(), np.abs(dang).max()):.2f} sigma, check points within "
        f"{worst_check:.2f} sigma; mosaic ({dx:.3f}, {dy:.3f}) cells from the texture (peak "
        f"{peak:.3f}); from the direct-georeferencing EO ({gx:.1f}, {gy:.1f}) cells, peak "
        f"{gpeak:.2f}"
    )
