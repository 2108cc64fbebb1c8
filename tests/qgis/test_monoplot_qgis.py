"""lidarphoto:monoplot in real QGIS: processing.run and qgis_process on a simulated image over
the DSM of the real AHN3 Delft tile (LAZ rasterised by the algorithm, and a GeoTIFF)."""

from __future__ import annotations

import csv
import json
import subprocess
from pathlib import Path

import numpy as np
import processing
import pytest
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.collinearity import project
from lidarphoto.core.geometry.frames import LocalFrame, MappingFrame
from lidarphoto.core.geometry.rotations import matrix_to_opk
from lidarphoto.core.io.camera import write_camera_json
from lidarphoto.core.io.dsm import dsm_from_las, write_dsm
from lidarphoto.core.io.observations import write_observations_csv
from lidarphoto.core.io.orientation import write_eo_csv
from lidarphoto.core.jobs import monoplot as monoplot_job
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.photo.observations import ImageObservations
from lidarphoto.core.photo.orientation import ExteriorOrientationTable, eo_map_to_local
from qgis.core import QgsProcessingException, QgsRasterLayer, QgsVectorLayer, QgsWkbTypes
from qgis_helpers import QGIS_PROCESS

ALG = "lidarphoto:monoplot"
CRS = "EPSG:28992"
AHN3 = Path(__file__).resolve().parents[1] / "data" / "ahn3" / "ahn3_delft_crop60.laz"


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    """Camera 140 m above the tile; 120 surface points and a 3-vertex line, as the picking
    dock would store them; the DSM also as a GeoTIFF."""
    folder = tmp_path_factory.mktemp("mono")
    dsm = dsm_from_las(AHN3, 0.5, crs=CRS)
    write_dsm(folder / "dsm.tif", dsm)
    cam = Camera("sim", focal_mm=35.0, pixel_size_mm=0.005, width_px=4000, height_px=3000)
    write_camera_json(folder / "camera.json", cam)
    g = dsm.grid
    centre = np.array([[g.x0 + 39.0, g.y_top - 37.0, 140.0]])
    table = ExteriorOrientationTable(("img1",), np.array([np.nan]), ("",), centre,
                                     np.radians([[2.0, -3.0, 25.0]]), CRS)  # fmt: skip
    write_eo_csv(folder / "eo.csv", table)
    rng = np.random.default_rng(8)
    xc, yc = dsm.centre_origin
    x, y = xc + rng.uniform(1, 58, 200), yc - rng.uniform(1, 58, 200)
    truth = np.column_stack([x, y, dsm.height_at(x, y)])
    local = LocalFrame.at_map_point(MappingFrame.from_user_input(CRS), truth.mean(axis=0))
    c, m = eo_map_to_local(table.xyz, table.opk, local)
    pixels = project(local.map_to_enu(truth), np.r_[c[0], matrix_to_opk(m[0])], cam)
    # only what the image shows can be picked (an off-image pixel is refused)
    seen = np.flatnonzero(((pixels >= 0) & (pixels <= [cam.width_px, cam.height_px])).all(1))
    truth, pixels = truth[seen[:123]], pixels[seen[:123]]
    kinds = ["check"] * 120 + ["line"] * 3
    targets = ["0"] * 120 + ["4"] * 3  # the CSV needs a target id; points ignore it
    ids = [f"p{k}" for k in range(123)]
    obs = ImageObservations.from_arrays(["img1"] * 123, ids, pixels, 0.5, kinds, targets)
    write_observations_csv(folder / "obs.csv", obs)
    return folder, truth


def _params(folder: Path, **extra) -> dict:
    return {
        "OBSERVATIONS": str(folder / "obs.csv"),
        "CAMERA": str(folder / "camera.json"),
        "EO": str(folder / "eo.csv"),
        "CRS": CRS,
        "OUTPUT_POINTS": "TEMPORARY_OUTPUT",
        "OUTPUT_LINES": "TEMPORARY_OUTPUT",
        **extra,
    }


def test_processing_run_from_laz(provider, scene, tmp_path):
    folder, truth = scene
    result = processing.run(ALG, _params(
        folder, DSM=str(AHN3), DSM_CRS=CRS, CELL_SIZE=0.5, LINE_STEP=40.0,
        OUTPUT_CSV=str(tmp_path / "pts.csv"), LINES_CSV=str(tmp_path / "lines.csv"),
        OUTPUT_DSM=str(tmp_path / "dsm.tif"),
    ))  # fmt: skip
    points, lines = result["OUTPUT_POINTS"], result["OUTPUT_LINES"]
    assert QgsWkbTypes.hasZ(points.wkbType()) and QgsWkbTypes.hasZ(lines.wkbType())
    assert points.crs().authid() == CRS and lines.featureCount() == 1
    assert points.featureCount() == result["POINT_COUNT"] > 123  # line densified
    feats = {f["point_id"]: f for f in points.getFeatures() if f["line"] == -1}
    err = []
    for k in range(120):
        f = feats[f"p{k}"]
        if f["status_text"] == "ok":
            p = f.geometry().constGet()
            err.append(np.linalg.norm([p.x() - truth[k, 0], p.y() - truth[k, 1],
                                       p.z() - truth[k, 2]]))  # fmt: skip
            assert 0 < f["sigma_z"] < 1.0
    err = np.array(err)
    # points hidden behind a roof or tree come back on the occluding surface (core tests)
    assert len(err) > 100 and np.mean(err < 1e-3) > 0.85
    # the layer holds exactly what the core computes from the same files
    core = run_job(monoplot_job, {
        "OBSERVATIONS": str(folder / "obs.csv"), "CAMERA": str(folder / "camera.json"),
        "EO": str(folder / "eo.csv"), "DSM": str(AHN3), "CRS": CRS, "DSM_CRS": CRS,
        "LINE_STEP": 40.0,
    }).data  # fmt: skip
    got = np.array([[f.geometry().constGet().x(), f.geometry().constGet().y(),
                     f.geometry().constGet().z()] for f in points.getFeatures()])  # fmt: skip
    np.testing.assert_allclose(got, core.points, atol=1e-6)
    with open(tmp_path / "pts.csv", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == points.featureCount() and {"cov_xy", "status_text"} <= set(rows[0])
    dsm_out = QgsRasterLayer(str(tmp_path / "dsm.tif"), "dsm")  # compressed, tiled GeoTIFF
    assert dsm_out.isValid() and (dsm_out.width(), dsm_out.height()) >= (120, 120)


def test_dsm_whose_geoid_grid_is_missing_is_refused(provider, scene, tmp_path):
    folder, _ = scene
    out = tmp_path / "pts.csv"
    # the file says EPSG:7415 (RD New + NAP); the NAP geoid grid is not installed
    with pytest.raises(
        QgsProcessingException,
        match=r"cannot be brought into the mapping CRS"
        r".*nl_nsgi_nlgeo2018",
    ):
        processing.run(ALG, _params(folder, DSM=str(AHN3), OUTPUT_CSV=str(out)))
    assert not out.exists() and not list(tmp_path.iterdir())


def test_missing_camera_is_an_error(provider, scene, tmp_path):
    folder, _ = scene
    with pytest.raises(QgsProcessingException, match=r"not found|camera"):
        processing.run(ALG, _params(folder, DSM=str(folder / "dsm.tif"),
                                    CAMERA=str(tmp_path / "none.json")))  # fmt: skip


def test_qgis_process_geotiff_makarovic(qp_env, scene, tmp_path):
    folder, truth = scene
    gpkg = tmp_path / "points.gpkg"
    r = subprocess.run(
        [QGIS_PROCESS, "--json", "run", ALG, "--",
         f"OBSERVATIONS={folder / 'obs.csv'}", f"CAMERA={folder / 'camera.json'}",
         f"EO={folder / 'eo.csv'}", f"DSM={folder / 'dsm.tif'}", f"CRS={CRS}", "METHOD=1",
         f"OUTPUT_POINTS={gpkg}", f"OUTPUT_LINES={tmp_path / 'lines.gpkg'}"],
        env=qp_env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    results = json.loads(r.stdout)["results"]
    assert results["POINT_COUNT"] == 123 and results["HIT_COUNT"] > 100
    layer = QgsVectorLayer(str(gpkg), "points", "ogr")
    assert layer.isValid() and layer.featureCount() == 123
    ok = [f for f in layer.getFeatures() if f["status_text"] == "ok" and f["line"] == -1]
    err = [np.linalg.norm([f.geometry().constGet().x() - truth[int(f["point_id"][1:]), 0],
                           f.geometry().constGet().z() - truth[int(f["point_id"][1:]), 2]])
           for f in ok]  # fmt: skip
    assert np.mean(np.array(err) < 1e-3) > 0.85
    assert {f["method"] for f in ok} == {"makarovic"}


def test_monoplot_tool_in_the_picking_dock(qgis_parent, qgis_app, qgis_new_project, scene):
    """Clicks in the image dock become 3D points and lines on the map at once."""
    from lidarphoto.core.io.observations import read_observations_csv
    from lidarphoto.plugin.image_dock import ImagePickingDock
    from lidarphoto.plugin.monoplot_tool import MonoplotTool
    from qgis.core import QgsProject

    folder, truth = scene
    dock = ImagePickingDock(None, qgis_parent)
    dock.set_project_files(camera=str(folder / "camera.json"), eo=str(folder / "eo.csv"),
                           crs=CRS)  # fmt: skip
    dock.current_image = "img1"
    tool = MonoplotTool(dock)
    tool.set_dsm(str(folder / "dsm.tif"))
    pixels = read_observations_csv(folder / "obs.csv").pixels
    core = run_job(monoplot_job, {
        "OBSERVATIONS": str(folder / "obs.csv"), "CAMERA": str(folder / "camera.json"),
        "EO": str(folder / "eo.csv"), "DSM": str(folder / "dsm.tif"), "CRS": CRS,
    }).data  # fmt: skip
    visible = [k for k in range(120) if np.linalg.norm(core.points[k] - truth[k]) < 1e-3][:3]
    tool.start("point")
    for k in visible:
        dock.view.pointPicked.emit(*map(float, pixels[k]))
    layer = tool.points_layer
    assert layer is not None and QgsProject.instance().mapLayer(layer.id()) is not None
    assert layer.featureCount() == 3 and layer.crs().authid() == CRS
    for f, k in zip(layer.getFeatures(), visible):
        p = f.geometry().constGet()
        np.testing.assert_allclose([p.x(), p.y(), p.z()], truth[k], atol=1e-3)
        assert f["status_text"] == "ok" and f["sigma_z"] > 0
    tool.line_step_px = 50.0
    tool.start("line")
    for k in (120, 121, 122):
        dock.view.pointPicked.emit(*map(float, pixels[k]))
    assert tool.finish_line() > 3
    assert tool.lines_layer.featureCount() == 1
    tool.stop()
    before = layer.featureCount()
    dock.view.pointPicked.emit(*map(float, pixels[visible[0]]))  # the dock's again
    assert layer.featureCount() == before


def test_a_dsm_layer_of_the_project_gives_the_file_s_result(provider, scene, tmp_path):
    """The DSM chosen among the project's layers (a raster layer loaded from the GeoTIFF, given
    as the layer or its id) gives the same points as the file path; a layer that is not a
    file (a memory layer) is refused by name."""
    from qgis.core import (
        QgsProcessingContext,
        QgsProcessingFeedback,
        QgsProcessingParameterMapLayer,
        QgsProject,
    )

    folder, _ = scene
    alg = provider.algorithm("monoplot")
    assert isinstance(alg.parameterDefinition("DSM"), QgsProcessingParameterMapLayer)
    layer = QgsRasterLayer(str(folder / "dsm.tif"), "the DSM")
    assert layer.isValid()
    QgsProject.instance().addMapLayer(layer)
    try:
        base = _params(folder, OUTPUT_CSV=str(tmp_path / "a.csv"), DSM=str(folder / "dsm.tif"))
        by_file = processing.run(ALG, base)["OUTPUT_POINTS"]
        got = {}
        for key, value in (("layer", layer), ("id", layer.id())):
            out = processing.run(
                ALG, {**base, "DSM": value, "OUTPUT_CSV": str(tmp_path / f"{key}.csv")}
            )
            got[key] = out["OUTPUT_POINTS"]
        want = [f.geometry().asWkt(6) for f in by_file.getFeatures()]
        for key, points in got.items():
            assert [f.geometry().asWkt(6) for f in points.getFeatures()] == want, key
        memory = QgsVectorLayer("Point?crs=EPSG:28992", "scratch", "memory")
        QgsProject.instance().addMapLayer(memory)
        context = QgsProcessingContext()
        context.setProject(QgsProject.instance())
        with pytest.raises(
            QgsProcessingException,
            match="DSM: the layer scratch is not backed by a raster or LAS/LAZ file",
        ):
            processing.run(
                ALG, {**base, "DSM": memory.id()}, context=context, feedback=QgsProcessingFeedback()
            )
    finally:
        QgsProject.instance().removeAllMapLayers()
