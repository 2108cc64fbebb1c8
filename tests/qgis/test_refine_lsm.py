"""The picking dock's "Refine" action in real QGIS (offscreen): the selected point snaps to the
least-squares match of the same point measured in another image; the truth is the projection
of the ground point into rendered images of a textured plane (core.simulation.control_chips),
and locatecontrolpoints through processing.run on the same data."""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pyproj
import pytest
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.collinearity import project_with_status
from lidarphoto.core.geometry.frames import LocalFrame, MappingFrame
from lidarphoto.core.geometry.rotations import matrix_to_opk
from lidarphoto.core.io.camera import write_camera_json
from lidarphoto.core.io.observations import read_observations_csv, write_observations_csv
from lidarphoto.core.io.orientation import write_eo_csv
from lidarphoto.core.io.raster_write import write_geotiff
from lidarphoto.core.photo.observations import ImageObservations
from lidarphoto.core.photo.orientation import ExteriorOrientationTable, eo_map_to_local
from lidarphoto.core.simulation.control_chips import GroundTexture, make_chip, render_plane_image
from lidarphoto.plugin.image_dock import ImagePickingDock
from osgeo import gdal
from qgis.PyQt.QtCore import Qt
from qgis.PyQt.QtTest import QTest
from qgis_helpers import QGIS_PROCESS

CRS = "EPSG:25832"
POINT = np.array([500000.0, 5500000.0, 100.0])
CAM = Camera("c", focal_mm=50.0, pixel_size_mm=0.01, width_px=240, height_px=180)


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    out = tmp_path_factory.mktemp("refine")
    wkt = pyproj.CRS(CRS).to_wkt()
    tex = GroundTexture(origin=(POINT[0], POINT[1]), seed=3, n=40)
    xyz = np.array([[POINT[0] - 3, POINT[1] + 2, 600.0], [POINT[0] + 4, POINT[1] - 1, 602.0]])
    opk = np.deg2rad([[0.5, -0.3, 10.0], [-0.4, 0.8, -5.0]])
    eo = ExteriorOrientationTable(("I0", "I1"), np.zeros(2), ("", ""), xyz, opk, wkt)
    (out / "images").mkdir()
    for k, iid in enumerate(eo.image_id):
        img = render_plane_image(tex, POINT[2], CAM, xyz[k], opk[k], CRS, supersample=2,
                                 noise=1.0, seed=k)  # fmt: skip
        ds = gdal.GetDriverByName("GTiff").Create(
            str(out / "images" / f"{iid}.tif"), CAM.width_px, CAM.height_px, 1, gdal.GDT_Byte
        )
        ds.GetRasterBand(1).WriteArray(np.clip(np.round(img), 0, 255).astype(np.uint8))
        ds = None
    write_camera_json(out / "camera.json", CAM)
    write_eo_csv(out / "eo.csv", eo)
    local = LocalFrame.at_map_point(MappingFrame.from_user_input(CRS), POINT)
    c, m = eo_map_to_local(xyz, opk, local)
    om, ph, ka = matrix_to_opk(m)
    p = local.map_to_enu(POINT[None])
    truth = {
        iid: project_with_status(p, np.r_[c[k], om[k], ph[k], ka[k]], CAM)[0][0]
        for k, iid in enumerate(eo.image_id)
    }
    chip = make_chip("GCP1", tex, POINT, 0.1, noise=1.0)
    (out / "chips").mkdir()
    write_geotiff(out / "chips" / "GCP1.tif", chip.grey.astype(np.float32), chip.geotransform,
                  -9999.0, CRS)  # fmt: skip
    (out / "control.csv").write_text(f"point_id,X,Y,Z\nGCP1,{POINT[0]},{POINT[1]},{POINT[2]}\n")
    return {"dir": out, "truth": truth}


def _observations(path, truth, offset):
    pix = np.array([truth["I0"], truth["I1"] + offset, truth["I1"] + [30.0, 20.0]])
    obs = ImageObservations.from_arrays(
        ["I0", "I1", "I1"], ["GCP1", "GCP1", "LONE"], pix, [0.5] * 3, ["tie"] * 3, ["", "", ""]
    )
    write_observations_csv(path, obs)


def test_refine_snaps_to_the_lsm_match_of_the_other_image(qgis_parent, qgis_app, scene, tmp_path):
    d = scene["dir"]
    _observations(tmp_path / "obs.csv", scene["truth"], np.array([1.4, -0.9]))
    dock = ImagePickingDock(None, qgis_parent)
    dock.resize(800, 700)
    dock.show()
    QTest.qWaitForWindowExposed(dock, 2000)
    dock.set_project_files(
        camera=str(d / "camera.json"),
        eo=str(d / "eo.csv"),
        crs=CRS,
        images=[str(d / "images" / "I0.tif"), str(d / "images" / "I1.tif")],
        observations=str(tmp_path / "obs.csv"),
    )
    qgis_app.processEvents()
    dock.show_image("I1")
    qgis_app.processEvents()
    assert len(dock.store.rows) == 3
    k = next(
        i for i, o in enumerate(dock.store.rows) if o.image_id == "I1" and o.point_id == "GCP1"
    )
    dock.picking.selected_index = k
    QTest.mouseClick(dock.viewer.refine_button, Qt.MouseButton.LeftButton)
    o = dock.store.rows[k]
    err = np.hypot(o.col - scene["truth"]["I1"][0], o.row - scene["truth"]["I1"][1])
    assert err < 0.1, (err, dock.messages[-1])
    assert "refined by least-squares matching" in dock.messages[-1]
    on_disk = read_observations_csv(tmp_path / "obs.csv")
    assert np.allclose(on_disk.pixels[k], (o.col, o.row), atol=1e-6)
    # undo brings the click back
    dock.store.undo()
    assert dock.store.rows[k].col == pytest.approx(scene["truth"]["I1"][0] + 1.4)
    # a point measured in no other image: refused with the reason, nothing moves
    lone = next(i for i, o in enumerate(dock.store.rows) if o.point_id == "LONE")
    before = dock.store.rows[lone]
    dock.picking.selected_index = lone
    QTest.mouseClick(dock.viewer.refine_button, Qt.MouseButton.LeftButton)
    assert dock.store.rows[lone] == before
    assert "measured in no other image" in dock.messages[-1]
    dock.close()


def test_locatecontrolpoints_through_processing_run(provider, scene, tmp_path):
    import processing

    d = scene["dir"]
    res = processing.run(
        "lidarphoto:locatecontrolpoints",
        {
            "CHIPS": [str(d / "chips")],
            "CONTROL_POINTS": str(d / "control.csv"),
            "CAMERA": str(d / "camera.json"),
            "EO": str(d / "eo.csv"),
            "IMAGES": [str(d / "images")],
            "CRS": CRS,
            "OUTPUT": str(tmp_path / "located.csv"),
            "OUTPUT_REPORT": str(tmp_path / "report.csv"),
        },
    )
    assert res["LOCATED"] == 2 and res["REJECTED"] == 0
    obs = read_observations_csv(tmp_path / "located.csv")
    for iid, px in zip(obs.image_id, obs.pixels):
        assert np.hypot(*(px - scene["truth"][iid])) < 0.1


def test_locatecontrolpoints_through_qgis_process(qp_env, scene, tmp_path):
    d = scene["dir"]
    r = subprocess.run(
        [QGIS_PROCESS, "--json", "run", "lidarphoto:locatecontrolpoints", "--",
         f"CHIPS={d / 'chips' / 'GCP1.tif'}", f"CONTROL_POINTS={d / 'control.csv'}",
         f"CAMERA={d / 'camera.json'}", f"EO={d / 'eo.csv'}", f"IMAGES={d / 'images'}",
         f"CRS={CRS}", "TRANSFER=false", f"OUTPUT={tmp_path / 'located.csv'}",
         f"OUTPUT_HTML={tmp_path / 'report.html'}"],
        env=qp_env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert json.loads(r.stdout)["results"]["LOCATED"] == 2
    assert (tmp_path / "report.html").read_text().count("data:image/png;base64,") == 4
