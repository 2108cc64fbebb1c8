"""Regenerate tests/qgis/data/lidar_control_model.model3 (run once, then commit the file).

    QT_QPA_PLATFORM=offscreen PROJ_DATA=/usr/share/proj \
        .venv-qgis/bin/python tests/qgis/make_lidar_control_model.py

The whole LiDAR-control chain as one graphical model: ``ground`` = lidarphoto:groundfilter ->
``roofs`` = lidarphoto:extractroofplanes -> ``lcps`` = lidarphoto:createlcps on the roof
child's plane table and plane-id cloud. Inputs ``cloud`` (LAS/LAZ) and ``epsilon`` (m); model
outputs ``lcps:control_points`` (PointZ), ``lcps:control_lines`` (LineStringZ) and
``lcps:control_table`` (CSV), besides those of tests/qgis/make_ground_roof_model.py.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
MODEL = HERE / "data" / "lidar_control_model.model3"


def build_model():
    from make_ground_roof_model import build_model as ground_roof_model
    from model_tools import static_defaults
    from qgis.core import QgsProcessingModelChildAlgorithm, QgsProcessingModelOutput
    from qgis.core import QgsProcessingModelChildParameterSource as Src
    from qgis.PyQt.QtCore import QPointF

    model = ground_roof_model()
    model.setName("Ground filter, roof planes and LiDAR control (model)")
    roofs = model.childAlgorithm("roofs")
    outputs = dict(roofs.modelOutputs())
    cloud_out = QgsProcessingModelOutput("plane_cloud", "plane_cloud")
    cloud_out.setChildId("roofs")
    cloud_out.setChildOutputName("OUTPUT_CLOUD")
    cloud_out.setPosition(QPointF(700.0, 320.0))
    outputs["plane_cloud"] = cloud_out
    roofs.setModelOutputs(outputs)
    model.setChildAlgorithm(roofs)

    lcps = QgsProcessingModelChildAlgorithm("lidarphoto:createlcps")
    lcps.setChildId("lcps")
    lcps.setDescription("Create LiDAR control points and lines")
    lcps.setPosition(QPointF(400.0, 380.0))
    lcps.addParameterSources("PLANES", [Src.fromChildOutput("roofs", "OUTPUT_CSV")])
    lcps.addParameterSources("CLOUD", [Src.fromChildOutput("roofs", "OUTPUT_CLOUD")])
    lcps.addParameterSources("DISTANCE_UNIT", [Src.fromStaticValue(1)])  # metres
    outs = {}
    for name, child_output in (
        ("control_points", "OUTPUT_POINTS"),
        ("control_lines", "OUTPUT_LINES"),
        ("control_table", "POINTS_CSV"),
    ):
        o = QgsProcessingModelOutput(name, name)
        o.setChildId("lcps")
        o.setChildOutputName(child_output)
        o.setPosition(QPointF(700.0, 400.0 + 60.0 * len(outs)))
        outs[name] = o
    lcps.setModelOutputs(outs)
    static_defaults(lcps)
    model.addChildAlgorithm(lcps)
    model.updateDestinationParameters()
    return model


if __name__ == "__main__":
    sys.path.insert(0, str(HERE))
    from model_tools import write_model

    raise SystemExit(write_model(build_model, MODEL))
