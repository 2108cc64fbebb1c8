"""Plane fit (Pathak weighted eigen method) and its covariance against Monte Carlo, plane table."""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.geometry.planes import fit_plane
from lidarphoto.core.io.planes import COV_COLUMNS, PLANE_COLUMNS, read_planes_csv, write_planes_csv
from scipy.stats import chi2

ORIGIN = np.array([85000.0, 447000.0, 10.0])  # RD New-like map coordinates


def _plane_points(rng, normal, n=150, half=5.0, centre=ORIGIN):
    """Noise-free points (n, 3) on the plane through ``centre`` with unit ``normal``."""
    u = np.cross(normal, [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    st = rng.uniform(-half, half, (n, 2))
    return centre + st[:, :1] * u + st[:, 1:] * v


def _unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def test_exact_plane_slope_aspect_and_orientation():
    # z = 5 - 0.5 (x - x0): rises to the west, so it drains east (aspect 90 deg), 26.57 deg slope
    rng = np.random.default_rng(0)
    xy = rng.uniform(0, 20, (50, 2)) + ORIGIN[:2]
    z = 5.0 - 0.5 * (xy[:, 0] - ORIGIN[0])
    p = fit_plane(np.column_stack([xy, z]))
    np.testing.assert_allclose(p.normal, _unit([0.5, 0.0, 1.0]), atol=1e-12)
    assert p.normal[2] > 0
    assert p.slope_deg == pytest.approx(np.degrees(np.arctan(0.5)), abs=1e-9)
    assert p.aspect_deg == pytest.approx(90.0, abs=1e-9)
    assert p.rms < 1e-9 and p.sigma_d < 1e-6
    assert np.abs(p.distance(np.column_stack([xy, z]))).max() < 1e-8
    # n.p + d = 0 with the absolute map coordinates
    assert abs(p.normal @ np.array([*xy[0], z[0]]) + p.d) < 1e-7


def test_large_coordinates_do_not_cost_digits():
    rng = np.random.default_rng(1)
    n0 = _unit([0.2, -0.3, 1.0])
    local = _plane_points(rng, n0, centre=np.zeros(3)) + rng.normal(0, 0.02, (150, 3))
    far = local + np.array([6.0e5, 5.2e6, 300.0])  # UTM-sized
    a, b = fit_plane(local), fit_plane(far)
    np.testing.assert_allclose(a.normal, b.normal, atol=1e-9)
    assert a.rms == pytest.approx(b.rms, rel=1e-6)
    # the offset at the centroid (independent of the origin) agrees; d moves by -n.shift
    assert b.d == pytest.approx(a.d - b.normal @ np.array([6.0e5, 5.2e6, 300.0]), abs=1e-6)
    np.testing.assert_allclose(a.covariance[:3, :3], b.covariance[:3, :3], rtol=1e-5, atol=1e-14)


def test_weights_equal_repeated_points():
    rng = np.random.default_rng(2)
    pts = _plane_points(rng, _unit([0.1, 0.4, 1.0]), n=40) + rng.normal(0, 0.03, (40, 3))
    w = rng.integers(1, 4, 40)
    a = fit_plane(pts, weights=w)
    b = fit_plane(np.repeat(pts, w, axis=0))
    np.testing.assert_allclose(a.normal, b.normal, atol=1e-12)
    np.testing.assert_allclose(a.centroid, b.centroid, atol=1e-9)
    assert a.rms == pytest.approx(b.rms, rel=1e-9)


def test_covariance_is_rank_three_and_orthogonal_to_the_normal():
    rng = np.random.default_rng(3)
    pts = _plane_points(rng, _unit([0.3, 0.1, 1.0])) + rng.normal(0, 0.05, (150, 3))
    p = fit_plane(pts)
    np.testing.assert_allclose(p.covariance, p.covariance.T)
    assert (
        np.abs(p.covariance @ np.append(p.normal, 0.0)).max() < 1e-12 * np.abs(p.covariance).max()
    )
    assert np.all(np.linalg.eigvalsh(p.covariance)[1:] > 0)
    assert p.sigma_d == pytest.approx(np.sqrt(p.covariance[3, 3]))
    # Khoshelham: var(d) = m' C_nn m + sigma0^2 / n
    m = p.centroid
    sigma0_sq = p.rms**2 * len(pts) / (len(pts) - 3)
    assert p.sigma_d**2 == pytest.approx(m @ p.covariance[:3, :3] @ m + sigma0_sq / len(pts))


@pytest.mark.parametrize("weighted", [False, True])
def test_covariance_and_sigma_d_match_monte_carlo(weighted):
    """Reported covariance vs scatter over R noise draws of the same points (known truth).

    Normalised errors: z_d = (d - d_true) / sigma_d ~ N(0, 1), so sum z_d^2 ~ chi2(R); the
    normal's error in the tangent plane, with the reported 2x2 covariance, gives a Mahalanobis
    distance ~ chi2(2), summed ~ chi2(2R). Bounds: two-sided 99.9 %. Also the variance ratio
    empirical / mean reported for d, with chi2(R - 1) bounds.
    """
    rng = np.random.default_rng(10 + weighted)
    n0 = _unit([0.35, -0.2, 1.0])
    base = _plane_points(rng, n0, n=120, half=6.0)
    d_true = -n0 @ ORIGIN
    sig = rng.uniform(0.02, 0.08, len(base)) if weighted else np.full(len(base), 0.05)
    w = 1.0 / sig**2 if weighted else None
    u = _unit(np.cross(n0, [1.0, 0.0, 0.0]))
    v = np.cross(n0, u)
    tangent = np.column_stack([u, v])  # (3, 2)
    r = 600
    z_d, maha, d_est, var_d = [], [], [], []
    for _ in range(r):
        # noise along the normal with the per-point sigma (plus isotropic in-plane jitter)
        pts = base + rng.normal(0, 1, len(base))[:, None] * sig[:, None] * n0
        pts += rng.normal(0, 0.05, (len(base), 2)) @ tangent.T
        p = fit_plane(pts, w)
        z_d.append((p.d - d_true) / p.sigma_d)
        e = tangent.T @ (p.normal - n0)
        c2 = tangent.T @ p.covariance[:3, :3] @ tangent
        maha.append(e @ np.linalg.solve(c2, e))
        d_est.append(p.d)
        var_d.append(p.sigma_d**2)
    s_d = float(np.sum(np.square(z_d)))
    assert chi2.ppf(0.0005, r) < s_d < chi2.ppf(0.9995, r), s_d / r
    s_n = float(np.sum(maha))
    assert chi2.ppf(0.0005, 2 * r) < s_n < chi2.ppf(0.9995, 2 * r), s_n / (2 * r)
    ratio = np.var(d_est, ddof=1) / np.mean(var_d)
    lo, hi = chi2.ppf([0.0005, 0.9995], r - 1) / (r - 1)
    assert lo < ratio < hi, ratio


def test_bad_input():
    with pytest.raises(InputError, match="at least 3"):
        fit_plane([[0, 0, 0], [1, 0, 0]])
    with pytest.raises(InputError, match="collinear"):
        fit_plane([[0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 3, 3.0]])
    with pytest.raises(InputError, match="NaN"):
        fit_plane([[0, 0, 0], [1, 0, 0], [0, 1, np.nan]])
    with pytest.raises(InputError, match="weights"):
        fit_plane([[0, 0, 0], [1, 0, 0], [0, 1, 0]], weights=[1, 0, 1])
    with pytest.raises(InputError, match="shape"):
        fit_plane(np.zeros((5, 2)))


def test_plane_table_round_trip(tmp_path):
    rng = np.random.default_rng(4)
    planes = [
        fit_plane(_plane_points(rng, _unit(n)) + rng.normal(0, 0.03, (150, 3)), plane_id=k)
        for k, n in enumerate(([0.1, 0.2, 1.0], [0.0, 0.0, 1.0], [-0.6, 0.3, 1.0]))
    ]
    path = tmp_path / "planes.csv"
    write_planes_csv(path, planes)
    header = path.read_text(encoding="utf-8").splitlines()[0].split(",")
    assert tuple(header) == PLANE_COLUMNS
    assert header[:9] == [
        "id",
        "a",
        "b",
        "c",
        "d",
        "centroid_x",
        "centroid_y",
        "centroid_z",
        "n_points",
    ]  # the paper's list
    assert len(COV_COLUMNS) == 10 and COV_COLUMNS[0] == "cov_aa" and COV_COLUMNS[-1] == "cov_dd"
    back = read_planes_csv(path)
    for a, b in zip(planes, back):
        assert a.id == b.id and a.n_points == b.n_points
        np.testing.assert_array_equal(a.normal, b.normal)  # full round-trip precision
        np.testing.assert_array_equal(a.covariance, b.covariance)
        assert (a.d, a.rms, a.sigma_d, a.slope_deg, a.aspect_deg) == (
            b.d,
            b.rms,
            b.sigma_d,
            b.slope_deg,
            b.aspect_deg,
        )
    # no planes: header only, read back as an empty list
    write_planes_csv(tmp_path / "none.csv", [])
    assert read_planes_csv(tmp_path / "none.csv") == []


def test_plane_table_errors_name_row_and_column(tmp_path):
    rng = np.random.default_rng(5)
    p = fit_plane(_plane_points(rng, _unit([0.1, 0.2, 1.0])) + rng.normal(0, 0.03, (150, 3)))
    path = tmp_path / "p.csv"
    write_planes_csv(path, [p.with_id(0), p.with_id(1)])
    lines = path.read_text(encoding="utf-8").splitlines()
    cells = lines[2].split(",")
    cells[PLANE_COLUMNS.index("sigma_d")] = "abc"
    bad = tmp_path / "bad.csv"
    bad.write_text("\n".join([lines[0], lines[1], ",".join(cells)]) + "\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"row 3.*sigma_d"):
        read_planes_csv(bad)
    dup = tmp_path / "dup.csv"
    dup.write_text("\n".join([lines[0], lines[1], lines[1]]) + "\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"row 3.*id"):
        read_planes_csv(dup)
    missing = tmp_path / "missing.csv"
    missing.write_text(lines[0].replace(",cov_dd", "") + "\n" + lines[1].rsplit(",", 1)[0] + "\n")
    with pytest.raises(InputError, match="cov_dd"):
        read_planes_csv(missing)
    with pytest.raises(InputError, match="not found"):
        read_planes_csv(tmp_path / "nope.csv")
