"""The scene the renderer (:mod:`.render`) draws: its options (sun, noise, tints), the
shading, and the DSM with its region raster (the LAS class or the roof plane of every cell)
and the roof planes, in the mapping CRS.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pyproj
from numpy.typing import ArrayLike, NDArray

from ..errors import CrsError, InputError
from ..geometry.frames import parse_crs
from ..geometry.grid import Grid
from ..geometry.planes import Plane
from ..geometry.raycast import DsmTracer
from ..geometry.surface import Dsm

LOG = logging.getLogger(__name__)

Array = NDArray[np.float64]

__all__ = [
    "CLASS_ALBEDO",
    "PLANE_TINTS",
    "SKY_RGB",
    "RenderOptions",
    "RenderScene",
    "lambert",
    "sun_vector",
]

CLASS_ALBEDO = {
    1: (0.30, 0.46, 0.22),  # unclassified: in AHN3 mostly trees and shrubs
    2: (0.47, 0.50, 0.40),  # ground: grey-green
    3: (0.33, 0.52, 0.24),  # low vegetation
    4: (0.28, 0.47, 0.20),  # medium vegetation
    5: (0.22, 0.42, 0.17),  # high vegetation
    6: (0.62, 0.58, 0.54),  # building, not on a roof plane (walls, chimneys, dormers)
    9: (0.16, 0.25, 0.34),  # water
}
_OTHER = (0.50, 0.50, 0.50)
#: Roof tints (R, G, B albedo), chosen by plane id so that neighbouring faces differ.
PLANE_TINTS = (
    (0.72, 0.34, 0.23),  # terracotta
    (0.40, 0.44, 0.52),  # slate
    (0.80, 0.62, 0.33),  # ochre
    (0.55, 0.22, 0.20),  # dark red
    (0.45, 0.58, 0.62),  # zinc
    (0.52, 0.38, 0.28),  # brown
    (0.66, 0.66, 0.60),  # concrete
)
#: Colour of rays that miss the DSM (8-bit RGB).
SKY_RGB = (22, 26, 34)
#: Class code of the region raster for "no plane".
NO_PLANE = -1


@dataclass(frozen=True)
class RenderOptions:
    """Parameters of :func:`render_image`.

    Attributes
    ----------
    step_px : int
        One DSM ray per ``step_px`` x ``step_px`` block of pixels (1: every pixel).
    sun_azimuth_deg, sun_elevation_deg : float
        Direction towards the sun: clockwise from grid north, and above the horizon, degrees.
    ambient : float
        Share of the light that does not depend on the face orientation, in [0, 1].
    noise_dn : float
        Standard deviation of the Gaussian luminance noise (the same on R, G and B), 8-bit
        digital numbers (0: none).
    seed : int
        Seed of the noise.
    window_px : int
        Neighbourhood (coarse pixels, odd) searched for other planes near a label change.
    occlusion_tol_m : float
        A non-plane DSM hit hides a plane when it is this much nearer along the ray, metres.
    line_band_m : float
        Distance (x, y) from a LiDAR line within which its planes' edge rule overrides the
        plane regions, CRS unit (about the point spacing: the regions' uncertainty there).
    direction_grid_px : int
        Spacing of the lattice of exact chord directions, pixels.
    """

    step_px: int = 4
    sun_azimuth_deg: float = 160.0
    sun_elevation_deg: float = 45.0
    ambient: float = 0.45
    noise_dn: float = 1.0
    seed: int = 0
    window_px: int = 7
    occlusion_tol_m: float = 0.75
    line_band_m: float = 0.6
    direction_grid_px: int = 16

    def __post_init__(self) -> None:
        checks = (
            (int(self.step_px) >= 1, "step_px must be >= 1"),
            (0.0 <= self.ambient <= 1.0, "ambient must lie in [0, 1]"),
            (self.noise_dn >= 0.0, "noise_dn must be >= 0"),
            (int(self.window_px) >= 1 and int(self.window_px) % 2 == 1, "window_px: odd, >= 1"),
            (int(self.direction_grid_px) >= 1, "direction_grid_px must be >= 1"),
            (-90.0 <= self.sun_elevation_deg <= 90.0, "sun elevation in [-90, 90] degrees"),
        )
        for ok, text in checks:
            if not ok:
                raise InputError(f"render options: {text}")


def sun_vector(azimuth_deg: float, elevation_deg: float) -> Array:
    """Unit vector (3,) towards the sun in (east, north, up).

    >>> sun_vector(90.0, 0.0).round(12).tolist()
    [1.0, 0.0, 0.0]
    """
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    return np.array([math.sin(az) * math.cos(el), math.cos(az) * math.cos(el), math.sin(el)])


def lambert(normals: ArrayLike, sun: ArrayLike, ambient: float) -> Array:
    """Lambert shading factor ``ambient + (1 - ambient) max(0, n . s)`` of unit normals.

    Parameters
    ----------
    normals : (N, 3) array_like
        Unit surface normals (east, north, up).
    sun : (3,) array_like
        Unit vector towards the sun.
    ambient : float

    Returns
    -------
    (N,) ndarray in [ambient, 1]

    Examples
    --------
    >>> lambert([[0.0, 0.0, 1.0]], [0.0, 0.6, 0.8], 0.25).round(12).tolist()
    [0.85]
    """
    n = np.atleast_2d(np.asarray(normals, dtype=np.float64))
    cos = np.maximum(n @ np.asarray(sun, dtype=np.float64), 0.0)
    return ambient + (1.0 - ambient) * cos


# --------------------------------------------------------------------------- the scene
@dataclass(frozen=True)
class _Raster:
    """An integer label raster (north-up, ``grid``); :meth:`at` looks labels up by x, y."""

    grid: Grid
    values: NDArray[np.int32]
    outside: int

    def at(self, x: Array, y: Array) -> NDArray[np.int32]:
        g = self.grid
        col = np.floor((x - g.x0) / g.cell)
        row = np.floor((g.y_top - y) / g.cell)
        inside = (col >= 0) & (row >= 0) & (col < g.cols) & (row < g.rows)
        inside &= np.isfinite(x) & np.isfinite(y)
        out = np.full(np.shape(x), self.outside, dtype=np.int32)
        out[inside] = self.values[row[inside].astype(np.int64), col[inside].astype(np.int64)]
        return out


def _nearest_label_raster(
    grid: Grid, x: Array, y: Array, z: Array, labels: NDArray, fill: int, max_dist: float
) -> NDArray[np.int32]:
    """Label of the highest point in each cell; empty cells take the label of the nearest
    occupied cell (Euclidean distance transform) up to ``max_dist``, else ``fill``."""
    from scipy.ndimage import distance_transform_edt

    flat = grid.flat_index(x, y)
    # sort by cell, then height: the last of each run is the highest point of the cell
    order = np.lexsort((z, flat))
    fs = flat[order]
    last = np.flatnonzero(np.r_[fs[1:] != fs[:-1], True])
    out: NDArray[np.int32] = np.full(grid.rows * grid.cols, fill, dtype=np.int32)
    occupied: NDArray[np.bool_] = np.zeros(grid.rows * grid.cols, dtype=bool)
    out[fs[last]] = labels[order[last]]
    occupied[fs[last]] = True
    out = out.reshape(grid.rows, grid.cols)
    occupied = occupied.reshape(grid.rows, grid.cols)
    if occupied.all():
        return out
    dist, (ri, ci) = distance_transform_edt(~occupied, return_indices=True)
    filled = out[ri, ci]
    filled[dist * grid.cell > max_dist] = fill
    return filled.astype(np.int32)


def _edge_kind(line, a: int, b: int, normals: Array, centroids: Array, region: _Raster) -> int:
    """1 if planes a and b meet in a convex edge along ``line`` (each face below the other
    plane's extension: ridge, hip), -1 if concave (valley), 0 if undecided.

    The side of the line each face lies on is read from the region raster at points beside
    the line (both planes are infinite; only their regions tell the sides), then the sign of
    ``z_a - z_b`` on a's side decides. Faces on opposite sides make the two one-sided tests
    equivalent, so one suffices.
    """
    start, end = np.asarray(line.start, float), np.asarray(line.end, float)
    u = (end - start)[:2]
    length = float(np.hypot(*u))
    if length == 0:
        return 0
    perp = np.array([-u[1], u[0]]) / length
    t = np.array([0.2, 0.35, 0.5, 0.65, 0.8])
    mid = start[:2] + t[:, None] * (end - start)[:2]
    side = 0
    for delta in (0.25, 0.5, 0.75):
        plus = region.at(*(mid + delta * perp).T)
        minus = region.at(*(mid - delta * perp).T)
        side += int(np.sum((plus == a) & (minus == b))) - int(np.sum((plus == b) & (minus == a)))
    if side == 0:
        return 0
    p = start[:2] + 0.5 * (end - start)[:2] + np.sign(side) * 0.5 * perp

    def height(k: int) -> float:
        n, c = normals[k], centroids[k]
        return float(c[2] - (n[0] * (p[0] - c[0]) + n[1] * (p[1] - c[1])) / n[2])

    f = height(a) - height(b)
    return 1 if f < 0 else (-1 if f > 0 else 0)


def _colour_planes(regions: NDArray[np.int32], lines: NDArray[np.bool_], n: int) -> NDArray:
    """Greedy colouring: a tint index per plane, different from the tints of the planes whose
    regions touch it or that share a LiDAR line with it, while ``n`` tints suffice."""
    p = lines.shape[0]
    touch = lines.copy()
    for a, b in ((regions[:, :-1], regions[:, 1:]), (regions[:-1], regions[1:])):
        m = (a != b) & (a >= 0) & (b >= 0)
        touch[a[m], b[m]] = True
        touch[b[m], a[m]] = True
    tint = np.full(p, -1, dtype=np.int64)
    for k in range(p):
        used = set(tint[touch[k]].tolist())
        free = [c for c in range(n) if c not in used]
        tint[k] = free[k % len(free)] if free else k % n  # rotate: all tints get used
    return tint


@dataclass(frozen=True)
class RenderScene:
    """A DSM with LAS classes, and roof planes with their regions and edge types.

    Build with :meth:`build`. All coordinates are in the mapping CRS ``crs``.

    Attributes
    ----------
    tracer : DsmTracer
    classes : _Raster
        LAS class of the highest point of each DSM cell (gaps: nearest cell's class).
    regions : _Raster
        Plane index (into ``plane_ids``) owning each cell of ``region_cell``, or -1.
    plane_ids : (P,) int64
    normals, centroids : (P, 3) float64
        Unit normals (up) and points of the planes.
    edge : (P, P) int8
        1 convex edge (ridge, hip), -1 concave edge (valley), 0 no LiDAR line between them.
    line_of : (P, P) int32
        Index of the LiDAR line between two planes in ``segments`` (-1: none).
    segments : (L, 2, 2) float64
        x, y of the lines' end points.
    tint : (P,) int64
        Index into :data:`PLANE_TINTS` of each plane (touching planes differ where possible).
    crs : pyproj.CRS
    """

    tracer: DsmTracer
    classes: _Raster
    regions: _Raster
    plane_ids: NDArray[np.int64]
    normals: Array
    centroids: Array
    edge: NDArray[np.int8]
    line_of: NDArray[np.int32]
    segments: Array
    tint: NDArray[np.int64]
    crs: pyproj.CRS

    @classmethod
    def build(
        cls,
        dsm: Dsm,
        points: ArrayLike,
        classification: ArrayLike,
        plane_ids: ArrayLike | None = None,
        planes: Sequence[Plane] = (),
        lines: Sequence = (),
        *,
        crs: str | int | pyproj.CRS | None = None,
        region_cell: float = 0.05,
        max_gap: float = 1.0,
    ) -> RenderScene:
        """Prepare a scene for :func:`render_image`.

        Parameters
        ----------
        dsm : Dsm
            The surface (e.g. :func:`core.io.dsm.dsm_from_las` of the cloud).
        points : (M, 3) array_like
            The LiDAR points (mapping CRS) that label the surface.
        classification : (M,) array_like
            Their LAS classes.
        plane_ids : (M,) array_like, optional
            Their plane ids (-1: none), as the ``plane_id`` dimension of extractroofplanes.
        planes : sequence of Plane
            The roof planes those ids refer to.
        lines : sequence of ControlLine
            LiDAR lines (:mod:`core.lidar.control`): the plane pairs whose shared edge is
            rendered exactly.
        crs : optional
            Mapping CRS (default: the DSM's).
        region_cell : float
            Cell of the plane-region raster, CRS unit.
        max_gap : float
            Raster cells farther than this from every point belong to no plane, CRS unit.

        Returns
        -------
        RenderScene
        """
        crs_ = parse_crs(crs, optional=True) if crs is not None else dsm.crs
        if crs_ is None:
            raise CrsError("the scene needs a mapping CRS (the DSM has none)")
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        cls_ = np.asarray(classification).astype(np.int32).ravel()
        if pts.shape[0] == 0 or cls_.shape[0] != pts.shape[0]:
            raise InputError("the scene needs LiDAR points with one class per point")
        if not region_cell > 0:
            raise InputError(f"region_cell must be > 0, got {region_cell!r}")
        tracer = DsmTracer.build(dsm)
        g = dsm.grid
        class_raster = _Raster(
            g, _nearest_label_raster(g, pts[:, 0], pts[:, 1], pts[:, 2], cls_, 0, math.inf), 0
        )
        by_id = {int(p.id): k for k, p in enumerate(planes)}
        pidx = np.full(pts.shape[0], NO_PLANE, dtype=np.int32)
        if plane_ids is not None and by_id:
            ids = np.asarray(plane_ids).astype(np.int64).ravel()
            if ids.shape[0] != pts.shape[0]:
                raise InputError("plane_ids needs one value per point")
            keys = np.array(sorted(by_id), dtype=np.int64)
            values = np.array([by_id[int(v)] for v in keys], dtype=np.int32)
            pos = np.clip(np.searchsorted(keys, ids), 0, keys.size - 1)
            pidx = np.where(keys[pos] == ids, values[pos], NO_PLANE).astype(np.int32)
        rows, cols = (max(1, math.ceil(m * g.cell / region_cell)) for m in (g.rows, g.cols))
        rg = Grid(g.x0, g.y_top, float(region_cell), rows, cols)
        region = _Raster(
            rg,
            _nearest_label_raster(rg, pts[:, 0], pts[:, 1], pts[:, 2], pidx, NO_PLANE, max_gap),
            NO_PLANE,
        )
        n_p = len(planes)
        normals = np.array([p.normal for p in planes], dtype=np.float64).reshape(n_p, 3)
        centroids = np.array([p.centroid for p in planes], dtype=np.float64).reshape(n_p, 3)
        edge = np.zeros((n_p, n_p), dtype=np.int8)
        line_of = np.full((n_p, n_p), -1, dtype=np.int32)
        segments: list[list[Array]] = []
        for line in lines:
            a, b = (by_id.get(int(i), -1) for i in line.plane_ids)
            if a >= 0 and b >= 0 and a != b:
                edge[a, b] = edge[b, a] = _edge_kind(line, a, b, normals, centroids, region)
                line_of[a, b] = line_of[b, a] = len(segments)
                segments.append([np.asarray(line.start)[:2], np.asarray(line.end)[:2]])
        segs = np.array(segments, dtype=np.float64).reshape(-1, 2, 2)
        if segs.shape[0] == 0:
            segs = np.full((1, 2, 2), np.nan)  # gathered by index 0 where no line exists
        ids = np.array([int(p.id) for p in planes], dtype=np.int64)
        tint = _colour_planes(region.values, edge != 0, len(PLANE_TINTS))
        LOG.info(
            "render scene: DSM %d x %d, %d planes, %d exact edges, regions %d x %d of %g",
            g.rows,
            g.cols,
            n_p,
            int(np.count_nonzero(edge)) // 2,
            rg.rows,
            rg.cols,
            region_cell,
        )
        return cls(
            tracer, class_raster, region, ids, normals, centroids, edge, line_of, segs, tint, crs_
        )

    @property
    def dsm(self) -> Dsm:
        return self.tracer.dsm

    def albedo_at(self, x: Array, y: Array) -> Array:
        """(N, 3) albedo of the DSM surface at map points: the class albedo of the cells,
        interpolated bilinearly between cell centres (no staircase at class changes)."""
        table = np.array([CLASS_ALBEDO.get(c, _OTHER) for c in range(256)], dtype=np.float32)
        cells = table[np.clip(self.classes.values, 0, 255)]
        g = self.classes.grid
        xs, ys = np.nan_to_num(np.asarray(x, float)), np.nan_to_num(np.asarray(y, float))
        return np.column_stack(
            [g.bilinear(np.ascontiguousarray(cells[:, :, k]), xs, ys) for k in range(3)]
        ).astype(np.float64)

    def outlines(self, min_cells: int = 4) -> dict[int, Array]:
        """Outline polygon (M, 3) of each plane's region, counter-clockwise, z on the plane.

        The largest connected part of the region, traced on the region raster and simplified
        by Douglas-Peucker at 0.75 cell; these are the edges :func:`render_image` draws at the
        eaves (the shared edges of planes are drawn at their exact intersection instead).
        """
        import cv2

        g = self.regions.grid
        out: dict[int, Array] = {}
        for k, pid in enumerate(self.plane_ids):
            mask = (self.regions.values == k).astype(np.uint8)
            if int(mask.sum()) < min_cells:
                continue
            contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
            biggest = max(contours, key=lambda c: (cv2.contourArea(c), len(c)))
            poly = cv2.approxPolyDP(biggest, 0.75, True).reshape(-1, 2).astype(np.float64)
            if len(poly) < 3:
                continue
            # contour points are cell indices (col, row); their centres in map coordinates
            xy = np.column_stack(
                [g.x0 + (poly[:, 0] + 0.5) * g.cell, g.y_top - (poly[:, 1] + 0.5) * g.cell]
            )
            area2 = np.sum(xy[:, 0] * np.roll(xy[:, 1], -1) - np.roll(xy[:, 0], -1) * xy[:, 1])
            if area2 < 0:
                xy = xy[::-1]
            n, c = self.normals[k], self.centroids[k]
            z = c[2] - (n[0] * (xy[:, 0] - c[0]) + n[1] * (xy[:, 1] - c[1])) / n[2]
            out[int(pid)] = np.column_stack([xy, z])
        return out
