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
"""

from __future__ import annotations

from collections.abc import Sequence
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
    "PickingScene",
    "PlaneCandidate",
    "nearest_point",
    "nearest_segment",
    "points_in_polygons",
]

Array = NDArray[np.float64]


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
        """Project outline rings (each (M_i, 3), mapping CRS) in one call: (M_i, 2) pixels."""
        sizes = [len(np.asarray(r).reshape(-1, 3)) for r in rings]
        if sum(sizes) == 0:
            return [np.empty((0, 2)) for _ in rings]
        px = self.project(image_id, np.vstack([np.asarray(r).reshape(-1, 3) for r in rings]))
        return np.split(px, np.cumsum(sizes)[:-1])

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
        """Ground footprint of an image: its four corners cut with the level surface at
        ``height`` (mapping CRS heights), (4, 3) mapping CRS, clockwise from the top-left."""
        w, h = self.camera.width_px, self.camera.height_px
        corners = np.array([[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]])
        origin, direction = self.rays(image_id, corners)
        # the level surface through a point below the centre, as a plane in the local frame
        below = self.local.enu_to_map(origin[:1])[0].copy()
        below[2] = height
        nl, q0 = self._planes_local([[0.0, 0.0, 1.0]], [below])
        with np.errstate(invalid="ignore", divide="ignore"):
            t = ((q0 - origin) @ nl[0]) / (direction @ nl[0])
        t = np.where(t > 0, t, np.nan)
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
        out = np.full((4, 3), np.nan)
        good = np.isfinite(hit).all(axis=1)
        if good.any():
            out[good] = self.local.enu_to_map(hit[good])
        return out
