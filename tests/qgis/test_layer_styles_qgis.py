"""Output layers load with a style that shows what matters: planes coloured by id with
outlines, LCPs sized by sigma, control lines by kind, residual vectors scaled, turned and
labelled, the DTM as a hillshade; a run that loads its results applies them."""

from __future__ import annotations

import numpy as np
import processing
import pytest
from lidarphoto.processing_provider.layer_styles import (
    MAX_SIZE_MM,
    MIN_SIZE_MM,
    style_control_lines,
    style_dtm,
    style_image_residuals,
    style_lcps,
    style_planes,
)
from qgis.core import (
    QgsExpressionContext,
    QgsExpressionContextUtils,
    QgsFeature,
    QgsGeometry,
    QgsPointXY,
    QgsProject,
    QgsRasterLayer,
    QgsVectorLayer,
)
from test_accuracy_report_qgis import _write_csv


def _layer(geometry: str, fields: str, rows: list[tuple]) -> QgsVectorLayer:
    layer = QgsVectorLayer(f"{geometry}?crs=EPSG:31983&{fields}", "t", "memory")
    feats = []
    for k, values in enumerate(rows):
        f = QgsFeature(layer.fields())
        f.setAttributes(list(values))
        if geometry == "Polygon":
            x = 10.0 * k
            f.setGeometry(QgsGeometry.fromWkt(f"POLYGON(({x} 0, {x + 5} 0, {x + 5} 5, {x} 0))"))
        elif geometry == "LineString":
            f.setGeometry(QgsGeometry.fromWkt(f"LINESTRING({k} 0, {k} 5)"))
        else:
            f.setGeometry(QgsGeometry.fromPointXY(QgsPointXY(float(k), 0.0)))
        feats.append(f)
    layer.dataProvider().addFeatures(feats)
    return layer


def _evaluate(layer, prop, feature):
    ctx = QgsExpressionContext(QgsExpressionContextUtils.globalProjectLayerScopes(layer))
    ctx.setFeature(feature)
    value, ok = prop.valueAsDouble(ctx, float("nan"))
    assert ok
    return value


def test_planes_are_coloured_by_id_with_outlines():
    layer = _layer("Polygon", "field=id:integer", [(3,), (7,), (12,)])
    style_planes(layer)
    r = layer.renderer()
    assert r.type() == "categorizedSymbol" and r.classAttribute() == "id"
    cats = r.categories()
    assert [c.value() for c in cats] == [3, 7, 12]
    colours = {c.symbol().color().name() for c in cats}
    assert len(colours) == 3  # one colour per plane
    for c in cats:
        outline = c.symbol().symbolLayer(0)
        assert outline.strokeColor().name() == "#282828" and outline.strokeWidth() > 0


def test_lcps_are_sized_by_their_sigma_and_labelled():
    rows = [(1, 0.01, 0.01, 0.02), (2, 0.03, 0.04, 0.12)]
    layer = _layer("Point", "field=id:integer&field=sigma_x:double&field=sigma_y:double"
                   "&field=sigma_z:double", rows)  # fmt: skip
    style_lcps(layer)
    symbol = layer.renderer().symbol()
    prop = symbol.dataDefinedSize()
    assert prop.isActive()
    feats = list(layer.getFeatures())
    small, large = (_evaluate(layer, prop, f) for f in feats)
    assert large == pytest.approx(MAX_SIZE_MM)  # the largest sigma gets the largest marker
    s_small, s_large = np.linalg.norm(rows[0][1:]), np.linalg.norm(rows[1][1:])
    expected = MIN_SIZE_MM + (MAX_SIZE_MM - MIN_SIZE_MM) * s_small / s_large
    assert small == pytest.approx(expected)
    assert layer.labelsEnabled() and "format_number" in layer.labeling().settings().fieldName


def test_control_lines_by_kind():
    layer = _layer("LineString", "field=kind:string", [("ridge",), ("valley",)])
    style_control_lines(layer)
    r = layer.renderer()
    assert r.classAttribute() == "kind"
    assert {c.value() for c in r.categories()} == {"ridge", "hip", "valley", "other"}


def test_image_residuals_are_arrows_scaled_turned_and_labelled():
    rows = [(1.0, 0.0, 1.0, 0), (0.0, -0.5, 0.5, 1)]  # right; up in the image (rejected)
    layer = _layer("Point", "field=vx:double&field=vy:double&field=v:double"
                   "&field=rejected:integer", rows)  # fmt: skip
    style_image_residuals(layer)
    symbol = layer.renderer().symbol()
    assert symbol.symbolLayer(0).shape() == symbol.symbolLayer(0).Shape.Arrow
    right, up = layer.getFeatures()
    angle = symbol.dataDefinedAngle()
    assert _evaluate(layer, angle, right) == pytest.approx(90.0)  # clockwise from up
    assert _evaluate(layer, angle, up) == pytest.approx(0.0)
    size = symbol.dataDefinedSize()
    assert _evaluate(layer, size, right) == pytest.approx(MAX_SIZE_MM)
    assert _evaluate(layer, size, up) == pytest.approx((MIN_SIZE_MM + MAX_SIZE_MM) / 2)
    assert "' px'" in layer.labeling().settings().fieldName


def test_dtm_is_a_hillshade(tmp_path):
    from osgeo import gdal, osr

    path = str(tmp_path / "dtm.tif")
    ds = gdal.GetDriverByName("GTiff").Create(path, 20, 20, 1, gdal.GDT_Float32)
    ds.SetGeoTransform((500000, 1, 0, 7450020, 0, -1))
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(31983)
    ds.SetProjection(srs.ExportToWkt())
    ds.GetRasterBand(1).WriteArray(np.add.outer(np.arange(20.0), np.arange(20.0)))
    ds = None
    layer = QgsRasterLayer(path, "dtm")
    style_dtm(layer)
    assert layer.renderer().type() == "hillshade"


def test_accuracy_report_loads_its_layer_styled(provider, tmp_path):
    table = _write_csv(tmp_path / "cp.csv")
    project = QgsProject.instance()
    before = set(project.mapLayers())
    try:
        processing.runAndLoadResults(
            "lidarphoto:accuracyreport",
            {"INPUT": str(table), "CRS": "EPSG:31983", "OUTPUT": "TEMPORARY_OUTPUT"},
        )
        added = [project.mapLayer(i) for i in set(project.mapLayers()) - before]
        layer = next(lyr for lyr in added if isinstance(lyr, QgsVectorLayer))
        symbol = layer.renderer().symbol()
        assert symbol.dataDefinedAngle().isActive() and symbol.dataDefinedSize().isActive()
        assert layer.labelsEnabled() and "dU" in layer.labeling().settings().fieldName
    finally:
        project.removeMapLayers(list(set(project.mapLayers()) - before))
