"""LiDAR control from roof planes: plane adjacency, three-plane points (LCPs) and two-plane
lines (ridges, hips, valleys), each with a covariance propagated from the plane fits.

Planes are ``n . p + d = 0`` with unit normal ``n`` (c >= 0) and a 4 x 4 covariance of
``(a, b, c, d)`` from the roof-plane fit; planes of different roof faces are independent (their
points are). Coordinates are those of the cloud (a projected CRS; metres or the CRS unit, as
the planes were fitted). First-order (Jacobian) propagation is used throughout; the tests
check it against Monte Carlo scatter.

Three planes: ``N X = -d`` with the normals as rows of ``N``; with ``J_i = -N^-1 e_i [X', 1]``
the covariance is ``sum_i J_i C_i J_i'``.

Two planes: the direction ``u = n1 x n2 / |n1 x n2|`` and the point ``X0`` of the line
nearest to a reference point ``c`` (the centre of the contact zone) solve
``[n1; n2; u] X0 = [-d1, -d2, u . c]``; its covariance is the 6 x 6 of ``(X0, u)``.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Callable

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError, stop_if_asked
from ..geometry.rotations import skew
from ..geometry.sym3 import eigh_sym3
from ..i18n import Message, joined
from ..i18n import mark as _t
from .control_options import ControlOptions

log = logging.getLogger(__name__)

Array = NDArray[np.float64]

LINE_KINDS = ("ridge", "hip", "valley", "other")
#: the six parameters of a :class:`ControlLine` in the order of its covariance: the line
#: point X0 (CRS units) and the unit direction u
LINE_PARAMETERS = ("x0", "y0", "z0", "ux", "uy", "uz")


# ----------------------------------------------------------------------------- intersections
def intersect_three_planes(
    normals: Array, d: Array, covariances: Array
) -> tuple[Array, Array, Array]:
    """Batched three-plane intersection with first-order covariance.

    Parameters
    ----------
    normals : (T, 3, 3) unit normals, one plane per row.
    d : (T, 3) plane offsets.
    covariances : (T, 3, 4, 4) covariance of (a, b, c, d) of each plane.

    Returns
    -------
    points (T, 3), covariance (T, 3, 3), condition number of N (T,) (inf when singular;
    those rows are NaN).
    """
    n = np.asarray(normals, dtype=np.float64)
    dd = np.asarray(d, dtype=np.float64)
    cov = np.asarray(covariances, dtype=np.float64)
    cond = np.linalg.cond(n)
    ok = np.isfinite(cond) & (cond < 1e12)
    x = np.full(dd.shape, np.nan)
    c = np.full((*dd.shape[:-1], 3, 3), np.nan)
    if not np.any(ok):
        return x, c, np.where(ok, cond, np.inf)
    inv = np.linalg.inv(n[ok])  # (T, 3, 3)
    xo = -np.einsum("tij,tj->ti", inv, dd[ok])
    xh = np.concatenate([xo, np.ones((xo.shape[0], 1))], axis=1)  # [X', 1]
    # J_i = -inv[:, :, i] outer [X', 1]: (T, 3 planes, 3, 4)
    jac = -inv.transpose(0, 2, 1)[:, :, :, None] * xh[:, None, None, :]
    c_ok = np.einsum("tpik,tpkl,tpjl->tij", jac, cov[ok], jac)
    c_ok = 0.5 * (c_ok + c_ok.transpose(0, 2, 1))
    x[ok], c[ok] = xo, c_ok
    return x, c, np.where(ok, cond, np.inf)


def intersect_two_planes(
    n1: Array, d1: Array, cov1: Array, n2: Array, d2: Array, cov2: Array, ref: Array
) -> tuple[Array, Array, Array]:
    """Batched two-plane line: point nearest ``ref`` (E, 3), unit direction (E, 3), and the
    (E, 6, 6) covariance of (point, direction). Parallel planes give NaN rows."""
    n1, n2 = np.asarray(n1, dtype=float), np.asarray(n2, dtype=float)
    d1, d2 = np.asarray(d1, dtype=float), np.asarray(d2, dtype=float)
    ref = np.asarray(ref, dtype=float)
    raw = np.cross(n1, n2)
    norm = np.linalg.norm(raw, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        u = raw / norm[:, None]
    a = np.stack([n1, n2, u], axis=1)
    b = np.stack([-d1, -d2, np.einsum("ei,ei->e", u, ref)], axis=1)
    good = norm > 1e-9
    x0 = np.full(ref.shape, np.nan)
    cov = np.full((ref.shape[0], 6, 6), np.nan)
    if not np.any(good):
        return x0, u, cov
    ainv = np.linalg.inv(a[good])
    xg = np.einsum("eij,ej->ei", ainv, b[good])
    ug, ng = u[good], norm[good]
    # du = P du_raw / |raw|, du_raw = -[n2]x dn1 + [n1]x dn2
    proj = (np.eye(3) - ug[:, :, None] * ug[:, None, :]) / ng[:, None, None]
    du_dn1 = proj @ -skew(n2[good])
    du_dn2 = proj @ skew(n1[good])
    # dX0 = A^-1 [-(dd1 + dn1.X0), -(dd2 + dn2.X0), du.(c - X0)]
    e = xg.shape[0]
    r = ref[good] - xg
    rows = np.zeros((e, 3, 8))
    rows[:, 0, 0:3] = -xg
    rows[:, 0, 3] = -1.0
    rows[:, 1, 4:7] = -xg
    rows[:, 1, 7] = -1.0
    rows[:, 2, 0:3] = np.einsum("ei,eij->ej", r, du_dn1)
    rows[:, 2, 4:7] = np.einsum("ei,eij->ej", r, du_dn2)
    jx = ainv @ rows  # wrt (n1, d1, n2, d2)
    ju = np.zeros((e, 3, 8))
    ju[:, :, 0:3] = du_dn1
    ju[:, :, 4:7] = du_dn2
    jac = np.concatenate([jx, ju], axis=1)  # (E, 6, 8)
    cp = np.zeros((e, 8, 8))
    cp[:, :4, :4] = np.asarray(cov1, dtype=float)[good]
    cp[:, 4:, 4:] = np.asarray(cov2, dtype=float)[good]
    x0[good] = xg
    cg = jac @ cp @ jac.transpose(0, 2, 1)
    cov[good] = 0.5 * (cg + cg.transpose(0, 2, 1))  # exactly symmetric, as tables store it
    return x0, u, cov


def error_ellipsoid(cov: Array, confidence_scale: float = 1.0) -> tuple[Array, Array]:
    """Semi-axes (..., 3) in decreasing order and their directions (..., 3, 3) as columns, of
    covariances (..., 3, 3) (CRS unit^2). By the fixed Jacobi rotations of
    :func:`core.geometry.sym3.eigh_sym3`, not LAPACK: the same bits on any thread count or
    numpy (LAPACK's eigh on Debian's OpenBLAS moved the axes with the thread count)."""
    c = np.asarray(cov, dtype=float)
    w, v = eigh_sym3(c.reshape(-1, 3, 3))
    w = np.clip(w[:, ::-1], 0.0, None).reshape(c.shape[:-1])
    return confidence_scale * np.sqrt(w), v[:, :, ::-1].reshape(c.shape)


# ----------------------------------------------------------------------------- adjacency
@dataclass(frozen=True)
class Adjacency:
    """Plane pairs whose points touch (E, 2) (plane ids, first < second), the length of their
    common boundary (E,), the centre of the contact zone (E, 3), the number of contact points,
    and ``adjacent`` (E,): the boundary is at least ``min_length`` long."""

    pairs: NDArray[np.int64]
    boundary_length: Array
    contact_centre: Array
    contact_count: NDArray[np.int64]
    adjacent: NDArray[np.bool_]
    _contacts: dict = field(default_factory=dict, repr=False, compare=False)

    def neighbours(self, adjacent_only: bool = True) -> dict[int, set[int]]:
        out: dict[int, set[int]] = {}
        for (a, b), adj in zip(self.pairs.tolist(), self.adjacent.tolist()):
            if adj or not adjacent_only:
                out.setdefault(a, set()).add(b)
                out.setdefault(b, set()).add(a)
        return out

    def contact_points(self, a: int, b: int) -> Array:
        """Points of either plane within the contact distance of the other, (M, 3)."""
        return self._contacts[(min(a, b), max(a, b))]


def plane_adjacency(
    points: Array,
    plane_ids: NDArray[np.integer],
    delta: float,
    min_length: float,
    k: int = 12,
) -> Adjacency:
    """Planes whose points come within ``delta`` of each other; adjacent when along a common
    boundary at least ``min_length`` long (both in the cloud's units).

    ``plane_ids`` (N,) gives each point's plane, negative for none. The boundary length is the
    extent of the contact points along their principal horizontal direction.
    """
    from scipy.spatial import cKDTree

    pts = np.asarray(points, dtype=np.float64)
    ids = np.asarray(plane_ids)
    keep = ids >= 0
    pts, ids = pts[keep], ids[keep].astype(np.int64)
    empty = Adjacency(
        np.zeros((0, 2), np.int64),
        np.zeros(0),
        np.zeros((0, 3)),
        np.zeros(0, np.int64),
        np.zeros(0, bool),
    )
    if pts.shape[0] < 2:
        return empty
    tree = cKDTree(pts)
    dist, nb = tree.query(pts, k=min(k + 1, pts.shape[0]), distance_upper_bound=delta)
    valid = np.isfinite(dist) & (nb < pts.shape[0])
    src = np.repeat(np.arange(pts.shape[0]), nb.shape[1]).reshape(nb.shape)[valid]
    dst = nb[valid]
    differ = ids[src] != ids[dst]
    src, dst = src[differ], dst[differ]
    if src.size == 0:
        return empty
    a, b = np.minimum(ids[src], ids[dst]), np.maximum(ids[src], ids[dst])
    # each contact point once per pair: (pair, point index) unique
    pair_key = a * (ids.max() + 1) + b
    both = np.concatenate([np.stack([pair_key, src], 1), np.stack([pair_key, dst], 1)])
    both = np.unique(both, axis=0)
    keys, starts = np.unique(both[:, 0], return_index=True)
    groups = np.split(both[:, 1], starts[1:])
    pairs, lengths, centres, counts = [], [], [], []
    contacts = {}
    base = ids.max() + 1
    for key, members in zip(keys, groups):
        p = pts[members]
        centre = p.mean(axis=0)
        if p.shape[0] >= 2:
            q = p[:, :2] - centre[:2]
            axis = np.linalg.svd(q, full_matrices=False)[2][0]
            t = q @ axis
            length = float(t.max() - t.min())
        else:
            length = 0.0
        pair = (int(key // base), int(key % base))
        pairs.append(pair)
        lengths.append(length)
        centres.append(centre)
        counts.append(p.shape[0])
        contacts[pair] = p
    if not pairs:
        return empty
    lengths_arr = np.array(lengths)
    return Adjacency(
        np.array(pairs, dtype=np.int64),
        lengths_arr,
        np.array(centres),
        np.array(counts, dtype=np.int64),
        lengths_arr >= min_length,
        contacts,
    )


# ----------------------------------------------------------------------------- results
@dataclass(frozen=True)
class ControlPoint:
    """A LiDAR control point: three-plane intersection with its 3 x 3 covariance."""

    id: int
    xyz: Array
    covariance: Array
    plane_ids: tuple[int, int, int]
    min_angle_deg: float
    condition: float
    support_distance: Array  # (3,) distance to the nearest point of each plane

    @property
    def sigma(self) -> Array:
        return np.sqrt(np.diag(self.covariance))


@dataclass(frozen=True)
class ControlLine:
    """A 3D line where two roof planes meet, clipped to their common support."""

    id: int
    plane_ids: tuple[int, int]
    kind: str
    start: Array
    end: Array
    point: Array  # X0, the line point nearest the contact centre
    direction: Array
    covariance: Array  # (6, 6) of (X0, direction)
    dihedral_deg: float

    @property
    def length(self) -> float:
        return float(np.linalg.norm(self.end - self.start))

    @property
    def sigma_perpendicular(self) -> float:
        """RMS standard deviation across the line at X0 (the along-line part is arbitrary)."""
        return self.sigma_across(0.0)

    def sigma_across(self, t: float) -> float:
        """RMS standard deviation across the line at ``X0 + t u`` (the direction's uncertainty
        grows it away from X0)."""
        p = np.eye(3) - np.outer(self.direction, self.direction)
        jac = np.hstack([np.eye(3), t * np.eye(3)])
        cov = jac @ self.covariance @ jac.T
        return float(np.sqrt(np.trace(p @ cov @ p) / 2.0))

    @property
    def sigma_ends(self) -> tuple[float, float]:
        """:meth:`sigma_across` at the start and the end point."""
        return tuple(  # type: ignore[return-value]
            self.sigma_across(float((e - self.point) @ self.direction))
            for e in (self.start, self.end)
        )


#: catalogue context of this module's ``_t("...")`` texts (the rejection summary in the log)
TR_CONTEXT = "Report"

#: Why a candidate was not kept: the ``kind`` of a :class:`Rejection` (the log counts them).
REJECT_PARALLEL = _t("normals nearly parallel")
REJECT_CONDITION = _t("planes meet in a line, not a point")
REJECT_SUPPORT = _t("intersection far from a plane's points")
REJECT_DUPLICATE = _t("same corner as a more precise triple")
REJECT_NO_BOUNDARY = _t("no common boundary")
REJECT_LINE_PARALLEL = _t("planes nearly parallel: no stable line")
REJECT_TOO_FEW = _t("fewer than two planes")


@dataclass(frozen=True)
class Rejection:
    """A candidate that was not kept: ``kind`` (one of the ``REJECT_*`` texts, counted in the
    log's summary) and ``reason`` (the details with their numbers and units)."""

    plane_ids: tuple[int, ...]
    reason: str
    kind: str = ""


@dataclass(frozen=True)
class LidarControl:
    points: list[ControlPoint]
    lines: list[ControlLine]
    adjacency: Adjacency
    rejected: list[Rejection]


# ----------------------------------------------------------------------------- main entry
def _pair_angles(n: Array) -> Array:
    """Angles (degrees) between every pair of normals of each triple (T, 3)."""
    pairs = [(0, 1), (0, 2), (1, 2)]
    return np.stack([_angles_deg(n[:, i], n[:, j]) for i, j in pairs], 1)


def _angles_deg(u: Array, v: Array) -> Array:
    """Angles (degrees, 0-90) between the lines of unit normals u and v (E, 3): products
    written out and ``math.acos`` (numpy 2's vectorised arccos rounds differently from
    numpy 1's in the last bit; libm is the same for both)."""
    cos = np.abs(u[:, 0] * v[:, 0] + u[:, 1] * v[:, 1] + u[:, 2] * v[:, 2])
    return np.array([math.degrees(math.acos(c)) for c in np.clip(cos, 0.0, 1.0).tolist()])


def corner_candidates(adjacency: Adjacency) -> NDArray[np.int64]:
    """Triples (T, 3) of plane ids, sorted, that may meet at a roof corner: two of the three
    pairs are adjacent (share a boundary). The third pair need not touch (opposite faces of a
    pyramid meet only at the apex); whether the three planes really meet near their points is
    decided afterwards from the geometry (support distance, angles, conditioning)."""
    adj = adjacency.neighbours(adjacent_only=True)
    out = set()
    for b, around in adj.items():
        for a in around:
            for c in around:
                if a < c:
                    out.add(tuple(sorted((a, b, c))))
    return np.array(sorted(out), dtype=np.int64).reshape(-1, 3)


def rejection_summary(rejected: Sequence[Rejection]) -> str:
    """Counts per reason, most frequent first: "12 rejected: 9 intersection far from a
    plane's points, 3 normals nearly parallel" ("" when nothing was rejected).

    >>> rejection_summary([Rejection((1, 2, 3), "x", REJECT_PARALLEL)] * 2)
    '2 candidates rejected: 2 normals nearly parallel'
    """
    if not rejected:
        return ""
    counts: dict[str, int] = {}
    for r in rejected:
        counts[r.kind or r.reason] = counts.get(r.kind or r.reason, 0) + 1
    parts = sorted(counts.items(), key=lambda kv: (-kv[1], kv[0]))
    # a Message: the log bridge and the reports show it (and each reason) in the user's language
    return _t(
        "{n} candidates rejected: {reasons}",
        n=len(rejected),
        reasons=joined(Message("{n} {reason}", n=n, reason=k) for k, n in parts),
    )


def lidar_control(
    planes: Sequence,
    points: Array,
    plane_ids: NDArray[np.integer],
    options: ControlOptions = ControlOptions(),  # noqa: B008 - frozen, shared safely
    triples: Sequence[Sequence[int]] | None = None,
    pairs: Sequence[Sequence[int]] | None = None,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> LidarControl:
    """Adjacency, LCPs and lines from fitted planes and the points that support them.

    ``planes`` are objects with ``id``, ``normal`` (3,), ``d``, ``covariance`` (4, 4) (e.g.
    :class:`lidarphoto.core.geometry.planes.Plane`). ``triples``/``pairs``: user-chosen plane ids to
    intersect instead of the automatic mutually adjacent ones (still checked for geometry).
    """
    by_id = {int(p.id): p for p in planes}
    pts = np.asarray(points, dtype=np.float64)
    ids = np.asarray(plane_ids)
    unknown = sorted(set(np.unique(ids[ids >= 0]).tolist()) - set(by_id))
    if unknown:
        raise InputError(f"points refer to plane ids not in the plane table: {unknown[:10]}")
    adjacency = plane_adjacency(pts, ids, options.delta, options.min_boundary, options.neighbours)
    _tick(progress, should_stop, 0.4)
    rejected: list[Rejection] = []

    if triples is None:
        cand3 = corner_candidates(adjacency)
    else:
        cand3 = _user_ids(triples, 3, by_id, "triple")
    control_points = _three_plane_points(cand3, by_id, pts, ids, options, rejected)
    _tick(progress, should_stop, 0.7)

    if pairs is None:
        cand2 = adjacency.pairs[adjacency.adjacent]
    else:
        cand2 = _user_ids(pairs, 2, by_id, "pair")
    lines = _two_plane_lines(cand2, by_id, pts, ids, adjacency, options, rejected)
    _tick(progress, should_stop, 1.0)
    if len(by_id) < 2:
        rejected.append(
            Rejection(tuple(by_id), "fewer than two planes: no line or point", REJECT_TOO_FEW)
        )
    return LidarControl(control_points, lines, adjacency, rejected)


def _tick(progress, should_stop, value: float) -> None:
    stop_if_asked(should_stop, "building LiDAR control")
    if progress is not None:
        progress(value)


def _user_ids(items, size: int, by_id: dict, what: str) -> NDArray[np.int64]:
    arr = np.array([list(map(int, t)) for t in items], dtype=np.int64).reshape(-1, size)
    for row in arr:
        missing = [i for i in row.tolist() if i not in by_id]
        if missing:
            raise InputError(f"{what} {tuple(row.tolist())}: plane id(s) {missing} not found")
        if len(set(row.tolist())) != size:
            raise InputError(f"{what} {tuple(row.tolist())} repeats a plane")
    return arr


def _stack(by_id: dict, ids: NDArray[np.int64]) -> tuple[Array, Array, Array]:
    n = np.array([[by_id[int(i)].normal for i in row] for row in ids], dtype=float)
    d = np.array([[by_id[int(i)].d for i in row] for row in ids], dtype=float)
    c = np.array([[by_id[int(i)].covariance for i in row] for row in ids], dtype=float)
    return n, d, c


def _three_plane_points(cand, by_id, pts, ids, options, rejected) -> list[ControlPoint]:
    from scipy.spatial import cKDTree

    if cand.shape[0] == 0:
        return []
    n, d, c = _stack(by_id, cand)
    x, cov, cond = intersect_three_planes(n, d, c)
    angles = _pair_angles(n)
    trees = {}
    out: list[ControlPoint] = []
    for t, triple in enumerate(cand.tolist()):
        tri = (int(triple[0]), int(triple[1]), int(triple[2]))
        u = options.length_unit
        min_angle = float(angles[t].min())
        if min_angle < options.min_angle_deg:
            rejected.append(
                Rejection(
                    tri,
                    f"normals nearly parallel: {min_angle:.1f} deg between two planes "
                    f"(< {options.min_angle_deg:g} deg)",
                    REJECT_PARALLEL,
                )
            )
            continue
        if not np.isfinite(cond[t]) or cond[t] > options.max_condition:
            rejected.append(
                Rejection(
                    tri,
                    f"the planes meet in a line rather than a point "
                    f"(condition number {cond[t]:.3g} > {options.max_condition:g})",
                    REJECT_CONDITION,
                )
            )
            continue
        support = np.empty(3)
        for k, pid in enumerate(tri):
            if pid not in trees:
                trees[pid] = cKDTree(pts[ids == pid])
            support[k] = trees[pid].query(x[t])[0]
        if np.any(support > options.max_support_distance):
            far = tri[int(np.argmax(support))]
            rejected.append(
                Rejection(
                    tri,
                    f"intersection {support.max():.2f} {u} from the points of plane "
                    f"{far} (> {options.max_support_distance:g} {u})",
                    REJECT_SUPPORT,
                )
            )
            continue
        out.append(
            ControlPoint(len(out) + 1, x[t], cov[t], tri, min_angle, float(cond[t]), support)
        )
    return _merge_duplicates(out, options.delta, rejected, options.length_unit)


def _merge_duplicates(
    points: list[ControlPoint], radius: float, rejected, unit: str = "m"
) -> list[ControlPoint]:
    """One LCP per corner: where more than three planes meet (a pyramid apex), several triples
    give the same point; keep the most precise (smallest trace of the covariance)."""
    if len(points) < 2:
        return points
    kept: list[ControlPoint] = []
    for p in sorted(points, key=lambda p: float(np.trace(p.covariance))):
        twin = next((k for k in kept if np.linalg.norm(k.xyz - p.xyz) < radius), None)
        if twin is None:
            kept.append(p)
        else:
            rejected.append(
                Rejection(
                    p.plane_ids,
                    f"same corner as planes {twin.plane_ids} (within "
                    f"{radius:g} {unit}), which give a more precise point",
                    REJECT_DUPLICATE,
                )
            )
    kept.sort(key=lambda p: p.id)
    return [replace(p, id=i + 1) for i, p in enumerate(kept)]


def _two_plane_lines(cand, by_id, pts, ids, adjacency, options, rejected) -> list[ControlLine]:
    if cand.shape[0] == 0:
        return []
    n, d, c = _stack(by_id, cand)
    lookup = {tuple(p): i for i, p in enumerate(adjacency.pairs.tolist())}
    refs = []
    contact = []
    for a, b in cand.tolist():
        key = (min(a, b), max(a, b))
        if key in lookup:
            cp = adjacency.contact_points(*key)
        else:  # user pair without detected contact: use the planes' nearest points
            cp = _closest_points(pts[ids == a], pts[ids == b], options.delta * 3)
        contact.append(cp)
        refs.append(cp.mean(axis=0) if cp.size else np.full(3, np.nan))
    x0, u, cov = intersect_two_planes(
        n[:, 0], d[:, 0], c[:, 0], n[:, 1], d[:, 1], c[:, 1], np.array(refs)
    )
    dihedral = _angles_deg(n[:, 0], n[:, 1])
    out: list[ControlLine] = []
    for e, (a, b) in enumerate(cand.tolist()):
        pair = (int(a), int(b))
        if contact[e].shape[0] < 2:
            rejected.append(
                Rejection(pair, "no common boundary between the two planes", REJECT_NO_BOUNDARY)
            )
            continue
        if dihedral[e] < options.min_angle_deg or not np.all(np.isfinite(x0[e])):
            rejected.append(
                Rejection(
                    pair,
                    f"planes nearly parallel ({dihedral[e]:.1f} deg "
                    f"< {options.min_angle_deg:g} deg): no stable line",
                    REJECT_LINE_PARALLEL,
                )
            )
            continue
        t = (contact[e] - x0[e]) @ u[e]
        start, end = x0[e] + t.min() * u[e], x0[e] + t.max() * u[e]
        kind = _line_kind(n[e, 0], n[e, 1], x0[e], u[e], by_id[a].centroid, by_id[b].centroid)
        out.append(
            ControlLine(
                len(out) + 1, pair, kind, start, end, x0[e], u[e], cov[e], float(dihedral[e])
            )
        )
    return out


def _closest_points(pa: Array, pb: Array, radius: float) -> Array:
    from scipy.spatial import cKDTree

    if pa.shape[0] == 0 or pb.shape[0] == 0:
        return np.zeros((0, 3))
    tb = cKDTree(pb)
    dist, _ = tb.query(pa, distance_upper_bound=radius)
    ta = cKDTree(pa)
    dist_b, _ = ta.query(pb, distance_upper_bound=radius)
    return np.vstack([pa[np.isfinite(dist)], pb[np.isfinite(dist_b)]])


def _line_kind(n1, n2, x0, u, c1, c2) -> str:
    """Ridge/hip (convex: both faces slope down away from the line), valley (concave)."""
    side = []
    for n, c in ((n1, c1), (n2, c2)):
        away = np.asarray(c, dtype=float) - x0
        away -= (away @ u) * u  # perpendicular to the line, towards the plane's support
        side.append(np.sign(n[:2] @ away[:2]))
    if side[0] > 0 and side[1] > 0:
        return "ridge" if abs(u[2]) < np.sin(np.radians(5.0)) else "hip"
    if side[0] < 0 and side[1] < 0:
        return "valley"
    return "other"
