"""docs/architecture.md's "Adding an algorithm", checked end to end: the test suite's
``fitplane`` (tests/core/job_fixtures/fitplane.py, a spec and a run()) added to the registry
is listed, documented and run by the command line, with nothing else to write."""

from __future__ import annotations

import csv

import numpy as np
import pytest
from lidarphoto.core import cli, jobs
from lidarphoto.core.lidar.roof_planes import RoofPlaneParams

FIXTURE = "job_fixtures.fitplane"


@pytest.fixture()
def registered(monkeypatch):
    """The registry with ``fitplane`` added, as step 4 of the recipe does."""
    monkeypatch.setattr(jobs, "NAMES", (*jobs.NAMES, FIXTURE))


def _plane_points(path, normal, d, sigma, n=400, seed=1):
    """Points on n . p + d = 0 with normal noise of ``sigma`` (m) along the normal."""
    rng = np.random.default_rng(seed)
    normal = np.asarray(normal, dtype=float) / np.linalg.norm(normal)
    u = np.cross(normal, [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    w = np.cross(normal, u)
    st = rng.uniform(-20.0, 20.0, (n, 2))
    xyz = -d * normal + st[:, :1] * u + st[:, 1:] * w + rng.normal(0.0, sigma, (n, 1)) * normal
    centre = np.array([85000.0, 445000.0, 0.0])  # projected coordinates, as a cloud has them
    with open(path, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(["x", "y", "z"])
        writer.writerows((xyz + centre).tolist())
    return normal, centre - d * normal  # the true plane's point under the data's centre


def test_the_registered_algorithm_is_listed_and_documented(registered, capsys):
    with pytest.raises(SystemExit) as stop:
        cli.main(["--help"])
    assert stop.value.code == 0
    assert "one least-squares plane through a point table" in capsys.readouterr().out
    with pytest.raises(SystemExit):
        cli.main(["fitplane", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    # the default comes from the science dataclass, with its unit and range
    epsilon = RoofPlaneParams().epsilon
    assert f"--epsilon NUMBER Inlier tolerance; default: {epsilon:g}; unit: m" in help_text
    assert "range: 0.001 to 100" in help_text and "Pathak et al. (2010)" in help_text


def test_the_registered_algorithm_runs_through_the_command_line(registered, tmp_path, capsys):
    """A plane with known parameters and 1 cm noise is recovered within what the noise
    allows; the outputs are the ones the spec names."""
    normal, centre = _plane_points(tmp_path / "points.csv", (0.2, -0.1, 1.0), -12.5, 0.01)
    out = tmp_path / "plane.csv"
    code = cli.main(["fitplane", "--input", str(tmp_path / "points.csv"), "--output", str(out)])
    assert code == 0
    printed = capsys.readouterr().out
    assert "400 points" in printed
    row = next(csv.DictReader(out.open()))
    fitted = np.array([float(row[k]) for k in "abc"])
    # 400 points over 40 m x 40 m with 1 cm noise: the normal is good to 4e-5 rad (1 sigma,
    # 0.0025 deg), the plane's height at the centre to 0.5 mm; tolerances of 6-8 sigma
    assert np.degrees(np.arccos(min(1.0, abs(fitted @ normal)))) < 0.02
    assert abs(fitted @ centre + float(row["d"])) < 0.003
    assert 0.008 < float(row["rms"]) < 0.012
    assert int(row["inliers"]) == 400  # 0.15 m is 15 sigma


def test_a_bad_value_is_refused_by_the_generated_command_line(registered, tmp_path, capsys):
    _plane_points(tmp_path / "points.csv", (0.0, 0.0, 1.0), 0.0, sigma=0.01)
    out = tmp_path / "plane.csv"
    argv = ["fitplane", "--input", str(tmp_path / "points.csv"), "--output", str(out)]
    assert cli.main([*argv, "--epsilon", "0"]) == 2
    assert "EPSILON: must be >= 0.001 m, got 0" in capsys.readouterr().err
    assert not out.exists()
