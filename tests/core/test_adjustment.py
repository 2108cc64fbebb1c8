"""Least-squares engine: closed forms, independent solvers, Monte Carlo, datum, snooping, speed.

Every expected value is computed independently (closed forms, numpy/scipy solvers, an SVD);
tolerances follow from the problem (rounding of well-conditioned problems, chi-square bounds
for random quantities), never from what the engine happens to return.
"""

from __future__ import annotations

import time

import numpy as np
import pytest
from lidarphoto.core.errors import AdjustmentError, Cancelled, InputError, NotObservableError
from lidarphoto.core.lsq import observability, solve
from lidarphoto.core.lsq.adjustment import adjust
from lidarphoto.core.lsq.model import (
    AdjustmentOptions,
    Constraint,
    GaussHelmertBlock,
    GaussMarkovBlock,
    prior_block,
)
from scipy import optimize, stats

# ----------------------------------------------------------------------------- helpers


def line_block(
    t: np.ndarray,
    y: np.ndarray,
    sigma: np.ndarray,
    name: str = "y",
    index: tuple[int, int] = (0, 1),
) -> GaussMarkovBlock:
    """y = a + b t, one row per group, parameters (a, b) at ``index``."""
    design = np.stack([np.ones_like(t), t], axis=1)

    def model(xl: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return (xl[:, 0] + xl[:, 1] * t)[:, None], design[:, None, :]

    return GaussMarkovBlock(
        name=name,
        observed=y[:, None],
        sigma=np.broadcast_to(sigma, t.shape)[:, None],
        param_index=np.tile(np.asarray(index), (t.size, 1)),
        model=model,
        labels=[f"{name} {i}" for i in range(t.size)],
    )


def distance_block(
    stations: np.ndarray, point_of: np.ndarray, observed: np.ndarray, sigma: float
) -> GaussMarkovBlock:
    """Distances from known 2D stations to unknown points (x_p, y_p) at 2p, 2p + 1."""

    def model(xl: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d = xl - stations
        r = np.hypot(d[:, 0], d[:, 1])
        return r[:, None], (d / r[:, None])[:, None, :]

    idx = np.stack([2 * point_of, 2 * point_of + 1], axis=1)
    return GaussMarkovBlock(
        "dist", observed[:, None], np.full((observed.size, 1), sigma), idx, model
    )


def polar_network(
    n_points: int,
    n_groups: int,
    seed: int,
    sigma_d: float = 0.005,
    sigma_a: float = 2e-5,
    noisy: bool = True,
):
    """Distance + azimuth (2 rows per group) between near neighbours of a random 2D network.

    Returns truth (2 n_points,), blocks with a datum prior on point 0 and the approximate values.
    """
    rng = np.random.default_rng(seed)
    side = 50.0 * np.sqrt(n_points)
    truth_xy = rng.uniform(0, side, (n_points, 2))
    i = rng.integers(0, n_points, n_groups)
    # Neighbours in the index order of points sorted along x: a sparse, banded-like graph.
    order = np.argsort(truth_xy[:, 0])
    rank = np.empty(n_points, dtype=int)
    rank[order] = np.arange(n_points)
    off = rng.integers(1, 6, n_groups) * rng.choice([-1, 1], n_groups)
    j = order[np.clip(rank[i] + off, 0, n_points - 1)]
    same = i == j
    j[same] = order[np.where(rank[i[same]] > 0, rank[i[same]] - 1, 1)]
    d = truth_xy[j] - truth_xy[i]
    dist = np.hypot(d[:, 0], d[:, 1])
    azi = np.arctan2(d[:, 0], d[:, 1])
    sig = np.array([sigma_d, sigma_a])
    obs = np.stack([dist, azi], axis=1)
    if noisy:
        obs = obs + rng.normal(0, 1, obs.shape) * sig

    def model(xl: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        dx = xl[:, 2] - xl[:, 0]
        dy = xl[:, 3] - xl[:, 1]
        r2 = dx * dx + dy * dy
        r = np.sqrt(r2)
        # The azimuth is returned on the branch of its observation (no 2 pi jumps in f - l).
        az = obs[:, 1] + np.angle(np.exp(1j * (np.arctan2(dx, dy) - obs[:, 1])))
        f = np.stack([r, az], axis=1)
        J = np.zeros((xl.shape[0], 2, 4))
        J[:, 0] = np.stack([-dx / r, -dy / r, dx / r, dy / r], axis=1)
        J[:, 1] = np.stack([-dy / r2, dx / r2, dy / r2, -dx / r2], axis=1)
        return f, J

    idx = np.stack([2 * i, 2 * i + 1, 2 * j, 2 * j + 1], axis=1)
    block = GaussMarkovBlock(
        "polar", obs, np.broadcast_to(sig, obs.shape), idx, model, row_names=("dist", "azimuth")
    )
    datum = prior_block("datum", [0, 1], truth_xy[0], 1e-3)
    x0 = (truth_xy + rng.normal(0, 0.3, truth_xy.shape)).ravel()
    names = [f"{c}{p}" for p in range(n_points) for c in "xy"]
    return truth_xy.ravel(), [block, datum], x0, names


def chi2_ratio_bounds(dof: int, p: float) -> tuple[float, float]:
    """Two-sided bounds of s^2 / sigma^2 for a sample variance with ``dof`` degrees of freedom."""
    return stats.chi2.ppf(p / 2, dof) / dof, stats.chi2.ppf(1 - p / 2, dof) / dof


# ----------------------------------------------------------------------------- 1. linear


def test_linear_regression_matches_closed_form_and_lstsq():
    rng = np.random.default_rng(1)
    t = np.linspace(-5.0, 12.0, 40)
    sigma = rng.uniform(0.01, 0.05, t.size)
    y = 2.0 + 0.5 * t + rng.normal(0, sigma)
    res = adjust([0.0, 0.0], ["a", "b"], [line_block(t, y, sigma)])

    A = np.stack([np.ones_like(t), t], axis=1)
    P = np.diag(sigma**-2)
    Q = np.linalg.inv(A.T @ P @ A)
    x = Q @ A.T @ P @ y
    x_lstsq = np.linalg.lstsq(A / sigma[:, None], y / sigma, rcond=None)[0]
    v = A @ x - y
    omega = v @ P @ v
    r = t.size - 2

    assert res.converged
    np.testing.assert_allclose(res.x, x, rtol=0, atol=1e-10)
    np.testing.assert_allclose(res.x, x_lstsq, rtol=0, atol=1e-10)
    np.testing.assert_allclose(res.cofactor, Q, rtol=1e-10, atol=0)
    assert res.redundancy == r
    assert res.omega == pytest.approx(omega, rel=1e-10)
    assert res.global_test.statistic == pytest.approx(omega, rel=1e-10)
    assert res.global_test.dof == r
    assert res.sigma0 == pytest.approx(np.sqrt(omega / r), rel=1e-10)
    np.testing.assert_allclose(res.covariance, omega / r * Q, rtol=1e-10)
    np.testing.assert_allclose(res.std, np.sqrt(np.diag(omega / r * Q)), rtol=1e-10)
    assert res.parameter("b") == pytest.approx((x[1], np.sqrt(omega / r * Q[1, 1])), rel=1e-10)

    table = res.residuals["y"]
    np.testing.assert_allclose(table.v[:, 0], v, rtol=0, atol=1e-12)
    Qvv = np.diag(sigma**2) - A @ Q @ A.T
    np.testing.assert_allclose(table.redundancy_numbers[:, 0], np.diag(Qvv @ P), rtol=1e-9)
    assert table.redundancy_numbers.sum() == pytest.approx(r, rel=1e-10)
    np.testing.assert_allclose(table.w[:, 0], v / np.sqrt(np.diag(Qvv)), rtol=1e-9)
    lo, hi = stats.chi2.ppf([0.025, 0.975], r)
    assert res.global_test.lower == pytest.approx(lo) and res.global_test.upper == pytest.approx(hi)
    assert res.global_test.passed == bool(lo <= omega <= hi)
    text = res.summary()
    assert "sigma0" in text and "chi-square" in text and "b" in text


def test_sigma0_prior_scales_test_and_prior_covariance():
    rng = np.random.default_rng(2)
    t = np.linspace(0, 1, 25)
    y = 1.0 - 3.0 * t + rng.normal(0, 0.02, t.size)
    base = adjust([0, 0], ["a", "b"], [line_block(t, y, np.full(t.size, 0.02))])
    scaled = adjust(
        [0, 0],
        ["a", "b"],
        [line_block(t, y, np.full(t.size, 0.02))],
        options=AdjustmentOptions(sigma0_prior=2.0),
    )
    assert scaled.global_test.statistic == pytest.approx(base.omega / 4.0, rel=1e-12)
    np.testing.assert_allclose(scaled.covariance_prior, 4.0 * base.cofactor, rtol=1e-12)
    np.testing.assert_allclose(scaled.covariance, base.covariance, rtol=1e-12)


# ----------------------------------------------------------------------------- 2. non-linear


def trilateration_problem(seed: int, sigma: float = 0.01):
    rng = np.random.default_rng(seed)
    stations = np.array([[0.0, 0.0], [100.0, 0.0], [100.0, 80.0], [0.0, 90.0], [50.0, -40.0]])
    points = np.array([[30.0, 40.0], [70.0, 20.0], [55.0, 60.0]])
    st = np.repeat(stations, len(points), axis=0)
    pt = np.tile(np.arange(len(points)), len(stations))
    true_d = np.hypot(*(points[pt] - st).T)
    obs = true_d + rng.normal(0, sigma, true_d.size)
    x0 = (points + rng.normal(0, 2.0, points.shape)).ravel()
    names = [f"{c}{p}" for p in range(len(points)) for c in "xy"]
    return stations, st, pt, obs, x0, names, points.ravel()


def test_nonlinear_trilateration_matches_scipy_least_squares():
    _, st, pt, obs, x0, names, _ = trilateration_problem(3)
    sigma = 0.01
    res = adjust(x0, names, [distance_block(st, pt, obs, sigma)])

    def fun(x):
        p = x.reshape(-1, 2)[pt]
        return (np.hypot(*(p - st).T) - obs) / sigma

    ref = optimize.least_squares(fun, x0, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15)
    assert res.converged
    np.testing.assert_allclose(res.x, ref.x, rtol=0, atol=1e-8)
    # Cofactor from the analytic Jacobian at scipy's solution (its own jac is by differences).
    J = np.zeros((obs.size, x0.size))
    d = ref.x.reshape(-1, 2)[pt] - st
    u = d / np.hypot(d[:, 0], d[:, 1])[:, None] / sigma
    J[np.arange(obs.size), 2 * pt] = u[:, 0]
    J[np.arange(obs.size), 2 * pt + 1] = u[:, 1]
    Q = np.linalg.inv(J.T @ J)
    np.testing.assert_allclose(res.cofactor, Q, rtol=1e-7, atol=1e-9 * np.abs(Q).max())
    assert res.omega == pytest.approx(2 * ref.cost, rel=1e-9)

    dense = adjust(
        x0, names, [distance_block(st, pt, obs, sigma)], options=AdjustmentOptions(sparse=False)
    )
    sparse = adjust(
        x0, names, [distance_block(st, pt, obs, sigma)], options=AdjustmentOptions(sparse=True)
    )
    assert dense.solver == "dense" and sparse.solver == "sparse"
    np.testing.assert_allclose(sparse.x, dense.x, rtol=0, atol=1e-10)
    np.testing.assert_allclose(sparse.cofactor, dense.cofactor, rtol=1e-10, atol=1e-16)


def test_plain_gauss_newton_and_damped_agree_from_a_poor_start():
    _, st, pt, obs, x0, names, _ = trilateration_problem(4)
    far = x0 + np.array([15.0, -12.0, 10.0, 14.0, -9.0, 11.0])
    gn = adjust(
        far, names, [distance_block(st, pt, obs, 0.01)], options=AdjustmentOptions(damping=False)
    )
    lm = adjust(far, names, [distance_block(st, pt, obs, 0.01)])
    assert gn.converged and lm.converged
    np.testing.assert_allclose(gn.x, lm.x, rtol=0, atol=1e-8)


# ----------------------------------------------------------------------------- 3. Monte Carlo


def test_monte_carlo_covariance_and_global_test():
    draws = 300
    sigma = 0.01
    _, st, pt, _, _, names, truth = trilateration_problem(5, sigma)
    true_d = np.hypot(*(truth.reshape(-1, 2)[pt] - st).T)
    rng = np.random.default_rng(55)
    est = np.empty((draws, truth.size))
    statistic = np.empty(draws)
    ref = adjust(truth, names, [distance_block(st, pt, true_d, sigma)])
    for k in range(draws):
        obs = true_d + rng.normal(0, sigma, true_d.size)
        res = adjust(
            truth + rng.normal(0, 0.5, truth.size), names, [distance_block(st, pt, obs, sigma)]
        )
        assert res.converged
        est[k] = res.x
        statistic[k] = res.global_test.statistic
    cov_emp = np.cov(est, rowvar=False)
    cov_rep = ref.covariance_prior
    # Each sample variance ratio is chi2(draws-1)/(draws-1); Bonferroni over the parameters.
    lo, hi = chi2_ratio_bounds(draws - 1, 0.001 / truth.size)
    ratio = np.diag(cov_emp) / np.diag(cov_rep)
    assert np.all((ratio > lo) & (ratio < hi)), ratio
    # Correlations: Fisher z is normal with standard deviation 1/sqrt(draws - 3).
    iu = np.triu_indices(truth.size, 1)
    r_emp = (cov_emp / np.sqrt(np.outer(np.diag(cov_emp), np.diag(cov_emp))))[iu]
    r_rep = ref.correlation[iu]
    zcrit = stats.norm.ppf(1 - 0.0005 / r_emp.size)
    assert np.all(np.abs(np.arctanh(r_emp) - np.arctanh(r_rep)) * np.sqrt(draws - 3) < zcrit)
    # The sum of the statistics is chi2(draws * r).
    r = ref.redundancy
    total_lo, total_hi = stats.chi2.ppf([0.0005, 0.9995], draws * r)
    assert total_lo < statistic.sum() < total_hi
    assert abs(statistic.mean() - r) < 0.2 * r
    # Unbiased to well within the precision of the mean (non-linearity is ~1e-6 m here).
    bias = est.mean(axis=0) - truth
    assert np.all(np.abs(bias) < 4.5 * np.sqrt(np.diag(cov_rep) / draws))


# ----------------------------------------------------------------------------- 4. Gauss-Helmert


def line_condition(xl: np.ndarray, lhat: np.ndarray):
    """Line n . p = d with n = (cos th, sin th); parameters (th, d); observations (x, y)."""
    th, d = xl[:, 0], xl[:, 1]
    c, s = np.cos(th), np.sin(th)
    g = (lhat[:, 0] * c + lhat[:, 1] * s - d)[:, None]
    A = np.stack([-lhat[:, 0] * s + lhat[:, 1] * c, -np.ones_like(th)], axis=1)[:, None, :]
    B = np.stack([c, s], axis=1)[:, None, :]
    return g, A, B


def test_gauss_helmert_line_equals_total_least_squares():
    rng = np.random.default_rng(6)
    u = np.linspace(0, 50, 35)
    truth = np.stack([3.0 + 0.8 * u, -2.0 + 0.6 * u], axis=1)
    sigma = 0.05
    pts = truth + rng.normal(0, sigma, truth.shape)
    # Independent solution: the normal is the right singular vector of the smallest value.
    centroid = pts.mean(axis=0)
    _, sv, vt = np.linalg.svd(pts - centroid)
    normal = vt[-1]
    d_tls = normal @ centroid
    # Start from the ordinary regression y(x), rotated into (theta, d).
    slope, icpt = np.polyfit(pts[:, 0], pts[:, 1], 1)
    th0 = np.arctan2(1.0, -slope)
    x0 = [th0, icpt * np.sin(th0)]
    block = GaussHelmertBlock(
        "pts",
        pts,
        np.full(pts.shape, sigma),
        np.tile([0, 1], (len(pts), 1)),
        line_condition,
        row_names=("x", "y"),
    )
    res = adjust(x0, ["theta", "d"], [block])
    n_hat = np.array([np.cos(res.x[0]), np.sin(res.x[0])])
    sign = np.sign(n_hat @ normal)
    assert res.converged
    np.testing.assert_allclose(n_hat, sign * normal, rtol=0, atol=1e-9)
    assert res.x[1] == pytest.approx(sign * d_tls, abs=1e-9)
    # v'Pv is the sum of squared orthogonal distances over sigma^2 = smallest sv^2 / sigma^2.
    assert res.omega == pytest.approx(sv[-1] ** 2 / sigma**2, rel=1e-9)
    assert res.redundancy == len(pts) - 2
    v = res.residuals["pts"].v
    adjusted = pts + v
    np.testing.assert_allclose(adjusted @ n_hat - res.x[1], 0.0, atol=1e-9)
    # Residuals are orthogonal to the line: the orthogonal projection of each point.
    np.testing.assert_allclose(v, -np.outer(pts @ n_hat - res.x[1], n_hat), atol=1e-9)


# ----------------------------------------------------------------------------- 5. constraints


def angle_problem(meas: np.ndarray, sigma: np.ndarray):
    block = GaussMarkovBlock(
        "angles",
        meas[:, None],
        sigma[:, None],
        np.arange(3)[:, None],
        lambda xl: (xl.copy(), np.ones((3, 1, 1))),
    )

    def closure(xl):
        return (xl.sum(axis=1) - np.pi)[:, None], np.ones((1, 1, 3))

    return block, Constraint("closure", np.arange(3)[None, :], closure)


@pytest.mark.parametrize("sparse", [False, True])
def test_triangle_closure_constraint_equals_condition_adjustment(sparse):
    meas = np.deg2rad([59.99, 60.02, 60.005])
    sigma = np.deg2rad(np.array([1.0, 2.0, 3.0]) / 3600)
    misclosure = meas.sum() - np.pi
    block, closure = angle_problem(meas, sigma)
    res = adjust(meas, ["A", "B", "C"], [block], [closure], AdjustmentOptions(sparse=sparse))
    # Condition adjustment: misclosure spread in proportion to the variances.
    share = sigma**2 / np.sum(sigma**2)
    np.testing.assert_allclose(res.x, meas - misclosure * share, rtol=0, atol=1e-14)
    assert res.x.sum() == pytest.approx(np.pi, abs=1e-14)
    assert res.redundancy == 1
    assert res.n_constraints == 1
    assert res.omega == pytest.approx(misclosure**2 / np.sum(sigma**2), rel=1e-9)
    S = np.diag(sigma**2)
    one = np.ones(3)
    Q = S - np.outer(S @ one, S @ one) / (one @ S @ one)
    np.testing.assert_allclose(res.cofactor, Q, rtol=1e-9, atol=1e-9 * Q.max())
    # Equal weights: the misclosure is spread equally.
    eq = np.full(3, sigma[0])
    block, closure = angle_problem(meas, eq)
    res = adjust(meas, ["A", "B", "C"], [block], [closure], AdjustmentOptions(sparse=sparse))
    np.testing.assert_allclose(res.x, meas - misclosure / 3, rtol=0, atol=1e-14)


def test_nonlinear_constraint_point_on_circle():
    # A measured point constrained to a circle of radius R: the adjusted point is the radial
    # projection (equal sigmas), and vTPv is the squared radial misfit over sigma^2.
    R, sigma = 10.0, 0.02
    p = np.array([6.1, 8.05])
    block = GaussMarkovBlock(
        "pt",
        p[None, :],
        np.full((1, 2), sigma),
        np.array([[0, 1]]),
        lambda xl: (xl.copy(), np.eye(2)[None]),
        row_names=("x", "y"),
    )

    def circle(xl):
        return (xl[:, :1] ** 2 + xl[:, 1:] ** 2 - R**2), 2 * xl[:, None, :]

    res = adjust(p, ["x", "y"], [block], [Constraint("circle", np.array([[0, 1]]), circle)])
    assert res.converged
    np.testing.assert_allclose(res.x, R * p / np.linalg.norm(p), rtol=0, atol=1e-12)
    assert res.omega == pytest.approx((np.linalg.norm(p) - R) ** 2 / sigma**2, rel=1e-9)


def test_dependent_constraints_are_rejected():
    meas = np.deg2rad([59.99, 60.02, 60.005])
    block, closure = angle_problem(meas, np.full(3, 1e-5))
    twice = Constraint("closure again", closure.param_index, closure.function)
    with pytest.raises(AdjustmentError, match="linearly dependent"):
        adjust(meas, ["A", "B", "C"], [block], [closure, twice])


# ----------------------------------------------------------------------------- 6. priors


def test_tight_prior_keeps_its_value_and_sigma():
    rng = np.random.default_rng(7)
    t = np.linspace(0, 10, 30)
    sigma = 0.1
    y = 2.0 + 0.5 * t + rng.normal(0, sigma, t.size)
    free = adjust([0, 0], ["a", "b"], [line_block(t, y, np.full(t.size, sigma))])
    prior_value, prior_sigma = 2.3, 1e-6
    res = adjust(
        [0, 0],
        ["a", "b"],
        [
            line_block(t, y, np.full(t.size, sigma)),
            prior_block("prior a", 0, prior_value, prior_sigma),
        ],
    )
    # The data pull the prior by about sigma_p^2 / Q_free(a) times the disagreement.
    pull = prior_sigma**2 / free.cofactor[0, 0] * abs(free.x[0] - prior_value)
    assert abs(res.x[0] - prior_value) < 2 * pull + 1e-14
    assert res.std_prior[0] == pytest.approx(prior_sigma, rel=1e-3)
    assert res.residuals["prior a"].labels == ["a"]
    # b is then the regression of y - a on t.
    A = t[:, None]
    b = np.linalg.lstsq(A, y - res.x[0], rcond=None)[0][0]
    assert res.x[1] == pytest.approx(b, abs=1e-9)


# ----------------------------------------------------------------------------- 7. datum


def levelling_blocks(with_datum: bool):
    # Heights h1..h4 (x[0:4]) from height differences around two loops; a separate, well
    # determined regression (a, b) at x[4:6] shares the adjustment.
    frm = np.array([0, 1, 2, 3, 0, 1])
    to = np.array([1, 2, 3, 0, 2, 3])
    true_h = np.array([100.0, 101.5, 99.2, 100.7])
    rng = np.random.default_rng(8)
    dh = true_h[to] - true_h[frm] + rng.normal(0, 0.002, frm.size)
    design = np.tile([[-1.0, 1.0]], (frm.size, 1))[:, None, :]

    def model(xl):
        return (xl[:, 1] - xl[:, 0])[:, None], design

    lev = GaussMarkovBlock(
        "dh", dh[:, None], np.full((frm.size, 1), 0.002), np.stack([frm, to], axis=1), model
    )
    t = np.linspace(0, 4, 12)
    reg = line_block(
        t,
        1.0 + 2.0 * t + rng.normal(0, 0.01, t.size),
        np.full(t.size, 0.01),
        name="reg",
        index=(4, 5),
    )
    blocks = [lev, reg]
    if with_datum:
        blocks.append(prior_block("datum", 0, 100.0, 1e-9))
    names = ["h1", "h2", "h3", "h4", "a", "b"]
    x0 = np.array([100.0, 100.0, 100.0, 100.0, 0.0, 0.0])
    return x0, names, blocks, frm, to, dh


def test_levelling_without_datum_names_exactly_the_heights():
    x0, names, blocks, *_ = levelling_blocks(with_datum=False)
    with pytest.raises(NotObservableError) as info:
        adjust(x0, names, blocks)
    err = info.value
    assert err.parameters == ["h1", "h2", "h3", "h4"]
    assert "h1, h2, h3, h4" in str(err) and "datum" in str(err)
    assert err.null_vectors.shape == (6, 1)
    nv = err.null_vectors[:, 0] * np.sign(err.null_vectors[0, 0])
    np.testing.assert_allclose(nv, [0.5, 0.5, 0.5, 0.5, 0, 0], atol=1e-8)
    assert err.condition_number > 1e12


def test_levelling_with_one_height_fixed_solves():
    x0, names, blocks, frm, to, dh = levelling_blocks(with_datum=True)
    res = adjust(x0, names, blocks)
    assert res.converged
    assert res.x[0] == pytest.approx(100.0, abs=1e-8)
    # Reduced system with h1 = 100 (its prior sigma is 1e-9, i.e. practically fixed).
    A = np.zeros((frm.size, 3))
    rhs = dh.copy()
    for r, (f, t) in enumerate(zip(frm, to)):
        for k, s in ((f, -1.0), (t, 1.0)):
            if k == 0:
                rhs[r] -= s * 100.0
            else:
                A[r, k - 1] = s
    h = np.linalg.lstsq(A, rhs, rcond=None)[0]
    np.testing.assert_allclose(res.x[1:4], h, rtol=0, atol=1e-7)
    assert res.redundancy == 6 + 12 + 1 - 6


def test_nearly_collinear_regressors_are_detected():
    rng = np.random.default_rng(9)
    u = rng.uniform(0, 1, 50)

    def block(u2):
        design = np.stack([u, u2], axis=1)

        def model(xl):
            return (xl * design).sum(axis=1)[:, None], design[:, None, :]

        y = design @ [1.0, 2.0] + rng.normal(0, 0.01, u.size)
        return GaussMarkovBlock(
            "y", y[:, None], np.full((u.size, 1), 0.01), np.tile([0, 1], (u.size, 1)), model
        ), design

    # Independent regressors: fine (so the check below is not a blanket failure).
    good, _ = block(rng.uniform(0, 1, 50))
    assert adjust([0, 0], ["a", "b"], [good]).condition_number < 100
    bad, design = block(u + 3e-7 * rng.normal(size=u.size))
    N = design.T @ design
    d = np.sqrt(np.diag(N))
    cond = np.linalg.cond(N / np.outer(d, d))
    assert 1e12 < cond < 1e15  # nearly, not exactly, singular
    with pytest.raises(NotObservableError) as info:
        adjust([0, 0], ["a", "b"], [bad])
    assert info.value.parameters == ["a", "b"]
    assert info.value.condition_number == pytest.approx(cond, rel=1e-2)
    assert "ill-conditioned" in str(info.value)
    # The limit decides: with a looser one the same system is solved.
    loose = adjust([0, 0], ["a", "b"], [bad], options=AdjustmentOptions(condition_limit=1e16))
    assert loose.condition_number == pytest.approx(cond, rel=1e-2)


def test_parameter_without_observations_is_named():
    t = np.linspace(0, 1, 10)
    with pytest.raises(NotObservableError) as info:
        adjust([0, 0, 0], ["a", "b", "unused"], [line_block(t, 1 + t, np.full(10, 0.1))])
    assert info.value.parameters == ["unused"]


def test_fewer_equations_than_unknowns_are_refused_with_the_counts():
    """Two observations of a line for three unknowns: refused before any analysis, the
    message giving the counts (a BAL extract such as GTSAM's dubrovnik-3-7, 48 unknowns and
    38 residuals, is refused the same way, where Ceres returns one of its solutions)."""
    t = np.array([0.0, 1.0])
    with pytest.raises(NotObservableError, match=r"3 unknowns but 2 observation rows") as info:
        adjust([0, 0, 0], ["a", "b", "c"], [line_block(t, 1 + t, np.full(2, 0.1))])
    assert "redundancy -1" in str(info.value)
    # as many equations as unknowns is determined (redundancy 0)
    res = adjust([0, 0], ["a", "b"], [line_block(t, 1 + t, np.full(2, 0.1))])
    np.testing.assert_allclose(res.x, [1.0, 1.0], atol=1e-12)


# ----------------------------------------------------------------------------- 8. snooping


def test_planted_blunder_is_rejected_and_result_matches_fit_without_it():
    rng = np.random.default_rng(10)
    t = np.linspace(0, 20, 40)
    sigma = 0.01
    y = 5.0 - 0.3 * t + rng.normal(0, sigma, t.size)
    bad = 17
    y_bad = y.copy()
    y_bad[bad] += 20 * sigma
    opts = AdjustmentOptions(snooping=True)
    res = adjust([0, 0], ["a", "b"], [line_block(t, y_bad, np.full(t.size, sigma))], options=opts)
    keep = np.arange(t.size) != bad
    ref = adjust([0, 0], ["a", "b"], [line_block(t[keep], y_bad[keep], np.full(keep.sum(), sigma))])
    assert [(r.block, r.label) for r in res.rejected] == [("y", f"y {bad}")]
    assert res.rejected[0].w < -3.29  # v = adjusted - observed: the shifted value is too high
    assert res.residuals["y"].rejected.tolist() == (~keep).tolist()
    assert "Baarda" in res.outlier_method
    np.testing.assert_allclose(res.x, ref.x, rtol=0, atol=1e-10)
    np.testing.assert_allclose(res.cofactor, ref.cofactor, rtol=1e-10)
    assert res.redundancy == ref.redundancy
    assert res.omega == pytest.approx(ref.omega, rel=1e-9)
    # The rejected row keeps a predicted residual of about the blunder and a large w.
    assert res.residuals["y"].v[bad, 0] == pytest.approx(-20 * sigma, abs=5 * sigma)
    assert abs(res.residuals["y"].w[bad, 0]) > 10
    # Without the blunder nothing is rejected.
    clean = adjust([0, 0], ["a", "b"], [line_block(t, y, np.full(t.size, sigma))], options=opts)
    assert clean.rejected == []


def test_snooping_keeps_a_group_whose_rejection_would_lose_observability():
    sigma = 0.01
    # (x, y) observed together once, x alone three times; the joint group has the blunder.
    pt = GaussMarkovBlock(
        "pt",
        np.array([[1.0 + 100 * sigma, 2.0]]),
        np.full((1, 2), sigma),
        np.array([[0, 1]]),
        lambda xl: (xl.copy(), np.eye(2)[None]),
    )
    xs = np.array([1.0, 1.004, 0.997])
    xonly = GaussMarkovBlock(
        "x",
        xs[:, None],
        np.full((3, 1), sigma),
        np.zeros((3, 1), int),
        lambda xl: (xl.copy(), np.ones((3, 1, 1))),
    )
    res = adjust([0, 0], ["x", "y"], [pt, xonly], options=AdjustmentOptions(snooping=True))
    assert res.rejected == []
    assert any("not observable" in w for w in res.warnings)
    assert np.isnan(res.residuals["pt"].w[0, 1])  # y has no redundancy


# ----------------------------------------------------------------------------- 9. cancel


def test_cancel_and_progress():
    _, st, pt, obs, x0, names, _ = trilateration_problem(11)
    seen: list[float] = []
    res = adjust(x0, names, [distance_block(st, pt, obs, 0.01)], progress=seen.append)
    assert seen and all(0.0 <= f <= 1.0 for f in seen)
    assert seen == sorted(seen) and seen[-1] == 1.0
    assert len(seen) >= res.iterations
    with pytest.raises(Cancelled):
        adjust(x0, names, [distance_block(st, pt, obs, 0.01)], should_stop=lambda: True)
    calls = []

    def stop_later():
        calls.append(1)
        return len(calls) > 2

    with pytest.raises(Cancelled):
        adjust(x0, names, [distance_block(st, pt, obs, 0.01)], should_stop=stop_later)
    assert len(calls) == 3


# ----------------------------------------------------------------------------- 10. full cov


def test_full_covariance_groups_equal_explicit_whitening():
    rng = np.random.default_rng(12)
    g = 30
    t = rng.uniform(0, 10, g)
    # Groups of 2 rows: y1 = a + b t, y2 = a - b t + c t^2, correlated within a group.
    design = np.zeros((g, 2, 3))
    design[:, 0, 0] = 1
    design[:, 0, 1] = t
    design[:, 1, 0] = 1
    design[:, 1, 1] = -t
    design[:, 1, 2] = t**2
    root = rng.normal(0, 0.02, (g, 2, 2))
    cov = root @ np.swapaxes(root, 1, 2) + 1e-4 * np.eye(2)
    L = np.linalg.cholesky(cov)
    truth = np.array([1.0, 0.2, -0.03])
    obs = design @ truth + (L @ rng.normal(size=(g, 2, 1)))[..., 0]
    idx = np.tile([0, 1, 2], (g, 1))

    def model(xl):
        return np.einsum("gck,gk->gc", design, xl), design

    full = adjust(np.zeros(3), ["a", "b", "c"], [GaussMarkovBlock("yy", obs, cov, idx, model)])
    Li = np.linalg.inv(L)
    wobs = np.einsum("gij,gj->gi", Li, obs)
    wdes = Li @ design

    def wmodel(xl):
        return np.einsum("gck,gk->gc", wdes, xl), wdes

    white = adjust(
        np.zeros(3), ["a", "b", "c"], [GaussMarkovBlock("yy", wobs, np.ones((g, 2)), idx, wmodel)]
    )
    np.testing.assert_allclose(full.x, white.x, rtol=0, atol=1e-12)
    np.testing.assert_allclose(full.cofactor, white.cofactor, rtol=1e-10)
    assert full.omega == pytest.approx(white.omega, rel=1e-10)
    # And the generalised least-squares closed form.
    A = design.reshape(-1, 3)
    W = np.zeros((2 * g, 2 * g))
    for k in range(g):
        W[2 * k : 2 * k + 2, 2 * k : 2 * k + 2] = np.linalg.inv(cov[k])
    Q = np.linalg.inv(A.T @ W @ A)
    np.testing.assert_allclose(full.x, Q @ A.T @ W @ obs.ravel(), rtol=0, atol=1e-10)
    # Redundancy numbers of correlated groups: diag(Qvv P) sums to the redundancy.
    assert np.nansum(full.residuals["yy"].redundancy_numbers) == pytest.approx(
        full.redundancy, rel=1e-9
    )


# ----------------------------------------------------------------------------- sparse + speed


def test_medium_network_sparse_equals_dense(monkeypatch):
    _, blocks, x0, names = polar_network(250, 2500, seed=13)
    auto = adjust(x0, names, blocks)
    dense = adjust(x0, names, blocks, options=AdjustmentOptions(sparse=False))
    assert auto.solver == "sparse" and dense.solver == "dense"
    np.testing.assert_allclose(auto.x, dense.x, rtol=0, atol=1e-9)
    np.testing.assert_allclose(
        auto.cofactor, dense.cofactor, rtol=1e-8, atol=1e-10 * np.abs(dense.cofactor).max()
    )
    # The large-system path: sparse LU observability check and column-wise sparse Qxx.
    monkeypatch.setattr(observability, "_DENSE_ANALYSIS_MAX_N", 100)
    monkeypatch.setattr(solve, "_DENSE_ANALYSIS_MAX_N", 100)
    big = adjust(x0, names, blocks)
    np.testing.assert_allclose(big.x, dense.x, rtol=0, atol=1e-9)
    np.testing.assert_allclose(
        big.cofactor, dense.cofactor, rtol=1e-8, atol=1e-10 * np.abs(dense.cofactor).max()
    )
    # Without a datum the sparse check fails and the dense fallback names every coordinate.
    with pytest.raises(NotObservableError) as info:
        adjust(x0, names, blocks[:1])
    assert sorted(info.value.parameters) == sorted(names)
    monkeypatch.setattr(observability, "_DENSE_FALLBACK_MAX_N", 100)
    with pytest.raises(NotObservableError, match="too large"):
        adjust(x0, names, blocks[:1])


def test_large_sparse_network_is_fast_and_correct():
    truth, blocks, x0, names = polar_network(1000, 20000, seed=14)
    start = time.perf_counter()
    res = adjust(x0, names, blocks)
    elapsed = time.perf_counter() - start
    print(f"20000 groups x 2 rows, 2000 parameters: {elapsed:.2f} s, {res.iterations} iterations")
    assert res.converged and res.solver == "sparse"
    assert res.redundancy == 40000 + 2 - 2000
    z = (res.x - truth) / res.std_prior
    # Estimates within chi-square bounds of the truth (z ~ N(0, 1) each, correlated).
    assert np.abs(z).max() < stats.norm.ppf(1 - 0.001 / (2 * z.size))
    lo, hi = stats.chi2.ppf([0.0005, 0.9995], res.redundancy)
    assert lo < res.global_test.statistic < hi
    # Generous bound: only catches a fall-back to dense algebra or per-observation loops.
    assert elapsed < 60.0


# ----------------------------------------------------------------------------- edge cases


def test_without_covariance_the_estimates_are_the_same():
    _, st, pt, obs, x0, names, _ = trilateration_problem(15)
    full = adjust(x0, names, [distance_block(st, pt, obs, 0.01)])
    bare = adjust(
        x0,
        names,
        [distance_block(st, pt, obs, 0.01)],
        options=AdjustmentOptions(compute_covariance=False),
    )
    np.testing.assert_allclose(bare.x, full.x, rtol=0, atol=1e-12)
    assert bare.cofactor is None and bare.covariance is None and bare.correlation is None
    assert np.isnan(bare.std).all() and np.isnan(bare.residuals["dist"].w).all()
    assert bare.omega == pytest.approx(full.omega, rel=1e-12)
    assert "sigma0" in bare.summary()


def test_iteration_limit_is_reported_not_hidden():
    _, st, pt, obs, x0, names, _ = trilateration_problem(16)
    res = adjust(
        x0 + 5.0,
        names,
        [distance_block(st, pt, obs, 0.01)],
        options=AdjustmentOptions(max_iterations=1),
    )
    assert not res.converged
    assert any("no convergence" in w for w in res.warnings)
    assert "NO" in res.summary()


def test_bad_inputs_are_named():
    t = np.linspace(0, 1, 5)
    good = line_block(t, t, np.full(5, 0.1))
    with pytest.raises(InputError, match="param_index outside"):
        adjust([0, 0], ["a", "b"], [line_block(t, t, np.full(5, 0.1), index=(0, 2))])
    with pytest.raises(InputError, match="2 names for 3 parameters"):
        adjust([0, 0, 0], ["a", "b"], [good])
    with pytest.raises(InputError, match="sigma must be finite and > 0"):
        adjust([0, 0], ["a", "b"], [line_block(t, t, np.zeros(5))])

    def wrong_shape(xl):
        return xl[:, :1], np.ones((5, 1, 1))

    block = GaussMarkovBlock(
        "w", t[:, None], np.full((5, 1), 0.1), np.tile([0, 1], (5, 1)), wrong_shape
    )
    with pytest.raises(InputError, match="block 'w': model Jacobian J"):
        adjust([0, 0], ["a", "b"], [block])

    def nan_model(xl):
        with np.errstate(invalid="ignore", divide="ignore"):
            f = xl[:, :1] + np.log(xl[:, 1:] - 1.0)
            return f, np.concatenate([np.ones((5, 1, 1)), 1 / (xl[:, 1:, None] - 1.0)], axis=2)

    block = GaussMarkovBlock(
        "log",
        t[:, None],
        np.full((5, 1), 0.1),
        np.tile([0, 1], (5, 1)),
        nan_model,
        labels=[f"obs {i}" for i in range(5)],
    )
    with pytest.raises(AdjustmentError, match="block 'log' returned non-finite values"):
        adjust([0, 0], ["a", "b"], [block])


def test_snooping_summary_states_the_method():
    rng = np.random.default_rng(17)
    t = np.linspace(0, 20, 30)
    y = 1.0 + 0.1 * t + rng.normal(0, 0.01, t.size)
    y[4] -= 0.3
    res = adjust(
        [0, 0],
        ["a", "b"],
        [line_block(t, y, np.full(t.size, 0.01))],
        options=AdjustmentOptions(snooping=True),
    )
    text = res.summary()
    assert "Baarda data snooping" in text and "y 4" in text and "rejected" in text
