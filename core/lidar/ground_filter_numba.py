"""The ground filter's per-point passes compiled with numba: each pass reads the coordinates
straight from the point records' integers (``x = X * scale + offset``, the LAS rule) and does
its work in one loop, without the float64 x, y, z arrays and the full-size temporaries of the
numpy back end of :mod:`core.lidar.ground_filter`:

- :func:`cells`: cell index, z relative to the lowest point (float32) and the minimum grid of
  the candidates, in one pass;
- :func:`low_pass`: one pass of the low-outlier test against the grid references, marking the
  new low outliers and building the minimum grid without them;
- :func:`classify`: height above the DTM (bilinear between cell centres), the slope-dependent
  tolerance and the ground flag (and the height when asked).

numba is an optional dependency: :data:`AVAILABLE` tells whether it imports, and
:func:`core.lidar.ground_filter.ground_filter` falls back to numpy without it. Both back ends
give the same bits: every quantity is computed with the same operations in the same order and
precision as the numpy code (float64 coordinates and cell indices, float32 heights and
bilinear weights, no fused multiply-add); tests/core/test_ground_filter_backends.py compares
them array by array.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

try:  # pragma: no cover - depends on the environment
    import numba

    AVAILABLE = True
except Exception:  # ImportError, or a numba built against another numpy
    numba = None
    AVAILABLE = False

__all__ = ["AVAILABLE", "bounds", "cells", "classify", "low_pass"]


def _cells_kernel(X, Y, Z, sx, ox, sy, oy, sz, oz, x0, y_top, inv, cols, rows, z0, cand,
                  use_cand, lo, flat, zr, zmin):  # fmt: skip
    """Points lo .. lo + len(X) - 1: flat cell index, float32 z - z0, and the lowest candidate
    of each cell into ``zmin`` (flat, +inf where none)."""
    for i in range(X.shape[0]):
        x = X[i] * sx + ox
        y = Y[i] * sy + oy
        z = Z[i] * sz + oz
        col = np.int64((x - x0) * inv)
        row = np.int64((y_top - y) * inv)
        if col < 0:
            col = 0
        elif col > cols - 1:
            col = cols - 1
        if row < 0:
            row = 0
        elif row > rows - 1:
            row = rows - 1
        f = row * cols + col
        j = lo + i
        flat[j] = f
        h = np.float32(z - z0)
        zr[j] = h
        if (not use_cand or cand[j]) and h < zmin[f]:
            zmin[f] = h


def _bounds_kernel(X, Y, Z, out):
    """Smallest and largest X, Y, Z into out (3, 2), updated (one pass over the records)."""
    for i in range(X.shape[0]):
        for k, v in ((0, X[i]), (1, Y[i]), (2, Z[i])):
            if v < out[k, 0]:
                out[k, 0] = v
            if v > out[k, 1]:
                out[k, 1] = v


def _low_pass_kernel(flat, zr, cand, use_cand, low, reference, around, use_around, zmin):
    """One low-outlier pass: a candidate not yet low is low when below its cell's reference
    (or the ring's, where ``use_around``); the others build the new minimum grid ``zmin``
    (flat, +inf on entry). Returns the number of new low outliers."""
    count = 0
    for i in range(flat.shape[0]):
        if low[i] or (use_cand and not cand[i]):
            continue  # +inf in the numpy back end: never below a reference, never a minimum
        f = flat[i]
        z = zr[i]
        if z < reference[f] or (use_around and z < around[f]):
            low[i] = True
            count += 1
        elif z < zmin[f]:
            zmin[f] = z
    return count


def _classify_kernel(X, Y, sx, ox, sy, oy, x0, y_top, inv, cols, rows, lo, flat, zr, dtm, thr,
                     low, cand, use_cand, nodata, ground, hag, want_hag):  # fmt: skip
    """Points lo .. lo + len(X) - 1: ground when |z - DTM| <= the cell's tolerance (the DTM
    bilinear between cell centres, as Grid.bilinear computes it, in float32), never when low
    or not a candidate; the height (NaN where the DTM is nodata) when ``want_hag``."""
    one = np.float32(1.0)
    zero = np.float32(0.0)
    fc_max = np.float32(cols - 1)
    fr_max = np.float32(rows - 1)
    c_max = max(cols - 2, 0)
    r_max = max(rows - 2, 0)
    dc = 1 if cols > 1 else 0
    dr = cols if rows > 1 else 0
    nan = np.float32(np.nan)
    for i in range(X.shape[0]):
        j = lo + i
        x = X[i] * sx + ox
        y = Y[i] * sy + oy
        fc = np.float32((x - x0) * inv - 0.5)
        fr = np.float32((y_top - y) * inv - 0.5)
        fc = min(max(fc, zero), fc_max)
        fr = min(max(fr, zero), fr_max)
        c0 = min(np.int64(fc), c_max)
        r0 = min(np.int64(fr), r_max)
        fc = fc - np.float32(c0)  # exact, as numpy's float64 difference cast back
        fr = fr - np.float32(r0)
        k = r0 * cols + c0
        top = dtm[k] * (one - fc) + dtm[k + dc] * fc
        bottom = dtm[k + dr] * (one - fc) + dtm[k + dr + dc] * fc
        h = zr[j] - (top * (one - fr) + bottom * fr)
        f = flat[j]
        ground[j] = abs(h) <= thr[f] and not low[j] and (not use_cand or cand[j])
        if want_hag:
            hag[j] = nan if nodata[f] else h


_COMPILED: dict[str, Callable[..., Any]] = {}


def _compiled(name: str) -> Callable[..., Any]:
    """The jitted function (compiled at its first call for each argument type, cached next to
    this module; no kernel calls another, so the cache is not tied to the import name)."""
    if name not in _COMPILED:
        func = {"cells": _cells_kernel, "low_pass": _low_pass_kernel,
                "classify": _classify_kernel, "bounds": _bounds_kernel}[name]  # fmt: skip
        _COMPILED[name] = numba.njit(cache=True, nogil=True)(func)
    return _COMPILED[name]


_NO_BOOL = np.zeros(0, dtype=bool)
_NO_FLOAT = np.zeros(0, dtype=np.float32)


def cells(part: Any, grid: Any, z0: float, candidate: Any, lo: int, flat: Any, zr: Any,
          zmin: Any) -> None:  # fmt: skip
    """:func:`_cells_kernel` on one part ``(X, Y, Z, scales, offsets)`` of the points."""
    X, Y, Z, (sx, sy, sz), (ox, oy, oz) = part
    use = candidate is not None
    _compiled("cells")(X, Y, Z, float(sx), float(ox), float(sy), float(oy), float(sz), float(oz),
                       float(grid.x0), float(grid.y_top), 1.0 / grid.cell, int(grid.cols),
                       int(grid.rows), float(z0), candidate if use else _NO_BOOL, use, int(lo),
                       flat, zr, zmin)  # fmt: skip


def low_pass(flat: Any, zr: Any, candidate: Any, low: Any, reference: Any, around: Any,
             zmin: Any) -> int:  # fmt: skip
    """:func:`_low_pass_kernel` over every point; returns the number of new low outliers."""
    use = candidate is not None
    ring = around is not None
    kernel = _compiled("low_pass")
    return int(kernel(flat, zr, candidate if use else _NO_BOOL, use, low, reference,
                      around if ring else _NO_FLOAT, ring, zmin))  # fmt: skip


def classify(part: Any, grid: Any, lo: int, flat: Any, zr: Any, dtm: Any, thr: Any, low: Any,
             candidate: Any, nodata: Any, ground: Any, hag: Any) -> None:  # fmt: skip
    """:func:`_classify_kernel` on one part ``(X, Y, Z, scales, offsets)`` of the points."""
    X, Y, _, (sx, sy, _), (ox, oy, _) = part
    use = candidate is not None
    want = hag is not None
    _compiled("classify")(X, Y, float(sx), float(ox), float(sy), float(oy), float(grid.x0),
                          float(grid.y_top), 1.0 / grid.cell, int(grid.cols), int(grid.rows),
                          int(lo), flat, zr, dtm, thr, low, candidate if use else _NO_BOOL, use,
                          nodata, ground, hag if want else _NO_FLOAT, want)  # fmt: skip


def bounds(chunks: Any) -> Any:
    """(3, 2) smallest and largest integer X, Y, Z over chunks of (X, Y, Z) (int64)."""
    out = np.empty((3, 2), dtype=np.int64)
    out[:, 0] = np.iinfo(np.int64).max
    out[:, 1] = np.iinfo(np.int64).min
    for X, Y, Z in chunks:
        _compiled("bounds")(X, Y, Z, out)
    return out
