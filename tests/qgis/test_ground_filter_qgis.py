"""lidarphoto:groundfilter in real QGIS: processing.run, qgis_process.bin, outputs and errors."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import laspy
import numpy as np
import processing
import pytest
from qgis.core import QgsProcessingException, QgsRasterLayer
from qgis_helpers import QGIS_PROCESS, ROOT

ALG = "lidarphoto:groundfilter"
AHN3 = Path(ROOT) / "tests" / "data" / "ahn3" / "ahn3_delft_crop60.laz"


def test_parameters_and_outputs(provider):
    alg = provider.algorithm("groundfilter")
    assert alg.id() == ALG and alg.groupId() == "lidar"
    names = [p.name() for p in alg.parameterDefinitions()]
    for name in (
        "INPUT",
        "CRS",
        "DISTANCE_UNIT",
        "METHOD",
        "SMRF_CELL_SIZE",
        "SMRF_SLOPE",
        "SMRF_WINDOW",
        "SMRF_THRESHOLD",
        "CELL_SIZE",
        "MAX_WINDOW",
        "SLOPE",
        "INITIAL_DISTANCE",
        "MAX_DISTANCE",
        "GROUND_THRESHOLD",
        "CSF_RESOLUTION",
        "CSF_RIGIDNESS",
        "CSF_THRESHOLD",
        "HEIGHT_ABOVE_GROUND",
        "OUTPUT_CLOUD",
        "OUTPUT_DTM",
    ):
        assert name in names
    outputs = {o.name() for o in alg.outputDefinitions()}
    assert {"OUTPUT_CLOUD", "OUTPUT_DTM", "GROUND_COUNT", "POINT_COUNT", "UNIT"} <= outputs
    assert alg.parameterDefinition("CELL_SIZE").defaultValue() == 1.0
    assert alg.parameterDefinition("SMRF_THRESHOLD").defaultValue() == 0.3
    assert alg.parameterDefinition("METHOD").defaultValue() == 0  # smrf


def test_processing_run_writes_cloud_and_dtm(provider, tmp_path):
    cloud, dtm = tmp_path / "ground.laz", tmp_path / "dtm.tif"
    result = processing.run(
        ALG,
        {
            "INPUT": str(AHN3),
            "OUTPUT_CLOUD": str(cloud),
            "OUTPUT_DTM": str(dtm),
            "HEIGHT_ABOVE_GROUND": True,
        },
    )
    src, out = laspy.read(AHN3), laspy.read(cloud)
    assert result["POINT_COUNT"] == len(src.points)
    assert result["UNIT"] == "metre"
    ground = out.classification == 2
    assert result["GROUND_COUNT"] == ground.sum()
    # agreement with the producer's ground class (independent reference)
    assert np.mean(ground == (src.classification == 2)) > 0.975
    assert "height_above_ground" in out.point_format.extra_dimension_names
    layer = QgsRasterLayer(str(dtm), "dtm")
    assert layer.isValid()
    assert (
        layer.crs().authid() in ("EPSG:28992", "EPSG:7415") or "Amersfoort" in layer.crs().toWkt()
    )
    ext = layer.extent()
    assert ext.xMinimum() <= src.header.mins[0] and ext.xMaximum() >= src.header.maxs[0]
    assert ext.yMinimum() <= src.header.mins[1] and ext.yMaximum() >= src.header.maxs[1]
    stats = layer.dataProvider().bandStatistics(1)
    ground_z = src.z[src.classification == 2]
    assert np.percentile(ground_z, 1) - 0.5 < stats.mean < np.percentile(ground_z, 99) + 0.5


def test_metres_on_a_feet_crs_converts(provider, tmp_path):
    # the same crop declared in international feet: metres chosen -> cell 1/0.3048 ft
    out = tmp_path / "ft.las"
    result = processing.run(
        ALG,
        {"INPUT": str(AHN3), "CRS": "EPSG:2994", "DISTANCE_UNIT": 1, "OUTPUT_CLOUD": str(out)},
    )
    assert result["UNIT"] == "metre (converted)"
    assert out.exists()


def test_bad_input_raises_and_leaves_nothing(provider, tmp_path):
    broken = tmp_path / "broken.laz"
    raw = AHN3.read_bytes()
    broken.write_bytes(raw[: len(raw) // 2])
    out = tmp_path / "out.laz"
    with pytest.raises(QgsProcessingException, match="broken"):
        processing.run(ALG, {"INPUT": str(broken), "OUTPUT_CLOUD": str(out)})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["broken.laz"]
    with pytest.raises(QgsProcessingException, match="geographic"):
        processing.run(ALG, {"INPUT": str(AHN3), "CRS": "EPSG:4326", "OUTPUT_CLOUD": str(out)})


def test_point_cloud_layer_input_on_this_qgis():
    """Records whether QgsPointCloudLayer opens a LAZ headless here (why INPUT is a file)."""
    from qgis.core import QgsPointCloudLayer, QgsProviderRegistry

    has_pdal = "pdal" in QgsProviderRegistry.instance().providerList()
    layer = QgsPointCloudLayer(str(AHN3), "cloud", "pdal")
    # Debian's QGIS 3.22 may lack the PDAL provider; the algorithm must not depend on it
    assert layer.isValid() == has_pdal or not has_pdal


def test_qgis_process_runs_the_algorithm(qp_env, tmp_path):
    cloud = tmp_path / "qp.laz"
    r = subprocess.run(
        [
            QGIS_PROCESS,
            "--json",
            "run",
            ALG,
            "--",
            f"INPUT={AHN3}",
            f"OUTPUT_CLOUD={cloud}",
            "DISTANCE_UNIT=0",
            "CELL_SIZE=1",
        ],
        env=qp_env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    results = json.loads(r.stdout[r.stdout.index("{") :])["results"]
    assert results["UNIT"] == "metre"
    assert int(results["GROUND_COUNT"]) == (laspy.read(cloud).classification == 2).sum()


@pytest.mark.parametrize("method", ["smrf", "pmf", "csf"])
def test_one_algorithm_per_method_shows_its_fields_only(provider, method):
    """groundfiltersmrf / pmf / csf: the common fields and their method's, no METHOD; the
    all-methods groundfilter is out of the toolbox but runs in models and qgis_process."""
    from lidarphoto.core.jobs.ground_filter import PARAM_METHODS
    from qgis.core import QgsProcessingAlgorithm

    alg = provider.algorithm(f"groundfilter{method}")
    assert alg is not None and alg.groupId() == "lidar"
    names = {p.name() for p in alg.parameterDefinitions()}
    assert "METHOD" not in names
    own = {k for k, m in PARAM_METHODS.items() if m == method}
    others = {k for k, m in PARAM_METHODS.items() if m not in ("", method)}
    assert own and own <= names and not names & others
    visible = [
        p
        for p in alg.parameterDefinitions()
        if not p.flags() & p.FlagAdvanced and not p.flags() & p.FlagHidden
    ]
    assert len(visible) <= 14, [p.name() for p in visible]  # 22 in the all-methods form
    generic = provider.algorithm("groundfilter")
    assert generic.flags() & QgsProcessingAlgorithm.Flag.FlagHideFromToolbox
    assert not alg.flags() & QgsProcessingAlgorithm.Flag.FlagHideFromToolbox
    assert alg.helpUrl() == generic.helpUrl() != ""


def test_the_one_method_algorithm_gives_the_all_methods_result(provider, tmp_path):
    """groundfilterpmf equals groundfilter with METHOD pmf, point for point."""
    a, b = tmp_path / "a.laz", tmp_path / "b.laz"
    ra = processing.run("lidarphoto:groundfilterpmf", {"INPUT": str(AHN3), "OUTPUT_CLOUD": str(a)})
    rb = processing.run(ALG, {"INPUT": str(AHN3), "METHOD": 1, "OUTPUT_CLOUD": str(b)})
    assert ra["GROUND_COUNT"] == rb["GROUND_COUNT"] > 0
    assert np.array_equal(laspy.read(a).classification, laspy.read(b).classification)
