"""Regenerate tests/qgis/data/resection_model.model3 (run once, then commit the file).

    QT_HASH_SEED=0 QT_QPA_PLATFORM=offscreen PROJ_DATA=/usr/share/proj \
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
    from model_tools import add_child, add_inputs, new_model, output_of, param
    from qgis.core import (
        QgsProcessingParameterCrs,
        QgsProcessingParameterFile,
    )

    model = new_model("LiDAR control to space resection (model)")
    inputs = [
        QgsProcessingParameterFile("camera", "Camera (JSON)"),
        QgsProcessingParameterFile("observations", "Image observations (CSV)"),
        QgsProcessingParameterFile("planes", "Roof planes (CSV)"),
        QgsProcessingParameterFile("cloud", "Cloud with plane ids (LAS/LAZ)"),
        QgsProcessingParameterCrs("crs", "Mapping CRS"),
    ]
    add_inputs(model, inputs, 80.0, 60.0, 50.0)

    add_child(model, "lidarphoto:createlcps", "lcps", "Create LiDAR control points and lines",
              (400.0, 120.0), {"PLANES": param("planes"), "CLOUD": param("cloud")},
              (("lcp_table", "POINTS_CSV"), ("line_table", "LINES_CSV")), (700.0, 80.0),
              50.0)  # fmt: skip
    sources = {"CAMERA": param("camera"), "OBSERVATIONS": param("observations"),
               "CRS": param("crs"), "CONTROL_POINTS": output_of("lcps", "POINTS_CSV"),
               "CONTROL_LINES": output_of("lcps", "LINES_CSV")}  # fmt: skip
    add_child(model, "lidarphoto:resection", "resect", "Space resection from points and lines",
              (400.0, 320.0), sources, (("eo", "OUTPUT_EO"),), (700.0, 320.0))  # fmt: skip
    model.updateDestinationParameters()
    return model


if __name__ == "__main__":
    sys.path.insert(0, str(HERE))
    from model_tools import write_model

    raise SystemExit(write_model(build_model, MODEL))
