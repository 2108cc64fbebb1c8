"""Regenerate tests/qgis/data/ground_roof_model.model3 (run once, then commit the file).

    QT_HASH_SEED=0 QT_QPA_PLATFORM=offscreen PROJ_DATA=/usr/share/proj \
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
    from model_tools import add_child, add_inputs, new_model, output_of, param
    from qgis.core import (
        QgsProcessingParameterFile,
        QgsProcessingParameterNumber,
    )

    model = new_model("Ground filter and roof planes (model)", "lidarphoto")
    inputs = [
        QgsProcessingParameterFile("cloud", "Point cloud (LAS/LAZ)", extension="laz"),
        QgsProcessingParameterNumber(
            "epsilon", "Plane tolerance (m)", QgsProcessingParameterNumber.Type.Double, 0.15
        ),
    ]
    add_inputs(model, inputs, 120.0, 60.0, 70.0)

    # DISTANCE_UNIT 1: metres; POINTS 0: the non-ground points
    add_child(model, "lidarphoto:groundfilter", "ground", "Ground filter", (400.0, 80.0),
              {"INPUT": param("cloud"), "DISTANCE_UNIT": 1},
              (("classified_cloud", "OUTPUT_CLOUD"),), (650.0, 40.0))  # fmt: skip
    sources = {"INPUT": output_of("ground", "OUTPUT_CLOUD"), "DISTANCE_UNIT": 1, "POINTS": 0,
               "EPSILON": param("epsilon")}  # fmt: skip
    add_child(model, "lidarphoto:extractroofplanes", "roofs", "Extract roof planes",
              (400.0, 220.0), sources, (("roof_planes", "OUTPUT"), ("plane_table", "OUTPUT_CSV")),
              (700.0, 200.0))  # fmt: skip
    model.updateDestinationParameters()
    return model


if __name__ == "__main__":
    sys.path.insert(0, str(HERE))
    from model_tools import write_model

    raise SystemExit(write_model(build_model, MODEL))
