"""Synthetic aerial images: ray casting through a frame camera onto a LiDAR DSM and roof planes.

Each image is rendered from its camera (lens model included) and its exterior orientation in
the mapping CRS, with the ray construction of :func:`core.photo.monoplot.monoplot`: rays are
built in a local ENU frame tangent at the DSM's centre and intersected with the surface along
their chord in the mapping frame (:func:`core.geometry.raycast.chord_rays`), so that a pixel shows
the object point that the project's collinearity chain projects onto it.

Surfaces, from coarse to fine:

1. **DSM** (:class:`core.geometry.surface.Dsm`, traced by
   :func:`core.geometry.raycast.intersect_dsm`): one ray per ``step_px`` x ``step_px`` block
   of pixels (the block centre). Each hit is shaded with Lambert's law on the DSM face normal
   and an albedo by LAS class (the class of the highest point of the DSM cell: ground
   grey-green, vegetation green, building grey, water blue). Rays that leave the DSM show a
   dark "sky".
2. **Roof planes** (:class:`core.geometry.planes.Plane`): each plane owns a region in x, y (a
   raster of ``region_cell``: every cell takes the plane of its nearest LiDAR point, when that point
   belongs to a plane; so the eaves lie halfway between the last roof point and the first
   point off the roof). Where the DSM hit falls in a plane's region, the ray is intersected
   with the plane itself and the plane's tint is shaded with its exact normal.
3. **Edges between planes**: near a change of label (a ``window_px`` neighbourhood of coarse
   pixels), the candidate planes of the neighbourhood are intersected exactly, per pixel at
   full resolution. A candidate is kept when its hit lies in its own region, or, within
   ``line_band_m`` of a LiDAR line it shares with another plane, in that plane's region and on
   its own visible side of the line: below the other plane for a convex edge (ridge, hip:
   each face below the other's extension on its side of the line, the sides read from the
   regions beside the line), above it for a concave one (valley). The nearest kept hit wins.
   Rendered ridges and valleys are therefore the projections of the planes' intersection
   lines, i.e. of the LiDAR lines (:mod:`core.lidar.control`), to a fraction of a pixel; the
   eaves follow the plane regions (raster ``region_cell``).

A DSM hit more than ``occlusion_tol_m`` in front of a plane's hit, on a point that belongs to
no plane (a chimney, a tree over the roof), hides the plane. The rest of the image is the DSM
rendering upsampled bilinearly (OpenCV) from the coarse grid. Mild Gaussian luminance noise
is added.

The ray directions of the coarse grid and of the edge pixels are interpolated bilinearly from
exact chord directions on a lattice of ``direction_grid_px`` (the direction field of a frame
camera is smooth: 16 px give < 1e-6 rad, checked by the tests), which keeps the number of
mapping-CRS transformations per image small. A fisheye camera (its projection's own rays,
:meth:`core.geometry.camera.Camera.ray_from_ideal`) bends faster: 2 px keep the interpolated
rays within 0.003 px of the exact ones where they meet the scene (16 px: 0.04-0.14 px); a
pixel beyond its field (or within one lattice step of it) shows the sky.

Output: 8-bit RGB. The images exist to be measured by eye in the picking dock and to show
faces apart; 8 bits hold the shading and the noise without loss and keep a 24-Mpx image near
16 MB with LZW (16 bits would double the files and need a contrast stretch to be seen).
"""

from __future__ import annotations

import logging
import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Union

import numpy as np
import pyproj
from numpy.typing import ArrayLike, NDArray

from ..errors import CrsError, InputError, stop_if_asked
from ..geometry.camera import Camera
from ..geometry.frames import LocalFrame, MappingFrame
from ..geometry.raycast import chord_rays, intersect_dsm
from ..io.raster_write import write_rgb_tiff
from ..photo.orientation import ExteriorOrientationTable, eo_map_to_local
from .render_scene import (
    NO_PLANE,
    PLANE_TINTS,
    SKY_RGB,
    RenderOptions,
    RenderScene,
    lambert,
    sun_vector,
)

LOG = logging.getLogger(__name__)

Array = NDArray[np.float64]
PathLike = Union[str, "os.PathLike[str]"]

__all__ = [
    "RenderedImage",
    "edge_offsets",
    "render_image",
    "render_images",
]


# --------------------------------------------------------------------------- rays
@dataclass(frozen=True)
class _Rays:
    """Exact chord directions (mapping frame) on a pixel lattice, interpolated bilinearly."""

    origin: Array  # (3,) perspective centre, mapping CRS
    field: Array  # (ny, nx, 3) unit directions at pixels (j g, i g)
    spacing: float

    @classmethod
    def build(cls, scene: RenderScene, camera: Camera, xyz: Array, opk: Array, spacing: int):
        dsm = scene.dsm
        mapping = MappingFrame(scene.crs)
        zmin = scene.tracer.zmin
        xc = dsm.grid.x0 + dsm.grid.cols * dsm.cell / 2
        yc = dsm.grid.y_top - dsm.grid.rows * dsm.cell / 2
        # the frame and the far point of the chord as in core.photo.monoplot.monoplot
        local = LocalFrame.at_map_point(mapping, [xc, yc, zmin])
        c_loc, m_loc = eo_map_to_local(xyz[None], opk[None], local)
        nx = math.ceil(camera.width_px / spacing) + 1
        ny = math.ceil(camera.height_px / spacing) + 1
        jj, ii = np.meshgrid(np.arange(nx) * float(spacing), np.arange(ny) * float(spacing))
        pix = np.column_stack([jj.ravel(), ii.ravel()])
        ideal = camera.ideal_from_pixel(pix)
        ray_c = camera.ray_from_ideal(ideal)  # perspective or fisheye (NaN: beyond its field)
        d_loc = ray_c @ m_loc[0]  # M^T r for every row: camera -> local ENU
        d_loc /= np.linalg.norm(d_loc, axis=1, keepdims=True)
        z_low = local.map_to_enu(np.array([[xc, yc, zmin - 10.0]]))[0, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            s_far = np.where(d_loc[:, 2] < -1e-6, (c_loc[0, 2] - z_low) / -d_loc[:, 2], 1e3)
        s_far = np.maximum(s_far, 1.0)
        n = len(pix)
        dirs = chord_rays(local, np.repeat(xyz[None], n, 0), np.repeat(c_loc, n, 0), d_loc, s_far)
        return cls(np.asarray(xyz, dtype=np.float64), dirs.reshape(ny, nx, 3), float(spacing))

    def at(self, cols: Array, rows: Array) -> Array:
        """Unit directions (N, 3) at pixel positions (col, row), pixels."""
        ny, nx, _ = self.field.shape
        u, v = np.asarray(cols, float) / self.spacing, np.asarray(rows, float) / self.spacing
        j = np.clip(np.floor(u), 0, nx - 2).astype(np.int64)
        i = np.clip(np.floor(v), 0, ny - 2).astype(np.int64)
        fu, fv = (u - j)[:, None], (v - i)[:, None]
        f = self.field
        d = (f[i, j] * (1 - fu) + f[i, j + 1] * fu) * (1 - fv) + (
            f[i + 1, j] * (1 - fu) + f[i + 1, j + 1] * fu
        ) * fv
        return d / np.linalg.norm(d, axis=1, keepdims=True)

    def on_grid(self, cols: Array, rows: Array) -> Array:
        """Unit directions (len(rows) * len(cols), 3) on the grid ``rows x cols`` (row-major):
        the same bilinear interpolation as :meth:`at`, done one axis at a time."""
        ny, nx, _ = self.field.shape

        def axis(pos: Array, size: int) -> tuple[NDArray[np.int64], Array]:
            x = np.asarray(pos, float) / self.spacing
            k = np.clip(np.floor(x), 0, size - 2).astype(np.int64)
            return k, (x - k)[:, None]

        j, fu = axis(cols, nx)
        i, fv = axis(rows, ny)
        f = self.field
        by_col = f[:, j] * (1 - fu) + f[:, j + 1] * fu  # (ny, W, 3)
        d = by_col[i] * (1 - fv)[:, :, None] + by_col[i + 1] * fv[:, :, None]
        d = d.reshape(-1, 3)
        return d / np.linalg.norm(d, axis=1, keepdims=True)


def _near_line(scene: RenderScene, xy: Array, line: NDArray[np.int32], band: float) -> NDArray:
    """True where the point xy (N, 2) lies within ``band`` (x, y) of the LiDAR line ``line``
    (N,) (index into the scene's segments, >= 0)."""
    a, b = scene.segments[line, 0], scene.segments[line, 1]
    ab = b - a
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.clip(np.einsum("nj,nj->n", xy - a, ab) / np.einsum("nj,nj->n", ab, ab), 0.0, 1.0)
    gap = xy - (a + np.nan_to_num(t)[:, None] * ab)
    return np.einsum("nj,nj->n", gap, gap) <= band * band


def _resolve(
    scene: RenderScene,
    origin: Array,
    dirs: Array,
    cands: NDArray[np.int32],
    t_dsm: Array,
    lab_dsm: NDArray[np.int32],
    occlusion_tol: float,
    band: float,
) -> NDArray[np.int32]:
    """Visible plane (index, or -1) of each ray among its candidate planes (module docstring).

    ``cands`` (N, C) plane indices (-1: empty slot); ``t_dsm`` (N,) distance of the DSM hit
    (NaN: none) and ``lab_dsm`` (N,) plane region at it. Within ``band`` of a LiDAR line the
    edge rule of its two planes overrides the region raster.
    """
    n, c = cands.shape
    nrm, cen = scene.normals, scene.centroids
    # n . (o - c) per plane: the same origin for every ray of the image
    q = np.einsum("pj,pj->p", nrm, origin[None, :] - cen)
    idx = np.maximum(cands, 0)
    t = np.full((n, c), np.inf)
    hits = np.empty((c, n, 3))
    labs = np.empty((n, c), dtype=np.int32)
    for s in range(c):
        den = np.einsum("nj,nj->n", dirs, nrm[idx[:, s]])
        with np.errstate(divide="ignore", invalid="ignore"):
            ts = -q[idx[:, s]] / den
        ok = (cands[:, s] >= 0) & np.isfinite(ts) & (ts > 0)
        t[:, s] = np.where(ok, ts, np.inf)
        hits[s] = origin + np.where(ok, ts, 0.0)[:, None] * dirs
        labs[:, s] = np.where(ok, scene.regions.at(hits[s, :, 0], hits[s, :, 1]), NO_PLANE)
    for s in range(c):
        a = cands[:, s]
        lab = labs[:, s]
        valid = np.isfinite(t[:, s]) & (lab == a)
        # or in the region of a plane it shares a LiDAR line with, near that line
        line = scene.line_of[idx[:, s], np.maximum(lab, 0)]
        k = np.flatnonzero(np.isfinite(t[:, s]) & (lab >= 0) & (lab != a) & (line >= 0))
        valid[k] = _near_line(scene, hits[s, k, :2], line[k], band)
        for r in range(c):
            if r == s:
                continue
            b = cands[:, r]
            line = scene.line_of[idx[:, s], np.maximum(b, 0)]
            k = np.flatnonzero(valid & (b >= 0) & (b != a) & (line >= 0))
            if k.size == 0:
                continue
            k = k[_near_line(scene, hits[s, k, :2], line[k], band)]
            kind = scene.edge[idx[k, s], b[k]]
            above = np.einsum("nj,nj->n", hits[s, k] - cen[b[k]], nrm[b[k]])
            # convex edge: the visible face lies below the other plane; concave: above it
            valid[k[((kind > 0) & (above > 1e-6)) | ((kind < 0) & (above < -1e-6))]] = False
        hidden = (lab_dsm < 0) & np.isfinite(t_dsm) & (t_dsm < t[:, s] - occlusion_tol)
        t[:, s] = np.where(valid & ~hidden, t[:, s], np.inf)
    best = np.argmin(t, axis=1)
    rows = np.arange(n)
    return np.where(np.isfinite(t[rows, best]), cands[rows, best], NO_PLANE).astype(np.int32)


def _window_candidates(labels: NDArray[np.int32], size: int, slots: int = 4) -> NDArray[np.int32]:
    """(h, w, m) distinct planes found in the ``size`` x ``size`` neighbourhood of each pixel,
    its own label first (empty slots and non-planes: -1; m <= ``slots``, and beyond ``slots``
    planes the last ones found are dropped)."""
    import cv2
    from scipy.ndimage import find_objects

    h, w = labels.shape
    out = np.full((h, w, slots), NO_PLANE, dtype=np.int32)
    out[:, :, 0] = labels
    count = (labels >= 0).astype(np.int32)
    kernel = np.ones((size, size), np.uint8)
    r = size // 2
    for p, box in enumerate(find_objects(labels + 1)):
        if box is None:
            continue
        r0, r1 = max(box[0].start - r, 0), min(box[0].stop + r, h)
        c0, c1 = max(box[1].start - r, 0), min(box[1].stop + r, w)
        win = labels[r0:r1, c0:c1]
        near = cv2.dilate((win == p).astype(np.uint8), kernel) > 0
        near &= (win != p) & (count[r0:r1, c0:c1] < slots)
        rr, cc = np.nonzero(near)
        rr += r0
        cc += c0
        out[rr, cc, count[rr, cc]] = p
        count[rr, cc] += 1
    return out[:, :, : max(1, int(count.max()))]


# --------------------------------------------------------------------------- rendering
@dataclass(frozen=True)
class RenderedImage:
    """A rendered frame.

    Attributes
    ----------
    rgb : (H, W, 3) uint8
        Red, green, blue.
    plane_id : (H, W) int32
        Id of the roof plane each pixel shows, -1 for the rest.
    coarse_rays, edge_pixels : int
        DSM rays cast, and pixels whose plane was decided at full resolution.
    seconds : float
        Wall time of the rendering.
    """

    rgb: NDArray[np.uint8]
    plane_id: NDArray[np.int32]
    coarse_rays: int
    edge_pixels: int
    seconds: float


def _paint_planes(
    base: NDArray, label: NDArray, scene: RenderScene, sun: Array, ambient: float
) -> None:
    """The pixels of ``base`` (H, W, 3) whose ``label`` is a plane painted with its tint,
    shaded by the sun (in place)."""
    shade = lambert(scene.normals, sun, ambient)
    tint = np.array(PLANE_TINTS)[scene.tint]
    plane_rgb = np.clip(np.rint(255.0 * tint * shade[:, None]), 0, 255).astype(np.uint8)
    on = label >= 0
    base[on] = plane_rgb[label[on]]


def _with_noise(base: NDArray, opt: RenderOptions) -> NDArray:
    """``base`` with luminance noise of ``opt.noise_dn`` (DN, seeded by ``opt.seed``): the same
    on the three channels, as after demosaicing; also keeps a 24-Mpx LZW TIFF near 16 MB
    instead of 30 MB with independent channels."""
    import cv2

    noise = np.empty(base.shape[:2], np.int16)
    cv2.setRNGSeed(int(opt.seed))
    # OpenCV's stubs want arrays for the mean and deviation; it takes numbers
    cv2.randn(noise, 0.0, float(opt.noise_dn))  # type: ignore[call-overload]
    return cv2.add(base, cv2.merge([noise, noise, noise]), dtype=cv2.CV_8U)


def render_image(
    scene: RenderScene,
    camera: Camera,
    xyz: ArrayLike,
    opk: ArrayLike,
    options: RenderOptions | None = None,
    *,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> RenderedImage:
    """Render one frame (module docstring).

    Parameters
    ----------
    scene : RenderScene
    camera : Camera
        Interior orientation (lens model applied); the image has its size.
    xyz : (3,) array_like
        Perspective centre, mapping CRS (the scene's).
    opk : (3,) array_like
        Omega, phi, kappa relative to the grid frame at the centre, radians (as in the EO CSV).
    options : RenderOptions, optional
    progress, should_stop
        Fraction done; cancellation (raises :class:`core.errors.Cancelled`).

    Returns
    -------
    RenderedImage
    """
    import time

    import cv2

    t0 = time.perf_counter()
    opt = options or RenderOptions()
    k = int(opt.step_px)
    width, height = camera.width_px, camera.height_px
    origin = np.asarray(xyz, dtype=np.float64).reshape(3)
    angles = np.asarray(opk, dtype=np.float64).reshape(3)
    rays = _Rays.build(scene, camera, origin, angles, int(opt.direction_grid_px))
    stop_if_asked(should_stop, "rendering")

    # ---- coarse: one DSM ray per k x k block, at the block centre
    w, h = -(-width // k), -(-height // k)
    dirs = rays.on_grid((np.arange(w) + 0.5) * k, (np.arange(h) + 0.5) * k)
    n = dirs.shape[0]
    sub = None if progress is None else (lambda f: progress(0.6 * f))
    hits = intersect_dsm(
        scene.tracer,
        np.broadcast_to(origin, (n, 3)),
        dirs,
        min_incidence_deg=0.0,
        progress=sub,
        should_stop=should_stop,
    )
    hit = np.isin(hits.status, (0, 1))
    px, py = hits.points[:, 0], hits.points[:, 1]
    sun = sun_vector(opt.sun_azimuth_deg, opt.sun_elevation_deg)
    grad = np.nan_to_num(hits.gradient)
    face = np.column_stack([-grad, np.ones(n)])
    face /= np.linalg.norm(face, axis=1, keepdims=True)
    rgb = scene.albedo_at(px, py) * (255.0 * lambert(face, sun, opt.ambient))[:, None]
    rgb[~hit] = SKY_RGB
    rgb_c = np.clip(np.rint(rgb), 0, 255).astype(np.uint8).reshape(h, w, 3)
    t_dsm = np.where(hit, hits.t, np.nan)
    lab_dsm = np.where(hit, scene.regions.at(px, py), NO_PLANE).astype(np.int32)
    del rgb, face, grad
    stop_if_asked(should_stop, "rendering")

    # ---- coarse plane labels: the plane under the DSM hit and its neighbours, exactly
    n_planes = len(scene.plane_ids)
    label_c = np.full(n, NO_PLANE, dtype=np.int32)
    if n_planes:
        cand = _window_candidates(lab_dsm.reshape(h, w), int(opt.window_px)).reshape(n, -1)
        # a single candidate that owns the DSM hit: well inside a region, no decision to make
        many = (cand[:, 1:] >= 0).any(axis=1) if cand.shape[1] > 1 else np.zeros(n, bool)
        label_c[:] = np.where(~many, cand[:, 0], NO_PLANE)
        todo = np.flatnonzero(many)
        if todo.size:
            label_c[todo] = _resolve(
                scene,
                origin,
                dirs[todo],
                cand[todo],
                t_dsm[todo],
                lab_dsm[todo],
                opt.occlusion_tol_m,
                opt.line_band_m,
            )
    del dirs
    if progress is not None:
        progress(0.7)
    stop_if_asked(should_stop, "rendering")

    # ---- full resolution: upsample, then decide the plane per pixel near label changes
    label_c = label_c.reshape(h, w)
    rows_k = np.arange(height) // k
    cols_k = np.arange(width) // k
    label = label_c[rows_k[:, None], cols_k[None, :]]
    edge_pixels = 0
    if n_planes:
        lab_f = label_c.astype(np.float32)
        kernel = np.ones((3, 3), np.uint8)
        band_c = cv2.dilate(lab_f, kernel) != cv2.erode(lab_f, kernel)
        band_c &= cv2.dilate(lab_f, kernel) >= 0
        cand_c = _window_candidates(label_c, 3)
        br, bc = np.nonzero(band_c[rows_k[:, None], cols_k[None, :]])
        edge_pixels = int(br.size)
        chunk = 1 << 20
        for s in range(0, br.size, chunk):
            stop_if_asked(should_stop, "rendering")
            r, c = br[s : s + chunk], bc[s : s + chunk]
            rk, ck = r // k, c // k
            d = rays.at(c + 0.5, r + 0.5)
            flat = rk * w + ck
            label[r, c] = _resolve(
                scene,
                origin,
                d,
                cand_c[rk, ck],
                t_dsm[flat],
                lab_dsm[flat],
                opt.occlusion_tol_m,
                opt.line_band_m,
            )
            if progress is not None:
                progress(0.7 + 0.2 * min(1.0, (s + chunk) / max(br.size, 1)))
    base = cv2.resize(rgb_c, (w * k, h * k), interpolation=cv2.INTER_LINEAR)[:height, :width]
    if n_planes:
        _paint_planes(base, label, scene, sun, opt.ambient)
    if opt.noise_dn > 0:
        base = _with_noise(base, opt)
    ids = np.append(scene.plane_ids, -1).astype(np.int32)
    plane_id = ids[label]  # -1 indexes the appended "no plane"
    if progress is not None:
        progress(1.0)
    return RenderedImage(
        np.ascontiguousarray(base), plane_id, n, edge_pixels, time.perf_counter() - t0
    )


def render_images(
    scene: RenderScene,
    camera: Camera,
    eo: ExteriorOrientationTable,
    folder: PathLike,
    image_ids: Sequence[str] | None = None,
    options: RenderOptions | None = None,
    *,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> dict[str, Path]:
    """Render images of an EO table to ``<folder>/<image_id>.tif``; returns their paths.

    The EO must be in the scene's CRS; each image gets its own noise seed
    (``options.seed + row``).
    """
    from dataclasses import replace

    opt = options or RenderOptions()
    if eo.crs_wkt and not pyproj.CRS.from_user_input(eo.crs_wkt).equals(
        scene.crs, ignore_axis_order=True
    ):
        raise CrsError("the exterior orientation and the scene are in different CRSs")
    out = Path(os.fspath(folder))
    out.mkdir(parents=True, exist_ok=True)
    wanted = list(eo.image_id) if image_ids is None else list(image_ids)
    index = {name: k for k, name in enumerate(eo.image_id)}
    missing = [i for i in wanted if i not in index]
    if missing:
        raise InputError(f"no exterior orientation for image(s) {', '.join(missing[:5])}")
    paths: dict[str, Path] = {}
    for m, name in enumerate(wanted):
        row = index[name]
        sub = None if progress is None else (lambda f, m=m: progress((m + f) / len(wanted)))
        img = render_image(
            scene,
            camera,
            eo.xyz[row],
            eo.opk[row],
            replace(opt, seed=opt.seed + row),
            progress=sub,
            should_stop=should_stop,
        )
        paths[name] = out / f"{name}.tif"
        write_rgb_tiff(paths[name], img.rgb)
        LOG.info(
            "rendered %s in %.2f s (%d rays, %d edge pixels)",
            name,
            img.seconds,
            img.coarse_rays,
            img.edge_pixels,
        )
    return paths


def edge_offsets(
    plane_id: NDArray[np.integer],
    starts: ArrayLike,
    ends: ArrayLike,
    pairs: ArrayLike,
    *,
    samples: int = 15,
    reach_px: float = 8.0,
    step_px: float = 0.25,
) -> tuple[Array, NDArray[np.int64]]:
    """Distance from projected lines to the rendered edge between their two planes.

    Along each projected segment, at ``samples`` points (10 % to 90 % of its length), the
    plane labels are read across the line (every ``step_px`` up to ``reach_px`` on both
    sides, nearest pixel). Where the profile holds only the line's two planes and changes once
    from one to the other, the signed distance of that change from the line is returned.

    Parameters
    ----------
    plane_id : (H, W) int
        Plane id per pixel (:attr:`RenderedImage.plane_id`).
    starts, ends : (L, 2) array_like
        Projected end points (col, row), pixels.
    pairs : (L, 2) array_like
        The plane ids on either side of each line.

    Returns
    -------
    offsets : (M,) ndarray
        Pixels, for the profiles that crossed the edge (M <= L * samples).
    line : (M,) int64
        Index of the line of each offset.
    """
    a = np.asarray(starts, dtype=np.float64).reshape(-1, 2)
    b = np.asarray(ends, dtype=np.float64).reshape(-1, 2)
    ids = np.asarray(pairs).reshape(-1, 2)
    h, w = plane_id.shape
    d = b - a
    length = np.linalg.norm(d, axis=1, keepdims=True)
    with np.errstate(divide="ignore", invalid="ignore"):
        u = d / length
    normal = np.column_stack([-u[:, 1], u[:, 0]])
    t = np.linspace(0.1, 0.9, samples)
    offs = np.arange(-reach_px, reach_px + 1e-9, step_px)
    # (L, S, O, 2) sample positions
    pts = (
        a[:, None, None]
        + t[None, :, None, None] * d[:, None, None]
        + offs[None, None, :, None] * normal[:, None, None]
    )
    col = np.floor(pts[..., 0])
    row = np.floor(pts[..., 1])
    inside = (col >= 0) & (row >= 0) & (col < w) & (row < h) & np.isfinite(col) & np.isfinite(row)
    lab = np.full(col.shape, -2, dtype=np.int64)
    lab[inside] = plane_id[row[inside].astype(np.int64), col[inside].astype(np.int64)]
    pa, pb = ids[:, 0][:, None, None], ids[:, 1][:, None, None]
    clean = ((lab == pa) | (lab == pb)).all(axis=2) & (length[:, 0] > 0)[:, None]
    change = lab[..., 1:] != lab[..., :-1]
    single = change.sum(axis=2) == 1
    keep = clean & single
    where = np.argmax(change, axis=2)
    mid = (offs[where] + offs[where + 1]) / 2.0
    line = np.broadcast_to(np.arange(len(a))[:, None], keep.shape)
    return mid[keep], line[keep].astype(np.int64)
