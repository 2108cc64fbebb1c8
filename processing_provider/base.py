"""The base of the toolkit's algorithms: a QGIS algorithm generated from a core job's spec,
and the bridge from core calls to QGIS feedback (progress, cancel, log, errors)."""

from __future__ import annotations

import logging
import math
from contextlib import contextmanager
from pathlib import Path
from types import ModuleType
from typing import Any, Callable

from qgis.core import (
    NULL,
    QgsCoordinateReferenceSystem,
    QgsFeature,
    QgsField,
    QgsFields,
    QgsGeometry,
    QgsProcessingAlgorithm,
    QgsProcessingException,
    QgsProcessingFeedback,
)
from qgis.PyQt.QtCore import QCoreApplication
from qgis.PyQt.QtGui import QIcon

from ..core.dependencies import missing_message, missing_modules
from ..core.errors import Cancelled, LidarPhotoError
from ..core.i18n import log_text, render
from ..core.jobs.runner import JobResult, run_job
from ..core.jobs.spec import AlgorithmSpec
from .compat import FIELD_INT, FIELD_STRING, SINK_FAST_INSERT
from .i18n import spec_help_html, spec_translator
from .parameters import make_output, make_parameter, read_parameter

ICONS = Path(__file__).resolve().parents[1] / "icons"
PLUGIN_ICON = ICONS.parent / "icon.svg"
#: Logger of the whole package ("lidarphoto"); the core logs below it ("lidarphoto.core.*").
PACKAGE_LOGGER = __name__.split(".")[0]


class _FeedbackLogHandler(logging.Handler):
    """Forwards core ``logging`` records to a QgsProcessingFeedback."""

    def __init__(self, feedback: QgsProcessingFeedback) -> None:
        super().__init__(logging.DEBUG)
        self.feedback = feedback
        self.setFormatter(logging.Formatter("%(message)s"))

    def emit(self, record: logging.LogRecord) -> None:
        try:
            text = log_text(record)  # core sentences (Message) in QGIS's language
            if record.exc_info:
                text = f"{text}\n{self.formatter.formatException(record.exc_info)}"
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


def verbose_log(context) -> bool:
    """Whether ``context`` asks for a verbose log (QgsProcessingContext.logLevel() Verbose or
    ModelDebug; QGIS 3.22 to 4)."""
    try:
        level = context.logLevel()
    except AttributeError:
        return False
    return int(getattr(level, "value", level)) >= 1


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
    """Turn ``LidarPhotoError``, ``ValueError``, ``OSError`` and ``MemoryError`` into
    QgsProcessingException.

    The exception keeps the core's message (which names the file, row and column).
    """
    try:
        yield
    except Cancelled as exc:
        raise QgsProcessingException(str(exc) or cancelled_text) from exc
    except (LidarPhotoError, ValueError, OSError) as exc:
        raise QgsProcessingException(str(exc)) from exc
    except MemoryError as exc:
        raise QgsProcessingException(
            QCoreApplication.translate(
                "BaseAlgorithm",
                "out of memory; nothing was written (use a coarser cell or a smaller input)",
            )
        ) from exc


class BaseAlgorithm(QgsProcessingAlgorithm):
    """A QGIS algorithm made from a core job (``core/jobs/<algorithm>.py``).

    Subclasses set ``JOB`` (the job module: its ``SPEC`` gives the id, names, help, parameters
    and outputs; its ``run`` does the work) and, where the algorithm has layer outputs or layer
    inputs, override :meth:`write_layers` and :meth:`prepare`.
    """

    JOB: ModuleType
    #: whether the current run logs details (see :func:`verbose_log`)
    _verbose = False

    def tr(self, text: str) -> str:
        """Translate in the class's context (where lupdate files a subclass's ``self.tr``),
        else in ``BaseAlgorithm``'s (the strings written in this file)."""
        out = QCoreApplication.translate(type(self).__name__, text)
        return out if out != text else QCoreApplication.translate("BaseAlgorithm", text)

    def spec_tr(self, text: str) -> str:
        """Translate a text of the spec (context ``lidarphoto:<algorithm>``)."""
        return spec_translator(self.spec)(text)

    @property
    def spec(self) -> AlgorithmSpec:
        return self.JOB.SPEC

    def createInstance(self):
        return type(self)()

    def name(self) -> str:
        return self.spec.name

    def svgIconPath(self) -> str:
        """The icon of the algorithm's family (``icons/<group id>.svg``, drawn for the plugin);
        the plugin's own icon for a group that has none."""
        path = ICONS / f"{self.spec.group_id}.svg"
        return str(path if path.is_file() else PLUGIN_ICON)

    def icon(self) -> QIcon:
        return QIcon(self.svgIconPath())

    def displayName(self) -> str:
        return self.spec_tr(self.spec.title)

    def group(self) -> str:
        return self.spec_tr(self.spec.group)

    def groupId(self) -> str:
        return self.spec.group_id

    def tags(self) -> list[str]:
        return ["lidarphoto", "lidar", "photogrammetry", *self.spec.tags]

    def shortHelpString(self) -> str:
        return spec_help_html(self.spec)

    def helpUrl(self) -> str:
        from .help_docs import help_url  # the pages are written on the first Help asked

        return help_url(self.name())

    def shown(self, name: str) -> bool:
        """Whether the spec's parameter ``name`` is in this algorithm's form (all are; a
        variant of a job may leave some at their defaults)."""
        return True

    def initAlgorithm(self, config=None):
        for p in self.spec.params:
            if self.shown(p.name):
                self.addParameter(make_parameter(p, self.spec_tr, self.spec))
        for r in self.spec.results:
            self.addOutput(make_output(r, self.spec_tr))

    def canExecute(self):
        missing = missing_modules()
        if missing:
            return False, missing_message(missing)
        return True, ""

    def read_raw(self, parameters, context) -> dict:
        """The values of the spec's parameters as the job takes them (before :meth:`prepare`)."""
        return {
            p.name: read_parameter(self, p, parameters, context)
            for p in self.spec.params
            if p.kind != "sink" and self.shown(p.name)
        }

    def processAlgorithm(self, parameters, context, feedback):
        raw = self.read_raw(parameters, context)
        raw = self.prepare(raw, parameters, context, feedback)
        self._verbose = verbose_log(context)
        result = self.run_core(run_job, self.JOB, raw, feedback=feedback)
        for line in result.lines:
            feedback.pushInfo(render(line, "Report"))  # a Message in QGIS's language
        outputs = {p.name: raw.get(p.name) for p in self.spec.outputs if p.kind != "sink"}
        outputs.update(result.results)
        outputs.update(self.write_layers(result, parameters, context, feedback))
        self.attach_styles(outputs, context)
        self._html_reports = [
            str(outputs[p.name]) for p in self.spec.outputs
            if p.kind == "file_out" and str(outputs.get(p.name) or "").lower().endswith(".html")
        ]  # fmt: skip
        sinks = {p.name: outputs.get(p.name) for p in self.spec.outputs if p.kind == "sink"}
        self.load_outputs(raw, result, context, sinks)
        return outputs

    def load_outputs(self, raw: dict, result: JobResult, context, sinks=None) -> list[str]:
        """Tables with coordinates and point clouds among the file outputs load as layers
        (``processing_provider/output_layers.py``), except a table whose layer twin the run
        wrote (``sinks``: sink name -> layer id); returns their paths."""
        from .output_layers import load_outputs

        return load_outputs(self, raw, result.data, context, sinks)

    def postProcessAlgorithm(self, context, feedback):
        """Every HTML report the run wrote also as PDF beside it (printing needs the main
        thread, where QGIS calls this)."""
        from .report_pdf import can_print, write_pdf

        for html in getattr(self, "_html_reports", []):
            if not Path(html).is_file():
                continue
            why = can_print()
            if why:
                feedback.pushInfo(self.tr("No PDF of {}: {}").format(html, why))
                continue
            try:
                pdf = write_pdf(html)
            except RuntimeError as exc:
                feedback.reportError(str(exc))
                continue
            feedback.pushInfo(self.tr("Report as PDF: {}").format(pdf))
        return {}

    #: (output name, style function of processing_provider/layer_styles.py) pairs: how each
    #: output layer looks when QGIS loads it after the run.
    STYLES: tuple[tuple[str, Callable[[Any], None]], ...] = ()

    def attach_styles(self, outputs: dict, context) -> None:
        """Give each output QGIS will load its style from :attr:`STYLES`."""
        from .layer_styles import LayerStyle

        for name, func in self.STYLES:
            dest = outputs.get(name)
            if dest and context.willLoadLayerOnCompletion(dest):
                context.layerToLoadOnCompletionDetails(dest).setPostProcessor(
                    LayerStyle.create(func)
                )

    def error(self, text: str) -> QgsProcessingException:
        """An error for the user (translated)."""
        return QgsProcessingException(self.tr(text))

    def prepare(self, raw: dict, parameters, context, feedback) -> dict:
        """Turn QGIS-only inputs (layers) into what the job takes; the default keeps ``raw``."""
        return raw

    def write_layers(self, result: JobResult, parameters, context, feedback) -> dict:
        """Fill the feature sinks from the job's result; returns {sink name: layer id}."""
        return {}

    def run_core(self, func: Callable[..., Any], *args: Any, feedback=None, **kwargs: Any) -> Any:
        """Call a core function with progress/cancel wired to ``feedback`` and its log forwarded.

        Errors the core raises on purpose become ``QgsProcessingException`` (see core_errors).
        """
        if feedback is None:
            feedback = QgsProcessingFeedback()
        # details (debug records, such as every rejected candidate) only when the processing
        # context asks for a verbose log (Processing options: logging level Verbose), as
        # pushDebugInfo; otherwise the summaries alone
        level = logging.DEBUG if self._verbose else logging.INFO
        with (
            forward_logging(feedback, level),
            core_errors(self.tr("Cancelled by the user")),
        ):
            return func(
                *args,
                progress=progress_callback(feedback),
                should_stop=stop_callback(feedback),
                **kwargs,
            )

    # -- feature sinks described by (name, QVariant type) field specs -------------------------
    def field_sink(self, parameters, context, key, spec, wkb, crs):
        """Open the sink ``key`` with the fields of ``spec`` in ``crs`` (a
        QgsCoordinateReferenceSystem, the WKT of one, e.g. a result's ``crs_wkt``, or None);
        returns ((sink, fields), dest id).

        ((None, fields), None) when the user did not ask for the layer."""
        if isinstance(crs, str):
            crs = QgsCoordinateReferenceSystem.fromWkt(crs)
        fields = QgsFields()
        for name, kind in spec:
            fields.append(QgsField(name, kind))
        sink, dest = self.parameterAsSink(parameters, key, context, fields, wkb, crs)
        if sink is None and parameters.get(key) not in (None, ""):
            raise QgsProcessingException(self.invalidSinkError(parameters, key))
        return (sink, fields), dest

    @staticmethod
    def add_feature(sink_fields, spec, geometry, values) -> None:
        """Add one feature; ``geometry`` None keeps the row without a geometry (e.g. a failed
        point with its status); non-finite numbers become NULL."""
        sink, fields = sink_fields
        if sink is None:
            return
        feature = QgsFeature(fields)
        if geometry is not None:
            feature.setGeometry(QgsGeometry(geometry))
        feature.setAttributes([_field_value(v, kind) for v, (_, kind) in zip(values, spec)])
        sink.addFeature(feature, SINK_FAST_INSERT)


def _field_value(v, kind):
    if kind == FIELD_STRING:
        return str(v)
    if kind == FIELD_INT:
        return int(v)
    return float(v) if math.isfinite(float(v)) else NULL
