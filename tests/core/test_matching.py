"""NCC template search, least-squares matching (Gruen 1985) and control-point location against
truth: synthetic pairs with a known affine + radiometric change + noise (bias, Monte Carlo
sigma), rendered aerial images of a textured plane with known EO (located control within
0.1 px), the job's files, and the per-point reasons for bad input."""

from __future__ import annotations

import csv
import math

import numpy as np
import pyproj
import pytest
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.collinearity import project_with_status
from lidarphoto.core.geometry.frames import LocalFrame, MappingFrame
from lidarphoto.core.geometry.rotations import matrix_to_opk
from lidarphoto.core.photo.control_location import LocateOptions, locate_control_points
from lidarphoto.core.photo.least_squares_matching import (
    LsmOptions,
    affine_start,
    lsm_batch,
    lsm_in_image,
)
from lidarphoto.core.photo.orientation import ExteriorOrientationTable, eo_map_to_local
from lidarphoto.core.photo.template_matching import choose_template_size, ncc_search
from lidarphoto.core.simulation.control_chips import (
    GroundTexture,
    make_chip,
    render_plane_image,
)

cv2 = pytest.importorskip("cv2")


def waves(x, y, seed, fmax=0.25, n=40):
    """Analytic texture (grey values) at array coordinates x, y: exact at any sub-pixel."""
    rng = np.random.default_rng(seed)
    f = rng.uniform(0.03, fmax, n)
    th = rng.uniform(0, np.pi, n)
    ph = rng.uniform(0, 2 * np.pi, n)
    amp = 1.0 / (1 + (f / 0.1) ** 2)
    out = np.zeros(np.broadcast(x, y).shape)
    for k in range(n):
        out += amp[k] * np.cos(2 * np.pi * f[k] * (np.cos(th[k]) * x + np.sin(th[k]) * y) + ph[k])
    return 100 + 40 * out


M, S = 21, 41  # template and search sides
AFFINE = np.array([[1.05, 0.03], [-0.02, 0.97]])
SHIFT = np.array([0.37, -0.21])
GAIN, OFFSET = 0.8, 10.0


def _pair(seed, k, noise, rng):
    """k noisy copies of one template/search pair: template pixel (x, y) sees the search
    image's texture at AFFINE (x, y) + SHIFT, through gain and offset."""
    yy, xx = np.mgrid[0:M, 0:M] - (M - 1) / 2
    u = AFFINE[0, 0] * xx + AFFINE[0, 1] * yy + SHIFT[0]
    v = AFFINE[1, 0] * xx + AFFINE[1, 1] * yy + SHIFT[1]
    yy2, xx2 = np.mgrid[0:S, 0:S] - (S - 1) / 2
    f0 = GAIN * waves(u, v, seed) + OFFSET
    g0 = waves(xx2, yy2, seed)
    return f0 + rng.normal(0, noise, (k, M, M)), g0 + rng.normal(0, noise, (k, S, S))


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_lsm_bias_and_sigma_against_monte_carlo(seed):
    """500 noise realisations (sigma 2 grey values in both images) of one pair: the mean
    position is within 0.01 px of the truth, the reported sigma within 20 % of the spread."""
    rng = np.random.default_rng(100 + seed)
    k = 500
    f, g = _pair(seed, k, 2.0, rng)
    centre = (S - 1) / 2
    res = lsm_batch(f, g, affine_start(np.full((k, 2), centre)))
    assert res.ok.all(), set(res.reasons())
    err = res.position - (centre + SHIFT)
    assert np.all(np.abs(err.mean(axis=0)) < 0.01), err.mean(axis=0)
    mc = err.std(axis=0)
    reported = np.sqrt((res.sigma_px**2).mean(axis=0))
    assert np.all(np.abs(reported / mc - 1) < 0.2), (reported, mc)
    np.testing.assert_allclose(res.affine[:, :, 1:].mean(axis=0), AFFINE, atol=0.005)
    # f = r0 + r1 g: r1 = GAIN, r0 = OFFSET (the model's direction)
    np.testing.assert_allclose(res.radiometry.mean(axis=0), [OFFSET, GAIN], rtol=0.02, atol=0.5)


def test_numba_and_numpy_back_ends_agree():
    from lidarphoto.core.photo import least_squares_matching_numba as nb

    if not nb.AVAILABLE:
        pytest.skip("numba not installed")
    f, g = _pair(5, 20, 2.0, np.random.default_rng(1))
    c = (S - 1) / 2
    start = affine_start(np.full((20, 2), c) + np.random.default_rng(2).normal(0, 0.7, (20, 2)))
    a = lsm_batch(f, g, start, options=LsmOptions(backend="numba"))
    b = lsm_batch(f, g, start, options=LsmOptions(backend="numpy"))
    np.testing.assert_array_equal(a.status, b.status)
    np.testing.assert_allclose(a.affine, b.affine, atol=1e-9)
    np.testing.assert_allclose(a.sigma_px, b.sigma_px, rtol=1e-9)


def test_lsm_noise_free_within_the_interpolation_error():
    f, g = _pair(4, 1, 0.0, np.random.default_rng(0))
    centre = (S - 1) / 2
    res = lsm_batch(f, g, affine_start([[centre + 1.2, centre - 0.9]]))
    assert res.ok[0]
    np.testing.assert_allclose(res.position[0], centre + SHIFT, atol=0.01)  # bicubic


def test_lsm_rejections_name_the_reason():
    rng = np.random.default_rng(5)
    f, g = _pair(6, 1, 1.0, rng)
    c = (S - 1) / 2
    flat = np.full((1, M, M), 50.0)
    assert lsm_batch(flat, g, affine_start([[c, c]])).reasons() == ["no texture"]
    other = waves(*np.meshgrid(np.arange(S), np.arange(S)), seed=99)[None]
    r = lsm_batch(f, other, affine_start([[c, c]]))
    assert r.reasons()[0] in (
        "low correlation",
        "moved too far",
        "left the search window",
        "not converged",
    ), r.reasons()
    once = lsm_batch(f, g, affine_start([[c + 2, c]]), options=LsmOptions(max_iterations=1))
    assert once.reasons() == ["not converged"]
    tight = lsm_batch(f, g, affine_start([[c, c]]), options=LsmOptions(max_sigma_px=1e-5))
    assert tight.reasons() == ["sigma too large"]
    edge = lsm_batch(f, g, affine_start([[8.0, c]]))
    assert edge.reasons() == ["left the search window"]


def test_lsm_in_image_matches_many_points_of_one_image():
    img = waves(*np.meshgrid(np.arange(300.0), np.arange(200.0)), seed=7, fmax=0.15)
    pts = np.array([[50.3, 40.7], [150.0, 100.2], [250.8, 150.5]])
    yy, xx = np.mgrid[0:M, 0:M] - (M - 1) / 2
    tmpl = np.stack([waves(xx + p[0], yy + p[1], seed=7, fmax=0.15) for p in pts])
    res = lsm_in_image(tmpl, img, affine_start(np.round(pts)))
    assert res.ok.all()
    np.testing.assert_allclose(res.position, pts, atol=0.01)
    edge = lsm_in_image(tmpl[:1], img, affine_start([[3.0, 40.0]]))
    assert edge.reasons() == ["left the search window"]


def test_ncc_subpixel_within_a_tenth_and_the_template_rule():
    xx, yy = np.meshgrid(np.arange(80.0), np.arange(80.0))
    img = waves(xx, yy, seed=8, fmax=0.15)
    t = waves(np.arange(15.0)[None, :] + 30.4, np.arange(15.0)[:, None] + 20.7, seed=8, fmax=0.15)
    m = ncc_search(t, img)
    assert abs(m.col - 37.4) < 0.1 and abs(m.row - 27.7) < 0.1 and m.peak > 0.98
    # noise grows the template; a smooth texture needs more pixels than a rough one
    noise = np.random.default_rng(0).normal(0, 8.0, xx.shape)
    sizes = {(fm, nz): choose_template_size(waves(xx, yy, seed=9, fmax=fm) + nz * noise,
                                            (40, 40)).size
             for fm in (0.3, 0.05) for nz in (0, 1)}  # fmt: skip
    assert sizes[(0.3, 0)] == sizes[(0.05, 0)] == 15
    assert sizes[(0.05, 1)] > sizes[(0.3, 1)] > 15
    ramp = choose_template_size(xx * 2.0, (40, 40))
    assert ramp.reason == "edge only"
    assert choose_template_size(np.full((80, 80), 3.0), (40, 40)).reason == "no texture"


# ------------------------------------------------------------------ rendered aerial images
CRS = pyproj.CRS("EPSG:25832").to_wkt()
POINT = np.array([500000.0, 5500000.0, 100.0])
CAM = Camera("c", focal_mm=50.0, pixel_size_mm=0.01, width_px=240, height_px=180)


@pytest.fixture(scope="module")
def block():
    """Three images (GSD 0.1 m, kappa 10, -5 and 182 degrees, tilts < 1 degree) of a textured
    plane, noise 1 grey value, and the chip of the point (0.1 m, 1 grey value of noise)."""
    tex = GroundTexture(origin=(POINT[0], POINT[1]), seed=3, n=40)
    xyz = np.array([[POINT[0] - 3, POINT[1] + 2, 600.0], [POINT[0] + 4, POINT[1] - 1, 602.0],
                    [POINT[0] - 2, POINT[1] - 3, 598.0]])  # fmt: skip
    opk = np.deg2rad([[0.5, -0.3, 10.0], [-0.4, 0.8, -5.0], [0.2, 0.1, 182.0]])
    images = {f"I{k}": render_plane_image(tex, POINT[2], CAM, xyz[k], opk[k], CRS,
                                          supersample=2, noise=1.0, seed=k)
              for k in range(3)}  # fmt: skip
    eo = ExteriorOrientationTable(tuple(images), np.zeros(3), ("",) * 3, xyz, opk, CRS)
    chip = make_chip("GCP1", tex, POINT, 0.1, noise=1.0)
    return tex, images, eo, chip


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


def _truth(eo, xyz):
    local = LocalFrame.at_map_point(MappingFrame.from_user_input(CRS), xyz)
    c, m = eo_map_to_local(eo.xyz, eo.opk, local)
    om, ph, ka = matrix_to_opk(m)
    p = local.map_to_enu(np.asarray(xyz)[None])
    return {i: project_with_status(p, np.r_[c[k], om[k], ph[k], ka[k]], CAM)[0][0]
            for k, i in enumerate(eo.image_id)}  # fmt: skip


def test_located_control_within_a_tenth_of_a_pixel(block):
    _, images, eo, chip = block
    res = locate_control_points([chip], eo, CAM, _reader(images))
    truth = _truth(eo, POINT)
    assert [p.status for p in res.pairs] == ["ok"] * 3, [p.reason for p in res.pairs]
    for p in res.pairs:
        err = math.hypot(p.col - truth[p.image_id][0], p.row - truth[p.image_id][1])
        assert err < 0.1, (p.image_id, err)
        assert 0 < p.sigma_col < 0.05 and p.lsm_correlation > 0.9
    assert res.observations.type == ("control",) * 3
    assert res.observations.point_id == ("GCP1",) * 3


def test_eo_sigmas_set_the_search_window_and_a_wrong_eo_is_found(block):
    """The EO off by 0.8 m in X (8 px): found with sigmas of 0.5 m (3 sigma = 15 px window);
    with 0.05 m sigmas (1.5 px, raised to the 5 px minimum) it is not, and says why."""
    _, images, eo, chip = block
    from dataclasses import replace

    shifted = replace(eo, xyz=eo.xyz + [0.8, 0, 0])
    wide = np.tile([0.5, 0.5, 0.5, 1e-4, 1e-4, 1e-4], (3, 1))
    res = locate_control_points([chip], shifted, CAM, _reader(images), eo_sigmas=wide)
    truth = _truth(eo, POINT)
    for p in res.pairs:
        assert p.status == "ok", p.reason
        assert math.hypot(p.col - truth[p.image_id][0], p.row - truth[p.image_id][1]) < 0.1
        assert 14 < p.search_px[0] < 16
    narrow = locate_control_points([chip], shifted, CAM, _reader(images),
                                   eo_sigmas=wide / 10,
                                   options=LocateOptions(transfer=False))  # fmt: skip
    assert all(p.status == "rejected" for p in narrow.pairs)
    assert all(p.reason and p.search_px[0] == 5.0 for p in narrow.pairs)


def test_transfer_carries_the_master_offset_to_images_whose_chip_search_failed(block):
    """A common EO error (0.8 m in X: 8 px in every image, as a boresight error would give):
    I0's sigmas are wide (its chip match succeeds), I1 and I2 claim 0.05 m (5 px windows
    around a prediction 8 px off: the chip search fails); the transfer from I0 predicts with
    I0's offset and finds both within 0.1 px of the truth."""
    from dataclasses import replace

    _, images, eo, chip = block
    shifted = replace(eo, xyz=eo.xyz + [0.8, 0, 0])
    sig = np.tile([0.05, 0.05, 0.05, 1e-5, 1e-5, 1e-5], (3, 1))
    sig[0, :3] = 0.5
    res = locate_control_points([chip], shifted, CAM, _reader(images), eo_sigmas=sig)
    truth = _truth(eo, POINT)
    by_image = {p.image_id: p for p in res.pairs}
    assert by_image["I0"].source == "chip" and by_image["I0"].status == "ok"
    for iid in ("I1", "I2"):
        p = by_image[iid]
        assert (p.status, p.source) == ("ok", "transfer from I0"), p.reason
        assert math.hypot(p.col - truth[iid][0], p.row - truth[iid][1]) < 0.1
        assert p.sigma_col > by_image["I0"].sigma_col * 0.9  # the master's sigma is added
    off = locate_control_points([chip], shifted, CAM, _reader(images), eo_sigmas=sig,
                                options=LocateOptions(transfer=False))  # fmt: skip
    assert [p.status for p in off.pairs] == ["ok", "rejected", "rejected"]


def test_bad_chips_and_points_get_their_reasons(block):
    tex, images, eo, _ = block
    flat = make_chip("FLAT", None, POINT, 0.1)
    far = make_chip("FAR", tex, POINT + [500.0, 0, 0], 0.1)
    # the ground point that image I1 sees 4 px from its right border
    from lidarphoto.core.geometry.collinearity import image_rays

    local = LocalFrame.at_map_point(MappingFrame.from_user_input(CRS), POINT)
    c, m = eo_map_to_local(eo.xyz[1:2], eo.opk[1:2], local)
    om, ph, ka = matrix_to_opk(m)
    o, d = image_rays([[CAM.width_px - 4.0, 90.0]], np.r_[c[0], om[0], ph[0], ka[0]], CAM)
    z = local.map_to_enu(POINT[None])[0, 2]
    edge_xyz = local.enu_to_map(o + (z - o[:, 2:3]) / d[:, 2:3] * d)[0]
    edge_xyz[2] = POINT[2]
    edge = make_chip("EDGE", tex, edge_xyz, 0.1)
    res = locate_control_points([flat, far, edge], eo, CAM, _reader(images))
    by_point: dict = {}
    for p in res.pairs:
        by_point.setdefault(p.point_id, []).append(p)
    assert [(p.status, p.reason) for p in by_point["FLAT"]] == [
        ("rejected", "chip refused: no texture")
    ]
    assert [(p.status, p.reason) for p in by_point["FAR"]] == [("outside", "outside every image")]
    assert by_point["EDGE"], "the edge point projects into the images"
    for p in by_point["EDGE"]:
        if p.status != "ok":
            assert p.reason, "a rejection always names its reason"
    assert any(
        "outside the image" in p.reason or "left the search window" in p.reason
        for p in by_point["EDGE"]
    ), [p.reason for p in by_point["EDGE"]]
    assert set(res.observations.point_id) <= {"EDGE"}


def _write_inputs(block, tmp_path):
    """Images (8-bit), chips GCP1 and FLAT (GeoTIFF), control, camera and EO files."""
    from lidarphoto.core.io.camera import write_camera_json
    from lidarphoto.core.io.orientation import write_eo_csv
    from lidarphoto.core.io.raster_write import write_geotiff, write_rgb_tiff

    _, images, eo, chip = block
    (tmp_path / "img").mkdir()
    (tmp_path / "chips").mkdir()
    for iid, img in images.items():
        u8 = np.clip(np.round(img), 0, 255).astype(np.uint8)
        write_rgb_tiff(tmp_path / "img" / f"{iid}.tif", np.dstack([u8] * 3))
    write_geotiff(tmp_path / "chips" / "GCP1.tif", chip.grey.astype(np.float32),
                  chip.geotransform, -9999.0, "EPSG:25832")  # fmt: skip
    write_geotiff(tmp_path / "chips" / "FLAT.tif", np.full((81, 81), 7.0, np.float32),
                  chip.geotransform, -9999.0, "EPSG:25832")  # fmt: skip
    with open(tmp_path / "control.csv", "w") as fh:
        fh.write(f"point_id,X,Y,Z\nGCP1,{POINT[0]},{POINT[1]},{POINT[2]}\n"
                 f"FLAT,{POINT[0] + 0.5},{POINT[1]},{POINT[2]}\n")  # fmt: skip
    write_camera_json(tmp_path / "camera.json", CAM)
    write_eo_csv(tmp_path / "eo.csv", eo)
    return eo


def test_the_job_writes_observations_report_and_gallery(block, tmp_path):
    from lidarphoto.core.io.observations import read_observations_csv
    from lidarphoto.core.jobs import locate_control_points as job
    from lidarphoto.core.jobs.runner import run_job

    eo = _write_inputs(block, tmp_path)
    v = {"CHIPS": [str(tmp_path / "chips")], "CONTROL_POINTS": str(tmp_path / "control.csv"),
         "CAMERA": str(tmp_path / "camera.json"), "EO": str(tmp_path / "eo.csv"),
         "IMAGES": [str(tmp_path / "img")], "CRS": "EPSG:25832",
         "OUTPUT": str(tmp_path / "obs.csv"), "OUTPUT_REPORT": str(tmp_path / "report.csv"),
         "OUTPUT_HTML": str(tmp_path / "report.html")}  # fmt: skip
    result = run_job(job, v)
    assert result.results == {"LOCATED": 3, "REJECTED": 1}
    obs = read_observations_csv(tmp_path / "obs.csv")
    truth = _truth(eo, POINT)
    for iid, px in zip(obs.image_id, obs.pixels):
        assert np.hypot(*(px - truth[iid])) < 0.1
    rows = list(csv.DictReader(open(tmp_path / "report.csv")))
    assert {r["reason"] for r in rows if r["point_id"] == "FLAT"} == {"chip refused: no texture"}
    page = (tmp_path / "report.html").read_text()
    assert page.count("data:image/png;base64,") == 6 and "no texture" in page


def test_located_control_feeds_the_resection_directly(block, tmp_path):
    """Five chips spread over the common area, located in the three images; the observation
    CSV goes unchanged into `resection` with the control CSV (the EO as weighted start values:
    the narrow 2.7-degree field of view cannot separate X0 from phi alone): every located
    point is used as control, the
    residuals are below 0.1 px and the pose agrees with the truth within 3 sigma."""
    from lidarphoto.core.io.camera import write_camera_json
    from lidarphoto.core.io.observations import write_observations_csv
    from lidarphoto.core.io.orientation import read_eo_csv_full, write_eo_csv
    from lidarphoto.core.jobs import resection
    from lidarphoto.core.jobs.runner import run_job

    tex, images, eo, _ = block
    offsets = [(0, 0), (-3, 2), (3, 2), (-3, -2), (3, -2)]
    chips = [make_chip(f"G{k}", tex, POINT + [dx, dy, 0.0], 0.1, noise=1.0, seed=k)
             for k, (dx, dy) in enumerate(offsets)]  # fmt: skip
    res = locate_control_points(chips, eo, CAM, _reader(images))
    per_image = {i: res.observations.image_id.count(i) for i in eo.image_id}
    assert min(per_image.values()) >= 4, per_image  # near a border: refused with the reason
    assert all(p.reason == "template partly outside the image" for p in res.pairs if p.reason)
    write_observations_csv(tmp_path / "obs.csv", res.observations)
    with open(tmp_path / "control.csv", "w") as fh:
        fh.write("point_id,X,Y,Z\n")
        for c in chips:
            fh.write(f"{c.point_id},{c.xyz[0]:.4f},{c.xyz[1]:.4f},{c.xyz[2]:.4f}\n")
    write_camera_json(tmp_path / "camera.json", CAM)
    write_eo_csv(tmp_path / "eo_in.csv", eo)
    run_job(resection, {"CAMERA": str(tmp_path / "camera.json"),
                        "OBSERVATIONS": str(tmp_path / "obs.csv"),
                        "CONTROL_POINTS": str(tmp_path / "control.csv"), "CRS": "EPSG:25832",
                        "APPROX_EO": str(tmp_path / "eo_in.csv"),
                        "APPROX_EO_SIGMAS": [1.0, 1.0, 1.0, 0.05, 0.05, 0.05],
                        "OUTPUT_RESIDUALS": str(tmp_path / "res.csv"),
                        "OUTPUT_EO": str(tmp_path / "eo_out.csv")})  # fmt: skip
    rows = list(csv.DictReader(open(tmp_path / "res.csv")))
    assert len(rows) == len(res.observations)
    assert all(r["used"] == "1" and float(r["distance_px"]) < 0.1 for r in rows), rows
    out = read_eo_csv_full(tmp_path / "eo_out.csv")
    for k, iid in enumerate(out.eo.image_id):
        j = eo.image_id.index(iid)
        err = out.eo.xyz[k] - eo.xyz[j]
        assert np.all(np.abs(err) < 3 * out.sigma[k, :3] + 1e-3), (iid, err, out.sigma[k, :3])


@pytest.mark.parametrize(
    "change, message",
    [
        ("unknown_chip", r"chips of unknown points \(not in the control table\): EXTRA"),
        ("no_image", r"eo\.csv: no exterior orientation for image\(s\) X9 \(image_id = file name"),
    ],
)
def test_bad_job_inputs_are_refused_by_name(block, tmp_path, capsys, change, message):
    """The command line refuses with one line naming the problem; nothing is written."""
    import re
    import shutil

    from lidarphoto.core.cli import main

    _write_inputs(block, tmp_path)
    images = tmp_path / "img"
    if change == "unknown_chip":
        shutil.copy(tmp_path / "chips" / "GCP1.tif", tmp_path / "chips" / "EXTRA.tif")
    else:
        images = tmp_path / "other"
        images.mkdir()
        shutil.copy(tmp_path / "img" / "I0.tif", images / "X9.tif")
    out = tmp_path / "out"
    out.mkdir()
    code = main(["locatecontrolpoints", "--chips", str(tmp_path / "chips"),
                 "--control-points", str(tmp_path / "control.csv"),
                 "--camera", str(tmp_path / "camera.json"), "--eo", str(tmp_path / "eo.csv"),
                 "--images", str(images), "--crs", "EPSG:25832",
                 "--output", str(out / "obs.csv")])  # fmt: skip
    err = capsys.readouterr().err.strip().splitlines()
    assert code != 0 and len(err) == 1, err
    assert re.search(message, err[0]), err[0]
    assert list(out.iterdir()) == []
