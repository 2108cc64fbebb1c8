"""The demo's user story in real QGIS: a reduced ``make demo`` (4 images at half resolution) ->
scripts/make_demo_project.py -> QgsProject.read -> the picking dock restores the session ->
clicks on rendered roofs (a plane-constrained tie point with its prediction in a second image, an
LCP) -> autosave -> close, re-read, reopen: the observations are back -> calibration from the
dock -> residuals; and a screenshot of the dock (tests/qgis/output/demo_dock.png).

Truth: the simulation's true orientation (flight/eo_true.csv, what the images are rendered
with) through the project's collinearity chain (core.picking.PickingScene); the dock itself is
given the INS orientation with the boresight not yet calibrated, as a user has it.
"""

from __future__ import annotations

import csv
import importlib.util
import math
import sys
import time
from pathlib import Path

import cv2
import numpy as np
import pytest
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.frames import MappingFrame
from lidarphoto.core.io.observations import read_observations_csv
from lidarphoto.core.io.orientation import read_eo_csv, write_eo_csv
from lidarphoto.core.photo.georeference import direct_georeference
from lidarphoto.core.photo.picking import PickingScene
from lidarphoto.core.simulation.render import render_image
from lidarphoto.core.simulation.render_scene import RenderOptions, RenderScene
from lidarphoto.plugin.image_dock import ImagePickingDock
from qgis.core import QgsProject
from qgis.PyQt.QtCore import QPoint, QPointF, Qt
from qgis.PyQt.QtTest import QTest
from qgis.PyQt.QtWidgets import QSplitter

ROOT = Path(__file__).resolve().parents[2]
OUTPUT = Path(__file__).resolve().parent / "output"
CRS = "EPSG:28992"
ARCSEC = np.pi / (180.0 * 3600.0)
HALF = Camera("small format 35 mm, half resolution", focal_mm=35.0, pixel_size_mm=0.009,
              width_px=3000, height_px=2000)  # fmt: skip


def _load(name: str, path: Path):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


DEMO = _load("lidarphoto_demo_script", ROOT / "scripts" / "demo.py")
MAKE = _load("lidarphoto_make_demo_project", ROOT / "scripts" / "make_demo_project.py")


def _wait(app, cond, timeout_s=120.0) -> bool:
    t0 = time.perf_counter()
    while not cond() and time.perf_counter() - t0 < timeout_s:
        QTest.qWait(20)
        app.processEvents()
    return cond()


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    """The reduced demo: the real tile through the command line, a 4-image flight of a 6-Mpx
    camera, the images rendered, the initial (INS) orientation."""
    out = tmp_path_factory.mktemp("demo")
    t0 = time.perf_counter()
    lidar = DEMO.lidar_step(out / "lidar")
    sim, paths, eo_true = DEMO.flight_step(lidar, out / "flight", camera=HALF, images_per_line=2)
    figures = DEMO.render_step(lidar, sim, eo_true, out / "flight" / "images")
    DEMO.ortho_step(out, out / "flight" / "eo_true.csv", gsd=0.1)  # no calibration here
    (out / "calibration").mkdir()
    initial = direct_georeference(sim.trajectory, sim.mount, MappingFrame.from_user_input(CRS))
    write_eo_csv(out / "calibration" / "eo_initial.csv", initial)
    build_s = time.perf_counter() - t0
    print(f"\nreduced demo built in {build_s:.1f} s; rendering {figures}")
    return {"out": out, "lidar": lidar, "sim": sim, "paths": paths, "eo_true": eo_true,
            "figures": figures, "build_s": build_s}  # fmt: skip


def _deep_pixel(labels: np.ndarray, plane_id: int) -> tuple[np.ndarray, float]:
    """The pixel (col, row centre) of a plane's rendered region farthest from its edges."""
    mask = (labels == plane_id).astype(np.uint8)
    dist = cv2.distanceTransform(mask, cv2.DIST_L2, 5)
    r, c = np.unravel_index(int(np.argmax(dist)), dist.shape)
    return np.array([c + 0.5, r + 0.5]), float(dist[r, c])


def _click(view, app, pixel, zoom=None) -> QPointF:
    """Left click on the screen pixel that shows the image point ``pixel`` (centred at
    ``zoom`` if given); returns the scene position of that screen pixel's centre."""
    if zoom is not None:
        view.set_zoom(zoom, QPointF(*pixel))
    app.processEvents()
    at = view.viewportTransform().map(QPointF(*pixel))
    pos = QPoint(math.floor(at.x()), math.floor(at.y()))
    QTest.mouseClick(view.viewport(), Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier,
                     pos)  # fmt: skip
    return view._scene_f(QPointF(pos) + QPointF(0.5, 0.5))


def test_demo_project_user_story(demo, qgis_app, qgis_parent, qgis_new_project, provider):
    out, sim, lidar = demo["out"], demo["sim"], demo["lidar"]
    figures = demo["figures"]
    # the rendered ridges/valleys lie on the projected LiDAR lines (true orientation)
    assert figures["edge_profiles"] >= 100 and figures["edge_within_1px"] > 0.9
    assert figures["edge_offset_median_px"] <= 0.5

    # ---- the project, written by the script, read by QGIS
    t0 = time.perf_counter()
    path = MAKE.build_project(out)
    project = QgsProject.instance()
    assert project.read(str(path))
    layers = {lyr.name(): lyr for lyr in project.mapLayers().values()}
    for name in ("Roof planes", "LiDAR lines", "LiDAR control points", "Check points (truth)"):
        assert layers[name].isValid() and layers[name].providerType() == "ogr"
        assert str(out / "demo_layers.gpkg") in layers[name].source()
    assert layers["Roof planes"].featureCount() == len(lidar.planes)
    assert layers["LiDAR lines"].featureCount() == len(lidar.lines)
    dsm = layers["DSM 0.5 m (highest return)"]
    assert dsm.isValid() and dsm.crs().authid() == CRS
    mosaic = layers["Orthomosaic (true orthophotos)"]
    assert mosaic.isValid() and mosaic.crs().authid() == CRS
    assert mosaic.renderer().type() == "multibandcolor" and mosaic.renderer().alphaBand() == 4
    assert layers["Orthomosaic seamlines"].featureCount() == len(sim.trajectory.image_id)

    # ---- the dock restores the session
    dock = ImagePickingDock(None, qgis_parent)
    dock.choose_candidate = lambda cands, labels: cands[0]
    dock.resize(1000, 950)
    dock.show()
    QTest.qWaitForWindowExposed(dock, 2000)
    assert dock.wait_restored()  # (the files are read in steps, QGIS responsive between)
    ids = list(sim.trajectory.image_id)
    assert [
        dock.viewer.image_combo.itemData(k) for k in range(dock.viewer.image_combo.count())
    ] == ids
    assert all(dock.image_status(i) == "ok" for i in ids)  # file on disk and orientation
    assert dock.project_panel.planes_combo.currentLayer() is layers["Roof planes"]
    assert dock.project_panel.lines_combo.currentLayer() is layers["LiDAR lines"]
    assert dock.project_panel.lcps_combo.currentLayer() is layers["LiDAR control points"]
    assert dock.project_panel.dsm_combo.currentLayer() is dsm
    assert dock.project_panel.eo_edit.filePath() == str(out / "calibration" / "eo_initial.csv")
    simulated = [o for o in read_observations_csv(demo["paths"]["observations"]).type
                 if o in ("tie", "line", "lcp")]  # fmt: skip
    n0 = len(dock.store.rows)
    assert n0 == len(simulated) and dock.store.path == out / "picking" / "observations.csv"
    assert dock.viewer.overlays.counts["planes"] >= 10
    restore_s = time.perf_counter() - t0

    # ---- a tie point on a rendered roof, predicted in a second image, corrected there
    eo_true = demo["eo_true"]
    truth = PickingScene(eo_true, HALF, CRS)
    scene = RenderScene.build(DEMO.dsm_from_las(lidar.folder / "planes.laz", 0.5, crs=CRS),
                              lidar.xyz, lidar.classification, lidar.plane_id, lidar.planes,
                              lidar.lines, crs=CRS)  # fmt: skip
    a, b = ids[0], ids[1]
    k = ids.index(a)
    rendered = render_image(scene, HALF, eo_true.xyz[k], eo_true.opk[k],
                            DEMO._with_seed(RenderOptions(), k))  # fmt: skip
    on_disk = cv2.cvtColor(cv2.imread(str(out / "flight" / "images" / f"{a}.tif")),
                           cv2.COLOR_BGR2RGB)  # fmt: skip
    np.testing.assert_array_equal(on_disk, rendered.rgb)  # the file is that rendering
    planes = {int(p.id): p for p in lidar.planes}
    best = max(planes, key=lambda pid: _deep_pixel(rendered.plane_id, pid)[1])
    pixel, depth = _deep_pixel(rendered.plane_id, best)
    assert depth > 60  # px: deeper than the offset of the uncalibrated overlays
    dock.show_image(a)
    dock.viewer.type_combo.setCurrentText("tie")
    got = _click(dock.view, qgis_app, pixel, zoom=1.0)
    tie = dock.store.rows[-1]
    assert (tie.image_id, tie.type, tie.target_id) == (a, "tie", str(best))
    assert (tie.col, tie.row) == pytest.approx((got.x(), got.y()), abs=1e-9)
    assert np.abs([tie.col - pixel[0], tie.row - pixel[1]]).max() <= 0.5  # 1 screen px
    assert rendered.plane_id[int(tie.row), int(tie.col)] == best  # on the rendered roof
    plane = planes[best]
    true_b = truth.predict_tie(a, (tie.col, tie.row), plane.normal, plane.centroid)[b]
    pred_b = dock.session.pending.pixels[b]
    miss_px = math.hypot(*(np.asarray(pred_b) - true_b))
    assert miss_px < 60  # the uncalibrated boresight: the user corrects the prediction
    dock.show_image(b)
    assert dock.viewer.overlays.counts["predictions"] == 1
    got = _click(dock.view, qgis_app, true_b, zoom=1.0)
    tie_b = dock.store.rows[-1]
    assert (tie_b.image_id, tie_b.point_id, tie_b.target_id) == (b, tie.point_id, str(best))
    assert np.abs([tie_b.col - true_b[0], tie_b.row - true_b[1]]).max() <= 0.5

    # ---- an LCP at its true projection (fit zoom: the dock looks within 10 screen px)
    lcp = next(c for c in lidar.lcps if HALF.in_frame(truth.project(a, [c.xyz]), 100)[0])
    true_px = truth.project(a, [lcp.xyz])[0]
    win = rendered.plane_id[int(true_px[1]) - 3 : int(true_px[1]) + 4,
                            int(true_px[0]) - 3 : int(true_px[0]) + 4]  # fmt: skip
    assert len(set(lcp.plane_ids) & set(np.unique(win).tolist())) >= 2  # a rendered corner
    dock.show_image(a)
    dock.view.fit()
    dock.viewer.type_combo.setCurrentText("lcp")
    _click(dock.view, qgis_app, true_px)
    c_obs = dock.store.rows[-1]
    assert (c_obs.type, c_obs.target_id) == ("lcp", str(lcp.id))
    assert np.abs([c_obs.col - true_px[0], c_obs.row - true_px[1]]).max() <= 0.5 / dock.view.zoom

    # ---- autosaved; close, read the project again, reopen: everything is back
    assert len(read_observations_csv(dock.store.path)) == n0 + 3
    rows = list(dock.store.rows)
    dock.close()
    assert project.read(str(path))
    dock = ImagePickingDock(None, qgis_parent)
    dock.resize(1000, 1280)
    dock.show()
    QTest.qWaitForWindowExposed(dock, 2000)
    assert dock.wait_restored()
    assert dock.store.rows == rows
    assert dock.current_image == a and dock.source is not None

    # ---- calibration from the dock: the simulated measurements and the clicks
    done = []
    dock.calibrationFinished.connect(done.append)
    t1 = time.perf_counter()
    assert dock.run_calibration()
    assert _wait(qgis_app, lambda: bool(done)), "the calibration task did not finish"
    calib_s = time.perf_counter() - t1
    assert done == [True], dock.calibration_panel.result_label.text()
    with open(dock.calibration.params["OUTPUT_TABLE"], encoding="utf-8") as fh:
        table = list(csv.DictReader(fh))
    assert {r["group"] for r in table} == set(sim.truth.groups)
    for row in table:
        true = sim.truth.boresight[row["group"]] / ARCSEC
        for j, angle in enumerate(("omega", "phi", "kappa")):
            est, sd = float(row[f"d_{angle}_arcsec"]), float(row[f"std_d_{angle}_arcsec"])
            assert abs(est - true[j]) < 3.5 * sd, (row["group"], angle, est, true[j], sd)
    assert "RMS" in dock.calibration_panel.result_label.text()
    assert len(dock.session.residuals()) > 0.9 * len(rows)
    dock.show_image(a)
    assert dock.viewer.overlays.counts["residuals"] > 20
    # the calibrated orientation puts the LCP's overlay on the rendered corner
    cal = read_eo_csv(dock.calibration.params["OUTPUT_EO"])
    kept = dock.session.calibration.result.eo  # the result the dock keeps is what was written
    assert kept.image_id == cal.image_id  # (the file has 0.1 mm and 1e-10 degrees)
    assert np.abs(kept.xyz - cal.xyz).max() <= 5e-5
    assert np.degrees(np.abs(kept.opk - cal.opk)).max() <= 5e-11
    moved = PickingScene(cal, HALF, CRS).project(a, [lcp.xyz])[0]
    before = PickingScene(dock.eo, HALF, CRS).project(a, [lcp.xyz])[0]
    assert math.hypot(*(moved - true_px)) < 2.0 < math.hypot(*(before - true_px))

    # ---- the calibrated orientation in the dock: the overlays now sit on the rendered roofs
    # (the result's, from memory, with one button; the Project tab then names its file)
    button = dock.calibration_panel.use_eo_button
    assert button.isEnabled()
    QTest.mouseClick(button, Qt.MouseButton.LeftButton)
    assert dock.eo is kept
    assert dock.project_panel.eo_edit.filePath() == dock.calibration.params["OUTPUT_EO"]
    dock.show_image(a)
    lcp_k = dock.session.control.lcp_ids.index(str(lcp.id))
    assert math.hypot(*(dock.picking.projected.lcps[lcp_k] - true_px)) < 2.0
    # the same from the file (as a user sets it, or the project restores it)
    dock.project_panel.eo_edit.setFilePath("")
    dock.project_panel.eo_edit.setFilePath(dock.calibration.params["OUTPUT_EO"])
    assert dock.eo is not kept
    dock.show_image(a)
    assert math.hypot(*(dock.picking.projected.lcps[lcp_k] - true_px)) < 2.0

    # ---- the screenshot: roofs with their outlines, lines, LCPs, picks and residual vectors
    split = dock.widget().findChild(QSplitter)
    split.setSizes([330, 820, 130])
    centre = truth.project(a, [np.mean([p.centroid for p in lidar.planes], axis=0)])[0]
    dock.view.set_zoom(0.8, QPointF(*centre))
    dock.view.update_tiles()
    qgis_app.processEvents()
    OUTPUT.mkdir(exist_ok=True)
    shot = dock.grab()
    assert shot.save(str(OUTPUT / "demo_dock.png"))
    assert shot.width() >= 900
    dock.close()
    gap = (math.hypot(*(before - true_px)), math.hypot(*(moved - true_px)))
    print(
        f"\nuser story: project + restore {restore_s:.1f} s, prediction off by {miss_px:.1f} px "
        f"(uncalibrated), calibration {calib_s:.1f} s; LCP overlay {gap[0]:.1f} px -> "
        f"{gap[1]:.2f} px after calibration"
    )
