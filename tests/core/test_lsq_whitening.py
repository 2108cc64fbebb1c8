"""The whitening of uncorrelated Gauss-Markov blocks (core/lsq/problem.py): with unit sigmas
the design rows are the model's Jacobian itself, taken as it is when the model promises a
new one on every call (``fresh_jacobian``) and copied otherwise, so that a model that hands
out one buffer and overwrites it on its next call (a trial step) cannot change the
linearisation the engine holds.

The problem: an exponential decay fitted to noisy data from a poor start (Levenberg-Marquardt
needs damping, so trial steps are evaluated while the accepted linearisation is in use).
"""

from __future__ import annotations

import numpy as np
from lidarphoto.core.lsq.adjustment import _problem, adjust
from lidarphoto.core.lsq.model import AdjustmentOptions, GaussMarkovBlock

T = np.linspace(0.0, 4.0, 40)


class _Decay:
    """``y = a exp(-b t)`` at the epochs ``T``; ``reuse``: one Jacobian buffer for every call
    (overwritten by the next call), else a new array each time."""

    def __init__(self, reuse: bool, fresh: bool = False) -> None:
        self.reuse = reuse
        self.fresh_jacobian = fresh
        self.buffer = np.zeros((T.size, 1, 2))
        self.calls = 0

    def __call__(self, xl: np.ndarray):
        self.calls += 1
        e = np.exp(-xl[:, 1] * T)
        J = self.buffer if self.reuse else np.empty((T.size, 1, 2))
        J[:, 0, 0] = e
        J[:, 0, 1] = -xl[:, 0] * T * e
        return (xl[:, 0] * e)[:, None], J


def _fit(model: _Decay, sigma: float):
    rng = np.random.default_rng(3)
    y = 5.0 * np.exp(-1.3 * T) + rng.normal(0.0, 0.05, T.size)
    block = GaussMarkovBlock("y", y[:, None], sigma, np.tile([0, 1], (T.size, 1)), model)
    return adjust([1.0, 5.0], ["a", "b"], [block], options=AdjustmentOptions(snooping=False))


def test_unit_sigmas_with_a_reused_jacobian_buffer_match_fresh_jacobians():
    """A model that overwrites its Jacobian buffer on every call gives, with unit sigmas, the
    same estimates, cost, sigmas, residuals and redundancy numbers as one that returns new
    arrays (bit for bit: the same arithmetic), and a run with sigma 2 the same estimates and
    a quarter of the cost; trial steps were evaluated (more model calls than iterations plus
    one)."""
    reused = _Decay(reuse=True)
    res = _fit(reused, 1.0)
    fresh = _fit(_Decay(reuse=False, fresh=True), 1.0)
    assert res.converged and fresh.converged
    assert reused.calls > res.iterations + 1
    np.testing.assert_array_equal(res.x, fresh.x)
    assert res.omega == fresh.omega
    np.testing.assert_array_equal(res.std, fresh.std)
    got, want = res.residuals["y"], fresh.residuals["y"]
    np.testing.assert_array_equal(got.v, want.v)
    np.testing.assert_array_equal(got.redundancy_numbers, want.redundancy_numbers)
    np.testing.assert_allclose(got.redundancy_numbers.sum(), T.size - 2, rtol=1e-9)
    np.testing.assert_allclose(res.x, [5.0, 1.3], atol=0.1)
    scaled = _fit(_Decay(reuse=True), 2.0)
    np.testing.assert_allclose(scaled.x, res.x, rtol=1e-8)
    np.testing.assert_allclose(4.0 * scaled.omega, res.omega, rtol=1e-8)


def test_a_linearisation_keeps_its_rows_when_a_reused_buffer_is_overwritten():
    """Two linearisations at two points, with the buffer-reusing model and with a fresh one:
    the first keeps the Jacobian and misclosures of its own point (fails when the reused
    buffer is taken without a copy)."""
    y = (5.0 * np.exp(-1.3 * T))[:, None]
    idx = np.tile([0, 1], (T.size, 1))
    for model in (_Decay(reuse=True), _Decay(reuse=False, fresh=True)):
        block = GaussMarkovBlock("y", y, 1.0, idx, model)
        _, problem = _problem([1.0, 5.0], ["a", "b"], [block], (), AdjustmentOptions())
        active = [np.ones(T.size, dtype=bool)]
        vhat = [np.zeros((T.size, 1))]
        first = problem.linearize(np.array([1.0, 5.0]), vhat, active)
        second = problem.linearize(np.array([4.0, 1.0]), vhat, active)
        _, J1 = _Decay(reuse=False)(np.tile([1.0, 5.0], (T.size, 1)))
        _, J2 = _Decay(reuse=False)(np.tile([4.0, 1.0], (T.size, 1)))
        np.testing.assert_array_equal(first.blocks[0].abar, J1)
        np.testing.assert_array_equal(second.blocks[0].abar, J2)
        np.testing.assert_array_equal(first.blocks[0].wbar, np.exp(-5.0 * T)[:, None] - y)
