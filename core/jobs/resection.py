"""``resection``: the exterior orientation of single images from control points and straight
lines (LiDAR lines), without approximate values.

Outputs: the exterior orientation with its precision (the EO CSV with sigma and test columns,
readable wherever an EO table is read), the residual table (every measured point, line point
and check point) and an HTML summary (orientation, sigmas, correlation matrix, global test,
residuals, rejected observations).
"""

from __future__ import annotations

import logging
import math

from .common import camera_param, csv_out, enum_param, global_test_verdict, html_out, table_param
from .runner import JobResult
from .spec import AlgorithmSpec, Fields, Param, Result, Values, options_from

log = logging.getLogger(__name__)
_OPTIONS = Fields("photo.resection_options", "ResectionOptions")

SPEC = AlgorithmSpec(
    name="resection",
    title="Space resection from points and lines",
    group="Aerotriangulation",
    group_id="aerotriangulation",
    summary="exterior orientation of single images from control points and straight lines",
    description="""\
Orients each image on its own from control points (collinearity) and straight lines: image
lines matched to 3D lines, such as the ridge, hip and valley lines of Create LiDAR control
points and lines, or lines monoplotted on another image (dos Santos, Dal Poz & Dalmolin 2010).
No approximate orientation is needed: a global search over the rotation with the position
eliminated in closed form (Hesch & Roumeliotis 2011; Mirzaei & Roumeliotis 2011) gives the
start, OpenCV's solvePnP another when there are four or more points, and the one that fits
best starts the rigorous adjustment. The camera may be perspective or, for control points,
fisheye (equidistant, equisolid-angle, orthographic, stereographic, Brown added: its own
projection and rays); straight lines need a perspective camera (line rows with a fisheye
camera are refused).

Line models: coplanarity (every point measured on an image line lies on the projected 3D
line; no parametrisation, the default) or the equivalent-planes model of Tommaselli & Tozzi
(1996) as used by dos Santos et al. (2010), in its two parametrisations y = a x + b and
x = a* y + b*, chosen per line by its direction. Both give the same estimate at convergence;
they differ in how far from the solution they converge. The pixel sigmas and the covariance
of the control (LCP and line tables, or sx, sy, sz) are propagated; the focal length and the
principal point can be refined when the control has depth.

Observations: the image-observation CSV (image_id, point_id, col, row, sigma_px, type,
target_id). Rows of type line with the same image and target_id are one image line (two or
more points: its ends); lcp rows are control points and check rows check points (target_id:
the control point id); control rows (as Locate control points writes them) are the control
point point_id, and tie and paper rows whose point_id is a control point are control points
too. LINE_OBSERVATIONS may hold the line rows in a second file.

Control points: point_id,X,Y,Z[,sx,sy,sz] or the LCP table. Control lines: the line table of
Create LiDAR control points and lines, a segment table id,x1,y1,z1,x2,y2,z2[,sigma_start,
sigma_end], or the line table of Monoplot. APPROX_EO (an EO table) replaces the automatic
start; with APPROX_EO_SIGMAS it is weighted as observations (the source's weighted
constraints).

Statistics per image: sigma0, the global chi-square test (the statistic against the
one-sided 5 % critical value, as the source reports it, and the two-sided test), the
standard deviations and correlations of the six parameters, Baarda's data snooping of points
and whole lines, and a diagnosis naming what the observations cannot determine (e.g. all
lines parallel).""",
    params=(
        camera_param(),
        table_param(
            "OBSERVATIONS",
            "Image observations (CSV)",
            optional=True,
            help="points (and line points) measured in the images",
        ),
        table_param(
            "LINE_OBSERVATIONS",
            "Image line observations (CSV)",
            optional=True,
            help="rows of type line in a second observation file",
        ),
        table_param(
            "CONTROL_POINTS",
            "Control points (CSV)",
            optional=True,
            help="point_id,X,Y,Z[,sx,sy,sz] or the LCP table",
        ),
        table_param(
            "CONTROL_LINES",
            "Control lines (CSV)",
            optional=True,
            help="LiDAR line table, 3D segments (id,x1..z2) or monoplotted lines",
        ),
        Param(
            "CRS",
            "crs",
            "Mapping CRS of the control",
            qgis_default="ProjectCrs",
            help="projected CRS of the control points and lines (and of APPROX_EO)",
        ),
        table_param(
            "APPROX_EO",
            "Approximate exterior orientation (CSV)",
            optional=True,
            help="start values instead of the automatic start (images not in it start "
            "automatically)",
        ),
        Param(
            "APPROX_EO_SIGMAS",
            "numbers",
            "Weights of the approximate EO: X, Y, Z, omega, phi, kappa",
            count=6,
            unit="m, degrees",
            optional=True,
            advanced=True,
            minimum=1e-6,
            maximum=1e6,
            help="empty: start values only; given: weighted observations",
        ),
        Param(
            "IMAGES",
            "string",
            "Images (comma separated; empty: all)",
            "",
            optional=True,
            advanced=True,
        ),
        enum_param(
            "MODEL",
            "Line model",
            _OPTIONS.model,
            "MODELS",
            labels=(
                "coplanarity (no parametrisation)",
                "equivalent planes (Tommaselli & Tozzi 1996)",
            ),
            advanced=True,
        ),
        Param(
            "ESTIMATE_INTERIOR",
            "boolean",
            "Refine focal length and principal point",
            _OPTIONS.estimate_interior,
        ),
        Param("SNOOPING", "boolean", "Data snooping (Baarda)", _OPTIONS.snooping, advanced=True),
        csv_out("OUTPUT_EO", "Exterior orientation with sigmas (CSV)", optional=False),
        csv_out("OUTPUT_RESIDUALS", "Residuals (CSV)"),
        html_out("OUTPUT_HTML", "Summary (HTML)"),
    ),
    results=(
        Result("IMAGE_COUNT", "number", "Images resected"),
        Result("SIGMA0", "number", "Largest sigma0 a-posteriori"),
    ),
    tags=(
        "resection",
        "orientation",
        "exterior orientation",
        "straight lines",
        "lidar lines",
        "equivalent planes",
        "pnp",
    ),
    references=(
        "dos Santos, Dal Poz & Dalmolin (2010)",
        "Tommaselli & Tozzi (1996)",
        "Hesch & Roumeliotis (2011)",
        "Mirzaei & Roumeliotis (2011)",
        "Baarda (1968)",
    ),
)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the inputs, resect each image, write the outputs."""
    import numpy as np

    from ..errors import Cancelled, InputError, LidarPhotoError, stop_if_asked
    from ..photo.resection import ResectionOptions
    from ..photo.resection_map import control_frame, image_inputs, resect_in_map

    if not v.observations and not v.line_observations:
        raise InputError("give OBSERVATIONS or LINE_OBSERVATIONS (the measured image points)")
    if not v.control_points and not v.control_lines:
        raise InputError("give CONTROL_POINTS or CONTROL_LINES (the object coordinates)")
    frame, camera, obs, points, lines = _read_inputs(v)
    approx, prior = _approximations(v, frame)
    images = [s.strip() for s in (v.images or "").split(",") if s.strip()]
    inputs = image_inputs(obs, points, lines, images or None)
    options = options_from(ResectionOptions, SPEC, v, eo_prior_sigma=prior)
    local = control_frame(inputs, frame)
    runs = []
    for n, item in enumerate(inputs):
        stop_if_asked(should_stop, "resecting")
        sub = None if progress is None else (lambda f, n=n: progress((n + f) / len(inputs)))
        start = approx.get(item.image_id)
        eo0 = None if start is None else np.concatenate([start[0], start[1]])
        try:
            res = resect_in_map(
                item.image_id,
                item.data,
                camera,
                frame,
                options,
                eo0,
                local,
                progress=sub,
                should_stop=should_stop,
            )
        except LidarPhotoError as exc:
            if isinstance(exc, Cancelled):
                raise
            raise _prefixed(exc, item.image_id) from None
        runs.append(ImageRun(item, res, start))
    _write_outputs(v, out, runs, camera, obs, points, lines, frame)
    sigma0 = max((r.result.result.sigma0 for r in runs), default=math.nan)
    return JobResult(
        results={"IMAGE_COUNT": len(runs), "SIGMA0": sigma0},
        lines=_summary_lines(runs, options.snooping_alpha),
        data=runs,
    )


def _read_inputs(v: Values) -> tuple:
    """The frame, the camera, the image observations (points and lines, a file given twice
    read once) and the control points and lines, checked against the CRS's area of use."""
    from pathlib import Path

    import numpy as np

    from ..errors import InputError
    from ..geometry.frames import MappingFrame, check_points_in_area
    from ..geometry.projection import PROJECTIONS
    from ..io.camera import read_camera_json
    from ..io.observations import read_observations_csv
    from ..io.resection import read_line_control_csv, read_point_control_csv

    frame = MappingFrame.from_user_input(v.crs)
    camera = read_camera_json(v.camera, projections=PROJECTIONS)  # perspective or fisheye
    points = read_point_control_csv(v.control_points) if v.control_points else None
    obs = None
    for path in (v.observations, v.line_observations):
        if not path:
            continue
        if obs is not None and Path(path).resolve() == Path(v.observations).resolve():
            continue  # the same file twice
        o = read_observations_csv(path, camera=camera)
        if path == v.line_observations and path != v.observations:
            o = o.subset(o.mask("line"))
        if not camera.is_perspective and o.mask("line").any():
            # a straight object line images as a curve through a fisheye lens: the line
            # models (coplanarity, equivalent planes) hold for the perspective projection only
            row = int(np.flatnonzero(o.mask("line"))[0])
            raise InputError(
                f"camera {camera.name!r} ({v.camera}) has the {camera.projection} (fisheye) "
                "projection; the resection from straight lines handles perspective cameras "
                "only: leave the rows of type line out (use control points)",
                **o.where(row),
            )
        _check_control_rows(o, points)
        obs = o if obs is None else obs.concat(o)
    lines = read_line_control_csv(v.control_lines) if v.control_lines else None
    for what, path, xyz in (
        ("control points", v.control_points, None if points is None else points.xyz),
        (
            "control lines",
            v.control_lines,
            None if lines is None else np.vstack([lines.p1, lines.p2]),
        ),
    ):
        if xyz is not None:
            check_points_in_area(frame.crs, xyz, what=f"the {what}", path=path)
    return frame, camera, obs, points, lines


def _approximations(v: Values, frame) -> tuple[dict, tuple | None]:
    """The approximate orientations by image id ((xyz, opk, time, group)) and the sigmas of
    their prior (m, m, m, rad x 3; None without APPROX_EO_SIGMAS)."""
    from ..errors import InputError
    from ..geometry.frames import check_points_in_area
    from ..io.orientation import read_eo_csv

    approx = {}
    if v.approx_eo:
        table = read_eo_csv(v.approx_eo)
        check_points_in_area(
            frame.crs, table.xyz, what="the approximate perspective centres", path=v.approx_eo
        )
        approx = {
            i: (table.xyz[k], table.opk[k], table.time[k], table.group[k])
            for k, i in enumerate(table.image_id)
        }
    prior = None
    if v.approx_eo_sigmas:
        if not v.approx_eo:
            raise InputError("APPROX_EO_SIGMAS needs APPROX_EO")
        s = v.approx_eo_sigmas
        prior = (*s[:3], *(math.radians(a) for a in s[3:]))
    return approx, prior


def _write_outputs(v: Values, out, runs: list, camera, obs, points, lines, frame) -> None:
    """The requested EO table, residuals and report."""
    from ..io.atomic import write_text_atomic
    from ..quality.resection_html import render_resection_html

    rows = [run_eo_row(r) for r in runs]
    if out.requested("OUTPUT_EO"):
        from ..io.resection import write_eo_sigma_csv

        write_eo_sigma_csv(out.path("OUTPUT_EO"), rows)
    residuals = [row for r in runs for row in residual_rows(r, obs, camera)]
    if out.requested("OUTPUT_RESIDUALS"):
        from ..io.resection import write_residuals_csv

        write_residuals_csv(out.path("OUTPUT_RESIDUALS"), residuals)
    settings = _settings(v, camera, obs, points, lines, frame)
    if out.requested("OUTPUT_HTML"):
        write_text_atomic(out.path("OUTPUT_HTML"), render_resection_html(runs, residuals, settings))


def _summary_lines(runs: list, snooping_alpha: float) -> list[str]:
    """The log's table: one line per image."""
    import numpy as np

    lines_out = [
        f"{'image':16} {'X':>12} {'Y':>13} {'Z':>9} {'omega':>9} {'phi':>9} {'kappa':>10} "
        f"{'sigma0':>7} {'pts':>4} {'lns':>4} test"
    ]
    for r in runs:
        res = r.result.result
        deg = np.degrees(r.result.opk)
        lines_out.append(
            f"{r.image.image_id:16} {r.result.xyz[0]:12.3f} {r.result.xyz[1]:13.3f} "
            f"{r.result.xyz[2]:9.3f} {deg[0]:9.5f} {deg[1]:9.5f} {deg[2]:10.5f} "
            f"{res.sigma0:7.3f} {r.image.data.n_points:4d} {r.image.data.n_lines:4d} "
            + global_test_verdict(res.chi2_passed, res.adjustment, snooping_alpha, "FAILED")
        )
    return lines_out


def _check_control_rows(obs, points) -> None:
    """A ``control`` row measures a surveyed point: its point_id must be a control point."""
    obs.require_control_known(
        points.index() if points is not None else {},
        "CONTROL_POINTS"
        if points is not None
        else "the control: give CONTROL_POINTS with that point_id",
    )


def _prefixed(exc, image_id: str):
    """The same error with the image named first (keeps the type and the named parameters)."""
    from ..errors import NotObservableError

    if isinstance(exc, NotObservableError):
        return NotObservableError(
            f"image {image_id}: {exc}", exc.parameters, exc.null_vectors, exc.condition_number
        )
    try:
        return type(exc)(f"image {image_id}: {exc}")
    except TypeError:
        return exc


class ImageRun:
    """One image's resection as the outputs and the picking dock use it: the observation rows
    (``image``), the result in the mapping CRS (``result``) and the approximate EO row
    (``start``: xyz, opk, time, group, or None)."""

    def __init__(self, image, result, start) -> None:
        self.image = image
        self.result = result
        self.start = start

    @property
    def image_id(self) -> str:
        return self.image.image_id


def run_eo_row(r: ImageRun) -> tuple:
    """The values of one row of the EO table with precision (angles in radians)."""
    res = r.result.result
    s = r.result.std
    time = r.start[2] if r.start is not None else math.nan
    group = r.start[3] if r.start is not None else ""
    rejected = int(res.point_rejected.sum() + res.line_rejected.sum())
    return (
        r.image_id,
        time,
        group,
        *r.result.xyz,
        *r.result.opk,
        *s,
        res.sigma0,
        res.redundancy,
        res.chi2.statistic,
        res.chi2_critical,
        res.chi2_passed,
        r.image.data.n_points,
        r.image.data.n_lines,
        rejected,
        res.model,
        res.start,
    )


def residual_rows(r: ImageRun, obs, camera) -> list[tuple]:
    """Rows of the residual table of one image (see :mod:`core.io.resection`)."""
    import numpy as np

    from ..geometry.collinearity import project

    item, res = r.image, r.result.result
    rows = []
    for j, k in enumerate(item.point_rows):
        v = res.point_v[j]
        rows.append(
            (
                item.image_id,
                obs.point_id[k],
                obs.type[k],
                obs.target_id[k],
                0,
                *obs.pixels[k],
                *v,
                float(np.hypot(*v)),
                res.point_w[j],
                bool(res.point_rejected[j]),
                True,
            )
        )
    for j, ks in enumerate(item.line_rows):
        for vi, k in enumerate(ks):
            v = res.line_v[j][vi]
            rows.append(
                (
                    item.image_id,
                    obs.point_id[k],
                    "line",
                    obs.target_id[k],
                    vi + 1,
                    *obs.pixels[k],
                    *v,
                    float(res.line_distance_px[j][vi]),
                    res.line_w[j],
                    bool(res.line_rejected[j]),
                    True,
                )
            )
    if item.check_rows:
        local = r.result.local
        xyz = local.map_to_enu(item.check_xyz)
        cam = (
            camera
            if res.interior is None
            else camera.with_interior(np.concatenate([res.interior, camera.distortion.params]))
        )
        pred = project(xyz, res.eo, cam)
        for j, k in enumerate(item.check_rows):
            v = pred[j] - obs.pixels[k]
            rows.append(
                (
                    item.image_id,
                    obs.point_id[k],
                    "check",
                    obs.target_id[k],
                    0,
                    *obs.pixels[k],
                    *v,
                    float(np.hypot(*v)),
                    math.nan,
                    False,
                    False,
                )
            )
    return rows


def _settings(v, camera, obs, points, lines, frame) -> dict[str, str]:
    """The run's settings as text (the HTML summary shows them)."""
    import numpy as np

    kinds, counts = np.unique(np.array(obs.type), return_counts=True)
    return {
        "camera": f"{camera.name} (f = {camera.focal_mm:g} mm, {camera.width_px} x "
        f"{camera.height_px} px of {camera.pixel_size_mm * 1000:g} um, {camera.projection} "
        "projection)",
        "observations": ", ".join(f"{t} {n}" for t, n in zip(kinds, counts)),
        "control points / lines": f"{0 if points is None else len(points.ids)} / "
        f"{0 if lines is None else len(lines.ids)}",
        "mapping CRS": frame.crs.name,
        "line model": v.model,
        "interior orientation": "refined (f, x0, y0)" if v.estimate_interior else "fixed",
        "start": "approximate EO" + (" (weighted)" if v.approx_eo_sigmas else "")
        if v.approx_eo
        else "automatic (no approximate values)",
        "data snooping": "Baarda, alpha = 0.001 per observation" if v.snooping else "off",
    }
