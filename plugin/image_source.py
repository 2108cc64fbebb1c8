"""Tiled, pyramidal reading of aerial images for the picking dock (no Qt here).

GDAL (``osgeo``, shipped with QGIS) reads any raster by window with a decimated buffer, and uses
the overview pyramid for it. An image without overviews can get a sidecar ``.ovr``
(:func:`build_overview_file`): built under a temporary name in the image's folder and renamed
when complete, so an interrupted build never leaves a half-written ``.ovr``. The picking view
builds it in the background (``image_loader.OverviewTask``); ``ImageSource(...,
build_overviews=True)`` builds it synchronously. OpenCV is the fallback for small JPG/PNG files
GDAL cannot open: the whole image is read once and ``pyrDown`` levels are cached.

GDAL dataset handles are not thread-safe: a thread that reads must use its own handle
(:meth:`ImageSource.clone`).

Pixels follow the project convention: ``(col, row)`` with the origin at the top-left corner of
the top-left pixel; a window ``(x0, y0, w, h)`` covers ``[x0, x0 + w) x [y0, y0 + h)``.
"""

from __future__ import annotations

import copy
import math
import os
import time
import uuid
from pathlib import Path
from typing import Callable

import numpy as np
from numpy.typing import NDArray

from ..core.errors import Cancelled
from ..core.i18n import mark as _t
from ..core.i18n import render
from ..core.io.raster import overview_factors

#: catalogue context of this module's ``_t("...")`` messages (``make i18n``)
TR_CONTEXT = "ImageSource"

__all__ = [
    "OVERVIEW_MIN_SIDE",
    "ImageSource",
    "ImageSourceError",
    "build_overview_file",
    "error_text",
    "open_image",
    "overview_factors",
]

#: images at least this large (pixels, either side) get an overview pyramid when they lack one
OVERVIEW_MIN_SIDE = 2048
#: side of the smallest overview level GDAL is asked to build (the in-memory pyramid of a
#: small image also stops there); the same rule as core.io.raster.overview_factors
_SMALLEST_LEVEL = 256
#: side of the decimated whole-image sample the contrast stretch is computed from
STRETCH_SAMPLE_SIDE = 1024
#: a whole-image read is "quick" (done in the GUI thread) from a level of at most this many
#: pixels: decoding 2048 x 2048 x 3 takes ~50 ms (LZW), a 4000 x 3000 tiled LZW ~0.5 s
QUICK_PIXELS = 2048 * 2048
#: marks the temporary files of an overview build (swept when stale)
_TMP_TAG = ".lidarphoto-ovr-"


class ImageSourceError(RuntimeError):
    """An image that cannot be opened or read (the message names the file).

    Its message is a :class:`core.i18n.Message` (English; :func:`error_text` shows it in the
    language of the user interface)."""


def error_text(exc: BaseException) -> str:
    """The message of ``exc`` in the user's language (an :class:`ImageSourceError`'s sentence
    translated; any other exception as it is)."""
    return render(exc.args[0], TR_CONTEXT) if exc.args else str(exc)


def _stretch_limits(sample: NDArray, low_pct: float, high_pct: float) -> tuple[NDArray, NDArray]:
    """Per-band percentile limits (B,) of a (h, w, B) sample, ignoring zero (no-data) cells."""
    flat = sample.reshape(-1, sample.shape[-1])
    valid = flat[(flat > 0).any(axis=1)]
    if valid.shape[0] < 16:
        valid = flat
    if valid.dtype in (np.uint8, np.uint16):
        # histogram percentiles: ~40x faster than sorting a 1024-px sample (this runs in the
        # GUI thread when an image opens); the value where the cumulative count reaches p %
        lo, hi = np.empty(valid.shape[1]), np.empty(valid.shape[1])
        for b in range(valid.shape[1]):  # 1 or 3 bands
            cum = np.cumsum(np.bincount(valid[:, b]))
            n = cum[-1]
            lo[b] = np.searchsorted(cum, low_pct / 100.0 * (n - 1) + 1.0)
            hi[b] = np.searchsorted(cum, high_pct / 100.0 * (n - 1) + 1.0)
    else:
        step = max(1, valid.shape[0] // 262144)
        v = valid[::step].astype(np.float64)
        lo, hi = np.percentile(v, low_pct, axis=0), np.percentile(v, high_pct, axis=0)
    return lo, np.where(hi > lo, hi, lo + 1.0)


def _gdal():
    try:
        from osgeo import gdal
    except ImportError as exc:  # QGIS always ships it; a bare Python may not
        raise ImageSourceError(_t("GDAL is not available ({error})", error=str(exc))) from exc
    gdal.UseExceptions()
    return gdal


def _sweep_stale_temporaries(image: Path, max_age_s: float = 600.0) -> None:
    """Remove temporaries of an earlier build of ``image`` that was killed (QGIS crashed).

    A running build rewrites its file continuously, so one untouched for ``max_age_s`` is dead.
    """
    prefix = f".{image.name}{_TMP_TAG}"
    now = time.time()
    try:
        entries = list(os.scandir(image.parent))
    except OSError:
        return
    for entry in entries:
        if entry.name.startswith(prefix):
            try:
                if now - entry.stat().st_mtime > max_age_s:
                    os.remove(entry.path)
            except OSError:
                pass


def build_overview_file(
    path: str | os.PathLike,
    factors: list[int] | None = None,
    *,
    resampling: str = "AVERAGE",
    threads: int | None = None,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> Path:
    """Build the sidecar overview pyramid ``<image>.ovr`` of an image, atomically.

    GDAL builds the pyramid of a read-only dataset into ``<dataset>.ovr``. The dataset here is
    a VRT (same pixels) under a temporary name in the image's folder, so the pyramid is first
    written to ``.<image>.lidarphoto-ovr-<id>.vrt.ovr`` and renamed to ``<image>.ovr`` once
    complete (``os.replace``, atomic on one file system). On cancel or error the temporaries
    are removed. Safe to call from any thread: it opens its own GDAL handles.

    Parameters
    ----------
    path : path of the image.
    factors : decimation factors, default :func:`overview_factors` of the image size.
    resampling : GDAL resampling of the levels ("AVERAGE": each level the mean of 2 x 2
        pixels of the finer one, alias-free).
    threads : GDAL worker threads for the computation (default: all cores but one, leaving a
        core to the GUI thread and the tile reader).
    progress : called with the fraction done, 0..1.
    should_stop : polled by GDAL's progress callback; True aborts with :class:`Cancelled`.

    Returns
    -------
    Path of the ``.ovr`` written.

    Raises
    ------
    Cancelled
        When ``should_stop()`` returned True (no ``.ovr`` is left).
    ImageSourceError
        The image cannot be opened or its folder is not writable (message names the file).
    """
    gdal = _gdal()
    image = Path(path)
    target = image.with_name(image.name + ".ovr")
    tmp_vrt = image.with_name(f".{image.name}{_TMP_TAG}{os.getpid()}-{uuid.uuid4().hex[:8]}.vrt")
    tmp_ovr = tmp_vrt.with_name(tmp_vrt.name + ".ovr")
    if not os.access(image.parent, os.W_OK):
        raise ImageSourceError(
            _t(
                "{path}: its folder is read-only, no overview pyramid can be written next to it",
                path=str(image),
            )
        )
    _sweep_stale_temporaries(image)
    if threads is None:
        threads = max(1, (os.cpu_count() or 1) - 1)
    stopped = False

    def callback(done, _msg, _data):
        nonlocal stopped
        if should_stop is not None and should_stop():
            stopped = True
            return 0
        if progress is not None:
            progress(float(done))
        return 1

    # thread-local: another thread (QGIS rendering, our tile reader) keeps its own settings
    gdal.SetThreadLocalConfigOption("GDAL_NUM_THREADS", str(threads))
    try:
        try:
            src = gdal.Open(str(image), gdal.GA_ReadOnly)
            if factors is None:
                factors = overview_factors(src.RasterXSize, src.RasterYSize, _SMALLEST_LEVEL)
            vrt = gdal.Translate(str(tmp_vrt), src, format="VRT")
            src = None
            vrt = None  # flush the VRT file
            vrt = gdal.Open(str(tmp_vrt), gdal.GA_ReadOnly)
            vrt.BuildOverviews(resampling, factors, callback)
            vrt = None  # closes the .ovr: all levels are on disk
        except RuntimeError as exc:
            vrt = src = None
            if stopped:
                raise Cancelled(_t("{path}: overview build cancelled", path=str(image))) from None
            raise ImageSourceError(
                _t("{path}: cannot build the overview pyramid ({error})", path=str(image),
                   error=str(exc))
            ) from exc  # fmt: skip
        if stopped:  # GDAL may finish the last level after the callback said stop
            raise Cancelled(_t("{path}: overview build cancelled", path=str(image)))
        try:
            os.replace(tmp_ovr, target)
        except OSError as exc:
            raise ImageSourceError(
                _t("{path}: cannot write the overview pyramid ({error})", path=str(target),
                   error=str(exc))
            ) from exc  # fmt: skip
    finally:
        gdal.SetThreadLocalConfigOption("GDAL_NUM_THREADS", None)
        for p in (tmp_vrt, tmp_ovr, tmp_ovr.with_name(tmp_ovr.name + ".aux.xml")):
            try:
                os.remove(p)
            except OSError:
                pass
    if progress is not None:
        progress(1.0)
    return target


class ImageSource:
    """A raster opened for windowed, decimated reads with a percentile contrast stretch.

    Attributes
    ----------
    path : Path
    width, height : int
        Full-resolution size, pixels.
    bands : int
        1 (grey) or 3 (RGB: the first three bands).
    dtype : numpy dtype
        Of the stored pixels (8 or 16 bit, or float).
    backend : {"gdal", "opencv"}
    overview_count : int
        Levels of the GDAL pyramid (0 for OpenCV: its levels are made in memory).
    block_size : tuple of int
        (columns, rows) of GDAL's storage block: (width, 1..n) for a striped TIFF.

    Notes
    -----
    The contrast stretch is computed from a decimated read of the whole image. For an image
    that has no overviews (:attr:`quick` False) that read touches every strip or tile, so it
    is deferred to the first :meth:`read` (or taken from :meth:`set_stretch_limits`, which
    the picking view calls with the limits its worker thread computed).
    """

    def __init__(
        self,
        path: str | os.PathLike,
        *,
        backend: str = "auto",
        build_overviews: bool = False,
        stretch_pct: tuple[float, float] = (0.5, 99.5),
        progress: Callable[[float], None] | None = None,
        should_stop: Callable[[], bool] | None = None,
        stretch_now: bool = True,
    ) -> None:
        """Open an image.

        Parameters
        ----------
        path : image file.
        backend : "auto" (GDAL, then OpenCV), "gdal" or "opencv".
        build_overviews : build the missing pyramid of a large image now, in this thread
            (``progress``/``should_stop`` as in :func:`build_overview_file`). The default,
            False, leaves it to the caller (the picking view builds it in the background).
        stretch_pct : percentiles of the contrast stretch.
        stretch_now : compute the stretch of a :attr:`quick` image now (a whole-image read,
            tens of ms); False leaves it to the first :meth:`read` or to
            :meth:`set_stretch_limits` (the picking view has its worker compute it).
        """
        self.path = Path(path)
        if not self.path.is_file():
            raise ImageSourceError(_t("{path}: the image file does not exist", path=str(self.path)))
        self._ds = None
        self._pyramid: list[NDArray] = []
        self._limits: tuple[NDArray, NDArray] | None = None
        self._sample: NDArray | None = None
        self._sample_ovr = -1
        self.stretch_pct = (float(stretch_pct[0]), float(stretch_pct[1]))
        self.overview_count = 0
        self.block_size = (0, 0)
        gdal_error = ""
        if backend in ("auto", "gdal"):
            try:
                self._open_gdal()
            except ImageSourceError as exc:
                if backend == "gdal":
                    raise
                gdal_error = str(exc)
        if self._ds is None:
            self._open_opencv(gdal_error)
        if build_overviews and self.needs_overviews:
            try:
                build_overview_file(self.path, progress=progress, should_stop=should_stop)
            except ImageSourceError:
                pass  # read-only folder: reads stay correct, only slower when zoomed out
            else:
                self.reopen()
        if self.quick and stretch_now:
            self.set_stretch(*self.stretch_pct)

    # -- opening ----------------------------------------------------------------------------
    def _open_gdal(self) -> None:
        gdal = _gdal()
        try:
            ds = gdal.Open(str(self.path), gdal.GA_ReadOnly)
        except RuntimeError as exc:
            raise ImageSourceError(
                _t("{path}: GDAL cannot open it ({error})", path=str(self.path), error=str(exc))
            ) from exc
        if ds is None or ds.RasterCount < 1:
            raise ImageSourceError(
                _t("{path}: GDAL cannot open it (no raster band)", path=str(self.path))
            )
        self.width, self.height = ds.RasterXSize, ds.RasterYSize
        self.bands = 3 if ds.RasterCount >= 3 else 1
        band = ds.GetRasterBand(1)
        self.dtype = np.dtype(gdal.GetDataTypeName(band.DataType).lower().replace("byte", "uint8"))
        self.overview_count = band.GetOverviewCount()
        self.block_size = tuple(band.GetBlockSize())
        self._ds = ds
        self.backend = "gdal"

    def _open_opencv(self, gdal_error: str = "") -> None:
        import cv2

        data = np.fromfile(str(self.path), dtype=np.uint8)  # non-ASCII paths on Windows
        img = cv2.imdecode(data, cv2.IMREAD_UNCHANGED) if data.size else None
        if img is None:
            why = f" ({gdal_error.split(': ', 1)[-1]})" if gdal_error else ""
            raise ImageSourceError(
                _t("{path}: neither GDAL nor OpenCV can read this image{why}",
                   path=str(self.path), why=why)
            )  # fmt: skip
        if img.ndim == 3:
            img = cv2.cvtColor(img[:, :, :3], cv2.COLOR_BGR2RGB)
        self._pyramid = [img]
        while max(self._pyramid[-1].shape[:2]) > _SMALLEST_LEVEL:
            self._pyramid.append(cv2.pyrDown(self._pyramid[-1]))
        self.height, self.width = img.shape[:2]
        self.bands = 3 if img.ndim == 3 else 1
        self.dtype = img.dtype
        self.backend = "opencv"

    def reopen(self) -> None:
        """Reopen the GDAL dataset (to see a pyramid built since); keeps the stretch."""
        if self.backend != "gdal":
            return
        self._drop_dataset()
        self._open_gdal()

    def clone(self) -> ImageSource:
        """The same image with its own GDAL handle, for another thread (the stretch is shared
        when known; the OpenCV pyramid is shared, read-only)."""
        other = copy.copy(self)
        other._sample = None
        if self.backend == "gdal":
            other._ds = None
            other._open_gdal()
        return other

    @property
    def needs_overviews(self) -> bool:
        """A large GDAL image without a pyramid (zoomed-out reads touch every strip or tile)."""
        return (
            self.backend == "gdal"
            and self.overview_count == 0
            and max(self.width, self.height) >= OVERVIEW_MIN_SIDE
        )

    @property
    def quick(self) -> bool:
        """Whether a decimated read of the whole image is cheap: the coarsest level GDAL can
        read it from (the image itself or its smallest overview) has at most
        ``QUICK_PIXELS`` pixels (all of them may have to be decoded)."""
        if self.backend != "gdal":
            return True
        w, h = self.width, self.height
        if self._ds is not None and self.overview_count:
            ov = self._ds.GetRasterBand(1).GetOverview(self.overview_count - 1)
            if ov is not None:
                w, h = ov.XSize, ov.YSize
        return w * h <= QUICK_PIXELS

    # -- reading ----------------------------------------------------------------------------
    def read_raw(
        self,
        x0: int,
        y0: int,
        w: int,
        h: int,
        out_w: int,
        out_h: int,
        callback: Callable | None = None,
    ) -> NDArray:
        """Read a window of the full-resolution image decimated to ``out_w x out_h``.

        ``callback(done, message, data)`` is GDAL's progress callback: returning 0 aborts the
        read (RuntimeError), which a worker thread uses to drop a request gone stale.

        Returns
        -------
        ndarray, shape (out_h, out_w, B)
            Stored values (no stretch); B = 1 or 3. The window is clipped to the image, so a
            window past the border returns a smaller array.
        """
        x1, y1 = min(self.width, x0 + w), min(self.height, y0 + h)
        x0, y0 = max(0, x0), max(0, y0)
        if x1 <= x0 or y1 <= y0:
            return np.zeros((0, 0, self.bands), dtype=self.dtype)
        out_w = max(1, min(out_w, round((x1 - x0) * out_w / w)))
        out_h = max(1, min(out_h, round((y1 - y0) * out_h / h)))
        if self._ds is not None:
            try:
                a = self._ds.ReadAsArray(
                    x0,
                    y0,
                    x1 - x0,
                    y1 - y0,
                    buf_xsize=out_w,
                    buf_ysize=out_h,
                    band_list=list(range(1, self.bands + 1)),
                    callback=callback,
                )
            except RuntimeError as exc:
                raise ImageSourceError(
                    _t("{path}: read failed ({error})", path=str(self.path), error=str(exc))
                ) from exc
            if a is None:
                raise ImageSourceError(_t("{path}: read failed", path=str(self.path)))
            return a[:, :, None] if a.ndim == 2 else np.moveaxis(a, 0, -1)
        if not self._pyramid:
            raise ImageSourceError(_t("{path}: the image is closed", path=str(self.path)))
        import cv2

        f = (x1 - x0) / out_w
        level = max(0, min(len(self._pyramid) - 1, math.floor(math.log2(max(f, 1.0)))))
        s = 2**level
        src = self._pyramid[level][y0 // s : -(-y1 // s), x0 // s : -(-x1 // s)]
        a = cv2.resize(src, (out_w, out_h), interpolation=cv2.INTER_AREA)
        return a[:, :, None] if a.ndim == 2 else a

    def stretch_sample_size(self) -> tuple[int, int]:
        """(out_w, out_h) of the whole-image sample the stretch comes from (<= 1024 px)."""
        f = max(1.0, max(self.width, self.height) / STRETCH_SAMPLE_SIDE)
        return max(1, int(self.width / f)), max(1, int(self.height / f))

    def sample(self, callback: Callable | None = None) -> NDArray:
        """The whole image decimated to :meth:`stretch_sample_size`, stored values (h, w, B).

        Kept after the first read (a few MB): the stretch and the view's background share it.
        """
        if self._sample is None or self._sample_ovr != self.overview_count:
            self._sample = self.read_raw(
                0, 0, self.width, self.height, *self.stretch_sample_size(), callback
            )
            self._sample_ovr = self.overview_count
        return self._sample

    def set_stretch(self, low_pct: float = 0.5, high_pct: float = 99.5) -> None:
        """Percentile contrast stretch from a decimated read of the whole image (<= 1024 px)."""
        self.stretch_pct = (float(low_pct), float(high_pct))
        self._limits = _stretch_limits(self.sample(), low_pct, high_pct)

    def stretch_from_sample(self, sample: NDArray) -> None:
        """Set the stretch from a whole-image sample already read (shape (h, w, B))."""
        self._limits = _stretch_limits(sample, *self.stretch_pct)

    def set_stretch_limits(self, low: NDArray, high: NDArray) -> None:
        """Set the per-band stretch limits (B,) directly (stored values mapped to 0 and 255)."""
        self._limits = (np.asarray(low, dtype=np.float64), np.asarray(high, dtype=np.float64))

    @property
    def stretch_limits(self) -> tuple[NDArray, NDArray] | None:
        """(low, high) per band, or None while not computed yet."""
        return self._limits

    @property
    def low(self) -> NDArray:
        if self._limits is None:
            self.set_stretch(*self.stretch_pct)
        return self._limits[0]

    @property
    def high(self) -> NDArray:
        if self._limits is None:
            self.set_stretch(*self.stretch_pct)
        return self._limits[1]

    def stretch(self, raw: NDArray) -> NDArray[np.uint8]:
        """Stored values (h, w, B) to 8 bit: (h, w) grey or (h, w, 3)."""
        low, high = self.low, self.high
        scale = (255.0 / (high - low)).astype(np.float32)
        a = np.clip((raw.astype(np.float32) - low.astype(np.float32)) * scale, 0, 255)
        a = a.astype(np.uint8)
        return np.ascontiguousarray(a[:, :, 0] if self.bands == 1 else a)

    def read(
        self,
        x0: int,
        y0: int,
        w: int,
        h: int,
        out_w: int,
        out_h: int,
        callback: Callable | None = None,
    ) -> NDArray[np.uint8]:
        """As :meth:`read_raw`, stretched to 8 bit: (out_h, out_w) grey or (out_h, out_w, 3)."""
        return self.stretch(self.read_raw(x0, y0, w, h, out_w, out_h, callback))

    def close(self) -> None:
        """Release the GDAL handle (safe after QGIS has shut GDAL down, see below)."""
        self._drop_dataset()
        self._pyramid = []
        self._sample = None

    def _drop_dataset(self) -> None:
        ds, self._ds = self._ds, None
        if ds is not None and _gdal().GetDriverCount() == 0:
            # QgsApplication.exitQgis() destroyed GDAL's drivers and force-closed every open
            # dataset: closing this handle again would free it twice (a crash at exit)
            ds.thisown = False

    def __del__(self) -> None:
        try:
            self._drop_dataset()
        except Exception:  # interpreter shutdown: modules may be gone already
            pass


def open_image(path: str | os.PathLike, **kwargs) -> ImageSource:
    """Open an image (see :class:`ImageSource`); raises :class:`ImageSourceError`."""
    return ImageSource(path, **kwargs)
