"""Which GDAL binding this process uses for rasters: ``osgeo`` (always in QGIS) first, else
``rasterio`` (its wheels bundle GDAL); ``LIDARPHOTO_RASTER_BACKEND=gdal`` or ``rasterio``
forces one (:mod:`.raster` for the files). And the writes GDAL fails quietly: a file cut by a
full device or the file size limit (rasterio only logs it, osgeo raises a bare RuntimeError)."""

from __future__ import annotations

import contextlib
import errno
import os
import shutil
from collections.abc import Callable, Iterator
from typing import Any

from ..errors import InputError

__all__ = ["check_written", "gdal_write_errors", "quietly", "raster_backend", "rio_env"]

#: Free bytes below which a write that just ended is taken to have hit a full device.
MIN_FREE_BYTES = 1 << 16
_INSTALL = "GDAL is needed for rasters: it comes with QGIS; outside QGIS: pip install rasterio"


def raster_backend() -> str:
    """``"gdal"`` (osgeo) or ``"rasterio"``: the binding this process uses (module docstring)."""
    forced = os.environ.get("LIDARPHOTO_RASTER_BACKEND", "").strip().lower()
    order = [forced] if forced in ("gdal", "rasterio") else ["gdal", "rasterio"]
    for name in order:
        try:
            if name == "gdal":
                from osgeo import gdal  # noqa: F401
            else:
                import rasterio  # noqa: F401
        except ImportError:
            continue
        return name
    raise InputError(_INSTALL)


@contextlib.contextmanager
def rio_env(**options: Any) -> Iterator[None]:
    """``rasterio.Env(**options)`` that reads the PROJ database of rasterio's own wheel.

    rasterio points PROJ at ``PROJ_DATA`` each time a first ``Env`` starts, when that variable
    is set; a wheel's PROJ then refuses an older system ``proj.db`` (Debian 12's, which QGIS
    set-ups export) and no CRS parses. pyproj's wheels prefer their own data; so does this."""
    import rasterio
    from rasterio.env import PROJDataFinder, set_proj_data_search_path

    with rasterio.Env(**options):
        bundled = PROJDataFinder().search_wheel()
        if bundled:
            set_proj_data_search_path(bundled)
        yield


def check_written(path: str) -> None:
    """Raise OSError (ENOSPC, EFBIG) when a file just written cannot be whole: the device has
    no space left, or the file reached the process's size limit (``ulimit -f``). GDAL's TIFF
    writer reports neither through rasterio: it logs them and closes a cut file."""
    size = os.path.getsize(path)
    try:
        import resource

        limit, unlimited = resource.getrlimit(resource.RLIMIT_FSIZE)[0], resource.RLIM_INFINITY
    except (ImportError, OSError, ValueError):  # not on Windows
        limit = unlimited = -1
    if 0 <= limit != unlimited and size >= limit:
        raise OSError(
            errno.EFBIG,
            f"cannot write it whole: the file reached the process's "
            f"file size limit of {limit} bytes (ulimit -f)",
            path,
        )
    free = shutil.disk_usage(os.path.dirname(os.path.abspath(path))).free
    if free < MIN_FREE_BYTES:
        raise OSError(
            errno.ENOSPC,
            f"cannot write it whole: no space left on the device ({free} bytes free)",
            path,
        )


def quietly(drop: Callable[[], None]) -> None:
    """``drop()`` (releasing an osgeo dataset) without the "Exception ignored" its destructor
    prints when closing a cut file fails again (:func:`check_written` tells the cause)."""
    import sys

    hook = sys.unraisablehook
    sys.unraisablehook = lambda _: None
    try:
        drop()
    finally:
        sys.unraisablehook = hook


@contextlib.contextmanager
def gdal_write_errors(path: str, drop: Callable[[], None]) -> Iterator[None]:
    """osgeo's RuntimeError of a failed write ("Write error at scanline") as an OSError with
    its likely cause (:func:`check_written`). ``drop()`` releases the last reference to the
    dataset: it is closed here, quietly (its destructor fails again on the cut file and
    would print "Exception ignored" whenever it is collected)."""
    try:
        yield
    except RuntimeError as exc:
        import traceback

        traceback.clear_frames(exc.__traceback__)  # the finished frames' references
        quietly(drop)
        check_written(path)
        raise OSError(errno.EIO, f"cannot write it: {exc}", path) from exc
