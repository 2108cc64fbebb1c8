"""qgis_process (the QGIS command line) finds the plugin's provider and runs the algorithm."""

from __future__ import annotations

import json
import subprocess

import pytest
from qgis.core import QgsVectorLayer
from qgis_helpers import ALG, CRS, QGIS_PROCESS, write_csv

E0, N0 = 500000.0, 7450000.0


def _qgis_process(args: list[str], env: dict[str, str]) -> subprocess.CompletedProcess:
    return subprocess.run(
        [QGIS_PROCESS, *args], env=env, capture_output=True, text=True, timeout=300
    )


def test_help_lists_the_parameters(qp_env):
    r = _qgis_process(["help", ALG], qp_env)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    for word in (
        "Trajectory to exterior orientation",
        "INPUT",
        "CRS",
        "LEVER_ARM",
        "MOUNT",
        "MOUNT_MATRIX",
        "BORESIGHT",
        "OUTPUT",
        "OUTPUT_CSV",
        "IMAGE_COUNT",
        "image_top_forward",
    ):
        assert word in r.stdout, word


def test_list_shows_the_provider(qp_env):
    r = _qgis_process(["list"], qp_env)
    assert r.returncode == 0, r.stderr[-2000:]
    assert ALG in r.stdout


def test_run_writes_layer_and_csv(qp_env, tmp_path):
    path = write_csv(
        tmp_path / "traj.csv",
        [f"a,1,L1,{E0},{N0},2400,0,0,0", f"b,2,L1,{E0},{N0 + 250},2400,0,0,0"],
    )
    gpkg, out_csv = tmp_path / "eo.gpkg", tmp_path / "eo.csv"
    r = _qgis_process(
        [
            "--json",
            "run",
            ALG,
            "--",
            f"INPUT={path}",
            f"CRS={CRS}",
            "LEVER_ARM=0,0,0",
            "MOUNT=0",
            "BORESIGHT=0,0,0",
            f"OUTPUT={gpkg}",
            f"OUTPUT_CSV={out_csv}",
        ],
        qp_env,
    )
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    results = json.loads(r.stdout)["results"]
    assert results["IMAGE_COUNT"] == 2
    assert out_csv.read_text(encoding="utf-8").splitlines()[0].startswith("image_id")
    layer = QgsVectorLayer(str(gpkg), "eo", "ogr")
    assert layer.isValid() and layer.featureCount() == 2
    assert layer.crs().authid() == CRS
    ys = sorted(f["Y"] for f in layer.getFeatures())
    assert ys == pytest.approx([N0, N0 + 250], abs=1e-3)


def test_run_bad_csv_fails_with_the_row(qp_env, tmp_path):
    path = write_csv(tmp_path / "bad.csv", [f"a,1,L1,{E0},{N0},2400,0,x,0"])
    r = _qgis_process(
        ["run", ALG, "--", f"INPUT={path}", f"CRS={CRS}", f"OUTPUT={tmp_path / 'o.gpkg'}"], qp_env
    )
    assert r.returncode != 0
    output = r.stdout + r.stderr
    assert "row 2" in output and "pitch" in output
