"""Parameters shared by several algorithms: the camera mount, the LiDAR cloud and its units;
and how an adjustment whose result failed its checks is settled (:func:`settle_doubts`).

Written once here so that every algorithm names, documents and defaults them the same way.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import replace
from typing import Any

from ..io.suffixes import IMAGE_SUFFIXES
from .spec import Param, Ref

CSV_FILTER = "CSV files (*.csv *.txt)"
JSON_FILTER = "JSON files (*.json)"
CSV_OUT = "CSV files (*.csv)"
LAS_FILTER = "LAS/LAZ files (*.las *.laz *.LAS *.LAZ)"
#: A point cloud output (LAZ first: the smaller file).
LAS_OUT = "LAZ files (*.laz);;LAS files (*.las)"
DSM_FILTER = "DSM (*.tif *.tiff *.img *.vrt *.asc *.las *.laz *.LAS *.LAZ)"
DISTANCE_UNITS = ("crs", "metre")
#: Largest lever-arm component (m): longer than any survey aircraft, so a larger value is a
#: unit mistake (millimetres typed as metres).
MAX_LEVER_ARM_M = 50.0
#: Largest boresight angle (degrees) an input may have: a misalignment is a fraction of a
#: degree; a rotation of the mount belongs in MOUNT / MOUNT_MATRIX.
MAX_BORESIGHT_DEG = 10.0


def mount_params(initial_boresight: bool = False) -> tuple[Param, ...]:
    """LEVER_ARM, MOUNT, MOUNT_MATRIX and BORESIGHT (``core.photo.mount``);
    ``initial_boresight``: BORESIGHT is only the start of an estimate (under Advanced: 0 is
    a fine first value)."""
    return (
        _offsets(
            "LEVER_ARM",
            "Lever arm x,y,z",
            "m, body frame",
            MAX_LEVER_ARM_M,
            help="camera perspective centre in the INS body frame (x forward, y right, z down)",
        ),
        choice_param(
            "MOUNT",
            "Camera mount",
            "photo.mount_choices",
            "MOUNT_CHOICES",
            labels=Ref("photo.mount_choices", "MOUNT_LABELS", convert=_mount_labels),
            help="nominal camera-to-body rotation; custom uses MOUNT_MATRIX",
        ),
        Param(
            "MOUNT_MATRIX",
            "numbers",
            "Mount matrix R_c^b (9 numbers, row-major)",
            count=9,
            optional=True,
            advanced=True,
            minimum=-1.0,
            maximum=1.0,
            help="the nominal mount R_c^b when MOUNT is custom",
        ),
        _offsets(
            "BORESIGHT",
            "Boresight domega,dphi,dkappa",
            "degrees",
            MAX_BORESIGHT_DEG,
            advanced=initial_boresight,
            help="small misalignment about the camera axes x, y, z (a larger rotation "
            "belongs in MOUNT)",
        ),
    )


def _offsets(name: str, label: str, unit: str, limit: float, **extra: Any) -> Param:
    """Three numbers, each within +-``limit``, 0 by default (a lever arm, a boresight)."""
    zero = (0.0, 0.0, 0.0)
    return Param(
        name, "numbers", label, zero, count=3, unit=unit, minimum=-limit, maximum=limit, **extra
    )


def choice_param(name: str, label: str, module: str, constant: str, **extra: Any) -> Param:
    """An ``enum`` parameter whose options are the tuple ``constant`` of the science module
    ``module`` (below core, e.g. ``"io.colmap_names"``), the first of them its default."""
    return Param(
        name,
        "enum",
        label,
        Ref(module, constant, convert=_first),
        options=Ref(module, constant),  # type: ignore[arg-type]
        **extra,
    )


def enum_param(name: str, label: str, default: Ref, choices: str, **extra: Any) -> Param:
    """An ``enum`` parameter whose default is ``default``, a field of a science dataclass
    (:class:`~.spec.Fields`), and whose options are the tuple ``choices`` of the same module."""
    return Param(name, "enum", label, default, options=Ref(default.module, choices), **extra)


def _first(choices: tuple[str, ...]) -> str:
    return choices[0]


def _mount_labels(labels: Mapping[str, str]) -> tuple[str, ...]:
    from ..photo.mount_choices import MOUNT_CHOICES

    return tuple(f"{m}: {labels[m]}" for m in MOUNT_CHOICES)


def mount_from(values: Mapping[str, Any]):
    """The :class:`~lidarphoto.core.photo.mount.Mount` of :func:`mount_params` values."""
    from ..photo.mount import Mount

    return Mount.from_parameters(
        values["LEVER_ARM"], values["MOUNT"], values["MOUNT_MATRIX"], values["BORESIGHT"]
    )


def file_out(name: str, label: str, file_filter: str, **options: Any) -> Param:
    """A file output (``file_out``) of ``file_filter``. ``options``: those of :class:`Param`,
    ``optional`` True unless said, and ``on_demand`` (not written unless asked: QGIS leaves it
    unchecked) and ``twin`` (the layer output, ``sink``, that carries the same rows:
    :attr:`Param.layer_twin`)."""
    create = not options.pop("on_demand", False)
    twin = options.pop("twin", "")
    options.setdefault("optional", True)
    return Param(
        name,
        "file_out",
        label,
        file_filter=file_filter,
        create_by_default=create,
        layer_twin=twin,
        **options,
    )


def cloud_out(name: str, label: str, **extra: Any) -> Param:
    """A LAS/LAZ point cloud output: :func:`file_out` with its options."""
    return file_out(name, label, LAS_OUT, **extra)


def csv_out(name: str, label: str, **extra: Any) -> Param:
    """A CSV table output: :func:`file_out` with its options."""
    return file_out(name, label, CSV_OUT, **extra)


def html_out(name: str, label: str, **extra: Any) -> Param:
    """An HTML report output: :func:`file_out` with its options."""
    return file_out(name, label, "HTML files (*.html)", **extra)


def json_out(name: str, label: str, **extra: Any) -> Param:
    """A JSON file output (a camera, the figures of a report): :func:`file_out` with its
    options."""
    return file_out(name, label, JSON_FILTER, **extra)


def table_param(name: str, label: str, **extra: Any) -> Param:
    """An input table ``name``: a CSV file (or, in QGIS, any layer with attributes)."""
    return Param(name, "table", label, file_filter=CSV_FILTER, **extra)


def camera_param(label: str = "Camera (JSON)", **extra: Any) -> Param:
    """CAMERA: the camera file (JSON: ``core.io.camera``)."""
    return Param("CAMERA", "file", label, file_filter=JSON_FILTER, **extra)


def eo_param(label: str = "Exterior orientation (CSV)", **extra: Any) -> Param:
    """EO: the exterior orientation table (``core.io.orientation``)."""
    return table_param("EO", label, **extra)


def images_param(
    label: str = "Images (files or folders)",
    help: str = "image files, or folders whose images are all taken",
    **extra: Any,
) -> Param:
    """IMAGES: image files, or folders whose images are all taken (``core.io.suffixes``)."""
    return Param("IMAGES", "files", label, suffixes=IMAGE_SUFFIXES, help=help, **extra)


def mapping_crs_param(help: str, label: str = "Mapping CRS (projected)", **extra: Any) -> Param:
    """CRS: the projected mapping CRS of the outputs, the QGIS project's by default."""
    return Param("CRS", "crs", label, qgis_default="ProjectCrs", help=help, **extra)


def dsm_cell_param(advanced: bool = False) -> Param:
    """CELL_SIZE: the cell (CRS units) of the DSM rasterised from a LAS/LAZ given as DSM."""
    return Param(
        "CELL_SIZE",
        "number",
        "DSM cell size for LAS/LAZ",
        0.5,
        unit="CRS unit",
        minimum=0.01,
        maximum=1000.0,
        advanced=advanced,
    )


def block_export_params() -> tuple[Param, ...]:
    """CAMERA, EO and the optional OBSERVATIONS and POINTS: the oriented block an exporter
    (``exportcolmap``, ``exportopensfm``) writes out."""
    return (
        camera_param("Camera(s) (JSON)"),
        eo_param("Exterior orientation table (CSV)"),
        table_param("OBSERVATIONS", "Observations (CSV)", optional=True),
        table_param("POINTS", "3D points (ground point table, CSV)", optional=True),
    )


def cloud_params(key: str = "INPUT", label: str = "Point cloud (LAS/LAZ)") -> tuple[Param, ...]:
    """The cloud file, ``CRS`` (overrides or supplies the file's) and ``DISTANCE_UNIT``."""
    return (
        Param(key, "pointcloud", label, file_filter=LAS_FILTER),
        Param(
            "CRS",
            "crs",
            "CRS (overrides the file's)",
            optional=True,
            help="the cloud's CRS when the file has none or a wrong one (EPSG:xxxx or WKT)",
        ),
        Param(
            "DISTANCE_UNIT",
            "enum",
            "Distance unit",
            "crs",
            options=DISTANCE_UNITS,
            labels=("cloud CRS units", "metres"),
            aliases={"metres": "metre", "m": "metre"},
            help="unit of the length parameters: the cloud's CRS unit (e.g. international "
            "feet) or metres, converted",
        ),
    )


def lengths_in_cloud_units(
    params: Any,
    info: Any,
    distance_unit: str,
    horizontal: Iterable[str] = (),
    vertical: Iterable[str] = (),
) -> Any:
    """``params`` (a dataclass) with its ``horizontal`` and ``vertical`` length fields turned
    from ``distance_unit`` into the cloud's units (``info``: a CloudInfo, whose
    :meth:`~lidarphoto.core.io.pointcloud.CloudInfo.length_factors` holds the rule)."""
    h, v = info.length_factors(distance_unit)
    if (h, v) == (1.0, 1.0):
        return params
    changes = {name: getattr(params, name) * h for name in horizontal}
    changes.update({name: getattr(params, name) * v for name in vertical})
    return replace(params, **changes)


_UNIT_SYMBOLS = {"metre": "m", "meter": "m", "foot": "ft", "us survey foot": "US ft"}


def unit_symbol(name: str) -> str:
    """The symbol of a CRS length unit for messages ("metre" -> "m"; unknown names as they are).

    >>> unit_symbol("metre"), unit_symbol("US survey foot"), unit_symbol("")
    ('m', 'US ft', 'CRS unit')
    """
    if not name:
        return "CRS unit"
    return _UNIT_SYMBOLS.get(name.strip().lower(), name)


def cluster_params(advanced: bool = False) -> tuple[Param, ...]:
    """CLUSTER, WORKERS, MEMORY_LIMIT and LOCAL_CLUSTER: the dask cluster that processes tiles
    (``lidar_block.cluster_session``); ``advanced``: all four among the advanced parameters
    (else CLUSTER and WORKERS shown)."""
    return (
        Param(
            "CLUSTER",
            "string",
            "dask scheduler address (empty: a local cluster)",
            "",
            optional=True,
            advanced=advanced,
            help="e.g. tcp://10.0.0.5:8786",
        ),
        Param(
            "WORKERS",
            "integer",
            "Local cluster: workers (0 = one per core)",
            0,
            minimum=0,
            maximum=1024,
            advanced=advanced,
        ),
        Param(
            "MEMORY_LIMIT",
            "number",
            "Local cluster: memory limit per worker (0 = RAM / workers)",
            0.0,
            unit="GB",
            minimum=0.0,
            maximum=4096.0,
            advanced=True,
        ),
        Param(
            "LOCAL_CLUSTER",
            "enum",
            "Local cluster workers",
            "auto",
            options=("auto", "processes", "threads"),
            labels=(
                "auto (processes on the command line, threads inside QGIS)",
                "processes (one per worker)",
                "threads of this process",
            ),
            advanced=True,
            help="auto: processes on the command line, threads inside QGIS or "
            "qgis_process, where a process cluster would start QGIS's own executable for "
            "each worker",
        ),
    )


def length_unit_text(info: Any, distance_unit: str) -> str:
    """How the job reports the unit its lengths were taken in (the cloud CRS unit, or metres
    converted; not the help's unit of a parameter, :func:`.spec.unit_text`)."""
    return "metre (converted)" if distance_unit == "metre" else info.horizontal_unit


#: GeoTIFF compressions of the image outputs (orthophotos, mosaics).
COMPRESSIONS = ("deflate", "zstd", "lzw", "jpeg", "none")


def compression_param() -> Param:
    """COMPRESSION of an image output (:class:`~lidarphoto.core.io.raster.GeoTiffWriter`)."""
    return Param(
        "COMPRESSION",
        "enum",
        "GeoTIFF compression",
        COMPRESSIONS[0],
        options=COMPRESSIONS,
        advanced=True,
        labels=(
            "DEFLATE (lossless, level 1: fast)",
            "ZSTD (lossless, level 1)",
            "LZW (lossless)",
            "JPEG (lossy, quality 90; 8-bit images)",
            "none",
        ),
        help="deflate and zstd at their fastest level (files about 15 % larger than "
        "at the default level); jpeg is lossy and only for 8-bit images",
    )


def compression_args(name: str) -> dict[str, Any]:
    """GeoTiffWriter keywords of a COMPRESSION value."""
    return {"compress": name.upper(), "level": 1 if name in ("deflate", "zstd") else None}


def doubt_params(sigma0_help: str, accept_help: str) -> tuple[Param, Param]:
    """MAX_SIGMA0 and ACCEPT_DOUBTFUL of an adjustment whose result is checked
    (:func:`settle_doubts`); the helps say which checks."""
    return (
        Param(
            "MAX_SIGMA0",
            "number",
            "Largest sigma0 when the global test fails",
            3.0,
            minimum=1.0,
            maximum=1000.0,
            advanced=True,
            help=sigma0_help,
        ),
        Param(
            "ACCEPT_DOUBTFUL",
            "boolean",
            "Write the results even when the checks fail",
            False,
            advanced=True,
            help=accept_help,
        ),
    )


def settle_doubts(
    what: str,
    doubts: Sequence[str],
    accept: bool,
    out: Any,
    failed_page: Callable[[], str],
    report: str = "HTML report",
) -> list[str]:
    """Settle a result that failed its checks (``doubts``: why; empty when it passed them).

    Refused unless ``accept`` (ACCEPT_DOUBTFUL): OUTPUT_HTML, when asked for, is written alone
    from ``failed_page()`` (the failed numbers are the user's diagnosis) and
    :class:`~core.errors.AdjustmentError` names ``what`` and every doubt. Accepted: the
    warning lines every output starts with (logged too); none when there is no doubt.
    """
    from ..errors import AdjustmentError
    from ..io.atomic import write_text_atomic

    if doubts and not accept:
        if out.requested("OUTPUT_HTML"):
            write_text_atomic(out.path("OUTPUT_HTML"), failed_page())
            out.commit(["OUTPUT_HTML"])
        raise AdjustmentError(
            f"the {what} failed its checks: "
            + "; ".join(str(d) for d in doubts)
            + ". No result was written"
            + (
                f" (the {report} shows the failed adjustment)"
                if out.requested("OUTPUT_HTML")
                else ""
            )
            + "; ACCEPT_DOUBTFUL writes them with a warning"
        )
    warning = [f"WARNING: {d}" for d in doubts]
    if doubts:
        warning.insert(
            0,
            "WARNING: this calibration failed its checks and was written only "
            "because ACCEPT_DOUBTFUL was set; do not use it without review",
        )
        for line in warning:
            logging.getLogger(__name__).warning(line.removeprefix("WARNING: "))
    return warning


def global_test_verdict(passed: bool, adjustment: Any, alpha: float, failed: str = "failed") -> str:
    """The global test's word for a summary line: ``failed``, ``passed``, or, when the
    robust stage and data snooping (per-row significance ``alpha``) rejected more
    observations than their false alarms explain (:func:`~core.lsq.results.rejection_test`
    on ``adjustment``), "passed only after rejecting ...": the test of the rest then says
    nothing about the model (the message is logged as a warning too).

    >>> from types import SimpleNamespace as NS
    >>> import numpy as np
    >>> table = lambda n, k: NS(v=np.zeros((n, 2)), rejected=np.arange(n) < k)
    >>> global_test_verdict(True, NS(residuals={"image": table(100, 1)}), 0.001)
    'passed'
    >>> global_test_verdict(True, NS(residuals={"image": table(100, 30)}), 0.001)
    'passed only after rejecting 30 of 100 observations (false alarms explain at most 3)'
    """
    if not passed:
        return failed
    rejections = rejection_doubts(adjustment, alpha)
    if not rejections:
        return "passed"
    test = rejections[0]
    logging.getLogger(__name__).warning(str(test.message()))
    return (
        f"passed only after rejecting {test.rejected} of {test.groups} observations (false "
        f"alarms explain at most {test.bound})"
    )


def rejection_doubts(adjustment: Any, alpha: float) -> list[Any]:
    """``[test]`` when the rejections of ``adjustment`` (robust stage and data snooping at
    ``alpha`` per row) fail :func:`~core.lsq.results.rejection_test` (its ``message()`` is
    the doubt :func:`settle_doubts` takes), else ``[]``."""
    from ..lsq.results import unexplained_rejections

    test = unexplained_rejections(adjustment, alpha)
    return [] if test is None else [test]
