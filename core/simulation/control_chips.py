"""Synthetic control chips and aerial images of a textured horizontal ground patch (tests and
benchmarks of control-point location; not in the plugin zip).

The ground is the plane ``Z = z0`` of the mapping CRS with an analytic grey texture (a sum of
random plane waves with a 1/f-like spectrum up to ``fmax`` cycles per metre), so every image
and chip can be rendered exactly: a pixel is the mean of ``supersample^2`` rays (a box filter,
the pixel's area). Rays are built in a local ENU frame (the project's collinearity chain) and
met with the plane in two steps: with the local horizontal plane at the height of the point,
then corrected along the ray by the height difference the mapping CRS sees (Earth curvature
over the patch), so the rendered point projects where :func:`core.geometry.collinearity.project`
puts it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..geometry.camera import Camera
from ..geometry.collinearity import image_rays
from ..geometry.frames import LocalFrame, MappingFrame
from ..photo.control_location import ControlChip
from ..photo.orientation import eo_map_to_local
from .ground_photo import GroundPatch

Array = NDArray[np.float64]


@dataclass(frozen=True)
class GroundTexture:
    """Sum of ``n`` plane waves (frequencies in cycles per metre) around ``origin`` (X, Y)."""

    origin: tuple[float, float]
    seed: int = 0
    n: int = 60
    fmin: float = 0.2
    fmax: float = 3.0
    mean: float = 120.0
    contrast: float = 45.0

    def at(self, x: ArrayLike, y: ArrayLike) -> Array:
        """Grey value at map (x, y)."""
        rng = np.random.default_rng(self.seed)
        f = rng.uniform(self.fmin, self.fmax, self.n)
        th = rng.uniform(0, np.pi, self.n)
        ph = rng.uniform(0, 2 * np.pi, self.n)
        amp = 1.0 / (1.0 + (f / (0.4 * self.fmax)) ** 2)
        amp /= np.sqrt((amp**2).sum() / 2)
        dx = np.asarray(x, dtype=np.float64) - self.origin[0]
        dy = np.asarray(y, dtype=np.float64) - self.origin[1]
        out = np.zeros(np.broadcast(dx, dy).shape)
        for k in range(self.n):
            kx, ky = 2 * np.pi * f[k] * np.cos(th[k]), 2 * np.pi * f[k] * np.sin(th[k])
            out += amp[k] * np.cos(kx * dx + ky * dy + ph[k])
        return self.mean + self.contrast * out


def render_plane_image(
    texture: GroundTexture | None,
    z0: float,
    camera: Camera,
    xyz: ArrayLike,
    opk: ArrayLike,
    crs: str,
    supersample: int = 3,
    noise: float = 0.0,
    seed: int = 0,
    flat_value: float | None = None,
) -> Array:
    """(H, W) grey image of the plane Z = z0 (texture, or ``flat_value`` everywhere)."""
    mapping = MappingFrame.from_user_input(crs)
    centre = np.asarray(xyz, dtype=np.float64).reshape(1, 3)
    local = LocalFrame.at_map_point(mapping, [centre[0, 0], centre[0, 1], z0])
    c_loc, m_loc = eo_map_to_local(centre, np.asarray(opk, float).reshape(1, 3), local)
    from ..geometry.rotations import matrix_to_opk

    om, ph, ka = matrix_to_opk(m_loc)
    eo6 = np.concatenate([c_loc[0], [om[0], ph[0], ka[0]]])
    w, h = camera.width_px, camera.height_px
    s = int(supersample)
    sub = (np.arange(s) + 0.5) / s
    cols = (np.arange(w)[:, None] + sub[None, :]).ravel()
    rows = (np.arange(h)[:, None] + sub[None, :]).ravel()
    cc, rr = np.meshgrid(cols, rows)
    px = np.column_stack([cc.ravel(), rr.ravel()])
    o, d = image_rays(px, eo6, camera)
    z_loc = local.map_to_enu([[centre[0, 0], centre[0, 1], z0]])[0, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (z_loc - o[:, 2]) / d[:, 2]
    # rays that miss the plane (at or above the horizon, or beyond a fisheye's field) and those
    # meeting it more than 10 flying heights away (84 degrees below the horizontal: the
    # quadratic map fit below would lose its precision) see a black sky
    ground = np.isfinite(t) & (t > 0)
    reach = np.hypot(d[:, 0], d[:, 1]) * np.where(ground, t, 0.0)
    ground &= reach <= 10.0 * abs(float(z_loc - o[0, 2]))
    t = np.where(ground, t, 0.0)
    d = np.where(ground[:, None], d, 0.0)
    hit = o + t[:, None] * d
    # local -> map is smooth over an image footprint: a quadratic fitted on an 11 x 11 grid of
    # exact transformations (residuals far below a micrometre) replaces millions of PROJ calls.
    lo, hi = hit[ground, :2].min(axis=0), hit[ground, :2].max(axis=0)
    ge, gn = np.meshgrid(np.linspace(lo[0], hi[0], 11), np.linspace(lo[1], hi[1], 11))
    grid = np.column_stack([ge.ravel(), gn.ravel(), np.full(ge.size, z_loc)])
    exact = local.enu_to_map(grid)

    def design(e: Array, n: Array) -> Array:
        e = (e - lo[0]) / max(hi[0] - lo[0], 1.0)
        n = (n - lo[1]) / max(hi[1] - lo[1], 1.0)
        return np.column_stack([np.ones_like(e), e, n, e * e, e * n, n * n])

    coef = np.linalg.lstsq(design(grid[:, 0], grid[:, 1]), exact, rcond=None)[0]
    # d map / d local-up is 1 to first order: the map height of a hit differs from z0 by
    # micrometres to millimetres, corrected along the ray.
    zmap = design(hit[:, 0], hit[:, 1]) @ coef[:, 2] + (hit[:, 2] - z_loc)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(ground, t + (z0 - zmap) / d[:, 2], 0.0)
    hit = o + t[:, None] * d
    m = design(hit[:, 0], hit[:, 1]) @ coef
    if texture is None:
        grey = np.full(len(m), float(flat_value if flat_value is not None else 100.0))
    else:
        grey = texture.at(m[:, 0], m[:, 1])
    grey = np.where(ground, grey, 0.0)
    img = grey.reshape(h * s, w * s).reshape(h, s, w, s).mean(axis=(1, 3))
    if noise > 0:
        img = img + np.random.default_rng(seed).normal(0, noise, img.shape)
    return img


def make_chip(
    point_id: str,
    texture: GroundTexture | None,
    xyz: ArrayLike,
    gsd: float,
    size: int = 81,
    supersample: int = 3,
    offset_px: tuple[float, float] = (0.3, -0.2),
    noise: float = 0.0,
    seed: int = 1,
    flat_value: float = 100.0,
) -> ControlChip:
    """A north-up chip of ``size`` x ``size`` pixels of ``gsd`` metres on Z = Z_point, with the
    point ``offset_px`` (col, row) off the chip's centre pixel."""
    p = np.asarray(xyz, dtype=np.float64).reshape(3)
    half = (size - 1) / 2.0
    # point at array coords (half + offset): x0 + (half + ox + 0.5) gsd = X
    x0 = p[0] - (half + offset_px[0] + 0.5) * gsd
    y0 = p[1] + (half + offset_px[1] + 0.5) * gsd
    s = int(supersample)
    sub = (np.arange(s) + 0.5) / s
    u = (np.arange(size)[:, None] + sub[None, :]).ravel()
    xs = x0 + u * gsd
    ys = y0 - u * gsd
    xx, yy = np.meshgrid(xs, ys)
    if texture is None:
        grey = np.full(xx.shape, flat_value)
    else:
        grey = texture.at(xx, yy)
    chip = grey.reshape(size, s, size, s).mean(axis=(1, 3))
    if noise > 0:
        chip = chip + np.random.default_rng(seed).normal(0, noise, chip.shape)
    return ControlChip(point_id, chip, (x0, gsd, 0.0, y0, 0.0, -gsd), p)


def ground_patch(
    texture: GroundTexture, xy: ArrayLike, size_m: float = 5.0, cell_m: float = 0.005
) -> GroundPatch:
    """The texture around the map point ``xy`` as a :class:`core.simulation.ground_photo.
    GroundPatch` in the point's local frame (map X, Y minus ``xy``: the frame of the ground
    photos and of :mod:`core.photo.control_chips`), so that the ground photos of a point and
    the aerial images of :func:`render_plane_image` see one surface.

    The grid holds the texture's exact values at the cell centres; the ground photo renderer
    reads it bilinearly, whose relative error on a wave of length L is about
    (pi cell / L)^2 / 8: with 1 cm cells and waves of at least 1 / fmax = 16.7 cm (6 cycles
    per metre) below 0.5 % of that wave's (small) amplitude.
    """
    p = np.asarray(xy, dtype=np.float64).reshape(-1)[:2]
    n = int(np.ceil(size_m / cell_m))
    half = n * cell_m / 2.0
    c = -half + (np.arange(n) + 0.5) * cell_m
    gx, gy = np.meshgrid(c, -c)  # rows go south
    grey = texture.at(p[0] + gx, p[1] + gy).astype(np.float32)
    return GroundPatch(grey, float(cell_m), -half, half)
