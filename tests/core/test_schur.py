"""The reduced camera system of the least-squares engine (points eliminated by the Schur
complement), its robust stage, inner constraints and the BAL/Snavely pieces of the benchmark.

The reference for every eliminated solve is the engine's own full solve of the same problem
(the path the rest of the project has used and tested), so any difference is an error of the
elimination; independent properties (inner constraints give the minimum trace of the point
covariance; planted blunders are found) are checked besides.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from lidarphoto.core.errors import InputError, NotObservableError
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.collinearity import collinearity_jacobians
from lidarphoto.core.geometry.distortion import BrownConrady
from lidarphoto.core.geometry.snavely import snavely_project
from lidarphoto.core.lsq import schur
from lidarphoto.core.lsq.adjustment import adjust
from lidarphoto.core.lsq.model import AdjustmentOptions, Constraint, GaussMarkovBlock, prior_block
from numpy.testing import assert_allclose

BAL = Path(__file__).resolve().parents[3] / "shared" / "data" / "bal"


def small_block(seed: int = 1, blunders: int = 0, n_img: int = 8, n_pt: int = 120):
    """A strip of images over random points, with self-calibration (f, x0, y0, k1, k2, k3,
    p1, p2); returns (x_true, x0, names, image block, n_eo, n_int, elim, extra)."""
    rng = np.random.default_rng(seed)
    cam = Camera("c", 8.0, 0.002, 3000, 2000, 0.01, -0.02, BrownConrady(k1=-1e-3, k2=2e-6))
    ni = 3 + cam.distortion.n_params
    pts = np.column_stack(
        [rng.uniform(-50, 50, n_pt), rng.uniform(-30, 30, n_pt), rng.uniform(-5, 5, n_pt)]
    )
    eos = np.column_stack(
        [
            np.linspace(-40, 40, n_img),
            rng.uniform(-3, 3, n_img),
            100 + rng.uniform(-3, 3, n_img),
            rng.normal(0, 0.03, (n_img, 2)),
            rng.normal(0, 0.05, n_img),
        ]
    )
    img, pid, px = [], [], []
    for i in range(n_img):
        p = collinearity_jacobians(pts, eos[i], cam, wrt=())["pixels"]
        ok = np.flatnonzero(cam.in_frame(p, 10.0))
        img += [i] * ok.size
        pid.append(ok)
        px.append(p[ok])
    img, pid, px = np.array(img), np.concatenate(pid), np.vstack(px)
    keep = np.bincount(pid, minlength=n_pt)[pid] >= 2
    img, pid, px = img[keep], pid[keep], px[keep]
    used = np.unique(pid)
    remap = np.full(n_pt, -1)
    remap[used] = np.arange(used.size)
    pid, pts = remap[pid], pts[used]
    n_pt = pts.shape[0]
    px = px + rng.normal(0, 0.3, px.shape)
    bad = rng.choice(img.size, blunders, replace=False) if blunders else np.zeros(0, int)
    px[bad] += rng.choice([-1, 1], (bad.size, 2)) * rng.uniform(15, 40, (bad.size, 2))
    n_eo = 6 * n_img
    names = [f"eo{i} {k}" for i in range(n_img) for k in range(6)]
    names += [f"int {n}" for n in cam.interior_names]
    names += [f"p{j} {c}" for j in range(n_pt) for c in "XYZ"]
    x_true = np.concatenate([eos.ravel(), cam.interior_params, pts.ravel()])
    idx = np.column_stack(
        [
            6 * img[:, None] + np.arange(6),
            n_eo + ni + 3 * pid[:, None] + np.arange(3),
            np.broadcast_to(n_eo + np.arange(ni), (img.size, ni)),
        ]
    )

    def model(xl):
        c = cam.with_interior(xl[0, 9:])
        out = collinearity_jacobians(xl[:, 6:9], xl[:, :6], c)
        return out["pixels"], np.concatenate([out["eo"], out["point"], out["interior"]], axis=2)

    block = GaussMarkovBlock(
        "img",
        px,
        0.3,
        idx,
        model,
        labels=[f"{i}/{j}" for i, j in zip(img, pid)],
        row_names=("col", "row"),
    )
    x0 = x_true + np.concatenate(
        [
            rng.normal(0, [1, 1, 1, 0.01, 0.01, 0.01] * n_img),
            np.zeros(ni),
            rng.normal(0, 0.5, 3 * n_pt),
        ]
    )
    elim = n_eo + ni + np.arange(3 * n_pt).reshape(n_pt, 3)
    return x_true, x0, names, block, n_eo, ni, elim, {"bad": bad, "pts": pts}


def _compare(full, red, tol=1e-8):
    assert_allclose(red.x, full.x, rtol=0, atol=tol * np.maximum(1.0, np.abs(full.x)).max())
    # (a held parameter's sigma is 0 in one and rounding noise, ~1e-11, in the other)
    assert_allclose(red.std, full.std, rtol=1e-6, atol=1e-9 * full.std.max())
    assert red.redundancy == full.redundancy
    assert abs(red.sigma0 / full.sigma0 - 1) < 1e-9
    for name, t in full.residuals.items():
        assert_allclose(red.residuals[name].w, t.w, rtol=1e-6, atol=1e-7)
        assert_allclose(red.residuals[name].redundancy_numbers, t.redundancy_numbers, atol=1e-8)
    Q = red.cofactor_blocks
    ref_rr = full.cofactor[np.ix_(Q.reduced_index, Q.reduced_index)]
    assert_allclose(Q.Q_reduced, ref_rr, rtol=1e-6, atol=1e-9 * np.abs(ref_rr).max())
    p = Q.eliminated_index
    ref_pp = full.cofactor[p[:, :, None], p[:, None, :]]
    assert_allclose(Q.Q_eliminated, ref_pp, rtol=1e-6, atol=1e-9 * np.abs(ref_pp).max())


def test_eliminated_solve_equals_the_full_one():
    x_true, x0, names, block, n_eo, ni, elim, extra = small_block()
    ctrl = np.arange(0, elim.shape[0], 9)
    priors = [
        prior_block("control", elim[ctrl].ravel(), extra["pts"][ctrl].ravel(), 0.02),
        prior_block(
            "eo", np.arange(n_eo), x_true[:n_eo], np.tile([0.5] * 3 + [1e-3] * 3, n_eo // 6)
        ),
    ]
    # a hard constraint on a reduced parameter too (the principal point x0 held)
    held = Constraint(
        "x0 held",
        np.array([[n_eo + 1]]),
        lambda xl: ((xl - x_true[n_eo + 1])[:, :1], np.ones((1, 1, 1))),
    )
    opts = AdjustmentOptions(snooping=True)
    full = adjust(x0, names, [block, *priors], [held], opts)
    red = adjust(
        x0, names, [block, *priors], [held], AdjustmentOptions(snooping=True, eliminate=elim)
    )
    assert full.converged and red.converged and full.cofactor_blocks is None
    assert red.cofactor is None and red.cofactor_blocks is not None
    _compare(full, red)
    # covariance_of agrees with the full matrix for reduced and point blocks
    i = np.arange(n_eo, n_eo + ni)
    ref = full.covariance[np.ix_(i, i)]
    assert_allclose(red.covariance_of(i), ref, rtol=1e-6, atol=1e-9 * np.abs(ref).max())
    ref = full.covariance[np.ix_(elim[3], elim[3])]
    # near-zero off-diagonal terms differ by rounding (1e-11 seen): an absolute floor as above
    assert_allclose(red.covariance_of(elim[3]), ref, rtol=1e-6, atol=1e-9 * np.abs(ref).max())
    with pytest.raises(InputError, match="span several"):
        red.covariance_of(np.r_[elim[3], 0])


def test_sparse_reduced_system_equals_the_dense_one(monkeypatch):
    x_true, x0, names, block, n_eo, _ni, elim, extra = small_block(seed=4)
    ctrl = np.arange(0, elim.shape[0], 7)
    pri = prior_block("control", elim[ctrl].ravel(), extra["pts"][ctrl].ravel(), 0.02)
    eo = prior_block("eo", np.arange(n_eo), x_true[:n_eo], 1.0)
    dense = adjust(x0, names, [block, pri, eo], options=AdjustmentOptions(eliminate=elim))
    monkeypatch.setattr(schur, "_DENSE_MAX", 10)
    monkeypatch.setattr(schur, "_SPARSE_MAX_DENSITY", 1.0)  # this small block is dense
    sparse = adjust(x0, names, [block, pri, eo], options=AdjustmentOptions(eliminate=elim))
    assert dense.solver == "dense" and sparse.solver == "sparse"  # two paths compared
    assert_allclose(sparse.x, dense.x, atol=1e-9 * np.abs(dense.x).max())
    assert_allclose(sparse.std, dense.std, rtol=1e-8)


def _inner_constraint(P0: np.ndarray):
    q = P0 - P0.mean(axis=0)
    G = np.zeros((7, P0.shape[0], 3))
    G[0, :, 0] = G[1, :, 1] = G[2, :, 2] = 1.0
    G[3, :, 1], G[3, :, 2] = -q[:, 2], q[:, 1]
    G[4, :, 0], G[4, :, 2] = q[:, 2], -q[:, 0]
    G[5, :, 0], G[5, :, 1] = -q[:, 1], q[:, 0]
    G[6] = q
    Gm = G.reshape(7, -1)
    return Gm, lambda xl: ((Gm @ (xl[0] - P0.ravel()))[None], Gm[None])


def test_inner_constraints_on_eliminated_points():
    """A free network: inner constraints on the object points (which are eliminated) equal the
    full solve, hold at the solution, and give the smallest trace of the point covariance of
    all datum choices (checked against minimal constraints)."""
    _x_true, x0, names, block, _n_eo, _ni, elim, _extra = small_block(seed=2)
    P0 = x0[elim]
    Gm, fn = _inner_constraint(P0)
    inner = Constraint("inner", elim.ravel()[None], fn)
    full = adjust(x0, names, [block], [inner])
    red = adjust(x0, names, [block], [inner], AdjustmentOptions(eliminate=elim))
    _compare(full, red, tol=1e-7)
    assert np.abs(Gm @ (red.x[elim].ravel() - P0.ravel())).max() < 1e-6
    # minimal constraints: first image's orientation and one coordinate of the last one
    held = np.r_[np.arange(6), 6 * 7]
    vals = x0[held]
    minimal = Constraint("minimal", held[None], lambda xl: ((xl[0] - vals)[None], np.eye(7)[None]))
    mini = adjust(x0, names, [block], [minimal], AdjustmentOptions(eliminate=elim))
    tr_inner = np.trace(red.cofactor_blocks.Q_eliminated, axis1=1, axis2=2).sum()
    tr_min = np.trace(mini.cofactor_blocks.Q_eliminated, axis1=1, axis2=2).sum()
    assert tr_inner < tr_min
    # the datum does not change the fit
    assert abs(mini.omega / red.omega - 1) < 1e-8
    # without a datum the null space is named
    with pytest.raises(NotObservableError, match="eo0 0"):
        adjust(x0, names, [block], options=AdjustmentOptions(eliminate=elim))


def test_robust_stage_then_snooping_find_planted_blunders():
    """Eight measurements with 15-40 px errors among ~400: Huber reweighting then data
    snooping reject every one of them; good measurements are rejected only as false alarms
    (about one expected at alpha 0.001 for 800 rows, at most four allowed: Poisson p < 0.5 %),
    marginally (|w| < 4.5 where the blunders give |w| > 30); and the estimate equals plain
    least squares without the rejected measurements."""
    x_true, x0, names, block, n_eo, _ni, elim, extra = small_block(seed=3, blunders=8)
    ctrl = np.arange(0, elim.shape[0], 6)
    pri = prior_block("control", elim[ctrl].ravel(), extra["pts"][ctrl].ravel(), 0.02)
    eo = prior_block("eo", np.arange(n_eo), x_true[:n_eo], 1.0)
    opts = AdjustmentOptions(
        robust="huber",
        snooping=True,
        eliminate=elim,
        robust_blocks=["img"],
        snooping_blocks=["img"],
    )
    res = adjust(x0, names, [block, pri, eo], options=opts)
    rej = set(np.flatnonzero(res.residuals["img"].rejected))
    bad = set(extra["bad"].tolist())
    assert bad <= rej and len(rej - bad) <= 4, (sorted(bad), sorted(rej))
    w = {r.label: abs(r.w) for r in res.rejected}
    assert all(w[block.labels[i]] > 30 for i in bad)
    assert all(w[block.labels[i]] < 4.5 for i in rej - bad)
    assert any(r.iteration == 0 for r in res.rejected)  # the robust stage set some aside
    assert "Huber" in res.outlier_method and "Baarda" in res.outlier_method
    keep = np.array([i not in rej for i in range(block.observed.shape[0])])
    # the same estimate from plain least squares on the measurements kept
    ref = adjust(
        x0, names, [_subset(block, keep), pri, eo], options=AdjustmentOptions(eliminate=elim)
    )
    assert_allclose(res.x, ref.x, atol=1e-6 * np.abs(ref.x).max())


def _subset(block: GaussMarkovBlock, keep: np.ndarray) -> GaussMarkovBlock:
    """The block restricted to some groups (its model depends on x_local only, so it is
    reused)."""
    return GaussMarkovBlock(
        block.name,
        block.observed[keep],
        0.3,
        block.param_index[keep],
        block.model,
        row_names=block.row_names,
    )


def test_elimination_refuses_what_it_cannot_do():
    x_true, x0, names, block, n_eo, _ni, elim, _extra = small_block(seed=5)
    # a group depending on two eliminated points
    two = GaussMarkovBlock(
        "dist",
        np.zeros((1, 1)),
        1.0,
        np.r_[elim[0], elim[1]][None],
        lambda xl: (np.zeros((1, 1)), np.ones((1, 1, 6))),
    )
    with pytest.raises(InputError, match="two eliminated blocks"):
        adjust(x0, names, [block, two], options=AdjustmentOptions(eliminate=elim))
    with pytest.raises(InputError, match="appears twice"):
        adjust(x0, names, [block], options=AdjustmentOptions(eliminate=np.r_[elim, elim[:1]]))
    # a point seen by one image only: named
    one = block.param_index[:, 6] == elim[5, 0]
    keep = ~one
    keep[np.flatnonzero(one)[0]] = True
    eo = prior_block("eo", np.arange(n_eo), x_true[:n_eo], 1.0)
    with pytest.raises(NotObservableError, match="p5 X"):
        adjust(x0, names, [_subset(block, keep), eo], options=AdjustmentOptions(eliminate=elim))


def test_snavely_jacobians_against_finite_differences():
    rng = np.random.default_rng(0)
    n = 40
    cam = np.column_stack(
        [
            rng.normal(0, 0.5, (n, 3)),
            rng.normal(0, 1, (n, 2)),
            rng.normal(-8, 1, n),
            rng.uniform(400, 600, n),
            rng.normal(0, 0.1, n),
            rng.normal(0, 0.01, n),
        ]
    )
    X = rng.normal(0, 1, (n, 3))
    _, jc, jp = snavely_project(cam, X)
    for j in range(9):
        h = 1e-6 * max(1.0, float(np.abs(cam[:, j]).mean()))
        cp, cm = cam.copy(), cam.copy()
        cp[:, j] += h
        cm[:, j] -= h
        num = (snavely_project(cp, X, False) - snavely_project(cm, X, False)) / (2 * h)
        assert np.abs(num - jc[:, :, j]).max() < 1e-7 * np.abs(jc[:, :, j]).max()
    for j in range(3):
        xp, xm = X.copy(), X.copy()
        xp[:, j] += 1e-6
        xm[:, j] -= 1e-6
        num = (snavely_project(cam, xp, False) - snavely_project(cam, xm, False)) / 2e-6
        assert np.abs(num - jp[:, :, j]).max() < 1e-7 * np.abs(jp[:, :, j]).max()


def test_snavely_compiled_kernel_equals_numpy():
    """The numba kernel (core/geometry/snavely_numba.py) and the numpy code: the same
    projections and Jacobians to rounding, also for rotations below the series threshold."""
    pytest.importorskip("numba")
    rng = np.random.default_rng(3)
    n = 200
    cam = np.column_stack([rng.normal(0, 0.5, (n, 3)), rng.normal(0, 1, (n, 2)),
                           rng.normal(-8, 1, n), rng.uniform(400, 600, n),
                           rng.normal(0, 0.1, n), rng.normal(0, 0.01, n)])  # fmt: skip
    cam[:20, :3] *= 1e-6  # |r| < 1e-4: the series branch
    X = rng.normal(0, 1, (n, 3))
    ref = snavely_project(cam, X, compiled=False)
    got = snavely_project(cam, X, compiled=True)
    for a, b in zip(ref, got):
        np.testing.assert_allclose(b, a, rtol=1e-12, atol=1e-12 * np.abs(a).max())
    u = snavely_project(cam, X, jacobian=False, compiled=True)
    np.testing.assert_allclose(u, ref[0], rtol=1e-12, atol=1e-9)
    # the joint Jacobian (camera columns, then point columns), compiled and numpy
    J_ref = np.concatenate(ref[1:], axis=2)
    for compiled in (True, False):
        uj, J = snavely_project(cam, X, compiled=compiled, joint=True)
        np.testing.assert_allclose(uj, ref[0], rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(J, J_ref, rtol=1e-12, atol=1e-12 * np.abs(J_ref).max())


@pytest.mark.skipif(not (BAL / "dubrovnik-3-7-pre.txt").is_file(), reason="BAL data not here")
def test_bal_reader_and_projection_on_dubrovnik():
    from lidarphoto.core.io.bal import read_bal

    p = read_bal(BAL / "dubrovnik-3-7-pre.txt")
    assert (
        p.cameras.shape == (3, 9) and p.points.shape == (7, 3) and p.observations.shape == (19, 2)
    )
    u = snavely_project(p.cameras[p.camera_index], p.points[p.point_index], jacobian=False)
    # the "pre" start is the incremental reconstruction: residuals of a few pixels, and the
    # cost the shared MANIFEST states (2.764220e3)
    cost = 0.5 * np.sum((u - p.observations) ** 2)
    assert abs(cost / 2.764220e3 - 1) < 1e-6


@pytest.mark.parametrize("sparse", [False, True])
@pytest.mark.parametrize("datum", ["priors", "constraints"])
def test_compiled_reduced_system_equals_numpy(monkeypatch, datum, sparse):
    """A BAL-like block (Snavely's model, every camera with its own 9 parameters, so the
    compiled per-block sums and the compiled dense reduced system both run): the same
    adjustment with the numba kernels and with the numpy code of core/lsq/schur.py, to
    rounding; the datum by priors on the cameras, or by hard constraints (the dense system's
    bordered solve). ``sparse``: the reduced system of the large blocks (sparse LU), whose
    point factors, point products, right-hand side and back-substitution are compiled."""
    pytest.importorskip("numba")
    from lidarphoto.core.lsq import schur

    if sparse:
        monkeypatch.setattr(schur, "_DENSE_MAX", 0)
        monkeypatch.setattr(schur, "_SPARSE_MAX_DENSITY", 2.0)

    rng = np.random.default_rng(4)
    nc, npt = 6, 80
    cams = np.column_stack([rng.normal(0, 0.1, (nc, 3)), rng.normal(0, 0.5, (nc, 2)),
                            np.full(nc, -10.0), np.full(nc, 500.0), np.zeros((nc, 2))])  # fmt: skip
    pts = rng.normal(0, 1.5, (npt, 3))
    ci = np.repeat(np.arange(nc), npt)
    pi = np.tile(np.arange(npt), nc)
    keep = rng.random(ci.size) < 0.8
    ci, pi = ci[keep], pi[keep]
    obs = snavely_project(cams[ci], pts[pi], jacobian=False) + rng.normal(0, 0.5, (ci.size, 2))
    x_true = np.concatenate([cams.ravel(), pts.ravel()])
    x0 = x_true + np.concatenate([rng.normal(0, 1e-3, 9 * nc), rng.normal(0, 0.05, 3 * npt)])
    names = [f"c{c} {k}" for c in range(nc) for k in range(9)]
    names += [f"p{p} {a}" for p in range(npt) for a in "XYZ"]
    idx = np.concatenate([ci[:, None] * 9 + np.arange(9), 9 * nc + pi[:, None] * 3 + np.arange(3)],
                         axis=1)  # fmt: skip

    def model(xl):
        u, jc, jp = snavely_project(xl[:, :9], xl[:, 9:])
        return u, np.concatenate([jc, jp], axis=2)

    block = GaussMarkovBlock("obs", obs, 0.5, idx, model)
    sig = np.tile([1e-3] * 6 + [1.0, 1e-3, 1e-3], nc)
    prior = prior_block("cams", np.arange(9 * nc), cams.ravel(), sig)
    elim = 9 * nc + np.arange(3 * npt).reshape(npt, 3)
    opts = AdjustmentOptions(eliminate=elim)
    blocks, cons = [block, prior], []
    if datum == "constraints":
        # camera 0's rotation and translation and camera 1's first translation held; the
        # focal lengths and distortions of all cameras observed
        held = np.array([0, 1, 2, 3, 4, 5, 12])
        vals = x0[held]
        cons = [Constraint("gauge", held[None], lambda xl: ((xl[0] - vals)[None], np.eye(7)[None]))]
        keep_f = np.flatnonzero(np.tile(np.arange(9) >= 6, nc))
        blocks = [block, prior_block("interior", keep_f, cams.ravel()[keep_f], sig[keep_f])]
    monkeypatch.setattr(schur, "_COMPILED_MIN", 0)  # compiled at any size
    fast = adjust(x0, names, blocks, cons, options=opts)
    monkeypatch.setattr(schur, "_COMPILED", False)
    slow = adjust(x0, names, blocks, cons, options=opts)
    assert fast.converged and slow.converged and fast.iterations == slow.iterations
    assert_allclose(fast.x, slow.x, rtol=1e-10, atol=1e-10)
    # (held parameters: sigma 0, to rounding of the bordered inverse)
    assert_allclose(fast.std, slow.std, rtol=1e-8, atol=1e-9)
    assert fast.omega == pytest.approx(slow.omega, rel=1e-10)


def test_compiled_dense_reduced_system_with_scattered_rows():
    """The compiled dense reduced system (core/lsq/schur_numba.py) on occurrences whose
    reduced rows are not contiguous runs and blocks of 2 parameters (its general loop),
    against the sums written out in numpy."""
    pytest.importorskip("numba")
    from lidarphoto.core.lsq.schur_numba import back_substitute, dense_reduced

    rng = np.random.default_rng(7)
    P, b, kk, n_sig, n = 30, 2, 4, 6, 24
    srows = np.array([rng.permutation(n)[:kk] for _ in range(n_sig)], dtype=np.intp)
    point = np.repeat(np.arange(P), rng.integers(1, 5, P)).astype(np.intp)
    rng.shuffle(point)
    osig = rng.integers(0, n_sig, point.size).astype(np.intp)
    T = rng.normal(size=(point.size, kk, b))
    A = rng.normal(size=(P, b, b))
    V = A @ np.swapaxes(A, 1, 2) + np.eye(b)
    g_e = rng.normal(size=(P, b))
    lam = 0.3
    order = np.argsort(point, kind="stable").astype(np.intp)
    start = np.concatenate([[0], np.cumsum(np.bincount(point, minlength=P))]).astype(np.intp)
    K = np.zeros((n, n))
    rhs = np.zeros(n)
    Li, y = dense_reduced(V, lam, g_e, T, order, start, osig, srows, K, rhs)
    Vinv = np.linalg.inv(V + lam * np.eye(b))
    K_ref = np.zeros((n, n))
    rhs_ref = np.zeros(n)
    for o1 in range(point.size):
        p = point[o1]
        r1 = srows[osig[o1]]
        rhs_ref[r1] += T[o1] @ Vinv[p] @ g_e[p]
        for o2 in np.flatnonzero(point == p):
            K_ref[np.ix_(r1, srows[osig[o2]])] -= T[o1] @ Vinv[p] @ T[o2].T
    assert_allclose(K + K.T, K_ref, rtol=1e-12, atol=1e-12)
    assert_allclose(rhs, rhs_ref, rtol=1e-12, atol=1e-12)
    assert_allclose(np.swapaxes(Li, 1, 2) @ Li, Vinv, rtol=1e-12, atol=1e-12)
    assert_allclose(y, np.einsum("pij,pj->pi", Vinv, g_e), rtol=1e-12, atol=1e-12)
    z = rng.normal(size=n)
    ze = back_substitute(g_e, T, point, osig, srows, z, Li)
    acc = -g_e.copy()
    for o in range(point.size):
        acc[point[o]] -= T[o].T @ z[srows[osig[o]]]
    assert_allclose(ze, np.einsum("pij,pj->pi", Vinv, acc), rtol=1e-12, atol=1e-12)


def test_compiled_point_factors_share_the_dense_kernels_factorisation():
    """The point factors (core/lsq/schur_numba.py) and the dense reduced system compute the
    inverse Cholesky factors of ``V_p + lam I`` with one compiled helper: both equal numpy's
    (lower triangular, ``Li' Li`` the inverse), the same to the last bit in both kernels;
    a block that is not positive definite is named (1-based) or refused."""
    pytest.importorskip("numba")
    from lidarphoto.core.lsq.schur_numba import dense_reduced, point_factors

    rng = np.random.default_rng(11)
    P, b, lam = 40, 3, 0.25
    A = rng.normal(size=(P, b, b))
    V = A @ np.swapaxes(A, 1, 2) + 0.1 * np.eye(b)
    got = point_factors(V, lam)
    assert isinstance(got, tuple)
    Li, Vinv = got
    L = np.linalg.cholesky(V + lam * np.eye(b))
    assert_allclose(Li, np.linalg.inv(L), rtol=1e-12, atol=1e-12)
    assert_allclose(Vinv, np.linalg.inv(V + lam * np.eye(b)), rtol=1e-10, atol=1e-12)
    assert (np.triu(Li, 1) == 0.0).all()
    point = np.arange(P, dtype=np.intp)
    srows = np.arange(2, dtype=np.intp)[None, :]
    T = rng.normal(size=(P, 2, b))
    start = np.arange(P + 1, dtype=np.intp)
    Li2, _ = dense_reduced(V, lam, np.zeros((P, b)), T, point, start, np.zeros(P, np.intp),
                           srows, np.zeros((2, 2)), np.zeros(2))  # fmt: skip
    np.testing.assert_array_equal(Li2, Li)
    bad = V.copy()
    bad[17] = -np.eye(b)
    assert point_factors(bad, 0.0) == 18
    with pytest.raises(ValueError):
        dense_reduced(bad, 0.0, np.zeros((P, b)), T, point, start, np.zeros(P, np.intp),
                      srows, np.zeros((2, 2)), np.zeros(2))  # fmt: skip


@pytest.mark.parametrize("dense_min", [0, 10**9])
def test_banded_selected_inverse_equals_the_dense_inverse(monkeypatch, dense_min):
    """The cofactor blocks from the band factor (Takahashi's recurrence, the interior
    orientation as the dense part or inside the band) equal those of the dense inverse of the
    reduced system to 1e-10 relative: Q_rr (in the band and, solved column by column,
    outside it), the point blocks, the sigmas, the w-tests and the redundancy numbers."""
    from lidarphoto.core.lsq import selected_inverse

    x_true, x0, names, block, n_eo, ni, elim, extra = small_block(seed=6, n_img=16, n_pt=300)
    ctrl = np.arange(0, elim.shape[0], 9)
    priors = [
        prior_block("control", elim[ctrl].ravel(), extra["pts"][ctrl].ravel(), 0.02),
        prior_block("eo", np.arange(n_eo), x_true[:n_eo], np.tile([0.5] * 3 + [1e-3] * 3, 16)),
    ]
    opts = AdjustmentOptions(snooping=True, eliminate=elim)
    dense = adjust(x0, names, [block, *priors], options=opts)
    monkeypatch.setattr(schur, "_SELECTED_MIN", 0)
    monkeypatch.setattr(selected_inverse, "_DENSE_MIN_DEGREE", dense_min)
    monkeypatch.setattr(selected_inverse, "_DENSE_SHARE", 0.99)  # the interior (all images)
    seen = []
    real = selected_inverse.banded_inverse

    def spy(S):
        out = real(S)
        seen.append(out)
        return out

    monkeypatch.setattr(schur, "banded_inverse", spy)
    band = adjust(x0, names, [block, *priors], options=opts)
    assert seen and seen[-1] is not None  # the band path ran
    b = seen[-1]
    assert (ni <= b.n_dense < b.n) if dense_min == 0 else b.n_dense == 0
    qd, qb = dense.cofactor_blocks, band.cofactor_blocks
    ref = qd.Q_reduced
    rel = np.abs(qb.Q_reduced - ref).max() / np.abs(ref).max()
    assert rel < 1e-10
    ref = qd.Q_eliminated
    assert np.abs(qb.Q_eliminated - ref).max() / np.abs(ref).max() < 1e-10
    assert_allclose(band.std, dense.std, rtol=1e-10)
    # the solve is the same: bit for bit on numpy 2; on Debian's numpy 1.24, whose BLAS rounds
    # the two paths' products differently, within 3e-13 (x up to 100), and w-tests (|w| up to
    # 3.3) within 4e-11
    assert np.abs(band.x - dense.x).max() <= 1e-12 * np.abs(dense.x).max()
    t1, t2 = dense.residuals["img"], band.residuals["img"]
    assert_allclose(t2.w, t1.w, rtol=1e-10, atol=1e-9)
    assert_allclose(t2.redundancy_numbers, t1.redundancy_numbers, rtol=1e-10, atol=1e-12)


def test_banded_inverse_of_a_random_sparse_matrix():
    """Every entry of the inverse of a random sparse SPD matrix with five dense rows, in the
    band and outside it, against numpy's dense inverse (1e-10 relative)."""
    import scipy.sparse as sp
    from lidarphoto.core.lsq import selected_inverse

    rng = np.random.default_rng(3)
    n = 300
    A = sp.random(n, n, density=0.01, random_state=4).toarray()
    A[-5:, :] = rng.normal(0, 0.1, (5, n))
    A = A + A.T
    A += np.eye(n) * (np.abs(A).sum(axis=1).max() + 1.0)
    old = selected_inverse._DENSE_MIN_DEGREE
    selected_inverse._DENSE_MIN_DEGREE = 10
    try:
        b = selected_inverse.banded_inverse(sp.csr_matrix(A))
    finally:
        selected_inverse._DENSE_MIN_DEGREE = old
    assert b is not None and b.n_dense == 5 and b.bandwidth < n - 6
    ref = np.linalg.inv(A)
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    assert np.abs(b.take(i, j) - ref).max() / np.abs(ref).max() < 1e-10
    assert np.abs(b.diagonal() - np.diag(ref)).max() / np.abs(ref).max() < 1e-10
