"""Run inside the real QGIS desktop (``qgis.bin --code``, tests/qgis/test_dock_layout_desktop.py):
open the picking dock docked at the right of the maximised main window, show an image, and
write the dock's and the image widget's geometry (docked, then floated full screen) as JSON
to ``$LIDARPHOTO_PROBE_OUT``; then quit QGIS."""

import json
import os
import traceback

from qgis.PyQt.QtCore import Qt, QTimer
from qgis.PyQt.QtWidgets import QApplication
from qgis.utils import iface

OUT = os.environ["LIDARPHOTO_PROBE_OUT"]
IMAGE = os.environ["LIDARPHOTO_PROBE_IMAGE"]
state = {}


def settle(ms=300):
    end = QTimer()
    end.setSingleShot(True)
    end.start(ms)
    while end.isActive():
        QApplication.processEvents()


def geometry(dock):
    view = dock.view
    vp = view.viewport()
    return {
        "dock": [dock.width(), dock.height()],
        "view": [view.width(), view.height()],
        "viewport": [vp.width(), vp.height()],
        "zoom": view.zoom,
        "image": [dock.source.width, dock.source.height] if dock.source else None,
        "floating": dock.isFloating(),
    }


def probe():
    try:
        import lidarphoto

        window = iface.mainWindow()
        window.showMaximized()  # without a window manager (Xvfb): the screen's geometry
        window.setGeometry(window.screen().availableGeometry())
        settle()
        plugin = lidarphoto.classFactory(iface)
        plugin.initGui()
        dock = plugin.toggle_image_dock(True)
        window.resizeDocks([dock], [800], Qt.Orientation.Horizontal)
        settle()
        state["screen"] = [window.screen().size().width(), window.screen().size().height()]
        state["window"] = [window.width(), window.height()]
        state["before_image"] = geometry(dock)
        dock.set_images([IMAGE])
        settle()
        state["docked"] = geometry(dock)
        dock.setFloating(True)
        dock.setGeometry(window.screen().availableGeometry())
        settle(600)
        state["floated"] = geometry(dock)
    except Exception:
        state["error"] = traceback.format_exc()
    with open(OUT, "w", encoding="utf-8") as fh:
        json.dump(state, fh)
    os._exit(0)


QTimer.singleShot(500, probe)
