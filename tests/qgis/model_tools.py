"""Shared by the scripts that (re)generate the committed .model3 files of the QGIS tests."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Callable

HERE = Path(__file__).resolve().parent


def static_defaults(child) -> None:
    """Every parameter not wired by the model gets its default as a static value (as the
    modeler dialog does), so the model validates and stores the full parameter set."""
    from qgis.core import QgsApplication, QgsProcessingDestinationParameter
    from qgis.core import QgsProcessingModelChildParameterSource as Src

    alg = QgsApplication.processingRegistry().algorithmById(child.algorithmId())
    for param in alg.parameterDefinitions():
        if param.name() in child.parameterSources() or isinstance(
            param, QgsProcessingDestinationParameter
        ):
            continue
        child.addParameterSources(param.name(), [Src.fromStaticValue(param.defaultValue())])


def new_model(name: str, group_id: str = ""):
    """An empty QgsProcessingModelAlgorithm ``name`` in the group "LiDAR Photogrammetry"
    (with the group id ``group_id``, none by default)."""
    from qgis.core import QgsProcessingModelAlgorithm

    return QgsProcessingModelAlgorithm(name, "LiDAR Photogrammetry", group_id)


def add_inputs(model, params, x: float, y0: float, dy: float) -> None:
    """The model's inputs (QgsProcessingParameter objects), one under the other at
    (x, y0 + dy i) on the canvas."""
    from qgis.core import QgsProcessingModelParameter
    from qgis.PyQt.QtCore import QPointF

    for i, param in enumerate(params):
        component = QgsProcessingModelParameter(param.name())
        component.setPosition(QPointF(x, y0 + dy * i))
        model.addModelParameter(param, component)


def param(name: str):
    """The source "model input ``name``" of a child's parameter."""
    from qgis.core import QgsProcessingModelChildParameterSource as Src

    return Src.fromModelParameter(name)


def output_of(child_id: str, name: str):
    """The source "output ``name`` of child ``child_id``" of a child's parameter."""
    from qgis.core import QgsProcessingModelChildParameterSource as Src

    return Src.fromChildOutput(child_id, name)


def model_outputs(child_id: str, pairs, x: float, y0: float, dy: float = 60.0) -> dict:
    """A QgsProcessingModelOutput per (model output name, child output name) of child
    ``child_id``, one under the other at (x, y0 + dy i)."""
    from qgis.core import QgsProcessingModelOutput
    from qgis.PyQt.QtCore import QPointF

    outputs = {}
    for name, child_output in pairs:
        out = QgsProcessingModelOutput(name, name)
        out.setChildId(child_id)
        out.setChildOutputName(child_output)
        out.setPosition(QPointF(x, y0 + dy * len(outputs)))
        outputs[name] = out
    return outputs


def add_child(model, alg_id, child_id, description, at, sources, outputs=(), out_at=(0.0, 0.0),
              out_dy=60.0, defaults=True):  # fmt: skip
    """Add child ``child_id`` (algorithm ``alg_id``, canvas position ``at``) to the model.

    ``sources``: parameter name -> a source (:func:`param`, :func:`output_of`) or a static
    value; ``outputs``: (model output name, child output name) pairs placed from ``out_at``
    down by ``out_dy`` (:func:`model_outputs`); with ``defaults`` every other parameter gets
    its default (:func:`static_defaults`). The model stores a copy: the child is complete
    before it is added. Returns that child."""
    from qgis.core import QgsProcessingModelChildAlgorithm
    from qgis.core import QgsProcessingModelChildParameterSource as Src
    from qgis.PyQt.QtCore import QPointF

    child = QgsProcessingModelChildAlgorithm(alg_id)
    child.setChildId(child_id)
    child.setDescription(description)
    child.setPosition(QPointF(*at))
    for name, source in sources.items():
        if not isinstance(source, Src):
            source = Src.fromStaticValue(source)
        child.addParameterSources(name, [source])
    if outputs:
        child.setModelOutputs(model_outputs(child_id, outputs, *out_at, out_dy))
    if defaults:
        static_defaults(child)
    model.addChildAlgorithm(child)
    return child


def write_model(build: Callable[[], object], path: Path) -> int:
    """Start QGIS headless with the plugin's provider, build the model, validate, write it."""
    sys.path.insert(0, str(HERE))
    from qgis.core import QgsApplication

    app = QgsApplication([], False)
    app.initQgis()
    sys.path.append("/usr/share/qgis/python/plugins")
    from processing.core.Processing import Processing

    Processing.initialize()
    import lidarphoto

    plugin = lidarphoto.classFactory(None)
    plugin.initProcessing()
    model = build()
    ok, errors = model.validate()
    if not ok:
        print("\n".join(errors), file=sys.stderr)
        return 1
    path.parent.mkdir(parents=True, exist_ok=True)
    if not model.toFile(str(path)):
        return 1
    print(f"wrote {path}")
    plugin.unload()
    return 0
