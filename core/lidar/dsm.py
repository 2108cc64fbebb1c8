"""Digital surface models: rasterised from LAS/LAZ or read from a raster, and their surface.

A DSM is a north-up grid of heights given at the cell *centres* (``Grid`` of
:mod:`core.ground_filter`: cell (row, col) covers ``x0 + col c .. x0 + (col + 1) c`` and
``y_top - (row + 1) c .. y_top - row c``). NaN marks nodata.

The surface is the polyhedron of paper 001 (Dal Poz 1991): the centres of four neighbouring
cells ``(r, c), (r, c+1), (r+1, c), (r+1, c+1)`` span a *quad*, split along its diagonal from
``(r, c)`` to ``(r+1, c+1)`` into two triangles. With the quad's local coordinates
``u = (x - x_c) / cell`` (east) and ``v = (y_r - y) / cell`` (south), in [0, 1]:

- triangle 0 (``u >= v``): vertices (0, 0), (1, 0), (1, 1), i.e. cells (r, c), (r, c+1),
  (r+1, c+1);
- triangle 1 (``u <= v``): vertices (0, 0), (0, 1), (1, 1), i.e. cells (r, c), (r+1, c),
  (r+1, c+1).

The surface spans the centres of the first and last rows and columns: half a cell inside
the raster's outer edge.
"""

from __future__ import annotations

import logging
import math
import os
import struct
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Union

import numpy as np
import pyproj
from numpy.typing import ArrayLike, NDArray

from ..errors import CrsError, InputError, stop_if_asked
from ..io.pointcloud import parse_crs, read_points
from .ground_filter import Grid, fill_holes, write_geotiff

LOG = logging.getLogger(__name__)

PathLike = Union[str, "os.PathLike[str]"]
Array = NDArray[np.float64]

#: Nodata value written to DSM GeoTIFFs.
DSM_NODATA = -9999.0
#: Extensions read as point clouds (anything else is a raster).
CLOUD_SUFFIXES = (".las", ".laz")
#: Classes never used for a surface: low point (7) and high noise (18).
NOISE_CLASSES = (7, 18)

__all__ = [
    "CLOUD_SUFFIXES",
    "DSM_NODATA",
    "Dsm",
    "dsm_from_las",
    "dsm_from_points",
    "load_dsm",
    "read_dsm_raster",
]


@dataclass(frozen=True)
class Dsm:
    """A gridded surface model.

    Attributes
    ----------
    heights : (rows, cols) float32
        Heights at the cell centres, CRS unit; NaN for nodata.
    grid : Grid
        Geometry of the raster (top-left corner, square cell, size).
    crs : pyproj.CRS or None
        CRS of x, y and the heights; None when the source had none.
    source : str
        File it came from (for messages).
    """

    heights: NDArray[np.float32]
    grid: Grid
    crs: pyproj.CRS | None = None
    source: str = ""

    @property
    def cell(self) -> float:
        return self.grid.cell

    @property
    def centre_origin(self) -> tuple[float, float]:
        """(x, y) of the centre of cell (0, 0)."""
        return self.grid.x0 + 0.5 * self.grid.cell, self.grid.y_top - 0.5 * self.grid.cell

    @property
    def z_range(self) -> tuple[float, float]:
        """(min, max) of the valid heights."""
        return float(np.nanmin(self.heights)), float(np.nanmax(self.heights))

    def to_grid_uv(self, x: ArrayLike, y: ArrayLike) -> tuple[Array, Array]:
        """Map x, y -> lattice coordinates (u east, v south) in cells from the centre of (0, 0)."""
        xc, yc = self.centre_origin
        inv = 1.0 / self.grid.cell
        return (np.asarray(x, float) - xc) * inv, (yc - np.asarray(y, float)) * inv

    def height_at(self, x: ArrayLike, y: ArrayLike) -> Array:
        """(N,) height of the triangulated surface at map points; NaN outside or on nodata.

        Examples
        --------
        >>> d = Dsm(np.array([[0, 1], [2, 3]], np.float32), Grid(0.0, 2.0, 1.0, 2, 2))
        >>> d.height_at([0.5, 1.0, 1.5], [1.5, 1.0, 0.5]).tolist()
        [0.0, 1.5, 3.0]
        """
        u, v = self.to_grid_uv(x, y)
        u, v = np.atleast_1d(u), np.atleast_1d(v)
        rows, cols = self.heights.shape
        inside = (u >= 0) & (v >= 0) & (u <= cols - 1) & (v <= rows - 1)
        c = np.clip(np.floor(u), 0, max(cols - 2, 0)).astype(np.int64)
        r = np.clip(np.floor(v), 0, max(rows - 2, 0)).astype(np.int64)
        fu, fv = u - c, v - r
        z = self.heights
        z00 = z[r, c].astype(float)
        z01 = z[r, np.minimum(c + 1, cols - 1)].astype(float)
        z10 = z[np.minimum(r + 1, rows - 1), c].astype(float)
        z11 = z[np.minimum(r + 1, rows - 1), np.minimum(c + 1, cols - 1)].astype(float)
        upper = fu >= fv
        out = np.where(
            upper,
            z00 + (z01 - z00) * fu + (z11 - z01) * fv,
            z00 + (z11 - z10) * fu + (z10 - z00) * fv,
        )
        out[~inside] = np.nan
        return out

    def to_geotiff(self, path: PathLike) -> None:
        """Write as float32 GeoTIFF (nodata -9999), atomically."""
        data = np.where(np.isfinite(self.heights), self.heights, DSM_NODATA).astype(np.float32)
        write_geotiff(os.fspath(path), data, self.grid.geotransform, DSM_NODATA, self.crs)



def dsm_from_points(
    x: ArrayLike,
    y: ArrayLike,
    z: ArrayLike,
    cell: float,
    *,
    fill: bool = True,
    bounds: Sequence[float] | None = None,
) -> tuple[NDArray[np.float32], Grid]:
    """Highest point per cell, with the empty cells filled (pull-push interpolation).

    Parameters
    ----------
    x, y, z : (N,) array_like
        Points, CRS unit.
    cell : float
        Cell size, CRS unit, > 0.
    fill : bool
        Fill the cells without points (:func:`core.ground_filter.fill_holes`); else NaN.
    bounds : (xmin, ymin, xmax, ymax), optional
        Area to cover (default: the points' box); the grid is aligned on multiples of ``cell``.

    Returns
    -------
    heights : (rows, cols) float32
    grid : Grid

    Examples
    --------
    >>> h, g = dsm_from_points([0.2, 0.4, 1.5], [0.5, 0.5, 0.5], [1, 3, 2], 1.0)
    >>> h.tolist(), (g.rows, g.cols)
    ([[3.0, 2.0]], (1, 2))
    """
    x, y, z = (np.asarray(a, dtype=np.float64).ravel() for a in (x, y, z))
    if not (cell > 0 and np.isfinite(cell)):
        raise InputError(f"cell size must be a positive number, got {cell!r}")
    if x.size == 0:
        raise InputError("no points to make a DSM from")
    if bounds is None:
        mins, maxs = (x.min(), y.min()), (x.max(), y.max())
    else:
        mins, maxs = (bounds[0], bounds[1]), (bounds[2], bounds[3])
    grid = Grid.covering(mins, maxs, float(cell))
    flat = grid.flat_index(x, y)
    # ufunc.at is slow on numpy < 1.25: sort by cell and reduce each run instead.
    order = np.argsort(flat, kind="stable")
    fs = flat[order]
    starts = np.flatnonzero(np.r_[True, fs[1:] != fs[:-1]])
    out = np.full(grid.rows * grid.cols, np.nan, dtype=np.float32)
    out[fs[starts]] = np.maximum.reduceat(z[order], starts).astype(np.float32)
    heights = out.reshape(grid.rows, grid.cols)
    if fill:
        valid = np.isfinite(heights)
        heights = fill_holes(np.where(valid, heights, 0).astype(np.float32), valid)
    return heights, grid


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
    if distance_unit not in ("crs", "metre"):
        raise InputError(f"distance unit must be 'crs' or 'metre', got {distance_unit!r}")
    if distance_unit == "metre":
        if not np.isfinite(info.unit_to_metre):
            raise CrsError("the cloud has no CRS: give the cell size in its own unit", path=path)
        cell = cell / info.unit_to_metre
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


# ---------------------------------------------------------------------------- raster input
def _gdal_read(path: str) -> tuple[NDArray[np.float32], tuple[float, ...], str] | None:
    try:
        from osgeo import gdal
    except ImportError:
        return None
    gdal.UseExceptions()
    try:
        ds = gdal.Open(path)
    except RuntimeError as exc:
        raise InputError(f"not a readable raster ({exc})", path=path) from exc
    band = ds.GetRasterBand(1)
    data = band.ReadAsArray().astype(np.float32)
    nodata = band.GetNoDataValue()
    if nodata is not None:
        data[data == np.float32(nodata)] = np.nan
    return data, tuple(ds.GetGeoTransform()), ds.GetProjection() or ""


def _tiff_read(path: str) -> tuple[NDArray[np.float32], tuple[float, ...], str]:
    """Minimal reader for uncompressed, striped, single-band float GeoTIFFs (ours, and others
    written that way); anything else needs GDAL."""
    raw = Path(path).read_bytes()
    if raw[:4] not in (b"II*\0", b"MM\0*"):
        raise InputError("not a TIFF file (GDAL is not available for other formats)", path=path)
    end = "<" if raw[:2] == b"II" else ">"
    (ifd,) = struct.unpack(end + "I", raw[4:8])
    (count,) = struct.unpack(end + "H", raw[ifd : ifd + 2])
    sizes = {1: 1, 2: 1, 3: 2, 4: 4, 11: 4, 12: 8, 16: 8}
    codes = {1: "B", 2: "s", 3: "H", 4: "I", 11: "f", 12: "d", 16: "Q"}
    tags: dict[int, Any] = {}
    for k in range(count):
        tag, typ, n, value = struct.unpack(end + "HHI4s", raw[ifd + 2 + 12 * k : ifd + 14 + 12 * k])
        if typ not in sizes:
            continue
        nbytes = sizes[typ] * n
        blob = (
            value
            if nbytes <= 4
            else raw[(off := struct.unpack(end + "I", value)[0]) : off + nbytes]
        )
        tags[tag] = blob[:n] if typ == 2 else struct.unpack(end + f"{n}{codes[typ]}", blob[:nbytes])
    need = "; install GDAL (it comes with QGIS) for other rasters"
    if tags.get(259, (1,))[0] != 1 or tags.get(284, (1,))[0] != 1 or 322 in tags:
        raise InputError("compressed or tiled TIFF" + need, path=path)
    if tags.get(277, (1,))[0] != 1:
        raise InputError("the DSM raster must have one band" + need, path=path)
    bits, fmt = tags.get(258, (32,))[0], tags.get(339, (1,))[0]
    dtype = {(32, 3): "f4", (64, 3): "f8", (16, 2): "i2", (32, 2): "i4", (16, 1): "u2"}.get(
        (bits, fmt)
    )
    if dtype is None or 33922 not in tags or 33550 not in tags:
        raise InputError("unsupported sample type or no georeferencing" + need, path=path)
    cols, rows = tags[256][0], tags[257][0]
    data = np.concatenate(
        [
            np.frombuffer(raw, end + dtype, count=nb // np.dtype(dtype).itemsize, offset=off)
            for off, nb in zip(tags[273], tags[279])
        ]
    )[: rows * cols]
    data = data.reshape(rows, cols).astype(np.float32)
    if 42113 in tags:
        nodata = float(tags[42113].rstrip(b"\0").decode("ascii"))
        data[data == np.float32(nodata)] = np.nan
    sx, sy = tags[33550][:2]
    tie = tags[33922]
    gt = (tie[3] - tie[0] * sx, sx, 0.0, tie[4] + tie[1] * sy, 0.0, -sy)
    wkt = ""
    keys = tags.get(34735, ())
    for k in range(keys[3] if keys else 0):
        key, loc, _, val = keys[4 + 4 * k : 8 + 4 * k]
        if key == 3072 and loc == 0:
            wkt = pyproj.CRS.from_epsg(val).to_wkt()
    aux = Path(path + ".aux.xml")
    if not wkt and aux.is_file():
        import re
        from xml.sax.saxutils import unescape

        m = re.search(r"<SRS[^>]*>(.*?)</SRS>", aux.read_text(encoding="utf-8"), re.S)
        wkt = unescape(m.group(1)) if m else ""
    return data, gt, wkt


def read_dsm_raster(path: PathLike, crs: str | int | pyproj.CRS | None = None) -> Dsm:
    """Read a north-up, single-band DSM raster (GDAL when importable, else uncompressed TIFF).

    ``crs`` overrides (or supplies) the raster's CRS.
    """
    p = os.fspath(path)
    if not Path(p).is_file():
        raise InputError("file not found", path=p)
    got = _gdal_read(p)
    data, gt, wkt = got if got is not None else _tiff_read(p)
    if abs(gt[2]) > 0 or abs(gt[4]) > 0 or not np.isclose(gt[1], -gt[5], rtol=1e-9):
        raise InputError("the DSM must be north-up with square cells", path=p)
    if not np.isfinite(data).any():
        raise InputError("the DSM has no valid cell", path=p)
    rows, cols = data.shape
    grid = Grid(float(gt[0]), float(gt[3]), float(gt[1]), rows, cols)
    file_crs = parse_crs(wkt) if wkt else None
    return Dsm(data, grid, parse_crs(crs) if crs else file_crs, p)


def reproject_dsm(
    dsm: Dsm,
    crs: str | int | pyproj.CRS,
    cell: float | None = None,
    *,
    block_rows: int = 256,
    should_stop: Callable[[], bool] | None = None,
) -> Dsm:
    """The DSM resampled onto a north-up grid of another CRS, heights transformed too.

    Each target cell centre is mapped back to the source CRS, the source surface (the
    triangulated polyhedron) is sampled there and the point (x, y, height) is transformed
    to the target: vertical datum changes are applied (2D CRSs carry ellipsoidal heights,
    :func:`core.frames.as_3d`), and a transformation that needs a grid PROJ does not have
    raises :class:`CrsError` instead of silently dropping it.

    Parameters
    ----------
    dsm : Dsm
        With its CRS.
    crs : target CRS.
    cell : float, optional
        Target cell, target CRS unit (default: the source cell times the local scale
        between the two CRSs at the DSM's centre, rounded to 1 mm).
    block_rows : int
        Target rows transformed per batch (memory).
    """
    from ..geometry.frames import transformer_3d

    if dsm.crs is None:
        raise CrsError("the DSM has no CRS: it cannot be reprojected", path=dsm.source or None)
    dst = parse_crs(crs)
    fwd = transformer_3d(dsm.crs, dst)
    inv = transformer_3d(dst, dsm.crs)
    g = dsm.grid
    rows, cols = dsm.heights.shape
    # the footprint: the surface's outline (cell centres of the border), densified
    k = np.linspace(0.0, 1.0, 65)
    xc, yc = dsm.centre_origin
    xs = xc + np.r_[k, np.ones_like(k), k[::-1], np.zeros_like(k)] * (cols - 1) * g.cell
    ys = yc - np.r_[np.zeros_like(k), k, np.ones_like(k), k[::-1]] * (rows - 1) * g.cell
    zmid = float(np.nanmedian(dsm.heights)) if np.isfinite(dsm.heights).any() else 0.0
    bx, by, _ = fwd.transform(xs, ys, np.full(xs.size, zmid))
    if not (np.isfinite(bx).all() and np.isfinite(by).all()):
        raise CrsError(f"the DSM's footprint cannot be transformed to '{dst.name}'",
                       path=dsm.source or None)  # fmt: skip
    if cell is None:
        cx, cy = xc + (cols - 1) * g.cell / 2, yc - (rows - 1) * g.cell / 2
        px, py, _ = fwd.transform(
            [cx, cx + g.cell, cx], [cy, cy, cy + g.cell], [zmid] * 3
        )  # fmt: skip
        scale = 0.5 * (math.hypot(px[1] - px[0], py[1] - py[0])
                       + math.hypot(px[2] - px[0], py[2] - py[0])) / g.cell  # fmt: skip
        cell = max(round(g.cell * scale, 3), 1e-3)
    cell = float(cell)
    out = Grid.covering((bx.min() - cell / 2, by.min() - cell / 2),
                        (bx.max() + cell / 2, by.max() + cell / 2), cell)  # fmt: skip
    heights = np.full((out.rows, out.cols), np.nan, np.float32)
    cols_x = out.x0 + (np.arange(out.cols) + 0.5) * cell
    for r0 in range(0, out.rows, max(int(block_rows), 1)):
        stop_if_asked(should_stop, "building the DSM")
        r1 = min(r0 + block_rows, out.rows)
        yy = out.y_top - (np.arange(r0, r1) + 0.5) * cell
        tx, ty = np.meshgrid(cols_x, yy)
        sx, sy, _ = inv.transform(tx.ravel(), ty.ravel(), np.full(tx.size, zmid))
        h = dsm.height_at(sx, sy)
        ok = np.isfinite(h)
        if ok.any():
            _, _, th = fwd.transform(sx[ok], sy[ok], h[ok])
            block = np.full(tx.size, np.nan)
            block[ok] = th
            heights[r0:r1] = block.reshape(tx.shape)
    LOG.info("DSM reprojected from '%s' to '%s': %d x %d cells of %g", dsm.crs.name, dst.name,
             out.rows, out.cols, cell)  # fmt: skip
    return Dsm(heights, out, dst, dsm.source)


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
            path, cell, crs, distance_unit=distance_unit, progress=progress,
            should_stop=should_stop,
        )  # fmt: skip
    return read_dsm_raster(path, crs)
