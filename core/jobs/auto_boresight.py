"""``autoboresight``: the boresight calibrated without hand picks, from image edges along the
projected LiDAR lines and tie tracks on LiDAR roof planes (issue 32).

Outputs: those of ``boresightcalibration`` (the boresight per group, the updated EO, the HTML
summary), the observations it found (the image-observation CSV, which ``boresightcalibration``
reads) and a table of the rounds (search width, tie gate, observation counts, ties refused per
reason, the boresight and its change).
"""

from __future__ import annotations

import logging

from ..io.suffixes import IMAGE_SUFFIXES
from .boresight_calibration import ESTIMATE_PARAMS, GROUPING_PARAM, INS_SIGMAS_PARAM
from .common import (
    CSV_FILTER,
    CSV_OUT,
    LAS_FILTER,
    doubt_params,
    mount_from,
    mount_params,
    settle_doubts,
)
from .runner import JobResult, stages
from .spec import AlgorithmSpec, Fields, Param, Result, Values, options_from

log = logging.getLogger(__name__)

_AUTO = Fields("photo.auto_boresight_options", "AutoBoresightOptions")
_OPTIONS = Fields("photo.boresight_options", "BoresightOptions")
#: Columns of the rounds table (OUTPUT_ROUNDS).
ROUND_COLUMNS = (
    "round",
    "search_px",
    "gate_m",
    "line_points",
    "lines_seen",
    "tie_tracks",
    "ties_associated",
    "ties_refused",
    "group",
    "d_omega_deg",
    "d_phi_deg",
    "d_kappa_deg",
    "std_d_omega_arcsec",
    "std_d_phi_arcsec",
    "std_d_kappa_arcsec",
    "change_d_omega_arcsec",
    "change_d_phi_arcsec",
    "change_d_kappa_arcsec",
    "rejected",
    "line_sigma_scale",
    "segment_offset_sigma_px",
    "segment_tilt_sigma_px",
)

SPEC = AlgorithmSpec(
    name="autoboresight",
    title="Automatic boresight calibration",
    group="Calibration",
    group_id="calibration",
    summary="boresight without hand picks: image edges along LiDAR lines, ties on roof planes",
    description="""\
Calibrates the camera-INS boresight from the images themselves, with no picked point. The
LiDAR ridge, hip and valley lines (the line table of Create LiDAR control points and lines)
are projected into every image with the trajectory, the mount and the approximate boresight.
First an angle search (coarse to fine, within Search range of the approximate boresight)
finds the boresight whose projected lines lie on the strongest image edges; then, in rounds,
sub-pixel image edges are found along every projected line (the dock's edge refinement, within
3 sigma of the projection's uncertainty) and each tie track (found between the images by
the chain of Automatic tie points, pairs from the footprints and least-squares refinement on,
or its observation CSV given as Tie points) is intersected and kept as a point-to-plane tie of
the roof plane it lies on (inside the plane's outline, from the cloud's plane ids; off the
borders; within a gate of 3 sigma of the pose and intersection uncertainty; not on a wall).
Each round runs the rigorous calibration of Boresight calibration (line and tie models,
INS priors, data snooping) and starts the next from its result, until every angle changes
by less than its standard deviation.

A scene with no sloped roof plane and fewer than two LiDAR line directions (flat ground,
flat roofs) is refused: the angles are not observable there.

Outputs: the boresight per group and the updated exterior orientation (as Boresight
calibration), the observations found (image-observation CSV: Boresight calibration reads it
again, e.g. to compare with hand picks), the rounds (CSV) and the HTML summary, whose settings
give the counts per round and the ties refused per reason.""",
    params=(
        Param(
            "IMAGES",
            "files",
            "Images (files or folders)",
            suffixes=IMAGE_SUFFIXES,
            help="the image id is the file name without extension, as in the trajectory",
        ),
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
        Param("LINES", "table", "Line table (CSV)", file_filter=CSV_FILTER),
        Param(
            "PLANES",
            "table",
            "Plane table (CSV)",
            optional=True,
            file_filter=CSV_FILTER,
            help="the roof planes of the tie points and of the observability check",
        ),
        Param(
            "CLOUD",
            "pointcloud",
            "Cloud with plane ids (LAS/LAZ)",
            optional=True,
            file_filter=LAS_FILTER,
            advanced=True,
            help="the planes' outlines (convex hull of their points): needed by tie points",
        ),
        Param(
            "TIE_POINTS",
            "table",
            "Tie points (observation CSV)",
            optional=True,
            file_filter=CSV_FILTER,
            advanced=True,
            help="the output of Automatic tie points",
        ),
        Param(
            "FIND_TIES",
            "boolean",
            "Find tie points when none are given",
            _AUTO.find_ties,
            advanced=True,
            help="without TIE_POINTS, and with PLANES and CLOUD, run Automatic tie points "
            "on the images (pairs from the footprints, least-squares refinement on)",
        ),
        Param(
            "HAND_PICKS",
            "table",
            "Hand picks to compare with (observation CSV)",
            optional=True,
            file_filter=CSV_FILTER,
            advanced=True,
            help="observations picked in the dock: their tie and line rows are calibrated "
            "alone and the summary compares the two boresights",
        ),
        Param(
            "SEARCH",
            "number",
            "Search range of the boresight",
            _AUTO.search_deg,
            unit="degrees",
            minimum=0.0,
            maximum=10.0,
            advanced=True,
            help="half width of the angle search about BORESIGHT (0: none)",
        ),
        Param(
            "MAX_ROUNDS",
            "integer",
            "Most rounds",
            _AUTO.max_rounds,
            minimum=1,
            maximum=50,
            advanced=True,
        ),
        GROUPING_PARAM,
        *ESTIMATE_PARAMS,
        INS_SIGMAS_PARAM,
        Param(
            "MAX_BORESIGHT",
            "number",
            "Largest plausible boresight angle",
            2.0,
            unit="degrees",
            minimum=0.001,
            maximum=45.0,
            advanced=True,
            help="an estimated angle beyond this fails the run",
        ),
        *doubt_params(
            "a failed global test with sigma0 above this fails the run",
            "no convergence, global test beyond MAX_SIGMA0, more rejections than false alarms "
            "explain or boresight beyond MAX_BORESIGHT: write the outputs anyway, each with a "
            "warning at its top",
        ),
        Param("OUTPUT_TABLE", "file_out", "Boresight per group (CSV)", file_filter=CSV_OUT),
        Param("OUTPUT_EO", "file_out", "Updated exterior orientation (CSV)", file_filter=CSV_OUT),
        Param("OUTPUT_OBSERVATIONS", "file_out", "Observations found (CSV)", file_filter=CSV_OUT),
        Param(
            "OUTPUT_ROUNDS",
            "file_out",
            "Rounds (CSV)",
            optional=True,
            file_filter=CSV_OUT,
            advanced=True,
        ),
        Param("OUTPUT_HTML", "file_out", "Summary (HTML)", file_filter="HTML files (*.html)"),
    ),
    results=(
        Result("SIGMA0", "number", "Sigma0 a-posteriori"),
        Result("ROUNDS", "number", "Rounds"),
        Result("LINE_POINTS", "number", "Line observations"),
        Result("TIES_ASSOCIATED", "number", "Tie points on roof planes"),
    ),
    tags=("boresight", "automatic", "calibration", "lidar lines", "roof planes", "tie points"),
    references=("Pedrosa & dos Santos (2020)", "Baarda (1968)"),
)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the inputs, calibrate automatically, write the outputs."""
    from ..geometry.frames import MappingFrame
    from ..photo.auto_boresight import auto_calibrate
    from ..photo.auto_boresight_options import AutoBoresightOptions
    from ..photo.boresight_setup import BoresightOptions
    from ..photo.ins import ins_grade
    from .boresight_calibration import doubts_about

    frame = MappingFrame.from_user_input(v.crs)
    mount = mount_from(v)
    grade = ins_grade(v.ins_grade, v.ins_sigmas)
    cam, traj, planes, lines, ties = _read_inputs(v)
    images = _read_images(v, traj, should_stop)
    auto = options_from(AutoBoresightOptions, SPEC, v)
    cal = options_from(BoresightOptions, SPEC, v, ins_grade=grade)
    ties, detected, rest = _tie_stage(
        v, auto, ties, images, cam, traj, mount, frame, planes, progress, should_stop
    )
    args = (traj, cam, mount, frame, images, planes, lines, ties, None, auto, cal)
    found = auto_calibrate(*args, progress=rest, should_stop=should_stop)
    result = found.result
    doubts = doubts_about(result, v.max_boresight, v.max_sigma0, cal.snooping_alpha)
    run_ = _boresight_run(found, cam, traj, planes, lines, frame, cal)
    settings = _settings(v, cam, traj, found, frame, grade, detected)
    if v.hand_picks:
        settings.update(
            _compare_hand_picks(v, cam, traj, mount, frame, planes, lines, cal, result, should_stop)
        )

    def failed_page() -> str:
        from ..quality.boresight_html import render_boresight_html

        return render_boresight_html(run_, settings, problems=doubts, accepted=False)

    what = "automatic boresight calibration"
    warning = settle_doubts(what, doubts, v.accept_doubtful, out, failed_page, "HTML summary")
    _write_outputs(out, found, run_, settings, doubts, warning)
    lines_out = [*warning, *_summary_lines(found)]
    for line in lines_out:
        log.info("%s", line)
    last = found.rounds[-1]
    return JobResult(
        results={
            "SIGMA0": found.result.sigma0,
            "ROUNDS": len(found.rounds),
            "LINE_POINTS": last.line_points,
            "TIES_ASSOCIATED": last.ties_associated,
        },
        lines=lines_out,
        data=found,
    )


def _summary_lines(found) -> list[str]:
    """The rounds, the boresight per group and the convergence, one line each."""
    return [
        *(
            f"round {r.round}: {r.line_points} line points on {r.lines_seen} lines, "
            f"{r.ties_associated} of {r.tie_tracks} tie tracks on planes, search {r.search_px:.1f}"
            f" px, gate {r.gate_m:.3f} m"
            for r in found.rounds
        ),
        *(
            f"{row['group']:8} {row['parameter']:8} {row['value_deg']:12.6f} deg "
            f"+- {row['std_arcsec']:.1f} arcsec"
            for row in found.result.table_rows()
        ),
        "converged" if found.converged else f"not converged after {len(found.rounds)} rounds",
    ]


def _read_inputs(v: Values) -> tuple:
    """The camera, trajectory, planes (with outlines from the cloud), lines and tie points."""
    import numpy as np

    from ..errors import InputError
    from ..io.camera import read_camera_json
    from ..io.control import read_lines_csv
    from ..io.observations import read_observations_csv
    from ..io.planes import read_planes_csv
    from ..io.pointcloud import read_points
    from ..io.trajectory import read_trajectory_csv
    from ..photo.auto_ties import outlines_from_points

    cam = read_camera_json(v.camera)
    traj = read_trajectory_csv(v.trajectory)
    lines = read_lines_csv(v.lines)
    planes = read_planes_csv(v.planes) if v.planes else []
    if v.cloud and planes:
        arrays, _ = read_points(v.cloud, ("x", "y", "z", "plane_id"), require_crs=False)
        xyz = np.column_stack([arrays["x"], arrays["y"], arrays["z"]])
        planes = outlines_from_points(planes, xyz, np.asarray(arrays["plane_id"]))
    ties = None
    if v.tie_points:
        if not planes or not v.cloud:
            raise InputError("TIE_POINTS need PLANES and CLOUD (the planes' outlines)")
        ties = read_observations_csv(v.tie_points, camera=cam)
    return cam, traj, planes, lines, ties


def _read_images(v: Values, traj, should_stop=None) -> list:
    """(image id, 8-bit grey image) of the IMAGES named in the trajectory; ``should_stop``
    asked before each image is read (cancellation)."""
    from ..errors import InputError, stop_if_asked
    from ..io.images import list_image_files, read_gray

    files = list_image_files(v.images, ("IMAGES", "identical images have no parallax"))
    known = set(traj.image_id)
    images = []
    for f in files:
        if f.stem in known:
            stop_if_asked(should_stop, f"reading the images ({f.name})")
            images.append((f.stem, read_gray(f)))
    if not images:
        raise InputError(
            "IMAGES: no image is named in the trajectory (image id = file name without extension)",
            path=v.trajectory,
        )
    return images


def _tie_stage(
    v, auto, ties, images, cam, traj, mount, frame, planes, progress, should_stop
) -> tuple:
    """(the tie points, the summary's line on those found or None, the calibration's share
    of the progress): TIE_POINTS when given, else those found between the images (FIND_TIES,
    with CLOUD: the planes' outlines), else None."""
    find = (
        ties is None
        and auto.find_ties
        and bool(v.cloud)
        and any(len(p.outline) >= 3 for p in planes)
    )
    tie_progress, rest = stages(progress, 0.4 if find else 0.0, 1.0)
    detected = None
    if find:
        ties, detected = _find_ties(
            images, cam, traj, mount, frame, planes, auto.ties, tie_progress, should_stop
        )
    return ties, detected, rest


def _find_ties(images, cam, traj, mount, frame, planes, options, progress, should_stop) -> tuple:
    """Tie tracks found between the images read (FIND_TIES): the observations and a line of
    counts for the summary. Pairs from the footprints of the approximate orientation at the
    planes' median height."""
    import numpy as np

    from ..errors import InputError
    from ..photo.auto_ties import find_ties
    from ..photo.georeference import direct_georeference

    if len(images) < 2:
        raise InputError(
            "IMAGES: finding tie points needs at least two images (or give TIE_POINTS)"
        )
    eo = direct_georeference(traj, mount, frame)
    height = float(np.median([p.centroid[2] for p in planes]))
    res = find_ties(images, cam, eo, height, options, progress=progress, should_stop=should_stop)
    s = res.summary()
    text = (
        f"{s['tracks']} tracks, {s['measurements']} measurements; pairs "
        f"{s['pairs_kept']} of {s['pairs_tried']} kept"
    )
    log.info("tie points found: %s", text)
    return res.observations(), text


def _boresight_run(found, cam, traj, planes, lines, frame, cal):
    """The :class:`BoresightRun` of the last round (residuals at their ground positions)."""
    from ..photo.boresight_result import BoresightRun
    from ..photo.boresight_setup import group_labels
    from ..photo.intersection import ground_positions

    obs = found.observations
    positions = ground_positions(found.result, obs, cam, planes, lines, [], None)
    image_group = dict(zip(traj.image_id, group_labels(traj, cal.groups)))
    return BoresightRun(
        found.result,
        obs,
        positions,
        tuple(image_group.get(i, "") for i in obs.image_id),
        {},
        frame.crs.to_wkt(),
    )


def _settings(v, cam, traj, found, frame, grade, detected) -> dict[str, str]:
    """The run's settings and counts as text (the HTML summary shows them)."""
    import numpy as np

    s = {
        "camera": f"{cam.name} (f = {cam.focal_mm:g} mm, {cam.width_px} x {cam.height_px} px)",
        "images": str(len(traj)),
        "mapping CRS": frame.crs.name,
        "INS grade": grade.name,
        "initial boresight (deg)": ", ".join(f"{a:g}" for a in v.boresight),
        "boresight after the angle search (deg)": ", ".join(
            f"{np.degrees(a):.4f}" for a in found.searched
        ),
        "converged": "yes" if found.converged else "no",
    }
    for r in found.rounds:
        refused = ", ".join(f"{k} {n}" for k, n in r.ties_refused.items() if n) or "none"
        s[f"round {r.round}"] = (
            f"search {r.search_px:.1f} px, gate {r.gate_m:.3f} m; {r.line_points} line points "
            f"on {r.lines_seen} lines; tie tracks {r.tie_tracks}, on planes {r.ties_associated}"
            f", refused: {refused}; rejected by the adjustment {r.rejected}"
        )
        if r.weights is not None:
            s[f"round {r.round}"] += (
                "; line points' sigma x {:.3f}, segment offset / tilt sigma {:.3f} / {:.3f} px"
            ).format(*r.weights)
    if detected is not None:
        s["tie points found"] = detected
    s["line points per image"] = ", ".join(f"{k} {n}" for k, n in found.per_image.items())
    s["tie measurements per plane"] = (
        ", ".join(f"{k} {n}" for k, n in found.per_plane.items()) or "none"
    )
    return s


def _compare_hand_picks(
    v, cam, traj, mount, frame, planes, lines, cal, result, should_stop
) -> dict[str, str]:
    """The calibration from the hand picks' tie and line rows, and its difference from the
    automatic one per group (arc-seconds, and in sigmas of the difference, the two taken as
    independent: an upper bound, both share the INS priors)."""
    from dataclasses import replace

    import numpy as np

    from ..io.observations import read_observations_csv
    from ..photo.boresight import calibrate

    picks = read_observations_csv(v.hand_picks, camera=cam)
    hand = calibrate(
        traj,
        cam,
        mount,
        frame,
        picks,
        planes,
        lines,
        options=replace(cal, use_types=("tie", "line")),
        should_stop=should_stop,
    )
    out = {}
    arcsec = 3600.0 * 180.0 / np.pi
    for g, name in enumerate(result.groups):
        if name not in hand.groups:
            continue
        h = hand.groups.index(name)
        diff = (result.boresight[g] - hand.boresight[h]) * arcsec
        both = np.hypot(result.std[g], hand.std[h]) * arcsec
        out[f"hand picks, group {name}"] = (
            f"{sum(t in ('tie', 'line') for t in picks.type)} rows; boresight "
            + ", ".join(f"{np.degrees(a):.5f}" for a in hand.boresight[h])
            + " deg, sigmas "
            + ", ".join(f"{a * arcsec:.1f}" for a in hand.std[h])
            + " arcsec; automatic minus "
            "hand "
            + ", ".join(f"{d:.1f}" for d in diff)
            + " arcsec ("
            + ", ".join(f"{d / b:.1f}" for d, b in zip(diff, both))
            + " sigma)"
        )
    return out


def _round_rows(found) -> list[tuple[str, ...]]:
    import numpy as np

    from .boresight_calibration import _text

    rows = []
    for r in found.rounds:
        refused = "; ".join(f"{k}: {n}" for k, n in r.ties_refused.items() if n)
        for g, name in enumerate(found.result.groups):
            rows.append(
                _text(
                    (
                        r.round,
                        r.search_px,
                        r.gate_m,
                        r.line_points,
                        r.lines_seen,
                        r.tie_tracks,
                        r.ties_associated,
                        refused,
                        name,
                        *np.degrees(r.boresight[g]),
                        *np.degrees(r.std[g]) * 3600,
                        *np.degrees(r.change[g]) * 3600,
                        r.rejected,
                        *(r.weights if r.weights is not None else ("", "", "")),
                    )
                )
            )
    return rows


def _write_outputs(out, found, run_, settings, doubts, warning) -> None:
    from ..io.atomic import write_text_atomic
    from ..io.observations import write_observations_csv
    from ..io.orientation import write_eo_csv
    from ..io.tables import write_csv_atomic
    from ..quality.boresight_html import render_boresight_html
    from .boresight_calibration import TABLE_COLUMNS, _table_rows

    if out.requested("OUTPUT_TABLE"):
        write_csv_atomic(out.path("OUTPUT_TABLE"), TABLE_COLUMNS, _table_rows(run_), warning)
    if out.requested("OUTPUT_EO"):
        write_eo_csv(out.path("OUTPUT_EO"), found.result.eo, warning)
    if out.requested("OUTPUT_OBSERVATIONS"):
        write_observations_csv(out.path("OUTPUT_OBSERVATIONS"), found.observations)
    if out.requested("OUTPUT_ROUNDS"):
        write_csv_atomic(out.path("OUTPUT_ROUNDS"), ROUND_COLUMNS, _round_rows(found), warning)
    if out.requested("OUTPUT_HTML"):
        page = render_boresight_html(run_, settings, problems=doubts, accepted=True)
        write_text_atomic(out.path("OUTPUT_HTML"), page)
