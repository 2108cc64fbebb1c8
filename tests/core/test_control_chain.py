"""The whole control chain on a synthetic block: ground photos -> control chips
(``makecontrolchips``) -> control located in the aerial images (``locatecontrolpoints``) ->
bundle adjustment (``bundleadjustment``), against the truth.

One textured ground (:class:`core.simulation.control_chips.GroundTexture`, map coordinates)
is seen by everything: the ground photos of each control point (with the plate, and without
it from a slightly moved camera: :func:`core.simulation.ground_photo.render_ground_photo` on
the texture's patch around the point, :func:`core.simulation.control_chips.ground_patch`) and
six aerial images (2 strips x 3, GSD 8 cm) rendered with known EO
(:func:`core.simulation.control_chips.render_plane_image`). The chips come only from the
ground photos (plate detection, resection, SIFT registration, rectification), never from the
texture itself.

Truth: the projections of the surveyed points with the true EO. Tie and check points are
their true projections plus Gaussian noise of ``NOISE_PX``; the reference for the bundle is
the same block with the control observed at its true projections plus the same noise
("manually placed perfect observations"), over several noise draws.
"""

from __future__ import annotations

import csv
import math
import time

import numpy as np
import pyproj
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.geometry.camera import Camera, camera_from_dict
from lidarphoto.core.geometry.collinearity import project_with_status
from lidarphoto.core.geometry.frames import LocalFrame, MappingFrame
from lidarphoto.core.geometry.rotations import matrix_to_opk
from lidarphoto.core.io.camera import write_camera_json
from lidarphoto.core.io.observations import read_observations_csv, write_observations_csv
from lidarphoto.core.io.orientation import write_eo_csv, write_eo_csv_with_sigmas
from lidarphoto.core.io.raster_write import GeoTiffWriter
from lidarphoto.core.jobs import bundle_adjustment, locate_control_points, make_control_chips
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.photo.control_plate import PlateGeometry, photo_azimuth
from lidarphoto.core.photo.observations import ImageObservations
from lidarphoto.core.photo.orientation import ExteriorOrientationTable, eo_map_to_local
from lidarphoto.core.simulation.control_chips import (
    GroundTexture,
    ground_patch,
    render_plane_image,
)
from lidarphoto.core.simulation.ground_photo import render_ground_photo

cv2 = pytest.importorskip("cv2")

EPSG = "EPSG:25832"
CRS = pyproj.CRS(EPSG).to_wkt()
ORIGIN = np.array([500_000.0, 5_500_000.0])
Z0 = 100.0
GSD = 0.08
CHIP = 31
#: Pixel noise of the tie and check observations and of the reference control, pixels.
NOISE_PX = 0.25
#: Aerial camera: 10 mm, 10 um pixels (GSD 8 cm from 80 m).
AERIAL = Camera("aerial", focal_mm=10.0, pixel_size_mm=0.01, width_px=400, height_px=300)
H = GSD * AERIAL.focal_mm / AERIAL.pixel_size_mm
#: The ground camera on a 3.3 m pole (a Brown lens the chip maker removes).
GROUND = camera_from_dict({"name": "ground", "focal_mm": 2.0, "pixel_size_mm": 0.005,
                           "width_px": 640, "height_px": 480,
                           "distortion": {"model": "brown_conrady", "k1": 4e-3}})  # fmt: skip
PLATE = PlateGeometry(outer_m=0.5, inner_m=0.25, height_m=0.0, azimuth_deg=20.0)
#: Control (corners and centre of the common area) and check points, metres from ORIGIN.
CONTROL = [(-12.0, -8.0), (12.0, -8.0), (-12.0, 8.0), (12.0, 8.0), (0.5, 0.5)]
CHECK = [(-6.0, -4.0), (6.0, 4.0), (-6.0, 4.5), (6.5, -4.0), (0.0, -7.0), (0.0, 7.5)]
#: The ground: waves of 0.3-6 cycles per metre (down to 2 aerial pixels, 33 ground-photo
#: pixels: SIFT finds a few hundred matches), grey 125 +- 22 (the plate's black, 15, and
#: white, 240, stay apart from the ground).
TEXTURE = GroundTexture(origin=tuple(ORIGIN), seed=3, n=80, fmin=0.3, fmax=6.0, mean=125.0,
                        contrast=22.0)  # fmt: skip
#: Noise draws of the tie, check and reference control observations.
DRAWS = 8


def _project(eo: ExteriorOrientationTable, xyz: np.ndarray) -> np.ndarray:
    """(images, points, 2) true pixels (corner convention), NaN outside the frame."""
    local = LocalFrame.at_map_point(MappingFrame.from_user_input(CRS), xyz.mean(axis=0))
    c, m = eo_map_to_local(eo.xyz, eo.opk, local)
    om, ph, ka = matrix_to_opk(m)
    p = local.map_to_enu(xyz)
    out = np.full((len(eo), len(xyz), 2), np.nan)
    for k in range(len(eo)):
        px, front, conv = project_with_status(p, np.r_[c[k], om[k], ph[k], ka[k]], AERIAL)
        ok = front & conv & AERIAL.in_frame(np.nan_to_num(px, nan=-1.0), margin_px=25.0)
        out[k, ok] = px[ok]
    return out


def _write_grey(path, img: np.ndarray) -> None:
    u8 = np.clip(np.rint(img), 0, 255).astype(np.uint8)
    with GeoTiffWriter(str(path), u8.shape[1], u8.shape[0], 1, np.uint8, None, None) as w:
        w.write(u8)


def _observations(eo, ids, xyz, rng, noise=NOISE_PX) -> ImageObservations:
    px = _project(eo, xyz)
    seen = [(k, j) for k in range(len(eo)) for j in range(len(ids)) if np.isfinite(px[k, j, 0])]
    rows = [(eo.image_id[k], ids[j], *(px[k, j] + rng.normal(0.0, noise, 2))) for k, j in seen]
    img, pid, c, r = zip(*rows)
    n = len(rows)
    return ImageObservations.from_arrays(img, pid, np.column_stack([c, r]), np.full(n, NOISE_PX),
                                         ["tie"] * n, [""] * n)  # fmt: skip


def _merge(*parts: ImageObservations) -> ImageObservations:
    """The rows of ``parts`` with their own types (the located control: ``control``)."""
    img = [i for p in parts for i in p.image_id]
    pid = [i for p in parts for i in p.point_id]
    px = np.vstack([p.pixels for p in parts])
    sig = np.concatenate([p.sigma_px for p in parts])
    kinds = [t for p in parts for t in p.type]
    return ImageObservations.from_arrays(img, pid, px, sig, kinds, [""] * len(img))


@pytest.fixture(scope="module")
def chain(tmp_path_factory):
    d = tmp_path_factory.mktemp("chain")
    rng = np.random.default_rng(18)
    tex = TEXTURE
    # --- the block: 2 strips x 3 images, 60 % forward and 30 % side overlap, flown east
    base, strip = 0.4 * AERIAL.width_px * GSD, 0.7 * AERIAL.height_px * GSD
    xyz, opk, ids = [], [], []
    for s, dy in enumerate((-strip / 2, strip / 2)):
        for k, dx in enumerate((-base, 0.0, base)):
            xyz.append([ORIGIN[0] + dx + rng.normal(0, 0.3), ORIGIN[1] + dy + rng.normal(0, 0.3),
                        Z0 + H + rng.normal(0, 0.5)])  # fmt: skip
            opk.append(np.radians([rng.normal(0, 1.0), rng.normal(0, 1.0),
                                   rng.normal(0, 2.0) + 180.0 * s]))  # fmt: skip
            ids.append(f"S{s}_{k}")
    eo = ExteriorOrientationTable(tuple(ids), np.zeros(6), ("",) * 6, np.array(xyz),
                                  np.array(opk), CRS)  # fmt: skip
    (d / "img").mkdir()
    for k, iid in enumerate(ids):
        img = render_plane_image(tex, Z0, AERIAL, xyz[k], opk[k], CRS, supersample=2,
                                 noise=1.0, seed=10 + k)  # fmt: skip
        _write_grey(d / "img" / f"{iid}.tif", img)
    # the EO as direct georeferencing gives it: 0.2 m and 0.02 degrees off, with sigmas
    approx = ExteriorOrientationTable(
        eo.image_id, eo.time, eo.group, eo.xyz + rng.normal(0, 0.2, (6, 3)),
        eo.opk + np.radians(rng.normal(0, 0.02, (6, 3))), CRS)  # fmt: skip
    sig = np.tile([0.3, 0.3, 0.3, *np.radians([0.05] * 3)], (6, 1))
    write_eo_csv_with_sigmas(d / "eo_sigmas.csv", approx, sig)
    write_eo_csv(d / "eo_approx.csv", approx)
    write_camera_json(d / "aerial.json", AERIAL)
    write_camera_json(d / "ground.json", GROUND)
    # --- ground points: control and check on the plane Z = Z0
    ctrl = np.array([[ORIGIN[0] + x, ORIGIN[1] + y, Z0] for x, y in CONTROL])
    chk = np.array([[ORIGIN[0] + x, ORIGIN[1] + y, Z0] for x, y in CHECK])
    ctrl_ids = [f"GCP{k + 1}" for k in range(len(ctrl))]
    chk_ids = [f"CHK{k + 1}" for k in range(len(chk))]
    with open(d / "ground.csv", "w") as fh:
        fh.write("point_id,X,Y,Z,sx,sy,sz,role\n")
        for pid, p in zip(ctrl_ids, ctrl):
            fh.write(f"{pid},{p[0]:.4f},{p[1]:.4f},{p[2]:.4f},0.005,0.005,0.005,control\n")
        for pid, p in zip(chk_ids, chk):
            fh.write(f"{pid},{p[0]:.4f},{p[1]:.4f},{p[2]:.4f},0.005,0.005,0.005,check\n")
    # --- ground photos of each control point: plate photo and the plate-free one
    (d / "photos").mkdir()
    table = ["point_id,plate_photo,free_photo,photo_azimuth_deg"]
    for k, (pid, p) in enumerate(zip(ctrl_ids, ctrl)):
        patch = ground_patch(tex, p[:2], 4.5, 0.01)
        kappa = 25.0 + 60.0 * k
        eo_plate = np.array([rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), 3.3,
                             *np.radians([rng.normal(0, 1), rng.normal(0, 1), kappa])])  # fmt: skip
        eo_free = eo_plate + np.array([0.004, -0.003, 0.002, *np.radians([1.0, 0.5, 4.0])])
        plate = render_ground_photo(patch, GROUND, eo_plate, PLATE, supersample=1, seed=40 + k)
        free = render_ground_photo(patch, GROUND, eo_free, None, supersample=1, seed=60 + k)
        _write_grey(d / "photos" / f"{pid}_plate.tif", plate)
        _write_grey(d / "photos" / f"{pid}_free.tif", free)
        table.append(f"{pid},photos/{pid}_plate.tif,photos/{pid}_free.tif,"
                     f"{photo_azimuth(eo_plate):.3f}")  # fmt: skip
    (d / "photos.csv").write_text("\n".join(table) + "\n")
    # --- ties on a 2 m grid (each seen in two or more images) and the check points
    g = np.arange(-20.0, 20.01, 2.0)
    gx, gy = np.meshgrid(g + 0.3, g * 0.8 + 0.7)
    tie_xyz = np.column_stack([ORIGIN[0] + gx.ravel(), ORIGIN[1] + gy.ravel(),
                               np.full(gx.size, Z0)])  # fmt: skip
    tie_xyz = tie_xyz[np.isfinite(_project(eo, tie_xyz)[:, :, 0]).sum(axis=0) >= 2]
    return {"dir": d, "eo": eo, "ctrl": ctrl, "ctrl_ids": ctrl_ids, "tie_xyz": tie_xyz,
            "tie_ids": [f"T{k}" for k in range(len(tie_xyz))], "chk": chk, "chk_ids": chk_ids}


def test_ground_patch_is_the_texture():
    """The ground photos' patch reads the aerial images' texture (bilinear error < 0.3 grey)."""
    tex = TEXTURE
    p = ORIGIN + [3.21, -4.56]
    patch = ground_patch(tex, p, 2.0, 0.01)
    xy = np.random.default_rng(0).uniform(-0.9, 0.9, (2000, 2))
    diff = patch.sample(xy[:, 0], xy[:, 1]) - tex.at(p[0] + xy[:, 0], p[1] + xy[:, 1])
    assert np.abs(diff).max() < 0.3, np.abs(diff).max()


def _bundle(d, obs: ImageObservations, tag: str) -> dict:
    write_observations_csv(d / f"{tag}_obs.csv", obs)
    res = run_job(bundle_adjustment, {
        "CAMERA": str(d / "aerial.json"), "OBSERVATIONS": str(d / f"{tag}_obs.csv"),
        "GROUND_POINTS": str(d / "ground.csv"), "EO": str(d / "eo_approx.csv"), "CRS": EPSG,
        "AP_MODEL": "none", "ESTIMATE_INTERIOR": False, "ROBUST": "none", "SNOOPING": False,
        "OUTPUT_EO": str(d / f"{tag}_eo.csv"), "OUTPUT_CHECK_CSV": str(d / f"{tag}_check.csv"),
    })  # fmt: skip
    with open(d / f"{tag}_check.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    return {"rms": res.results["CHECK_RMS"], "sigma0": res.results["SIGMA0"], "rows": rows}


@pytest.fixture(scope="module")
def located(chain):
    d = chain["dir"]
    t0 = time.perf_counter()
    chips = run_job(make_control_chips, {
        "POINTS": str(d / "ground.csv"), "CRS": EPSG, "CAMERA": str(d / "ground.json"),
        "PHOTO_TABLE": str(d / "photos.csv"), "OUTER_SIDE": PLATE.outer_m,
        "INNER_SIDE": PLATE.inner_m, "PLATE_AZIMUTH": PLATE.azimuth_deg, "GSD": GSD,
        "CHIP_SIZE": CHIP, "OUTPUT_FOLDER": str(d / "chips"),
    })  # fmt: skip
    t1 = time.perf_counter()
    run_job(locate_control_points, {
        "CHIPS": [str(d / "chips")], "CONTROL_POINTS": str(d / "ground.csv"),
        "CAMERA": str(d / "aerial.json"), "EO": str(d / "eo_sigmas.csv"),
        "IMAGES": [str(d / "img")], "CRS": EPSG, "OUTPUT": str(d / "located.csv"),
        "OUTPUT_REPORT": str(d / "located_report.csv"),
    })  # fmt: skip
    t2 = time.perf_counter()
    print(f"makecontrolchips {t1 - t0:.1f} s, locatecontrolpoints {t2 - t1:.1f} s")
    return chips, read_observations_csv(d / "located.csv")


def test_chips_are_made_for_every_control_point(chain, located):
    chips, _ = located
    rows = {r["point_id"]: r for r in chips.data}
    for pid in chain["ctrl_ids"]:
        assert rows[pid]["status"] == "ok", (pid, rows[pid]["reason"])
        assert rows[pid]["source"] == "free" and rows[pid]["corners_found"] == 8
    assert chips.results["CHIP_COUNT"] == len(chain["ctrl_ids"])


def test_located_control_within_a_tenth_of_a_pixel(chain, located):
    """Every control point located in every image that sees it, within 0.1 px of its true
    projection."""
    _, obs = located
    eo, ctrl, ids = chain["eo"], chain["ctrl"], chain["ctrl_ids"]
    truth = _project(eo, ctrl)
    expected = {(eo.image_id[k], ids[j]) for k in range(len(eo)) for j in range(len(ids))
                if np.isfinite(truth[k, j, 0])}  # fmt: skip
    got = set(zip(obs.image_id, obs.point_id))
    assert got >= expected, sorted(expected - got)
    assert set(obs.type) == {"control"} and set(obs.target_id) == {""}
    err = np.array([np.hypot(*(px - truth[eo.image_id.index(i), ids.index(p)]))
                    for i, p, px in zip(obs.image_id, obs.point_id, obs.pixels)
                    if (i, p) in expected])  # fmt: skip
    print(f"located control: {len(err)} observations, error RMS {np.sqrt((err**2).mean()):.3f}"
          f" px, max {err.max():.3f} px; {np.round(err, 3).tolist()}")  # fmt: skip
    assert err.max() < 0.1, err


def test_bundle_with_located_control_reaches_the_perfect_observations(chain, located):
    """For each of DRAWS noise draws of the ties and check observations (true projections +
    NOISE_PX), the block is adjusted twice: with the located control, and with the control at
    its true projections plus the same noise (its own draw). The check-point RMSE (3D, over
    the draws) with the located control is within 10 % of (or below) the reference."""
    _, obs = located
    d, eo = chain["dir"], chain["eo"]
    rng = np.random.default_rng(2014)
    auto, ref = [], []
    for k in range(DRAWS):
        base = (_observations(eo, chain["tie_ids"], chain["tie_xyz"], rng),
                _observations(eo, chain["chk_ids"], chain["chk"], rng))  # fmt: skip
        perfect = _observations(eo, chain["ctrl_ids"], chain["ctrl"], rng)
        a = _bundle(d, _merge(*base, obs), f"located{k}")
        assert len(a["rows"]) == len(CHECK)
        auto.append(a["rms"])
        ref.append(_bundle(d, _merge(*base, perfect), f"perfect{k}")["rms"])
    rms_auto = math.sqrt(np.mean(np.square(auto)))
    rms_ref = math.sqrt(np.mean(np.square(ref)))
    print(f"check RMSE 3D over {DRAWS} draws: located {rms_auto:.4f} m, perfect + "
          f"{NOISE_PX} px {rms_ref:.4f} m, ratio {rms_auto / rms_ref:.3f}; per draw "
          f"{np.round(auto, 4).tolist()} / {np.round(ref, 4).tolist()}")  # fmt: skip
    assert rms_auto <= 1.10 * rms_ref


def test_located_control_typed_tie_as_earlier_versions_wrote_it_gives_the_same_block(
    chain, located
):
    """Back-compatibility: the located control re-typed ``tie`` (files of earlier versions)
    joins the ground points by point_id as before: the same adjustment as type ``control``."""
    _, obs = located
    d, eo = chain["dir"], chain["eo"]
    rng = np.random.default_rng(7)
    base = (_observations(eo, chain["tie_ids"], chain["tie_xyz"], rng),
            _observations(eo, chain["chk_ids"], chain["chk"], rng))  # fmt: skip
    as_tie = ImageObservations.from_arrays(obs.image_id, obs.point_id, obs.pixels, obs.sigma_px,
                                           ["tie"] * len(obs), [""] * len(obs))  # fmt: skip
    new = _bundle(d, _merge(*base, obs), "compat_control")
    old = _bundle(d, _merge(*base, as_tie), "compat_tie")
    assert new["rms"] == pytest.approx(old["rms"], rel=1e-9)
    assert new["sigma0"] == pytest.approx(old["sigma0"], rel=1e-9)


def test_control_row_naming_no_ground_point_is_refused_with_its_row(chain, located):
    """Unlike a tie row, a control row never becomes a free tie point."""
    _, obs = located
    d = chain["dir"]
    rng = np.random.default_rng(8)
    base = _observations(chain["eo"], chain["tie_ids"], chain["tie_xyz"], rng)
    pid = list(obs.point_id)
    pid[1] = "GCP_MISSING"
    bad = ImageObservations.from_arrays(obs.image_id, pid, obs.pixels, obs.sigma_px, obs.type,
                                        obs.target_id)  # fmt: skip
    with pytest.raises(InputError) as err:
        _bundle(d, _merge(base, bad), "missing")
    row = len(base) + 1 + 2  # the header is row 1
    assert "GCP_MISSING" in str(err.value) and f"row {row}" in str(err.value)
    assert "missing_obs.csv" in str(err.value)
