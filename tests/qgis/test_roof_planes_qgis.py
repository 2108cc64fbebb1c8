"""lidarphoto:extractroofplanes in real QGIS: processing.run, qgis_process.bin, the
ground filter -> roof planes model, outputs and errors, on the AHN3 Delft crop."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import laspy
import numpy as np
import processing
import pytest
from qgis.core import QgsProcessingException, QgsProcessingModelAlgorithm, QgsVectorLayer
from qgis_helpers import DATA, QGIS_PROCESS, ROOT

ALG = "lidarphoto:extractroofplanes"
AHN3 = Path(ROOT) / "tests" / "data" / "ahn3" / "ahn3_delft_crop60.laz"
MODEL = DATA / "ground_roof_model.model3"


def _check_outputs(layer, csv_path: Path, cloud_path: Path | None = None):
    from lidarphoto.core.io.planes import read_planes_csv

    planes = read_planes_csv(csv_path)
    assert len(planes) > 30
    assert layer.featureCount() == len(planes)
    feats = {f["id"]: f for f in layer.getFeatures()}
    for p in planes[:5]:
        f = feats[p.id]
        assert f["n_points"] == p.n_points
        assert f["d"] == pytest.approx(p.d) and f["cov_dd"] == pytest.approx(p.covariance[3, 3])
        geom = f.geometry()
        assert geom.constGet().is3D() and geom.area() > 1.0
        # the outline's vertices lie on the plane
        for v in geom.vertices():
            assert abs(p.normal @ [v.x(), v.y(), v.z()] + p.d) < 1e-3
    if cloud_path is not None:
        las = laspy.read(str(cloud_path))
        pid = np.asarray(las.plane_id)
        assert set(np.unique(pid)) == {-1, *range(len(planes))}
        cls = np.asarray(las.classification)
        assert np.mean(cls[pid >= 0] == 6) > 0.9  # plane points are the producer's buildings
    return planes


def test_parameters_and_outputs(provider):
    alg = provider.algorithm("extractroofplanes")
    assert alg.id() == ALG and alg.groupId() == "lidar"
    names = {p.name() for p in alg.parameterDefinitions()}
    assert {"INPUT", "CRS", "DISTANCE_UNIT", "POINTS", "CLASSES", "K_NEIGHBOURS", "EPSILON",
            "MIN_SUPPORT", "MIN_SLOPE", "MAX_SLOPE", "MIN_PLANE_POINTS", "SEED", "OUTPUT",
            "OUTPUT_CSV", "OUTPUT_CLOUD"} <= names  # fmt: skip
    assert {o.name() for o in alg.outputDefinitions()} >= {"OUTPUT", "PLANE_COUNT", "UNIT"}


def test_processing_run_writes_layer_table_and_cloud(provider, tmp_path):
    csv_path, cloud = tmp_path / "planes.csv", tmp_path / "planes.laz"
    result = processing.run(
        ALG,
        {
            "INPUT": str(AHN3),
            "OUTPUT": "TEMPORARY_OUTPUT",
            "OUTPUT_CSV": str(csv_path),
            "OUTPUT_CLOUD": str(cloud),
        },
    )
    layer = result["OUTPUT"]
    if isinstance(layer, str):
        layer = QgsVectorLayer(layer, "planes", "ogr")
    assert result["UNIT"] == "metre"
    planes = _check_outputs(layer, csv_path, cloud)
    assert result["PLANE_COUNT"] == len(planes)
    assert "Amersfoort" in layer.crs().toWkt() or layer.crs().authid() in (
        "EPSG:7415",
        "EPSG:28992",
    )


def test_processing_bad_input_raises_and_leaves_nothing(provider, tmp_path):
    csv_path = tmp_path / "planes.csv"
    with pytest.raises(QgsProcessingException, match="no point"):
        processing.run(
            ALG,
            {
                "INPUT": str(AHN3),
                "POINTS": 1,
                "CLASSES": "17",
                "OUTPUT": "TEMPORARY_OUTPUT",
                "OUTPUT_CSV": str(csv_path),
            },
        )
    with pytest.raises(QgsProcessingException, match="MIN_SUPPORT"):
        processing.run(
            ALG,
            {
                "INPUT": str(AHN3),
                "MIN_SUPPORT": 40,
                "OUTPUT": "TEMPORARY_OUTPUT",
                "OUTPUT_CSV": str(csv_path),
            },
        )
    assert not csv_path.exists()


def _qgis_process(args, env):
    return subprocess.run(
        [QGIS_PROCESS, *args], env=env, capture_output=True, text=True, timeout=600
    )


def test_qgis_process_runs_the_algorithm(qp_env, tmp_path):
    gpkg, csv_path = tmp_path / "planes.gpkg", tmp_path / "planes.csv"
    r = _qgis_process(
        [
            "--json",
            "run",
            ALG,
            "--",
            f"INPUT={AHN3}",
            "DISTANCE_UNIT=1",
            "EPSILON=0.15",
            f"OUTPUT={gpkg}",
            f"OUTPUT_CSV={csv_path}",
        ],
        qp_env,
    )
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    results = json.loads(r.stdout)["results"]
    layer = QgsVectorLayer(str(gpkg), "planes", "ogr")
    assert layer.isValid()
    planes = _check_outputs(layer, csv_path)
    assert results["PLANE_COUNT"] == len(planes) and results["UNIT"] == "metre"


def test_qgis_process_bad_file_fails_clearly(qp_env, tmp_path):
    bad = tmp_path / "corrupt.laz"
    bad.write_bytes(AHN3.read_bytes()[:5000])
    r = _qgis_process(
        [
            "run",
            ALG,
            "--",
            f"INPUT={bad}",
            f"OUTPUT={tmp_path / 'o.gpkg'}",
            f"OUTPUT_CSV={tmp_path / 'o.csv'}",
        ],
        qp_env,
    )
    assert r.returncode != 0
    assert "corrupt.laz" in r.stdout + r.stderr
    assert not (tmp_path / "o.csv").exists()


def _load_model() -> QgsProcessingModelAlgorithm:
    model = QgsProcessingModelAlgorithm()
    assert model.fromFile(str(MODEL))
    return model


def test_model_chains_ground_filter_and_roof_planes(provider, tmp_path):
    model = _load_model()
    ok, errors = model.validate()
    assert ok, errors
    assert sorted(c.algorithmId() for c in model.childAlgorithms().values()) == [
        "lidarphoto:extractroofplanes",
        "lidarphoto:groundfilter",
    ]
    csv_path, cloud = tmp_path / "planes.csv", tmp_path / "ground.laz"
    result = processing.run(
        model,
        {
            "cloud": str(AHN3),
            "epsilon": 0.15,
            "roofs:roof_planes": "TEMPORARY_OUTPUT",
            "roofs:plane_table": str(csv_path),
            "ground:classified_cloud": str(cloud),
        },
    )
    layer = result["roofs:roof_planes"]
    if isinstance(layer, str):
        layer = QgsVectorLayer(layer, "planes", "ogr")
    _check_outputs(layer, csv_path)
    assert cloud.exists()


def test_model_runs_in_qgis_process(qp_env, tmp_path):
    gpkg, csv_path = tmp_path / "planes.gpkg", tmp_path / "planes.csv"
    r = _qgis_process(
        [
            "--json",
            "run",
            str(MODEL),
            "--",
            f"cloud={AHN3}",
            "epsilon=0.15",
            f"roofs:roof_planes={gpkg}",
            f"roofs:plane_table={csv_path}",
            f"ground:classified_cloud={tmp_path / 'ground.laz'}",
        ],
        qp_env,
    )
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    layer = QgsVectorLayer(str(gpkg), "planes", "ogr")
    assert layer.isValid()
    _check_outputs(layer, csv_path)
