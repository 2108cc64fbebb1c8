"""The stopping rules of the adjustment engine (core/lsq/solve.py): Ceres' function tolerance
(relative decrease of the cost of an accepted step, then one Gauss-Newton step), the
scale-free gradient tolerance, the step tolerance, and the reported reason.

The slowly converging case: an exponential decay fitted to data with large residuals (2.0 for
values from 5 down to 0.03), where Gauss-Newton converges linearly and the step tolerance
(1e-10 sigma) alone takes twice the iterations the cost needs.
"""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.lsq.adjustment import adjust
from lidarphoto.core.lsq.model import AdjustmentOptions, GaussMarkovBlock

T = np.linspace(0.0, 4.0, 40)
NOISE = 2.0


class _Decay:
    """``y = a exp(-b t)`` at the 40 epochs ``T``."""

    def __call__(self, xl: np.ndarray):
        e = np.exp(-xl[:, 1] * T)
        f = (xl[:, 0] * e)[:, None]
        return f, np.stack([e, -xl[:, 0] * T * e], axis=1)[:, None, :]


def _decay_block() -> GaussMarkovBlock:
    rng = np.random.default_rng(1)
    y = 5.0 * np.exp(-1.3 * T) + rng.normal(0.0, NOISE, T.size)
    return GaussMarkovBlock("y", y[:, None], NOISE, np.tile([0, 1], (T.size, 1)), _Decay())


def _fit(**kw):
    return adjust([1.0, 0.1], ["a", "b"], [_decay_block()], options=AdjustmentOptions(**kw))


def test_function_tolerance_stops_a_problem_that_converges_in_seven_iterations():
    """The default rules stop within 10 iterations, by the function tolerance, at the cost
    and the estimates of the run that iterates to the step tolerance (which needs more than
    10): the same cost to 1e-9 and the same parameters to 1e-3 of their sigmas."""
    full = _fit(function_tolerance=0.0, gradient_tolerance=0.0, max_iterations=100)
    assert full.converged and full.termination == "step tolerance"
    assert full.iterations > 10
    res = _fit()
    assert res.converged and res.termination == "function tolerance"
    assert res.iterations <= 10
    assert res.omega <= full.omega * (1 + 1e-9)
    np.testing.assert_array_less(np.abs(res.x - full.x), 1e-3 * full.std)
    # the trace: the start and one entry per iteration, the cost never rising
    costs = [c for _, c, _ in res.trace]
    assert [i for i, _, _ in res.trace] == list(range(res.iterations + 1))
    assert all(b <= a * (1 + 1e-12) for a, b in zip(costs, costs[1:]))
    assert "stopped by: function tolerance" in res.summary()


def test_iteration_limit_and_gradient_tolerance_are_reported():
    short = _fit(function_tolerance=0.0, gradient_tolerance=0.0, max_iterations=3)
    assert not short.converged and short.termination == "iteration limit"
    assert any("no convergence within 3 iterations" in w for w in short.warnings)
    # a linear regression: solved by the first step, the gradient is then at rounding level
    rng = np.random.default_rng(2)
    t = np.linspace(0.0, 10.0, 30)
    y = 2.0 + 0.5 * t + rng.normal(0.0, 0.1, t.size)

    def line(xl: np.ndarray):
        f = (xl[:, 0] + xl[:, 1] * t)[:, None]
        return f, np.stack([np.ones_like(t), t], axis=1)[:, None, :]

    blk = GaussMarkovBlock("y", y[:, None], 0.1, np.tile([0, 1], (t.size, 1)), line)
    res = adjust([0.0, 0.0], ["c", "m"], [blk], options=AdjustmentOptions(function_tolerance=0))
    assert res.converged and res.termination == "gradient tolerance" and res.iterations == 1
    ref = np.polyfit(t, y, 1)[::-1]
    np.testing.assert_allclose(res.x, ref, rtol=0, atol=1e-10)


@pytest.mark.parametrize("field", ["function_tolerance", "gradient_tolerance"])
def test_negative_tolerances_are_refused(field):
    with pytest.raises(InputError, match="function_tolerance and gradient_tolerance"):
        _fit(**{field: -1e-6})


class _RoughLine:
    """``y = a + b t`` whose evaluation carries an error of 1e-5 that jumps with the sixth
    decimals of ``a`` and ``b`` (the Jacobian does not see it): near the optimum a step of the
    size the error itself causes moves the cost at random, as the rounding of a large network's
    cost does at its own scale (4e-13 of the cost, seen on a TLS network)."""

    def __call__(self, xl: np.ndarray):
        key = xl[:, 0] * 1e6 + xl[:, 1] * 3.7e6 + np.arange(len(xl)) * 0.61803
        f = xl[:, 0] + xl[:, 1] * T + 1e-5 * np.sin(key)
        return f[:, None], np.stack([np.ones_like(T), T], axis=1)[:, None, :]


def test_a_cost_at_its_rounding_floor_stops_as_converged():
    """At the optimum the Gauss-Newton step raises the rough cost and damped steps tie with
    it: the adjustment stops there, converged, within a few iterations (before, each tie grew
    the damping and it idled to the iteration limit), at the line's least-squares solution."""
    rng = np.random.default_rng(4)
    y = 2.0 + 0.5 * T + rng.normal(0.0, 1.0, T.size)
    block = GaussMarkovBlock("y", y[:, None], 1.0, np.tile([0, 1], (T.size, 1)), _RoughLine())
    res = adjust([0.0, 0.0], ["a", "b"], [block], options=AdjustmentOptions(max_iterations=50))
    assert res.converged, res.summary()
    assert res.iterations < 15
    ref = np.polynomial.polynomial.polyfit(T, y, 1)
    # the rough evaluation moves the optimum by about its own 1e-5 (std of a: 0.3)
    np.testing.assert_array_less(np.abs(res.x - ref), 1e-4 * res.std)
