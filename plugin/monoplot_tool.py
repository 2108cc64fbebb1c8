"""Monoplotting in the image-picking dock: clicks on the image become 3D points and lines on
the QGIS map at once (core.monoplot on a LiDAR DSM).

The tool borrows the dock's image view while it is active: the view's ``pointPicked`` signal
goes to the tool instead of the dock's own picking, and is handed back by :meth:`stop`. It
uses the dock's camera, exterior orientation, mapping CRS and current image, and writes to two
memory layers (PointZ and LineStringZ, in the mapping CRS) that it adds to the project.
"""

from __future__ import annotations

import math

import numpy as np
from qgis.core import (
    NULL,
    QgsFeature,
    QgsField,
    QgsGeometry,
    QgsLineString,
    QgsPoint,
    QgsProject,
    QgsVectorLayer,
)
from qgis.PyQt.QtCore import QCoreApplication, QObject, pyqtSignal

from ..processing_provider.compat import FIELD_DOUBLE, FIELD_INT, FIELD_STRING

_FIELDS = (
    ("image_id", FIELD_STRING), ("col", FIELD_DOUBLE), ("row", FIELD_DOUBLE),
    ("sigma_x", FIELD_DOUBLE), ("sigma_y", FIELD_DOUBLE), ("sigma_z", FIELD_DOUBLE),
    ("status", FIELD_INT), ("status_text", FIELD_STRING),
)  # fmt: skip
_LINE_FIELDS = (("image_id", FIELD_STRING), ("n_vertices", FIELD_INT),
                ("status_text", FIELD_STRING))  # fmt: skip


class MonoplotTool(QObject):
    """Point and line monoplotting driven by clicks in an ``ImagePickingDock``."""

    pointMonoplotted = pyqtSignal(object)  # noqa: N815 - Qt signal naming; a MonoplotResult
    message = pyqtSignal(str)

    def __init__(self, dock, project: QgsProject | None = None) -> None:
        super().__init__(dock)
        self.dock = dock
        self.project = project or QgsProject.instance()
        self.tracer = None
        self.mode = ""
        self.line_step_px = 0.0
        self.sigma_dsm = 0.10
        self.vertices: list[tuple[float, float]] = []
        self.points_layer: QgsVectorLayer | None = None
        self.lines_layer: QgsVectorLayer | None = None

    def tr(self, text: str) -> str:
        return QCoreApplication.translate("MonoplotTool", text)

    # ------------------------------------------------------------------ setup
    def set_dsm(self, path: str, cell_size: float = 0.5, crs: str | None = None) -> None:
        """Load (or rasterise) the DSM once and prepare it for ray casting."""
        from ..core.dsm import load_dsm
        from ..core.monoplot import DsmTracer

        self.tracer = DsmTracer.build(load_dsm(path, cell_size, crs))

    def start(self, mode: str = "point") -> None:
        """Take over the dock's clicks: ``"point"`` or ``"line"`` (finish with finish_line)."""
        if mode not in ("point", "line"):
            raise ValueError(f"mode must be 'point' or 'line', got {mode!r}")
        if not self.mode:
            self.dock.view.pointPicked.disconnect(self.dock.pick)
            self.dock.view.pointPicked.connect(self._picked)
        self.mode, self.vertices = mode, []

    def stop(self) -> None:
        """Give the clicks back to the dock's picking."""
        if self.mode:
            self.finish_line()
            self.dock.view.pointPicked.disconnect(self._picked)
            self.dock.view.pointPicked.connect(self.dock.pick)
        self.mode = ""

    # ------------------------------------------------------------------ work
    def monoplot(self, pixels, image_id: str | None = None, line: bool = False):
        """Monoplot pixels (N, 2) of an image (default: the dock's current one)."""
        from ..core.io.observations import ImageObservations
        from ..core.monoplot import run_monoplot

        crs = self.dock.eo_crs()
        if self.tracer is None or self.dock.camera is None or self.dock.eo is None:
            raise RuntimeError(self.tr("Load the camera, the orientation and a DSM first"))
        image = image_id or self.dock.current_image
        px = np.asarray(pixels, dtype=float).reshape(-1, 2)
        n = len(px)
        obs = ImageObservations.from_arrays(
            [image] * n, [str(k) for k in range(n)], px, 0.5, ["line" if line else "check"] * n,
            ["0"] * n,
        )  # fmt: skip
        return run_monoplot(
            obs, self.dock.camera, self.dock.eo, self.tracer, crs.authid() or crs.toWkt(),
            sigma_dsm=self.sigma_dsm, line_step_px=self.line_step_px if line else 0.0,
        )  # fmt: skip

    def _picked(self, col: float, row: float) -> None:
        if self.mode == "line":
            self.vertices.append((col, row))
            return
        try:
            res = self.monoplot([(col, row)])
        except Exception as exc:  # shown to the user, never raised into Qt's event loop
            self.message.emit(str(exc))
            return
        self._add_points(res)
        self.pointMonoplotted.emit(res)

    def finish_line(self) -> int:
        """Monoplot the clicked vertices as one 3D line; returns its number of vertices."""
        vertices, self.vertices = self.vertices, []
        if self.mode != "line" or len(vertices) < 2:
            return 0
        res = self.monoplot(vertices, line=True)
        self._add_points(res)
        v = [QgsPoint(*map(float, p)) for p in res.lines[0].vertices if np.isfinite(p).all()]
        from ..core.monoplot import STATUS_TEXT

        layer = self._layer("lines")
        feature = QgsFeature(layer.fields())
        if len(v) > 1:
            feature.setGeometry(QgsGeometry(QgsLineString(v)))
        feature.setAttributes([res.rows[0][0], len(res.lines[0].vertices),
                               STATUS_TEXT[res.lines[0].status]])  # fmt: skip
        layer.dataProvider().addFeatures([feature])
        layer.updateExtents()
        layer.triggerRepaint()
        return len(v)

    def _layer(self, kind: str) -> QgsVectorLayer:
        attr = f"{kind}_layer"
        layer = getattr(self, attr)
        if layer is None or not layer.isValid():
            geom = "PointZ" if kind == "points" else "LineStringZ"
            crs = self.dock.eo_crs()
            layer = QgsVectorLayer(f"{geom}?crs={crs.authid()}", self.tr(f"Monoplotted {kind}"),
                                   "memory")  # fmt: skip
            if not crs.authid():
                layer.setCrs(crs)
            spec = _FIELDS if kind == "points" else _LINE_FIELDS
            layer.dataProvider().addAttributes([QgsField(name, t) for name, t in spec])
            layer.updateFields()
            self.project.addMapLayer(layer)
            setattr(self, attr, layer)
        return layer

    def _add_points(self, res) -> None:
        from ..core.monoplot import STATUS_TEXT

        layer = self._layer("points")
        sig = res.sigmas
        features = []
        for k in range(len(res.rows)):
            f = QgsFeature(layer.fields())
            p = res.points[k]
            if np.isfinite(p).all():
                f.setGeometry(QgsGeometry(QgsPoint(*map(float, p))))
            st = int(res.status[k])
            vals = [res.rows[k][0], *res.pixels[k], *sig[k]]
            f.setAttributes([v if isinstance(v, str) else (float(v) if math.isfinite(v) else NULL)
                             for v in vals] + [st, STATUS_TEXT[st]])  # fmt: skip
            features.append(f)
        layer.dataProvider().addFeatures(features)
        layer.updateExtents()
        layer.triggerRepaint()
