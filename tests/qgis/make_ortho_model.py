"""Regenerate tests/qgis/data/ortho_model.model3 (run once, then commit the file).

    QT_QPA_PLATFORM=offscreen PROJ_DATA=/usr/share/proj \
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
    from model_tools import static_defaults
    from qgis.core import (
        QgsProcessingModelAlgorithm,
        QgsProcessingModelChildAlgorithm,
        QgsProcessingModelOutput,
        QgsProcessingModelParameter,
        QgsProcessingParameterCrs,
        QgsProcessingParameterEnum,
        QgsProcessingParameterFile,
        QgsProcessingParameterMultipleLayers,
        QgsProcessingParameterNumber,
        QgsProcessingParameterString,
    )
    from qgis.core import QgsProcessingModelChildParameterSource as Src
    from qgis.PyQt.QtCore import QPointF

    model = QgsProcessingModelAlgorithm("Boresight calibration to orthomosaic (model)",
                                        "LiDAR Photogrammetry")  # fmt: skip
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
    for k, p in enumerate(inputs):
        mp = QgsProcessingModelParameter(p.name())
        mp.setPosition(QPointF(80.0, 60.0 + 50.0 * k))
        model.addModelParameter(p, mp)

    bore = QgsProcessingModelChildAlgorithm("lidarphoto:boresightcalibration")
    bore.setChildId("boresight")
    bore.setDescription("Boresight calibration")
    bore.setPosition(QPointF(400.0, 120.0))
    for child, source in (("CAMERA", "camera"), ("TRAJECTORY", "trajectory"), ("CRS", "crs"),
                          ("LEVER_ARM", "lever_arm"), ("MOUNT", "mount"),
                          ("OBSERVATIONS", "observations"), ("PLANES", "planes"),
                          ("LINES", "lines"), ("LCPS", "lcps")):  # fmt: skip
        bore.addParameterSources(child, [Src.fromModelParameter(source)])
    bore.addParameterSources("BORESIGHT", [Src.fromStaticValue("0,0,0")])
    bore.addParameterSources("CONTROL_TYPES", [Src.fromStaticValue([0, 1, 2])])
    table = QgsProcessingModelOutput("boresight_table", "boresight_table")
    table.setChildId("boresight")
    table.setChildOutputName("OUTPUT_TABLE")
    table.setPosition(QPointF(700.0, 80.0))
    bore.setModelOutputs({"boresight_table": table})
    static_defaults(bore)
    model.addChildAlgorithm(bore)

    ortho = QgsProcessingModelChildAlgorithm("lidarphoto:orthorectify")
    ortho.setChildId("ortho")
    ortho.setDescription("Orthorectify (true orthophotos)")
    ortho.setPosition(QPointF(400.0, 300.0))
    ortho.addParameterSources("CAMERA", [Src.fromModelParameter("camera")])
    ortho.addParameterSources("EO", [Src.fromChildOutput("boresight", "OUTPUT_EO")])
    ortho.addParameterSources("IMAGES", [Src.fromModelParameter("images")])
    ortho.addParameterSources("DSM", [Src.fromModelParameter("dsm")])
    ortho.addParameterSources("CRS", [Src.fromModelParameter("crs")])
    ortho.addParameterSources("GSD", [Src.fromModelParameter("gsd")])
    ortho.addParameterSources("TRUE_ORTHO", [Src.fromStaticValue(True)])
    static_defaults(ortho)
    model.addChildAlgorithm(ortho)

    mosaic = QgsProcessingModelChildAlgorithm("lidarphoto:orthomosaic")
    mosaic.setChildId("mosaic")
    mosaic.setDescription("Orthomosaic")
    mosaic.setPosition(QPointF(400.0, 460.0))
    mosaic.addParameterSources("ORTHOPHOTOS", [Src.fromChildOutput("ortho", "OUTPUT_FOLDER")])
    outs = {}
    for name, child_output in (("orthomosaic", "OUTPUT"), ("seamlines", "OUTPUT_SEAMLINES")):
        o = QgsProcessingModelOutput(name, name)
        o.setChildId("mosaic")
        o.setChildOutputName(child_output)
        o.setPosition(QPointF(700.0, 440.0 + 60.0 * len(outs)))
        outs[name] = o
    mosaic.setModelOutputs(outs)
    static_defaults(mosaic)
    model.addChildAlgorithm(mosaic)
    model.updateDestinationParameters()
    return model


if __name__ == "__main__":
    sys.path.insert(0, str(HERE))
    from model_tools import write_model

    raise SystemExit(write_model(build_model, MODEL))
