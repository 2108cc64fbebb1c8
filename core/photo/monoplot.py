"""Monoplotting: 3D points and lines from one oriented image and a LiDAR DSM (paper 001).

The collinearity ray of an image point, ``G = CP + t N`` with ``N = M^T (x - x0, y - y0, -f)``
(paper 001, Eqs. 1-4), is intersected with the DSM polyhedron of :mod:`core.dsm`:

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
(here) and compiled with numba one ray after the other (:mod:`core.dda_compiled`, optional,
2-3x faster); :func:`intersect_dsm` takes numba when it imports.

Also here: Makarovic's iterative method (height -> planimetric position -> DSM height ...,
until the height changes less than a tolerance), the intersection with a LiDAR roof plane
(Eqs. 7-10 with the fitted plane) and the propagation of the image-point sigma, the
exterior-orientation covariance and the DSM (or plane) uncertainty into a 3 x 3 covariance.

Each ray gets a status code (:data:`STATUS_TEXT`): a ray that leaves the DSM, crosses a
nodata hole before hitting the surface, or belongs to an image without orientation is
reported, never raised. A DSM in another CRS is resampled into the mapping CRS first
(:func:`core.dsm.reproject_dsm`); when that is impossible (a vertical grid PROJ lacks) its
rays get the status crs_mismatch.

Frames: the EO table's omega-phi-kappa are relative to the grid frame at the perspective
centre, and a straight ray in the real (ENU) world is not straight in projected coordinates
(scale factor, Earth curvature: up to decimetres at 1 km). :func:`run_monoplot` therefore
builds each ray in the local ENU frame and intersects the DSM with its chord in the mapping
frame through the camera and the ray's point at the hit distance, found in two passes.
"""

from __future__ import annotations

import logging
import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Union

import numpy as np
import pyproj
from numpy.typing import ArrayLike, NDArray

from ..errors import Cancelled, CrsError, InputError, stop_if_asked
from ..geometry.camera import Camera, read_camera_json
from ..geometry.collinearity import collinearity_jacobians
from ..io.observations import ImageObservations, read_observations_csv
from ..io.pointcloud import parse_crs
from ..io.tables import write_csv_atomic
from ..lidar.dsm import Dsm, load_dsm, reproject_dsm
from .orientation import ExteriorOrientationTable, eo_map_to_local, read_eo_csv

LOG = logging.getLogger(__name__)

Array = NDArray[np.float64]
PathLike = Union[str, "os.PathLike[str]"]

STATUS_OK = 0
STATUS_GRAZING = 1
STATUS_OUTSIDE = 2
STATUS_NODATA = 3
STATUS_NO_ORIENTATION = 4
STATUS_NOT_CONVERGED = 5
STATUS_PARALLEL = 6
STATUS_UNKNOWN_PLANE = 7
STATUS_CRS_MISMATCH = 8
#: Meaning of each status code (the outputs carry both).
STATUS_TEXT = {
    STATUS_OK: "ok",
    STATUS_GRAZING: "grazing",  # hit, but the ray meets the face at less than the minimum angle
    STATUS_OUTSIDE: "outside",  # the ray leaves the DSM (or never reaches it) without a hit
    STATUS_NODATA: "nodata",  # the ray crosses a nodata hole before hitting the surface
    STATUS_NO_ORIENTATION: "no_orientation",  # the image is not in the EO table
    STATUS_NOT_CONVERGED: "not_converged",  # Makarovic's iteration did not converge
    STATUS_PARALLEL: "parallel",  # the ray is parallel to the plane or meets it behind
    STATUS_UNKNOWN_PLANE: "unknown_plane",  # target_id is not in the plane table
    STATUS_CRS_MISMATCH: "crs_mismatch",  # the DSM cannot be brought into the EO's CRS
}
METHODS = ("dal_poz", "makarovic")
#: Exterior-orientation sigmas (X, Y, Z m; omega, phi, kappa degrees) of a survey-grade
#: GNSS/INS after post-processing (POS AV 510 class), used when none is given.
DEFAULT_EO_SIGMAS = (0.05, 0.05, 0.08, 0.005, 0.005, 0.008)
_HIT = (STATUS_OK, STATUS_GRAZING)

__all__ = [
    "DEFAULT_EO_SIGMAS",
    "METHODS",
    "STATUS_TEXT",
    "DsmHits",
    "DsmTracer",
    "MonoplotLine",
    "MonoplotResult",
    "chord_rays",
    "dal_poz_intersect",
    "dal_poz_plane",
    "intersect_dsm",
    "intersect_planes",
    "makarovic",
    "propagate_covariance",
    "run_monoplot",
]


# --------------------------------------------------------------------------- Eqs. 6-10
def dal_poz_plane(o: ArrayLike, p: ArrayLike, q: ArrayLike) -> tuple[Array, Array]:
    """Plane ``A . X + B = 0`` of the faces OPQ (paper 001, Eqs. 5-7), vectorised.

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
    """Direct monorestitution (paper 001, Eqs. 9-10): ray ``CP + t N`` with ``A . X + B = 0``.

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
        :data:`STATUS_TEXT` codes (ok, grazing, outside, nodata).
    quad : (N, 2) int64
        (row, col) of the quad's top-left cell.
    triangle : (N,) int8
        0 or 1 (see :mod:`core.dsm`).
    weights : (N, 3) float64
        Barycentric weights at the hit of the face's three cells, in the order of
        :mod:`core.dsm`: (r, c), (r, c+1), (r+1, c+1) for triangle 0 and (r, c), (r+1, c),
        (r+1, c+1) for triangle 1 (the surface height is the weighted sum).
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
                block, np.ones((3, 3), np.uint8), borderType=cv2.BORDER_CONSTANT,
                borderValue=-np.inf,
            )  # fmt: skip
            out.append((lev, np.ascontiguousarray(dil, dtype=np.float32)))
        zmin, zmax = dsm.z_range
        # (z[r, c], z[r + 1, c]) side by side, 8 bytes per entry: the two corners of a quad
        # column come in one gather (the last row repeats itself; it is never a quad's top)
        below = np.vstack([z[1:], z[-1:]])
        pairs = np.ascontiguousarray(np.stack([z, below], axis=-1), np.float32)
        pairs = pairs.view(np.float64).reshape(-1)
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
        with np.errstate(divide="ignore", invalid="ignore"):
            a, b = z01 - z00, z11 - z01  # triangle 0: z = z00 + a u + b v
            ta = (rhs + a * ul + b * vl) / (dz - a * du - b * dv)
            ua, va = ul + du * ta, vl + dv * ta
            ok_a = (va >= -eps) & (ua <= 1 + eps) & (ua - va >= -eps) & (ta >= tc)
            a, b = z11 - z10, z10 - z00  # triangle 1
            tb = (rhs + a * ul + b * vl) / (dz - a * du - b * dv)
            ub, vb = ul + du * tb, vl + dv * tb
            ok_b = (ub >= -eps) & (vb <= 1 + eps) & (vb - ub >= -eps) & (tb >= tc)
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
        The traversal compiled with numba (:mod:`core.dda_compiled`, optional dependency,
        10-30x faster) or vectorised with numpy; "auto" takes numba when it imports. Both
        return the same hits.
    progress, should_stop
        Fraction done; cancellation (raises :class:`core.errors.Cancelled`).

    Returns
    -------
    DsmHits

    Examples
    --------
    >>> from core.ground_filter import Grid
    >>> flat = Dsm(np.full((3, 3), 2.0, np.float32), Grid(0.0, 3.0, 1.0, 3, 3))
    >>> hits = intersect_dsm(flat, [[1.2, 1.7, 50.0]], [[0.0, 0.0, -1.0]])
    >>> hits.points.round(6).tolist(), STATUS_TEXT[int(hits.status[0])]
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
        from ..geometry import raycast_numba as dda_compiled

        out = {
            "t": np.empty(n), "status": np.empty(n, np.int8), "qi": np.empty(n, np.int64),
            "qj": np.empty(n, np.int64), "tri": np.empty(n, np.int8),
            "points": np.empty((n, 3)), "weights": np.empty((n, 3)),
            "gradient": np.empty((n, 2)), "incidence": np.empty(n),
        }  # fmt: skip
        for start in range(0, n, step):
            stop_if_asked(should_stop, "intersecting rays with the DSM")
            sl = slice(start, min(start + step, n))
            dda_compiled.trace_rays(tr, o, d, accelerate, min_incidence_deg, out, sl)
            if progress is not None:
                progress(sl.stop / n)
        return DsmHits(out["points"], out["t"], out["status"],
                       np.stack([out["qi"], out["qj"]], 1), out["tri"], out["weights"],
                       out["gradient"], out["incidence"])  # fmt: skip
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
    from ..geometry.raycast_numba import AVAILABLE

    if backend not in ("auto", "numba", "numpy"):
        raise ValueError(f"backend must be 'auto', 'numba' or 'numpy', got {backend!r}")
    if backend == "numba" and not AVAILABLE:
        raise InputError("backend 'numba' asked for, but numba is not installed "
                         "(pip install numba)")  # fmt: skip
    return AVAILABLE and backend != "numpy"


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


# --------------------------------------------------------------------------- Makarovic
def makarovic(
    dsm: Dsm,
    origins: ArrayLike,
    directions: ArrayLike,
    *,
    z_start: float | None = None,
    tol: float = 1e-4,
    max_iter: int = 100,
) -> tuple[Array, NDArray[np.int8], NDArray[np.int64]]:
    """Makarovic's iterative monoplotting: Z -> (X, Y) on the ray -> Z = DSM(X, Y) -> ...

    Converges where the ray is steeper than the terrain (``|slope| tan(off-nadir) < 1``);
    on walls and behind occluders it oscillates or stops on a surface the camera cannot see.

    Parameters
    ----------
    dsm : Dsm
    origins, directions : (N, 3) array_like
        Rays as in :func:`intersect_dsm` (directions must point downwards).
    z_start : float, optional
        First height (default: the mean DSM height).
    tol : float
        Height change (CRS unit) below which the iteration stops.
    max_iter : int

    Returns
    -------
    points : (N, 3) ndarray
        NaN where not converged.
    status : (N,) int8
        ok, outside, nodata or not_converged.
    iterations : (N,) int64
    """
    o = np.atleast_2d(np.asarray(origins, dtype=np.float64))
    d = np.atleast_2d(np.asarray(directions, dtype=np.float64))
    n = o.shape[0]
    z = np.full(n, float(np.nanmean(dsm.heights)) if z_start is None else float(z_start))
    status = np.full(n, STATUS_NOT_CONVERGED, np.int8)
    status[~(d[:, 2] < 0)] = STATUS_OUTSIDE
    iters = np.zeros(n, np.int64)
    out = np.full((n, 3), np.nan)
    act = np.flatnonzero(d[:, 2] < 0)
    rows, cols = dsm.heights.shape
    for _ in range(max_iter):
        if act.size == 0:
            break
        s = (z[act] - o[act, 2]) / d[act, 2]
        x, y = o[act, 0] + s * d[act, 0], o[act, 1] + s * d[act, 1]
        zn = dsm.height_at(x, y)
        iters[act] += 1
        u, v = dsm.to_grid_uv(x, y)
        inside = (u >= 0) & (v >= 0) & (u <= cols - 1) & (v <= rows - 1)
        bad = ~np.isfinite(zn)
        status[act[bad]] = np.where(inside[bad], STATUS_NODATA, STATUS_OUTSIDE)
        conv = ~bad & (np.abs(zn - z[act]) < tol)
        k = act[conv]
        sk = (zn[conv] - o[k, 2]) / d[k, 2]
        out[k] = o[k] + sk[:, None] * d[k]
        status[k] = STATUS_OK
        z[act] = zn
        act = act[~bad & ~conv]
    return out, status, iters


# --------------------------------------------------------------------------- planes
def intersect_planes(
    origins: ArrayLike, directions: ArrayLike, normals: ArrayLike, d: ArrayLike
) -> tuple[Array, NDArray[np.int8]]:
    """Ray / roof-plane intersection (Eqs. 7-10 with ``A = n``, ``B = d`` of the fitted plane).

    Returns the points (N, 3) and the status (ok, or parallel where the ray is within 1e-9
    of parallel to the plane or meets it behind the camera).
    """
    o = np.atleast_2d(np.asarray(origins, dtype=np.float64))
    v = np.atleast_2d(np.asarray(directions, dtype=np.float64))
    g, t = dal_poz_intersect(o, v, normals, d)
    nn = np.atleast_2d(np.asarray(normals, dtype=np.float64))
    cos = np.abs(np.einsum("ij,ij->i", nn, v)) / (
        np.linalg.norm(nn, axis=1) * np.linalg.norm(v, axis=1)
    )
    ok = np.isfinite(t) & (t > 0) & (cos > 1e-9)
    g[~ok] = np.nan
    return g, np.where(ok, STATUS_OK, STATUS_PARALLEL).astype(np.int8)


# --------------------------------------------------------------------------- precision
def propagate_covariance(
    points: ArrayLike,
    eo: ArrayLike,
    camera: Camera,
    sigma_px: ArrayLike,
    eo_cov: ArrayLike,
    constraint: ArrayLike,
    constraint_var: ArrayLike,
) -> Array:
    """3 x 3 covariance of monoplotted points (first-order, analytic Jacobians).

    The point G solves ``pixel(G, eo) = measured pixel`` (2 equations, collinearity) and
    ``h(G) = 0`` (the surface: the DSM face ``G_z - z(G_x, G_y)`` or a plane ``n . G + d``).
    With ``A = [dpixel/dG; dh/dG]`` (3 x 3) and the covariance ``S`` of the right-hand side,
    ``Sigma_G = A^-1 S A^-T``, where ``S[:2, :2] = sigma_px^2 I + J_eo Sigma_eo J_eo^T`` and
    ``S[2, 2]`` is the variance of the surface at G.

    Parameters
    ----------
    points : (N, 3) array_like
        Monoplotted points (frame of the EO).
    eo : (N, 6) array_like
        (X0, Y0, Z0, omega, phi, kappa) per point, metres and radians.
    camera : Camera
    sigma_px : (N,) array_like
        Image-point sigma, pixels (col and row, uncorrelated).
    eo_cov : (6, 6) or (N, 6, 6) array_like
        EO covariance (metres, radians).
    constraint : (N, 3) array_like
        Gradient of h: ``(-dz/dx, -dz/dy, 1)`` for a DSM face, the normal for a plane.
    constraint_var : (N,) array_like
        Variance of h at G: ``sigma_h^2 sum(w_k^2)`` for a face with independent vertex
        heights, ``[G, 1]^T C [G, 1]`` for a plane with covariance C of (a, b, c, d).

    Returns
    -------
    (N, 3, 3) ndarray
    """
    p = np.atleast_2d(np.asarray(points, dtype=np.float64))
    n = p.shape[0]
    jac = collinearity_jacobians(p, eo, camera, wrt=("eo", "point"))
    a = np.concatenate([jac["point"], np.asarray(constraint, float).reshape(n, 1, 3)], axis=1)
    cov_eo = np.broadcast_to(np.asarray(eo_cov, dtype=np.float64), (n, 6, 6))
    s = np.zeros((n, 3, 3))
    sig = np.broadcast_to(np.asarray(sigma_px, dtype=np.float64), (n,))
    s[:, :2, :2] = np.einsum("nij,njk,nlk->nil", jac["eo"], cov_eo, jac["eo"])
    s[:, 0, 0] += sig**2
    s[:, 1, 1] += sig**2
    s[:, 2, 2] = np.asarray(constraint_var, dtype=np.float64)
    out = np.full((n, 3, 3), np.nan)
    ok = np.isfinite(a).all(axis=(1, 2)) & (np.abs(np.linalg.det(np.where(
        np.isfinite(a), a, 0.0))) > 1e-300)  # fmt: skip
    if ok.any():
        ainv = np.linalg.inv(a[ok])
        out[ok] = ainv @ s[ok] @ np.swapaxes(ainv, 1, 2)
    return out


# --------------------------------------------------------------------------- the job
@dataclass(frozen=True)
class MonoplotLine:
    """A 3D line from one image: its vertices in order (image line end points and, when
    densified, points along it)."""

    image_id: str
    target_id: str
    vertices: Array  # (M, 3), NaN rows where a vertex failed
    status: int  # worst vertex status
    sigma_ends: tuple[float, float]  # 3D sigma (sqrt of the covariance trace) at both ends


@dataclass(frozen=True)
class MonoplotResult:
    """Every monoplotted ray (observation points, line vertices) and the lines.

    Arrays are per ray (N rows): ``points`` (N, 3) mapping CRS, ``covariance`` (N, 3, 3),
    ``status`` (N,), ``incidence_deg`` (N,), ``pixels`` (N, 2); ``rows`` holds per ray
    ``(image_id, point_id, type, target_id, line, vertex, method)`` (line -1 for points).
    """

    rows: list[tuple[str, str, str, str, int, int, str]]
    pixels: Array
    points: Array
    covariance: Array
    status: NDArray[np.int8]
    incidence_deg: Array
    lines: list[MonoplotLine]
    crs_wkt: str
    dsm: Dsm | None = field(default=None, repr=False)

    @property
    def sigmas(self) -> Array:
        """(N, 3) standard deviations of X, Y, Z."""
        return np.sqrt(np.clip(np.diagonal(self.covariance, axis1=1, axis2=2), 0, None))

    def status_counts(self) -> dict[str, int]:
        codes, counts = np.unique(self.status, return_counts=True)
        return {STATUS_TEXT[int(c)]: int(k) for c, k in zip(codes, counts)}


def _parse_sigmas(value: Any) -> Array:
    if isinstance(value, str):
        try:
            value = [float(v) for v in value.replace(";", ",").split(",") if v.strip()]
        except ValueError:
            raise InputError(f"EO sigmas: '{value}' is not 6 numbers") from None
    arr = np.asarray(value, dtype=np.float64).ravel()
    if arr.size != 6 or not np.isfinite(arr).all() or (arr < 0).any():
        raise InputError("EO sigmas: give 6 numbers >= 0: X, Y, Z (m), omega, phi, kappa (deg)")
    return arr


def _line_rays(
    obs: ImageObservations, step_px: float
) -> tuple[list[tuple[int, int, int, float]], list[tuple[str, str]]]:
    """Rays of the line observations: (observation row, line, vertex, fraction to next row).

    Rows of type ``line`` with the same image_id and target_id form one line, vertices in
    file order. With ``step_px > 0``, points every ``step_px`` pixels are added between them.
    """
    groups: dict[tuple[str, str], list[int]] = {}
    for k, (img, kind, tgt) in enumerate(zip(obs.image_id, obs.type, obs.target_id)):
        if kind == "line":
            groups.setdefault((img, tgt), []).append(k)
    rays: list[tuple[int, int, int, float]] = []
    keys: list[tuple[str, str]] = []
    for key, members in groups.items():
        if len(members) < 2:
            LOG.warning("line %s in image %s has one vertex: kept as a point", key[1], key[0])
            continue
        line = len(keys)
        keys.append(key)
        vertex = 0
        for a, b in zip(members[:-1], members[1:]):
            rays.append((a, line, vertex, 0.0))
            vertex += 1
            if step_px > 0:
                length = float(np.linalg.norm(obs.pixels[b] - obs.pixels[a]))
                m = math.ceil(length / step_px) - 1
                for s in range(1, m + 1):
                    rays.append((a, line, vertex, s / (m + 1)))
                    vertex += 1
        rays.append((members[-1], line, vertex, 0.0))
    return rays, keys


def chord_rays(local: Any, c_map: Array, c_loc: Array, d_loc: Array, s: Array) -> Array:
    """Unit directions in the mapping frame from each centre to its ENU ray's point at ``s``."""
    far = local.enu_to_map(c_loc + s[:, None] * d_loc)
    v = far - c_map
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _two_pass(
    solve: Callable[[Array, Array], tuple[Array, NDArray[np.int8]]],
    local: Any,
    c_map: Array,
    c_loc: Array,
    d_loc: Array,
    s_far: Array,
) -> tuple[Array, NDArray[np.int8], Array]:
    """Intersect along the chord to ``s_far``, then along the chord to the first hit."""
    dirs = chord_rays(local, c_map, c_loc, d_loc, s_far)
    pts, status = solve(c_map, dirs)
    hit = np.isin(status, _HIT)
    if hit.any():
        s1 = np.einsum("ij,ij->i", local.map_to_enu(pts[hit]) - c_loc[hit], d_loc[hit])
        d2 = dirs.copy()
        d2[hit] = chord_rays(local, c_map[hit], c_loc[hit], d_loc[hit], s1)
        p2, st2 = solve(c_map, d2)
        pts, status, dirs = np.where(hit[:, None], p2, pts), np.where(hit, st2, status), d2
    return pts, status.astype(np.int8), dirs


def _crs_equal(a: pyproj.CRS, b: pyproj.CRS) -> bool:
    return bool(a.equals(b, ignore_axis_order=True))


def run_monoplot(
    observations: PathLike | ImageObservations,
    camera: PathLike | Camera,
    eo: PathLike | ExteriorOrientationTable,
    dsm: PathLike | Dsm | DsmTracer,
    crs: str | int | pyproj.CRS,
    *,
    dsm_crs: str | int | pyproj.CRS | None = None,
    cell_size: float = 0.5,
    distance_unit: str = "crs",
    method: str = "dal_poz",
    sigma_dsm: float = 0.10,
    eo_sigmas: Any = DEFAULT_EO_SIGMAS,
    planes: PathLike | None = None,
    line_step_px: float = 0.0,
    min_incidence_deg: float = 5.0,
    output_csv: PathLike | None = None,
    lines_csv: PathLike | None = None,
    output_dsm: PathLike | None = None,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> MonoplotResult:
    """Monoplot the observations of oriented images on a DSM (or on roof planes).

    Parameters
    ----------
    observations : path or ImageObservations
        Image-observation CSV (:mod:`core.io.observations`). Rows of type ``line`` with the
        same image_id and target_id form one 3D line (vertices in file order); every other
        row is a point. Rows of type ``tie`` or ``paper`` whose target_id is a plane of
        ``planes`` are intersected with that plane instead of the DSM.
    camera : path or Camera
        Camera JSON.
    eo : path or ExteriorOrientationTable
        EO CSV (:mod:`core.orientation`), in ``crs``.
    dsm : path, Dsm or DsmTracer
        DSM raster (GeoTIFF...) or LAS/LAZ rasterised at ``cell_size`` (highest return); a
        DsmTracer is reused as is (no rebuild of the skipping pyramid).
    crs : mapping CRS of the EO and of the outputs (projected, metres).
    dsm_crs : optional
        CRS of the DSM when its file has none (or to override it).
    cell_size, distance_unit
        DSM cell for a LAS/LAZ input, in the cloud's unit or metres.
    method : {"dal_poz", "makarovic"}
        Direct (DDA + Eq. 9) or iterative intersection with the DSM.
    sigma_dsm : float
        Standard deviation of a DSM height, metres (vertices independent).
    eo_sigmas : 6 numbers or str
        X, Y, Z (m) and omega, phi, kappa (degrees) standard deviations of the EO.
    planes : path, optional
        Plane table CSV (:mod:`core.planes`).
    line_step_px : float
        Spacing of the extra points along image lines, pixels (0: end points only).
    min_incidence_deg : float
        Rays meeting the DSM face at a smaller angle get status "grazing".
    output_csv, lines_csv, output_dsm : paths, optional
        Point table, line table and (for a LAS/LAZ input) the DSM GeoTIFF, written atomically.
    progress, should_stop
        Progress fraction; cancellation.

    Returns
    -------
    MonoplotResult
    """
    from ..geometry.frames import LocalFrame, MappingFrame

    if method not in METHODS:
        raise InputError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    sig6 = _parse_sigmas(eo_sigmas)
    eo_cov = np.diag(np.r_[sig6[:3], np.radians(sig6[3:])] ** 2)
    obs = observations if isinstance(observations, ImageObservations) else (
        read_observations_csv(observations))  # fmt: skip
    cam = camera if isinstance(camera, Camera) else read_camera_json(camera)
    table = eo if isinstance(eo, ExteriorOrientationTable) else read_eo_csv(eo)
    mapping_crs = parse_crs(crs)
    if mapping_crs is None:
        raise CrsError("the mapping CRS of the exterior orientation is required")

    def sub(lo: float, hi: float) -> Callable[[float], None] | None:
        return None if progress is None else (lambda f: progress(lo + (hi - lo) * f))

    tracer = dsm if isinstance(dsm, DsmTracer) else None
    if tracer is not None:  # a prepared DSM (interactive use: one click after another)
        dsm = tracer.dsm
    if not isinstance(dsm, Dsm):
        dsm = load_dsm(dsm, cell_size, dsm_crs, distance_unit=distance_unit,
                       progress=sub(0.0, 0.4), should_stop=should_stop)  # fmt: skip
    elif dsm_crs:
        dsm = Dsm(dsm.heights, dsm.grid, parse_crs(dsm_crs), dsm.source)

    # --- the rays: points, then line vertices (with densified points)
    step = float(line_step_px)
    line_rays, line_keys = _line_rays(obs, step if step > 0 else 0.0)
    in_lines = {r[0] for r in line_rays}
    point_rows = [k for k in range(len(obs)) if k not in in_lines]
    src = np.array(point_rows + [r[0] for r in line_rays], dtype=np.int64)
    frac = np.array([0.0] * len(point_rows) + [r[3] for r in line_rays])
    nxt = np.array(point_rows + [r[0] + 0 for r in line_rays], dtype=np.int64)
    # densified points interpolate towards the next vertex of their line
    for n_i, r in enumerate(line_rays):
        if r[3] > 0:
            later = [q for q in line_rays[n_i:] if q[1] == r[1] and q[3] == 0.0]
            nxt[len(point_rows) + n_i] = later[0][0]
    pixels = obs.pixels[src] * (1 - frac[:, None]) + obs.pixels[nxt] * frac[:, None]
    sigma_px = obs.sigma_px[src]
    line_of = np.array([-1] * len(point_rows) + [r[1] for r in line_rays], dtype=np.int64)
    vertex_of = np.array([-1] * len(point_rows) + [r[2] for r in line_rays], dtype=np.int64)
    n = src.size
    points = np.full((n, 3), np.nan)
    cov = np.full((n, 3, 3), np.nan)
    status = np.full(n, STATUS_OUTSIDE, np.int8)
    incidence = np.full(n, np.nan)
    used = ["dsm"] * n

    index = {img: k for k, img in enumerate(table.image_id)}
    img_idx = np.array([index.get(obs.image_id[k], -1) for k in src], dtype=np.int64)
    status[img_idx < 0] = STATUS_NO_ORIENTATION
    if (img_idx < 0).any():
        missing = sorted({obs.image_id[k] for k in src[img_idx < 0]})
        LOG.warning("no exterior orientation for image(s) %s", ", ".join(missing[:10]))

    dsm_ok = True
    if dsm.crs is None:
        LOG.warning("the DSM has no CRS: taken to be the mapping CRS %s", mapping_crs.name)
    elif not _crs_equal(dsm.crs, mapping_crs):
        try:
            source_crs = dsm.crs.name
            dsm = reproject_dsm(dsm, mapping_crs, should_stop=should_stop)
            LOG.warning("the DSM was in '%s': resampled into the mapping CRS '%s' (cell %g)",
                        source_crs, mapping_crs.name, dsm.cell)  # fmt: skip
        except CrsError as exc:
            dsm_ok = False
            LOG.warning("the DSM cannot be brought into the mapping CRS '%s': %s; its points "
                        "are not monoplotted", mapping_crs.name, exc)  # fmt: skip
    if output_dsm:
        dsm.to_geotiff(output_dsm)

    plane_map: dict[str, Any] = {}
    if planes:
        from ..geometry.planes import read_planes_csv

        plane_map = {str(p.id): p for p in read_planes_csv(planes)}
    kinds = [obs.type[k] for k in src]
    targets = [obs.target_id[k] for k in src]
    on_plane = np.array(
        [bool(planes) and kd in ("tie", "paper") and line_of[r] < 0 for r, kd in enumerate(kinds)]
    )
    unknown = on_plane & np.array([t not in plane_map for t in targets])
    status[unknown & (img_idx >= 0)] = STATUS_UNKNOWN_PLANE
    on_plane &= ~unknown
    if not dsm_ok:
        status[(img_idx >= 0) & ~on_plane & ~unknown] = STATUS_CRS_MISMATCH

    todo = np.flatnonzero((img_idx >= 0) & ~unknown & (on_plane | dsm_ok))
    if todo.size:
        if should_stop is not None and should_stop():
            raise Cancelled("cancelled before monoplotting")
        mapping = MappingFrame(mapping_crs)
        zmin = dsm.z_range[0]
        xc, yc = (
            dsm.grid.x0 + dsm.grid.cols * dsm.cell / 2,
            dsm.grid.y_top - dsm.grid.rows * dsm.cell / 2,
        )
        local = LocalFrame.at_map_point(mapping, [xc, yc, zmin])
        c_loc_img, m_loc_img = eo_map_to_local(table.xyz, table.opk, local)
        ideal = cam.ideal_from_pixel(pixels[todo])
        ray_c = np.column_stack([ideal, np.full(todo.size, -cam.focal_mm)])
        d_loc = np.einsum("nji,nj->ni", m_loc_img[img_idx[todo]], ray_c)
        d_loc /= np.linalg.norm(d_loc, axis=1, keepdims=True)
        c_loc = c_loc_img[img_idx[todo]]
        c_map = table.xyz[img_idx[todo]]
        z_low = local.map_to_enu(np.array([[xc, yc, zmin - 10.0]]))[0, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            s_far = np.where(d_loc[:, 2] < -1e-6, (c_loc[:, 2] - z_low) / -d_loc[:, 2], 1e3)
        s_far = np.maximum(s_far, 1.0)
        eo_rows = np.hstack([table.xyz, table.opk])[img_idx[todo]]
        grad = np.full((todo.size, 3), np.nan)
        var_h = np.full(todo.size, np.nan)
        plane_sel = on_plane[todo]
        dsm_sel = ~plane_sel
        res_pts = np.full((todo.size, 3), np.nan)
        res_st = np.full(todo.size, STATUS_OUTSIDE, np.int8)
        res_inc = np.full(todo.size, np.nan)
        if dsm_sel.any():
            k = np.flatnonzero(dsm_sel)
            if tracer is None or tracer.dsm is not dsm:
                tracer = DsmTracer.build(dsm)
            last: dict[str, DsmHits] = {}

            def solve_dsm(o: Array, d: Array) -> tuple[Array, NDArray[np.int8]]:
                if method == "makarovic":
                    return makarovic(dsm, o, d)[:2]
                hits = intersect_dsm(tracer, o, d, min_incidence_deg=min_incidence_deg,
                                     should_stop=should_stop)  # fmt: skip
                last["hits"] = hits
                return hits.points, hits.status

            args = (local, c_map[k], c_loc[k], d_loc[k], s_far[k])
            pts, st, dirs = _two_pass(solve_dsm, *args)
            if method == "dal_poz":
                hits = last["hits"]
            else:
                # the face under the converged point gives the gradient for the precision
                hits = intersect_dsm(tracer, c_map[k], dirs, min_incidence_deg=0.0)
                st = np.where((st == STATUS_OK) & (hits.status == STATUS_GRAZING),
                              STATUS_GRAZING, st).astype(np.int8)  # fmt: skip
            res_pts[k], res_st[k], res_inc[k] = pts, st, hits.incidence_deg
            grad[k] = np.column_stack([-hits.gradient, np.ones(k.size)])
            var_h[k] = sigma_dsm**2 * np.sum(hits.weights**2, axis=1)
        if plane_sel.any():
            k = np.flatnonzero(plane_sel)
            pl = [plane_map[targets[todo[q]]] for q in k]
            normal = np.array([p.normal for p in pl])
            offset = np.array([p.d for p in pl])
            pcov = np.array([p.covariance for p in pl])

            def solve_plane(o: Array, d: Array) -> tuple[Array, NDArray[np.int8]]:
                return intersect_planes(o, d, normal, offset)

            pts, st, _ = _two_pass(solve_plane, local, c_map[k], c_loc[k], d_loc[k], s_far[k])
            res_pts[k], res_st[k] = pts, st
            res_inc[k] = 90.0 - np.degrees(np.arccos(np.clip(np.abs(
                np.einsum("ij,ij->i", normal, d_loc[k])), 0, 1)))  # fmt: skip
            grad[k] = normal
            g1 = np.column_stack([np.nan_to_num(pts), np.ones(k.size)])
            var_h[k] = np.einsum("ni,nij,nj->n", g1, pcov, g1)
            for q in k:
                used[todo[q]] = "plane"
        if method == "makarovic":
            for q in np.flatnonzero(dsm_sel):
                used[todo[q]] = "makarovic"
        points[todo], status[todo], incidence[todo] = res_pts, res_st, res_inc
        hit = np.isin(res_st, _HIT)
        if hit.any():
            cov[todo[hit]] = propagate_covariance(
                res_pts[hit], eo_rows[hit], cam, sigma_px[todo[hit]], eo_cov, grad[hit],
                var_h[hit],
            )  # fmt: skip
    if progress is not None:
        progress(0.95)

    rows = [
        (obs.image_id[s], obs.point_id[s], obs.type[s], obs.target_id[s], int(li), int(vi),
         used[r])
        for r, (s, li, vi) in enumerate(zip(src, line_of, vertex_of))
    ]  # fmt: skip
    lines = []
    for li, (img, tgt) in enumerate(line_keys):
        sel = np.flatnonzero(line_of == li)
        sel = sel[np.argsort(vertex_of[sel])]
        ends = [float(np.sqrt(np.trace(cov[sel[e]]))) for e in (0, -1)]
        worst = int(max(status[sel], key=lambda s: (s not in _HIT, s)))
        lines.append(MonoplotLine(img, tgt, points[sel], worst, (ends[0], ends[1])))
    result = MonoplotResult(rows, pixels, points, cov, status, incidence, lines,
                            mapping_crs.to_wkt(), dsm)  # fmt: skip
    if output_csv:
        _write_points_csv(output_csv, result)
    if lines_csv:
        _write_lines_csv(lines_csv, result)
    LOG.info("monoplotted %d rays: %s", n, result.status_counts())
    if progress is not None:
        progress(1.0)
    return result


POINT_COLUMNS = (
    "image_id", "point_id", "type", "target_id", "line", "vertex", "col", "row", "X", "Y",
    "Z", "sigma_x", "sigma_y", "sigma_z", "cov_xy", "cov_xz", "cov_yz", "status",
    "status_text", "method", "incidence_deg",
)  # fmt: skip
LINE_COLUMNS = ("line", "image_id", "target_id", "n_vertices", "status", "status_text",
                "length", "sigma_start", "sigma_end", "wkt")  # fmt: skip


def _f(v: float, fmt: str = ".4f") -> str:
    return format(float(v), fmt) if np.isfinite(v) else ""


def _write_points_csv(path: PathLike, r: MonoplotResult) -> None:
    sig = r.sigmas
    out = []
    for k, (img, pid, kind, tgt, li, vi, how) in enumerate(r.rows):
        c = r.covariance[k]
        out.append((
            img, pid, kind, tgt, li, vi, _f(r.pixels[k, 0], ".3f"), _f(r.pixels[k, 1], ".3f"),
            *(_f(v) for v in r.points[k]), *(_f(v, ".5f") for v in sig[k]),
            *(_f(v, ".3e") for v in (c[0, 1], c[0, 2], c[1, 2])), int(r.status[k]),
            STATUS_TEXT[int(r.status[k])], how, _f(r.incidence_deg[k], ".2f"),
        ))  # fmt: skip
    write_csv_atomic(Path(path), POINT_COLUMNS, out)


def _write_lines_csv(path: PathLike, r: MonoplotResult) -> None:
    out = []
    for li, ln in enumerate(r.lines):
        v = ln.vertices[np.isfinite(ln.vertices).all(axis=1)]
        length = float(np.linalg.norm(np.diff(v, axis=0), axis=1).sum()) if len(v) > 1 else 0.0
        wkt = "LINESTRING Z (" + ", ".join(f"{x:.4f} {y:.4f} {z:.4f}" for x, y, z in v) + ")"
        out.append((li, ln.image_id, ln.target_id, len(ln.vertices), ln.status,
                    STATUS_TEXT[ln.status], _f(length), _f(ln.sigma_ends[0], ".5f"),
                    _f(ln.sigma_ends[1], ".5f"), wkt if len(v) > 1 else ""))  # fmt: skip
    write_csv_atomic(Path(path), LINE_COLUMNS, out)
