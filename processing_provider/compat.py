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

if hasattr(Qgis, "ProcessingSourceType"):  # QGIS >= 3.36
    SOURCE_VECTOR_POINT = Qgis.ProcessingSourceType.VectorPoint
    SOURCE_VECTOR_LINE = Qgis.ProcessingSourceType.VectorLine
    SOURCE_VECTOR_POLYGON = Qgis.ProcessingSourceType.VectorPolygon
    SOURCE_FILE = Qgis.ProcessingSourceType.File
    SOURCE_RASTER = Qgis.ProcessingSourceType.Raster
    SOURCE_POINT_CLOUD = Qgis.ProcessingSourceType.PointCloud
    SOURCE_TABLE = Qgis.ProcessingSourceType.Vector  # any geometry or none
else:  # QGIS 3.22-3.34
    SOURCE_VECTOR_POINT = QgsProcessing.SourceType.TypeVectorPoint
    SOURCE_VECTOR_LINE = QgsProcessing.SourceType.TypeVectorLine
    SOURCE_VECTOR_POLYGON = QgsProcessing.SourceType.TypeVectorPolygon
    SOURCE_FILE = QgsProcessing.SourceType.TypeFile
    SOURCE_RASTER = QgsProcessing.SourceType.TypeRaster
    SOURCE_POINT_CLOUD = QgsProcessing.SourceType.TypePointCloud
    SOURCE_TABLE = QgsProcessing.SourceType.TypeVector

if hasattr(Qgis, "ProcessingParameterFlag"):  # QGIS >= 3.36
    FLAG_ADVANCED = Qgis.ProcessingParameterFlag.Advanced
    FLAG_OPTIONAL = Qgis.ProcessingParameterFlag.Optional
else:
    FLAG_ADVANCED = QgsProcessingParameterDefinition.Flag.FlagAdvanced
    FLAG_OPTIONAL = QgsProcessingParameterDefinition.Flag.FlagOptional

if hasattr(Qgis, "ProcessingFileParameterBehavior"):  # QGIS >= 3.36
    FILE_BEHAVIOR_FILE = Qgis.ProcessingFileParameterBehavior.File
else:
    FILE_BEHAVIOR_FILE = QgsProcessingParameterFile.Behavior.File

if hasattr(Qgis, "WkbType"):  # QGIS >= 3.30
    WKB_POINT_Z = Qgis.WkbType.PointZ
    WKB_LINESTRING_Z = Qgis.WkbType.LineStringZ
    WKB_POLYGON_Z = Qgis.WkbType.PolygonZ
    WKB_MULTIPOLYGON = Qgis.WkbType.MultiPolygon
else:
    WKB_POINT_Z = QgsWkbTypes.Type.PointZ
    WKB_LINESTRING_Z = QgsWkbTypes.Type.LineStringZ
    WKB_POLYGON_Z = QgsWkbTypes.Type.PolygonZ
    WKB_MULTIPOLYGON = QgsWkbTypes.Type.MultiPolygon

if hasattr(Qgis, "ProcessingNumberParameterType"):  # QGIS >= 3.36
    NUMBER_DOUBLE = Qgis.ProcessingNumberParameterType.Double
    NUMBER_INTEGER = Qgis.ProcessingNumberParameterType.Integer
else:  # QGIS 3.22-3.34
    NUMBER_DOUBLE = QgsProcessingParameterNumber.Type.Double
    NUMBER_INTEGER = QgsProcessingParameterNumber.Type.Integer

if hasattr(Qgis, "ProcessingFieldParameterDataType"):  # QGIS >= 3.36
    FIELD_TYPE_ANY = Qgis.ProcessingFieldParameterDataType.Any
    FIELD_TYPE_NUMERIC = Qgis.ProcessingFieldParameterDataType.Numeric
else:
    FIELD_TYPE_ANY = QgsProcessingParameterField.DataType.Any
    FIELD_TYPE_NUMERIC = QgsProcessingParameterField.DataType.Numeric

if hasattr(Qgis, "CrsWktVariant"):  # QGIS >= 3.36
    WKT_PREFERRED = Qgis.CrsWktVariant.Preferred
else:
    WKT_PREFERRED = QgsCoordinateReferenceSystem.WktVariant.WKT_PREFERRED

SINK_FAST_INSERT = QgsFeatureSink.Flag.FastInsert  # same name on 3.22 and 4.x

# QgsField types: QVariant.<Type> works on 3.22 and is patched to QMetaType.Type on Qt6 builds
# (STYLE.md section 5, rule 4; flake8-qgis QGS402 is expected here).
FIELD_STRING = QVariant.String
FIELD_DOUBLE = QVariant.Double
FIELD_INT = QVariant.Int
