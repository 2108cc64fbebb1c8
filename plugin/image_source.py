"""Tiled, pyramidal reading of aerial images for the picking dock (no Qt here).

GDAL (``osgeo``, shipped with QGIS) reads any raster by window with a decimated buffer, and uses
the overview pyramid for it; an image without overviews gets a sidecar ``.ovr`` built once
(GDAL writes it next to the image, or, when that folder is read-only, ``GDAL`` is told to keep
it in memory and the image is read decimated from full resolution). OpenCV is the fallback for
small JPG/PNG files GDAL cannot open: the whole image is read once and ``pyrDown`` levels are
cached.

Pixels follow the project convention: ``(col, row)`` with the origin at the top-left corner of
the top-left pixel; a window ``(x0, y0, w, h)`` covers ``[x0, x0 + w) x [y0, y0 + h)``.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Callable

import numpy as np
from numpy.typing import NDArray

__all__ = ["ImageSource", "ImageSourceError", "open_image"]

#: images at least this large (pixels, either side) get an overview pyramid when they lack one
OVERVIEW_MIN_SIDE = 2048
#: side of the smallest overview level GDAL is asked to build
_SMALLEST_LEVEL = 256


class ImageSourceError(RuntimeError):
    """An image that cannot be opened or read (the message names the file)."""


def _stretch_limits(sample: NDArray, low_pct: float, high_pct: float) -> tuple[NDArray, NDArray]:
    """Per-band percentile limits (B,) of a (h, w, B) sample, ignoring zero (no-data) cells."""
    flat = sample.reshape(-1, sample.shape[-1]).astype(np.float64)
    valid = flat[(flat > 0).any(axis=1)]
    if valid.shape[0] < 16:
        valid = flat
    lo = np.percentile(valid, low_pct, axis=0)
    hi = np.percentile(valid, high_pct, axis=0)
    return lo, np.where(hi > lo, hi, lo + 1.0)


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
    """

    def __init__(
        self,
        path: str | os.PathLike,
        *,
        backend: str = "auto",
        build_overviews: bool = True,
        stretch_pct: tuple[float, float] = (0.5, 99.5),
        progress: Callable[[float], None] | None = None,
    ) -> None:
        self.path = Path(path)
        if not self.path.is_file():
            raise ImageSourceError(f"{self.path}: the image file does not exist")
        self._ds = None
        self._pyramid: list[NDArray] = []
        self.overview_count = 0
        if backend in ("auto", "gdal"):
            try:
                self._open_gdal(build_overviews, progress)
            except ImageSourceError:
                if backend == "gdal":
                    raise
        if self._ds is None:
            self._open_opencv()
        self.set_stretch(*stretch_pct)

    # -- opening ----------------------------------------------------------------------------
    def _open_gdal(self, build_overviews: bool, progress) -> None:
        try:
            from osgeo import gdal
        except ImportError as exc:
            raise ImageSourceError(f"{self.path}: GDAL is not available ({exc})") from exc
        gdal.UseExceptions()
        try:
            ds = gdal.Open(str(self.path), gdal.GA_ReadOnly)
        except RuntimeError as exc:
            raise ImageSourceError(f"{self.path}: GDAL cannot open it ({exc})") from exc
        if ds is None or ds.RasterCount < 1:
            raise ImageSourceError(f"{self.path}: GDAL cannot open it")
        self.width, self.height = ds.RasterXSize, ds.RasterYSize
        self.bands = 3 if ds.RasterCount >= 3 else 1
        self.dtype = np.dtype(
            gdal.GetDataTypeName(ds.GetRasterBand(1).DataType).lower().replace("byte", "uint8")
        )
        self.overview_count = ds.GetRasterBand(1).GetOverviewCount()
        big = max(self.width, self.height) >= OVERVIEW_MIN_SIDE
        if build_overviews and big and self.overview_count == 0:
            levels, f = [], 2
            while max(self.width, self.height) / f >= _SMALLEST_LEVEL:
                levels.append(f)
                f *= 2
            callback = None
            if progress is not None:

                def callback(done, _msg, _data):
                    progress(float(done))
                    return 1

            try:  # a read-only dataset writes an external .ovr next to the image
                ds.BuildOverviews("AVERAGE", levels, callback)
            except RuntimeError:
                pass  # read-only folder: reads stay correct, only slower when zoomed out
            self.overview_count = ds.GetRasterBand(1).GetOverviewCount()
        self._ds = ds
        self.backend = "gdal"

    def _open_opencv(self) -> None:
        import cv2

        data = np.fromfile(str(self.path), dtype=np.uint8)  # non-ASCII paths on Windows
        img = cv2.imdecode(data, cv2.IMREAD_UNCHANGED) if data.size else None
        if img is None:
            raise ImageSourceError(f"{self.path}: neither GDAL nor OpenCV can read this image")
        if img.ndim == 3:
            img = cv2.cvtColor(img[:, :, :3], cv2.COLOR_BGR2RGB)
        self._pyramid = [img]
        while max(self._pyramid[-1].shape[:2]) > _SMALLEST_LEVEL:
            self._pyramid.append(cv2.pyrDown(self._pyramid[-1]))
        self.height, self.width = img.shape[:2]
        self.bands = 3 if img.ndim == 3 else 1
        self.dtype = img.dtype
        self.backend = "opencv"

    # -- reading ----------------------------------------------------------------------------
    def read_raw(self, x0: int, y0: int, w: int, h: int, out_w: int, out_h: int) -> NDArray:
        """Read a window of the full-resolution image decimated to ``out_w x out_h``.

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
            a = self._ds.ReadAsArray(
                x0,
                y0,
                x1 - x0,
                y1 - y0,
                buf_xsize=out_w,
                buf_ysize=out_h,
                band_list=list(range(1, self.bands + 1)),
            )
            return a[:, :, None] if a.ndim == 2 else np.moveaxis(a, 0, -1)
        import cv2

        f = (x1 - x0) / out_w
        level = max(0, min(len(self._pyramid) - 1, math.floor(math.log2(max(f, 1.0)))))
        s = 2**level
        src = self._pyramid[level][y0 // s : -(-y1 // s), x0 // s : -(-x1 // s)]
        a = cv2.resize(src, (out_w, out_h), interpolation=cv2.INTER_AREA)
        return a[:, :, None] if a.ndim == 2 else a

    def set_stretch(self, low_pct: float = 0.5, high_pct: float = 99.5) -> None:
        """Percentile contrast stretch from a decimated read of the whole image (<= 1024 px)."""
        f = max(1.0, max(self.width, self.height) / 1024.0)
        sample = self.read_raw(
            0, 0, self.width, self.height, max(1, int(self.width / f)), max(1, int(self.height / f))
        )
        self.low, self.high = _stretch_limits(sample, low_pct, high_pct)

    def read(self, x0: int, y0: int, w: int, h: int, out_w: int, out_h: int) -> NDArray[np.uint8]:
        """As :meth:`read_raw`, stretched to 8 bit: (out_h, out_w) grey or (out_h, out_w, 3)."""
        a = self.read_raw(x0, y0, w, h, out_w, out_h).astype(np.float32)
        scale = (255.0 / (self.high - self.low)).astype(np.float32)
        a = np.clip((a - self.low.astype(np.float32)) * scale, 0, 255).astype(np.uint8)
        return np.ascontiguousarray(a[:, :, 0] if self.bands == 1 else a)

    def close(self) -> None:
        self._ds = None
        self._pyramid = []


def open_image(path: str | os.PathLike, **kwargs) -> ImageSource:
    """Open an image (see :class:`ImageSource`); raises :class:`ImageSourceError`."""
    return ImageSource(path, **kwargs)
