"""The tlscalibration job: CSV in, CSV and HTML out, bad tables refused naming file and row."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.io.tls import (
    read_tls_observations_csv,
    write_tls_control_csv,
    write_tls_observations_csv,
)
from lidarphoto.core.jobs import tls_calibration
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.simulation.tls import (
    PAPER_APS,
    SCANNER_CLASSES,
    observe,
    paper_cube,
    room_network,
)
from lidarphoto.core.tls.aps import ARCSEC


def _rows(path):
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def _outputs(tmp_path):
    return {
        "OUTPUT_STATIONS": str(tmp_path / "stations_out.csv"),
        "OUTPUT_APS": str(tmp_path / "aps.csv"),
        "OUTPUT_TARGETS": str(tmp_path / "targets.csv"),
        "OUTPUT_RESIDUALS": str(tmp_path / "residuals.csv"),
        "OUTPUT_HTML": str(tmp_path / "report.html"),
    }


@pytest.fixture(scope="module")
def cube_files(tmp_path_factory):
    d = tmp_path_factory.mktemp("cube")
    t = paper_cube()
    obs, _ = observe(t, *SCANNER_CLASSES["high_end"], rng=11)
    write_tls_observations_csv(d / "obs.csv", obs)
    write_tls_control_csv(d / "control.csv", t.control())
    return d, t


def test_job_recovers_the_paper_cube_and_writes_every_output(cube_files, tmp_path):
    d, t = cube_files
    res = run_job(tls_calibration, {"OBSERVATIONS": str(d / "obs.csv"),
                                    "CONTROL": str(d / "control.csv"), "LEVELLED": False,
                                    **_outputs(tmp_path)})  # fmt: skip
    aps = {r["name"]: r for r in _rows(tmp_path / "aps.csv")}
    assert list(aps) == ["a0", "b1", "b2", "c0"]
    for name, row in aps.items():
        scale = 1000.0 if name == "a0" else 1.0 / ARCSEC
        truth = PAPER_APS[name] * scale
        assert abs(float(row["value"]) - truth) < 4 * float(row["std"]), (name, row)
    st = _rows(tmp_path / "stations_out.csv")
    assert [r["station_id"] for r in st] == ["1", "2", "3"]
    for r, pose in zip(st, t.poses):
        xyz = np.array([float(r[c]) for c in "XYZ"])
        sig = np.array([float(r[f"s_{c}"]) for c in "XYZ"])
        assert np.all(np.abs(xyz - pose[:3]) < 4 * sig + 1e-9)
        assert abs(float(r["kappa_deg"]) - math.degrees(pose[5])) < 4 * float(
            r["s_kappa_arcsec"]) / 3600  # fmt: skip
    tg = _rows(tmp_path / "targets.csv")
    assert len(tg) == 144 and {r["kind"] for r in tg} == {"fixed"}
    resid = _rows(tmp_path / "residuals.csv")
    assert len(resid) == 432 and resid[0]["row"] == "2"
    page = (tmp_path / "report.html").read_text(encoding="utf-8")
    assert "Correlations" in page and 'class="corr"' in page and "collimation" in page
    assert res.results["APS"] == "a0,b1,b2,c0"
    assert 0.8 < res.results["SIGMA0"] < 1.2


def test_job_free_network_with_gon_and_stations_table(tmp_path):
    """The room in gon, no control (inner constraints), levelled stations from a table."""
    t = room_network()
    obs, _ = observe(t, *SCANNER_CLASSES["high_end"], rng=12)
    write_tls_observations_csv(tmp_path / "obs.csv", obs, "gon")
    with open(tmp_path / "stations.csv", "w", encoding="utf-8") as fh:
        fh.write("station_id,levelled\n")
        for s, lv in zip(t.station_ids, t.levelled):
            fh.write(f"{s},{int(lv)}\n")
    run_job(tls_calibration, {"OBSERVATIONS": str(tmp_path / "obs.csv"),
                              "STATIONS": str(tmp_path / "stations.csv"),
                              **_outputs(tmp_path)})  # fmt: skip
    aps = {r["name"]: r for r in _rows(tmp_path / "aps.csv")}
    for name, row in aps.items():
        scale = 1000.0 if name == "a0" else 1.0 / ARCSEC
        assert abs(float(row["value"]) - PAPER_APS[name] * scale) < 4 * float(row["std"])
    st = _rows(tmp_path / "stations_out.csv")
    assert [r["levelled"] for r in st] == ["1", "1", "1", "1", "0", "0"]


def test_xyz_target_centres_give_the_polar_result(tmp_path):
    """The same observations as scanner-frame x, y, z with the propagated covariance: the
    same APs (the transformation is exact; only the covariance is linearised)."""
    t = paper_cube()
    obs, _ = observe(t, *SCANNER_CLASSES["high_end"], rng=13)
    xyz = obs.scanner_xyz()
    with open(tmp_path / "xyz.csv", "w", encoding="utf-8") as fh:
        fh.write("station_id,target_id,x,y,z,s_x,s_y,s_z\n")
        for s, tg, p in zip(obs.station, obs.target, xyz):
            x, y, z = (repr(float(c)) for c in p)
            fh.write(f"{s},{tg},{x},{y},{z},0.001,0.001,0.001\n")
    back = read_tls_observations_csv(tmp_path / "xyz.csv")
    np.testing.assert_allclose(back.polar[:, 0], obs.polar[:, 0], atol=1e-12)
    np.testing.assert_allclose(np.cos(back.polar[:, 1] - obs.polar[:, 1]), 1.0, atol=1e-12)
    assert back.cov.shape == (len(obs), 3, 3)
    # a 1 mm point sigma at range r is 1/r rad across the beam
    r = obs.polar[:, 0]
    np.testing.assert_allclose(np.sqrt(back.cov[:, 1, 1]) * r * np.cos(obs.polar[:, 2]), 0.001,
                               rtol=1e-9)  # fmt: skip


# ----------------------------------------------------------------------------- bad input


def _write(path, text):
    path.write_text(text, encoding="utf-8")
    return str(path)


def test_gon_read_as_degrees_is_refused(tmp_path):
    """A table in gon whose columns say degrees: the distances between targets disagree
    between stations by percent, which names the file and the stations."""
    t = room_network()
    obs, _ = observe(t, *SCANNER_CLASSES["high_end"], rng=14)
    write_tls_observations_csv(tmp_path / "g.csv", obs, "gon")
    text = (tmp_path / "g.csv").read_text().replace("_gon", "_deg")
    # keep every value below 360 so that only the distance check can catch it
    lines = [ln for ln in text.splitlines() if ln.startswith("station") or
             all(abs(float(c)) < 360 for c in ln.split(",")[3:5])]  # fmt: skip
    path = _write(tmp_path / "bad.csv", "\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"bad.csv: the distances between targets disagree"):
        run_job(tls_calibration, {"OBSERVATIONS": path, **_outputs(tmp_path)})
    assert not (tmp_path / "aps.csv").exists()


def test_angle_beyond_a_full_turn_names_the_row(tmp_path):
    path = _write(tmp_path / "o.csv", "station_id,target_id,range,hz_deg,vt_deg\n"
                  "A,T1,5.0,10.0,1.0\nA,T2,5.0,385.0,1.0\n")  # fmt: skip
    with pytest.raises(InputError, match=r"o.csv, row 3, column 'hz_deg': 385 is beyond 360"):
        read_tls_observations_csv(path)


def test_station_missing_from_the_stations_table_names_file_and_row(cube_files, tmp_path):
    d, _ = cube_files
    st = _write(tmp_path / "st.csv", "station_id,levelled\n1,0\n2,0\n")
    with pytest.raises(InputError, match=r"obs.csv, row \d+: station '3' is not in the stations"):
        run_job(tls_calibration, {"OBSERVATIONS": str(d / "obs.csv"), "STATIONS": st,
                                  **_outputs(tmp_path)})  # fmt: skip
    st = _write(tmp_path / "st.csv", "station_id\n1\n2\n3\n9\n")
    with pytest.raises(InputError, match=r"st.csv, row 5: station '9' has no observations"):
        run_job(tls_calibration, {"OBSERVATIONS": str(d / "obs.csv"), "STATIONS": st,
                                  **_outputs(tmp_path)})  # fmt: skip


def test_target_of_one_station_in_a_file_names_its_row(cube_files, tmp_path):
    d, _ = cube_files
    text = (d / "obs.csv").read_text() + "1,LONELY,5.0,10.0,1.0,0.001,5,5\n"
    path = _write(tmp_path / "o.csv", text)
    with pytest.raises(InputError, match=r"o.csv, row 434: target 'LONELY' is seen by station"):
        run_job(tls_calibration, {"OBSERVATIONS": path, **_outputs(tmp_path)})


def test_missing_columns_are_named(tmp_path):
    path = _write(tmp_path / "o.csv", "station_id,target_id,range,hz_deg\nA,T1,5,1\n")
    with pytest.raises(InputError, match="no column for the vertical angle"):
        read_tls_observations_csv(path)
