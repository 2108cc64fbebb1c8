"""A tiled, pyramidal image viewer for picking image points (QGraphicsView).

The scene is in full-resolution pixel units of the image in the project convention: scene point
``(x, y)`` is pixel position ``(col, row)`` with the origin at the top-left *corner* of the
top-left pixel, so the centre of the first pixel is (0.5, 0.5). Picks are the exact (float)
scene position of the mouse, so their precision is a fraction of an image pixel once zoomed in.

Only what is visible is read: one coarse background picture of the whole image (<= 1024 px)
and 512 x 512 tiles of the pyramid level that matches the zoom (level L reads the image
decimated by 2**L through :class:`ImageSource`, i.e. the GDAL overviews).

Mouse and keys (also in :data:`VIEW_HELP`): wheel zooms about the cursor; middle or right
button, or Space + left button, pans; left click picks, left drag on a point moves it;
``+``/``-`` zoom, ``F`` fits the image, ``1`` shows one image pixel per screen pixel, ``M``
toggles the magnifier, arrow keys pan.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np
from qgis.PyQt.QtCore import QPointF, QRectF, Qt, QTimer, pyqtSignal
from qgis.PyQt.QtGui import QColor, QImage, QPainter, QPen, QPixmap, QTransform
from qgis.PyQt.QtWidgets import QGraphicsPixmapItem, QGraphicsScene, QGraphicsView, QLabel

from .image_source import ImageSource

__all__ = ["TILE", "VIEW_HELP", "ImageView", "event_position"]

TILE = 512
_BACKGROUND_SIDE = 1024
_MAX_TILES = 400
_MAX_ZOOM = 32.0
_DRAG_PX = 4.0
_HIT_PX = 8.0

VIEW_HELP = (
    "Wheel: zoom about the cursor · middle/right drag or Space+drag: pan · "
    "left click: pick · left drag on a point: move it · +/-: zoom · F: fit · "
    "1: 100 % · M: magnifier · arrows: pan"
)


def event_position(event) -> QPointF:
    """Float position of a mouse event in the receiving widget (Qt6 ``position()``, Qt5
    ``localPos()``)."""
    if hasattr(event, "position"):
        return QPointF(event.position())
    return QPointF(event.localPos())


def _to_qimage(a: np.ndarray) -> QImage:
    """A deep-copied QImage of an 8-bit (h, w) or (h, w, 3) array."""
    a = np.ascontiguousarray(a)
    h, w = a.shape[:2]
    if a.ndim == 2:
        img = QImage(a.data, w, h, a.strides[0], QImage.Format.Format_Grayscale8)
    else:
        img = QImage(a.data, w, h, a.strides[0], QImage.Format.Format_RGB888)
    return img.copy()  # own the pixels: `a` dies with this call


class ImageView(QGraphicsView):
    """Viewer of one :class:`ImageSource` with overlays on top (z > 0).

    Signals
    -------
    pointPicked(col, row)
        Left click (not a drag) at a scene position.
    pointMoved(key, col, row)
        A point reported by :attr:`hit_test` was dragged to a new position.
    cursorMoved(col, row)
    zoomChanged(zoom)
        Screen pixels per image pixel.
    """

    pointPicked = pyqtSignal(float, float)  # noqa: N815 - Qt signal naming
    pointMoved = pyqtSignal(object, float, float)  # noqa: N815 - Qt signal naming
    cursorMoved = pyqtSignal(float, float)  # noqa: N815 - Qt signal naming
    zoomChanged = pyqtSignal(float)  # noqa: N815 - Qt signal naming

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setScene(QGraphicsScene(self))
        self.setObjectName("lidarphotoImageView")
        self.setBackgroundBrush(QColor(40, 40, 40))
        self.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.setVerticalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.setTransformationAnchor(QGraphicsView.ViewportAnchor.NoAnchor)
        self.setResizeAnchor(QGraphicsView.ViewportAnchor.AnchorViewCenter)
        self.setViewportUpdateMode(QGraphicsView.ViewportUpdateMode.SmartViewportUpdate)
        self.setMouseTracking(True)
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self.setToolTip(VIEW_HELP)
        self.source: ImageSource | None = None
        #: ``hit_test(col, row, tolerance_px) -> key or None``: a movable point under the mouse
        self.hit_test: Callable[[float, float, float], object] | None = None
        self._tiles: dict[tuple[int, int, int], QGraphicsPixmapItem] = {}
        self._background: QGraphicsPixmapItem | None = None
        self._level = -1
        self._press: QPointF | None = None
        self._pan_from: QPointF | None = None
        self._drag_key = None
        self._drag_item = None
        self._space = False
        self.tiles_loaded = 0
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(0)
        self._timer.timeout.connect(self.update_tiles)
        self.magnifier = QLabel(self.viewport())
        self.magnifier.setObjectName("lidarphotoMagnifier")
        self.magnifier.setFixedSize(168, 168)
        self.magnifier.setStyleSheet("border: 2px solid #ffd400; background: #202020;")
        self.magnifier.hide()
        self.magnifier_factor = 4.0

    # -- image --------------------------------------------------------------------------------
    def set_source(self, source: ImageSource | None) -> None:
        """Show an image (None clears the view); fits it in the view."""
        for item in self._tiles.values():
            self.scene().removeItem(item)
        self._tiles.clear()
        if self._background is not None:
            self.scene().removeItem(self._background)
            self._background = None
        self.source = source
        self._level = -1
        if source is None:
            return
        w, h = source.width, source.height
        # room around the image so that any pixel can be brought to the centre of the view
        self.setSceneRect(QRectF(-w / 2, -h / 2, 2 * w, 2 * h))
        f = max(1.0, max(w, h) / _BACKGROUND_SIDE)
        a = source.read(0, 0, w, h, max(1, round(w / f)), max(1, round(h / f)))
        self._background = self._pixmap_item(a, 0, 0, w, h, z=-10.0)
        self.fit()

    def _pixmap_item(self, a, x0, y0, w, h, z) -> QGraphicsPixmapItem:
        item = QGraphicsPixmapItem(QPixmap.fromImage(_to_qimage(a)))
        item.setTransformationMode(Qt.TransformationMode.FastTransformation)  # crisp pixels
        item.setTransform(QTransform.fromScale(w / a.shape[1], h / a.shape[0]))
        item.setPos(x0, y0)
        item.setZValue(z)
        self.scene().addItem(item)
        return item

    @property
    def zoom(self) -> float:
        """Screen pixels per image pixel."""
        return float(self.transform().m11())

    def visible_rect(self) -> QRectF:
        """The part of the scene shown, scene units."""
        return self.mapToScene(self.viewport().rect()).boundingRect()

    def level_for_zoom(self) -> int:
        """Pyramid level whose decimation matches the zoom (0 at 100 % and closer)."""
        if self.source is None:
            return 0
        top = max(0, math.ceil(math.log2(max(self.source.width, self.source.height) / TILE)))
        return int(min(top, max(0, math.floor(math.log2(1.0 / max(self.zoom, 1e-9))))))

    def update_tiles(self) -> None:
        """Load the tiles of the visible area at the zoom's level; drop the others."""
        src = self.source
        if src is None:
            return
        level = self.level_for_zoom()
        f = 2**level
        span = TILE * f
        if level != self._level:  # another level: its tiles replace the previous ones
            for key in [k for k in self._tiles if k[0] != level]:
                self.scene().removeItem(self._tiles.pop(key))
            self._level = level
        r = self.visible_rect().intersected(QRectF(0, 0, src.width, src.height))
        if r.isEmpty():
            return
        tx0, ty0 = int(r.left() // span), int(r.top() // span)
        tx1, ty1 = math.ceil(r.right() / span), math.ceil(r.bottom() / span)
        for ty in range(ty0, ty1):
            for tx in range(tx0, tx1):
                key = (level, tx, ty)
                if key in self._tiles:
                    continue
                x0, y0 = tx * span, ty * span
                w, h = min(span, src.width - x0), min(span, src.height - y0)
                a = src.read(x0, y0, w, h, max(1, math.ceil(w / f)), max(1, math.ceil(h / f)))
                self._tiles[key] = self._pixmap_item(a, x0, y0, w, h, z=-5.0)
                self.tiles_loaded += 1
        if len(self._tiles) > _MAX_TILES:  # forget the tiles farthest from the view
            cx, cy = r.center().x(), r.center().y()
            far = sorted(
                self._tiles,
                key=lambda k: -math.hypot((k[1] + 0.5) * span - cx, (k[2] + 0.5) * span - cy),
            )
            for key in far[: len(self._tiles) - _MAX_TILES]:
                self.scene().removeItem(self._tiles.pop(key))

    def tile_count(self) -> int:
        return len(self._tiles)

    def _schedule(self) -> None:
        self._timer.start()

    # -- zoom and pan -------------------------------------------------------------------------
    def fit(self) -> None:
        """Show the whole image."""
        if self.source is None:
            return
        vp = self.viewport().rect()
        z = min(vp.width() / self.source.width, vp.height() / self.source.height) * 0.98
        self.set_zoom(z, QPointF(self.source.width / 2, self.source.height / 2))

    def set_zoom(self, zoom: float, centre: QPointF | None = None) -> None:
        """Set the zoom (screen px per image px) and optionally centre on a scene point."""
        c = centre if centre is not None else self.visible_rect().center()
        zoom = float(min(_MAX_ZOOM, max(1e-4, zoom)))
        self.setTransform(QTransform.fromScale(zoom, zoom))
        self.centerOn(c)
        self.zoomChanged.emit(zoom)
        self._schedule()

    def zoom_about(self, factor: float, view_pos: QPointF) -> None:
        """Zoom by ``factor`` keeping the scene point under ``view_pos`` (viewport px) fixed."""
        before = self._scene_f(view_pos)
        z = float(min(_MAX_ZOOM, max(1e-4, self.zoom * factor)))
        self.setTransform(QTransform.fromScale(z, z))
        after = self.viewportTransform().map(before)
        self._scroll_by(after.x() - view_pos.x(), after.y() - view_pos.y())
        self.zoomChanged.emit(z)
        self._schedule()

    def _scroll_by(self, dx: float, dy: float) -> None:
        h, v = self.horizontalScrollBar(), self.verticalScrollBar()
        h.setValue(h.value() + round(dx))
        v.setValue(v.value() + round(dy))
        self._schedule()

    def pan(self, dx: float, dy: float) -> None:
        """Move the image by (dx, dy) screen pixels."""
        self._scroll_by(-dx, -dy)

    def scrollContentsBy(self, dx: int, dy: int) -> None:
        super().scrollContentsBy(dx, dy)
        self._schedule()

    def resizeEvent(self, event) -> None:
        super().resizeEvent(event)
        self._schedule()

    def wheelEvent(self, event) -> None:
        steps = event.angleDelta().y() / 120.0
        if steps:
            self.zoom_about(1.25**steps, event_position(event))
        event.accept()

    # -- mouse --------------------------------------------------------------------------------
    def mousePressEvent(self, event) -> None:
        pos = event_position(event)
        button = event.button()
        if button in (Qt.MouseButton.MiddleButton, Qt.MouseButton.RightButton) or (
            button == Qt.MouseButton.LeftButton and self._space
        ):
            self._pan_from = pos
            self.viewport().setCursor(Qt.CursorShape.ClosedHandCursor)
            event.accept()
            return
        if button == Qt.MouseButton.LeftButton:
            self._press = pos
            scene_pos = self._scene_f(pos)
            self._drag_key = None
            if self.hit_test is not None:
                self._drag_key = self.hit_test(scene_pos.x(), scene_pos.y(), _HIT_PX / self.zoom)
            event.accept()
            return
        super().mousePressEvent(event)

    def _scene_f(self, pos: QPointF) -> QPointF:
        """Exact (float) scene position of a viewport position."""
        inv, _ok = self.viewportTransform().inverted()
        return inv.map(pos)

    def mouseMoveEvent(self, event) -> None:
        pos = event_position(event)
        if self._pan_from is not None:
            d = pos - self._pan_from
            self._pan_from = pos
            self.pan(d.x(), d.y())
            event.accept()
            return
        sp = self._scene_f(pos)
        self.cursorMoved.emit(sp.x(), sp.y())
        if self.magnifier.isVisible():
            self.update_magnifier(sp)
        if self._press is not None and self._drag_key is not None:
            self.viewport().setCursor(Qt.CursorShape.SizeAllCursor)
        event.accept()

    def mouseReleaseEvent(self, event) -> None:
        pos = event_position(event)
        if self._pan_from is not None:
            self._pan_from = None
            self.viewport().unsetCursor()
            event.accept()
            return
        if self._press is not None and event.button() == Qt.MouseButton.LeftButton:
            moved = math.hypot(pos.x() - self._press.x(), pos.y() - self._press.y())
            sp = self._scene_f(pos)
            if self._drag_key is not None and moved >= _DRAG_PX:
                self.pointMoved.emit(self._drag_key, sp.x(), sp.y())
            elif moved < _DRAG_PX:
                self.pointPicked.emit(sp.x(), sp.y())
            self._press = None
            self._drag_key = None
            self.viewport().unsetCursor()
            event.accept()
            return
        super().mouseReleaseEvent(event)

    # -- keys ---------------------------------------------------------------------------------
    def keyPressEvent(self, event) -> None:
        key = event.key()
        step = 60.0
        if key == Qt.Key.Key_Space and not event.isAutoRepeat():
            self._space = True
            self.viewport().setCursor(Qt.CursorShape.OpenHandCursor)
        elif key in (Qt.Key.Key_Plus, Qt.Key.Key_Equal):
            self.zoom_about(1.5, QPointF(self.viewport().rect().center()))
        elif key == Qt.Key.Key_Minus:
            self.zoom_about(1 / 1.5, QPointF(self.viewport().rect().center()))
        elif key == Qt.Key.Key_F:
            self.fit()
        elif key == Qt.Key.Key_1:
            self.set_zoom(1.0)
        elif key == Qt.Key.Key_M:
            self.magnifier.setVisible(not self.magnifier.isVisible())
        elif key == Qt.Key.Key_Left:
            self.pan(step, 0)
        elif key == Qt.Key.Key_Right:
            self.pan(-step, 0)
        elif key == Qt.Key.Key_Up:
            self.pan(0, step)
        elif key == Qt.Key.Key_Down:
            self.pan(0, -step)
        elif key in (Qt.Key.Key_PageUp, Qt.Key.Key_PageDown, Qt.Key.Key_Home, Qt.Key.Key_End):
            event.ignore()  # for the dock (the scroll area would scroll with them)
            return
        else:
            super().keyPressEvent(event)
            return
        event.accept()

    def keyReleaseEvent(self, event) -> None:
        if event.key() == Qt.Key.Key_Space and not event.isAutoRepeat():
            self._space = False
            self.viewport().unsetCursor()
        super().keyReleaseEvent(event)

    # -- magnifier ----------------------------------------------------------------------------
    def update_magnifier(self, centre: QPointF) -> None:
        """Render the scene around ``centre`` (scene units) magnified into the magnifier."""
        size = self.magnifier.width() - 4
        half = size / (2.0 * self.zoom * self.magnifier_factor)
        pm = QPixmap(size, size)
        pm.fill(QColor(32, 32, 32))
        painter = QPainter(pm)
        src = QRectF(centre.x() - half, centre.y() - half, 2 * half, 2 * half)
        self.scene().render(painter, QRectF(0, 0, size, size), src)
        painter.setPen(QPen(QColor(255, 212, 0), 1))
        c = size / 2.0
        painter.drawLine(QPointF(c - 10, c), QPointF(c + 10, c))
        painter.drawLine(QPointF(c, c - 10), QPointF(c, c + 10))
        painter.end()
        self.magnifier.setPixmap(pm)
        self.magnifier.move(self.viewport().width() - self.magnifier.width() - 6, 6)
