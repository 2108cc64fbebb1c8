"""lidarphoto:bundleadjustment in real QGIS: processing.run and qgis_process on a simulated UAV
block (simulate_uav_block(...).write), and the graphical model chaining it into the accuracy
report (tests/qgis/data/bundle_accuracy_model.model3, made by make_bundle_model.py)."""

from __future__ import annotations

import csv
import json
import subprocess
from pathlib import Path

import processing
import pytest
from lidarphoto.core.simulation.uav_block import simulate_uav_block
from qgis.core import QgsProcessingModelAlgorithm, QgsVectorLayer, QgsWkbTypes
from qgis_helpers import QGIS_PROCESS

ALG = "lidarphoto:bundleadjustment"
MODEL = Path(__file__).resolve().parent / "data" / "bundle_accuracy_model.model3"
CRS = "EPSG:31983"


@pytest.fixture(scope="module")
def block(tmp_path_factory):
    blk = simulate_uav_block("bauer", seed=1, n_tie=300)
    return blk, blk.write(tmp_path_factory.mktemp("uav"))


def _inputs(paths):
    return {
        "CAMERA": str(paths["camera"]),
        "OBSERVATIONS": str(paths["observations"]),
        "GROUND_POINTS": str(paths["ground_points"]),
        "EO": str(paths["eo"]),
        "CRS": CRS,
    }


def _rows(path):
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def test_processing_run_writes_layer_and_tables(provider, block, tmp_path):
    _, paths = block
    result = processing.run(
        ALG,
        {
            **_inputs(paths),
            "AP_MODEL": 2,  # bauer (enum index)
            "OUTPUT_EO": str(tmp_path / "eo.csv"),
            "OUTPUT_CHECK_CSV": str(tmp_path / "check.csv"),
            "OUTPUT_POINTS_LAYER": "TEMPORARY_OUTPUT",
            "OUTPUT_HTML": str(tmp_path / "summary.html"),
        },
    )
    assert result["MODEL"] == "bauer"
    assert 0.8 < result["SIGMA0"] < 1.2 and result["CHECK_RMS"] < 0.2
    layer = result["OUTPUT_POINTS_LAYER"]
    if isinstance(layer, str):
        layer = QgsVectorLayer(layer, "points", "ogr")
    assert QgsWkbTypes.hasZ(layer.wkbType())
    roles = {f["role"] for f in layer.getFeatures()}
    assert roles == {"tie", "control", "check"}
    assert len(_rows(tmp_path / "eo.csv")) == 15
    assert len(_rows(tmp_path / "check.csv")) >= 4
    assert "Interior orientation and additional parameters" in (
        tmp_path / "summary.html"
    ).read_text(encoding="utf-8")


def test_qgis_process_run(qp_env, block, tmp_path):
    blk, paths = block
    args = [f"{k}={v}" for k, v in _inputs(paths).items()]
    r = subprocess.run(
        [QGIS_PROCESS, "--json", "run", ALG, "--", *args, "AP_MODEL=3",
         f"OUTPUT_EO={tmp_path / 'eo.csv'}", f"OUTPUT_CAMERA={tmp_path / 'cam.json'}",
         f"OUTPUT_POINTS_LAYER={tmp_path / 'pts.gpkg'}",
         f"OUTPUT_RESIDUALS={tmp_path / 'res.csv'}"],
        env=qp_env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    results = json.loads(r.stdout)["results"]
    assert results["MODEL"] == "jacobsen" and 0.8 < results["SIGMA0"] < 1.2
    cam = json.loads((tmp_path / "cam.json").read_text(encoding="utf-8"))
    assert cam["distortion"]["model"] == "jacobsen" and "focal_mm" in cam["sigmas"]
    layer = QgsVectorLayer(str(tmp_path / "pts.gpkg"), "pts", "ogr")
    assert layer.isValid() and layer.featureCount() > 250
    assert len(_rows(tmp_path / "res.csv")) == len(blk.observations)


def _model_outputs(tmp_path):
    return {
        "bundle:eo": str(tmp_path / "eo.csv"),
        "bundle:check_points": str(tmp_path / "check.csv"),
        "bundle:points": "TEMPORARY_OUTPUT",
        "accuracy:report": str(tmp_path / "report.html"),
        "accuracy:check_layer": "TEMPORARY_OUTPUT",
    }


def _check_chain(tmp_path):
    rows = _rows(tmp_path / "check.csv")
    # every AP model's check points, one group per model, ids kept unique
    groups = {r["group"] for r in rows}
    assert len(groups) == 7 and len({r["id"] for r in rows}) == len(rows)
    report = (tmp_path / "report.html").read_text(encoding="utf-8")
    assert all(g in report for g in groups)


def test_model_chains_bundle_and_accuracy_report(provider, block, tmp_path):
    _, paths = block
    model = QgsProcessingModelAlgorithm()
    assert model.fromFile(str(MODEL))
    ok, errors = model.validate()
    assert ok, errors
    assert sorted(c.algorithmId() for c in model.childAlgorithms().values()) == [
        "lidarphoto:accuracyreport",
        "lidarphoto:bundleadjustment",
    ]
    params = {k.lower(): v for k, v in _inputs(paths).items()}
    processing.run(model, {**params, **_model_outputs(tmp_path)})
    _check_chain(tmp_path)


def test_model_in_qgis_process(qp_env, block, tmp_path):
    _, paths = block
    args = [f"{k.lower()}={v}" for k, v in _inputs(paths).items()]
    layers = {"bundle:points": tmp_path / "pts.gpkg", "accuracy:check_layer": tmp_path / "chk.gpkg"}
    outs = [f"{k}={layers.get(k, v)}" for k, v in _model_outputs(tmp_path).items()]
    r = subprocess.run(
        [QGIS_PROCESS, "--json", "run", str(MODEL), "--", *args, *outs],
        env=qp_env, capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    _check_chain(tmp_path)
