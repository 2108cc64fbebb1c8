"""Raster regions as vectors: the region of each label of a raster as a WKT MultiPolygon
(GDAL's polygonize through osgeo or rasterio, as :mod:`.raster` chooses)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from .gdal_binding import raster_backend, rio_env

__all__ = ["polygonize"]


def polygonize(
    labels: NDArray[np.integer], geotransform: Sequence[float], empty: int = -1
) -> dict[int, str]:
    """The region of each label of a raster as a WKT MultiPolygon in map coordinates.

    Polygons follow the pixel edges exactly (GDAL's polygonize, 4-connected regions); pixels
    with the label ``empty`` belong to no region.

    Parameters
    ----------
    labels : (rows, cols) integer array
    geotransform : 6 floats, GDAL order

    Returns
    -------
    dict
        label -> ``MULTIPOLYGON (((x y, ...)))``.
    """
    lab = np.ascontiguousarray(labels, dtype=np.int32)
    gt = tuple(float(v) for v in geotransform)
    parts: dict[int, list[str]] = {}
    if raster_backend() == "gdal":
        from osgeo import gdal, ogr

        gdal.UseExceptions()
        mem = gdal.GetDriverByName("MEM").Create("", lab.shape[1], lab.shape[0], 2, gdal.GDT_Int32)
        mem.SetGeoTransform(gt)
        mem.GetRasterBand(1).WriteArray(lab)
        mem.GetRasterBand(2).WriteArray((lab != empty).astype(np.int32))
        vec = ogr.GetDriverByName("Memory").CreateDataSource("")
        layer = vec.CreateLayer("regions")
        layer.CreateField(ogr.FieldDefn("label", ogr.OFTInteger))
        gdal.Polygonize(mem.GetRasterBand(1), mem.GetRasterBand(2), layer, 0, [])
        for feat in layer:
            geom = feat.GetGeometryRef()
            wkt = geom.ExportToWkt()
            parts.setdefault(int(feat.GetField(0)), []).append(wkt[len("POLYGON ") :])
    else:
        from rasterio import features
        from rasterio.transform import Affine

        with rio_env():
            shapes = list(features.shapes(lab, mask=lab != empty, transform=Affine.from_gdal(*gt)))
        for geom, value in shapes:
            rings = ", ".join(
                "(" + ", ".join(f"{x!r} {y!r}" for x, y in ring) + ")"
                for ring in geom["coordinates"]
            )
            parts.setdefault(int(value), []).append(f"({rings})")
    return {k: "MULTIPOLYGON (" + ", ".join(v) + ")" for k, v in sorted(parts.items())}
