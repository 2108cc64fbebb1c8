"""Monoplotting: 3D points and lines from one oriented image and a LiDAR DSM (dos Santos et al.
2010).

The collinearity ray of an image point, ``G = CP + t N`` with ``N = M^T (x - x0, y - y0, -f)`` (dos
Santos et al. 2010, Eqs. 1-4), is intersected with the DSM polyhedron: directly, with the traversal
and Dal Poz's Eq. 9 of :mod:`core.geometry.raycast`, or by Makarovic's iterative method (height ->
planimetric position -> DSM height ..., until the height changes less than a tolerance); rows on
LiDAR roof planes are intersected with their plane (Eqs. 7-10 with the fitted plane). The
image-point sigma, the exterior-orientation covariance and the DSM (or plane) uncertainty are
propagated into a 3 x 3 covariance per point.

For a fisheye camera (equidistant, equisolid, orthographic, stereographic, with its lens
correction; :mod:`core.geometry.projection`) the camera-frame ray ``(x - x0, y - y0, -f)``
above is replaced by the projection's own ray of the ideal point, at the angle ``theta(r)``
off the axis (:meth:`core.geometry.camera.Camera.ray_from_ideal`); the ray casting is the same.
A pixel beyond the projection's field (``r > f`` for the orthographic one) has no ray: status
``out_of_field``.

Each ray gets a status code (:data:`STATUS_TEXT`): a ray that leaves the DSM, crosses a
nodata hole before hitting the surface, or belongs to an image without orientation is
reported, never raised. A DSM in another CRS is resampled into the mapping CRS first
(:func:`core.geometry.surface.reproject_dsm`); when that is impossible (a vertical grid PROJ
lacks) the run is refused with :class:`CrsError`, as docs/conventions.md says: heights are
never taken without their datum.

Frames: the EO table's omega-phi-kappa are relative to the grid frame at the perspective
centre, and a straight ray in the real (ENU) world is not straight in projected coordinates
(scale factor, Earth curvature: up to decimetres at 1 km). :func:`monoplot` therefore
builds each ray in the local ENU frame and intersects the DSM with its chord in the mapping
frame through the camera and the ray's point at the hit distance, found in two passes.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import pyproj
from numpy.typing import ArrayLike, NDArray

from ..errors import Cancelled, CrsError, InputError
from ..geometry.camera import Camera
from ..geometry.collinearity import collinearity_jacobians
from ..geometry.frames import LocalFrame
from ..geometry.planes import Plane
from ..geometry.raycast import (
    RAY_STATUS_TEXT,
    STATUS_GRAZING,
    STATUS_NODATA,
    STATUS_NOT_CONVERGED,
    STATUS_OK,
    STATUS_OUTSIDE,
    DsmHits,
    DsmTracer,
    chord_rays,
    dal_poz_intersect,
    intersect_dsm,
)
from ..geometry.surface import Dsm, reproject_dsm
from .monoplot_options import DEFAULT_EO_SIGMAS, METHODS
from .observations import ImageObservations
from .orientation import ExteriorOrientationTable, eo_map_to_local

LOG = logging.getLogger(__name__)

Array = NDArray[np.float64]

STATUS_NO_ORIENTATION = 4
STATUS_PARALLEL = 6
STATUS_UNKNOWN_PLANE = 7
STATUS_OUT_OF_FIELD = 8
#: Meaning of each status code (the outputs carry both).
STATUS_TEXT = {
    **RAY_STATUS_TEXT,
    STATUS_NO_ORIENTATION: "no_orientation",  # the image is not in the EO table
    STATUS_PARALLEL: "parallel",  # the ray is parallel to the plane or meets it behind
    STATUS_UNKNOWN_PLANE: "unknown_plane",  # target_id is not in the plane table
    STATUS_OUT_OF_FIELD: "out_of_field",  # the pixel lies beyond the fisheye projection's field
}
_HIT = (STATUS_OK, STATUS_GRAZING)

__all__ = [
    "DEFAULT_EO_SIGMAS",
    "METHODS",
    "STATUS_TEXT",
    "MonoplotLine",
    "MonoplotResult",
    "intersect_planes",
    "makarovic",
    "monoplot",
    "propagate_covariance",
]


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
    ok = np.isfinite(a).all(axis=(1, 2)) & (
        np.abs(np.linalg.det(np.where(np.isfinite(a), a, 0.0))) > 1e-300
    )
    if ok.any():
        ainv = np.linalg.inv(a[ok])
        out[ok] = ainv @ s[ok] @ np.swapaxes(ainv, 1, 2)
    return out


# --------------------------------------------------------------------------- monoplotting
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


def _two_pass(
    solve: Callable[[Array, Array], tuple[Array, NDArray[np.int8]]],
    local: LocalFrame,
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


def _ray_table(
    obs: ImageObservations, step_px: float
) -> tuple[NDArray[np.int64], Array, NDArray[np.int64], NDArray[np.int64], list[tuple[str, str]]]:
    """The rays to cast: points, then line vertices (with densified points, ``step_px`` > 0).

    Returns (source row of each ray, its pixel, its line index or -1, its vertex index or -1,
    the (image, target) key of each line).
    """
    line_rays, line_keys = _line_rays(obs, step_px if step_px > 0 else 0.0)
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
    line_of = np.array([-1] * len(point_rows) + [r[1] for r in line_rays], dtype=np.int64)
    vertex_of = np.array([-1] * len(point_rows) + [r[2] for r in line_rays], dtype=np.int64)
    return src, pixels, line_of, vertex_of, line_keys


def _dsm_in_crs(dsm: Dsm, mapping_crs: pyproj.CRS, should_stop: Callable[[], bool] | None) -> Dsm:
    """The DSM in the mapping CRS: as is when it has no CRS or the same, else resampled
    (heights transformed); CrsError when the heights cannot be brought over."""
    if dsm.crs is None:
        LOG.warning("the DSM has no CRS: taken to be the mapping CRS %s", mapping_crs.name)
    elif not _crs_equal(dsm.crs, mapping_crs):
        source_crs = dsm.crs.name
        try:
            dsm = reproject_dsm(dsm, mapping_crs, should_stop=should_stop)
        except CrsError as exc:  # docs/conventions.md: never a height without its datum
            raise CrsError(
                f"the DSM in '{source_crs}' cannot be brought into the mapping CRS "
                f"'{mapping_crs.name}': {exc}",
                path=dsm.source or None,
            ) from exc
        LOG.warning(
            "the DSM was in '%s': resampled into the mapping CRS '%s' (cell %g)",
            source_crs,
            mapping_crs.name,
            dsm.cell,
        )
    return dsm


@dataclass(frozen=True)
class _Chords:
    """Rays in the local ENU frame at the DSM's centre, and how far to look along them."""

    local: LocalFrame
    c_map: Array  # (n, 3) perspective centres, mapping frame
    c_loc: Array  # (n, 3) the same, local frame
    d_loc: Array  # (n, 3) unit ray directions, local frame
    s_far: Array  # (n,) distance to below the DSM's lowest point, metres

    def take(self, k: NDArray[np.intp]) -> tuple[LocalFrame, Array, Array, Array, Array]:
        """The arguments of _two_pass for the rays ``k``."""
        return self.local, self.c_map[k], self.c_loc[k], self.d_loc[k], self.s_far[k]


def _chords(
    mapping_crs: pyproj.CRS,
    dsm: Dsm,
    table: ExteriorOrientationTable,
    cam: Camera,
    pixels: Array,
    img: NDArray[np.int64],
) -> _Chords:
    """The rays of ``pixels`` seen from the images ``img`` (rows of ``table``)."""
    from ..geometry.frames import MappingFrame

    mapping = MappingFrame(mapping_crs)
    zmin = dsm.z_range[0]
    xc, yc = (
        dsm.grid.x0 + dsm.grid.cols * dsm.cell / 2,
        dsm.grid.y_top - dsm.grid.rows * dsm.cell / 2,
    )
    local = LocalFrame.at_map_point(mapping, [xc, yc, zmin])
    c_loc_img, m_loc_img = eo_map_to_local(table.xyz, table.opk, local)
    ideal = cam.ideal_from_pixel(pixels)
    # the camera's own projection (perspective or fisheye); NaN outside a fisheye's field
    ray_c = cam.ray_from_ideal(ideal)
    d_loc = np.einsum("nji,nj->ni", m_loc_img[img], ray_c)
    d_loc /= np.linalg.norm(d_loc, axis=1, keepdims=True)
    c_loc = c_loc_img[img]
    c_map = table.xyz[img]
    z_low = local.map_to_enu(np.array([[xc, yc, zmin - 10.0]]))[0, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        s_far = np.where(d_loc[:, 2] < -1e-6, (c_loc[:, 2] - z_low) / -d_loc[:, 2], 1e3)
    return _Chords(local, c_map, c_loc, d_loc, np.maximum(s_far, 1.0))


#: (points (n, 3), status (n,), incidence (n,) degrees, surface gradient (n, 3), variance of
#: the surface height (n,) m^2) of the rays solved on one kind of surface
_Solved = tuple[Array, NDArray[np.int8], Array, Array, Array]


def _on_dsm(
    dsm: Dsm,
    tracer: DsmTracer,
    method: str,
    args: tuple,
    min_incidence_deg: float,
    sigma_dsm: float,
    should_stop: Callable[[], bool] | None,
) -> _Solved:
    """Intersect the rays ``args`` (of _two_pass) with the DSM by ``method``."""
    last: dict[str, DsmHits] = {}

    def solve_dsm(o: Array, d: Array) -> tuple[Array, NDArray[np.int8]]:
        if method == "makarovic":
            return makarovic(dsm, o, d)[:2]
        hits = intersect_dsm(
            tracer, o, d, min_incidence_deg=min_incidence_deg, should_stop=should_stop
        )
        last["hits"] = hits
        return hits.points, hits.status

    pts, st, dirs = _two_pass(solve_dsm, *args)
    if method == "dal_poz":
        hits = last["hits"]
    else:
        # the face under the converged point gives the gradient for the precision
        hits = intersect_dsm(tracer, args[1], dirs, min_incidence_deg=0.0)
        st = np.where(
            (st == STATUS_OK) & (hits.status == STATUS_GRAZING), STATUS_GRAZING, st
        ).astype(np.int8)
    grad = np.column_stack([-hits.gradient, np.ones(len(pts))])
    var_h = sigma_dsm**2 * np.sum(hits.weights**2, axis=1)
    return pts, st, hits.incidence_deg, grad, var_h


def _on_planes(planes: list[Plane], args: tuple) -> _Solved:
    """Intersect the rays ``args`` (of _two_pass) with one plane each."""
    normal = np.array([p.normal for p in planes])
    offset = np.array([p.d for p in planes])
    pcov = np.array([p.covariance for p in planes])

    def solve_plane(o: Array, d: Array) -> tuple[Array, NDArray[np.int8]]:
        return intersect_planes(o, d, normal, offset)

    pts, st, _ = _two_pass(solve_plane, *args)
    inc = 90.0 - np.degrees(
        np.arccos(np.clip(np.abs(np.einsum("ij,ij->i", normal, args[3])), 0, 1))
    )
    g1 = np.column_stack([np.nan_to_num(pts), np.ones(len(pts))])
    var_h = np.einsum("ni,nij,nj->n", g1, pcov, g1)
    return pts, st, inc, normal, var_h


def _result_lines(
    line_keys: list[tuple[str, str]],
    line_of: NDArray[np.int64],
    vertex_of: NDArray[np.int64],
    points: Array,
    cov: Array,
    status: NDArray[np.int8],
) -> list[MonoplotLine]:
    """The 3D lines (vertices in order), each with its worst status and end-point sigmas."""
    lines = []
    for li, (img, tgt) in enumerate(line_keys):
        sel = np.flatnonzero(line_of == li)
        sel = sel[np.argsort(vertex_of[sel])]
        ends = [float(np.sqrt(np.trace(cov[sel[e]]))) for e in (0, -1)]
        worst = int(max(status[sel], key=lambda s: (s not in _HIT, s)))
        lines.append(MonoplotLine(img, tgt, points[sel], worst, (ends[0], ends[1])))
    return lines


def _eo_covariance(eo_sigmas) -> Array:
    """(6, 6) covariance of the exterior orientation (m, rad) from its 6 sigmas: X, Y, Z (m),
    omega, phi, kappa (deg); InputError unless 6 finite numbers >= 0."""
    sig6 = np.asarray(eo_sigmas, dtype=np.float64).ravel()
    if sig6.size != 6 or not np.isfinite(sig6).all() or (sig6 < 0).any():
        raise InputError("EO sigmas: give 6 numbers >= 0: X, Y, Z (m), omega, phi, kappa (deg)")
    return np.diag(np.r_[sig6[:3], np.radians(sig6[3:])] ** 2)


def _plane_rays(
    obs: ImageObservations, src: NDArray[np.int64], line_of: NDArray[np.int64], plane_map: dict
) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """(rays cut with a plane: tie and paper points, not on lines, when planes are given;
    those among them whose plane is not in ``plane_map``)."""
    kinds = [obs.type[k] for k in src]
    on_plane = np.array(
        [
            bool(plane_map) and kd in ("tie", "paper") and line_of[r] < 0
            for r, kd in enumerate(kinds)
        ]
    )
    unknown = on_plane & np.array([obs.target_id[k] not in plane_map for k in src])
    return on_plane, unknown


def _rows(obs: ImageObservations, src, line_of, vertex_of, used: list[str]) -> list[tuple]:
    """The result's row per ray: image, point, type, target, line, vertex, surface used."""
    return [
        (obs.image_id[s], obs.point_id[s], obs.type[s], obs.target_id[s], int(li), int(vi), used[r])
        for r, (s, li, vi) in enumerate(zip(src, line_of, vertex_of))
    ]


def monoplot(
    observations: ImageObservations,
    camera: Camera,
    eo: ExteriorOrientationTable,
    dsm: Dsm | DsmTracer,
    crs: str | int | pyproj.CRS,
    *,
    method: str = "dal_poz",
    sigma_dsm: float = 0.10,
    eo_sigmas: Sequence[float] = DEFAULT_EO_SIGMAS,
    planes: Sequence[Plane] = (),
    line_step_px: float = 0.0,
    min_incidence_deg: float = 5.0,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> MonoplotResult:
    """Monoplot the observations of oriented images on a DSM (or on roof planes).

    Parameters
    ----------
    observations : ImageObservations
        Rows of type ``line`` with the same image_id and target_id form one 3D line (vertices
        in file order); every other row is a point. Rows of type ``tie`` or ``paper`` whose
        target_id is one of ``planes`` are intersected with that plane instead of the DSM.
    camera : Camera
    eo : ExteriorOrientationTable
        In ``crs``.
    dsm : Dsm or DsmTracer
        The surface; a DSM in another CRS is resampled into ``crs`` (heights transformed); a
        DsmTracer is reused as is (no rebuild of the skipping pyramid).
    crs : mapping CRS of the EO and of the results (projected, metres).
    method : {"dal_poz", "makarovic"}
        Direct (DDA + Eq. 9) or iterative intersection with the DSM.
    sigma_dsm : float
        Standard deviation of a DSM height, metres (vertices independent).
    eo_sigmas : 6 numbers
        X, Y, Z (m) and omega, phi, kappa (degrees) standard deviations of the EO.
    planes : sequence of Plane
        Roof planes (``tie``/``paper`` rows on them).
    line_step_px : float
        Spacing of the extra points along image lines, pixels (0: end points only).
    min_incidence_deg : float
        Rays meeting the DSM face at a smaller angle get status "grazing".
    progress, should_stop
        Progress fraction; cancellation.

    Returns
    -------
    MonoplotResult
        With ``dsm`` the surface actually used (in ``crs``).
    """
    from ..geometry.frames import parse_crs

    if method not in METHODS:
        raise InputError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    eo_cov = _eo_covariance(eo_sigmas)
    obs, cam, table = observations, camera, eo
    mapping_crs = parse_crs(crs)
    tracer = dsm if isinstance(dsm, DsmTracer) else None
    if isinstance(dsm, DsmTracer):  # a prepared DSM (interactive use: one click after another)
        dsm = dsm.dsm
    plane_map: dict[str, Plane] = {str(p.id): p for p in planes}

    src, pixels, line_of, vertex_of, line_keys = _ray_table(obs, float(line_step_px))
    sigma_px = obs.sigma_px[src]
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

    dsm = _dsm_in_crs(dsm, mapping_crs, should_stop)
    targets = [obs.target_id[k] for k in src]
    on_plane, unknown = _plane_rays(obs, src, line_of, plane_map)
    status[unknown & (img_idx >= 0)] = STATUS_UNKNOWN_PLANE
    on_plane &= ~unknown

    todo = np.flatnonzero((img_idx >= 0) & ~unknown)
    if todo.size:
        if should_stop is not None and should_stop():
            raise Cancelled("cancelled before monoplotting")
        chords = _chords(mapping_crs, dsm, table, cam, pixels[todo], img_idx[todo])
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
            res_pts[k], res_st[k], res_inc[k], grad[k], var_h[k] = _on_dsm(
                dsm, tracer, method, chords.take(k), min_incidence_deg, sigma_dsm, should_stop
            )
        if plane_sel.any():
            k = np.flatnonzero(plane_sel)
            pl = [plane_map[targets[todo[q]]] for q in k]
            res_pts[k], res_st[k], res_inc[k], grad[k], var_h[k] = _on_planes(pl, chords.take(k))
            for q in k:
                used[todo[q]] = "plane"
        if method == "makarovic":
            for q in np.flatnonzero(dsm_sel):
                used[todo[q]] = "makarovic"
        no_ray = ~np.isfinite(chords.d_loc).all(axis=1)
        res_st[no_ray] = STATUS_OUT_OF_FIELD
        points[todo], status[todo], incidence[todo] = res_pts, res_st, res_inc
        hit = np.isin(res_st, _HIT)
        if hit.any():
            cov[todo[hit]] = propagate_covariance(
                res_pts[hit],
                eo_rows[hit],
                cam,
                sigma_px[todo[hit]],
                eo_cov,
                grad[hit],
                var_h[hit],
            )
    if progress is not None:
        progress(0.95)

    rows = _rows(obs, src, line_of, vertex_of, used)
    lines = _result_lines(line_keys, line_of, vertex_of, points, cov, status)
    result = MonoplotResult(
        rows, pixels, points, cov, status, incidence, lines, mapping_crs.to_wkt(), dsm
    )
    LOG.info("monoplotted %d rays: %s", n, result.status_counts())
    if progress is not None:
        progress(1.0)
    return result
