"""``bundleadjustment``: aerotriangulation of a block with self-calibration.

Outputs: the adjusted exterior orientation with sigmas (EO CSV), the adjusted camera(s) with
their APs and sigmas (camera JSON), the object points with sigmas (CSV and a point layer), the
residual of every image measurement with its w-test (CSV), the check-point discrepancies in
the table the accuracy report reads (CSV), the comparison of the AP models (CSV, with
``AP_MODEL=all``) and the HTML summary.
"""

from __future__ import annotations

import logging

from .common import (
    camera_param,
    csv_out,
    enum_param,
    eo_param,
    global_test_verdict,
    html_out,
    json_out,
    table_param,
)
from .runner import JobResult
from .spec import AlgorithmSpec, Fields, Param, Ref, Result, Values, options_from

log = logging.getLogger(__name__)

_OPTIONS = Fields("photo.bundle_options", "BundleOptions")
_AP_CHOICES = Ref("geometry.ap_families", "AP_FAMILIES", convert=lambda f: (*f, "all"))
#: the frame of the coordinates: the mapping CRS, or a local engineering frame (no CRS)
FRAME_CHOICES = ("crs", "local_m", "local_mm")

SPEC = AlgorithmSpec(
    name="bundleadjustment",
    title="Bundle adjustment with self-calibration",
    group="Aerotriangulation",
    group_id="aerotriangulation",
    summary="exterior orientations, object points, interior orientation and APs of a block",
    description="""\
Bundle adjustment of a block of frame images: the exterior orientation of every image, the
object points (tie, control with sigmas; check points kept out and reported), and per camera
the interior orientation (principal distance, principal point) with the additional
parameters (APs) of one family, in one rigorous least-squares adjustment in a local
east-north-up frame (results in the mapping CRS).

AP families (Lima, Debiasi & Menezes compare them on a UAV block): lens_k1k2 (radial k1, k2),
bauer (3: radial, affinity, shear; Bauer & Mueller 1972), jacobsen (4), ebner (12, orthogonal
on a 3 x 3 grid; Ebner 1976), brown (14-term polynomial; Brown 1976 as in Murai et al. 1984),
conrady_brown (physical k1 k2 k3 p1 p2); none holds the camera's own lens model. all runs every
family on the same block, writes the comparison table (mean, standard deviation and RMS of the
check-point discrepancies, sigma0, significant APs) and the outputs of the best model.

Inputs: camera JSON (one camera, or {"cameras": [...]} with a camera column in the EO or
observation table; perspective or fisheye: equidistant, equisolid-angle, orthographic or
stereographic with Brown added, as Calibrate camera writes it, each through its own
projection), image observations (image_id, point_id, col, row, sigma_px; a row of
type control, as Locate control points writes it, must name a ground point), ground points
(point_id, X, Y, Z, sx, sy, sz, role = control | check), optionally exterior
orientations: approximate (e.g. direct georeferencing, a few degrees and metres off), or
observed when the table has sigma columns (GNSS/INS with sigmas; lever arm and boresight
corrections can be estimated). Without orientations the images that see four or more control
points are resected and the rest of the block grows by intersection and resection.

Camera timing offset (ESTIMATE_TIMING): with observed orientations, a constant dt (exposure =
recorded time + dt) as one more unknown, the observed centres being the GNSS/INS positions at
the recorded times; the velocity of each exposure from the EO table (v_north, v_east, v_up or
vx, vy, vz) or differenced from the neighbouring exposures of its group. It needs strips in
different directions or at different speeds, or ground control; estimated with the lever arm,
strips at one speed are refused as not observable, naming both. dt in ms with its sigma and
correlations: the results TIMING_OFFSET_MS and TIMING_OFFSET_STD_MS, the log and the summary.

Statistics: sigma0, the global chi-square test, sigmas and correlations; each AP's t-test
and |correlation| above 0.9 flagged; automatic selection drops insignificant APs one at a
time (an AP correlated with others is dropped only when a joint F-test finds them
insignificant together; a correlation alone never drops one) and says which and why.
Outliers: robust reweighting (Huber or Cauchy) then Baarda's data snooping.
Datum: control points and/or observed orientations, or a
free network (inner or minimal constraints); scale bars (measured distances with sigmas) are
observations, and with a free network they give its scale. Close-range networks: FRAME
local_m or local_mm takes the coordinates in a local engineering frame with no CRS.
Tables that cannot make a block (an image without observations, a tie point seen once,
duplicated rows, unknown images, ground points in another CRS, unconnected parts) are refused
with the file and row named.""",
    params=(
        camera_param('Camera (JSON; several as {"cameras": [...]})'),
        table_param("OBSERVATIONS", "Image observations (CSV)"),
        table_param(
            "GROUND_POINTS", "Ground points (CSV: point_id,X,Y,Z,sx,sy,sz,role)", optional=True
        ),
        eo_param(
            "Exterior orientation, approximate or observed (CSV)",
            optional=True,
            help="approximate values, or observations when the sigma columns are filled",
        ),
        Param(
            "EO_SIGMAS",
            "numbers",
            "EO sigmas when the table has none: X, Y, Z, omega, phi, kappa",
            count=6,
            unit="frame unit (m, or mm in a local frame), degrees",
            optional=True,
            minimum=0.0001,
            maximum=100.0,
            help="makes an EO table without sigma columns (e.g. from trajectorytoeo) "
            "observations; empty: approximate values only",
            advanced=True,
        ),
        Param(
            "CRS",
            "crs",
            "Mapping CRS",
            optional=True,
            qgis_default="ProjectCrs",
            help="projected CRS of the ground points and exterior orientations (needed "
            "unless FRAME is a local frame, which ignores it)",
        ),
        Param(
            "FRAME",
            "enum",
            "Coordinate frame",
            "crs",
            options=FRAME_CHOICES,
            labels=(
                "mapping CRS (projected, metres)",
                "local engineering frame, metres (no CRS)",
                "local engineering frame, millimetres (no CRS)",
            ),
            help="a local frame takes X, Y, Z and omega-phi-kappa as they are (close-range "
            "networks, calibration fields): no projection, no earth curvature; every length "
            "of the inputs (coordinates, sigmas, EO_SIGMAS, scale bars) and of the outputs is "
            "in its unit",
            advanced=True,
        ),
        Param(
            "AP_MODEL",
            "enum",
            "Additional parameters",
            _OPTIONS.ap_model,
            options=_AP_CHOICES,
            labels=(
                "none (camera fixed)",
                "lens distortion k1, k2",
                "Bauer (3)",
                "Jacobsen (4)",
                "Ebner (12)",
                "Brown (14)",
                "Conrady-Brown k1 k2 k3 p1 p2",
                "all (compare every family)",
            ),
        ),
        Param(
            "ESTIMATE_INTERIOR",
            "boolean",
            "Estimate principal distance and point",
            _OPTIONS.estimate_interior,
        ),
        Param(
            "AP_SELECTION",
            "boolean",
            "Drop insignificant APs",
            _OPTIONS.ap_selection,
            advanced=True,
        ),
        enum_param(
            "ROBUST",
            "Robust reweighting before data snooping",
            _OPTIONS.robust,
            "ROBUSTS",
            advanced=True,
        ),
        Param("SNOOPING", "boolean", "Data snooping (Baarda)", _OPTIONS.snooping, advanced=True),
        enum_param(
            "DATUM",
            "Datum",
            _OPTIONS.datum,
            "DATUMS",
            labels=(
                "control points / observed EO",
                "free network: inner constraints",
                "free network: minimal constraints",
            ),
            advanced=True,
        ),
        table_param(
            "SCALE_BARS",
            "Scale bars / measured distances (CSV: point_a,point_b,distance,sigma)",
            optional=True,
            help="distances between adjusted points, observations with their sigmas (frame "
            "units); with a free-network datum they give its scale (inner constraints "
            "without the scale row, or six parameters held)",
            advanced=True,
        ),
        Param(
            "ESTIMATE_MOUNT",
            "boolean",
            "Estimate lever arm and boresight corrections",
            _OPTIONS.estimate_mount,
            advanced=True,
            help="needs observed exterior orientations",
        ),
        Param(
            "ESTIMATE_TIMING",
            "boolean",
            "Estimate the camera timing offset",
            _OPTIONS.estimate_timing,
            help="observed orientations taken at the recorded time, the exposure at recorded "
            "time + dt: one constant dt from the EO table's velocities (v_north, v_east, v_up "
            "or vx, vy, vz) or differenced from neighbouring exposures of each group by time; "
            "needs strips in different directions or at different speeds (or ground control); "
            "with the lever arm, different speeds",
            advanced=True,
        ),
        csv_out("OUTPUT_EO", "Adjusted exterior orientation (CSV)", optional=False),
        json_out("OUTPUT_CAMERA", "Adjusted camera (JSON)"),
        csv_out("OUTPUT_POINTS", "Object points (CSV)", twin="OUTPUT_POINTS_LAYER"),
        Param("OUTPUT_POINTS_LAYER", "sink", "Object points", geometry="point", optional=True),
        csv_out("OUTPUT_RESIDUALS", "Image residuals with w-tests (CSV)", advanced=True),
        csv_out("OUTPUT_CHECK_CSV", "Check-point discrepancies (CSV)", advanced=True),
        csv_out("OUTPUT_COMPARISON", "AP model comparison (CSV)", on_demand=True, advanced=True),
        csv_out(
            "OUTPUT_SCALE_BARS",
            "Adjusted scale bars with w-tests (CSV)",
            on_demand=True,
            advanced=True,
        ),
        html_out("OUTPUT_HTML", "Summary (HTML)"),
    ),
    results=(
        Result("SIGMA0", "number", "Sigma0 a-posteriori"),
        Result("CHECK_RMS", "number", "Check-point RMS 3D (frame unit)"),
        Result("MODEL", "string", "AP model of the outputs"),
        Result("TIMING_OFFSET_MS", "number", "Camera timing offset dt (ms, NaN if not estimated)"),
        Result("TIMING_OFFSET_STD_MS", "number", "Sigma of the timing offset (ms)"),
    ),
    tags=(
        "bundle adjustment",
        "aerotriangulation",
        "self-calibration",
        "additional parameters",
        "uav",
        "drone",
        "ebner",
        "brown",
        "bauer",
        "jacobsen",
    ),
    references=(
        "Lima, Debiasi & Menezes",
        "Bauer & Mueller (1972)",
        "Ebner (1976)",
        "Brown (1976)",
        "Murai, Matsuoka & Okuda (1984)",
        "Baarda (1968)",
        "Huber (1964)",
        "Triggs et al. (2000)",
        "Nielsen (1999)",
    ),
)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the inputs, adjust (each AP family for ``all``), write the outputs."""
    from ..errors import AdjustmentError
    from ..geometry.ap_models import AP_FAMILIES
    from ..photo.bundle import bundle_adjust
    from ..photo.bundle_setup import BundleOptions
    from .runner import stages

    frame, cams, obs, ground, eo, sigma, eo_rows, eo_source, image_camera, bars, velocity = (
        _read_inputs(v)
    )
    models = tuple(m for m in AP_FAMILIES) if v.ap_model == "all" else (v.ap_model,)
    parts = stages(progress, *([1.0] * len(models)))
    stage = dict(zip(models, parts))

    def one(model: str):
        opts = options_from(BundleOptions, SPEC, v, ap_model=model)
        log.info("bundle adjustment with AP model %s", model)
        try:
            return bundle_adjust(
                cams,
                obs,
                ground,
                frame,
                eo,
                sigma,
                image_camera,
                opts,
                eo_rows,
                eo_source,
                stage[model],
                should_stop,
                scale_bars=bars,
                velocity=velocity,
            )
        except AdjustmentError as exc:
            if eo is not None:  # an approximate orientation far off is the usual cause
                _blame_eo(exc, cams, obs, ground, eo, image_camera, eo_rows, eo_source)
            raise

    rows, results = _adjust_models(models, one)
    best = str(next(r["model"] for r in rows if r["model"] in results))
    res = results[best]
    settings = _settings(v, cams, obs, ground, eo, sigma, frame, velocity)
    _write_outputs(
        out, results, best, rows, settings, multi=len(cams) > 1, compared=len(models) > 1
    )
    return JobResult(
        results=_results(res, best),
        lines=_summary_lines(res, best, rows if len(models) > 1 else ()),
        data=res,
    )


def _adjust_models(models: tuple, one) -> tuple[list, dict]:
    """``one(model)`` for each AP model: (the comparison rows ranked, {model: result}); with
    several models those that fail are rows with their error (InputError when all do)."""
    from ..errors import InputError
    from ..photo.bundle import compare_ap_models

    if len(models) == 1:
        res = one(models[0])
        return [{**res.summary_row(), "rank": 1}], {models[0]: res}
    rows, results = compare_ap_models(models, one)
    if not results:
        raise InputError(
            "no AP model could be adjusted: " + "; ".join(str(r.get("error")) for r in rows)
        )
    return rows, results


def _results(res, best: str) -> dict:
    """The job's results: sigma0, the check points' 3D RMS (NaN without), the model chosen
    and the timing offset."""
    import math

    st = res.check.statistics()
    return {
        "SIGMA0": float(res.adjustment.sigma0),
        "CHECK_RMS": float(st["rms_3d"]) if math.isfinite(st["rms_3d"]) else float("nan"),
        "MODEL": best,
        **_timing_results(res),
    }


def _timing_results(res) -> dict[str, float]:
    """TIMING_OFFSET_MS and TIMING_OFFSET_STD_MS (NaN when the offset is not estimated)."""
    t = res.timing
    nan = float("nan")
    return {
        "TIMING_OFFSET_MS": nan if t is None else 1e3 * t["dt_s"],
        "TIMING_OFFSET_STD_MS": nan if t is None else 1e3 * t["dt_std_s"],
    }


def _read_inputs(v: Values) -> tuple:
    """The frame, cameras, observations and ground points, and the approximate orientations
    with their sigmas (EO_SIGMAS when the file has none) and the camera of every image, all
    checked, the scale bars and the EO's velocities: (frame, cameras, observations, ground,
    eo, sigma, eo_rows, eo_source, image_camera, bars, velocity)."""
    import numpy as np

    from ..errors import InputError
    from ..geometry.frames import check_points_in_area
    from ..geometry.projection import PROJECTIONS
    from ..io.camera import read_cameras_json
    from ..io.ground_points import read_ground_points_csv
    from ..io.observations import read_observations_csv
    from ..io.orientation import read_eo_csv_full
    from ..io.scale_bars import read_scale_bars_csv
    from ..photo.bundle_setup import GroundPoints

    frame = _frame(v)
    crs = getattr(frame, "crs", None)  # None: a local engineering frame
    cams = read_cameras_json(v.camera, projections=PROJECTIONS)  # perspective or fisheye
    # one camera: its image size bounds every pixel as the table is read (several: below)
    obs = read_observations_csv(v.observations, camera=cams[0] if len(cams) == 1 else None)
    ground = read_ground_points_csv(v.ground_points) if v.ground_points else GroundPoints.empty()
    if crs is not None:
        check_points_in_area(crs, ground.xyz, what="the ground points", path=v.ground_points)
    eo = sigma = velocity = None
    eo_rows: tuple[int, ...] = ()
    eo_source = ""
    image_camera: dict[str, str] = {}
    if v.eo:
        f = read_eo_csv_full(v.eo, crs.to_wkt() if crs is not None else "")
        eo, sigma, eo_rows, eo_source, velocity = f.eo, f.sigma, f.rows, f.path, f.velocity
        if crs is not None:
            check_points_in_area(crs, eo.xyz, what="the perspective centres", path=v.eo)
        if sigma is None and v.eo_sigmas:
            s6 = np.array(v.eo_sigmas, dtype=float)
            if not (s6 > 0).all():
                raise InputError("EO_SIGMAS: every sigma must be > 0")
            s6[3:] = np.radians(s6[3:])
            sigma = np.tile(s6, (len(eo), 1))
        if f.camera is not None:
            image_camera.update(zip(f.eo.image_id, f.camera))
    for k, (im, cam) in enumerate(zip(obs.image_id, obs.camera)):
        if image_camera.setdefault(im, cam) != cam:
            raise InputError(
                f"image '{im}' is given camera '{cam}' here and '{image_camera[im]}' elsewhere",
                **obs.where(k),
            )
    if len(cams) > 1:
        _check_on_image(obs, image_camera, cams)
    bars = read_scale_bars_csv(v.scale_bars) if v.scale_bars else None
    if bars is None and v.output_scale_bars:
        raise InputError("OUTPUT_SCALE_BARS needs the scale bars (SCALE_BARS)")
    return frame, cams, obs, ground, eo, sigma, eo_rows, eo_source, image_camera, bars, velocity


def _frame(v: Values):
    """The frame of the coordinates: the mapping CRS, or a local engineering frame."""
    from ..errors import InputError
    from ..geometry.engineering import EngineeringFrame
    from ..geometry.frames import MappingFrame

    if v.frame == "crs":
        if not v.crs:
            raise InputError(
                "CRS: give the mapping CRS of the coordinates, or a local "
                "engineering frame (FRAME local_m or local_mm)"
            )
        return MappingFrame.from_user_input(v.crs)
    return EngineeringFrame(v.frame.split("_")[1])


def _write_outputs(
    out, results: dict, best: str, rows: list, settings, *, multi: bool, compared: bool
) -> None:
    """The requested outputs of the adjustment of AP model ``best`` (of ``results``, ranked
    in ``rows``); ``multi``: several cameras, ``compared``: several AP models."""
    from ..io.atomic import write_text_atomic
    from ..io.bundle import (
        write_bundle_points,
        write_bundle_residuals,
        write_check_points,
        write_comparison,
    )
    from ..io.camera import write_cameras_json
    from ..io.orientation import write_eo_csv_with_sigmas
    from ..io.scale_bars import write_scale_bars_csv
    from ..quality.bundle_html import render_bundle_html

    res = results[best]
    if out.requested("OUTPUT_EO"):
        write_eo_csv_with_sigmas(
            out.path("OUTPUT_EO"), res.eo, res.eo_sigma, res.image_camera if multi else None
        )
    if out.requested("OUTPUT_CAMERA"):
        sig = [
            {p.name: p.std for p in res.interior if p.camera == c.name and p.status == "estimated"}
            for c in res.cameras.values()
        ]
        write_cameras_json(
            out.path("OUTPUT_CAMERA"),
            list(res.cameras.values()),
            sig,
            {
                "_bundle": {
                    "ap_model": best,
                    "sigma0": res.sigma0,
                    "frame": res.local.mapping.name,
                    "dropped": [list(d) for d in res.dropped],
                }
            },
        )
    if out.requested("OUTPUT_POINTS"):
        write_bundle_points(out.path("OUTPUT_POINTS"), res)
    if out.requested("OUTPUT_RESIDUALS"):
        write_bundle_residuals(out.path("OUTPUT_RESIDUALS"), res)
    if out.requested("OUTPUT_CHECK_CSV"):
        write_check_points(out.path("OUTPUT_CHECK_CSV"), results.values())
    if out.requested("OUTPUT_COMPARISON"):
        write_comparison(out.path("OUTPUT_COMPARISON"), rows)
    if out.requested("OUTPUT_SCALE_BARS") and res.scale_bars is not None:
        write_scale_bars_csv(out.path("OUTPUT_SCALE_BARS"), res.scale_bars, res.length_unit)
    if out.requested("OUTPUT_HTML"):
        page = render_bundle_html(results, best, settings, rows if compared else ())
        write_text_atomic(out.path("OUTPUT_HTML"), page)


def _summary_lines(res, best: str, rows) -> list[str]:
    """The log's summary: the ranking of the AP models (``rows``, when several), then the
    adjustment of ``best`` and its check points."""
    import math

    import numpy as np

    from ..photo.bundle_options import BundleOptions

    st = res.check.statistics()
    u = res.length_unit
    lines = [f"frame: {res.local.mapping.name}"] if u != "m" or _local(res) else []
    if rows:
        lines.append(
            f"{'rank':>4} {'model':14} {'check RMS 3D ' + u:>14} {'planimetric ' + u:>13} "
            f"{'sigma0':>7} {'sig. APs':>8}"
        )
        for r in rows:
            if r.get("error"):
                lines.append(f"{'-':>4} {r['model']:14} not observable")
                continue
            lines.append(
                f"{r['rank']:>4} {r['model']:14} {r['rms_3d']:14.3f} "
                f"{r['rms_planimetric']:13.3f} {r['sigma0']:7.3f} "
                f"{r['n_significant']:8d}"
            )
    a = res.adjustment
    lines.append(
        f"{best}: sigma0 {a.sigma0:.3f}, redundancy {a.redundancy}, global test "
        f"{global_test_verdict(a.global_test.passed, a, BundleOptions.snooping_alpha)}, "
        f"{int(res.rejected.sum())} "
        f"measurements rejected, {len(res.dropped)} APs dropped"
    )
    if res.timing is not None:
        lines.append(
            f"timing offset dt {1e3 * res.timing['dt_s']:.2f} ms, sigma "
            f"{1e3 * res.timing['dt_std_s']:.2f} ms (exposure = recorded time + dt)"
        )
    if len(res.check.point_id):
        lines.append(
            f"check points ({int(st['n'])}): RMS E/N/H {st['rms_e']:.4g} / {st['rms_n']:.4g} / "
            f"{st['rms_h']:.4g} {u}, 3D {st['rms_3d']:.4g} {u}"
        )
    b = res.scale_bars
    if b is not None:
        lines.append(
            f"scale bars ({len(b.v)}): RMS residual {math.sqrt(float(np.mean(b.v**2))):.4g} {u}, "
            f"max |w| {float(np.nanmax(np.abs(b.w), initial=0.0)):.2f}, "
            f"{int(b.rejected.sum())} rejected"
        )
    return lines


def _local(res) -> bool:
    """Whether a bundle result is in a local engineering frame."""
    return bool(getattr(res.local, "engineering", False))


def _misfit(xyz, px, eo6, cam) -> float:
    """Median distance (pixels) between measured pixels and the projections of their ground
    points with ``eo6`` (map frame taken as the EO's grid frame: a diagnosis, not a model);
    infinite when half the points are behind the camera."""
    import numpy as np

    from ..geometry.collinearity import project_with_status

    p, front, ok = project_with_status(xyz, eo6, cam)
    good = front & ok
    if good.sum() * 2 <= len(px):
        return float("inf")
    return float(np.median(np.hypot(*(p[good] - px[good]).T)))


def _blame_eo(exc, cams, obs, ground, eo, image_camera, rows, path) -> None:
    """Raise an InputError naming the EO row (and the likely mistake) of the first image
    whose approximate orientation cannot be right: the ground points it measures (three or
    more) project, median, more than a quarter of the image's diagonal from their pixels;
    the cause is a kappa off by 90 or 180 degrees when turning it makes them fit (within a
    tenth of the diagonal, five times better). Returns when no image is found."""
    import math

    import numpy as np

    from ..errors import InputError

    where = {p: k for k, p in enumerate(ground.point_id)}
    by_name = {c.name: c for c in cams}
    for k, image in enumerate(eo.image_id):
        cam = by_name.get(image_camera.get(image, ""), cams[0])
        sel = [
            m
            for m, (im, p) in enumerate(zip(obs.image_id, obs.point_id))
            if im == image and p in where
        ]
        if len(sel) < 3:
            continue
        xyz = ground.xyz[[where[obs.point_id[m]] for m in sel]]
        px = obs.pixels[sel]
        eo6 = np.r_[eo.xyz[k], eo.opk[k]]
        diag = math.hypot(cam.width_px, cam.height_px)
        now = _misfit(xyz, px, eo6, cam)
        if now <= 0.25 * diag:
            continue
        turns = {
            d: _misfit(xyz, px, eo6 + np.r_[0, 0, 0, 0, 0, math.radians(d)], cam)
            for d in (180, 90, -90)
        }
        d = min(turns, key=turns.get)
        cause = (
            f"kappa looks {abs(d)} degrees off (turned by {d:+d} degrees, the ground points "
            f"fit within {turns[d]:.0f} px)"
            if turns[d] <= min(0.1 * diag, now / 5)
            else "the position or the angles are far off (degrees, the order omega-phi-kappa, "
            "the axes' signs)"
        )
        raise InputError(
            f"the approximate orientation of image {image} cannot be right: its "
            f"{len(sel)} ground points project more than a quarter of the image "
            f"away from their measurements; {cause} (the adjustment: {exc})",
            path=path,
            row=rows[k] if rows else None,
        ) from exc


def _check_on_image(obs, image_camera: dict[str, str], cams) -> None:
    """Refuse a measured pixel off its camera's image (0 <= col <= width_px, 0 <= row <=
    height_px), naming the row; images of unknown cameras are left to the adjustment."""
    import numpy as np

    from ..errors import InputError

    cam_of = np.array([image_camera.get(im, "") for im in obs.image_id], dtype=object)
    outside = np.zeros(len(cam_of), dtype=bool)
    for c in cams:
        rows = cam_of == c.name
        outside[rows] = ~c.in_frame(obs.pixels[rows])
    off = np.flatnonzero(outside)
    if off.size:
        k = int(off[0])
        cam = next(c for c in cams if c.name == cam_of[k])
        raise InputError(
            f"pixel ({obs.pixels[k, 0]:g}, {obs.pixels[k, 1]:g}) is off the image: camera "
            f"'{cam.name}' has {cam.width_px} x {cam.height_px} pixels; {off.size} row(s) "
            "affected",
            **obs.where(k),
        )


def _settings(v, cams, obs, ground, eo, sigma, frame, velocity=None) -> dict[str, str]:
    roles = list(ground.role)
    return {
        "cameras": "; ".join(
            f"{c.name} (f = {c.focal_mm:g} mm, {c.width_px} x {c.height_px} px of "
            f"{c.pixel_size_mm * 1000:g} um, {c.projection} projection, lens "
            f"{c.distortion.model})"
            for c in cams
        ),
        "images / measurements": f"{len(set(obs.image_id))} / {len(obs)}",
        "ground points": f"{roles.count('control')} control, {roles.count('check')} check",
        "exterior orientation": "none (resection and growth)"
        if eo is None
        else ("observed (with sigmas)" if sigma is not None else "approximate values"),
        ("mapping CRS" if hasattr(frame, "crs") else "frame"): frame.name,
        "AP model": v.ap_model,
        "interior orientation": "estimated" if v.estimate_interior else "fixed",
        "AP selection": "on" if v.ap_selection else "off",
        "outliers": f"robust {v.robust}, data snooping {'on' if v.snooping else 'off'}",
        "datum": v.datum + (" + scale bars" if v.scale_bars else ""),
        "lever arm / boresight": "estimated" if v.estimate_mount else "held",
        "camera timing offset": ("estimated" if v.estimate_timing else "held (0)")
        + (
            ""
            if not v.estimate_timing
            else ", velocities from the EO table"
            if velocity is not None
            else ", velocities from neighbouring exposures"
        ),
    }
