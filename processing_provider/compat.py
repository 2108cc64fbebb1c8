"""QGIS enums resolved once, for QGIS 3.22 to 4.x (STYLE.md section 5, rule 3).

The enums moved to ``Qgis.*`` in QGIS 3.30-3.36; the old class-scoped names are deprecated
aliases there. Each value is chosen with ``hasattr`` (never ``a or b``: several values are 0).
"""

from __future__ import annotations

from qgis.core import (
    Qgis,
    QgsCoordinateReferenceSystem,
    QgsFeatureSink,
    QgsProcessing,
    QgsProcessingParameterDefinition,
    QgsProcessingParameterField,
    QgsProcessingParameterFile,
    QgsProcessingParameterNumber,
    QgsWkbTypes,
)
from qgis.PyQt.QtCore import QVariant


def _members(new: str, old: object, names: dict[str, str]) -> list:
    """The values ``names`` (name in ``Qgis.<new>``: name in ``old``) of the enum ``Qgis.<new>``
    where this QGIS has it, else of the old class-scoped enum ``old``."""
    if hasattr(Qgis, new):
        return [getattr(getattr(Qgis, new), n) for n in names]
    return [getattr(old, n) for n in names.values()]


_SOURCES = {  # QGIS >= 3.36; before, QgsProcessing.SourceType
    "VectorPoint": "TypeVectorPoint",
    "VectorLine": "TypeVectorLine",
    "VectorPolygon": "TypeVectorPolygon",
    "File": "TypeFile",
    "Raster": "TypeRaster",
    "PointCloud": "TypePointCloud",
    "Vector": "TypeVector",  # any geometry or none
}
(
    SOURCE_VECTOR_POINT,
    SOURCE_VECTOR_LINE,
    SOURCE_VECTOR_POLYGON,
    SOURCE_FILE,
    SOURCE_RASTER,
    SOURCE_POINT_CLOUD,
    SOURCE_TABLE,
) = _members("ProcessingSourceType", QgsProcessing.SourceType, _SOURCES)
FLAG_ADVANCED, FLAG_OPTIONAL = _members(  # QGIS >= 3.36
    "ProcessingParameterFlag",
    QgsProcessingParameterDefinition.Flag,
    {"Advanced": "FlagAdvanced", "Optional": "FlagOptional"},
)
(FILE_BEHAVIOR_FILE,) = _members(  # QGIS >= 3.36
    "ProcessingFileParameterBehavior", QgsProcessingParameterFile.Behavior, {"File": "File"}
)
WKB_POINT_Z, WKB_LINESTRING_Z, WKB_POLYGON_Z, WKB_MULTIPOLYGON = _members(  # QGIS >= 3.30
    "WkbType",
    QgsWkbTypes.Type,
    {n: n for n in ("PointZ", "LineStringZ", "PolygonZ", "MultiPolygon")},
)
NUMBER_DOUBLE, NUMBER_INTEGER = _members(  # QGIS >= 3.36
    "ProcessingNumberParameterType",
    QgsProcessingParameterNumber.Type,
    {"Double": "Double", "Integer": "Integer"},
)
FIELD_TYPE_ANY, FIELD_TYPE_NUMERIC = _members(  # QGIS >= 3.36
    "ProcessingFieldParameterDataType",
    QgsProcessingParameterField.DataType,
    {"Any": "Any", "Numeric": "Numeric"},
)
(WKT_PREFERRED,) = _members(  # QGIS >= 3.36
    "CrsWktVariant", QgsCoordinateReferenceSystem.WktVariant, {"Preferred": "WKT_PREFERRED"}
)

SINK_FAST_INSERT = QgsFeatureSink.Flag.FastInsert  # same name on 3.22 and 4.x

# QgsField types: QVariant.<Type> works on 3.22 and is patched to QMetaType.Type on Qt6 builds
# (STYLE.md section 5, rule 4; flake8-qgis QGS402 is expected here).
FIELD_STRING = QVariant.String
FIELD_DOUBLE = QVariant.Double
FIELD_INT = QVariant.Int
