"""Control chips (GeoTIFF) and the control-point location report (CSV).

**Control chip**: one GeoTIFF per control point, file name stem = the point's id (e.g.
``chips/GCP12.tif``); single band, or RGB (3 or 4 bands: converted to grey as
``0.299 R + 0.587 G + 0.114 B``, alpha ignored); north up (no rotation terms), square or
rectangular cells; in the control table's CRS, rectified onto the horizontal plane
``Z = Z_point``. The geotransform places the surveyed point at its map X, Y: its chip
position is ``col = (X - x0) / dx``, ``row = (Y - y0) / dy`` (corner convention, as image
pixels). No-data pixels are read as NaN (a chip with no-data around its point is refused).

**Location report** (one row per point and image, or per point when it was refused as a
whole)::

    point_id,image_id,status,reason,source,col,row,sigma_col,sigma_row,sigma0,ncc,
    lsm_correlation,template_px,predicted_col,predicted_row,search_col_px,search_row_px,
    iterations

status ``ok`` | ``rejected`` | ``outside`` (outside every image: image_id empty); reason: why it
was rejected; source ``chip`` or ``transfer from <image>``; col, row: located position (pixels,
corner convention, as the observation CSV); sigma_col, sigma_row: LSM standard deviations
(pixels); sigma0: LSM grey-value residual sigma; ncc: NCC peak; lsm_correlation: correlation
of chip and image at the LSM solution; template_px: template side in chip pixels;
predicted_col/row: projection with the EO; search_col_px/search_row_px: search half-widths
(pixels); iterations: LSM iterations. Empty cells: not computed.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Union

import numpy as np

from ..errors import InputError
from ..photo.control_location import ControlChip, LocatedPair
from .raster import RasterReader
from .suffixes import CHIP_SUFFIXES
from .tables import write_csv_atomic

if TYPE_CHECKING:
    import pyproj

PathLike = Union[str, "os.PathLike[str]"]

__all__ = ["REPORT_COLUMNS", "list_chips", "read_control_chip", "write_location_report"]

REPORT_COLUMNS = (
    "point_id",
    "image_id",
    "status",
    "reason",
    "source",
    "col",
    "row",
    "sigma_col",
    "sigma_row",
    "sigma0",
    "ncc",
    "lsm_correlation",
    "template_px",
    "predicted_col",
    "predicted_row",
    "search_col_px",
    "search_row_px",
    "iterations",
)


def list_chips(paths: Iterable[PathLike]) -> dict[str, Path]:
    """point id -> chip file for files and folders (folders: their ``*.tif``/``*.tiff``)."""
    out: dict[str, Path] = {}
    for p in map(Path, paths):
        if p.is_dir():
            files = sorted(f for f in p.iterdir() if f.suffix.lower() in CHIP_SUFFIXES)
            if not files:
                raise InputError("the folder holds no chip (*.tif)", path=str(p))
        elif p.is_file():
            files = [p]
        else:
            raise InputError("no such chip file or folder", path=str(p))
        for f in files:
            if f.stem in out:
                raise InputError(f"two chips are named {f.stem}: {out[f.stem]} and {f}")
            out[f.stem] = f
    return out


def read_control_chip(
    path: PathLike, point_id: str, xyz: Sequence[float], crs: pyproj.CRS | None = None
) -> ControlChip:
    """Read a chip (module docstring) as a :class:`ControlChip` of the point at ``xyz``;
    with ``crs`` (the control's, a pyproj CRS), a chip tagged with another CRS is refused."""
    with RasterReader(path) as src:
        info = src.info
        if info.geotransform is None:
            raise InputError("the chip has no georeferencing", path=str(path))
        if crs is not None and info.crs_wkt:
            import pyproj

            own = pyproj.CRS.from_wkt(info.crs_wkt)
            if not _horizontal(own).equals(_horizontal(crs), ignore_axis_order=True):
                raise InputError(
                    f"the chip is in '{own.name}', the control points in "
                    f"'{crs.name}' (CRS): make the chips in the control's CRS",
                    path=str(path),
                )
        data = src.read().astype(np.float64)
        valid = src.read_mask()
    if data.shape[0] >= 3:
        grey = 0.299 * data[0] + 0.587 * data[1] + 0.114 * data[2]
    else:
        grey = data[0]
    if info.nodata is not None and not math.isnan(info.nodata):
        valid &= data[0] != info.nodata
    grey[~valid] = np.nan
    try:
        return ControlChip(point_id, grey, tuple(info.geotransform), np.asarray(xyz, float))
    except InputError as exc:
        raise InputError(str(exc), path=str(path)) from None


def _horizontal(crs):
    """The horizontal part of a compound CRS (the chips' planimetry is what must agree)."""
    return crs.sub_crs_list[0] if crs.is_compound and crs.sub_crs_list else crs


def _f(v: float, digits: int = 4) -> str:
    return "" if v is None or not math.isfinite(v) else f"{v:.{digits}f}"


def write_location_report(path: PathLike, pairs: Sequence[LocatedPair]) -> None:
    """Write the location report (module docstring)."""
    rows = [
        (
            p.point_id,
            p.image_id,
            p.status,
            p.reason,
            p.source if p.image_id else "",
            _f(p.col),
            _f(p.row),
            _f(p.sigma_col),
            _f(p.sigma_row),
            _f(p.sigma0, 3),
            _f(p.ncc, 3),
            _f(p.lsm_correlation, 3),
            p.template_px or "",
            _f(p.predicted_col, 2),
            _f(p.predicted_row, 2),
            _f(p.search_px[0], 1),
            _f(p.search_px[1], 1),
            p.iterations or "",
        )
        for p in pairs
    ]
    write_csv_atomic(path, REPORT_COLUMNS, rows)
