"""Observability of an adjustment: the condition of the Jacobi-scaled ``N + C'C`` (dense
eigen-decomposition up to a few thousand parameters, a sparse LU with a 1-norm condition
estimate above), and, when it is (near) singular, the parameters of its null space named in a
:class:`~lidarphoto.core.errors.NotObservableError` (see :mod:`.adjustment`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from ..errors import AdjustmentError, NotObservableError
from .problem import _Normal
from .schur import ReducedNormal, SingularSystem

Array = NDArray[np.float64]

# Largest n for which the observability check is a dense eigen-decomposition every time.
_DENSE_ANALYSIS_MAX_N = 3000
# Largest n for which a failed sparse check is repeated densely to name the parameters.
_DENSE_FALLBACK_MAX_N = 6000
# A parameter takes part in a near-null direction when its component exceeds this share of the
# largest component.
_NULL_COMPONENT_SHARE = 0.1
# Eigenvalues below this many eps (relative to the largest) are an exact null space (the
# rounding error of a zero eigenvalue is a few eps).
_EXACT_NULL_EPS = 50.0
# Maximum number of names quoted in an error message (the full list is on the exception).
_MAX_NAMES_IN_MESSAGE = 30


def _join_names(names: list[str]) -> str:
    if len(names) <= _MAX_NAMES_IN_MESSAGE:
        return ", ".join(names)
    shown = ", ".join(names[:_MAX_NAMES_IN_MESSAGE])
    return f"{shown} and {len(names) - _MAX_NAMES_IN_MESSAGE} more"


def _dense_analysis(M: Array, scale: Array, names: list[str], limit: float) -> float:
    """Eigen-analysis of the (twice) Jacobi-scaled matrix; raises when it is near-singular.

    ``scale`` maps the eigenvectors back to parameter units (``dx = scale * y``).
    """
    ev = np.linalg.eigvalsh(M)
    lmax = float(ev[-1])
    lmin = float(ev[0])
    cond = lmax / lmin if lmin > 0 else math.inf
    if lmax > 0 and cond <= limit:
        return cond
    eps = np.finfo(float).eps
    vals, vecs = np.linalg.eigh(M)
    if lmax > 0:
        null = vals <= lmax / limit
        exact_null = vals <= lmax * _EXACT_NULL_EPS * eps
    else:
        null = exact_null = np.ones(vals.size, dtype=bool)
    involved = np.zeros(vals.size, dtype=bool)
    if exact_null.any():
        # An exact null space: every parameter in its support takes part. The support is
        # read from basis-independent row norms, above the rounding noise of the eigenvectors
        # (about eps over the relative gap to the next eigenvalue).
        rows = np.linalg.norm(vecs[:, exact_null], axis=1)
        rest = vals[~exact_null]
        gap = rest[0] / lmax if rest.size and lmax > 0 else 1.0
        noise = min(_NULL_COMPONENT_SHARE, max(1e-6, 1e3 * eps / max(gap, eps)))
        involved |= rows > noise * rows.max()
    near = null & ~exact_null
    if near.any():
        # Near-null directions: the parameters with a significant share of each direction.
        V = np.abs(vecs[:, near])
        involved |= (V > _NULL_COMPONENT_SHARE * V.max(axis=0)).any(axis=1)
    who = [names[i] for i in np.flatnonzero(involved)]
    nv = scale[:, None] * vecs[:, null]
    nv /= np.linalg.norm(nv, axis=0)
    exact = bool(exact_null.any())
    if exact:
        msg = (
            f"Not observable: the observations do not determine {_join_names(who)} (they can "
            "move together without changing any observation); add a datum (fix or weight "
            "one of them) or observations that connect them"
        )
    else:
        msg = (
            f"Not observable: the normal matrix is ill-conditioned (condition number "
            f"{cond:.3g} > limit {limit:.3g}); the observations barely determine "
            f"{_join_names(who)} (nearly collinear or badly configured observations); add "
            "observations with a better geometry or weight one of them"
        )
    raise NotObservableError(msg, parameters=who, null_vectors=nv, condition_number=cond)


def _check_observability(
    nrm: _Normal, names: list[str], limit: float, constraint_names: Sequence[str] = ()
) -> float:
    """Condition number of the Jacobi-scaled ``N + C'C``; raises NotObservableError."""
    if isinstance(nrm, ReducedNormal):
        return _check_reduced(nrm, names, limit, constraint_names)
    n = nrm.ns.size
    Ms = nrm.Ns
    if nrm.Cs is not None:
        mc = nrm.Cs.shape[0]
        if mc > n:
            raise AdjustmentError(
                f"{mc} hard constraint rows for {n} parameters: they cannot be independent"
            )
        if mc * n <= 2e7:
            s = np.linalg.svd(nrm.Cs.toarray(), compute_uv=False)
            if s.size and (s[-1] <= s[0] * 1e-8 or s[0] == 0):
                raise AdjustmentError(
                    "The hard constraints are linearly dependent (redundant or contradictory): "
                    + ", ".join(constraint_names)
                )
        Ms = (Ms + nrm.Cs.T @ nrm.Cs).tocsr()
    e = np.sqrt(np.clip(Ms.diagonal(), 0.0, None))
    e = np.where(e > 0, e, 1.0)
    Mss = sp.csr_matrix(sp.diags(1.0 / e) @ Ms @ sp.diags(1.0 / e))
    scale = 1.0 / (nrm.d * e)
    if n <= _DENSE_ANALYSIS_MAX_N:
        return _dense_analysis(Mss.toarray(), scale, names, limit)
    cond = math.inf
    try:
        lu = spla.splu(
            Mss.tocsc(),
            permc_spec="MMD_AT_PLUS_A",
            diag_pivot_thresh=0.0,
            options={"SymmetricMode": True},
        )
        op = spla.LinearOperator((n, n), matvec=lu.solve, rmatvec=lu.solve, dtype=np.float64)
        inv_norm = float(spla.onenormest(op))
        norm1 = float(abs(Mss).sum(axis=0).max())
        if np.isfinite(inv_norm):
            cond = norm1 * inv_norm
    except RuntimeError:
        cond = math.inf
    if cond <= limit:
        return cond
    if n <= _DENSE_FALLBACK_MAX_N:
        return _dense_analysis(Mss.toarray(), scale, names, limit)
    unseen = [names[i] for i in np.flatnonzero(nrm.Ns.diagonal() <= 0)]
    extra = f"; parameters without any observation: {_join_names(unseen)}" if unseen else ""
    raise NotObservableError(
        f"Not observable: the normal matrix of {n} parameters is singular or ill-conditioned "
        f"(condition estimate {cond:.3g} > limit {limit:.3g}) and too large to name the "
        f"parameters involved{extra}; check the datum and the connectivity of the network",
        parameters=unseen,
        condition_number=cond,
    )


def _check_reduced(
    red: ReducedNormal, names: list[str], limit: float, constraint_names: Sequence[str]
) -> float:
    """Observability of a reduced system: each eliminated block, then ``S + C~'C~``."""
    plan = red.plan
    cond_p = red.point_conditions()
    bad = np.flatnonzero(~(cond_p <= limit))
    if bad.size:
        who = [names[i] for i in plan.elim[bad].ravel()]
        worst = float(np.max(cond_p[bad]))
        raise NotObservableError(
            f"Not observable: the observations do not determine {_join_names(who)} "
            f"({bad.size} eliminated block(s), condition number up to {worst:.3g} > limit "
            f"{limit:.3g}); each of them needs observations that fix it on their own (an "
            "object point needs rays from two or more images that intersect at an angle)",
            parameters=who,
            condition_number=worst,
        )
    try:
        S, Ct = red.observability_parts()
    except SingularSystem:
        raise NotObservableError(
            "Not observable: the eliminated blocks are singular", parameters=[]
        ) from None
    sub = _Normal(A=None, d=red.d[plan.reduced], Ns=S, ns=red.g_r, Cs=Ct, hs=red.hs)
    rnames = [names[i] for i in plan.reduced]
    cond = _check_observability(sub, rnames, limit, constraint_names)
    return max(cond, float(np.max(cond_p)) if cond_p.size else 1.0)
