"""lidarphoto:calibratecamera in real QGIS: processing.run and qgis_process on chessboard images
rendered with a known perspective camera (no distortion), which the calibration recovers."""

from __future__ import annotations

import json
import math
import subprocess

import cv2
import numpy as np
import processing
import pytest
from qgis.core import QgsProcessingException
from qgis_helpers import QGIS_PROCESS

ALG = "lidarphoto:calibratecamera"
F_PX, CX, CY, W, H = 800.0, 322.0, 238.0, 640, 480  # OpenCV pixel centres at integers
SQ_PX, SQ_M = 40, 0.03  # square of the rendered board, pixels and metres


def _board() -> np.ndarray:
    img = np.full((9 * SQ_PX, 12 * SQ_PX), 255, np.uint8)  # 10 x 7 squares + a 1-square margin
    for r in range(7):
        for c in range(10):
            if (r + c) % 2 == 0:
                y, x = (r + 1) * SQ_PX, (c + 1) * SQ_PX
                img[y : y + SQ_PX, x : x + SQ_PX] = 0
    return img


@pytest.fixture(scope="module")
def views(tmp_path_factory):
    folder = tmp_path_factory.mktemp("chess")
    k = np.array([[F_PX, 0, CX], [0, F_PX, CY], [0, 0, 1.0]])
    # board pixel -> metres in the target frame (the first inner corner at the origin)
    to_m = np.array([[SQ_M / SQ_PX, 0, -2 * SQ_M], [0, SQ_M / SQ_PX, -2 * SQ_M], [0, 0, 1.0]])
    board = cv2.GaussianBlur(_board(), (0, 0), 1.0)
    rng = np.random.default_rng(3)
    for i in range(8):
        rvec = np.array([rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5), rng.uniform(-0.3, 0.3)])
        r, _ = cv2.Rodrigues(rvec)
        centre = np.array([0.12, 0.075, 0.0])  # middle of the inner corners
        t = -r @ centre + np.array([0.0, 0.0, 0.55])
        hom = k @ np.column_stack([r[:, 0], r[:, 1], t]) @ to_m
        img = cv2.warpPerspective(board, hom, (W, H), flags=cv2.INTER_CUBIC,
                                  borderValue=255)  # fmt: skip
        cv2.imwrite(str(folder / f"view{i}.png"), img)
    return folder


def test_processing_run_recovers_the_camera(provider, views, tmp_path):
    out = tmp_path / "camera.json"
    res = processing.run(ALG, {
        "IMAGES": [str(views)], "TARGET": 0, "COLUMNS": 9, "ROWS": 6, "SPACING": SQ_M,
        "LENS_PARAMETERS": [0, 1], "PIXEL_SIZE": 0.005, "OUTPUT_CAMERA": str(out),
        "OUTPUT_REPORT": str(tmp_path / "report.json"),
        "OUTPUT_RESIDUALS": str(tmp_path / "res.csv"), "OUTPUT_HTML": str(tmp_path / "r.html"),
    })  # fmt: skip
    assert res["VIEW_COUNT"] == 8 and res["POINT_COUNT"] == 8 * 54
    assert res["RMS_PX"] < 0.1
    cam = json.loads(out.read_text())
    assert abs(cam["focal_mm"] / 0.005 - F_PX) < 0.005 * F_PX
    # principal point: OpenCV's (322, 238) is (322.5, 238.5) in the project's pixels
    assert abs(cam["x0_mm"] / 0.005 + W / 2 - (CX + 0.5)) < 1.5
    assert abs(H / 2 - cam["y0_mm"] / 0.005 - (CY + 0.5)) < 1.5
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["parameters"] == ["focal_mm", "x0_mm", "y0_mm", "k1", "k2"]
    assert len(report["views"]) == 8
    page = (tmp_path / "r.html").read_text()
    assert "Camera calibration: camera (perspective)" in page and page.count("<tr") > 20
    lines = (tmp_path / "res.csv").read_text().splitlines()
    assert lines[0] == "image,point_id,col,row,v_col,v_row,w_col,w_row" and len(lines) == 433


def test_processing_run_refuses_a_missing_target(provider, views, tmp_path):
    with pytest.raises(QgsProcessingException, match="found in none of the 8 images"):
        processing.run(
            ALG,
            {
                "IMAGES": [str(views)],
                "TARGET": 0,
                "COLUMNS": 5,
                "ROWS": 12,
                "SPACING": SQ_M,
                "OUTPUT_CAMERA": str(tmp_path / "c.json"),
            },
        )
    assert not (tmp_path / "c.json").exists()


def test_qgis_process_run(qp_env, views, tmp_path):
    out = tmp_path / "camera.json"
    r = subprocess.run(
        [QGIS_PROCESS, "--json", "run", ALG, "--", f"IMAGES={views}", "TARGET=0", "COLUMNS=9",
         "ROWS=6", f"SPACING={SQ_M}", "PIXEL_SIZE=0.005", "LENS_PARAMETERS=0",
         f"OUTPUT_CAMERA={out}"],
        env=qp_env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    results = json.loads(r.stdout)["results"]
    assert results["VIEW_COUNT"] == 8
    assert math.isclose(json.loads(out.read_text())["focal_mm"] / 0.005, F_PX, rel_tol=0.005)
