"""The iteration of an adjustment: the (damped) step of the bordered normal equations, the
Gauss-Newton / Levenberg-Marquardt loop with its acceptance and convergence rules, and the
scaled cofactor matrix at the solution (see :mod:`.adjustment` for the method).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from ..errors import AdjustmentError, ConvergenceError, NotObservableError, stop_if_asked
from ..i18n import mark as _t
from .model import AdjustmentOptions
from .observability import _DENSE_ANALYSIS_MAX_N, _check_observability
from .problem import _Lin, _NonFiniteError, _Normal, _Problem
from .schur import ReducedNormal, SingularSystem

#: catalogue context of this module's ``_t("...")`` sentences (``make i18n``): the reports'
TR_CONTEXT = "Report"

Array = NDArray[np.float64]

# Automatic choice of the sparse solver: n above this and N at most this dense.
_SPARSE_AUTO_MIN_N = 300
_SPARSE_AUTO_MAX_DENSITY = 0.05
# Column chunk of the sparse computation of Qxx (bounds the memory of the right-hand sides).
_QXX_CHUNK = 512
# Largest lambda of Levenberg-Marquardt before the cost is declared irreducible.
_LAMBDA_MAX = 1e12
# First lambda after the first rejected Gauss-Newton step (Ceres' initial trust region, 1e-4,
# took the BAL problems to Ceres' cost in 0.73-0.77x of its time, but left a line resection
# from 35 degrees of kappa at a point no damped step could leave: 1e-3, as before); the
# largest damping of a step after which the function tolerance may stop the run; the smallest
# kept before returning to Gauss-Newton (all in the Jacobi-scaled space, where the diagonal
# of N is one).
_LAMBDA_FIRST = 1e-3
_LAMBDA_START = 1e-3
_LAMBDA_MIN = 1e-7
#: The clock of :attr:`_Run.trace` (wall time; a benchmark may set ``time.process_time`` to
#: trace the CPU time of the run on a loaded machine).
TRACE_CLOCK: Callable[[], float] = time.perf_counter


def _dense_ns(nrm: _Normal) -> Array:
    if nrm.dense is None:
        nrm.dense = nrm.Ns.toarray()
    return nrm.dense


def _solve(nrm: _Normal, lam: float, use_sparse: bool) -> tuple[Array, Array]:
    """Scaled (damped) step ``z`` and multipliers ``k`` of the bordered system.

    Solves ``(N_s + lam I) z + C_s' k = -n_s``, ``C_s z = -h_s``. Raises SingularSystem when a
    factorisation fails or gives non-finite numbers.
    """
    if isinstance(nrm, ReducedNormal):
        return nrm.solve(lam)
    n = nrm.ns.size
    if use_sparse:
        Nl = (nrm.Ns + lam * sp.identity(n, format="csr")).tocsc()
        try:
            if nrm.Cs is None:
                lu = spla.splu(
                    Nl,
                    permc_spec="MMD_AT_PLUS_A",
                    diag_pivot_thresh=0.0,
                    options={"SymmetricMode": True},
                )
                z = lu.solve(-nrm.ns)
                k = np.zeros(0)
            else:
                K = sp.bmat([[Nl, nrm.Cs.T], [nrm.Cs, None]], format="csc")
                sol = spla.splu(K).solve(np.concatenate([-nrm.ns, -nrm.hs]))
                z, k = sol[:n], sol[n:]
        except RuntimeError as exc:  # SuperLU: "Factor is exactly singular"
            raise SingularSystem(str(exc)) from None
    else:
        M = _dense_ns(nrm) + lam * np.eye(n)
        try:
            if nrm.Cs is None:
                cf = sla.cho_factor(M, lower=True, check_finite=False)
                z = sla.cho_solve(cf, -nrm.ns, check_finite=False)
                k = np.zeros(0)
            else:
                # (N + C'C) is positive definite exactly when the constrained problem is
                # determined; the multipliers then follow from the small Schur complement.
                C = nrm.Cs.toarray()
                cf = sla.cho_factor(M + C.T @ C, lower=True, check_finite=False)
                r = -nrm.ns - C.T @ nrm.hs
                Y = sla.cho_solve(cf, C.T, check_finite=False)
                zr = sla.cho_solve(cf, r, check_finite=False)
                S = C @ Y
                k = sla.solve(S, C @ zr + nrm.hs, assume_a="pos", check_finite=False)
                z = zr - Y @ k
        except (np.linalg.LinAlgError, ValueError) as exc:
            raise SingularSystem(str(exc)) from None
    if not (np.isfinite(z).all() and np.isfinite(k).all()):
        raise SingularSystem("non-finite solution")
    return z, k


def _scaled_cofactor(nrm: _Normal, use_sparse: bool) -> Array:
    """``Q_s = (D Qxx D)``: inverse of ``N_s`` or upper-left block of the bordered inverse."""
    n = nrm.ns.size
    if not use_sparse or n <= _DENSE_ANALYSIS_MAX_N:
        Nd = _dense_ns(nrm)
        if nrm.Cs is None:
            cf = sla.cho_factor(Nd, lower=True, check_finite=False)
            Q = sla.cho_solve(cf, np.eye(n), check_finite=False)
        else:
            C = nrm.Cs.toarray()
            cf = sla.cho_factor(Nd + C.T @ C, lower=True, check_finite=False)
            Minv = sla.cho_solve(cf, np.eye(n), check_finite=False)
            Y = Minv @ C.T
            S = C @ Y
            Q = Minv - Y @ sla.solve(S, Y.T, assume_a="pos", check_finite=False)
    else:
        if nrm.Cs is None:
            lu = spla.splu(
                nrm.Ns.tocsc(),
                permc_spec="MMD_AT_PLUS_A",
                diag_pivot_thresh=0.0,
                options={"SymmetricMode": True},
            )
            mc = 0
        else:
            K = sp.bmat([[nrm.Ns, nrm.Cs.T], [nrm.Cs, None]], format="csc")
            lu = spla.splu(K)
            mc = nrm.Cs.shape[0]
        Q = np.empty((n, n))
        for s in range(0, n, _QXX_CHUNK):
            e = min(n, s + _QXX_CHUNK)
            rhs = np.zeros((n + mc, e - s))
            rhs[np.arange(s, e), np.arange(e - s)] = 1.0
            Q[:, s:e] = lu.solve(rhs)[:n]
    Q = 0.5 * (Q + Q.T)
    if not np.isfinite(Q).all():
        raise SingularSystem("non-finite cofactor matrix")
    return Q


class _Progress:
    """Monotone progress in [0, 1] over possibly several adjustment runs."""

    def __init__(self, callback: Callable[[float], None] | None) -> None:
        self.callback = callback
        self.last = 0.0
        self.lo, self.hi = 0.0, 1.0

    def span(self, lo: float, hi: float) -> None:
        self.lo, self.hi = lo, hi

    def __call__(self, fraction: float) -> None:
        value = self.lo + (self.hi - self.lo) * min(max(fraction, 0.0), 1.0)
        self.last = max(self.last, min(value, 1.0))
        if self.callback is not None:
            self.callback(self.last)


#: Why an iteration ended (:attr:`AdjustmentResult.termination`).
STEP_TOLERANCE = "step tolerance"
FUNCTION_TOLERANCE = "function tolerance"
GRADIENT_TOLERANCE = "gradient tolerance"
ROUNDING_FLOOR = "rounding floor"
ITERATION_LIMIT = "iteration limit"
NO_DECREASE = "no decrease"


@dataclass
class _Run:
    lin: _Lin
    nrm: _Normal
    iterations: int
    converged: bool
    use_sparse: bool
    warnings: list[str]
    termination: str = ""
    # (iteration, cost v'Pv after it, seconds since the start of the run)
    trace: list[tuple[int, float, float]] = field(default_factory=list)


def _apply(problem: _Problem, lin: _Lin, nrm: _Normal, z: Array) -> tuple[Array, list[Array]]:
    """New parameters and residual estimates after the scaled step ``z``."""
    dx = z / nrm.d
    x = lin.x + dx
    vhat = []
    for b, bl in zip(problem.blocks, lin.blocks):
        e = bl.wbar + np.einsum("gck,gk->gc", bl.abar, dx[b.param_index])
        vhat.append(-np.einsum("goc,gc->go", bl.K, e))
    return x, vhat


def _refreshed(
    problem: _Problem, lin: _Lin, active: list[NDArray[np.bool_]], rounds: int = 3
) -> _Lin | None:
    """The linearisation at ``lin.x`` with the residuals of Gauss-Helmert blocks re-solved at
    fixed parameters (a few fixed-point rounds of ``v = -S B' Pe (g - B v)``), whose cost is
    the true cost at ``x``; None without Gauss-Helmert blocks or on non-finite values."""
    if all(b.gauss_markov for b in problem.blocks):
        return None
    for _ in range(rounds):
        vhat = [-np.einsum("goc,gc->go", bl.K, bl.wbar) for bl in lin.blocks]
        try:
            lin = problem.linearize(lin.x, vhat, active)
        except _NonFiniteError:
            return None
    return lin


def _merit(lin: _Lin, nrm_rowscale: Array | None, nu: float) -> float:
    if nrm_rowscale is None or lin.h.size == 0:
        return lin.phi
    return lin.phi + nu * float(np.abs(nrm_rowscale * lin.h).sum())


@dataclass
class _Damping:
    """Levenberg-Marquardt state carried from one iteration to the next."""

    memory: float = 0.0  # the damping the next iteration starts from (0: Gauss-Newton)
    good: float = _LAMBDA_FIRST  # the last positive damping that reduced the cost
    growth: float = 2.0  # growth factor of the damping after rejected steps (Nielsen 1999)
    # Damping below which Gauss-Newton is tried again; lowered after each rejected
    # Gauss-Newton step (nearly singular directions, e.g. points far away, need a little
    # damping all the way).
    floor: float = _LAMBDA_MIN
    last: float = 0.0  # the damping of the step accepted last


def _damped_step(
    problem: _Problem,
    lin: _Lin,
    nrm: _Normal,
    z: Array | None,
    active: list[NDArray[np.bool_]],
    rowscale: Array | None,
    nu: float,
    m_old: float,
    use_sparse: bool,
    tol: float,
    damp: _Damping,
) -> _Lin | None:
    """The linearisation after the first step, from ``damp.memory`` on with growing damping,
    whose merit is not above ``m_old``; None when no damping up to the largest does that.
    ``z`` is the Gauss-Newton step (None when it was not solved for); ``damp`` is updated."""
    # Start from the damping that last worked (0: Gauss-Newton): in a long curved
    # valley (e.g. focal length against flying height) the accepted damping then
    # shrinks by ten per step and the steps grow back to Gauss-Newton, instead of
    # crawling at the smallest damping after every rejected Gauss-Newton step.
    lam = damp.memory
    while True:
        if lam > 0:
            try:
                z_try, _ = _solve(nrm, lam, use_sparse)
            except SingularSystem:
                z_try = None
        else:
            z_try = z
        if z_try is not None:
            x, vhat = _apply(problem, lin, nrm, z_try)
            cand = None  # a rejected candidate is not held while the next one is evaluated
            try:
                cand = problem.linearize(x, vhat, active)
            except _NonFiniteError:
                cand = None
            # Ties at rounding level are accepted: the cost cannot go lower.
            m_try = _merit(cand, rowscale, nu) if cand is not None else math.inf
            if m_try <= m_old * (1 + 1e-13):
                damp.last = lam
                factor = 0.1
                if lam > 0:
                    damp.good = lam
                    # Nielsen's update from the gain ratio: the damping shrinks
                    # little when the quadratic model predicted the decrease badly
                    pred = lam * float(z_try @ z_try) - float(nrm.ns @ z_try)
                    if pred > 0:
                        rho = (m_old - m_try) / pred
                        if rho < 0.9:
                            factor = max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
                damp.growth = 2.0
                damp.memory = lam * factor if lam * factor >= damp.floor else 0.0
                if lam > 0 and float(np.abs(z_try).max(initial=0.0)) <= math.sqrt(tol):
                    # near the optimum: let the Gauss-Newton step test convergence
                    damp.memory = 0.0
                return cand
        # after a rejected Gauss-Newton step go back to the damping that last worked
        if lam == 0:
            lam = damp.good
            damp.floor = max(damp.floor * 1e-2, 1e-14)
        else:
            lam *= damp.growth
            damp.growth *= 2.0
        if lam > _LAMBDA_MAX:
            return None


def _trial(
    problem: _Problem, lin: _Lin, nrm: _Normal, z: Array, active: list[NDArray[np.bool_]]
) -> _Lin | None:
    """The linearisation after the scaled step ``z`` (None on non-finite values)."""
    x, vhat = _apply(problem, lin, nrm, z)
    try:
        return problem.linearize(x, vhat, active)
    except _NonFiniteError:
        return None


def _normal(
    problem: _Problem,
    lin: _Lin,
    active: list[NDArray[np.bool_]],
    rowscale: Array | None,
    use_sparse: bool | None,
    opts: AdjustmentOptions,
    check: bool,
) -> tuple[_Normal, Array | None, bool | None]:
    """The normal equations at ``lin``, the solver choice, and (``check``) the observability
    analysis of the first iteration."""
    nrm, rowscale = problem.normal(lin, active, rowscale)
    if isinstance(nrm, ReducedNormal):
        use_sparse = nrm.use_sparse
    elif use_sparse is None:
        n = problem.n
        use_sparse = n > _SPARSE_AUTO_MIN_N and nrm.Ns.nnz <= _SPARSE_AUTO_MAX_DENSITY * n * n
    if check:
        _check_count(problem, active)
        _check_observability(nrm, problem.names, opts.condition_limit, problem.constraint_labels())
    return nrm, rowscale, use_sparse


def _check_count(problem: _Problem, active: list[NDArray[np.bool_]]) -> None:
    """Refuse fewer equations than unknowns before any analysis: no datum or weighting makes
    such a system determined, and the message says so with the counts."""
    rows, cons = problem.rows(active), problem.constraint_rows()
    if rows + cons < problem.n:
        raise NotObservableError(
            f"Not observable: {problem.n} unknowns but {rows} observation rows and {cons} "
            f"constraint rows (redundancy {rows + cons - problem.n}): fewer equations than "
            "unknowns; add observations (more points, more images of each point) or hold "
            "parameters fixed",
            parameters=list(problem.names),
        )


def _function_tolerance_met(
    opts: AdjustmentOptions, damp: _Damping, m_old: float, m_new: float
) -> bool:
    """Ceres' function tolerance: the accepted step changed the cost too little to be worth
    another damped iteration (one Gauss-Newton step follows). Not after a heavily damped
    step: a small decrease there is a stall (e.g. a model that cannot fit), not the minimum."""
    ftol = opts.function_tolerance
    return bool(
        ftol > 0
        and m_new <= m_old * (1 + 1e-13)
        and m_old - m_new <= ftol * m_old
        and (not opts.damping or damp.last <= _LAMBDA_START)
    )


def _gradient_small(nrm: _Normal, lin: _Lin, opts: AdjustmentOptions) -> bool:
    """The gradient test of :attr:`AdjustmentOptions.gradient_tolerance` (no constraints)."""
    if lin.h.size or opts.gradient_tolerance <= 0 or not nrm.ns.size:
        return False
    g = float(np.abs(nrm.ns).max())
    return g <= opts.gradient_tolerance * math.sqrt(max(lin.phi, 0.0))


def _tie_at_floor(
    problem: _Problem, nrm: _Normal, z: Array | None, m_old: float, opts: AdjustmentOptions,
    use_sparse: bool,
) -> bool:  # fmt: skip
    """After a damped step that tied the cost (it did not move at all): whether the point is
    the optimum, where the Gauss-Newton step was rejected by the cost's rounding and damped
    steps cannot help (the damping only grows on ties: 36 idle iterations to the limit seen on
    a TLS network). The Gauss-Newton step ``z`` (solved here when None) decides: its largest
    scaled component below the step tolerance's root, or the decrease it promises (z'Nz in the
    scaled space) below the function tolerance (Ceres' rule; the rise seen is the rounding of
    the cost, 4e-13 of it on that network). Elsewhere the damped iteration goes on as before
    (a tie far from the optimum, e.g. a resection 35 degrees off, is followed by progress)."""
    if z is None:
        z, _ = _gauss_newton(problem, nrm, opts, use_sparse)
    step = float(np.abs(z).max()) if z.size else 0.0
    promised = abs(float(nrm.ns @ z)) if z.size else 0.0
    return step <= math.sqrt(opts.tolerance) or promised <= opts.function_tolerance * m_old


def _no_decrease(it: int, step: float) -> str:
    return _t(
        "the cost could not be reduced further at iteration {iteration} (step {step:.3g} "
        "sigma): stopped without convergence",
        iteration=it,
        step=step,
    )


def _gauss_newton(
    problem: _Problem, nrm: _Normal, opts: AdjustmentOptions, use_sparse: bool
) -> tuple[Array, Array]:
    """The Gauss-Newton step of the normal equations ``nrm`` (undamped) and the constraints'
    multipliers; a singular system is diagnosed (NotObservableError naming the parameters)
    or AdjustmentError."""
    try:
        return _solve(nrm, 0.0, use_sparse)
    except SingularSystem:
        _check_observability(nrm, problem.names, opts.condition_limit, problem.constraint_labels())
        raise AdjustmentError("the normal equations could not be solved") from None


def _run(
    problem: _Problem,
    x0: Array,
    vhat0: list[Array],
    active: list[NDArray[np.bool_]],
    opts: AdjustmentOptions,
    progress: _Progress,
    should_stop: Callable[[], bool] | None,
    initial: bool,
) -> _Run:
    """One adjustment from ``x0`` with the given groups active."""
    t0 = TRACE_CLOCK()
    try:
        lin = problem.linearize(x0.copy(), vhat0, active)
    except _NonFiniteError as exc:
        state = "initial values" if initial else "current estimate"
        raise AdjustmentError(f"{exc} at the {state}; check the approximate values") from None
    rowscale: Array | None = None
    use_sparse: bool | None = opts.sparse
    tol = opts.tolerance
    damp = _Damping()
    nu, prev_step = 0.0, math.inf
    converged, why = False, ITERATION_LIMIT
    warnings: list[str] = []
    trace = [(0, lin.phi, TRACE_CLOCK() - t0)]
    it, nrm = 0, None
    final: _Normal | None = None  # the normal equations at the final lin, when built
    finishing = False  # the function tolerance was met: one last Gauss-Newton step
    for it in range(1, opts.max_iterations + 1):
        stop_if_asked(should_stop, "adjusting")
        progress((it - 1) / opts.max_iterations)
        # the previous point's normal equations are not needed any more: not held while the
        # new ones are built (on a large block they are hundreds of MB)
        nrm = None
        nrm, rowscale, use_sparse = _normal(
            problem, lin, active, rowscale, use_sparse, opts, it == 1
        )
        if _gradient_small(nrm, lin, opts):
            converged, why, final = True, GRADIENT_TOLERANCE, nrm
            it -= 1  # no step taken
            break

        # While damping is still needed the Gauss-Newton step is not solved for (it would be
        # rejected); it is solved again once the damping has shrunk back to zero, or when no
        # damped step reduces the cost (to tell convergence from a stall).
        if opts.damping and damp.memory > 0:
            z = None
            step = math.inf
        else:
            z, k = _gauss_newton(problem, nrm, opts, use_sparse)
            step = float(np.abs(z).max()) if z.size else 0.0
            if k.size:
                # Exact-penalty weight above the Lagrange multipliers of min ||.||^2 (= 2 k).
                nu = max(nu, 2.5 * float(np.abs(k).max()))
        if step <= tol:
            x, vhat = _apply(problem, lin, nrm, z)
            # the final normal equations are built at the new point below: the old ones and
            # the old linearisation are not held meanwhile (hundreds of MB on a large block)
            del nrm, lin
            nrm = None
            try:
                lin = problem.linearize(x, vhat, active)
            except _NonFiniteError as exc:
                raise ConvergenceError(f"{exc} after the final step") from None
            trace.append((it, lin.phi, TRACE_CLOCK() - t0))
            converged, why = True, STEP_TOLERANCE
            break
        m_old = _merit(lin, rowscale, nu)
        if finishing:
            # after the function tolerance: one Gauss-Newton step, kept if it does not
            # raise the cost (near the minimum it gains the digits the cost cannot show)
            new = _trial(problem, lin, nrm, z, active)
            if new is not None and _merit(new, rowscale, nu) <= m_old * (1 + 1e-13):
                lin = new
                trace.append((it, lin.phi, TRACE_CLOCK() - t0))
            else:
                final = nrm
            converged, why = True, FUNCTION_TOLERANCE
            break
        if not opts.damping:
            x, vhat = _apply(problem, lin, nrm, z)
            try:
                new = problem.linearize(x, vhat, active)
            except _NonFiniteError as exc:
                raise ConvergenceError(
                    f"Gauss-Newton diverged: {exc} at iteration {it}; try damping=True"
                ) from None
        else:
            new = _damped_step(
                problem, lin, nrm, z, active, rowscale, nu, m_old, use_sparse, tol, damp
            )
            if new is None and z is None:
                z, k = _gauss_newton(problem, nrm, opts, use_sparse)
                step = float(np.abs(z).max()) if z.size else 0.0
            if new is None:
                if step <= math.sqrt(tol):
                    converged, why, final = True, ROUNDING_FLOOR, nrm
                    break
                fresh = _refreshed(problem, lin, active)
                if fresh is not None and _merit(fresh, rowscale, nu) > m_old * (1 + 1e-12):
                    # The Gauss-Helmert cost of this linearisation (residuals predicted by the
                    # last step) sat below the true cost at x: continue from the consistent one.
                    lin = fresh
                    continue
                warnings.append(_no_decrease(it, step))
                why, final = NO_DECREASE, nrm
                break
        m_new = _merit(new, rowscale, nu)
        if (
            opts.damping
            and damp.last > 0
            and m_new >= m_old
            and _tie_at_floor(problem, nrm, z, m_old, opts, use_sparse)
        ):
            lin = new
            trace.append((it, lin.phi, TRACE_CLOCK() - t0))
            converged, why = True, ROUNDING_FLOOR
            break
        lin = new
        trace.append((it, lin.phi, TRACE_CLOCK() - t0))
        if _function_tolerance_met(opts, damp, m_old, m_new):
            finishing = True
            damp.memory = 0.0
            continue
        # Rounding floor (large parameter values): the cost no longer changes and the step
        # has stopped shrinking although it is above tolerance.
        if (
            abs(m_old - m_new) <= tol * max(m_old, 1e-300)
            and step <= math.sqrt(tol)
            and step >= 0.5 * prev_step
        ):
            converged, why = True, ROUNDING_FLOOR
            break
        prev_step = step
    if finishing and not converged:  # met at the last iteration: no room for the last step
        converged, why = True, FUNCTION_TOLERANCE
    if not converged and it >= opts.max_iterations and why == ITERATION_LIMIT:
        warnings.append(_t("no convergence within {n} iterations", n=opts.max_iterations))
    # Final normal equations at the final linearisation point, checked before use.
    if final is None:
        nrm = None  # not held while the final ones are built
        final, _ = problem.normal(lin, active, rowscale)
    if use_sparse is None:
        use_sparse = False
    return _Run(lin, final, it, converged, bool(use_sparse), warnings, why, trace)
