"""lidarphoto:lidaraccuracy in real QGIS: processing.run on three AHN3 flight lines, the
figures equal to the core's, the dz raster loaded on its diverging ramp."""

from __future__ import annotations

import json
from pathlib import Path

import processing
from qgis.core import QgsProject, QgsRasterLayer, QgsSingleBandPseudoColorRenderer
from qgis_helpers import ROOT

ALG = "lidarphoto:lidaraccuracy"
CROP = Path(ROOT) / "tests" / "data" / "ahn3_swaths" / "ahn3_delft_swaths30.laz"


def test_processing_run_matches_the_core(provider, tmp_path):
    from lidarphoto.core.jobs import lidar_accuracy
    from lidarphoto.core.jobs.runner import run_job

    alg = provider.algorithm("lidaraccuracy")
    assert alg.id() == ALG and alg.groupId() == "accuracy"
    result = processing.run(ALG, {"INPUT": [str(CROP)], "OUTPUT_HTML": str(tmp_path / "r.html"),
                                  "OUTPUT_JSON": str(tmp_path / "r.json")})  # fmt: skip
    core = run_job(lidar_accuracy, {"INPUT": [str(CROP)]})
    assert result["RMSDZ"] == core.results["RMSDZ"]
    assert result["SMOOTH_CELLS"] == core.results["SMOOTH_CELLS"] > 300
    d = json.loads((tmp_path / "r.json").read_text())
    assert [(p["swath_a"], p["swath_b"]) for p in d["pairs"]] == [(44266, 57138), (44266, 57139),
                                                                  (57138, 57139)]  # fmt: skip


def test_dz_raster_loads_on_a_diverging_ramp(provider, tmp_path):
    project = QgsProject.instance()
    before = set(project.mapLayers())
    try:
        processing.runAndLoadResults(ALG, {"INPUT": [str(CROP)],
                                           "OUTPUT_HTML": str(tmp_path / "r.html"),
                                           "OUTPUT_RASTER": str(tmp_path / "dz.tif")})  # fmt: skip
        added = [project.mapLayer(i) for i in set(project.mapLayers()) - before]
        layer = next(lyr for lyr in added if isinstance(lyr, QgsRasterLayer))
        renderer = layer.renderer()
        assert isinstance(renderer, QgsSingleBandPseudoColorRenderer)
        assert renderer.classificationMin() == -renderer.classificationMax() < 0
        assert layer.bandCount() == 3  # one band per swath pair
    finally:
        project.removeMapLayers(list(set(project.mapLayers()) - before))
