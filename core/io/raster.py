"""Raster files: single-band float GeoTIFFs (DSM, DTM) and RGB images.

Written without GDAL (an uncompressed, striped float32 GeoTIFF with GeoTIFF keys, or the WKT
in a ``.aux.xml`` sidecar when the CRS has no EPSG code), read with GDAL when it can be
imported (always in QGIS) and otherwise with a minimal reader for such TIFFs. Every write
goes through :func:`~lidarphoto.core.io.atomic.atomic_path`.
"""

from __future__ import annotations

import os
import re
import struct
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Union

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from .atomic import atomic_path, write_text_atomic

PathLike = Union[str, "os.PathLike[str]"]


def read_geotiff(path: PathLike) -> tuple[NDArray[np.float32], tuple[float, ...], str]:
    """Band 1 of a raster as float32 (nodata -> NaN), its GDAL geotransform and CRS WKT.

    GDAL reads any format it knows; without GDAL only uncompressed, striped, single-band
    TIFFs (as :func:`write_geotiff` writes them) can be read.
    """
    p = os.fspath(path)
    if not Path(p).is_file():
        raise InputError("file not found", path=p)
    got = _gdal_read(p)
    return got if got is not None else _tiff_read(p)


def write_geotiff(
    path: PathLike,
    array: NDArray[np.float32],
    geotransform: Sequence[float],
    nodata: float,
    crs: Any = None,
) -> None:
    """Write a float32 north-up raster as an uncompressed GeoTIFF (no GDAL needed).

    The CRS is written as GeoTIFF keys when it has an EPSG code (the horizontal and vertical
    parts of a compound CRS separately); otherwise its WKT goes into a GDAL ``.aux.xml``
    sidecar. Written to a temporary file and moved into place.

    Parameters
    ----------
    path : str
        Destination ``.tif``.
    array : (rows, cols) float32
    geotransform : 6 floats, GDAL order (top-left corner, square cells, north up)
    nodata : float
    crs : str, int or pyproj.CRS, optional
    """
    import os
    import struct

    from ..io.pointcloud import parse_crs

    data = np.ascontiguousarray(array, dtype="<f4")
    rows, cols = data.shape
    x0, cx, _, y_top, _, cy = (float(v) for v in geotransform)
    keys = [(1024, 0, 1, 1), (1025, 0, 1, 1)]  # projected model, PixelIsArea
    wkt = ""
    pcrs = parse_crs(crs)
    if pcrs is not None:
        horizontal = pcrs.sub_crs_list[0] if pcrs.is_compound else pcrs
        code = horizontal.to_epsg()
        if code:
            keys.append((3072, 0, 1, code))
            if pcrs.is_compound and len(pcrs.sub_crs_list) > 1:
                vcode = pcrs.sub_crs_list[1].to_epsg()
                if vcode:
                    keys.append((4096, 0, 1, vcode))
        else:
            wkt = pcrs.to_wkt()
    geokeys = [1, 1, 0, len(keys)] + [v for k in keys for v in k]
    nodata_text = f"{nodata:g}\0".encode("ascii")
    # (tag, type, values): types 3 SHORT, 4 LONG, 12 DOUBLE, 2 ASCII
    body = data.tobytes()
    entries: list[tuple[int, int, Any]] = [
        (256, 4, [cols]),
        (257, 4, [rows]),
        (258, 3, [32]),
        (259, 3, [1]),
        (262, 3, [1]),
        (273, 4, [0]),  # strip offset, patched below
        (277, 3, [1]),
        (278, 4, [rows]),
        (279, 4, [len(body)]),
        (284, 3, [1]),
        (339, 3, [3]),
        (33550, 12, [cx, -cy, 0.0]),
        (33922, 12, [0.0, 0.0, 0.0, x0, y_top, 0.0]),
        (34735, 3, geokeys),
        (42113, 2, nodata_text),
    ]
    fmt = {2: "s", 3: "H", 4: "I", 12: "d"}
    ifd_offset = 8
    ifd_size = 2 + 12 * len(entries) + 4
    extra_offset = ifd_offset + ifd_size
    extra = b""
    packed = []
    for tag, typ, values in entries:
        count = len(values)
        raw = values if typ == 2 else struct.pack(f"<{count}{fmt[typ]}", *values)
        packed.append((tag, typ, count, raw))
        if len(raw) > 4:
            extra += raw + (b"\0" if len(raw) % 2 else b"")
    strip_offset = extra_offset + len(extra)
    ifd = struct.pack("<H", len(entries))
    cursor = extra_offset
    for tag, typ, count, raw in packed:
        if tag == 273:
            raw = struct.pack("<I", strip_offset)
        if len(raw) > 4:
            ifd += struct.pack("<HHII", tag, typ, count, cursor)
            cursor += len(raw) + (len(raw) % 2)
        else:
            ifd += struct.pack("<HHI", tag, typ, count) + raw.ljust(4, b"\0")
    ifd += struct.pack("<I", 0)
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        fh.write(b"II*\0" + struct.pack("<I", ifd_offset) + ifd + extra + body)
    if wkt:
        from xml.sax.saxutils import escape

        sidecar = f"<PAMDataset>\n  <SRS>{escape(wkt)}</SRS>\n</PAMDataset>\n"
        write_text_atomic(os.fspath(path) + ".aux.xml", sidecar)


def write_rgb_tiff(path: PathLike, rgb: NDArray[np.uint8]) -> None:
    """Write an (H, W, 3) RGB image as an LZW TIFF (no georeferencing), atomically."""
    import cv2

    bgr = cv2.cvtColor(np.ascontiguousarray(rgb), cv2.COLOR_RGB2BGR)
    with atomic_path(path) as tmp:
        if not cv2.imwrite(tmp, bgr, [cv2.IMWRITE_TIFF_COMPRESSION, 5]):
            raise InputError("OpenCV could not write the image", path=os.fspath(path))


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
            import pyproj

            wkt = pyproj.CRS.from_epsg(val).to_wkt()
    aux = Path(path + ".aux.xml")
    if not wkt and aux.is_file():
        from xml.sax.saxutils import unescape

        m = re.search(r"<SRS[^>]*>(.*?)</SRS>", aux.read_text(encoding="utf-8"), re.S)
        wkt = unescape(m.group(1)) if m else ""
    return data, gt, wkt
