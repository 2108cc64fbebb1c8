"""LiDAR control on a synthetic town (hip, pyramid and gable roofs) with LiDAR noise of known
sigma: corners and ridges against the town's exact geometry, and the scatter of the corners
over repeated noise draws against the covariance propagated from the plane fits."""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.geometry.planes import fit_plane
from lidarphoto.core.lidar.control import ControlOptions, lidar_control
from lidarphoto.core.simulation.town import make_town, sample_town

SIGMA = 0.05  # m, LiDAR noise per coordinate
DENSITY = 8.0  # points per m^2
OPTIONS = ControlOptions(delta=0.6, min_boundary=2.0, max_support_distance=1.0)


@pytest.fixture(scope="module")
def town():
    return make_town(n_buildings=6, roof_types=("hip", "pyramid", "gable"), n_trees=0, seed=5)


def _true_corners(town):
    """Roof vertices shared by at least three faces of a building: the LCPs to expect."""
    out = []
    for b in town.buildings:
        verts = np.vstack([town.faces[f].polygon for f in b.face_ids])
        keys, counts = np.unique(np.round(verts, 6), axis=0, return_counts=True)
        out.extend(keys[counts >= 3])
    return np.array(out)


def _control(town, seed):
    pts = sample_town(town, density=DENSITY, noise_sigma=SIGMA, seed=seed)
    roof = (pts.face_id >= 0) & ~pts.is_wall
    xyz, face = pts.xyz[roof], pts.face_id[roof]
    planes = [fit_plane(xyz[face == f], plane_id=int(f)) for f in np.unique(face)]
    return lidar_control(planes, xyz, face, OPTIONS)


def test_corners_and_ridges_against_truth(town):
    truth = _true_corners(town)
    assert len(truth) == 2 * 2 + 2  # two hip roofs (2 corners each), two pyramid apexes
    result = _control(town, seed=11)
    found = np.array([p.xyz for p in result.points])
    # each true corner is found once (the four triples of a pyramid apex are merged)
    for corner in truth:
        err = np.linalg.norm(found - corner, axis=1)
        assert err.min() < 0.25, (corner, err.min())
    for p in result.points:
        err = p.xyz - truth[np.argmin(np.linalg.norm(truth - p.xyz, axis=1))]
        assert np.all(np.abs(err) < 5 * p.sigma + 1e-3), (err, p.sigma)
    # ridges and hips: both true end points lie on the estimated line within 5 sigma
    lines = {ln.plane_ids: ln for ln in result.lines}
    for b in town.buildings:
        for seg in b.ridges:
            on = [
                ln for ln in lines.values()
                if np.linalg.norm(np.cross(seg[0] - ln.point, ln.direction)) < 0.3
                and np.linalg.norm(np.cross(seg[1] - ln.point, ln.direction)) < 0.3
            ]  # fmt: skip
            assert on, (b.roof_type, seg)
            ln = on[0]
            expected = "ridge" if abs(seg[1, 2] - seg[0, 2]) < 1e-6 else "hip"
            assert ln.kind == expected
            for end in seg:
                off = np.linalg.norm(np.cross(end - ln.point, ln.direction))
                sig = ln.sigma_across(float((end - ln.point) @ ln.direction))
                assert off < 5 * np.sqrt(2) * sig, (off, sig)
    # gable roofs give lines but no LCP; no spurious corner anywhere
    assert len(result.points) == len(truth)


def test_corner_and_line_scatter_match_propagated_covariance(town):
    truth = _true_corners(town)
    maha, across, predicted = [], [], []
    for seed in range(100, 130):
        result = _control(town, seed)
        for p in result.points:
            err = p.xyz - truth[np.argmin(np.linalg.norm(truth - p.xyz, axis=1))]
            maha.append(err @ np.linalg.solve(p.covariance, err))
        for b in town.buildings:
            for seg in b.ridges:
                for ln in result.lines:
                    dist = [np.linalg.norm(np.cross(e - ln.point, ln.direction)) for e in seg]
                    if max(dist) < 0.3:
                        for e, dd in zip(seg, dist):
                            across.append(dd**2)
                            predicted.append(
                                2 * ln.sigma_across(float((e - ln.point) @ ln.direction)) ** 2
                            )
    # lines: the mean squared distance of the true end points across the estimated line equals
    # the propagated variance (2 directions) within 15 % over ~2000 end points
    assert 0.85 < np.mean(across) / np.mean(predicted) < 1.15, np.mean(across) / np.mean(predicted)
    maha = np.array(maha)
    # chi-square with 3 dof: mean 3, standard error sqrt(6 / m); 4-sigma bound. (Corners of one
    # draw share planes, so the effective m is smaller: the bound is loose by design.)
    m = len(maha) / 2
    assert abs(maha.mean() - 3.0) < 4 * np.sqrt(6.0 / m), (maha.mean(), len(maha))
