"""Boresight calibration from surveyed ground control (observation type ``control`` and the
GROUND_POINTS table), against the truth of a simulated flight."""

from __future__ import annotations

import csv

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.io.observations import read_observations_csv, write_observations_csv
from lidarphoto.core.jobs import boresight_calibration
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.photo.observations import ImageObservations
from lidarphoto.core.simulation.flight import FlightConfig, surveyed_control

# LiDAR corners stand in for surveyed points (core.simulation.flight.surveyed_control): their
# true coordinates plus survey noise are the ground points, measured with 0.5 px noise.
CONFIG = FlightConfig(
    n_buildings=12, n_planes=30, town_size_m=700.0, n_check=4, types=("lcp", "check")
)
SURVEY_SIGMA = np.array([0.02, 0.02, 0.03])  # metres: sx, sy, sz given and applied
SEED = 5


def _ground_control(folder):
    """Files of a flight whose only control is surveyed points measured as ``control`` rows."""
    sim, _rows, ground, paths = surveyed_control(CONFIG, SEED, tuple(SURVEY_SIGMA),
                                                 folder=folder)  # fmt: skip
    return sim, ground, paths


def _run(paths, sim, **params):
    raw = {
        "CAMERA": str(paths["camera"]),
        "TRAJECTORY": str(paths["trajectory"]),
        "CRS": sim.crs,
        "OBSERVATIONS": str(paths["observations"]),
        "GROUND_POINTS": str(paths["ground"]),
        "LEVER_ARM": ",".join(repr(float(v)) for v in sim.mount.lever_arm),
        "GROUPING": "single",
        "CONTROL_TYPES": "control",
    }
    raw.update({k.upper(): v for k, v in params.items()})
    return run_job(boresight_calibration, raw).data


@pytest.fixture(scope="module")
def calibrated(tmp_path_factory):
    folder = tmp_path_factory.mktemp("gcp")
    sim, ground, paths = _ground_control(folder)
    run = _run(paths, sim, residuals_csv=folder / "residuals.csv",
               output_table=folder / "table.csv", output_eo=folder / "eo.csv",
               output_html=folder / "summary.html")  # fmt: skip
    return sim, ground, paths, run, folder


def test_control_rows_recover_the_boresight_within_their_sigmas(calibrated):
    sim, ground, _paths, run, _ = calibrated
    res = run.result
    # one true boresight for every line (CONFIG), one estimated (GROUPING single)
    true = np.array([next(iter(sim.truth.boresight.values()))])
    err = res.boresight - true
    # the tolerance the noise gives: 4 sigma of the reported (a-posteriori) sigmas
    assert np.all(np.abs(err) < 4.0 * res.std), (err / res.std)
    # and the sigmas are those of a real determination: omega and phi well below the true
    # misalignment (252", -468"), kappa below the INS heading sigma (126")
    assert np.all(res.std_arcsec[0, :2] < 30.0) and res.std_arcsec[0, 2] < 100.0, res.std_arcsec
    assert res.chi2_passed
    obs = run.observations
    kinds = set(obs.type)
    assert kinds == {"control"}
    role = dict(zip(ground.point_id, ground.role))
    used = res.residuals.used
    is_check = np.array([role[p] == "check" for p in obs.point_id])
    assert is_check.any() and (~is_check).any()
    # check points are kept out of the adjustment, control points are in it
    assert not used[is_check].any() and used[~is_check].all()
    assert np.isfinite(res.residuals.v_px[~is_check]).all()


def test_check_points_are_placed_at_their_surveyed_height_and_named(calibrated):
    _sim, ground, _paths, run, folder = calibrated
    obs = run.observations
    by_id = dict(zip(ground.point_id, ground.xyz))
    role = dict(zip(ground.point_id, ground.role))
    rows = [k for k, p in enumerate(obs.point_id) if role[p] == "check"]
    xyz = np.array([by_id[obs.point_id[k]] for k in rows])
    # (the cut is horizontal in the local ENU frame: micrometres from the map height)
    np.testing.assert_allclose(run.ground[rows, 2], xyz[:, 2], atol=1e-4)
    # planimetric position of a check point from the calibrated orientation: within a few
    # sigmas of 0.5 px at ~1600 m with 100 mm / 7.2 um (GSD ~ 0.12 m) plus the survey noise
    d = np.hypot(*(run.ground[rows, :2] - xyz[:, :2]).T)
    assert np.sqrt(np.mean(d**2)) < 0.5, d
    with open(folder / "residuals.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert {r["point_id"] for r in table} == set(obs.point_id)
    assert all(r["type"] == "control" and r["target_id"] == "" for r in table)


def test_control_row_naming_a_missing_ground_point_is_an_error_naming_the_row(calibrated):
    sim, _ground, paths, _, folder = calibrated
    obs = read_observations_csv(paths["observations"])
    bad_obs = ImageObservations(obs.image_id, ("GCP1",) * 2 + ("NOPE",) + obs.point_id[3:],
                                obs.pixels, obs.sigma_px, obs.type, obs.target_id)  # fmt: skip
    bad = dict(paths, observations=folder / "bad.csv")
    write_observations_csv(bad["observations"], bad_obs)
    with pytest.raises(InputError) as err:
        _run(bad, sim)
    text = str(err.value)
    assert "NOPE" in text and "bad.csv" in text and "row 4" in text, text
    # without the ground points the control rows are refused, not ignored
    none = dict(paths)
    none["ground"] = ""
    with pytest.raises(InputError, match="GROUND_POINTS"):
        _run(none, sim)
