"""Ground positions of image observations: forward intersection of rays from several images,
and each observation's ray cut with its control (plane, line or LCP) after an adjustment."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..geometry.camera import Camera
from ..geometry.frames import LocalFrame
from .boresight_result import BoresightResult
from .boresight_setup import SurveyedPoints
from .observations import ImageObservations
from .orientation import ExteriorOrientationTable, eo_map_to_local

Array = NDArray[np.float64]


def meet_rays(
    centres: Array, rays: Array, point_of: NDArray[np.intp], n_points: int
) -> tuple[Array, NDArray[np.intp]]:
    """Least-squares meeting point of the rays of each point, and each point's ray count.

    Parameters
    ----------
    centres, rays : ndarray, shape (N, 3)
        Ray origins and unit directions, one Cartesian frame (metres).
    point_of : ndarray of int, shape (N,)
        Point number ``0 .. n_points - 1`` of every ray.

    Returns
    -------
    xyz : ndarray, shape (n_points, 3)
        The point minimising the sum of squared perpendicular distances to its rays; NaN for
        points with fewer than two rays or rays meeting at less than about 0.05 degrees,
        which do not fix a point.
    counts : ndarray of int, shape (n_points,)

    >>> c = np.array([[0.0, 0, 10], [10, 0, 10]])
    >>> r = np.array([[0.0, 0, -1], [-1, 0, -1]]) / np.array([[1.0], [np.sqrt(2)]])
    >>> xyz, n = meet_rays(c, r, np.array([0, 0]), 1)
    >>> np.round(xyz, 9).tolist(), n.tolist()
    ([[0.0, 0.0, 0.0]], [2])
    """
    proj = np.eye(3) - rays[:, :, None] * rays[:, None, :]  # removes the along-ray component
    a = np.zeros((n_points, 3, 3))
    b = np.zeros((n_points, 3))
    np.add.at(a, point_of, proj)
    np.add.at(b, point_of, np.einsum("nij,nj->ni", proj, centres))
    counts = np.bincount(point_of, minlength=n_points)
    xyz = np.full((n_points, 3), np.nan)
    ok = np.flatnonzero(counts >= 2)
    if ok.size:
        good = ok[np.linalg.eigvalsh(a[ok])[:, 0] > 1e-7]
        if good.size:
            xyz[good] = np.linalg.solve(a[good], b[good][:, :, None])[:, :, 0]
    return xyz, counts


def forward_intersection(
    observations: ImageObservations,
    eo: ExteriorOrientationTable,
    camera: Camera,
    local: LocalFrame,
    kind: str = "check",
) -> tuple[list[str], Array, NDArray[np.int64]]:
    """Intersect the rays of the rows of one type, per point id, in an ENU frame.

    Each point is the least-squares meeting point of its rays (minimum sum of squared
    perpendicular distances), solved in the adjustment frame ``local`` and returned in the
    mapping CRS. Points seen in fewer than two images, or whose rays are nearly parallel,
    are skipped.

    Returns
    -------
    ids : list of str
    xyz : ndarray, shape (K, 3)
        Mapping CRS.
    n_rays : ndarray of int, shape (K,)
    """
    sel = np.flatnonzero(np.array(observations.type) == kind)
    image_of = {i: k for k, i in enumerate(eo.image_id)}
    sel = np.array([r for r in sel if observations.image_id[r] in image_of], dtype=np.intp)
    names, inv = np.unique(np.array(observations.point_id)[sel], return_inverse=True)
    if sel.size == 0:
        return [], np.empty((0, 3)), np.empty(0, dtype=np.int64)
    centres, m = eo_map_to_local(eo.xyz, eo.opk, local)
    img = np.array([image_of[observations.image_id[r]] for r in sel])
    ideal = camera.ideal_from_pixel(observations.pixels[sel])
    ray_c = np.column_stack([ideal, np.full(sel.size, -camera.focal_mm)])
    d = np.einsum("nji,nj->ni", m[img], ray_c)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    xyz, counts = meet_rays(centres[img], d, inv, len(names))
    ok = np.isfinite(xyz[:, 0])
    xyz = xyz[ok]
    return [str(v) for v in names[ok]], local.enu_to_map(xyz), counts[ok].astype(np.int64)


def ground_positions(
    result: BoresightResult,
    observations: ImageObservations,
    camera: Camera,
    planes: Sequence = (),
    lines: Sequence = (),
    lcps: Sequence = (),
    ground_points: SurveyedPoints | None = None,
) -> Array:
    """Ground position of each observation row with the adjusted orientations (mapping CRS).

    ``tie`` and ``paper`` rows: the ray cut with the row's plane; ``line`` rows: the point of
    the line nearest the ray; ``lcp`` and ``check`` rows: the ray cut with the horizontal plane
    through the LCP; ``control`` rows: the same through the ground point ``point_id`` of
    ``ground_points`` (control and check points). Rays use the calibrated interior
    orientation when it was estimated. Rows whose image or target is unknown are NaN.

    Returns
    -------
    ndarray, shape (N, 3)
    """
    local: LocalFrame = result.local
    n = len(observations)
    out = np.full((n, 3), np.nan)
    if n == 0:
        return out
    cam = camera
    if result.interior is not None:
        cam = camera.with_interior(np.concatenate([result.interior, camera.distortion.params]))
    image_of = {i: k for k, i in enumerate(result.eo.image_id)}
    img = np.array([image_of.get(i, -1) for i in observations.image_id])
    ok = img >= 0
    centres, m = eo_map_to_local(result.eo.xyz, result.eo.opk, local)
    ideal = cam.ideal_from_pixel(observations.pixels)
    ray_c = cam.ray_from_ideal(ideal)  # the camera's own projection (perspective or fisheye)
    safe = np.where(ok, img, 0)
    c = centres[safe]
    d = np.einsum("nji,nj->ni", m[safe], ray_c)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    kinds = np.array(observations.type)
    target = np.array(observations.target_id)
    local_pts = np.full((n, 3), np.nan)

    def by_id(items) -> dict[str, int]:
        return {str(p.id): k for k, p in enumerate(items)}

    # planes: carried into the ENU frame through three of their points (exact for a plane)
    if planes:
        pid = by_id(planes)
        rows = np.flatnonzero(ok & np.isin(kinds, ("tie", "paper")) & np.isin(target, list(pid)))
        if rows.size:
            k = np.array([pid[t] for t in target[rows]])
            cen = np.array([planes[j].centroid for j in k])
            nrm = np.array([planes[j].normal for j in k])
            u = np.cross(nrm, np.where(np.abs(nrm[:, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]]))
            u /= np.linalg.norm(u, axis=1, keepdims=True)
            v = np.cross(nrm, u)
            p0, p1, p2 = (local.map_to_enu(q) for q in (cen, cen + u, cen + v))
            nl = np.cross(p1 - p0, p2 - p0)
            nl /= np.linalg.norm(nl, axis=1, keepdims=True)
            t = np.einsum("ni,ni->n", p0 - c[rows], nl) / np.einsum("ni,ni->n", d[rows], nl)
            local_pts[rows] = c[rows] + t[:, None] * d[rows]
    if lines:
        lid = by_id(lines)
        rows = np.flatnonzero(ok & (kinds == "line") & np.isin(target, list(lid)))
        if rows.size:
            k = np.array([lid[t] for t in target[rows]])
            x0 = local.map_to_enu(np.array([lines[j].point for j in k]))
            x1 = local.map_to_enu(np.array([lines[j].point + lines[j].direction for j in k]))
            u = (x1 - x0) / np.linalg.norm(x1 - x0, axis=1, keepdims=True)
            # closest point of the line to the ray: solve the 2 x 2 normal equations
            w0 = x0 - c[rows]
            b = np.einsum("ni,ni->n", u, d[rows])
            den = 1.0 - b**2
            s = (b * np.einsum("ni,ni->n", w0, d[rows]) - np.einsum("ni,ni->n", w0, u)) / np.where(
                den > 1e-12, den, np.nan
            )
            local_pts[rows] = x0 + s[:, None] * u
    if lcps:
        cid = by_id(lcps)
        rows = np.flatnonzero(ok & np.isin(kinds, ("lcp", "check")) & np.isin(target, list(cid)))
        if rows.size:
            xyz = local.map_to_enu(np.array([lcps[cid[t]].xyz for t in target[rows]]))
            t = (xyz[:, 2] - c[rows, 2]) / d[rows, 2]
            local_pts[rows] = c[rows] + t[:, None] * d[rows]
    if ground_points is not None and len(ground_points.point_id):
        gid = {p: k for k, p in enumerate(ground_points.point_id)}
        point = np.array(observations.point_id)
        rows = np.flatnonzero(ok & (kinds == "control") & np.isin(point, list(gid)))
        if rows.size:
            xyz = local.map_to_enu(ground_points.xyz[[gid[p] for p in point[rows]]])
            t = (xyz[:, 2] - c[rows, 2]) / d[rows, 2]
            local_pts[rows] = c[rows] + t[:, None] * d[rows]
    good = np.isfinite(local_pts).all(axis=1)
    if good.any():
        out[good] = local.enu_to_map(local_pts[good])
    return out
