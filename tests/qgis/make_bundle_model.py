"""Regenerate tests/qgis/data/bundle_accuracy_model.model3 (run once, then commit the file).

    QT_QPA_PLATFORM=offscreen PROJ_DATA=/usr/share/proj \
        .venv-qgis/bin/python tests/qgis/make_bundle_model.py

Bundle adjustment -> accuracy report as one graphical model: ``bundle`` =
lidarphoto:bundleadjustment (AP_MODEL all) on the model inputs ``camera``, ``observations``,
``ground_points``, ``eo`` and ``crs``; ``accuracy`` = lidarphoto:accuracyreport on the bundle's
check-point table. Model outputs ``bundle:eo`` (CSV), ``bundle:check_points`` (CSV),
``bundle:points`` (PointZ), ``accuracy:report`` (HTML) and ``accuracy:check_layer`` (PointZ).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
MODEL = HERE / "data" / "bundle_accuracy_model.model3"


def _outputs(child, pairs, x, y0):
    from qgis.core import QgsProcessingModelOutput
    from qgis.PyQt.QtCore import QPointF

    outs = {}
    for name, child_output in pairs:
        o = QgsProcessingModelOutput(name, name)
        o.setChildId(child.childId())
        o.setChildOutputName(child_output)
        o.setPosition(QPointF(x, y0 + 60.0 * len(outs)))
        outs[name] = o
    child.setModelOutputs(outs)


def build_model():
    from model_tools import static_defaults
    from qgis.core import (
        QgsProcessingModelAlgorithm,
        QgsProcessingModelChildAlgorithm,
        QgsProcessingModelParameter,
        QgsProcessingParameterCrs,
        QgsProcessingParameterFile,
    )
    from qgis.core import QgsProcessingModelChildParameterSource as Src
    from qgis.PyQt.QtCore import QPointF

    model = QgsProcessingModelAlgorithm(
        "Bundle adjustment and accuracy report (model)", "LiDAR Photogrammetry", "lidarphoto"
    )
    inputs = [
        QgsProcessingParameterFile("camera", "Camera (JSON)", extension="json"),
        QgsProcessingParameterFile("observations", "Image observations (CSV)", extension="csv"),
        QgsProcessingParameterFile("ground_points", "Ground points (CSV)", extension="csv"),
        QgsProcessingParameterFile("eo", "Exterior orientation (CSV)", extension="csv"),
        QgsProcessingParameterCrs("crs", "Mapping CRS", "EPSG:31983"),
    ]
    for i, param in enumerate(inputs):
        component = QgsProcessingModelParameter(param.name())
        component.setPosition(QPointF(120.0, 60.0 + 70.0 * i))
        model.addModelParameter(param, component)

    bundle = QgsProcessingModelChildAlgorithm("lidarphoto:bundleadjustment")
    bundle.setChildId("bundle")
    bundle.setDescription("Bundle adjustment with self-calibration")
    bundle.setPosition(QPointF(420.0, 140.0))
    for key, name in (
        ("CAMERA", "camera"),
        ("OBSERVATIONS", "observations"),
        ("GROUND_POINTS", "ground_points"),
        ("EO", "eo"),
        ("CRS", "crs"),
    ):
        bundle.addParameterSources(key, [Src.fromModelParameter(name)])
    bundle.addParameterSources("AP_MODEL", [Src.fromStaticValue(7)])  # all
    _outputs(
        bundle,
        (
            ("eo", "OUTPUT_EO"),
            ("check_points", "OUTPUT_CHECK_CSV"),
            ("points", "OUTPUT_POINTS_LAYER"),
        ),
        720.0,
        80.0,
    )
    static_defaults(bundle)
    model.addChildAlgorithm(bundle)

    acc = QgsProcessingModelChildAlgorithm("lidarphoto:accuracyreport")
    acc.setChildId("accuracy")
    acc.setDescription("Accuracy report of the check points")
    acc.setPosition(QPointF(420.0, 360.0))
    acc.addParameterSources("INPUT", [Src.fromChildOutput("bundle", "OUTPUT_CHECK_CSV")])
    acc.addParameterSources("CRS", [Src.fromModelParameter("crs")])
    _outputs(acc, (("report", "OUTPUT_HTML"), ("check_layer", "OUTPUT")), 720.0, 340.0)
    static_defaults(acc)
    model.addChildAlgorithm(acc)
    model.updateDestinationParameters()
    return model


if __name__ == "__main__":
    sys.path.insert(0, str(HERE))
    from model_tools import write_model

    raise SystemExit(write_model(build_model, MODEL))
