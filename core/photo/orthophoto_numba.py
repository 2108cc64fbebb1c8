"""The per-cell loop of :mod:`core.photo.orthophoto` compiled with numba: surface height,
collinearity and lens lookup of every orthophoto cell in one pass, the same arithmetic as the
vectorised numpy version (the tests compare them cell by cell).

numba is optional (:data:`AVAILABLE`); without it the numpy version runs (about 3x slower).
The compiled function releases the GIL, so that tiles run in parallel threads.
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from ..geometry.raycast_numba import AVAILABLE, numba

__all__ = ["AVAILABLE", "cell_pixels"]


def _cell_pixels(
    x0, y0, g, h, w, z, xc, yc, inv_cell, lat, step, focal, lens, lx0, ly0, inv_ls, nolens,
    out_col, out_row, out_z,
):  # fmt: skip
    """Fill out_col, out_row (image pixels, NaN: none) and out_z (surface height) of an h x w
    block of cells whose first centre is (x0, y0) and spacing g (see
    :func:`core.photo.orthophoto.cell_pixels_numpy` for the arguments)."""
    rows, cols = z.shape
    ny, nx = lat.shape[0], lat.shape[1]
    cx0, ps, cy0, wpx, hpx = nolens[0], nolens[1], nolens[2], nolens[3], nolens[4]
    has_lens = lens.shape[0] > 1
    my, mx = lens.shape[0], lens.shape[1]
    for i in range(h):
        y = y0 - i * g
        v = (yc - y) * inv_cell
        fi = i / step
        ki = min(int(fi), ny - 2)
        ti = fi - ki
        for j in range(w):
            out_col[i, j] = np.nan
            out_row[i, j] = np.nan
            out_z[i, j] = np.nan
            x = x0 + j * g
            u = (x - xc) * inv_cell
            if not (u >= 0.0 and v >= 0.0 and u <= cols - 1 and v <= rows - 1):
                continue
            c = min(max(math.floor(u), 0), max(cols - 2, 0))
            r = min(max(math.floor(v), 0), max(rows - 2, 0))
            fu, fv = u - c, v - r
            c1, r1 = min(c + 1, cols - 1), min(r + 1, rows - 1)
            z00 = float(z[r, c])
            z01 = float(z[r, c1])
            z10 = float(z[r1, c])
            z11 = float(z[r1, c1])
            if fu >= fv:
                zz = z00 + (z01 - z00) * fu + (z11 - z01) * fv
            else:
                zz = z00 + (z11 - z10) * fu + (z10 - z00) * fv
            if not math.isfinite(zz):
                continue
            out_z[i, j] = zz
            fj = j / step
            kj = min(int(fj), nx - 2)
            tj = fj - kj
            # q = a + z b, a and b interpolated bilinearly between the lattice nodes
            w00, w01 = (1 - ti) * (1 - tj), (1 - ti) * tj
            w10, w11 = ti * (1 - tj), ti * tj
            q0 = (w00 * (lat[ki, kj, 0] + zz * lat[ki, kj, 3])
                  + w01 * (lat[ki, kj + 1, 0] + zz * lat[ki, kj + 1, 3])
                  + w10 * (lat[ki + 1, kj, 0] + zz * lat[ki + 1, kj, 3])
                  + w11 * (lat[ki + 1, kj + 1, 0] + zz * lat[ki + 1, kj + 1, 3]))
            q1 = (w00 * (lat[ki, kj, 1] + zz * lat[ki, kj, 4])
                  + w01 * (lat[ki, kj + 1, 1] + zz * lat[ki, kj + 1, 4])
                  + w10 * (lat[ki + 1, kj, 1] + zz * lat[ki + 1, kj, 4])
                  + w11 * (lat[ki + 1, kj + 1, 1] + zz * lat[ki + 1, kj + 1, 4]))
            q2 = (w00 * (lat[ki, kj, 2] + zz * lat[ki, kj, 5])
                  + w01 * (lat[ki, kj + 1, 2] + zz * lat[ki, kj + 1, 5])
                  + w10 * (lat[ki + 1, kj, 2] + zz * lat[ki + 1, kj, 5])
                  + w11 * (lat[ki + 1, kj + 1, 2] + zz * lat[ki + 1, kj + 1, 5]))
            if not q2 < 0.0:  # behind the camera
                continue
            xi = -focal * q0 / q2
            yi = -focal * q1 / q2
            if has_lens:
                lu = (xi - lx0) * inv_ls
                lv = (yi - ly0) * inv_ls
                if not (lu >= 0.0 and lv >= 0.0 and lu <= mx - 1 and lv <= my - 1):
                    continue
                lj = min(int(lu), mx - 2)
                li = min(int(lv), my - 2)
                su, sv = lu - lj, lv - li
                col = ((lens[li, lj, 0] * (1 - su) + lens[li, lj + 1, 0] * su) * (1 - sv)
                       + (lens[li + 1, lj, 0] * (1 - su) + lens[li + 1, lj + 1, 0] * su) * sv)
                row = ((lens[li, lj, 1] * (1 - su) + lens[li, lj + 1, 1] * su) * (1 - sv)
                       + (lens[li + 1, lj, 1] * (1 - su) + lens[li + 1, lj + 1, 1] * su) * sv)
            else:
                col = cx0 + xi / ps
                row = cy0 - yi / ps
            if col >= 0.0 and row >= 0.0 and col <= wpx and row <= hpx:
                out_col[i, j] = col
                out_row[i, j] = row


_COMPILED: dict[str, Callable[..., Any]] = {}


def cell_pixels(*args: Any) -> None:
    """Run the compiled loop (compiled at the first call, cached next to this module)."""
    if not AVAILABLE:
        raise RuntimeError("numba is not installed")
    if "cells" not in _COMPILED:
        _COMPILED["cells"] = numba.njit(cache=True, nogil=True)(_cell_pixels)
    _COMPILED["cells"](*args)
