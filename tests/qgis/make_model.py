"""Regenerate tests/qgis/data/trajectory_model.model3 (run once, then commit the file).

    QT_HASH_SEED=0 QT_QPA_PLATFORM=offscreen .venv-qgis/bin/python tests/qgis/make_model.py

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
    from model_tools import add_child, add_inputs, new_model, param
    from qgis.core import (
        QgsProcessingParameterCrs,
        QgsProcessingParameterFile,
        QgsProcessingParameterString,
    )

    model = new_model("Trajectory to exterior orientation (model)", "lidarphoto")
    inputs = [
        QgsProcessingParameterFile("trajectory", "Trajectory table (CSV)", extension="csv"),
        QgsProcessingParameterCrs("crs", "Mapping CRS", "EPSG:31983"),
        QgsProcessingParameterString("lever_arm", "Lever arm x,y,z (m)", "0,0,0"),
    ]
    add_inputs(model, inputs, 120.0, 60.0, 70.0)
    sources = {"INPUT": param("trajectory"), "CRS": param("crs"), "LEVER_ARM": param("lever_arm"),
               "MOUNT": 0, "MOUNT_MATRIX": "", "BORESIGHT": "0,0,0"}  # fmt: skip
    add_child(model, "lidarphoto:trajectorytoeo", "eo", "Trajectory to exterior orientation",
              (420.0, 130.0), sources, (("eo_points", "OUTPUT"), ("eo_table", "OUTPUT_CSV")),
              (700.0, 100.0), defaults=False)  # fmt: skip
    model.updateDestinationParameters()
    return model


if __name__ == "__main__":
    sys.path.insert(0, str(HERE))
    from model_tools import write_model

    raise SystemExit(write_model(build_model, MODEL))
