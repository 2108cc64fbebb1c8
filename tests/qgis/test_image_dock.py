"""The image point picking dock in real QGIS (pytest-qgis, QTest, QT_QPA_PLATFORM=offscreen).

Data: a 20000 x 20000 tiled GeoTIFF made here (time to first display), a real aerial JPEG
(tests/data/images/aero1.jpg), and a noise-free simulated flight (core.simulate_flight) whose
16-bit frames show the roofs where the camera model puts them. The truth of every geometric
check is the simulation's own projection chain (through ECEF), independent of the dock's
(EO CSV in the mapping CRS -> local frame -> core.picking).
"""

from __future__ import annotations

import json
import math
import shutil
import time
from pathlib import Path

import cv2
import numpy as np
import pytest
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.frames import MappingFrame
from lidarphoto.core.io.control import write_lcps_csv, write_lines_csv
from lidarphoto.core.io.observations import read_observations_csv, write_observations_csv
from lidarphoto.core.io.orientation import write_eo_csv
from lidarphoto.core.io.planes import read_planes_csv, write_planes_csv
from lidarphoto.core.photo.georeference import direct_georeference
from lidarphoto.core.photo.mount import Mount
from lidarphoto.core.photo.observations import ImageObservations
from lidarphoto.core.photo.picking import PickingScene
from lidarphoto.core.simulation.flight import FlightConfig, simulate_flight
from lidarphoto.plugin.image_dock import ImagePickingDock
from lidarphoto.plugin.image_source import ImageSource
from lidarphoto.plugin.image_view import event_position, pointer_position
from lidarphoto.plugin.observation_store import ObservationStore
from osgeo import gdal
from qgis.core import (
    QgsCoordinateReferenceSystem,
    QgsFeature,
    QgsGeometry,
    QgsLineString,
    QgsPoint,
    QgsPolygon,
    QgsProject,
    QgsVectorLayer,
)
from qgis.PyQt.QtCore import QEvent, QPoint, QPointF, Qt
from qgis.PyQt.QtGui import QMouseEvent
from qgis.PyQt.QtTest import QTest
from qgis.PyQt.QtWidgets import QApplication
from qgis_helpers import DATA

ROOT = Path(__file__).resolve().parent
OUTPUT = ROOT / "output"
AERO = ROOT.parents[0] / "data" / "images" / "aero1.jpg"
CRS = "EPSG:28992"
CAMERA = Camera("test frame", focal_mm=50.0, pixel_size_mm=0.012, width_px=3000, height_px=2000)
CONFIG = FlightConfig(
    camera=CAMERA,
    flying_height_m=800.0,
    n_buildings=9,
    n_planes=24,
    town_size_m=400.0,
    n_check=0,
    types=("tie", "line", "lcp"),
    ties_per_plane=2,
    plane_source="exact",
)
ARCSEC = np.pi / (180.0 * 3600.0)
del DATA


def _wait(app, cond, timeout_s=60.0):
    t0 = time.perf_counter()
    while not cond() and time.perf_counter() - t0 < timeout_s:
        QTest.qWait(20)
        app.processEvents()
    return cond()


def _screen_pixel(view, pixel) -> QPoint:
    """The screen pixel (viewport) that shows the image point ``pixel`` (col, row)."""
    p = view.viewportTransform().map(QPointF(float(pixel[0]), float(pixel[1])))
    return QPoint(math.floor(p.x()), math.floor(p.y()))


def _move(widget, pos: QPoint, buttons) -> None:
    """A mouse move with buttons held (QTest.mouseMove only moves the cursor in Qt 5)."""
    event = QMouseEvent(
        QEvent.Type.MouseMove,
        QPointF(pos),
        Qt.MouseButton.NoButton,
        buttons,
        Qt.KeyboardModifier.NoModifier,
    )
    QApplication.sendEvent(widget, event)


def _memory_layer(kind: str, crs: str, name: str) -> QgsVectorLayer:
    layer = QgsVectorLayer(f"{kind}?crs={crs}&field=id:integer", name, "memory")
    assert layer.isValid()
    return layer


def _add(layer, geometries, ids) -> None:
    feats = []
    for g, i in zip(geometries, ids):
        f = QgsFeature(layer.fields())
        f.setGeometry(g)
        f.setAttributes([int(i)])
        feats.append(f)
    assert layer.dataProvider().addFeatures(feats)[0]
    layer.updateExtents()


def _polygon(ring: np.ndarray) -> QgsGeometry:
    pts = [QgsPoint(*map(float, p)) for p in ring] + [QgsPoint(*map(float, ring[0]))]
    return QgsGeometry(QgsPolygon(QgsLineString(pts)))


@pytest.fixture(scope="module")
def block(tmp_path_factory):
    """The simulated project on disk: camera, EO (true mount), trajectory, tables, 16-bit
    frames with the roofs painted in, and the observations with 0.5 px noise."""
    out = tmp_path_factory.mktemp("block")
    sim = simulate_flight(CONFIG, seed=5, exact=True)
    paths = sim.write(out)
    group = sim.truth.groups[0]
    mount = Mount(sim.truth.lever_arm, sim.mount.nominal, sim.truth.boresight[group])
    eo = direct_georeference(sim.truth.trajectory, mount, MappingFrame.from_user_input(CRS))
    write_eo_csv(out / "eo.csv", eo)
    faces = {f.face_id: f for f in sim.town.faces}
    outlines = [faces[int(p.id)].polygon for p in sim.planes]
    scene = PickingScene(eo, CAMERA, CRS)
    images = []
    rng = np.random.default_rng(0)
    for image_id in eo.image_id:
        img = rng.normal(1000, 25, (CAMERA.height_px, CAMERA.width_px)).astype(np.uint16)
        for k, ring in enumerate(scene.project_rings(image_id, outlines)):
            if np.isfinite(ring).all():
                cv2.fillPoly(
                    img, [np.round(ring * 16).astype(np.int32)], 700 + 150 * (k % 5), shift=4
                )
        path = out / f"{image_id}.tif"
        ds = gdal.GetDriverByName("GTiff").Create(
            str(path), CAMERA.width_px, CAMERA.height_px, 1, gdal.GDT_UInt16, ["TILED=YES"]
        )
        ds.GetRasterBand(1).WriteArray(img)
        ds = None
        images.append(path)
    noisy = sim.observations
    noisy = type(noisy)(
        noisy.image_id,
        noisy.point_id,
        noisy.pixels + rng.normal(0, 0.5, noisy.pixels.shape),
        noisy.sigma_px,
        noisy.type,
        noisy.target_id,
    )
    write_observations_csv(out / "measured.csv", noisy)
    write_planes_csv(paths["planes"], sim.planes)
    write_lines_csv(paths["lines"], sim.lines)
    write_lcps_csv(paths["lcps"], sim.lcps)
    return {
        "sim": sim,
        "paths": paths,
        "eo": out / "eo.csv",
        "images": images,
        "outlines": outlines,
        "scene": scene,
        "dir": out,
    }


@pytest.fixture()
def layers(block, qgis_new_project):
    sim = block["sim"]
    project = QgsProject.instance()
    planes = _memory_layer("PolygonZ", CRS, "roof planes")
    _add(planes, [_polygon(r) for r in block["outlines"]], [p.id for p in sim.planes])
    lines = _memory_layer("LineStringZ", CRS, "ridge lines")
    _add(
        lines,
        [
            QgsGeometry(
                QgsLineString([QgsPoint(*map(float, ln.start)), QgsPoint(*map(float, ln.end))])
            )
            for ln in sim.lines
        ],
        [ln.id for ln in sim.lines],
    )
    lcps = _memory_layer("PointZ", CRS, "lcps")
    _add(
        lcps,
        [QgsGeometry(QgsPoint(*map(float, c.xyz))) for c in sim.lcps],
        [c.id for c in sim.lcps],
    )
    project.addMapLayers([planes, lines, lcps])
    return planes, lines, lcps


def _dock(qgis_parent, qgis_app, block, layers, tmp_path, iface=None, obs_name="obs.csv"):
    dock = ImagePickingDock(iface, qgis_parent)
    dock.choose_candidate = lambda cands, labels: cands[0]
    dock.resize(900, 900)
    dock.show()
    QTest.qWaitForWindowExposed(dock, 2000)
    planes, lines, lcps = layers
    dock.project_panel.planes_combo.setLayer(planes)
    dock.project_panel.lines_combo.setLayer(lines)
    dock.project_panel.lcps_combo.setLayer(lcps)
    dock.set_project_files(
        camera=str(block["paths"]["camera"]),
        eo=str(block["eo"]),
        crs=CRS,
        images=[str(p) for p in block["images"]],
        observations=str(tmp_path / obs_name),
    )
    qgis_app.processEvents()
    return dock


def _record(name: str, value) -> None:
    OUTPUT.mkdir(exist_ok=True)
    path = OUTPUT / "image_dock_timings.json"
    data = json.loads(path.read_text()) if path.exists() else {}
    data[name] = value
    path.write_text(json.dumps(data, indent=2))


# ------------------------------------------------------------------------------ large image


def _make_large_tiff(path: Path, n: int = 20000) -> None:
    """A 20000 x 20000 tiled LZW GeoTIFF: 64 px checker of 40/140 grey, overviews built."""
    ds = gdal.GetDriverByName("GTiff").Create(
        str(path),
        n,
        n,
        1,
        gdal.GDT_Byte,
        ["TILED=YES", "COMPRESS=LZW", "BLOCKXSIZE=512", "BLOCKYSIZE=512"],
    )
    yy, xx = np.mgrid[0:512, 0:512]
    tile = (((xx // 64 + yy // 64) % 2) * 100 + 40).astype(np.uint8)
    strip = np.tile(tile, (1, -(-n // 512)))[:, :n]
    band = ds.GetRasterBand(1)
    for r0 in range(0, n, 512):
        band.WriteArray(strip[: min(512, n - r0)], 0, r0)
    ds.BuildOverviews("NEAREST", [2, 4, 8, 16, 32, 64])
    ds = None


def test_large_geotiff_first_display_zoom_and_pan(
    qgis_parent, qgis_app, qgis_new_project, tmp_path
):
    path = tmp_path / "large.tif"
    t0 = time.perf_counter()
    _make_large_tiff(path)
    make_s = time.perf_counter() - t0
    dock = ImagePickingDock(None, qgis_parent)
    dock.resize(900, 900)
    dock.show()
    QTest.qWaitForWindowExposed(dock, 2000)
    dock.set_images([str(path)])  # no EO for it: shown, with a message, no picking
    t0 = time.perf_counter()
    assert not dock.show_image("large") or dock.source is not None
    dock.view.update_tiles()
    shot = dock.view.viewport().grab()
    first_s = time.perf_counter() - t0
    assert not shot.isNull()
    view = dock.view
    assert (dock.source.width, dock.source.height) == (20000, 20000)
    assert dock.source.overview_count >= 5
    assert "no exterior orientation" in dock.messages[-1]
    assert view.level_for_zoom() >= 5 and view.tiles_loaded <= 16  # never the full image
    assert dock.pick(100.0, 100.0) == -1  # no orientation, no picking

    # zoom about the cursor to 100 %: the image point under the cursor stays put
    vp = QPointF(view.viewport().width() * 0.3, view.viewport().height() * 0.6)
    before = view._scene_f(vp)
    t0 = time.perf_counter()
    view.zoom_about(1.0 / view.zoom, vp)
    view.update_tiles()
    view.viewport().grab()
    zoom_s = time.perf_counter() - t0
    assert view.zoom == pytest.approx(1.0)
    after = view._scene_f(vp)
    assert abs(after.x() - before.x()) <= 1.0 and abs(after.y() - before.y()) <= 1.0
    assert view.level_for_zoom() == 0
    # pan with the middle button: the scene moves with the mouse
    start = view.visible_rect().center()
    c = view.viewport().rect().center()
    QTest.mousePress(
        view.viewport(), Qt.MouseButton.MiddleButton, Qt.KeyboardModifier.NoModifier, c
    )
    _move(view.viewport(), c + QPoint(-300, -200), Qt.MouseButton.MiddleButton)
    QTest.mouseRelease(
        view.viewport(),
        Qt.MouseButton.MiddleButton,
        Qt.KeyboardModifier.NoModifier,
        c + QPoint(-300, -200),
    )
    t0 = time.perf_counter()
    view.update_tiles()
    img = view.viewport().grab().toImage()
    pan_s = time.perf_counter() - t0
    moved = view.visible_rect().center() - start
    assert abs(moved.x() - 300) <= 2 and abs(moved.y() - 200) <= 2
    # what is on screen is the checker at its place: test cell centres around the view centre
    centre = view.visible_rect().center()
    checked = 0
    for dx in (-96, -32, 32, 96):
        for dy in (-96, -32, 32, 96):
            x = (math.floor((centre.x() + dx) / 64) + 0.5) * 64
            y = (math.floor((centre.y() + dy) / 64) + 0.5) * 64
            p = view.mapFromScene(QPointF(x, y))
            if not img.rect().contains(p):
                continue
            grey = QColorValue(img.pixel(p.x(), p.y()))
            bright = ((int(x) // 64 + int(y) // 64) % 2) == 1
            assert (grey > 200) if bright else (grey < 50), (x, y, grey, p, img.size())
            checked += 1
    assert checked >= 8, (checked, img.size())
    _record(
        "large_geotiff_20000x20000",
        {
            "make_s": round(make_s, 2),
            "first_display_s": round(first_s, 3),
            "zoom_to_100pct_s": round(zoom_s, 3),
            "pan_300x200px_s": round(pan_s, 3),
            "tiles_loaded": view.tiles_loaded,
        },
    )
    print(
        f"\nlarge image: make {make_s:.2f} s, first display {first_s:.3f} s, "
        f"zoom 100 % {zoom_s:.3f} s, pan {pan_s:.3f} s, {view.tiles_loaded} tiles"
    )
    assert first_s < 5.0
    dock.close()


def QColorValue(rgb: int) -> int:
    return (rgb >> 8) & 0xFF


def test_real_aerial_jpeg_gdal_and_opencv_agree(tmp_path):
    shutil.copy(AERO, tmp_path / "aero1.jpg")
    g = ImageSource(tmp_path / "aero1.jpg", backend="gdal")
    o = ImageSource(tmp_path / "aero1.jpg", backend="opencv")
    assert (g.width, g.height, g.bands) == (o.width, o.height, o.bands) == (640, 480, 3)
    a = g.read_raw(0, 0, 640, 480, 640, 480).astype(float)
    b = o.read_raw(0, 0, 640, 480, 640, 480).astype(float)
    assert np.abs(a - b).mean() < 1.0  # two JPEG decoders
    half = o.read(100, 50, 200, 100, 100, 50)
    assert half.shape == (50, 100, 3) and half.dtype == np.uint8
    # the OpenCV pyramid level is the decimated image: compare with GDAL's decimated read
    assert np.abs(half.astype(float) - g.read(100, 50, 200, 100, 100, 50)).mean() < 12.0


# ------------------------------------------------------------------------------ picking


def _inside_plane(block, image_id: str):
    """A plane wholly inside the image and its projected outline's centre (pixels)."""
    scene, sim = block["scene"], block["sim"]
    for k, ring in enumerate(scene.project_rings(image_id, block["outlines"])):
        if np.isfinite(ring).all() and CAMERA.in_frame(ring, 200).all():
            return str(sim.planes[k].id), ring.mean(axis=0)
    raise AssertionError("no plane inside the image")


def test_click_adds_observation_undo_redo_move_reload(
    qgis_parent, qgis_app, block, layers, tmp_path
):
    dock = _dock(qgis_parent, qgis_app, block, layers, tmp_path)
    image = block["sim"].trajectory.image_id[1]
    dock.show_image(image)
    assert dock.viewer.overlays.counts["planes"] >= 5 and dock.viewer.overlays.counts["lcps"] >= 1
    target, centre = _inside_plane(block, image)
    view = dock.view
    view.set_zoom(2.0, QPointF(*centre))
    qgis_app.processEvents()
    click = _screen_pixel(view, centre)
    QTest.mouseClick(
        view.viewport(), Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, click
    )
    assert len(dock.store.rows) == 1
    o = dock.store.rows[0]
    assert (o.image_id, o.type, o.target_id) == (image, "tie", target)
    # the centre of the screen pixel clicked (zoom 2: a screen pixel is 0.5 image px)
    expected = view._scene_f(QPointF(click) + QPointF(0.5, 0.5))
    assert abs(o.col - expected.x()) < 1e-6 and abs(o.row - expected.y()) < 1e-6
    assert max(abs(o.col - centre[0]), abs(o.row - centre[1])) <= 0.25
    on_disk = read_observations_csv(tmp_path / "obs.csv")
    assert len(on_disk) == 1 and np.allclose(on_disk.pixels[0], (o.col, o.row), atol=1e-9)
    # image -> map: the plane is selected in its layer
    planes = layers[0]
    sel = [f["id"] for f in planes.getSelectedFeatures()]
    assert sel == [int(target)]
    assert dock.session.pending is not None and len(dock.session.pending.pixels) >= 1

    # drag the point by (+20, -10) screen px = (+10, -5) image px
    QTest.mousePress(
        view.viewport(), Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, click
    )
    _move(view.viewport(), click + QPoint(10, -5), Qt.MouseButton.LeftButton)
    QTest.mouseRelease(
        view.viewport(),
        Qt.MouseButton.LeftButton,
        Qt.KeyboardModifier.NoModifier,
        click + QPoint(20, -10),
    )
    moved = dock.store.rows[0]
    assert len(dock.store.rows) == 1
    assert (moved.col - o.col, moved.row - o.row) == pytest.approx((10.0, -5.0), abs=1e-6)
    # undo / redo through the keyboard shortcuts
    view.setFocus()
    QTest.keyClick(view, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert dock.store.rows[0].col == pytest.approx(o.col)
    QTest.keyClick(
        view, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier
    )
    assert dock.store.rows[0].col == pytest.approx(moved.col)
    dock.store.undo()
    dock.store.undo()
    assert dock.store.rows == [] and ObservationStore().load(tmp_path / "obs.csv") == 0
    dock.store.redo()
    dock.store.redo()
    assert read_observations_csv(tmp_path / "obs.csv").pixels[0] == pytest.approx(
        [moved.col, moved.row]
    )
    # delete the selected point, undo the deletion
    dock.picking.selected_index = 0
    QTest.keyClick(view, Qt.Key.Key_Delete)
    assert dock.store.rows == []
    dock.store.undo()
    # reload from the file: the same rows
    fresh = ObservationStore()
    assert fresh.load(tmp_path / "obs.csv") == 1
    assert fresh.rows == dock.store.rows
    dock.close()


def test_tie_prediction_within_a_pixel(qgis_parent, qgis_app, block, layers, tmp_path):
    """Measure the simulated tie point in one image: the dock predicts it in the others."""
    dock = _dock(qgis_parent, qgis_app, block, layers, tmp_path)
    obs = block["sim"].observations  # noise-free: the true pixels
    names = np.array(obs.point_id)
    errors = []
    for name in [n for n in np.unique(names[np.array(obs.type) == "tie"])][:12]:
        rows = np.flatnonzero(names == name)
        if rows.size < 2:
            continue
        a = rows[0]
        dock.cancel_prediction()
        dock.show_image(obs.image_id[a])
        dock.viewer.type_combo.setCurrentText("tie")
        k = dock.pick(*obs.pixels[a])
        assert k >= 0 and dock.store.rows[k].target_id == obs.target_id[a]
        for b in rows[1:]:
            pred = dock.session.pending.pixels[obs.image_id[b]]
            errors.append(math.hypot(*(pred - obs.pixels[b])))
        # confirm in the second image with Enter: stored at the prediction
        b = rows[1]
        dock.show_image(obs.image_id[b])
        assert dock.viewer.overlays.counts["predictions"] == 1
        dock.view.setFocus()
        QTest.keyClick(dock.view, Qt.Key.Key_Return)
        last = dock.store.rows[-1]
        assert (last.image_id, last.point_id) == (obs.image_id[b], dock.store.rows[k].point_id)
        assert math.hypot(last.col - obs.pixels[b][0], last.row - obs.pixels[b][1]) < 1.0
    errors = np.array(errors)
    print(f"\ntie prediction: {errors.size} predictions, max error {errors.max():.4f} px")
    _record("tie_prediction_max_error_px", float(errors.max()))
    assert errors.size >= 10 and errors.max() < 1.0
    dock.close()


def test_bad_inputs_and_other_crs(qgis_parent, qgis_app, block, layers, tmp_path):
    foreign = tmp_path / "foreign.csv"
    foreign.write_text(
        "image_id,point_id,col,row,sigma_px,type,target_id\nOTHER_1,T1,10.5,20.5,0.5,tie,3\n",
        encoding="utf-8",
    )
    dock = _dock(qgis_parent, qgis_app, block, layers, tmp_path, obs_name="foreign.csv")
    assert any("not in the exterior orientation" in m for m in dock.messages)
    # a missing image file, an image without orientation
    missing = tmp_path / f"{block['sim'].trajectory.image_id[0]}.tif"
    shutil.copy(AERO, tmp_path / "aero1.jpg")
    dock.set_images(
        [str(p) for p in block["images"][1:]] + [str(missing), str(tmp_path / "aero1.jpg")]
    )
    assert not dock.show_image(block["sim"].trajectory.image_id[0])
    assert "missing on disk" in dock.messages[-1]
    assert dock.pick(10.0, 10.0) == -1
    assert dock.show_image("aero1") and "no exterior orientation" in dock.messages[-1]
    assert dock.pick(100.0, 100.0) == -1
    # adding a point keeps the foreign row in the file: nothing is lost
    image = block["sim"].trajectory.image_id[2]
    dock.show_image(image)
    _target, centre = _inside_plane(block, image)
    assert dock.pick(*centre) >= 0
    kept = read_observations_csv(foreign)
    assert kept.image_id == ("OTHER_1", image)
    # the plane layer in WGS 84: reprojected, the same overlay within 0.05 px
    ref = [r.copy() for r in dock.picking.projected.rings]
    planes_wgs = _memory_layer("PolygonZ", "EPSG:4326", "planes wgs84")
    ct_src = layers[0]
    from qgis.core import QgsCoordinateTransform

    ct = QgsCoordinateTransform(
        ct_src.crs(), QgsCoordinateReferenceSystem("EPSG:4326"), QgsProject.instance()
    )
    geoms, ids = [], []
    for f in ct_src.getFeatures():
        g = QgsGeometry(f.geometry())
        g.transform(ct)
        geoms.append(g)
        ids.append(f["id"])
    _add(planes_wgs, geoms, ids)
    QgsProject.instance().addMapLayer(planes_wgs)
    dock.project_panel.planes_combo.setLayer(planes_wgs)
    got = dock.picking.projected.rings
    assert len(got) == len(ref)
    assert max(np.abs(a - b).max() for a, b in zip(got, ref)) < 0.05
    dock.close()


def test_canvas_sync_and_session_restore(
    qgis_parent, qgis_app, qgis_iface, block, layers, tmp_path
):
    dock = _dock(qgis_parent, qgis_app, block, layers, tmp_path, iface=qgis_iface)
    image = block["sim"].trajectory.image_id[3]
    dock.show_image(image)
    # the footprint on the canvas: 4 corners, around the image centre's ground point
    band = dock.canvas_footprint.rubber_band
    assert band is not None and band.numberOfVertices() >= 4
    corners = dock.footprint()
    centre = dock.scene_geometry.ray_plane(
        image,
        (CAMERA.width_px / 2, CAMERA.height_px / 2),
        [[0, 0, 1.0]],
        [[*dock.eo.xyz[3, :2], dock.session.control.ground_height()]],
    )[0][0]
    assert QgsGeometry.fromPolygonXY([[*(QgsPointXY_(c) for c in corners)]]).contains(
        QgsGeometry.fromPointXY(QgsPointXY_(centre))
    )
    # map -> image: selecting a plane on the map highlights it in the image
    planes = layers[0]
    target, _c = _inside_plane(block, image)
    fid = next(f.id() for f in planes.getFeatures() if str(f["id"]) == target)
    planes.selectByIds([fid])
    qgis_app.processEvents()
    assert dock.highlighted()[0] == {target}
    # a session stored in the project comes back in a new dock
    dock.viewer.type_combo.setCurrentText("lcp")
    lcp_px = dock.picking.projected.lcps
    k = int(np.flatnonzero(np.isfinite(lcp_px).all(axis=1))[0])
    assert dock.pick(*(lcp_px[k] + 1.0)) >= 0
    assert dock.store.rows[-1].target_id == dock.session.control.lcp_ids[k]
    dock.calibration_panel.trajectory_edit.setFilePath(str(block["paths"]["trajectory"]))
    dock.save_session()
    rows = list(dock.store.rows)
    dock.close()
    again = ImagePickingDock(None, qgis_parent)
    # the tabs at once; the files in steps of their own, the observation markers last
    assert again.calibration_panel.trajectory_edit.filePath() == str(block["paths"]["trajectory"])
    assert again.loader.steps_left == 4 and again.store.rows == []
    assert again.wait_restored()
    assert again.loader.steps_left == 0 and again.store.rows == rows
    assert again.current_image == image and again.source is not None
    shown = [o for o in rows if o.image_id == image]
    assert again.viewer.overlays.counts["observations"] == len(shown) >= 1
    assert again.calibration_panel.trajectory_edit.filePath() == str(block["paths"]["trajectory"])
    assert again.project_panel.planes_combo.currentLayer() is planes
    assert again.viewer.overlays.counts["planes"] >= 5
    again.close()
    dock.remove_footprint()


def QgsPointXY_(xyz):
    from qgis.core import QgsPointXY

    return QgsPointXY(float(xyz[0]), float(xyz[1]))


def test_run_calibration_shows_residuals_and_screenshot(
    qgis_parent, qgis_app, provider, block, layers, tmp_path
):
    shutil.copy(block["dir"] / "measured.csv", tmp_path / "measured.csv")
    dock = _dock(qgis_parent, qgis_app, block, layers, tmp_path, obs_name="measured.csv")
    sim, paths = block["sim"], block["paths"]
    dock.calibration_panel.trajectory_edit.setFilePath(str(paths["trajectory"]))
    dock.calibration_panel.lever_edit.setText(",".join(repr(float(v)) for v in sim.mount.lever_arm))
    dock.calibration_panel.planes_csv_edit.setFilePath(str(paths["planes"]))
    dock.calibration_panel.lines_csv_edit.setFilePath(str(paths["lines"]))
    dock.calibration_panel.lcps_csv_edit.setFilePath(str(paths["lcps"]))
    done = []
    dock.calibrationFinished.connect(done.append)
    QTest.mouseClick(dock.calibration_panel.run_button, Qt.MouseButton.LeftButton)
    assert _wait(qgis_app, lambda: bool(done), 90.0), "the calibration task did not finish"
    assert done == [True], dock.calibration_panel.result_label.text()
    # the truth within 3 sigma (noise-free INS, 0.5 px pixel noise)
    import csv

    with open(dock.calibration.params["OUTPUT_TABLE"], encoding="utf-8") as fh:
        for row in csv.DictReader(fh):
            true = sim.truth.boresight[row["group"]] / ARCSEC
            for k, angle in enumerate(("omega", "phi", "kappa")):
                est, sd = float(row[f"d_{angle}_arcsec"]), float(row[f"std_d_{angle}_arcsec"])
                assert abs(est - true[k]) < 3 * sd + 0.5, (angle, est, true[k], sd)
    v = np.array(
        [math.hypot(*x) for x in dock.session.residuals().values() if np.isfinite(x).all()]
    )
    assert v.size > 100
    rms = float(np.sqrt(np.mean(v**2)))
    assert 0.2 < rms < 1.2  # 0.5 px per coordinate put in
    assert "RMS" in dock.calibration_panel.result_label.text()
    # what the dock shows is the result object's, and the files written say the same
    run = dock.session.calibration
    assert run is not None and len(run.observations) == len(dock.store.rows)
    with open(dock.calibration.params["RESIDUALS_CSV"], encoding="utf-8") as fh:
        written = list(csv.DictReader(fh))
    shown = dock.session.residuals()
    for k, vec in list(shown.items())[:50]:
        o, w = dock.store.rows[k], written[k]
        assert (w["image_id"], w["point_id"], w["target_id"]) == (
            o.image_id,
            o.point_id,
            o.target_id,
        )
        assert (float(w["vx_px"]), float(w["vy_px"])) == pytest.approx(tuple(vec), abs=1e-12)
    # the control the calibration read is the dock's (the tables' rows, outlines of the layer)
    params = dock.calibration.params
    assert params["PLANES"].endswith("control_planes.csv") and Path(params["PLANES"]).is_file()
    assert len(read_planes_csv(params["PLANES"])) == len(dock.session.control.planes)
    image = sim.trajectory.image_id[1]
    dock.show_image(image)
    assert dock.viewer.overlays.counts["residuals"] > 10
    assert dock.table.text(0, 6) != ""
    # the screenshot: the dock with roof outlines, ids, lines, LCPs, points and residuals
    _target, centre = _inside_plane(block, image)
    dock.view.set_zoom(2.0, QPointF(*centre))
    dock.view.update_tiles()
    qgis_app.processEvents()
    OUTPUT.mkdir(exist_ok=True)
    shot = dock.grab()
    assert shot.save(str(OUTPUT / "image_dock.png"))
    img = shot.toImage()
    assert img.width() >= 800 and not img.isNull()
    dock.close()


def test_plugin_action_shows_and_unload_removes_the_dock(qgis_iface, qgis_app, qgis_new_project):
    import lidarphoto

    plugin = lidarphoto.classFactory(qgis_iface)
    plugin.initGui()
    try:
        action = next(a for a in plugin.actions if a.objectName() == "lidarphotoImagePicking")
        action.trigger()
        dock = plugin.image_dock
        assert isinstance(dock, ImagePickingDock) and not dock.isHidden()
        assert "Ctrl+Z" in dock.viewer.help_button.toolTip()  # the keyboard help
        action.trigger()  # a checkable action: the second trigger hides the dock
        assert dock.isHidden() and plugin.image_dock is dock
    finally:
        plugin.unload()
    assert plugin.image_dock is None


# ------------------------------------------------------------------------------ issue 14


def test_pointer_position_is_the_centre_of_the_pixel_or_the_sub_pixel_position(qgis_app):
    """Qt reports a mouse position as the top-left corner of the pixel under the cursor; a
    position between device pixels (a tablet, a touchpad, a fractional scale) is kept."""

    def event(x, y):
        return QMouseEvent(
            QEvent.Type.MouseButtonRelease,
            QPointF(x, y),
            Qt.MouseButton.LeftButton,
            Qt.MouseButton.NoButton,
            Qt.KeyboardModifier.NoModifier,
        )

    cases = [
        ((10.0, 7.0), 1.0, (10.5, 7.5)),  # a screen pixel: its centre
        ((10.25, 7.0), 1.0, (10.25, 7.5)),  # sub-pixel in x: kept
        ((10.5, 7.0), 2.0, (10.75, 7.25)),  # device pixel (21, 14) of a 2x screen: its centre
        ((10.25, 7.75), 2.0, (10.25, 7.75)),  # between device pixels: kept
        ((0.0, 0.0), 1.5, (1 / 3, 1 / 3)),  # a 150 % screen: device pixel 0 is 2/3 px wide
    ]
    for (x, y), ratio, expected in cases:
        got = pointer_position(event(x, y), ratio)
        assert (got.x(), got.y()) == pytest.approx(expected, abs=1e-12), (x, y, ratio)
    assert event_position(event(10.0, 7.0)) == QPointF(10.0, 7.0)  # Qt's own, unchanged


def test_click_stores_the_centre_of_the_clicked_screen_pixel(
    qgis_parent, qgis_app, block, layers, tmp_path
):
    """A real click on the screen pixel that shows a known image pixel, at 25 %, 100 % and
    400 %: the observation is the centre of the screen pixel clicked (< 0.01 px), computed
    here from the zoom and the scroll offsets alone; at 100 % that is the image pixel's centre
    (c + 0.5, r + 0.5) and the pixel on screen is that image pixel. The former code stored the
    pixel's top-left corner: 0.5 / zoom px off in each coordinate (0.71 px at 100 %)."""
    dock = _dock(qgis_parent, qgis_app, block, layers, tmp_path)
    image = block["sim"].trajectory.image_id[1]
    dock.show_image(image)
    _target, centre = _inside_plane(block, image)
    c, r = (int(v) for v in np.floor(centre))  # the image pixel (c, r)
    view = dock.view
    dock.viewer.type_combo.setCurrentText("tie")
    for zoom in (0.25, 1.0, 4.0):
        dock.cancel_prediction()
        view.set_zoom(zoom, QPointF(c + 0.5, r + 0.5))
        assert view.wait_idle(60.0, build=False)
        assert view.zoom == pytest.approx(zoom)
        assert view.transform().m12() == 0.0 and view.transform().m21() == 0.0
        hs, vs = view.horizontalScrollBar().value(), view.verticalScrollBar().value()
        # the screen pixel showing the image point (c + 0.5, r + 0.5): x = zoom * col - hs
        sx, sy = math.floor(zoom * (c + 0.5) - hs), math.floor(zoom * (r + 0.5) - vs)
        n = len(dock.store.rows)
        QTest.mouseClick(
            view.viewport(),
            Qt.MouseButton.LeftButton,
            Qt.KeyboardModifier.NoModifier,
            QPoint(sx, sy),
        )
        assert len(dock.store.rows) == n + 1
        o = dock.store.rows[-1]
        expected = ((sx + 0.5 + hs) / zoom, (sy + 0.5 + vs) / zoom)
        assert abs(o.col - expected[0]) < 0.01 and abs(o.row - expected[1]) < 0.01, (zoom, o)
        # and the clicked screen pixel covers image pixel (c, r) (its centre at 100 %)
        assert (sx + hs) / zoom <= c + 0.5 < (sx + 1 + hs) / zoom
        if zoom == 1.0:
            assert (o.col, o.row) == pytest.approx((c + 0.5, r + 0.5), abs=1e-9)
        if zoom >= 1.0:
            assert (math.floor(o.col), math.floor(o.row)) == (c, r)
        on_disk = read_observations_csv(tmp_path / "obs.csv")
        assert on_disk.pixels[-1] == pytest.approx([o.col, o.row], abs=1e-12)
    # at 100 % the screen pixel clicked shows image pixel (c, r): the view's picture, overlays
    # hidden, against a direct read of that pixel and its neighbours
    view.set_zoom(1.0, QPointF(c + 0.5, r + 0.5))
    assert view.wait_idle(60.0, build=False)
    for name in dock.viewer.overlays.groups:
        dock.viewer.overlays.set_visible(name, False)
    view.update_tiles()
    shot = view.viewport().grab().toImage()
    hs, vs = view.horizontalScrollBar().value(), view.verticalScrollBar().value()
    for dc, dr in ((0, 0), (1, 0), (0, 1), (-1, -1)):
        sx, sy = c + dc - hs, r + dr - vs
        grey = QColorValue(shot.pixel(sx, sy))
        direct = int(view.source.read(c + dc, r + dr, 1, 1, 1, 1).reshape(-1)[0])
        assert grey == direct, (dc, dr, grey, direct)
    dock.close()


def test_undo_and_redo_take_the_prediction_with_the_tie_point(
    qgis_parent, qgis_app, block, layers, tmp_path
):
    """Ctrl+Z of a tie point leaves no prediction behind: the next image shows none and Enter
    adds nothing there; Ctrl+Shift+Z brings the point and its prediction back; undoing the
    measurement in the second image predicts it there again."""
    dock = _dock(qgis_parent, qgis_app, block, layers, tmp_path)
    obs = block["sim"].observations
    names = np.array(obs.point_id)
    rows = next(
        np.flatnonzero(names == n)
        for n in np.unique(names[np.array(obs.type) == "tie"])
        if (names == n).sum() >= 2
    )
    a, b = rows[:2]
    img_a, img_b = obs.image_id[a], obs.image_id[b]
    dock.show_image(img_a)
    dock.viewer.type_combo.setCurrentText("tie")
    assert dock.pick(*obs.pixels[a]) == 0
    pending = dock.session.pending
    assert pending is not None and img_b in pending.pixels
    view = dock.view
    ctrl, shift = Qt.KeyboardModifier.ControlModifier, Qt.KeyboardModifier.ShiftModifier

    def keys(key, mods=Qt.KeyboardModifier.NoModifier):
        view.setFocus()
        QTest.keyClick(view, key, mods)

    keys(Qt.Key.Key_Z, ctrl)  # undo the tie point
    assert dock.store.rows == [] and dock.session.pending is None
    dock.show_image(img_b)
    assert dock.viewer.overlays.counts["predictions"] == 0
    keys(Qt.Key.Key_Return)  # Enter: nothing to accept
    assert dock.store.rows == []
    keys(Qt.Key.Key_Z, ctrl | shift)  # redo: the point and its prediction in B
    assert len(dock.store.rows) == 1 and dock.session.pending is pending
    assert dock.viewer.overlays.counts["predictions"] == 1
    keys(Qt.Key.Key_Return)  # measured in B at its prediction
    assert [o.image_id for o in dock.store.rows] == [img_a, img_b]
    assert dock.store.rows[1].point_id == dock.store.rows[0].point_id
    assert dock.viewer.overlays.counts["predictions"] == 0
    keys(Qt.Key.Key_Z, ctrl)  # undo B: predicted in B again, drawn
    assert [o.image_id for o in dock.store.rows] == [img_a]
    assert dock.session.prediction(img_b) is not None
    assert dock.viewer.overlays.counts["predictions"] == 1
    on_disk = read_observations_csv(tmp_path / "obs.csv")
    assert on_disk.image_id == (img_a,)  # the autosave follows the undo
    # deleting the only row of the point drops the prediction
    dock.show_image(img_a)
    dock.picking.selected_index = 0
    keys(Qt.Key.Key_Delete)
    assert dock.store.rows == [] and dock.session.pending is None
    keys(Qt.Key.Key_Z, ctrl)
    assert len(dock.store.rows) == 1 and dock.session.prediction(img_b) is not None
    dock.close()


def test_a_click_redraws_only_what_changed(qgis_parent, qgis_app, block, layers, tmp_path):
    """With 600 observations in the image, a tie click adds the three items of its marker
    (and three for its selection) and keeps every other overlay item (none is made again); the
    map selection it makes restyles the plane (the same item, highlighted); undo removes
    exactly the new items."""
    image = block["sim"].trajectory.image_id[1]
    rng = np.random.default_rng(3)
    n = 600
    many = ImageObservations.from_arrays(
        [image] * n,
        [f"B{k}" for k in range(n)],
        rng.uniform([10, 10], [CAMERA.width_px - 10, CAMERA.height_px - 10], (n, 2)),
        np.full(n, 0.5),
        ["tie"] * n,
        [str(block["sim"].planes[k % len(block["sim"].planes)].id) for k in range(n)],
    )
    write_observations_csv(tmp_path / "many.csv", many)
    dock = _dock(qgis_parent, qgis_app, block, layers, tmp_path, obs_name="many.csv")
    dock.show_image(image)
    overlays = dock.viewer.overlays
    assert overlays.counts["observations"] == n

    def items(name):
        return set(overlays.groups[name].childItems())

    before = {name: items(name) for name in overlays.groups}
    assert len(before["observations"]) == 3 * n  # cross, circle, label
    target, centre = _inside_plane(block, image)
    dock.view.set_zoom(1.0, QPointF(*centre))
    qgis_app.processEvents()
    dock.viewer.type_combo.setCurrentText("tie")
    QTest.mouseClick(
        dock.view.viewport(),
        Qt.MouseButton.LeftButton,
        Qt.KeyboardModifier.NoModifier,
        _screen_pixel(dock.view, centre),
    )
    assert len(dock.store.rows) == n + 1 and dock.store.rows[-1].target_id == target
    after = {name: items(name) for name in overlays.groups}
    assert before["observations"] < after["observations"]
    assert len(after["observations"] - before["observations"]) == 3 + 3  # marker, selection
    for name in ("planes", "lines", "lcps"):
        assert after[name] == before[name], name  # not drawn again
    assert overlays.highlighted("planes") == {target}  # restyled: selected on the map
    assert dock.table.model_.rowCount() == n + 1
    assert dock.table.text(dock.table.row_of(n), 1) == dock.store.rows[-1].point_id
    dock.view.setFocus()
    QTest.keyClick(dock.view, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert items("observations") == before["observations"]
    # the map selection changed elsewhere (another plane): only the highlight follows
    planes = layers[0]
    other = next(f for f in planes.getFeatures() if str(f["id"]) != target)
    planes.selectByIds([other.id()])
    assert overlays.highlighted("planes") == {str(other["id"])}
    assert items("planes") == before["planes"]
    dock.close()
