"""``calibratecamera``: camera calibration from images of a chessboard, ChArUco or ArUco target."""

from __future__ import annotations

from .common import csv_out, enum_param, html_out, images_param, json_out
from .runner import JobResult
from .spec import AlgorithmSpec, Fields, Param, Ref, Result, Values, options_from

_D = Fields("photo.calibration_options", "CalibrationOptions")
_T = Fields("photo.calibration_options", "TargetSpec")

SPEC = AlgorithmSpec(
    name="calibratecamera",
    title="Calibrate a camera from target images",
    group="Calibration",
    group_id="calibration",
    summary="Interior orientation and lens distortion (perspective or fisheye) from views of "
    "a planar target",
    description="""\
Detects a planar target in every image of a folder with OpenCV (chessboard:
findChessboardCornersSB; ChArUco: CharucoDetector; ArUco grid board: ArucoDetector with
sub-pixel corners) and calibrates the camera with the project's own least-squares adjustment:
a self-calibrating bundle with one pose per view, the interior orientation f, x0, y0 and the
Brown-Conrady coefficients k1 k2 k3 p1 p2 (any subset), for the perspective projection or a
fisheye projection (equidistant, equisolid-angle, orthographic, stereographic; Schneider,
Schwalbe & Maas 2009) with the Brown correction added. LENS_MODEL opencv adjusts OpenCV's own
radial-tangential model instead (perspective): the same least-squares problem as OpenCV's
calibrateCamera with a fixed aspect ratio (on OpenCV's ChArUco views: the same focal length,
principal point and sigmas), and a camera that OpenCV and COLMAP read without conversion.

Target: chessboard COLUMNS x ROWS inner corners, SPACING the square side; ChArUco COLUMNS x ROWS
squares, SPACING the square side, MARKER the marker side; ArUco grid board COLUMNS x ROWS
markers, SPACING the marker side, MARKER the gap between markers. The field is fixed (its
nominal coordinates) or free (estimated; datum: the origin corner and the end of the first row
held at their nominal coordinates, which sets the scale from the square size, and the start of
the last row held in the plane Z = 0).

Outputs: the camera JSON (a fisheye camera is taken by control chips, orthorectify (and so
the orthomosaic), monoplot, the bundle adjustment (self-calibrating its lens), the resection
(from control points; its straight lines stay perspective-only) and the tie points (verified
on the camera's rays: 0.021-0.033 px from the truth, refined, on simulated fisheye blocks),
the equidistant one by the COLMAP export; the algorithms still perspective-only refuse it by
name: boresight calibration, control point location), a report JSON (sigmas, correlations,
sigma0, the t-test of every lens coefficient, per-view RMS and poses), the same as an HTML
page, and the residual table (CSV). PIXEL_SIZE only scales the millimetre values of the
camera file: the calibration itself is in pixels.""",
    params=(
        images_param("Target images (files or folders)"),
        enum_param(
            "TARGET",
            "Target",
            _T.kind,
            "TARGET_KINDS",
            labels=("chessboard", "ChArUco board", "ArUco grid board"),
        ),
        Param(
            "COLUMNS",
            "integer",
            "Columns (inner corners / squares / markers)",
            _T.cols,
            minimum=2,
            maximum=200,
        ),
        Param(
            "ROWS",
            "integer",
            "Rows (inner corners / squares / markers)",
            _T.rows,
            minimum=2,
            maximum=200,
        ),
        Param(
            "SPACING",
            "number",
            "Square side (ArUco: marker side)",
            _T.spacing_m,
            unit="m",
            minimum=1e-4,
            maximum=10.0,
        ),
        Param(
            "MARKER",
            "number",
            "ChArUco marker side / ArUco gap",
            _T.marker_m,
            unit="m",
            minimum=0.0,
            maximum=10.0,
        ),
        enum_param("DICTIONARY", "ArUco dictionary", _T.dictionary, "DICTIONARIES"),
        Param(
            "PROJECTION",
            "enum",
            "Projection",
            _D.projection,
            options=Ref("geometry.projection_names", "PROJECTIONS"),
            labels=(
                "perspective (central)",
                "fisheye: equidistant",
                "fisheye: equisolid-angle",
                "fisheye: orthographic",
                "fisheye: stereographic",
            ),
        ),
        enum_param(
            "LENS_MODEL",
            "Lens model",
            _D.lens_model,
            "LENS_MODELS",
            labels=(
                "Brown-Conrady correction (photogrammetric)",
                "OpenCV / COLMAP distortion (perspective)",
            ),
            help="the same coefficients k1 k2 k3 p1 p2 in either direction: Brown-Conrady "
            "corrects the measured point, OpenCV's model distorts the ideal one (the camera "
            "then goes to OpenCV or COLMAP unchanged); OpenCV's model only with the "
            "perspective projection",
            advanced=True,
        ),
        enum_param(
            "LENS_PARAMETERS",
            "Lens coefficients estimated",
            _D.lens_parameters,
            "LENS_NAMES",
            multiple=True,
            help="coefficients of the lens model; the others are held at zero",
        ),
        enum_param(
            "FIELD",
            "Target field",
            _D.field,
            "FIELD_MODES",
            labels=("fixed (nominal coordinates)", "free (estimated, minimal datum)"),
            advanced=True,
        ),
        Param("PIXEL_SIZE", "number", "Pixel size", 0.003, unit="mm", minimum=0.0005, maximum=0.5),
        Param(
            "SIGMA_PX",
            "number",
            "A-priori sigma of a detected point",
            _D.sigma_px,
            unit="px",
            minimum=0.001,
            maximum=10.0,
            advanced=True,
        ),
        Param("CAMERA_NAME", "string", "Camera name", "camera", advanced=True),
        json_out("OUTPUT_CAMERA", "Calibrated camera (JSON)", optional=False),
        json_out("OUTPUT_REPORT", "Calibration report (JSON)", on_demand=True, advanced=True),
        html_out("OUTPUT_HTML", "Calibration report (HTML)", on_demand=True),
        csv_out("OUTPUT_RESIDUALS", "Residuals per point (CSV)", on_demand=True, advanced=True),
    ),
    results=(
        Result("VIEW_COUNT", "number", "Views used"),
        Result("POINT_COUNT", "number", "Target points used"),
        Result("RMS_PX", "number", "Reprojection RMS (px)"),
        Result("SIGMA0", "number", "Sigma0 (a-priori 1)"),
        Result("FOCAL_PX", "number", "Focal length (px)"),
    ),
    tags=(
        "camera calibration",
        "fisheye",
        "chessboard",
        "charuco",
        "aruco",
        "brown",
        "self-calibration",
        "interior orientation",
    ),
    references=(
        "Schneider, Schwalbe & Maas (2009)",
        "Brown (1971)",
        "Zhang (2000)",
        "Garrido-Jurado et al. (2014)",
    ),
)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the images, detect the target, calibrate, write the camera, report and residuals."""
    from ..errors import InputError
    from ..io.images import list_image_files
    from ..photo.calibration_targets import TargetSpec, target_field
    from ..photo.camera_calibration import CalibrationOptions, calibrate_camera
    from .runner import stages

    spec = options_from(TargetSpec, SPEC, v)
    opts = options_from(CalibrationOptions, SPEC, v)
    fld = target_field(spec)
    images = list_image_files(v.images)
    detect, adjust = stages(progress, 0.7, 0.3)
    detections, size = _detect(images, spec, detect, should_stop)
    found = sum(d.ids.size > 0 for d in detections)
    if found == 0:
        raise InputError(
            f"the {v.target} target ({v.columns} x {v.rows}) was found in none "
            f"of the {len(images)} images"
        )
    result = calibrate_camera(
        fld,
        detections,
        size[0],
        size[1],
        v.pixel_size,
        opts,
        name=v.camera_name,
        progress=adjust,
        should_stop=should_stop,
    )
    missing = [d.image for d in detections if d.ids.size == 0]
    if missing:
        result.warnings.insert(
            0, f"target not found in {len(missing)} image(s): " + ", ".join(missing)
        )
    _write_outputs(out, result, spec, opts, len(images), found)
    cam = result.camera
    ppx, ppy = cam.principal_point_px
    s = result.sigmas
    lines = [
        f"{len(result.view_names)} views ({found} of {len(images)} images with the target), "
        f"{result.n_points} points; RMS {result.rms_px:.3f} px, sigma0 {result.sigma0:.3f}",
        f"{cam.projection}: f {cam.focal_px:.3f} +- {s['focal_mm'] / cam.pixel_size_mm:.3f} px, "
        f"principal point ({ppx:.2f}, {ppy:.2f}) px",
        *result.warnings,
    ]
    return JobResult(
        results={
            "VIEW_COUNT": len(result.view_names),
            "POINT_COUNT": result.n_points,
            "RMS_PX": result.rms_px,
            "SIGMA0": result.sigma0,
            "FOCAL_PX": cam.focal_px,
        },
        lines=lines,
        data=result,
    )


def _detect(images: list, spec, progress, should_stop) -> tuple:
    """(the target's detection in each image, the images' common (width, height) in pixels),
    refused when an image's size differs from the first's."""
    from ..errors import InputError, stop_if_asked
    from ..io.calibration import read_image_grey
    from ..photo.calibration_targets import detect_target

    detections, size = [], None
    for i, path in enumerate(images):
        stop_if_asked(should_stop, "detecting the target")
        img = read_image_grey(path)
        shape = (img.shape[1], img.shape[0])
        if size is None:
            size = shape
        elif shape != size:
            raise InputError(
                f"image size {shape[0]} x {shape[1]} differs from that of the "
                f"first image ({size[0]} x {size[1]}): one camera, one size",
                path=str(path),
            )
        detections.append(detect_target(img, spec, path.name))
        if progress:
            progress((i + 1) / len(images))
    return detections, size


def _write_outputs(out, result, spec, opts, n_images: int, found: int) -> None:
    """The camera file and the requested report, HTML page and residuals."""
    from ..io.calibration import write_report_json, write_residuals_csv
    from ..io.camera import write_cameras_json

    extra = {
        "target": {
            "kind": spec.kind,
            "columns": spec.cols,
            "rows": spec.rows,
            "spacing_m": spec.spacing_m,
            "marker_m": spec.marker_m,
            "dictionary": spec.dictionary if spec.kind != "chessboard" else None,
        },
        "field": opts.field,
        "images": n_images,
        "images_with_target": found,
    }
    write_cameras_json(
        out.path("OUTPUT_CAMERA"),
        [result.camera],
        sigmas=[result.sigmas],
        extra={
            "calibration": {
                "rms_px": result.rms_px,
                "sigma0": result.sigma0,
                "views": len(result.view_names),
                "points": result.n_points,
            }
        },
    )
    if out.requested("OUTPUT_REPORT"):
        write_report_json(out.path("OUTPUT_REPORT"), result, extra)
    if out.requested("OUTPUT_HTML"):
        from ..io.atomic import write_text_atomic
        from ..quality.calibration_html import render_calibration_html

        settings = {
            "images": f"{n_images} ({found} with the target)",
            "target": f"{spec.kind} {spec.cols} x {spec.rows}, spacing {spec.spacing_m:g} m",
            "field": opts.field,
            "lens model": opts.lens_model,
            "lens coefficients": ", ".join(opts.lens_parameters) or "none",
            "initial values": result.initial["method"],
        }
        write_text_atomic(out.path("OUTPUT_HTML"), render_calibration_html(result, settings))
    if out.requested("OUTPUT_RESIDUALS"):
        write_residuals_csv(out.path("OUTPUT_RESIDUALS"), result)
