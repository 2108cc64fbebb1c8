"""GeoTIFF writing (:mod:`.raster` reads): :class:`GeoTiffWriter` (tiled, compressed, written
by blocks, with its overview levels computed from the blocks or by GDAL), and the one-call
writers of a whole array or an RGB image. Through GDAL: osgeo in QGIS, rasterio outside.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import Executor, Future
from typing import Any, Union

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from .atomic import atomic_path
from .gdal_binding import check_written, gdal_write_errors, quietly, raster_backend
from .gdal_binding import rio_env as _rio_env
from .raster import _crs_text, _threads, overview_factors

PathLike = Union[str, "os.PathLike[str]"]
Window = tuple[int, int, int, int]

__all__ = ["GeoTiffWriter", "write_geotiff", "write_rgb_tiff"]

#: Largest memory the overview levels computed from the blocks may hold (bytes); a larger
#: raster gets GDAL's overviews, read back from the file.
OVERVIEW_MEMORY_BYTES = 256 << 20


_GDAL_TYPES = {
    "uint8": "Byte",
    "uint16": "UInt16",
    "int16": "Int16",
    "uint32": "UInt32",
    "int32": "Int32",
    "float32": "Float32",
    "float64": "Float64",
}


class GeoTiffWriter:
    """A GeoTIFF being written window by window (module docstring for the layout).

    Parameters
    ----------
    path : str
        The file to write (a temporary name: :func:`write_geotiff` and the jobs pass one).
    width, height, bands : int
    dtype : numpy dtype
        uint8, uint16, int16, uint32, int32, float32 or float64.
    geotransform : 6 floats, GDAL order, or None
    crs : CRS (EPSG code, WKT, pyproj.CRS) or None
    nodata : float, optional
        Nodata value of every band.
    mask : bool
        Write an internal per-dataset mask (:meth:`write` takes it per window).
    compress : {"DEFLATE", "ZSTD", "LZW", "JPEG", "NONE"}
        JPEG (lossy, quality 90, YCbCr for three 8-bit bands) needs 8-bit data.
    level : int, optional
        DEFLATE (1-9) or ZSTD (1-22) level (default: GDAL's, 6 and 9).
    predictor : bool
        Horizontal (integers) or floating-point predictor before DEFLATE, ZSTD, LZW.
    tile : int
        Block side, pixels (multiple of 16); 0 writes strips.
    photometric : str, optional
        e.g. "RGB" for three 8-bit bands.
    metadata : mapping, optional
        Items of the default metadata domain.
    overviews_in_memory : bool, optional
        Compute the overviews from the blocks as they are written
        (:mod:`core.io.raster_overviews`: the same pixels as GDAL's, without reading the file
        back) and write them directly. Default: with a mask, for 8- and 16-bit unsigned data
        whose levels fit :data:`OVERVIEW_MEMORY_BYTES`, unless ``LIDARPHOTO_OVERVIEWS=gdal``;
        falls back to GDAL's when the blocks do not come
        row band after row band or a block comes without its mask.
    """

    def __init__(
        self,
        path: PathLike,
        width: int,
        height: int,
        bands: int,
        dtype: Any,
        geotransform: Sequence[float] | None,
        crs: Any = None,
        *,
        nodata: float | None = None,
        mask: bool = False,
        compress: str = "DEFLATE",
        level: int | None = None,
        predictor: bool = True,
        tile: int = 256,
        photometric: str | None = None,
        metadata: Mapping[str, str] | None = None,
        overviews_in_memory: bool | None = None,
    ) -> None:
        self.path = os.fspath(path)
        self.backend = raster_backend()
        self.width, self.height, self.bands = int(width), int(height), int(bands)
        self.dtype = np.dtype(dtype)
        if self.dtype.name not in _GDAL_TYPES:
            raise ValueError(f"unsupported raster type {self.dtype}")
        self.mask = bool(mask)
        self._closed = False
        self._level = level
        factors = overview_factors(self.width, self.height)
        if overviews_in_memory is None:
            # the levels held until the file is closed: level 1, a quarter of the raster and
            # its mask, and the deeper ones (a third more)
            held = (
                -(-self.height // 2)
                * -(-self.width // 2)
                * (self.bands * self.dtype.itemsize + 1)
                * 4
                // 3
            )
            overviews_in_memory = (
                self.mask
                and self.dtype in (np.uint8, np.uint16)
                and held <= OVERVIEW_MEMORY_BYTES
                and os.environ.get("LIDARPHOTO_OVERVIEWS", "").lower() != "gdal"
            )
        self._ovr = None
        if overviews_in_memory and factors:
            from .raster_overviews import OverviewBuilder

            self._ovr = OverviewBuilder(
                self.bands, self.height, self.width, self.dtype, len(factors)
            )
        compress = compress.upper()
        integer = self.dtype.kind in "ui"
        opts: dict[str, str] = {
            "COMPRESS": compress,
            "BIGTIFF": "IF_SAFER",
            "NUM_THREADS": str(_threads()),
            "INTERLEAVE": "PIXEL",
        }
        if tile:
            opts.update(TILED="YES", BLOCKXSIZE=str(int(tile)), BLOCKYSIZE=str(int(tile)))
        if predictor and compress in ("DEFLATE", "LZW", "ZSTD"):
            opts["PREDICTOR"] = "2" if integer else "3"
        if level is not None and compress in ("DEFLATE", "ZSTD"):
            opts["ZLEVEL" if compress == "DEFLATE" else "ZSTD_LEVEL"] = str(int(level))
        if photometric:
            opts["PHOTOMETRIC"] = photometric.upper()
        if compress == "JPEG":
            if self.dtype != np.uint8:
                raise InputError(f"JPEG compression needs 8-bit data, not {self.dtype}")
            opts["JPEG_QUALITY"] = "90"
            if self.bands == 3:
                opts["PHOTOMETRIC"] = "YCBCR"
        crs_text = _crs_text(crs)
        gt = tuple(float(v) for v in geotransform) if geotransform is not None else None
        if self.backend == "gdal":
            from osgeo import gdal

            gdal.UseExceptions()
            drv = gdal.GetDriverByName("GTiff")
            self._ds = drv.Create(
                self.path,
                self.width,
                self.height,
                self.bands,
                getattr(gdal, "GDT_" + _GDAL_TYPES[self.dtype.name]),
                [f"{k}={v}" for k, v in opts.items()],
            )
            if gt is not None:
                self._ds.SetGeoTransform(gt)
            if crs_text:
                from osgeo import osr

                srs = osr.SpatialReference()
                srs.SetFromUserInput(crs_text)
                self._ds.SetSpatialRef(srs)
            if nodata is not None:
                for b in range(1, self.bands + 1):
                    self._ds.GetRasterBand(b).SetNoDataValue(float(nodata))
            if metadata:
                self._ds.SetMetadata({str(k): str(v) for k, v in metadata.items()})
            if self.mask:
                gdal.SetThreadLocalConfigOption("GDAL_TIFF_INTERNAL_MASK", "YES")
                try:
                    self._ds.CreateMaskBand(gdal.GMF_PER_DATASET)
                finally:
                    gdal.SetThreadLocalConfigOption("GDAL_TIFF_INTERNAL_MASK", None)
        else:
            import rasterio
            from rasterio.crs import CRS as RIO_CRS
            from rasterio.errors import NotGeoreferencedWarning
            from rasterio.transform import Affine

            self._env = _rio_env(GDAL_TIFF_INTERNAL_MASK=True)
            self._env.__enter__()
            kwargs: dict[str, Any] = {k.lower(): v for k, v in opts.items()}
            kwargs.pop("tiled", None)
            with warnings.catch_warnings():  # an image without georeferencing is fine here
                warnings.simplefilter("ignore", NotGeoreferencedWarning)
                self._ds = rasterio.open(
                    self.path,
                    "w",
                    driver="GTiff",
                    width=self.width,
                    height=self.height,
                    count=self.bands,
                    dtype=self.dtype.name,
                    nodata=nodata,
                    crs=RIO_CRS.from_user_input(crs_text) if crs_text else None,
                    transform=Affine.from_gdal(*gt) if gt is not None else None,
                    tiled=bool(tile),
                    **kwargs,
                )
            if metadata:
                self._ds.update_tags(**{str(k): str(v) for k, v in metadata.items()})

    def __enter__(self) -> GeoTiffWriter:
        return self

    def __exit__(self, exc_type: Any, *exc: object) -> None:
        self.close(overviews=exc_type is None)

    def write(
        self,
        array: NDArray,
        col0: int = 0,
        row0: int = 0,
        mask: NDArray[np.bool_] | None = None,
    ) -> None:
        """Write a (bands, rows, cols) or (rows, cols) block at (col0, row0); ``mask`` (rows,
        cols) True where valid (writers made with ``mask=True``)."""
        a = np.asarray(array)
        if a.ndim == 2:
            a = a[None]
        a = a.astype(self.dtype, copy=False)
        _, h, w = a.shape
        if self._ovr is not None and not (self.mask and mask is None):
            self._ovr.add(a, mask, int(col0), int(row0))
        elif self._ovr is not None:
            self._ovr.ok = False
        if self.backend == "gdal":
            with gdal_write_errors(self.path, self._drop):
                self._ds.WriteArray(a, xoff=int(col0), yoff=int(row0))
                if self.mask and mask is not None:
                    m = _mask_bytes(mask)
                    self._ds.GetRasterBand(1).GetMaskBand().WriteArray(m, int(col0), int(row0))
        else:
            from rasterio.windows import Window as RioWindow

            win = RioWindow(int(col0), int(row0), w, h)
            self._ds.write(a, window=win)
            if self.mask and mask is not None:
                self._ds.write_mask(_mask_bytes(mask), window=win)

    def _drop(self) -> None:
        self._ds = None
        self._closed = True

    def close(self, overviews: bool = True, finish_in: Executor | None = None) -> Future | None:
        """Build the overviews (unless ``overviews`` is False) and close the file.

        With ``finish_in``, overview levels made from the blocks in memory are written by that
        executor, after the full resolution is closed here (a job goes on with its next image
        meanwhile): the returned Future is done when the file is whole. Otherwise (and
        when GDAL builds the levels) everything is done here and None is returned."""
        if self._closed:
            return None
        self._closed = True
        later: Callable[[], None] | None = None
        try:
            factors = overview_factors(self.width, self.height) if overviews else []
            levels = None
            if factors and self._ovr is not None and self._ovr.ok:
                try:
                    levels = self._ovr.levels()
                except ValueError:  # not every row written: GDAL's overviews
                    levels = None
            self._ovr = None
            if self.backend == "gdal":
                held, self._ds = [self._ds], None

                def finish() -> None:  # (no local name for the dataset: see _drop)
                    with gdal_write_errors(self.path, held.clear):
                        if factors and levels is not None:
                            held[0].BuildOverviews("NONE", factors)  # the levels made
                            _write_levels_gdal(held[0], levels)
                        elif factors:
                            held[0].BuildOverviews("AVERAGE", factors)
                        held[0].FlushCache()
                    quietly(held.clear)  # the last reference: the file is closed here
                    check_written(self.path)  # (what the closing could not write)

                if levels is not None:
                    later = finish
                else:
                    finish()
            else:
                from rasterio.enums import Resampling

                if factors and levels is None:
                    self._ds.build_overviews(factors, Resampling.average)
                self._ds.close()
                check_written(self.path)  # (GDAL would crash on the levels of a cut file)
                if factors and levels is not None:
                    path, level = self.path, self._level

                    def later() -> None:
                        _write_levels_rasterio(path, factors, levels, level)
                        check_written(path)

        finally:
            if self.backend == "rasterio":
                self._env.__exit__(None, None, None)
        if later is None:
            return None
        if finish_in is None:
            later()
            return None
        return finish_in.submit(later)


def _mask_bytes(valid: NDArray) -> NDArray[np.uint8]:
    """GDAL's mask values of a boolean array: 255 where valid, 0 elsewhere (in uint8 from the
    start: no int64 temporary)."""
    return np.multiply(np.asarray(valid, bool), np.uint8(255), dtype=np.uint8)


#: Rows of an overview level written at once (a row of 512-px blocks, or several of smaller)
_LEVEL_ROWS = 512


def _write_levels_gdal(ds: Any, levels: list) -> None:
    """Write the overview levels (made empty by ``BuildOverviews("NONE")``) of an osgeo
    dataset: every band, and the mask's levels."""
    for k, (data, valid) in enumerate(levels):
        nb, rows, cols = data.shape
        level = ds.GetRasterBand(1).GetOverview(k).GetDataset()
        mask = ds.GetRasterBand(1).GetMaskBand().GetOverview(k)
        m = _mask_bytes(valid)
        for r0 in range(0, rows, _LEVEL_ROWS):  # as in _write_levels_rasterio
            part = np.ascontiguousarray(np.moveaxis(data[:, r0 : r0 + _LEVEL_ROWS], 0, -1))
            n = part.shape[0]
            level.WriteRaster(
                0,
                r0,
                cols,
                n,
                part.data,
                cols,
                n,
                band_list=list(range(1, nb + 1)),
                buf_pixel_space=part.strides[1],
                buf_line_space=part.strides[0],
                buf_band_space=part.strides[2],
            )
            mask.WriteArray(m[r0 : r0 + _LEVEL_ROWS], 0, r0)


def _rasterio_gdal() -> Any:
    """The GDAL C library that rasterio's modules are linked to (ctypes), with the few
    functions used here typed; None when it cannot be found (GDAL's overviews then)."""
    import ctypes

    import rasterio._io

    try:
        lib = ctypes.CDLL(rasterio._io.__file__)
        vp, ci = ctypes.c_void_p, ctypes.c_int
        lib.GDALOpenEx.restype = vp
        lib.GDALOpenEx.argtypes = [ctypes.c_char_p, ctypes.c_uint, vp, vp, vp]
        lib.GDALBuildOverviews.restype = ci
        lib.GDALBuildOverviews.argtypes = [
            vp,
            ctypes.c_char_p,
            ci,
            ctypes.POINTER(ci),
            ci,
            ctypes.POINTER(ci),
            vp,
            vp,
        ]
        lib.GDALGetRasterBand.restype = vp
        lib.GDALGetRasterBand.argtypes = [vp, ci]
        lib.GDALGetOverview.restype = vp
        lib.GDALGetOverview.argtypes = [vp, ci]
        lib.GDALGetMaskBand.restype = vp
        lib.GDALGetMaskBand.argtypes = [vp]
        lib.GDALRasterIO.restype = ci
        lib.GDALRasterIO.argtypes = [vp, ci, ci, ci, ci, ci, vp, ci, ci, ci, ci, ci]
        lib.GDALClose.restype = ci
        lib.GDALClose.argtypes = [vp]
        lib.GDALGetBandDataset.restype = vp
        lib.GDALGetBandDataset.argtypes = [vp]
        lib.GDALDatasetRasterIO.restype = ci
        lib.GDALDatasetRasterIO.argtypes = [
            vp,
            ci,
            ci,
            ci,
            ci,
            ci,
            vp,
            ci,
            ci,
            ci,
            ci,
            ctypes.POINTER(ci),
            ci,
            ci,
            ci,
        ]
    except (OSError, AttributeError):
        return None
    return lib


_GDT = {"uint8": 1, "uint16": 2}


def _write_levels_rasterio(path: str, factors: list[int], levels: list, zlevel: Any) -> None:
    """The overview levels into a closed GeoTIFF through the GDAL library rasterio carries
    (rasterio has no call to write an overview): levels made empty, then written."""
    lib = _rasterio_gdal()
    if lib is None:  # GDAL's own overviews
        import rasterio
        from rasterio.enums import Resampling

        with _rio_env(), rasterio.open(path, "r+") as ds:
            ds.build_overviews(factors, Resampling.average)
        return
    import ctypes

    # the levels' blocks compressed on every core, as the full resolution's (NUM_THREADS)
    options = {"GDAL_NUM_THREADS": str(_threads())}
    if zlevel is not None:
        options["ZLEVEL_OVERVIEW"] = str(int(zlevel))
    with _rio_env(**options):
        h = lib.GDALOpenEx(os.fsencode(path), 0x01 | 0x02 | 0x40, None, None, None)
        if not h:
            raise OSError(f"cannot reopen {path} to write its overviews")
        try:
            n = len(factors)
            arr = (ctypes.c_int * n)(*factors)
            if lib.GDALBuildOverviews(h, b"NONE", n, arr, 0, None, None, None) != 0:
                raise OSError(f"cannot make the overview levels of {path}")
            for k, (data, valid) in enumerate(levels):
                _, rows, cols = data.shape
                first = lib.GDALGetOverview(lib.GDALGetRasterBand(h, 1), k)
                level = lib.GDALGetBandDataset(first) if first else None
                mask = lib.GDALGetOverview(lib.GDALGetMaskBand(lib.GDALGetRasterBand(h, 1)), k)
                if not level or not mask:
                    raise OSError(f"cannot write the overviews of {path}")
                nb = data.shape[0]
                band_map = (ctypes.c_int * nb)(*range(1, nb + 1))
                m = _mask_bytes(valid)
                # all bands at once, a row of blocks after the other: each block is complete
                # when written, so GDAL's threads compress it while the next rows are copied
                for r0 in range(0, rows, _LEVEL_ROWS):
                    n = min(_LEVEL_ROWS, rows - r0)
                    part = data[:, r0 : r0 + n]
                    if (
                        lib.GDALDatasetRasterIO(
                            level,
                            1,
                            0,
                            r0,
                            cols,
                            n,
                            part.ctypes.data,
                            cols,
                            n,
                            _GDT[data.dtype.name],
                            nb,
                            band_map,
                            part.strides[2],
                            part.strides[1],
                            part.strides[0],
                        )
                        != 0
                    ):
                        raise OSError(f"cannot write the overviews of {path}")
                    mp = m[r0 : r0 + n]
                    if (
                        lib.GDALRasterIO(
                            mask,
                            1,
                            0,
                            r0,
                            cols,
                            n,
                            mp.ctypes.data,
                            cols,
                            n,
                            1,
                            mp.strides[1],
                            mp.strides[0],
                        )
                        != 0
                    ):
                        raise OSError(f"cannot write the overviews of {path}")
        finally:
            lib.GDALClose(h)


def write_geotiff(
    path: PathLike,
    array: NDArray[np.float32],
    geotransform: Sequence[float],
    nodata: float,
    crs: Any = None,
) -> None:
    """Write a float32 north-up raster (DSM, DTM): tiled, compressed, overviews, the CRS;
    written under a temporary name and moved into place.

    Parameters
    ----------
    path : str
        Destination ``.tif``.
    array : (rows, cols) float32
    geotransform : 6 floats, GDAL order (top-left corner, square cells, north up)
    nodata : float
    crs : str, int or pyproj.CRS, optional
    """
    data = np.asarray(array, dtype=np.float32)
    rows, cols = data.shape
    with atomic_path(path) as tmp:
        with GeoTiffWriter(tmp, cols, rows, 1, np.float32, geotransform, crs, nodata=nodata) as w:
            w.write(data)


def write_rgb_tiff(path: PathLike, rgb: NDArray[np.uint8]) -> None:
    """Write an (H, W, 3) RGB image as a tiled LZW TIFF without georeferencing, atomically."""
    a = np.asarray(rgb)
    if a.ndim != 3 or a.shape[2] != 3 or a.dtype != np.uint8:
        raise ValueError(f"expected an (H, W, 3) uint8 image, got {a.shape} {a.dtype}")
    h, w, _ = a.shape
    with atomic_path(path) as tmp:
        with GeoTiffWriter(
            tmp,
            w,
            h,
            3,
            np.uint8,
            None,
            compress="LZW",
            predictor=True,
            tile=512,
            photometric="RGB",
        ) as out:
            out.write(np.moveaxis(a, 2, 0))
            out.close(overviews=False)
