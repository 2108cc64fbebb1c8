"""``groundfilter``: progressive morphological ground filter of a LAS/LAZ cloud."""

from __future__ import annotations

import logging

from ..errors import InputError
from ..lidar.ground_filter import GROWTH_CHOICES, WINDOW_SHAPES, GroundFilterParams
from .checks import GROUND_FILTER_BYTES_PER_CELL, GROUND_FILTER_BYTES_PER_POINT, check_cell_size
from .common import cloud_params, lengths_in_cloud_units, unit_text
from .runner import JobResult, stages
from .spec import AlgorithmSpec, Param, Result, Values

log = logging.getLogger(__name__)

_D = GroundFilterParams()
H, V = "horizontal length", "vertical length"
#: (parameter, GroundFilterParams field, label, unit, advanced, minimum, maximum): the ranges
#: are physical (a cell of 1 cm to 1 km, a slope up to 10:1) and hold in feet as in metres.
_NUMBERS = (
    ("CELL_SIZE", "cell_size", "Cell size", H, False, 0.01, 1000.0),
    ("MAX_WINDOW", "max_window", "Maximum window size", H, False, 0.01, 10000.0),
    ("SLOPE", "slope", "Terrain slope", "rise/run", False, 0.0, 10.0),
    ("INITIAL_DISTANCE", "initial_distance", "Initial elevation threshold", V, False, 0.0,
     1000.0),
    ("MAX_DISTANCE", "max_distance", "Maximum elevation threshold", V, False, 0.0, 1000.0),
    ("WINDOW_BASE", "window_base", "Window growth base b", "cells", True, 0.5, 100.0),
    ("GROUND_THRESHOLD", "ground_threshold", "Final height tolerance", V, False, 0.0, 1000.0),
    ("SLOPE_SCALAR", "slope_scalar", "Tolerance added per unit of slope", V, True, 0.0, 1000.0),
    ("LOW_OUTLIER_HEIGHT", "low_outlier_height", "Low outlier depth (0 = off)", V, True, 0.0,
     1000.0),
    ("LOW_OUTLIER_RADIUS", "low_outlier_radius", "Low outlier radius", H, True, 0.0, 10000.0),
)  # fmt: skip
HORIZONTAL_LENGTHS = tuple(f for _, f, _, unit, *_ in _NUMBERS if unit == H)
VERTICAL_LENGTHS = tuple(f for _, f, _, unit, *_ in _NUMBERS if unit == V)

SPEC = AlgorithmSpec(
    name="groundfilter",
    title="Ground filter (progressive morphological)",
    group="LiDAR",
    group_id="lidar",
    summary="progressive morphological ground filter of a LAS/LAZ cloud",
    description="""\
Separates ground from objects with the Progressive Morphological Filter (Zhang et al. 2003):
minimum grid, openings with growing windows and slope-dependent elevation thresholds, then
each point is ground when its height above the filtered surface is within a slope-dependent
tolerance (as in SMRF, Pingel et al. 2013). Low outliers are removed first (class 7); only
last returns can be ground when the file has return numbers.

## Units
With Distance unit = cloud CRS units, every length is in the unit of the cloud's CRS (e.g.
international feet for Autzen); with metres, they are converted. The log and the UNIT output
say which unit was used. CRS overrides the file's CRS (needed when the file has none).

## Outputs
A copy of the cloud (LAS/LAZ by suffix) with every original dimension and VLR, class 2 for
ground (other classes kept, or set to 1), and the extra dimension height_above_ground
(float32); optionally the DTM as GeoTIFF.""",
    params=(
        *cloud_params("INPUT"),
        *(
            Param(key, "number", label, getattr(_D, field), unit=unit, minimum=lo, maximum=hi,
                  advanced=advanced)
            for key, field, label, unit, advanced, lo, hi in _NUMBERS
        ),
        Param("GROWTH", "enum", "Window growth", _D.growth, options=GROWTH_CHOICES,
              advanced=True),
        Param("WINDOW_SHAPE", "enum", "Window shape", _D.window_shape, options=WINDOW_SHAPES,
              advanced=True),
        Param("LAST_RETURNS_ONLY", "boolean", "Only last returns can be ground",
              _D.last_returns_only),
        Param("NON_GROUND_CLASS", "enum", "Non-ground points", "keep",
              options=("keep", "unclassified"),
              labels=("keep their class", "set to 1 (unclassified)")),
        Param("OUTPUT_CLOUD", "file_out", "Classified point cloud",
              file_filter="LAZ files (*.laz);;LAS files (*.las)"),
        Param("OUTPUT_DTM", "raster_out", "DTM", optional=True, create_by_default=False),
    ),
    results=(
        Result("POINT_COUNT", "number", "Number of points"),
        Result("GROUND_COUNT", "number", "Number of ground points"),
        Result("LOW_OUTLIER_COUNT", "number", "Number of low outliers"),
        Result("UNIT", "string", "Unit of the distances"),
    ),
    tags=("ground", "dtm", "pmf", "morphological", "las", "laz", "point cloud", "classification"),
    references=("Zhang et al. (2003)", "Pingel et al. (2013)"),
)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the cloud, filter its ground, write the classified copy (and the DTM)."""
    from ..io.pointcloud import read_info, read_points, write_cloud
    from ..io.raster import write_geotiff
    from ..lidar.ground_filter import (
        GROUND_CLASS,
        HEIGHT_FIELD,
        LOW_NOISE_CLASS,
        UNCLASSIFIED_CLASS,
        ground_filter,
    )

    params = GroundFilterParams(
        **{field: v[key] for key, field, *_ in _NUMBERS},
        growth=v.growth,
        window_shape=v.window_shape,
        last_returns_only=v.last_returns_only,
    )
    _check_together(v)
    params.validate()
    read, compute, write = stages(progress, 0.3, 0.3, 0.4)
    info = read_info(v.input, v.crs)
    _check_against_data(v, info)
    params = lengths_in_cloud_units(
        params, info, v.distance_unit, HORIZONTAL_LENGTHS, VERTICAL_LENGTHS
    )
    fields: tuple[str, ...] = ("x", "y", "z", "classification")
    if info.has_return_numbers and params.last_returns_only:
        fields = (*fields, "return_number", "number_of_returns")
    arrays, info = read_points(v.input, fields, v.crs, progress=read, should_stop=should_stop)
    converted = v.distance_unit == "metre"
    log.info(
        "%s: %d points, CRS %s, distances in %s (%s)",
        v.input,
        info.point_count,
        info.crs.name if info.crs is not None else "?",
        "metres" if converted else info.horizontal_unit,
        "converted from metres" if converted else "the cloud's CRS unit",
    )
    result = ground_filter(
        arrays.pop("x"),
        arrays.pop("y"),
        arrays.pop("z"),
        params,
        return_number=arrays.get("return_number"),
        number_of_returns=arrays.get("number_of_returns"),
        unit_to_metre=info.unit_to_metre,
        vertical_unit_to_metre=info.vertical_unit_to_metre,
        unit=info.horizontal_unit,
        progress=compute,
        should_stop=should_stop,
    )
    cls = arrays.pop("classification").copy()
    if v.non_ground_class == "unclassified":
        cls[:] = UNCLASSIFIED_CLASS
    else:  # a point the file had as ground but the filter rejects becomes unclassified
        cls[(cls == GROUND_CLASS) & ~result.ground] = UNCLASSIFIED_CLASS
    cls[result.ground] = GROUND_CLASS
    cls[result.low_outlier] = LOW_NOISE_CLASS
    write_cloud(
        v.input,
        out.path("OUTPUT_CLOUD"),
        classification=cls,
        extra={HEIGHT_FIELD: result.height_above_ground},
        progress=write,
        should_stop=should_stop,
    )
    crs_wkt = info.crs.to_wkt() if info.crs is not None else ""
    if out.requested("OUTPUT_DTM"):
        write_geotiff(
            out.path("OUTPUT_DTM"), result.dtm, result.geotransform, result.nodata, crs_wkt or None
        )
    unit = unit_text(info, v.distance_unit)
    ground, low = int(result.ground.sum()), int(result.low_outlier.sum())
    return JobResult(
        results={
            "POINT_COUNT": info.point_count,
            "GROUND_COUNT": ground,
            "LOW_OUTLIER_COUNT": low,
            "UNIT": unit,
        },
        lines=[
            f"{info.point_count} points, {ground} ground, {low} low outliers; distances in "
            f"{unit} -> {out.target('OUTPUT_CLOUD')}"
        ],
        data=result,
    )


def _check_together(v: Values) -> None:
    """Parameters that are only meaningful together."""
    if v.max_window < v.cell_size:
        raise InputError(
            f"MAX_WINDOW ({v.max_window:g}) must be at least one cell (CELL_SIZE {v.cell_size:g})"
        )
    if v.initial_distance > v.max_distance:
        raise InputError(
            f"INITIAL_DISTANCE ({v.initial_distance:g}) must not exceed MAX_DISTANCE "
            f"({v.max_distance:g})"
        )
    if v.growth == "exponential" and v.window_base <= 1:
        raise InputError(f"WINDOW_BASE must be > 1 for exponential growth, got {v.window_base:g}")


def _check_against_data(v: Values, info) -> None:
    """Cell and window sizes against the cloud's extent (from its header) and the memory the
    grids will take (lengths compared in the unit the user gave them)."""
    metre = v.distance_unit == "metre"
    factor = info.unit_to_metre if metre else 1.0
    unit = "m" if metre else info.horizontal_unit
    mins, maxs = info.mins[:2] * factor, info.maxs[:2] * factor
    per_point = GROUND_FILTER_BYTES_PER_POINT + 27  # + x, y, z, class, returns as read
    check_cell_size("CELL_SIZE", v.cell_size, unit, mins, maxs, GROUND_FILTER_BYTES_PER_CELL,
                    extra_bytes=info.point_count * per_point)  # fmt: skip
    width, height = maxs - mins
    # a window wider than the data opens it as one the data's size does: harmless up to a
    # point, a unit or typing mistake beyond twice the extent
    if v.max_window > 2.0 * max(width, height):
        raise InputError(
            f"MAX_WINDOW: {v.max_window:g} {unit} is more than twice the data's extent "
            f"({width:.4g} x {height:.4g} {unit}): give about the size of the largest building"
        )

