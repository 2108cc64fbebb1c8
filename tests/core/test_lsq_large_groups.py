"""Large Gauss-Helmert groups (core.lsq.problem._whiten_large): a group of many conditions whose
observations are mostly uncorrelated (a LiDAR line's pixels) beside a few correlated ones (the
line itself) is whitened per group with sparse products; the adjustment, its statistics and
data snooping must be those of the batched dense path, and of the equivalent model in which the
shared observations are unknowns with a prior."""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.lsq import problem
from lidarphoto.core.lsq.adjustment import adjust
from lidarphoto.core.lsq.model import AdjustmentOptions, GaussHelmertBlock, GaussMarkovBlock

K = 90  # points per line: above problem._LARGE_GROUP
SIGMA = 0.02  # m, each point's x and y
T_COV = np.array([[0.05**2, 0.3 * 0.05 * 0.004], [0.3 * 0.05 * 0.004, 0.004**2]])


def _data(outlier: bool):
    """Three lines y = (a + t0) + (b + t1) x: a, b unknown (shared), t = (t0, t1) observed per
    line with the correlated covariance T_COV, K points per line with noise SIGMA."""
    rng = np.random.default_rng(21)
    a, b = 1.5, -0.4
    rows = []
    for _line in range(3):
        t = rng.multivariate_normal([0, 0], T_COV)  # the observed line offsets' errors
        x = np.sort(rng.uniform(-20, 20, K))
        y = a + b * x
        pts = np.column_stack([x, y]) + rng.normal(0, SIGMA, (K, 2))
        rows.append((pts, t))
    if outlier:
        rows[1][0][40, 1] += 0.5  # 25 sigma
    return rows


def _condition(xl, lhat):
    """y_j - (a + t0) - (b + t1) x_j = 0 for the K points of a group."""
    a, b = xl[:, 0:1], xl[:, 1:2]
    px, py = lhat[:, 0 : 2 * K : 2], lhat[:, 1 : 2 * K : 2]
    t0, t1 = lhat[:, 2 * K : 2 * K + 1], lhat[:, 2 * K + 1 :]
    g = py - (a + t0) - (b + t1) * px
    n = xl.shape[0]
    A = np.stack([-np.ones((n, K)), -px], axis=2)
    B = np.zeros((n, K, 2 * K + 2))
    j = np.arange(K)
    B[:, j, 2 * j] = -(b + t1)
    B[:, j, 2 * j + 1] = 1.0
    B[:, :, 2 * K] = -1.0
    B[:, :, 2 * K + 1] = -px
    return g, A, B


def _grouped(rows, snooping: bool):
    obs = np.array([np.r_[pts.ravel(), t] for pts, t in rows])
    cov = np.zeros((3, 2 * K + 2, 2 * K + 2))
    cov[:, np.arange(2 * K), np.arange(2 * K)] = SIGMA**2
    cov[:, 2 * K :, 2 * K :] = T_COV
    block = GaussHelmertBlock("lines", obs, cov, np.tile([0, 1], (3, 1)), _condition)
    return adjust([1.0, 0.0], ["a", "b"], [block], options=AdjustmentOptions(snooping=snooping))


def test_large_groups_equal_the_dense_path_and_the_prior_model(monkeypatch):
    rows = _data(outlier=False)
    fast = _grouped(rows, snooping=False)
    monkeypatch.setattr(problem, "_LARGE_GROUP", 10**9)
    dense = _grouped(rows, snooping=False)
    assert fast.converged and dense.converged
    np.testing.assert_allclose(fast.x, dense.x, rtol=0, atol=1e-10 * np.max(dense.std))
    np.testing.assert_allclose(fast.std, dense.std, rtol=1e-9)
    assert fast.omega == pytest.approx(dense.omega, rel=1e-9)
    tf, td = fast.residuals["lines"], dense.residuals["lines"]
    np.testing.assert_allclose(tf.v, td.v, rtol=0, atol=1e-9 * SIGMA)
    np.testing.assert_allclose(tf.w, td.w, rtol=0, atol=1e-7)
    np.testing.assert_allclose(tf.redundancy_numbers, td.redundancy_numbers, rtol=0, atol=1e-9)
    # the equivalent model: t of each line an unknown with its prior, one group per point
    obs = np.array([[*p] for pts, _ in rows for p in pts])
    line = np.repeat(np.arange(3), K)

    def point(xl, lhat):
        a, b, t0, t1 = xl.T
        g = lhat[:, 1] - (a + t0) - (b + t1) * lhat[:, 0]
        A = np.column_stack([-np.ones(len(g)), -lhat[:, 0], -np.ones(len(g)), -lhat[:, 0]])
        B = np.column_stack([-(b + t1), np.ones(len(g))])
        return g[:, None], A[:, None, :], B[:, None, :]

    idx = np.column_stack([np.zeros(3 * K, int), np.ones(3 * K, int), 2 + 2 * line, 3 + 2 * line])
    pts_block = GaussHelmertBlock("points", obs, np.full(obs.shape, SIGMA), idx, point)
    prior = GaussMarkovBlock(
        "t",
        np.array([t for _, t in rows]),
        np.broadcast_to(T_COV, (3, 2, 2)),
        2 + 2 * np.arange(3)[:, None] + np.arange(2),
        lambda xl: (xl.copy(), np.broadcast_to(np.eye(2), (3, 2, 2)).copy()),
    )
    names = ["a", "b"] + [f"t{i}{j}" for i in range(3) for j in range(2)]
    ref = adjust([1.0, 0.0] + [0.0] * 6, names, [pts_block, prior])
    np.testing.assert_allclose(fast.x, ref.x[:2], rtol=0, atol=1e-8 * np.max(ref.std[:2]))
    np.testing.assert_allclose(fast.std, ref.std[:2], rtol=1e-7)
    assert fast.omega == pytest.approx(ref.omega, rel=1e-8)
    # per observation, Baarda's w is the same in both models
    np.testing.assert_allclose(tf.w[:, : 2 * K].ravel(), ref.residuals["points"].w.ravel(),
                               rtol=0, atol=1e-6)  # fmt: skip


def test_large_groups_snoop_the_same_planted_outlier(monkeypatch):
    rows = _data(outlier=True)
    fast = _grouped(rows, snooping=True)
    monkeypatch.setattr(problem, "_LARGE_GROUP", 10**9)
    dense = _grouped(rows, snooping=True)
    assert [r.label for r in fast.rejected] == [r.label for r in dense.rejected] == ["lines[1]"]
    # the point's x and y rows have the same |w| (one condition): either may be named
    assert int(fast.rejected[0].row_name) // 2 == int(dense.rejected[0].row_name) // 2 == 40
    assert abs(fast.rejected[0].w) == pytest.approx(abs(dense.rejected[0].w), rel=1e-9)
    assert abs(fast.rejected[0].w) > 20
    np.testing.assert_allclose(fast.x, dense.x, rtol=0, atol=1e-10 * np.max(dense.std))
