"""The camera timing offset in the bundle adjustment (BundleOptions.estimate_timing) against
simulated truth: the UAV block of test_bundle.py flown on straight strips (serpentine: the
strips alternate direction) at about 60 m/s, its GNSS/INS centres recorded dt = +12.3 ms
before the exposures (exposure = recorded time + dt), so the observed centres lie v dt
(0.74 m) behind the true ones along track. Tolerances: 3 a-posteriori sigmas for dt, a
chi-square bound for the Monte Carlo scatter of dt over its sigma.
"""

from __future__ import annotations

import csv
from dataclasses import replace

import numpy as np
import pytest
from lidarphoto.core.errors import NotObservableError
from lidarphoto.core.photo.bundle import bundle_adjust
from lidarphoto.core.photo.bundle_setup import BundleOptions, GroundPoints
from lidarphoto.core.photo.timing import ExposureVelocities
from lidarphoto.core.simulation.uav_block import simulate_uav_block
from scipy import stats

DT = 0.0123  # s
SIG_P, SIG_A = 0.02, np.radians(0.003)  # GNSS/INS sigmas: m, rad
PLAIN = {"robust": "none", "snooping": False, "ap_selection": False,
         "estimate_interior": False}  # fmt: skip


@pytest.fixture(scope="module")
def block():
    return simulate_uav_block("none", seed=2, n_tie=400, position_jitter_m=0.0)


def _recorded(blk, speeds, seed: int, dt: float = DT, directions: bool = True):
    """The observed orientations (GNSS/INS at the recorded time, with noise), the velocity of
    every exposure (map axes, m/s) and the recorded times; ``speeds`` per strip (m/s)."""
    rng = np.random.default_rng(seed)
    eo = blk.eo_true
    strips = np.array(eo.group)
    vel = np.zeros((len(eo), 3))
    times = np.zeros(len(eo))
    start = 0.0
    for s, name in enumerate(dict.fromkeys(strips.tolist())):
        sel = np.flatnonzero(strips == name)
        d = eo.xyz[sel[-1], :2] - eo.xyz[sel[0], :2]
        u = d / np.linalg.norm(d)
        vel[sel, :2] = u * speeds[s % len(speeds)]
        along = (eo.xyz[sel, :2] - eo.xyz[sel[0], :2]) @ u
        times[sel] = start + along / speeds[s % len(speeds)]
        start = times[sel[-1]] + 30.0
    xyz = eo.xyz - vel * dt + rng.normal(0, SIG_P, eo.xyz.shape)
    opk = eo.opk + rng.normal(0, SIG_A, eo.opk.shape)
    observed = replace(eo, xyz=xyz, opk=opk, time=times - dt)
    sigma = np.tile([SIG_P] * 3 + [SIG_A] * 3, (len(eo), 1))
    if not directions:  # every strip said to be flown east at its speed
        vel = np.column_stack([np.linalg.norm(vel, axis=1), np.zeros((len(eo), 2))])
    return observed, sigma, vel


def _adjust(blk, observed, sigma, vel=None, ground=None, **kw):
    velocity = None if vel is None else ExposureVelocities(vel, "map")
    # the true interior orientation: a principal point off along track would mimic dt on
    # strips of alternating direction (a camera-frame shift; see the interior test below)
    return bundle_adjust(
        [blk.true_camera], blk.observations, blk.ground if ground is None else ground, blk.mapping,
        observed, sigma, options=BundleOptions(**{**PLAIN, **kw}), velocity=velocity,
    )  # fmt: skip


def _along_track(blk, res_xyz) -> float:
    """Mean (adjusted - true) centre along each image's flight direction, metres."""
    vel = _recorded(blk, (60.0,), 0)[2]
    u = vel[:, :2] / np.linalg.norm(vel[:, :2], axis=1)[:, None]
    return float(np.mean(np.sum((res_xyz[:, :2] - blk.eo_true.xyz[:, :2]) * u, axis=1)))


def test_dt_recovered_within_three_sigma_and_without_it_the_centres_are_biased(block):
    observed, sigma, vel = _recorded(block, (60.0,), seed=5)
    res = _adjust(block, observed, sigma, vel, estimate_timing=True)
    t = res.timing
    assert abs(t["dt_s"] - DT) < 3 * t["dt_std_s"], t
    assert t["dt_std_s"] < DT / 10  # resolved
    assert set(t["correlation"]) and all(abs(r) <= 1 for r in t["correlation"].values())
    with_dt = _along_track(block, res.eo.xyz)
    plain = _adjust(block, observed, sigma, vel)
    assert plain.timing is None
    without = _along_track(block, plain.eo.xyz)
    # 60 m/s x 12.3 ms = 0.74 m behind the exposure: the adjusted centres follow the GNSS
    # part of the way without dt, and not with it
    assert without < -0.1 and abs(with_dt) < 0.03, (without, with_dt)
    assert plain.sigma0 > 2 * res.sigma0


def test_monte_carlo_scatter_of_dt_matches_its_sigma(block):
    z = []
    for seed in range(10, 16):
        observed, sigma, vel = _recorded(block, (60.0, 45.0), seed)
        t = _adjust(block, observed, sigma, vel, estimate_timing=True).timing
        z.append((t["dt_s"] - DT) / t["dt_std_s"])
    chi2 = float(np.sum(np.square(z)))
    assert stats.chi2.ppf(0.001, len(z)) < chi2 < stats.chi2.ppf(0.999, len(z)), z


def test_velocities_differenced_from_the_exposures_by_time(block):
    observed, sigma, _ = _recorded(block, (60.0,), seed=6)
    t = _adjust(block, observed, sigma, estimate_timing=True).timing
    assert abs(t["dt_s"] - DT) < 3 * t["dt_std_s"], t


def test_with_the_lever_arm_one_speed_is_refused_and_two_speeds_separate(block):
    observed, sigma, vel = _recorded(block, (60.0,), seed=7)
    with pytest.raises(NotObservableError, match="timing dt") as info:
        _adjust(block, observed, sigma, vel, estimate_timing=True, estimate_mount=True)
    # the image's top looks forward: camera y is along track
    assert info.value.parameters == ["timing dt", "lever dy_c"]
    observed, sigma, vel = _recorded(block, (60.0, 35.0), seed=7)
    res = _adjust(block, observed, sigma, vel, estimate_timing=True, estimate_mount=True)
    t = res.timing
    assert abs(t["dt_s"] - DT) < 3 * t["dt_std_s"], t
    assert "lever dy_c" in t["correlation"] and abs(t["correlation"]["lever dy_c"]) > 0.5


def test_one_velocity_and_no_control_is_not_observable_naming_dt(block):
    """Every exposure with the same velocity and the datum from the GNSS/INS alone: dt times
    the velocity shifts the whole block; the adjustment's own observability check names dt."""
    observed, sigma, vel = _recorded(block, (60.0,), seed=8, directions=False)
    g = block.ground
    checks = GroundPoints(g.point_id, g.xyz, g.sigma, ("check",) * len(g))
    obs = block.observations
    once = {p for p in set(obs.point_id) if obs.point_id.count(p) < 2}
    blk = replace(block, observations=obs.subset([p not in once for p in obs.point_id]))
    with pytest.raises(NotObservableError) as info:
        _adjust(blk, observed, sigma, vel, ground=checks, estimate_timing=True)
    assert "timing dt" in info.value.parameters or "timing dt" in str(info.value)


def test_job_estimates_dt_and_reports_it(block, tmp_path):
    from lidarphoto.core.io.camera import write_cameras_json
    from lidarphoto.core.io.orientation import read_eo_csv_full, write_eo_csv_with_sigmas
    from lidarphoto.core.jobs import bundle_adjustment
    from lidarphoto.core.jobs.runner import run_job

    observed, sigma, vel = _recorded(block, (60.0, 45.0), seed=9)
    paths = block.write(tmp_path)
    write_cameras_json(paths["camera"], [block.true_camera])  # as in _adjust
    eo_path = tmp_path / "eo_timed.csv"
    write_eo_csv_with_sigmas(eo_path, observed, sigma)
    with open(eo_path, encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    rows[0] += ["vx", "vy", "vz"]
    for r, v in zip(rows[1:], vel):
        r += [repr(float(x)) for x in v]
    with open(eo_path, "w", encoding="utf-8", newline="") as fh:
        csv.writer(fh).writerows(rows)
    assert read_eo_csv_full(eo_path).velocity.frame == "map"
    html = tmp_path / "summary.html"
    base = {
        "CAMERA": str(paths["camera"]), "OBSERVATIONS": str(paths["observations"]),
        "GROUND_POINTS": str(paths["ground_points"]), "EO": str(eo_path), "CRS": block.config.crs,
        "ESTIMATE_INTERIOR": False, "ROBUST": "none", "SNOOPING": False,
        "AP_SELECTION": False, "OUTPUT_EO": str(tmp_path / "eo.csv"), "OUTPUT_HTML": str(html),
    }  # fmt: skip
    job = run_job(bundle_adjustment, {**base, "ESTIMATE_TIMING": True})
    t = job.data.timing
    assert job.results["TIMING_OFFSET_MS"] == pytest.approx(1e3 * t["dt_s"])
    assert job.results["TIMING_OFFSET_STD_MS"] == pytest.approx(1e3 * t["dt_std_s"])
    assert abs(job.results["TIMING_OFFSET_MS"] - 1e3 * DT) < 3 * job.results["TIMING_OFFSET_STD_MS"]
    page = html.read_text(encoding="utf-8")
    assert "Camera timing offset" in page and "velocities from the EO table" in page
    assert any("timing offset dt" in line for line in job.lines)
    plain = run_job(bundle_adjustment, base)
    assert np.isnan(plain.results["TIMING_OFFSET_MS"])


def test_with_the_interior_estimated_dt_trades_with_the_principal_point_and_says_so(block):
    """Strips of alternating direction at one speed: dt shifts the GNSS centres along track
    in the camera frame, as a principal point off in y does; dt is still recovered within 3
    sigma, its sigma grows, and the warning names y0."""
    observed, sigma, vel = _recorded(block, (60.0,), seed=5)
    res = bundle_adjust(
        [block.camera], block.observations, block.ground, block.mapping, observed, sigma,
        options=BundleOptions(**{**PLAIN, "estimate_interior": True, "estimate_timing": True}),
        velocity=ExposureVelocities(vel, "map"),
    )  # fmt: skip
    t = res.timing
    assert abs(t["dt_s"] - DT) < 3 * t["dt_std_s"], t
    name = f"{block.camera.name} y0_mm"
    assert abs(t["correlation"][name]) > 0.9
    assert any("timing offset dt is correlated with" in w and name in w for w in res.warnings)


def test_eo_velocity_columns_read_and_refused_by_name(tmp_path):
    from lidarphoto.core.errors import InputError
    from lidarphoto.core.io.orientation import read_eo_csv_full

    head = "image_id,time,group,X,Y,Z,omega_deg,phi_deg,kappa_deg"
    row = "I1,1.0,L1,500000,7450000,300,0,0,0"

    def eo(cols: str, vals: str):
        path = tmp_path / "eo.csv"
        path.write_text(f"{head},{cols}\n{row},{vals}\n", encoding="utf-8")
        return read_eo_csv_full(path)

    v = eo("v_north,v_east,v_up", "10,50,2").velocity
    assert v.frame == "ned" and np.allclose(v.values, [[10, 50, -2]])
    v = eo("vx,vy,vz", "50,10,2").velocity
    assert v.frame == "map" and np.allclose(v.values, [[50, 10, 2]])
    assert _plain_eo(tmp_path, head, row).velocity is None
    with pytest.raises(InputError, match="all three"):
        eo("vx,vy", "50,10")
    with pytest.raises(InputError, match="all three"):
        eo("vx,vy,vz,v_north,v_east,v_up", "1,2,3,4,5,6")
    with pytest.raises(InputError, match="m/s") as info:
        eo("vx,vy,vz", "500,10,2")
    assert info.value.row == 2


def _plain_eo(folder, head: str, row: str):
    from lidarphoto.core.io.orientation import read_eo_csv_full

    path = folder / "plain.csv"
    path.write_text(f"{head}\n{row}\n", encoding="utf-8")
    return read_eo_csv_full(path)


def test_timing_needs_observed_orientations_and_velocities_or_times(block):
    from lidarphoto.core.errors import InputError

    observed, sigma, _ = _recorded(block, (60.0,), seed=3)
    with pytest.raises(InputError, match="needs observed orientations"):
        _adjust(block, observed, None, estimate_timing=True)
    untimed = replace(observed, time=np.full(len(observed), np.nan))
    with pytest.raises(InputError, match="velocity columns"):
        _adjust(block, untimed, sigma, estimate_timing=True)


@pytest.mark.parametrize("mount", [True, False])
def test_observed_orientation_model_with_dt_jacobian(mount):
    """The analytic Jacobian of the observed-orientation model with dt (with and without the
    lever arm and boresight) against central differences; dt moves the centre by -v dt."""
    from lidarphoto.core.photo.bundle_model import _ObservedEOModel

    rng = np.random.default_rng(1)
    g = 5
    cols = [rng.normal(0, 10, (g, 3)), rng.normal(0, 0.05, (g, 2)), rng.uniform(-3, 3, (g, 1))]
    if mount:
        cols += [rng.normal(0, 0.3, (g, 3)), rng.normal(0, 0.01, (g, 3))]
    xl = np.column_stack([*cols, np.full(g, 0.02)])
    vel = rng.normal(0, 50, (g, 3))
    model = _ObservedEOModel(np.zeros((g, 6)), mount, vel)
    f, J = model(xl)
    assert J.shape == (g, 6, xl.shape[1])
    for j in range(xl.shape[1]):
        p, q = xl.copy(), xl.copy()
        p[:, j] += 1e-7
        q[:, j] -= 1e-7
        num = (model(p)[0] - model(q)[0]) / 2e-7
        assert np.abs(num - J[:, :, j]).max() < 1e-5, j
    still = xl.copy()
    still[:, -1] = 0.0
    assert np.allclose(model(still)[0][:, :3] - f[:, :3], 0.02 * vel)


def test_default_pipeline_carries_dt_through_the_ap_selection(block):
    """Robust reweighting, data snooping and the AP selection (Brown's 14 terms on a lens
    without distortion: most are dropped, each drop a new adjustment) keep dt."""
    observed, sigma, vel = _recorded(block, (60.0, 45.0), seed=4)
    res = bundle_adjust(
        [block.true_camera], block.observations, block.ground, block.mapping, observed, sigma,
        options=BundleOptions(ap_model="brown", estimate_interior=False, estimate_timing=True),
        velocity=ExposureVelocities(vel, "map"),
    )  # fmt: skip
    assert res.dropped  # the selection re-adjusted
    t = res.timing
    assert abs(t["dt_s"] - DT) < 3 * t["dt_std_s"], t
