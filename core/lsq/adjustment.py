"""General weighted non-linear least-squares adjustment (Gauss-Markov, Gauss-Helmert, constraints).

Every adjustment of the project (bundle adjustment, boresight and lever-arm calibration, plane
fits, levelling-like datum problems) is written as a set of observation *blocks* handed to
:func:`adjust`. A block holds ``G`` groups of identical shape (an image point is one group of two
rows) so that the models are evaluated batched, with a leading dimension ``G``, and never in a
Python loop over observations.

Method
------
Both kinds of block are treated as Gauss-Helmert condition equations ``g(x, l + v) = 0``:

- a Gauss-Markov block (``l + v = f(x)``) is ``g = f(x) - l`` with ``B = dg/dl = -I``;
- a Gauss-Helmert block provides ``g``, ``A = dg/dx`` and ``B = dg/dl`` itself;
- a-priori parameter values with sigmas (:func:`prior_block`) are Gauss-Markov blocks with the
  identity model.

At the current estimate ``(x, l^ = l + v^)`` the conditions are linearised as
``A dx + B v + w = 0`` with the misclosure ``w = g(x, l^) - B v^``. Minimising ``v' S^-1 v``
(``S`` the covariance of the observations of a group) under these conditions gives, per group,
the equivalent weight ``Pe = (B S B')^-1`` (``c x c``, batched; ``S^-1`` for Gauss-Markov). With
the Cholesky factor ``B S B' = L L'`` every group is whitened, ``A_ = L^-1 A``, ``w_ = L^-1 w``,
and the whitened design matrix of all groups is assembled as one ``scipy.sparse`` matrix from
the parameter indices of the groups. The step solves::

    min || A_ dx + w_ ||^2            subject to  h(x) + H dx = 0   (hard constraints)

through the normal equations ``N = A_' A_`` bordered by the constraint Jacobian (a KKT system
with Lagrange multipliers). All solves run in Jacobi-scaled variables ``z = D dx`` with
``D = sqrt(diag(N))``, so the step length is measured in units of parameter precision. After
the step the residuals follow from ``v = -S B' Pe (A dx + w)``; Gauss-Helmert blocks are
re-linearised at the new ``l^ = l + v``. The cost ``Omega = sum v' S^-1 v`` equals the squared
whitened misclosure ``||w_||^2`` of the linearisation at the new point (exactly so for linear
models), which is what the step acceptance compares.

Each iteration computes the Gauss-Newton step; with ``damping`` it is kept only when it does
not increase the cost, otherwise Levenberg-Marquardt steps ``(N_s + lambda I) z = -n_s``
(Marquardt's scaling: ``lambda diag(N)`` in the original variables) are tried with growing
``lambda`` (from 1e-4, Ceres' initial trust region, then the last that worked; doubling
factors after each rejection). The next iteration starts from the
``lambda`` that worked, reduced by Nielsen's (1999) rule from the gain ratio (by ten when the
quadratic model predicted the decrease well), and Gauss-Newton is tried again once it falls
below 1e-7 (lowered a hundredfold after each rejected Gauss-Newton step, so that nearly
singular directions keep a little damping). With constraints the merit function is
``Omega + nu ||h||_1`` (an exact penalty, ``nu`` above the multipliers). Convergence is
declared (:attr:`AdjustmentResult.termination` says which rule) when an accepted step lowers
the merit by at most ``function_tolerance`` of it (Ceres' rule and default, 1e-6; one
Gauss-Newton step follows, kept when it does not raise the cost, so that the estimates gain
the digits a relative cost cannot show), when the Jacobi-scaled gradient is below
``gradient_tolerance`` of the misclosure norm (no constraints), when the Gauss-Newton step is
below ``tolerance`` in units of parameter precision, or at the rounding floor of parameters
with large values (such as map coordinates): the relative change of the cost is below
``tolerance``, the step is below ``sqrt(tolerance)`` and has stopped shrinking (more than
half the previous one).

Observability: before trusting a solve, the Jacobi-scaled ``N + C'C`` (``C`` the constraint rows
normalised in the scaled space) is checked with a dense symmetric eigen-decomposition (up to a
few thousand parameters; above, a sparse LU with a 1-norm condition estimate, falling back to
the dense analysis up to 6000 parameters). A condition number above ``condition_limit`` raises
:class:`~lidarphoto.core.errors.NotObservableError` naming the parameters of the (near) null
space. No numbers from a singular system are ever returned.

Statistics
----------
``Qxx`` is ``N^-1`` (the upper-left block of the inverse bordered matrix with constraints),
``sigma0 = sqrt(Omega / r)`` with the redundancy ``r = rows - n + constraints``, the global test
is the two-sided chi-square test of ``Omega / sigma0_prior^2`` with ``r`` degrees of freedom.
For every group ``Qvv = S B' Pe (Pe^-1 - A Qxx A') Pe B S`` (only the ``k x k`` blocks of ``Qxx``
at the parameter indices of the group are needed), redundancy numbers ``diag(Qvv S^-1)`` and
Baarda's standardised residuals ``w_i = (S^-1 v)_i / (sigma0_prior sqrt((S^-1 Qvv S^-1)_ii))``.
Outliers are flagged by Baarda's data snooping with iterative rejection of whole groups,
optionally preceded by a robust estimator (below).

Eliminated blocks
-----------------
With :attr:`AdjustmentOptions.eliminate` the normal equations are assembled and solved in
reduced form (:mod:`.schur`): the named blocks (object points) are eliminated by the Schur
complement, damping, constraints (also on eliminated parameters), the observability analysis
(of every eliminated block, then of the reduced system ``S + C~'C~``, whose null space is that
of the full system projected on the reduced parameters) and the statistics are the same as
above; ``Qxx`` is formed in blocks (reduced parameters in full, each eliminated block, and the
cross blocks each group needs for its standardised residuals).

Robust estimation
-----------------
With :attr:`AdjustmentOptions.robust` the adjustment first runs as iteratively reweighted
least squares (Huber 1964; the Cauchy weight function): each group gets the weight
``psi(u)/u`` of its standardised misfit ``u = |w_g| / sqrt(c) / s`` (``w_g`` the whitened
misclosure, ``s`` the robust scale: the median of ``u`` over the observation groups divided by
its expected value, but at least 1, the a-priori unit weight that data snooping also uses),
until the weights settle. Groups with ``u`` above the critical value of
data snooping at the robust solution are then set aside (reported as rejected in round 0),
and the ordinary adjustment, with its statistics and data snooping, runs on the rest from the
robust estimate, so that several gross errors cannot mask one another.

Sigmas define the weights ``P = S^-1``; ``sigma0_prior`` is the a-priori standard deviation of
unit weight, so ``Omega / sigma0_prior^2`` is chi-square distributed when the sigmas are right.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Iterator, Sequence
from typing import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import special

from ..errors import InputError
from ..i18n import mark as _t
from .model import AdjustmentOptions, Constraint
from .outliers import _ROBUST_K, _robust_stage, _snoop
from .problem import Block, _as_index, _Con, _labels, _prepare_block, _Problem
from .results import AdjustmentResult, RejectedObservation
from .schur_plan import EliminationPlan
from .solve import _Progress, _run
from .statistics import _finish

#: catalogue context of this module's ``_t("...")`` sentences (``make i18n``): the reports'
TR_CONTEXT = "Report"

__all__ = ["adjust"]

Array = NDArray[np.float64]


def _hugepage_switch() -> Callable[[bool], bool] | None:
    """numpy's switch of its transparent-huge-page advice (``madvise(MADV_HUGEPAGE)`` on every
    array of 4 MiB or more, Linux), or None where this numpy has none."""
    for where in ("numpy._core.multiarray", "numpy.core.multiarray"):
        try:
            mod = __import__(where, fromlist=["_set_madvise_hugepage"])
        except ImportError:
            continue
        switch = getattr(mod, "_set_madvise_hugepage", None)
        if switch is not None:
            return switch  # type: ignore[no-any-return]
    return None


_PAGES_LOCK = threading.Lock()
_PAGES_STATE: dict[str, int | bool] = {"depth": 0, "before": True}


@contextlib.contextmanager
def small_pages() -> Iterator[None]:
    """Within the block (or the decorated function), numpy's large arrays are not advised
    onto transparent huge pages (restored after; a no-op where numpy has no switch).

    An adjustment creates and drops arrays of tens to hundreds of MB in every iteration;
    where the kernel's huge-page defragmentation honours the advice (``defrag`` =
    ``madvise``, a common default), each first touch of such an array may compact memory
    synchronously: on the synthetic 1,000-image block (bench/bundle.md) 7-10 s of system
    time against 2.5 s with ordinary pages. Only where the pages come from changes, not one
    value. The switch is numpy's, for the whole process: arrays other threads create
    meanwhile get ordinary pages too.
    """
    switch = _hugepage_switch()
    if switch is None:
        yield
        return
    # Counted, not saved per block: two adjustments in two threads must not restore each
    # other's "off" as the previous state; the first block in switches off, the last out
    # restores what it found.
    with _PAGES_LOCK:
        if _PAGES_STATE["depth"] == 0:
            _PAGES_STATE["before"] = bool(switch(False))
        _PAGES_STATE["depth"] += 1
    try:
        yield
    finally:
        with _PAGES_LOCK:
            _PAGES_STATE["depth"] -= 1
            if _PAGES_STATE["depth"] == 0:
                switch(_PAGES_STATE["before"])


def _problem(
    x0: ArrayLike,
    names: Sequence[str],
    blocks: Sequence[Block],
    constraints: Sequence[Constraint],
    opts: AdjustmentOptions,
) -> tuple[Array, _Problem]:
    """The approximate values and the validated problem (raises InputError)."""
    x = np.array(x0, dtype=np.float64).ravel()
    n = x.size
    name_list = [str(s) for s in names]
    if n == 0:
        raise InputError("the adjustment has no parameters")
    if len(name_list) != n:
        raise InputError(f"{len(name_list)} names for {n} parameters")
    if len(set(name_list)) != n:
        dup = sorted({s for s in name_list if name_list.count(s) > 1})
        raise InputError(f"duplicate parameter names: {', '.join(dup)}")
    if not np.isfinite(x).all():
        raise InputError("x0 contains NaN or inf")
    if opts.max_iterations < 1 or not opts.tolerance > 0 or not opts.sigma0_prior > 0:
        raise InputError("max_iterations >= 1, tolerance > 0 and sigma0_prior > 0 are required")
    if not (opts.function_tolerance >= 0 and opts.gradient_tolerance >= 0):
        raise InputError("function_tolerance and gradient_tolerance must be >= 0")
    obs = [_prepare_block(b, n, name_list) for b in blocks]
    bnames = [b.name for b in obs]
    if len(set(bnames)) != len(bnames):
        raise InputError(f"duplicate block names: {', '.join(bnames)}")
    if not obs:
        raise InputError("the adjustment has no observations")
    cons = []
    for c in constraints:
        where = f"constraint '{c.name}'"
        idx = _as_index(c.param_index, n, where)
        labels = _labels(c.labels, idx.shape[0], lambda i, nm=c.name: f"{nm}[{i}]", where, "labels")
        cons.append(_Con(c.name, idx, c.function, labels, None))
    plan = None
    if opts.eliminate is not None:
        plan = EliminationPlan(n, opts.eliminate, obs, [c.param_index for c in cons])
    if opts.robust not in ("none", *_ROBUST_K):
        raise InputError(f"robust must be none, huber or cauchy, got {opts.robust!r}")
    return x, _Problem(name_list, obs, cons, plan)


@small_pages()
def adjust(
    x0: ArrayLike,
    names: Sequence[str],
    blocks: Sequence[Block],
    constraints: Sequence[Constraint] = (),
    options: AdjustmentOptions | None = None,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> AdjustmentResult:
    """Weighted non-linear least-squares adjustment (see the module docstring for the method).

    Parameters
    ----------
    x0 : ndarray, shape (n,)
        Approximate values of the parameters.
    names : sequence of str, shape (n,)
        Unique parameter names (used in reports and error messages).
    blocks : sequence of GaussMarkovBlock or GaussHelmertBlock
        Observations, with unique block names.
    constraints : sequence of Constraint
        Hard constraints ``h(x) = 0``.
    options : AdjustmentOptions, optional
        Defaults to ``AdjustmentOptions()``.
    progress : callable, optional
        ``progress(fraction)`` with a non-decreasing fraction in [0, 1], once per iteration.
    should_stop : callable, optional
        Polled once per iteration; when it returns True, :class:`errors.Cancelled` is raised.

    Returns
    -------
    AdjustmentResult

    Raises
    ------
    InputError
        Inconsistent shapes, names or sigmas.
    NotObservableError
        The normal equations are singular or worse conditioned than ``condition_limit``.
    AdjustmentError
        A model gave non-finite values at the approximate values, dependent constraints, ...
    ConvergenceError
        Plain Gauss-Newton (``damping=False``) diverged to non-finite values.
    Cancelled
        ``should_stop()`` returned True.
    """
    opts = options if options is not None else AdjustmentOptions()
    x, problem = _problem(x0, names, blocks, constraints, opts)
    obs = problem.blocks
    reporter = _Progress(progress)
    want_cov = opts.compute_covariance or opts.snooping
    active = [np.ones(b.groups, dtype=bool) for b in obs]
    vhat = [np.zeros((b.groups, b.o)) for b in obs]
    crit = float(special.ndtri(1 - opts.snooping_alpha / 2))  # the normal quantile
    rejected: list[RejectedObservation] = []
    extra_warnings: list[str] = []
    robust_text = ""
    run = None
    if opts.robust != "none":
        reporter.span(0.0, 0.3)
        stage = _robust_stage(problem, x, vhat, active, opts, crit, reporter, should_stop)
        x, vhat, active, run = stage.x, stage.vhat, stage.active, stage.run
        rejected, robust_text, extra_warnings = stage.rejected, stage.text, stage.warnings
    if opts.snooping:
        reporter.span(0.3 if opts.robust != "none" else 0.0, 0.5)
    elif opts.robust != "none":
        reporter.span(0.3, 1.0)
    if run is None:  # else the robust stage's (same start, same active groups): not again
        run = _run(
            problem, x, vhat, active, opts, reporter, should_stop, initial=opts.robust == "none"
        )
    result = _finish(problem, run, active, opts, want_cov)
    if not opts.snooping:
        result.outlier_method = (
            _t("{robust}; no data snooping", robust=robust_text)
            if robust_text
            else _t("none (data snooping disabled)")
        )
        result.rejected = rejected
        result.warnings.extend(extra_warnings)
        reporter.span(0.0, 1.0)
        reporter(1.0)
        return result

    result = _snoop(
        problem,
        run,
        result,
        active,
        opts,
        crit,
        want_cov,
        rejected,
        extra_warnings,
        reporter,
        should_stop,
    )
    result.outlier_method = _t(
        "Baarda data snooping (alpha = {alpha:g} per observation, critical |w| = "
        "{critical:.2f}, iterative rejection of whole groups)",
        alpha=opts.snooping_alpha,
        critical=crit,
    )
    if robust_text:
        result.outlier_method = _t(
            "{robust}, then {snooping}", robust=robust_text, snooping=result.outlier_method
        )
    result.rejected = rejected
    result.warnings.extend(extra_warnings)
    reporter.span(0.0, 1.0)
    reporter(1.0)
    return result
