"""lidarphoto:tiepoints in real QGIS: processing.run and qgis_process on rendered images of the
simulated UAV block (known geometry), errors as QgsProcessingException."""

from __future__ import annotations

import json
import subprocess

import cv2
import numpy as np
import processing
import pytest
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.io.camera import write_camera_json
from lidarphoto.core.io.observations import read_observations_csv
from lidarphoto.core.io.orientation import write_eo_csv
from lidarphoto.core.simulation.textured_block import TexturedBlock, make_texture, render_view
from lidarphoto.core.simulation.uav_block import simulate_uav_block
from qgis.core import QgsProcessingException
from qgis_helpers import QGIS_PROCESS

CAMERA = Camera("small", focal_mm=5.0, pixel_size_mm=0.00924, width_px=660, height_px=500)


@pytest.fixture(scope="module")
def block(tmp_path_factory):
    """Six images (two strips of three) of the UAV block, rendered with known poses."""
    folder = tmp_path_factory.mktemp("tie_qgis")
    blk = simulate_uav_block("none", seed=3, n_tie=30, camera=CAMERA, strips=(3, 3),
                             true_focal_mm=5.0, true_x0_mm=0.0, true_y0_mm=0.0)  # fmt: skip
    tb = TexturedBlock.of(blk)
    tex = make_texture(tb.extent(), 0.3, seed=2)
    (folder / "images").mkdir()
    for k, name in enumerate(blk.eo_true.image_id):
        cv2.imwrite(str(folder / "images" / f"{name}.jpg"), render_view(tb, tex, k),
                    [cv2.IMWRITE_JPEG_QUALITY, 95])  # fmt: skip
    write_eo_csv(folder / "eo.csv", blk.eo_dg)
    write_camera_json(folder / "camera.json", blk.camera)
    return blk, folder


def _params(folder, out) -> dict:
    return {"IMAGES": [str(folder / "images")], "EO": str(folder / "eo.csv"),
            "CAMERA": str(folder / "camera.json"), "HEIGHT": 25.0, "MAX_FEATURES": 1000,
            "OUTPUT_OBSERVATIONS": str(out / "tie.csv"),
            "OUTPUT_PAIRS": str(out / "pairs.csv")}  # fmt: skip


def test_processing_run(provider, block, tmp_path):
    blk, folder = block
    res = processing.run("lidarphoto:tiepoints", _params(folder, tmp_path))
    obs = read_observations_csv(res["OUTPUT_OBSERVATIONS"], camera=blk.camera)
    assert res["TRACK_COUNT"] > 200 and res["PAIRS_KEPT"] >= 5
    assert len(set(obs.image_id)) == 6 and set(obs.type) == {"tie"}
    # every track spans at least two images, each image at most once
    pairs = set(zip(obs.point_id, obs.image_id))
    assert len(pairs) == len(obs)
    _, counts = np.unique(obs.point_id, return_counts=True)
    assert counts.min() >= 2 and counts.sum() == res["MEASUREMENT_COUNT"]


def test_errors_are_processing_exceptions(provider, block, tmp_path):
    _, folder = block
    bad = tmp_path / "broken.jpg"
    bad.write_bytes(b"no image")
    with pytest.raises(QgsProcessingException, match="broken"):
        processing.run("lidarphoto:tiepoints", {
            "IMAGES": [str(folder / "images" / "IMG_0101.jpg"), str(bad)],
            "OUTPUT_OBSERVATIONS": str(tmp_path / "x.csv")})  # fmt: skip
    assert not (tmp_path / "x.csv").exists()


def test_qgis_process(qp_env, block, tmp_path):
    _, folder = block
    p = _params(folder, tmp_path)
    p["IMAGES"] = p["IMAGES"][0]
    r = subprocess.run(
        [QGIS_PROCESS, "--json", "run", "lidarphoto:tiepoints", "--",
         *(f"{k}={v}" for k, v in p.items())],
        env=qp_env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    results = json.loads(r.stdout)["results"]
    assert results["TRACK_COUNT"] > 200
    assert (tmp_path / "tie.csv").exists() and (tmp_path / "pairs.csv").exists()
