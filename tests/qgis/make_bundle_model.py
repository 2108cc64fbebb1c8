"""Regenerate tests/qgis/data/bundle_accuracy_model.model3 (run once, then commit the file).

    QT_HASH_SEED=0 QT_QPA_PLATFORM=offscreen PROJ_DATA=/usr/share/proj \
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


def build_model():
    from model_tools import add_child, add_inputs, new_model, output_of, param
    from qgis.core import (
        QgsProcessingParameterCrs,
        QgsProcessingParameterFile,
    )

    model = new_model("Bundle adjustment and accuracy report (model)", "lidarphoto")
    inputs = [
        QgsProcessingParameterFile("camera", "Camera (JSON)", extension="json"),
        QgsProcessingParameterFile("observations", "Image observations (CSV)", extension="csv"),
        QgsProcessingParameterFile("ground_points", "Ground points (CSV)", extension="csv"),
        QgsProcessingParameterFile("eo", "Exterior orientation (CSV)", extension="csv"),
        QgsProcessingParameterCrs("crs", "Mapping CRS", "EPSG:31983"),
    ]
    add_inputs(model, inputs, 120.0, 60.0, 70.0)

    sources = {key: param(name) for key, name in (
        ("CAMERA", "camera"), ("OBSERVATIONS", "observations"),
        ("GROUND_POINTS", "ground_points"), ("EO", "eo"), ("CRS", "crs"))}  # fmt: skip
    sources["AP_MODEL"] = 7  # all
    outputs = (("eo", "OUTPUT_EO"), ("check_points", "OUTPUT_CHECK_CSV"),
               ("points", "OUTPUT_POINTS_LAYER"))  # fmt: skip
    add_child(model, "lidarphoto:bundleadjustment", "bundle",
              "Bundle adjustment with self-calibration", (420.0, 140.0), sources, outputs,
              (720.0, 80.0))  # fmt: skip
    add_child(model, "lidarphoto:accuracyreport", "accuracy",
              "Accuracy report of the check points", (420.0, 360.0),
              {"INPUT": output_of("bundle", "OUTPUT_CHECK_CSV"), "CRS": param("crs")},
              (("report", "OUTPUT_HTML"), ("check_layer", "OUTPUT")), (720.0, 340.0))  # fmt: skip
    model.updateDestinationParameters()
    return model


if __name__ == "__main__":
    sys.path.insert(0, str(HERE))
    from model_tools import write_model

    raise SystemExit(write_model(build_model, MODEL))
