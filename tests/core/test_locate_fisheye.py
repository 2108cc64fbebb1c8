"""Control points located in fisheye images from their chips, against simulated truth.

Truth: a textured horizontal ground (core/simulation/control_chips.py) seen by a 1 mm fisheye
of each projection (400 x 300 px of 5 um, Brown k1 -0.02: up to 57 degrees off the axis at
the image's side), 15 m up, the point 5, 35 and 50 degrees off the axis in three images
(kappa 10, -5, 182 degrees), rendered through the fisheye's own rays (2 x 2 rays a pixel,
1 grey value of noise); the chip at 7.5 cm (the nadir GSD), 1 grey value of noise.

Tolerances: within 0.15 px of the true point's projection. The affine of least-squares
matching cannot follow the fisheye's curved image of the ground over the template (0.06-0.24
px off the affine 10 chip pixels from the point): the mean of that curvature over the template
is taken off the match (core/photo/control_location.py, _curvature_shift), which leaves
0.002-0.017 px noise-free (0.01-0.05 px without it). With the image noise the point 50
degrees off the axis, where the ground is seen at 2-3 times the nadir GSD and its contrast
is low, lands up to 0.112 px off (measured: 0.014-0.039 px at 5 and 35 degrees, 0.017-0.112 px
at 50), several times LSM's own sigma there (0.006-0.010 px). The perspective formula on the
same camera predicts the point tens of pixels off. Transfer (image to image, when the chip
fails in an image): the master-to-image map curves in the same way and gets the same correction
(_transfer_curvature_shift): 0.02-0.04 px from the truth, 0.16-0.26 px without it.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pyproj
import pytest
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.collinearity import project_with_status
from lidarphoto.core.geometry.distortion import distortion_from_dict
from lidarphoto.core.geometry.frames import LocalFrame, MappingFrame
from lidarphoto.core.geometry.projection import FISHEYE_PROJECTIONS, theta_from_radius
from lidarphoto.core.geometry.rotations import matrix_to_opk
from lidarphoto.core.photo.control_location import locate_control_points
from lidarphoto.core.photo.orientation import ExteriorOrientationTable, eo_map_to_local
from lidarphoto.core.simulation.control_chips import GroundTexture, make_chip, render_plane_image

pytest.importorskip("cv2")

CRS = pyproj.CRS("EPSG:25832").to_wkt()
POINT = np.array([500000.0, 5500000.0, 100.0])
HEIGHT = 15.0
OFF_AXIS_DEG = (5.0, 35.0, 50.0)
LENS = distortion_from_dict({"model": "brown_conrady", "k1": -0.02})


def _camera(projection: str) -> Camera:
    return Camera("fisheye", 1.0, 0.005, 400, 300, distortion=LENS, projection=projection)


def _reader(images):
    def read(iid, c0, r0, w, h):
        img = images[iid]
        out = np.full((h, w), np.nan)
        cs, rs = max(c0, 0), max(r0, 0)
        ce, re = min(c0 + w, img.shape[1]), min(r0 + h, img.shape[0])
        if ce > cs and re > rs:
            out[rs - r0 : re - r0, cs - c0 : ce - c0] = img[rs:re, cs:ce]
        return out

    return read


def _scene(projection: str):
    cam = _camera(projection)
    tex = GroundTexture(origin=(POINT[0], POINT[1]), seed=3, n=40, fmin=0.1, fmax=1.2)
    # image centres placed so that the point is the given angle off the (nearly nadir) axis
    dx = [-1.0, HEIGHT * math.tan(math.radians(35.0)), -HEIGHT * math.tan(math.radians(50.0))]
    xyz = np.column_stack([POINT[0] + np.array(dx), POINT[1] + np.array([1.0, -2.0, 1.5]),
                           np.full(3, POINT[2] + HEIGHT)])  # fmt: skip
    opk = np.deg2rad([[0.5, -0.3, 10.0], [-0.4, 0.8, -5.0], [0.2, 0.1, 182.0]])
    images = {f"I{k}": render_plane_image(tex, POINT[2], cam, xyz[k], opk[k], CRS,
                                          supersample=2, noise=1.0, seed=k)
              for k in range(3)}  # fmt: skip
    eo = ExteriorOrientationTable(tuple(images), np.zeros(3), ("",) * 3, xyz, opk, CRS)
    chip = make_chip("GCP1", tex, POINT, 0.075, noise=1.0)
    return cam, images, eo, chip


def _truth(eo, cam):
    local = LocalFrame.at_map_point(MappingFrame.from_user_input(CRS), POINT)
    c, m = eo_map_to_local(eo.xyz, eo.opk, local)
    om, ph, ka = matrix_to_opk(m)
    p = local.map_to_enu(POINT[None])
    return {i: project_with_status(p, np.r_[c[k], om[k], ph[k], ka[k]], cam)[0][0]
            for k, i in enumerate(eo.image_id)}  # fmt: skip


@pytest.fixture(scope="module")
def scenes():
    return {p: _scene(p) for p in FISHEYE_PROJECTIONS}


@pytest.mark.parametrize("projection", FISHEYE_PROJECTIONS)
def test_fisheye_control_located_at_the_true_point(scenes, projection):
    """Measured: 0.014-0.112 px from the truth (equisolid 50 degrees the largest), LSM
    sigmas 0.006-0.017 px."""
    cam, images, eo, chip = scenes[projection]
    truth = _truth(eo, cam)
    res = locate_control_points([chip], eo, cam, _reader(images))
    assert [p.status for p in res.pairs] == ["ok"] * 3, [p.reason for p in res.pairs]
    for p, angle in zip(res.pairs, OFF_AXIS_DEG):
        t = truth[p.image_id]
        r = np.hypot(*cam.ideal_from_pixel(t[None])[0])
        assert abs(np.degrees(theta_from_radius(r, projection)) - angle) < 1.0
        # the prediction with the true EO is the true point's projection
        assert math.hypot(p.predicted_col - t[0], p.predicted_row - t[1]) < 1e-6
        err = math.hypot(p.col - t[0], p.row - t[1])
        assert err < 0.15, (p.image_id, err)
        assert 0 < p.sigma_col < 0.05 and p.lsm_correlation > 0.9
    assert res.observations.type == ("control",) * 3


@pytest.mark.parametrize("projection", FISHEYE_PROJECTIONS)
def test_the_perspective_formula_predicts_fisheye_points_far_off(scenes, projection):
    """The same camera declared perspective: the point 35 degrees off the axis is predicted
    tens of pixels from where it is (r = f tan theta against the fisheye's r), and the one
    50 degrees off falls outside the perspective image or as far off."""
    cam, images, eo, chip = scenes[projection]
    truth = _truth(eo, cam)
    persp = dataclasses.replace(cam, projection="perspective")
    res = locate_control_points([chip], eo, persp, _reader(images))
    by_image = {p.image_id: p for p in res.pairs}
    p = by_image["I1"]
    assert math.hypot(p.predicted_col - truth["I1"][0], p.predicted_row - truth["I1"][1]) > 10.0
    if "I2" in by_image:
        q = by_image["I2"]
        assert math.hypot(q.predicted_col - truth["I2"][0], q.predicted_row - truth["I2"][1]) > 30


def test_the_job_locates_control_in_fisheye_images(scenes, tmp_path):
    """locatecontrolpoints on files with an equisolid camera JSON: three observations within
    0.15 px of the truth."""
    from lidarphoto.core.io.camera import write_camera_json
    from lidarphoto.core.io.observations import read_observations_csv
    from lidarphoto.core.io.orientation import write_eo_csv
    from lidarphoto.core.io.raster_write import write_geotiff, write_rgb_tiff
    from lidarphoto.core.jobs import locate_control_points as job
    from lidarphoto.core.jobs.runner import run_job

    cam, images, eo, chip = scenes["equisolid"]
    (tmp_path / "img").mkdir()
    (tmp_path / "chips").mkdir()
    for iid, img in images.items():
        u8 = np.clip(np.round(img), 0, 255).astype(np.uint8)
        write_rgb_tiff(tmp_path / "img" / f"{iid}.tif", np.dstack([u8] * 3))
    write_geotiff(tmp_path / "chips" / "GCP1.tif", chip.grey.astype(np.float32),
                  chip.geotransform, -9999.0, "EPSG:25832")  # fmt: skip
    x, y, z = POINT
    (tmp_path / "control.csv").write_text(f"point_id,X,Y,Z\nGCP1,{x},{y},{z}\n")
    write_camera_json(tmp_path / "camera.json", cam)
    write_eo_csv(tmp_path / "eo.csv", eo)
    v = {"CHIPS": [str(tmp_path / "chips")], "CONTROL_POINTS": str(tmp_path / "control.csv"),
         "CAMERA": str(tmp_path / "camera.json"), "EO": str(tmp_path / "eo.csv"),
         "IMAGES": [str(tmp_path / "img")], "CRS": "EPSG:25832",
         "OUTPUT": str(tmp_path / "obs.csv")}  # fmt: skip
    result = run_job(job, v)
    assert result.results["LOCATED"] == 3
    obs = read_observations_csv(tmp_path / "obs.csv")
    truth = _truth(eo, cam)
    for iid, px in zip(obs.image_id, obs.pixels):
        assert np.hypot(*(px - truth[iid])) < 0.15, iid


#: the transfer's template (chip pixels; the master image's patch has as many) per projection:
#: 41 px, or 35 where the stereographic transfer's least-squares patch leaves its window at 41
#: (rejected with and without the correction)
TRANSFER_TEMPLATE = {"equidistant": 41, "equisolid": 41, "orthographic": 41, "stereographic": 35}


def _transferred(scenes, projection, monkeypatch, corrected: bool):
    """Locate with an EO whose centres are all 1.2 m / 0.8 m off (the chip found 10-25 px from
    its prediction in I0 and I1, whose sigmas are 1 m and 10 mrad) and image I2 (50 degrees
    off the axis) given sigmas so small that its search is the 5 px minimum: its chip match
    fails there, and it is transferred from the best of the other two (the master's offset
    carried over). ``corrected`` False: the transfer's curvature correction replaced by zero."""
    from lidarphoto.core.photo import control_location
    from lidarphoto.core.photo.matching_options import LocateOptions, TextureOptions

    cam, images, eo, chip = scenes[projection]
    if not corrected:
        monkeypatch.setattr(
            control_location, "_transfer_curvature_shift", lambda *a, **k: np.zeros(2)
        )
    wrong = dataclasses.replace(eo, xyz=eo.xyz + np.array([1.2, -0.8, 0.0]))
    sigmas = np.array([[1.0, 1.0, 1.0, 0.01, 0.01, 0.01]] * 3)
    sigmas[2] = 1e-5
    size = TRANSFER_TEMPLATE[projection]
    opt = LocateOptions(texture=TextureOptions(min_size=size))
    res = locate_control_points([chip], wrong, cam, _reader(images), sigmas, opt)
    return {p.image_id: p for p in res.pairs}, _truth(eo, cam), size


@pytest.mark.parametrize("projection", FISHEYE_PROJECTIONS)
def test_fisheye_transfer_corrected_for_the_curved_image(scenes, projection, monkeypatch):
    """A transferred match (master image -> image 50 degrees off the axis) through a fisheye:
    the master-to-image map curves over the patch as the chip-to-image one does, and the
    same correction (the mean over the patch of the exact map minus the start affine) puts
    it within the chip match's 0.15 px of the true point, where without it it is more than
    0.15 px off. Measured: 0.02-0.04 px corrected, 0.16-0.26 px without (noise 1 grey value;
    the chip matches of I0 and I1 0.03-0.11 px)."""
    pairs, truth, size = _transferred(scenes, projection, monkeypatch, corrected=True)
    for iid in ("I0", "I1"):
        p = pairs[iid]
        assert p.status == "ok" and p.source == "chip", p.reason
        assert p.template_px == size
        assert math.hypot(p.col - truth[iid][0], p.row - truth[iid][1]) < 0.15
    t = pairs["I2"]
    assert t.status == "ok" and t.source.startswith("transfer from I"), t.reason
    # the chip could not find it: the EO's error put it outside I2's 5 px search
    assert math.hypot(t.predicted_col - truth["I2"][0], t.predicted_row - truth["I2"][1]) > 5
    err = math.hypot(t.col - truth["I2"][0], t.row - truth["I2"][1])
    assert err < 0.15, err
    assert 0 < t.sigma_col < 0.05
    monkeypatch.undo()
    plain, _truth2, _size = _transferred(scenes, projection, monkeypatch, corrected=False)
    u = plain["I2"]
    assert u.source == t.source
    miss = math.hypot(u.col - truth["I2"][0], u.row - truth["I2"][1])
    assert miss > 0.15 and miss > 3 * err, (miss, err)
    print(f"\n{projection}: transfer {t.source}, {size} px: {err:.3f} px from the truth, "
          f"{miss:.3f} px without the correction")  # fmt: skip
