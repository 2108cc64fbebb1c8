"""Fisheye cameras in the bundle adjustment and the resection, against simulated truth.

Truth: the UAV block of core/simulation/uav_block.py (three strips of four images at 188 m,
16 control and 5 check points, 500 tie points drawn, 0.5 px image noise, 1 / 1.5 cm survey
noise) flown with a 3 mm fisheye of each projection of core/geometry/projection.py (4000 x
3000 px of 1.54 um: 52 degrees off the axis in the image corners) whose true principal
distance is 3.02 mm, with the principal point off by (12, -9) um and the "real" Brown-Conrady
lens (about 30 px radial in the corner, 2 px decentring). The bundle self-calibrates f, x0,
y0 and k1 k2 k3 p1 p2 (``conrady_brown``).

Tolerances from the noise put in: sigma0 inside the two-sided 0.1 % chi-square band of the
redundancy; every interior parameter within 4 of its reported a-posteriori sigmas of the
truth (measured: at most 2.02); the check points within 0.2 m 3D RMS of the survey (measured
0.075-0.103 m). The same measurements adjusted with the perspective formula (r = f tan theta,
the same lens model) fail the global test: the projection is what the model needs.

The ``resection`` job: a 3 mm fisheye of each projection (Brown k1, p1) 120 m over the 12
control points (3 cm) of core/simulation/resection.py, 0.5 px: the pose within 4 of its
written sigmas of the truth (measured: at most 2.14), sigma0 in the band of redundancy 18
(measured 0.82-0.83); line rows with a fisheye camera refused by name.
"""

from __future__ import annotations

import csv
import dataclasses
import json

import numpy as np
import pytest
from lidarphoto.core.cli import main as cli_main
from lidarphoto.core.errors import InputError
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.distortion import BrownConrady
from lidarphoto.core.geometry.projection import FISHEYE_PROJECTIONS
from lidarphoto.core.io.orientation import read_eo_csv
from lidarphoto.core.io.resection import RESECTION_EO_COLUMNS
from lidarphoto.core.jobs import resection as resection_job
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.photo.bundle import bundle_adjust
from lidarphoto.core.photo.bundle_setup import BundleOptions
from lidarphoto.core.simulation.resection import make_scene, write_scene_files
from lidarphoto.core.simulation.uav_block import simulate_uav_block
from scipy import stats

PLAIN = {"robust": "none", "snooping": False, "ap_selection": False}
CRS = "EPSG:31983"


def _block(projection: str):
    cam = Camera("fisheye UAV", 3.0, 0.00154, 4000, 3000, projection=projection)
    return simulate_uav_block("real", seed=3, n_tie=500, camera=cam, true_focal_mm=3.02,
                              strips=(4, 4, 4))  # fmt: skip


def _adjust(blk, camera: Camera, eo=True):
    return bundle_adjust([camera], blk.observations, blk.ground, blk.mapping,
                         blk.eo_dg if eo else None, blk.eo_sigma if eo else None,
                         options=BundleOptions(ap_model="conrady_brown", **PLAIN))  # fmt: skip


def _band(res) -> tuple[float, float]:
    """The two-sided 0.1 % band of sigma0 for the redundancy of ``res``."""
    r = res.adjustment.redundancy
    lo, hi = np.sqrt(stats.chi2.ppf([0.0005, 0.9995], r) / r)
    return float(lo), float(hi)


def _z(blk, res) -> dict[str, float]:
    """(estimate - truth) / reported sigma of every estimated interior parameter."""
    tc = blk.true_camera
    truth = {"focal_mm": tc.focal_mm, "x0_mm": tc.x0_mm, "y0_mm": tc.y0_mm, **blk.true_ap}
    return {p.name: (p.value - truth[p.name]) / p.std for p in res.interior
            if p.status == "estimated"}  # fmt: skip


@pytest.fixture(scope="module")
def blocks():
    return {p: _block(p) for p in FISHEYE_PROJECTIONS}


@pytest.mark.parametrize("projection", FISHEYE_PROJECTIONS)
def test_fisheye_block_self_calibrates_to_the_truth(blocks, projection):
    """Measured (seed 3): sigma0 1.003-1.012, interior within 2.02 sigma of the truth
    (equisolid 1.61), check points 0.075-0.103 m 3D RMS."""
    blk = blocks[projection]
    res = _adjust(blk, blk.camera)
    assert res.adjustment.converged
    lo, hi = _band(res)
    assert lo < res.sigma0 < hi, (res.sigma0, lo, hi)
    z = _z(blk, res)
    assert len(z) == 3 + len(blk.true_ap)
    assert all(abs(v) < 4.0 for v in z.values()), z
    st = res.check.statistics()
    assert st["n"] >= 4 and st["rms_3d"] < 0.2, st
    # the adjusted camera keeps its projection (what the products downstream read)
    assert res.cameras[blk.camera.name].projection == projection


@pytest.mark.parametrize("projection", FISHEYE_PROJECTIONS)
def test_the_perspective_formula_fails_on_fisheye_images(blocks, projection):
    """The same measurements with the camera declared perspective: the Brown lens cannot
    absorb the difference and the global test rejects the model (measured sigma0: equisolid
    2.82, equidistant 1.96, orthographic 8.43; stereographic, the closest to the
    perspective projection, 1.040 against an upper bound of 1.032)."""
    blk = blocks[projection]
    res = _adjust(blk, dataclasses.replace(blk.camera, projection="perspective"))
    assert res.sigma0 > _band(res)[1], res.sigma0


def test_fisheye_monte_carlo_errors_match_the_reported_sigmas():
    """10 noise draws per projection on one geometry (300 tie points drawn): the squared
    Mahalanobis distance of each draw's interior error (f, x0, y0, k1 k2 k3 p1 p2) under its
    reported covariance is chi-square with 8 degrees of freedom; the sum over the 40 draws
    must fall inside the two-sided 0.1 % bounds of chi-square(320) (measured 273.2 in
    243.2-409.8; the same block with a perspective camera gives a mean of 6.8-7.7 per draw
    against 8, as the fisheye's 6.8). The centres' errors over their sigmas, pooled: RMS
    within 20 % of 1 (measured 0.936)."""
    from lidarphoto.core.photo.orientation import eo_map_to_local

    d2, eo_z = [], []
    for projection in FISHEYE_PROJECTIONS:
        cam = Camera("fisheye UAV", 3.0, 0.00154, 4000, 3000, projection=projection)
        for k in range(10):
            blk = simulate_uav_block("real", seed=3, noise_seed=2000 + k, n_tie=300, camera=cam,
                                     true_focal_mm=3.02, strips=(4, 4, 4))  # fmt: skip
            res = _adjust(blk, blk.camera)
            tc = blk.true_camera
            truth = {"focal_mm": tc.focal_mm, "x0_mm": tc.x0_mm, "y0_mm": tc.y0_mm,
                     **blk.true_ap}  # fmt: skip
            est = [p for p in res.interior if p.status == "estimated"]
            err = np.array([p.value - truth[p.name] for p in est])
            idx = np.array([res.adjustment.names.index(f"{p.camera} {p.name}") for p in est])
            cov = res.adjustment.covariance_of(idx, prior=True)
            d2.append(float(err @ np.linalg.solve(cov, err)))
            c_est, _ = eo_map_to_local(res.eo.xyz, res.eo.opk, res.local)
            c_true, _ = eo_map_to_local(blk.eo_true.xyz, blk.eo_true.opk, res.local)
            eo_idx = [res.adjustment.names.index(f"{im} {c}") for im in res.eo.image_id
                      for c in ("X0", "Y0", "Z0")]  # fmt: skip
            eo_z.append((c_est - c_true).ravel() / res.adjustment.std_prior[eo_idx])
    lo, hi = stats.chi2.ppf([0.0005, 0.9995], 8 * len(d2))
    assert lo < sum(d2) < hi, (sum(d2), lo, hi)
    z = np.concatenate(eo_z)
    assert 0.8 < np.sqrt(np.mean(z**2)) < 1.2


def test_fisheye_block_without_orientations_grows_from_control(blocks):
    """No EO: the images seeing control are resected through the fisheye projection and the
    block grows by intersection and resection; the adjusted centres within 4 of their sigmas
    of the truth (measured 1.49), sigma0 in the band (measured 1.002)."""
    blk = blocks["equisolid"]
    res = _adjust(blk, blk.camera, eo=False)
    lo, hi = _band(res)
    assert lo < res.sigma0 < hi, res.sigma0
    order = [list(res.eo.image_id).index(i) for i in blk.eo_true.image_id]
    d = res.eo.xyz[order] - blk.eo_true.xyz
    assert (np.abs(d) < 4.0 * res.eo_sigma[order, :3]).all(), (d, res.eo_sigma[order, :3])
    assert all(abs(v) < 4.0 for v in _z(blk, res).values())


def test_bundleadjustment_command_line_takes_a_fisheye_camera(blocks, tmp_path, capsys):
    """The job end to end with its default outliers and AP selection: the adjusted camera
    JSON keeps the projection, f and the principal point within 4 of its written sigmas of the
    truth; the HTML names the projection."""
    blk = blocks["equidistant"]
    paths = blk.write(tmp_path)
    assert json.loads(paths["camera"].read_text())["projection"] == "equidistant"
    out_cam, html = tmp_path / "adjusted.json", tmp_path / "bundle.html"
    args = ["bundleadjustment", "--camera", str(paths["camera"]), "--observations",
            str(paths["observations"]), "--ground-points", str(paths["ground_points"]),
            "--eo", str(paths["eo"]), "--crs", CRS, "--ap-model", "conrady_brown",
            "--output-eo", str(tmp_path / "adjusted_eo.csv"), "--output-camera", str(out_cam),
            "--output-html", str(html)]  # fmt: skip
    assert cli_main(args) == 0
    assert "conrady_brown: sigma0" in capsys.readouterr().out
    cam = json.loads(out_cam.read_text())
    assert cam["projection"] == "equidistant"
    tc = blk.true_camera
    for key, truth in (("focal_mm", tc.focal_mm), ("x0_mm", tc.x0_mm), ("y0_mm", tc.y0_mm)):
        assert abs(cam[key] - truth) < 4.0 * cam["sigmas"][key], (key, cam[key], truth)
    assert "equidistant projection" in html.read_text(encoding="utf-8")
    assert len(read_eo_csv(tmp_path / "adjusted_eo.csv")) == len(blk.eo_true)


def _fisheye_scene(projection: str):
    """A fisheye camera (3 mm, Brown k1) 120 m over the roofs of the resection scene."""
    cam = Camera("fish", 3.0, 0.00154, 4000, 3000, 0.012, -0.009,
                 BrownConrady(k1=8e-4, p1=6e-5), projection=projection)  # fmt: skip
    return make_scene(51, camera=cam, height_m=120.0, n_points=12, point_sigma_m=0.03)


def _rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


@pytest.mark.parametrize("projection", FISHEYE_PROJECTIONS)
def test_resection_job_orients_a_fisheye_image(tmp_path, projection):
    """Control points only, from the files (no approximate values): the EO in the mapping CRS
    within 4 of its written sigmas of the truth; sigma0 in the chi-square band."""
    scene = _fisheye_scene(projection)
    data = scene.observe(np.random.default_rng(7), lines=False)
    files = write_scene_files(tmp_path, scene, data, "EPSG:32632")
    v = {"CAMERA": str(files["camera"]), "OBSERVATIONS": str(files["observations"]),
         "CONTROL_POINTS": str(files["control_points"]), "CRS": "EPSG:32632",
         "OUTPUT_EO": str(tmp_path / "eo.csv"), "OUTPUT_HTML": str(tmp_path / "r.html")}
    result = run_job(resection_job, v)
    assert result.results["IMAGE_COUNT"] == 1
    truth, got = read_eo_csv(files["eo_true"]), read_eo_csv(tmp_path / "eo.csv")
    row = _rows(tmp_path / "eo.csv")[0]
    sig = np.array([float(row[c]) for c in RESECTION_EO_COLUMNS[9:15]])
    d_xyz = got.xyz[0] - truth.xyz[0]
    d_opk = (np.degrees(got.opk[0] - truth.opk[0]) + 180.0) % 360.0 - 180.0
    assert (np.abs(d_xyz) < 4.0 * sig[:3]).all(), (d_xyz, sig[:3])
    assert (np.abs(d_opk) < 4.0 * sig[3:]).all(), (d_opk, sig[3:])
    r = 2 * data.n_points - 6
    lo, hi = np.sqrt(stats.chi2.ppf([0.0005, 0.9995], r) / r)
    assert lo < float(row["sigma0"]) < hi, row["sigma0"]
    assert f"{projection} projection" in (tmp_path / "r.html").read_text(encoding="utf-8")


def test_resection_job_refuses_lines_with_a_fisheye_camera_by_name(tmp_path):
    """Line rows with a fisheye camera: refused before any adjustment, naming the observation
    file and row, the camera and its file; nothing written."""
    scene = _fisheye_scene("equisolid")
    data = scene.observe(np.random.default_rng(7))
    files = write_scene_files(tmp_path, scene, data, "EPSG:32632")
    first_line = 2 + [r["type"] for r in _rows(files["observations"])].index("line")
    v = {"CAMERA": str(files["camera"]), "OBSERVATIONS": str(files["observations"]),
         "CONTROL_POINTS": str(files["control_points"]),
         "CONTROL_LINES": str(files["control_lines"]), "CRS": "EPSG:32632",
         "OUTPUT_EO": str(tmp_path / "eo.csv")}  # fmt: skip
    with pytest.raises(InputError, match=rf"observations\.csv, row {first_line}: camera 'fish' "
                       r"\(.*camera\.json\) has the equisolid \(fisheye\) projection; the "
                       r"resection from straight lines"):  # fmt: skip
        run_job(resection_job, v)
    assert not (tmp_path / "eo.csv").exists()
