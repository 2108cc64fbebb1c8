"""Regenerate tests/qgis/data/lidar_control_model.model3 (run once, then commit the file).

    QT_HASH_SEED=0 QT_QPA_PLATFORM=offscreen PROJ_DATA=/usr/share/proj \
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
    from model_tools import add_child, model_outputs, output_of

    model = ground_roof_model()
    model.setName("Ground filter, roof planes and LiDAR control (model)")
    roofs = model.childAlgorithm("roofs")
    outputs = dict(roofs.modelOutputs())
    outputs.update(model_outputs("roofs", (("plane_cloud", "OUTPUT_CLOUD"),), 700.0, 320.0))
    roofs.setModelOutputs(outputs)
    model.setChildAlgorithm(roofs)

    sources = {"PLANES": output_of("roofs", "OUTPUT_CSV"),
               "CLOUD": output_of("roofs", "OUTPUT_CLOUD"),
               "DISTANCE_UNIT": 1}  # metres  # fmt: skip
    outs = (("control_points", "OUTPUT_POINTS"), ("control_lines", "OUTPUT_LINES"),
            ("control_table", "POINTS_CSV"))  # fmt: skip
    add_child(model, "lidarphoto:createlcps", "lcps", "Create LiDAR control points and lines",
              (400.0, 380.0), sources, outs, (700.0, 400.0))  # fmt: skip
    model.updateDestinationParameters()
    return model


if __name__ == "__main__":
    sys.path.insert(0, str(HERE))
    from model_tools import write_model

    raise SystemExit(write_model(build_model, MODEL))
