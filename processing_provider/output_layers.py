"""Layers out, one rule for every algorithm: after a run, each CSV output that holds
coordinates (X, Y[, Z] or E, N[, U] columns: ground points, check points, image centres, LCPs,
residual tables) loads as a styled point layer in the run's CRS, and each LAS/LAZ output as a
point-cloud layer where this QGIS reads LAS/LAZ (the PDAL provider; elsewhere the file stays a
file output, its path in the results).

The base algorithm calls :func:`load_outputs` after the job; the layers go into the
context's temporary store and load when the algorithm completes, as QGIS's own outputs do."""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any
from urllib.parse import quote

from qgis.core import (
    QgsCoordinateReferenceSystem,
    QgsMarkerSymbol,
    QgsProcessingContext,
    QgsProperty,
    QgsSingleSymbolRenderer,
    QgsSymbolLayer,
    QgsVectorLayer,
)

#: Coordinate columns a table may carry, tried in this order: (x, y, z or "").
COORDINATE_COLUMNS = (("X", "Y", "Z"), ("x", "y", "z"), ("E", "N", "U"),
                      ("easting", "northing", "height"))  # fmt: skip
#: Flag columns that mark a point as rejected or an outlier (drawn red).
FLAG_COLUMNS = ("rejected", "outlier")
CLOUD_SUFFIXES = (".las", ".laz")


def table_columns(path: str) -> tuple[int, list[str]]:
    """(comment lines before the header, the header's column names) of a CSV file: a
    doubtful result's tables start with ``#`` warning lines (``core/jobs/common.py``)."""
    skipped = 0
    with open(path, encoding="utf-8", newline="") as fh:
        for line in fh:
            if line.startswith("#") or not line.strip():
                skipped += 1
                continue
            return skipped, next(csv.reader([line]))
    return skipped, []


def coordinate_columns(header: list[str]) -> tuple[str, str, str] | None:
    """The first (x, y, z) of :data:`COORDINATE_COLUMNS` the header holds (z "" when the
    table has no height column); None for a table without coordinates."""
    names = set(header)
    for x, y, z in COORDINATE_COLUMNS:
        if x in names and y in names:
            return x, y, (z if z in names else "")
    return None


def table_layer(path: str, crs: QgsCoordinateReferenceSystem, name: str) -> QgsVectorLayer | None:
    """The CSV ``path`` as a delimited-text point layer in ``crs``, styled; None when it holds
    no coordinate columns."""
    skipped, header = table_columns(path)
    columns = coordinate_columns(header)
    if columns is None:
        return None
    x, y, z = columns
    options = {"type": "csv", "delimiter": ",", "detectTypes": "yes", "geomType": "point",
               "xField": x, "yField": y, "skipLines": str(skipped), "spatialIndex": "no",
               "subsetIndex": "no", "watchFile": "no"}  # fmt: skip
    if z:
        options["zField"] = z
    if crs.isValid():
        options["crs"] = crs.authid() or crs.toWkt()
    uri = Path(path).resolve().as_uri() + "?" + "&".join(
        f"{k}={quote(v, safe=':,')}" for k, v in options.items()
    )  # fmt: skip
    layer = QgsVectorLayer(uri, name, "delimitedtext")
    if not layer.isValid():
        return None
    if crs.isValid():
        layer.setCrs(crs)
    style_table_points(layer)
    return layer


def style_table_points(layer: QgsVectorLayer) -> None:
    """A clear point symbol: a dark-outlined circle, blue, red where the row is flagged
    rejected or outlier (1)."""
    symbol = QgsMarkerSymbol.createSimple(
        {"name": "circle", "color": "31,120,180", "outline_color": "0,0,0", "size": "2.4"}
    )
    flags = [f for f in FLAG_COLUMNS if layer.fields().indexOf(f) >= 0]
    if flags:
        test = " or ".join(f'to_int("{f}") = 1' for f in flags)
        symbol.symbolLayer(0).setDataDefinedProperty(
            QgsSymbolLayer.Property.PropertyFillColor,
            QgsProperty.fromExpression(f"if({test}, '#e31a1c', '#1f78b4')"),
        )
    layer.setRenderer(QgsSingleSymbolRenderer(symbol))


def cloud_layer(path: str, name: str):
    """The LAS/LAZ ``path`` as a point-cloud layer, or None where this QGIS has no provider
    for it (Debian's 3.22: no PDAL) or cannot open it."""
    from .parameters import point_cloud_layers

    if not point_cloud_layers():
        return None
    from qgis.core import QgsPointCloudLayer

    layer = QgsPointCloudLayer(path, name, "pdal")
    return layer if layer.isValid() else None


def run_crs(raw: dict, data: Any) -> QgsCoordinateReferenceSystem:
    """The CRS of a run's coordinates: the job's CRS parameter, else the CRS its result
    carries (``crs_wkt``, ``crs``, or those of a tuple's items or of ``eo``); invalid when
    neither says."""
    given = raw.get("CRS")
    if isinstance(given, str) and given:
        crs = QgsCoordinateReferenceSystem(given)
        if not crs.isValid():
            crs = QgsCoordinateReferenceSystem.fromWkt(given)
        if crs.isValid():
            return crs
    items = list(data) if isinstance(data, tuple) else [data]
    items += [getattr(d, "eo", None) for d in list(items)]
    for item in items:
        wkt = getattr(item, "crs_wkt", None)
        if not wkt:
            pyproj_crs = getattr(item, "crs", None)
            wkt = pyproj_crs.to_wkt() if hasattr(pyproj_crs, "to_wkt") else None
        if isinstance(wkt, str) and wkt:
            crs = QgsCoordinateReferenceSystem.fromWkt(wkt)
            if crs.isValid():
                return crs
    return QgsCoordinateReferenceSystem()


def load_outputs(alg, raw: dict, data: Any, context, sinks: dict | None = None) -> list[str]:
    """Register every coordinate table and point cloud among ``alg``'s file outputs to load
    when the run completes; returns the paths registered. A table whose CRS the run does not
    know, or a cloud this QGIS cannot show, stays a file."""
    crs = None
    loaded = []
    for p in alg.spec.outputs:
        path = raw.get(p.name)
        if p.kind != "file_out" or not isinstance(path, str) or not Path(path).is_file():
            continue
        if p.layer_twin and (sinks or {}).get(p.layer_twin):
            continue  # the run wrote its layer twin: the same rows load once
        suffix = Path(path).suffix.lower()
        name = alg.spec_tr(p.label)
        layer = None
        if suffix == ".csv":
            crs = run_crs(raw, data) if crs is None else crs
            if not crs.isValid():
                continue
            layer = table_layer(path, crs, name)
        elif suffix in CLOUD_SUFFIXES:
            layer = cloud_layer(path, name)  # None: the path stays the output (results)
        if layer is None:
            continue
        context.temporaryLayerStore().addMapLayer(layer)
        details = QgsProcessingContext.LayerDetails(name, context.project(), p.name)
        context.addLayerToLoadOnCompletion(layer.id(), details)
        loaded.append(path)
    return loaded
