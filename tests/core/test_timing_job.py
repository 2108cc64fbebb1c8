"""The camera timing offset through the boresightcalibration job (ESTIMATE_TIMING): a
simulated dt recovered from files, in the results table, the job's results and the HTML; the
trajectory's velocities (v_north, v_east, v_up) used instead of differenced exposures."""

from __future__ import annotations

import csv
import math
from dataclasses import replace

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.geometry.frames import MappingFrame
from lidarphoto.core.io.trajectory import read_trajectory_csv, write_trajectory_csv
from lidarphoto.core.jobs import boresight_calibration
from lidarphoto.core.jobs.boresight_calibration import TABLE_COLUMNS, TIMING_COLUMNS
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.photo.boresight_result import BoresightNotObservable
from lidarphoto.core.photo.boresight_setup import BoresightOptions
from lidarphoto.core.simulation.flight import FlightConfig, simulate_flight

CFG = FlightConfig(n_buildings=12, n_planes=30, town_size_m=700.0, n_check=0,
                   types=("tie", "lcp"))  # fmt: skip
DT = 0.0123  # s: the issue's +12.3 ms (0.5 m along track at ~43 m/s)


def _recorded(sim, dt: float):
    """The simulation with the INS recorded at the camera's event time: the true pose at
    exposure minus v dt, and the true velocity (north-east-down) of each exposure. The lines
    are straight at constant speed, so differences of the true positions are exact."""
    traj = sim.trajectory
    t = traj.time.astype(float)
    groups = np.array(traj.group)
    true = sim.truth.trajectory.position
    v_grid = np.zeros_like(true)
    for g in dict.fromkeys(groups.tolist()):
        sel = np.flatnonzero(groups == g)
        v_grid[sel] = np.gradient(true[sel], t[sel], axis=0)
    frame = MappingFrame.from_user_input(sim.crs)
    r_ng = frame.ned_to_grid(frame.map_to_geodetic(true))
    v_ned = np.einsum("nji,nj->ni", r_ng, v_grid)  # the grid's scale (1e-4) neglected
    pos = traj.position - v_grid * dt
    return replace(sim, trajectory=replace(traj, position=pos)), v_ned


def _job(sim, folder, **params):
    paths = sim.write(folder)
    raw = {
        "CAMERA": str(paths["camera"]), "TRAJECTORY": str(paths["trajectory"]),
        "CRS": sim.crs, "OBSERVATIONS": str(paths["observations"]),
        "PLANES": str(paths["planes"]), "LCPS": str(paths["lcps"]),
        "LEVER_ARM": ",".join(repr(float(v)) for v in sim.mount.lever_arm),
        "CONTROL_TYPES": "tie,lcp", "GROUPING": "single", "SNOOPING": False,
        "OUTPUT_TABLE": str(folder / "table.csv"), "OUTPUT_EO": str(folder / "eo.csv"),
        "OUTPUT_HTML": str(folder / "summary.html"),
    }  # fmt: skip
    raw.update({k.upper(): v for k, v in params.items()})
    return run_job(boresight_calibration, raw)


@pytest.fixture(scope="module")
def timed(tmp_path_factory):
    sim, v_ned = _recorded(simulate_flight(CFG, seed=3), DT)
    folder = tmp_path_factory.mktemp("timing")
    return sim, v_ned, folder, _job(sim, folder, estimate_timing=True)


def test_job_recovers_dt_within_three_sigma_in_table_results_and_html(timed):
    _, _, folder, job = timed
    res = job.data.result
    assert abs(res.timing_offset - DT) < 3.0 * res.timing_offset_std
    assert res.timing_offset_std < DT / 3  # resolved
    assert job.results["TIMING_OFFSET_MS"] == pytest.approx(1e3 * res.timing_offset)
    assert job.results["TIMING_OFFSET_STD_MS"] == pytest.approx(1e3 * res.timing_offset_std)
    with open(folder / "table.csv", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert tuple(rows[0]) == TABLE_COLUMNS and set(TIMING_COLUMNS) <= set(rows[0])
    names = res.parameter_names
    at = names.index("timing.dt")
    row = rows[0]
    assert float(row["dt_ms"]) == pytest.approx(1e3 * res.timing_offset)
    assert float(row["std_dt_ms"]) == pytest.approx(1e3 * res.timing_offset_std)
    for a in ("d_omega", "d_phi", "d_kappa"):
        r = float(row[f"corr_dt_{a}"])
        assert r == pytest.approx(res.correlation[at, names.index(f"bore[all].{a}")])
        assert -1.0 <= r <= 1.0
    assert row["corr_dt_lever_arm_x"] == ""  # the lever arm is fixed
    page = (folder / "summary.html").read_text(encoding="utf-8")
    assert "Camera timing offset" in page and f"{1e3 * res.timing_offset:.2f}" in page
    assert f"{1e3 * res.timing_offset_std:.2f}" in page and "correlation with dt" in page
    assert any("timing offset dt" in line for line in job.lines)


def test_job_without_timing_leaves_the_columns_empty(tmp_path):
    sim = simulate_flight(CFG, seed=3)
    job = _job(sim, tmp_path)
    assert math.isnan(job.results["TIMING_OFFSET_MS"])
    with open(tmp_path / "table.csv", encoding="utf-8") as fh:
        row = next(csv.DictReader(fh))
    assert all(row[c] == "" for c in TIMING_COLUMNS)
    assert "Camera timing offset" not in (tmp_path / "summary.html").read_text(encoding="utf-8")


def test_trajectory_velocities_are_read_written_and_used(timed, tmp_path):
    sim, v_ned, _, differenced = timed
    with_v = replace(sim, trajectory=replace(sim.trajectory, velocity_ned=v_ned))
    path = tmp_path / "traj.csv"
    write_trajectory_csv(path, with_v.trajectory)
    back = read_trajectory_csv(path)
    np.testing.assert_allclose(back.velocity_ned, v_ned, rtol=0, atol=1e-12)
    job = _job(with_v, tmp_path, estimate_timing=True)
    res, ref = job.data.result, differenced.data.result
    assert job.data.settings["camera timing offset"].endswith("from the trajectory")
    assert abs(res.timing_offset - DT) < 3.0 * res.timing_offset_std
    # the model takes the velocity as known: the sigma moves with |v| only (exact velocities
    # against differences of INS-noisy positions: 3.831 against 3.828 ms, seed 3)
    assert res.timing_offset_std <= ref.timing_offset_std * (1 + 1e-3)
    # used, not recomputed: one image per line cannot be differenced, but has a velocity
    single = replace(with_v.trajectory, group=tuple(with_v.trajectory.image_id))
    opts = BoresightOptions(groups="single", snooping=False, estimate_timing=True)
    one = replace(with_v, trajectory=single).calibrate(opts)
    assert abs(one.timing_offset - DT) < 3.0 * one.timing_offset_std
    with pytest.raises(InputError, match="needs >= 2 images"):
        replace(with_v, trajectory=replace(single, velocity_ned=None)).calibrate(opts)


def test_some_velocity_columns_or_another_unit_are_refused(tmp_path):
    sim = simulate_flight(CFG, seed=3)
    path = tmp_path / "traj.csv"
    fast = np.tile([400.0, 0.0, 0.0], (len(sim.trajectory), 1))
    write_trajectory_csv(path, replace(sim.trajectory, velocity_ned=fast))
    with pytest.raises(InputError, match="beyond the plausible"):
        read_trajectory_csv(path)
    lines = path.read_text(encoding="utf-8").splitlines()
    cut = [",".join(line.split(",")[:-1]) for line in lines]  # v_up dropped
    path.write_text("\n".join(cut) + "\n", encoding="utf-8")
    with pytest.raises(InputError, match="all three velocity columns"):
        read_trajectory_csv(path)


def test_job_refuses_one_line_with_the_lever_arm_and_writes_the_diagnosis(tmp_path):
    """A single straight line at constant speed: dt times the speed is an along-track lever
    arm. The run fails naming both, and the HTML summary says why."""
    sim, _ = _recorded(simulate_flight(replace(CFG, n_lines=1, images_per_line=4), seed=3), DT)
    with pytest.raises(BoresightNotObservable) as info:
        _job(sim, tmp_path, estimate_timing=True, estimate_lever_arm=True)
    assert info.value.parameters == ["timing.dt", "lever_arm.x"]
    page = (tmp_path / "summary.html").read_text(encoding="utf-8")
    assert "Not observable" in page and "timing offset dt cannot be separated" in page
    assert not (tmp_path / "table.csv").exists()
