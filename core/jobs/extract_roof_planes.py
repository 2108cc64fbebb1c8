"""``extractroofplanes``: roof planes with their precision from a classified LAS/LAZ cloud."""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

from ..errors import InputError
from .checks import check_memory
from .common import cloud_out, cloud_params, csv_out, lengths_in_cloud_units
from .runner import JobResult, stages
from .spec import AlgorithmSpec, Fields, Param, Ref, Result, Values, options_from

if TYPE_CHECKING:
    from ..lidar.roof_planes import RoofPlaneParams

log = logging.getLogger(__name__)

_D = Fields("lidar.roof_plane_params", "RoofPlaneParams")
#: (parameter, RoofPlaneParams field, label, kind, unit, minimum, maximum, advanced)
_NUMBERS = (
    (
        "K_NEIGHBOURS",
        "k_neighbours",
        "Neighbours K of the local RANSAC",
        "integer",
        "",
        6,
        500,
        True,
    ),
    (
        "EPSILON",
        "epsilon",
        "Point-to-plane tolerance epsilon",
        "number",
        "length",
        0.001,
        100.0,
        False,
    ),
    (
        "MIN_SUPPORT",
        "min_support",
        "Minimum support of a local plane",
        "integer",
        "points",
        3,
        500,
        True,
    ),
    (
        "RANSAC_ITERATIONS",
        "ransac_iterations",
        "RANSAC triplets per point",
        "integer",
        "",
        1,
        1000,
        True,
    ),
    ("MIN_SLOPE", "min_slope_deg", "Minimum slope alpha", "number", "degrees", 0.0, 90.0, False),
    ("MAX_SLOPE", "max_slope_deg", "Maximum slope beta", "number", "degrees", 0.0, 90.0, True),
    (
        "ANGLE_TOLERANCE",
        "angle_tolerance_deg",
        "Normal angle tolerance",
        "number",
        "degrees",
        0.1,
        89.9,
        True,
    ),
    (
        "MIN_PLANE_POINTS",
        "min_plane_points",
        "Minimum points per plane",
        "integer",
        "",
        3,
        1e9,
        False,
    ),
    (
        "OUTLINE_CELL",
        "outline_cell",
        "Outline raster cell (0 = auto)",
        "number",
        "length",
        0.0,
        1000.0,
        True,
    ),
    ("SEED", "seed", "Random seed", "integer", "", 0, 2**32 - 1, True),
)
#: Help of the parameters that need one.
_HELP = {
    "SEED": "no effect, kept for scripts and models that give it: the RANSAC triplets "
    "are a fixed set, every seed gives the same planes"
}
_LENGTHS = ("epsilon", "outline_cell")
#: Bytes per RANSAC sample (point x triplet) of a batch: the float32 distances, their
#: product and the inlier flags (about 10 B; rounded up).
RANSAC_BYTES_PER_SAMPLE = 16

SPEC = AlgorithmSpec(
    name="extractroofplanes",
    title="Extract roof planes",
    group="LiDAR",
    group_id="lidar",
    summary="roof planes with their precision from a classified LAS/LAZ cloud",
    description="""\
Extracts roof planes from a LiDAR cloud classified by a ground filter (Pedrosa & dos Santos
2020, section 2.1): for every point, RANSAC on its K nearest neighbours with tolerance
epsilon; the point is kept when the plane has the minimum support, the point lies on it and
its slope is between alpha and beta (rejects vegetation and walls). Kept points are grown into
regions (distance to the region's plane and normal angle), small regions dropped, ridge and
eave points attached to the nearest plane, coplanar neighbours merged. Each plane is fitted by
the weighted eigen method of Pathak et al. (2010) on centred coordinates, with the full
covariance of (a, b, c, d) and the standard deviation of d (Khoshelham 2016). The same points
give the same planes whatever their order, the seed or the number of threads: the RANSAC
triplets are a fixed set, not random draws.

## Points
Non-ground (class != 2), the listed Classes (e.g. 6), or all points (a cloud that is already
non-ground). CRS overrides the file's CRS.

## Units
With Distance unit = cloud CRS units, epsilon and the outline cell are in the unit of the
cloud's CRS (international feet for Autzen); with metres they are converted. Plane
parameters, centroids, rms and sigma_d are always in the CRS unit (the UNIT output names it).

## Outputs
Plane outlines (PolygonZ, concave hull for display) with every attribute; the plane table
CSV: id, a, b, c, d (n.p + d = 0, normal up), centroid_x/y/z, n_points, rms, sigma_d,
slope_deg, aspect_deg (clockwise from grid north, downslope), and the 10 upper-triangle
covariance elements cov_aa ... cov_dd; optionally a copy of the cloud with the int32 extra
dimension plane_id (-1 = none). A cloud without roofs gives zero planes and a message, not an
error.""",
    params=(
        *cloud_params("INPUT"),
        Param(
            "POINTS",
            "enum",
            "Points",
            "non_ground",
            options=Ref("lidar.roof_plane_params", "SELECTION_CHOICES"),
            labels=("non-ground (class != 2)", "the classes below", "all"),
            aliases={"non-ground": "non_ground"},
        ),
        Param(
            "CLASSES",
            "string",
            "Classes (e.g. 6)",
            "6",
            optional=True,
            help="LAS classes searched when POINTS is classes, e.g. 6 or 1,6",
        ),
        *_D.params(_NUMBERS, _HELP),
        Param("OUTPUT", "sink", "Roof planes", geometry="polygon", optional=True),
        csv_out("OUTPUT_CSV", "Plane table (CSV)", optional=False),
        cloud_out("OUTPUT_CLOUD", "Point cloud with plane_id", on_demand=True),
    ),
    results=(
        Result("PLANE_COUNT", "number", "Number of planes"),
        Result("UNIT", "string", "Unit of the lengths"),
    ),
    tags=("roof", "plane", "ransac", "building", "las", "laz", "point cloud", "segmentation"),
    references=("Pedrosa & dos Santos (2020)", "Pathak et al. (2010)", "Khoshelham (2016)"),
)


def parse_classes(text: str) -> tuple[int, ...]:
    """LAS classes from user text ``"6"``, ``"6,17"`` or ``"6 17"``.

    >>> parse_classes("6, 17")
    (6, 17)
    """
    parts = [p for p in text.replace(",", " ").replace(";", " ").split() if p]
    try:
        classes = tuple(int(p) for p in parts)
    except ValueError:
        raise InputError(f"CLASSES must be integers separated by commas, got {text!r}") from None
    if not classes or any(not 0 <= c <= 255 for c in classes):
        raise InputError(f"CLASSES: give one or more classes between 0 and 255, got {text!r}")
    return classes


@dataclass(frozen=True)
class RoofPlaneRun:
    """What the job did: the planes (``result``, with the plane id of every point of the
    file), the parameters actually used in the cloud's unit ``unit``, the cloud's CRS."""

    result: Any
    params: RoofPlaneParams
    unit: str
    unit_to_metre: float
    crs_wkt: str
    n_points: int
    n_selected: int
    messages: tuple[str, ...] = ()


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the cloud, extract roof planes, write the plane table (and the cloud)."""
    import numpy as np

    from ..io.planes import write_planes_csv
    from ..lidar.roof_planes import extract_roof_planes

    params = _params(v)
    wanted = parse_classes(v.classes) if v.points == "classes" else ()
    weights = (0.15, 0.7, 0.15) if out.requested("OUTPUT_CLOUD") else (0.2, 0.8, 0.0)
    read, compute, write = stages(progress, *weights)
    cloud, arrays, info = _read(v, out, read, should_stop)
    params = lengths_in_cloud_units(params, info, v.distance_unit, _LENGTHS)
    messages = [
        f"lengths in {info.horizontal_unit} (1 unit = {info.unit_to_metre:g} m): "
        f"epsilon = {params.epsilon:g}, outline cell = {params.outline_cell:g} (0 = auto)"
    ]
    n = info.point_count
    sel = _selected(v, arrays, n, wanted)
    n_sel = int(sel.sum())
    xyz = np.column_stack([arrays["x"][sel], arrays["y"][sel], arrays["z"][sel]])
    del arrays
    result = extract_roof_planes(xyz, params, progress=compute, should_stop=should_stop)
    del xyz
    messages.append(result.message)
    plane_id = np.full(n, -1, dtype=np.int32)
    plane_id[sel] = result.plane_id
    if out.requested("OUTPUT_CLOUD"):
        _write_cloud(v.input, out.path("OUTPUT_CLOUD"), plane_id, cloud, write, should_stop)
    write_planes_csv(out.path("OUTPUT_CSV"), result.planes)
    if progress is not None:
        progress(1.0)
    run_info = RoofPlaneRun(
        result=replace(result, plane_id=plane_id),
        params=params,
        unit=info.horizontal_unit,
        unit_to_metre=info.unit_to_metre,
        crs_wkt=info.crs.to_wkt() if info.crs is not None else "",
        n_points=n,
        n_selected=n_sel,
        messages=tuple(messages),
    )
    for message in messages:
        log.info(message)
    return JobResult(
        results={"PLANE_COUNT": len(result.planes), "UNIT": info.horizontal_unit},
        lines=[
            f"{result.message}; lengths in {info.horizontal_unit} -> {out.target('OUTPUT_CSV')}"
        ],
        data=run_info,
    )


def _write_cloud(source, target, plane_id, cloud, progress, should_stop) -> None:
    """The input cloud's points with their ``plane_id`` (-1: none) as an extra dimension."""
    from ..io.pointcloud import write_cloud

    write_cloud(
        source,
        target,
        extra={"plane_id": plane_id},
        points=cloud,
        progress=progress,
        should_stop=should_stop,
    )


def _params(v: Values):
    """The :class:`RoofPlaneParams` of the parameters, checked against each other and against
    the memory a RANSAC batch needs."""
    from ..lidar.roof_planes import RoofPlaneParams

    if v.min_support > v.k_neighbours:
        raise InputError(
            f"MIN_SUPPORT ({v.min_support}) must not exceed K_NEIGHBOURS ({v.k_neighbours})"
        )
    if v.min_slope > v.max_slope:
        raise InputError(
            f"MIN_SLOPE ({v.min_slope:g}) must not exceed MAX_SLOPE ({v.max_slope:g} degrees)"
        )
    params = options_from(RoofPlaneParams, SPEC, v)
    # RANSAC works on batches of points: each holds batch x iterations x K samples
    check_memory(
        float(params.batch_size)
        * params.ransac_iterations
        * params.k_neighbours
        * RANSAC_BYTES_PER_SAMPLE,
        f"K_NEIGHBOURS {params.k_neighbours} with RANSAC_ITERATIONS "
        f"{params.ransac_iterations}: one batch of {params.batch_size} points",
        "give fewer neighbours or iterations",
    )
    return params


def _read(v: Values, out, progress, should_stop) -> tuple:
    """(the whole cloud when OUTPUT_CLOUD is written from it else None, the x, y, z (and
    classification) arrays, the cloud's info), refused when x, y and z are in two units."""
    from ..io.pointcloud import read_cloud, read_points

    fields = ("x", "y", "z") if v.points == "all" else ("x", "y", "z", "classification")
    cloud = None
    if out.requested("OUTPUT_CLOUD"):  # decoded once: the copy is written from memory
        cloud = read_cloud(v.input, v.crs or None, progress=progress, should_stop=should_stop)
        arrays, info = {f: cloud.values(f) for f in fields}, cloud.info
    else:
        arrays, info = read_points(
            v.input, fields, crs=v.crs or None, progress=progress, should_stop=should_stop
        )
    ratio = info.vertical_unit_to_metre / info.unit_to_metre
    if not math.isfinite(ratio) or abs(ratio - 1.0) > 1e-9:
        raise InputError(
            f"horizontal unit ({info.horizontal_unit}) and vertical unit "
            f"({info.vertical_unit_to_metre} m) differ: planes need x, y and z in one unit; "
            "convert the heights first",
            path=str(v.input),
        )
    return cloud, arrays, info


def _selected(v: Values, arrays: dict, n: int, wanted: tuple):
    """The mask (n,) of the points POINTS selects (``wanted``: the classes of CLASSES),
    refused when it selects none."""
    import numpy as np

    selection = v.points
    if selection == "all":
        sel = np.ones(n, dtype=bool)
    elif selection == "classes":
        sel = np.isin(arrays["classification"], wanted)
    else:
        sel = arrays["classification"] != 2
    if not sel.any():
        what = {"classes": f"of class {v.classes}", "non_ground": "that is not ground (class 2)"}
        raise InputError(f"no point {what.get(selection, '')} in the cloud", path=str(v.input))
    return sel
