"""Terrestrial laser scanner self-calibration against simulated truth (core.tls).

The observations come from core.simulation.tls, which writes the polar model and the AP
corrections out on its own (not through core.tls), so a wrong sign, unit or term in the
adjustment's model fails these tests.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.simulation.tls import (
    PAPER_APS,
    SCANNER_CLASSES,
    observe,
    paper_cube,
    room_network,
)
from lidarphoto.core.tls.aps import AP_SETS, ap_terms
from lidarphoto.core.tls.calibration import CalibrationOptions, _PolarModel, calibrate
from lidarphoto.core.tls.network import TlsObservations, check_network
from lidarphoto.core.tls.polar import polar_covariance, polar_to_cartesian
from numdiff import central_difference

FREE = CalibrationOptions(levelled=False)  # the paper's stations: six free EOPs each


def _truth_vector(names):
    return np.array([PAPER_APS[n] for n in names])


# ----------------------------------------------------------------------------- the model


def test_polar_jacobian_matches_finite_differences():
    """The analytic Jacobian of the observation model (APs, pose, target; both faces, every
    AP of the extended set) against central differences."""
    names = AP_SETS["extended"]
    rng = np.random.default_rng(1)
    k = len(names)
    for face in (False, True):
        ap = rng.normal(0, 1e-4, k)
        pose = np.array([1.0, -2.0, 0.5, 0.02, -0.03, 0.7])
        xyz = np.array([6.0, 3.0, 2.5])
        model = _PolarModel(names, np.array([face]), np.zeros((1, 3)), 1.2)
        x = np.concatenate([ap, pose, xyz])
        _, jac = model(x[None])
        steps = [1e-6] * k + [1e-6] * 3 + [1e-7] * 3 + [1e-6] * 3
        num = central_difference(lambda z, m=model: m(z[None])[0], x, steps)
        np.testing.assert_allclose(jac[0], num[0], rtol=1e-6, atol=1e-7)


def test_scanner_xyz_covariance_propagates_to_polar_form():
    """x, y, z target centres with a covariance become polar observations whose covariance,
    drawn back through the exact transformation, matches the original to first order."""
    rng = np.random.default_rng(2)
    d = np.array([[8.0, -3.0, 2.0]])
    cov = np.diag([1e-6, 4e-6, 2.25e-6])[None]
    polar, pcov = polar_covariance(d, cov)
    samples = rng.multivariate_normal(polar[0], pcov[0], size=20000)
    back = polar_to_cartesian(samples)
    np.testing.assert_allclose(np.cov(back.T), cov[0], rtol=0.05, atol=2e-8)


# ----------------------------------------------------------------------------- paper's cube


@pytest.mark.parametrize("datum", ["control", "inner", "reference"])
def test_paper_cube_without_noise_recovers_the_inserted_aps(datum):
    """Carvalho, Correa & dos Santos' cube (144 targets, 3 stations, a0 2 mm, b1 5", b2 4",
    c0 3"), no noise: the APs come back to numerical precision (the paper got b1 1.7" and
    c0 0.1"), and so do the station poses, whatever the datum."""
    t = paper_cube()
    obs, _ = observe(t, exact=True)
    control = t.control() if datum == "control" else ()
    opts = CalibrationOptions(levelled=False, datum="inner" if datum == "control" else datum)
    cal = calibrate(obs, control, t.station_info(with_pose=datum == "reference"), opts)
    assert cal.ap_names == ("a0", "b1", "b2", "c0")
    np.testing.assert_allclose(cal.ap, _truth_vector(cal.ap_names), rtol=0, atol=1e-10)
    if datum != "inner":  # the inner datum keeps the registration's frame, not the truth's
        np.testing.assert_allclose(cal.pose[:, :3], t.poses[:, :3], atol=1e-8)
        np.testing.assert_allclose(cal.pose[:, 3:], t.poses[:, 3:], atol=1e-10)
    assert cal.sigma0 < 1e-6


def test_paper_cube_monte_carlo_matches_the_cramer_rao_bound():
    """High-end scanner noise (1.2 mm, 8"): over 120 draws the RMSE of each AP about the
    inserted value is within 20 % of its a-priori sigma (the network's Cramer-Rao bound; the
    RMSE of 120 draws scatters by 6.5 %, so 20 % is 3 of its sigmas; bench/tls.md reaches
    10 % with 1000 draws), and the bias is below 0.3 sigma."""
    t = paper_cube()
    sig = SCANNER_CLASSES["high_end"]
    opts = CalibrationOptions(levelled=False, snooping=False)
    est, std = [], None
    for i in range(120):
        obs, _ = observe(t, *sig, rng=1000 + i)
        cal = calibrate(obs, t.control(), t.station_info(), opts)
        est.append(cal.ap)
        std = cal.ap_std_prior
    err = np.array(est) - _truth_vector(cal.ap_names)
    ratio = np.sqrt(np.mean(err**2, axis=0)) / std
    assert np.all(np.abs(ratio - 1) < 0.2), ratio
    assert np.all(np.abs(err.mean(axis=0)) / std < 0.3)


def test_blunders_are_rejected_by_data_snooping():
    t = paper_cube()
    obs, bad = observe(t, *SCANNER_CLASSES["high_end"], rng=5, blunders=4)
    cal = calibrate(obs, t.control(), t.station_info(), FREE)
    assert set(np.flatnonzero(cal.rejected)) >= set(bad.tolist())
    assert cal.rejected.sum() <= bad.size + 3
    np.testing.assert_allclose(cal.ap, _truth_vector(cal.ap_names), atol=4 * cal.ap_std.max())


# ----------------------------------------------------------------------------- the room


def _max_corr(cal, ap: str, tails: tuple[str, ...]) -> float:
    i = cal.calib_names.index(ap)
    cols = [j for j, n in enumerate(cal.calib_names) if n.rsplit(".", 1)[-1] in tails]
    return float(np.max(np.abs(cal.calib_correlation[i, cols])))


def test_tilted_stations_decorrelate_the_aps_from_the_station_parameters():
    """Lichti (2010): stations rolled by 90 degrees break the correlation of b1 with kappa
    and of c0 with the station heights, and shrink the sigmas of b1, b2, c0 (measured: b1-kappa
    0.99 -> 0.87, c0-Z 0.87 -> 0.35; sigma b1 7.7" -> 1.6", b2 2.9" -> 0.8", c0 6.1" -> 1.3")."""
    out = {}
    for tilted in (False, True):
        t = room_network(tilted=tilted)
        obs, _ = observe(t, *SCANNER_CLASSES["high_end"], rng=5)
        out[tilted] = calibrate(obs, (), t.station_info(), CalibrationOptions())
    flat, tilt = out[False], out[True]
    assert _max_corr(flat, "b1", ("kappa",)) > 0.98
    assert _max_corr(tilt, "b1", ("kappa",)) < 0.92
    assert _max_corr(flat, "c0", ("Z",)) > 0.8
    assert _max_corr(tilt, "c0", ("Z",)) < 0.5
    # the report names the pair: b1 with a station's kappa
    assert any("b1" in p[:2] and any(str(q).endswith(".kappa") for q in p[:2])
               for p in flat.strong_pairs), flat.strong_pairs  # fmt: skip
    ratio = tilt.ap_std_prior[1:] / flat.ap_std_prior[1:]  # b1, b2, c0
    assert np.all(ratio < 0.4), ratio
    # and the estimates are right within their sigmas
    err = (tilt.ap - _truth_vector(tilt.ap_names)) / tilt.ap_std
    assert np.all(np.abs(err) < 4), err


def test_automatic_selection_keeps_the_inserted_terms():
    """From Lichti's extended set, with the paper's four APs inserted, backward elimination
    keeps a0, b1, b2 and one vertical-index term (c0, or c3 = cos(alpha), which equals c0
    near the horizon), and drops a1 (the scale of a network without control)."""
    t = room_network()
    obs, _ = observe(t, *SCANNER_CLASSES["high_end"], rng=5)
    cal = calibrate(obs, (), t.station_info(), CalibrationOptions(ap_set="extended",
                                                                  select_aps=True))  # fmt: skip
    kept = set(cal.ap_names)
    assert {"a0", "b1", "b2"} <= kept
    assert kept & {"c0", "c3"}
    assert len(kept) <= 5
    assert "a1" in {s.removed for s in cal.selection}


def test_a1_without_control_is_not_observable_with_a_diagnosis():
    from lidarphoto.core.tls.calibration import TlsNotObservable

    t = room_network()
    obs, _ = observe(t, *SCANNER_CLASSES["high_end"], rng=5)
    with pytest.raises(TlsNotObservable) as exc:
        calibrate(obs, (), t.station_info(), CalibrationOptions(ap_set="a0,a1,b1"))
    assert "a1" in exc.value.parameters
    assert "control" in " ".join(exc.value.diagnosis)


def test_a1_with_control_is_recovered():
    """With the targets as control (1 mm), the range scale error is determined."""
    aps = dict(PAPER_APS, a1=50e-6)
    t = room_network(aps=aps)
    obs, _ = observe(t, *SCANNER_CLASSES["high_end"], rng=6)
    cal = calibrate(obs, t.control(sigma=0.001), t.station_info(),
                    CalibrationOptions(ap_set="a0,a1,b1,b2,c0"))  # fmt: skip
    truth = np.array([aps[n] for n in cal.ap_names])
    assert np.all(np.abs(cal.ap - truth) < 4 * cal.ap_std)


def test_two_faces_separate_the_index_error_from_the_tilts():
    """Face II readings (theta + pi, pi - alpha) flip the sign of b1 and c0 relative to the
    geometry: both become much better determined than in face I alone."""
    t = paper_cube()
    one, _ = observe(t, *SCANNER_CLASSES["high_end"], rng=8)
    two, _ = observe(t, *SCANNER_CLASSES["high_end"], rng=8, two_faces=True)
    c1 = calibrate(one, (), t.station_info(), FREE)
    c2 = calibrate(two, (), t.station_info(), FREE)
    assert c2.ap_std_prior[3] < 0.3 * c1.ap_std_prior[3]  # c0
    err = (c2.ap - _truth_vector(c2.ap_names)) / c2.ap_std
    assert np.all(np.abs(err) < 4), err


# ----------------------------------------------------------------------------- bad networks


def test_tilted_station_flagged_levelled_is_refused():
    """The room's two stations rolled by 90 degrees, all taken as levelled (the option's
    default, no stations table): refused, naming the station, instead of letting the
    compensator pull it to a wrong orientation."""
    t = room_network()
    obs, _ = observe(t, *SCANNER_CLASSES["high_end"], rng=5)
    with pytest.raises(InputError, match=r"row \d+: station 'S5' is taken as levelled .* "
                       r"place it at omega, phi = -?89.99"):  # fmt: skip
        calibrate(obs, (), (), CalibrationOptions(levelled=True))


def _obs(rows):
    st, tg, p = zip(*[(r[0], r[1], r[2:]) for r in rows])
    n = len(rows)
    return TlsObservations(st, tg, np.array(p, dtype=float), np.tile(np.eye(3) * 1e-6, (n, 1, 1)),
                           np.arange(2, n + 2), "obs.csv")  # fmt: skip


def test_target_seen_by_one_station_only_is_refused_with_its_row():
    rows = [("A", f"T{i}", 5.0, 0.5 * i, 0.1) for i in range(4)]
    rows += [("B", f"T{i}", 5.0, 0.5 * i + 0.2, 0.1) for i in range(3)]
    with pytest.raises(InputError, match=r"obs.csv, row 5: target 'T3' is seen by station 'A'"):
        check_network(_obs(rows))


def test_station_with_fewer_than_three_targets_is_refused_with_its_row():
    rows = [("A", f"T{i}", 5.0, 0.5 * i, 0.1) for i in range(3)]
    rows += [("B", f"T{i}", 5.0, 0.5 * i + 0.2, 0.1) for i in range(2)]
    rows += [("C", "T2", 5.0, 1.0, 0.1)]
    with pytest.raises(InputError, match=r"obs.csv, row 5: station 'B' observes 2 target"):
        check_network(_obs(rows))


def test_ap_names_are_checked():
    assert ap_terms("a0, c0") == ("a0", "c0")
    with pytest.raises(InputError, match="unknown additional parameter"):
        ap_terms("a0,z9")


def test_zenith_observation_is_refused():
    rows = [("A", f"T{i}", 5.0, 0.5 * i, 0.1) for i in range(3)]
    rows += [("B", f"T{i}", 5.0, 0.5 * i, math.radians(89.8)) for i in range(3)]
    with pytest.raises(InputError, match=r"row 5: vertical angle .* zenith"):
        check_network(_obs(rows))
