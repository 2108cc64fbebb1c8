"""``importpix4d``: Pix4D's calibrated camera parameters (``..._calibrated_camera_parameters.txt``
with ``..._offset.xyz``) as the project's camera JSON and EO."""

from __future__ import annotations

import logging

from .common import choice_param
from .import_colmap import BLOCK_OUTPUTS, block_results, finish_import, pixel_size_param
from .runner import JobResult
from .spec import AlgorithmSpec, Param, Values

log = logging.getLogger(__name__)


SPEC = AlgorithmSpec(
    name="importpix4d",
    title="Import Pix4D calibrated cameras",
    group="Aerotriangulation",
    group_id="aerotriangulation",
    summary="Pix4D calibrated_camera_parameters.txt -> cameras (exact lens model), orientations",
    description="""\
Reads the file PIX4Dmapper writes in 1_initial/params, <project>_calibrated_camera_parameters.txt
(per image: K, radial R1 R2 R3, tangential T1 T2, position t and rotation R, with
m = K [R | -R t] X on the coordinates minus <project>_offset.xyz), and writes the project's
camera JSON and exterior orientation with the lens converted exactly: the forward OpenCV
model with Pix4D's coefficients (k1..k3 = R1..R3, p1 = T1, p2 = T2; docs/formats.md, Pix4D).
Images with the same K and coefficients share a camera. A K with skew is refused by name.

## Assumptions
Pix4D's documentation found does not state the pixel origin of K nor show the distortion
formula in the y-down frame of this file: the tangential terms are read as OpenCV's in that
frame, and PIXEL_ORIGIN says whether K's pixels start at the image's corner (default) or at
the centre of the first pixel.

## Frame
OFFSET: the <project>_offset.xyz (empty: the one beside INPUT; none found: no offset, said in
the log). CRS: the output CRS Pix4D used (empty: the <project>_wkt.prj beside INPUT when there
is one, else LOCAL); the coordinates are its easting, northing and height.

## Outputs
OUTPUT_CAMERA: the cameras (pix4d_1, pix4d_2, ...); OUTPUT_EO: one row per image (image_id =
the image's file name as Pix4D writes it; with a camera column when there are several). The
file has no tie points.""",
    params=(
        Param(
            "INPUT",
            "file",
            "Pix4D calibrated camera parameters (TXT)",
            file_filter="Pix4D calibrated cameras (*_calibrated_camera_parameters.txt);;"
            "All files (*)",
        ),
        Param(
            "OFFSET",
            "file",
            "Pix4D offset (XYZ)",
            optional=True,
            file_filter="Pix4D offset (*_offset.xyz);;All files (*)",
            help="empty: <project>_offset.xyz beside INPUT",
        ),
        Param(
            "CRS",
            "crs",
            "Output CRS of the Pix4D project",
            optional=True,
            help="empty: <project>_wkt.prj beside INPUT, else LOCAL",
        ),
        pixel_size_param(
            "the file states none: it sets the millimetres of the camera, never the projection"
        ),
        choice_param(
            "PIXEL_ORIGIN",
            "Pixel origin of K",
            "io.colmap_names",
            "PIX4D_PIXEL_ORIGINS",
            help="corner: K's pixel coordinates start at the image's top-left corner; "
            "centre: the first pixel's centre is (0, 0)",
        ),
        *BLOCK_OUTPUTS,
    ),
    results=block_results("Number of imported images"),
    tags=("pix4d", "pix4dmapper", "structure from motion", "import", "lens"),
    references=("Pix4D (2024)",),
)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the file and its offset, convert them (in CRS or LOCAL), write the tables."""
    from ..io.pix4d import block_from_pix4d, companion_files, read_pix4d

    offset, crs, notes = companion_files(v.input, v.offset or None, v.crs or "")
    for note in notes:
        log.info(note)
    block = block_from_pix4d(read_pix4d(v.input), offset, crs, v.pixel_size, v.pixel_origin)
    result = finish_import(block, out, progress, "images")
    result.lines.extend(notes)
    return result
