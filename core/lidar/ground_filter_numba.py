"""The ground filter's per-point passes compiled with numba: each pass reads the coordinates
straight from the point records' integers (``x = X * scale + offset``, the LAS rule) and does
its work in one loop, without the float64 x, y, z arrays and the full-size temporaries of the
numpy back end of :mod:`core.lidar.ground_filter`:

- :func:`cells`: cell index, z relative to the lowest point (float32) and the minimum grid of
  the candidates, in one pass;
- :func:`low_pass`: one pass of the low-outlier test against the grid references, marking the
  new low outliers and building the minimum grid without them;
- :func:`classify`: height above the DTM (bilinear between cell centres), the slope-dependent
  tolerance and the ground flag (and the height when asked);
- :func:`cells_all`, :func:`low_pass_all`, :func:`classify_all`: the same passes on all
  cores (each thread a share of the points, with its own minimum grid where one is built;
  the grids' minimum is the same whatever the order);
- :func:`opening`: the grey-level opening of a grid by a flat disk (or square), the same
  values as OpenCV's ``morphologyEx`` with the same kernel at a fraction of its cost, on all
  cores (:func:`rectangles` says how).

numba is an optional dependency: :data:`AVAILABLE` tells whether it imports, and
:func:`core.lidar.ground_filter.ground_filter` falls back to numpy without it. Both back ends
give the same bits: every quantity is computed with the same operations in the same order and
precision as the numpy code (float64 coordinates and cell indices, float32 heights and
bilinear weights, no fused multiply-add); tests/core/test_ground_filter_backends.py compares
them array by array.
"""

from __future__ import annotations

import threading
from functools import partial
from typing import Any, Callable

import numpy as np

from ..compiled import Kernels

numba: Any  # the module, or None without it
try:  # pragma: no cover - depends on the environment
    import numba

    AVAILABLE = True
except Exception:  # ImportError, or a numba built against another numpy
    numba = None
    AVAILABLE = False

__all__ = [
    "AVAILABLE",
    "bounds",
    "cells",
    "cells_all",
    "classify",
    "classify_all",
    "low_pass",
    "low_pass_all",
    "opening",
    "rectangles",
]


def _cells_kernel(
    X,
    Y,
    Z,
    sx,
    ox,
    sy,
    oy,
    sz,
    oz,
    x0,
    y_top,
    inv,
    cols,
    rows,
    z0,
    cand,
    use_cand,
    lo,
    flat,
    zr,
    zmin,
):
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


def _classify_kernel(
    X,
    Y,
    sx,
    ox,
    sy,
    oy,
    x0,
    y_top,
    inv,
    cols,
    rows,
    lo,
    flat,
    zr,
    dtm,
    thr,
    low,
    cand,
    use_cand,
    nodata,
    ground,
    hag,
    want_hag,
):
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


def _rect_union_kernel(src, out, ws, ds, sign, y_first, y_stop):
    """``out`` = the minimum (``sign`` 1: erosion) or maximum (``sign`` -1: dilation, as the
    minimum of ``-src``, negated back) of ``src`` over the union of the rectangles
    ``|dx| <= ws[k], |dy| <= ds[k]`` centred on each cell, as OpenCV's erode and dilate with
    their default border. ``ws`` ascending, ``ds`` descending.

    Horner's scheme over the rectangles (H_w: horizontal minimum of half-width w, V_d:
    vertical of half-height d; H distributes over the minimum and H_a H_b = H_(a+b))::

        out = H_w0(min(V_d0, H_(w1-w0)(min(V_d1, ... H_(wK-wK-1)(V_dK)))))

    Every step keeps to one row, so each output row is made on its own in four row buffers
    that stay in the L1 cache: V_d grows by a row pair at a time (one pass), H by steps
    ``g[x] = min(f[x - s], f[x + s])`` with s up to the half-width so far (the first also
    keeps ``f[x]``; indices clipped to the grid, which keeps the window exact at the borders),
    the minimum with V fused into the last step of each growth: about r + K + log2 passes
    per row for a disk of radius r (OpenCV: its area, 3 r^2 minima per cell). Output rows
    ``y_first`` to ``y_stop - 1`` (the threads of :func:`morph` share the rows out). Cells
    outside the grid are ignored, except that an infinite result where the element reaches
    outside becomes the largest finite float32, as OpenCV's border gives."""
    rows, cols = src.shape
    nk = ws.shape[0]
    sg = np.float32(sign)
    big = np.float32(3.4028234663852886e38)  # FLT_MAX
    wmax = ws[nk - 1]
    dmax = ds[0]
    last = cols - 1
    v = np.empty(cols, dtype=np.float32)
    a = np.empty(cols, dtype=np.float32)
    b = np.empty(cols, dtype=np.float32)
    w = np.empty(cols, dtype=np.float32)
    for y in range(y_first, y_stop):
        sy = src[y]
        for x in range(cols):
            v[x] = sy[x] * sg
        dcur = 0
        for kk in range(nk - 1, -2, -1):
            if kk >= 0:
                while dcur < ds[kk]:  # V grows to the rectangle's half-height
                    dcur += 1
                    up = y - dcur >= 0
                    down = y + dcur < rows
                    # into another buffer: an update in place is not vectorised
                    if up and down:
                        s1 = src[y - dcur]
                        s2 = src[y + dcur]
                        for x in range(cols):
                            p = s1[x] * sg
                            q = s2[x] * sg
                            r = v[x]
                            p = p if p < q else q
                            w[x] = p if p < r else r
                        v, w = w, v
                    elif up or down:
                        s1 = src[y - dcur] if up else src[y + dcur]
                        for x in range(cols):
                            p = s1[x] * sg
                            r = v[x]
                            w[x] = p if p < r else r
                        v, w = w, v
                if kk == nk - 1:
                    a[:] = v
                    continue
                grow = ws[kk + 1] - ws[kk]
            else:
                grow = ws[0]
            done = 0
            while done < grow:  # b = one step of a's growth; then swap
                s = 1 if done == 0 else min(done, grow - done)
                first = done == 0
                withv = kk >= 0 and done + s == grow
                # the two borders (indices clipped), then the inner part
                for lo, hi in ((0, min(s, cols)), (max(cols - s, s), cols)):
                    for x in range(lo, hi):
                        p = a[max(x - s, 0)]
                        q = a[min(x + s, last)]
                        p = p if p < q else q
                        if first and a[x] < p:
                            p = a[x]
                        if withv and v[x] < p:
                            p = v[x]
                        b[x] = p
                # the inner part through views indexed from 0: indices the compiler
                # knows are not negative, so the loops are vectorised
                n = max(cols - 2 * s, 0)
                al = a[0:n]
                ar = a[2 * s : 2 * s + n]
                am = a[s : s + n]
                vm = v[s : s + n]
                bm = b[s : s + n]
                if first and withv:
                    for x in range(n):
                        p = al[x]
                        q = ar[x]
                        r = am[x]
                        t = vm[x]
                        p = p if p < q else q
                        r = r if r < t else t
                        bm[x] = p if p < r else r
                elif first or withv:  # one more operand: a's own cell or V
                    c = am if first else vm
                    for x in range(n):
                        p = al[x]
                        q = ar[x]
                        r = c[x]
                        p = p if p < q else q
                        bm[x] = p if p < r else r
                else:
                    for x in range(n):
                        p = al[x]
                        q = ar[x]
                        bm[x] = p if p < q else q
                a, b = b, a
                done += s
            if kk >= 0 and grow == 0:  # (not for a union of distinct widths)
                for x in range(cols):
                    p = v[x]
                    q = a[x]
                    b[x] = p if p < q else q
                a, b = b, a
        # OpenCV pads the grid with the largest finite float32 (the smallest for
        # dilation), not infinity: where the element reaches outside, an infinite
        # result is that.
        oy = out[y]
        for x in range(cols):
            oy[x] = a[x] * sg
        if y < dmax or y >= rows - dmax:  # the element reaches above or below
            for x in range(cols):
                if a[x] > big:
                    oy[x] = big * sg
        else:  # left and right
            for x in range(min(wmax, cols)):
                if a[x] > big:
                    oy[x] = big * sg
            for x in range(max(cols - wmax, wmax), cols):
                if a[x] > big:
                    oy[x] = big * sg


_POOL: list[Any] = []
_POOL_LOCK = threading.Lock()


#: The jitted functions (each compiled at its first call, cached: core/compiled.py).
_compiled = Kernels(
    {
        "cells": _cells_kernel,
        "low_pass": _low_pass_kernel,
        "classify": _classify_kernel,
        "bounds": _bounds_kernel,
        "rect_union": _rect_union_kernel,
    }
)


_NO_BOOL = np.zeros(0, dtype=bool)
_NO_FLOAT = np.zeros(0, dtype=np.float32)


def cells(
    part: Any, grid: Any, z0: float, candidate: Any, lo: int, flat: Any, zr: Any, zmin: Any
) -> None:
    """:func:`_cells_kernel` on one part ``(X, Y, Z, scales, offsets)`` of the points."""
    X, Y, Z, (sx, sy, sz), (ox, oy, oz) = part
    use = candidate is not None
    _compiled("cells")(
        X,
        Y,
        Z,
        float(sx),
        float(ox),
        float(sy),
        float(oy),
        float(sz),
        float(oz),
        float(grid.x0),
        float(grid.y_top),
        1.0 / grid.cell,
        int(grid.cols),
        int(grid.rows),
        float(z0),
        candidate if use else _NO_BOOL,
        use,
        int(lo),
        flat,
        zr,
        zmin,
    )


def low_pass(
    flat: Any, zr: Any, candidate: Any, low: Any, reference: Any, around: Any, zmin: Any
) -> int:
    """:func:`_low_pass_kernel` over every point; returns the number of new low outliers."""
    use = candidate is not None
    ring = around is not None
    kernel = _compiled("low_pass")
    return int(
        kernel(
            flat,
            zr,
            candidate if use else _NO_BOOL,
            use,
            low,
            reference,
            around if ring else _NO_FLOAT,
            ring,
            zmin,
        )
    )


def classify(
    part: Any,
    grid: Any,
    lo: int,
    flat: Any,
    zr: Any,
    dtm: Any,
    thr: Any,
    low: Any,
    candidate: Any,
    nodata: Any,
    ground: Any,
    hag: Any,
) -> None:
    """:func:`_classify_kernel` on one part ``(X, Y, Z, scales, offsets)`` of the points."""
    X, Y, _, (sx, sy, _), (ox, oy, _) = part
    use = candidate is not None
    want = hag is not None
    _compiled("classify")(
        X,
        Y,
        float(sx),
        float(ox),
        float(sy),
        float(oy),
        float(grid.x0),
        float(grid.y_top),
        1.0 / grid.cell,
        int(grid.cols),
        int(grid.rows),
        int(lo),
        flat,
        zr,
        dtm,
        thr,
        low,
        candidate if use else _NO_BOOL,
        use,
        nodata,
        ground,
        hag if want else _NO_FLOAT,
        want,
    )


def bounds(chunks: Any) -> Any:
    """(3, 2) smallest and largest integer X, Y, Z over chunks of (X, Y, Z) (int64)."""
    out = np.empty((3, 2), dtype=np.int64)
    out[:, 0] = np.iinfo(np.int64).max
    out[:, 1] = np.iinfo(np.int64).min
    for X, Y, Z in chunks:
        _compiled("bounds")(X, Y, Z, out)
    return out


def rectangles(kernel: Any) -> tuple[Any, Any] | None:
    """A flat structuring element (OpenCV's uint8 kernel, odd sides, anchored at its centre)
    as the union of the rectangles ``|dx| <= ws[k], |dy| <= ds[k]`` (``ws`` ascending, ``ds``
    descending, int64), or None when it is not such a union (each row a run centred on the
    column of the anchor, the rows symmetric about it and no wider than the rows nearer it:
    disks as ``cv2.getStructuringElement(MORPH_ELLIPSE)`` draws them, and squares, are).

    Examples
    --------
    >>> import cv2
    >>> [a.tolist() for a in rectangles(cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (7, 7)))]
    [[0, 2, 3], [3, 2, 1]]
    """
    k = np.asarray(kernel) != 0
    rows, cols = k.shape
    if rows % 2 == 0 or cols % 2 == 0 or not k[rows // 2, cols // 2]:
        return None
    ry, rx = rows // 2, cols // 2
    half: list[int] = []
    for dy in range(ry + 1):
        row = k[ry + dy]
        if not np.array_equal(row, k[ry - dy]):
            return None
        if not row.any():
            break
        w = rx - int(np.argmax(row))
        expected = np.zeros(cols, dtype=bool)
        expected[rx - w : rx + w + 1] = True
        if not np.array_equal(row, expected) or (half and w > half[-1]):
            return None
        half.append(w)
    if k[ry + len(half) :].any() or k[: ry - len(half) + 1].any():
        return None
    ws = sorted(set(half))
    ds = [max(dy for dy, w in enumerate(half) if w >= wk) for wk in ws]
    return np.array(ws, dtype=np.int64), np.array(ds, dtype=np.int64)


def _threads() -> int:
    """Threads of the grid kernels: numba's thread count (NUMBA_NUM_THREADS, the cores)."""
    return max(1, int(numba.config.NUMBA_NUM_THREADS))


def _pool() -> Any:
    """The threads that run the grid kernels (made once). Plain threads running kernels that
    release the GIL: no threading layer of numba (the OpenMP one keeps its threads spinning
    after each parallel loop, CPU time spent for nothing; the workqueue one aborts when two
    threads launch at once), safe when QGIS runs algorithms in several threads."""
    with _POOL_LOCK:
        if not _POOL:
            from concurrent.futures import ThreadPoolExecutor

            _POOL.append(
                ThreadPoolExecutor(
                    _threads(), thread_name_prefix="lidarphoto-grid", initializer=_block_signals
                )
            )
    return _POOL[0]


#: signals the kernel raises in the thread that faults (a crash in a kernel): left unblocked
#: so that Python's fault handler and the default actions still see them
_SYNCHRONOUS = ("SIGSEGV", "SIGBUS", "SIGFPE", "SIGILL", "SIGABRT", "SIGTRAP", "SIGSYS")


def _block_signals() -> None:
    """In a pool thread: block the asynchronous signals, so that the kernel delivers SIGINT,
    SIGTERM, ... to the main thread, where Python handles them (one delivered to a pool thread
    would leave the main thread asleep in a blocking call: Ctrl+C and the job's cancellation
    would wait). The synchronous ones (:data:`_SYNCHRONOUS`) stay unblocked."""
    import signal

    if hasattr(signal, "pthread_sigmask"):
        keep = {getattr(signal, n) for n in _SYNCHRONOUS if hasattr(signal, n)}
        signal.pthread_sigmask(signal.SIG_BLOCK, signal.valid_signals() - keep)


def morph(src: Any, kernel: Any, dilate: bool) -> Any | None:
    """Erosion (or dilation) of the float32 grid ``src`` by the flat ``kernel`` with OpenCV's
    default border: :func:`_rect_union_kernel`, the same values as ``cv2.erode``
    (``cv2.dilate``), the rows shared out among the threads; None when the kernel is not a
    union of centred rectangles (:func:`rectangles`)."""
    rects = rectangles(kernel)
    if rects is None:
        return None
    src = np.ascontiguousarray(src, dtype=np.float32)
    out = np.empty_like(src)
    rows = src.shape[0]
    if src.size == 0:
        return out
    kernel_fn = _compiled("rect_union")
    sign = -1.0 if dilate else 1.0
    parts = min(_threads(), max(rows // 16, 1))  # not worth a thread below 16 rows each
    cuts = [rows * k // parts for k in range(parts + 1)]
    if parts == 1:
        kernel_fn(src, out, rects[0], rects[1], sign, 0, rows)
        return out
    jobs = [
        _pool().submit(kernel_fn, src, out, rects[0], rects[1], sign, lo, hi)
        for lo, hi in zip(cuts[:-1], cuts[1:])
    ]
    for job in jobs:
        job.result()
    return out


def opening(src: Any, kernel: Any) -> Any | None:
    """Grey-level opening (erosion then dilation) of the float32 grid ``src`` by the flat
    ``kernel``: the same values as ``cv2.morphologyEx(src, cv2.MORPH_OPEN, kernel)`` (minima
    and maxima are exact; only the sign of a zero may differ where -0.0 and 0.0 meet), for
    grids without NaN (OpenCV's result there depends on its order of comparisons; the caller
    keeps OpenCV for them); None when the kernel is not a union of centred rectangles."""
    eroded = morph(src, kernel, dilate=False)
    return None if eroded is None else morph(eroded, kernel, dilate=True)


#: Points per piece of the threaded passes.
_PIECE = 1 << 20


def _run(tasks: list[Callable[[], Any]]) -> list[Any]:
    """Run the tasks (closures calling nogil kernels) on the grid threads; their results."""
    if len(tasks) <= 1 or _threads() == 1:
        return [t() for t in tasks]
    futures = [_pool().submit(t) for t in tasks]
    return [f.result() for f in futures]


def _pieces(parts: Any) -> list[tuple[int, Any]]:
    """(first index, part) pieces of at most ``_PIECE`` points cut from the parts
    ``(first index, (X, Y, Z, scales, offsets))`` (views)."""
    out = []
    for lo, (X, Y, Z, scales, offsets) in parts:
        for a in range(0, len(X), _PIECE):
            b = a + _PIECE
            out.append((lo + a, (X[a:b], Y[a:b], Z[a:b], scales, offsets)))
    return out


def _shares(count: int) -> list[tuple[int, int]]:
    """Contiguous (start, stop) ranges of ``count`` items, one per thread."""
    k = max(1, min(_threads(), count))
    cuts = [count * i // k for i in range(k + 1)]
    return list(zip(cuts[:-1], cuts[1:]))


def cells_all(parts: Any, grid: Any, z0: float, candidate: Any, flat: Any, zr: Any) -> Any:
    """:func:`cells` over every part, the threads each on a share of the points with their own
    minimum grid; returns the flat minimum grid (+inf where no candidate)."""
    pieces = _pieces(parts)
    size = int(grid.rows) * int(grid.cols)

    def task(share: tuple[int, int]) -> Any:
        zmin = np.full(size, np.inf, dtype=np.float32)
        for lo, part in pieces[share[0] : share[1]]:
            cells(part, grid, z0, candidate, lo, flat, zr, zmin)
        return zmin

    grids = _run([partial(task, s) for s in _shares(len(pieces))])
    for other in grids[1:]:
        np.minimum(grids[0], other, out=grids[0])
    return grids[0]


def low_pass_all(
    flat: Any, zr: Any, candidate: Any, low: Any, reference: Any, around: Any, size: int
) -> tuple[int, Any]:
    """:func:`low_pass` over every point, the threads each on a share with their own grid;
    returns the number of new low outliers and the new flat minimum grid."""

    def task(share: tuple[int, int]) -> tuple[int, Any]:
        a, b = share
        zmin = np.full(size, np.inf, dtype=np.float32)
        cand = None if candidate is None else candidate[a:b]
        return low_pass(flat[a:b], zr[a:b], cand, low[a:b], reference, around, zmin), zmin

    results = _run([partial(task, r) for r in _shares(len(flat))])
    zmin = results[0][1]
    for _, other in results[1:]:
        np.minimum(zmin, other, out=zmin)
    return sum(c for c, _ in results), zmin


def classify_all(parts: Any, grid: Any, *arrays: Any) -> None:
    """:func:`classify` over every part, pieces shared out among the threads (each point is
    written by one thread); ``arrays``: those of :func:`classify` from ``flat`` to ``hag``."""
    pieces = _pieces(parts)

    def task(share: tuple[int, int]) -> None:
        for lo, part in pieces[share[0] : share[1]]:
            classify(part, grid, lo, *arrays)

    _run([partial(task, s) for s in _shares(len(pieces))])
