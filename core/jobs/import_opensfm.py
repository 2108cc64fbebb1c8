"""``importopensfm``: an OpenSfM / ODM reconstruction (reconstruction.json) as the project's
camera JSON, EO, observation table and points."""

from __future__ import annotations

import logging

from .import_colmap import BLOCK_OUTPUTS, block_results, finish_import, pixel_size_param
from .runner import JobResult
from .spec import AlgorithmSpec, Param, Values

log = logging.getLogger(__name__)

SPEC = AlgorithmSpec(
    name="importopensfm",
    title="Import OpenSfM / ODM reconstruction",
    group="Aerotriangulation",
    group_id="aerotriangulation",
    summary="OpenSfM or ODM reconstruction.json -> cameras, orientations, tie points",
    description="""\
Reads an OpenSfM reconstruction (reconstruction.json, as OpenSfM and OpenDroneMap write it,
with tracks.csv beside it when present) and writes the project's camera JSON, exterior
orientation, observation table and points, with the lens models converted exactly: OpenSfM's
distortion maps ideal to measured coordinates, and each camera gets the forward lens model
with OpenSfM's own coefficients (docs/formats.md, OpenSfM). The perspective, simple_radial,
radial, brown, fisheye and fisheye_opencv projection types are supported; spherical, dual and
fisheye62/624 are refused by name.

## Frame
OpenSfM's coordinates are topocentric (east, north, up) at reference_lla. CRS empty: they
are kept as they are (LOCAL, no CRS); a projected CRS (e.g. EPSG:32723): they are converted
into it through ECEF, with each orientation turned to the grid frame at its centre.

## Inputs
INPUT: reconstruction.json (or its folder); RECONSTRUCTION: which of its reconstructions (0:
the first, the largest). PIXEL_SIZE: OpenSfM has none; it scales the millimetres, never the
projection.

## Outputs
OUTPUT_CAMERA: the cameras (opensfm_<id>); OUTPUT_EO: one row per shot (image_id = the shot's
image name, with a camera column when there are several); OUTPUT_OBSERVATIONS: the tracks of
tracks.csv as tie rows (point_id = the track id); OUTPUT_POINTS: the 3D points as a ground
point table with role check (triangulated tie points, never control).""",
    params=(
        Param(
            "INPUT",
            "file",
            "OpenSfM reconstruction (reconstruction.json)",
            file_filter="OpenSfM reconstruction (*.json);;All files (*)",
        ),
        Param(
            "CRS",
            "crs",
            "Mapping CRS",
            optional=True,
            help="the projected CRS to convert to; empty: the topocentric frame (LOCAL)",
        ),
        Param(
            "RECONSTRUCTION",
            "integer",
            "Reconstruction index",
            0,
            minimum=0,
            help="which reconstruction of the file (0: the first)",
        ),
        pixel_size_param("OpenSfM stores none: it sets the millimetres of the camera"),
        *BLOCK_OUTPUTS,
    ),
    results=block_results("Number of shots"),
    tags=("opensfm", "odm", "opendronemap", "structure from motion", "sfm", "import", "lens"),
    references=("Mapillary (n. d.)",),
)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the reconstruction, convert it (LOCAL or into CRS), write the requested tables."""
    from ..io.opensfm import block_from_opensfm, read_opensfm

    rec = read_opensfm(v.input, int(v.reconstruction))
    block = block_from_opensfm(rec, v.crs or "", v.pixel_size)
    return finish_import(block, out, progress, "shots")
