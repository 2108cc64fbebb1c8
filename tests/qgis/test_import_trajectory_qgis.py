"""lidarphoto:importtrajectory through processing.run: an SBET and an event file give the
perspective centres as a PointZ layer in the mapping CRS, equal to the EO table the job writes;
an event outside the trajectory is a QgsProcessingException naming the file, row and image,
with nothing written. (The interpolation's accuracy is tested in tests/core.)"""

from __future__ import annotations

import math

import numpy as np
import processing
import pytest
from qgis.core import QgsProcessingException, QgsVectorLayer, QgsWkbTypes

ALG = "lidarphoto:importtrajectory"
CRS = "EPSG:31983"


def _inputs(tmp_path, late: bool = False):
    from lidarphoto.core.geometry.frames import MappingFrame
    from lidarphoto.core.io.sbet import sbet_records, write_sbet
    from lidarphoto.core.simulation.navigation import SimulatedFlight

    sim = SimulatedFlight(MappingFrame.from_user_input(CRS))
    t = sim.t0 + np.arange(801) / 200.0  # 4 s at 200 Hz
    rec = sim.records(t)
    llh_rad = np.column_stack([np.radians(rec["llh"][:, :2]), rec["llh"][:, 2]])
    sbet = tmp_path / "sbet_flight.out"
    write_sbet(sbet, sbet_records(t, llh_rad, rec["v_ned"], rec["rph"], rec["wander"]))
    times = [sim.t0 + 0.5012, sim.t0 + 1.7513, sim.t0 + (9.0 if late else 3.2514)]
    events = tmp_path / "events.csv"
    events.write_text("image_id,time,group\n" + "".join(
        f"IMG_{k},{float(x)!r},L1\n" for k, x in enumerate(times)), encoding="utf-8")  # fmt: skip
    return sbet, events


def test_sbet_and_events_give_the_centres_layer_and_the_tables(provider, tmp_path):
    from lidarphoto.core.io.orientation import read_eo_csv
    from lidarphoto.core.io.trajectory import read_trajectory_csv

    sbet, events = _inputs(tmp_path)
    result = processing.run(ALG, {
        "INPUT": str(sbet), "EVENTS": str(events), "CRS": CRS, "LEVER_ARM": "0.5,0,-1",
        "OUTPUT": "TEMPORARY_OUTPUT", "OUTPUT_TRAJECTORY": str(tmp_path / "traj.csv"),
        "OUTPUT_EO": str(tmp_path / "eo.csv"),
    })  # fmt: skip
    assert result["IMAGE_COUNT"] == 3 and result["RECORD_COUNT"] == 801
    layer = result["OUTPUT"]
    if isinstance(layer, str):
        layer = QgsVectorLayer(layer, "centres", "ogr")
    assert layer.isValid() and layer.featureCount() == 3
    assert QgsWkbTypes.hasZ(layer.wkbType()) and layer.crs().authid() == CRS
    eo = read_eo_csv(tmp_path / "eo.csv")
    assert len(read_trajectory_csv(tmp_path / "traj.csv")) == 3
    for f in layer.getFeatures():
        k = eo.image_id.index(f["image_id"])
        p = f.geometry().constGet()
        # the EO CSV holds 0.1 mm (core/io/orientation.py); the layer full precision
        assert math.dist((p.x(), p.y(), p.z()), tuple(eo.xyz[k])) < 1e-4
        assert f["group"] == "L1"


def test_an_event_outside_the_trajectory_names_its_row_and_writes_nothing(provider, tmp_path):
    sbet, events = _inputs(tmp_path, late=True)
    with pytest.raises(QgsProcessingException) as err:
        processing.run(ALG, {"INPUT": str(sbet), "EVENTS": str(events), "CRS": CRS,
                             "OUTPUT": "TEMPORARY_OUTPUT",
                             "OUTPUT_TRAJECTORY": str(tmp_path / "traj.csv")})  # fmt: skip
    message = str(err.value)
    assert "events.csv" in message and "row 4" in message and "IMG_2" in message
    assert not (tmp_path / "traj.csv").exists()
