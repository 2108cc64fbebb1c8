"""``fitplane``: an algorithm of the test suite, written as docs/architecture.md's "Adding an
algorithm" says (tests/core/test_add_algorithm.py registers it and runs it through the command
line; tests/qgis/test_add_algorithm_qgis.py through the QGIS provider).

It fits one least-squares plane to a point table and counts the points within EPSILON of it;
EPSILON's default is read from the science (the roof-plane tolerance), not retyped.
"""

from __future__ import annotations

from lidarphoto.core.jobs.common import CSV_FILTER, CSV_OUT
from lidarphoto.core.jobs.runner import JobResult
from lidarphoto.core.jobs.spec import AlgorithmSpec, Fields, Param, Result, Values

_ROOF = Fields("lidar.roof_planes", "RoofPlaneParams")
COLUMNS = ("a", "b", "c", "d", "rms", "inliers")

SPEC = AlgorithmSpec(
    name="fitplane",
    title="Fit a plane",
    group="LiDAR",
    group_id="lidar",
    summary="one least-squares plane through a point table",
    description="""\
Fits the plane n . p + d = 0 (unit normal, c >= 0) to the points of a CSV table (columns
x, y, z) by weighted least squares and counts the points within EPSILON of it.""",
    params=(
        Param("INPUT", "file", "Points (CSV: x, y, z)", file_filter=CSV_FILTER),
        Param("EPSILON", "number", "Inlier tolerance", _ROOF.epsilon, unit="m", minimum=0.001,
              maximum=100.0),
        Param("OUTPUT", "file_out", "Plane (CSV)", file_filter=CSV_OUT),
    ),
    results=(
        Result("RMS", "number", "RMS of the residuals (m)"),
        Result("INLIERS", "number", "Points within EPSILON"),
    ),
    references=("Pathak et al. (2010)",),
)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the points, fit the plane, write it."""
    import numpy as np
    from lidarphoto.core.geometry.planes import fit_plane
    from lidarphoto.core.io.tables import find_column, float_column, read_table, write_csv_atomic

    table = read_table(v.input)
    xyz = np.column_stack([float_column(table, find_column(table, (c,))) for c in "xyz"])
    plane = fit_plane(xyz)
    inliers = int(np.count_nonzero(np.abs(xyz @ plane.normal + plane.d) <= v.epsilon))
    write_csv_atomic(out.path("OUTPUT"), COLUMNS, [(*plane.normal, plane.d, plane.rms, inliers)])
    return JobResult(
        results={"RMS": plane.rms, "INLIERS": inliers},
        lines=[f"{len(xyz)} points, RMS {plane.rms:.4f} m, {inliers} within {v.epsilon:g} m"],
    )
