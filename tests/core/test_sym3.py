"""The 3 x 3 Jacobi eigen-solver (core/geometry/sym3.py) against LAPACK, and the plane fits
built on it (core/geometry/planes.py) against an independent LAPACK fit: the same eigenpairs
and planes to rounding, on well and badly conditioned matrices, at map coordinates; and the
same bits on 1 and 2 BLAS threads for a fit large enough for a threaded BLAS product."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.geometry.planes import fit_plane, fit_planes
from lidarphoto.core.geometry.sym3 import eigh_sym3

EPS = np.finfo(float).eps


def _spd_batch(rng):
    """Symmetric matrices of every kind: random scatter matrices, plane-like ones (two large
    spreads, one small, rotated), repeated eigenvalues, diagonal, zero, huge and tiny."""
    m = rng.normal(size=(400, 3, 8))
    cov = m @ m.transpose(0, 2, 1)
    q, _ = np.linalg.qr(rng.normal(size=(200, 3, 3)))
    lam = np.column_stack([rng.uniform(1, 1e4, 200), rng.uniform(1, 1e4, 200),
                           rng.uniform(1e-6, 1e-1, 200)])  # fmt: skip
    lam[:40, 1] = lam[:40, 0]  # a square roof: two equal spreads
    planes = np.einsum("bij,bj,bkj->bik", q, lam, q)
    special = np.array([np.diag([4.0, 1.0, 0.0]), np.diag([1.0, 1.0, 1.0]), np.zeros((3, 3)),
                        [[2.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 5.0]]])  # fmt: skip
    return np.concatenate([cov, planes, special, cov[:20] * 1e-300, cov[20:40] * 1e150])


def test_eigenpairs_agree_with_lapack():
    rng = np.random.default_rng(7)
    a = _spd_batch(rng)
    lam, vec = eigh_sym3(a)
    ref = np.linalg.eigh(a)[0]
    scale = np.abs(a).max(axis=(1, 2))[:, None]
    # eigenvalues to a few ulps of the matrix's norm (LAPACK's own accuracy)
    assert np.all(np.abs(lam - ref) <= 16 * EPS * scale)
    assert np.all(np.diff(lam, axis=1) >= 0)
    # orthonormal eigenvectors that rebuild the matrix
    eye = np.einsum("bki,bkj->bij", vec, vec)
    np.testing.assert_allclose(eye, np.broadcast_to(np.eye(3), eye.shape), atol=16 * EPS)
    back = np.einsum("bij,bj,bkj->bik", vec, lam, vec)
    assert np.all(np.abs(back - a) <= 16 * EPS * scale[:, :, None])
    # the eigenvector of a simple eigenvalue is LAPACK's up to its sign (the plane normal)
    gap = np.minimum(ref[:, 1] - ref[:, 0], ref[:, 2] - ref[:, 0]) > 1e-6 * scale[:, 0]
    ref_v = np.linalg.eigh(a)[1][:, :, 0]
    dots = np.abs(np.einsum("bi,bi->b", vec[:, :, 0], ref_v))
    assert np.all(np.abs(dots[gap] - 1.0) < 1e-12)
    with pytest.raises(InputError, match=r"\(B, 3, 3\)"):
        eigh_sym3(np.zeros((3, 3)))


def _lapack_plane(pts):
    """Normal, d and the covariance of (a, b, c, d) by LAPACK (the module docstring's
    formulas, written independently of core/geometry/planes.py)."""
    m = pts.mean(axis=0)
    q = pts - m
    lam, vec = np.linalg.eigh(q.T @ q)
    n = vec[:, 0] * np.sign(vec[2, 0])
    s0 = np.sum((q @ n) ** 2) / (len(pts) - 3)
    c_nn = s0 * sum(np.outer(vec[:, k], vec[:, k]) / (lam[k] - lam[0]) for k in (1, 2))
    cov = np.zeros((4, 4))
    cov[:3, :3] = c_nn
    cov[:3, 3] = cov[3, :3] = -c_nn @ m
    cov[3, 3] = m @ c_nn @ m + s0 / len(pts)
    return n, -n @ m, cov


def test_plane_fits_agree_with_an_independent_lapack_fit():
    """Roof-sized planes at RD New coordinates (1e5 m): normals to 1e-13, d to 1e-9 m, every
    covariance entry to 1e-12 of the largest (the rounding of LAPACK against Jacobi)."""
    rng = np.random.default_rng(3)
    pts, labels = [], []
    for k in range(30):
        n = rng.normal(size=3) * [0.5, 0.5, 0.1] + [0, 0, 1]
        n /= np.linalg.norm(n)
        u = np.cross(n, [1.0, 0, 0])
        u /= np.linalg.norm(u)
        st = rng.uniform(-2 - k, 2 + k, (50 + 40 * k, 2))
        p = [85000.0 + 40 * k, 447000.0, 12.0] + st[:, :1] * u + st[:, 1:] * np.cross(n, u)
        pts.append(p + rng.normal(0, 0.03, p.shape))
        labels.append(np.full(len(p), k))
    xyz, lab = np.concatenate(pts), np.concatenate(labels)
    got = fit_planes(xyz, lab)
    for k, plane in enumerate(got):
        assert plane is not None
        n, d, cov = _lapack_plane(pts[k])
        np.testing.assert_allclose(plane.normal, n, atol=1e-13)
        assert abs(plane.d - d) < 1e-9
        np.testing.assert_allclose(plane.covariance, cov, rtol=0, atol=1e-12 * abs(cov).max())
        # fit_plane is fit_planes' fit of the same points as one label, bit for bit
        one, alone = fit_plane(pts[k], plane_id=k), fit_planes(pts[k], np.zeros(len(pts[k])))[0]
        np.testing.assert_array_equal(one.covariance, alone.covariance)
        assert (one.d, one.rms, one.id) == (alone.d, alone.rms, k)


_CHILD = """
import json, sys
import numpy as np
from lidarphoto.core.geometry.planes import fit_plane
rng = np.random.default_rng(1)
xy = rng.uniform(0, 200, (400_000, 2))
xyz = np.column_stack([xy + [85000, 447000], 5 + 0.3 * xy[:, 0] + rng.normal(0, 0.05, len(xy))])
w = rng.uniform(0.5, 2.0, len(xy))
print(json.dumps([fit_plane(xyz).params.tolist() + fit_plane(xyz).covariance.ravel().tolist(),
                  fit_plane(xyz, w).covariance.ravel().tolist()]))
"""


def test_a_large_fit_is_the_same_on_one_and_two_blas_threads():
    """400,000 points: a (3, N) x (N, 3) BLAS product would be split between the threads;
    the bincount sums and the Jacobi rotations are not. Compared with repr precision."""
    out = []
    for n in ("1", "2"):
        env = {**os.environ, "OMP_NUM_THREADS": n, "OPENBLAS_NUM_THREADS": n,
               "MKL_NUM_THREADS": n}  # fmt: skip
        r = subprocess.run([sys.executable, "-c", _CHILD], env=env, capture_output=True,
                           text=True, check=True)  # fmt: skip
        out.append(json.loads(r.stdout.strip().splitlines()[-1]))
    assert out[0] == out[1]
