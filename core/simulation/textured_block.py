"""Textured images of the simulated UAV block (:mod:`core.simulation.uav_block`), with the truth,
for feature matching: tie points found in them can be checked against the projection of the
true ground point.

The ground is the block's terrain (``UavBlock.terrain``) painted with a grey texture that
never repeats: random noise of several octaves (cells of 1 to 64 texture cells, upsampled
bicubically and summed with weights growing with the size), stored as an 8-bit raster in the
mapping CRS (``cell_m``). An image is rendered by ray casting: the rays of the pixel centres
of a lattice every ``step_px`` pixels are built with the project's collinearity chain in the
block's local ENU frame (lens model included), met with the terrain (Newton steps on the
ellipsoidal height, the ray point carried to the mapping CRS by PROJ at each step), and the
ground positions of the other pixels are interpolated bilinearly between lattice nodes (the
pixel-to-ground map of a frame camera over smooth terrain is smooth: the test measures the
interpolation error). The texture is sampled bilinearly; Gaussian noise of ``noise_dn`` is
added. Rays that miss the texture show grey 0.

:func:`ground_of_pixels` gives the exact ground point of any pixel (the truth of a tie point).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import cast

import numpy as np
from numpy.typing import NDArray

from ..geometry.camera import Camera
from ..geometry.collinearity import image_rays
from ..geometry.frames import LocalFrame
from ..geometry.rotations import matrix_to_opk
from ..photo.orientation import eo_map_to_local
from .uav_block import UavBlock

Array = NDArray[np.float64]

__all__ = ["GroundTexture", "TexturedBlock", "ground_of_pixels", "make_texture", "render_view"]


@dataclass(frozen=True)
class GroundTexture:
    """A grey raster in the mapping CRS: ``values[r, c]`` covers eastings
    ``x0 + c * cell .. x0 + (c + 1) * cell`` and northings
    ``y_top - (r + 1) * cell .. y_top - r * cell``."""

    values: NDArray[np.uint8]
    x0: float
    y_top: float
    cell: float


def make_texture(
    extent: tuple[float, float, float, float], cell_m: float, seed: int = 0, max_octave: int = 64
) -> GroundTexture:
    """Non-repeating multi-octave noise over ``(xmin, ymin, xmax, ymax)``, cell ``cell_m``.

    >>> t = make_texture((0.0, 0.0, 100.0, 50.0), 0.5, seed=1)
    >>> t.values.shape, t.values.dtype.name
    ((100, 200), 'uint8')
    """
    import cv2

    rng = np.random.default_rng(seed)
    cols = math.ceil((extent[2] - extent[0]) / cell_m)
    rows = math.ceil((extent[3] - extent[1]) / cell_m)
    acc = np.zeros((rows, cols), np.float32)
    size = 1
    while size <= max_octave:
        small = rng.standard_normal((rows // size + 2, cols // size + 2)).astype(np.float32)
        up = cv2.resize(
            small, (small.shape[1] * size, small.shape[0] * size), interpolation=cv2.INTER_CUBIC
        )
        acc += (size**0.6) * up[:rows, :cols]
        size *= 2
    # mean and spread from exact integer sums: numpy's float32 sums (and, before NEP 50,
    # the float64 scalar 45 / std) differ between numpy 1.24 and 2, which changed about half
    # of the rendered test images by one grey level here and there (and so their tie points)
    mean = _exact_mean(acc)
    dev = acc - np.float32(mean)
    scale = np.float32(45.0 / math.sqrt(_exact_mean(dev.astype(np.float64) ** 2)))
    vals = np.clip(dev * scale + np.float32(128.0), 0, 255).astype(np.uint8)
    return GroundTexture(vals, float(extent[0]), float(extent[3]), float(cell_m))


def _exact_mean(x: NDArray) -> float:
    """Mean of ``x`` from its values rounded to 2^-20 and summed as int64: integer sums are
    exact, so the order numpy adds in (its version, SIMD width, blocking) cannot change it.

    >>> a = np.array([0.1, 0.2, 0.3, 1e3], np.float32)
    >>> _exact_mean(a) == _exact_mean(a[::-1].copy()), round(_exact_mean(a), 4)
    (True, 250.15)
    """
    v = np.asarray(x, np.float64)
    if v.size and float(np.abs(v).max()) * v.size >= 2.0**42:
        raise ValueError("values too large for an exact int64 sum at 2^-20")
    q = np.rint(v * 2.0**20).astype(np.int64)
    return int(q.sum(dtype=np.int64)) / 2.0**20 / max(q.size, 1)


@dataclass(frozen=True)
class TexturedBlock:
    """A simulated block with its local frame and ENU orientations (``eo_local`` (M, 6):
    centre in metres, omega-phi-kappa in radians of the local frame)."""

    block: UavBlock
    local: LocalFrame
    eo_local: Array

    @classmethod
    def of(cls, block: UavBlock) -> TexturedBlock:
        cfg = block.config
        local = LocalFrame.at_map_point(block.mapping, np.array([*cfg.centre, cfg.ground_height_m]))
        centres, m = eo_map_to_local(block.eo_true.xyz, block.eo_true.opk, local)
        opk = np.column_stack(matrix_to_opk(m))
        return cls(block, local, np.column_stack([centres, opk]))

    def extent(self, margin_m: float = 30.0) -> tuple[float, float, float, float]:
        """Map extent of all footprints (corners met with the mean terrain), plus a margin."""
        cam = self.block.true_camera
        corners = np.array(
            [[0, 0], [cam.width_px, 0], [cam.width_px, cam.height_px], [0, cam.height_px]], float
        )
        pts = [ground_of_pixels(self, corners, k) for k in range(len(self.eo_local))]
        xy = np.vstack(pts)[:, :2]
        lo, hi = xy.min(0) - margin_m, xy.max(0) + margin_m
        return float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])


def _meet_terrain(tb: TexturedBlock, o: Array, d: Array, iterations: int = 8) -> Array:
    """Map coordinates (N, 3) where local rays (origins, unit directions) meet the terrain."""
    z0 = tb.block.config.ground_height_m
    t = (z0 - o[:, 2]) / d[:, 2]  # the local up is close to the ellipsoidal height here
    for _ in range(iterations):
        p = tb.local.enu_to_map(o + t[:, None] * d)
        dz = p[:, 2] - tb.block.terrain(p[:, 0], p[:, 1])
        t = t + dz / (-d[:, 2])
    return tb.local.enu_to_map(o + t[:, None] * d)


def ground_of_pixels(tb: TexturedBlock, pixels: Array, k: int) -> Array:
    """Exact ground point (mapping CRS) of pixels (N, 2) of image ``k`` (true camera)."""
    o, d = image_rays(np.asarray(pixels, float), tb.eo_local[k], tb.block.true_camera)
    return _meet_terrain(tb, o, d)


def _bilinear_matrix(n_out: int, step: float, n_nodes: int) -> NDArray[np.float32]:
    """(n_out, n_nodes) weights interpolating nodes at pixel centres 0.5 + k * step."""
    pos = np.arange(n_out) / step  # (centre - 0.5) / step
    k = np.clip(np.floor(pos).astype(int), 0, n_nodes - 2)
    w = pos - k
    a = np.zeros((n_out, n_nodes), np.float32)
    a[np.arange(n_out), k] = 1.0 - w
    a[np.arange(n_out), k + 1] = w
    return a


def render_view(
    tb: TexturedBlock,
    texture: GroundTexture,
    k: int,
    *,
    step_px: int = 16,
    noise_dn: float = 2.0,
    seed: int = 0,
) -> NDArray[np.uint8]:
    """Render image ``k`` of the block (module docstring): (H, W) uint8 grey."""
    import cv2

    cam: Camera = tb.block.true_camera
    w, h = cam.width_px, cam.height_px
    nc = math.ceil((w - 1) / step_px) + 1
    nr = math.ceil((h - 1) / step_px) + 1
    cc = 0.5 + np.arange(nc) * step_px
    rr = 0.5 + np.arange(nr) * step_px
    grid = np.stack(np.meshgrid(cc, rr), -1).reshape(-1, 2)
    g = ground_of_pixels(tb, grid, k)
    u = ((g[:, 0] - texture.x0) / texture.cell - 0.5).reshape(nr, nc)
    v = ((texture.y_top - g[:, 1]) / texture.cell - 0.5).reshape(nr, nc)
    ar = _bilinear_matrix(h, step_px, nr)
    ac = _bilinear_matrix(w, step_px, nc)
    map_u = (ar @ u.astype(np.float32)) @ ac.T
    map_v = (ar @ v.astype(np.float32)) @ ac.T
    img = cv2.remap(
        texture.values,
        map_u,
        map_v,
        cv2.INTER_LINEAR,
        borderMode=cv2.BORDER_CONSTANT,
        borderValue=(0,),
    )
    del map_u, map_v
    if noise_dn > 0:
        noise = np.empty(img.shape, np.int16)
        cv2.setRNGSeed(int(seed) + k)
        # OpenCV's stubs want arrays for the mean and deviation; it takes numbers
        cv2.randn(noise, 0.0, float(noise_dn))  # type: ignore[call-overload]
        img = cv2.add(img, noise, dtype=cv2.CV_8U)
    return cast(NDArray[np.uint8], img)  # the texture's 8 bits, kept by remap and add
