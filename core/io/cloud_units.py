"""The units of a point cloud's CRS (:mod:`core.io.pointcloud`): the horizontal unit and its
size in metres, and the vertical unit's (a compound CRS's vertical part, or the LAS file's
GeoTIFF VerticalUnitsGeoKey)."""

from __future__ import annotations

from typing import Any

import pyproj

from ..errors import CrsError

#: Sizes in metres of the linear units of GeoTIFF keys (EPSG unit codes).
_EPSG_LINEAR_UNITS = {
    9001: ("metre", 1.0),
    9002: ("foot", 0.3048),
    9003: ("US survey foot", 1200.0 / 3937.0),
}
_VERTICAL_UNITS_GEOKEY = 4099


def _horizontal_crs(crs: pyproj.CRS) -> pyproj.CRS:
    if crs.is_compound and crs.sub_crs_list:
        return crs.sub_crs_list[0]
    return crs


def _linear_unit(crs: pyproj.CRS) -> tuple[str, float]:
    axes = crs.axis_info
    if not axes:
        return "unknown", float("nan")
    return axes[0].unit_name, float(axes[0].unit_conversion_factor)


def _vertical_geokey_unit(header: Any) -> float | None:
    """Size in metres of the GeoTIFF VerticalUnitsGeoKey, when the file has a known one."""
    for vlr in header.vlrs:
        for key in getattr(vlr, "geo_keys", ()):
            if key.id == _VERTICAL_UNITS_GEOKEY and key.tiff_tag_location == 0:
                unit = _EPSG_LINEAR_UNITS.get(int(key.value_offset))
                return unit[1] if unit else None
    return None


def crs_units(
    crs: pyproj.CRS, vertical_geokey_to_metre: float | None = None
) -> tuple[str, float, float]:
    """Horizontal unit name, its size in metres, and the vertical unit's size in metres.

    Raises
    ------
    CrsError
        When the CRS is geographic or geocentric (no linear horizontal unit).

    Examples
    --------
    >>> crs_units(pyproj.CRS.from_epsg(2994))[:2]
    ('foot', 0.3048)
    """
    horizontal = _horizontal_crs(crs)
    if horizontal.is_geographic or horizontal.is_geocentric:
        raise CrsError(
            f"the CRS {horizontal.name!r} is geographic/geocentric: the algorithms need a "
            "projected CRS with a linear unit (reproject the cloud, or give its projected CRS)"
        )
    name, to_metre = _linear_unit(horizontal)
    vertical = to_metre
    if crs.is_compound and len(crs.sub_crs_list) > 1:
        vertical = _linear_unit(crs.sub_crs_list[1])[1]
    elif vertical_geokey_to_metre is not None:
        vertical = vertical_geokey_to_metre
    return name, to_metre, vertical
