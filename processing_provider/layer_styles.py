"""How the toolkit's output layers look when QGIS loads them after a run: each style shows
what matters in that layer (roof planes coloured by id with outlines, LiDAR control points
sized by their sigma, control lines by kind, residual vectors scaled and labelled, the DTM as
a hillshade, 8-bit orthophotos as they are). An algorithm names them in ``STYLES`` ({output
name: style function}); the base class attaches them to the outputs QGIS will load."""

from __future__ import annotations

import colorsys
import math
from typing import Callable, ClassVar

from qgis.core import (
    Qgis,
    QgsCategorizedSymbolRenderer,
    QgsFillSymbol,
    QgsHillshadeRenderer,
    QgsLineSymbol,
    QgsMarkerSymbol,
    QgsMultiBandColorRenderer,
    QgsPalLayerSettings,
    QgsProcessingLayerPostProcessorInterface,
    QgsProperty,
    QgsRasterLayer,
    QgsRendererCategory,
    QgsSingleSymbolRenderer,
    QgsSymbolLayer,
    QgsTextFormat,
    QgsVectorLayer,
    QgsVectorLayerSimpleLabeling,
)
from qgis.PyQt.QtGui import QColor

#: Largest marker (mm) of a scaled symbol: the largest value of the layer gets it.
MAX_SIZE_MM = 8.0
MIN_SIZE_MM = 1.5


def _colour(k: int, n: int) -> QColor:
    """Distinct colours around the hue circle (golden-ratio steps: neighbours differ)."""
    h = (k * 0.618033988749895) % 1.0
    r, g, b = colorsys.hsv_to_rgb(h, 0.65, 0.95)
    return QColor(int(255 * r), int(255 * g), int(255 * b), 160)


def _largest(layer: QgsVectorLayer, expression: Callable[[object], float]) -> float:
    values = []
    for f in layer.getFeatures():
        try:
            v = float(expression(f))
        except (TypeError, ValueError, KeyError):
            continue
        if math.isfinite(v):
            values.append(abs(v))
    return max(values) if values else 0.0


def _scaled_size(field_expression: str, largest: float) -> QgsProperty:
    top = largest if largest > 0 else 1.0
    return QgsProperty.fromExpression(
        f"{MIN_SIZE_MM} + {MAX_SIZE_MM - MIN_SIZE_MM} * coalesce({field_expression}, 0) / {top!r}"
    )


def _label(layer: QgsVectorLayer, expression: str) -> None:
    settings = QgsPalLayerSettings()
    settings.fieldName = expression
    settings.isExpression = True
    fmt = QgsTextFormat()
    fmt.setSize(8)
    settings.setFormat(fmt)
    layer.setLabeling(QgsVectorLayerSimpleLabeling(settings))
    layer.setLabelsEnabled(True)


def style_planes(layer) -> None:
    """Roof planes: one colour per plane id, semi-transparent fill, dark outline."""
    if not isinstance(layer, QgsVectorLayer):
        return
    ids = sorted({f["id"] for f in layer.getFeatures()})
    categories = []
    for k, pid in enumerate(ids):
        symbol = QgsFillSymbol.createSimple({"outline_color": "40,40,40", "outline_width": "0.3"})
        symbol.setColor(_colour(k, len(ids)))
        categories.append(QgsRendererCategory(pid, symbol, str(pid)))
    layer.setRenderer(QgsCategorizedSymbolRenderer("id", categories))
    layer.triggerRepaint()


def style_lcps(layer) -> None:
    """LiDAR control points: circles whose size grows with the 3D sigma, labelled with it."""
    if not isinstance(layer, QgsVectorLayer):
        return
    sigma = 'sqrt("sigma_x"^2 + "sigma_y"^2 + "sigma_z"^2)'
    largest = _largest(layer, lambda f: math.hypot(f["sigma_x"], f["sigma_y"], f["sigma_z"]))
    symbol = QgsMarkerSymbol.createSimple(
        {"name": "circle", "color": "230,80,30,180", "outline_color": "0,0,0"}
    )
    symbol.setDataDefinedSize(_scaled_size(sigma, largest))
    layer.setRenderer(QgsSingleSymbolRenderer(symbol))
    _label(layer, f"'σ ' || format_number({sigma}, 3)")
    layer.triggerRepaint()


_KIND_COLOURS = {"ridge": "200,30,30", "hip": "240,150,0", "valley": "30,90,200",
                 "other": "120,120,120"}  # fmt: skip


def style_control_lines(layer) -> None:
    """LiDAR control lines coloured by kind (ridge, hip, valley, other)."""
    if not isinstance(layer, QgsVectorLayer):
        return
    categories = [
        QgsRendererCategory(
            kind, QgsLineSymbol.createSimple({"line_color": rgb, "line_width": "0.8"}), kind
        )
        for kind, rgb in _KIND_COLOURS.items()
    ]
    layer.setRenderer(QgsCategorizedSymbolRenderer("kind", categories))
    layer.triggerRepaint()


def _vector_style(layer, dx: str, dy_up: str, length: str, largest: float, label: str) -> None:
    """Arrows pointing along (dx, dy_up) (up = north on the map), sized by ``length``."""
    symbol = QgsMarkerSymbol.createSimple(
        {"name": "arrow", "color": "31,120,180", "outline_color": "0,0,0"}
    )
    symbol.setDataDefinedSize(_scaled_size(length, largest))
    symbol.setDataDefinedAngle(QgsProperty.fromExpression(f"degrees(atan2({dx}, {dy_up}))"))
    if layer.fields().indexOf("rejected") >= 0:
        symbol.symbolLayer(0).setDataDefinedProperty(
            QgsSymbolLayer.Property.PropertyFillColor,
            QgsProperty.fromExpression("if(\"rejected\" = 1, '#e31a1c', '#1f78b4')"),
        )
    layer.setRenderer(QgsSingleSymbolRenderer(symbol))
    _label(layer, label)
    layer.triggerRepaint()


def style_image_residuals(layer) -> None:
    """Image residuals (px): an arrow along (vx, vy) in the image (rows grow downwards), its
    size proportional to |v|, labelled "0.25 px"; rejected observations in red."""
    if not isinstance(layer, QgsVectorLayer):
        return
    largest = _largest(layer, lambda f: f["v"])
    _vector_style(layer, '"vx"', '-"vy"', '"v"', largest,
                  "format_number(\"v\", 2) || ' px'")  # fmt: skip


def style_discrepancies(layer) -> None:
    """Check-point discrepancies (m): an arrow along (dE, dN), its size proportional to the
    horizontal discrepancy, labelled with it and dU."""
    if not isinstance(layer, QgsVectorLayer):
        return
    largest = _largest(layer, lambda f: f["dHorizontal"])
    _vector_style(layer, '"dE"', '"dN"', '"dHorizontal"', largest,
                  "format_number(\"dHorizontal\", 3) || ' m, dU ' || "
                  "format_number(\"dU\", 3) || ' m'")  # fmt: skip


def style_dtm(layer) -> None:
    """A DTM or DSM as a hillshade (sun from the north-west, 45 deg high)."""
    if not isinstance(layer, QgsRasterLayer) or not layer.isValid():
        return
    renderer = QgsHillshadeRenderer(layer.dataProvider(), 1, 315.0, 45.0)
    renderer.setMultiDirectional(True)
    layer.setRenderer(renderer)
    layer.triggerRepaint()


def style_orthophoto(layer) -> None:
    """8-bit RGB orthophotos shown as they are (QGIS would stretch each band to its 2-98 %
    cut; the mask stays the transparency); seamline regions as outlines."""
    if isinstance(layer, QgsRasterLayer) and layer.bandCount() >= 3:
        if layer.dataProvider().dataType(1) == Qgis.DataType.Byte:
            renderer = QgsMultiBandColorRenderer(layer.dataProvider(), 1, 2, 3)
            if layer.renderer() is not None:
                renderer.setAlphaBand(layer.renderer().alphaBand())
            layer.setRenderer(renderer)
            layer.triggerRepaint()
    elif isinstance(layer, QgsVectorLayer):
        symbol = QgsFillSymbol.createSimple(
            {"color": "0,0,0,0", "outline_color": "255,230,0", "outline_width": "0.5"}
        )
        layer.setRenderer(QgsSingleSymbolRenderer(symbol))
        layer.triggerRepaint()


class LayerStyle(QgsProcessingLayerPostProcessorInterface):
    """Applies one style function to a layer QGIS loads after a run.

    QGIS takes ownership of each post-processor (one per layer) and deletes it with the
    processing context; the Python side keeps a reference until then (:meth:`create`)."""

    _alive: ClassVar[list] = []

    def __init__(self, func: Callable[[object], None]) -> None:
        super().__init__()
        self.func = func

    def postProcessLayer(self, layer, context, feedback):
        self.func(layer)

    @classmethod
    def create(cls, func: Callable[[object], None]) -> LayerStyle:
        style = cls(func)
        cls._alive.append(style)
        return style


class LayerInGroup(LayerStyle):
    """A style function, then the layer moved into the layer-tree group ``group`` (made at
    the top of the tree on first use): one run's orthophotos side by side in one group."""

    def __init__(self, func: Callable[[object], None], group: str) -> None:
        super().__init__(func)
        self.group = group

    def postProcessLayer(self, layer, context, feedback):
        super().postProcessLayer(layer, context, feedback)
        project = context.project()
        if project is None:
            return
        root = project.layerTreeRoot()
        node = root.findLayer(layer.id())
        if node is None:
            return
        group = root.findGroup(self.group) or root.insertGroup(0, self.group)
        if node.parent() is not group:
            group.addChildNode(node.clone())
            node.parent().removeChildNode(node)

    @classmethod
    def create_in(cls, func: Callable[[object], None], group: str) -> LayerInGroup:
        style = cls(func, group)
        cls._alive.append(style)
        return style
