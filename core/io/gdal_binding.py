"""Which GDAL binding this process uses for rasters: ``osgeo`` (always in QGIS) first, else
``rasterio`` (its wheels bundle GDAL); ``LIDARPHOTO_RASTER_BACKEND=gdal`` or ``rasterio``
forces one (:mod:`.raster` for the files)."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from typing import Any

from ..errors import InputError

__all__ = ["raster_backend", "rio_env"]

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
