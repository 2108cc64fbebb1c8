"""``exportopensfm``: the project's cameras and orientations (and tie points) as an OpenSfM
``reconstruction.json`` (and ``tracks.csv``)."""

from __future__ import annotations

from .common import block_export_params
from .runner import JobResult
from .spec import AlgorithmSpec, Param, Result, Values

SPEC = AlgorithmSpec(
    name="exportopensfm",
    title="Export OpenSfM reconstruction",
    group="Aerotriangulation",
    group_id="aerotriangulation",
    summary="Cameras + exterior orientation (+ observations, points) -> OpenSfM reconstruction",
    description="""\
Writes reconstruction.json (and tracks.csv with OBSERVATIONS and POINTS) in OUTPUT_FOLDER, so
a block oriented or calibrated here continues in OpenSfM or ODM. Cameras are written exactly,
with the simplest OpenSfM type that holds them: perspective (centred, square, k1 k2), brown
(k1 k2 k3 p1 p2, focal_x/y, c_x/y) for the opencv lenses, fisheye or fisheye_opencv for the
equidistant projection with opencv_fisheye; their coefficients renormalised exactly to the
current focal length. A correction lens model (brown_conrady and the other photogrammetric
ones), metashape, thin_prism_fisheye and a rational opencv_full have no exact OpenSfM camera
and are refused by name (docs/formats.md, OpenSfM export).

Shots are OpenSfM's world-to-camera axis-angle rotation and translation. With CRS (the
EO's and the points' projected CRS) they are written in OpenSfM's topocentric frame (east,
north, up at reference_lla, the mean of the centres), the rotations turned from the grid
frame through ECEF; without CRS as they are (LOCAL, no reference_lla).
OBSERVATIONS of the POINTS (same point_id) become tracks.csv.""",
    params=(
        *block_export_params(),
        Param(
            "CRS",
            "crs",
            "CRS of the EO",
            optional=True,
            help="the projected CRS of the EO and points (written topocentric with "
            "reference_lla); empty: LOCAL, written as they are",
        ),
        Param("OUTPUT_FOLDER", "folder_out", "Output folder (reconstruction.json)"),
    ),
    results=(
        Result("IMAGE_COUNT", "number", "Number of images"),
        Result("POINT_COUNT", "number", "Number of 3D points"),
    ),
    tags=("opensfm", "odm", "opendronemap", "structure from motion", "sfm", "export", "lens"),
    references=("Mapillary (n. d.)",),
)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the camera, EO (and observations, points), write the OpenSfM reconstruction."""
    from ..io.camera import read_cameras_json
    from ..io.ground_points import read_ground_points_csv
    from ..io.observations import read_observations_csv
    from ..io.opensfm_export import opensfm_from_block, write_opensfm
    from ..io.orientation import read_eo_csv_full

    cams = read_cameras_json(v.camera, projections=("perspective", "equidistant"))
    eo = read_eo_csv_full(v.eo, v.crs or "")
    obs = read_observations_csv(v.observations) if v.observations else None
    points = read_ground_points_csv(v.points) if v.points else None
    rec, tracks = opensfm_from_block(cams, eo.eo, eo.camera, obs, points)
    path = write_opensfm(v.output_folder, rec, tracks)
    n_img, n_pts = len(rec[0]["shots"]), len(rec[0]["points"])
    lines = [f"{n_img} images, {len(rec[0]['cameras'])} camera(s), {n_pts} points -> {path}"]
    if progress is not None:
        progress(1.0)
    return JobResult(results={"IMAGE_COUNT": n_img, "POINT_COUNT": n_pts}, lines=lines)
