"""Ray / DSM traversal compiled with numba: the same algorithm as the vectorised numpy
traversal of :mod:`core.geometry.raycast`, one ray after the other, 10-30x faster.

numba is an optional dependency: :data:`AVAILABLE` tells whether it imports, and
:func:`core.geometry.raycast.intersect_dsm` falls back to numpy without it. Both back ends visit the
quads of a ray in the same order (the 2D DDA from the camera), skip the same provably empty
space (the dilated maximum pyramid of :class:`core.geometry.raycast.DsmTracer`) and intersect the
same two triangles per quad with Dal Poz's Eq. 9, so they return the same first hit; the
tests compare them ray by ray.

What the compiled loop adds: a quad is only intersected when the ray's lowest point in it is
not above the quad's highest corner (the numpy version intersects every visited quad), and the
hit description (point, barycentric weights, face gradient, incidence angle) is computed in
the same pass.
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from ..compiled import Kernels

numba: Any  # the module, or None without it
register_jitable: Callable[[Callable[..., Any]], Callable[..., Any]]
try:  # pragma: no cover - depends on the environment
    import numba
    from numba.extending import register_jitable

    AVAILABLE = True
except Exception:  # ImportError, or a numba built against another numpy
    numba = None
    AVAILABLE = False

    def _plain(func: Callable[..., Any]) -> Callable[..., Any]:
        """Without numba the kernels' helpers stay plain Python (never called then)."""
        return func

    register_jitable = _plain

__all__ = ["AVAILABLE", "trace_rays"]

# status codes, as in core.geometry.raycast (not imported: the compiled function takes plain ints)
_OK, _GRAZING, _OUTSIDE, _NODATA, _NOT_CONVERGED = 0, 1, 2, 3, 5
_EPS = 1e-9
_TOL_T = 1e-9


def _spatial_order(o, d, x_c, y_c, cell, zmax, rows, cols):
    """Ray indices sorted by the 16 x 16-cell block where each ray crosses the DSM's top.

    Consecutive rays then read the same part of the grid (cache): a counting sort, O(N).
    """
    n = o.shape[0]
    nbr = (rows >> 4) + 1
    nbc = (cols >> 4) + 1
    key = np.zeros(n, np.int64)
    start = np.zeros(nbr * nbc + 1, np.int64)
    for r in range(n):
        t = (zmax - o[r, 2]) / d[r, 2] if d[r, 2] != 0.0 else 0.0
        u = (o[r, 0] + t * d[r, 0] - x_c) / cell
        v = (y_c - o[r, 1] - t * d[r, 1]) / cell
        if math.isfinite(u) and math.isfinite(v):
            bi = min(max(int(v), 0), rows - 1) >> 4
            bj = min(max(int(u), 0), cols - 1) >> 4
            key[r] = bi * nbc + bj
        start[key[r] + 1] += 1
    for k in range(1, start.size):
        start[k] += start[k - 1]
    order = np.empty(n, np.int64)
    for r in range(n):
        order[start[key[r]]] = r
        start[key[r]] += 1
    return order


@register_jitable
def _slabs(u0, du, v0, dv, oz, dz, rows, cols, z_lo, z_hi):
    """(t_lo, t_hi) of the ray inside the grid's footprint (lattice u, v) and the height range
    ``z_lo..z_hi``, from t = 0; empty when t_lo > t_hi."""
    t_lo = 0.0
    t_hi = np.inf
    for axis in range(3):
        if axis == 0:
            p0, dp, lo, hi = u0, du, 0.0, cols - 1.0
        elif axis == 1:
            p0, dp, lo, hi = v0, dv, 0.0, rows - 1.0
        else:
            p0, dp, lo, hi = oz, dz, z_lo, z_hi
        if dp != 0.0:
            ta = (lo - p0) / dp
            tb = (hi - p0) / dp
            near, far = min(ta, tb), max(ta, tb)
        elif lo <= p0 <= hi:
            near, far = -np.inf, np.inf
        else:
            near, far = np.inf, -np.inf
        t_lo = max(t_lo, near)
        t_hi = min(t_hi, far)
    return t_lo, t_hi


@register_jitable
def _triangle(a, b, rhs, ul, vl, du, dv, dz, tc, lower):
    """Dal Poz's Eq. 9 on one triangle of a quad, z = z00 + a u + b v (u, v in the quad's unit
    square, ray from (ul, vl) along (du, dv, dz), ``rhs`` = z00 - oz): (hit, t); ``lower``:
    the triangle (r, c), (r+1, c), (r+1, c+1), else (r, c), (r, c+1), (r+1, c+1). A hit
    before ``tc`` does not count."""
    den = dz - a * du - b * dv
    if den == 0.0:
        return False, np.nan
    t = (rhs + a * ul + b * vl) / den
    u = ul + du * t
    v = vl + dv * t
    if lower:
        return u >= -_EPS and v <= 1 + _EPS and v - u >= -_EPS and t >= tc, t
    return v >= -_EPS and u <= 1 + _EPS and u - v >= -_EPS and t >= tc, t


@register_jitable
def _clear(r, t_out, st_out, qi_out, qj_out, tri_out, pts_out, w_out, grad_out, inc_out):
    """Row ``r`` of the *_out arrays set to "no hit" (outside, NaN, -1)."""
    t_out[r] = np.nan
    st_out[r] = _OUTSIDE
    qi_out[r] = -1
    qj_out[r] = -1
    tri_out[r] = -1
    for c in range(3):
        pts_out[r, c] = np.nan
        w_out[r, c] = np.nan
    grad_out[r, 0] = np.nan
    grad_out[r, 1] = np.nan
    inc_out[r] = np.nan


@register_jitable
def _describe_hit(r, th, k, i, j, o, d, z, x_c, y_c, cell, pts_out, w_out, grad_out, inc_out):
    """Row ``r`` of the hit arrays: the point of ray ``r`` at parameter ``th`` on triangle ``k``
    of quad (i, j) of the heights ``z``, its barycentric weights, the face gradient and the
    incidence angle (degrees)."""
    ox, oy, oz = o[r, 0], o[r, 1], o[r, 2]
    dx, dy, dz = d[r, 0], d[r, 1], d[r, 2]
    z00 = np.float64(z[i, j])
    z01 = np.float64(z[i, j + 1])
    z10 = np.float64(z[i + 1, j])
    z11 = np.float64(z[i + 1, j + 1])
    inv = 1.0 / cell
    px, py, pz = ox + th * dx, oy + th * dy, oz + th * dz
    pts_out[r, 0] = px
    pts_out[r, 1] = py
    pts_out[r, 2] = pz
    u = (px - x_c) * inv - j
    v = (y_c - py) * inv - i
    if k == 1:
        gx = (z11 - z10) / cell
        gy = (z10 - z00) / -cell
        w_out[r, 0] = 1 - v
        w_out[r, 1] = v - u
        w_out[r, 2] = u
    else:
        gx = (z01 - z00) / cell
        gy = (z11 - z01) / -cell
        w_out[r, 0] = 1 - u
        w_out[r, 1] = u - v
        w_out[r, 2] = v
    grad_out[r, 0] = gx
    grad_out[r, 1] = gy
    cosang = abs(dz - gx * dx - gy * dy) / math.sqrt(
        (gx * gx + gy * gy + 1.0) * (dx * dx + dy * dy + dz * dz)
    )
    inc_out[r] = math.degrees(math.asin(min(cosang, 1.0)))


def _trace(
    o,
    d,
    order,
    z,
    qmax,
    mstack,
    offsets,
    bcols,
    shifts,
    x_c,
    y_c,
    cell,
    zmin,
    zmax,
    n_lev,
    min_inc_deg,
    t_out,
    st_out,
    qi_out,
    qj_out,
    tri_out,
    pts_out,
    w_out,
    grad_out,
    inc_out,
):
    """Trace rays o + t d (CRS units) through the DSM heights z, in the given order; fills
    the *_out arrays."""
    rows, cols = z.shape
    inv = 1.0 / cell
    margin = 1e-6 * max(1.0, abs(zmax), abs(zmin))
    budget = 4 * (rows + cols) + 16
    for r in order:
        _clear(r, t_out, st_out, qi_out, qj_out, tri_out, pts_out, w_out, grad_out, inc_out)
        ox, oy, oz = o[r, 0], o[r, 1], o[r, 2]
        dx, dy, dz = d[r, 0], d[r, 1], d[r, 2]
        finite = True
        for c in range(3):
            if not (math.isfinite(o[r, c]) and math.isfinite(d[r, c])):
                finite = False
        if not finite or abs(dx) + abs(dy) + abs(dz) == 0.0:
            continue
        # lattice coordinates (u east, v south, cells from the centre of cell (0, 0))
        u0 = (ox - x_c) * inv
        v0 = (y_c - oy) * inv
        du = dx * inv
        dv = -dy * inv
        # slab test: the grid's footprint and the height range
        t_lo, t_hi = _slabs(u0, du, v0, dv, oz, dz, rows, cols, zmin - margin, zmax + margin)
        if not t_lo <= t_hi:
            continue
        su = 1.0 if du >= 0 else 0.0
        sv = 1.0 if dv >= 0 else 0.0
        iu = 1.0 / du if du != 0 else 1e300
        iv = 1.0 / dv if dv != 0 else 1e300
        iz = 1.0 / dz if dz < 0 else -1e-300
        big = max(abs(du), abs(dv))
        nudge = min(1e-7 / big, 1e-6) if big > 0 else 1e-6
        ou = 3.0 * su - 1.0
        ov = 3.0 * sv - 1.0
        t = t_lo
        lv = 0
        status = _NOT_CONVERGED
        i = j = k = 0  # the quad and triangle of the hit
        th = t_lo
        for _ in range(budget):
            tp = t + nudge
            j = min(max(math.floor(u0 + du * tp), 0), cols - 2)
            i = min(max(math.floor(v0 + dv * tp), 0), rows - 2)
            t_exit = min((j + su - u0) * iu, (i + sv - v0) * iv)
            t_new = t_exit
            skip_quad = False
            if n_lev > 0:
                sh = shifts[lv]
                bi = i >> sh
                bj = j >> sh
                size = float(1 << sh)
                mx = mstack[offsets[lv] + bi * bcols[lv] + bj]
                if oz + dz * t > mx:
                    t_box = min(((bj + ou) * size - u0) * iu, ((bi + ov) * size - v0) * iv)
                    t_safe = min(t_box, (mx - oz) * iz)
                    if t_safe > t_new:
                        t_new = t_safe
                        # no hit in this quad before t_safe >= its exit
                        skip_quad = True
                    lv = min(lv + 1, n_lev - 1)
                else:
                    lv = max(lv - 1, 0)
            if not skip_quad:
                zlow = min(oz + dz * t, oz + dz * t_exit)
                qm = qmax[i, j]
                if not zlow > qm + 1e-9 * (1.0 + abs(qm)):  # NaN / inf maxima are tested
                    z00 = np.float64(z[i, j])
                    z01 = np.float64(z[i, j + 1])
                    z10 = np.float64(z[i + 1, j])
                    z11 = np.float64(z[i + 1, j + 1])
                    if not (
                        math.isfinite(z00)
                        and math.isfinite(z01)
                        and math.isfinite(z10)
                        and math.isfinite(z11)
                    ):
                        status = _NODATA
                        qi_out[r] = i
                        qj_out[r] = j
                        break
                    ul = u0 - j
                    vl = v0 - i
                    tc = t - _TOL_T
                    rhs = z00 - oz
                    # triangle 0: (r, c), (r, c+1), (r+1, c+1); z = z00 + a u + b v
                    ok_a, ta = _triangle(z01 - z00, z11 - z01, rhs, ul, vl, du, dv, dz, tc, False)
                    # triangle 1: (r, c), (r+1, c), (r+1, c+1)
                    ok_b, tb = _triangle(z11 - z10, z10 - z00, rhs, ul, vl, du, dv, dz, tc, True)
                    if ok_a or ok_b:
                        first_b = ok_b and not (ok_a and ta <= tb)
                        th = tb if first_b else ta
                        k = 1 if first_b else 0
                        status = _OK
                        break
            # the quad index was clipped (t_exit <= t): the ray is past the grid's edge
            if t_new >= t_hi or t_exit <= t:
                status = _OUTSIDE
                break
            t = t_new
        if status == _OK:
            t_out[r] = th
            qi_out[r] = i
            qj_out[r] = j
            tri_out[r] = k
            _describe_hit(
                r, th, k, i, j, o, d, z, x_c, y_c, cell, pts_out, w_out, grad_out, inc_out
            )
            if inc_out[r] < min_inc_deg:
                status = _GRAZING
        st_out[r] = status


#: The jitted functions (each compiled at its first call, cached: core/compiled.py).
_compiled = Kernels({"order": _spatial_order, "trace": _trace})


def trace_rays(
    tracer: Any,
    origins: np.ndarray,
    directions: np.ndarray,
    accelerate: bool,
    min_incidence_deg: float,
    out: dict[str, np.ndarray],
    rows: slice,
) -> None:
    """Trace ``origins[rows]``, ``directions[rows]`` into ``out[...][rows]`` (see DsmHits).

    ``tracer`` is a :class:`core.geometry.raycast.DsmTracer`; ``out`` holds the arrays t, status,
    qi, qj, tri, points, weights, gradient and incidence of :func:`intersect_dsm`.
    """
    if not AVAILABLE:
        raise RuntimeError("numba is not installed")
    dsm = tracer.dsm
    z = np.ascontiguousarray(dsm.heights, np.float32)
    r_, c_ = z.shape
    qmax = tracer.qmax.reshape(r_ - 1, c_ - 1)
    if accelerate and tracer.levels:
        pyramid: tuple[Any, ...]  # the stacked levels, offsets, columns, shifts
        pyramid = (tracer.mstack, tracer.level_offsets, tracer.level_cols, tracer.level_shifts)
        n_lev = len(tracer.levels)
    else:
        pyramid = (np.zeros(1, np.float32), *(np.zeros(1, np.int64) for _ in range(3)))
        n_lev = 0
    xc, yc = dsm.centre_origin
    o = np.ascontiguousarray(origins[rows], np.float64)
    d = np.ascontiguousarray(directions[rows], np.float64)
    order = _compiled("order")(
        o, d, float(xc), float(yc), float(dsm.cell), float(tracer.zmax), r_, c_
    )
    _compiled("trace")(
        o,
        d,
        order,
        z,
        qmax,
        *pyramid,
        float(xc),
        float(yc),
        float(dsm.cell),
        float(tracer.zmin),
        float(tracer.zmax),
        n_lev,
        float(min_incidence_deg),
        out["t"][rows],
        out["status"][rows],
        out["qi"][rows],
        out["qj"][rows],
        out["tri"][rows],
        out["points"][rows],
        out["weights"][rows],
        out["gradient"][rows],
        out["incidence"][rows],
    )
