"""Common base of the toolkit's algorithms and the bridge from core calls to QGIS feedback."""

from __future__ import annotations

import configparser
import logging
import math
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Callable

from qgis.core import (
    NULL,
    QgsFeature,
    QgsField,
    QgsFields,
    QgsGeometry,
    QgsProcessingAlgorithm,
    QgsProcessingException,
    QgsProcessingFeedback,
    QgsProcessingParameterCrs,
    QgsProcessingParameterEnum,
    QgsProcessingParameterFile,
)
from qgis.PyQt.QtCore import QCoreApplication

from ..core.errors import Cancelled, LidarPhotoError
from .compat import FIELD_INT, FIELD_STRING, FILE_BEHAVIOR_FILE, SINK_FAST_INSERT, WKT_PREFERRED

_PLUGIN_DIR = Path(__file__).resolve().parents[1]
#: Logger of the whole package ("lidarphoto"); the core logs below it ("lidarphoto.core.*").
PACKAGE_LOGGER = __name__.split(".")[0]


def _homepage() -> str:
    meta = configparser.ConfigParser()
    meta.read(_PLUGIN_DIR / "metadata.txt", encoding="utf-8")
    return meta.get("general", "homepage", fallback="")


class _FeedbackLogHandler(logging.Handler):
    """Forwards core ``logging`` records to a QgsProcessingFeedback."""

    def __init__(self, feedback: QgsProcessingFeedback) -> None:
        super().__init__(logging.DEBUG)
        self.feedback = feedback
        self.setFormatter(logging.Formatter("%(message)s"))

    def emit(self, record: logging.LogRecord) -> None:
        try:
            text = self.format(record)
            if record.levelno >= logging.ERROR:
                self.feedback.reportError(text, False)
            elif record.levelno >= logging.WARNING:
                self.feedback.pushWarning(text)
            elif record.levelno >= logging.INFO:
                self.feedback.pushInfo(text)
            else:
                self.feedback.pushDebugInfo(text)
        except Exception:  # logging must never break the run
            self.handleError(record)


@contextmanager
def forward_logging(feedback: QgsProcessingFeedback, level: int = logging.INFO):
    """Within the block, core log records of ``level`` and above go to ``feedback``."""
    logger = logging.getLogger(PACKAGE_LOGGER)
    handler = _FeedbackLogHandler(feedback)
    old_level = logger.level
    if logger.level == logging.NOTSET or logger.level > level:
        logger.setLevel(level)
    logger.addHandler(handler)
    try:
        yield handler
    finally:
        logger.removeHandler(handler)
        logger.setLevel(old_level)


def progress_callback(feedback: QgsProcessingFeedback) -> Callable[[float], None]:
    """Core progress (a fraction in [0, 1]) -> ``feedback.setProgress`` (percent)."""

    def progress(fraction: float) -> None:
        feedback.setProgress(100.0 * min(max(float(fraction), 0.0), 1.0))

    return progress


def stop_callback(feedback: QgsProcessingFeedback) -> Callable[[], bool]:
    """Core ``should_stop`` -> ``feedback.isCanceled``."""
    return feedback.isCanceled


@contextmanager
def core_errors(cancelled_text: str = "Cancelled"):
    """Turn ``LidarPhotoError``, ``ValueError`` and ``OSError`` into QgsProcessingException.

    The exception keeps the core's message (which names the file, row and column).
    """
    try:
        yield
    except Cancelled as exc:
        raise QgsProcessingException(str(exc) or cancelled_text) from exc
    except (LidarPhotoError, ValueError, OSError) as exc:
        raise QgsProcessingException(str(exc)) from exc


class BaseAlgorithm(QgsProcessingAlgorithm):
    """tr/createInstance/group/helpUrl for every algorithm of the provider.

    Subclasses set ``GROUP`` (English, translated on display) and ``GROUP_ID``, and implement
    name/displayName/shortHelpString/initAlgorithm/processAlgorithm.
    """

    GROUP = ""
    GROUP_ID = ""
    TAGS: tuple[str, ...] = ()

    def tr(self, text: str) -> str:
        return QCoreApplication.translate(type(self).__name__, text)

    def createInstance(self):
        return type(self)()

    def group(self) -> str:
        return self.tr(self.GROUP)

    def groupId(self) -> str:
        return self.GROUP_ID

    def tags(self) -> list[str]:
        return ["lidarphoto", "lidar", "photogrammetry", *self.TAGS]

    def helpUrl(self) -> str:
        home = _homepage()
        return f"{home.rstrip('/')}/algorithms/{self.name()}" if home else ""

    # -- parameters shared by the algorithms that read a LAS/LAZ cloud -----------------------
    DISTANCE_UNITS = ("crs", "metre")

    def add_cloud_parameters(
        self, key: str = "INPUT", label: str = "Point cloud (LAS/LAZ)"
    ) -> None:
        """The cloud file, ``CRS`` (overrides or supplies the file's) and ``DISTANCE_UNIT``
        (0: the cloud's CRS unit, 1: metres) — the same names in every LiDAR algorithm."""
        self.addParameter(
            QgsProcessingParameterFile(
                key,
                self.tr(label),
                behavior=FILE_BEHAVIOR_FILE,
                fileFilter=self.tr("LAS/LAZ files (*.las *.laz *.LAS *.LAZ)"),
            )
        )
        self.addParameter(
            QgsProcessingParameterCrs("CRS", self.tr("CRS (overrides the file's)"), None, True)
        )
        self.addParameter(
            QgsProcessingParameterEnum(
                "DISTANCE_UNIT",
                self.tr("Distance unit"),
                [self.tr("cloud CRS units"), self.tr("metres")],
                False,
                0,
            )
        )

    def cloud_crs(self, parameters, context) -> str | None:
        """The ``CRS`` parameter for the core (authority id, else WKT), None when not given."""
        crs = self.parameterAsCrs(parameters, "CRS", context)
        return (crs.authid() or crs.toWkt(WKT_PREFERRED)) if crs.isValid() else None

    def distance_unit(self, parameters, context) -> str:
        """``"crs"`` or ``"metre"`` from the ``DISTANCE_UNIT`` parameter."""
        return self.DISTANCE_UNITS[self.parameterAsEnum(parameters, "DISTANCE_UNIT", context)]

    # -- feature sinks described by (name, QVariant type) field specs -------------------------
    def field_sink(self, parameters, context, key, spec, wkb, crs):
        """Open the sink ``key`` with the fields of ``spec``; returns ((sink, fields), dest id)."""
        fields = QgsFields()
        for name, kind in spec:
            fields.append(QgsField(name, kind))
        sink, dest = self.parameterAsSink(parameters, key, context, fields, wkb, crs)
        if sink is None:
            raise QgsProcessingException(self.invalidSinkError(parameters, key))
        return (sink, fields), dest

    @staticmethod
    def add_feature(sink_fields, spec, geometry, values) -> None:
        """Add one feature; ``geometry`` None keeps the row without a geometry (e.g. a failed
        point with its status); non-finite numbers become NULL."""
        sink, fields = sink_fields
        feature = QgsFeature(fields)
        if geometry is not None:
            feature.setGeometry(QgsGeometry(geometry))
        feature.setAttributes([_field_value(v, kind) for v, (_, kind) in zip(values, spec)])
        sink.addFeature(feature, SINK_FAST_INSERT)

    def canExecute(self):
        from ..core.dependencies import missing_message, missing_modules

        missing = missing_modules()
        if missing:
            return False, missing_message(missing)
        return True, ""

    def run_core(self, func: Callable[..., Any], *args: Any, feedback=None, **kwargs: Any) -> Any:
        """Call a core function with progress/cancel wired to ``feedback`` and its log forwarded.

        Errors the core raises on purpose become ``QgsProcessingException`` (see core_errors).
        """
        if feedback is None:
            feedback = QgsProcessingFeedback()
        with forward_logging(feedback), core_errors(self.tr("Cancelled by the user")):
            return func(
                *args,
                progress=progress_callback(feedback),
                should_stop=stop_callback(feedback),
                **kwargs,
            )


def _field_value(v, kind):
    if kind == FIELD_STRING:
        return str(v)
    if kind == FIELD_INT:
        return int(v)
    return float(v) if math.isfinite(float(v)) else NULL
