"""lidarphoto:lidaraccuracy - swath-to-swath, within-swath and absolute vertical accuracy of a
LiDAR survey (ASPRS Ed. 2, 2023)."""

from __future__ import annotations

import math

from qgis.core import (
    QgsColorRampShader,
    QgsRasterLayer,
    QgsRasterShader,
    QgsSingleBandPseudoColorRenderer,
)
from qgis.PyQt.QtGui import QColor

from ...core.jobs import lidar_accuracy
from ..base import BaseAlgorithm


def style_swath_dz(layer) -> None:
    """The overlap differences dz (m) on a diverging ramp (blue below, white 0, red above)
    symmetric about 0, its limit the largest |dz| of the first band's statistics."""
    if not isinstance(layer, QgsRasterLayer) or not layer.isValid():
        return
    provider = layer.dataProvider()
    stats = provider.bandStatistics(1)
    limit = max(abs(stats.minimumValue), abs(stats.maximumValue))
    if not math.isfinite(limit) or limit <= 0:
        limit = 0.1
    shader = QgsColorRampShader(-limit, limit)
    shader.setColorRampType(QgsColorRampShader.Type.Interpolated)
    shader.setColorRampItemList([
        QgsColorRampShader.ColorRampItem(-limit, QColor(33, 102, 172), f"{-limit:.3f}"),
        QgsColorRampShader.ColorRampItem(0.0, QColor(247, 247, 247), "0"),
        QgsColorRampShader.ColorRampItem(limit, QColor(178, 24, 43), f"{limit:.3f}"),
    ])  # fmt: skip
    raster_shader = QgsRasterShader()
    raster_shader.setRasterShaderFunction(shader)
    renderer = QgsSingleBandPseudoColorRenderer(provider, 1, raster_shader)
    renderer.setClassificationMin(-limit)
    renderer.setClassificationMax(limit)
    layer.setRenderer(renderer)
    layer.triggerRepaint()


class LidarAccuracyAlgorithm(BaseAlgorithm):
    """Adapter of ``core.jobs.lidar_accuracy``: file outputs, the dz raster on a diverging
    colour ramp when QGIS loads it."""

    JOB = lidar_accuracy
    STYLES = (("OUTPUT_RASTER", style_swath_dz),)
