"""The inner loop of least-squares matching compiled with numba: for each patch, bicubic (Keys
1981) samples of the search window and of its derivative at the affine positions, accumulated
straight into the 8 x 8 normal equations (no (K, 8, P) design matrix in memory).

The same arithmetic as the numpy path of :mod:`core.photo.least_squares_matching` (the tests
compare them); numba is optional: :data:`AVAILABLE` tells whether it imports.
"""

from __future__ import annotations

from types import ModuleType

import numpy as np

from ..compiled import Kernels, cached_njit

numba: ModuleType | None  # None without numba
try:  # pragma: no cover - depends on the environment
    import numba

    AVAILABLE = True
except Exception:  # ImportError, or a numba built against another numpy
    numba = None
    AVAILABLE = False

__all__ = ["AVAILABLE", "normals", "samples"]


def _keys(t):  # pragma: no cover - compiled
    """Keys' cubic weights (a = -0.5) of the four samples around a point a fraction ``t`` past
    the second one, and their derivatives in t."""
    t2 = t * t
    t3 = t2 * t
    return (
        (
            -0.5 * t3 + t2 - 0.5 * t,
            1.5 * t3 - 2.5 * t2 + 1.0,
            -1.5 * t3 + 2.0 * t2 + 0.5 * t,
            0.5 * t3 - 0.5 * t2,
        ),
        (-1.5 * t2 + 2.0 * t - 0.5, 4.5 * t2 - 5.0 * t, -4.5 * t2 + 4.0 * t + 0.5, 1.5 * t2 - t),
    )


if AVAILABLE:  # inlined into the kernels (a plain function cannot be called from them)
    _keys = cached_njit(_keys, inline="always")


def _normals(g, idx, aff, rad, f, x, y, nn, rhs, outside):  # pragma: no cover - compiled
    h = g.shape[1]
    w = g.shape[2]
    p_n = x.shape[0]
    jv = np.empty(8)
    for q in range(idx.shape[0]):
        k = idx[q]
        a0, a1, a2 = aff[k, 0, 0], aff[k, 0, 1], aff[k, 0, 2]
        b0, b1, b2 = aff[k, 1, 0], aff[k, 1, 1], aff[k, 1, 2]
        r0, r1 = rad[k, 0], rad[k, 1]
        out = False
        for i in range(8):
            rhs[q, i] = 0.0
            for j in range(8):
                nn[q, i, j] = 0.0
        for p in range(p_n):
            c = a0 + a1 * x[p] + a2 * y[p]
            r = b0 + b1 * x[p] + b2 * y[p]
            if c < 1.0 or r < 1.0 or c > w - 3.0 or r > h - 3.0:
                out = True
                c = min(max(c, 1.0), w - 3.000001)
                r = min(max(r, 1.0), h - 3.000001)
            ci = int(c)
            ri = int(r)
            (wx0, wx1, wx2, wx3), (dx0, dx1, dx2, dx3) = _keys(c - ci)
            (wy0, wy1, wy2, wy3), (dy0, dy1, dy2, dy3) = _keys(r - ri)
            val = 0.0
            gcol = 0.0
            grow = 0.0
            for m in range(4):
                rr = ri - 1 + m
                s0 = g[k, rr, ci - 1]
                s1 = g[k, rr, ci]
                s2 = g[k, rr, ci + 1]
                s3 = g[k, rr, ci + 2]
                ax = wx0 * s0 + wx1 * s1 + wx2 * s2 + wx3 * s3
                dxv = dx0 * s0 + dx1 * s1 + dx2 * s2 + dx3 * s3
                wym = wy0 if m == 0 else (wy1 if m == 1 else (wy2 if m == 2 else wy3))
                dym = dy0 if m == 0 else (dy1 if m == 1 else (dy2 if m == 2 else dy3))
                val += wym * ax
                gcol += wym * dxv
                grow += dym * ax
            res = f[k, p] - (r0 + r1 * val)
            ux = r1 * gcol
            uy = r1 * grow
            jv[0] = ux
            jv[1] = ux * x[p]
            jv[2] = ux * y[p]
            jv[3] = uy
            jv[4] = uy * x[p]
            jv[5] = uy * y[p]
            jv[6] = 1.0
            jv[7] = val
            for i in range(8):
                rhs[q, i] += jv[i] * res
                for j in range(i, 8):
                    nn[q, i, j] += jv[i] * jv[j]
        for i in range(8):
            for j in range(i):
                nn[q, i, j] = nn[q, j, i]
        outside[q] = out


def _samples(g, aff, x, y, out):  # pragma: no cover - compiled
    h = g.shape[1]
    w = g.shape[2]
    for k in range(aff.shape[0]):
        for p in range(x.shape[0]):
            c = aff[k, 0, 0] + aff[k, 0, 1] * x[p] + aff[k, 0, 2] * y[p]
            r = aff[k, 1, 0] + aff[k, 1, 1] * x[p] + aff[k, 1, 2] * y[p]
            c = min(max(c, 1.0), w - 3.000001)
            r = min(max(r, 1.0), h - 3.000001)
            ci = int(c)
            ri = int(r)
            wx = _keys(c - ci)[0]
            wy = _keys(r - ri)[0]
            val = 0.0
            for m in range(4):
                ax = 0.0
                for n in range(4):
                    ax += wx[n] * g[k, ri - 1 + m, ci - 1 + n]
                val += wy[m] * ax
            out[k, p] = val


#: The jitted functions (each compiled at its first call, cached: core/compiled.py).
_compiled = Kernels({"normals": _normals, "samples": _samples})


def normals(g, idx, aff, rad, f, x, y):
    """(n, 8, 8) normal matrices, (n, 8) right-hand sides and (n,) "left the window" flags of
    the patches ``idx`` (see :func:`core.photo.least_squares_matching.lsm_batch`)."""
    n = idx.shape[0]
    nn = np.empty((n, 8, 8))
    rhs = np.empty((n, 8))
    outside = np.empty(n, dtype=np.bool_)
    _compiled("normals")(g, idx.astype(np.int64), aff, rad, f, x, y, nn, rhs, outside)
    return nn, rhs, outside


def samples(g, aff, x, y):
    """(K, P) bicubic samples of each patch's window at its affine positions."""
    out = np.empty((aff.shape[0], x.shape[0]))
    _compiled("samples")(g, np.ascontiguousarray(aff), x, y, out)
    return out
