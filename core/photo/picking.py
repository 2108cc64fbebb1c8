"""Maths of the image point picking dock (Qt-free): what is under a pixel, where a tie point
falls in the other images, hit tests of lines and control points.

Frames
------
Inputs are in the **mapping CRS** of the exterior orientation table (EO CSV of
``trajectorytoeo``: perspective centres in the mapping CRS, omega-phi-kappa relative to the
grid frame at each centre). Every ray and projection is computed rigorously in a local ENU
frame tangent at the block centre (:func:`core.orientation.eo_map_to_local`), because the
projected frame is not Cartesian: over a 2 km block the earth curvature alone moves a point
by about 0.3 m, a few pixels at a 10 cm ground sample distance. Pixels follow
:mod:`core.camera`: origin at the top-left corner of the top-left pixel, rows downwards.

Fisheye cameras
---------------
Through a perspective camera a straight 3-D segment images as the straight segment between
its projected end points, so lines and outline edges are projected as their end points
(2 points a line). Through a fisheye projection (:mod:`core.geometry.projection`) it images
as a curve: :meth:`PickingScene.project_segments` and :meth:`PickingScene.project_rings`
then subdivide each segment adaptively in object space (bisection in its parameter, first
into pieces of at most :data:`_MAX_PIECE_RAD` seen from the perspective centre) until the
projected midpoint of every piece lies within half of :data:`CHORD_TOL_PX` of its chord:
the polyline stays within :data:`CHORD_TOL_PX` of the exact image of the line (measured in
tests/core/test_picking_fisheye.py). Parts beyond the projection's field are left out,
with a NaN row between the visible runs.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..geometry.camera import Camera
from ..geometry.collinearity import image_rays, project_with_status
from ..geometry.frames import LocalFrame, MappingFrame
from ..geometry.rotations import matrix_to_opk
from .orientation import ExteriorOrientationTable, eo_map_to_local

__all__ = [
    "CHORD_TOL_PX",
    "FOOTPRINT_BORDER_POINTS",
    "FOOTPRINT_RANGE",
    "PickingScene",
    "PlaneCandidate",
    "nearest_point",
    "nearest_polyline",
    "nearest_segment",
    "points_in_polygons",
    "polyline_tangent",
]

Array = NDArray[np.float64]

#: border pixels a side of a fisheye image's footprint (:meth:`PickingScene.footprint`)
FOOTPRINT_BORDER_POINTS = 64
#: farthest ground of a fisheye footprint, in heights of the centre above the ground (84
#: degrees below the horizontal)
FOOTPRINT_RANGE = 10.0
#: largest distance of a fisheye polyline from the exact image of its 3-D segment, pixels
CHORD_TOL_PX = 0.25
#: longest piece of a segment before the chord test, radians seen from the centre (so that a
#: curve cannot enter the image between three samples that all lie outside it)
_MAX_PIECE_RAD = np.radians(3.0)
#: most halvings of a piece, and bisection steps to the edge of the field (2**-40 of a piece)
_MAX_DEPTH = 40


def points_in_polygons(pixel: ArrayLike, polygons: Sequence[ArrayLike]) -> NDArray[np.intp]:
    """Indices of the polygons that contain a point (even-odd rule), vectorised over edges.

    Parameters
    ----------
    pixel : (2,) array_like
        The point (col, row).
    polygons : sequence of (M_i, 2) array_like
        Rings, closed implicitly (the first vertex is not repeated). Rings holding NaN (a vertex
        behind the camera) or fewer than three vertices never contain the point.

    Returns
    -------
    ndarray of int, shape (K,)
        Indices into ``polygons``, ascending.
    """
    x, y = (float(v) for v in np.asarray(pixel, dtype=np.float64).reshape(2))
    rings = [np.asarray(p, dtype=np.float64).reshape(-1, 2) for p in polygons]
    sizes = np.array([len(r) for r in rings], dtype=np.intp)
    if sizes.sum() == 0:
        return np.empty(0, dtype=np.intp)
    a = np.vstack([r for r in rings if len(r)])
    owner = np.repeat(np.arange(len(rings)), sizes)
    # the next vertex of each vertex within its own ring (closing edge included)
    start = np.repeat(np.cumsum(sizes) - sizes, sizes)
    local = np.arange(a.shape[0]) - start
    b = a[start + (local + 1) % np.repeat(np.maximum(sizes, 1), sizes)]
    with np.errstate(invalid="ignore", divide="ignore"):
        straddles = (a[:, 1] > y) != (b[:, 1] > y)
        x_cross = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
        crossing = straddles & (x < x_cross)
    counts = np.bincount(owner[crossing], minlength=len(rings))
    bad = np.bincount(owner[~np.isfinite(a).all(axis=1)], minlength=len(rings)) > 0
    inside = (counts % 2 == 1) & ~bad & (sizes >= 3)
    return np.flatnonzero(inside)


def nearest_point(pixel: ArrayLike, points: ArrayLike, tol_px: float) -> tuple[int, float]:
    """The point nearest to ``pixel`` within ``tol_px`` (an LCP or observation hit test).

    Parameters
    ----------
    pixel : (2,) array_like
    points : (P, 2) array_like
        Pixel positions; NaN rows are ignored.
    tol_px : float
        Largest accepted distance, pixels.

    Returns
    -------
    index, distance : int, float
        ``(-1, inf)`` when no point is within the tolerance.
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    if p.shape[0] == 0:
        return -1, float("inf")
    dist = np.hypot(*(p - np.asarray(pixel, dtype=np.float64).reshape(1, 2)).T)
    dist = np.where(np.isfinite(dist), dist, np.inf)
    k = int(np.argmin(dist))
    return (k, float(dist[k])) if dist[k] <= tol_px else (-1, float("inf"))


def nearest_segment(
    pixel: ArrayLike, starts: ArrayLike, ends: ArrayLike, tol_px: float
) -> tuple[int, float]:
    """The segment nearest to ``pixel`` within ``tol_px`` (a line hit test).

    Parameters
    ----------
    pixel : (2,) array_like
    starts, ends : (L, 2) array_like
        Segment end points in pixels; NaN rows are ignored.
    tol_px : float

    Returns
    -------
    index, distance : int, float
        ``(-1, inf)`` when no segment is within the tolerance.
    """
    a = np.asarray(starts, dtype=np.float64).reshape(-1, 2)
    b = np.asarray(ends, dtype=np.float64).reshape(-1, 2)
    if a.shape[0] == 0:
        return -1, float("inf")
    q = np.asarray(pixel, dtype=np.float64).reshape(1, 2)
    ab = b - a
    len2 = np.einsum("ij,ij->i", ab, ab)
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.clip(np.einsum("ij,ij->i", q - a, ab) / np.where(len2 > 0, len2, np.nan), 0, 1)
    t = np.where(len2 > 0, t, 0.0)
    dist = np.hypot(*(a + t[:, None] * ab - q).T)
    dist = np.where(np.isfinite(dist), dist, np.inf)
    k = int(np.argmin(dist))
    return (k, float(dist[k])) if dist[k] <= tol_px else (-1, float("inf"))


def nearest_polyline(
    pixel: ArrayLike, polylines: Sequence[ArrayLike], tol_px: float
) -> tuple[int, float]:
    """The polyline nearest to ``pixel`` within ``tol_px`` (the hit test of projected lines).

    Parameters
    ----------
    pixel : (2,) array_like
    polylines : sequence of (K_i, 2) array_like
        Pixels; an edge to or from a NaN row is no edge (a gap). Two-point polylines give
        what :func:`nearest_segment` gives for their end points.
    tol_px : float

    Returns
    -------
    index, distance : int, float
        Index into ``polylines``; ``(-1, inf)`` when none is within the tolerance.

    >>> nearest_polyline((7.0, 1.0), [[[0, 0], [4, 0]], [[0, 3], [4, 3], [9, 3]]], 2.5)
    (1, 2.0)
    """
    lines = [np.asarray(p, dtype=np.float64).reshape(-1, 2) for p in polylines]
    edges = np.array([max(len(p) - 1, 0) for p in lines], dtype=np.intp)
    if edges.sum() == 0:
        return -1, float("inf")
    a = np.vstack([p[:-1] for p in lines if len(p) > 1])
    b = np.vstack([p[1:] for p in lines if len(p) > 1])
    k, dist = nearest_segment(pixel, a, b, tol_px)
    if k < 0:
        return -1, float("inf")
    return int(np.repeat(np.arange(len(lines)), edges)[k]), dist


def polyline_tangent(pixel: ArrayLike, polyline: ArrayLike) -> Array:
    """The direction (unit, (2,)) of a projected line's polyline at the point nearest to
    ``pixel``: the tangent of the curve it follows, interpolated along the nearest edge
    between the tangents at its two vertices (each the mean of the unit directions of the
    edges meeting there; an edge to or from a NaN row is no edge). A two-point polyline (a
    perspective camera's line) gives its own direction; NaN when it has no edge.

    >>> polyline_tangent((1.0, 0.2), [[0, 0], [1, 0], [2, 1]]).round(3).tolist()
    [0.907, 0.421]
    """
    p = np.asarray(polyline, dtype=np.float64).reshape(-1, 2)
    if len(p) < 2:
        return np.full(2, np.nan)
    d = p[1:] - p[:-1]
    length = np.hypot(d[:, 0], d[:, 1])
    ok = np.isfinite(length) & (length > 0)
    if not ok.any():
        return np.full(2, np.nan)
    unit = np.where(ok[:, None], d / np.where(ok, length, 1.0)[:, None], 0.0)
    k, _dist = nearest_segment(pixel, np.where(ok[:, None], p[:-1], np.nan), p[1:], np.inf)
    a, ab = p[k], d[k]
    t = float(np.clip(np.dot(np.asarray(pixel, dtype=np.float64) - a, ab) / length[k] ** 2, 0, 1))
    # vertex tangents: the mean of the unit edges around vertex k and vertex k + 1
    has_before, has_after = k > 0 and bool(ok[k - 1]), k + 1 < len(unit) and bool(ok[k + 1])
    at_a = (unit[k] + unit[k - 1]) / 2 if has_before else unit[k]
    at_b = (unit[k] + unit[k + 1]) / 2 if has_after else unit[k]
    tangent = (1.0 - t) * at_a + t * at_b
    norm = float(np.hypot(*tangent))
    return tangent / norm if norm > 0 else unit[k].copy()


def _densify(
    project: Callable[[Array], Array],
    centre: Array,
    a: Array,
    b: Array,
    frame: tuple[float, float],
    tol_px: float,
) -> list[Array]:
    """Polylines (K_i, 2) pixels of the straight segments ``a[i] -> b[i]`` ((L, 3), the
    frame ``project`` takes: points -> pixels, NaN outside the field) seen from ``centre``.

    Each segment is cut into pieces of at most :data:`_MAX_PIECE_RAD` seen from the centre,
    then a piece is halved while its projected midpoint lies more than ``tol_px / 2`` from
    its chord, or one of its halves holds over 90 % of the chord's length (unless the piece
    is wholly off the image ``frame`` = (width, height) px: it is kept as it is). A piece
    still so after :data:`_MAX_DEPTH` halvings spans a jump of the image (the segment passes
    exactly through the backward axis or the centre) and is left out. A piece with one end
    outside the field is first cut at the field's edge (bisection to 2**-40 of the piece).
    Pieces outside the field are left out: a NaN row separates the visible runs; a segment
    not seen at all gives two NaN rows.
    """
    n = len(a)
    if n == 0:
        return []
    da, db = a - centre, b - centre
    with np.errstate(invalid="ignore", divide="ignore"):
        cos = np.einsum("ij,ij->i", da, db) / (
            np.linalg.norm(da, axis=1) * np.linalg.norm(db, axis=1)
        )
        ang = np.arccos(np.clip(cos, -1.0, 1.0))
    m = np.ones(n, dtype=np.intp)
    good = np.isfinite(ang)
    m[good] = np.clip(np.ceil(ang[good] / _MAX_PIECE_RAD), 1, 4096).astype(np.intp)
    owner = np.repeat(np.arange(n), m)
    k = np.arange(owner.size) - np.repeat(np.cumsum(m) - m, m)
    t0, t1 = k / m[owner], (k + 1) / m[owner]

    def at(o: NDArray[np.intp], t: Array) -> Array:
        return project(a[o] + t[:, None] * (b[o] - a[o]))

    p0, p1 = at(owner, t0), at(owner, t1)
    depth = np.zeros(owner.size, dtype=np.intp)
    w, h = frame
    kept: list[tuple[NDArray[np.intp], Array, Array, Array, Array]] = []
    while owner.size:
        v0, v1 = np.isfinite(p0).all(axis=1), np.isfinite(p1).all(axis=1)
        edge = np.flatnonzero(v0 != v1)
        if edge.size:  # one end outside the field: keep the part inside (bisection)
            good_t = np.where(v0, t0, t1)[edge]
            in_t, out_t = good_t.copy(), np.where(v0, t1, t0)[edge]
            for _ in range(_MAX_DEPTH):
                mid = 0.5 * (in_t + out_t)
                inside = np.isfinite(at(owner[edge], mid)).all(axis=1)
                in_t, out_t = np.where(inside, mid, in_t), np.where(inside, out_t, mid)
            t0[edge], t1[edge] = np.minimum(good_t, in_t), np.maximum(good_t, in_t)
            p0[edge], p1[edge] = at(owner[edge], t0[edge]), at(owner[edge], t1[edge])
            v0[edge] = v1[edge] = True
        tm = 0.5 * (t0 + t1)
        pm = at(owner, tm)
        vm = np.isfinite(pm).all(axis=1)
        chord = p1 - p0
        len2 = np.einsum("ij,ij->i", chord, chord)
        with np.errstate(invalid="ignore", divide="ignore"):
            s = np.clip(np.einsum("ij,ij->i", pm - p0, chord) / len2, 0.0, 1.0)
        s = np.where(len2 > 0, s, 0.0)
        dev = np.hypot(*(p0 + s[:, None] * chord - pm).T)
        grow = (np.sqrt(len2) + dev)[:, None]
        lo = np.minimum(np.minimum(p0, p1), pm) - grow
        hi = np.maximum(np.maximum(p0, p1), pm) + grow
        off = (hi[:, 0] < 0) | (lo[:, 0] > w) | (hi[:, 1] < 0) | (lo[:, 1] > h)
        both = v0 & v1
        # bent: the midpoint off the chord; uneven: nearly all of the chord in one half (a
        # jump of the image hides there even when the points are in a row)
        half = np.maximum(np.hypot(*(pm - p0).T), np.hypot(*(p1 - pm).T))
        uneven = (half > 0.9 * np.sqrt(len2)) & (len2 > (0.5 * tol_px) ** 2)
        bent = ((dev > 0.5 * tol_px) | uneven) & ~off
        split = both & (~vm | bent) & (depth < _MAX_DEPTH)
        # still bent after every halving: a jump of the image (the segment passes exactly
        # through the backward axis, or the centre), not a curve: a gap, not a chord
        done = ~split & both & vm & ~bent
        kept.append((owner[done], t0[done], t1[done], p0[done], p1[done]))
        o, d = owner[split], depth[split] + 1
        owner = np.concatenate([o, o])
        depth = np.concatenate([d, d])
        t0, t1 = np.concatenate([t0[split], tm[split]]), np.concatenate([tm[split], t1[split]])
        p0 = np.concatenate([p0[split], pm[split]])
        p1 = np.concatenate([pm[split], p1[split]])
    own, s0, s1, q0, q1 = (np.concatenate(x) for x in zip(*kept))
    order = np.lexsort((s0, own))
    own, s0, s1, q0, q1 = own[order], s0[order], s1[order], q0[order], q1[order]
    new_run = np.ones(own.size, dtype=bool)
    new_run[1:] = (own[1:] != own[:-1]) | (s0[1:] != s1[:-1])
    starts = np.flatnonzero(new_run)
    parts: list[list[Array]] = [[] for _ in range(n)]
    gap = np.full((1, 2), np.nan)
    for i, j in zip(starts.tolist(), [*starts[1:].tolist(), own.size]):
        out = parts[int(own[i])]
        if out:
            out.append(gap)
        out += [q0[i:j], q1[j - 1 : j]]
    return [np.vstack(p) if p else np.full((2, 2), np.nan) for p in parts]


@dataclass(frozen=True)
class PlaneCandidate:
    """A plane under a pixel: its index in the given outlines, the ground point (mapping CRS)
    and the distance from the perspective centre along the ray, metres."""

    index: int
    ground: Array
    range_m: float


class PickingScene:
    """The images of a block (camera + EO) and the rigorous local frame they are solved in.

    Parameters
    ----------
    eo : ExteriorOrientationTable
        Mapping CRS; ``eo.crs_wkt`` (or ``crs``) names that CRS.
    camera : Camera
    crs : str, optional
        The mapping CRS (EPSG code or WKT) when the table carries none.
    local : LocalFrame, optional
        The adjustment frame; by default tangent at the mean perspective centre, lowered to the
        mean of ``ground_height`` if given.

    Raises
    ------
    InputError
        No CRS, or an empty table.
    """

    def __init__(
        self,
        eo: ExteriorOrientationTable,
        camera: Camera,
        crs: str = "",
        local: LocalFrame | None = None,
    ) -> None:
        if len(eo) == 0:
            raise InputError("the exterior orientation table holds no image")
        crs_text = crs or eo.crs_wkt
        if not crs_text:
            raise InputError("the mapping CRS of the exterior orientation is unknown")
        mapping = MappingFrame.from_user_input(crs_text)
        self.eo = eo
        self.camera = camera
        self.local = local or LocalFrame.at_map_point(mapping, eo.xyz.mean(axis=0))
        centres, m = eo_map_to_local(eo.xyz, eo.opk, self.local)
        omega, phi, kappa = matrix_to_opk(m)
        #: (N, 6) EO rows in the local frame, as :mod:`core.collinearity` expects
        self.local_eo = np.column_stack([centres, omega, phi, kappa])
        self._index = {name: k for k, name in enumerate(eo.image_id)}

    # -- images -------------------------------------------------------------------------------
    def has_image(self, image_id: str) -> bool:
        return image_id in self._index

    def _eo(self, image_id: str) -> Array:
        try:
            return self.local_eo[self._index[image_id]]
        except KeyError:
            raise InputError(f"image '{image_id}' has no exterior orientation") from None

    def to_local(self, xyz: ArrayLike) -> Array:
        """Mapping CRS (N, 3) -> local ENU (N, 3), metres."""
        return self.local.map_to_enu(np.asarray(xyz, dtype=np.float64).reshape(-1, 3))

    def project(self, image_id: str, xyz: ArrayLike) -> Array:
        """Project mapping-CRS points (N, 3) into an image: pixels (N, 2), NaN behind it."""
        pts = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
        if pts.shape[0] == 0:
            return np.empty((0, 2))
        px, front, ok = project_with_status(self.to_local(pts), self._eo(image_id), self.camera)
        px[~(front & ok)] = np.nan
        return px

    def rays(self, image_id: str, pixels: ArrayLike) -> tuple[Array, Array]:
        """Rays of pixels (N, 2): origins (N, 3) and unit directions (N, 3), local frame."""
        return image_rays(
            np.asarray(pixels, dtype=np.float64).reshape(-1, 2), self._eo(image_id), self.camera
        )

    def _planes_local(self, normals: ArrayLike, points: ArrayLike) -> tuple[Array, Array]:
        """Planes (normal, point on it) mapping CRS -> local frame, through three points each
        (exact for a plane; the projected frame is not Cartesian)."""
        nrm = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
        p0 = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        helper = np.where(np.abs(nrm[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
        u = np.cross(nrm, helper)
        u /= np.linalg.norm(u, axis=1, keepdims=True)
        v = np.cross(nrm, u)
        q0, q1, q2 = (self.to_local(q) for q in (p0, p0 + u, p0 + v))
        nl = np.cross(q1 - q0, q2 - q0)
        nl /= np.linalg.norm(nl, axis=1, keepdims=True)
        return nl, q0

    def ray_plane(
        self, image_id: str, pixel: ArrayLike, normals: ArrayLike, points: ArrayLike
    ) -> tuple[Array, Array]:
        """Cut the ray of one pixel with P planes.

        Parameters
        ----------
        pixel : (2,) array_like
        normals, points : (P, 3) array_like
            Unit normal and a point of each plane, mapping CRS.

        Returns
        -------
        ground : (P, 3) ndarray
            Intersections, mapping CRS; NaN where the ray is parallel to the plane or the
            plane lies behind the camera.
        range_m : (P,) ndarray
            Distance from the perspective centre, metres (NaN likewise).
        """
        origin, direction = self.rays(image_id, pixel)
        nl, q0 = self._planes_local(normals, points)
        with np.errstate(invalid="ignore", divide="ignore"):
            t = np.einsum("pi,pi->p", q0 - origin, nl) / (nl @ direction[0])
        t = np.where(np.isfinite(t) & (t > 0), t, np.nan)
        hit = origin + t[:, None] * direction
        out = np.full_like(hit, np.nan)
        good = np.isfinite(t)
        if good.any():
            out[good] = self.local.enu_to_map(hit[good])
        return out, t

    # -- picking ------------------------------------------------------------------------------
    def project_rings(self, image_id: str, rings: Sequence[ArrayLike]) -> list[Array]:
        """Project outline rings (each (M_i, 3), mapping CRS) in one call: pixels.

        Perspective camera: the projected vertices, (M_i, 2). Fisheye camera: each edge
        (the closing one included) densified as :meth:`project_segments` does, the ring
        closed implicitly as before; a ring with a vertex or a stretch of edge outside the
        projection's field holds a NaN row (it then contains no pixel,
        :func:`points_in_polygons`).
        """
        verts = [np.asarray(r, dtype=np.float64).reshape(-1, 3) for r in rings]
        sizes = [len(v) for v in verts]
        if sum(sizes) == 0:
            return [np.empty((0, 2)) for _ in rings]
        if self.camera.is_perspective:
            px = self.project(image_id, np.vstack(verts))
            return np.split(px, np.cumsum(sizes)[:-1])
        starts = np.vstack([v for v in verts if len(v)])
        ends = np.vstack([np.roll(v, -1, axis=0) for v in verts if len(v)])
        edges = self.project_segments(image_id, starts, ends)
        out, k = [], 0
        for size in sizes:
            parts = []
            for e in edges[k : k + size]:
                whole = np.isfinite(e).all()
                parts.append(e[:-1] if whole else np.vstack([e, np.full((1, 2), np.nan)]))
            out.append(np.vstack(parts) if parts else np.empty((0, 2)))
            k += size
        return out

    def project_segments(
        self, image_id: str, starts: ArrayLike, ends: ArrayLike, tol_px: float = CHORD_TOL_PX
    ) -> list[Array]:
        """Project straight 3-D segments (``starts`` -> ``ends``, (L, 3) mapping CRS) into an
        image: one polyline (K_i, 2) pixels each.

        Perspective camera: the two projected end points (K_i = 2; NaN behind the camera), as
        :meth:`project` gives them. Fisheye camera: the segment (straight in the local frame)
        subdivided until the polyline lies within ``tol_px`` of its exact curved image (see
        the module docstring); runs beyond the projection's field are left out, a NaN row
        between the visible runs (two NaN rows: not seen at all).
        """
        a = np.asarray(starts, dtype=np.float64).reshape(-1, 3)
        b = np.asarray(ends, dtype=np.float64).reshape(-1, 3)
        if a.shape[0] == 0:
            return []
        if self.camera.is_perspective:
            return list(np.stack([self.project(image_id, a), self.project(image_id, b)], 1))
        eo = self._eo(image_id)

        def to_pixels(pts: Array) -> Array:
            px, front, ok = project_with_status(pts, eo, self.camera)
            px[~(front & ok)] = np.nan
            return px

        frame = (float(self.camera.width_px), float(self.camera.height_px))
        return _densify(to_pixels, eo[:3], self.to_local(a), self.to_local(b), frame, tol_px)

    def planes_under_pixel(
        self,
        image_id: str,
        pixel: ArrayLike,
        outlines: Sequence[ArrayLike],
        normals: ArrayLike,
        points: ArrayLike,
        rings: Sequence[ArrayLike] | None = None,
    ) -> list[PlaneCandidate]:
        """Planes whose reprojected outline contains ``pixel``, nearest to the camera first.

        Overlapping outlines (a roof seen over another, or seams between faces) give several
        candidates: the GUI lets the user choose; the nearest is the one usually visible.

        Parameters
        ----------
        outlines : sequence of (M_i, 3) array_like
            Outline rings, mapping CRS.
        normals, points : (P, 3) array_like
            Plane of each outline (unit normal and a point on it), mapping CRS.
        rings : sequence of (M_i, 2) array_like, optional
            The outlines already projected into the image (:meth:`project_rings`), pixels.
        """
        if rings is None:
            rings = self.project_rings(image_id, outlines)
        hits = points_in_polygons(pixel, rings)
        if hits.size == 0:
            return []
        ground, rng = self.ray_plane(
            image_id, pixel, np.asarray(normals)[hits], np.asarray(points)[hits]
        )
        order = np.argsort(np.where(np.isfinite(rng), rng, np.inf), kind="stable")
        return [PlaneCandidate(int(hits[k]), ground[k], float(rng[k])) for k in order]

    def predict_tie(
        self,
        image_id: str,
        pixel: ArrayLike,
        normal: ArrayLike,
        point: ArrayLike,
        margin_px: float = 0.0,
    ) -> dict[str, Array]:
        """Where a plane-constrained tie point measured in one image falls in the others.

        The pixel's ray is cut with the plane (local frame), and the ground point projected
        into every other image; images where it lies behind the camera or outside the frame
        (less ``margin_px``) are left out.

        Parameters
        ----------
        image_id : str
        pixel : (2,) array_like
        normal, point : (3,) array_like
            The plane, mapping CRS.
        margin_px : float

        Returns
        -------
        dict of image id to (2,) ndarray
            Predicted pixel (col, row) per image, in the EO table's order.
        """
        ground, _ = self.ray_plane(
            image_id, pixel, np.reshape(normal, (1, 3)), np.reshape(point, (1, 3))
        )
        if not np.isfinite(ground).all():
            return {}
        hit = self.to_local(ground)
        others = [i for i in self.eo.image_id if i != image_id]
        if not others:
            return {}
        idx = np.array([self._index[i] for i in others])
        px, front, ok = project_with_status(
            np.repeat(hit, idx.size, axis=0), self.local_eo[idx], self.camera
        )
        keep = front & ok & self.camera.in_frame(px, margin_px)
        return {others[k]: px[k] for k in np.flatnonzero(keep)}

    def footprint(self, image_id: str, height: float) -> Array:
        """Ground footprint of an image on the level surface at ``height`` (mapping CRS
        heights), mapping CRS, clockwise from the top-left corner of the image.

        Perspective camera: its four corners, (4, 3). Fisheye camera, whose border curves on
        the ground: :data:`FOOTPRINT_BORDER_POINTS` pixels a side, (4 K, 3); a border pixel
        beyond the projection's field, or whose ray meets the ground farther than
        :data:`FOOTPRINT_RANGE` times the height of the centre above it (at or past the
        horizon for a lens of more than 180 degrees), is moved towards the principal point
        to where its ray reaches that range: the outline then bounds the part of the field
        of view that reaches the ground. Rows that find no ground are NaN.
        """
        w, h = self.camera.width_px, self.camera.height_px
        corners = np.array([[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]])
        if self.camera.is_perspective:
            return self._level_hits(image_id, corners, height, np.inf)[0]
        from .tie_pairs import _border

        pixels = _border(w, h, FOOTPRINT_BORDER_POINTS)
        out, far = self._level_hits(image_id, pixels, height, FOOTPRINT_RANGE)
        if far.any():
            pp = np.asarray(self.camera.principal_point_px, np.float64)
            lo = np.zeros(int(far.sum()))  # fractions of the way to the border that reach
            hi = np.ones_like(lo)
            for _ in range(40):  # bisection: 1e-12 of the distance to the border
                mid = 0.5 * (lo + hi)
                _, miss = self._level_hits(
                    image_id, pp + mid[:, None] * (pixels[far] - pp), height, FOOTPRINT_RANGE
                )
                lo, hi = np.where(miss, lo, mid), np.where(miss, mid, hi)
            moved = pp + lo[:, None] * (pixels[far] - pp)
            out[far] = self._level_hits(image_id, moved, height, np.inf)[0]
        return out

    def _level_hits(
        self, image_id: str, pixels: Array, height: float, max_range: float
    ) -> tuple[Array, NDArray[np.bool_]]:
        """Rays of ``pixels`` (K, 2) cut with the level surface at ``height``: the points
        (K, 3) mapping CRS (NaN where none) and where the ray has none within ``max_range``
        times the centre's height above the surface (horizontally, tangent plane)."""
        origin, direction = self.rays(image_id, pixels)
        # the level surface through a point below the centre, as a plane in the local frame
        below = self.local.enu_to_map(origin[:1])[0].copy()
        depth = abs(below[2] - height)
        below[2] = height
        nl, q0 = self._planes_local([[0.0, 0.0, 1.0]], [below])
        with np.errstate(invalid="ignore", divide="ignore"):
            t = ((q0 - origin) @ nl[0]) / (direction @ nl[0])
        t = np.where(t > 0, t, np.nan)
        reach = t * np.linalg.norm(direction - np.outer(direction @ nl[0], nl[0]), axis=1)
        far = ~(reach <= max_range * depth)
        hit = origin + t[:, None] * direction
        # the tangent plane drops below the level surface away from the nadir (8 cm at 1 km):
        # a few Newton steps along each ray on the mapping-CRS height
        for _ in range(3):
            good = np.isfinite(t)
            if not good.any():
                break
            dz = self.local.enu_to_map(hit[good])[:, 2] - height
            t[good] -= dz / (direction[good] @ nl[0])
            hit = origin + t[:, None] * direction
        out = np.full((len(pixels), 3), np.nan)
        good = np.isfinite(hit).all(axis=1)
        if good.any():
            out[good] = self.local.enu_to_map(hit[good])
        return out, far
