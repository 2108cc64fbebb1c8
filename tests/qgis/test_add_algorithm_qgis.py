"""docs/architecture.md's "Adding an algorithm" in QGIS: the test suite's ``fitplane``
(tests/core/job_fixtures/fitplane.py) added to the registry appears in the toolbox without a
provider file (a generated algorithm) and runs through processing.run like the command line."""

from __future__ import annotations

import csv

import numpy as np
import pytest
from lidarphoto.core import jobs
from lidarphoto.core.lidar.roof_planes import RoofPlaneParams
from qgis.core import QgsProcessingException


@pytest.fixture()
def fitplane_provider(monkeypatch, qgis_processing):
    """The provider loaded with ``fitplane`` in the registry (step 4 of the recipe)."""
    import lidarphoto
    from qgis.core import QgsApplication

    monkeypatch.setattr(jobs, "NAMES", (*jobs.NAMES, "job_fixtures.fitplane"))
    plugin = lidarphoto.classFactory(None)
    plugin.initProcessing()
    yield QgsApplication.processingRegistry().providerById("lidarphoto")
    plugin.unload()


def _points(path, sigma=0.01, n=300, seed=2):
    """Points on z = 0.1 x - 0.05 y + 3 (map coordinates near the origin of a grid)."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform(-15.0, 15.0, (n, 2))
    z = 0.1 * xy[:, 0] - 0.05 * xy[:, 1] + 3.0 + rng.normal(0.0, sigma, n)
    with open(path, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(["x", "y", "z"])
        writer.writerows(np.column_stack([xy, z]).tolist())
    return np.array([-0.1, 0.05, 1.0]) / np.linalg.norm([-0.1, 0.05, 1.0])


def test_the_registered_algorithm_is_generated_and_runs(fitplane_provider, tmp_path):
    import processing

    alg = fitplane_provider.algorithm("fitplane")
    assert alg is not None and type(alg).__name__ == "FitplaneAlgorithm"
    assert alg.displayName() == "Fit a plane" and alg.groupId() == "lidar"
    eps = alg.parameterDefinition("EPSILON")
    assert eps.defaultValue() == RoofPlaneParams().epsilon  # read from the science
    normal = _points(tmp_path / "points.csv")
    out = tmp_path / "plane.csv"
    result = processing.run(
        "lidarphoto:fitplane", {"INPUT": str(tmp_path / "points.csv"), "OUTPUT": str(out)}
    )
    row = next(csv.DictReader(out.open()))
    fitted = np.array([float(row[k]) for k in "abc"])
    # 300 points over 30 m x 30 m, 1 cm noise: the normal is good to 7e-5 rad (1 sigma)
    assert np.degrees(np.arccos(min(1.0, abs(fitted @ normal)))) < 0.03
    assert result["INLIERS"] == 300 and 0.008 < result["RMS"] < 0.012
    with pytest.raises(QgsProcessingException):
        processing.run(
            "lidarphoto:fitplane",
            {"INPUT": str(tmp_path / "missing.csv"), "OUTPUT": str(tmp_path / "x.csv")},
        )
    assert not (tmp_path / "x.csv").exists()
