"""``importcolmap``: a COLMAP sparse model (text or binary) as the project's camera JSON, EO,
observation table and points."""

from __future__ import annotations

import logging

from .common import csv_out, json_out
from .runner import JobResult
from .spec import AlgorithmSpec, Param, Ref, Result, Values

log = logging.getLogger(__name__)

COLMAP_FILTER = "COLMAP cameras (cameras.txt cameras.bin);;All files (*)"

#: The tables every block import writes (importcolmap, importopensfm).
BLOCK_OUTPUTS = (
    json_out("OUTPUT_CAMERA", "Cameras (JSON)"),
    csv_out("OUTPUT_EO", "Exterior orientation table (CSV)"),
    csv_out("OUTPUT_OBSERVATIONS", "Observations (tie points, CSV)"),
    csv_out("OUTPUT_POINTS", "3D points (ground point table, CSV)", on_demand=True),
)


def pixel_size_param(help: str) -> Param:
    """The importers' PIXEL_SIZE (mm): the file states none (or, for Metashape, may not), so
    it only sets the camera's millimetres, never the projection."""
    return Param(
        "PIXEL_SIZE",
        "number",
        "Pixel size",
        Ref("io.colmap_names", "DEFAULT_PIXEL_SIZE_MM"),
        unit="mm",
        minimum=0.0005,
        maximum=0.5,
        help=help,
    )


def block_results(images: str) -> tuple[Result, ...]:
    """The counts a block import reports; ``images`` names the image count."""
    return (
        Result("IMAGE_COUNT", "number", images),
        Result("CAMERA_COUNT", "number", "Number of cameras"),
        Result("POINT_COUNT", "number", "Number of 3D points"),
    )


SPEC = AlgorithmSpec(
    name="importcolmap",
    title="Import COLMAP model",
    group="Aerotriangulation",
    group_id="aerotriangulation",
    summary="COLMAP sparse model (text or binary) -> cameras, orientations, tie points",
    description="""\
Reads a COLMAP sparse model (cameras, images and points3D, as text or binary files) and
writes the project's camera JSON, exterior orientation, observation table and points, with
the lens models converted exactly: COLMAP's distortion maps ideal to measured coordinates,
and each camera gets the forward lens model with COLMAP's own coefficients (docs/formats.md,
COLMAP). SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV,
OPENCV_FISHEYE, SIMPLE_RADIAL_FISHEYE, RADIAL_FISHEYE and THIN_PRISM_FISHEYE are supported;
FOV and RAD_TAN_THIN_PRISM_FISHEYE are refused by name.

## Frame
A COLMAP model has no coordinate reference system: FRAME states it, and a model without one
is refused. LOCAL: the coordinates as they are (no CRS); ECEF (as COLMAP's model aligner
writes it): converted into the mapping CRS given as CRS; or the CRS the coordinates are in
(e.g. EPSG:32723: easting, northing, height). SIMILARITY (s qw qx qy qz tx ty tz) is applied
first, model -> frame (X' = s R(q) X + t).

## Inputs
INPUT: the model's cameras.txt or cameras.bin (or its folder); images and points3D are read
beside it. PIXEL_SIZE: COLMAP has none; it scales the millimetres, never the projection.

## Outputs
OUTPUT_CAMERA: the cameras (colmap_<id>); OUTPUT_EO: one row per registered image (image_id =
COLMAP's image name, with a camera column when there are several); OUTPUT_OBSERVATIONS: the
tracked keypoints as tie rows (point_id = COLMAP's 3D point id); OUTPUT_POINTS: the 3D points
as a ground point table with role check (triangulated tie points, never control).""",
    params=(
        Param(
            "INPUT", "file", "COLMAP model (cameras.txt or cameras.bin)", file_filter=COLMAP_FILTER
        ),
        Param(
            "FRAME",
            "string",
            "Frame of the model's coordinates",
            "",
            help="LOCAL, ECEF (with CRS) or a CRS (EPSG code or WKT); required",
        ),
        Param(
            "CRS",
            "crs",
            "Mapping CRS (for ECEF)",
            optional=True,
            help="the projected CRS an ECEF model is converted to",
        ),
        Param(
            "SIMILARITY",
            "string",
            "Similarity model -> frame",
            "",
            optional=True,
            help="s qw qx qy qz tx ty tz (X' = s R(q) X + t); empty: none",
        ),
        pixel_size_param("COLMAP stores none: it sets the millimetres of the camera"),
        *BLOCK_OUTPUTS,
    ),
    results=block_results("Number of registered images"),
    tags=("colmap", "structure from motion", "sfm", "import", "opencv", "lens"),
    references=("Schönberger & Frahm (2016)",),
)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the COLMAP model, convert it in the stated frame, write the requested tables."""
    from pathlib import Path

    from ..io.colmap import read_colmap_model
    from ..io.colmap_block import block_from_colmap, frame_from_text

    frame = frame_from_text(v.frame, v.crs or "", v.similarity or "")
    folder = Path(v.input)
    model = read_colmap_model(folder if folder.is_dir() else folder.parent)
    block = block_from_colmap(model, frame, v.pixel_size)
    return finish_import(block, out, progress, "images")


def finish_import(block, out, progress, images: str) -> JobResult:
    """Log the counts, write the requested tables (the EO to stdout when none is), report."""
    from ..io.orientation import eo_csv_text

    log.info(
        "%d %s, %d cameras, %d points",
        len(block.eo),
        images,
        len(block.cameras),
        len(block.points.point_id),
    )
    result = JobResult(
        results={
            "IMAGE_COUNT": len(block.eo),
            "CAMERA_COUNT": len(block.cameras),
            "POINT_COUNT": len(block.points.point_id),
        },
        data=block,
    )
    _write_outputs(block, out, result.lines)
    if not result.lines:
        result.stdout = eo_csv_text(block.eo)
    if progress is not None:
        progress(1.0)
    return result


def _write_outputs(block, out, lines: list) -> None:
    from ..io.camera import write_cameras_json
    from ..io.ground_points import write_ground_points_csv
    from ..io.observations import write_observations_csv
    from ..io.orientation import EO_COLUMNS, _eo_rows
    from ..io.tables import write_csv_atomic

    def eo(path: str, blk) -> None:
        several = len(blk.cameras) > 1
        cols = EO_COLUMNS + (("camera",) if several else ())
        rows = (r + ((c,) if several else ()) for r, c in zip(_eo_rows(blk.eo), blk.camera))
        write_csv_atomic(path, cols, rows)

    for name, write, count in (
        ("OUTPUT_CAMERA", lambda p, b: write_cameras_json(p, b.cameras), len(block.cameras)),
        ("OUTPUT_EO", eo, len(block.eo)),
        (
            "OUTPUT_OBSERVATIONS",
            lambda p, b: write_observations_csv(p, b.observations),
            len(block.observations.image_id),
        ),
        (
            "OUTPUT_POINTS",
            lambda p, b: write_ground_points_csv(p, b.points),
            len(block.points.point_id),
        ),
    ):
        if out.requested(name):
            write(out.path(name), block)
            lines.append(f"{count} rows -> {out.target(name)}")
