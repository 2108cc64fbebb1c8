"""Regenerate tests/qgis/data/ground_roof_model.model3 (run once, then commit the file).

    QT_QPA_PLATFORM=offscreen PROJ_DATA=/usr/share/proj \
        .venv-qgis/bin/python tests/qgis/make_ground_roof_model.py

The model has the inputs ``cloud`` (LAS/LAZ file) and ``epsilon`` (number, metres), the
children ``ground`` = lidarphoto:groundfilter (distances in metres) and ``roofs`` =
lidarphoto:extractroofplanes on the ground child's classified cloud (non-ground points,
distances in metres), and the model outputs ``roofs:roof_planes`` (PolygonZ layer),
``roofs:plane_table`` (CSV) and ``ground:classified_cloud`` (LAZ).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
MODEL = HERE / "data" / "ground_roof_model.model3"


def build_model():
    from model_tools import static_defaults
    from qgis.core import (
        QgsProcessingModelAlgorithm,
        QgsProcessingModelChildAlgorithm,
        QgsProcessingModelOutput,
        QgsProcessingModelParameter,
        QgsProcessingParameterFile,
        QgsProcessingParameterNumber,
    )
    from qgis.core import QgsProcessingModelChildParameterSource as Src
    from qgis.PyQt.QtCore import QPointF

    model = QgsProcessingModelAlgorithm(
        "Ground filter and roof planes (model)", "LiDAR Photogrammetry", "lidarphoto"
    )
    inputs = [
        QgsProcessingParameterFile("cloud", "Point cloud (LAS/LAZ)", extension="laz"),
        QgsProcessingParameterNumber(
            "epsilon", "Plane tolerance (m)", QgsProcessingParameterNumber.Type.Double, 0.15
        ),
    ]
    for i, param in enumerate(inputs):
        component = QgsProcessingModelParameter(param.name())
        component.setPosition(QPointF(120.0, 60.0 + 70.0 * i))
        model.addModelParameter(param, component)

    ground = QgsProcessingModelChildAlgorithm("lidarphoto:groundfilter")
    ground.setChildId("ground")
    ground.setDescription("Ground filter")
    ground.setPosition(QPointF(400.0, 80.0))
    ground.addParameterSources("INPUT", [Src.fromModelParameter("cloud")])
    ground.addParameterSources("DISTANCE_UNIT", [Src.fromStaticValue(1)])  # metres
    out = QgsProcessingModelOutput("classified_cloud", "classified_cloud")
    out.setChildId("ground")
    out.setChildOutputName("OUTPUT_CLOUD")
    out.setPosition(QPointF(650.0, 40.0))
    ground.setModelOutputs({"classified_cloud": out})
    static_defaults(ground)  # addChildAlgorithm stores a copy: complete the child first
    model.addChildAlgorithm(ground)

    roofs = QgsProcessingModelChildAlgorithm("lidarphoto:extractroofplanes")
    roofs.setChildId("roofs")
    roofs.setDescription("Extract roof planes")
    roofs.setPosition(QPointF(400.0, 220.0))
    roofs.addParameterSources("INPUT", [Src.fromChildOutput("ground", "OUTPUT_CLOUD")])
    roofs.addParameterSources("DISTANCE_UNIT", [Src.fromStaticValue(1)])  # metres
    roofs.addParameterSources("POINTS", [Src.fromStaticValue(0)])  # non-ground
    roofs.addParameterSources("EPSILON", [Src.fromModelParameter("epsilon")])
    outputs = {}
    for name, child_output in (("roof_planes", "OUTPUT"), ("plane_table", "OUTPUT_CSV")):
        o = QgsProcessingModelOutput(name, name)
        o.setChildId("roofs")
        o.setChildOutputName(child_output)
        o.setPosition(QPointF(700.0, 200.0 + 60.0 * len(outputs)))
        outputs[name] = o
    roofs.setModelOutputs(outputs)
    static_defaults(roofs)
    model.addChildAlgorithm(roofs)
    model.updateDestinationParameters()
    return model


if __name__ == "__main__":
    sys.path.insert(0, str(HERE))
    from model_tools import write_model

    raise SystemExit(write_model(build_model, MODEL))
