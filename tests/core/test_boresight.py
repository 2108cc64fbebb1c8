"""Boresight calibration: Jacobians, recovery per control type, snooping, diagnosis, frames."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.distortion import distortion_from_dict
from lidarphoto.core.geometry.rotations import rph_to_matrix
from lidarphoto.core.photo.boresight_models import PoseSpec, collinearity, coplanarity, paper_plane
from lidarphoto.core.photo.boresight_result import BoresightNotObservable
from lidarphoto.core.photo.boresight_setup import ARCSEC, BoresightOptions
from lidarphoto.core.photo.mount import MOUNT_PRESETS
from lidarphoto.core.simulation.flight import FlightConfig, simulate_flight
from numdiff import central_difference

# A small, fast block: 2 x 3 images over ~30 roof planes, every control type.
SMALL = FlightConfig(
    n_buildings=12,
    n_planes=30,
    town_size_m=700.0,
    n_check=3,
    types=("tie", "line", "lcp", "paper", "check"),
)


def _run(sim, **kw):
    return sim.calibrate(BoresightOptions(**{"snooping": False, **kw}))


# ----------------------------------------------------------------------------- Jacobians
@pytest.fixture(scope="module")
def spec():
    dist = distortion_from_dict(
        {"model": "brown_conrady", "k1": -2e-5, "k2": 1e-9, "p1": 1e-6, "p2": -2e-6}
    )
    cam = Camera(
        "c",
        focal_mm=100.0,
        pixel_size_mm=0.006,
        width_px=12000,
        height_px=8000,
        x0_mm=0.02,
        y0_mm=-0.01,
        distortion=dist,
    )
    return PoseSpec(cam, MOUNT_PRESETS["image_top_forward"], np.zeros(3), True, True)


def _pose(spec):
    rng = np.random.default_rng(3)
    xp = np.concatenate(
        [
            [0.01, -0.02, 0.03],
            [100.0, -50.0, 1600.0],
            [0.02, -0.01, 0.7],
            [0.2, -0.1, -0.6],
            [100.0, 0.02, -0.01],
        ]
    )
    r_nl = rph_to_matrix(0.001, -0.002, 0.0) @ np.array(
        [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]]
    )
    pts = np.array([100.0, -50.0, 0.0]) + rng.uniform(-300, 300, (5, 3)) * [1, 1, 0.03]
    return xp, r_nl, pts


STEPS = [1e-7] * 3 + [1e-3] * 3 + [1e-7] * 3 + [1e-3] * 3 + [1e-5] * 3


def test_collinearity_jacobian_matches_finite_differences(spec):
    xp, r_nl, pts = _pose(spec)
    n = len(pts)
    rn = np.broadcast_to(r_nl, (n, 3, 3))
    _, jac, jpt = collinearity(np.tile(xp, (n, 1)), pts, rn, spec)
    num = central_difference(
        lambda x: collinearity(np.tile(x, (n, 1)), pts, rn, spec)[0], xp, STEPS
    )
    np.testing.assert_allclose(jac, num, rtol=1e-5, atol=1e-4)
    numpt = central_difference(
        lambda p: collinearity(np.tile(xp, (1, 1)), p[None], rn[:1], spec)[0], pts[0], [1e-3] * 3
    )
    np.testing.assert_allclose(jpt[:1], numpt, rtol=1e-6, atol=1e-6)


def test_coplanarity_and_paper_jacobians_match_finite_differences(spec):
    xp, r_nl, pts = _pose(spec)
    n = len(pts)
    rn = np.broadcast_to(r_nl, (n, 3, 3))
    xps = np.tile(xp, (n, 1))
    px = collinearity(xps, pts, rn, spec)[0]
    u = np.tile([0.6, 0.8, 0.0], (n, 1))
    g, jp, jpx, jpt, ju = coplanarity(xps, px, pts, u, rn, spec)
    np.testing.assert_allclose(g, 0.0, atol=1e-6)  # the ray passes through the line point
    num = central_difference(
        lambda x: coplanarity(np.tile(x, (n, 1)), px, pts, u, rn, spec)[0][:, None], xp, STEPS
    )[:, 0]
    np.testing.assert_allclose(jp, num, rtol=1e-5, atol=1e-5)
    for j, (arr, base, step) in enumerate(((px, jpx, 1e-3), (pts, jpt, 1e-3), (u, ju, 1e-6))):

        def f(v, j=j, arr=arr):
            args = [px, pts, u]
            args[j] = v.reshape(arr.shape)
            return coplanarity(xps, *args, rn, spec)[0].reshape(-1, 1, 1)

        flat = arr.ravel()
        numj = central_difference(lambda v: f(v)[:, :, 0], flat, [step] * flat.size)
        got = numj.reshape(n, -1)[
            np.arange(n)[:, None], np.arange(arr.shape[1]) + arr.shape[1] * np.arange(n)[:, None]
        ]
        np.testing.assert_allclose(base, got, rtol=1e-5, atol=1e-6)
    normal = np.tile([0.3, 0.1, 0.95], (n, 1))
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    z = pts[:, 2] + 2.0
    _, jd = paper_plane(xps, px, normal, z, rn, spec)
    numd = central_difference(
        lambda x: paper_plane(np.tile(x, (n, 1)), px, normal, z, rn, spec)[0][:, None], xp, STEPS
    )
    np.testing.assert_allclose(jd, numd, rtol=1e-5, atol=1e-6)


# ----------------------------------------------------------------------------- recovery
@pytest.mark.parametrize("types", [("tie",), ("line",), ("lcp",), ("tie", "line", "lcp")])
@pytest.mark.parametrize(
    "mount,initial",
    [("image_top_forward", (0.0, 0.0, 0.0)), ("image_bottom_forward", (1.2, -0.9, 1.5))],
)
def test_each_control_type_recovers_the_boresight(types, mount, initial):
    sim = simulate_flight(replace(SMALL, mount=mount, initial_boresight_deg=initial), seed=11)
    res = _run(sim, use_types=types)
    err = res.boresight - sim.true_boresight(res.groups)
    assert res.adjustment.converged
    assert np.all(np.abs(err) < 3.0 * res.std_prior), (err / ARCSEC, res.std_prior / ARCSEC)
    # reported sigmas: INS attitude floor sigma/sqrt(3) and not much more (30 planes)
    assert np.all(res.std_prior[:, :2] / ARCSEC > 54.0 / np.sqrt(3) * 0.99)
    assert 0.6 < res.sigma0 < 1.4


def test_reported_sigmas_match_the_scatter_over_draws():
    cfg = replace(SMALL, types=("lcp",))
    z = []
    for seed in range(25):
        sim = simulate_flight(cfg, seed=100 + seed)
        res = _run(sim, use_types=("lcp",))
        z.append((res.boresight - sim.true_boresight(res.groups)) / res.std_prior)
    chi2 = float(np.sum(np.square(z)))
    dof = np.size(z)  # 150: chi-square(150) has its 0.1 % / 99.9 % points at 102 and 209
    assert 102.0 < chi2 < 209.0, chi2 / dof


def test_blunders_are_found_by_data_snooping():
    sim = simulate_flight(replace(SMALL, n_blunders=3, blunder_px=30.0), seed=5)
    res = _run(sim, use_types=("tie", "lcp"), snooping=True)
    flagged = np.flatnonzero(res.residuals.rejected)
    assert set(sim.truth.blunders.tolist()) <= set(flagged.tolist())
    assert len(flagged) <= len(sim.truth.blunders) + 2
    err = res.boresight - sim.true_boresight(res.groups)
    assert np.all(np.abs(err) < 3.0 * res.std_prior)


def test_unobservable_group_raises_the_diagnosis():
    sim = simulate_flight(SMALL, seed=2)
    groups = {
        i: ("lonely" if i == sim.trajectory.image_id[0] else "rest")
        for i in sim.trajectory.image_id
    }
    keep = np.array([i != sim.trajectory.image_id[0] for i in sim.observations.image_id])
    sim = replace(sim, observations=sim.observations.subset(keep))
    with pytest.raises(BoresightNotObservable) as info:
        _run(sim, use_types=("lcp",), groups=groups, ins_as_parameters=False)
    assert any("'lonely'" in d for d in info.value.diagnosis)
    assert any(p.startswith("bore[lonely]") for p in info.value.parameters)


# ----------------------------------------------------------------------------- frames
@pytest.mark.parametrize(
    "crs,lonlat",
    [
        ("EPSG:28992", None),
        ("EPSG:32631", None),
        ("EPSG:32632", (9.0, 0.5)),
        ("EPSG:32633", (17.0, 70.0)),
    ],
)
def test_same_block_anywhere_gives_the_same_boresight(crs, lonlat):
    from pyproj import Transformer

    if lonlat is None:  # the RD New block near Delft, in RD New and in UTM 31N
        lonlat = Transformer.from_crs("EPSG:28992", "EPSG:4326", always_xy=True).transform(
            85500.0, 447500.0
        )
    e, n = Transformer.from_crs("EPSG:4326", crs, always_xy=True).transform(*lonlat)
    cfg = replace(SMALL, crs=crs, centre=(e, n), types=("tie", "lcp", "line"))
    sim = simulate_flight(cfg, seed=4, exact=True)
    res = _run(sim)
    err = (res.boresight - sim.true_boresight(res.groups)) / ARCSEC
    np.testing.assert_allclose(err, 0.0, atol=0.05)  # arc-seconds
