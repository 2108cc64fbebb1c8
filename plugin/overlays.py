"""Overlays of the picking view: LiDAR planes, lines and control points, observations, their
residual vectors and tie-point predictions, drawn in image pixels (scene units of
:class:`ImageView`) with cosmetic pens so that their width does not change with the zoom.

Each kind lives in its own item group, toggled with :meth:`Overlays.set_visible`. Positions come
already projected (``core.picking.PickingScene``); NaN vertices (behind the camera) are skipped.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from qgis.PyQt.QtCore import QPointF, Qt
from qgis.PyQt.QtGui import QBrush, QColor, QFont, QPainterPath, QPen, QPolygonF
from qgis.PyQt.QtWidgets import (
    QGraphicsItem,
    QGraphicsItemGroup,
    QGraphicsPathItem,
    QGraphicsSimpleTextItem,
)

__all__ = ["GROUPS", "Overlays"]

#: overlay groups, drawing order bottom to top
GROUPS = ("planes", "lines", "lcps", "residuals", "observations", "predictions")
_Z = {name: 1.0 + k for k, name in enumerate(GROUPS)}
COLOURS = {
    "planes": QColor(0, 200, 255),
    "highlight": QColor(255, 212, 0),
    "lines": QColor(255, 90, 200),
    "lcps": QColor(255, 60, 60),
    "residuals": QColor(255, 140, 0),
    "observations": QColor(60, 255, 60),
    "selected": QColor(255, 255, 255),
    "predictions": QColor(255, 255, 0),
}


def _pen(colour: QColor, width: float = 1.5, style=Qt.PenStyle.SolidLine) -> QPen:
    pen = QPen(colour, width, style)
    pen.setCosmetic(True)  # constant screen width at every zoom
    return pen


def _marker(shape: str, size: float) -> QPainterPath:
    """A marker path in screen pixels (drawn with ItemIgnoresTransformations)."""
    path = QPainterPath()
    s = size
    if shape == "cross":
        path.moveTo(-s, 0)
        path.lineTo(s, 0)
        path.moveTo(0, -s)
        path.lineTo(0, s)
    elif shape == "x":
        path.moveTo(-s, -s)
        path.lineTo(s, s)
        path.moveTo(-s, s)
        path.lineTo(s, -s)
    elif shape == "square":
        path.addRect(-s, -s, 2 * s, 2 * s)
    else:  # circle
        path.addEllipse(QPointF(0, 0), s, s)
    return path


def _finite(p) -> bool:
    return bool(np.isfinite(p).all())


class Overlays:
    """The overlay item groups of one QGraphicsScene."""

    def __init__(self, scene) -> None:
        self.scene = scene
        self.groups: dict[str, QGraphicsItemGroup] = {}
        self.visible = {name: True for name in GROUPS}
        self.counts = {name: 0 for name in GROUPS}
        for name in GROUPS:
            self._new_group(name)

    def _new_group(self, name: str) -> QGraphicsItemGroup:
        group = QGraphicsItemGroup()
        group.setZValue(_Z[name])
        group.setVisible(self.visible[name])
        self.scene.addItem(group)
        self.groups[name] = group
        return group

    def clear(self, name: str) -> QGraphicsItemGroup:
        """Empty one group (a fresh group: removing a group deletes its children)."""
        old = self.groups.get(name)
        if old is not None:
            self.scene.removeItem(old)
        self.counts[name] = 0
        return self._new_group(name)

    def clear_all(self) -> None:
        for name in GROUPS:
            self.clear(name)

    def set_visible(self, name: str, on: bool) -> None:
        self.visible[name] = bool(on)
        self.groups[name].setVisible(bool(on))

    # -- builders -----------------------------------------------------------------------------
    def _label(self, group, text: str, at: Sequence[float], colour: QColor) -> None:
        item = QGraphicsSimpleTextItem(text)
        item.setBrush(QBrush(colour))
        font = QFont()
        font.setPointSizeF(8.0)
        font.setBold(True)
        item.setFont(font)
        item.setFlag(QGraphicsItem.GraphicsItemFlag.ItemIgnoresTransformations, True)
        item.setPos(float(at[0]), float(at[1]))
        group.addToGroup(item)

    def _add_marker(self, group, at, shape, size, colour, width=1.5) -> QGraphicsPathItem:
        item = QGraphicsPathItem(_marker(shape, size))
        item.setPen(_pen(colour, width))
        item.setFlag(QGraphicsItem.GraphicsItemFlag.ItemIgnoresTransformations, True)
        item.setPos(float(at[0]), float(at[1]))
        group.addToGroup(item)
        return item

    def set_planes(
        self, rings: Sequence[np.ndarray], ids: Sequence[str], highlighted: set[str] = frozenset()
    ) -> None:
        """Plane outlines (each (M, 2) pixels) with their ids at the ring centre."""
        group = self.clear("planes")
        for ring, pid in zip(rings, ids):
            r = np.asarray(ring, dtype=np.float64).reshape(-1, 2)
            if len(r) < 3 or not _finite(r):
                continue
            hot = str(pid) in highlighted
            colour = COLOURS["highlight" if hot else "planes"]
            path = QPainterPath()
            path.addPolygon(QPolygonF([QPointF(float(x), float(y)) for x, y in r]))
            path.closeSubpath()
            item = QGraphicsPathItem(path)
            item.setPen(_pen(colour, 3.0 if hot else 1.5))
            if hot:
                fill = QColor(colour)
                fill.setAlpha(50)
                item.setBrush(QBrush(fill))
            group.addToGroup(item)
            self._label(group, str(pid), r.mean(axis=0), colour)
            self.counts["planes"] += 1

    def set_lines(self, starts: np.ndarray, ends: np.ndarray, ids: Sequence[str]) -> None:
        """LiDAR lines as segments (L, 2) -> (L, 2) pixels."""
        group = self.clear("lines")
        for a, b, lid in zip(np.reshape(starts, (-1, 2)), np.reshape(ends, (-1, 2)), ids):
            if not (_finite(a) and _finite(b)):
                continue
            path = QPainterPath(QPointF(float(a[0]), float(a[1])))
            path.lineTo(float(b[0]), float(b[1]))
            item = QGraphicsPathItem(path)
            item.setPen(_pen(COLOURS["lines"], 2.0, Qt.PenStyle.DashLine))
            group.addToGroup(item)
            self._label(group, f"L{lid}", (a + b) / 2, COLOURS["lines"])
            self.counts["lines"] += 1

    def set_lcps(self, pixels: np.ndarray, ids: Sequence[str], highlighted=frozenset()) -> None:
        """LiDAR control points (P, 2) pixels."""
        group = self.clear("lcps")
        for p, cid in zip(np.reshape(pixels, (-1, 2)), ids):
            if not _finite(p):
                continue
            hot = str(cid) in highlighted
            colour = COLOURS["highlight" if hot else "lcps"]
            self._add_marker(group, p, "square", 9 if hot else 6, colour, 2.0)
            self._label(group, f"C{cid}", p + 2, colour)
            self.counts["lcps"] += 1

    def set_observations(
        self, pixels: np.ndarray, labels: Sequence[str], selected: int = -1
    ) -> None:
        """Measured points (N, 2) of the current image; ``selected`` is drawn larger."""
        group = self.clear("observations")
        for k, (p, text) in enumerate(zip(np.reshape(pixels, (-1, 2)), labels)):
            if not _finite(p):
                continue
            sel = k == selected
            colour = COLOURS["selected" if sel else "observations"]
            self._add_marker(group, p, "cross", 10 if sel else 7, colour, 2.0)
            self._add_marker(group, p, "circle", 10 if sel else 7, colour, 1.0)
            self._label(group, text, p, colour)
            self.counts["observations"] += 1

    def set_residuals(self, pixels: np.ndarray, v: np.ndarray, scale: float) -> None:
        """Residual vectors: a segment from each point along ``v`` (N, 2) px times ``scale``."""
        group = self.clear("residuals")
        for p, d in zip(np.reshape(pixels, (-1, 2)), np.reshape(v, (-1, 2))):
            if not (_finite(p) and _finite(d)):
                continue
            q = p + scale * d
            path = QPainterPath(QPointF(float(p[0]), float(p[1])))
            path.lineTo(float(q[0]), float(q[1]))
            item = QGraphicsPathItem(path)
            item.setPen(_pen(COLOURS["residuals"], 2.0))
            group.addToGroup(item)
            self.counts["residuals"] += 1

    def set_predictions(self, pixels: np.ndarray, labels: Sequence[str]) -> None:
        """Predicted tie-point positions waiting for confirmation."""
        group = self.clear("predictions")
        for p, text in zip(np.reshape(pixels, (-1, 2)), labels):
            if not _finite(p):
                continue
            self._add_marker(group, p, "x", 9, COLOURS["predictions"], 2.0)
            self._add_marker(group, p, "circle", 14, COLOURS["predictions"], 1.0)
            self._label(group, text + "?", p, COLOURS["predictions"])
            self.counts["predictions"] += 1
