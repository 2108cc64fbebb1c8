"""Ray casting on a gridded surface: the first intersection of rays with a DSM (dos Santos et al.
2010).

The surface is the DSM polyhedron of :mod:`core.geometry.surface`. For each ray:

1. the ray is clipped to the DSM's footprint and height range (a slab test);
2. the quads (pairs of triangles) it crosses are visited in order from the camera, as in a
   2D DDA (Amanatides-Woo) traversal;
3. in each quad both triangles are intersected in Dal Poz's determinant form: the face
   ``OPQ`` gives the plane ``A . X + B = 0`` with ``A = (P - O) x (Q - P)`` (the expansion of
   the determinant of Eq. 6 along its first row, Eq. 7) and ``t = -(A . CP + B) / (A . N)``
   (Eq. 9); the first face hit inside its triangle is the visible point (occlusion).

Quads that the ray provably cannot hit are skipped (empty-space skipping, as in maximum
mipmaps for height fields): for blocks of ``2^L`` quads the maximum height over the block and
its 8 neighbours is kept; while the ray stays above that height inside the 3 x 3 blocks, no
quad there can be hit, so the traversal jumps to where it leaves them. The visiting order,
and therefore the first hit, is unchanged; ``accelerate=False`` gives the plain DDA.

The traversal exists twice, with the same result: vectorised with numpy over a pool of rays
(here) and compiled with numba one ray after the other (:mod:`core.geometry.raycast_numba`,
optional, 2-3x faster); :func:`intersect_dsm` takes numba when it imports.

Each ray gets a status code (:data:`RAY_STATUS_TEXT`): a ray that leaves the DSM or crosses
a nodata hole before hitting the surface is reported, never raised.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError, stop_if_asked, use_compiled
from .surface import Dsm

Array = NDArray[np.float64]
Bools = NDArray[np.bool_]

STATUS_OK = 0
STATUS_GRAZING = 1
STATUS_OUTSIDE = 2
STATUS_NODATA = 3
STATUS_NOT_CONVERGED = 5
#: Meaning of each status code of a ray.
RAY_STATUS_TEXT = {
    STATUS_OK: "ok",
    STATUS_GRAZING: "grazing",  # hit, but the ray meets the face at less than the minimum angle
    STATUS_OUTSIDE: "outside",  # the ray leaves the DSM (or never reaches it) without a hit
    STATUS_NODATA: "nodata",  # the ray crosses a nodata hole before hitting the surface
    STATUS_NOT_CONVERGED: "not_converged",  # an iteration did not converge
}

__all__ = [
    "RAY_STATUS_TEXT",
    "DsmHits",
    "DsmTracer",
    "chord_rays",
    "dal_poz_intersect",
    "dal_poz_plane",
    "intersect_dsm",
]


# --------------------------------------------------------------------------- Eqs. 6-10
def dal_poz_plane(o: ArrayLike, p: ArrayLike, q: ArrayLike) -> tuple[Array, Array]:
    """Plane ``A . X + B = 0`` of the faces OPQ (dos Santos et al. 2010, Eqs. 5-7), vectorised.

    Parameters
    ----------
    o, p, q : (N, 3) array_like
        Face vertices (E, N, H).

    Returns
    -------
    a : (N, 3) ndarray
        ``(A1, A2, A3) = (P - O) x (Q - P)``, the cofactors of the first row of Eq. 6.
    b : (N,) ndarray
        ``B = -A . O``.
    """
    o, p, q = (np.atleast_2d(np.asarray(v, dtype=np.float64)) for v in (o, p, q))
    a = np.cross(p - o, q - p)
    return a, -np.einsum("ij,ij->i", a, o)


def dal_poz_intersect(
    centre: ArrayLike, direction: ArrayLike, a: ArrayLike, b: ArrayLike
) -> tuple[Array, Array]:
    """Direct monorestitution (dos Santos et al. 2010, Eqs. 9-10): ray ``CP + t N`` with ``A . X + B
    = 0``.

    Parameters
    ----------
    centre, direction : (N, 3) array_like
        Perspective centre CP and ray direction N.
    a, b : (N, 3) and (N,) array_like
        Plane coefficients.

    Returns
    -------
    points : (N, 3) ndarray
        ``G = CP + t N`` (NaN where the ray is parallel to the plane).
    t : (N,) ndarray

    Examples
    --------
    >>> g, t = dal_poz_intersect([[0, 0, 10]], [[0, 0, -1]], [[0, 0, 1]], [-2.0])
    >>> g.tolist(), t.tolist()
    ([[0.0, 0.0, 2.0]], [8.0])
    """
    c = np.atleast_2d(np.asarray(centre, dtype=np.float64))
    n = np.atleast_2d(np.asarray(direction, dtype=np.float64))
    a = np.atleast_2d(np.asarray(a, dtype=np.float64))
    b = np.atleast_1d(np.asarray(b, dtype=np.float64))
    with np.errstate(divide="ignore", invalid="ignore"):
        t = -(np.einsum("ij,ij->i", a, c) + b) / np.einsum("ij,ij->i", a, n)
    t = np.where(np.isfinite(t), t, np.nan)
    return c + t[:, None] * n, t


# --------------------------------------------------------------------------- the tracer
@dataclass(frozen=True)
class DsmHits:
    """Result of :func:`intersect_dsm` for N rays (rows of non-hits are NaN / -1).

    Attributes
    ----------
    points : (N, 3) float64
        First intersection with the surface, CRS unit.
    t : (N,) float64
        Ray parameter of the hit (distance when the directions are unit vectors).
    status : (N,) int8
        :data:`RAY_STATUS_TEXT` codes (ok, grazing, outside, nodata).
    quad : (N, 2) int64
        (row, col) of the quad's top-left cell.
    triangle : (N,) int8
        0 or 1 (see :mod:`core.geometry.surface`).
    weights : (N, 3) float64
        Barycentric weights at the hit of the face's three cells, in the order of
        :mod:`core.geometry.surface`: (r, c), (r, c+1), (r+1, c+1) for triangle 0 and
        (r, c), (r+1, c), (r+1, c+1) for triangle 1 (the surface height is the weighted sum).
    gradient : (N, 2) float64
        (dz/dx, dz/dy) of the face.
    incidence_deg : (N,) float64
        Angle between the ray and the face, degrees (90 = perpendicular).
    """

    points: Array
    t: Array
    status: NDArray[np.int8]
    quad: NDArray[np.int64]
    triangle: NDArray[np.int8]
    weights: Array
    gradient: Array
    incidence_deg: Array


@dataclass(frozen=True)
class DsmTracer:
    """A DSM prepared for ray casting: packed heights and the skipping pyramid.

    Build once with :meth:`build` and reuse for many calls of :func:`intersect_dsm`.

    Attributes
    ----------
    pairs : (rows * cols,) float64 view
        ``(z[r, c], z[r + 1, c])`` packed as two float32 in 8 bytes (one gather per column
        of a quad).
    qmax : ((rows - 1) * (cols - 1),) float32
        Highest corner of each quad (+inf where a corner is nodata).
    levels : tuple of (L, (R, C) float32)
        For blocks of ``2^L`` quads, the maximum over the block and its 8 neighbours.
    mstack, level_offsets, level_cols, level_shifts
        The same levels flattened into one array, with the offset, block columns and L of
        each level (what the traversal loops index).
    """

    dsm: Dsm
    pairs: NDArray[np.float64]
    qmax: NDArray[np.float32]
    levels: tuple[tuple[int, NDArray[np.float32]], ...]
    zmin: float
    zmax: float
    mstack: NDArray[np.float32]
    level_offsets: NDArray[np.int64]
    level_cols: NDArray[np.int64]
    level_shifts: NDArray[np.int64]

    @classmethod
    def build(cls, dsm: Dsm, levels: Sequence[int] = (1, 2, 3, 4, 5, 6, 7)) -> DsmTracer:
        """Precompute the per-level maxima (``2^L`` quads per block, dilated by one block)."""
        import cv2

        z = dsm.heights
        rows, cols = z.shape
        if rows < 2 or cols < 2:
            raise InputError("the DSM needs at least 2 x 2 cells", path=dsm.source or None)
        zinf = np.where(np.isnan(z), np.inf, z).astype(np.float32)
        # a quad can only be skipped if its corners are known: nodata counts as +inf.
        qmax = np.maximum(
            np.maximum(zinf[:-1, :-1], zinf[1:, :-1]), np.maximum(zinf[:-1, 1:], zinf[1:, 1:])
        )
        out = []
        for lev in sorted(set(int(v) for v in levels)):
            b = 1 << lev
            qr, qc = qmax.shape
            pr, pc = (-qr) % b, (-qc) % b
            padded = np.pad(qmax, ((0, pr), (0, pc)), constant_values=-np.inf)
            block = padded.reshape(padded.shape[0] // b, b, padded.shape[1] // b, b).max(
                axis=(1, 3)
            )
            dil = cv2.dilate(
                block,
                np.ones((3, 3), np.uint8),
                borderType=cv2.BORDER_CONSTANT,
                borderValue=(-np.inf,),
            )
            out.append((lev, np.ascontiguousarray(dil, dtype=np.float32)))
        zmin, zmax = dsm.z_range
        # (z[r, c], z[r + 1, c]) side by side, 8 bytes per entry: the two corners of a quad
        # column come in one gather (the last row repeats itself; it is never a quad's top)
        below = np.vstack([z[1:], z[-1:]])
        packed = np.ascontiguousarray(np.stack([z, below], axis=-1), np.float32)
        pairs = packed.view(np.float64).reshape(-1)
        qflat = np.ascontiguousarray(qmax).ravel()
        mstack = np.concatenate([m.ravel() for _, m in out] or [np.zeros(0, np.float32)])
        offsets = np.cumsum([0] + [m.size for _, m in out])[:-1].astype(np.int64)
        bcols = np.array([m.shape[1] for _, m in out], np.int64)
        shifts = np.array([lev for lev, _ in out], np.int64)
        return cls(dsm, pairs, qflat, tuple(out), zmin, zmax, mstack, offsets, bcols, shifts)


def _slab(p0: Array, dp: Array, lo: float, hi: float) -> tuple[Array, Array]:
    inside = (p0 >= lo) & (p0 <= hi)
    with np.errstate(divide="ignore", invalid="ignore"):
        ta, tb = (lo - p0) / dp, (hi - p0) / dp
    moving = dp != 0
    near = np.where(moving, np.minimum(ta, tb), np.where(inside, -np.inf, np.inf))
    far = np.where(moving, np.maximum(ta, tb), np.where(inside, np.inf, -np.inf))
    return near, far


def _slabs(tr: DsmTracer, start: tuple, step: tuple, rows: int, cols: int) -> tuple[Array, Array]:
    """(t_lo, t_hi) of the rays ``start + t step`` (lattice u, v and height z) inside the
    grid's footprint and its height range (empty where t_lo > t_hi)."""
    (u0, v0, z0), (du, dv, dz) = start, step
    n = u0.shape[0]
    t_lo, t_hi = np.zeros(n), np.full(n, np.inf)
    margin = 1e-6 * max(1.0, abs(tr.zmax), abs(tr.zmin))
    for p0, dp, lo, hi in (
        (u0, du, 0.0, cols - 1.0),
        (v0, dv, 0.0, rows - 1.0),
        (z0, dz, tr.zmin - margin, tr.zmax + margin),
    ):
        near, far = _slab(p0, dp, lo, hi)
        np.maximum(t_lo, near, out=t_lo)
        np.minimum(t_hi, far, out=t_hi)
    return t_lo, t_hi


def _quad_triangles(
    corners: tuple,
    ul: Array,
    vl: Array,
    du: Array,
    dv: Array,
    dz: Array,
    rhs: Array,
    tc: Array,
    eps: float,
) -> tuple[Array, Bools, Array, Bools]:
    """Dal Poz's Eq. 9 for the two triangles of each ray's quad (corner heights z00, z01,
    z10, z11; the ray at (ul, vl) in the quad, ``rhs`` = z00 - z0): (ta, hits triangle 0,
    tb, hits triangle 1), a hit at t >= ``tc`` within ``eps`` of the triangle."""
    z00, z01, z10, z11 = corners
    with np.errstate(divide="ignore", invalid="ignore"):
        a, b = z01 - z00, z11 - z01  # triangle 0: z = z00 + a u + b v
        ta = (rhs + a * ul + b * vl) / (dz - a * du - b * dv)
        ua, va = ul + du * ta, vl + dv * ta
        ok_a = (va >= -eps) & (ua <= 1 + eps) & (ua - va >= -eps) & (ta >= tc)
        a, b = z11 - z10, z10 - z00  # triangle 1
        tb = (rhs + a * ul + b * vl) / (dz - a * du - b * dv)
        ub, vb = ul + du * tb, vl + dv * tb
        ok_b = (ub >= -eps) & (vb <= 1 + eps) & (vb - ub >= -eps) & (tb >= tc)
    return ta, ok_a, tb, ok_b


def _trace_chunk(
    tr: DsmTracer, o: Array, d: Array, accelerate: bool, pool: int = 8192
) -> tuple[Array, NDArray[np.int8], NDArray[np.int64], NDArray[np.int64], NDArray[np.int8]]:
    """Traverse one chunk of rays; returns t, status, quad row, quad col, triangle.

    The rays in flight form a pool of fixed size that is refilled from the chunk as rays
    finish, so that each vectorised step works on many rays (no long tail of stragglers).
    """
    dsm = tr.dsm
    rows, cols = dsm.heights.shape
    xc, yc = dsm.centre_origin
    n = o.shape[0]
    inv = 1.0 / dsm.cell
    # lattice coordinates: u east and v south in cells from the centre of cell (0, 0); the
    # map is affine, so t (and Eq. 9) is the same in both systems.
    u0, v0, z0 = (o[:, 0] - xc) * inv, (yc - o[:, 1]) * inv, o[:, 2].copy()
    du, dv, dz = d[:, 0] * inv, -d[:, 1] * inv, d[:, 2].copy()
    t_lo, t_hi = _slabs(tr, (u0, v0, z0), (du, dv, dz), rows, cols)
    t_out = np.full(n, np.nan)
    st_out = np.full(n, STATUS_OUTSIDE, np.int8)
    qi_out = np.full(n, -1, np.int64)
    qj_out = np.full(n, -1, np.int64)
    tri_out = np.full(n, -1, np.int8)
    queue = np.flatnonzero(t_lo <= t_hi)
    # rays in the pool at the same time should read nearby DSM cells (cache): process them
    # in the order of their entry cell, in bands of 16 rows; the state is kept in that
    # order, so that refilling the pool copies contiguous slices.
    te = t_lo[queue]
    band = np.clip(v0[queue] + dv[queue] * te, 0, rows - 1).astype(np.int64) >> 4
    col = np.clip(u0[queue] + du[queue] * te, 0, cols - 1).astype(np.int64)
    queue = queue[np.argsort(band * cols + col)]
    u0, v0, z0, du, dv, dz, t_lo, t_hi = (x[queue] for x in (u0, v0, z0, du, dv, dz, t_lo, t_hi))
    # per-ray constants of the traversal: the side of the next border (su, sv: 0 or 1) and
    # reciprocals (a huge finite value for an axis the ray does not move along, so that
    # the next border is never reached: u0 lies strictly inside its quad then).
    with np.errstate(divide="ignore"):
        su, sv = (du >= 0).astype(np.float64), (dv >= 0).astype(np.float64)
        iu = np.where(du != 0, 1.0 / np.where(du != 0, du, 1.0), 1e300)
        iv = np.where(dv != 0, 1.0 / np.where(dv != 0, dv, 1.0), 1e300)
        iz = np.where(dz < 0, 1.0 / np.where(dz < 0, dz, -1.0), -1e-300)
        # a nudge of 1e-7 cell along the ray makes the quad lookup unambiguous on borders
        nudge = np.minimum(1e-7 / np.maximum(np.abs(du), np.abs(dv)), 1e-6)
    # per-ray level of the skipping pyramid, adapted as in maximum-mipmap tracing: one
    # level is tested per step; up after a successful skip, down after a failed one.
    n_lev = len(tr.levels) if accelerate else 0
    lv = np.zeros(queue.size, np.int64)
    ou, ov = 3.0 * su - 1.0, 3.0 * sv - 1.0
    state: list[NDArray[Any]]  # the per-ray arrays, in the order unpacked below
    state = [u0, v0, z0, du, dv, dz, su, sv, iu, iv, iz, nudge, t_lo, t_hi, ou, ov, lv]
    pairs = tr.pairs
    t_q = np.full(queue.size, np.nan)
    st_q = np.full(queue.size, STATUS_OUTSIDE, np.int8)
    qi_q = np.full(queue.size, -1, np.int64)
    qj_q = np.full(queue.size, -1, np.int64)
    tri_q = np.full(queue.size, -1, np.int8)
    if n_lev:
        shifts, bcols, offsets, mstack = tr.level_shifts, tr.level_cols, tr.level_offsets, tr.mstack
        sizes = np.ldexp(1.0, shifts)
    eps, tol_t = 1e-9, 1e-9
    take = min(pool, queue.size)
    idx = np.arange(take)  # positions in queue order
    cur = [a[:take].copy() for a in state]
    alive = np.ones(take, bool)
    head = take
    budget = (4 * (rows + cols) + 16) * max(1, -(-queue.size // max(pool, 1)))
    for _ in range(budget):
        if idx.size == 0:
            break
        u0, v0, z0, du, dv, dz, su, sv, iu, iv, iz, nudge, t, t_hi, ou, ov, lv = cur
        tp = t + nudge
        j = np.clip(np.floor(u0 + du * tp), 0, cols - 2).astype(np.int64)
        i = np.clip(np.floor(v0 + dv * tp), 0, rows - 2).astype(np.int64)
        t_exit = np.minimum((j + su - u0) * iu, (i + sv - v0) * iv)
        base = i * cols + j
        # one 8-byte gather per column of the quad: (z[r, c], z[r + 1, c]) are packed
        # float64 corners: the face slopes are differences of heights, exact in float64
        left = pairs[base].view(np.float32).reshape(-1, 2).astype(np.float64)
        right = pairs[base + 1].view(np.float32).reshape(-1, 2).astype(np.float64)
        z00, z10, z01, z11 = left[:, 0], left[:, 1], right[:, 0], right[:, 1]
        ul, vl = u0 - j, v0 - i
        tc = t - tol_t
        rhs = z00 - z0
        ta, ok_a, tb, ok_b = _quad_triangles((z00, z01, z10, z11), ul, vl, du, dv, dz, rhs, tc, eps)
        nodata = np.isnan(z00 + z01 + z10 + z11)
        first_b = ok_b & ~(ok_a & (ta <= tb))
        hit = (ok_a | ok_b) & ~nodata
        t_new = t_exit
        if n_lev:
            sh = shifts[lv]
            bi, bj = i >> sh, j >> sh
            size = sizes[lv]
            mx = mstack[offsets[lv] + bi * bcols[lv] + bj]
            # leave the 3 x 3 blocks around the current one, or reach their top
            t_box = np.minimum(((bj + ou) * size - u0) * iu, ((bi + ov) * size - v0) * iv)
            t_safe = np.minimum(t_box, (mx - z0) * iz)
            up = z0 + dz * t > mx
            np.maximum(t_new, np.where(up, t_safe, -np.inf), out=t_new)
            cur[16] = np.where(up, np.minimum(lv + 1, n_lev - 1), np.maximum(lv - 1, 0))
        # t_exit <= t only when the quad index was clipped: the ray is past the grid's edge
        leaves = ~hit & ~nodata & ((t_new >= t_hi) | (t_exit <= t))
        done = (hit | nodata | leaves) & alive
        cur[12] = t_new
        slots = np.flatnonzero(done)
        if slots.size:
            k = idx[slots]
            hd = hit[slots]
            t_q[k[hd]] = np.where(first_b, tb, ta)[slots[hd]]
            st_q[k] = np.where(
                hd, STATUS_OK, np.where(nodata[slots], STATUS_NODATA, STATUS_OUTSIDE)
            )
            qi_q[k], qj_q[k], tri_q[k] = i[slots], j[slots], first_b[slots]
            # refill the finished slots from the queue (cost ~ finished rays, not the pool)
            m = min(slots.size, queue.size - head)
            filled, emptied = slots[:m], slots[m:]
            if m:
                for a, s in zip(cur, state):
                    a[filled] = s[head : head + m]
                idx[filled] = np.arange(head, head + m)
                head += m
            alive[emptied] = False
            if emptied.size and alive.sum() * 2 < alive.size:
                cur = [a[alive] for a in cur]
                idx = idx[alive]
                alive = np.ones(idx.size, bool)
    st_q[idx[alive]] = STATUS_NOT_CONVERGED  # iteration cap: cannot happen for finite rays
    st_q[head:] = STATUS_NOT_CONVERGED
    st_out[queue] = st_q
    t_out[queue], qi_out[queue], qj_out[queue], tri_out[queue] = t_q, qi_q, qj_q, tri_q
    return t_out, st_out, qi_out, qj_out, tri_out


def intersect_dsm(
    dsm: Dsm | DsmTracer,
    origins: ArrayLike,
    directions: ArrayLike,
    *,
    accelerate: bool = True,
    min_incidence_deg: float = 5.0,
    chunk_size: int = 262144,
    backend: str = "auto",
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> DsmHits:
    """First intersection of N rays with the triangulated DSM (see the module docstring).

    Parameters
    ----------
    dsm : Dsm or DsmTracer
        The surface, in the CRS of the rays.
    origins, directions : (N, 3) array_like
        Ray origins (perspective centres) and directions (any length, pointing away from the
        camera), CRS unit. Hits with ``t < 0`` (behind the origin) are never returned.
    accelerate : bool
        Skip empty space with the max pyramid (same result as the plain DDA, faster).
    min_incidence_deg : float
        Hits where the ray meets the face at a smaller angle get status "grazing".
    chunk_size : int
        Rays per batch (progress and cancellation are checked per batch).
    backend : {"auto", "numba", "numpy"}
        The traversal compiled with numba (:mod:`core.geometry.raycast_numba`, optional dependency,
        10-30x faster) or vectorised with numpy; "auto" takes numba when it imports. Both
        return the same hits.
    progress, should_stop
        Fraction done; cancellation (raises :class:`core.errors.Cancelled`).

    Returns
    -------
    DsmHits

    Examples
    --------
    >>> from lidarphoto.core.geometry.grid import Grid
    >>> flat = Dsm(np.full((3, 3), 2.0, np.float32), Grid(0.0, 3.0, 1.0, 3, 3))
    >>> hits = intersect_dsm(flat, [[1.2, 1.7, 50.0]], [[0.0, 0.0, -1.0]])
    >>> hits.points.round(6).tolist(), RAY_STATUS_TEXT[int(hits.status[0])]
    ([[1.2, 1.7, 2.0]], 'ok')
    """
    tr = dsm if isinstance(dsm, DsmTracer) else DsmTracer.build(dsm)
    o = np.atleast_2d(np.asarray(origins, dtype=np.float64))
    d = np.atleast_2d(np.asarray(directions, dtype=np.float64))
    if o.shape != d.shape or o.ndim != 2 or o.shape[1] != 3:
        raise ValueError(f"origins and directions must be (N, 3), got {o.shape} and {d.shape}")
    n = o.shape[0]
    step = max(int(chunk_size), 1)
    if _use_numba(backend):
        from . import raycast_numba as dda_compiled

        out: dict[str, NDArray[Any]] = {
            "t": np.empty(n),
            "status": np.empty(n, np.int8),
            "qi": np.empty(n, np.int64),
            "qj": np.empty(n, np.int64),
            "tri": np.empty(n, np.int8),
            "points": np.empty((n, 3)),
            "weights": np.empty((n, 3)),
            "gradient": np.empty((n, 2)),
            "incidence": np.empty(n),
        }
        for start in range(0, n, step):
            stop_if_asked(should_stop, "intersecting rays with the DSM")
            sl = slice(start, min(start + step, n))
            dda_compiled.trace_rays(tr, o, d, accelerate, min_incidence_deg, out, sl)
            if progress is not None:
                progress(sl.stop / n)
        return DsmHits(
            out["points"],
            out["t"],
            out["status"],
            np.stack([out["qi"], out["qj"]], 1),
            out["tri"],
            out["weights"],
            out["gradient"],
            out["incidence"],
        )
    t = np.full(n, np.nan)
    status = np.full(n, STATUS_OUTSIDE, np.int8)
    qi = np.full(n, -1, np.int64)
    qj = np.full(n, -1, np.int64)
    tri = np.full(n, -1, np.int8)
    good = np.isfinite(o).all(axis=1) & np.isfinite(d).all(axis=1) & (np.abs(d).sum(axis=1) > 0)
    for start in range(0, n, step):
        stop_if_asked(should_stop, "intersecting rays with the DSM")
        sl = slice(start, min(start + step, n))
        sel = np.flatnonzero(good[sl]) + start
        if sel.size:
            res = _trace_chunk(tr, o[sel], d[sel], accelerate)
            t[sel], status[sel], qi[sel], qj[sel], tri[sel] = res
        if progress is not None:
            progress(min(start + step, n) / n)
    return _describe_hits(tr, o, d, t, status, qi, qj, tri, min_incidence_deg)


def _use_numba(backend: str) -> bool:
    """Resolve intersect_dsm's ``backend`` argument."""
    from .raycast_numba import AVAILABLE

    return use_compiled(backend, AVAILABLE)


def _describe_hits(
    tr: DsmTracer,
    o: Array,
    d: Array,
    t: Array,
    status: NDArray[np.int8],
    qi: NDArray[np.int64],
    qj: NDArray[np.int64],
    tri: NDArray[np.int8],
    min_incidence_deg: float,
) -> DsmHits:
    dsm = tr.dsm
    n = o.shape[0]
    points = np.full((n, 3), np.nan)
    t_hit = np.full(n, np.nan)
    weights = np.full((n, 3), np.nan)
    gradient = np.full((n, 2), np.nan)
    incidence = np.full(n, np.nan)
    h = np.flatnonzero(status == STATUS_OK)
    if h.size:
        t_hit[h] = t[h]
        dh = d[h]
        points[h] = o[h] + t[h, None] * dh
        i, j, k = qi[h], qj[h], tri[h] == 1
        base = i * dsm.heights.shape[1] + j
        left = tr.pairs[base].view(np.float32).reshape(-1, 2).astype(np.float64)
        right = tr.pairs[base + 1].view(np.float32).reshape(-1, 2).astype(np.float64)
        z00, z10, z01, z11 = left[:, 0], left[:, 1], right[:, 0], right[:, 1]
        u, v = dsm.to_grid_uv(points[h, 0], points[h, 1])
        u -= j
        v -= i
        gx = np.where(k, z11 - z10, z01 - z00) / dsm.cell
        gy = np.where(k, z10 - z00, z11 - z01) / -dsm.cell
        gradient[h, 0], gradient[h, 1] = gx, gy
        weights[h, 0] = np.where(k, 1 - v, 1 - u)
        weights[h, 1] = np.where(k, v - u, u - v)
        weights[h, 2] = np.where(k, u, v)
        cosang = np.abs(dh[:, 2] - gx * dh[:, 0] - gy * dh[:, 1]) / np.sqrt(
            (gx * gx + gy * gy + 1.0) * np.einsum("ij,ij->i", dh, dh)
        )
        incidence[h] = np.degrees(np.arcsin(np.minimum(cosang, 1.0)))
        status[h[incidence[h] < min_incidence_deg]] = STATUS_GRAZING
    return DsmHits(points, t_hit, status, np.stack([qi, qj], 1), tri, weights, gradient, incidence)


def chord_rays(local: Any, c_map: Array, c_loc: Array, d_loc: Array, s: Array) -> Array:
    """Unit directions in the mapping frame from each centre to its ENU ray's point at ``s``."""
    far = local.enu_to_map(c_loc + s[:, None] * d_loc)
    v = far - c_map
    return v / np.linalg.norm(v, axis=1, keepdims=True)
