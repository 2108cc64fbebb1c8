"""Typical chains of algorithms: the "How to use" section of every algorithm's help.

Each :class:`Workflow` is a chain of steps (algorithm id, what the step takes and gives, in the
step's own parameter names). The help of an algorithm (QGIS and ``lidarphoto <alg> --help``)
lists every workflow it belongs to, with its own step marked, so a new algorithm gets a "How
to use" section by joining a workflow here (``tests/core/test_help.py`` checks that every
algorithm is in one, that every id exists and that every parameter name a note gives is a
parameter of that step).
"""

from __future__ import annotations

import textwrap
from collections.abc import Callable
from dataclasses import dataclass

#: The catalogue context of these texts (scripts/i18n.py): the help's, ``spec.TR_CONTEXT``
#: (not imported: spec imports this module; tests/core/test_help.py checks they agree).
TR_CONTEXT = "AlgorithmHelp"


def _t(text: str) -> str:
    """Marks a text for the translation catalogue; :func:`how_to_use` translates it."""
    return text


#: Width of the help text (the descriptions of the specs are wrapped at this width).
_WIDTH = 95


@dataclass(frozen=True)
class Workflow:
    """A chain of algorithms: ``steps`` are (algorithm id, note) in the order a user runs
    them; a note names the step's own parameters (upper case) where it takes or gives files."""

    title: str
    steps: tuple[tuple[str, str], ...]

    @property
    def ids(self) -> tuple[str, ...]:
        return tuple(alg for alg, _ in self.steps)

    def chain(self, mark: str = "") -> str:
        """``a -> b -> [c] -> d`` with ``mark`` in brackets.

        >>> Workflow("x", (("a", ""), ("b", ""))).chain("b")
        'a -> [b]'
        """
        return " -> ".join(f"[{a}]" if a == mark else a for a in self.ids)


#: steps shared by two workflows (one message each in the catalogue)
_CHIPS_STEP = (
    "makecontrolchips",
    _t(
        "POINTS = the surveyed control, PHOTOS = ground photos of each point with and without the "
        "control plate, CAMERA = the ground camera; OUTPUT_FOLDER = one chip per point at the GSD "
        "of the aerial images"
    ),
)
_LOCATE_STEP = (
    "locatecontrolpoints",
    _t(
        "CHIPS = one GeoTIFF chip per control point, CONTROL_POINTS, CAMERA, approximate EO, "
        "IMAGES; OUTPUT = the control points' image observations, without clicking them"
    ),
)
_ROOF_PLANES_STEP = (
    "extractroofplanes",
    _t(
        "INPUT = the classified cloud; OUTPUT_CSV = the plane table, "
        "OUTPUT_CLOUD = the cloud with plane_id"
    ),
)

WORKFLOWS: tuple[Workflow, ...] = (
    Workflow(
        _t("Boresight calibration with LiDAR control (Pedrosa & dos Santos 2020)"),
        (
            (
                "trajectorytoeo",
                _t(
                    "INPUT = the GNSS/INS trajectory CSV; OUTPUT_CSV = the "
                    "exterior orientation of every image"
                ),
            ),
            (
                "groundfilter",
                _t(
                    "INPUT = the LAS/LAZ; OUTPUT_CLOUD = the cloud classified into "
                    "ground (2) and non-ground"
                ),
            ),
            _ROOF_PLANES_STEP,
            (
                "createlcps",
                _t(
                    "PLANES and CLOUD = the two outputs of extractroofplanes; "
                    "POINTS_CSV and LINES_CSV = LiDAR control points and lines"
                ),
            ),
            (
                "boresightcalibration",
                _t(
                    "TRAJECTORY = the exterior orientation, PLANES / LINES / "
                    "LCPS = the control, OBSERVATIONS = image measurements made in the picking "
                    "dock; "
                    "OUTPUT_TABLE = boresight per group, OUTPUT_EO = corrected orientation"
                ),
            ),
            (
                "accuracyreport",
                _t(
                    "INPUT = check points measured with the corrected orientation; "
                    "OUTPUT_HTML and OUTPUT_JSON = the accuracy figures against the standards"
                ),
            ),
        ),
    ),
    Workflow(
        _t("Monoplotting on a LiDAR surface (dos Santos, Dal Poz & Dalmolin 2010)"),
        (
            (
                "groundfilter",
                _t(
                    "INPUT = the LAS/LAZ; OUTPUT_DTM = the terrain model (or use the "
                    "cloud itself as DSM)"
                ),
            ),
            (
                "extractroofplanes",
                _t("OUTPUT_CSV = roof planes, used by monoplot for points on roofs"),
            ),
            (
                "resection",
                _t(
                    "OBSERVATIONS + CONTROL_POINTS (or lines) of one image; OUTPUT_EO = "
                    "its exterior orientation"
                ),
            ),
            (
                "monoplot",
                _t(
                    "OBSERVATIONS of the image, EO, DSM (raster or LAS/LAZ), optional "
                    "PLANES; OUTPUT_CSV = 3D points"
                ),
            ),
            ("accuracyreport", _t("INPUT = monoplotted check points against their reference")),
        ),
    ),
    Workflow(
        _t("Aerial triangulation and orthophotos"),
        (
            (
                "calibratecamera",
                _t(
                    "IMAGES = views of a chessboard or ChArUco target; "
                    "OUTPUT_CAMERA = the camera JSON (start values for the block, or held fixed)"
                ),
            ),
            (
                "tiepoints",
                _t(
                    "IMAGES (and the approximate EO + CAMERA to pair images by their "
                    "footprints); OUTPUT_OBSERVATIONS = tie points for the bundle"
                ),
            ),
            _CHIPS_STEP,
            _LOCATE_STEP,
            (
                "bundleadjustment",
                _t(
                    "CAMERA, OBSERVATIONS, GROUND_POINTS, EO (approximate); "
                    "OUTPUT_EO = adjusted orientation, OUTPUT_CAMERA = calibrated camera"
                ),
            ),
            ("groundfilter", _t("OUTPUT_DTM = the terrain for the orthophotos")),
            (
                "orthorectify",
                _t(
                    "CAMERA and EO from the bundle, IMAGES, DSM = the DTM or DSM; "
                    "OUTPUT_FOLDER = one orthophoto per image"
                ),
            ),
            (
                "orthomosaic",
                _t(
                    "ORTHOPHOTOS = that folder; OUTPUT = the mosaic, SEAMLINES_CSV = "
                    "the region of each image"
                ),
            ),
            ("accuracyreport", _t("INPUT = check points measured on the mosaic")),
        ),
    ),
    Workflow(
        _t("A COLMAP block: orthophotos on the LiDAR DSM, and back to COLMAP"),
        (
            (
                "importcolmap",
                _t(
                    "INPUT = the model's cameras.txt or cameras.bin; FRAME = the "
                    "frame of its coordinates (LOCAL, ECEF with CRS, or a CRS); OUTPUT_CAMERA, "
                    "OUTPUT_EO, OUTPUT_OBSERVATIONS, OUTPUT_POINTS"
                ),
            ),
            (
                "orthorectify",
                _t(
                    "CAMERA and EO from the import, IMAGES, DSM = the LiDAR DSM; "
                    "OUTPUT_FOLDER = one orthophoto per image"
                ),
            ),
            (
                "exportcolmap",
                _t(
                    "CAMERA, EO (e.g. adjusted by bundleadjustment), OBSERVATIONS "
                    "and POINTS; OUTPUT_FOLDER = the COLMAP text model"
                ),
            ),
        ),
    ),
    Workflow(
        _t("An OpenSfM / ODM block: orthophotos on the LiDAR DSM"),
        (
            (
                "importopensfm",
                _t(
                    "INPUT = the reconstruction.json (ODM: opensfm/); CRS = the "
                    "mapping CRS (empty: topocentric, LOCAL); OUTPUT_CAMERA, OUTPUT_EO, "
                    "OUTPUT_OBSERVATIONS, OUTPUT_POINTS"
                ),
            ),
            (
                "orthorectify",
                _t(
                    "CAMERA and EO from the import, IMAGES, DSM = the LiDAR DSM; "
                    "OUTPUT_FOLDER = one orthophoto per image"
                ),
            ),
            (
                "exportopensfm",
                _t(
                    "CAMERA, EO (e.g. adjusted by bundleadjustment), "
                    "OBSERVATIONS and POINTS; OUTPUT_FOLDER = the reconstruction.json for "
                    "OpenSfM / ODM"
                ),
            ),
        ),
    ),
    Workflow(
        _t("A Metashape block: orthophotos on the LiDAR DSM"),
        (
            (
                "importmetashape",
                _t(
                    "INPUT = the camera XML (Export Cameras, Agisoft XML); "
                    "CRS = the mapping CRS (empty: the chunk's projected CRS); OUTPUT_CAMERA, "
                    "OUTPUT_EO"
                ),
            ),
            (
                "orthorectify",
                _t(
                    "CAMERA and EO from the import, IMAGES, DSM = the LiDAR DSM; "
                    "OUTPUT_FOLDER = one orthophoto per image"
                ),
            ),
        ),
    ),
    Workflow(
        _t("Boresight calibration without hand picks (automatic)"),
        (
            _ROOF_PLANES_STEP,
            (
                "createlcps",
                _t(
                    "PLANES and CLOUD = the two outputs of extractroofplanes; "
                    "LINES_CSV = the LiDAR ridge, hip and valley lines"
                ),
            ),
            (
                "tiepoints",
                _t(
                    "IMAGES (and the approximate EO + CAMERA to pair images by their "
                    "footprints); OUTPUT_OBSERVATIONS = tie points (optional for the next step)"
                ),
            ),
            (
                "autoboresight",
                _t(
                    "IMAGES, CAMERA, TRAJECTORY, LINES, PLANES and CLOUD, "
                    "TIE_POINTS; OUTPUT_TABLE = boresight per group, OUTPUT_OBSERVATIONS = the "
                    "observations found"
                ),
            ),
        ),
    ),
    Workflow(
        _t("A Pix4D block: orthophotos on the LiDAR DSM"),
        (
            (
                "importpix4d",
                _t(
                    "INPUT = <project>_calibrated_camera_parameters.txt (Pix4D's "
                    "1_initial/params, its offset beside it); CRS = the project's output CRS "
                    "(empty: "
                    "its _wkt.prj); OUTPUT_CAMERA, OUTPUT_EO"
                ),
            ),
            (
                "orthorectify",
                _t(
                    "CAMERA and EO from the import, IMAGES, DSM = the LiDAR DSM; "
                    "OUTPUT_FOLDER = one orthophoto per image"
                ),
            ),
        ),
    ),
    Workflow(
        _t("Boresight calibration from an SBET (or ASCII export) and the camera events"),
        (
            (
                "importtrajectory",
                _t(
                    "INPUT = the SBET, POSPac / Inertial Explorer export or "
                    "CSV; EVENTS = image_id, time; OUTPUT_TRAJECTORY = the trajectory table at the "
                    "events, OUTPUT_EO = the exterior orientation"
                ),
            ),
            (
                "boresightcalibration",
                _t(
                    "TRAJECTORY = that trajectory table, OBSERVATIONS = "
                    "image measurements of the control; OUTPUT_TABLE = boresight per group"
                ),
            ),
        ),
    ),
    Workflow(
        _t("Boresight calibration with surveyed ground control located automatically"),
        (
            (
                "trajectorytoeo",
                _t(
                    "INPUT = the GNSS/INS trajectory CSV; OUTPUT_CSV = the "
                    "exterior orientation of every image"
                ),
            ),
            _CHIPS_STEP,
            _LOCATE_STEP,
            (
                "boresightcalibration",
                _t(
                    "OBSERVATIONS = those control rows, GROUND_POINTS = the "
                    "surveyed points (role control or check), TRAJECTORY; OUTPUT_TABLE = boresight "
                    "per group, OUTPUT_EO = corrected orientation"
                ),
            ),
        ),
    ),
    Workflow(
        _t("LiDAR control for a whole block of tiles (dask.distributed)"),
        (
            (
                "lidarblock",
                _t(
                    "INPUT = a folder of LAS/LAZ tiles or a .vpc; OUTPUT_FOLDER = "
                    "classified tiles, block.vpc, planes.csv, lcps.csv and lines.csv"
                ),
            ),
            (
                "boresightcalibration",
                _t(
                    "PLANES / LINES / LCPS = the block's tables, TRAJECTORY "
                    "and OBSERVATIONS as above"
                ),
            ),
        ),
    ),
    Workflow(
        _t("Accepting a LiDAR survey (ASPRS Ed. 2: swath and vertical accuracy)"),
        (
            (
                "lidaraccuracy",
                _t(
                    "INPUT = the survey's LAS/LAZ (ground classified), "
                    "CHECKPOINTS = surveyed points with land cover; OUTPUT_HTML = swath overlap, "
                    "within-swath and NVA/VVA verdicts, OUTPUT_CHECKPOINTS = the check points with "
                    "LiDAR heights"
                ),
            ),
            (
                "accuracyreport",
                _t(
                    "INPUT = that check-point table; OUTPUT_HTML = the NSSDA and "
                    "PEC-PCD sections of the LiDAR's vertical accuracy"
                ),
            ),
        ),
    ),
    Workflow(
        _t("Terrestrial laser scanner calibration (Lichti 2007)"),
        (
            (
                "extracttlstargets",
                _t(
                    "SCANS = the station clouds, CONTROL = target ids; OUTPUT = target observations"
                ),
            ),
            (
                "tlscalibration",
                _t(
                    "OBSERVATIONS = those targets, CONTROL and STATIONS; "
                    "OUTPUT_APS = the scanner's additional parameters, OUTPUT_HTML = the report"
                ),
            ),
        ),
    ),
)


def workflows_of(name: str) -> tuple[Workflow, ...]:
    """The workflows algorithm ``name`` is a step of.

    >>> [w.title for w in workflows_of("createlcps")]  # doctest: +NORMALIZE_WHITESPACE
    ['Boresight calibration with LiDAR control (Pedrosa & dos Santos 2020)',
     'Boresight calibration without hand picks (automatic)']
    """
    return tuple(w for w in WORKFLOWS if name in w.ids)


def how_to_use(name: str, tr: Callable[[str], str] | None = None) -> str:
    """The "How to use" section of an algorithm's help (plain text, see ``spec.text_to_html``);
    "" when the algorithm is in no workflow. ``tr`` translates the titles and notes (context
    ``AlgorithmHelp``)."""
    t = tr or _t
    blocks = []
    for w in workflows_of(name):
        lines = textwrap.wrap(f"{t(w.title)}: {w.chain(name)}", _WIDTH, break_on_hyphens=False)
        for alg, note in w.steps:
            here = " " + t("(this algorithm)") if alg == name else ""
            lines += textwrap.wrap(
                f"- {alg}{here}: {t(note)}",
                _WIDTH,
                subsequent_indent="  ",
                break_on_hyphens=False,
            )
        blocks.append("\n".join(lines))
    return "\n\n".join(blocks)
