"""DSM files: a LAS/LAZ cloud rasterised into a DSM, DSM rasters read and written."""

from __future__ import annotations

import logging
import os
from collections.abc import Callable
from pathlib import Path
from typing import Union

import numpy as np
import pyproj

from ..errors import InputError, stop_if_asked
from ..geometry.frames import check_area_of_use, parse_crs
from ..geometry.grid import Grid
from ..geometry.surface import Dsm
from ..lidar.dsm import NOISE_CLASSES, dsm_from_points
from .pointcloud import read_points
from .raster import read_geotiff
from .raster_write import write_geotiff

LOG = logging.getLogger(__name__)

PathLike = Union[str, "os.PathLike[str]"]
#: Nodata value written to DSM GeoTIFFs.
DSM_NODATA = -9999.0
#: Extensions read as point clouds (anything else is a raster).
CLOUD_SUFFIXES = (".las", ".laz")


def write_dsm(path: PathLike, dsm: Dsm) -> None:
    """Write as float32 GeoTIFF (nodata -9999), atomically."""
    data = np.where(np.isfinite(dsm.heights), dsm.heights, DSM_NODATA).astype(np.float32)
    write_geotiff(path, data, dsm.grid.geotransform, DSM_NODATA, dsm.crs)


def dsm_from_las(
    path: PathLike,
    cell: float,
    crs: str | int | pyproj.CRS | None = None,
    *,
    distance_unit: str = "crs",
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> Dsm:
    """Rasterise a LAS/LAZ cloud into a DSM: highest return per cell, gaps filled.

    Points of class 7 (low point) and 18 (high noise) are left out.

    Parameters
    ----------
    path : str or os.PathLike
        LAS/LAZ file.
    cell : float
        Cell size in the cloud's CRS unit, or in metres when ``distance_unit == "metre"``.
    crs : optional
        Overrides (or supplies) the file's CRS.
    distance_unit : {"crs", "metre"}
    progress, should_stop
        Reading progress (fraction) and cancellation.

    Returns
    -------
    Dsm
    """
    arrays, info = read_points(
        path,
        ("x", "y", "z", "classification"),
        crs=crs,
        progress=progress,
        should_stop=should_stop,
        require_crs=False,
    )
    stop_if_asked(should_stop, "building the DSM")
    cell = cell * info.length_factors(distance_unit)[0]
    keep = ~np.isin(arrays["classification"], NOISE_CLASSES)
    heights, grid = dsm_from_points(
        arrays["x"][keep], arrays["y"][keep], arrays["z"][keep], cell, fill=True
    )
    LOG.info(
        "DSM %d x %d cells of %g from %d points of %s",
        grid.rows,
        grid.cols,
        grid.cell,
        int(keep.sum()),
        os.fspath(path),
    )
    return Dsm(heights, grid, info.crs, os.fspath(path))


def read_dsm_raster(path: PathLike, crs: str | int | pyproj.CRS | None = None) -> Dsm:
    """Read a north-up, single-band DSM raster (any format GDAL reads).

    ``crs`` overrides (or supplies) the raster's CRS.
    """
    p = os.fspath(path)
    data, gt, wkt = read_geotiff(p)
    if abs(gt[2]) > 0 or abs(gt[4]) > 0 or not np.isclose(gt[1], -gt[5], rtol=1e-9):
        raise InputError("the DSM must be north-up with square cells", path=p)
    if not np.isfinite(data).any():
        raise InputError("the DSM has no valid cell", path=p)
    rows, cols = data.shape
    grid = Grid(float(gt[0]), float(gt[3]), float(gt[1]), rows, cols)
    file_crs = parse_crs(wkt) if wkt else None
    use = parse_crs(crs) if crs else file_crs
    if use is not None:
        x1, y0 = grid.x0 + cols * grid.cell, grid.y_top - rows * grid.cell
        check_area_of_use(use, (grid.x0, y0), (x1, grid.y_top), what="the DSM", path=p)
    return Dsm(data, grid, use, p)


def load_dsm(
    path: PathLike,
    cell: float = 0.5,
    crs: str | int | pyproj.CRS | None = None,
    *,
    distance_unit: str = "crs",
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> Dsm:
    """A DSM from a LAS/LAZ file (rasterised at ``cell``) or from a raster file."""
    if Path(os.fspath(path)).suffix.lower() in CLOUD_SUFFIXES:
        return dsm_from_las(
            path,
            cell,
            crs,
            distance_unit=distance_unit,
            progress=progress,
            should_stop=should_stop,
        )
    return read_dsm_raster(path, crs)
