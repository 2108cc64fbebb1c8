"""Layers in (issue 31): the layer kinds of core/jobs/spec.py (``raster``, ``pointcloud``,
``surface``, ``table``) take a layer of the project or a file; the job gets the file behind
the layer, the same run as from the path. A layer not backed by such a file (memory,
GeoPackage for a CSV table) is refused naming the parameter.

Real QGIS (Debian's 3.22 has no PDAL provider: there a point-cloud input is a file parameter;
the point-cloud layer branch runs only where QGIS has PDAL)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import processing
import pytest
from lidarphoto.core.jobs import ALGORITHMS
from lidarphoto.core.jobs.spec import Param
from lidarphoto.processing_provider.compat import SOURCE_TABLE
from lidarphoto.processing_provider.parameters import (
    LayerOrFileParameter,
    PointCloudOrFileParameter,
    RasterFilesParameter,
    RasterOrFileParameter,
    TableOrFileParameter,
    layer_file,
    point_cloud_layers,
)
from qgis.core import (
    QgsProcessingContext,
    QgsProcessingException,
    QgsProcessingFeedback,
    QgsProcessingParameterFile,
    QgsProcessingParameterMultipleLayers,
    QgsProject,
    QgsRasterLayer,
    QgsVectorLayer,
)
from qgis_helpers import CRS, ROOT

ACCURACY = "lidarphoto:accuracyreport"
AHN3 = Path(ROOT) / "tests" / "data" / "ahn3" / "ahn3_delft_crop60.laz"
LAYER_KINDS = ("raster", "pointcloud", "surface", "table")


@pytest.fixture()
def project():
    """The project the runs read layers from, emptied afterwards."""
    yield QgsProject.instance()
    QgsProject.instance().removeAllMapLayers()


def _context(project) -> QgsProcessingContext:
    context = QgsProcessingContext()
    context.setProject(project)
    return context


def test_every_layer_kind_is_a_layer_parameter(provider, tmp_path):
    """Each spec parameter of a layer kind is QGIS's layer parameter of that kind (a point
    cloud a LAS/LAZ file parameter where QGIS has no PDAL), accepts an existing file's path
    as it is (a .txt CSV that OGR would not open as a layer) and keeps its class when QGIS
    clones it (models, dialogs)."""
    want = {"raster": RasterOrFileParameter, "surface": LayerOrFileParameter,
            "table": TableOrFileParameter, "pointcloud": PointCloudOrFileParameter}  # fmt: skip
    txt = tmp_path / "points.txt"
    txt.write_text("# a comment line\npoint_id,X,Y,Z\n1,0,0,0\n", encoding="utf-8")
    context = _context(QgsProject.instance())
    seen = dict.fromkeys(LAYER_KINDS, 0)
    for job in ALGORITHMS:
        alg = provider.algorithm(job.SPEC.name)
        for p in job.SPEC.params:
            if p.kind not in LAYER_KINDS:
                continue
            seen[p.kind] += 1
            d = alg.parameterDefinition(p.name)
            if p.kind == "pointcloud" and not point_cloud_layers():
                assert isinstance(d, QgsProcessingParameterFile), p.name
                assert "*.laz" in d.fileFilter(), p.name
                continue
            assert isinstance(d, want[p.kind]), (job.SPEC.name, p.name)
            assert type(d.clone()) is want[p.kind]
            assert d.clone().flags() == d.flags() and d.clone().help() == d.help()
            assert d.checkValueIsAcceptable(str(txt), context), p.name
            assert d.checkValueIsAcceptable(str(AHN3), context), p.name
            if p.kind == "table":
                assert d.dataTypes() == [SOURCE_TABLE], p.name
    # the DSMs, the clouds of the LiDAR algorithms and every CSV table (points, planes, lines, EO,
    # image observations, trajectories, events, scale bars, stations, ground photos)
    assert seen == {"raster": 0, "pointcloud": 5, "surface": 2, "table": 44}, seen


def test_image_lists_take_raster_layers_files_and_folders(provider, tmp_path):
    """Every list of images (images, orthophotos, ground photos, control chips) offers the
    project's raster layers and accepts files and folders as they are; other lists of files
    (scans, swaths) stay file lists; each keeps its class when cloned."""
    from lidarphoto.processing_provider.compat import SOURCE_FILE, SOURCE_RASTER

    image = tmp_path / "a.tif"
    image.write_bytes(b"")
    context = _context(QgsProject.instance())
    names = []
    for job in ALGORITHMS:
        alg = provider.algorithm(job.SPEC.name)
        for p in job.SPEC.params:
            if p.kind != "files":
                continue
            d = alg.parameterDefinition(p.name)
            assert isinstance(d, QgsProcessingParameterMultipleLayers), p.name
            if not isinstance(d, RasterFilesParameter):
                assert d.layerType() == SOURCE_FILE, (job.SPEC.name, p.name)
                continue
            names.append(f"{job.SPEC.name}.{p.name}")
            assert d.layerType() == SOURCE_RASTER
            clone = d.clone()
            assert type(clone) is RasterFilesParameter and clone.flags() == d.flags()
            assert clone.help() == d.help()
            for value in (str(tmp_path), [str(tmp_path), str(image)], str(image)):
                assert d.checkValueIsAcceptable(value, context), (p.name, value)
            assert not d.checkValueIsAcceptable(str(tmp_path / "missing.tif"), context)
    assert sorted(names) == [
        "autoboresight.IMAGES",
        "calibratecamera.IMAGES",
        "locatecontrolpoints.CHIPS",
        "locatecontrolpoints.IMAGES",
        "makecontrolchips.PHOTOS",
        "orthomosaic.ORTHOPHOTOS",
        "orthorectify.IMAGES",
        "tiepoints.IMAGES",
    ], names


def _checkpoints(path: Path) -> Path:
    """15 check points, measured = reference + a known bias + noise (m)."""
    rng = np.random.default_rng(31)
    ref = np.column_stack(
        [
            500000.0 + rng.uniform(0, 2000, 15),
            7450000.0 + rng.uniform(0, 2000, 15),
            780.0 + rng.uniform(0, 60, 15),
        ]
    )
    meas = ref + [0.05, -0.04, 0.08] + rng.normal(0.0, 0.2, (15, 3))  # fmt: skip
    rows = [f"P{k},{m[0]!r},{m[1]!r},{m[2]!r},{r[0]!r},{r[1]!r},{r[2]!r},{'NE' if k < 8 else 'SW'}"
            for k, (m, r) in enumerate(zip(meas, ref))]  # fmt: skip
    path.write_text("id,e,n,h,e_ref,n_ref,h_ref,group\n" + "\n".join(rows) + "\n", "utf-8")
    return path


def _figures(out: Path) -> dict:
    """The report's figures (the JSON: it names no input file)."""
    data = json.loads(out.read_text(encoding="utf-8"))
    assert len(json.dumps(data)) > 1000  # every statistic of 15 points, not an empty report
    return data


def test_a_csv_table_layer_gives_the_file_s_result(provider, project, tmp_path):
    """The check-point table as a delimited-text layer (with and without point geometry), as
    an OGR layer and by its layer id: the same figures as from the file."""
    table = _checkpoints(tmp_path / "check points.csv")  # a space: %20 in the URI
    uri = table.resolve().as_uri()
    layers = {
        "delimited, no geometry": QgsVectorLayer(f"{uri}?type=csv&geomType=none", "cp1",
                                                 "delimitedtext"),
        "delimited, points": QgsVectorLayer(f"{uri}?type=csv&xField=e&yField=n&crs={CRS}",
                                            "cp2", "delimitedtext"),
        "ogr": QgsVectorLayer(str(table), "cp3", "ogr"),
    }  # fmt: skip
    for key, layer in layers.items():
        assert layer.isValid(), key
        project.addMapLayer(layer)
    base = {"CRS": CRS}
    ref = processing.run(ACCURACY, {**base, "INPUT": str(table),
                                    "OUTPUT_JSON": str(tmp_path / "file.json")})  # fmt: skip
    want = _figures(tmp_path / "file.json")
    assert ref["RMSE_3D"] > 0.1  # 15 points with 0.2 m noise per component
    values = [(k, layer) for k, layer in layers.items()] + [("id", layers["ogr"].id())]
    for k, (key, value) in enumerate(values):
        out = tmp_path / f"layer{k}.json"
        got = processing.run(
            ACCURACY, {**base, "INPUT": value, "OUTPUT_JSON": str(out)}, context=_context(project)
        )
        for name in ("RMSE_E", "RMSE_N", "RMSE_U", "RMSE_HORIZONTAL", "RMSE_3D"):
            assert got[name] == ref[name], (key, name)  # the same numbers, bit for bit
        assert _figures(out) == want, key


def test_a_layer_not_backed_by_a_csv_file_is_refused_by_name(provider, project, tmp_path):
    """A memory layer and a GeoPackage layer given as a CSV table: QgsProcessingException
    naming the parameter and the layer; nothing written."""
    from osgeo import ogr

    memory = QgsVectorLayer("Point?crs=EPSG:31983&field=id:string", "scratch", "memory")
    gpkg = tmp_path / "cp.gpkg"
    ds = ogr.GetDriverByName("GPKG").CreateDataSource(str(gpkg))
    ds.CreateLayer("cp", geom_type=ogr.wkbPoint).CreateField(ogr.FieldDefn("id", ogr.OFTString))
    ds = None
    geopackage = QgsVectorLayer(f"{gpkg}|layername=cp", "the gpkg", "ogr")
    assert geopackage.isValid()
    out = tmp_path / "report.json"
    for layer in (memory, geopackage):
        project.addMapLayer(layer)
        with pytest.raises(
            QgsProcessingException,
            match=f"INPUT: the layer {layer.name()} is not backed by a CSV file",
        ):
            processing.run(ACCURACY, {"INPUT": layer.id(), "OUTPUT_JSON": str(out)},
                           context=_context(project), feedback=QgsProcessingFeedback())  # fmt: skip
    assert not out.exists()


def test_the_raster_kind_takes_a_raster_layer_s_file(provider, project, tmp_path):
    """A ``raster`` parameter: a raster layer of the project gives its GeoTIFF, a vector layer
    is refused by name."""
    from osgeo import gdal

    tif = tmp_path / "dtm.tif"
    ds = gdal.GetDriverByName("GTiff").Create(str(tif), 4, 3, 1, gdal.GDT_Float32)
    ds.SetGeoTransform((1000.0, 1.0, 0.0, 2000.0, 0.0, -1.0))
    ds = None
    raster = QgsRasterLayer(str(tif), "the DTM")
    memory = QgsVectorLayer("Point?crs=EPSG:31983", "scratch", "memory")
    project.addMapLayers([raster, memory])
    alg = provider.algorithm("monoplot")  # any algorithm: the parameter is read through it
    p = Param("DSM", "raster", "DTM")
    context = _context(project)
    for value in (raster, raster.id(), str(tif)):
        assert layer_file(alg, p, {"DSM": value}, context) == str(tif)
    with pytest.raises(QgsProcessingException, match="DSM: the layer scratch is not backed by a "
                                                     "raster file"):  # fmt: skip
        layer_file(alg, p, {"DSM": memory.id()}, context)


@pytest.mark.skipif(not point_cloud_layers(), reason="this QGIS has no PDAL provider")
def test_a_point_cloud_layer_gives_the_file_s_result(provider, project, tmp_path):
    """Where QGIS reads LAS/LAZ: the ground filter from a point-cloud layer of the project
    writes the same classes as from the file."""
    import laspy
    from qgis.core import QgsPointCloudLayer

    layer = QgsPointCloudLayer(str(AHN3), "ahn3", "pdal")
    assert layer.isValid()
    project.addMapLayer(layer)
    outs = {}
    for key, value in (("file", str(AHN3)), ("layer", layer.id())):
        outs[key] = tmp_path / f"{key}.laz"
        processing.run("lidarphoto:groundfilter", {"INPUT": value, "OUTPUT_CLOUD": str(outs[key])},
                       context=_context(project))  # fmt: skip
    a, b = (laspy.read(outs[k]).classification for k in ("file", "layer"))
    assert len(a) > 1000 and np.array_equal(a, b)


@pytest.mark.skipif(point_cloud_layers(), reason="this QGIS reads LAS/LAZ as layers")
def test_without_pdal_a_cloud_is_a_file_and_a_dsm_takes_a_laz_path(provider, tmp_path):
    """Where QGIS has no PDAL provider (Debian's 3.22): the cloud inputs are LAS/LAZ file
    parameters, and the DSM's layer parameter takes a LAZ path it cannot open as a layer."""
    alg = provider.algorithm("groundfilter")
    assert isinstance(alg.parameterDefinition("INPUT"), QgsProcessingParameterFile)
    dsm = provider.algorithm("orthorectify").parameterDefinition("DSM")
    assert dsm.checkValueIsAcceptable(str(AHN3), _context(QgsProject.instance()))
    ortho = provider.algorithm("orthorectify")
    p = next(q for q in ortho.JOB.SPEC.params if q.name == "DSM")
    assert layer_file(ortho, p, {"DSM": str(AHN3)}, _context(QgsProject.instance())) == str(AHN3)


def test_an_output_table_layer_is_read_back_as_its_file(provider, project, tmp_path):
    """A table as the runs load it (output_layers.table_layer: delimited text with points, its
    ``#`` warning lines skipped) given to a ``table`` parameter is its CSV file again, warning
    lines included: the output of one run is the input of the next."""
    from lidarphoto.processing_provider.output_layers import table_layer
    from qgis.core import QgsCoordinateReferenceSystem

    csv = tmp_path / "ground points.csv"
    csv.write_text("# doubtful: 2 images only\npoint_id,X,Y,Z\nA,500000.5,7450000.25,781.0\n",
                   encoding="utf-8")  # fmt: skip
    layer = table_layer(str(csv), QgsCoordinateReferenceSystem(CRS), "ground points")
    assert layer is not None and layer.featureCount() == 1
    project.addMapLayer(layer)
    alg = provider.algorithm("bundleadjustment")
    p = next(q for q in alg.JOB.SPEC.params if q.name == "GROUND_POINTS")
    assert p.kind == "table"
    for value in (layer, layer.id()):
        assert layer_file(alg, p, {"GROUND_POINTS": value}, _context(project)) == str(csv)


def test_the_form_offers_the_csv_layer_and_runs_from_it(provider, project, monkeypatch, tmp_path):
    """The algorithm dialog (Processing's own, headless): the table parameter's widget takes a
    CSV layer of the project; the parameters the form hands over run to the file's figures."""
    from processing.gui import ParametersPanel

    monkeypatch.setattr(
        ParametersPanel, "iface", None
    )  # no main window: the form without map canvas
    table = _checkpoints(tmp_path / "cp.csv")
    layer = QgsVectorLayer(f"{table.as_uri()}?type=csv&geomType=none", "cp", "delimitedtext")
    project.addMapLayers([QgsVectorLayer("Point?crs=EPSG:31983", "scratch", "memory"), layer])
    dialog = processing.createAlgorithmDialog(ACCURACY, {})
    try:
        widget = dialog.mainWidget().wrappers["INPUT"]
        widget.setParameterValue(layer.id(), QgsProcessingContext())
        assert widget.parameterValue() == layer.id()
        params = dialog.createProcessingParameters()
    finally:
        dialog.deleteLater()
    assert params["INPUT"] == layer.id()
    from_form = processing.run(ACCURACY, {**params, "CRS": CRS}, context=_context(project))
    from_file = processing.run(ACCURACY, {"INPUT": str(table), "CRS": CRS})
    assert from_form["RMSE_3D"] == from_file["RMSE_3D"] > 0.1
