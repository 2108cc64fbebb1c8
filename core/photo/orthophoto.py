"""Orthophotos: a frame image resampled onto a north-up ground grid through a surface model
(a LiDAR DSM or DTM), and true orthophotos, where ground the camera cannot see is no data.

For the centre (X, Y) of every cell of the output grid (mapping CRS):

1. **Height**: Z on the triangulated surface of :mod:`core.geometry.surface` (the polyhedron the
   ray casting also uses, so that the visibility test below and the projection agree).
2. **Image position**, rigorously: the exterior orientation (mapping CRS, omega-phi-kappa in the
   grid frame at the centre) is carried into a local ENU frame (:func:`eo_map_to_local`), and the
   point (X, Y, Z) into the same frame through pyproj (geodetic, ECEF). That point is
   ``A(X, Y) + Z B(X, Y)`` *exactly* (the height enters the geodetic -> ECEF step linearly; a
   map projection is 2D), so the camera-frame vector is ``q = a(X, Y) + Z b(X, Y)`` with
   ``a = M (A - C)`` and ``b = M B``. ``a`` and ``b`` are exact at the nodes of a lattice
   (every ``lattice_px`` cells) and bilinear between them: they vary with the Earth's curvature
   and the projection's scale, far below 1e-4 px over a lattice cell (tested). Collinearity
   ``x = -f q_x / q_z``, ``y = -f q_y / q_z`` is then exact per cell. A fisheye camera maps
   ``q`` by its own projection instead (``r = f g(theta)``, :mod:`core.geometry.projection`;
   vectorised numpy, the compiled loop being the perspective one's); a cell beyond its field
   (``theta`` past the projection's limit) has no pixel.
3. **Lens**: the camera's own model (any of the registry, :mod:`core.geometry.distortion`) maps
   ideal to measured coordinates by Newton iteration at the nodes of a lattice in the image
   (refined until bilinear interpolation is within 1e-3 px of Newton at the cell midpoints).
4. **Resampling**: ``cv2.remap`` (nearest, bilinear or bicubic) of the window of the image the
   tile needs (pixels follow docs/conventions.md: OpenCV's pixel centres are at integers,
   ours at half-integers). Cells outside the image, behind the camera, or without a height
   are no data.
5. **Visibility** (true orthophoto): the ray from the perspective centre to the ground point G
   is traced through the DSM (:func:`core.geometry.raycast.intersect_dsm`, the DDA and Dal Poz's
   face intersection of monoplotting); G is occluded when the first surface hit lies more than
   ``occlusion_tol_m`` before G. The ray is the chord from the centre to G in the mapping frame:
   it meets the true (ENU-straight) ray at G and departs from it by millimetres over the tens of
   metres where occluders stand. Rays are traced on a lattice of cells (spacing at most half a
   DSM cell) and per cell wherever neighbouring lattice rays disagree.

The output grid is processed in tiles (``tile_px`` square) by a pool of threads, so memory holds
a few tiles and the image windows they need, whatever the image size.
"""

from __future__ import annotations

import logging
import math
import os
import threading
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pyproj
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError, stop_if_asked
from ..geometry.camera import Camera
from ..geometry.frames import LocalFrame, MappingFrame, parse_crs
from ..geometry.grid import Grid
from ..geometry.raycast import STATUS_GRAZING, STATUS_OK, DsmTracer, intersect_dsm
from ..geometry.surface import Dsm
from .orientation import eo_map_to_local
from .ortho_options import RESAMPLING, OrthoOptions
from .orthophoto_cells import _lens_lattice, cell_pixels_numpy
from .orthophoto_numba import cell_stats, remap_maps, remap_maps_fixed, valid_bounds

LOG = logging.getLogger(__name__)

Array = NDArray[np.float64]
#: read_window((col0, row0, cols, rows), f) -> (bands, rows // f, cols // f) array of the
#: source image, each pixel the mean of f x f (f = 1: the pixels themselves)
ReadWindow = Callable[[tuple[int, int, int, int], int], NDArray]

_PAD = {"nearest": 1, "bilinear": 1, "cubic": 2}

__all__ = [
    "RESAMPLING",
    "OrthoOptions",
    "OrthoProjector",
    "OrthoTile",
    "auto_gsd",
    "cell_pixels_numpy",
    "ordered_map",
    "ortho_grid",
    "orthorectify_tiles",
]


@dataclass(frozen=True)
class OrthoTile:
    """One tile of an orthophoto: ``data`` (bands, rows, cols) in the image's type, zero where
    ``valid`` (rows, cols) is False; ``occluded`` counts the cells the visibility test removed
    and ``no_surface`` those without a height."""

    row0: int
    col0: int
    data: NDArray
    valid: NDArray[np.bool_]
    occluded: int = 0
    no_surface: int = 0


# --------------------------------------------------------------------------- the projector
@dataclass(frozen=True)
class OrthoProjector:
    """The ground -> image mapping of one oriented frame on a surface (build with :meth:`build`).

    Attributes
    ----------
    camera : Camera
    xyz : (3,) perspective centre, mapping CRS
    dsm : Dsm
        The surface, in the mapping CRS.
    tracer : DsmTracer or None
        For the visibility test (shared between the images of a block); built by
        :func:`orthorectify_tiles` when a true orthophoto needs it.
    z_range : (2,)
        Lowest and highest surface heights.
    local : LocalFrame
        The ENU frame the collinearity is evaluated in.
    centre_local : (3,)
        The perspective centre there.
    m_local : (3, 3)
        World-to-camera rotation there.
    """

    camera: Camera
    xyz: Array
    opk: Array
    dsm: Dsm
    tracer: DsmTracer | None
    local: LocalFrame
    centre_local: Array
    m_local: Array
    lens: tuple[Array, float, float, float]
    z_range: tuple[float, float] = (0.0, 0.0)
    # the lattice of a whole grid, made once for its tiles (_lattice)
    _lattices: dict = field(default_factory=dict, init=False, compare=False, repr=False)
    _lock: threading.Lock = field(
        default_factory=threading.Lock, init=False, compare=False, repr=False
    )

    @classmethod
    def build(
        cls,
        camera: Camera,
        xyz: ArrayLike,
        opk: ArrayLike,
        dsm: Dsm | DsmTracer,
        crs: str | int | pyproj.CRS,
        *,
        local: LocalFrame | None = None,
        lens: tuple[Array, float, float, float] | None = None,
    ) -> OrthoProjector:
        """Prepare one image.

        Parameters
        ----------
        camera : Camera
        xyz : (3,) array_like
            Perspective centre, mapping CRS.
        opk : (3,) array_like
            Omega, phi, kappa relative to the grid frame at the centre, radians.
        dsm : Dsm or DsmTracer
            The surface in the mapping CRS (resample it first: :func:`reproject_dsm`).
        crs : the mapping CRS.
        local : LocalFrame, optional
            The ENU frame (default: tangent at the DSM's centre, as monoplotting).
        lens : optional
            A lens lattice of the same camera (:func:`_lens_lattice`), to share between images.
        """
        tracer = dsm if isinstance(dsm, DsmTracer) else None
        surface = dsm.dsm if isinstance(dsm, DsmTracer) else dsm
        zr = (tracer.zmin, tracer.zmax) if tracer is not None else surface.z_range
        if local is None:
            mapping = MappingFrame(parse_crs(crs))
            g = surface.grid
            xc, yc = g.x0 + g.cols * g.cell / 2, g.y_top - g.rows * g.cell / 2
            local = LocalFrame.at_map_point(mapping, [xc, yc, zr[0]])
        centre = np.asarray(xyz, dtype=np.float64).reshape(3)
        angles = np.asarray(opk, dtype=np.float64).reshape(3)
        c_loc, m_loc = eo_map_to_local(centre[None], angles[None], local)
        return cls(
            camera,
            centre,
            angles,
            surface,
            tracer,
            local,
            c_loc[0],
            m_loc[0],
            lens if lens is not None else _lens_lattice(camera),
            (float(zr[0]), float(zr[1])),
        )

    # ------------------------------------------------------------------ geometry
    def _lattice(self, grid: Grid, row0: int, col0: int, h: int, w: int, step: int) -> Array:
        """``a`` and ``b`` (ny, nx, 6) at the nodes of a block (module docstring, step 2):
        the same nodes of the whole grid's lattice, made at the first tile, for a block of the
        grid that starts on a node (the tiles: one transformation instead of one per tile)."""
        ny = max(2, math.ceil((h - 1) / step) + 1)
        nx = max(2, math.ceil((w - 1) / step) + 1)
        if (
            row0 % step
            or col0 % step
            or row0 < 0
            or col0 < 0
            or row0 + h > grid.rows
            or col0 + w > grid.cols
        ):
            return self._nodes(grid, row0, col0, ny, nx, step)
        key = (grid, step)
        with self._lock:
            full = self._lattices.get(key)
            if full is None:
                full = self._nodes(
                    grid,
                    0,
                    0,
                    math.ceil((grid.rows - 1) / step) + 2,
                    math.ceil((grid.cols - 1) / step) + 2,
                    step,
                )
                self._lattices[key] = full
        k, m = row0 // step, col0 // step
        return full[k : k + ny, m : m + nx]

    def _nodes(self, grid: Grid, row0: int, col0: int, ny: int, nx: int, step: int) -> Array:
        """``a`` and ``b`` (ny, nx, 6) at nodes every ``step`` cells from cell (row0, col0)."""
        xs = grid.x0 + (col0 + np.arange(nx) * step + 0.5) * grid.cell
        ys = grid.y_top - (row0 + np.arange(ny) * step + 0.5) * grid.cell
        gx, gy = np.meshgrid(xs, ys)
        flat = np.column_stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)])
        a_enu = self.local.map_to_enu(flat)
        flat[:, 2] = 1.0
        b_enu = self.local.map_to_enu(flat) - a_enu
        m = self.m_local
        a = (a_enu - self.centre_local) @ m.T
        b = b_enu @ m.T
        return np.concatenate([a, b], axis=1).reshape(ny, nx, 6)

    def pixels(
        self,
        grid: Grid,
        row0: int,
        col0: int,
        rows: int,
        cols: int,
        *,
        lattice_px: int = 64,
        backend: str = "auto",
    ) -> tuple[Array, Array, Array]:
        """Image pixels of the cells ``[row0, row0 + rows) x [col0, col0 + cols)`` of ``grid``.

        ``backend`` ("auto", "numba", "numpy") chooses the perspective projection's loop; a
        fisheye camera always takes the vectorised numpy one.

        Returns
        -------
        col, row : (rows, cols) float64
            Measured pixel (col, row) of each cell centre (docs/conventions.md), NaN where the
            cell has no height, lies behind the camera (beyond a fisheye's field) or off the
            image.
        z : (rows, cols) float64
            Surface height at the cell centre (NaN: none).
        """
        from .orthophoto_numba import AVAILABLE, cell_pixels

        step = max(2, int(lattice_px))
        lat = self._lattice(grid, row0, col0, rows, cols, step)
        cam = self.camera
        lens, lx0, ly0, ls = self.lens
        pp = cam.principal_point_px
        nolens = np.array([pp[0], cam.pixel_size_mm, pp[1], cam.width_px, cam.height_px], float)
        dsm = self.dsm
        xc, yc = dsm.centre_origin
        z = np.ascontiguousarray(dsm.heights, dtype=np.float32)
        args = (
            grid.x0 + (col0 + 0.5) * grid.cell,
            grid.y_top - (row0 + 0.5) * grid.cell,
            grid.cell,
            int(rows),
            int(cols),
            z,
            float(xc),
            float(yc),
            1.0 / dsm.cell,
            np.ascontiguousarray(lat),
            float(step),
            float(cam.focal_mm),
            np.ascontiguousarray(lens, dtype=np.float64),
            lx0,
            ly0,
            1.0 / ls,
            nolens,
        )
        if backend not in ("auto", "numba", "numpy"):
            raise ValueError(f"backend must be 'auto', 'numba' or 'numpy', got {backend!r}")
        if backend == "numpy" or not AVAILABLE or not cam.is_perspective:
            if backend == "numba" and not AVAILABLE:
                raise InputError("backend 'numba' asked for, but numba is not installed")
            # a fisheye camera: the vectorised numpy version (the compiled loop is the
            # perspective projection's)
            return cell_pixels_numpy(*args, projection=cam.projection)
        out = [np.empty((rows, cols)) for _ in range(3)]
        cell_pixels(*args, *out)
        return out[0], out[1], out[2]

    def visible(self, x: Array, y: Array, z: Array, tol: float) -> NDArray[np.bool_]:
        """(N,) False where the ground point (x, y, z) is hidden from the camera by the
        surface: the first hit of the chord from the centre lies more than ``tol`` before it."""
        g = np.column_stack([x, y, z])
        d = g - self.xyz
        if g.shape[0] == 0:
            return np.ones(0, bool)
        if self.tracer is None:
            raise ValueError(
                "no DsmTracer: build the projector with one (or through "
                "orthorectify_tiles) for the visibility test"
            )
        hits = intersect_dsm(
            self.tracer,
            np.broadcast_to(self.xyz, g.shape),
            d,
            min_incidence_deg=0.0,
            chunk_size=max(g.shape[0], 1),
        )
        dist = np.linalg.norm(d, axis=1)
        hit = np.isin(hits.status, (STATUS_OK, STATUS_GRAZING))
        with np.errstate(invalid="ignore"):
            occluded = hit & (hits.t < 1.0 - tol / np.maximum(dist, 1e-9))
        return ~occluded

    def ground_points(self, pixels: ArrayLike, z: float) -> Array:
        """(N, 2) x, y where the rays of image pixels (N, 2) (col, row) meet the height ``z``
        (mapping CRS; the level surface of the local frame at the DSM's centre); NaN for rays
        that do not descend."""
        cam = self.camera
        ideal = cam.ideal_from_pixel(np.asarray(pixels, float).reshape(-1, 2))
        d = cam.ray_from_ideal(ideal) @ self.m_local
        g = self.dsm.grid
        mid = np.array([[g.x0 + g.cols * g.cell / 2, g.y_top - g.rows * g.cell / 2, z]])
        up = self.local.map_to_enu(mid)[0, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            s = np.where(d[:, 2] < 0, (up - self.centre_local[2]) / d[:, 2], np.nan)
        return self.local.enu_to_map(self.centre_local + s[:, None] * d)[:, :2]

    def footprint(
        self, samples: int = 64, *, clip: bool = True
    ) -> tuple[float, float, float, float] | None:
        """(xmin, ymin, xmax, ymax) of the image's ground coverage between the surface's lowest
        and highest heights, clipped to the surface (unless ``clip`` is False); None when they
        do not overlap."""
        cam, dsm = self.camera, self.dsm
        border = cam.border_pixels(samples)
        ideal = cam.ideal_from_pixel(border)
        ray_c = cam.ray_from_ideal(ideal)  # NaN beyond a fisheye's field: the whole surface
        d = ray_c @ self.m_local  # M^T r: camera -> local ENU
        gx0, gy0 = dsm.centre_origin
        gx1 = gx0 + (dsm.grid.cols - 1) * dsm.cell
        gy1 = gy0 - (dsm.grid.rows - 1) * dsm.cell
        surf = (min(gx0, gx1), min(gy0, gy1), max(gx0, gx1), max(gy0, gy1))
        if not (d[:, 2] < -1e-9).all():  # the view reaches the horizon: the whole surface
            return surf if clip else (-np.inf, -np.inf, np.inf, np.inf)
        pts = []
        for zz in self.z_range:
            mid = np.array([[(surf[0] + surf[2]) / 2, (surf[1] + surf[3]) / 2, zz]])
            up = self.local.map_to_enu(mid)[0, 2]
            s = (up - self.centre_local[2]) / d[:, 2]
            pts.append(self.local.enu_to_map(self.centre_local + s[:, None] * d))
        p = np.vstack(pts)
        lo, hi = p[:, :2].min(axis=0), p[:, :2].max(axis=0)
        margin = 0.02 * (hi - lo)  # Earth curvature between the ENU planes and true heights
        lo, hi = lo - margin, hi + margin
        if not clip:
            return float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])
        box = (max(lo[0], surf[0]), max(lo[1], surf[1]), min(hi[0], surf[2]), min(hi[1], surf[3]))
        return box if box[0] < box[2] and box[1] < box[3] else None


def auto_gsd(camera: Camera, centre_z: float, ground_z: float) -> float:
    """The image's nadir ground sampling distance, to 2 significant digits.

    >>> from lidarphoto.core.geometry.camera import Camera
    >>> auto_gsd(Camera("c", 35.0, 0.0045, 6000, 4000), 130.0, 0.0)
    0.017
    """
    height = float(centre_z) - float(ground_z)
    if not height > 0:
        raise InputError("the camera is not above the surface: give the GSD")
    gsd = height * camera.pixel_size_mm / camera.focal_mm
    digits = 1 - math.floor(math.log10(gsd))
    return round(gsd, digits)


def ortho_grid(box: Sequence[float], gsd: float) -> Grid:
    """The grid of ``gsd`` cells aligned on multiples of ``gsd`` covering (xmin, ymin, xmax,
    ymax): orthophotos of one block then share their cell edges (mosaics need no resampling).

    >>> g = ortho_grid((10.05, 20.0, 12.0, 21.0), 0.5)
    >>> (g.x0, g.y_top, g.rows, g.cols)
    (10.0, 21.5, 4, 5)
    """
    if not gsd > 0:
        raise InputError(f"GSD must be > 0, got {gsd!r}")
    return Grid.covering((box[0], box[1]), (box[2], box[3]), float(gsd))


# --------------------------------------------------------------------------- the tiles
def _occlusion(
    proj: OrthoProjector,
    grid: Grid,
    row0: int,
    col0: int,
    z: Array,
    valid: NDArray[np.bool_],
    tol: float,
) -> NDArray[np.bool_]:
    """(rows, cols) True where a valid cell is occluded (module docstring, step 5): rays on a
    lattice of spacing s (at most half a DSM cell, at most 8 cells); the cells of a lattice
    square whose four corners agree take their value, the others get their own ray."""
    h, w = z.shape
    s = int(max(1, min(8, math.floor(proj.dsm.cell / (2 * grid.cell)))))
    # float64 already: asarray makes no copy
    ys = np.asarray(grid.y_top - (row0 + np.arange(h) + 0.5) * grid.cell, dtype=np.float64)
    xs = np.asarray(grid.x0 + (col0 + np.arange(w) + 0.5) * grid.cell, dtype=np.float64)
    occ = np.zeros((h, w), bool)
    if s == 1 or h < 2 or w < 2:
        r, c = np.nonzero(valid)
        occ[r, c] = ~proj.visible(xs[c], ys[r], z[r, c], tol)
        return occ
    rs = np.unique(np.r_[np.arange(0, h, s), h - 1])
    cs = np.unique(np.r_[np.arange(0, w, s), w - 1])
    sub_valid = valid[np.ix_(rs, cs)]
    coarse = np.zeros(sub_valid.shape, np.int8)  # 0 no data, 1 visible, 2 occluded
    rr, cc = np.nonzero(sub_valid)
    vis = proj.visible(xs[cs[cc]], ys[rs[rr]], z[rs[rr], cs[cc]], tol)
    coarse[rr, cc] = np.where(vis, 1, 2)
    # squares whose 4 corners all have data and agree: every cell takes the corners' value
    a, b, c_, d = coarse[:-1, :-1], coarse[:-1, 1:], coarse[1:, :-1], coarse[1:, 1:]
    same = (a == b) & (a == c_) & (a == d) & (a > 0)
    # expand square -> cells (cell row i belongs to the square k with rs[k] <= i < rs[k+1])
    ki = np.clip(np.searchsorted(rs, np.arange(h), side="right") - 1, 0, len(rs) - 2)
    kj = np.clip(np.searchsorted(cs, np.arange(w), side="right") - 1, 0, len(cs) - 2)
    sq_same = same[np.ix_(ki, kj)]
    sq_occ = (a == 2)[np.ix_(ki, kj)]
    occ[sq_same] = sq_occ[sq_same]
    todo = valid & ~sq_same
    # the lattice cells themselves are known
    lat_known = np.zeros((h, w), bool)
    lat_known[np.ix_(rs, cs)] = sub_valid
    occ[np.ix_(rs, cs)] = np.where(sub_valid, coarse == 2, occ[np.ix_(rs, cs)])
    todo &= ~lat_known
    r, c = np.nonzero(todo)
    if r.size:
        occ[r, c] = ~proj.visible(xs[c], ys[r], z[r, c], tol)
    return occ & valid


def _decimation(proj: OrthoProjector, grid: Grid, lattice_px: int) -> int:
    """Whole image pixels per cell over the orthophoto: the 5th percentile, over a 64 x 64
    sample of the grid, of the larger step of the image position from one cell to the next;
    1 when below 2. One value per orthophoto, so that no tile border shows a change."""
    s = max(1, min(grid.rows, grid.cols) // 64)
    coarse = Grid(grid.x0, grid.y_top, grid.cell * s, -(-grid.rows // s), -(-grid.cols // s))
    col, row, _ = proj.pixels(coarse, 0, 0, coarse.rows, coarse.cols, lattice_px=lattice_px)
    with np.errstate(invalid="ignore"):
        dc = np.hypot(np.diff(col, axis=1), np.diff(row, axis=1))
        dr = np.hypot(np.diff(col, axis=0), np.diff(row, axis=0))
    steps = np.r_[dc[np.isfinite(dc)], dr[np.isfinite(dr)]] / s
    if steps.size == 0:
        return 1
    return max(1, math.floor(float(np.percentile(steps, 5))))


def _remap(src: NDArray, mapx: NDArray, mapy: NDArray, resampling: str) -> NDArray:
    """(bands, rows, cols) of the source sampled at the maps (OpenCV pixel-centre convention:
    float32 maps, or the fixed-point pair of :func:`remap_maps_fixed`)."""
    import cv2

    interp = {"nearest": cv2.INTER_NEAREST, "bilinear": cv2.INTER_LINEAR, "cubic": cv2.INTER_CUBIC}[
        resampling
    ]
    kind = src.dtype
    work = (
        src
        if kind in (np.uint8, np.uint16, np.int16, np.float32, np.float64)
        else (src.astype(np.float64))
    )
    bands = work.shape[0]
    out = []
    for b0 in range(0, bands, 4):  # OpenCV remaps up to 4 interleaved channels at once
        chunk = np.ascontiguousarray(np.moveaxis(work[b0 : b0 + 4], 0, -1))
        res = cv2.remap(chunk, mapx, mapy, interp, borderMode=cv2.BORDER_REPLICATE)
        out.append(res.reshape(*res.shape[:2], -1))
    merged = np.concatenate(out, axis=2) if len(out) > 1 else out[0]
    res = np.moveaxis(merged, -1, 0)
    if kind.kind in "ui" and res.dtype != kind:  # cubic may overshoot: clip to the type
        info = np.iinfo(kind)
        res = np.clip(np.rint(res), info.min, info.max)
    return res.astype(kind, copy=False)


def _tile(
    proj: OrthoProjector,
    grid: Grid,
    row0: int,
    col0: int,
    rows: int,
    cols: int,
    read_window: ReadWindow,
    bands: int,
    dtype: np.dtype,
    opt: OrthoOptions,
    f: int = 1,
) -> OrthoTile:
    col, row, z = proj.pixels(grid, row0, col0, rows, cols, lattice_px=opt.lattice_px)
    valid, n, no_surface, c_min, c_max, r_min, r_max = cell_stats(col, row, z)
    occluded = 0
    if opt.true_ortho and n:
        occ = _occlusion(proj, grid, row0, col0, z, valid, opt.occlusion_tol_m)
        occluded = int(np.count_nonzero(occ))
        valid &= ~occ
        col = np.where(valid, col, np.nan)
        n, c_min, c_max, r_min, r_max = valid_bounds(col, row)
    if n == 0:
        return OrthoTile(
            row0, col0, np.zeros((bands, rows, cols), dtype), valid, occluded, no_surface
        )
    pad = _PAD[opt.resampling]
    cam = proj.camera
    c_lo = max(math.floor(c_min - 0.5) - pad * f, 0)
    r_lo = max(math.floor(r_min - 0.5) - pad * f, 0)
    c_hi = min(math.ceil(c_max - 0.5) + (pad + 1) * f, cam.width_px)
    r_hi = min(math.ceil(r_max - 0.5) + (pad + 1) * f, cam.height_px)
    if f > 1:  # sides that are multiples of f
        c_hi = c_lo + (c_hi - c_lo) // f * f
        r_hi = r_lo + (r_hi - r_lo) // f * f
        if c_hi - c_lo < f or r_hi - r_lo < f:
            f, c_hi, r_hi = 1, min(c_hi + f, cam.width_px), min(r_hi + f, cam.height_px)
    src = read_window((c_lo, r_lo, c_hi - c_lo, r_hi - r_lo), f)
    if f > 1:  # decimated pixel k covers [c_lo + k f, c_lo + (k + 1) f): its centre
        col = c_lo + (col - c_lo) / f
        row = r_lo + (row - r_lo) / f
    # bilinear and cubic: OpenCV's fixed-point maps made here in one pass (cv2.remap would
    # convert float maps to them itself: the same pixels, tested)
    maps = remap_maps_fixed if opt.resampling != "nearest" else remap_maps
    mapx, mapy = maps(col, row, c_lo, r_lo)
    out = _remap(src, mapx, mapy, opt.resampling)
    np.moveaxis(out, 0, -1)[~valid] = 0  # OpenCV's (rows, cols, bands) layout underneath
    return OrthoTile(row0, col0, out, valid, occluded, no_surface)


def orthorectify_tiles(
    projector: OrthoProjector,
    grid: Grid,
    read_window: ReadWindow,
    bands: int,
    dtype: np.dtype | type,
    options: OrthoOptions | None = None,
    *,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> Iterator[OrthoTile]:
    """The orthophoto of one image on ``grid``, tile after tile (row-major), as they are done.

    Parameters
    ----------
    projector : OrthoProjector
    grid : Grid
        The output grid (mapping CRS; :func:`ortho_grid`).
    read_window : callable
        ``read_window((col0, row0, cols, rows), f)`` -> (bands, rows // f, cols // f) array
        of the source image (pixels of the camera; each the mean of f x f pixels); called from
        several threads.
    bands, dtype
        Of the source image (and of the tiles).
    options : OrthoOptions
    progress, should_stop
        Fraction of tiles done; cancellation (checked per tile: raises Cancelled).
    """
    opt = options or OrthoOptions()
    windows = tile_windows(grid, opt.tile_px)
    kind = np.dtype(dtype)
    if opt.true_ortho and projector.tracer is None:
        from dataclasses import replace

        projector = replace(projector, tracer=DsmTracer.build(projector.dsm))
    # image pixels per cell: when the cells are 2 or more pixels wide, the image is read
    # averaged over f x f pixels (anti-aliasing; an overview level when the file has one)
    f = _decimation(projector, grid, opt.lattice_px) if opt.antialias else 1

    def one(win: tuple[int, int, int, int]) -> OrthoTile:
        return _tile(projector, grid, *win, read_window, bands, kind, opt, f)

    yield from ordered_map(one, windows, opt.workers, progress, should_stop, "orthorectifying")


def tile_windows(grid: Grid, size: int) -> list[tuple[int, int, int, int]]:
    """The (row0, col0, rows, cols) tiles of at most ``size`` cells that cover ``grid``,
    row-major (the last row and column of tiles cut at the grid's edge).

    >>> tile_windows(Grid(0.0, 0.0, 1.0, 3, 5), 2)
    [(0, 0, 2, 2), (0, 2, 2, 2), (0, 4, 2, 1), (2, 0, 1, 2), (2, 2, 1, 2), (2, 4, 1, 1)]
    """
    size = int(size)
    return [
        (r0, c0, min(size, grid.rows - r0), min(size, grid.cols - c0))
        for r0 in range(0, grid.rows, size)
        for c0 in range(0, grid.cols, size)
    ]


def ordered_map(
    func: Callable[[Any], Any],
    items: Sequence[Any],
    workers: int = 0,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
    doing: str = "working",
    ahead: int = 8,
) -> Iterator[Any]:
    """``func`` of each item, computed by a pool of threads, yielded in the items' order.

    At most ``ahead * workers`` items are submitted and not yet handed over, so memory stays
    bounded when the consumer is slower. The default lets the workers go on while the
    consumer works in bursts (a writer that grows overview level 1 a row of tiles at a
    time: with 2 per worker an orthophoto took 6-8 % more wall time). OpenCV's own threads
    are set to 1 meanwhile (the pool already fills the CPUs).
    ``should_stop`` is checked before each result is handed over (Cancelled).
    """
    import cv2

    n_workers = int(workers) or max(1, min(4, os.cpu_count() or 1))
    cv_threads = cv2.getNumThreads()
    cv2.setNumThreads(1)
    done = 0
    try:
        with ThreadPoolExecutor(max_workers=n_workers) as pool:
            pending: deque = deque()
            try:
                for item in items:
                    pending.append(pool.submit(func, item))
                    if len(pending) < ahead * n_workers:
                        continue
                    stop_if_asked(should_stop, doing)
                    yield pending.popleft().result()
                    done += 1
                    if progress is not None:
                        progress(done / len(items))
                while pending:
                    stop_if_asked(should_stop, doing)
                    yield pending.popleft().result()
                    done += 1
                    if progress is not None:
                        progress(done / len(items))
            finally:
                for f in pending:
                    f.cancel()
    finally:
        cv2.setNumThreads(cv_threads)
