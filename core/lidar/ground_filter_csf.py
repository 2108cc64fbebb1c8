"""The cloth simulation filter CSF (Zhang et al. 2016) of :mod:`.ground_filter`: the cloth
falling onto the inverted cloud, its internal forces, and the slope post-processing.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from ..errors import stop_if_asked
from ..geometry.grid import Grid, fill_nearest
from .ground_filter_params import CsfParams

#: CSF's constants (Zhang et al. 2016): velocity damping per step, gravity (m per unit time
#: squared), the distance within which slope smoothing pins a particle (m).
CSF_DAMPING = 0.01
CSF_GRAVITY_M = 0.2
CSF_SMOOTH_M = 0.3
#: CSF stops when no free particle moved more than this in a step (m), and smooths slopes only
#: in free regions of more particles than this (the authors' package).
CSF_STOP_M = 0.005
CSF_SMOOTH_MIN_REGION = 50


def _csf_cloth(
    grid: Grid,
    flat: NDArray[np.int32],
    x: NDArray[np.float64],
    y: NDArray[np.float64],
    zc: NDArray[np.float32],
    p: CsfParams,
    metre: float,
    should_stop: Callable[[], bool] | None,
) -> tuple[NDArray[np.float32], int, float]:
    """The cloth (Zhang et al. 2016) as a ground surface at the cell centres, in the upright
    frame (z relative to the lowest point); also the number of steps and the last largest move.

    ``metre`` is one metre in z units (gravity, the stop criterion and slope smoothing are in
    metres).
    """
    rows, cols = grid.rows, grid.cols
    # Intersection heights: the candidate nearest to each particle (cell centre) horizontally
    # (Zhang et al. 2016, section 2.2); in the inverted frame it is -z.
    usable = np.isfinite(zc)
    f = flat[usable].astype(np.int64)
    cr = f // cols
    cc = f - cr * cols
    dx = x[usable] - (grid.x0 + (cc + 0.5) * grid.cell)
    dy = y[usable] - (grid.y_top - (cr + 0.5) * grid.cell)
    d2 = dx * dx + dy * dy
    nearest = np.full(rows * cols, np.inf)
    np.minimum.at(nearest, f, d2)
    pick = d2 == nearest[f]
    ihv: NDArray[np.float64] = np.full(rows * cols, np.nan, dtype=np.float64)
    ihv[f[pick]] = -zc[usable][pick].astype(np.float64)
    has = np.isfinite(ihv).reshape(rows, cols)
    ihv = fill_nearest(ihv.reshape(rows, cols), has)  # particles without a point: nearest one

    height = np.full((rows, cols), float(ihv.max()) + 0.05 * metre)  # starts above everything
    previous = height.copy()
    movable = np.ones((rows, cols), dtype=bool)
    fall = CSF_GRAVITY_M * metre * p.time_step**2
    # Internal forces: a free particle moves towards a free neighbour by `both` of their height
    # difference (each moves), towards a pinned one by `one` of it: the closed forms of the
    # paper's half-difference move repeated `rigidness` times with relaxation (the values the
    # authors' package uses: 0.3/0.42/0.468 and 0.3/0.51/0.657 for rigidness 1/2/3). Springs
    # join each particle to its 8 neighbours and to those 2 cells away in the same 8
    # directions, as in the package.
    both = 0.5 * (1.0 - 0.4**p.rigidness)
    one = 1.0 - 0.7**p.rigidness
    pairs = _spring_pairs(rows, cols)
    done, moved = 0, 0.0
    for done in range(1, p.iterations + 1):
        if done % 16 == 0:
            stop_if_asked(should_stop, "filtering the ground")
        new = height + (height - previous) * (1.0 - CSF_DAMPING) - fall
        np.copyto(new, height, where=~movable)
        previous, height = height, new
        for _ in range(2):  # every spring acts from both of its particles
            for a, b in pairs:
                _spring(height, movable, a, b, both, one)
        moved = float(np.abs(height - previous)[movable].max()) if movable.any() else 0.0
        hit = movable & (height < ihv)
        height[hit] = ihv[hit]
        movable &= ~hit
        if 0.0 < moved < CSF_STOP_M * metre or not movable.any():
            break
    if p.slope_smooth:
        _csf_smooth(height, ihv, movable, CSF_SMOOTH_M * metre)
    return (-height).astype(np.float32), done, round(moved, 6)


def _spring_pairs(rows: int, cols: int) -> list[tuple[tuple[slice, slice], tuple[slice, slice]]]:
    """Index pairs (a, b) of views, one per batch of springs that share no particle: for every
    spring direction (dr, dc) of length 1 or 2, the particles split by their row (or column)
    index so that each is in at most one spring of the batch."""
    out = []
    for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1), (0, 2), (2, 0), (2, 2), (2, -2)):
        ca = slice(max(-dc, 0), cols - max(dc, 0))
        cb = slice(max(dc, 0), cols - max(-dc, 0) if dc < 0 else cols)
        step = dr if dr else dc
        n = rows if dr else cols
        for colour in (0, 1):
            for first in range(colour * step, colour * step + step):
                lo = slice(first, n - step, 2 * step)
                hi = slice(first + step, n, 2 * step)
                if dr:
                    out.append(((lo, ca), (hi, cb)))
                else:
                    out.append(((slice(None), lo), (slice(None), hi)))
    return out


def _spring(
    h: NDArray[np.float64],
    movable: NDArray[np.bool_],
    a: tuple[slice, slice],
    b: tuple[slice, slice],
    both: float,
    one: float,
) -> None:
    """Apply one batch of springs between the particles ``h[a]`` and ``h[b]`` (views), in place."""
    ha, hb = h[a], h[b]
    if ha.size == 0:
        return
    ma, mb = movable[a], movable[b]
    diff = hb - ha
    free = ma & mb
    ha += np.where(free, both, np.where(ma, one, 0.0)) * diff
    hb -= np.where(free, both, np.where(mb, one, 0.0)) * diff


def _csf_smooth(
    height: NDArray[np.float64], ihv: NDArray[np.float64], movable: NDArray[np.bool_], near: float
) -> None:
    """Slope post-processing (Zhang et al. 2016), in place: in every connected region of more
    than 50 free particles, those reachable from a pinned particle through neighbours whose
    point heights differ by less than ``near`` are pinned on their points (the cloth left
    hanging over steep ground)."""
    from scipy import ndimage
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    rows, cols = height.shape
    labels, count = ndimage.label(movable)
    if count == 0:
        return
    sizes = np.bincount(labels.ravel())
    big = (sizes > CSF_SMOOTH_MIN_REGION)[labels] & movable
    index = np.arange(rows * cols).reshape(rows, cols)
    heads, tails = [], []
    for sa, sb in (
        ((slice(None), slice(0, -1)), (slice(None), slice(1, None))),
        ((slice(0, -1), slice(None)), (slice(1, None), slice(None))),
    ):
        close = np.abs(ihv[sa] - ihv[sb]) < near
        heads.append(index[sa][close])
        tails.append(index[sb][close])
    u, v = np.concatenate(heads), np.concatenate(tails)
    flat_big = big.ravel()
    pinned = ~movable.ravel()
    # the graph: close neighbours among the big free regions, plus one node for "pinned"
    inside = flat_big[u] & flat_big[v]
    seed_u = flat_big[u] & pinned[v]
    seed_v = flat_big[v] & pinned[u]
    root = rows * cols
    gu = np.concatenate([u[inside], u[seed_u], v[seed_v]])
    gv = np.concatenate([v[inside], np.full(seed_u.sum(), root), np.full(seed_v.sum(), root)])
    graph = coo_matrix((np.ones(len(gu), np.int8), (gu, gv)), shape=(root + 1, root + 1))
    _, comp = connected_components(graph, directed=False)
    reach = (comp[:root] == comp[root]) & flat_big
    flat_h = height.reshape(-1)
    flat_h[reach] = ihv.reshape(-1)[reach]
    movable.reshape(-1)[reach] = False
