"""The Calibration tab's *Calibrate automatically* in real QGIS: the boresight of the open
images from image edges along the LiDAR lines, no picked observation.

Data: the rendered block of tests/core/test_auto_boresight.py (its fixtures): 3 hip roofs
ray-cast with texture and occlusion into 4 images of 800 x 600 px through the true boresight
(0.3, -0.2, 0.25 deg) and a POS AV 310-grade noisy trajectory. The dock starts from a boresight
of zero, its lines come from a line layer of the project with the line table's covariances."""

# ruff: noqa: F811 - the fixtures lidar, block and files are imported from test_auto_boresight
from __future__ import annotations

import csv
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from lidarphoto.core.geometry.frames import MappingFrame
from lidarphoto.core.io.observations import read_observations_csv
from lidarphoto.core.io.orientation import read_eo_csv, write_eo_csv
from lidarphoto.core.photo.georeference import direct_georeference
from lidarphoto.core.photo.mount import Mount
from lidarphoto.plugin.image_dock import ImagePickingDock
from qgis.core import QgsFeature, QgsGeometry, QgsLineString, QgsPoint, QgsProject, QgsVectorLayer
from qgis.PyQt.QtCore import Qt
from qgis.PyQt.QtTest import QTest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "core"))
from test_auto_boresight import CRS, TRUTH_DEG, block, files, lidar  # noqa: F401


@pytest.fixture(autouse=True)
def _clean_project(qgis_new_project):
    """The line layer the dock reads is removed afterwards (later tests count the layers)."""
    yield
    QgsProject.instance().removeAllMapLayers()
    QgsProject.instance().layerTreeRoot().removeAllChildren()


def _wait(app, cond, timeout_s: float) -> bool:
    t0 = time.perf_counter()
    while not cond() and time.perf_counter() - t0 < timeout_s:
        QTest.qWait(20)
    return cond()


def _lines_layer(lines) -> QgsVectorLayer:
    layer = QgsVectorLayer(f"LineStringZ?crs={CRS}&field=id:integer", "ridge lines", "memory")
    feats = []
    for ln in lines:
        f = QgsFeature(layer.fields())
        f.setGeometry(QgsGeometry(QgsLineString([QgsPoint(*map(float, ln.start)),
                                                 QgsPoint(*map(float, ln.end))])))  # fmt: skip
        f.setAttribute("id", int(ln.id))
        feats.append(f)
    assert layer.dataProvider().addFeatures(feats)
    return layer


def _open_dock(qgis_parent, qgis_app, block, files, tmp_path, trajectory=True):
    """The dock on the block: camera, the direct georeferencing EO of boresight zero, the
    images, the line layer (and its table), the trajectory and mount of the Calibration tab."""
    folder, inputs = files
    _cam, _frame, _true_eo, traj, _images, _planes, lines, _dsm = block
    eo0 = direct_georeference(traj, Mount.from_parameters(), MappingFrame.from_user_input(CRS))
    write_eo_csv(tmp_path / "eo_start.csv", eo0)
    layer = _lines_layer(lines)
    QgsProject.instance().addMapLayer(layer)
    dock = ImagePickingDock(None, qgis_parent)
    dock.resize(900, 900)
    dock.show()
    QTest.qWaitForWindowExposed(dock, 2000)
    dock.project_panel.lines_combo.setLayer(layer)
    dock.set_project_files(camera=inputs["CAMERA"], eo=str(tmp_path / "eo_start.csv"), crs=CRS,
                           images=sorted(str(p) for p in (folder / "images").iterdir()),
                           observations=str(tmp_path / "obs.csv"))  # fmt: skip
    panel = dock.calibration_panel
    panel.lines_csv_edit.setFilePath(inputs["LINES"])
    if trajectory:
        panel.trajectory_edit.setFilePath(inputs["TRAJECTORY"])
    panel.boresight_edit.setText("0,0,0")
    qgis_app.processEvents()
    return dock


def test_calibrate_automatically_recovers_the_boresight(qgis_parent, qgis_app, qgis_new_project,
                                                        block, files, tmp_path):  # fmt: skip
    """A real click on *Calibrate automatically*: one run at a time, the task finishes, every
    angle within 3 of its sigmas of the truth, line observations found in every image and
    written, the panel shows the counts, and the dock draws with the calibrated orientation
    (its file in the Project tab); the user's observations are left alone."""
    dock = _open_dock(qgis_parent, qgis_app, block, files, tmp_path)
    panel = dock.calibration_panel
    assert panel.auto_button.isEnabled() and dock.store.rows == []
    done = []
    dock.autoCalibrationFinished.connect(done.append)
    QTest.mouseClick(panel.auto_button, Qt.MouseButton.LeftButton)
    assert not panel.auto_button.isEnabled() and not panel.run_button.isEnabled()
    assert _wait(qgis_app, lambda: bool(done), 300.0), "the automatic calibration did not finish"
    assert done == [True], panel.result_label.text()
    params = dock.auto_calibration.params
    rows = list(csv.DictReader(open(params["OUTPUT_TABLE"], encoding="utf-8")))
    assert len(rows) >= 1
    for row in rows:
        got = np.array([float(row[f"d_{a}_deg"]) for a in ("omega", "phi", "kappa")])
        std = np.array([float(row[f"std_d_{a}_arcsec"]) for a in ("omega", "phi", "kappa")])
        assert np.all(np.abs(got - TRUTH_DEG) * 3600 < 3 * std), ((got - TRUTH_DEG) * 3600, std)
    found = read_observations_csv(params["OUTPUT_OBSERVATIONS"])
    assert set(found.type) == {"line"} and len(found) >= 200
    assert set(found.image_id) == {"a", "b", "c", "d"}
    assert "line points" in panel.result_label.text() and panel.auto_button.isEnabled()
    assert dock.project_panel.eo_edit.filePath() == params["OUTPUT_EO"]
    eo = read_eo_csv(params["OUTPUT_EO"])
    # shown with the calibration (the file holds degrees: radians back to 1e-18)
    np.testing.assert_allclose(dock.session.eo.opk, eo.opk, rtol=0, atol=1e-15)
    assert dock.store.rows == []
    dock.close()


def test_calibrate_automatically_names_what_is_missing(qgis_parent, qgis_app, qgis_new_project,
                                                       block, files, tmp_path):  # fmt: skip
    """No trajectory: nothing starts, and the message names it."""
    dock = _open_dock(qgis_parent, qgis_app, block, files, tmp_path, trajectory=False)
    assert not dock.auto_calibration.run()
    assert "a trajectory" in dock.messages[-1] and not dock.auto_calibration.running
    dock.close()
