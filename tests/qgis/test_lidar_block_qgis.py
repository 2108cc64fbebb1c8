"""lidarphoto:lidarblock in real QGIS: processing.run on a folder of tiles (a thread
LocalCluster inside QGIS), progress and cancel through the feedback, and qgis_process (which
must exit: the cluster is closed)."""

from __future__ import annotations

import json
import subprocess

import laspy
import numpy as np
import processing
import pytest
from qgis.core import QgsProcessingException, QgsProcessingFeedback
from qgis_helpers import QGIS_PROCESS

pytest.importorskip("distributed")

ALG = "lidarphoto:lidarblock"


@pytest.fixture()
def tiles(tmp_path):
    from lidarphoto.core.simulation.block import town_tiles

    xyz, _, files = town_tiles(tmp_path / "tiles", 60.0, n_buildings=4, n_trees=2,
                               density=4.0)  # fmt: skip
    return tmp_path / "tiles", len(xyz), files


class _Feedback(QgsProcessingFeedback):
    def __init__(self, cancel_at: float | None = None):
        super().__init__()
        self.seen: list[float] = []
        self.cancel_at = cancel_at

    def setProgress(self, value):
        self.seen.append(value)
        if self.cancel_at is not None and value >= self.cancel_at:
            self.cancel()
        super().setProgress(value)


def test_processing_run_on_a_folder_of_tiles(provider, tiles, tmp_path):
    folder, n, files = tiles
    alg = provider.algorithm("lidarblock")
    assert alg.canExecute()[0]
    feedback = _Feedback()
    out = tmp_path / "out"
    result = processing.run(ALG, {"INPUT": str(folder), "OUTPUT_FOLDER": str(out),
                                  "WORKERS": 2, "LOCAL_CLUSTER": 2}, feedback=feedback)  # fmt: skip
    assert result["COMPLETE"] == 1 and result["FAILED_TILES"] == 0
    assert result["POINT_COUNT"] == n and result["TILE_COUNT"] == len(files)
    ids = np.concatenate(
        [np.asarray(laspy.read(f).gps_time) for f in (out / "tiles").glob("*.laz")]
    )
    assert np.array_equal(np.sort(ids).astype(np.int64), np.arange(n))
    assert result["PLANE_COUNT"] >= 8  # 4 buildings, most with 2-4 faces
    report = json.loads((out / "block_report.json").read_text())
    assert report["complete"] and len(report["tiles"]) == len(files)
    assert feedback.seen and max(feedback.seen) == pytest.approx(100.0)
    vpc = json.loads((out / "block.vpc").read_text())
    assert sum(f["properties"]["pc:count"] for f in vpc["features"]) == n


def test_cancel_in_qgis_writes_nothing(provider, tiles, tmp_path):
    folder, _, _ = tiles
    out = tmp_path / "out"
    with pytest.raises(QgsProcessingException):
        processing.run(ALG, {"INPUT": str(folder), "OUTPUT_FOLDER": str(out), "WORKERS": 1,
                             "LOCAL_CLUSTER": 2},
                       feedback=_Feedback(cancel_at=0.0))  # fmt: skip
    assert not out.exists()


def test_qgis_process_runs_and_exits(qp_env, tiles, tmp_path):
    folder, n, _ = tiles
    out = tmp_path / "out"
    r = subprocess.run(
        [QGIS_PROCESS, "--json", "run", ALG, "--", f"INPUT={folder}", f"OUTPUT_FOLDER={out}",
         "WORKERS=2"],
        env=qp_env, capture_output=True, text=True, timeout=240,
    )  # fmt: skip
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    results = json.loads(r.stdout)["results"]
    assert results["POINT_COUNT"] == n and results["COMPLETE"] == 1
