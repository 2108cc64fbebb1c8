"""The picking dock's layout in the real QGIS desktop (qgis.bin under Xvfb, 1920 x 1080): the
image gets at least two thirds of the dock's height when docked (the tab pages fold away once
an image is shown), and the whole image is refitted when the dock is floated full screen.
Labels at fit zoom: a block's worth of point labels is hidden until the user zooms in."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import cv2
import numpy as np
import pytest

PROBE = Path(__file__).resolve().parent / "desktop_dock_probe.py"
DESKTOP = shutil.which("xvfb-run") and os.path.exists("/usr/bin/qgis.bin")


@pytest.mark.skipif(not DESKTOP, reason="needs the QGIS desktop and xvfb-run")
def test_the_image_has_two_thirds_of_the_docked_dock_and_refits_when_floated(tmp_path, plugin_dir):
    image, out = tmp_path / "frame.png", tmp_path / "geometry.json"
    rng = np.random.default_rng(7)
    cv2.imwrite(str(image), (rng.random((2000, 3000)) * 255).astype(np.uint8))
    env = {
        **os.environ,
        "PYTHONPATH": str(plugin_dir),
        "HOME": str(tmp_path),
        "LIDARPHOTO_PROBE_OUT": str(out),
        "LIDARPHOTO_PROBE_IMAGE": str(image),
    }
    env.pop("QT_QPA_PLATFORM", None)
    subprocess.run(
        [
            "xvfb-run",
            "-a",
            "-s",
            "-screen 0 1920x1080x24",
            "/usr/bin/qgis.bin",
            "--nologo",
            "--noversioncheck",
            "--noplugins",
            "--code",
            str(PROBE),
        ],
        env=env,
        timeout=240,
        capture_output=True,
    )
    got = json.loads(out.read_text(encoding="utf-8"))
    assert "error" not in got, got.get("error")
    assert got["window"] == [1920, 1080]
    docked = got["docked"]
    assert not docked["floating"] and docked["image"] == [3000, 2000]
    share = docked["view"][1] / docked["dock"][1]
    assert share >= 2 / 3, docked  # 0.28 before (253 of 910 px)
    floated = got["floated"]
    assert floated["floating"] and floated["dock"][1] > docked["dock"][1]
    (vw, vh), (w, h) = floated["viewport"], floated["image"]
    assert floated["zoom"] == pytest.approx(min(vw / w, vh / h) * 0.98, rel=1e-9)  # refitted


def test_labels_are_hidden_at_fit_zoom_when_they_would_cover_the_image(qgis_app):
    """1,336 observations on a 6000 x 4000 image: at fit zoom (0.13) the labels would cover
    the image and are hidden (markers stay), at 50 % they show; the selected point keeps its
    label; a handful of labels shows at any zoom."""
    from lidarphoto.core.photo.observation_list import Observation
    from lidarphoto.plugin.overlays import Overlays, labels_fit
    from qgis.PyQt.QtCore import QRectF
    from qgis.PyQt.QtWidgets import QApplication, QGraphicsScene, QGraphicsSimpleTextItem

    w, h = 6000, 4000
    scene = QGraphicsScene()
    scene.setSceneRect(QRectF(-w / 2, -h / 2, 2 * w, 2 * h))  # as ImageView sets it
    overlays = Overlays(scene)
    rng = np.random.default_rng(3)
    rows = [
        Observation("img", f"P{k}", rng.uniform(0, w), rng.uniform(0, h), "tie", "")
        for k in range(1336)
    ]
    overlays.set_zoom(0.13)
    overlays.set_observations(rows, selected=5)
    QApplication.processEvents()  # the count after the batch of labels

    def shown():
        labels = [i for i in scene.items() if isinstance(i, QGraphicsSimpleTextItem)]
        return sum(i.isVisible() for i in labels), len(labels)

    assert not labels_fit(1336, w * h, 0.13) and labels_fit(1336, w * h, 0.5)
    assert shown() == (1, 1337)  # only the selected one
    overlays.set_zoom(0.5)
    assert shown() == (1337, 1337)
    overlays.set_zoom(0.13)
    overlays.set_observations(rows[:40], selected=-1)
    QApplication.processEvents()
    assert shown() == (40, 40)  # few enough to show at fit zoom
