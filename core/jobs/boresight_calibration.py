"""``boresightcalibration``: the camera-INS misalignment from LiDAR roof planes, lines, LCPs
and surveyed ground control points.

Outputs: the results table (one row per boresight group: the angles in degrees and
arc-seconds and their a-posteriori standard deviations in arc-seconds; with ESTIMATE_TIMING
the timing offset in ms, its sigma and correlations, :data:`TIMING_COLUMNS`); the updated exterior
orientations (the EO CSV of ``trajectorytoeo``); a residual table (every image observation
placed at its ground position, the adjusted ray cut with its plane or line, or the LCP, with
its pixel residual, Baarda w and rejection flag); the HTML summary, written also when the
set-up is not observable (then it carries the diagnosis and the error is raised afterwards).
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING

from ..i18n import joined as _joined
from ..i18n import mark as _t
from .common import (
    CSV_FILTER,
    LAS_FILTER,
    csv_out,
    doubt_params,
    global_test_verdict,
    html_out,
    mount_from,
    mount_params,
    rejection_doubts,
    settle_doubts,
)
from .runner import JobResult
from .spec import AlgorithmSpec, Fields, Param, Ref, Result, Values, options_from

#: catalogue context of the ``_t("...")`` sentences of the report (``make i18n``)
TR_CONTEXT = "Report"

if TYPE_CHECKING:
    from ..photo.boresight_result import BoresightRun

log = logging.getLogger(__name__)

#: Grouping choices: one set for all images; one per value of the trajectory's group column
#: (flight line, direction or session, as the user filled it); one per heading octant.
GROUPINGS = ("single", "group", "direction")
#: Control types the adjustment can use.
CONTROL_TYPES = ("tie", "line", "lcp", "paper", "control")
_OPTIONS = Fields("photo.boresight_options", "BoresightOptions")
_GRADES = Ref("photo.ins_grades", "INS_GRADES", convert=lambda grades: (*grades, "custom"))
_GRADE_LABELS = Ref(
    "photo.ins_grades",
    "INS_GRADES",
    convert=lambda grades: (*(g.name for g in grades.values()), "custom (INS sigmas)"),
)
#: The timing offset's columns of the results table (empty when it is not estimated): dt in
#: milliseconds (exposure = recorded time + dt), its a-posteriori sigma, and its correlations
#: with the group's boresight angles and with the lever arm (empty when that is fixed).
TIMING_COLUMNS = (
    "dt_ms",
    "std_dt_ms",
    "corr_dt_d_omega",
    "corr_dt_d_phi",
    "corr_dt_d_kappa",
    "corr_dt_lever_arm_x",
    "corr_dt_lever_arm_y",
    "corr_dt_lever_arm_z",
)
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
    *TIMING_COLUMNS,
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

#: How the images share boresights, shared with ``autoboresight``.
GROUPING_PARAM = Param(
    "GROUPING",
    "enum",
    "Boresight groups",
    _OPTIONS.groups,
    options=GROUPINGS,
    labels=(
        "one boresight for all images",
        "one per trajectory group (flight line, direction, session)",
        "one per heading direction (octant)",
    ),
    advanced=True,
)
#: The custom INS sigmas of both boresight algorithms (one definition: same label, default, range).
INS_SIGMAS_PARAM = Param(
    "INS_SIGMAS",
    "numbers",
    "Custom INS sigmas: horizontal, vertical, roll/pitch, heading",
    (0.02, 0.05, 0.015, 0.035),
    count=4,
    unit="m, m, deg, deg",
    optional=True,
    advanced=True,
    minimum=0.0001,
    maximum=100.0,
)

#: The calibration's optional unknowns and the INS grade, shared with ``autoboresight`` (the
#: same labels, defaults and help).
ESTIMATE_PARAMS: tuple[Param, ...] = (
    Param(
        "ESTIMATE_LEVER_ARM",
        "boolean",
        "Estimate the lever arm",
        _OPTIONS.estimate_lever_arm,
        advanced=True,
    ),
    Param(
        "ESTIMATE_INTERIOR",
        "boolean",
        "Estimate focal length and principal point",
        _OPTIONS.estimate_interior,
        advanced=True,
    ),
    Param(
        "ESTIMATE_TIMING",
        "boolean",
        "Estimate the camera timing offset",
        _OPTIONS.estimate_timing,
        advanced=True,
        help="a constant dt (exposure = recorded time + dt) from the trajectory's "
        "velocities (v_north, v_east, v_up columns, as Import trajectory writes them) or "
        "from neighbouring exposures of each line; with the lever arm it needs lines at "
        "clearly different speeds",
    ),
    Param(
        "INS_GRADE",
        "enum",
        "INS grade",
        _OPTIONS.ins_grade,
        options=_GRADES,
        labels=_GRADE_LABELS,
        advanced=True,
    ),
)


SPEC = AlgorithmSpec(
    name="boresightcalibration",
    title="Boresight calibration",
    group="Calibration",
    group_id="calibration",
    summary="boresight (and lever arm, interior) from LiDAR roof planes, lines and LCPs",
    description="""\
Estimates the angular misalignment (boresight) between the camera and the INS, per group of
images, from image points on roofs whose geometry comes from LiDAR: plane-constrained tie
points (a roof point in two or more images lying on its LiDAR plane), points on LiDAR
ridge/hip lines (coplanarity, one image suffices), LiDAR control points (lcp, three-plane
corners) and the single-image model of Pedrosa & dos Santos (2020) (paper, its Eqs. 12-17;
needs the cloud with plane ids). INS positions and attitudes are weighted observations (the
INS grade); optionally the lever arm and the interior orientation are estimated. The
adjustment runs in a local east-north-up frame with the rigorous navigation frame of each
image. The camera may be perspective or fisheye (equidistant, equisolid-angle, orthographic,
stereographic, Brown added, as Calibrate camera writes it): every ray and collinearity goes
through its own projection.

Inputs: camera JSON, trajectory CSV (as Trajectory to exterior orientation), the mount with
the initial boresight (degrees), the image observation CSV (image_id, point_id, col, row,
sigma_px, type, target_id), and the plane / line / LCP tables of Extract roof planes and
Create LiDAR control points and lines.

Surveyed ground control: rows of type control (as Locate control points writes them) measure
the point point_id of GROUND_POINTS (point_id, X, Y, Z, sx, sy, sz, role), used like an LCP
with the diagonal covariance of its sigmas; points of role check are left out of the
adjustment (their ground positions are in the residuals). A control row naming no ground
point is an error.

Grouping: one boresight for all images, one per value of the trajectory's group column
(flight line, direction or session) or one per heading octant.

Timing offset (ESTIMATE_TIMING): a constant camera timing offset dt (exposure = recorded
time + dt) as one more unknown, from the trajectory's velocities when the table has them
(v_north, v_east, v_up, as Import trajectory writes them), else from the neighbouring
exposures of each flight line. Estimated with the lever arm it needs lines flown at clearly
different speeds: with one speed dt times the speed is an along-track lever arm, and the run
is refused as not observable, naming both.

Outputs: the boresight per group (CSV), the updated exterior orientation (CSV), the image
residuals (a layer at each observation's ground position, and optionally CSV) and an HTML
summary; a set-up that cannot determine the boresight is an error that names the
parameters and why (the HTML then carries the diagnosis).

## Checks of the result
The run fails (nothing but the HTML summary, which says why, is written) when the
adjustment did not converge, when its global test fails with sigma0 above the largest sigma0
(the observations do not fit their sigmas), when the robust stage and data snooping rejected
more observations than their false alarms explain (the global test of the rest then says
nothing), or when an estimated angle exceeds the largest plausible boresight. With Write the
results even when the checks fail, the outputs are written and each starts with a warning (CSV:
comment lines beginning with #).""",
    params=(
        Param("CAMERA", "file", "Camera (JSON)", file_filter="JSON files (*.json)"),
        Param("TRAJECTORY", "table", "Trajectory table (CSV)", file_filter=CSV_FILTER),
        Param(
            "CRS",
            "crs",
            "Mapping CRS",
            qgis_default="ProjectCrs",
            help="projected CRS of the trajectory and of the LiDAR tables",
        ),
        *mount_params(initial_boresight=True),
        Param("OBSERVATIONS", "table", "Image observations (CSV)", file_filter=CSV_FILTER),
        Param("PLANES", "table", "Plane table (CSV)", optional=True, file_filter=CSV_FILTER),
        Param("LINES", "table", "Line table (CSV)", optional=True, file_filter=CSV_FILTER),
        Param(
            "LCPS",
            "table",
            "LiDAR control point table (CSV)",
            optional=True,
            file_filter=CSV_FILTER,
        ),
        Param(
            "GROUND_POINTS",
            "table",
            "Ground points (CSV)",
            optional=True,
            file_filter=CSV_FILTER,
            help="surveyed points of the control rows: point_id, X, Y, Z, sx, sy, sz, role "
            "(control or check), in the mapping CRS",
            advanced=True,
        ),
        Param(
            "CLOUD",
            "pointcloud",
            "Cloud with plane ids (LAS/LAZ, paper mode only)",
            optional=True,
            file_filter=LAS_FILTER,
            advanced=True,
        ),
        GROUPING_PARAM,
        Param(
            "CONTROL_TYPES",
            "enum",
            "Control types",
            _OPTIONS.use_types,
            options=CONTROL_TYPES,
            multiple=True,
            advanced=True,
        ),
        *ESTIMATE_PARAMS,
        INS_SIGMAS_PARAM,
        Param("SNOOPING", "boolean", "Data snooping (Baarda)", _OPTIONS.snooping, advanced=True),
        Param(
            "MAX_BORESIGHT",
            "number",
            "Largest plausible boresight angle",
            2.0,
            unit="degrees",
            minimum=0.001,
            maximum=45.0,
            advanced=True,
            help="an estimated angle beyond this fails the run (wrong MOUNT, image ids or "
            "observations)",
        ),
        *doubt_params(
            "a failed global test with sigma0 above this fails the run (wrong sigma_px or INS "
            "grade, or blunders data snooping did not catch)",
            "no convergence, global test beyond MAX_SIGMA0, more rejections than false alarms "
            "explain or boresight beyond MAX_BORESIGHT: "
            "write the outputs anyway, each with a warning at its top",
        ),
        csv_out("OUTPUT_TABLE", "Boresight per group (CSV)", optional=False),
        Param(
            "OUTPUT_RESIDUALS",
            "sink",
            "Image residuals",
            geometry="point",
            optional=True,
            advanced=True,
        ),
        csv_out(
            "RESIDUALS_CSV",
            "Image residuals (CSV)",
            on_demand=True,
            advanced=True,
            twin="OUTPUT_RESIDUALS",
        ),
        csv_out("OUTPUT_EO", "Updated exterior orientation (CSV)", optional=False),
        html_out("OUTPUT_HTML", "Summary (HTML)", optional=False),
    ),
    results=(
        Result("SIGMA0", "number", "Sigma0 a-posteriori"),
        Result("TIMING_OFFSET_MS", "number", "Camera timing offset dt (ms, NaN if not estimated)"),
        Result("TIMING_OFFSET_STD_MS", "number", "Sigma of the timing offset (ms)"),
    ),
    tags=("boresight", "misalignment", "ins", "imu", "calibration", "roof planes", "lever arm"),
    references=("Pedrosa & dos Santos (2020)", "Baarda (1968)"),
)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the inputs, calibrate, write the outputs."""
    from ..errors import InputError, stop_if_asked
    from ..geometry.frames import MappingFrame
    from ..photo.boresight_setup import BoresightOptions
    from ..photo.ins import ins_grade

    frame = MappingFrame.from_user_input(v.crs)
    mount = mount_from(v)
    grade = ins_grade(v.ins_grade, v.ins_sigmas)
    types = tuple(v.control_types)
    if not types:
        raise InputError(f"CONTROL_TYPES: choose at least one of {', '.join(CONTROL_TYPES)}")
    cam, traj, obs, plane_list, line_list, lcp_list, ground = _read_inputs(v, frame)
    lidar_xyz, lidar_ids = _paper_cloud(v, types, obs, should_stop)
    stop_if_asked(should_stop, "starting the adjustment")
    options = options_from(BoresightOptions, SPEC, v, ins_grade=grade, use_types=types)
    settings = _settings(
        v, cam, traj, obs, plane_list, line_list, lcp_list, frame, mount, grade, ground
    )
    args = (
        traj,
        cam,
        mount,
        frame,
        obs,
        plane_list,
        line_list,
        lcp_list,
        lidar_xyz,
        lidar_ids,
        options,
    )
    result = _calibrate(
        out, settings, args, progress=progress, should_stop=should_stop, ground_points=ground
    )
    doubts, warning = _settle(v, out, result, obs, settings, frame, options.snooping_alpha)
    run = _run_record(
        result, obs, cam, traj, options, (plane_list, line_list, lcp_list, ground), settings, frame
    )
    _write_outputs(out, run, settings, doubts, warning)
    lines = _summary_lines(result, warning, options.snooping_alpha)
    return JobResult(results=_results(result), lines=lines, data=run)


def _calibrate(out, settings: dict, args: tuple, **kwargs):
    """:func:`core.photo.boresight.calibrate` of ``args`` and ``kwargs``; when the boresight is
    not observable, the HTML page of its diagnosis (the user's answer) is written before the
    error goes on."""
    from ..io.atomic import write_text_atomic
    from ..photo.boresight import calibrate
    from ..photo.boresight_result import BoresightNotObservable
    from ..quality.boresight_html import render_boresight_html

    try:
        return calibrate(*args, **kwargs)
    except BoresightNotObservable as exc:
        if out.requested("OUTPUT_HTML"):  # the diagnosis is the user's answer: keep it
            page = render_boresight_html(None, settings, exc.diagnosis)
            write_text_atomic(out.path("OUTPUT_HTML"), page)
            out.commit(["OUTPUT_HTML"])
        raise


def _settle(v: Values, out, result, obs, settings: dict, frame, snooping_alpha: float) -> tuple:
    """The doubts about ``result`` (:func:`doubts_about`) and the warning lines when they are
    accepted; refused (the failed adjustment's page written) unless ACCEPT_DOUBTFUL."""
    import numpy as np

    from ..photo.boresight_result import BoresightRun
    from ..quality.boresight_html import render_boresight_html

    doubts = doubts_about(result, v.max_boresight, v.max_sigma0, snooping_alpha)

    def failed_page() -> str:  # the failed adjustment, without the positions it would give
        failed = BoresightRun(
            result,
            obs,
            np.full((len(obs), 3), np.nan),
            ("",) * len(obs),
            settings,
            frame.crs.to_wkt(),
        )
        return render_boresight_html(failed, settings, problems=doubts, accepted=False)

    warning = settle_doubts(
        "boresight calibration", doubts, v.accept_doubtful, out, failed_page, "HTML summary"
    )
    return doubts, warning


def _run_record(result, obs, cam, traj, options, control: tuple, settings: dict, frame):
    """The calibration's record for the outputs: the result, the observations' ground
    positions (``control``: planes, lines, LCPs, ground points) and the images' groups."""
    from ..photo.boresight_result import BoresightRun
    from ..photo.boresight_setup import group_labels
    from ..photo.intersection import ground_positions

    positions = ground_positions(result, obs, cam, *control)
    image_group = dict(zip(traj.image_id, group_labels(traj, options.groups)))
    return BoresightRun(
        result,
        obs,
        positions,
        tuple(image_group.get(i, "") for i in obs.image_id),
        settings,
        frame.crs.to_wkt(),
    )


def _results(result) -> dict[str, float]:
    """The job's numeric results: sigma0 and the timing offset in ms (NaN when fixed)."""
    dt, std = result.timing_offset, result.timing_offset_std
    nan = float("nan")
    return {
        "SIGMA0": result.sigma0,
        "TIMING_OFFSET_MS": nan if dt is None else 1e3 * dt,
        "TIMING_OFFSET_STD_MS": nan if std is None else 1e3 * std,
    }


def _read_inputs(v: Values, frame) -> tuple:
    """The camera, trajectory, observations and the control (planes, lines, LCPs, ground
    points), each checked against the mapping CRS's area of use."""

    from ..geometry.frames import check_points_in_area
    from ..geometry.projection import PROJECTIONS
    from ..io.camera import read_camera_json
    from ..io.control import read_lcps_csv, read_lines_csv
    from ..io.ground_points import read_ground_points_csv
    from ..io.observations import read_observations_csv
    from ..io.planes import read_planes_csv
    from ..io.trajectory import read_trajectory_csv

    cam = read_camera_json(v.camera, projections=PROJECTIONS)  # perspective or fisheye
    traj = read_trajectory_csv(v.trajectory)
    if not traj.geodetic:
        check_points_in_area(frame.crs, traj.position, what="the trajectory", path=v.trajectory)
    obs = read_observations_csv(v.observations, camera=cam)
    plane_list = read_planes_csv(v.planes) if v.planes else []
    line_list = read_lines_csv(v.lines) if v.lines else []
    lcp_list = read_lcps_csv(v.lcps) if v.lcps else []
    ground = read_ground_points_csv(v.ground_points) if v.ground_points else None
    for name, path, xyz in (
        ("planes", v.planes, [p.centroid for p in plane_list]),
        ("lines", v.lines, [ln.point for ln in line_list]),
        ("LCPs", v.lcps, [p.xyz for p in lcp_list]),
        ("ground points", v.ground_points, [] if ground is None else list(ground.xyz)),
    ):
        check_points_in_area(frame.crs, xyz, what=f"the {name}", path=path)
    return cam, traj, obs, plane_list, line_list, lcp_list, ground


def _paper_cloud(v: Values, types: tuple, obs, should_stop) -> tuple:
    """The LiDAR points (N, 3) and their plane ids of paper-mode observations, or (None,
    None) when none is used."""
    import numpy as np

    from ..errors import InputError
    from ..io.pointcloud import read_points

    if not ("paper" in types and "paper" in obs.type):
        return None, None
    if not v.cloud:
        raise InputError("paper-mode observations need CLOUD (LAS/LAZ with plane_id)")
    arrays, _ = read_points(
        v.cloud, ("x", "y", "z", "plane_id"), require_crs=False, should_stop=should_stop
    )
    lidar_xyz = np.column_stack([arrays["x"], arrays["y"], arrays["z"]])
    return lidar_xyz, np.asarray(arrays["plane_id"]).astype(np.int64)


def _write_outputs(out, run, settings, doubts: list, warning: list) -> None:
    """The requested outputs of the accepted calibration ``run``."""
    from ..io.atomic import write_text_atomic
    from ..io.orientation import write_eo_csv
    from ..io.tables import write_csv_atomic
    from ..quality.boresight_html import render_boresight_html

    if out.requested("OUTPUT_TABLE"):
        write_csv_atomic(out.path("OUTPUT_TABLE"), TABLE_COLUMNS, _table_rows(run), warning)
    if out.requested("OUTPUT_EO"):
        write_eo_csv(out.path("OUTPUT_EO"), run.result.eo, warning)
    if out.requested("RESIDUALS_CSV"):
        rows = [_text(r) for r in run.residual_rows()]
        write_csv_atomic(out.path("RESIDUALS_CSV"), RESIDUAL_COLUMNS, rows, warning)
    if out.requested("OUTPUT_HTML"):
        page = render_boresight_html(run, settings, problems=doubts, accepted=True)
        write_text_atomic(out.path("OUTPUT_HTML"), page)


def _summary_lines(result, warning: list, snooping_alpha: float) -> list[str]:
    """The log's summary: the angles of every group and the adjustment's figures."""
    lines = [*warning, f"{'group':8} {'angle':8} {'deg':>12} {'arcsec':>10} {'sigma':>8}"]
    for row in result.table_rows():
        lines.append(
            f"{row['group']:8} {row['parameter']:8} {row['value_deg']:12.6f} "
            f"{row['value_arcsec']:10.1f} {row['std_arcsec']:8.1f}"
        )
    if result.timing_offset is not None:
        lines.append(
            f"timing offset dt {1e3 * result.timing_offset:.2f} ms, sigma "
            f"{1e3 * result.timing_offset_std:.2f} ms (exposure = recorded time + dt)"
        )
    test = global_test_verdict(result.chi2_passed, result.adjustment, snooping_alpha)
    lines.append(
        f"sigma0 {result.sigma0:.3f}, redundancy {result.redundancy}, global test {test}, "
        f"{int(result.residuals.rejected.sum())} observations rejected"
    )
    return lines


def doubts_about(
    result, max_boresight_deg: float, max_sigma0: float, snooping_alpha: float = 0.001
) -> list[str]:
    """Why the calibration's numbers cannot be trusted (empty when they can): no convergence,
    a global test failed with sigma0 above ``max_sigma0``, more rejections than data
    snooping's false alarms at ``snooping_alpha`` explain, an angle beyond
    ``max_boresight_deg``, numbers that are not finite."""
    import numpy as np

    out = []
    adj = result.adjustment
    if not adj.converged:
        why = _joined([w for w in adj.warnings if "converg" in w or "reduced" in w], "; ")
        out.append(
            _t(
                "the adjustment did not converge after {n} iterations ({why})",
                n=adj.iterations,
                why=why,
            )
            if why
            else _t("the adjustment did not converge after {n} iterations", n=adj.iterations)
        )
    if not result.chi2_passed and result.sigma0 > max_sigma0:
        out.append(
            _t(
                "the global test failed with sigma0 = {sigma0:.3g} > MAX_SIGMA0 {maximum:g}: "
                "the observations are {sigma0:.3g} times less precise than their sigmas say "
                "(wrong sigma_px or INS grade, or undetected blunders)",
                sigma0=result.sigma0,
                maximum=max_sigma0,
            )
        )
    out.extend(t.message() for t in rejection_doubts(adj, snooping_alpha))
    deg = result.boresight_deg
    large, nonfinite = [], []
    for g, name in enumerate(result.groups):
        for k, angle in enumerate(("d_omega", "d_phi", "d_kappa")):
            value = float(deg[g, k])
            if not np.isfinite(value) or not np.isfinite(result.std[g, k]):
                nonfinite.append(_t("{angle} of group {group}", angle=angle, group=name))
            elif abs(value) > max_boresight_deg:
                large.append(
                    _t(
                        "{angle} = {value:.4f} deg in group {group}",
                        angle=angle,
                        value=value,
                        group=name,
                    )
                )
    if nonfinite:
        out.append(_t("not a finite number: {items}", items=_joined(nonfinite)))
    if large:
        out.append(
            _t(
                "{items} beyond MAX_BORESIGHT {maximum:g} deg: implausible for a misalignment "
                "(wrong MOUNT, image ids or observations?)",
                items=_joined(large),
                maximum=max_boresight_deg,
            )
        )
    return out


def _settings(
    v, cam, traj, obs, planes, lines, lcps, frame, mount, grade, ground=None
) -> dict[str, str]:
    """The run's settings as text (the HTML summary shows them)."""
    import numpy as np

    types = tuple(v.control_types)
    return {
        "camera": f"{cam.name} (f = {cam.focal_mm:g} mm, {cam.width_px} x {cam.height_px} px "
        f"of {cam.pixel_size_mm * 1000:g} um, {cam.projection} projection)",
        "images": str(len(traj)),
        "observations": ", ".join(
            f"{t} {n}" for t, n in zip(*np.unique(np.array(obs.type), return_counts=True))
        ),
        "planes / lines / LCPs": f"{len(planes)} / {len(lines)} / {len(lcps)}",
        **(
            {}
            if ground is None
            else {
                "ground points (control / check)": (
                    f"{ground.role.count('control')} / {ground.role.count('check')}"
                )
            }
        ),
        "mapping CRS": frame.crs.name,
        "grouping": v.grouping,
        "control types used": ", ".join(types),
        "initial boresight (deg)": ", ".join(f"{np.degrees(a):.6f}" for a in mount.boresight),
        "lever arm (m, body)": ", ".join(f"{a:.3f}" for a in mount.lever_arm)
        + (" (estimated)" if v.estimate_lever_arm else " (fixed)"),
        "interior orientation": "estimated" if v.estimate_interior else "fixed",
        "camera timing offset": (
            "fixed (0)"
            if not v.estimate_timing
            else "estimated, velocities from the trajectory"
            if traj.velocity_ned is not None
            else "estimated, velocities from neighbouring exposures"
        ),
        "INS grade": f"{grade.name}: position {grade.sigma_horizontal_m:g} m horizontal, "
        f"{grade.sigma_vertical_m:g} m vertical; roll/pitch {grade.sigma_roll_pitch_deg:g} deg, "
        f"heading {grade.sigma_heading_deg:g} deg",
        "data snooping": "Baarda, alpha = 0.001 per observation" if v.snooping else "off",
    }


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
                    *_timing_cells(res, g),
                )
            )
        )
    return rows


def _timing_cells(res, group: str) -> tuple:
    """The :data:`TIMING_COLUMNS` of one group's row ("" where not estimated)."""
    if res.timing_offset is None:
        return ("",) * len(TIMING_COLUMNS)
    names = res.parameter_names
    at = names.index("timing.dt")
    others = [f"bore[{group}].{a}" for a in ("d_omega", "d_phi", "d_kappa")]
    others += [f"lever_arm.{a}" for a in "xyz"]
    corr = [float(res.correlation[at, names.index(n)]) if n in names else "" for n in others]
    return (1e3 * res.timing_offset, 1e3 * res.timing_offset_std, *corr)


def _text(row) -> tuple[str, ...]:
    import numpy as np

    out = []
    for v in row:
        if isinstance(v, (float, np.floating)):
            out.append(repr(float(v)) if np.isfinite(v) else "")
        else:
            out.append(str(v))
    return tuple(out)
