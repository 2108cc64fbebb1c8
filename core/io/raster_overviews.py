"""Overview levels of a masked raster computed from its blocks while they are in memory, the
same pixels as GDAL's ``AVERAGE`` overviews of the written file (bit for bit).

GDAL (``BuildOverviews("AVERAGE")``) reads the whole written file back, decompresses it and
computes each level from the previous one. Here level 1 is computed from the rows of blocks as
they are written (:class:`OverviewBuilder`), each deeper level from the rows of the one above
as they are made, and the file gets them written directly (:mod:`core.io.raster`). The
arithmetic is GDAL's (3.x, ``GDALResampleChunk_AverageOrRMS`` with a mask): a level of
``n_dst = ceil(n_src / 2)`` cells along an axis takes for cell j the source interval
``[j r, (j + 1) r)``, ``r = n_src / n_dst`` (exactly 2 for an even ``n_src``, slightly less
for an odd one): whole pixels count 1, the pixels cut by the interval's ends their covered
fraction. Masked pixels count 0; the value is
``int(sum(w v) / sum(w) + 0.5)`` in double precision, summed in GDAL's order (along each row
first, then over the rows); a cell whose window has no valid pixel is 0 and masked.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..compiled import Kernels
from ..geometry.raycast_numba import AVAILABLE

__all__ = ["OverviewBuilder", "average_level", "level_windows"]

Windows = tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]]


def level_windows(n_src: int, n_dst: int) -> Windows:
    """GDAL's source windows of the ``n_dst`` cells of a level along one axis: first pixel,
    end pixel (exclusive), weight of the first pixel, weight of the last one.

    >>> a, b, wl, wr = level_windows(5, 3)
    >>> a.tolist(), b.tolist(), wl.round(4).tolist(), wr.round(4).tolist()
    ([0, 1, 3], [2, 4, 5], [1.0, 0.3333, 0.6667], [0.6667, 0.3333, 1.0])
    """
    r = n_src / n_dst
    j = np.arange(n_dst, dtype=np.float64)
    x0, x1 = j * r, (j + 1) * r
    a = (x0 + 1e-8).astype(np.int64)  # GDAL's epsilon against rounding
    b = np.ceil(x1 - 1e-8).astype(np.int64)
    b = np.minimum(np.where(b == a, b + 1, b), n_src)
    wl = np.where(b == a + 1, 1.0, 1.0 - (x0 - a))
    wr = 1.0 - (b - x1)
    if n_dst and (b - a).max() > 3:  # r <= 2: the kernels take at most 3 pixels
        raise ValueError(f"a level of {n_dst} cells from {n_src}: more than halving")
    return a, b, wl, wr


def _average_rows(src, mask, ya, yb, ywl, ywr, xa, xb, xwl, xwr, out, out_mask):
    """Cells (rows ya.size, cols xa.size) of a level from the source rows of ``src`` (rows,
    cols, bands: pixel-interleaved) and ``mask`` (rows, cols) into ``out`` (rows, cols, bands);
    ya, yb relative to src's first row; windows of at most 3 pixels per axis (r <= 2). Each
    band's sums in GDAL's order: along a row (first pixel weighted, middle one, last one
    weighted), then these line sums weighted over the rows. The line sums of a source row
    are made once for the (one or two) cells' rows that share it, a few rows at a time."""
    nb = src.shape[2]
    oh, ow = ya.shape[0], xa.shape[0]
    pairs = src.shape[1] == 2 * ow
    chunk = 16  # cells' rows per pass: their line sums stay in the cache
    line = np.empty((2 * chunk + 1, ow, nb))
    wline = np.empty((2 * chunk + 1, ow))
    cline = np.empty((2 * chunk + 1, ow), np.int64)
    for i0 in range(0, oh, chunk):
        i1 = min(i0 + chunk, oh)
        s0 = ya[i0]
        for y in range(s0, yb[i1 - 1]):  # the line sums: masked terms are exact zeros
            k = y - s0
            if pairs:  # every window 2 whole pixels along the row (an even width)
                for j in range(ow):
                    m0 = mask[y, 2 * j] != 0
                    m2 = mask[y, 2 * j + 1] != 0
                    wline[k, j] = (1.0 if m0 else 0.0) + (1.0 if m2 else 0.0)
                    cline[k, j] = np.int64(m0) + np.int64(m2)
                    for bb in range(nb):
                        v0 = np.float64(src[y, 2 * j, bb])
                        v2 = np.float64(src[y, 2 * j + 1, bb])
                        line[k, j, bb] = (v0 if m0 else 0.0) + (v2 if m2 else 0.0)
                continue
            for j in range(ow):
                x0 = xa[j]
                nx = xb[j] - x0
                x2 = x0 + nx - 1
                wl = xwl[j]
                wr = xwr[j]
                m0 = mask[y, x0] != 0
                m1 = nx == 3 and mask[y, x0 + 1] != 0
                m2 = nx >= 2 and mask[y, x2] != 0
                wline[k, j] = (wl if m0 else 0.0) + (1.0 if m1 else 0.0) + (wr if m2 else 0.0)
                cline[k, j] = int(m0) + int(m1) + int(m2)
                for bb in range(nb):
                    line[k, j, bb] = (
                        (src[y, x0, bb] * wl if m0 else 0.0)
                        + (src[y, x0 + 1, bb] if m1 else 0.0)
                        + (src[y, x2, bb] * wr if m2 else 0.0)
                    )
        for i in range(i0, i1):  # then over the rows
            k0 = ya[i] - s0
            ny = yb[i] - ya[i]
            w0 = ywl[i]
            w2 = ywr[i]
            for j in range(ow):
                cnt = cline[k0, j]
                wt = wline[k0, j] * w0
                if ny == 2:
                    cnt += cline[k0 + 1, j]
                    wt += wline[k0 + 1, j] * w2
                elif ny == 3:
                    cnt += cline[k0 + 1, j] + cline[k0 + 2, j]
                    wt += wline[k0 + 1, j]
                    wt += wline[k0 + 2, j] * w2
                out_mask[i, j] = cnt > 0
                for bb in range(nb):
                    tot = line[k0, j, bb] * w0
                    if ny == 2:
                        tot += line[k0 + 1, j, bb] * w2
                    elif ny == 3:
                        tot += line[k0 + 1, j, bb]
                        tot += line[k0 + 2, j, bb] * w2
                    out[i, j, bb] = 0 if cnt == 0 else math.floor(tot / wt + 0.5)


def _average_rows_2x2(src, mask, out, out_mask):
    """:func:`_average_rows` where every window is 2 x 2 whole pixels (even sides: r = 2);
    in integers, ``(sum + n // 2) // n`` equals GDAL's ``int(sum / n + 0.5)`` for n <= 4."""
    nb = src.shape[2]
    for i in range(out_mask.shape[0]):
        y = 2 * i
        for j in range(out_mask.shape[1]):
            x = 2 * j
            m00, m01 = mask[y, x] != 0, mask[y, x + 1] != 0
            m10, m11 = mask[y + 1, x] != 0, mask[y + 1, x + 1] != 0
            cnt = int(m00) + int(m01) + int(m10) + int(m11)
            out_mask[i, j] = cnt > 0
            half = cnt // 2
            for bb in range(nb):
                tot = 0
                if m00:
                    tot += int(src[y, x, bb])
                if m01:
                    tot += int(src[y, x + 1, bb])
                if m10:
                    tot += int(src[y + 1, x, bb])
                if m11:
                    tot += int(src[y + 1, x + 1, bb])
                out[i, j, bb] = (tot + half) // cnt if cnt else 0


def _average_rows_numpy(src, mask, ya, yb, ywl, ywr, xa, xb, xwl, xwr, out, out_mask):
    """The same as :func:`_average_rows`, vectorised (numba not installed): windows span at
    most 3 pixels per axis (r <= 2), so each sum has at most three terms, added in GDAL's
    order (masked terms are exact zeros)."""
    src, out = np.moveaxis(src, 2, 0), np.moveaxis(out, 2, 0)  # (bands, rows, cols) views
    w_src = src.shape[2]
    m = mask.astype(bool)
    nx, ny = xb - xa, yb - ya
    xm, ym = np.minimum(xa + 1, w_src - 1), np.minimum(ya + 1, src.shape[1] - 1)

    def lines(a):  # along each row: left * wl + middle + right * wr
        t = a[..., xa] * xwl
        t = np.where(nx == 3, t + a[..., xm], t)
        return np.where(nx >= 2, t + a[..., xb - 1] * xwr, t)

    def rows(a):  # over the rows, the same
        t = 0.0 + a[..., ya, :] * ywl[:, None]
        t = np.where((ny == 3)[:, None], t + a[..., ym, :], t)
        return np.where((ny >= 2)[:, None], t + a[..., yb - 1, :] * ywr[:, None], t)

    mi = m.astype(np.int64)
    c = mi[:, xa] + np.where(nx >= 2, mi[:, xb - 1], 0) + np.where(nx == 3, mi[:, xm], 0)
    cnt = (
        c[ya] + np.where((ny >= 2)[:, None], c[yb - 1], 0) + np.where((ny == 3)[:, None], c[ym], 0)
    )
    tot = rows(lines(np.where(m, src, 0).astype(np.float64)))
    wt = rows(lines(m.astype(np.float64)))
    with np.errstate(invalid="ignore", divide="ignore"):
        val = np.floor(tot / wt + 0.5)
    out[...] = np.where(cnt > 0, val, 0).astype(out.dtype)
    out_mask[...] = cnt > 0


#: The jitted level kernels (compiled at their first call, cached: core/compiled.py).
_compiled = Kernels({"rows": _average_rows, "2x2": _average_rows_2x2})


def _run_kernel(backend: str, src, mask, ya, yb, ywl, ywr, xa, xb, xwl, xwr, out, out_mask) -> None:
    """The level's cells from the source rows (:func:`_average_rows` arguments), compiled
    when numba is there (the 2 x 2 kernel when every window is 2 x 2 whole pixels)."""
    if backend == "numpy" or (backend == "auto" and not AVAILABLE):
        _average_rows_numpy(src, mask, ya, yb, ywl, ywr, xa, xb, xwl, xwr, out, out_mask)
        return
    two = ya.size == 0 or (
        np.all(yb - ya == 2)
        and ya[0] == 0
        and np.all(np.diff(ya) == 2)
        and np.all(ywl == 1.0)
        and np.all(ywr == 1.0)
    )
    two = two and (
        np.all(xb - xa == 2)
        and xa[0] == 0
        and np.all(np.diff(xa) == 2)
        and np.all(xwl == 1.0)
        and np.all(xwr == 1.0)
    )
    if two:
        _compiled("2x2")(src, mask, out, out_mask)
    else:
        _compiled("rows")(src, mask, ya, yb, ywl, ywr, xa, xb, xwl, xwr, out, out_mask)


def average_level(
    data: NDArray, mask: NDArray[np.bool_], backend: str = "auto"
) -> tuple[NDArray, NDArray[np.bool_]]:
    """The next overview level (factor 2, GDAL's AVERAGE honouring the mask) of ``data``
    (bands, rows, cols) with ``mask`` (rows, cols) True where valid: (bands, ceil(rows / 2),
    ceil(cols / 2)) and its mask. The data are a view of a pixel-interleaved array (fastest
    when ``data`` is one too: ``np.moveaxis(data, 0, -1)`` C-contiguous).

    >>> d = np.array([[[10, 20, 7], [30, 40, 9]]], np.uint8)
    >>> m = np.array([[True, True, True], [True, False, False]])
    >>> out, om = average_level(d, m)
    >>> out.tolist(), om.tolist()
    ([[[20, 11]]], [[True, True]])
    """
    nb, h, w = data.shape
    oh, ow = -(-h // 2), -(-w // 2)
    out = np.empty((oh, ow, nb), data.dtype)
    out_mask = np.empty((oh, ow), np.bool_)
    ya, yb, ywl, ywr = level_windows(h, oh)
    xa, xb, xwl, xwr = level_windows(w, ow)
    _run_kernel(
        backend,
        np.ascontiguousarray(np.moveaxis(data, 0, -1)),
        np.asarray(mask, np.uint8),
        ya,
        yb,
        ywl,
        ywr,
        xa,
        xb,
        xwl,
        xwr,
        out,
        out_mask,
    )
    return np.moveaxis(out, 2, 0), out_mask


class OverviewBuilder:
    """The overview levels of a raster being written block by block.

    :meth:`add` takes each block as it is written; level 1 is computed as soon as the rows
    its windows need are complete (the blocks' rows in any order within a band of rows, the
    bands of rows from top to bottom), so only a band of full-resolution rows is held, and
    the levels (level 1 a quarter of the raster); each deeper level grows the same way from
    the rows of the one above as they are made. A block that comes back above the rows already
    consumed makes :meth:`add` return False: the caller then lets GDAL build the overviews.
    """

    def __init__(
        self, bands: int, height: int, width: int, dtype: Any, levels: int, backend: str = "auto"
    ) -> None:
        self.bands, self.height, self.width = int(bands), int(height), int(width)
        self.dtype = np.dtype(dtype)
        self.n_levels = int(levels)
        self.backend = backend
        oh, ow = -(-self.height // 2), -(-self.width // 2)
        self._lv1 = np.zeros((oh, ow, self.bands), self.dtype)  # pixel-interleaved
        self.lv1 = np.moveaxis(self._lv1, 2, 0)
        self.lv1_mask = np.zeros((oh, ow), np.bool_)
        self._y = level_windows(self.height, oh)
        self._x = level_windows(self.width, ow)
        self._buf: NDArray | None = None
        self._mbuf: NDArray | None = None
        self._filled = np.zeros(0, np.int64)
        self._base = 0  # raster row of the buffer's first row
        self._next = 0  # next row of level 1 to compute
        self.ok = True
        # the next level grown from level 1's rows as they are made (GDAL makes each level
        # from the previous), so that none is left for the end
        self._child = (
            OverviewBuilder(self.bands, oh, ow, self.dtype, self.n_levels - 1, backend)
            if self.n_levels > 1
            else None
        )

    def _room(self, rows: int) -> None:
        """Make the buffer hold rows [base, base + rows)."""
        if self._buf is not None and self._buf.shape[1] >= rows:
            return
        cap = max(rows, 2 * (self._buf.shape[1] if self._buf is not None else 0))
        # pixel-interleaved (as the blocks usually come, and as GDAL stores them); the
        # (bands, rows, cols) view of it
        buf = np.moveaxis(np.zeros((cap, self.width, self.bands), self.dtype), 2, 0)
        mbuf = np.zeros((cap, self.width), np.uint8)
        filled = np.zeros(cap, np.int64)
        if self._buf is not None:
            n = self._buf.shape[1]
            buf[:, :n], mbuf[:n], filled[:n] = self._buf, self._mbuf, self._filled
        self._buf, self._mbuf, self._filled = buf, mbuf, filled

    def add(self, block: NDArray, mask: NDArray[np.bool_] | None, col0: int, row0: int) -> bool:
        """Take a (bands, rows, cols) block written at (col0, row0) with its mask (None: all
        valid). False when the block cannot be followed (see the class)."""
        if not self.ok:
            return False
        _, h, w = block.shape
        if row0 < self._base:
            self.ok = False
            return False
        r = row0 - self._base
        self._room(r + h)
        assert self._buf is not None and self._mbuf is not None
        self._buf[:, r : r + h, col0 : col0 + w] = block
        self._mbuf[r : r + h, col0 : col0 + w] = 1 if mask is None else mask
        self._filled[r : r + h] += w
        if self._filled[r : r + h].max() > self.width:  # cells written twice: GDAL's way
            self.ok = False
            return False
        self._advance()
        return True

    def _advance(self) -> None:
        assert self._buf is not None and self._mbuf is not None
        incomplete = np.flatnonzero(self._filled < self.width)
        complete = int(incomplete[0]) if incomplete.size else self._filled.size
        ya, yb, ywl, ywr = self._y
        end = int(np.searchsorted(yb, self._base + complete, side="right"))
        if end <= self._next:
            return
        i0 = self._next
        s0 = int(ya[i0]) - self._base
        _run_kernel(
            self.backend,
            np.moveaxis(self._buf, 0, -1)[s0:complete],
            self._mbuf[s0:complete],
            ya[i0:end] - ya[i0],
            yb[i0:end] - ya[i0],
            ywl[i0:end],
            ywr[i0:end],
            *self._x,
            self._lv1[i0:end],
            self.lv1_mask[i0:end],
        )
        self._next = end
        if self._child is not None:
            self._child.add(self.lv1[:, i0:end], self.lv1_mask[i0:end], 0, i0)
        if end >= ya.size:
            return
        drop = int(ya[end]) - self._base  # rows no window still needs
        # the rows still needed (at most 2 complete ones, then any partly written) move to
        # the top; the rows below are written again before they are used
        written = np.flatnonzero(self._filled)
        last = int(written[-1]) + 1 if written.size else 0
        if last > drop:
            self._buf[:, : last - drop] = self._buf[:, drop:last].copy()
            self._mbuf[: last - drop] = self._mbuf[drop:last].copy()
            self._filled[: last - drop] = self._filled[drop:last]
        self._filled[max(last - drop, 0) :] = 0
        self._base += drop

    def levels(self) -> list[tuple[NDArray, NDArray[np.bool_]]]:
        """Every level (data, mask), level 1 first, each from the previous (GDAL's order);
        every row must have been written."""
        if not self.ok or self._next < self.lv1_mask.shape[0]:
            raise ValueError("the overview levels are incomplete: not every row was written")
        out = [(self.lv1, self.lv1_mask)]
        return out + (self._child.levels() if self._child is not None else [])
