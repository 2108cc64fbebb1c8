"""The per-cell geometry of orthophotos (:mod:`core.photo.orthophoto`, whose module docstring
describes the method): the lens lattice (step 3) and the image pixels of a block of cells,
numpy back end (the compiled one is :mod:`core.photo.orthophoto_numba`)."""

from __future__ import annotations

import logging
import math

import numpy as np
from numpy.typing import NDArray

from ..geometry.camera import Camera
from ..geometry.distortion import NoDistortion
from ..geometry.projection import ideal_from_camera
from ..geometry.surface import triangle_height

LOG = logging.getLogger(__name__)

Array = NDArray[np.float64]


def _lens_lattice(camera: Camera, tol_px: float = 1e-3) -> tuple[Array, float, float, float]:
    """(ny, nx, 2) measured pixels (col, row) at lattice nodes of ideal image coordinates (mm),
    origin (x, y) and spacing (mm); spacing halved until bilinear interpolation matches Newton
    within ``tol_px`` at the lattice-cell centres. An empty lattice for a lens without
    distortion."""
    if isinstance(camera.distortion, NoDistortion):
        return np.zeros((1, 1, 2)), 0.0, 0.0, 1.0
    border = camera.border_pixels(256)
    ideal = camera.ideal_from_pixel(border)
    lo, hi = ideal.min(axis=0), ideal.max(axis=0)
    margin = 0.02 * (hi - lo) + 2 * camera.pixel_size_mm
    lo, hi = lo - margin, hi + margin
    step = 64 * camera.pixel_size_mm
    while True:
        nx = math.ceil((hi[0] - lo[0]) / step) + 1
        ny = math.ceil((hi[1] - lo[1]) / step) + 1
        xs, ys = lo[0] + np.arange(nx) * step, lo[1] + np.arange(ny) * step
        gx, gy = np.meshgrid(xs, ys)
        px, ok = camera.pixel_from_ideal_with_status(np.column_stack([gx.ravel(), gy.ravel()]))
        px[~ok] = np.nan
        lat = px.reshape(ny, nx, 2)
        # check at the lattice-cell centres (where bilinear interpolation is worst)
        mx, my = np.meshgrid(xs[:-1] + step / 2, ys[:-1] + step / 2)
        exact, ok2 = camera.pixel_from_ideal_with_status(np.column_stack([mx.ravel(), my.ravel()]))
        interp = 0.25 * (lat[:-1, :-1] + lat[:-1, 1:] + lat[1:, :-1] + lat[1:, 1:]).reshape(-1, 2)
        # only where the cell lies on the image: elsewhere no cell of an orthophoto is kept
        on = ok2 & camera.in_frame(exact, -2.0) & np.isfinite(interp).all(axis=1)
        err = np.abs(interp[on] - exact[on]).max() if on.any() else 0.0
        if err <= tol_px or step <= 2 * camera.pixel_size_mm:
            LOG.debug(
                "lens lattice %d x %d nodes every %.1f px: %.2g px",
                nx,
                ny,
                step / camera.pixel_size_mm,
                err,
            )
            return lat, float(lo[0]), float(lo[1]), float(step)
        step /= 2


def cell_pixels_numpy(
    x0: float,
    y0: float,
    g: float,
    h: int,
    w: int,
    z: NDArray[np.float32],
    xc: float,
    yc: float,
    inv_cell: float,
    lat: Array,
    step: float,
    focal: float,
    lens: Array,
    lx0: float,
    ly0: float,
    inv_ls: float,
    nolens: Array,
    projection: str = "perspective",
) -> tuple[Array, Array, Array]:
    """Image pixels of an h x w block of cells (numpy; the compiled version is
    :mod:`core.photo.orthophoto_numba`).

    Parameters
    ----------
    x0, y0, g, h, w
        Centre of the first cell (mapping CRS), cell size and block size.
    z, xc, yc, inv_cell
        DSM heights, centre of DSM cell (0, 0), 1 / DSM cell.
    lat : (ny, nx, 6)
        ``a`` and ``b`` (module docstring) at the lattice nodes, every ``step`` cells.
    focal
        Principal distance, mm.
    lens, lx0, ly0, inv_ls
        Measured pixels at ideal-coordinate nodes (:func:`_lens_lattice`); a (1, 1, 2) lens
        means none.
    nolens : (5,)
        Without lens: principal point column and row (pixels), pixel size (mm), W, H.
    projection
        The camera's projection (:mod:`core.geometry.projection`): a fisheye maps the angle
        off the axis, and a cell outside its field has no pixel.

    Returns
    -------
    col, row : (h, w) float64
        Measured image pixel (col, row), NaN where there is none.
    z : (h, w) float64
        Surface height (NaN outside the DSM or on nodata).
    """
    ny, nx = lat.shape[:2]
    ii = np.arange(h, dtype=np.float64)
    jj = np.arange(w, dtype=np.float64)
    y = y0 - ii * g
    x = x0 + jj * g
    v = ((yc - y) * inv_cell)[:, None]
    u = ((x - xc) * inv_cell)[None, :]
    zz = triangle_height(z, u, v)
    fi, fj = ii / step, jj / step
    ki = np.minimum(fi.astype(np.int64), ny - 2)
    kj = np.minimum(fj.astype(np.int64), nx - 2)
    ti, tj = (fi - ki)[:, None], (fj - kj)[None, :]
    w00, w01, w10, w11 = (1 - ti) * (1 - tj), (1 - ti) * tj, ti * (1 - tj), ti * tj
    q = []
    for k in range(3):
        a, b = lat[:, :, k], lat[:, :, k + 3]
        q.append(
            w00 * (a[ki][:, kj] + zz * b[ki][:, kj])
            + w01 * (a[ki][:, kj + 1] + zz * b[ki][:, kj + 1])
            + w10 * (a[ki + 1][:, kj] + zz * b[ki + 1][:, kj])
            + w11 * (a[ki + 1][:, kj + 1] + zz * b[ki + 1][:, kj + 1])
        )
    if projection == "perspective":
        front = q[2] < 0.0
        with np.errstate(divide="ignore", invalid="ignore"):
            xi = -focal * q[0] / q[2]
            yi = -focal * q[1] / q[2]
    else:
        qs = np.stack(np.broadcast_arrays(*q), axis=-1).reshape(-1, 3)
        ideal, inside = ideal_from_camera(qs, focal, projection)
        front = inside.reshape(h, w)
        xi, yi = ideal[:, 0].reshape(h, w), ideal[:, 1].reshape(h, w)
    if lens.shape[0] > 1:
        my, mx = lens.shape[:2]
        lu, lv = (xi - lx0) * inv_ls, (yi - ly0) * inv_ls
        on = (lu >= 0) & (lv >= 0) & (lu <= mx - 1) & (lv <= my - 1)
        lj = np.clip(np.nan_to_num(lu), 0, mx - 2).astype(np.int64)
        li = np.clip(np.nan_to_num(lv), 0, my - 2).astype(np.int64)
        su, sv = lu - lj, lv - li
        out = []
        for k in range(2):
            m = lens[:, :, k]
            out.append(
                (m[li, lj] * (1 - su) + m[li, lj + 1] * su) * (1 - sv)
                + (m[li + 1, lj] * (1 - su) + m[li + 1, lj + 1] * su) * sv
            )
        col, row = out
        front &= on
    else:
        col = nolens[0] + xi / nolens[1]
        row = nolens[2] - yi / nolens[1]
    with np.errstate(invalid="ignore"):
        ok = (
            front
            & np.isfinite(zz)
            & (col >= 0)
            & (row >= 0)
            & (col <= nolens[3])
            & (row <= nolens[4])
        )
    col = np.where(ok, col, np.nan)
    row = np.where(ok, row, np.nan)
    return col, row, zz
