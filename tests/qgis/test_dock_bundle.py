"""The Bundle tab of the picking dock in real QGIS: a bundle adjustment of the open images.

Data: the simulated flight of test_image_dock (its fixtures): 6 images, noise-free truth (the
EO of the true trajectory and mount, LCPs at the true roof corners), the measured rows with
0.5 px Gaussian noise (tie, line and lcp rows). The dock is given that EO perturbed by 10 m
and 1 degree (a poor direct georeferencing start, as approximate values): the adjustment must
find the truth from the tie points and the LCPs alone.
"""

# ruff: noqa: F811 - the fixtures block and layers are imported from test_image_dock
from __future__ import annotations

import shutil
from dataclasses import replace

import numpy as np
from lidarphoto.core.io.control import read_lcps_csv
from lidarphoto.core.io.observations import read_observations_csv, write_observations_csv
from lidarphoto.core.io.orientation import read_eo_csv, write_eo_csv
from lidarphoto.core.photo.dock_bundle import DEFAULT_EO_SIGMAS
from qgis.PyQt.QtCore import Qt
from qgis.PyQt.QtTest import QTest
from test_image_dock import _dock, _wait, block, layers  # noqa: F401 - fixtures


def _perturbed_block(block, tmp_path) -> dict:
    truth = read_eo_csv(block["eo"])
    rng = np.random.default_rng(15)
    start = replace(
        truth,
        xyz=truth.xyz + rng.choice([-10.0, 10.0], truth.xyz.shape),
        opk=truth.opk + np.radians(rng.choice([-1.0, 1.0], truth.opk.shape)),
    )
    write_eo_csv(tmp_path / "eo_start.csv", start)
    return {**block, "eo": tmp_path / "eo_start.csv"}


def test_bundle_from_the_dock_recovers_the_orientations(
    qgis_parent, qgis_app, block, layers, tmp_path
):
    """The measured rows in the dock, the EO 10 m / 1 deg off, the LCP table's covariances;
    Bundle (a real click): every adjusted orientation within 4 of its reported sigmas of the
    truth, with the well-determined height and kappa far inside the start's error (sigma_Z <
    3 m, sigma_kappa < 0.2 deg); sigma0 near 1 (0.5 px put in, 0.5 px a priori); the LCPs
    enter with their table's sigmas; the panel shows sigma0, the AP table and one residual
    row per image; every tie and lcp row gets its residual, drawn on the image."""
    shutil.copy(block["dir"] / "measured.csv", tmp_path / "measured.csv")
    dock = _dock(
        qgis_parent, qgis_app, _perturbed_block(block, tmp_path), layers, tmp_path,
        obs_name="measured.csv",
    )  # fmt: skip
    dock.calibration_panel.lcps_csv_edit.setFilePath(str(block["paths"]["lcps"]))
    qgis_app.processEvents()
    rows = list(dock.store.rows)
    assert len(rows) > 300 and {o.type for o in rows} == {"tie", "line", "lcp"}
    panel = dock.bundle_panel
    assert panel.ap_model() == "none" and panel.interior_check.isChecked()
    panel.interior_check.setChecked(False)  # 6 images over a flat town: f would follow Z
    done = []
    dock.bundleFinished.connect(done.append)
    QTest.mouseClick(panel.run_button, Qt.MouseButton.LeftButton)
    assert _wait(qgis_app, lambda: bool(done), 120.0), "the bundle task did not finish"
    assert done == [True], dock.bundle.error
    res = dock.bundle.result
    truth = read_eo_csv(block["eo"])
    assert res.eo.image_id == truth.image_id
    s = res.eo_sigma
    dxyz = res.eo.xyz - truth.xyz
    dopk = (res.eo.opk - truth.opk + np.pi) % (2 * np.pi) - np.pi
    assert np.all(np.abs(dxyz) < 4 * s[:, :3]), (dxyz, s[:, :3])
    assert np.all(np.abs(dopk) < 4 * s[:, 3:]), (np.degrees(dopk), np.degrees(s[:, 3:]))
    assert np.all(s[:, 2] < 3.0) and np.all(np.degrees(s[:, 5]) < 0.2), s
    assert 0.7 < res.adjustment.sigma0 < 1.3
    # measured: within 1.87 sigma; sigma up to 20 m in X, 8 m in Y (X-phi, Y-omega: 6 LCPs
    # on roofs of similar height), 1.5 m in Z, 0.002 deg in kappa; sigma0 0.991; image RMS
    # 0.25-0.46 px per coordinate
    # the LCPs as control with their table's covariance (not the layer's default 2 cm)
    table = {str(c.id): c for c in read_lcps_csv(block["paths"]["lcps"])}
    ground = dock.bundle.inputs.ground
    assert len(ground) == len(table) and set(ground.role) == {"control"}
    for pid, sig in zip(ground.point_id, ground.sigma):
        np.testing.assert_allclose(sig, np.sqrt(np.diag(table[pid[1:]].covariance)))
    assert dock.bundle.inputs.left_out == {"line row(s)": sum(o.type == "line" for o in rows)}
    # shown: sigma0, the AP table, one RMS row per image; residuals on every tie/lcp row
    text = panel.result_label.text()
    assert f"σ0 {res.adjustment.sigma0:.3f}" in text and "<th>parameter</th>" in text
    assert len(res.interior) >= 3 and all(f"<td>{p.name}</td>" in text for p in res.interior)
    for image_id in truth.image_id:
        assert f"<td>{image_id}</td>" in text
    assert set(res.image_rms) == set(truth.image_id)
    rms = np.array(list(res.image_rms.values()))
    assert np.all((rms > 0.2) & (rms < 0.8)), rms  # 0.5 px per coordinate put in
    shown = dock.session.shown_residuals()
    used = {k for k, o in enumerate(rows) if o.type in ("tie", "lcp")}
    assert set(shown) <= used and len(shown) >= len(used) - int(res.rejected.sum())
    assert dock.current_image in truth.image_id
    assert _wait(qgis_app, lambda: dock.viewer.overlays.counts["residuals"] > 0, 10.0)
    dock.close()


def test_bundle_refused_without_a_block(qgis_parent, qgis_app, block, layers, tmp_path):
    """Only line rows: the Bundle button refuses with the reason in the panel."""
    measured = read_observations_csv(block["dir"] / "measured.csv")
    write_observations_csv(tmp_path / "lines.csv", measured.subset(measured.mask("line")))
    dock = _dock(qgis_parent, qgis_app, block, layers, tmp_path, obs_name="lines.csv")
    assert not dock.run_bundle()
    assert "refused" in dock.bundle_panel.result_label.text()
    assert "line row(s)" in dock.bundle_panel.result_label.text()
    dock.close()


def test_bundle_job_error_shown(qgis_parent, qgis_app, block, layers, tmp_path):
    """A block the job refuses (tie points only: no control, no observed EO, no datum) shows
    the job's own error in the panel; nothing raises. With the dock's orientations as
    observations (the checkbox) the same rows adjust, the truth within 4 sigma."""
    measured = read_observations_csv(block["dir"] / "measured.csv")
    write_observations_csv(tmp_path / "ties.csv", measured.subset(measured.mask("tie")))
    dock = _dock(qgis_parent, qgis_app, block, layers, tmp_path, obs_name="ties.csv")
    done = []
    dock.bundleFinished.connect(done.append)
    assert dock.run_bundle(), (dock.bundle.error, len(dock.store.rows), dock.store.path)
    assert _wait(qgis_app, lambda: bool(done), 120.0)
    assert done == [False]
    text = dock.bundle_panel.result_label.text()
    assert text.startswith("Bundle adjustment failed.") and dock.bundle.error in text
    assert dock.bundle.error and dock.bundle.result is None
    assert "the datum needs three or more control points" in dock.bundle.error
    # the dock's (true) orientations as observations give the datum: the same block runs
    dock.bundle_panel.eo_check.setChecked(True)
    done.clear()
    assert dock.run_bundle()
    assert _wait(qgis_app, lambda: bool(done), 120.0)
    assert done == [True], dock.bundle.error
    assert dock.bundle.params["EO_SIGMAS"] == list(DEFAULT_EO_SIGMAS)
    res, truth = dock.bundle.result, read_eo_csv(block["eo"])
    assert np.all(np.abs(res.eo.xyz - truth.xyz) < 4 * res.eo_sigma[:, :3])
    assert np.all(res.eo_sigma[:, :3] <= DEFAULT_EO_SIGMAS[0] + 1e-9)  # never worse than given
    dock.close()
