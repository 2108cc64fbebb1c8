"""The per-cell loop of :mod:`core.photo.orthophoto` compiled with numba: surface height,
collinearity and lens lookup of every orthophoto cell in one pass, the same arithmetic as the
vectorised numpy version (the tests compare them cell by cell).

numba is optional (:data:`AVAILABLE`); without it the numpy version runs (29x slower: 2.1 CPU
s instead of 0.074 for the 11.8 M cells of a demo orthophoto).
The compiled function releases the GIL, so that tiles run in parallel threads.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..compiled import Kernels
from ..geometry.raycast_numba import AVAILABLE

__all__ = [
    "AVAILABLE",
    "cell_pixels",
    "cell_stats",
    "remap_maps",
    "remap_maps_fixed",
    "valid_bounds",
]


def _cell_pixels(
    x0,
    y0,
    g,
    h,
    w,
    z,
    xc,
    yc,
    inv_cell,
    lat,
    step,
    focal,
    lens,
    lx0,
    ly0,
    inv_ls,
    nolens,
    out_col,
    out_row,
    out_z,
):
    """Fill out_col, out_row (image pixels, NaN: none) and out_z (surface height) of an h x w
    block of cells whose first centre is (x0, y0) and spacing g (see
    :func:`core.photo.orthophoto_cells.cell_pixels_numpy` for the arguments).

    Written for speed: the lattice is interpolated to each row once, then along the row one
    lattice interval after the other (no per-cell division or clamping); in each interval the
    heights, then the pixels (without a lens in a loop the compiler vectorises)."""
    rows, cols = z.shape
    ny, nx = lat.shape[0], lat.shape[1]
    cx0, ps, cy0, wpx, hpx = nolens[0], nolens[1], nolens[2], nolens[3], nolens[4]
    has_lens = lens.shape[0] > 1
    my, mx = lens.shape[0], lens.shape[1]
    nan = np.nan
    istep = int(step)
    inv_step = 1.0 / step
    k_px = focal / ps
    c_top = max(cols - 2, 0)
    c_max = float(cols - 1)
    rl = np.empty((nx, 6))
    dl = np.empty((nx, 6))
    for i in range(h):
        y = y0 - i * g
        v = (yc - y) * inv_cell
        if not (v >= 0.0 and v <= rows - 1):  # the whole row off the DSM
            for j in range(w):
                out_col[i, j] = nan
                out_row[i, j] = nan
                out_z[i, j] = nan
            continue
        r = min(int(v), max(rows - 2, 0))
        fv = v - r
        r1 = min(r + 1, rows - 1)
        fi = i / step
        ki = min(int(fi), ny - 2)
        ti = fi - ki
        # the lattice interpolated to this row once, and its steps between nodes
        for kj in range(nx):
            for k in range(6):
                rl[kj, k] = lat[ki, kj, k] * (1 - ti) + lat[ki + 1, kj, k] * ti
        for kj in range(nx - 1):
            for k in range(6):
                dl[kj, k] = rl[kj + 1, k] - rl[kj, k]
        for kj in range(nx - 1):
            j0 = kj * istep
            j1 = w if kj == nx - 2 else min(j0 + istep, w)
            a0, a1, a2 = rl[kj, 0], rl[kj, 1], rl[kj, 2]
            b0, b1, b2 = rl[kj, 3], rl[kj, 4], rl[kj, 5]
            da0, da1, da2 = dl[kj, 0], dl[kj, 1], dl[kj, 2]
            db0, db1, db2 = dl[kj, 3], dl[kj, 4], dl[kj, 5]
            # the heights first (gathers from the DSM; np.float64: numba's float() keeps
            # float32, whose differences lose up to 1e-7 m)
            for j in range(j0, j1):
                u = (x0 + j * g - xc) * inv_cell
                zz = nan
                if u >= 0.0 and u <= c_max:
                    c = min(int(u), c_top)
                    fu = u - c
                    c1 = min(c + 1, cols - 1)
                    z00 = np.float64(z[r, c])
                    z11 = np.float64(z[r1, c1])
                    if fu >= fv:
                        z01 = np.float64(z[r, c1])
                        zz = z00 + (z01 - z00) * fu + (z11 - z01) * fv
                    else:
                        z10 = np.float64(z[r1, c])
                        zz = z00 + (z11 - z10) * fu + (z10 - z00) * fv
                out_z[i, j] = zz
            zrow = out_z[i]
            crow = out_col[i]
            rrow = out_row[i]
            if not has_lens:
                # then the projection, q = a + z b with a and b interpolated between the
                # lattice nodes: no branch, so that the compiler vectorises the loop
                for j in range(j0, j1):
                    zz = zrow[j]
                    tj = (j - j0) * inv_step
                    q2 = (a2 + tj * da2) + zz * (b2 + tj * db2)
                    q0 = (a0 + tj * da0) + zz * (b0 + tj * db0)
                    q1 = (a1 + tj * da1) + zz * (b1 + tj * db1)
                    s = -1.0 / q2
                    cc = cx0 + k_px * q0 * s
                    rr = cy0 - k_px * q1 * s
                    # NaN fails every comparison: no height, no pixel; q2 < 0: in front
                    ok = (q2 < 0.0) & (cc >= 0.0) & (rr >= 0.0) & (cc <= wpx) & (rr <= hpx)
                    crow[j] = cc if ok else nan
                    rrow[j] = rr if ok else nan
                continue
            for j in range(j0, j1):  # with the lens lattice: measured pixels
                zz = zrow[j]
                col = nan
                row = nan
                tj = (j - j0) * inv_step
                q2 = (a2 + tj * da2) + zz * (b2 + tj * db2)
                if q2 < 0.0:
                    q0 = (a0 + tj * da0) + zz * (b0 + tj * db0)
                    q1 = (a1 + tj * da1) + zz * (b1 + tj * db1)
                    s = -1.0 / q2
                    lu = (focal * q0 * s - lx0) * inv_ls
                    lv = (focal * q1 * s - ly0) * inv_ls
                    if lu >= 0.0 and lv >= 0.0 and lu <= mx - 1 and lv <= my - 1:
                        lj = min(int(lu), mx - 2)
                        li = min(int(lv), my - 2)
                        su, sv = lu - lj, lv - li
                        cc = (lens[li, lj, 0] * (1 - su) + lens[li, lj + 1, 0] * su) * (1 - sv) + (
                            lens[li + 1, lj, 0] * (1 - su) + lens[li + 1, lj + 1, 0] * su
                        ) * sv
                        rr = (lens[li, lj, 1] * (1 - su) + lens[li, lj + 1, 1] * su) * (1 - sv) + (
                            lens[li + 1, lj, 1] * (1 - su) + lens[li + 1, lj + 1, 1] * su
                        ) * sv
                        if cc >= 0.0 and rr >= 0.0 and cc <= wpx and rr <= hpx:
                            col = cc
                            row = rr
                crow[j] = col
                rrow[j] = row


def _remap_maps(col, row, c0, r0, mapx, mapy):
    """OpenCV's float32 maps of an image window starting at (c0, r0): pixel centres at
    integers; -1 (outside) where there is no pixel. Returns the number of cells with one."""
    n = 0
    for i in range(col.shape[0]):
        for j in range(col.shape[1]):
            c = col[i, j]
            if math.isfinite(c):
                mapx[i, j] = c - (0.5 + c0)
                mapy[i, j] = row[i, j] - (0.5 + r0)
                n += 1
            else:
                mapx[i, j] = -1.0
                mapy[i, j] = -1.0
    return n


def _remap_maps_fixed(col, row, c0, r0, xy, alpha):
    """The same maps in OpenCV's fixed-point form (what cv2.remap makes of float maps before
    it interpolates, done here in the same pass): integer pixel (xy) and the 1/32 fraction
    index (alpha) of ``round(32 m)`` for the float32 map value m, rounding half to even as
    OpenCV's cvRound. Returns the number of cells with a pixel."""
    n = 0
    for i in range(col.shape[0]):
        for j in range(col.shape[1]):
            c = col[i, j]
            if math.isfinite(c):
                fx = np.float32(c - (0.5 + c0))
                fy = np.float32(row[i, j] - (0.5 + r0))
                n += 1
            else:
                fx = np.float32(-1.0)
                fy = np.float32(-1.0)
            x = int(np.rint(np.float64(fx) * 32.0))
            y = int(np.rint(np.float64(fy) * 32.0))
            xy[i, j, 0] = x >> 5
            xy[i, j, 1] = y >> 5
            alpha[i, j] = (y & 31) * 32 + (x & 31)
    return n


def _cell_stats(col, row, z, valid):
    """Fill ``valid`` (col finite); (valid cells, cells whose z is not finite, smallest col,
    largest col, smallest row, largest row of the valid cells) in one pass (infinite bounds
    when none)."""
    n = 0
    no_z = 0
    c_lo = r_lo = math.inf
    c_hi = r_hi = -math.inf
    for i in range(col.shape[0]):
        for j in range(col.shape[1]):
            c = col[i, j]
            ok = math.isfinite(c)
            valid[i, j] = ok
            if not math.isfinite(z[i, j]):
                no_z += 1
            if ok:
                n += 1
                r = row[i, j]
                c_lo = min(c_lo, c)
                c_hi = max(c_hi, c)
                r_lo = min(r_lo, r)
                r_hi = max(r_hi, r)
    return n, no_z, c_lo, c_hi, r_lo, r_hi


#: The jitted functions (each compiled at its first call, cached: core/compiled.py), with
#: numpy's error model: a float division by zero gives inf (checked after), with no test per
#: division that would keep the cell loop from being vectorised.
_compiled = Kernels(
    {"cells": _cell_pixels, "maps": _remap_maps, "fixed": _remap_maps_fixed, "stats": _cell_stats},
    error_model="numpy",
)


def cell_pixels(*args: Any) -> None:
    """Run the compiled loop (compiled at the first call, cached next to this module)."""
    if not AVAILABLE:
        raise RuntimeError("numba is not installed")
    _compiled("cells")(*args)


def remap_maps(col: np.ndarray, row: np.ndarray, c0: int, r0: int) -> tuple[np.ndarray, np.ndarray]:
    """float32 maps for cv2.remap of a window at (c0, r0) (see :func:`_remap_maps`)."""
    mapx = np.empty(col.shape, np.float32)
    mapy = np.empty(col.shape, np.float32)
    if AVAILABLE:
        _compiled("maps")(col, row, int(c0), int(r0), mapx, mapy)
    else:
        ok = np.isfinite(col)
        mapx[...] = np.where(ok, col - (0.5 + c0), -1.0)
        mapy[...] = np.where(ok, row - (0.5 + r0), -1.0)
    return mapx, mapy


def remap_maps_fixed(
    col: np.ndarray, row: np.ndarray, c0: int, r0: int
) -> tuple[np.ndarray, np.ndarray]:
    """OpenCV's fixed-point maps (CV_16SC2 pixel, CV_16UC1 fraction index) of a window at
    (c0, r0) (:func:`_remap_maps_fixed`); cv2.remap gives with them, for bilinear and cubic
    resampling, what it gives with the float maps of :func:`remap_maps`."""
    xy = np.empty((*col.shape, 2), np.int16)
    alpha = np.empty(col.shape, np.uint16)
    if AVAILABLE:
        _compiled("fixed")(col, row, int(c0), int(r0), xy, alpha)
        return xy, alpha
    import cv2

    mapx, mapy = remap_maps(col, row, c0, r0)
    return cv2.convertMaps(mapx, mapy, cv2.CV_16SC2)


def valid_bounds(col: np.ndarray, row: np.ndarray) -> tuple[int, float, float, float, float]:
    """(count, col min, col max, row min, row max) over the cells whose col is finite."""
    _, n, _, c_lo, c_hi, r_lo, r_hi = cell_stats(col, row, col)
    return (n, c_lo, c_hi, r_lo, r_hi)


def cell_stats(
    col: np.ndarray, row: np.ndarray, z: np.ndarray
) -> tuple[np.ndarray, int, int, float, float, float, float]:
    """(valid: col finite, its count, cells whose z is not finite, col min, col max, row min,
    row max over the valid cells) in one pass."""
    if AVAILABLE:
        valid = np.empty(col.shape, np.bool_)
        n, no_z, *bounds = _compiled("stats")(col, row, z, valid)
        return (valid, n, no_z, *bounds)
    valid = np.isfinite(col)
    no_z = int(np.count_nonzero(~np.isfinite(z)))
    if not valid.any():
        return valid, 0, no_z, math.inf, -math.inf, math.inf, -math.inf
    cv, rv = col[valid], row[valid]
    return (
        valid,
        int(valid.sum()),
        no_z,
        float(cv.min()),
        float(cv.max()),
        float(rv.min()),
        float(rv.max()),
    )
