"""``createlcps``: LiDAR control points and lines from intersecting roof planes."""

from __future__ import annotations

import logging
from dataclasses import replace

from ..errors import InputError
from ..i18n import mark as _t
from .common import cloud_params, csv_out, lengths_in_cloud_units, table_param, unit_symbol
from .runner import JobResult, stages
from .spec import AlgorithmSpec, Fields, Param, Result, Values, options_from

log = logging.getLogger(__name__)

#: catalogue context of this module's ``_t("...")`` log sentences
TR_CONTEXT = "Report"

_D = Fields("lidar.control_options", "ControlOptions")
_LENGTHS = ("delta", "min_boundary", "max_support_distance")

SPEC = AlgorithmSpec(
    name="createlcps",
    title="Create LiDAR control points and lines",
    group="LiDAR",
    group_id="lidar",
    summary="LiDAR control points and lines from intersecting roof planes",
    description="""\
Intersects roof planes found by Extract roof planes: three planes meeting at a roof corner
give a LiDAR control point (LCP), two adjacent planes give a 3D line (ridge, hip, valley or
other), each with a covariance propagated from the plane fits.

Planes: the plane table CSV; Cloud: the LAS/LAZ written by the same algorithm (with its
plane_id dimension). Two planes are adjacent when their points come within delta of each
other along a common boundary at least min boundary long. A corner is kept only when every
pair of its normals differ by at least min angle, the 3x3 system is well conditioned (max
condition) and the point lies within max support distance of the points of each plane; where
more than three planes meet (a pyramid apex) the most precise triple is kept. Lines are
clipped to the common support of the two planes.

Distances are in the cloud's CRS unit (e.g. feet for a CRS in feet) unless distance unit is
metres; the outputs are in the CRS unit. Optionally give your own plane-id triples
("1,2,3; 4,5,6") or pairs ("1,2; 2,3") instead of the automatic ones. The log counts the
rejected candidates per reason; each one, with its numbers and units, is listed only in
verbose mode (command line: -vv; QGIS: Processing options, logging level Verbose).""",
    params=(
        table_param("PLANES", "Plane table (CSV)"),
        *cloud_params("CLOUD", "Cloud with plane ids (LAS/LAZ)"),
        Param(
            "DELTA",
            "number",
            "Adjacency distance delta",
            _D.delta,
            unit="length",
            minimum=0.001,
            maximum=1000.0,
        ),
        Param(
            "MIN_BOUNDARY",
            "number",
            "Minimum common boundary",
            _D.min_boundary,
            unit="length",
            minimum=0.0,
            maximum=10000.0,
        ),
        Param(
            "MAX_SUPPORT",
            "number",
            "Maximum distance of a corner from each plane's points",
            _D.max_support_distance,
            unit="length",
            minimum=0.001,
            maximum=1000.0,
            advanced=True,
        ),
        Param(
            "MIN_ANGLE",
            "number",
            "Minimum angle between normals",
            _D.min_angle_deg,
            unit="degrees",
            minimum=0.0,
            maximum=90.0,
        ),
        Param(
            "MAX_CONDITION",
            "number",
            "Maximum condition number",
            _D.max_condition,
            minimum=1.0,
            maximum=1e12,
            advanced=True,
        ),
        Param(
            "TRIPLES",
            "string",
            "Plane triples",
            "",
            optional=True,
            advanced=True,
            help='plane ids "1,2,3; 4,5,6" (default: automatic)',
        ),
        Param(
            "PAIRS",
            "string",
            "Plane pairs",
            "",
            optional=True,
            advanced=True,
            help='plane ids "1,2; 2,3" (default: automatic)',
        ),
        Param("OUTPUT_POINTS", "sink", "LiDAR control points", geometry="point", optional=True),
        Param("OUTPUT_LINES", "sink", "LiDAR control lines", geometry="line", optional=True),
        csv_out("POINTS_CSV", "Control point table (CSV)", on_demand=True, twin="OUTPUT_POINTS"),
        csv_out("LINES_CSV", "Control line table (CSV)", on_demand=True),
        csv_out("GRAPH_CSV", "Plane adjacency graph (CSV)", on_demand=True, advanced=True),
    ),
    results=(
        Result("LCP_COUNT", "number", "Number of LCPs"),
        Result("LINE_COUNT", "number", "Number of lines"),
    ),
    tags=("lcp", "control point", "roof", "ridge", "plane intersection", "covariance"),
    references=("Pedrosa & dos Santos (2020)",),
)


def parse_id_groups(text: str, size: int, name: str) -> list[tuple[int, ...]] | None:
    """``"1,2,3; 4,5,6"`` -> [(1, 2, 3), (4, 5, 6)]; empty text -> None (automatic).

    >>> parse_id_groups("1,2; 2 3", 2, "PAIRS")
    [(1, 2), (2, 3)]
    """
    text = (text or "").strip()
    if not text:
        return None
    out = []
    for part in text.replace("\n", ";").split(";"):
        if not part.strip():
            continue
        try:
            ids = tuple(int(v) for v in part.replace(" ", ",").split(",") if v)
        except ValueError:
            raise InputError(f"{name}: '{part.strip()}' is not a list of plane ids") from None
        if len(ids) != size:
            raise InputError(f"{name}: '{part.strip()}' must have {size} plane ids")
        out.append(ids)
    return out


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the planes and the cloud, intersect the planes, write the tables."""
    import numpy as np

    from ..io.planes import read_planes_csv
    from ..io.pointcloud import read_info, read_points
    from ..lidar.control import ControlOptions, lidar_control

    user_triples = parse_id_groups(v.triples, 3, "TRIPLES")
    user_pairs = parse_id_groups(v.pairs, 2, "PAIRS")
    options = options_from(ControlOptions, SPEC, v)
    planes = read_planes_csv(v.planes)
    info = read_info(v.cloud, crs=v.crs)
    options = lengths_in_cloud_units(options, info, v.distance_unit, _LENGTHS)
    options = replace(options, length_unit=unit_symbol(info.horizontal_unit))
    if v.distance_unit == "metre":
        log.info("distances converted from metres to %s", info.horizontal_unit)
    if "plane_id" not in info.dimensions:
        raise InputError(
            "the cloud has no 'plane_id' dimension: use the cloud written by "
            "lidarphoto:extractroofplanes",
            path=str(v.cloud),
        )
    read, compute = stages(progress, 0.3, 0.7)
    arrays, info = read_points(
        v.cloud, ("x", "y", "z", "plane_id"), crs=v.crs, progress=read, should_stop=should_stop
    )
    xyz = np.column_stack([arrays["x"], arrays["y"], arrays["z"]])
    result = lidar_control(
        planes,
        xyz,
        arrays["plane_id"],
        options,
        user_triples,
        user_pairs,
        progress=compute,
        should_stop=should_stop,
    )
    _write_tables(out, result)
    _log_rejected(result)
    pairs = int(result.adjacency.adjacent.sum())
    return JobResult(
        results={"LCP_COUNT": len(result.points), "LINE_COUNT": len(result.lines)},
        lines=[
            f"{len(result.points)} control points, {len(result.lines)} lines, {pairs} adjacent "
            f"plane pairs ({info.horizontal_unit})"
        ],
        data=(result, info),
    )


def _write_tables(out, result) -> None:
    """The requested tables of ``result``: LCPs, lines and the plane adjacency graph."""
    from ..io.control import write_graph_csv, write_lcps_csv, write_lines_csv

    if out.requested("POINTS_CSV"):
        write_lcps_csv(out.path("POINTS_CSV"), result.points)
    if out.requested("LINES_CSV"):
        write_lines_csv(out.path("LINES_CSV"), result.lines)
    if out.requested("GRAPH_CSV"):
        write_graph_csv(out.path("GRAPH_CSV"), result.adjacency)


def _log_rejected(result) -> None:
    """The rejected candidates: their counts always, each one in verbose mode only (CLI -vv,
    QGIS debug info)."""
    from ..lidar.control import rejection_summary

    if result.rejected:
        log.info(
            _t(
                "{summary} (details: lidarphoto -vv; QGIS: Processing logging level Verbose)",
                summary=rejection_summary(result.rejected),
            )
        )
    for r in result.rejected:
        log.debug("planes %s: %s", ",".join(map(str, r.plane_ids)), r.reason)
