"""lidarphoto:resection in real QGIS: processing.run and qgis_process on a synthetic image with
known orientation (the files are those the core writes from the same inputs), its errors as
QgsProcessingException, and the committed graphical model createlcps -> resection
(tests/qgis/data/resection_model.model3) on the demo: the real AHN3 tile's roof planes and a
simulated flight over them, against the flight's true orientation."""

from __future__ import annotations

import csv
import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import processing
import pytest
from lidarphoto.core.io.observations import read_observations_csv, write_observations_csv
from lidarphoto.core.io.orientation import read_eo_csv
from lidarphoto.core.jobs import resection as resection_job
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.simulation.resection import make_scene, write_scene_files
from qgis.core import QgsProcessingException, QgsProcessingModelAlgorithm
from qgis_helpers import DATA, QGIS_PROCESS

ROOT = Path(__file__).resolve().parents[2]
MODEL = DATA / "resection_model.model3"
CRS = "EPSG:32632"
SIGMAS = ("sigma_X", "sigma_Y", "sigma_Z", "sigma_omega_deg", "sigma_phi_deg", "sigma_kappa_deg")


def _rows(path):
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def _errors_in_sigma(eo_csv, truth_csv, prior: bool = False) -> np.ndarray:
    """(images, 6) differences from the truth in units of the file's own sigmas (a-posteriori,
    ``sigma0 sqrt(Qxx)``), or of the a-priori ones (``sqrt(Qxx)``: the file's divided by its
    sigma0) with ``prior``."""
    got, truth = read_eo_csv(eo_csv), read_eo_csv(truth_csv)
    rows = {r["image_id"]: r for r in _rows(eo_csv)}
    out = []
    for k, i in enumerate(got.image_id):
        t = truth.image_id.index(i)
        d_ang = (np.degrees(got.opk[k] - truth.opk[t]) + 180.0) % 360.0 - 180.0
        d = np.r_[got.xyz[k] - truth.xyz[t], d_ang]
        scale = float(rows[i]["sigma0"]) if prior else 1.0
        out.append(d / (scale * np.array([float(rows[i][c]) for c in SIGMAS])))
    return np.array(out)


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    sc = make_scene(61, point_sigma_m=0.03)
    data = sc.observe(np.random.default_rng(3))
    return write_scene_files(tmp_path_factory.mktemp("resection"), sc, data, CRS)


def _params(files, out: Path, **extra) -> dict:
    return {"CAMERA": str(files["camera"]), "OBSERVATIONS": str(files["observations"]),
            "CONTROL_POINTS": str(files["control_points"]),
            "CONTROL_LINES": str(files["control_lines"]), "CRS": CRS,
            "OUTPUT_EO": str(out / "eo.csv"), "OUTPUT_RESIDUALS": str(out / "res.csv"),
            "OUTPUT_HTML": str(out / "summary.html"), **extra}  # fmt: skip


def test_processing_run_matches_the_core(provider, scene, tmp_path):
    """The EO, residual and HTML files of processing.run are the core's; the orientation holds
    the truth within 4 sigma."""
    (tmp_path / "q").mkdir()
    (tmp_path / "c").mkdir()
    result = processing.run("lidarphoto:resection", _params(scene, tmp_path / "q",
                                                            MODEL=1))  # fmt: skip
    assert result["IMAGE_COUNT"] == 1 and 0.5 < result["SIGMA0"] < 1.5
    run_job(resection_job, _params(scene, tmp_path / "c", MODEL="equivalent_planes"))
    for name in ("eo.csv", "res.csv"):
        assert (tmp_path / "q" / name).read_text() == (tmp_path / "c" / name).read_text()
    assert (tmp_path / "q" / "summary.html").stat().st_size > 1000
    assert _rows(tmp_path / "q" / "eo.csv")[0]["model"] == "equivalent_planes"
    assert np.all(np.abs(_errors_in_sigma(tmp_path / "q" / "eo.csv", scene["eo_true"])) < 4)


def test_errors_reach_the_user(provider, scene, tmp_path):
    with pytest.raises(QgsProcessingException, match="give CONTROL_POINTS or CONTROL_LINES"):
        processing.run("lidarphoto:resection", _params(scene, tmp_path, CONTROL_POINTS=None,
                                                       CONTROL_LINES=None))  # fmt: skip
    assert not (tmp_path / "eo.csv").exists()


def test_qgis_process(qp_env, scene, tmp_path):
    r = subprocess.run(
        [QGIS_PROCESS, "--json", "run", "lidarphoto:resection", "--",
         *(f"{k}={v}" for k, v in _params(scene, tmp_path).items())],
        env=qp_env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert json.loads(r.stdout)["results"]["IMAGE_COUNT"] == 1
    assert np.all(np.abs(_errors_in_sigma(tmp_path / "eo.csv", scene["eo_true"])) < 4)


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    """The demo's LiDAR step (createlcps included) and its flight; the observations of the
    LCPs and of the lines measured over 20 px or more (the simulation also reports lines seen
    as a point or a few pixels in some images, which are not lines there)."""
    spec = importlib.util.spec_from_file_location("lidarphoto_demo_resection",
                                                  ROOT / "scripts" / "demo.py")  # fmt: skip
    module = importlib.util.module_from_spec(spec)
    sys.modules["lidarphoto_demo_resection"] = module
    spec.loader.exec_module(module)
    out = tmp_path_factory.mktemp("resection_demo")
    lidar = module.lidar_step(out / "lidar")
    _sim, paths, _ = module.flight_step(lidar, out / "flight")
    obs = read_observations_csv(paths["observations"])
    span: dict = {}
    for i, t, k, px in zip(obs.image_id, obs.target_id, obs.type, obs.pixels):
        if k == "line":
            span.setdefault((i, t), []).append(px)
    long = {p: np.ptp(np.array(v), axis=0).max() >= 20.0 for p, v in span.items()}
    keep = [k == "lcp" or (k == "line" and long[(i, t)])
            for i, t, k in zip(obs.image_id, obs.target_id, obs.type)]  # fmt: skip
    write_observations_csv(out / "obs.csv", obs.subset(np.array(keep)))
    return {"out": out, "lidar": out / "lidar", "paths": paths, "obs": out / "obs.csv",
            "crs": module.CRS}  # fmt: skip


def _model_inputs(demo, tmp_path) -> dict:
    return {"camera": str(demo["paths"]["camera"]), "observations": str(demo["obs"]),
            "planes": str(demo["lidar"] / "planes.csv"),
            "cloud": str(demo["lidar"] / "planes.laz"), "crs": demo["crs"],
            "lcps:lcp_table": str(tmp_path / "lcps.csv"),
            "lcps:line_table": str(tmp_path / "lines.csv"),
            "resect:eo": str(tmp_path / "eo.csv")}  # fmt: skip


#: The demo's flight takes the LiDAR control as the truth (core/simulation/flight_over.py) while
#: the resection weights it with its covariance: every image's sigma0 is below 1 (0.23-0.95),
#: and an image with little control estimates it from few degrees of freedom. With the planes
#: of seed voxels of 8 spacings, demo image 6 (L2_006: 2 LCPs and 4 lines, redundancy 6) got
#: sigma0 0.226 (chi-square 0.31 on 6 degrees of freedom, p = 0.0005 were the weights the
#: errors'): its a-posteriori sigmas were 0.226 of its a-priori ones, and it lay 7.35 of them
#: from the truth, 1.66 a-priori sigmas (the other nine within 1.8); with 16 spacings, sigma0
#: 0.53 and 1.59 a-posteriori sigmas. The demo's images are held to the a-priori sigmas; the
#: other tests of this file keep the a-posteriori ones (their scene draws the control with the
#: noise of its covariance, so the weights are the errors').


def test_model_createlcps_to_resection(provider, demo, tmp_path):
    """The model's LCPs and lines are the demo's (the same createlcps); every image of the
    flight is resected from them without approximate values, within 4 a-priori sigma of the
    truth."""
    model = QgsProcessingModelAlgorithm()
    assert model.fromFile(str(MODEL))
    ok, errors = model.validate()
    assert ok, errors
    assert sorted(c.algorithmId() for c in model.childAlgorithms().values()) == [
        "lidarphoto:createlcps", "lidarphoto:resection"]  # fmt: skip
    processing.run(model, _model_inputs(demo, tmp_path))
    assert (tmp_path / "lines.csv").read_text() == (demo["lidar"] / "lines.csv").read_text()
    z = _errors_in_sigma(tmp_path / "eo.csv", demo["paths"]["eo_true"], prior=True)
    assert len(z) == len(read_eo_csv(demo["paths"]["eo_true"]).image_id)
    assert np.all(np.abs(z) < 4.0), z


def test_model_in_qgis_process(qp_env, demo, tmp_path):
    args = [f"{k}={v}" for k, v in _model_inputs(demo, tmp_path).items()]
    r = subprocess.run([QGIS_PROCESS, "--json", "run", str(MODEL), "--", *args], env=qp_env,
                       capture_output=True, text=True, timeout=600)  # fmt: skip
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    z = _errors_in_sigma(tmp_path / "eo.csv", demo["paths"]["eo_true"], prior=True)
    assert np.all(np.abs(z) < 4.0), z
