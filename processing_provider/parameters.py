"""Core parameter specs (core/jobs/spec.py) as QGIS Processing parameters, and back."""

from __future__ import annotations

from typing import Any, Callable

from qgis.core import (
    QgsProcessingOutputNumber,
    QgsProcessingOutputString,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterCrs,
    QgsProcessingParameterDefinition,
    QgsProcessingParameterEnum,
    QgsProcessingParameterFeatureSink,
    QgsProcessingParameterFeatureSource,
    QgsProcessingParameterField,
    QgsProcessingParameterFile,
    QgsProcessingParameterFileDestination,
    QgsProcessingParameterFolderDestination,
    QgsProcessingParameterMultipleLayers,
    QgsProcessingParameterNumber,
    QgsProcessingParameterRasterDestination,
    QgsProcessingParameterString,
)
from qgis.PyQt.QtCore import QCoreApplication

from ..core.jobs.spec import AlgorithmSpec, Param, Result, facts_line
from .compat import (
    FIELD_TYPE_ANY,
    FIELD_TYPE_NUMERIC,
    FILE_BEHAVIOR_FILE,
    FLAG_ADVANCED,
    NUMBER_DOUBLE,
    NUMBER_INTEGER,
    SOURCE_FILE,
    SOURCE_VECTOR_LINE,
    SOURCE_VECTOR_POINT,
    SOURCE_VECTOR_POLYGON,
    WKT_PREFERRED,
)
from .i18n import help_tr


def _all_files() -> str:
    return QCoreApplication.translate("LidarPhotoProvider", "All files (*.*)")


_SINK_TYPES = {
    "point": SOURCE_VECTOR_POINT,
    "line": SOURCE_VECTOR_LINE,
    "polygon": SOURCE_VECTOR_POLYGON,
}


def make_parameter(
    p: Param, tr: Callable[[str], str], spec: AlgorithmSpec | None = None
) -> QgsProcessingParameterDefinition:
    """The QGIS parameter of a spec entry (label translated with ``tr``).

    Its help (the tooltip, and what ``qgis_process help`` prints under the parameter) ends
    with the default, unit and valid range, the same facts as the algorithm's help table.
    """
    title = tr(p.label) + (f" ({p.unit})" if p.unit else "")
    k = p.kind
    default = p.qgis_default if p.qgis_default is not None else p.default
    if k == "file":
        flt = f"{tr(p.file_filter)};;{_all_files()}" if p.file_filter else _all_files()
        q = QgsProcessingParameterFile(
            p.name, title, behavior=FILE_BEHAVIOR_FILE, fileFilter=flt, optional=p.optional
        )
    elif k == "crs":
        if default is None and not p.optional:  # the project's CRS, not "invalid projection"
            default = "ProjectCrs"
        q = QgsProcessingParameterCrs(p.name, title, default, p.optional)
    elif k in ("number", "integer"):
        q = QgsProcessingParameterNumber(
            p.name, title, NUMBER_DOUBLE if k == "number" else NUMBER_INTEGER, default, p.optional
        )
        if p.minimum is not None:
            q.setMinimum(p.minimum)
        if p.maximum is not None:
            q.setMaximum(p.maximum)
    elif k == "boolean":
        q = QgsProcessingParameterBoolean(p.name, title, bool(default), p.optional)
    elif k == "enum":
        labels = [tr(v) for v in (p.labels or p.options)]
        if p.multiple:
            index = [p.options.index(v) for v in (default or ())]
        else:
            index = p.options.index(default) if default is not None else None
        q = QgsProcessingParameterEnum(p.name, title, labels, p.multiple, index, p.optional)
    elif k in ("string", "numbers"):
        q = QgsProcessingParameterString(p.name, title, p.default_text(), False, p.optional)
    elif k == "points":
        q = QgsProcessingParameterFeatureSource(
            p.name, title, [SOURCE_VECTOR_POINT], optional=p.optional
        )
    elif k == "field":
        q = QgsProcessingParameterField(
            p.name, title, None, p.parent, FIELD_TYPE_NUMERIC if p.numeric_field
            else FIELD_TYPE_ANY, optional=True,
        )  # fmt: skip
    elif k == "files":
        q = QgsProcessingParameterMultipleLayers(p.name, title, SOURCE_FILE, None, p.optional)
    elif k == "folder_out":
        q = QgsProcessingParameterFolderDestination(
            p.name, title, optional=p.optional, createByDefault=p.create_by_default
        )
    elif k == "file_out":
        q = QgsProcessingParameterFileDestination(
            p.name, title, tr(p.file_filter), optional=p.optional,
            createByDefault=p.create_by_default,
        )  # fmt: skip
    elif k == "raster_out":
        q = QgsProcessingParameterRasterDestination(
            p.name, title, optional=p.optional, createByDefault=p.create_by_default
        )
    elif k == "sink":
        q = QgsProcessingParameterFeatureSink(
            p.name, title, _SINK_TYPES[p.geometry], optional=p.optional,
            createByDefault=p.create_by_default,
        )  # fmt: skip
    else:  # pragma: no cover - the spec refuses unknown kinds
        raise ValueError(k)
    if p.advanced:
        q.setFlags(q.flags() | FLAG_ADVANCED)
    facts = facts_line(p, spec, help_tr)
    q.setHelp(f"{tr(p.help)}; {facts}" if p.help else facts)
    return q


def make_output(r: Result, tr: Callable[[str], str]):
    """The QGIS output of a spec result."""
    cls = QgsProcessingOutputNumber if r.kind == "number" else QgsProcessingOutputString
    return cls(r.name, tr(r.label))


def read_parameter(alg, p: Param, parameters: dict, context) -> Any:
    """The value of a spec entry from QGIS's parameters, as the core job takes it.

    Empty files, CRSs and outputs are None; enums give option names; ``points`` gives the
    feature source (the algorithm turns it into a core object); ``field`` a field name or "".
    """
    k = p.kind
    if k == "file":
        return alg.parameterAsFile(parameters, p.name, context) or None
    if k == "crs":
        crs = alg.parameterAsCrs(parameters, p.name, context)
        return (crs.authid() or crs.toWkt(WKT_PREFERRED)) if crs.isValid() else None
    if k == "number":
        return alg.parameterAsDouble(parameters, p.name, context)
    if k == "integer":
        return alg.parameterAsInt(parameters, p.name, context)
    if k == "boolean":
        return alg.parameterAsBoolean(parameters, p.name, context)
    if k == "enum":
        if p.multiple:
            return tuple(p.options[i] for i in alg.parameterAsEnums(parameters, p.name, context))
        return p.options[alg.parameterAsEnum(parameters, p.name, context)]
    if k in ("string", "numbers"):
        return alg.parameterAsString(parameters, p.name, context)
    if k == "points":
        return alg.parameterAsSource(parameters, p.name, context)
    if k == "field":
        return (alg.parameterAsFields(parameters, p.name, context) or [""])[0]
    if k == "files":
        return tuple(alg.parameterAsFileList(parameters, p.name, context)) or None
    if k in ("file_out", "folder_out"):
        return alg.parameterAsFileOutput(parameters, p.name, context) or None
    if k == "raster_out":
        return alg.parameterAsOutputLayer(parameters, p.name, context) or None
    raise ValueError(f"{p.name}: no value for kind {k}")
