"""Synthetic ground photos of a surveyed point: a textured horizontal ground patch, with or
without a control plate, seen by a ground camera with a known pose; and the direct
orthographic rendering of the patch (the truth of a control chip).

Frame: the point's local frame (east, north, up relative to the surveyed point, metres); the
ground is the plane Z = 0, the plate the square of :class:`core.photo.control_plate.
PlateGeometry` at Z = ``height_m`` (it hides the ground under it).

The ground's grey level is a band-limited random field: white noise on a grid of
``cell_m``, smoothed by a Gaussian of ``feature_m``, scaled to a mean of 125 and a standard
deviation of 30 grey levels (clipped to 40-210, darker than the plate's white and lighter than
its black), read bilinearly. Every photo pixel is the mean of ``supersample`` x
``supersample`` rays (the camera's own back-projection,
:func:`core.geometry.collinearity.image_rays`, so the lens model is the one the code under test
inverts), ``EDGE_SUPERSAMPLE`` x ``EDGE_SUPERSAMPLE`` on the plate's edges. Any camera of the
registry renders: perspective or fisheye (equidistant, equisolid, orthographic,
stereographic, :mod:`core.geometry.projection`); a ray that does not meet the ground in front
of the camera (a fisheye's rays at or beyond 90 degrees off a nadir axis, or outside the
projection's image) sees the sky, grey 0; the
orthographic truth is the mean over each cell of ``supersample`` x
``supersample`` points. Gaussian noise of ``noise_dn`` grey levels is added to the photos.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..geometry.camera import Camera, camera_from_dict
from ..geometry.collinearity import image_rays
from ..photo.control_plate import PlateGeometry

__all__ = [
    "GroundPatch",
    "corner_errors",
    "ground_camera",
    "make_ground_patch",
    "render_ground_photo",
    "render_ortho",
]

#: Grey levels of the plate: the outer frame (black) and the inner square (white).
PLATE_DARK = 15.0
PLATE_LIGHT = 240.0
#: Rays per side of a pixel on the plate's edges.
EDGE_SUPERSAMPLE = 16


@dataclass(frozen=True)
class GroundPatch:
    """Grey levels (rows, cols) at the centres of cells of ``cell_m``; the top-left corner of
    the grid at local (``x0``, ``y_top``)."""

    grey: NDArray[np.float32]
    cell_m: float
    x0: float
    y_top: float

    def sample(self, x: ArrayLike, y: ArrayLike) -> NDArray[np.float32]:
        """Bilinear grey level at local points (any shape; 0 outside the patch)."""
        import cv2

        xa = np.asarray(x, dtype=np.float64)
        ya = np.asarray(y, dtype=np.float64)
        mx: NDArray[np.float32] = ((xa - self.x0) / self.cell_m - 0.5).astype(np.float32).ravel()
        my: NDArray[np.float32] = ((self.y_top - ya) / self.cell_m - 0.5).astype(np.float32).ravel()
        # cv2.remap wants sides below 32767: rows of 4096 points, padded
        width = 4096
        pad = (-len(mx)) % width
        mx = np.concatenate([mx, np.full(pad, -1e6, np.float32)]).reshape(-1, width)
        my = np.concatenate([my, np.full(pad, -1e6, np.float32)]).reshape(-1, width)
        out = np.empty(mx.shape, np.float32)
        for s in range(0, len(mx), 16384):
            out[s : s + 16384] = cv2.remap(
                self.grey,
                mx[s : s + 16384],
                my[s : s + 16384],
                cv2.INTER_LINEAR,
                borderMode=cv2.BORDER_CONSTANT,
                borderValue=(0.0,),
            )
        out = out.ravel()[: xa.size]
        return out.reshape(xa.shape)


def make_ground_patch(
    size_m: float = 4.0, cell_m: float = 0.002, feature_m: float = 0.012, seed: int = 0
) -> GroundPatch:
    """A square patch of ``size_m`` centred on the point (module docstring)."""
    import cv2

    n = math.ceil(size_m / cell_m)
    rng = np.random.default_rng(seed)
    g = rng.standard_normal((n, n)).astype(np.float32)
    g = cast(NDArray[np.float32], cv2.GaussianBlur(g, (0, 0), feature_m / cell_m))
    g = (g - g.mean()) / max(float(g.std()), 1e-12)
    grey = np.clip(125.0 + 30.0 * g, 40.0, 210.0).astype(np.float32)
    half = n * cell_m / 2.0
    return GroundPatch(grey, cell_m, -half, half)


def _scene(
    patch: GroundPatch, plate: PlateGeometry | None, o: NDArray, d: NDArray
) -> tuple[NDArray, NDArray]:
    """Grey level seen along rays (origins o, unit directions d), local frame, and what each
    ray sees (0 ground, 1 the plate's outer frame, 2 its inner square)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t = -o[:, 2] / d[:, 2]
    g = o + t[:, None] * d
    out = patch.sample(g[:, 0], g[:, 1]).astype(np.float64)
    out[~(t > 0)] = 0.0
    label = np.zeros(len(out), np.int8)
    if plate is not None:
        with np.errstate(divide="ignore", invalid="ignore"):
            tp = (plate.height_m - o[:, 2]) / d[:, 2]
        q = o + tp[:, None] * d
        a = math.radians(plate.azimuth_deg)
        e1 = np.array([math.sin(a), math.cos(a)])
        e2 = np.array([-math.cos(a), math.sin(a)])
        u = np.abs(q[:, :2] @ e1)
        v = np.abs(q[:, :2] @ e2)
        on = (tp > 0) & (np.maximum(u, v) <= plate.outer_m / 2)
        inner = on & (np.maximum(u, v) <= plate.inner_m / 2)
        out[on] = PLATE_DARK
        out[inner] = PLATE_LIGHT
        label[on] = 1
        label[inner] = 2
    return out, label


def render_ground_photo(
    patch: GroundPatch,
    camera: Camera,
    eo: ArrayLike,
    plate: PlateGeometry | None = None,
    supersample: int = 3,
    noise_dn: float = 1.0,
    seed: int = 1,
) -> NDArray[np.float32]:
    """(rows, cols) float32 grey photo of the patch (and plate) from ``eo`` (local frame,
    metres and radians)."""
    import cv2

    e = np.asarray(eo, dtype=np.float64)
    w, h, s = camera.width_px, camera.height_px, int(supersample)
    sub = (np.arange(s) + 0.5) / s
    cols = (np.arange(w)[:, None] + sub[None, :]).ravel()
    img = np.empty((h, w), np.float64)
    lo = np.zeros((h, w), np.uint8)
    hi = np.zeros((h, w), np.uint8)
    block = max(1, (1 << 20) // (w * s * s))
    for r0 in range(0, h, block):
        rows = (np.arange(r0, min(h, r0 + block))[:, None] + sub[None, :]).ravel()
        gc, gr = np.meshgrid(cols, rows)
        o, d = image_rays(np.column_stack([gc.ravel(), gr.ravel()]), e, camera)
        val, lab = _scene(patch, plate, o, d)
        n = len(rows) // s
        img[r0 : r0 + n] = val.reshape(n, s, w, s).mean(axis=(1, 3))
        lab = lab.reshape(n, s, w, s)
        lo[r0 : r0 + n] = lab.min(axis=(1, 3))
        hi[r0 : r0 + n] = lab.max(axis=(1, 3))
    # a pixel on an edge: its rays see two things, or a neighbour sees something else (with
    # few rays per pixel an edge can pass between them)
    lo = cast(NDArray[np.uint8], cv2.erode(lo, np.ones((3, 3), np.uint8)))  # depth kept
    hi = cast(NDArray[np.uint8], cv2.dilate(hi, np.ones((3, 3), np.uint8)))
    mixed = lo != hi
    # pixels on the plate's edges again with EDGE_SUPERSAMPLE^2 rays: the edge's position in
    # the grey level is then exact to 1/EDGE_SUPERSAMPLE^2 of a pixel's area
    r, c = np.nonzero(mixed)
    if r.size:
        k = EDGE_SUPERSAMPLE
        f = (np.arange(k) + 0.5) / k
        for s0 in range(0, r.size, 4096):
            rr, cc = r[s0 : s0 + 4096], c[s0 : s0 + 4096]
            pc = (cc[:, None, None] + f[None, None, :]) + 0 * f[None, :, None]
            pr = (rr[:, None, None] + f[None, :, None]) + 0 * f[None, None, :]
            o, d = image_rays(np.column_stack([pc.ravel(), pr.ravel()]), e, camera)
            val, _ = _scene(patch, plate, o, d)
            img[rr, cc] = val.reshape(len(rr), k * k).mean(axis=1)
    if noise_dn > 0:
        img += np.random.default_rng(seed).normal(0.0, noise_dn, img.shape)
    return img.astype(np.float32)


def render_ortho(
    patch: GroundPatch, geotransform: tuple[float, ...], size_px: int, supersample: int = 8
) -> NDArray[np.float32]:
    """(size, size) area mean of the ground over each cell of a north-up grid (geotransform
    in the local frame)."""
    x0, g, _, y0, _, _ = geotransform
    s = int(supersample)
    f = (np.arange(size_px * s) + 0.5) / s
    gx, gy = np.meshgrid(x0 + f * g, y0 - f * g)
    val = patch.sample(gx, gy).reshape(size_px, s, size_px, s)
    return val.mean(axis=(1, 3)).astype(np.float32)


def ground_camera(projection: str = "perspective") -> Camera:
    """The ground camera of the tests and benchmarks, 960 x 720 px: perspective (f 3 mm,
    5 um pixels, k1 4e-3) or a fisheye of the given projection (f 1.6 mm, 4.5 um pixels,
    principal point off the centre, k1 2e-3, k2 -1e-4: the image corners look beyond 90 deg)."""
    if projection == "perspective":
        return camera_from_dict(
            {
                "name": "ground",
                "focal_mm": 3.0,
                "pixel_size_mm": 0.005,
                "width_px": 960,
                "height_px": 720,
                "distortion": {"model": "brown_conrady", "k1": 4e-3},
            }
        )
    return camera_from_dict(
        {
            "name": "fisheye",
            "focal_mm": 1.6,
            "pixel_size_mm": 0.0045,
            "width_px": 960,
            "height_px": 720,
            "projection": projection,
            "x0_mm": 0.02,
            "y0_mm": -0.015,
            "distortion": {"model": "brown_conrady", "k1": 2e-3, "k2": -1e-4},
        }
    )


def corner_errors(found: ArrayLike, truth: ArrayLike) -> NDArray[np.float64]:
    """(8,) distance (px) of each found plate corner to its true corner, after the quarter
    turn that fits best: the found order must be the plate's order up to that turn (outer and
    inner together).

    >>> t = np.arange(16.0).reshape(8, 2)
    >>> float(corner_errors(t[[1, 2, 3, 0, 5, 6, 7, 4]], t).max())
    0.0
    """
    found, truth = np.asarray(found, dtype=np.float64), np.asarray(truth, dtype=np.float64)
    best = None
    for turn in range(4):
        order = np.r_[(np.arange(4) + turn) % 4, 4 + (np.arange(4) + turn) % 4]
        err = np.linalg.norm(found - truth[order], axis=1)
        if best is None or err.max() < best.max():
            best = err
    assert best is not None  # set at the first turn
    return best
