"""Full precision in every table the adjustments write (issue 37): a millimetre network, its
coordinates carrying sub-micrometre digits and its sigmas about a micrometre, written by the
bundle, resection and EO writers and read back by the project's own readers bit for bit (one
formatter, :func:`core.io.tables.number`: the shortest text that reads back to the double)."""

from __future__ import annotations

from types import SimpleNamespace as Ns

import numpy as np
from lidarphoto.core.io.bundle import write_bundle_points, write_check_points
from lidarphoto.core.io.orientation import read_eo_csv_full, write_eo_csv_with_sigmas
from lidarphoto.core.io.resection import write_eo_sigma_csv
from lidarphoto.core.io.tables import find_column, float_column, normalise, number, read_table
from lidarphoto.core.photo.orientation import ExteriorOrientationTable

N = 40


def _network(seed: int = 3):
    """Coordinates of a UTM-sized millimetre network (every digit of the double used) and
    sigmas of 0.3-3 um; angles in radians, their sigmas about 1e-7 rad."""
    rng = np.random.default_rng(seed)
    xyz = np.column_stack([rng.uniform(4e5, 6e5, N), rng.uniform(5.4e6, 5.6e6, N),
                           rng.uniform(50.0, 900.0, N)])  # fmt: skip
    sigma = rng.uniform(3e-7, 3e-6, (N, 3))
    opk = rng.uniform(-np.pi, np.pi, (N, 3))
    opk[:, 1] /= 2.0  # phi within +-90 degrees
    s_opk = rng.uniform(1e-8, 1e-6, (N, 3))
    return xyz, sigma, opk, s_opk


def _columns(path, names):
    table = read_table(path)
    return np.column_stack(
        [float_column(table, find_column(table, (normalise(n),))) for n in names]
    )


def test_the_formatter_round_trips_every_double():
    rng = np.random.default_rng(0)
    values = np.concatenate([rng.uniform(-1e7, 1e7, 1000), 10.0 ** rng.uniform(-12, 8, 1000),
                             [0.0, -0.0, 5e-324, 1.7976931348623157e308]])  # fmt: skip
    assert all(float(number(v)) == v for v in values)
    assert number(np.nan) == number(np.inf) == ""


def test_bundle_points_and_check_points_read_back_bit_exact(tmp_path):
    xyz, sigma, _, _ = _network()
    ids = tuple(f"P{k}" for k in range(N))
    res = Ns(point_id=ids, point_role=("tie",) * N, point_xyz=xyz, point_sigma=sigma,
             point_images=np.full(N, 3))  # fmt: skip
    write_bundle_points(tmp_path / "points.csv", res)
    back = _columns(tmp_path / "points.csv", ("X", "Y", "Z", "sigma_X", "sigma_Y", "sigma_Z"))
    assert np.array_equal(back, np.hstack([xyz, sigma]))
    check = Ns(point_id=ids, measured=xyz, reference=xyz + 1e-6, sigma=sigma,
               n_images=np.full(N, 2))  # fmt: skip
    write_check_points(tmp_path / "check.csv", [Ns(check=check, ap_model="bauer")])
    names = ("e", "n", "h", "e_ref", "n_ref", "h_ref", "sigma_e", "sigma_n", "sigma_h")
    back = _columns(tmp_path / "check.csv", names)
    assert np.array_equal(back, np.hstack([xyz, xyz + 1e-6, sigma]))


def test_eo_with_sigmas_reads_back_bit_exact(tmp_path):
    """Positions and their sigmas (metres) exactly; the angles and their sigmas exactly as the
    degrees written (one conversion each way: within an ulp of the radians)."""
    xyz, sigma, opk, s_opk = _network()
    times = np.linspace(0.0, 1.0, N) + 1e9 / 3  # GPS seconds with every digit
    eo = ExteriorOrientationTable(tuple(f"I{k}" for k in range(N)), times, ("",) * N, xyz, opk,
                                  "")  # fmt: skip
    write_eo_csv_with_sigmas(tmp_path / "eo.csv", eo, np.hstack([sigma, s_opk]))
    f = read_eo_csv_full(tmp_path / "eo.csv", "")
    assert np.array_equal(f.eo.xyz, xyz) and np.array_equal(f.sigma[:, :3], sigma)
    assert np.array_equal(f.eo.time, eo.time)
    deg = _columns(tmp_path / "eo.csv", ("omega_deg", "phi_deg", "kappa_deg"))
    assert np.array_equal(deg, np.degrees(opk))
    s_deg = _columns(tmp_path / "eo.csv", ("sigma_omega_deg", "sigma_phi_deg", "sigma_kappa_deg"))
    assert np.array_equal(s_deg, np.degrees(s_opk))
    np.testing.assert_allclose(f.eo.opk, opk, rtol=4e-16, atol=0)


def test_resection_eo_reads_back_bit_exact(tmp_path):
    xyz, sigma, opk, s_opk = _network()
    rows = [(f"I{k}", 12.5, "", *xyz[k], *opk[k], *sigma[k], *s_opk[k], 1.0, 10, 9.5, 18.3, True,
             8, 0, 0, "points", "given") for k in range(N)]  # fmt: skip
    write_eo_sigma_csv(tmp_path / "eo.csv", rows)
    back = _columns(tmp_path / "eo.csv", ("X", "Y", "Z", "sigma_X", "sigma_Y", "sigma_Z"))
    assert np.array_equal(back, np.hstack([xyz, sigma]))
    s_deg = _columns(tmp_path / "eo.csv", ("sigma_omega_deg", "sigma_phi_deg", "sigma_kappa_deg"))
    assert np.array_equal(s_deg, np.degrees(s_opk))
