"""One module per algorithm: its parameter spec and its run(), from which the QGIS toolbox
and the command line are both made (docs/architecture.md, "Adding an algorithm").

This package is the registry. Importing it imports no job; :func:`algorithms` (and
``ALGORITHMS``) import the job modules, which hold their specs and import their science only
when they run (a spec's science defaults are :class:`~.spec.Ref` s, read when its parameters
are first used), so listing the algorithms stays cheap. ``tests/core/test_startup.py`` holds
that line.
"""

from __future__ import annotations

import importlib
from types import ModuleType

#: Every algorithm's job module, in the order of the toolbox and of ``lidarphoto --help``.
NAMES = (
    "trajectory_to_eo",
    "import_trajectory",
    "import_colmap",
    "export_colmap",
    "import_opensfm",
    "export_opensfm",
    "import_metashape",
    "import_pix4d",
    "ground_filter",
    "create_lcps",
    "accuracy_report",
    "extract_roof_planes",
    "boresight_calibration",
    "auto_boresight",
    "monoplot",
    "bundle_adjustment",
    "resection",
    "orthorectify",
    "orthomosaic",
    "tls_calibration",
    "extract_tls_targets",
    "locate_control_points",
    "lidar_block",
    "lidar_accuracy",
    "calibrate_camera",
    "tie_points",
    "make_control_chips",
)


def algorithms() -> tuple[ModuleType, ...]:
    """The job modules of :data:`NAMES`, imported (specs only: no science). A name with a dot
    is a module path (a job kept elsewhere, e.g. the test suite's)."""
    return tuple(
        importlib.import_module(name if "." in name else f".{name}", __name__) for name in NAMES
    )


def __getattr__(name: str) -> object:
    if name == "ALGORITHMS":  # the job modules, as the CLI, the provider and the tests use them
        return algorithms()
    raise AttributeError(name)
