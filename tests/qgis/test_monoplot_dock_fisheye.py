"""The dock's monoplot and footprint with a fisheye camera, in real QGIS.

Data: the equisolid fisheye project of test_dock_fisheye (f 3 mm, 2000 x 1500 px of 3 um,
Brown k1, 150 m up, noise-free EO), and a DSM GeoTIFF of a tilted plane under the block
(slopes 1:4 east and 1:8 north, heights exact in float32, so that the bilinear surface is the
plane). Truth: points on that plane projected into an image by the picking scene's chain
(the fisheye projection and its lens), then picked in the dock with the Monoplot button on:
the points on the map within 1e-6 m of the truth (measured 5.5e-7 m); the footprint on the
canvas is the fisheye's curved outline (256 vertices), each on the border of the image within
0.01 px (measured 1.8e-8 px).
"""

from __future__ import annotations

import numpy as np
from lidarphoto.core.geometry.grid import Grid
from lidarphoto.core.geometry.surface import Dsm
from lidarphoto.core.io.dsm import write_dsm
from lidarphoto.core.photo.picking import FOOTPRINT_BORDER_POINTS
from lidarphoto.core.photo.tie_pairs import _border
from qgis.core import QgsProject
from test_dock_fisheye import FISHEYE, fisheye_block, fisheye_layers  # noqa: F401
from test_image_dock import _dock

SLOPE_E, SLOPE_N = 0.25, -0.125  # m per m; heights at cell centres multiples of 1/8 m


def _tilted_dsm(centre_xy: np.ndarray, ground: float) -> Dsm:
    cols = rows = 1200
    grid = Grid(float(np.floor(centre_xy[0])) - 600.0, float(np.floor(centre_xy[1])) + 600.0,
                1.0, rows, cols)  # fmt: skip
    r, c = np.mgrid[0:rows, 0:cols]
    z = np.round(ground) + SLOPE_E * (c - 600) - SLOPE_N * (r - 600)
    return Dsm(z.astype(np.float32), grid)


def _plane(dsm: Dsm, xy: np.ndarray) -> np.ndarray:
    x0, y0 = dsm.centre_origin
    col = (xy[:, 0] - x0) / dsm.cell
    row = (y0 - xy[:, 1]) / dsm.cell
    return float(dsm.heights[0, 0]) + SLOPE_E * col - SLOPE_N * row


def test_fisheye_monoplot_and_footprint_in_the_dock(qgis_parent, qgis_app, qgis_iface,
                                                    fisheye_block, fisheye_layers,  # noqa: F811
                                                    tmp_path):  # fmt: skip
    b = fisheye_block
    dock = _dock(qgis_parent, qgis_app, b, fisheye_layers, tmp_path, iface=qgis_iface)
    assert dock.camera is not None and dock.camera.projection == "equisolid"
    image = b["sim"].trajectory.image_id[1]
    dock.show_image(image)
    qgis_app.processEvents()
    # ---- footprint: the curved outline, every vertex on the image border
    fp = dock.footprint()
    border = _border(FISHEYE.width_px, FISHEYE.height_px, FOOTPRINT_BORDER_POINTS)
    assert fp.shape == (len(border), 3) and np.isfinite(fp).all()
    back = dock.scene_geometry.project(image, fp)
    assert np.hypot(*(back - border).T).max() < 0.01
    band = dock.canvas_footprint.rubber_band
    assert band is not None and band.numberOfVertices() >= len(border)
    # ---- monoplot on the tilted plane
    k = dock.eo.image_id.index(image)
    ground = float(dock.session.control.ground_height())
    dsm = _tilted_dsm(dock.eo.xyz[k, :2], ground)
    write_dsm(tmp_path / "plane.tif", dsm)
    rng = np.random.default_rng(3)
    xy = dock.eo.xyz[k, :2] + rng.uniform(-150.0, 150.0, (60, 2))
    truth = np.column_stack([xy, _plane(dsm, xy)])
    pixels = dock.scene_geometry.project(image, truth)
    keep = np.isfinite(pixels).all(axis=1) & FISHEYE.in_frame(pixels, 2.0)
    truth, pixels = truth[keep][:20], pixels[keep][:20]
    assert len(pixels) >= 10
    r = np.hypot(*FISHEYE.ideal_from_pixel(pixels).T)
    assert r.max() > 0.5 * FISHEYE.focal_mm  # far off the axis
    dock.project_panel.dsm_edit.setFilePath(str(tmp_path / "plane.tif"))
    dock.viewer.monoplot_button.click()
    assert dock.viewer.monoplot_button.isChecked(), dock.messages[-3:]
    for px in pixels:
        dock.view.pointPicked.emit(*map(float, px))
    layer = dock.monoplot_tool.points_layer
    assert layer is not None and QgsProject.instance().mapLayer(layer.id()) is layer
    feats = list(layer.getFeatures())
    assert len(feats) == len(pixels)
    got = np.array([[f.geometry().constGet().x(), f.geometry().constGet().y(),
                     f.geometry().constGet().z()] for f in feats])  # fmt: skip
    err = np.linalg.norm(got - truth, axis=1)
    assert err.max() < 1e-6, err.max()
    assert {f["status_text"] for f in feats} == {"ok"}
    dock.close()


def test_fisheye_boresight_calibration_from_the_dock(qgis_parent, qgis_app, provider,
                                                     fisheye_block, fisheye_layers,  # noqa: F811
                                                     tmp_path):  # fmt: skip
    """The dock's Run (boresightcalibration through Processing) with the equisolid camera:
    the simulated block's tie, line and LCP rows with 0.5 px of noise added (the INS
    noise-free): every angle within 3 sigma (+0.5 arc-second) of the truth, the residual
    RMS about the noise put in (measured: within 0.76 sigma, sigma0 1.011, residuals 0.575 px
    RMS)."""
    import csv

    from lidarphoto.core.io.observations import write_observations_csv
    from lidarphoto.core.photo.boresight_setup import ARCSEC
    from qgis.PyQt.QtCore import Qt
    from qgis.PyQt.QtTest import QTest
    from test_image_dock import _wait

    b, sim = fisheye_block, fisheye_block["sim"]
    o = sim.observations
    rng = np.random.default_rng(8)
    noisy = type(o)(o.image_id, o.point_id, o.pixels + rng.normal(0, 0.5, o.pixels.shape),
                    o.sigma_px, o.type, o.target_id)  # fmt: skip
    write_observations_csv(tmp_path / "measured.csv", noisy)
    dock = _dock(qgis_parent, qgis_app, b, fisheye_layers, tmp_path, obs_name="measured.csv")
    paths = b["paths"]
    panel = dock.calibration_panel
    panel.trajectory_edit.setFilePath(str(paths["trajectory"]))
    panel.lever_edit.setText(",".join(repr(float(v)) for v in sim.mount.lever_arm))
    panel.planes_csv_edit.setFilePath(str(paths["planes"]))
    panel.lines_csv_edit.setFilePath(str(paths["lines"]))
    panel.lcps_csv_edit.setFilePath(str(paths["lcps"]))
    done: list = []
    dock.calibrationFinished.connect(done.append)
    QTest.mouseClick(panel.run_button, Qt.MouseButton.LeftButton)
    assert _wait(qgis_app, lambda: bool(done), 120.0), "the calibration task did not finish"
    assert done == [True], panel.result_label.text()
    with open(dock.calibration.params["OUTPUT_TABLE"], encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert rows
    for row in rows:
        true = sim.truth.boresight[row["group"]] / ARCSEC
        for k, angle in enumerate(("omega", "phi", "kappa")):
            est, sd = float(row[f"d_{angle}_arcsec"]), float(row[f"std_d_{angle}_arcsec"])
            assert abs(est - true[k]) < 3 * sd + 0.5, (angle, est, true[k], sd)
    v = np.array([np.hypot(*x) for x in dock.session.residuals().values() if np.isfinite(x).all()])
    assert v.size > 50
    assert 0.2 < float(np.sqrt(np.mean(v**2))) < 1.2
    dock.close()
