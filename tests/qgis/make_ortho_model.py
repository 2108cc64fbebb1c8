"""Regenerate tests/qgis/data/ortho_model.model3 (run once, then commit the file).

    QT_HASH_SEED=0 QT_QPA_PLATFORM=offscreen PROJ_DATA=/usr/share/proj \
        .venv-qgis/bin/python tests/qgis/make_ortho_model.py

Calibration to orthomosaic as one graphical model: ``boresight`` = lidarphoto:boresightcalibration
(its updated exterior orientation) -> ``ortho`` = lidarphoto:orthorectify (true orthophotos of
the images on the DSM, into a folder) -> ``mosaic`` = lidarphoto:orthomosaic of that folder.
Inputs: camera, trajectory, crs, lever_arm, mount, observations, planes, lines, lcps, images,
dsm, gsd; outputs ``boresight:boresight_table``, ``mosaic:orthomosaic`` and
``mosaic:seamlines``.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
MODEL = HERE / "data" / "ortho_model.model3"


def build_model():
    from lidarphoto.processing_provider.compat import NUMBER_DOUBLE, SOURCE_FILE
    from model_tools import add_child, add_inputs, new_model, output_of, param
    from qgis.core import (
        QgsProcessingParameterCrs,
        QgsProcessingParameterEnum,
        QgsProcessingParameterFile,
        QgsProcessingParameterMultipleLayers,
        QgsProcessingParameterNumber,
        QgsProcessingParameterString,
    )

    model = new_model("Boresight calibration to orthomosaic (model)")
    files = {
        "camera": "Camera (JSON)", "trajectory": "Trajectory (CSV)",
        "observations": "Image observations (CSV)", "planes": "Roof planes (CSV)",
        "lines": "LiDAR lines (CSV)", "lcps": "LiDAR control points (CSV)",
    }  # fmt: skip
    inputs = []
    for name, label in files.items():
        inputs.append(QgsProcessingParameterFile(name, label))
    inputs += [
        QgsProcessingParameterCrs("crs", "Mapping CRS"),
        QgsProcessingParameterString("lever_arm", "Lever arm x,y,z (m)", "0,0,0"),
        QgsProcessingParameterEnum(
            "mount",
            "Camera mount",
            [
                "image_top_forward",
                "image_right_forward",
                "image_bottom_forward",
                "image_left_forward",
                "custom",
            ],
            False,
            0,
        ),
        QgsProcessingParameterMultipleLayers("images", "Images", SOURCE_FILE),
        QgsProcessingParameterFile("dsm", "DSM (raster or LAS/LAZ)"),
        QgsProcessingParameterNumber("gsd", "Orthophoto cell size", NUMBER_DOUBLE, 0.0),
    ]
    add_inputs(model, inputs, 80.0, 60.0, 50.0)

    sources = {key: param(key.lower()) for key in (
        "CAMERA", "TRAJECTORY", "CRS", "LEVER_ARM", "MOUNT", "OBSERVATIONS", "PLANES", "LINES",
        "LCPS")}  # fmt: skip
    sources.update(BORESIGHT="0,0,0", CONTROL_TYPES=[0, 1, 2])
    add_child(model, "lidarphoto:boresightcalibration", "boresight", "Boresight calibration",
              (400.0, 120.0), sources, (("boresight_table", "OUTPUT_TABLE"),),
              (700.0, 80.0))  # fmt: skip
    sources = {"CAMERA": param("camera"), "EO": output_of("boresight", "OUTPUT_EO"),
               "IMAGES": param("images"), "DSM": param("dsm"), "CRS": param("crs"),
               "GSD": param("gsd"), "TRUE_ORTHO": True}  # fmt: skip
    add_child(model, "lidarphoto:orthorectify", "ortho", "Orthorectify (true orthophotos)",
              (400.0, 300.0), sources)  # fmt: skip
    add_child(model, "lidarphoto:orthomosaic", "mosaic", "Orthomosaic", (400.0, 460.0),
              {"ORTHOPHOTOS": output_of("ortho", "OUTPUT_FOLDER")},
              (("orthomosaic", "OUTPUT"), ("seamlines", "OUTPUT_SEAMLINES")),
              (700.0, 440.0))  # fmt: skip
    model.updateDestinationParameters()
    return model


if __name__ == "__main__":
    sys.path.insert(0, str(HERE))
    from model_tools import write_model

    raise SystemExit(write_model(build_model, MODEL))
