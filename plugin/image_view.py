"""A tiled, pyramidal image viewer for picking image points (QGraphicsView).

The scene is in full-resolution pixel units of the image in the project convention: scene point
``(x, y)`` is pixel position ``(col, row)`` with the origin at the top-left *corner* of the
top-left pixel, so the centre of the first pixel is (0.5, 0.5). A pick is the scene position of
the *centre* of the screen pixel under the cursor (:func:`pointer_position`): Qt reports the
cursor as the integer top-left corner of that pixel, which would put every pick half a screen
pixel up and left of where the user points (0.7 image px at 100 %). At 100 % a click on the
screen pixel that shows image pixel (c, r) measures (c + 0.5, r + 0.5); zoomed in, the
precision is a fraction of an image pixel.

Only what is visible is read: one coarse background picture of the whole image (<= 1024 px)
and 512 x 512 tiles of the pyramid level that matches the zoom (level L reads the image
decimated by 2**L through :class:`ImageSource`, i.e. the GDAL overviews).

The GUI thread never waits for GDAL on its own: tiles are read by a worker thread
(:class:`~.image_loader.TileLoader`) and arrive by signal, the tiles of the previous level stay
on screen until the new level is complete, and requests made stale by further zooming or
panning are dropped. An image without overviews is first shown as a coarse preview read in the
worker (a placeholder until then) while its pyramid is built in the background
(:class:`~.image_loader.OverviewTask`, progress in :attr:`ImageView.overviewProgress` and in the
view's status line); the sharp pyramid levels replace the preview when it is done.
:meth:`ImageView.update_tiles` stays synchronous for callers that want the tiles now.

Mouse and keys (also in :data:`VIEW_HELP`): wheel zooms about the cursor; middle or right
button, or Space + left button, pans; left click picks, left drag on a point moves it;
``+``/``-`` zoom, ``F`` fits the image, ``1`` shows one image pixel per screen pixel, ``M``
toggles the magnifier, arrow keys pan.
"""

from __future__ import annotations

import math
import time
from typing import Callable

from qgis.core import QgsApplication
from qgis.PyQt.QtCore import (
    QT_TRANSLATE_NOOP,
    QCoreApplication,
    QPointF,
    QRectF,
    Qt,
    QTimer,
    pyqtSignal,
)
from qgis.PyQt.QtGui import QBrush, QColor, QImage, QPainter, QPen, QPixmap, QTransform
from qgis.PyQt.QtWidgets import (
    QApplication,
    QGraphicsPixmapItem,
    QGraphicsRectItem,
    QGraphicsScene,
    QGraphicsView,
    QLabel,
)

from .image_loader import OverviewTask, TileLoader, TileRequest, to_qimage
from .image_source import ImageSource, ImageSourceError, error_text

__all__ = [
    "TILE",
    "VIEW_HELP",
    "ImageView",
    "event_position",
    "pointer_position",
    "view_help",
]

TILE = 512
_MAX_TILES = 400
_MAX_ZOOM = 32.0
_DRAG_PX = 4.0
_HIT_PX = 8.0
_Z_PLACEHOLDER, _Z_BACKGROUND, _Z_OLD_LEVEL, _Z_TILE = -12.0, -10.0, -6.0, -5.0
#: while the pyramid is built, the preview stands for the tiles up to this upscaling on screen
_PREVIEW_UPSCALE = 1.5

VIEW_HELP = QT_TRANSLATE_NOOP(
    "ImageView",
    "Wheel: zoom about the cursor · middle/right drag or Space+drag: pan · "
    "left click: pick · left drag on a point: move it · +/-: zoom · F: fit · "
    "1: 100 % · M: magnifier · arrows: pan",
)


def view_help() -> str:
    """The viewer's mouse and keys, in QGIS's language."""
    return QCoreApplication.translate("ImageView", VIEW_HELP)


#: overview tasks still running, kept referenced until they end (a QgsTask whose Python object
#: is collected while it runs crashes QGIS)
_LIVE_TASKS: set = set()


def event_position(event) -> QPointF:
    """Float position of a mouse or wheel event in the receiving widget, as Qt gives it (Qt6
    and Qt 5.15 wheel events ``position()``, Qt5 mouse events ``localPos()``)."""
    if hasattr(event, "position"):
        return QPointF(event.position())
    return QPointF(event.localPos())


def pointer_position(event, device_pixel_ratio: float = 1.0) -> QPointF:
    """Where the user points, in the receiving widget's coordinates: the centre of the
    (device) pixel under the cursor.

    Qt gives a mouse position as the top-left corner of the pixel under the cursor's hot
    spot: an integer number of device pixels (logical pixels times ``device_pixel_ratio``).
    Such a coordinate is moved by half a device pixel, to the pixel's centre; a coordinate
    that is not a whole number of device pixels (a tablet, or a touchpad that reports
    sub-pixel positions) is the position itself and is kept.
    """
    p = event_position(event)
    r = float(device_pixel_ratio) or 1.0
    out = []
    for v in (p.x() * r, p.y() * r):
        if abs(v - round(v)) < 1e-6:  # a whole device pixel: its top-left corner
            v = round(v) + 0.5
        out.append(v / r)
    return QPointF(out[0], out[1])


def _pixel_ratio(widget) -> float:
    """Device pixels per logical pixel of a widget (Qt5 ``devicePixelRatioF``)."""
    f = getattr(widget, "devicePixelRatioF", None) or widget.devicePixelRatio
    return float(f())


_to_qimage = to_qimage  # the name used before the loader module existed


def _shutdown(loader: TileLoader, tasks: set) -> None:
    """When the view is destroyed: stop its worker and cancel its overview build."""
    loader.shutdown()
    for task in list(tasks):
        try:
            task.cancel()
        except RuntimeError:  # already deleted by the task manager
            pass


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
    overviewProgress(percent)
        The background build of the image's overview pyramid, 0..100.
    overviewFinished(ok, message)
        The build ended: built, failed (message says why) or cancelled.
    loadFailed(message)
        A background read failed (message names the file).
    tilesIdle()
        Every tile of the visible area at the zoom's level is on screen.
    """

    pointPicked = pyqtSignal(float, float)  # noqa: N815 - Qt signal naming
    pointMoved = pyqtSignal(object, float, float)  # noqa: N815 - Qt signal naming
    cursorMoved = pyqtSignal(float, float)  # noqa: N815 - Qt signal naming
    zoomChanged = pyqtSignal(float)  # noqa: N815 - Qt signal naming
    overviewProgress = pyqtSignal(float)  # noqa: N815 - Qt signal naming
    overviewFinished = pyqtSignal(bool, str)  # noqa: N815 - Qt signal naming
    loadFailed = pyqtSignal(str)  # noqa: N815 - Qt signal naming
    tilesIdle = pyqtSignal()  # noqa: N815 - Qt signal naming

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
        self.setToolTip(view_help())
        self.source: ImageSource | None = None
        #: ``hit_test(col, row, tolerance_px) -> key or None``: a movable point under the mouse
        self.hit_test: Callable[[float, float, float], object] | None = None
        self._tiles: dict[tuple[int, int, int], QGraphicsPixmapItem] = {}
        self._background: QGraphicsPixmapItem | None = None
        self._placeholder: QGraphicsRectItem | None = None
        self._level = -1
        self._press: QPointF | None = None
        self._pan_from: QPointF | None = None
        self._drag_key = None
        self._drag_item = None
        self._space = False
        #: the whole image is in view as fit() put it (a resize refits it)
        self.fitted = False
        self.tiles_loaded = 0
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(0)
        self._timer.timeout.connect(self._request_tiles)
        self.magnifier = QLabel(self.viewport())
        self.magnifier.setObjectName("lidarphotoMagnifier")
        self.magnifier.setFixedSize(168, 168)
        self.magnifier.setStyleSheet("border: 2px solid #ffd400; background: #202020;")
        self.magnifier.hide()
        self.magnifier_factor = 4.0
        #: what the background work is doing (shown at the bottom of the view)
        self.status_label = QLabel(self.viewport())
        self.status_label.setObjectName("lidarphotoImageStatus")
        self.status_label.setStyleSheet(
            "color: #ffffff; background: rgba(0, 0, 0, 170); padding: 3px;"
        )
        self.status_label.hide()
        # -- background work
        self._loader = TileLoader()
        self._loader.previewReady.connect(self._on_preview)
        self._loader.tileReady.connect(self._on_tile)
        self._loader.failed.connect(self._on_failed)
        self._sgen = 0
        self._pending: list[tuple[int, int, int]] = []
        self._task: OverviewTask | None = None
        self._tasks: set = set()
        self._build_after_preview = False
        self.preview_shown = False
        self.last_error = ""
        self.destroyed.connect(
            lambda *_a, loader=self._loader, tasks=self._tasks: _shutdown(loader, tasks)
        )

    # -- image --------------------------------------------------------------------------------
    def set_source(self, source: ImageSource | None, build_overviews: bool = True) -> None:
        """Show an image (None clears the view); fits it in the view.

        Returns at once: an image whose whole-image read is slow (no overviews), or whose
        contrast stretch is not computed yet (``ImageSource(stretch_now=False)``), is shown
        as a placeholder, then as a coarse preview read in the worker thread; with
        ``build_overviews`` its missing pyramid is built in the background (a running build of
        the previous image is cancelled).
        """
        self._cancel_build()
        self._build_after_preview = False
        for item in self._tiles.values():
            self.scene().removeItem(item)
        self._tiles.clear()
        for item in (self._background, self._placeholder):
            if item is not None:
                self.scene().removeItem(item)
        self._background = self._placeholder = None
        self._pending = []
        self.source = source
        self._level = -1
        self.preview_shown = False
        self.last_error = ""
        self._sgen = self._loader.set_source(source)
        if source is None:
            self._status("")
            return
        w, h = source.width, source.height
        # room around the image so that any pixel can be brought to the centre of the view
        self.setSceneRect(QRectF(-w / 2, -h / 2, 2 * w, 2 * h))
        self._placeholder = QGraphicsRectItem(0.0, 0.0, float(w), float(h))
        self._placeholder.setBrush(QBrush(QColor(70, 70, 70)))
        self._placeholder.setPen(QPen(Qt.PenStyle.NoPen))
        self._placeholder.setZValue(_Z_PLACEHOLDER)
        self.scene().addItem(self._placeholder)
        self._build_after_preview = bool(build_overviews and source.needs_overviews)
        if source.quick and source.stretch_limits is not None:
            # a small pyramid level (or image) whose stretch is known: show it now
            self._show_background(source.stretch(source.sample()))
        else:  # the worker reads the preview (and the stretch) without blocking
            if not source.quick:
                self._status(self.tr("Reading a preview of {}…").format(source.path.name))
            self._loader.request_preview()
        if self.preview_shown:
            self._start_pending_build()
        self.fit()

    def _show_background(self, image) -> None:
        if self._background is not None:
            self.scene().removeItem(self._background)
        qimage = image if isinstance(image, QImage) else to_qimage(image)
        w, h = self.source.width, self.source.height
        self._background = self._pixmap_item(qimage, 0, 0, w, h, z=_Z_BACKGROUND)
        self.preview_shown = True

    def _pixmap_item(self, a, x0, y0, w, h, z) -> QGraphicsPixmapItem:
        qimage = a if isinstance(a, QImage) else to_qimage(a)
        item = QGraphicsPixmapItem(QPixmap.fromImage(qimage))
        item.setTransformationMode(Qt.TransformationMode.FastTransformation)  # crisp pixels
        item.setTransform(QTransform.fromScale(w / qimage.width(), h / qimage.height()))
        item.setPos(x0, y0)
        item.setZValue(z)
        self.scene().addItem(item)
        return item

    # -- background work ----------------------------------------------------------------------
    def _status(self, text: str) -> None:
        if not text:
            self.status_label.hide()
            return
        self.status_label.setText(text)
        self.status_label.adjustSize()
        self.status_label.move(6, max(0, self.viewport().height() - self.status_label.height() - 6))
        self.status_label.show()

    def _start_build(self, source: ImageSource) -> None:
        task = OverviewTask(source)
        self._task = task
        self._tasks.add(task)
        _LIVE_TASKS.add(task)
        task.progressChanged.connect(self._on_build_progress)
        task.done.connect(lambda ok, msg, task=task: self._on_build_done(task, ok, msg))
        self._status(
            self.tr("Building the overview pyramid of {}: {:.0f} %").format(source.path.name, 0)
        )
        QgsApplication.taskManager().addTask(task)

    def _cancel_build(self) -> None:
        task, self._task = self._task, None
        if task is not None:
            try:
                task.cancel()
            except RuntimeError:
                pass

    def building(self) -> bool:
        """Whether the overview build of the current image runs (or waits for the preview)."""
        return self._task is not None or self._build_after_preview

    def shutdown(self, timeout_s: float = 30.0) -> bool:
        """Clear the view, cancel its overview build and wait until its background work has
        ended (e.g. when the plugin unloads). True when everything stopped in time."""
        self.set_source(None)
        t_end = time.perf_counter() + timeout_s
        app = QApplication.instance()
        while self._tasks and time.perf_counter() < t_end:
            app.processEvents()  # a cancelled task reports its end through the event loop
            time.sleep(0.005)
        return self._loader.join(max(0.0, t_end - time.perf_counter())) and not self._tasks

    def background_tasks(self) -> int:
        """Overview builds of this view not ended yet (a cancelled one ends shortly after)."""
        return len(self._tasks)

    def _on_build_progress(self, pct: float) -> None:
        if self.sender() is not self._task or self.source is None:
            return
        self._status(
            self.tr("Building the overview pyramid of {}: {:.0f} %").format(
                self.source.path.name, pct
            )
        )
        self.overviewProgress.emit(float(pct))

    def _on_build_done(self, task: OverviewTask, ok: bool, message: str) -> None:
        self._tasks.discard(task)
        _LIVE_TASKS.discard(task)
        if task is not self._task:  # the build of an image no longer shown (cancelled)
            return
        self._task = None
        src = self.source
        if ok and src is not None:
            try:
                src.reopen()  # now it sees the pyramid
            except ImageSourceError as exc:  # e.g. QGIS shutting down (GDAL's drivers gone)
                ok, message = False, error_text(exc)
        if ok and src is not None:
            self._loader.reopen()
            self._status("")
            if src.quick:  # the pyramid's averaged level replaces the decimated preview
                self._show_background(src.stretch(src.sample()))
            # tiles above level 0 were decimated from full resolution: read the pyramid's
            for key in [k for k in self._tiles if k[0] > 0]:
                self.scene().removeItem(self._tiles.pop(key))
            self._pending = []
            self._schedule()
        else:
            self._status(message)
        self.build_cancelled = bool(getattr(task, "cancelled", False))
        self.overviewFinished.emit(ok, message)

    def _on_preview(self, sgen: int, qimage: QImage, limits) -> None:
        if sgen != self._sgen or self.source is None:
            return
        if limits is not None and self.source.stretch_limits is None:
            self.source.set_stretch_limits(*limits)
        self._show_background(qimage)
        if self._task is None:
            self._status("")
        self._start_pending_build()

    def _start_pending_build(self) -> None:
        """The pyramid build starts once the preview is shown: both read the whole image, and
        on a tiled file (every tile decoded) running them together delays the preview ~2x."""
        if self._build_after_preview and self.source is not None and self._task is None:
            self._build_after_preview = False
            self._start_build(self.source)

    def _on_failed(self, sgen: int, message: str) -> None:
        if sgen != self._sgen:
            return
        self.last_error = message
        self._pending = []
        self._status(message)
        self._build_after_preview = False  # an unreadable image gets no pyramid either
        self.loadFailed.emit(message)

    def _on_tile(self, sgen: int, key, qimage: QImage) -> None:
        if sgen != self._sgen or self.source is None:
            return
        if key in self._pending:
            self._pending.remove(key)
        if key[0] == self._level and key not in self._tiles:
            _level, tx, ty = key
            span = TILE * 2 ** key[0]
            x0, y0 = tx * span, ty * span
            w, h = min(span, self.source.width - x0), min(span, self.source.height - y0)
            self._tiles[key] = self._pixmap_item(qimage, x0, y0, w, h, z=_Z_TILE)
            self.tiles_loaded += 1
        if not self._pending:
            self._request_tiles()  # drops the other levels when this one is complete

    def pending_tiles(self) -> int:
        """Tiles requested from the worker and not arrived yet."""
        return len(self._pending)

    def busy(self) -> bool:
        """Whether a preview or tiles are still being read, or the pyramid built."""
        return bool(self._pending) or self._loader.busy() or self.building()

    def wait_idle(self, timeout_s: float = 60.0, build: bool = True) -> bool:
        """Process events until the visible tiles are all shown (and, with ``build``, the
        pyramid is built); for tests and benchmarks. Returns False on timeout."""
        app = QApplication.instance()
        t_end = time.perf_counter() + timeout_s
        while time.perf_counter() < t_end:
            app.processEvents()
            if self._timer.isActive():
                continue
            if self.last_error:
                return False
            waiting = bool(self._pending) or (self.source is not None and not self.preview_shown)
            if not waiting and not (build and self.building()):
                return True
            time.sleep(0.002)
        return False

    # -- tiles --------------------------------------------------------------------------------
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

    def visible_tiles(self) -> tuple[int, list[TileRequest]]:
        """The zoom's level and its tiles covering the view, nearest to the centre first."""
        src = self.source
        level = self.level_for_zoom()
        if src is None:
            return level, []
        f = 2**level
        span = TILE * f
        r = self.visible_rect().intersected(QRectF(0, 0, src.width, src.height))
        if r.isEmpty():
            return level, []
        tx0, ty0 = int(r.left() // span), int(r.top() // span)
        tx1, ty1 = math.ceil(r.right() / span), math.ceil(r.bottom() / span)
        cx, cy = r.center().x(), r.center().y()
        out = []
        for ty in range(ty0, ty1):
            for tx in range(tx0, tx1):
                x0, y0 = tx * span, ty * span
                w, h = min(span, src.width - x0), min(span, src.height - y0)
                ow, oh = max(1, math.ceil(w / f)), max(1, math.ceil(h / f))
                out.append(TileRequest((level, tx, ty), x0, y0, w, h, ow, oh))
        out.sort(key=lambda t: math.hypot(t.x0 + t.w / 2 - cx, t.y0 + t.h / 2 - cy))
        return level, out

    def _enter_level(self, level: int, keep_others: bool) -> None:
        if level == self._level:
            return
        self._level = level
        for key in [k for k in self._tiles if k[0] != level]:
            if keep_others:  # shown under the new level until it is complete
                self._tiles[key].setZValue(_Z_OLD_LEVEL)
            else:
                self.scene().removeItem(self._tiles.pop(key))

    def _drop_other_levels(self) -> None:
        for key in [k for k in self._tiles if k[0] != self._level]:
            self.scene().removeItem(self._tiles.pop(key))

    def update_tiles(self) -> None:
        """Load the tiles of the visible area at the zoom's level now, in this thread; drop
        the others. (The view itself loads them in the background: see the module notes.)"""
        src = self.source
        if src is None:
            return
        level, tiles = self.visible_tiles()
        self._enter_level(level, keep_others=False)
        self._drop_other_levels()
        for t in tiles:
            if t.key in self._tiles:
                continue
            a = src.read(t.x0, t.y0, t.w, t.h, t.out_w, t.out_h)
            self._tiles[t.key] = self._pixmap_item(a, t.x0, t.y0, t.w, t.h, z=_Z_TILE)
            self.tiles_loaded += 1
        self._pending = [k for k in self._pending if k not in self._tiles]
        self._trim()

    def _request_tiles(self) -> None:
        """Ask the worker for the missing visible tiles (coarse ones stay until they come)."""
        if self.source is None:
            return
        level, tiles = self.visible_tiles()
        if self._preview_suffices():
            tiles = []
        self._enter_level(level, keep_others=True)
        missing = [t for t in tiles if t.key not in self._tiles]
        if not missing:
            self._pending = []
            self._drop_other_levels()
            self._trim()
            self.tilesIdle.emit()
            return
        keys = [t.key for t in missing]
        if keys != self._pending:  # a request the worker already has is not repeated
            self._pending = keys
            self._loader.request_tiles(missing)

    def _preview_suffices(self) -> bool:
        """Without a pyramid yet, a zoomed-out view keeps the preview instead of tiles: each
        tile would be decimated from full resolution (every strip or tile decoded), competing
        with the pyramid build, for a picture at most ``_PREVIEW_UPSCALE`` x sharper."""
        src = self.source
        if src is None or src.overview_count or self.last_error or not self.building():
            return False  # (a preview not shown yet is on its way: the worker reads it first)
        preview_scale = src.stretch_sample_size()[0] / src.width  # preview px per image px
        return self.zoom <= _PREVIEW_UPSCALE * preview_scale

    def _trim(self) -> None:
        if len(self._tiles) <= _MAX_TILES:
            return
        r = self.visible_rect()
        cx, cy = r.center().x(), r.center().y()

        def distance(k):
            span = TILE * 2 ** k[0]
            return math.hypot((k[1] + 0.5) * span - cx, (k[2] + 0.5) * span - cy)

        for key in sorted(self._tiles, key=distance, reverse=True)[: len(self._tiles) - _MAX_TILES]:
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
        self.fitted = True  # refitted on a resize until the user zooms or pans

    def set_zoom(self, zoom: float, centre: QPointF | None = None) -> None:
        """Set the zoom (screen px per image px) and optionally centre on a scene point."""
        self.fitted = False  # fit() sets it again
        c = centre if centre is not None else self.visible_rect().center()
        zoom = float(min(_MAX_ZOOM, max(1e-4, zoom)))
        self.setTransform(QTransform.fromScale(zoom, zoom))
        self.centerOn(c)
        self.zoomChanged.emit(zoom)
        self._schedule()

    def zoom_about(self, factor: float, view_pos: QPointF) -> None:
        """Zoom by ``factor`` keeping the scene point under ``view_pos`` (viewport px) fixed."""
        self.fitted = False
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
        self.fitted = False
        self._scroll_by(-dx, -dy)

    def scrollContentsBy(self, dx: int, dy: int) -> None:
        super().scrollContentsBy(dx, dy)
        self._schedule()

    def resizeEvent(self, event) -> None:
        super().resizeEvent(event)
        if self.fitted:  # docked, floated, maximised: the whole image stays in view
            self.fit()
        if self.status_label.isVisible():  # keep it in the bottom-left corner
            self._status(self.status_label.text())
        self._schedule()

    def wheelEvent(self, event) -> None:
        steps = event.angleDelta().y() / 120.0
        if steps:
            self.zoom_about(1.25**steps, self._pointer(event))
        event.accept()

    # -- mouse --------------------------------------------------------------------------------
    def _pointer(self, event) -> QPointF:
        """The viewport position the user points at (centre of the pixel under the cursor)."""
        return pointer_position(event, _pixel_ratio(self.viewport()))

    def mousePressEvent(self, event) -> None:
        pos = self._pointer(event)
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
        pos = self._pointer(event)
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
        pos = self._pointer(event)
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
