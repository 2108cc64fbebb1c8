"""The committed graphical model (.model3) runs in Processing and in qgis_process."""

from __future__ import annotations

import json
import subprocess

import processing
import pytest
from qgis.core import NULL, QgsProcessingModelAlgorithm, QgsVectorLayer
from qgis_helpers import CRS, DATA, QGIS_PROCESS, write_csv

MODEL = DATA / "trajectory_model.model3"
E0, N0 = 500000.0, 7450000.0


def _trajectory(tmp_path):
    return write_csv(
        tmp_path / "traj.csv",
        [f"a,1,L1,{E0},{N0},2400,0,0,0", f"b,2,L1,{E0},{N0 + 250},2400,0,0,0"],
    )


def _load_model() -> QgsProcessingModelAlgorithm:
    model = QgsProcessingModelAlgorithm()
    assert model.fromFile(str(MODEL))
    return model


def test_model_file_is_valid_and_uses_the_algorithm(provider):
    model = _load_model()
    ok, errors = model.validate()
    assert ok, errors
    assert [c.algorithmId() for c in model.childAlgorithms().values()] == [
        "lidarphoto:trajectorytoeo"
    ]
    names = {p.name() for p in model.parameterDefinitions()}
    assert {"trajectory", "crs", "lever_arm", "eo:eo_points", "eo:eo_table"} <= names


def test_model_runs_in_processing(provider, tmp_path):
    out_csv = tmp_path / "eo.csv"
    result = processing.run(
        _load_model(),
        {
            "trajectory": str(_trajectory(tmp_path)),
            "crs": CRS,
            "lever_arm": "0,0,0",
            "eo:eo_points": "TEMPORARY_OUTPUT",
            "eo:eo_table": str(out_csv),
        },
    )
    layer = result["eo:eo_points"]
    if isinstance(layer, str):
        layer = QgsVectorLayer(layer, "eo", "ogr")
    assert layer.featureCount() == 2
    assert sorted(f["Y"] for f in layer.getFeatures()) == pytest.approx([N0, N0 + 250], abs=1e-3)
    assert len(out_csv.read_text(encoding="utf-8").splitlines()) == 3


def test_model_runs_in_qgis_process(qp_env, tmp_path):
    gpkg = tmp_path / "eo.gpkg"
    r = subprocess.run(
        [
            QGIS_PROCESS,
            "--json",
            "run",
            str(MODEL),
            "--",
            f"trajectory={_trajectory(tmp_path)}",
            f"crs={CRS}",
            "lever_arm=0,1,0",
            f"eo:eo_points={gpkg}",
        ],
        env=qp_env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert json.loads(r.stdout)["results"]["eo:eo_points"].startswith(str(gpkg))
    layer = QgsVectorLayer(str(gpkg), "eo", "ogr")
    assert layer.isValid() and layer.featureCount() == 2
    # lever arm 1 m along body y (right wing = east when heading north)
    assert sorted(f["X"] for f in layer.getFeatures()) == pytest.approx([E0 + 1] * 2, abs=0.01)


@pytest.mark.parametrize(
    ("script", "model3"),
    [
        ("make_model", "trajectory_model"),
        ("make_bundle_model", "bundle_accuracy_model"),
        ("make_ground_roof_model", "ground_roof_model"),
        ("make_lidar_control_model", "lidar_control_model"),
        ("make_ortho_model", "ortho_model"),
        ("make_resection_model", "resection_model"),
    ],
)
def test_committed_models_are_what_their_scripts_build(provider, script, model3):
    """Each committed .model3 holds what its make_*.py script builds today (compared as
    QGIS's variant maps: the XML's attribute order is Qt's hash order), so that a changed
    algorithm cannot leave a stale model behind."""
    import importlib

    def plain(v):  # a null QVariant written and read back is an empty string
        if isinstance(v, dict):
            return {k: plain(x) for k, x in v.items()}
        if isinstance(v, list):
            return [plain(x) for x in v]
        return "" if v is None or v == NULL else v

    build = importlib.import_module(script).build_model
    committed = QgsProcessingModelAlgorithm()
    assert committed.fromFile(str(DATA / f"{model3}.model3"))
    assert plain(build().toVariant()) == plain(committed.toVariant())
