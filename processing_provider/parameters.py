"""Core parameter specs (core/jobs/spec.py) as QGIS Processing parameters, and back."""

from __future__ import annotations

import os
from typing import Any, Callable

from qgis.core import (
    QgsProcessingException,
    QgsProcessingOutputNumber,
    QgsProcessingOutputString,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterCrs,
    QgsProcessingParameterDefinition,
    QgsProcessingParameterEnum,
    QgsProcessingParameterExtent,
    QgsProcessingParameterFeatureSink,
    QgsProcessingParameterFeatureSource,
    QgsProcessingParameterField,
    QgsProcessingParameterFile,
    QgsProcessingParameterFileDestination,
    QgsProcessingParameterFolderDestination,
    QgsProcessingParameterMapLayer,
    QgsProcessingParameterMatrix,
    QgsProcessingParameterMultipleLayers,
    QgsProcessingParameterNumber,
    QgsProcessingParameterPointCloudLayer,
    QgsProcessingParameterRasterDestination,
    QgsProcessingParameterRasterLayer,
    QgsProcessingParameterString,
    QgsProcessingParameterVectorLayer,
)
from qgis.PyQt.QtCore import QCoreApplication, QUrl

from ..core.io.suffixes import IMAGE_SUFFIXES
from ..core.jobs.spec import FILE_KINDS, AlgorithmSpec, Param, Result, facts_line
from .compat import (
    FIELD_TYPE_ANY,
    FIELD_TYPE_NUMERIC,
    FILE_BEHAVIOR_FILE,
    FLAG_ADVANCED,
    FLAG_OPTIONAL,
    NUMBER_DOUBLE,
    NUMBER_INTEGER,
    SOURCE_FILE,
    SOURCE_POINT_CLOUD,
    SOURCE_RASTER,
    SOURCE_TABLE,
    SOURCE_VECTOR_LINE,
    SOURCE_VECTOR_POINT,
    SOURCE_VECTOR_POLYGON,
    WKT_PREFERRED,
)
from .i18n import help_tr


def _all_files() -> str:
    return QCoreApplication.translate("LidarPhotoProvider", "All files (*.*)")


def point_cloud_layers() -> bool:
    """Whether this QGIS reads LAS/LAZ as point-cloud layers (the PDAL provider: QGIS 3.26+
    builds with PDAL; Debian's 3.22 has none)."""
    from qgis.core import QgsProviderRegistry

    return "pdal" in QgsProviderRegistry.instance().providerList()


def is_extent(p: Param) -> bool:
    """A four-number extent (xmin, ymin, xmax, ymax in the algorithm's CRS): QGIS's extent
    widget (drawn on the map, taken from a layer, or typed)."""
    return p.kind == "numbers" and p.count == 4 and p.name.endswith("EXTENT")


def matrix_shape(p: Param) -> tuple[int, list[str]]:
    """(rows, column headers) of the table widget of a list of numbers: one row headed by the
    names the label lists after its colon or as its last word ("Lever arm x,y,z"), or a 3 x 3
    matrix for nine numbers."""
    if p.count == 9:
        return 3, ["1", "2", "3"]
    text = p.label.split(":", 1)[1] if ":" in p.label else p.label.rsplit(" ", 1)[-1]
    names = [n.strip() for n in text.split(",") if n.strip()]
    if len(names) != p.count:
        names = [str(k + 1) for k in range(p.count)]
    return 1, names


def read_numbers(alg, p: Param, parameters: dict, context):
    """A list of numbers from its widget: the extent in the CRS of the algorithm's CRS
    parameter (when it has one), the table's cells in order; "" when left empty."""
    value = parameters.get(p.name)
    if value in (None, "", []):
        return ""
    if is_extent(p):
        crs = (
            alg.parameterAsCrs(parameters, "CRS", context)
            if alg.parameterDefinition("CRS")
            else None
        )
        rect = (
            alg.parameterAsExtent(parameters, p.name, context, crs)
            if crs is not None and crs.isValid()
            else alg.parameterAsExtent(parameters, p.name, context)
        )
        if rect.isNull():
            return ""
        return (rect.xMinimum(), rect.yMinimum(), rect.xMaximum(), rect.yMaximum())
    cells = alg.parameterAsMatrix(parameters, p.name, context)
    return tuple(cells) if cells else ""


def layer_input(p: Param) -> bool:
    """Whether QGIS offers the project's layers for ``p`` (a file is accepted too): the layer
    kinds of core/jobs/spec.py, except a point cloud where this QGIS reads no LAS/LAZ (a file
    parameter there, so one spec works on QGIS with and without PDAL)."""
    if p.kind == "pointcloud":
        return point_cloud_layers()
    return p.kind in ("raster", "surface", "table")


def raster_files(p: Param) -> bool:
    """Whether a list of files is a list of images (every ending one GDAL reads as a raster):
    QGIS then offers the project's raster layers, and files and folders as well."""
    return p.kind == "files" and bool(p.suffixes) and set(p.suffixes) <= set(IMAGE_SUFFIXES)


_SINK_TYPES = {
    "point": SOURCE_VECTOR_POINT,
    "line": SOURCE_VECTOR_LINE,
    "polygon": SOURCE_VECTOR_POLYGON,
}
#: The QGIS class of each output kind of the spec.
_DESTINATIONS = {
    "folder_out": QgsProcessingParameterFolderDestination,
    "file_out": QgsProcessingParameterFileDestination,
    "raster_out": QgsProcessingParameterRasterDestination,
    "sink": QgsProcessingParameterFeatureSink,
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
    if layer_input(p):  # the project's layers, or a file
        q = layer_parameter(p, title)
    elif k in FILE_KINDS:  # a file (and a cloud where QGIS reads no LAS/LAZ)
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
    elif k == "numbers" and is_extent(p):
        q = QgsProcessingParameterExtent(p.name, title, None, p.optional)
    elif k == "numbers":
        rows, headers = matrix_shape(p)
        default = list(p.default) if p.default else None
        # QGIS refuses a matrix left out even with a default: the job's default then applies
        optional = p.optional or default is not None
        q = QgsProcessingParameterMatrix(p.name, title, rows, True, headers, default, optional)
    elif k == "string":
        q = QgsProcessingParameterString(p.name, title, p.default_text(), False, p.optional)
    elif k == "points":
        q = QgsProcessingParameterFeatureSource(
            p.name, title, [SOURCE_VECTOR_POINT], optional=p.optional
        )
    elif k == "field":
        q = QgsProcessingParameterField(
            p.name,
            title,
            None,
            p.parent,
            FIELD_TYPE_NUMERIC if p.numeric_field else FIELD_TYPE_ANY,
            optional=True,
        )
    elif raster_files(p):
        q = RasterFilesParameter(p.name, title, SOURCE_RASTER, None, p.optional)
    elif k == "files":
        q = QgsProcessingParameterMultipleLayers(p.name, title, SOURCE_FILE, None, p.optional)
    elif k in _DESTINATIONS:  # an output: its class, and what it takes besides the name
        extra = ()
        if k == "file_out":
            extra = (tr(p.file_filter),)
        elif k == "sink":
            extra = (_SINK_TYPES[p.geometry],)
        q = _DESTINATIONS[k](
            p.name,
            title,
            *extra,
            optional=p.optional,
            createByDefault=p.create_by_default,
        )
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
    if layer_input(p):
        return layer_file(alg, p, parameters, context)
    if k in FILE_KINDS:
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
    if k == "numbers":
        return read_numbers(alg, p, parameters, context)
    if k == "string":
        return alg.parameterAsString(parameters, p.name, context)
    if k == "points":
        return alg.parameterAsSource(parameters, p.name, context)
    if k == "field":
        return (alg.parameterAsFields(parameters, p.name, context) or [""])[0]
    if raster_files(p):
        return raster_file_list(p, parameters.get(p.name), context) or None
    if k == "files":
        return tuple(alg.parameterAsFileList(parameters, p.name, context)) or None
    if k in ("file_out", "folder_out"):
        return alg.parameterAsFileOutput(parameters, p.name, context) or None
    if k == "raster_out":
        return alg.parameterAsOutputLayer(parameters, p.name, context) or None
    raise ValueError(f"{p.name}: no value for kind {k}")


class _FileAccepted:
    """Mixin of the layer parameters: a path of an existing file is accepted as it is (a
    LAS/LAZ where QGIS has no point-cloud provider, a CSV with comment lines, qgis_process's
    arguments, a model input of type file): the job reads the file itself."""

    def checkValueIsAcceptable(self, value, context=None) -> bool:
        if isinstance(value, str) and os.path.isfile(value):
            return True
        return super().checkValueIsAcceptable(value, context)  # type: ignore[misc]

    def _copied(self, copy):
        copy.setFlags(self.flags())
        copy.setHelp(self.help())
        return copy


class LayerOrFileParameter(_FileAccepted, QgsProcessingParameterMapLayer):
    """A DSM: a raster layer, a point-cloud layer (where QGIS has PDAL) or a file."""

    def clone(self):
        return self._copied(LayerOrFileParameter(
            self.name(), self.description(), self.defaultValue(), False, self.dataTypes()
        ))  # fmt: skip


class RasterOrFileParameter(_FileAccepted, QgsProcessingParameterRasterLayer):
    """A raster layer of the project or a raster file."""

    def clone(self):
        return self._copied(
            RasterOrFileParameter(self.name(), self.description(), self.defaultValue())
        )


class PointCloudOrFileParameter(_FileAccepted, QgsProcessingParameterPointCloudLayer):
    """A point-cloud layer of the project or a LAS/LAZ file."""

    def clone(self):
        return self._copied(
            PointCloudOrFileParameter(self.name(), self.description(), self.defaultValue())
        )


class TableOrFileParameter(_FileAccepted, QgsProcessingParameterVectorLayer):
    """A vector layer of the project (with or without geometry) backed by a CSV, or a CSV."""

    def clone(self):
        return self._copied(TableOrFileParameter(
            self.name(), self.description(), self.dataTypes(), self.defaultValue()
        ))  # fmt: skip


class RasterFilesParameter(QgsProcessingParameterMultipleLayers):
    """Images: raster layers of the project, image files and folders of images (the job
    expands a folder with its endings), in any mix."""

    def checkValueIsAcceptable(self, value, context=None) -> bool:
        items = value if isinstance(value, (list, tuple)) else [value]
        if items and all(isinstance(i, str) and os.path.exists(i) for i in items):
            return True
        return super().checkValueIsAcceptable(value, context)

    def clone(self):
        copy = RasterFilesParameter(
            self.name(),
            self.description(),
            self.layerType(),
            self.defaultValue(),
            bool(self.flags() & FLAG_OPTIONAL),
        )
        copy.setFlags(self.flags())
        copy.setHelp(self.help())
        return copy


def raster_file_list(p: Param, value, context) -> tuple[str, ...]:
    """The files of an image list (:class:`RasterFilesParameter`): a path (file or folder)
    as it is, a raster layer (the object or its id) its GDAL file, other text as a path (the
    job names a missing file); a layer not backed by a raster file refused by name."""
    from qgis.core import QgsMapLayer, QgsProcessingUtils

    if value in (None, ""):
        return ()
    items = value if isinstance(value, (list, tuple)) else [value]
    files: list[str] = []
    for item in items:
        if isinstance(item, str) and (not item or os.path.exists(item)):
            files += [item] if item else []
            continue
        layer = item if isinstance(item, QgsMapLayer) else (
            QgsProcessingUtils.mapLayerFromString(str(item), context)
        )  # fmt: skip
        if layer is None:
            files.append(str(item))
            continue
        files.append(kind_file(p.name, layer, "raster"))
    return tuple(files)


def layer_parameter(p: Param, title: str) -> QgsProcessingParameterDefinition:
    """The layer parameter of a layer kind (see :func:`layer_input`)."""
    if p.kind == "raster":
        return RasterOrFileParameter(p.name, title, None, p.optional)
    if p.kind == "pointcloud":
        return PointCloudOrFileParameter(p.name, title, None, p.optional)
    if p.kind == "table":
        return TableOrFileParameter(p.name, title, [SOURCE_TABLE], None, p.optional)
    types = [SOURCE_RASTER] + ([SOURCE_POINT_CLOUD] if point_cloud_layers() else [])
    return LayerOrFileParameter(p.name, title, None, p.optional, types)


#: What each layer kind's file must be: (providers, file endings or () for any).
_LAYER_FILES = {
    "raster": (("gdal",), ()),
    "pointcloud": (("pdal", "copc"), (".las", ".laz")),
    "surface": (("gdal", "pdal", "copc"), ()),
    "table": (("delimitedtext", "ogr"), (".csv", ".txt")),
}


def _file_format(kind: str) -> str:
    """The name of a layer kind's file format, translated (the refusal's ``{what}``)."""
    names = {
        "raster": QCoreApplication.translate("LidarPhotoProvider", "raster"),
        "pointcloud": QCoreApplication.translate("LidarPhotoProvider", "LAS/LAZ"),
        "surface": QCoreApplication.translate("LidarPhotoProvider", "raster or LAS/LAZ"),
        "table": QCoreApplication.translate("LidarPhotoProvider", "CSV"),
    }
    return names[kind]


def layer_source_file(layer) -> str:
    """The file behind ``layer`` ("" when it has none): a delimited-text layer's file from its
    URI, an OGR or GDAL source without its ``|layername=`` / ``|option`` suffixes, a
    point-cloud layer's source."""
    provider, source = layer.providerType(), layer.source()
    if provider == "delimitedtext":
        path = QUrl(source).toLocalFile()
    elif provider in ("ogr", "gdal"):
        path = source.split("|")[0]
    elif provider in ("pdal", "copc"):
        path = source
    else:  # memory, database, web service, ...
        path = ""
    return path if path and os.path.isfile(path) else ""


def layer_file(alg, p: Param, parameters: dict, context) -> str | None:
    """The file behind a layer parameter: a path given as text is taken as it is (a LAS/LAZ
    where QGIS has no point-cloud provider, qgis_process's arguments); a layer of the project
    gives its file (:func:`layer_source_file`), which must be of the kind's format; a layer
    not backed by such a file (memory, database, another format) is refused by name."""
    value = parameters.get(p.name)
    if isinstance(value, str) and os.path.isfile(value):
        return value
    layer = alg.parameterAsLayer(parameters, p.name, context)
    if layer is None:  # not a layer: the text as a path (the job names a missing file)
        return value if isinstance(value, str) and value else None
    return kind_file(p.name, layer, p.kind)


def kind_file(name: str, layer, kind: str) -> str:
    """The file behind ``layer`` (:func:`layer_source_file`) when it is of the layer kind's
    format; else QgsProcessingException naming the parameter ``name`` and the layer."""
    providers, endings = _LAYER_FILES[kind]
    path = layer_source_file(layer)
    if (
        not path
        or layer.providerType() not in providers
        or (endings and not path.lower().endswith(endings))
    ):
        raise QgsProcessingException(
            QCoreApplication.translate(
                "LidarPhotoProvider",
                "{name}: the layer {layer} is not backed by a {what} file ({source}); "
                "save it as one first",
            ).format(name=name, layer=layer.name(), what=_file_format(kind), source=layer.source())
        )
    return path
