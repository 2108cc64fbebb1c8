"""``monoplot``: 3D points and lines from one oriented image and a LiDAR DSM."""

from __future__ import annotations

import logging

from .checks import DSM_BYTES_PER_CELL, check_cell_size, check_memory
from .common import (
    DSM_FILTER,
    camera_param,
    choice_param,
    csv_out,
    dsm_cell_param,
    eo_param,
    table_param,
)
from .runner import JobResult, stages
from .spec import AlgorithmSpec, Param, Ref, Result, Values

log = logging.getLogger(__name__)

#: Bytes per monoplotted ray: its point, 3 x 3 covariance, pixel, status, the row of text
#: and the intermediate arrays of the intersection (a generous round figure).
BYTES_PER_RAY = 1000

SPEC = AlgorithmSpec(
    name="monoplot",
    title="Monoplot image points and lines on a LiDAR DSM",
    group="Orthophotos",
    group_id="orthophotos",
    summary="3D points and lines from one oriented image and a LiDAR DSM",
    description="""\
Monoplotting (dos Santos, Dal Poz & Dalmolin 2010): the ray of each image point is
intersected with the LiDAR surface. The camera may be perspective or fisheye (equidistant,
equisolid-angle, orthographic, stereographic, with its Brown correction): the ray is the
one of the camera's own projection. Direct (Dal Poz 1991): the ray walks the DSM's cells in
order from the camera and meets the two triangles of each cell in the determinant form of
Eqs. 6-10; the first face hit is the visible point (occlusion). Makarovic: the classical
iteration height -> position -> height.

Observations: the image-observation CSV of the picking dock (image_id, point_id, col, row,
sigma_px, type, target_id). Rows of type line with the same image and target_id form one 3D
line (vertices in file order; line step adds points every so many pixels along it); other
rows are points (their target_id is not used). With a plane table, rows of type tie or paper
are intersected with their roof plane (target_id) instead.

DSM: a raster, or a LAS/LAZ rasterised at cell size (highest return per cell, gaps filled;
optionally saved). A DSM in another CRS than the mapping CRS of the exterior orientation is
resampled into it, heights transformed too (DSM CRS supplies the CRS when the file has none,
or replaces it); when PROJ lacks a grid for that (e.g. a geoid), the run is refused: install
the grid, or give the DSM's CRS with ellipsoidal heights as DSM CRS.

Each point carries a 3x3 covariance from the image sigma, the EO sigmas (X, Y, Z in m;
omega, phi, kappa in degrees) and the DSM height sigma, and a status: ok, grazing (ray meets
the face at less than the minimum angle), outside (the ray leaves the DSM), nodata (it crosses
a hole first), no_orientation (image not in the EO table), not_converged (Makarovic),
parallel / unknown_plane (planes), out_of_field (the point lies beyond a fisheye
projection's field: no ray).""",
    params=(
        table_param("OBSERVATIONS", "Image observations (CSV)"),
        camera_param(),
        eo_param(),
        Param(
            "DSM",
            "surface",
            "DSM (raster, or LAS/LAZ)",
            file_filter=DSM_FILTER,
        ),
        table_param("PLANES", "Roof plane table (CSV)", optional=True),
        Param("CRS", "crs", "Mapping CRS of the EO", help="e.g. EPSG:28992"),
        Param(
            "DSM_CRS",
            "crs",
            "DSM CRS (overrides the file's)",
            optional=True,
            help="the DSM's CRS when the file has none or a wrong one; a 2D CRS takes the "
            "heights as ellipsoidal",
            advanced=True,
        ),
        choice_param(
            "METHOD",
            "Method",
            "photo.monoplot_options",
            "METHODS",
            labels=("direct (Dal Poz, DDA)", "Makarovic iteration"),
        ),
        dsm_cell_param(advanced=True),
        Param(
            "SIGMA_DSM",
            "number",
            "DSM height sigma",
            0.10,
            unit="m",
            minimum=0.0,
            maximum=100.0,
            advanced=True,
        ),
        Param(
            "LINE_STEP",
            "number",
            "Points along lines every (0 = end points)",
            0.0,
            unit="pixels",
            minimum=0.0,
            maximum=1e6,
            advanced=True,
        ),
        Param(
            "MIN_INCIDENCE",
            "number",
            "Minimum angle ray / face",
            5.0,
            unit="degrees",
            minimum=0.0,
            maximum=90.0,
            advanced=True,
        ),
        Param(
            "EO_SIGMAS",
            "numbers",
            "EO sigmas: X, Y, Z, omega, phi, kappa",
            Ref("photo.monoplot_options", "DEFAULT_EO_SIGMAS"),
            count=6,
            unit="m, degrees",
            minimum=0.0,
            maximum=100.0,
            advanced=True,
        ),
        Param("OUTPUT_POINTS", "sink", "Monoplotted points", geometry="point", optional=True),
        Param("OUTPUT_LINES", "sink", "Monoplotted lines", geometry="line", optional=True),
        csv_out("OUTPUT_CSV", "Point table (CSV)", on_demand=True, twin="OUTPUT_POINTS"),
        csv_out("LINES_CSV", "Line table", on_demand=True),
        Param(
            "OUTPUT_DSM",
            "raster_out",
            "DSM made from the LAS/LAZ",
            optional=True,
            create_by_default=False,
            advanced=True,
        ),
    ),
    results=(
        Result("POINT_COUNT", "number", "Rays monoplotted"),
        Result("HIT_COUNT", "number", "Rays with a 3D point"),
    ),
    tags=("monoplotting", "monorestitution", "dsm", "dal poz", "makarovic", "3d lines"),
    references=("dos Santos, Dal Poz & Dalmolin (2010)", "Dal Poz (1991)", "Makarovic (1973)"),
)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the observations, camera, EO, DSM (and planes), monoplot, write the tables."""
    from ..photo.monoplot import monoplot

    camera, obs, eo, planes = _read_inputs(v)
    load, compute = stages(progress, 0.4, 0.6)
    dsm = _load_dsm(v, load, should_stop)
    result = monoplot(
        obs,
        camera,
        eo,
        dsm,
        v.crs,
        method=v.method,
        sigma_dsm=v.sigma_dsm,
        eo_sigmas=v.eo_sigmas,
        planes=planes,
        line_step_px=v.line_step,
        min_incidence_deg=v.min_incidence,
        progress=compute,
        should_stop=should_stop,
    )
    _write_tables(out, result)
    hits = int(sum(int(s) in (0, 1) for s in result.status))
    return JobResult(
        results={"POINT_COUNT": len(result.rows), "HIT_COUNT": hits},
        lines=[f"{len(result.rows)} rays, {len(result.lines)} lines: {result.status_counts()}"],
        data=result,
    )


def _read_inputs(v: Values) -> tuple:
    """(camera, observations, EO, planes), the perspective centres checked against the CRS's
    area of use and the rays' memory against what is free."""
    from ..geometry.frames import check_points_in_area, parse_crs
    from ..geometry.projection import PROJECTIONS
    from ..io.camera import read_camera_json
    from ..io.observations import read_observations_csv
    from ..io.orientation import read_eo_csv
    from ..io.planes import read_planes_csv

    camera = read_camera_json(v.camera, projections=PROJECTIONS)  # perspective or fisheye
    obs = read_observations_csv(v.observations, camera=camera)
    eo = read_eo_csv(v.eo)
    check_points_in_area(
        parse_crs(v.crs, what="CRS"), eo.xyz, what="the perspective centres", path=v.eo
    )
    planes = read_planes_csv(v.planes) if v.planes else ()
    rays = ray_count(obs, v.line_step)
    check_memory(
        rays * BYTES_PER_RAY,
        f"LINE_STEP {v.line_step:g} px: {rays} rays",
        "give a larger step (or 0: the end points only)",
    )
    return camera, obs, eo, planes


def _load_dsm(v: Values, progress, should_stop):
    """The DSM of the DSM parameter (a raster, or a cloud gridded at CELL_SIZE), its size
    checked against the memory that is free (before and after reading)."""
    from pathlib import Path

    from ..io.dsm import CLOUD_SUFFIXES, load_dsm
    from ..io.pointcloud import read_info

    if Path(v.dsm).suffix.lower() in CLOUD_SUFFIXES:
        info = read_info(v.dsm, v.dsm_crs, require_crs=False)
        unit = info.horizontal_unit if info.crs is not None else "CRS unit"
        check_cell_size(
            "CELL_SIZE",
            v.cell_size,
            unit,
            info.mins[:2],
            info.maxs[:2],
            DSM_BYTES_PER_CELL,
            extra_bytes=40.0 * info.point_count,
        )
    dsm = load_dsm(v.dsm, v.cell_size, v.dsm_crs, progress=progress, should_stop=should_stop)
    rows, cols = dsm.heights.shape
    check_memory(
        float(rows) * cols * DSM_BYTES_PER_CELL,
        f"the DSM of {rows} x {cols} cells ({v.dsm})",
        "give a coarser DSM",
    )
    return dsm


def _write_tables(out, result) -> None:
    """The requested outputs: the DSM used, the points and the lines."""
    from ..io.dsm import write_dsm
    from ..io.monoplot import write_monoplot_lines_csv, write_monoplot_points_csv

    if out.requested("OUTPUT_DSM"):
        write_dsm(out.path("OUTPUT_DSM"), result.dsm)
    if out.requested("OUTPUT_CSV"):
        write_monoplot_points_csv(out.path("OUTPUT_CSV"), result)
    if out.requested("LINES_CSV"):
        write_monoplot_lines_csv(out.path("LINES_CSV"), result)


def ray_count(obs, line_step_px: float) -> int:
    """How many rays :func:`~lidarphoto.core.photo.monoplot.monoplot` will cast: one per
    observation row plus, with ``line_step_px > 0``, the points added along each line."""
    import numpy as np

    total = len(obs)
    if line_step_px <= 0:
        return total
    lines: dict[tuple[str, str], list[int]] = {}
    for k, (img, kind, tgt) in enumerate(zip(obs.image_id, obs.type, obs.target_id)):
        if kind == "line":
            lines.setdefault((img, tgt), []).append(k)
    for rows in lines.values():
        px = obs.pixels[rows]
        length = np.linalg.norm(np.diff(px, axis=0), axis=1)
        total += int(np.sum(np.maximum(np.ceil(length / line_step_px) - 1, 0)))
    return total
