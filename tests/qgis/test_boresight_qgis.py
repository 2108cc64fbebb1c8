"""lidarphoto:boresightcalibration in real QGIS: processing.run and qgis_process on simulated
files (simulate_flight(...).write), the truth recovered within 3 sigma, the diagnosis of a
set-up that is not observable in the exception."""

from __future__ import annotations

import csv
import json
import subprocess
from dataclasses import replace

import numpy as np
import processing
import pytest
from lidarphoto.core.simulation.flight import FlightConfig, simulate_flight
from qgis.core import QgsProcessingException, QgsVectorLayer, QgsWkbTypes
from qgis_helpers import QGIS_PROCESS

ALG = "lidarphoto:boresightcalibration"
SMALL = FlightConfig(
    n_buildings=12,
    n_planes=30,
    town_size_m=700.0,
    n_check=3,
    types=("tie", "line", "lcp", "check"),
)
ARCSEC = np.pi / (180.0 * 3600.0)


@pytest.fixture(scope="module")
def flight(tmp_path_factory):
    sim = simulate_flight(SMALL, seed=6)
    paths = sim.write(tmp_path_factory.mktemp("flight"))
    return sim, paths


def _params(sim, paths, **extra):
    return {
        "CAMERA": str(paths["camera"]),
        "TRAJECTORY": str(paths["trajectory"]),
        "CRS": sim.crs,
        "LEVER_ARM": ",".join(repr(float(v)) for v in sim.mount.lever_arm),
        "OBSERVATIONS": str(paths["observations"]),
        "PLANES": str(paths["planes"]),
        "LINES": str(paths["lines"]),
        "LCPS": str(paths["lcps"]),
        **extra,
    }


def _check_table(sim, path):
    with open(path, encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["group"] for r in rows] == ["NE", "SW"]
    for row in rows:
        true = sim.truth.boresight[row["group"]] / ARCSEC
        for k, angle in enumerate(("omega", "phi", "kappa")):
            est = float(row[f"d_{angle}_arcsec"])
            sigma = float(row[f"std_d_{angle}_arcsec"])
            assert abs(est - true[k]) < 3.0 * sigma, (row["group"], angle, est, true[k], sigma)
            assert float(row[f"d_{angle}_deg"]) == pytest.approx(est / 3600.0)
    return rows


def test_processing_run_recovers_the_boresight(provider, flight, tmp_path):
    sim, paths = flight
    result = processing.run(
        ALG,
        _params(
            sim,
            paths,
            CONTROL_TYPES=[0, 1, 2],
            OUTPUT_TABLE=str(tmp_path / "table.csv"),
            OUTPUT_RESIDUALS="TEMPORARY_OUTPUT",
            OUTPUT_EO=str(tmp_path / "eo.csv"),
            OUTPUT_HTML=str(tmp_path / "summary.html"),
        ),
    )
    _check_table(sim, result["OUTPUT_TABLE"])
    assert 0.8 < result["SIGMA0"] < 1.2  # the noise put in is the noise assumed
    layer = result["OUTPUT_RESIDUALS"]
    used = sum(t in ("tie", "line", "lcp") for t in sim.observations.type)
    assert layer.featureCount() == len(sim.observations)  # every row has a ground position
    assert QgsWkbTypes.hasZ(layer.wkbType()) and layer.crs().authid() == sim.crs
    features = list(layer.getFeatures())
    assert sum(f["used"] for f in features) == used
    v = np.array([f["v"] for f in features if f["type"] == "tie"])
    assert 0.2 < np.sqrt(np.mean(v**2)) < 1.0  # pixel noise 0.5 px per coordinate
    with open(tmp_path / "eo.csv", encoding="utf-8") as fh:
        eo = list(csv.DictReader(fh))
    assert len(eo) == len(sim.trajectory) and "omega_deg" in eo[0]
    page = (tmp_path / "summary.html").read_text(encoding="utf-8")
    assert "Boresight calibration" in page and f"{result['SIGMA0']:.3f}" in page


def test_not_observable_raises_the_diagnosis(provider, flight, tmp_path):
    sim, _ = flight
    lonely = sim.trajectory.image_id[0]
    groups = tuple("lonely" if i == lonely else g for i, g in
                   zip(sim.trajectory.image_id, sim.trajectory.group))  # fmt: skip
    keep = np.array([i != lonely for i in sim.observations.image_id])
    sim2 = replace(
        sim,
        trajectory=replace(sim.trajectory, group=groups),
        observations=sim.observations.subset(keep),
    )
    paths = sim2.write(tmp_path)
    with pytest.raises(QgsProcessingException, match="group 'lonely' is not determined") as info:
        processing.run(
            ALG,
            _params(
                sim2,
                paths,
                OUTPUT_TABLE=str(tmp_path / "t.csv"),
                OUTPUT_RESIDUALS="TEMPORARY_OUTPUT",
                OUTPUT_EO=str(tmp_path / "eo.csv"),
                OUTPUT_HTML=str(tmp_path / "s.html"),
            ),
        )
    assert "null" not in str(info.value) and "condition" not in str(info.value)


def test_qgis_process_run(qp_env, flight, tmp_path):
    sim, paths = flight
    args = [f"{k}={v}" for k, v in _params(sim, paths).items()]
    r = subprocess.run(
        [QGIS_PROCESS, "--json", "run", ALG, "--", *args, "CONTROL_TYPES=0,1,2",
         f"OUTPUT_TABLE={tmp_path / 'table.csv'}",
         f"OUTPUT_RESIDUALS={tmp_path / 'res.gpkg'}", f"OUTPUT_EO={tmp_path / 'eo.csv'}",
         f"OUTPUT_HTML={tmp_path / 's.html'}"],
        env=qp_env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    results = json.loads(r.stdout)["results"]
    assert 0.8 < results["SIGMA0"] < 1.2
    _check_table(sim, tmp_path / "table.csv")
    layer = QgsVectorLayer(str(tmp_path / "res.gpkg"), "res", "ogr")
    assert layer.isValid() and layer.featureCount() == len(sim.observations)


def test_processing_run_with_surveyed_ground_control(provider, tmp_path):
    """CONTROL_TYPES control + GROUND_POINTS (the located-control path): the boresight within
    4 sigma of the truth, every row a residual feature named by its surveyed point_id, the
    check points not used; a control row naming no ground point fails naming the row."""
    from lidarphoto.core.io.observations import write_observations_csv
    from lidarphoto.core.jobs.boresight_calibration import CONTROL_TYPES
    from lidarphoto.core.simulation.flight import surveyed_control

    cfg = replace(SMALL, n_check=4, types=("lcp", "check"))
    sim, rows, ground, paths = surveyed_control(cfg, 5, folder=tmp_path / "gcp")
    params = {
        "CAMERA": str(paths["camera"]), "TRAJECTORY": str(paths["trajectory"]),
        "CRS": sim.crs, "LEVER_ARM": ",".join(repr(float(v)) for v in sim.mount.lever_arm),
        "OBSERVATIONS": str(paths["observations"]), "GROUND_POINTS": str(paths["ground"]),
        "GROUPING": 0, "CONTROL_TYPES": [CONTROL_TYPES.index("control")],
        "OUTPUT_TABLE": str(tmp_path / "table.csv"), "OUTPUT_RESIDUALS": "TEMPORARY_OUTPUT",
        "OUTPUT_EO": str(tmp_path / "eo.csv"), "OUTPUT_HTML": str(tmp_path / "summary.html"),
    }  # fmt: skip
    result = processing.run(ALG, params)
    with open(result["OUTPUT_TABLE"], encoding="utf-8") as fh:
        (row,) = list(csv.DictReader(fh))
    true = next(iter(sim.truth.boresight.values())) / ARCSEC
    for k, angle in enumerate(("omega", "phi", "kappa")):
        est, sigma = float(row[f"d_{angle}_arcsec"]), float(row[f"std_d_{angle}_arcsec"])
        assert abs(est - true[k]) < 4.0 * sigma, (angle, est, true[k], sigma)
    role = dict(zip(ground.point_id, ground.role))
    features = list(result["OUTPUT_RESIDUALS"].getFeatures())
    assert len(features) == len(rows)
    for f in features:
        assert f["type"] == "control" and f["point_id"] in role
        assert f["used"] == (0 if role[f["point_id"]] == "check" else 1)
    bad = tmp_path / "bad.csv"
    write_observations_csv(bad, replace(rows, point_id=("GCP_X",) + rows.point_id[1:]))
    with pytest.raises(QgsProcessingException, match=r"GCP_X.*row 2|row 2.*GCP_X"):
        processing.run(ALG, dict(params, OBSERVATIONS=str(bad)))
