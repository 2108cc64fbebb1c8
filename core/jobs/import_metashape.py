"""``importmetashape``: an Agisoft Metashape camera XML (Export Cameras > Agisoft XML) as the
project's camera JSON, EO, marker observations and ground points."""

from __future__ import annotations

import logging

from .common import choice_param
from .import_colmap import BLOCK_OUTPUTS, block_results, finish_import, pixel_size_param
from .runner import JobResult
from .spec import AlgorithmSpec, Param, Result, Values

log = logging.getLogger(__name__)

SPEC = AlgorithmSpec(
    name="importmetashape",
    title="Import Agisoft Metashape cameras (XML)",
    group="Aerotriangulation",
    group_id="aerotriangulation",
    summary="Metashape camera XML -> cameras (exact lens model), orientations, markers",
    description="""\
Reads the camera file Agisoft Metashape writes with File > Export > Export Cameras (Agisoft
XML) and writes the project's camera JSON, exterior orientation and markers, with the lens model
converted exactly: each calibrated sensor gets the forward lens model of Metashape's own
equations and coefficients (f, cx, cy, k1-k4, p1, p2, b1, b2; docs/formats.md, Metashape).
Frame and fisheye sensors are supported; spherical, cylindrical and RPC sensors and nonzero
p3, p4 are refused by name.

## Frame
The chunk's transform (Metashape 2: each component's) takes the cameras to the chunk's
CRS: geocentric (ECEF) for a geographic or projected CRS, converted into CRS (empty: the
chunk's CRS when it is projected; a geographic chunk needs one, e.g. its UTM zone); local
coordinates (LOCAL_CS) stay as they are (LOCAL, no CRS; CRS must be empty).

## Skipped cameras
A camera without a transform (not aligned), whose sensor is missing or uncalibrated, or in a
component without a transform, is skipped and named in the log; so are the cameras of the
components other than the active one of a local chunk (their frames differ).

## Outputs
OUTPUT_CAMERA: the cameras (metashape_<sensor id>); OUTPUT_EO: one row per imported camera
(image_id = the camera's label, or its file name with IMAGE_NAMES file; with a camera column
when there are several sensors);
OUTPUT_OBSERVATIONS: the markers' pinned locations on the imported cameras (type control for a
marker with reference coordinates, tie without; point_id = the marker's label);
OUTPUT_POINTS: the markers' reference coordinates in CRS as a ground point table (role
control when the reference is enabled in Metashape, check when not; the marker accuracy as
sigma). The camera XML has no tie points.""",
    params=(
        Param(
            "INPUT",
            "file",
            "Metashape camera file (XML)",
            file_filter="Metashape cameras (*.xml);;All files (*)",
        ),
        Param(
            "CRS",
            "crs",
            "Mapping CRS",
            optional=True,
            help="the projected CRS to convert to; empty: the chunk's own (projected) CRS",
        ),
        pixel_size_param(
            "used when a sensor states no pixel_width: it sets the "
            "millimetres of the camera, never the projection"
        ),
        choice_param(
            "IMAGE_NAMES",
            "Image names in the EO",
            "io.colmap_names",
            "METASHAPE_IMAGE_NAMES",
            help="label: the camera labels as Metashape shows them; file: their file names "
            "without folder and extension (how orthorectify and the picking dock find images)",
        ),
        *BLOCK_OUTPUTS,
    ),
    results=(
        *block_results("Number of imported cameras"),
        Result("SKIPPED_COUNT", "number", "Number of skipped cameras"),
    ),
    tags=("metashape", "agisoft", "photoscan", "structure from motion", "import", "lens"),
    references=("Agisoft (2024)",),
)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the camera XML, convert it (LOCAL or into CRS), write the requested tables."""
    from ..io.metashape import block_from_metashape, read_metashape

    chunk = read_metashape(v.input)
    block, skipped = block_from_metashape(chunk, v.crs or "", v.pixel_size, v.image_names)
    result = finish_import(block, out, progress, "cameras")
    result.results["SKIPPED_COUNT"] = len(skipped)
    if skipped:
        result.lines.append(
            f"{len(skipped)} cameras skipped: "
            + "; ".join(f"{label} ({why})" for label, why in skipped[:20])
        )
    return result
