"""Outliers in an adjustment: the robust stage (iteratively reweighted least squares, the groups
it flags set aside) and Baarda's data snooping with iterative rejection of whole groups (see
:mod:`.adjustment`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Callable

import numpy as np
from numpy.typing import NDArray
from scipy import special

from ..errors import InputError, NotObservableError
from ..i18n import mark as _t
from .model import AdjustmentOptions, _PriorModel
from .problem import _Problem
from .results import AdjustmentResult, RejectedObservation
from .solve import _Progress, _Run, _run
from .statistics import _finish, chi2_ppf

#: catalogue context of this module's ``_t("...")`` sentences (``make i18n``): the reports'
TR_CONTEXT = "Report"

Array = NDArray[np.float64]

_ROBUST_K = {"huber": 1.5, "cauchy": 2.385}


def _worst(
    result: AdjustmentResult,
    blocks: Sequence[str] | None = None,
    scale: Sequence[float] | None = None,
) -> tuple[int, int, int, float] | None:
    """(block number, group, row, w) of the largest |w| among the groups kept (of the named
    blocks only, when given); with ``scale`` (per block), of the largest ``|w| / scale``, the
    value returned."""
    best = None
    for bi, (name, table) in enumerate(result.residuals.items()):
        if blocks is not None and name not in blocks:
            continue
        w = np.where(table.rejected[:, None], np.nan, np.abs(table.w))
        if scale is not None:
            w = w / scale[bi]
        if w.size == 0 or not np.isfinite(w).any():
            continue
        flat = int(np.nanargmax(w))
        g, i = np.unravel_index(flat, w.shape)
        if best is None or w[g, i] > best[3]:
            best = (bi, int(g), int(i), float(w[g, i]))
    return best


def _cascade(
    problem: _Problem, active: list[NDArray[np.bool_]]
) -> tuple[list[NDArray[np.bool_]], list[tuple[int, int]]]:
    """With eliminated blocks: an eliminated block (an object point) left with fewer rows
    than parameters by the groups set aside cannot be determined; its remaining groups are set
    aside with it (a tie point of two rays goes when one ray is rejected). Returns the new
    active masks and the (block, group) pairs this added."""
    plan = problem.plan
    if plan is None:
        return active, []
    rows = plan.rows_per_block([b.c for b in problem.blocks], active)
    seen = plan.rows_per_block([b.c for b in problem.blocks], None)
    dead = (rows < plan.b) & (seen > 0)
    if not dead.any():
        return active, []
    out, gone = [], []
    for bi, (a, bp) in enumerate(zip(active, plan.plans)):
        hit = a & (bp.point >= 0) & dead[np.maximum(bp.point, 0)]
        gone += [(bi, int(g)) for g in np.flatnonzero(hit)]
        out.append(a & ~hit)
    return out, gone


def _robust(
    problem: _Problem,
    x: Array,
    vhat: list[Array],
    active: list[NDArray[np.bool_]],
    opts: AdjustmentOptions,
    crit: float,
    reporter: _Progress,
    should_stop: Callable[[], bool] | None,
) -> tuple[Array, list[Array], list[NDArray[np.bool_]], dict]:
    """Iteratively reweighted least squares (see the module docstring).

    Returns the robust estimate, its residual estimates, the groups flagged (standardised
    misfit above ``crit``) and a summary (tuning constant, rounds, scale, misfits per row).
    """
    k = opts.robust_k if opts.robust_k is not None else _ROBUST_K[opts.robust]
    if not k > 0:
        raise InputError(f"robust_k must be > 0, got {k}")
    blocks = problem.blocks
    weights = [np.ones(b.groups) for b in blocks]
    if opts.robust_blocks is None:
        chosen = list(range(len(blocks)))
    else:
        known = [b.name for b in blocks]
        unknown = sorted(set(opts.robust_blocks) - set(known))
        if unknown:
            raise InputError(f"robust_blocks: unknown block(s) {', '.join(unknown)}")
        chosen = [i for i, b in enumerate(blocks) if b.name in opts.robust_blocks]
    # Scale from the observation blocks proper (a-priori parameter values have tiny misfits
    # that would drag the median down); all chosen blocks when there are no others.
    scale_blocks = [i for i in chosen if not isinstance(blocks[i].func, _PriorModel)]
    if not scale_blocks:
        scale_blocks = chosen
    rounds = 0
    scale = 1.0
    u_rows: list[Array] = []
    try:
        for rounds in range(1, opts.robust_iterations + 1):
            problem.weights = weights
            # The first round converges from the approximate values; later rounds start at
            # the previous estimate and take a few steps each (the weights and the estimate
            # converge together).
            short = replace(opts, max_iterations=min(4, opts.max_iterations))
            inner = opts if rounds == 1 else short
            run = _run(problem, x, vhat, active, inner, reporter, should_stop, initial=rounds == 1)
            x, vhat = run.lin.x, run.lin.vhat
            # Unweighted whitened misclosures at the estimate (the linearisation holds them
            # multiplied by sqrt(weight)).
            u_rows = [bl.wbar / np.sqrt(w)[:, None] for bl, w in zip(run.lin.blocks, weights)]
            u = [np.sqrt(np.sum(r * r, axis=1) / r.shape[1]) for r in u_rows]
            ref = [math.sqrt(chi2_ppf(0.5, int(b.c or 1)) / int(b.c or 1)) for b in blocks]
            pool = np.concatenate([u[i][active[i]] / ref[i] for i in scale_blocks] or [np.zeros(0)])
            scale = float(np.median(pool)) if pool.size else 1.0
            # never below the a-priori unit weight: measurements that fit as well as their
            # stated sigmas (or better, when those are pessimistic) are not outliers, the same
            # reference as data snooping's
            scale = max(scale, 1.0) if np.isfinite(scale) else 1.0
            new = []
            for i, ui in enumerate(u):
                t = ui / (k * scale)
                if i not in chosen:
                    new.append(np.ones_like(ui))
                elif opts.robust == "huber":
                    new.append(np.where(t <= 1.0, 1.0, 1.0 / np.where(t > 0, t, 1.0)))
                else:
                    new.append(1.0 / (1.0 + t * t))
            change = max(
                (float(np.max(np.abs(a - b))) for a, b in zip(new, weights) if a.size), default=0.0
            )
            weights = new
            if change < 1e-2:
                break
    finally:
        problem.weights = None
    flagged = [
        a & (np.sqrt(np.sum(r * r, axis=1) / r.shape[1]) / scale > crit) & (i in chosen)
        for i, (r, a) in enumerate(zip(u_rows, active))
    ]
    u_std = [r / scale for r in u_rows]
    return x, vhat, flagged, {"k": k, "rounds": rounds, "scale": scale, "u": u_std}


@dataclass
class _RobustStage:
    """What the robust stage hands to the ordinary adjustment."""

    x: Array
    vhat: list[Array]
    active: list[NDArray[np.bool_]]
    run: _Run | None  # the adjustment without the flagged groups (None: they are kept)
    rejected: list[RejectedObservation]
    text: str
    warnings: list[str]


def _robust_stage(
    problem: _Problem,
    x: Array,
    vhat: list[Array],
    active: list[NDArray[np.bool_]],
    opts: AdjustmentOptions,
    crit: float,
    reporter: _Progress,
    should_stop: Callable[[], bool] | None,
) -> _RobustStage:
    """The robust estimate (:func:`_robust`), then the adjustment without the groups it flagged
    (and the eliminated blocks they leave undetermined), unless that is not observable."""
    obs = problem.blocks
    rejected: list[RejectedObservation] = []
    warnings: list[str] = []
    x, vhat, flagged, rob = _robust(problem, x, vhat, active, opts, crit, reporter, should_stop)
    text = _t(
        "{method} reweighting (k = {k:g} robust scale units, {rounds} rounds, robust scale "
        "{scale:.3g}), groups with a standardised misfit above {critical:.2f} set aside",
        method=opts.robust.capitalize(),
        k=rob["k"],
        rounds=rob["rounds"],
        scale=rob["scale"],
        critical=crit,
    )
    trial = [a & ~f for a, f in zip(active, flagged)]
    trial, gone = _cascade(problem, trial)
    try:  # the adjustment without the flagged groups: kept as the final run
        run = _run(problem, x, vhat, trial, opts, reporter, should_stop, initial=False)
    except NotObservableError:
        warnings.append(
            _t(
                "robust estimation: setting aside the {n} groups it flagged would leave the "
                "adjustment not observable; they are kept",
                n=int(sum(f.sum() for f in flagged)),
            )
        )
        return _RobustStage(x, vhat, active, None, rejected, text, warnings)
    for bj, gj in gone:
        flagged[bj][gj] = True
    for bi, f in enumerate(flagged):
        for g in np.flatnonzero(f):
            u = rob["u"][bi][g]
            rejected.append(
                RejectedObservation(
                    obs[bi].name,
                    obs[bi].labels[g],
                    obs[bi].row_names[int(np.argmax(np.abs(u)))],
                    float(u[int(np.argmax(np.abs(u)))]),
                    0,
                )
            )
    return _RobustStage(x, vhat, trial, run, rejected, text, warnings)


def _snoop(
    problem: _Problem,
    run: _Run,
    result: AdjustmentResult,
    active: list[NDArray[np.bool_]],
    opts: AdjustmentOptions,
    crit: float,
    want_cov: bool,
    rejected: list[RejectedObservation],
    warnings: list[str],
    reporter: _Progress,
    should_stop: Callable[[], bool] | None,
) -> AdjustmentResult:
    """Baarda's data snooping from ``run`` (and its ``result``): the group of the largest
    standardised residual above ``crit`` set aside and the adjustment repeated, until none is
    above; returns the last result, appends what it set aside to ``rejected`` and its notes to
    ``warnings``."""
    if not result.converged:
        warnings.append(_t("data snooping skipped: the adjustment did not converge"))
        return result
    obs = problem.blocks
    round_no = 0
    scale = None  # per group: each block's critical value over the per-observation one
    if opts.snooping_per_group:
        alpha = opts.snooping_alpha
        scale = [float(special.ndtri(1 - alpha / (2 * max(int(b.o), 1)))) / crit for b in obs]
    while True:
        worst = _worst(result, opts.snooping_blocks, scale)
        if worst is None or worst[3] <= crit:
            break
        if len(rejected) >= opts.max_rejections:
            warnings.append(
                _t(
                    "data snooping stopped at max_rejections = {n} with |w| = {w:.2f} "
                    "still above {critical:.2f}",
                    n=opts.max_rejections,
                    w=worst[3],
                    critical=crit,
                )
            )
            break
        round_no += 1
        bi, g, i, wv = worst
        b = obs[bi]
        lo = 1.0 - 0.5**round_no
        reporter.span(lo, lo + 0.5 ** (round_no + 1))
        trial = [a.copy() for a in active]
        trial[bi][g] = False
        trial, gone = _cascade(problem, trial)
        try:
            new_run = _run(
                problem,
                result.x,
                run.lin.vhat,
                trial,
                opts,
                reporter,
                should_stop,
                initial=False,
            )
            new_result = _finish(problem, new_run, trial, opts, want_cov)
        except NotObservableError:
            warnings.append(
                _t(
                    "data snooping stopped: rejecting {block} / {label} (|w| = {w:.2f}) "
                    "would make the adjustment not observable; it is kept",
                    block=b.name,
                    label=b.labels[g],
                    w=wv,
                )
            )
            break
        if not new_run.converged:
            warnings.append(
                _t(
                    "data snooping stopped: without {block} / {label} the adjustment did "
                    "not converge; it is kept",
                    block=b.name,
                    label=b.labels[g],
                )
            )
            break
        signed = float(result.residuals[b.name].w[g, i])
        rejected.append(RejectedObservation(b.name, b.labels[g], b.row_names[i], signed, round_no))
        for bj, gj in gone:
            lab = obs[bj].labels[gj]
            rejected.append(
                RejectedObservation(obs[bj].name, lab, "(with its point)", math.nan, round_no)
            )
        active, run, result = trial, new_run, new_result
    untested = sum(
        int((np.isnan(t.w) & ~t.rejected[:, None]).sum()) for t in result.residuals.values()
    )
    if untested:
        warnings.append(
            _t(
                "{n} observation rows have a redundancy number of about zero and cannot "
                "be tested by data snooping",
                n=untested,
            )
        )
    return result
