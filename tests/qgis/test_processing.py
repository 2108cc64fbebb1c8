"""lidarphoto:trajectorytoeo through processing.run, and the core -> QGIS feedback bridge.

The numbers of direct georeferencing are tested in tests/core; here only the wiring and loose
geometric facts, with expectations computed independently (by hand or by QGIS itself).
"""

from __future__ import annotations

import csv
import logging
import math

import processing
import pytest
from qgis.core import (
    NULL,
    QgsCoordinateReferenceSystem,
    QgsCoordinateTransform,
    QgsPointXY,
    QgsProcessingException,
    QgsProcessingFeedback,
    QgsProject,
    QgsVectorLayer,
    QgsWkbTypes,
)
from qgis_helpers import ALG, CRS, write_csv

E0, N0 = 500000.0, 7450000.0  # on the central meridian of UTM 23S: no grid convergence
FIELDS = ["image_id", "time", "group", "X", "Y", "Z", "omega_deg", "phi_deg", "kappa_deg"]


def _run(params: dict) -> tuple[dict, QgsVectorLayer]:
    result = processing.run(ALG, {"CRS": CRS, "OUTPUT": "TEMPORARY_OUTPUT", **params})
    layer = result["OUTPUT"]
    if isinstance(layer, str):
        layer = QgsVectorLayer(layer, "eo", "ogr")
    assert layer.isValid()
    return result, layer


def _features(layer: QgsVectorLayer) -> dict[str, dict]:
    return {f["image_id"]: dict(zip(FIELDS, f.attributes())) for f in layer.getFeatures()}


def _angle_diff_deg(a: float, b: float) -> float:
    return (a - b + 180.0) % 360.0 - 180.0


def test_algorithm_parameters_are_the_documented_api(provider):
    from lidarphoto.core.photo.mount import MOUNT_CHOICES

    alg = provider.algorithm("trajectorytoeo")
    assert alg.id() == ALG
    names = [p.name() for p in alg.parameterDefinitions()]
    assert names == [
        "INPUT",
        "CRS",
        "LEVER_ARM",
        "MOUNT",
        "MOUNT_MATRIX",
        "BORESIGHT",
        "OUTPUT",
        "OUTPUT_CSV",
    ]
    assert {o.name() for o in alg.outputDefinitions()} >= {"OUTPUT", "OUTPUT_CSV", "IMAGE_COUNT"}
    mount = alg.parameterDefinition("MOUNT")
    assert [o.split(":")[0] for o in mount.options()] == list(MOUNT_CHOICES)
    assert mount.defaultValue() == 0
    assert alg.parameterDefinition("LEVER_ARM").defaultValue() == [0.0, 0.0, 0.0]
    assert alg.parameterDefinition("BORESIGHT").defaultValue() == [0.0, 0.0, 0.0]
    assert (
        alg.parameterDefinition("OUTPUT_CSV").flags()
        & alg.parameterDefinition("OUTPUT_CSV").Flag.FlagOptional
    )
    assert (
        alg.parameterDefinition("MOUNT_MATRIX").flags()
        & alg.parameterDefinition("MOUNT_MATRIX").Flag.FlagAdvanced
    )
    help_text = alg.shortHelpString()
    for word in ("image_id", "easting", "latitude", "roll, pitch, heading", "group", "degrees"):
        assert word in help_text
    assert alg.canExecute()[0]
    assert alg.createInstance() is not alg and alg.createInstance().name() == alg.name()


def test_level_flight_gives_the_camera_position_and_north_up_kappa(provider, tmp_path):
    path = write_csv(
        tmp_path / "traj.csv",
        [f"img1,10.0,L1,{E0},{N0},2400.0,0,0,0", f"img2,11.5,L1,{E0},{N0 + 300},2410.0,0,0,0"],
    )
    out_csv = tmp_path / "eo.csv"
    result, layer = _run({"INPUT": str(path), "OUTPUT_CSV": str(out_csv)})

    assert result["IMAGE_COUNT"] == 2
    assert layer.crs().authid() == CRS
    assert QgsWkbTypes.hasZ(layer.wkbType())
    assert QgsWkbTypes.geometryType(layer.wkbType()) == QgsWkbTypes.GeometryType.PointGeometry
    assert [f.name() for f in layer.fields()] == FIELDS
    rows = _features(layer)
    assert set(rows) == {"img1", "img2"}
    r1 = rows["img1"]
    assert (r1["X"], r1["Y"], r1["Z"]) == pytest.approx((E0, N0, 2400.0), abs=1e-6)
    assert r1["time"] == pytest.approx(10.0) and r1["group"] == "L1"
    # zero attitude, image top = forward = north: the camera looks straight down, north up
    assert r1["omega_deg"] == pytest.approx(0.0, abs=1e-6)
    assert r1["phi_deg"] == pytest.approx(0.0, abs=1e-6)
    assert _angle_diff_deg(r1["kappa_deg"], 0.0) == pytest.approx(0.0, abs=1e-4)
    geom = next(layer.getFeatures()).geometry().constGet()
    assert (geom.x(), geom.y(), geom.z()) == pytest.approx((E0, N0, 2400.0), abs=1e-3)

    with out_csv.open(newline="", encoding="utf-8") as fh:
        table = list(csv.DictReader(fh))
    assert [r["image_id"] for r in table] == ["img1", "img2"]
    assert float(table[1]["Y"]) == pytest.approx(N0 + 300, abs=1e-3)


def test_heading_east_turns_kappa_a_quarter_turn(provider, tmp_path):
    path = write_csv(tmp_path / "t.csv", [f"a,1,L,{E0 + 1000},{N0},2000,0,0,90"])
    _, layer = _run({"INPUT": str(path)})
    kappa = _features(layer)["a"]["kappa_deg"]
    assert abs(abs(_angle_diff_deg(kappa, 0.0)) - 90.0) < 1.0  # up to grid convergence


def test_lever_arm_is_applied_in_the_body_frame(provider, tmp_path):
    """Level, heading north: body x = north, y = east, z = down."""
    path = write_csv(tmp_path / "t.csv", [f"a,1,L,{E0},{N0},2000,0,0,0"])
    _, layer = _run({"INPUT": str(path), "LEVER_ARM": "1,2,3"})
    r = _features(layer)["a"]
    assert (r["X"], r["Y"], r["Z"]) == pytest.approx((E0 + 2, N0 + 1, 2000 - 3), abs=0.01)


def test_custom_mount_matrix_and_boresight_are_passed_through(provider, tmp_path):
    path = write_csv(tmp_path / "t.csv", [f"a,1,L,{E0},{N0},2000,2,-1,30"])
    _, preset = _run({"INPUT": str(path), "MOUNT": 0})
    # image top = body x (forward), image right = body y, camera z = -body z (looks down)
    _, custom = _run({"INPUT": str(path), "MOUNT": 4, "MOUNT_MATRIX": "0,1,0, 1,0,0, 0,0,-1"})
    a, b = _features(preset)["a"], _features(custom)["a"]
    for key in ("X", "Y", "Z", "omega_deg", "phi_deg", "kappa_deg"):
        assert a[key] == pytest.approx(b[key], abs=1e-6)

    level = write_csv(tmp_path / "level.csv", [f"a,1,L,{E0},{N0},2000,0,0,0"])
    _, turned = _run({"INPUT": str(level), "BORESIGHT": "0,0,10"})
    assert abs(abs(_angle_diff_deg(_features(turned)["a"]["kappa_deg"], 0.0)) - 10.0) < 1e-3


def test_geodetic_input_matches_qgis_projection(provider, tmp_path):
    lat, lon = -23.5, -46.2
    crs = QgsCoordinateReferenceSystem(CRS)
    geographic = QgsCoordinateReferenceSystem("EPSG:4674")  # SIRGAS 2000, the datum of CRS
    to_map = QgsCoordinateTransform(geographic, crs, QgsProject.instance())
    expected = to_map.transform(QgsPointXY(lon, lat))
    path = write_csv(
        tmp_path / "geo.csv",
        [f"g1,5,,{lat},{lon},1500,0,0,0"],
        header="image_id,time,group,latitude,longitude,height,roll,pitch,heading\n",
    )
    _, layer = _run({"INPUT": str(path)})
    r = _features(layer)["g1"]
    assert (r["X"], r["Y"]) == pytest.approx((expected.x(), expected.y()), abs=0.01)
    assert r["Z"] == pytest.approx(1500.0, abs=1e-6)


def test_bad_value_names_row_and_column(provider, tmp_path):
    path = write_csv(
        tmp_path / "bad.csv",
        [f"a,1,L,{E0},{N0},2000,0,0,0", f"b,2,L,{E0},{N0 + 10},2000,oops,0,0"],
    )
    with pytest.raises(QgsProcessingException) as err:
        processing.run(ALG, {"INPUT": str(path), "CRS": CRS, "OUTPUT": "TEMPORARY_OUTPUT"})
    message = str(err.value)
    assert "row 3" in message and "roll" in message
    assert "bad.csv" in message


def test_missing_column_is_reported(provider, tmp_path):
    path = write_csv(
        tmp_path / "nohead.csv",
        [f"a,1,L,{E0},{N0},2000,0,0"],
        header="image_id,time,group,easting,northing,height,roll,pitch\n",
    )
    with pytest.raises(QgsProcessingException, match="heading"):
        processing.run(ALG, {"INPUT": str(path), "CRS": CRS, "OUTPUT": "TEMPORARY_OUTPUT"})


# -- the core -> QGIS bridge of processing_provider/base.py -----------------------------------
def _alg(provider):
    return provider.algorithm("trajectorytoeo").createInstance()


def test_run_core_wires_progress_log_and_errors(provider):
    from lidarphoto.core.errors import InputError

    feedback = QgsProcessingFeedback()
    seen = []
    feedback.progressChanged.connect(seen.append)

    def fake_core(value, progress=None, should_stop=None):
        logging.getLogger("lidarphoto.core.fake").info("reading %s", value)
        logging.getLogger("lidarphoto.core.fake").debug("not shown")
        progress(0.5)
        progress(1.0)
        assert should_stop() is False
        return value * 2

    assert _alg(provider).run_core(fake_core, 21, feedback=feedback) == 42
    assert seen == [50.0, 100.0]
    assert "reading 21" in feedback.textLog()
    assert "not shown" not in feedback.textLog()

    error = InputError("not a number", path="t.csv", row=7, column="pitch")

    def failing(progress=None, should_stop=None):
        raise error

    with pytest.raises(QgsProcessingException) as raised:
        _alg(provider).run_core(failing, feedback=feedback)
    assert str(raised.value) == str(error) and "row 7" in str(error)

    def os_error(progress=None, should_stop=None):
        raise FileNotFoundError(2, "No such file", "nope.csv")

    with pytest.raises(QgsProcessingException, match=r"nope\.csv"):
        _alg(provider).run_core(os_error, feedback=feedback)


def test_run_core_cancel(provider):
    from lidarphoto.core.errors import Cancelled

    feedback = QgsProcessingFeedback()
    feedback.cancel()

    def core(progress=None, should_stop=None):
        if should_stop():
            raise Cancelled("stopped at image 3")
        return 1

    with pytest.raises(QgsProcessingException, match="stopped at image 3"):
        _alg(provider).run_core(core, feedback=feedback)


def test_cancelled_run_of_the_algorithm(provider, tmp_path):
    path = write_csv(tmp_path / "t.csv", [f"a,1,L,{E0},{N0},2000,0,0,0"])
    feedback = QgsProcessingFeedback()
    feedback.cancel()
    with pytest.raises(QgsProcessingException):
        processing.run(
            ALG, {"INPUT": str(path), "CRS": CRS, "OUTPUT": "TEMPORARY_OUTPUT"}, feedback=feedback
        )


def test_degrees_are_degrees(provider, tmp_path):
    """Roll 5 degrees (right wing down) tilts the camera by about 5 degrees, not 5 radians."""
    path = write_csv(tmp_path / "t.csv", [f"a,1,L,{E0},{N0},2000,5,0,0"])
    _, layer = _run({"INPUT": str(path)})
    r = _features(layer)["a"]
    tilt = math.degrees(
        math.acos(math.cos(math.radians(r["omega_deg"])) * math.cos(math.radians(r["phi_deg"])))
    )
    assert tilt == pytest.approx(5.0, abs=0.01)


def test_crs_defaults_to_the_project_crs(provider, tmp_path, qgis_new_project):
    QgsProject.instance().setCrs(QgsCoordinateReferenceSystem(CRS))
    path = write_csv(tmp_path / "t.csv", [f"a,1,L,{E0},{N0},2000,0,0,0"])
    # the dialog pre-fills "ProjectCrs" (3.22 applies defaults only in the GUI)
    result = processing.run(
        ALG, {"INPUT": str(path), "CRS": "ProjectCrs", "OUTPUT": "TEMPORARY_OUTPUT"}
    )
    assert result["OUTPUT"].crs().authid() == CRS
    assert result["IMAGE_COUNT"] == 1


def test_geographic_crs_is_refused(provider, tmp_path):
    path = write_csv(tmp_path / "t.csv", [f"a,1,L,{E0},{N0},2000,0,0,0"])
    with pytest.raises(QgsProcessingException):
        processing.run(ALG, {"INPUT": str(path), "CRS": "EPSG:4326", "OUTPUT": "TEMPORARY_OUTPUT"})


def test_runs_in_a_background_task_like_the_dialog(provider, tmp_path, qtbot):
    """The toolbox dialog runs algorithms in a QgsProcessingAlgRunnerTask on a worker thread."""
    from qgis.core import QgsApplication, QgsProcessingAlgRunnerTask, QgsProcessingContext

    path = write_csv(tmp_path / "t.csv", [f"a,1,L,{E0},{N0},2000,0,0,0"])
    out_csv = tmp_path / "eo.csv"
    alg = QgsApplication.processingRegistry().createAlgorithmById(ALG)
    context = QgsProcessingContext()
    context.setProject(QgsProject.instance())
    feedback = QgsProcessingFeedback()
    params = {
        "INPUT": str(path),
        "CRS": CRS,
        "OUTPUT": str(tmp_path / "eo.gpkg"),
        "OUTPUT_CSV": str(out_csv),
    }
    task = QgsProcessingAlgRunnerTask(alg, params, context, feedback)
    outcome = {}
    task.executed.connect(lambda ok, results: outcome.update(ok=ok, results=results))
    QgsApplication.taskManager().addTask(task)
    qtbot.waitUntil(lambda: "ok" in outcome, timeout=60000)
    assert outcome["ok"], feedback.textLog()
    assert outcome["results"]["IMAGE_COUNT"] == 1
    assert out_csv.is_file()
    assert str(path) in feedback.textLog()  # the core's log line about the file, forwarded


def test_empty_time_and_group_give_null_and_empty(provider, tmp_path):
    path = write_csv(tmp_path / "t.csv", [f"a,,,{E0},{N0},2000,0,0,0"])
    _, layer = _run({"INPUT": str(path)})
    feature = next(layer.getFeatures())
    assert feature["time"] is None or feature["time"] == NULL
    assert feature["group"] in ("", None, NULL)
