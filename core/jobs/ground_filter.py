"""``groundfilter``: ground filter of a LAS/LAZ cloud: SMRF (default), PMF or CSF."""

from __future__ import annotations

import logging

from ..errors import InputError
from .checks import GROUND_FILTER_BYTES_PER_CELL, GROUND_FILTER_BYTES_PER_POINT, check_cell_size
from .common import cloud_out, cloud_params, length_unit_text, lengths_in_cloud_units
from .runner import JobResult, stages
from .spec import AlgorithmSpec, Param, Ref, Result, Values

log = logging.getLogger(__name__)

H, V = "horizontal length", "vertical length"
#: The parameter dataclass of each method (core/lidar/ground_filter.py), which holds the
#: defaults; the parameters below name the method they belong to ("" = all).
_CLASSES = {"smrf": "SmrfParams", "pmf": "GroundFilterParams", "csf": "CsfParams"}
_SCIENCE = "lidar.ground_filter_params"
#: (parameter, method, field, label, kind, unit, advanced, minimum, maximum): the ranges are
#: physical (a cell of 1 cm to 1 km, a slope up to 10:1) and hold in feet as in metres.
_NUMBERS = (
    ("SMRF_CELL_SIZE", "smrf", "cell_size", "SMRF cell size", "number", H, False, 0.01, 1000.0),
    (
        "SMRF_SLOPE",
        "smrf",
        "slope",
        "SMRF terrain slope (0 = estimated from the cloud)",
        "number",
        "rise/run",
        False,
        0.0,
        10.0,
    ),
    (
        "SMRF_WINDOW",
        "smrf",
        "max_window",
        "SMRF largest window radius",
        "number",
        H,
        False,
        0.01,
        10000.0,
    ),
    (
        "SMRF_THRESHOLD",
        "smrf",
        "threshold",
        "SMRF final height tolerance",
        "number",
        V,
        False,
        0.0,
        1000.0,
    ),
    (
        "SMRF_SCALAR",
        "smrf",
        "scalar",
        "SMRF tolerance added per unit of slope",
        "number",
        V,
        True,
        0.0,
        1000.0,
    ),
    ("CELL_SIZE", "pmf", "cell_size", "PMF cell size", "number", H, False, 0.01, 1000.0),
    (
        "MAX_WINDOW",
        "pmf",
        "max_window",
        "PMF maximum window size",
        "number",
        H,
        False,
        0.01,
        10000.0,
    ),
    ("SLOPE", "pmf", "slope", "PMF terrain slope", "number", "rise/run", False, 0.0, 10.0),
    (
        "INITIAL_DISTANCE",
        "pmf",
        "initial_distance",
        "PMF initial elevation threshold",
        "number",
        V,
        True,
        0.0,
        1000.0,
    ),
    (
        "MAX_DISTANCE",
        "pmf",
        "max_distance",
        "PMF maximum elevation threshold",
        "number",
        V,
        False,
        0.0,
        1000.0,
    ),
    (
        "WINDOW_BASE",
        "pmf",
        "window_base",
        "PMF window growth base b",
        "number",
        "cells",
        True,
        0.5,
        100.0,
    ),
    (
        "GROUND_THRESHOLD",
        "pmf",
        "ground_threshold",
        "PMF final height tolerance",
        "number",
        V,
        True,
        0.0,
        1000.0,
    ),
    (
        "SLOPE_SCALAR",
        "pmf",
        "slope_scalar",
        "PMF tolerance added per unit of slope",
        "number",
        V,
        True,
        0.0,
        1000.0,
    ),
    (
        "CSF_RESOLUTION",
        "csf",
        "resolution",
        "CSF cloth resolution",
        "number",
        H,
        False,
        0.01,
        1000.0,
    ),
    (
        "CSF_RIGIDNESS",
        "csf",
        "rigidness",
        "CSF rigidness (1 steep, 2 terraces, 3 flat)",
        "integer",
        "",
        False,
        1,
        3,
    ),
    (
        "CSF_THRESHOLD",
        "csf",
        "threshold",
        "CSF distance to the cloth",
        "number",
        V,
        False,
        0.0,
        1000.0,
    ),
    ("CSF_TIME_STEP", "csf", "time_step", "CSF time step", "number", "", True, 0.01, 10.0),
    (
        "CSF_ITERATIONS",
        "csf",
        "iterations",
        "CSF largest number of steps",
        "integer",
        "",
        True,
        1,
        100000,
    ),
    (
        "LOW_OUTLIER_HEIGHT",
        "",
        "low_outlier_height",
        "Low outlier depth (0 = off)",
        "number",
        V,
        True,
        0.0,
        1000.0,
    ),
    (
        "LOW_OUTLIER_RADIUS",
        "",
        "low_outlier_radius",
        "Low outlier radius",
        "number",
        H,
        True,
        0.0,
        10000.0,
    ),
)
#: (parameter, method, field, label, kind, options, advanced)
_CHOICES = (
    ("GROWTH", "pmf", "growth", "PMF window growth", "enum", Ref(_SCIENCE, "GROWTH_CHOICES"), True),
    (
        "WINDOW_SHAPE",
        "pmf",
        "window_shape",
        "PMF window shape",
        "enum",
        Ref(_SCIENCE, "WINDOW_SHAPES"),
        True,
    ),
    ("CSF_SLOPE_SMOOTH", "csf", "slope_smooth", "CSF slope smoothing", "boolean", (), True),
    (
        "LAST_RETURNS_ONLY",
        "",
        "last_returns_only",
        "Only last returns can be ground",
        "boolean",
        (),
        False,
    ),
)
_FIELDS = tuple(row[:3] for row in _NUMBERS) + tuple(row[:3] for row in _CHOICES)
#: parameter -> the method it belongs to ("" = every method): the one-method forms in QGIS
PARAM_METHODS = {key: method for key, method, _ in _FIELDS}
HORIZONTAL_LENGTHS = {
    m: tuple(f for _, pm, f, _, _, u, *_ in _NUMBERS if u == H and pm in (m, "")) for m in _CLASSES
}
VERTICAL_LENGTHS = {
    m: tuple(f for _, pm, f, _, _, u, *_ in _NUMBERS if u == V and pm in (m, "")) for m in _CLASSES
}


def _default(method: str, field: str) -> Ref:
    return Ref(_SCIENCE, _CLASSES[method or "smrf"], field)


# fmt: off
SPEC = AlgorithmSpec(
    name="groundfilter",
    title="Ground filter (SMRF, PMF, cloth simulation)",
    group="LiDAR",
    group_id="lidar",
    summary="ground filter of a LAS/LAZ cloud: SMRF, PMF or cloth simulation",
    description="""\
Separates ground from objects. Low outliers are removed first (class 7); only last returns
can be ground when the file has return numbers. Methods:

- smrf (default): the Simple Morphological Filter of Pingel et al. (2013): openings of the
  lowest-point grid with disks of growing radius, a threshold growing with the radius
  (slope x radius), then each point within a slope-dependent tolerance of the ground surface
  is ground. The defaults are the published ones (cell 1 m, slope 0.15, window radius 18 m,
  scalar 1.25) except the final tolerance SMRF_THRESHOLD, 0.3 m instead of 0.5 m (chosen on
  AHN3, README). SMRF_SLOPE 0 estimates the terrain slope from the cloud (a first pass on
  cells twice as large; the 90th percentile of its ground slope, within 0.1-0.7); it
  over-estimates where vegetation covers steep slopes.
- pmf: the Progressive Morphological Filter of Zhang et al. (2003), with SMRF's final test.
- csf: the cloth simulation filter of Zhang et al. (2016): a cloth dropped on the cloud
  turned upside down; points within CSF_THRESHOLD of it are ground.

A parameter of another method than METHOD must keep its default (it would be ignored).

## Units
With Distance unit = cloud CRS units, every length is in the unit of the cloud's CRS (e.g.
international feet for Autzen); with metres, they are converted. The log and the UNIT output
say which unit was used. CRS overrides the file's CRS (needed when the file has none).

## Outputs
A copy of the cloud (LAS/LAZ by suffix) with every original dimension and VLR, class 2 for
ground (other classes kept, or set to 1), in the same point format; with Height above ground
also the extra dimension height_above_ground (float32); optionally the DTM as GeoTIFF.""",
    params=(
        *cloud_params("INPUT"),
        Param("METHOD", "enum", "Method", "smrf", options=Ref(_SCIENCE, "METHODS"),
              labels=("SMRF (Pingel et al. 2013)", "PMF (Zhang et al. 2003)",
                      "cloth simulation (Zhang et al. 2016)")),
        *(
            Param(key, kind, label, _default(method, field), unit=unit, minimum=lo,
                  maximum=hi, advanced=advanced)
            for key, method, field, label, kind, unit, advanced, lo, hi in _NUMBERS
        ),
        *(
            Param(key, kind, label, _default(method, field), options=options,
                  advanced=advanced)
            for key, method, field, label, kind, options, advanced in _CHOICES
        ),
        Param("NON_GROUND_CLASS", "enum", "Non-ground points", "keep",
              options=("keep", "unclassified"),
              labels=("keep their class", "set to 1 (unclassified)"), advanced=True),
        Param("HEIGHT_ABOVE_GROUND", "boolean", "Add the height above the DTM to the cloud",
              False, help="the extra dimension height_above_ground (float32, vertical unit); "
              "it changes the point format (extra bytes) and makes the file larger"),
        cloud_out("OUTPUT_CLOUD", "Classified point cloud", optional=False),
        Param("OUTPUT_DTM", "raster_out", "DTM", optional=True, create_by_default=False),
    ),
    results=(
        Result("POINT_COUNT", "number", "Number of points"),
        Result("GROUND_COUNT", "number", "Number of ground points"),
        Result("LOW_OUTLIER_COUNT", "number", "Number of low outliers"),
        Result("UNIT", "string", "Unit of the distances"),
    ),
    tags=("ground", "dtm", "smrf", "pmf", "csf", "morphological", "cloth", "las", "laz",
          "point cloud", "classification"),
    references=("Pingel et al. (2013)", "Zhang et al. (2003)", "Zhang et al. (2016)"),
)
# fmt: on


def method_params(v: Values):
    """The science parameters of the chosen method (SmrfParams, GroundFilterParams or
    CsfParams) from the job's values, lengths as given."""
    from ..lidar import ground_filter_params as science

    method = v.method
    cls = getattr(science, _CLASSES[method])
    fields = {field: v[key] for key, m, field in _FIELDS if m in (method, "")}
    return cls(**fields)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the cloud, filter its ground, write the classified copy (and the DTM)."""
    from ..io.pointcloud import read_cloud, read_info, write_cloud
    from ..io.raster_write import write_geotiff
    from ..lidar.ground_filter import HEIGHT_FIELD, ground_filter

    _check_together(v)
    params = method_params(v)
    params.validate()
    read, compute, write = stages(progress, 0.3, 0.3, 0.4)
    info = read_info(v.input, v.crs)
    _check_against_data(v, info)
    params = lengths_in_cloud_units(
        params, info, v.distance_unit, HORIZONTAL_LENGTHS[v.method], VERTICAL_LENGTHS[v.method]
    )
    cloud = read_cloud(v.input, v.crs, progress=read, should_stop=should_stop)
    info = cloud.info
    returns = info.has_return_numbers and params.last_returns_only
    _log_start(v, info)
    result = ground_filter(
        cloud.scaled_xyz(),  # the records' integers: no float64 x, y, z of every point
        params=params,
        return_number=cloud.values("return_number") if returns else None,
        number_of_returns=cloud.values("number_of_returns") if returns else None,
        unit_to_metre=info.unit_to_metre,
        vertical_unit_to_metre=info.vertical_unit_to_metre,
        unit=info.horizontal_unit,
        heights=v.height_above_ground,
        progress=compute,
        should_stop=should_stop,
    )
    cls = cloud.values("classification")
    result.classify(cls, reset_non_ground=v.non_ground_class == "unclassified")
    write_cloud(
        v.input,
        out.path("OUTPUT_CLOUD"),
        classification=cls,
        extra={HEIGHT_FIELD: result.height_above_ground} if v.height_above_ground else None,
        points=cloud,
        progress=write,
        should_stop=should_stop,
    )
    crs_wkt = info.crs.to_wkt() if info.crs is not None else ""
    if out.requested("OUTPUT_DTM"):
        write_geotiff(
            out.path("OUTPUT_DTM"), result.dtm, result.geotransform, result.nodata, crs_wkt or None
        )
    return _job_result(v, info, result, out)


def _job_result(v: Values, info, result, out) -> JobResult:
    """The figures and the summary line of the run."""
    unit = length_unit_text(info, v.distance_unit)
    ground, low = result.stats["ground_count"], result.stats["low_outlier_count"]
    slope = result.stats.get("slope_estimated")
    estimated = f"; terrain slope estimated at {slope:.3f}" if slope is not None else ""
    return JobResult(
        results={
            "POINT_COUNT": info.point_count,
            "GROUND_COUNT": ground,
            "LOW_OUTLIER_COUNT": low,
            "UNIT": unit,
        },
        lines=[
            f"{info.point_count} points, {ground} ground, {low} low outliers ({v.method}"
            f"{estimated}); distances in {unit} -> {out.target('OUTPUT_CLOUD')}"
        ],
        data=result,
    )


def _log_start(v: Values, info) -> None:
    """Log the cloud, its CRS, the unit of the distances and the method."""
    converted = v.distance_unit == "metre"
    log.info(
        "%s: %d points, CRS %s, distances in %s (%s), method %s",
        v.input,
        info.point_count,
        info.crs.name if info.crs is not None else "?",
        "metres" if converted else info.horizontal_unit,
        "converted from metres" if converted else "the cloud's CRS unit",
        v.method,
    )


def _check_together(v: Values) -> None:
    """Parameters that are only meaningful together, and none of another method."""
    others = [
        key
        for key, method, _ in _FIELDS
        if method not in ("", v.method) and v[key] != SPEC.param(key).default
    ]
    if others:
        raise InputError(
            f"{', '.join(others)}: parameter{'s' if len(others) > 1 else ''} of another method "
            f"than METHOD {v.method}: set METHOD, or leave {'them' if len(others) > 1 else 'it'} "
            "at the default"
        )
    if v.method == "pmf":
        if v.max_window < v.cell_size:
            raise InputError(
                f"MAX_WINDOW ({v.max_window:g}) must be at least one cell "
                f"(CELL_SIZE {v.cell_size:g})"
            )
        if v.initial_distance > v.max_distance:
            raise InputError(
                f"INITIAL_DISTANCE ({v.initial_distance:g}) must not exceed MAX_DISTANCE "
                f"({v.max_distance:g})"
            )
        if v.growth == "exponential" and v.window_base <= 1:
            raise InputError(
                f"WINDOW_BASE must be > 1 for exponential growth, got {v.window_base:g}"
            )
    elif v.method == "smrf" and v.smrf_window < v.smrf_cell_size:
        raise InputError(
            f"SMRF_WINDOW ({v.smrf_window:g}) must be at least one cell "
            f"(SMRF_CELL_SIZE {v.smrf_cell_size:g})"
        )


#: The cell and window parameters of each method (the window is a radius in SMRF).
_GRID = {
    "pmf": ("CELL_SIZE", "MAX_WINDOW"),
    "smrf": ("SMRF_CELL_SIZE", "SMRF_WINDOW"),
    "csf": ("CSF_RESOLUTION", None),
}


def _check_against_data(v: Values, info) -> None:
    """Cell and window sizes against the cloud's extent (from its header) and the memory the
    grids will take (lengths compared in the unit the user gave them)."""
    metre = v.distance_unit == "metre"
    factor = info.unit_to_metre if metre else 1.0
    unit = "m" if metre else info.horizontal_unit
    mins, maxs = info.mins[:2] * factor, info.maxs[:2] * factor
    # + class and returns as arrays and the records kept for the copy (x, y, z are read from
    # the records a block at a time)
    per_point = GROUND_FILTER_BYTES_PER_POINT + 3 + info.record_size
    cell_key, window_key = _GRID[v.method]
    check_cell_size(
        cell_key,
        v[cell_key],
        unit,
        mins,
        maxs,
        GROUND_FILTER_BYTES_PER_CELL,
        extra_bytes=info.point_count * per_point,
    )
    width, height = maxs - mins
    # a window wider than the data opens it as one the data's size does: harmless up to a
    # point, a unit or typing mistake beyond twice the extent
    if window_key is not None and v[window_key] > 2.0 * max(width, height):
        raise InputError(
            f"{window_key}: {v[window_key]:g} {unit} is more than twice the data's extent "
            f"({width:.4g} x {height:.4g} {unit}): give about the size of the largest building"
        )
