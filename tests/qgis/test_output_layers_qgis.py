"""Layers out in real QGIS: a CSV output with coordinates loads as a styled point layer in the
run's CRS (createlcps's LCP table on a synthetic town), a table without coordinates stays a
file, and a LAS/LAZ output loads as a point-cloud layer where this QGIS has the PDAL provider
and otherwise stays a file, logged (ground filter on the AHN3 crop)."""

from __future__ import annotations

import csv
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
    QgsCoordinateReferenceSystem,
    QgsProcessingContext,
    QgsProject,
    QgsProviderRegistry,
    QgsWkbTypes,
)
from qgis_helpers import ROOT

EPSG = 28992
AHN3 = Path(ROOT) / "tests" / "data" / "ahn3" / "ahn3_delft_crop60.laz"


@pytest.fixture(scope="module")
def town(tmp_path_factory):
    """Two hip roofs and a pyramid: 5 LCPs (as tests/qgis/test_create_lcps_qgis.py)."""
    folder = tmp_path_factory.mktemp("town")
    scene = make_town(n_buildings=3, roof_types=("hip", "pyramid", "hip"), n_trees=0, seed=2)
    pts = sample_town(scene, density=8.0, noise_sigma=0.05, seed=3)
    roof = (pts.face_id >= 0) & ~pts.is_wall
    xyz, face = pts.xyz[roof], pts.face_id[roof]
    write_planes_csv(
        folder / "planes.csv", [fit_plane(xyz[face == f], plane_id=int(f)) for f in np.unique(face)]
    )
    header = laspy.LasHeader(point_format=1, version="1.2")
    header.offsets = xyz.min(axis=0)
    header.scales = np.array([0.001, 0.001, 0.001])
    header.add_extra_dim(laspy.ExtraBytesParams(name="plane_id", type=np.int32))
    header.add_crs(pyproj.CRS.from_epsg(EPSG))
    las = laspy.LasData(header)
    las.x, las.y, las.z = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    las.plane_id = face.astype(np.int32)
    las.write(folder / "roofs.las")
    return folder


def _context() -> QgsProcessingContext:
    context = QgsProcessingContext()
    context.setProject(QgsProject.instance())
    return context


def _loaded(context) -> dict:
    """{output name: layer} of the layers registered to load on completion."""
    store = context.temporaryLayerStore()
    out = {}
    for layer_id in context.layersToLoadOnCompletion():
        details = context.layerToLoadOnCompletionDetails(layer_id)
        out[details.outputName] = store.mapLayer(layer_id)
    return out


def test_a_coordinate_table_loads_as_a_point_layer(provider, town, tmp_path):
    context = _context()
    processing.run("lidarphoto:createlcps", {
        "PLANES": str(town / "planes.csv"), "CLOUD": str(town / "roofs.las"), "DELTA": 0.6,
        "MAX_SUPPORT": 1.0, "OUTPUT_POINTS": None,
        "OUTPUT_LINES": "TEMPORARY_OUTPUT", "POINTS_CSV": str(tmp_path / "lcp.csv"),
        "LINES_CSV": str(tmp_path / "lines.csv"), "GRAPH_CSV": str(tmp_path / "graph.csv"),
    }, context=context)  # fmt: skip
    with open(tmp_path / "lcp.csv", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    loaded = _loaded(context)
    layer = loaded["POINTS_CSV"]
    assert layer is not None and layer.isValid() and layer.providerType() == "delimitedtext"
    assert layer.featureCount() == len(rows) == 5
    assert layer.crs().authid() == f"EPSG:{EPSG}"
    assert QgsWkbTypes.hasZ(layer.wkbType())
    # the geometry is the table's X, Y, Z (to the file's digits)
    by_id = {str(f["id"]): f.geometry().vertexAt(0) for f in layer.getFeatures()}  # copies
    for row in rows:
        p = by_id[row["id"]]
        assert (p.x(), p.y(), p.z()) == pytest.approx(
            (float(row["X"]), float(row["Y"]), float(row["Z"])), abs=1e-6
        )
    assert layer.renderer().type() == "singleSymbol"
    # the graph table has no coordinates: it stays a file
    assert (tmp_path / "graph.csv").is_file() and "GRAPH_CSV" not in loaded


def test_a_table_whose_layer_twin_was_written_does_not_load_twice(provider, town, tmp_path):
    context = _context()
    res = processing.run("lidarphoto:createlcps", {
        "PLANES": str(town / "planes.csv"), "CLOUD": str(town / "roofs.las"), "DELTA": 0.6,
        "MAX_SUPPORT": 1.0, "OUTPUT_POINTS": "TEMPORARY_OUTPUT",
        "POINTS_CSV": str(tmp_path / "lcp.csv"),
    }, context=context)  # fmt: skip
    assert (tmp_path / "lcp.csv").is_file() and "POINTS_CSV" not in _loaded(context)
    layer = res["OUTPUT_POINTS"]
    layer = layer if hasattr(layer, "featureCount") else context.getMapLayer(layer)
    assert layer.featureCount() == 5


def test_commented_table_and_flags(provider, tmp_path):
    """A doubtful result's table (``#`` warning lines first) loads all its rows; a row
    flagged rejected is drawn red, the others blue."""
    from lidarphoto.processing_provider.output_layers import table_layer

    path = tmp_path / "res.csv"
    path.write_text("# WARNING: the checks failed\n# second line\nid,X,Y,Z,rejected\n"
                    "a,85000.5,446000.25,1.5,0\nb,85010.0,446010.0,2.0,1\n"
                    "c,85020.0,446020.0,2.5,0\n", encoding="utf-8")  # fmt: skip
    layer = table_layer(str(path), QgsCoordinateReferenceSystem(f"EPSG:{EPSG}"), "res")
    assert layer is not None and layer.featureCount() == 3
    xs = sorted(f.geometry().vertexAt(0).x() for f in layer.getFeatures())
    assert xs == [85000.5, 85010.0, 85020.0]
    prop = layer.renderer().symbol().symbolLayer(0).dataDefinedProperties()
    assert "rejected" in prop.property(prop.propertyKeys()[0]).expressionString()
    plain = tmp_path / "plain.csv"
    plain.write_text("group,sigma0\nall,1.02\n", encoding="utf-8")
    assert table_layer(str(plain), QgsCoordinateReferenceSystem(f"EPSG:{EPSG}"), "p") is None


def test_a_classified_laz_loads_as_a_point_cloud_where_qgis_can(provider, tmp_path):
    cloud = tmp_path / "ground.laz"
    context = _context()
    result = processing.run(
        "lidarphoto:groundfiltersmrf",
        {"INPUT": str(AHN3), "OUTPUT_CLOUD": str(cloud)},
        context=context,
    )
    assert cloud.is_file() and result["OUTPUT_CLOUD"] == str(cloud)
    loaded = _loaded(context)
    if "pdal" in QgsProviderRegistry.instance().providerList():
        layer = loaded["OUTPUT_CLOUD"]
        assert layer is not None and layer.isValid() and layer.providerType() == "pdal"
        assert layer.pointCount() == laspy.read(cloud).header.point_count
    else:  # Debian's 3.22: no PDAL provider; the file is the output, nothing half-loaded
        assert "OUTPUT_CLOUD" not in loaded and loaded == {}
    # the rule itself, on this QGIS: a layer exactly where the PDAL provider is
    from lidarphoto.processing_provider.output_layers import cloud_layer

    has_pdal = "pdal" in QgsProviderRegistry.instance().providerList()
    assert (cloud_layer(str(cloud), "c") is not None) == has_pdal


def test_html_reports_go_to_the_results_viewer(provider):
    """Every HTML report is a QgsProcessingOutputHtml: QGIS's algorithm dialog adds those to
    the Processing results viewer after the run and opens it (one click to the report)."""
    from lidarphoto.core.jobs import ALGORITHMS

    html = {(job.SPEC.name, p.name) for job in ALGORITHMS for p in job.SPEC.outputs
            if p.kind == "file_out" and "htm" in p.file_filter.lower()}  # fmt: skip
    assert len(html) >= 8  # accuracy, boresight, bundle, camera, LiDAR, control, resection, TLS
    for name, key in sorted(html):
        alg = provider.algorithm(name)
        assert alg.outputDefinition(key).type() == "outputHtml", (name, key)
