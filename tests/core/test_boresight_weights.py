"""Line points that share an error per segment (one LiDAR line in one image): the segment
nuisances (offset and tilt across the line, ``BoresightOptions.line_segment_sigmas_px``) and
their variance components (core.photo.boresight_weights), on simulated flights where each
segment's points carry a common offset and tilt besides their own noise (issue 32)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from lidarphoto.core.photo.boresight_setup import BoresightOptions
from lidarphoto.core.photo.boresight_weights import line_variances
from lidarphoto.core.photo.ins import ins_grade
from lidarphoto.core.simulation.flight import FlightConfig, simulate_flight

POINT_PX = 0.1  # each point's own noise (the segment fit's RMS of the automatic points)
SEGMENT_PX = 0.3  # sigma of a segment's common offset and of its tilt (offset at its end)
# lines only, 20 points per line and image; INS attitude tight so the images matter
CFG = FlightConfig(
    n_buildings=12,
    n_planes=30,
    town_size_m=700.0,
    n_check=3,
    types=("line",),
    line_points_per_image=20,
    sigma_px=POINT_PX,
    ins_grade=ins_grade("custom", (0.02, 0.05, 0.0005, 0.001)),
)


def _options(**kw) -> BoresightOptions:
    """The calibration of the lines with the simulation's INS grade."""
    return BoresightOptions(use_types=("line",), ins_grade=CFG.ins_grade, **kw)


def _with_segment_errors(sim, rng):
    """The simulation's line points plus a common offset a and tilt b per segment (both
    N(0, SEGMENT_PX^2)) across the segment's image line: a + b tau, tau -1..1 along it
    (segments of fewer than 3 points, at the frame's border, left out)."""
    keys: dict[tuple[str, str], list[int]] = {}
    for r, key in enumerate(zip(sim.observations.image_id, sim.observations.target_id)):
        keys.setdefault(key, []).append(r)
    obs = sim.observations.subset(sorted(r for v in keys.values() if len(v) >= 3 for r in v))
    keys = {}
    for r, key in enumerate(zip(obs.image_id, obs.target_id)):
        keys.setdefault(key, []).append(r)
    px = obs.pixels.copy()
    for rows in keys.values():
        d = px[rows] - px[rows].mean(axis=0)
        along, normal = np.linalg.svd(d, full_matrices=False)[2]
        tau = d @ along
        a, b = rng.normal(0, SEGMENT_PX, 2)
        px[rows] += (a + b * tau / np.max(np.abs(tau)))[:, None] * normal
    return replace(sim, observations=replace(obs, pixels=px)), len(keys)


def _estimated(sim, sigmas=(0.1, 0.1), rounds=5, **kw):
    """Calibrations with the segment nuisances, the variance components re-estimated after
    each (as the automatic calibration's rounds do); the last result and its estimate."""
    scale = 1.0
    for _ in range(rounds):
        obs = replace(sim.observations, sigma_px=sim.observations.sigma_px * scale)
        opts = _options(line_segment_sigmas_px=sigmas, **kw)
        res = replace(sim, observations=obs).calibrate(opts)
        v = line_variances(res, sigmas)
        scale, sigmas = scale * v.scale, (v.offset_px, v.tilt_px)
    return res, v, scale, sigmas


@pytest.fixture(scope="module")
def flight():
    return _with_segment_errors(simulate_flight(CFG, seed=3), np.random.default_rng(4))


def test_independent_weighting_rejects_good_lines(flight):
    """The points weighted as independent at their own 0.1 px: sigma0 far above 1 and data
    snooping sets whole lines aside, though none has a gross error."""
    sim, _ = flight
    res = sim.calibrate(_options(snooping_per_group=True))
    n = len(sim.observations)
    print("independent: sigma0", res.sigma0, "rejected", int(res.residuals.rejected.sum()), n)
    assert res.residuals.rejected.sum() > 0.2 * n


def test_segment_variances_estimated_and_no_line_rejected(flight):
    """With the segment nuisances and their variances estimated: the offset and tilt sigmas
    within 4 standard errors of the simulated 0.3 px (a variance from redundancy r has a
    relative standard error sqrt(2 / r), its sigma half that), the points' scale within 4 of
    its (r in the thousands), sigma0 near 1, nothing rejected and the boresight within 3 of
    its sigmas of the truth."""
    sim, n_seg = flight
    res, v, scale, sigmas = _estimated(sim, snooping=True, snooping_per_group=True)
    print("segments", n_seg, "estimated", scale, sigmas, "r", v.r, "sigma0", res.sigma0)
    for s, r in zip(sigmas, v.r[1:]):
        assert abs(s / SEGMENT_PX - 1) < 4 * np.sqrt(0.5 / r), (s, r)
    assert abs(scale - 1) < 4 * np.sqrt(0.5 / v.r[0]), (scale, v.r[0])
    assert abs(res.sigma0 - 1) < 0.1
    assert not res.residuals.rejected.any()
    err = res.boresight - sim.true_boresight(res.groups)
    assert np.all(np.abs(err) < 3 * res.std_prior)


def test_sigmas_honest_over_draws_and_independent_ones_not():
    """Over 12 draws of the flight (INS, pixel and segment errors): the boresight errors over
    their sigmas with the estimated segment variances follow chi-square (2 groups x 3 angles
    x 12 = 72 degrees of freedom: 0.1 % / 99.9 % points 40.5 and 114.8); weighting the points
    as independent (sigma0-scaled sigmas, as before) gives sigmas that are too small: the same
    errors' sum beyond that range."""
    z_new, z_old = [], []
    for s in range(12):
        sim, _ = _with_segment_errors(
            simulate_flight(CFG, seed=200 + s), np.random.default_rng(300 + s)
        )
        res, *_ = _estimated(sim, rounds=4, snooping=False)
        z_new.append((res.boresight - sim.true_boresight(res.groups)) / res.std)
        old = sim.calibrate(_options(snooping=False))
        z_old.append((old.boresight - sim.true_boresight(old.groups)) / old.std)
    chi_new, chi_old = float(np.sum(np.square(z_new))), float(np.sum(np.square(z_old)))
    print("chi2 (72 dof): segment nuisances", chi_new, "independent", chi_old)
    assert 40.5 < chi_new < 114.8
    assert chi_old > 114.8
