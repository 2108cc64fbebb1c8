"""The monoplotting tool driven from the image picking dock (issue 7): the Monoplot button, the
DSM chooser of the project panel, points and lines on the map at once, saving, the session.

Truth: DSM surface points of the real AHN3 Delft tile (0.5 m DSM) projected into an oriented
image by the project's collinearity chain; an exact click must come back within 1 mm.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.surface import reproject_dsm
from lidarphoto.core.io.camera import read_camera_json, write_camera_json
from lidarphoto.core.io.dsm import dsm_from_las, load_dsm, write_dsm
from lidarphoto.core.io.observations import read_observations_csv
from lidarphoto.core.io.orientation import read_eo_csv, write_eo_csv
from lidarphoto.core.io.pointcloud import read_points
from lidarphoto.core.io.raster_write import write_rgb_tiff
from lidarphoto.core.photo.monoplot import monoplot
from lidarphoto.core.photo.observations import ImageObservations
from lidarphoto.core.photo.orientation import ExteriorOrientationTable
from lidarphoto.core.photo.picking import PickingScene
from lidarphoto.core.simulation.render import render_image
from lidarphoto.core.simulation.render_scene import RenderOptions, RenderScene
from lidarphoto.plugin.image_dock import ImagePickingDock
from qgis.core import (
    QgsFeature,
    QgsGeometry,
    QgsPoint,
    QgsProject,
    QgsRasterLayer,
    QgsVectorLayer,
    QgsWkbTypes,
)
from qgis.PyQt.QtCore import QPoint, QPointF, Qt
from qgis.PyQt.QtTest import QTest

CRS = "EPSG:28992"
AHN3 = Path(__file__).resolve().parents[1] / "data" / "ahn3" / "ahn3_delft_crop60.laz"
CAMERA = Camera("sim", focal_mm=35.0, pixel_size_mm=0.009, width_px=1600, height_px=1200)


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    """DSM GeoTIFF of the tile, camera, EO of one image 120 m above it, the image rendered
    from the DSM, and DSM surface points visible in it with their exact pixels."""
    folder = tmp_path_factory.mktemp("monodock")
    dsm = dsm_from_las(AHN3, 0.5, crs=CRS)
    write_dsm(folder / "dsm.tif", dsm)
    write_dsm(folder / "dsm_utm.tif", reproject_dsm(dsm, "EPSG:32631"))
    write_camera_json(folder / "camera.json", CAMERA)
    g = dsm.grid
    table = ExteriorOrientationTable(
        ("img1",), np.array([np.nan]), ("",), np.array([[g.x0 + 31.0, g.y_top - 29.0, 125.0]]),
        np.radians([[1.5, -2.0, 15.0]]), CRS,
    )  # fmt: skip
    write_eo_csv(folder / "eo.csv", table)
    arrays, _ = read_points(AHN3, ("x", "y", "z", "classification"), crs=CRS)
    xyz = np.column_stack([arrays["x"], arrays["y"], arrays["z"]])
    rs = RenderScene.build(dsm, xyz, arrays["classification"], crs=CRS)
    img = render_image(rs, CAMERA, table.xyz[0], table.opk[0], RenderOptions(step_px=2))
    write_rgb_tiff(folder / "img1.tif", img.rgb)
    rng = np.random.default_rng(4)
    xc, yc = dsm.centre_origin
    x, y = xc + rng.uniform(5, 54, 60), yc - rng.uniform(5, 54, 60)
    truth = np.column_stack([x, y, dsm.height_at(x, y)])
    pixels = PickingScene(table, CAMERA, CRS).project("img1", truth)
    # keep the points the image sees (not hidden by a roof or a tree): as the core finds them
    obs = ImageObservations.from_arrays(["img1"] * 60, [f"p{k}" for k in range(60)], pixels,
                                        0.5, ["check"] * 60, ["0"] * 60)  # fmt: skip
    core = monoplot(obs, CAMERA, table, dsm, CRS)
    seen = np.flatnonzero(np.linalg.norm(core.points - truth, axis=1) < 1e-3)
    assert seen.size >= 30
    return {"dir": folder, "truth": truth[seen], "pixels": pixels[seen]}


@pytest.fixture()
def dock(qgis_parent, qgis_app, qgis_new_project, scene, tmp_path):
    lcps = QgsVectorLayer(f"PointZ?crs={CRS}&field=id:integer", "lcps", "memory")
    f = QgsFeature(lcps.fields())
    f.setGeometry(QgsGeometry(QgsPoint(*map(float, scene["truth"][0]))))
    f.setAttributes([7])
    lcps.dataProvider().addFeatures([f])
    QgsProject.instance().addMapLayer(lcps)
    d = ImagePickingDock(None, qgis_parent)
    d.resize(900, 900)
    d.show()
    QTest.qWaitForWindowExposed(d, 2000)
    d.project_panel.lcps_combo.setLayer(lcps)
    folder = scene["dir"]
    d.set_project_files(camera=str(folder / "camera.json"), eo=str(folder / "eo.csv"), crs=CRS,
                        images=[str(folder / "img1.tif")],
                        observations=str(tmp_path / "obs.csv"))  # fmt: skip
    qgis_app.processEvents()
    yield d
    d.close()


def _xyz(feature) -> np.ndarray:
    p = feature.geometry().constGet()
    return np.array([p.x(), p.y(), p.z()])


def test_button_needs_a_dsm_resamples_one_in_another_crs(dock, scene, qgis_app):
    dock.viewer.monoplot_button.click()  # no DSM chosen
    assert not dock.viewer.monoplot_button.isChecked() and dock.monoplot_tool.mode == ""
    assert "Choose a DSM" in dock.messages[-1]
    # the tile's DSM resampled into UTM 31N: brought back into RD New for monoplotting
    utm = QgsRasterLayer(str(scene["dir"] / "dsm_utm.tif"), "dsm in UTM")
    assert utm.crs().authid() == "EPSG:32631"
    QgsProject.instance().addMapLayer(utm)
    dock.project_panel.dsm_combo.setLayer(utm)
    dock.viewer.monoplot_button.click()
    assert dock.viewer.monoplot_button.isChecked() and dock.monoplot_tool.mode == "point"
    assert "resampled" in dock.messages[-1] and "UTM zone 31N" in dock.messages[-1]
    assert dock.monoplot_tool.tracer.dsm.crs.to_epsg() == 28992
    for k in range(10):
        dock.view.pointPicked.emit(*map(float, scene["pixels"][k]))
    got = np.array([_xyz(f) for f in dock.monoplot_tool.points_layer.getFeatures()])
    # the same as the core's monoplot on that file (resampling accuracy: tests/core)
    n = 10
    ids = [str(k) for k in range(n)]
    obs = ImageObservations.from_arrays(
        ["img1"] * n, ids, scene["pixels"][:n], 0.5, ["check"] * n, ["0"] * n
    )
    folder = scene["dir"]
    core = monoplot(obs, read_camera_json(folder / "camera.json"), read_eo_csv(folder / "eo.csv"),
                    load_dsm(folder / "dsm_utm.tif"), CRS)  # fmt: skip
    np.testing.assert_allclose(got, core.points, atol=1e-6)
    # two resamplings of a 0.5 m city DSM (trees, walls): most points within a few decimetres
    assert np.median(np.linalg.norm(got - scene["truth"][:10], axis=1)) < 0.5
    dock.viewer.monoplot_button.click()
    # the LAZ in RD New + NAP: NAP heights need a geoid grid PROJ does not have here
    dock.project_panel.dsm_edit.setFilePath(str(AHN3))
    dock.viewer.monoplot_button.click()
    assert not dock.viewer.monoplot_button.isChecked()
    assert "DSM not loaded" in dock.messages[-1] and "nlgeo" in dock.messages[-1]
    # the raster in the mapping CRS: on
    dock.project_panel.dsm_edit.setFilePath(str(scene["dir"] / "dsm.tif"))
    dock.viewer.monoplot_button.click()
    assert dock.viewer.monoplot_button.isChecked() and dock.monoplot_tool.mode == "point"
    # no orientation: the camera file cleared
    dock.viewer.monoplot_button.click()
    dock.project_panel.camera_edit.setFilePath("")
    dock.viewer.monoplot_button.click()
    assert (
        not dock.viewer.monoplot_button.isChecked() and "exterior orientation" in dock.messages[-1]
    )


def test_points_and_lines_on_the_map_within_a_millimetre(dock, scene, tmp_path, qgis_app):
    truth, pixels = scene["truth"], scene["pixels"]
    dock.project_panel.dsm_edit.setFilePath(str(scene["dir"] / "dsm.tif"))
    dock.viewer.monoplot_button.click()
    assert dock.viewer.monoplot_button.isChecked()
    # a real mouse click: a point on the map where the view puts the click
    view = dock.view
    view.set_zoom(1.0, QPointF(*pixels[0]))
    qgis_app.processEvents()
    # the screen pixel that shows the surface point
    at = view.viewportTransform().map(QPointF(*pixels[0]))
    click = QPoint(math.floor(at.x()), math.floor(at.y()))
    QTest.mouseClick(view.viewport(), Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier,
                     click)  # fmt: skip
    layer = dock.monoplot_tool.points_layer
    assert layer is not None and QgsProject.instance().mapLayer(layer.id()) is layer
    assert QgsWkbTypes.hasZ(layer.wkbType()) and layer.crs().authid() == CRS
    first = next(layer.getFeatures())
    sp = view._scene_f(QPointF(click) + QPointF(0.5, 0.5))  # the centre of that pixel
    assert (first["col"], first["row"]) == pytest.approx((sp.x(), sp.y()), abs=1e-9)
    assert np.abs([sp.x() - pixels[0][0], sp.y() - pixels[0][1]]).max() <= 0.5
    assert np.linalg.norm(_xyz(first)[:2] - truth[0, :2]) < 0.05  # 1 screen px ~ 3 cm
    # exact clicks (the projected surface points): within 1 mm
    for k in range(1, 11):
        view.pointPicked.emit(*map(float, pixels[k]))
    feats = list(layer.getFeatures())[1:]
    assert len(feats) == 10
    err = [np.linalg.norm(_xyz(f) - truth[k + 1]) for k, f in enumerate(feats)]
    assert max(err) < 1e-3, err
    status = [f["status_text"] for f in feats]
    assert set(status) <= {"ok", "grazing"}, status
    assert all(0 < f["sigma_z"] < 5.0 for f in feats), [f["sigma_z"] for f in feats]
    assert dock.store.rows == []  # monoplotting measures no observation

    # lines: two vertices + Enter, then three vertices + a double click
    dock.viewer.monoplot_mode.setCurrentIndex(dock.viewer.monoplot_mode.findData("line"))
    assert dock.monoplot_tool.mode == "line" and dock.viewer.finish_line_button.isEnabled()
    for k in (11, 12):
        view.pointPicked.emit(*map(float, pixels[k]))
    view.setFocus()
    QTest.keyClick(view, Qt.Key.Key_Return)
    lines = dock.monoplot_tool.lines_layer
    assert lines is not None and lines.featureCount() == 1
    line = next(lines.getFeatures())
    verts = np.array([[v.x(), v.y(), v.z()] for v in line.geometry().vertices()])
    assert verts.shape == (2, 3) and np.abs(verts - truth[[11, 12]]).max() < 1e-3
    for k in (13, 14):
        view.pointPicked.emit(*map(float, pixels[k]))
    # what the window system sends for a double click: press, release, double click, release
    last = view.mapFromScene(QPointF(*pixels[15]))
    for send in (QTest.mouseClick, QTest.mouseDClick):
        send(view.viewport(), Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, last)
    assert lines.featureCount() == 2
    second = list(lines.getFeatures())[1]
    assert second["n_vertices"] == 3 and second.geometry().constGet().numPoints() == 3
    assert dock.monoplot_tool.vertices == []

    # saved to a GeoPackage, read back
    gpkg = tmp_path / "mono.gpkg"
    assert dock.save_monoplot(str(gpkg)) == ["monoplot_points", "monoplot_lines"]
    back = QgsVectorLayer(f"{gpkg}|layername=monoplot_points", "p", "ogr")
    assert back.isValid() and back.featureCount() == 11 + 5  # the line vertices are points too
    assert QgsWkbTypes.hasZ(back.wkbType())

    # off: clicks measure observations again (an LCP at its projection)
    dock.viewer.monoplot_button.click()
    assert not dock.viewer.monoplot_button.isChecked() and dock.monoplot_tool.mode == ""
    dock.viewer.type_combo.setCurrentText("lcp")
    view.pointPicked.emit(*map(float, pixels[0]))
    assert len(dock.store.rows) == 1 and dock.store.rows[0].target_id == "7"
    assert read_observations_csv(dock.store.path).image_id == ("img1",)
    assert layer.featureCount() == 16  # nothing more monoplotted


def test_dsm_choice_is_kept_in_the_session(dock, scene, qgis_parent):
    dock.project_panel.dsm_edit.setFilePath(str(scene["dir"] / "dsm.tif"))
    dock.project_panel.dsm_cell.setValue(0.25)
    dock.save_session()
    dock.close()
    again = ImagePickingDock(None, qgis_parent)
    assert again.wait_restored()  # (the files are read in steps after the constructor)
    assert again.project_panel.dsm_edit.filePath() == str(scene["dir"] / "dsm.tif")
    assert again.project_panel.dsm_cell.value() == pytest.approx(0.25)
    assert again.set_monoplot(True) and again.monoplot_tool.mode == "point"
    # an image without orientation: no 3D point, a message
    again.set_images([str(scene["dir"] / "img1.tif"), str(scene["dir"] / "dsm.tif")])
    again.show_image("dsm")
    again.view.pointPicked.emit(10.0, 10.0)
    assert "no exterior orientation" in again.messages[-1]
    assert again.monoplot_tool.points_layer is None
    again.close()
