"""lidarphoto:orthorectify and lidarphoto:orthomosaic in real QGIS: processing.run (the DSM as a
raster layer of the project, and as the LAZ file), qgis_process, and the committed graphical
model boresightcalibration -> orthorectify -> orthomosaic (tests/qgis/data/ortho_model.model3),
on a reduced demo: the real AHN3 tile, a 4-image flight of a small camera rendered on its DSM.

The outputs are compared with the core run on the same files (the layers hold what the core
computes), and the model's mosaic, made with the calibrated orientation, with the one made
with the true orientation (the images are rendered with it)."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import processing
import pytest
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.io.raster import RasterReader
from lidarphoto.core.jobs import orthomosaic as mosaic_job
from lidarphoto.core.jobs import orthorectify as ortho_job
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.quality.registration import phase_correlation
from qgis.core import (
    QgsProcessingContext,
    QgsProcessingException,
    QgsProcessingModelAlgorithm,
    QgsProject,
    QgsRasterLayer,
    QgsVectorLayer,
)
from qgis_helpers import DATA, QGIS_PROCESS

ROOT = Path(__file__).resolve().parents[2]
CRS = "EPSG:28992"
MODEL = DATA / "ortho_model.model3"
SMALL = Camera("small format, 1500 x 1000", focal_mm=35.0, pixel_size_mm=0.018,
               width_px=1500, height_px=1000)  # fmt: skip
GSD = 0.1


def _load(name: str, path: Path):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    """The demo's steps on a small camera: LiDAR products, flight, rendered images, DSM."""
    demo_script = _load("lidarphoto_demo_script_ortho", ROOT / "scripts" / "demo.py")
    out = tmp_path_factory.mktemp("ortho_demo")
    lidar = demo_script.lidar_step(out / "lidar")
    sim, paths, eo_true = demo_script.flight_step(lidar, out / "flight", camera=SMALL,
                                                  images_per_line=2)  # fmt: skip
    demo_script.render_step(lidar, sim, eo_true, out / "flight" / "images")
    return {"out": out, "sim": sim, "paths": paths, "lidar": out / "lidar",
            "images": out / "flight" / "images"}  # fmt: skip


def _params(d, out: Path, **extra) -> dict:
    return {
        "CAMERA": str(d["paths"]["camera"]),
        "EO": str(d["paths"]["eo_true"]),
        "IMAGES": [str(d["images"])],
        "DSM": str(d["lidar"] / "dsm.tif"),
        "CRS": CRS,
        "GSD": GSD,
        "OUTPUT_FOLDER": str(out),
        **extra,
    }


def _read(path):
    with RasterReader(path) as src:
        return src.info, src.read(), src.read_mask()


def test_processing_run_and_layers_to_load(provider, demo, tmp_path):
    """The orthophotos are registered to load with their style; the files are those the core
    writes from the same inputs."""
    context = QgsProcessingContext()
    context.setProject(QgsProject.instance())
    result = processing.run("lidarphoto:orthorectify",
                            _params(demo, tmp_path / "q", TRUE_ORTHO=True),
                            context=context)  # fmt: skip
    assert result["IMAGE_COUNT"] == 4 and result["GSD_USED"] == GSD
    assert 0.0 < result["OCCLUDED_FRACTION"] < 0.3
    written = sorted(p.name for p in (tmp_path / "q").iterdir())
    assert written == sorted(f"{i}_ortho.tif" for i in demo["sim"].trajectory.image_id)
    loads = context.layersToLoadOnCompletion()
    assert sorted(Path(p).name for p in loads) == written
    details = context.layerToLoadOnCompletionDetails(next(iter(loads)))
    assert details.name.endswith("orthophoto") and details.postProcessor() is not None
    core = run_job(ortho_job, {k: v for k, v in _params(demo, tmp_path / "c",
                                                         TRUE_ORTHO=True).items()})  # fmt: skip
    assert core.results["IMAGE_COUNT"] == 4
    for name in written:
        qi, qa, qm = _read(tmp_path / "q" / name)
        ci, ca, cm = _read(tmp_path / "c" / name)
        assert qi.geotransform == ci.geotransform
        np.testing.assert_array_equal(qm, cm)
        np.testing.assert_array_equal(qa, ca)
    # the style: 8-bit RGB shown as is, without QGIS's 2-98 % stretch; every orthophoto of
    # the run in one group named after the folder, as QGIS loads them after the run
    project = QgsProject.instance()
    try:
        for path in loads:
            layer = QgsRasterLayer(path, Path(path).stem)
            project.addMapLayer(layer)
            context.layerToLoadOnCompletionDetails(path).postProcessor().postProcessLayer(
                layer, context, None
            )
            assert layer.renderer().type() == "multibandcolor"
            assert layer.renderer().redContrastEnhancement() is None
        group = project.layerTreeRoot().findGroup("Orthophotos (q)")
        assert group is not None and len(group.findLayers()) == 4
        assert project.layerTreeRoot().findLayers() == group.findLayers()
    finally:
        project.removeAllMapLayers()
        project.layerTreeRoot().removeAllChildren()


def test_processing_run_mosaic_from_laz_dsm(provider, demo, tmp_path):
    """The DSM rasterised from the LAZ by the algorithm (its NAP heights taken as ellipsoidal,
    as the demo does: the file's RD New + NAP needs a geoid grid PROJ lacks here); the mosaic
    and its seamline layer."""
    planes = demo["lidar"] / "planes.laz"
    processing.run("lidarphoto:orthorectify", _params(
        demo, tmp_path / "o", DSM=str(planes), DSM_CRS=CRS, CELL_SIZE=0.5,
        TRUE_ORTHO=True))  # fmt: skip
    result = processing.run("lidarphoto:orthomosaic", {
        "ORTHOPHOTOS": [str(tmp_path / "o")], "FEATHER": 4.0,
        "OUTPUT": str(tmp_path / "mosaic.tif"), "OUTPUT_SEAMLINES": "TEMPORARY_OUTPUT",
    })  # fmt: skip
    assert result["SOURCE_COUNT"] == 4 and result["COVERED_FRACTION"] > 0.8
    raster = QgsRasterLayer(result["OUTPUT"], "mosaic")
    # red, green, blue, and the internal mask, which QGIS shows as the alpha band
    assert raster.isValid() and raster.crs().authid() == CRS and raster.bandCount() == 4
    assert any(p.getExists() for p in raster.dataProvider().buildPyramidList())  # overviews
    seams = result["OUTPUT_SEAMLINES"]
    if isinstance(seams, str):
        seams = QgsVectorLayer(seams, "seams", "ogr")
    assert seams.featureCount() == 4 and seams.crs().authid() == CRS
    area = sum(f.geometry().area() for f in seams.getFeatures())
    cells = sum(f["cells"] for f in seams.getFeatures())
    assert area == pytest.approx(cells * GSD**2, rel=1e-6)
    core = run_job(mosaic_job, {"ORTHOPHOTOS": [str(tmp_path / "o")], "FEATHER": 4.0,
                                "OUTPUT": str(tmp_path / "core.tif")})  # fmt: skip
    np.testing.assert_array_equal(_read(tmp_path / "core.tif")[1], _read(result["OUTPUT"])[1])
    assert sorted(s.image_id for s in core.data.seamlines) == sorted(
        f["image_id"] for f in seams.getFeatures())  # fmt: skip


def test_images_and_orthophotos_from_raster_layers(provider, demo, tmp_path):
    """Issue 31, layers in: the images as raster layers of the project (objects and ids, in a
    mix with a file) give the orthophotos the folder gives, bit for bit; the orthophotos loaded
    as layers give the mosaic their folder gives; a layer not backed by a raster file is
    refused naming the parameter, nothing written."""
    project = QgsProject.instance()
    context = QgsProcessingContext()
    context.setProject(project)
    files = sorted(Path(demo["images"]).iterdir())
    layers = [QgsRasterLayer(str(f), f.stem) for f in files]
    assert all(layer.isValid() for layer in layers) and len(layers) == 4
    project.addMapLayers(layers)
    try:
        mixed = [layers[0], layers[1].id(), layers[2].id(), str(files[3])]
        processing.run("lidarphoto:orthorectify", _params(demo, tmp_path / "f"), context=context)
        processing.run("lidarphoto:orthorectify",
                       _params(demo, tmp_path / "l", IMAGES=mixed), context=context)  # fmt: skip
        written = sorted(p.name for p in (tmp_path / "f").iterdir())
        assert len(written) == 4 and sorted(p.name for p in (tmp_path / "l").iterdir()) == written
        for name in written:
            np.testing.assert_array_equal(_read(tmp_path / "f" / name)[1],
                                          _read(tmp_path / "l" / name)[1])  # fmt: skip
        orthos = [QgsRasterLayer(str(tmp_path / "l" / n), n) for n in written]
        project.addMapLayers(orthos)
        outs = {}
        for key, value in (("folder", [str(tmp_path / "l")]), ("layers", [o.id() for o in orthos])):
            outs[key] = processing.run("lidarphoto:orthomosaic", {
                "ORTHOPHOTOS": value, "OUTPUT": str(tmp_path / f"{key}.tif"),
            }, context=context)["OUTPUT"]  # fmt: skip
        np.testing.assert_array_equal(_read(outs["folder"])[1], _read(outs["layers"])[1])
        memory = QgsVectorLayer("Point?crs=EPSG:28992", "scratch", "memory")
        project.addMapLayer(memory)
        refused = "IMAGES: the layer scratch is not backed by a raster file"
        with pytest.raises(QgsProcessingException, match=refused):
            processing.run(
                "lidarphoto:orthorectify",
                _params(demo, tmp_path / "m", IMAGES=[layers[0].id(), memory.id()]),
                context=context,
            )
        assert not (tmp_path / "m").exists() or not any((tmp_path / "m").iterdir())
    finally:
        project.removeAllMapLayers()


def test_errors_name_the_image(provider, demo, tmp_path):
    eo = tmp_path / "eo.csv"
    lines = Path(demo["paths"]["eo_true"]).read_text(encoding="utf-8").splitlines()
    eo.write_text("\n".join(lines[:-1]) + "\n", encoding="utf-8")  # the last image dropped
    last = lines[-1].split(",")[0]
    with pytest.raises(QgsProcessingException, match=f"no exterior orientation.*{last}"):
        processing.run("lidarphoto:orthorectify", _params(demo, tmp_path / "x", EO=str(eo)))
    assert not (tmp_path / "x").exists() or not any((tmp_path / "x").iterdir())


def test_qgis_process_runs_both(qp_env, demo, tmp_path):
    r = subprocess.run(
        [QGIS_PROCESS, "--json", "run", "lidarphoto:orthorectify", "--",
         f"CAMERA={demo['paths']['camera']}", f"EO={demo['paths']['eo_true']}",
         f"IMAGES={demo['images']}", f"DSM={demo['lidar'] / 'dsm.tif'}", f"CRS={CRS}",
         f"GSD={GSD}", "TRUE_ORTHO=true", f"OUTPUT_FOLDER={tmp_path / 'o'}"],
        env=qp_env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert json.loads(r.stdout)["results"]["IMAGE_COUNT"] == 4
    r = subprocess.run(
        [QGIS_PROCESS, "--json", "run", "lidarphoto:orthomosaic", "--",
         f"ORTHOPHOTOS={tmp_path / 'o'}", f"OUTPUT={tmp_path / 'm.tif'}",
         f"OUTPUT_SEAMLINES={tmp_path / 'seams.gpkg'}"],
        env=qp_env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert json.loads(r.stdout)["results"]["SOURCE_COUNT"] == 4
    assert QgsRasterLayer(str(tmp_path / "m.tif"), "m").isValid()
    assert QgsVectorLayer(str(tmp_path / "seams.gpkg"), "s", "ogr").featureCount() == 4


def _model_inputs(demo, tmp_path) -> dict:
    sim, paths, lidar = demo["sim"], demo["paths"], demo["lidar"]
    return {
        "camera": str(paths["camera"]), "trajectory": str(paths["trajectory"]), "crs": CRS,
        "lever_arm": ",".join(repr(float(v)) for v in sim.config.lever_arm_m),
        "mount": 0, "observations": str(paths["observations"]),
        "planes": str(lidar / "planes.csv"), "lines": str(lidar / "lines.csv"),
        "lcps": str(lidar / "lcps.csv"), "images": [str(demo["images"])],
        "dsm": str(lidar / "dsm.tif"), "gsd": GSD,
        "boresight:boresight_table": str(tmp_path / "boresight.csv"),
        "mosaic:orthomosaic": str(tmp_path / "mosaic.tif"),
        "mosaic:seamlines": "TEMPORARY_OUTPUT",
    }  # fmt: skip


def test_model_after_boresight_calibration(provider, demo, tmp_path):
    assert demo["sim"].config.mount == "image_top_forward"
    model = QgsProcessingModelAlgorithm()
    assert model.fromFile(str(MODEL))
    ok, errors = model.validate()
    assert ok, errors
    assert sorted(c.algorithmId() for c in model.childAlgorithms().values()) == [
        "lidarphoto:boresightcalibration",
        "lidarphoto:orthomosaic",
        "lidarphoto:orthorectify",
    ]
    result = processing.run(model, _model_inputs(demo, tmp_path))
    assert (tmp_path / "boresight.csv").is_file()
    info, data, mask = _read(result["mosaic:orthomosaic"])
    assert mask.mean() > 0.8
    # the same mosaic from the true orientation: the calibrated one is within a pixel of it
    ortho_true = tmp_path / "true"
    run_job(ortho_job, _params(demo, ortho_true, TRUE_ORTHO=True))
    run_job(mosaic_job, {"ORTHOPHOTOS": [str(ortho_true)], "OUTPUT": str(tmp_path / "t.tif")})
    ti, tdata, tmask = _read(tmp_path / "t.tif")
    assert ti.geotransform == info.geotransform
    both = mask & tmask
    rows, cols = np.nonzero(both)
    r0, c0 = int(np.median(rows)) - 100, int(np.median(cols)) - 100
    dx, dy, peak = phase_correlation(
        tdata[1, r0 : r0 + 200, c0 : c0 + 200].astype(float),
        data[1, r0 : r0 + 200, c0 : c0 + 200].astype(float),
    )
    assert np.hypot(dx, dy) < 1.0 and peak > 0.5, (dx, dy, peak)


def test_model_in_qgis_process(qp_env, demo, tmp_path):
    args = []
    for key, value in _model_inputs(demo, tmp_path).items():
        if key == "mosaic:seamlines":
            value = str(tmp_path / "seams.gpkg")
        for v in value if isinstance(value, list) else [value]:
            args.append(f"{key}={v}")
    r = subprocess.run([QGIS_PROCESS, "--json", "run", str(MODEL), "--", *args], env=qp_env,
                       capture_output=True, text=True, timeout=600)  # fmt: skip
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert (tmp_path / "mosaic.tif").is_file()
    assert QgsVectorLayer(str(tmp_path / "seams.gpkg"), "s", "ogr").featureCount() == 4
