"""``exportcolmap``: the project's cameras and orientations (and tie points) as a COLMAP text
model."""

from __future__ import annotations

from .common import block_export_params
from .runner import JobResult
from .spec import AlgorithmSpec, Param, Result, Values

SPEC = AlgorithmSpec(
    name="exportcolmap",
    title="Export COLMAP model",
    group="Aerotriangulation",
    group_id="aerotriangulation",
    summary="Cameras + exterior orientation (+ observations, points) -> COLMAP text model",
    description="""\
Writes cameras.txt, images.txt and points3D.txt in OUTPUT_FOLDER, so a block oriented or
calibrated here continues in COLMAP (or the tools that read its models: OpenMVS, Gaussian
splatting). Cameras are written exactly: no lens (SIMPLE_PINHOLE), the forward models opencv
(OPENCV, or FULL_OPENCV with k3), opencv_full (FULL_OPENCV), and with the equidistant
projection opencv_fisheye (OPENCV_FISHEYE) and thin_prism_fisheye (THIN_PRISM_FISHEYE),
their coefficients renormalised exactly to the current focal length; a correction lens model
(brown_conrady and the other photogrammetric ones) has no exact COLMAP model and is refused
by name.

Orientations are written as COLMAP's world-to-camera quaternion and translation in the EO's
own coordinates (the mapping CRS; COLMAP stores no CRS: import it back with FRAME = that
CRS). OBSERVATIONS become each image's keypoints, tracked to the POINTS (a ground point table,
e.g. importcolmap's OUTPUT_POINTS) that share their point_id; the others are untracked.""",
    params=(
        *block_export_params(),
        Param("OUTPUT_FOLDER", "folder_out", "Output folder (the COLMAP model)"),
    ),
    results=(
        Result("IMAGE_COUNT", "number", "Number of images"),
        Result("POINT_COUNT", "number", "Number of 3D points"),
    ),
    tags=("colmap", "structure from motion", "sfm", "export", "opencv", "lens"),
    references=("Schönberger & Frahm (2016)",),
)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the camera, EO (and observations, points), write the COLMAP text model."""
    from ..io.camera import read_cameras_json
    from ..io.colmap import write_colmap_text
    from ..io.colmap_block import colmap_from_block
    from ..io.ground_points import read_ground_points_csv
    from ..io.observations import read_observations_csv
    from ..io.orientation import read_eo_csv_full

    cams = read_cameras_json(v.camera, projections=("perspective", "equidistant"))
    eo = read_eo_csv_full(v.eo)
    obs = read_observations_csv(v.observations) if v.observations else None
    points = read_ground_points_csv(v.points) if v.points else None
    model = colmap_from_block(cams, eo.eo, eo.camera, obs, points)
    write_colmap_text(v.output_folder, model)
    lines = [
        f"{len(model.images)} images, {len(model.cameras)} camera(s), "
        f"{len(model.points)} points -> {v.output_folder}"
    ]
    if progress is not None:
        progress(1.0)
    return JobResult(
        results={"IMAGE_COUNT": len(model.images), "POINT_COUNT": len(model.points)}, lines=lines
    )
