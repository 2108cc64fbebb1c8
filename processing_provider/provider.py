"""The QGIS Processing provider ``lidarphoto``: one algorithm per job of the registry
(:mod:`core.jobs`), in its order.

An algorithm with QGIS-only behaviour (layer outputs, layer inputs, styles, its own checks)
has its adapter in ``algorithms/<job module>.py``: the :class:`~.base.BaseAlgorithm`
subclass whose ``JOB`` is that job. Every other job becomes a generated ``BaseAlgorithm``
subclass (:func:`algorithm_class`): its id, names, group, help and parameters all come from
the spec.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from pathlib import Path
from types import ModuleType

from qgis.core import QgsProcessingProvider
from qgis.PyQt.QtCore import QCoreApplication
from qgis.PyQt.QtGui import QIcon

from ..core.jobs import algorithms
from .base import BaseAlgorithm
from .i18n import install_translator

ICON_PATH = Path(__file__).resolve().parents[1] / "icon.svg"


def _class_name(job: ModuleType) -> str:
    """``...jobs.tie_points`` -> ``TiePointsAlgorithm``."""
    module = job.__name__.rsplit(".", 1)[1]
    return "".join(word.capitalize() for word in module.split("_")) + "Algorithm"


def algorithm_class(job: ModuleType) -> type[BaseAlgorithm]:
    """The QGIS algorithm of a job: its adapter in ``algorithms/`` when it has one, else a
    ``BaseAlgorithm`` subclass made from the spec alone."""
    module = job.__name__.rsplit(".", 1)[1]
    adapter = f"{__package__}.algorithms.{module}"
    if importlib.util.find_spec(adapter) is not None:
        for value in vars(importlib.import_module(adapter)).values():
            if (
                isinstance(value, type)
                and issubclass(value, BaseAlgorithm)
                and (value.__dict__.get("JOB") is job)
            ):
                return value
        raise TypeError(f"{adapter} has no BaseAlgorithm subclass with JOB = {job.__name__}")
    doc = f"Algorithm ``{job.SPEC.name}`` made from ``core.jobs.{module}`` (file outputs only)."
    return type(_class_name(job), (BaseAlgorithm,), {"JOB": job, "__doc__": doc})


class LidarPhotoProvider(QgsProcessingProvider):
    """Provider ``lidarphoto``; its id and the algorithm names are API (models, scripts)."""

    def __init__(self) -> None:
        super().__init__()
        install_translator()  # QGIS's language, also under qgis_process (no initGui)

    def tr(self, text: str) -> str:
        return QCoreApplication.translate("LidarPhotoProvider", text)

    def id(self) -> str:
        return "lidarphoto"

    def name(self) -> str:
        return self.tr("LiDAR Photogrammetry")

    def longName(self) -> str:
        return self.tr("LiDAR Photogrammetry Toolkit")

    def icon(self) -> QIcon:
        return QIcon(str(ICON_PATH))

    def svgIconPath(self) -> str:
        return str(ICON_PATH)

    def loadAlgorithms(self) -> None:
        for job in algorithms():
            cls = algorithm_class(job)
            self.addAlgorithm(cls())
            for extra in getattr(sys.modules[cls.__module__], "EXTRA_ALGORITHMS", ()):
                self.addAlgorithm(extra())
