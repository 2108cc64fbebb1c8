"""Regenerate tests/qgis/data/trajectory_model.model3 (run once, then commit the file).

    QT_QPA_PLATFORM=offscreen .venv-qgis/bin/python tests/qgis/make_model.py

The model has the inputs ``trajectory`` (file), ``crs`` and ``lever_arm``, one child
``eo`` = lidarphoto:trajectorytoeo and the model outputs ``eo:eo_points`` (the PointZ layer)
and ``eo:eo_table`` (the CSV).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
MODEL = HERE / "data" / "trajectory_model.model3"


def build_model():
    from qgis.core import (
        QgsProcessingModelAlgorithm,
        QgsProcessingModelChildAlgorithm,
        QgsProcessingModelOutput,
        QgsProcessingModelParameter,
        QgsProcessingParameterCrs,
        QgsProcessingParameterFile,
        QgsProcessingParameterString,
    )
    from qgis.core import QgsProcessingModelChildParameterSource as Src
    from qgis.PyQt.QtCore import QPointF

    model = QgsProcessingModelAlgorithm(
        "Trajectory to exterior orientation (model)", "LiDAR Photogrammetry", "lidarphoto"
    )
    inputs = [
        QgsProcessingParameterFile("trajectory", "Trajectory table (CSV)", extension="csv"),
        QgsProcessingParameterCrs("crs", "Mapping CRS", "EPSG:31983"),
        QgsProcessingParameterString("lever_arm", "Lever arm x,y,z (m)", "0,0,0"),
    ]
    for i, param in enumerate(inputs):
        component = QgsProcessingModelParameter(param.name())
        component.setPosition(QPointF(120.0, 60.0 + 70.0 * i))
        model.addModelParameter(param, component)

    child = QgsProcessingModelChildAlgorithm("lidarphoto:trajectorytoeo")
    child.setChildId("eo")
    child.setDescription("Trajectory to exterior orientation")
    child.setPosition(QPointF(420.0, 130.0))
    child.addParameterSources("INPUT", [Src.fromModelParameter("trajectory")])
    child.addParameterSources("CRS", [Src.fromModelParameter("crs")])
    child.addParameterSources("LEVER_ARM", [Src.fromModelParameter("lever_arm")])
    child.addParameterSources("MOUNT", [Src.fromStaticValue(0)])
    child.addParameterSources("MOUNT_MATRIX", [Src.fromStaticValue("")])
    child.addParameterSources("BORESIGHT", [Src.fromStaticValue("0,0,0")])
    outputs = {}
    for name, child_output in (("eo_points", "OUTPUT"), ("eo_table", "OUTPUT_CSV")):
        out = QgsProcessingModelOutput(name, name)
        out.setChildId("eo")
        out.setChildOutputName(child_output)
        out.setPosition(QPointF(700.0, 100.0 + 60.0 * len(outputs)))
        outputs[name] = out
    child.setModelOutputs(outputs)
    model.addChildAlgorithm(child)
    model.updateDestinationParameters()
    return model


if __name__ == "__main__":
    sys.path.insert(0, str(HERE))
    from model_tools import write_model

    raise SystemExit(write_model(build_model, MODEL))
