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
