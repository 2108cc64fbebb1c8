"""lidarphoto:makecontrolchips in real QGIS: processing.run (chips registered to load, the files
those the core writes from the same inputs) and qgis_process, on a synthetic ground photo pair
(core/simulation/ground_photo.py); a point without its plate gets its reason in the report."""

from __future__ import annotations

import csv
import json
import math
import subprocess
from pathlib import Path

import numpy as np
import processing
import pytest
from lidarphoto.core.geometry.camera import camera_from_dict
from lidarphoto.core.io.camera import write_camera_json
from lidarphoto.core.io.raster import RasterReader
from lidarphoto.core.io.raster_write import GeoTiffWriter
from lidarphoto.core.jobs import make_control_chips as chips_job
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.photo.control_plate import PlateGeometry, photo_azimuth
from lidarphoto.core.simulation.ground_photo import make_ground_patch, render_ground_photo
from qgis.core import QgsProcessingContext, QgsProject, QgsRasterLayer
from qgis_helpers import QGIS_PROCESS

CRS = "EPSG:31983"
POINT = (457_321.25, 7_552_104.75, 431.2)
PLATE = PlateGeometry(outer_m=0.5, inner_m=0.25, azimuth_deg=20.0)
EO = np.array([0.45, -0.30, 1.80, *np.radians([3.0, -2.0, 25.0])])


def _grey(path: Path, img: np.ndarray) -> None:
    u8 = np.clip(np.rint(img), 0, 255).astype(np.uint8)
    with GeoTiffWriter(str(path), u8.shape[1], u8.shape[0], 1, np.uint8, None, None) as w:
        w.write(u8)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("chips")
    cam = camera_from_dict({"name": "ground", "focal_mm": 3.0, "pixel_size_mm": 0.005,
                            "width_px": 960, "height_px": 720,
                            "distortion": {"model": "brown_conrady", "k1": 4e-3}})  # fmt: skip
    patch = make_ground_patch(seed=3)
    free_eo = EO + np.array([0.004, -0.003, 0.002, *np.radians([1.0, 0.5, 4.0])])
    photos = d / "photos"
    photos.mkdir()
    _grey(photos / "GCP1_plate.tif", render_ground_photo(patch, cam, EO, PLATE, supersample=2))
    _grey(photos / "GCP1_free.tif", render_ground_photo(patch, cam, free_eo, None, 2, seed=2))
    _grey(photos / "GCP2_plate.tif", render_ground_photo(patch, cam, free_eo, None, 2, seed=3))
    write_camera_json(d / "camera.json", cam)
    (d / "points.csv").write_text(
        "point_id,X,Y,Z,role\n"
        f"GCP1,{POINT[0]},{POINT[1]},{POINT[2]},control\n"
        f"GCP2,{POINT[0] + 40},{POINT[1]},{POINT[2]},check\n"
    )  # fmt: skip
    return d


def _params(d: Path, out: Path) -> dict:
    return {"POINTS": str(d / "points.csv"), "CRS": CRS, "CAMERA": str(d / "camera.json"),
            "PHOTOS": [str(d / "photos")], "OUTER_SIDE": 0.5, "INNER_SIDE": 0.25,
            "PLATE_AZIMUTH": 20.0, "PHOTO_AZIMUTH": round(photo_azimuth(EO), 3), "GSD": 0.01,
            "CHIP_SIZE": 81, "OUTPUT_FOLDER": str(out)}  # fmt: skip


def test_processing_run_loads_the_chips(provider, files, tmp_path):
    context = QgsProcessingContext()
    context.setProject(QgsProject.instance())
    result = processing.run("lidarphoto:makecontrolchips", _params(files, tmp_path / "q"),
                            context=context)  # fmt: skip
    assert result["CHIP_COUNT"] == 1 and result["FAILED_COUNT"] == 1
    loads = [Path(p).name for p in context.layersToLoadOnCompletion()]
    assert loads == ["GCP1.tif"]
    layer = QgsRasterLayer(str(tmp_path / "q" / "GCP1.tif"), "chip")
    assert layer.isValid() and layer.crs().authid() == CRS and layer.bandCount() == 1
    centre = layer.extent().center()
    assert (centre.x(), centre.y()) == pytest.approx(POINT[:2], abs=1e-6)
    rows = {r["point_id"]: r for r in csv.DictReader((tmp_path / "q" /
                                                      "control_chips.csv").open())}  # fmt: skip
    assert rows["GCP2"]["status"] == "failed" and rows["GCP2"]["reason"]
    core = run_job(chips_job, _params(files, tmp_path / "c"))
    assert core.results["CHIP_COUNT"] == 1
    with RasterReader(tmp_path / "q" / "GCP1.tif") as a, RasterReader(
        tmp_path / "c" / "GCP1.tif"
    ) as b:  # fmt: skip
        assert a.info.geotransform == b.info.geotransform
        np.testing.assert_array_equal(a.read(), b.read())


def test_qgis_process(qp_env, files, tmp_path):
    p = _params(files, tmp_path / "o")
    args = [f"{k}={v[0] if isinstance(v, list) else v}" for k, v in p.items()]
    r = subprocess.run([QGIS_PROCESS, "--json", "run", "lidarphoto:makecontrolchips", "--",
                        *args], env=qp_env, capture_output=True, text=True,
                       timeout=600)  # fmt: skip
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert json.loads(r.stdout)["results"]["CHIP_COUNT"] == 1
    report = json.loads((tmp_path / "o" / "control_chips.json").read_text())
    ok = next(r for r in report if r["point_id"] == "GCP1")
    assert ok["sift_inliers"] >= 100 and math.isfinite(ok["resection_sigma0"])
