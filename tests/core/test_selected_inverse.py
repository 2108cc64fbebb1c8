"""The sums of the eliminated blocks' cofactors (``selected_inverse.cofactor_sums``): the
entries of the inverse reduced matrix taken once per pair of images and the point sums formed
in place must give what the earlier formulation gave (one entry look-up per pair of
occurrences, whole-array sums), bit for bit, and what the definition gives, summed occurrence
by occurrence in plain loops.
"""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.lsq import schur, selected_inverse
from lidarphoto.core.lsq.adjustment import adjust
from lidarphoto.core.lsq.model import AdjustmentOptions, prior_block
from lidarphoto.core.lsq.schur_plan import _Reducer
from test_schur import small_block


def _earlier(plan, T, Vinv, take):
    """The formulation before the memory work: every pair of occurrences looks its block of
    ``M`` up, each direction is summed into an array of all occurrences, then added."""
    acc = [np.zeros_like(t) for t in T]
    for pl in plan.pairs:
        a, b = plan.sets[pl.s1], plan.sets[pl.s2]
        Ta, Tb = T[pl.s1], T[pl.s2]

        def fwd(items, a=a, b=b, Tb=Tb, o1=pl.o1, o2=pl.o2):
            ra, rb = a.rows[a.sig[o1[items]]], b.rows[b.sig[o2[items]]]
            return take(ra[:, :, None], rb[:, None, :]) @ Tb[o2[items]]

        acc[pl.s1] += _Reducer(pl.o1, pl.n1).sum(fwd, (Ta.shape[1], Tb.shape[2]))
        if pl.mirror:

            def bwd(items, a=a, b=b, Ta=Ta, o1=pl.o1, o2=pl.o2):
                ra, rb = a.rows[a.sig[o1[items]]], b.rows[b.sig[o2[items]]]
                return take(rb[:, :, None], ra[:, None, :]) @ Ta[o1[items]]

            acc[pl.s2] += _Reducer(pl.o2, pl.n2).sum(bwd, (Tb.shape[1], Ta.shape[2]))
    inner = np.zeros((plan.P, plan.b, plan.b))
    for t, A, s in zip(T, acc, plan.sets):
        contrib = np.swapaxes(t, 1, 2) @ A
        for i in range(plan.b):
            for j in range(plan.b):
                inner[:, i, j] += np.bincount(s.point, weights=contrib[:, i, j], minlength=plan.P)
    return inner, [-(A @ Vinv[s.point]) for A, s in zip(acc, plan.sets)]


def _definition(plan, T, Vinv, take):
    """A_o = sum over the occurrences o' at the block of o of M[rows_o, rows_o'] T_o', one
    occurrence at a time (every set against every set)."""
    occ = [(k, o) for k, s in enumerate(plan.sets) for o in range(s.point.size)]
    by_point: dict[int, list] = {}
    for k, o in occ:
        by_point.setdefault(int(plan.sets[k].point[o]), []).append((k, o))
    inner = np.zeros((plan.P, plan.b, plan.b))
    cross = [np.zeros_like(t) for t in T]
    for p, here in by_point.items():
        for k, o in here:
            s = plan.sets[k]
            ro = s.rows[s.sig[o]]
            A = np.zeros(T[k].shape[1:])
            for k2, o2 in here:
                s2 = plan.sets[k2]
                r2 = s2.rows[s2.sig[o2]]
                A += take(ro[:, None], r2[None, :]) @ T[k2][o2]
            inner[p] += T[k][o].T @ A
            cross[k][o] = -A @ Vinv[p]
    return inner, cross


@pytest.mark.parametrize("band", [False, True])
def test_cofactor_sums_equal_the_earlier_sums_and_the_definition(monkeypatch, band):
    """On a self-calibrating block (the exterior orientation varies per ray, the interior is
    shared by the block: two occurrence sets and the pairs between them), with the dense
    inverse and with the band factor: bit for bit the earlier formulation; the definition to
    1e-12 relative (another order of the sums)."""
    x_true, x0, names, block, n_eo, _, elim, extra = small_block(seed=6, n_img=10, n_pt=150)
    ctrl = np.arange(0, elim.shape[0], 9)
    priors = [
        prior_block("control", elim[ctrl].ravel(), extra["pts"][ctrl].ravel(), 0.02),
        prior_block("eo", np.arange(n_eo), x_true[:n_eo], np.tile([0.5] * 3 + [1e-3] * 3, 10)),
    ]
    if band:
        monkeypatch.setattr(schur, "_SELECTED_MIN", 0)
        monkeypatch.setattr(selected_inverse, "_DENSE_SHARE", 0.99)
        monkeypatch.setattr(selected_inverse, "_DENSE_MIN_DEGREE", 0)  # interior: dense part
    seen = []
    real = selected_inverse.cofactor_sums

    def spy(plan, T, Vinv, take):
        T = [t.copy() for t in T]  # the inputs as they came (checked unchanged below)
        out = real(plan, T, Vinv, take)
        seen.append((plan, T, Vinv, take, out))
        return out

    monkeypatch.setattr(schur, "cofactor_sums", spy)
    adjust(x0, names, [block, *priors], options=AdjustmentOptions(eliminate=elim))
    assert len(seen) == 1
    plan, T, Vinv, take, (inner, cross) = seen[0]
    assert len(plan.sets) == 2 and len(plan.pairs) >= 3  # EO and interior sets, their pairs
    T0 = [t.copy() for t in T]
    ref_inner, ref_cross = _earlier(plan, T, Vinv, take)
    assert np.array_equal(inner, ref_inner)
    assert all(np.array_equal(c, r) for c, r in zip(cross, ref_cross))
    assert all(np.array_equal(t, t0) for t, t0 in zip(T, T0))
    def_inner, def_cross = _definition(plan, T, Vinv, take)
    scale = np.abs(def_inner).max()
    assert scale > 0 and np.abs(inner - def_inner).max() <= 1e-12 * scale
    for c, r in zip(cross, def_cross):
        assert np.abs(c - r).max() <= 1e-12 * np.abs(r).max()
