"""How orthophotos and seamlines look when QGIS loads them after a run."""

from __future__ import annotations

from typing import ClassVar

from qgis.core import (
    Qgis,
    QgsFillSymbol,
    QgsMultiBandColorRenderer,
    QgsProcessingLayerPostProcessorInterface,
    QgsRasterLayer,
    QgsSingleSymbolRenderer,
    QgsVectorLayer,
)


class OrthoStyle(QgsProcessingLayerPostProcessorInterface):
    """8-bit RGB orthophotos shown as they are (QGIS would stretch each band to its 2-98 %
    cut; the mask stays the transparency); seamline regions as outlines.

    QGIS takes ownership of each post-processor (one per layer) and deletes it with the
    processing context; the Python side keeps a reference until then (:meth:`create`)."""

    _alive: ClassVar[list] = []

    def postProcessLayer(self, layer, context, feedback):
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

    @classmethod
    def create(cls) -> OrthoStyle:
        """A new post-processor (QGIS owns and deletes it; never share one between layers)."""
        style = cls()
        cls._alive.append(style)
        return style
