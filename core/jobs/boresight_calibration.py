"""The ``boresightcalibration`` job: read the project's files, calibrate, write the outputs.

Shared by the QGIS algorithm ``lidarphoto:boresightcalibration`` and the command line
``lidarphoto boresightcalibration`` so both accept the same inputs and write the same files:

- the results table (one row per boresight group: the angles in degrees and arc-seconds and
  their a-posteriori standard deviations in arc-seconds);
- the updated exterior orientations (the EO CSV of ``trajectorytoeo``);
- a residual table: every image observation placed at its ground position (the adjusted ray
  cut with its plane or line, or the LCP) with its pixel residual, Baarda w and rejection flag;
- the HTML summary (:mod:`core.boresight_report`), written also when the set-up is not
  observable (then it carries the diagnosis and the error is raised afterwards).
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Union

import numpy as np
from numpy.typing import NDArray

from ..errors import Cancelled, InputError
from ..geometry.camera import Camera, read_camera_json
from ..geometry.frames import LocalFrame, MappingFrame
from ..geometry.planes import read_planes_csv
from ..io.control import read_lcps_csv, read_lines_csv
from ..io.observations import ImageObservations, read_observations_csv
from ..io.tables import write_csv_atomic
from ..photo.boresight import (
    INS_GRADES,
    BoresightNotObservable,
    BoresightOptions,
    BoresightResult,
    InsGrade,
    _group_labels,
    calibrate,
)
from ..photo.georeference import Mount, parse_numbers, read_trajectory_csv
from ..photo.orientation import ExteriorOrientationTable, eo_map_to_local

__all__ = [
    "CONTROL_TYPES",
    "GROUPINGS",
    "RESIDUAL_COLUMNS",
    "TABLE_COLUMNS",
    "BoresightRun",
    "forward_intersection",
    "ground_positions",
    "parse_ins_grade",
    "run_boresight_calibration",
]

log = logging.getLogger(__name__)
Array = NDArray[np.float64]

#: Grouping choices, in the order of the QGIS enum: one set for all images; one per value of
#: the trajectory's group column (flight line, direction or session, as the user filled it);
#: one per compass octant of the INS heading.
GROUPINGS = ("single", "group", "direction")
#: Control types the adjustment can use, in the order of the QGIS enum.
CONTROL_TYPES = ("tie", "line", "lcp", "paper")
TABLE_COLUMNS = (
    "group",
    "images",
    "observations",
    "d_omega_deg",
    "d_phi_deg",
    "d_kappa_deg",
    "d_omega_arcsec",
    "d_phi_arcsec",
    "d_kappa_arcsec",
    "std_d_omega_arcsec",
    "std_d_phi_arcsec",
    "std_d_kappa_arcsec",
    "sigma0",
    "chi2_passed",
)
RESIDUAL_COLUMNS = (
    "image_id",
    "point_id",
    "type",
    "target_id",
    "group",
    "X",
    "Y",
    "Z",
    "col",
    "row",
    "vx_px",
    "vy_px",
    "v_px",
    "v_d_m",
    "w",
    "rejected",
    "used",
)


@dataclass
class BoresightRun:
    """What :func:`run_boresight_calibration` computed.

    Attributes
    ----------
    result : BoresightResult
    observations : ImageObservations
        The N observation rows, in file order.
    ground : ndarray, shape (N, 3)
        Ground position of each row in the mapping CRS (NaN where none can be computed).
    image_group : tuple of str, shape (N,)
        Boresight group of the image of each row ("" for unknown images).
    settings : dict of str to str
        The run's settings as text (also in the HTML).
    crs_wkt : str
        Mapping CRS (WKT).
    """

    result: BoresightResult
    observations: ImageObservations
    ground: Array
    image_group: tuple[str, ...]
    settings: dict[str, str] = field(default_factory=dict)
    crs_wkt: str = ""

    def residual_rows(self) -> list[tuple[object, ...]]:
        """Rows of the residual table (``RESIDUAL_COLUMNS``)."""
        r = self.result.residuals
        obs = self.observations
        v = np.hypot(r.v_px[:, 0], r.v_px[:, 1])
        return [
            (
                obs.image_id[k],
                obs.point_id[k],
                obs.type[k],
                obs.target_id[k],
                self.image_group[k],
                *self.ground[k],
                *obs.pixels[k],
                *r.v_px[k],
                v[k],
                r.v_d[k],
                r.w[k],
                int(r.rejected[k]),
                int(r.used[k]),
            )
            for k in range(len(obs))
        ]


def parse_ins_grade(grade: str, sigmas: Union[str, Sequence[float]] = "") -> InsGrade:
    """A named grade of :data:`core.boresight.INS_GRADES` or ``custom`` with four sigmas.

    ``sigmas`` for custom: horizontal and vertical position (metres), roll/pitch and heading
    (degrees), e.g. ``"0.02,0.05,0.015,0.035"``.

    >>> parse_ins_grade("custom", "0.1,0.2,0.01,0.02").sigma_vertical_m
    0.2
    """
    key = str(grade).strip().lower().replace(" ", "_")
    if key.isdigit() and int(key) <= len(INS_GRADES):
        key = ([*INS_GRADES, "custom"])[int(key)]
    if key == "custom":
        values = parse_numbers(sigmas, 4, "INS_SIGMAS")
        if not (values > 0).all():
            raise InputError(f"INS_SIGMAS must be four numbers > 0, got '{sigmas}'")
        return InsGrade("custom", *map(float, values))
    if key not in INS_GRADES:
        raise InputError(f"INS grade '{grade}' is unknown: use {', '.join(INS_GRADES)} or custom")
    return INS_GRADES[key]


def _choices(value: Union[str, Sequence[str]], options: Sequence[str], what: str) -> list[str]:
    items = value.split(",") if isinstance(value, str) else list(value)
    out = []
    for item in (str(v).strip().lower() for v in items):
        if not item:
            continue
        if item.isdigit() and int(item) < len(options):
            item = options[int(item)]
        if item not in options:
            raise InputError(f"{what}: '{item}' is not one of {', '.join(options)}")
        out.append(item)
    return out


def ground_positions(
    result: BoresightResult,
    observations: ImageObservations,
    camera: Camera,
    planes: Sequence = (),
    lines: Sequence = (),
    lcps: Sequence = (),
) -> Array:
    """Ground position of each observation row with the adjusted orientations (mapping CRS).

    ``tie`` and ``paper`` rows: the ray cut with the row's plane; ``line`` rows: the point of
    the line nearest the ray; ``lcp`` and ``check`` rows: the ray cut with the horizontal plane
    through the LCP. Rays use the calibrated interior orientation when it was estimated. Rows
    whose image or target is unknown are NaN.

    Returns
    -------
    ndarray, shape (N, 3)
    """
    local: LocalFrame = result.local
    n = len(observations)
    out = np.full((n, 3), np.nan)
    if n == 0:
        return out
    cam = camera
    if result.interior is not None:
        cam = camera.with_interior(np.concatenate([result.interior, camera.distortion.params]))
    image_of = {i: k for k, i in enumerate(result.eo.image_id)}
    img = np.array([image_of.get(i, -1) for i in observations.image_id])
    ok = img >= 0
    centres, m = eo_map_to_local(result.eo.xyz, result.eo.opk, local)
    ideal = cam.ideal_from_pixel(observations.pixels)
    ray_c = np.column_stack([ideal, np.full(n, -cam.focal_mm)])
    safe = np.where(ok, img, 0)
    c = centres[safe]
    d = np.einsum("nji,nj->ni", m[safe], ray_c)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    kinds = np.array(observations.type)
    target = np.array(observations.target_id)
    local_pts = np.full((n, 3), np.nan)

    def by_id(items) -> dict[str, int]:
        return {str(p.id): k for k, p in enumerate(items)}

    # planes: carried into the ENU frame through three of their points (exact for a plane)
    if planes:
        pid = by_id(planes)
        rows = np.flatnonzero(ok & np.isin(kinds, ("tie", "paper")) & np.isin(target, list(pid)))
        if rows.size:
            k = np.array([pid[t] for t in target[rows]])
            cen = np.array([planes[j].centroid for j in k])
            nrm = np.array([planes[j].normal for j in k])
            u = np.cross(nrm, np.where(np.abs(nrm[:, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]]))
            u /= np.linalg.norm(u, axis=1, keepdims=True)
            v = np.cross(nrm, u)
            p0, p1, p2 = (local.map_to_enu(q) for q in (cen, cen + u, cen + v))
            nl = np.cross(p1 - p0, p2 - p0)
            nl /= np.linalg.norm(nl, axis=1, keepdims=True)
            t = np.einsum("ni,ni->n", p0 - c[rows], nl) / np.einsum("ni,ni->n", d[rows], nl)
            local_pts[rows] = c[rows] + t[:, None] * d[rows]
    if lines:
        lid = by_id(lines)
        rows = np.flatnonzero(ok & (kinds == "line") & np.isin(target, list(lid)))
        if rows.size:
            k = np.array([lid[t] for t in target[rows]])
            x0 = local.map_to_enu(np.array([lines[j].point for j in k]))
            x1 = local.map_to_enu(np.array([lines[j].point + lines[j].direction for j in k]))
            u = (x1 - x0) / np.linalg.norm(x1 - x0, axis=1, keepdims=True)
            # closest point of the line to the ray: solve the 2 x 2 normal equations
            w0 = x0 - c[rows]
            b = np.einsum("ni,ni->n", u, d[rows])
            den = 1.0 - b**2
            s = (b * np.einsum("ni,ni->n", w0, d[rows]) - np.einsum("ni,ni->n", w0, u)) / np.where(
                den > 1e-12, den, np.nan
            )
            local_pts[rows] = x0 + s[:, None] * u
    if lcps:
        cid = by_id(lcps)
        rows = np.flatnonzero(ok & np.isin(kinds, ("lcp", "check")) & np.isin(target, list(cid)))
        if rows.size:
            xyz = local.map_to_enu(np.array([lcps[cid[t]].xyz for t in target[rows]]))
            t = (xyz[:, 2] - c[rows, 2]) / d[rows, 2]
            local_pts[rows] = c[rows] + t[:, None] * d[rows]
    good = np.isfinite(local_pts).all(axis=1)
    if good.any():
        out[good] = local.enu_to_map(local_pts[good])
    return out


def forward_intersection(
    observations: ImageObservations,
    eo: ExteriorOrientationTable,
    camera: Camera,
    local: LocalFrame,
    kind: str = "check",
) -> tuple[list[str], Array, NDArray[np.int64]]:
    """Intersect the rays of the rows of one type, per point id, in an ENU frame.

    Each point is the least-squares meeting point of its rays (minimum sum of squared
    perpendicular distances), solved in the adjustment frame ``local`` and returned in the
    mapping CRS. Points seen in fewer than two images are skipped.

    Returns
    -------
    ids : list of str
    xyz : ndarray, shape (K, 3)
        Mapping CRS.
    n_rays : ndarray of int, shape (K,)
    """
    sel = np.flatnonzero(np.array(observations.type) == kind)
    image_of = {i: k for k, i in enumerate(eo.image_id)}
    sel = np.array([r for r in sel if observations.image_id[r] in image_of], dtype=np.intp)
    names, inv = np.unique(np.array(observations.point_id)[sel], return_inverse=True)
    counts = np.bincount(inv, minlength=len(names))
    if sel.size == 0:
        return [], np.empty((0, 3)), np.empty(0, dtype=np.int64)
    centres, m = eo_map_to_local(eo.xyz, eo.opk, local)
    img = np.array([image_of[observations.image_id[r]] for r in sel])
    ideal = camera.ideal_from_pixel(observations.pixels[sel])
    ray_c = np.column_stack([ideal, np.full(sel.size, -camera.focal_mm)])
    d = np.einsum("nji,nj->ni", m[img], ray_c)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    proj = np.eye(3) - d[:, :, None] * d[:, None, :]  # removes the along-ray component
    a = np.zeros((len(names), 3, 3))
    b = np.zeros((len(names), 3))
    np.add.at(a, inv, proj)
    np.add.at(b, inv, np.einsum("nij,nj->ni", proj, centres[img]))
    ok = counts >= 2
    xyz = np.linalg.solve(a[ok], b[ok][:, :, None])[:, :, 0]
    return [str(v) for v in names[ok]], local.enu_to_map(xyz), counts[ok].astype(np.int64)


def run_boresight_calibration(
    camera: Union[str, Path],
    trajectory: Union[str, Path],
    crs: str,
    observations: Union[str, Path],
    *,
    lever_arm: Union[str, Sequence[float]] = "0,0,0",
    mount: str = "image_top_forward",
    mount_matrix: Union[str, Sequence[float]] = "",
    boresight: Union[str, Sequence[float]] = "0,0,0",
    planes: Union[str, Path, None] = None,
    lines: Union[str, Path, None] = None,
    lcps: Union[str, Path, None] = None,
    cloud: Union[str, Path, None] = None,
    grouping: str = "group",
    estimate_lever_arm: bool = False,
    estimate_interior: bool = False,
    ins_grade: str = "pos_av_310",
    ins_sigmas: Union[str, Sequence[float]] = "",
    control_types: Union[str, Sequence[str]] = CONTROL_TYPES,
    snooping: bool = True,
    output_table: Union[str, Path, None] = None,
    output_eo: Union[str, Path, None] = None,
    output_html: Union[str, Path, None] = None,
    residuals_csv: Union[str, Path, None] = None,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> BoresightRun:
    """Read the inputs, run :func:`core.boresight.calibrate`, write the outputs.

    Parameters
    ----------
    camera, trajectory, observations : path
        Camera JSON, trajectory CSV, image-observation CSV (``core.io.observations``).
    crs : str
        Mapping CRS of the trajectory and of the LiDAR tables (EPSG code or WKT).
    lever_arm, mount, mount_matrix, boresight
        As in ``trajectorytoeo``; ``boresight`` (degrees) is the initial value.
    planes, lines, lcps : path, optional
        Plane, line and LCP tables (``extractroofplanes`` / ``createlcps``).
    cloud : path, optional
        LAS/LAZ with a ``plane_id`` dimension: only paper mode reads it (its height z).
    grouping : str
        One of :data:`GROUPINGS` (or its index).
    estimate_lever_arm, estimate_interior, snooping : bool
    ins_grade, ins_sigmas
        See :func:`parse_ins_grade`.
    control_types : str or sequence of str
        Subset of :data:`CONTROL_TYPES` (comma list or names/indices).
    output_table, output_eo, output_html, residuals_csv : path, optional
        Files to write (atomically).
    progress, should_stop : callables, optional

    Returns
    -------
    BoresightRun

    Raises
    ------
    InputError, CrsError
        Unreadable or inconsistent inputs (naming file, row and column where it applies).
    BoresightNotObservable
        With its diagnosis; the HTML summary (if asked) is written first.
    Cancelled
    """
    frame = MappingFrame.from_user_input(crs)
    mount_ = Mount.from_user(lever_arm, mount, mount_matrix, boresight)
    grade = parse_ins_grade(ins_grade, ins_sigmas)
    group_mode = _choices(grouping, GROUPINGS, "GROUPING")
    if len(group_mode) != 1:
        raise InputError(f"GROUPING: give one of {', '.join(GROUPINGS)}")
    types = tuple(_choices(control_types, CONTROL_TYPES, "CONTROL_TYPES"))
    if not types:
        raise InputError(f"CONTROL_TYPES: choose at least one of {', '.join(CONTROL_TYPES)}")
    cam = read_camera_json(camera)
    traj = read_trajectory_csv(trajectory)
    obs = read_observations_csv(observations)
    plane_list = read_planes_csv(planes) if planes else []
    line_list = read_lines_csv(lines) if lines else []
    lcp_list = read_lcps_csv(lcps) if lcps else []
    lidar_xyz = lidar_ids = None
    if "paper" in types and "paper" in obs.type:
        if not cloud:
            raise InputError("paper-mode observations need CLOUD (LAS/LAZ with plane_id)")
        from ..io.pointcloud import read_points

        arrays, _ = read_points(
            cloud, ("x", "y", "z", "plane_id"), require_crs=False, should_stop=should_stop
        )
        lidar_xyz = np.column_stack([arrays["x"], arrays["y"], arrays["z"]])
        lidar_ids = np.asarray(arrays["plane_id"]).astype(np.int64)
    if should_stop is not None and should_stop():
        raise Cancelled("cancelled before the adjustment")
    options = BoresightOptions(
        groups=group_mode[0],
        estimate_lever_arm=bool(estimate_lever_arm),
        estimate_interior=bool(estimate_interior),
        ins_grade=grade,
        use_types=types,
        snooping=bool(snooping),
    )
    settings = {
        "camera": f"{cam.name} (f = {cam.focal_mm:g} mm, {cam.width_px} x {cam.height_px} px "
        f"of {cam.pixel_size_mm * 1000:g} um)",
        "images": str(len(traj)),
        "observations": ", ".join(
            f"{t} {n}" for t, n in zip(*np.unique(np.array(obs.type), return_counts=True))
        ),
        "planes / lines / LCPs": f"{len(plane_list)} / {len(line_list)} / {len(lcp_list)}",
        "mapping CRS": frame.crs.name,
        "grouping": group_mode[0],
        "control types used": ", ".join(types),
        "initial boresight (deg)": ", ".join(f"{np.degrees(v):.6f}" for v in mount_.boresight),
        "lever arm (m, body)": ", ".join(f"{v:.3f}" for v in mount_.lever_arm)
        + (" (estimated)" if estimate_lever_arm else " (fixed)"),
        "interior orientation": "estimated" if estimate_interior else "fixed",
        "INS grade": f"{grade.name}: position {grade.sigma_horizontal_m:g} m horizontal, "
        f"{grade.sigma_vertical_m:g} m vertical; roll/pitch {grade.sigma_roll_pitch_deg:g} deg, "
        f"heading {grade.sigma_heading_deg:g} deg",
        "data snooping": "Baarda, alpha = 0.001 per observation" if snooping else "off",
    }
    from ..quality.boresight_html import write_boresight_html

    try:
        result = calibrate(
            traj,
            cam,
            mount_,
            frame,
            obs,
            plane_list,
            line_list,
            lcp_list,
            lidar_xyz,
            lidar_ids,
            options,
            progress=progress,
            should_stop=should_stop,
        )
    except BoresightNotObservable as exc:
        if output_html:
            write_boresight_html(output_html, None, settings, diagnosis=exc.diagnosis)
        raise
    ground = ground_positions(result, obs, cam, plane_list, line_list, lcp_list)
    image_group = dict(zip(traj.image_id, _group_labels(traj, options.groups)))
    run = BoresightRun(
        result,
        obs,
        ground,
        tuple(image_group.get(i, "") for i in obs.image_id),
        settings,
        frame.crs.to_wkt(),
    )
    if output_table:
        write_csv_atomic(output_table, TABLE_COLUMNS, _table_rows(run))
        log.info("wrote %s", output_table)
    if output_eo:
        result.eo.to_csv(output_eo)
        log.info("wrote %s", output_eo)
    if residuals_csv:
        write_csv_atomic(residuals_csv, RESIDUAL_COLUMNS, [_text(r) for r in run.residual_rows()])
    if output_html:
        write_boresight_html(output_html, run, settings)
        log.info("wrote %s", output_html)
    return run


def _table_rows(run: BoresightRun) -> list[tuple[str, ...]]:
    res = run.result
    counts = {g: 0 for g in res.groups}
    images = {g: set() for g in res.groups}
    for g, used, i in zip(run.image_group, res.residuals.used, run.observations.image_id):
        if g in counts:
            counts[g] += int(used)
            images[g].add(i)
    rows = []
    for k, g in enumerate(res.groups):
        rows.append(
            _text(
                (
                    g,
                    len(images[g]),
                    counts[g],
                    *res.boresight_deg[k],
                    *res.boresight_arcsec[k],
                    *res.std_arcsec[k],
                    res.sigma0,
                    int(res.chi2_passed),
                )
            )
        )
    return rows


def _text(row) -> tuple[str, ...]:
    out = []
    for v in row:
        if isinstance(v, (float, np.floating)):
            out.append(repr(float(v)) if np.isfinite(v) else "")
        else:
            out.append(str(v))
    return tuple(out)
