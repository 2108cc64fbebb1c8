"""lidarphoto:createlcps in real QGIS: processing.run and qgis_process on a synthetic town whose
planes are fitted to the true roof faces and stored as the roof-plane algorithm stores them
(plane table CSV + a real LAS with a plane_id extra dimension, written through laspy)."""

from __future__ import annotations

import csv
import json
import subprocess
from pathlib import Path

import laspy
import numpy as np
import processing
import pyproj
import pytest
from lidarphoto.core.geometry.planes import fit_plane
from lidarphoto.core.io.planes import write_planes_csv
from lidarphoto.core.simulation.town import make_town, sample_town
from qgis.core import (
    QgsProcessingException,
    QgsProcessingModelAlgorithm,
    QgsVectorLayer,
    QgsWkbTypes,
)
from qgis_helpers import QGIS_PROCESS

ALG = "lidarphoto:createlcps"
EPSG = 28992  # RD New: the town's default origin is near Delft


@pytest.fixture(scope="module")
def town_files(tmp_path_factory):
    """Two hip roofs and a pyramid: 2 + 2 + 1 corners, 5 + 5 + 4 lines."""
    folder = tmp_path_factory.mktemp("town")
    town = make_town(n_buildings=3, roof_types=("hip", "pyramid", "hip"), n_trees=0, seed=2)
    pts = sample_town(town, density=8.0, noise_sigma=0.05, seed=3)
    roof = (pts.face_id >= 0) & ~pts.is_wall
    xyz, face = pts.xyz[roof], pts.face_id[roof]
    planes = [fit_plane(xyz[face == f], plane_id=int(f)) for f in np.unique(face)]
    write_planes_csv(folder / "planes.csv", planes)
    header = laspy.LasHeader(point_format=1, version="1.2")
    header.offsets = xyz.min(axis=0)
    header.scales = np.array([0.001, 0.001, 0.001])
    header.add_extra_dim(laspy.ExtraBytesParams(name="plane_id", type=np.int32))
    header.add_crs(pyproj.CRS.from_epsg(EPSG))
    las = laspy.LasData(header)
    las.x, las.y, las.z = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    las.plane_id = face.astype(np.int32)
    las.write(folder / "roofs.las")
    no_ids = laspy.LasData(laspy.LasHeader(point_format=1, version="1.2"))
    no_ids.header.add_crs(pyproj.CRS.from_epsg(EPSG))
    no_ids.x, no_ids.y, no_ids.z = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    no_ids.write(folder / "no_ids.las")
    return folder


def test_processing_run_makes_points_lines_and_tables(provider, town_files, tmp_path):
    result = processing.run(
        ALG,
        {
            "PLANES": str(town_files / "planes.csv"),
            "CLOUD": str(town_files / "roofs.las"),
            "DELTA": 0.6,
            "MAX_SUPPORT": 1.0,
            "OUTPUT_POINTS": "TEMPORARY_OUTPUT",
            "OUTPUT_LINES": "TEMPORARY_OUTPUT",
            "POINTS_CSV": str(tmp_path / "lcp.csv"),
            "LINES_CSV": str(tmp_path / "lines.csv"),
            "GRAPH_CSV": str(tmp_path / "graph.csv"),
        },
    )
    assert result["LCP_COUNT"] == 5 and result["LINE_COUNT"] == 14
    points, lines = result["OUTPUT_POINTS"], result["OUTPUT_LINES"]
    assert points.featureCount() == 5 and lines.featureCount() == 14
    assert QgsWkbTypes.hasZ(points.wkbType()) and QgsWkbTypes.hasZ(lines.wkbType())
    assert points.crs().authid() == f"EPSG:{EPSG}"
    sig = [f["sigma_z"] for f in points.getFeatures()]
    assert all(0 < s < 0.05 for s in sig)
    kinds = sorted(f["kind"] for f in lines.getFeatures())
    assert kinds.count("ridge") == 2 and kinds.count("hip") == 12
    with open(tmp_path / "lcp.csv", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 5 and {"X", "sigma_x", "cov_xy", "plane_3"} <= set(rows[0])


def test_missing_plane_ids_is_explained(provider, town_files):
    with pytest.raises(QgsProcessingException, match="plane_id"):
        processing.run(
            ALG,
            {
                "PLANES": str(town_files / "planes.csv"),
                "CLOUD": str(town_files / "no_ids.las"),
                "OUTPUT_POINTS": "TEMPORARY_OUTPUT",
                "OUTPUT_LINES": "TEMPORARY_OUTPUT",
            },
        )


def test_qgis_process_run(qp_env, town_files, tmp_path):
    gpkg = tmp_path / "lcp.gpkg"
    r = subprocess.run(
        [QGIS_PROCESS, "--json", "run", ALG, "--",
         f"PLANES={town_files / 'planes.csv'}", f"CLOUD={town_files / 'roofs.las'}",
         "DELTA=0.6", "MAX_SUPPORT=1.0", f"OUTPUT_POINTS={gpkg}",
         f"OUTPUT_LINES={tmp_path / 'lines.gpkg'}"],
        env=qp_env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    results = json.loads(r.stdout)["results"]
    assert results["LCP_COUNT"] == 5
    layer = QgsVectorLayer(str(gpkg), "lcp", "ogr")
    assert layer.isValid() and layer.featureCount() == 5


# ----------------------------------------------------------------------------- the whole chain
CONTROL_MODEL = Path(__file__).resolve().parent / "data" / "lidar_control_model.model3"
AHN3_CROP = Path(__file__).resolve().parents[1] / "data" / "ahn3" / "ahn3_delft_crop60.laz"


def _model_outputs(tmp_path):
    return {
        "roofs:roof_planes": str(tmp_path / "planes.gpkg"),
        "roofs:plane_table": str(tmp_path / "planes.csv"),
        "roofs:plane_cloud": str(tmp_path / "planes.laz"),
        "ground:classified_cloud": str(tmp_path / "ground.laz"),
        "lcps:control_points": str(tmp_path / "lcp.gpkg"),
        "lcps:control_lines": str(tmp_path / "lines.gpkg"),
        "lcps:control_table": str(tmp_path / "lcp.csv"),
    }


def _check_control(tmp_path) -> None:
    points = QgsVectorLayer(str(tmp_path / "lcp.gpkg"), "lcp", "ogr")
    lines = QgsVectorLayer(str(tmp_path / "lines.gpkg"), "lines", "ogr")
    assert points.isValid() and lines.isValid()
    # the real 60 m Delft crop: a handful of corners and tens of ridges, valleys and hips
    assert points.featureCount() >= 2 and lines.featureCount() >= 15
    with open(tmp_path / "lcp.csv", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == points.featureCount()
    assert all(0 < float(r["sigma_z"]) < 0.1 for r in rows)


def test_model_chains_ground_roofs_and_control(provider, tmp_path):
    model = QgsProcessingModelAlgorithm()
    assert model.fromFile(str(CONTROL_MODEL))
    ok, errors = model.validate()
    assert ok, errors
    assert sorted(c.algorithmId() for c in model.childAlgorithms().values()) == [
        "lidarphoto:createlcps",
        "lidarphoto:extractroofplanes",
        "lidarphoto:groundfilter",
    ]
    processing.run(model, {"cloud": str(AHN3_CROP), "epsilon": 0.15, **_model_outputs(tmp_path)})
    _check_control(tmp_path)


def test_control_model_in_qgis_process(qp_env, tmp_path):
    args = [f"{k}={v}" for k, v in _model_outputs(tmp_path).items()]
    r = subprocess.run(
        [QGIS_PROCESS, "--json", "run", str(CONTROL_MODEL), "--", f"cloud={AHN3_CROP}",
         "epsilon=0.15", *args],
        env=qp_env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    _check_control(tmp_path)


class _Log:
    """A feedback that keeps what each channel received."""

    def __init__(self):
        from qgis.core import QgsProcessingFeedback

        self.info, self.debug = [], []
        log = self

        class Feedback(QgsProcessingFeedback):
            def pushInfo(self, text):
                log.info.append(text)

            def pushDebugInfo(self, text):
                log.debug.append(text)

        self.feedback = Feedback()


@pytest.mark.parametrize("verbose", [False, True])
def test_rejections_counted_in_the_log_details_only_in_a_verbose_log(provider, town_files, verbose):
    from qgis.core import QgsProcessingContext, QgsProject

    log = _Log()
    context = QgsProcessingContext()
    context.setProject(QgsProject.instance())
    if verbose:  # Processing options, logging level "Verbose"
        context.setLogLevel(QgsProcessingContext.Verbose)
    processing.run(
        ALG,
        {"PLANES": str(town_files / "planes.csv"), "CLOUD": str(town_files / "roofs.las"),
         "POINTS_CSV": "TEMPORARY_OUTPUT"},  # no layer asked: the sinks are optional
        feedback=log.feedback,
        context=context,
    )  # fmt: skip
    summary = [t for t in log.info if "candidates rejected:" in t]
    assert len(summary) == 1, log.info
    count = int(summary[0].split()[0])
    details = [t for t in log.debug if t.startswith("planes ")]
    assert not any(t.startswith("planes ") for t in log.info)
    if not verbose:
        assert details == []
        return
    assert len(details) == count > 0  # one debug line per rejected candidate
    for t in details:  # every length with its unit (RD New: metres), angles in degrees
        if "from the points of plane" in t:
            assert " m from the points of plane " in t and t.rstrip().endswith(" m)"), t
        if "parallel" in t:
            assert t.count(" deg") == 2, t
