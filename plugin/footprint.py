"""The ground footprint of the current image on the QGIS map canvas (a ``QgsRubberBand``)."""

from __future__ import annotations

import numpy as np
from qgis.core import Qgis, QgsCoordinateTransform, QgsPointXY, QgsWkbTypes
from qgis.gui import QgsRubberBand
from qgis.PyQt.QtGui import QColor

__all__ = ["CanvasFootprint"]

if hasattr(Qgis, "GeometryType"):  # pragma: no cover - QGIS >= 3.30 / 4
    _POLYGON_GEOMETRY = Qgis.GeometryType.Polygon
else:  # QGIS 3.22-3.28 (scoped: PyQt6 has no unscoped enum values)
    _POLYGON_GEOMETRY = QgsWkbTypes.GeometryType.PolygonGeometry


class CanvasFootprint:
    """Draws an image's ground outline (mapping CRS) on the canvas of ``iface`` (none:
    nothing): four corners for a perspective camera, the curved outline of a fisheye."""

    def __init__(self, iface, project) -> None:
        self.iface = iface
        self.project = project
        self.rubber_band: QgsRubberBand | None = None

    def show(self, corners: np.ndarray | None, crs) -> None:
        """Draw the footprint ((K, 3) vertices in ``crs``: 4 corners, or a fisheye's outline;
        None or NaN: cleared)."""
        canvas = self.iface.mapCanvas() if self.iface is not None else None
        if canvas is None:
            return
        if self.rubber_band is None:
            self.rubber_band = QgsRubberBand(canvas, _POLYGON_GEOMETRY)
            self.rubber_band.setStrokeColor(QColor(255, 212, 0))
            self.rubber_band.setFillColor(QColor(255, 212, 0, 40))
            self.rubber_band.setWidth(2)
        self.rubber_band.reset(_POLYGON_GEOMETRY)
        if corners is None or not np.isfinite(corners).all() or len(corners) < 3:
            return
        vertices = np.asarray(corners, dtype=float)
        dest = canvas.mapSettings().destinationCrs()
        ct = QgsCoordinateTransform(crs, dest, self.project)
        last = len(vertices) - 1
        for k, (x, y, _z) in enumerate(vertices):
            self.rubber_band.addPoint(ct.transform(QgsPointXY(x, y)), k == last)
        self.rubber_band.show()

    def remove(self) -> None:
        if self.rubber_band is not None and self.iface is not None:
            self.iface.mapCanvas().scene().removeItem(self.rubber_band)
        self.rubber_band = None
