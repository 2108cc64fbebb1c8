"""Background work of the image viewer: tile reads in a worker thread, the overview build as a
QGIS task. The GUI thread only receives finished ``QImage`` s (by queued signals), so it never
waits for GDAL.

* :class:`TileLoader` runs one job at a time in its own Python thread, which ends after a short
  idle time (so nothing is left running when QGIS closes). Not a thread of Qt's global pool:
  Qt's own helpers (image conversion, QGIS rendering) need free threads there while the GUI
  thread waits, holding the GIL. Its reader is its own GDAL handle
  (:meth:`ImageSource.clone`), opened in that thread: GDAL datasets are not thread-safe.
  Requests carry a generation number; a tile request made stale by a newer one (the user
  panned or zoomed on) is dropped, and a long read in progress is aborted through GDAL's
  progress callback.
* :class:`OverviewTask` builds the missing ``.ovr`` (:func:`build_overview_file`, temporary
  name then rename) in the QGIS task manager: its progress shows in QGIS's status bar and the
  user can cancel it there as well.
"""

from __future__ import annotations

import atexit
import threading
import weakref
from collections import deque
from typing import NamedTuple

import numpy as np
from qgis.core import QgsTask
from qgis.PyQt.QtCore import QCoreApplication, QObject, pyqtSignal
from qgis.PyQt.QtGui import QImage

from ..core.errors import Cancelled
from .image_source import ImageSource, ImageSourceError, build_overview_file, error_text

__all__ = ["OverviewTask", "TileLoader", "TileRequest", "to_qimage"]

#: a worker thread with nothing to do for this long ends (and closes its GDAL handle)
IDLE_EXIT_S = 0.5
_LOADERS: weakref.WeakSet = weakref.WeakSet()


@atexit.register
def _stop_all() -> None:
    """Stop the workers when Python exits (they would otherwise finish their idle wait)."""
    for loader in list(_LOADERS):
        loader.shutdown()


def to_qimage(a: np.ndarray) -> QImage:
    """A QImage (Format_RGB32, owning its pixels) of an 8-bit (h, w) or (h, w, 3) array.

    RGB32 is the raster pixmap's own format, so ``QPixmap.fromImage`` in the GUI thread copies
    without converting: Qt converts large images with helper threads of the global pool and
    waits for them while Python holds the GIL, which deadlocks when those threads run Python.
    """
    h, w = a.shape[:2]
    bgra = np.empty((h, w, 4), dtype=np.uint8)  # 0xffRRGGBB, little endian: B G R A
    if a.ndim == 2:
        bgra[:, :, :3] = a[:, :, None]
    else:
        bgra[:, :, 0], bgra[:, :, 1], bgra[:, :, 2] = a[:, :, 2], a[:, :, 1], a[:, :, 0]
    bgra[:, :, 3] = 255
    img = QImage(bgra.data, w, h, 4 * w, QImage.Format.Format_RGB32)
    return img.copy()  # own the pixels: `bgra` dies with this call


class TileRequest(NamedTuple):
    """One tile: ``key`` (level, tx, ty), full-resolution window, output size (pixels)."""

    key: tuple[int, int, int]
    x0: int
    y0: int
    w: int
    h: int
    out_w: int
    out_h: int


class TileLoader(QObject):
    """Reads the preview and the tiles of one :class:`ImageSource` in a worker thread.

    Signals
    -------
    previewReady(source_gen, QImage, limits)
        The whole image decimated to the stretch sample size, stretched; ``limits`` the
        (low, high) stretch per band the worker used (to share with the GUI's source).
    tileReady(source_gen, key, QImage)
    failed(source_gen, message)
        A read failed (message names the file).
    """

    previewReady = pyqtSignal(int, object, object)  # noqa: N815 - Qt signal naming
    tileReady = pyqtSignal(int, object, object)  # noqa: N815 - Qt signal naming
    failed = pyqtSignal(int, str)

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self._lock = threading.Lock()
        self._cond = threading.Condition(self._lock)
        self._jobs: deque = deque()
        self._running = False
        self._source: ImageSource | None = None
        self._source_gen = 0
        self._tile_gen = 0
        self._reopen = False
        self._stopped = False
        self.tiles_read = 0
        self.tiles_requested = 0
        self._thread: threading.Thread | None = None
        _LOADERS.add(self)

    # -- requests (GUI thread) ----------------------------------------------------------------
    def set_source(self, source: ImageSource | None) -> int:
        """Switch to another image (None: stop); pending work of the previous one is dropped.

        Returns the new source generation: results of older generations must be ignored.
        """
        with self._lock:
            self._source_gen += 1
            self._tile_gen += 1
            self._jobs.clear()
            self._source = source
            self._cond.notify_all()  # an idle worker ends at once when there is no image
            return self._source_gen

    @property
    def source_gen(self) -> int:
        return self._source_gen

    def request_preview(self) -> None:
        """Read the whole image at the stretch sample size (and the stretch when unknown)."""
        self._put(("preview", self._source_gen, 0, None))

    def request_tiles(self, tiles: list[TileRequest]) -> None:
        """Read these tiles in this order; tiles of earlier requests not read yet are dropped."""
        with self._lock:
            self._tile_gen += 1
            self._jobs = deque(j for j in self._jobs if j[0] != "tiles")
            self.tiles_requested += len(tiles)
        self._put(("tiles", self._source_gen, self._tile_gen, list(tiles)))

    def reopen(self) -> None:
        """Reopen the reader's dataset before the next read (a pyramid was built)."""
        with self._lock:
            self._reopen = True

    def shutdown(self) -> None:
        """Drop every job; the worker thread ends after its current read (aborted if long)."""
        with self._lock:
            self._stopped = True
            self._source_gen += 1
            self._jobs.clear()
            self._source = None
            self._cond.notify_all()

    def join(self, timeout_s: float = 10.0) -> bool:
        """Wait for the worker thread to end (after :meth:`set_source` (None) or
        :meth:`shutdown`); True when no worker runs."""
        thread = self._thread
        if thread is not None:
            thread.join(timeout_s)
        return thread is None or not thread.is_alive()

    def busy(self) -> bool:
        with self._lock:
            return self._running or bool(self._jobs)

    def _put(self, job) -> None:
        with self._lock:
            if self._stopped or self._source is None:
                return
            self._jobs.append(job)
            self._cond.notify()
            if self._running:
                return
            self._running = True
            self._thread = threading.Thread(target=self._work, name="lidarphoto tiles")
        self._thread.start()

    # -- worker side --------------------------------------------------------------------------
    def _next(self, idle_s: float):
        """The next job, or None once idle for ``idle_s`` (the worker is then marked ended)."""
        with self._cond:
            while not self._jobs and not self._stopped and self._source is not None:
                if not self._cond.wait(idle_s):
                    break
            if self._jobs and not self._stopped:
                return self._jobs.popleft()
            self._running = False
            return None

    def _stale(self, source_gen: int, tile_gen: int = 0) -> bool:
        return source_gen != self._source_gen or bool(tile_gen and tile_gen != self._tile_gen)

    def _work(self) -> None:
        reader: ImageSource | None = None
        reader_gen = -1
        try:
            while True:
                job = self._next(IDLE_EXIT_S)
                if job is None:
                    return
                kind, sgen, tgen, payload = job
                with self._lock:
                    source = self._source if sgen == self._source_gen else None
                    reopen, self._reopen = self._reopen, False
                if source is None:
                    continue
                try:
                    if reader is None or reader_gen != sgen:
                        if reader is not None:
                            reader.close()
                        reader, reader_gen = source.clone(), sgen
                    elif reopen:
                        reader.reopen()
                    if source.stretch_limits is not None:
                        reader.set_stretch_limits(*source.stretch_limits)

                    def abort(_done, _msg, _data, sgen=sgen, tgen=tgen):
                        return 0 if self._stale(sgen, tgen) else 1

                    if kind == "preview":
                        self._preview(reader, sgen, abort)
                    else:
                        self._tiles(reader, sgen, tgen, payload, abort)
                except Exception as exc:  # reported, the worker goes on
                    if not self._stale(sgen, tgen):
                        msg = (
                            error_text(exc)
                            if isinstance(exc, ImageSourceError)
                            else QCoreApplication.translate(
                                "ImageLoader", "{path}: read failed ({error})"
                            ).format(path=source.path, error=exc)
                        )
                        self._emit(self.failed, sgen, msg)
        finally:
            if reader is not None:
                reader.close()

    def _preview(self, reader: ImageSource, sgen: int, abort) -> None:
        raw = reader.sample(abort)
        if reader.stretch_limits is None:
            reader.stretch_from_sample(raw)
        if not self._stale(sgen):
            self._emit(
                self.previewReady, sgen, to_qimage(reader.stretch(raw)), reader.stretch_limits
            )

    def _tiles(self, reader: ImageSource, sgen: int, tgen: int, tiles, abort) -> None:
        for t in tiles:
            if self._stale(sgen, tgen):
                return
            a = reader.read(t.x0, t.y0, t.w, t.h, t.out_w, t.out_h, abort)
            self.tiles_read += 1
            self._emit(self.tileReady, sgen, t.key, to_qimage(a))

    def _emit(self, signal, *args) -> None:
        try:
            signal.emit(*args)
        except RuntimeError:  # the loader's QObject is gone (QGIS closing)
            self.shutdown()


class OverviewTask(QgsTask):
    """Builds the missing overview pyramid of an image in QGIS's task manager (cancellable).

    ``progressChanged(float)`` (0..100, inherited) reports progress; when it ends,
    ``done(ok, message)`` is emitted in the GUI thread: ok False with "cancelled" in the message
    when cancelled, or with the reason when it failed (message names the file).
    """

    done = pyqtSignal(bool, str)

    def __init__(self, source: ImageSource) -> None:
        name = QCoreApplication.translate("OverviewTask", "Overview pyramid of {}")
        super().__init__(name.format(source.path.name), QgsTask.Flag.CanCancel)
        self.path = source.path
        self.message = ""
        self.cancelled = False
        self.ovr_path = None
        self._last = -1.0

    def _cancelled_text(self) -> str:
        return QCoreApplication.translate(
            "OverviewTask", "{path}: overview build cancelled"
        ).format(path=self.path)

    def _progress(self, fraction: float) -> None:
        pct = 100.0 * fraction
        if pct - self._last >= 0.5 or pct >= 100.0:  # one signal per half percent
            self._last = pct
            self.setProgress(pct)

    def run(self) -> bool:
        try:
            self.ovr_path = build_overview_file(
                self.path, progress=self._progress, should_stop=self.isCanceled
            )
        except Cancelled:
            self.cancelled = True
            self.message = self._cancelled_text()
            return False
        except ImageSourceError as exc:
            self.message = error_text(exc)
            return False
        except Exception as exc:  # a task must never let an exception escape into Qt
            self.message = QCoreApplication.translate(
                "OverviewTask", "{path}: overview build failed ({error})"
            ).format(path=self.path, error=exc)
            return False
        self.message = QCoreApplication.translate(
            "OverviewTask", "{path}: overview pyramid built ({name})"
        ).format(path=self.path, name=self.ovr_path.name)
        return True

    def finished(self, result: bool) -> None:
        if not result and not self.message:
            self.cancelled = True
            self.message = self._cancelled_text()
        self.done.emit(bool(result), self.message)
