"""What a least-squares adjustment is given: observation blocks (Gauss-Markov and
Gauss-Helmert), hard constraints, a-priori parameters and the options (:mod:`.adjustment`
describes the method)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

Array = NDArray[np.float64]


@dataclass
class GaussMarkovBlock:
    """Observation equations ``l + v = f(x)`` for ``G`` groups of ``c`` observations.

    Parameters
    ----------
    name : str
        Unique name of the block (key of :attr:`AdjustmentResult.residuals`).
    observed : ndarray, shape (G, c)
        Observations ``l``.
    sigma : ndarray, shape (G, c) or (G, c, c)
        Standard deviations (anything broadcastable to ``(G, c)``) or full covariance matrices
        of each group, in the units of the observations.
    param_index : ndarray of int, shape (G, k)
        Indices into ``x`` of the parameters each group depends on.
    model : callable
        ``model(x_local) -> (f, J)`` with ``x_local = x[param_index]`` of shape (G, k),
        ``f`` of shape (G, c) and ``J = df/dx_local`` of shape (G, c, k). It is always called
        with all ``G`` groups (rejected groups are excluded afterwards), so it may close over
        per-group arrays of length ``G``. A model whose attribute ``fresh_jacobian`` is
        True promises a new ``J`` on every call, which the adjustment then whitens in place
        (one (G, c, k) array less per evaluation).
    labels : sequence of str, shape (G,), optional
        Names of the groups (e.g. ``"img 12 / pt 345"``); default ``"<name>[g]"``.
    row_names : sequence of str, shape (c,), optional
        Names of the rows of a group (e.g. ``("col", "row")``); default ``"0", "1", ...``.
    """

    name: str
    observed: ArrayLike
    sigma: ArrayLike
    param_index: ArrayLike
    model: Callable[[Array], tuple[Array, Array]]
    labels: Sequence[str] | None = None
    row_names: Sequence[str] | None = None


@dataclass
class GaussHelmertBlock:
    """Condition equations ``g(x, l + v) = 0`` for ``G`` groups of ``o`` observations.

    Parameters
    ----------
    name : str
        Unique name of the block.
    observed : ndarray, shape (G, o)
        Observations ``l``.
    sigma : ndarray, shape (G, o) or (G, o, o)
        Standard deviations (broadcastable to ``(G, o)``) or covariance matrices.
    param_index : ndarray of int, shape (G, k)
        Indices into ``x`` used by each group.
    condition : callable
        ``condition(x_local, l_hat) -> (g, A, B)`` with ``x_local`` (G, k), the current
        estimate of the observations ``l_hat = l + v`` (G, o), and ``g`` (G, c),
        ``A = dg/dx_local`` (G, c, k), ``B = dg/dl`` (G, c, o). ``B S B'`` must be positive
        definite (``c <= o`` independent conditions per group). Called with all ``G`` groups.
    labels : sequence of str, shape (G,), optional
        Names of the groups.
    row_names : sequence of str, shape (o,), optional
        Names of the observations of a group.
    """

    name: str
    observed: ArrayLike
    sigma: ArrayLike
    param_index: ArrayLike
    condition: Callable[[Array, Array], tuple[Array, Array, Array]]
    labels: Sequence[str] | None = None
    row_names: Sequence[str] | None = None


@dataclass
class Constraint:
    """Hard constraints ``h(x) = 0`` enforced with Lagrange multipliers.

    Parameters
    ----------
    name : str
        Name of the constraint set.
    param_index : ndarray of int, shape (G, k)
        Indices into ``x`` used by each group of constraints.
    function : callable
        ``function(x_local) -> (h, H)`` with ``x_local`` (G, k), ``h`` (G, c) and
        ``H = dh/dx_local`` (G, c, k). The ``G * c`` constraint rows must be independent.
    labels : sequence of str, shape (G,), optional
        Names of the groups.
    """

    name: str
    param_index: ArrayLike
    function: Callable[[Array], tuple[Array, Array]]
    labels: Sequence[str] | None = None


class _PriorModel:
    """Identity model ``f(x) = x`` of weighted parameter observations (see :func:`prior_block`)."""

    def __call__(self, x_local: Array) -> tuple[Array, Array]:
        return x_local.copy(), np.ones((x_local.shape[0], 1, 1))


def prior_block(
    name: str,
    index: ArrayLike,
    value: ArrayLike,
    sigma: ArrayLike,
    labels: Sequence[str] | None = None,
) -> GaussMarkovBlock:
    """Weighted parameter observations: a-priori values of parameters with their sigmas.

    Parameters
    ----------
    name : str
        Name of the block.
    index : int or ndarray of int, shape (G,)
        Indices of the observed parameters.
    value : float or ndarray, shape (G,)
        A-priori values, in the units of the parameters.
    sigma : float or ndarray, shape (G,)
        Their standard deviations (same units, > 0).
    labels : sequence of str, shape (G,), optional
        Group labels; by default the names of the parameters.

    Returns
    -------
    GaussMarkovBlock
        A block with ``c = k = 1`` and the identity model.
    """
    idx = np.atleast_1d(np.asarray(index)).astype(np.intp).ravel()
    g = idx.size
    val = np.broadcast_to(np.asarray(value, dtype=np.float64), (g,)).astype(np.float64)
    sig = np.broadcast_to(np.asarray(sigma, dtype=np.float64), (g,)).astype(np.float64)
    return GaussMarkovBlock(
        name=name,
        observed=val[:, None],
        sigma=sig[:, None],
        param_index=idx[:, None],
        model=_PriorModel(),
        labels=None if labels is None else list(labels),
        row_names=("value",),
    )


@dataclass
class AdjustmentOptions:
    """Options of :func:`adjust`.

    Attributes
    ----------
    max_iterations : int
        Maximum number of linearisations of one adjustment (each snooping round has its own).
    tolerance : float
        Step tolerance: converged when the Gauss-Newton step is below this in units of
        parameter precision (``max_i |dx_i| sqrt(N_ii)``; Ceres' ``parameter_tolerance`` is
        relative to ``|x|`` instead, which map coordinates would make meaningless). Also the
        rounding floor: the relative change of ``v'Pv`` below it with a step below
        ``sqrt(tolerance)`` that no longer shrinks. Default 1e-10.
    function_tolerance : float
        Converged when an accepted step lowers the cost (``v'Pv``, with constraints the merit
        function) by at most this fraction of it, as Ceres' ``function_tolerance``
        (``|dcost| / cost``); default 1e-6, Ceres' default. 0 turns the rule off (then only
        the step tolerance ends the iteration, as before).
    gradient_tolerance : float
        Converged when the Jacobi-scaled gradient is below this fraction of the norm of the
        whitened misclosures (``max_i |a_i' w| / (|a_i| |w|)``: the largest cosine between a
        column of the design matrix and the misclosure vector; scale-free, unlike Ceres'
        ``gradient_tolerance``, whose default 1e-10 it shares). Not used with hard
        constraints (the gradient there is balanced by the multipliers, not zero).
    damping : bool
        Levenberg-Marquardt (Marquardt's diagonal scaling) on top of Gauss-Newton; plain
        Gauss-Newton when False.
    sparse : bool or None
        Force the sparse (True) or dense (False) solver; None chooses sparse when
        ``n > 300`` and the normal matrix is at most 5 % full.
    sigma0_prior : float
        A-priori standard deviation of unit weight.
    alpha : float
        Significance level of the two-sided global chi-square test.
    snooping : bool
        Baarda data snooping with iterative rejection of the worst group.
    snooping_alpha : float
        Two-sided significance per observation (0.001 -> critical ``|w|`` = 3.29).
    max_rejections : int
        Maximum number of rejected groups.
    condition_limit : float
        Largest accepted condition number of the Jacobi-scaled normal matrix.
    compute_covariance : bool
        Compute ``Qxx`` and everything derived from it (standard deviations, correlations,
        standardised residuals). Forced on when ``snooping`` is True.
    eliminate : array_like of int, shape (P, b), optional
        Parameter indices of ``P`` small independent blocks (e.g. the object points of a
        bundle adjustment, ``b = 3``) eliminated from the normal equations by the Schur
        complement (:mod:`.schur`): the solver factorises the reduced system of the other
        parameters only. Each observation group may depend on at most one block. The
        estimates are those of the full system; ``Qxx`` is returned in blocks
        (:attr:`AdjustmentResult.cofactor_blocks`) instead of as one matrix.
    robust : {"none", "huber", "cauchy"}
        Iteratively reweighted least squares with Huber's or the Cauchy weight function
        before the final least-squares run: groups whose standardised misfit at the robust
        solution exceeds the critical value of data snooping are set aside, then the
        adjustment (and data snooping, when on) runs on the rest.
    robust_k : float or None
        Tuning constant of the weight function in units of the robust scale of the
        whitened residuals (None: 1.5 for Huber, 2.385 for Cauchy).
    robust_iterations : int
        Maximum number of reweighting rounds.
    robust_blocks : sequence of str or None
        Names of the blocks that are reweighted (and set aside when flagged); None: every
        block. Typically the measurements, not the control whose misfits mostly reflect an
        imperfect model.
    snooping_blocks : sequence of str or None
        Names of the blocks whose groups data snooping may reject; None: every block. The
        others are tested (their w is reported) but never removed.
    snooping_per_group : bool
        Data snooping at ``snooping_alpha`` per group instead of per observation: a group of
        o observation rows is set aside when its largest |w| exceeds the normal quantile of
        ``1 - snooping_alpha / (2 o)`` (Bonferroni over its rows: a good group is rejected
        with probability at most ``snooping_alpha``), so that a group of hundreds of rows (a
        LiDAR line's points) is not rejected by chance.
    """

    max_iterations: int = 50
    tolerance: float = 1e-10
    function_tolerance: float = 1e-6
    gradient_tolerance: float = 1e-10
    damping: bool = True
    sparse: bool | None = None
    sigma0_prior: float = 1.0
    alpha: float = 0.05
    snooping: bool = False
    snooping_alpha: float = 0.001
    max_rejections: int = 50
    condition_limit: float = 1e12
    compute_covariance: bool = True
    eliminate: ArrayLike | None = None
    robust: str = "none"
    robust_k: float | None = None
    robust_iterations: int = 20
    robust_blocks: Sequence[str] | None = None
    snooping_blocks: Sequence[str] | None = None
    snooping_per_group: bool = False
