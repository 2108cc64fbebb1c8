"""Monoplotting in the image-picking dock: clicks on the image become 3D points and lines on
the QGIS map at once (core.monoplot on a LiDAR DSM).

The tool borrows the dock's image view while it is active: the view's ``pointPicked`` signal
goes to the tool instead of the dock's own picking, and is handed back by :meth:`stop`. It
uses the dock's camera, exterior orientation, mapping CRS and current image, and writes to two
memory layers (PointZ and LineStringZ, in the mapping CRS) that it adds to the project;
:meth:`save` writes them to a GeoPackage. The dock's *Monoplot* button drives it
(``ImagePickingDock.set_monoplot``); the vertices of a line in progress are drawn in the image.
"""

from __future__ import annotations

import math
import os

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
from qgis.PyQt.QtCore import QCoreApplication, QObject, QPointF, Qt, pyqtSignal
from qgis.PyQt.QtGui import QColor, QPainterPath, QPen
from qgis.PyQt.QtWidgets import QGraphicsPathItem

from ..processing_provider import FIELD_DOUBLE, FIELD_INT, FIELD_STRING

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
        self._sketch: QGraphicsPathItem | None = None

    def tr(self, text: str) -> str:
        return QCoreApplication.translate("MonoplotTool", text)

    # ------------------------------------------------------------------ setup
    def set_dsm(
        self,
        path: str,
        cell_size: float = 0.5,
        crs: str | None = None,
        target_crs: str | None = None,
    ) -> str:
        """Load (or rasterise) the DSM once and prepare it for ray casting.

        ``crs`` overrides the file's CRS; a DSM in another CRS than ``target_crs`` (the
        exterior orientation's) is resampled into it once, heights transformed (raises
        CrsError when PROJ cannot, e.g. a missing geoid grid). Returns a note for the user
        ("" when the DSM was used as it is)."""
        import pyproj

        from ..core.geometry.raycast import DsmTracer
        from ..core.geometry.surface import reproject_dsm
        from ..core.io.dsm import load_dsm

        dsm = load_dsm(path, cell_size, crs)
        note = ""
        if target_crs and dsm.crs is not None:
            target = pyproj.CRS.from_user_input(target_crs)
            if not dsm.crs.equals(target, ignore_axis_order=True):
                source = dsm.crs.name
                dsm = reproject_dsm(dsm, target)
                note = self.tr(
                    "The DSM was in '{}': resampled into '{}' (cell {:g}) for monoplotting."
                ).format(source, target.name, dsm.cell)
        self.tracer = DsmTracer.build(dsm)
        return note

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
        self._draw_sketch()

    # ------------------------------------------------------------------ work
    def monoplot(self, pixels, image_id: str | None = None, line: bool = False):
        """Monoplot pixels (N, 2) of an image (default: the dock's current one)."""
        from ..core.photo.monoplot import monoplot
        from ..core.photo.observations import ImageObservations

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
        return monoplot(
            obs, self.dock.camera, self.dock.eo, self.tracer, crs.authid() or crs.toWkt(),
            sigma_dsm=self.sigma_dsm, line_step_px=self.line_step_px if line else 0.0,
        )  # fmt: skip

    def _oriented(self) -> bool:
        """The current image has a file and an orientation; else a message."""
        dock = self.dock
        sg = dock.scene_geometry
        if sg is None or not sg.has_image(dock.current_image):
            self.message.emit(
                self.tr("Image {} has no exterior orientation: nothing to monoplot.").format(
                    dock.current_image
                )
            )
            return False
        return True

    def _picked(self, col: float, row: float) -> None:
        if not self._oriented():
            return
        if self.mode == "line":
            self.vertices.append((col, row))
            self._draw_sketch()
            self.message.emit(
                self.tr("Line vertex {} (Enter or a double click ends the line).").format(
                    len(self.vertices)
                )
            )
            return
        try:
            res = self.monoplot([(col, row)])
        except Exception as exc:  # shown to the user, never raised into Qt's event loop
            self.message.emit(str(exc))
            return
        self._add_points(res)
        from ..core.photo.monoplot import STATUS_TEXT

        p, st = res.points[0], int(res.status[0])
        if np.isfinite(p).all():
            self.message.emit(
                self.tr("3D point {:.3f}, {:.3f}, {:.3f} (sigma Z {:.3f} m, {}).").format(
                    *p, float(res.sigmas[0, 2]), STATUS_TEXT[st]
                )
            )
        else:
            self.message.emit(self.tr("No 3D point: {}.").format(STATUS_TEXT[st]))
        self.pointMonoplotted.emit(res)

    def _draw_sketch(self) -> None:
        """The vertices of the line in progress, as a polyline in the image."""
        scene = self.dock.view.scene()
        if self._sketch is not None:
            scene.removeItem(self._sketch)
            self._sketch = None
        if self.mode != "line" or not self.vertices:
            return
        path = QPainterPath(QPointF(*self.vertices[0]))
        for v in self.vertices[1:]:
            path.lineTo(QPointF(*v))
        for v in self.vertices:
            path.addEllipse(QPointF(*v), 2.0, 2.0)
        pen = QPen(QColor(0, 255, 255), 2.0, Qt.PenStyle.SolidLine)
        pen.setCosmetic(True)
        self._sketch = QGraphicsPathItem(path)
        self._sketch.setPen(pen)
        self._sketch.setZValue(50.0)
        scene.addItem(self._sketch)

    def finish_line(self) -> int:
        """Monoplot the clicked vertices as one 3D line; returns its number of vertices."""
        vertices, self.vertices = self.vertices, []
        self._draw_sketch()
        if self.mode != "line" or len(vertices) < 2:
            if self.mode == "line" and vertices:
                self.message.emit(self.tr("A line needs two vertices or more."))
            return 0
        res = self.monoplot(vertices, line=True)
        self._add_points(res)
        v = [QgsPoint(*map(float, p)) for p in res.lines[0].vertices if np.isfinite(p).all()]
        from ..core.photo.monoplot import STATUS_TEXT

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
            title = (
                self.tr("Monoplotted points") if kind == "points" else self.tr("Monoplotted lines")
            )
            layer = QgsVectorLayer(f"{geom}?crs={crs.authid()}", title, "memory")
            if not crs.authid():
                layer.setCrs(crs)
            spec = _FIELDS if kind == "points" else _LINE_FIELDS
            layer.dataProvider().addAttributes([QgsField(name, t) for name, t in spec])
            layer.updateFields()
            self.project.addMapLayer(layer)
            setattr(self, attr, layer)
        return layer

    def _add_points(self, res) -> None:
        from ..core.photo.monoplot import STATUS_TEXT

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

    # ------------------------------------------------------------------ saving
    def save(self, path: str) -> list[str]:
        """Write the points and lines layers (those that exist) to the GeoPackage ``path``
        (created, or its tables replaced); returns the names of the tables written."""
        from qgis.core import QgsVectorFileWriter

        written: list[str] = []
        for layer, name in ((self.points_layer, "monoplot_points"),
                            (self.lines_layer, "monoplot_lines")):  # fmt: skip
            if layer is None or not layer.isValid() or layer.featureCount() == 0:
                continue
            options = QgsVectorFileWriter.SaveVectorOptions()
            options.driverName = "GPKG"
            options.layerName = name
            first = not written and not os.path.exists(path)
            options.actionOnExistingFile = (
                QgsVectorFileWriter.ActionOnExistingFile.CreateOrOverwriteFile
                if first
                else QgsVectorFileWriter.ActionOnExistingFile.CreateOrOverwriteLayer
            )
            ctx = self.project.transformContext()
            if hasattr(QgsVectorFileWriter, "writeAsVectorFormatV3"):
                res = QgsVectorFileWriter.writeAsVectorFormatV3(layer, path, ctx, options)
            else:  # pragma: no cover - QGIS < 3.20
                res = QgsVectorFileWriter.writeAsVectorFormatV2(layer, path, ctx, options)
            if res[0] != QgsVectorFileWriter.WriterError.NoError:
                raise RuntimeError(f"{path}: {res[1]}")
            written.append(name)
        return written
