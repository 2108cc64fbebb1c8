"""Regenerate tests/qgis/data/resection_model.model3 (run once, then commit the file).

    QT_QPA_PLATFORM=offscreen PROJ_DATA=/usr/share/proj \
        .venv-qgis/bin/python tests/qgis/make_resection_model.py

LiDAR control to image orientation as one graphical model: ``lcps`` = lidarphoto:createlcps
(roof plane table + plane-id cloud -> LCP and line tables) -> ``resect`` =
lidarphoto:resection of the images from their observations of those LCPs and lines, without
approximate values. Inputs: camera, observations, planes, cloud, crs; model outputs
``lcps:lcp_table``, ``lcps:line_table`` (CSV) and ``resect:eo`` (EO CSV with sigmas).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
MODEL = HERE / "data" / "resection_model.model3"


def build_model():
    from model_tools import static_defaults
    from qgis.core import (
        QgsProcessingModelAlgorithm,
        QgsProcessingModelChildAlgorithm,
        QgsProcessingModelOutput,
        QgsProcessingModelParameter,
        QgsProcessingParameterCrs,
        QgsProcessingParameterFile,
    )
    from qgis.core import QgsProcessingModelChildParameterSource as Src
    from qgis.PyQt.QtCore import QPointF

    model = QgsProcessingModelAlgorithm(
        "LiDAR control to space resection (model)", "LiDAR Photogrammetry"
    )
    inputs = [
        QgsProcessingParameterFile("camera", "Camera (JSON)"),
        QgsProcessingParameterFile("observations", "Image observations (CSV)"),
        QgsProcessingParameterFile("planes", "Roof planes (CSV)"),
        QgsProcessingParameterFile("cloud", "Cloud with plane ids (LAS/LAZ)"),
        QgsProcessingParameterCrs("crs", "Mapping CRS"),
    ]
    for k, p in enumerate(inputs):
        mp = QgsProcessingModelParameter(p.name())
        mp.setPosition(QPointF(80.0, 60.0 + 50.0 * k))
        model.addModelParameter(p, mp)

    lcps = QgsProcessingModelChildAlgorithm("lidarphoto:createlcps")
    lcps.setChildId("lcps")
    lcps.setDescription("Create LiDAR control points and lines")
    lcps.setPosition(QPointF(400.0, 120.0))
    lcps.addParameterSources("PLANES", [Src.fromModelParameter("planes")])
    lcps.addParameterSources("CLOUD", [Src.fromModelParameter("cloud")])
    outs = {}
    for name, child_output in (("lcp_table", "POINTS_CSV"), ("line_table", "LINES_CSV")):
        o = QgsProcessingModelOutput(name, name)
        o.setChildId("lcps")
        o.setChildOutputName(child_output)
        o.setPosition(QPointF(700.0, 80.0 + 50.0 * len(outs)))
        outs[name] = o
    lcps.setModelOutputs(outs)
    static_defaults(lcps)
    model.addChildAlgorithm(lcps)

    resect = QgsProcessingModelChildAlgorithm("lidarphoto:resection")
    resect.setChildId("resect")
    resect.setDescription("Space resection from points and lines")
    resect.setPosition(QPointF(400.0, 320.0))
    resect.addParameterSources("CAMERA", [Src.fromModelParameter("camera")])
    resect.addParameterSources("OBSERVATIONS", [Src.fromModelParameter("observations")])
    resect.addParameterSources("CRS", [Src.fromModelParameter("crs")])
    resect.addParameterSources("CONTROL_POINTS", [Src.fromChildOutput("lcps", "POINTS_CSV")])
    resect.addParameterSources("CONTROL_LINES", [Src.fromChildOutput("lcps", "LINES_CSV")])
    eo = QgsProcessingModelOutput("eo", "eo")
    eo.setChildId("resect")
    eo.setChildOutputName("OUTPUT_EO")
    eo.setPosition(QPointF(700.0, 320.0))
    resect.setModelOutputs({"eo": eo})
    static_defaults(resect)
    model.addChildAlgorithm(resect)
    model.updateDestinationParameters()
    return model


if __name__ == "__main__":
    sys.path.insert(0, str(HERE))
    from model_tools import write_model

    raise SystemExit(write_model(build_model, MODEL))
