"""Second pass of a LiDAR block's roof planes: the regions a tile saw only in part, re-run
whole (issue 33).

A tile holds its core plus a buffer of :func:`core.lidar.block.roof_buffer`; a region that
reaches the outer edge of that buffer (a large field, a long roof cut by a border) was grown,
refitted, released and merged from the tile's part of it only, and the points it took or
left moved its neighbours' planes too. No finite buffer makes that the single run's. So,
after the tiles and :func:`core.lidar.block.merge_cut_planes`:

1. the block planes with a piece flagged ``edge`` (:class:`core.lidar.block.PlanePiece`:
   the tile's region came within an eighth of a buffer of the edge of the tile's points,
   :data:`core.lidar.block.EDGE`) mark the
   cells, on a grid of a quarter buffer aligned on the map coordinates, that hold their
   points;
2. the marked cells, dilated by half a buffer, are the window's **core**; the core dilated by
   one buffer is the **window**; each connected core is one pass;
3. the extraction (:func:`core.lidar.roof_planes.extract_roof_planes`, the same parameters,
   so the same seeds, triplet tables and ties as the single run) runs once on all the
   non-ground points of the window (from the tiles' point sets, ``fetch``); a plane of that
   run on marked cells that reaches the window's outer quarter buffer marks its cells too
   and the window is re-run larger (at most ``MAX_ROUNDS`` times); the other planes the
   window's border cuts are joined as a tile's are (step 4);
4. the window run's labels replace the block's on the core's points; across the core's
   border the window planes are joined to the block planes by the merge's own test on the
   points within half a buffer of that border (both sides): the two runs put the same points
   into them, at least half of what either gave its plane there, one to one, strongest first;
5. every plane the pass touched is refitted by the merge's rule (its regions' interior
   points; all of them when fewer than half are) and the block's ids are re-ranked by
   decreasing point count.

Memory: a window holds the cut regions, half a buffer and one buffer around them, small
against a tile in a block of roofs; where a field or a car park spans the block, the block.
lidarblock (core/jobs/lidar_block.py) runs each window as one dask task (``map_windows``),
which reads the window's points from the tiles' saved non-ground points, one tile at a time.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..geometry.planes import fit_plane
from .block import MIN_SHARED, MergedPlane, PlanePiece

log = logging.getLogger(__name__)

#: Re-runs of a window whose own planes reach its edge (each grows it by their extent).
MAX_ROUNDS = 4

#: ``fetch(box) -> (xyz (N, 3), ids (N,))``: the block's non-ground points in ``box`` (xmin,
#: ymin, xmax, ymax; CRS unit), each once, with the ids the tiles gave them.
Fetch = Callable[[tuple[float, float, float, float]], tuple[NDArray[np.float64], NDArray[np.int64]]]


def _dilate(mask: NDArray[np.bool_], r: int) -> NDArray[np.bool_]:
    """Square (Chebyshev) dilation of a 2-D mask by ``r`` cells (the mask has the margin)."""
    out = mask.copy()
    for _ in range(r):
        grown = out.copy()
        grown[1:] |= out[:-1]
        grown[:-1] |= out[1:]
        grown[:, 1:] |= grown[:, :-1].copy()
        grown[:, :-1] |= grown[:, 1:].copy()
        out = grown
    return out


class _Grid:
    """Cells of ``size`` on the map coordinates (index floor(x / size)), a dense window of them
    around ``cells`` (K, 2) with ``margin`` free cells each side."""

    def __init__(self, cells: NDArray[np.int64], size: float, margin: int) -> None:
        self.size = size
        self.lo = cells.min(axis=0) - margin
        shape = cells.max(axis=0) - self.lo + margin + 1
        self.shape = (int(shape[0]), int(shape[1]))

    def mask(self, cells: NDArray[np.int64]) -> NDArray[np.bool_]:
        """Dense mask of ``cells`` (those outside the grid are ignored)."""
        m = np.zeros(self.shape, dtype=bool)
        ij = cells - self.lo
        ok = (ij >= 0).all(axis=1) & (ij[:, 0] < self.shape[0]) & (ij[:, 1] < self.shape[1])
        m[ij[ok, 0], ij[ok, 1]] = True
        return m

    def of(self, xy: NDArray[np.float64]) -> NDArray[np.int64]:
        """Cell of each point (K, 2), global indices."""
        return np.floor(xy / self.size).astype(np.int64)

    def look(self, mask: NDArray[np.bool_], xy: NDArray[np.float64]) -> NDArray[np.bool_]:
        """``mask`` at each point's cell (False outside the grid)."""
        ij = self.of(xy) - self.lo
        ok = (ij >= 0).all(axis=1) & (ij[:, 0] < self.shape[0]) & (ij[:, 1] < self.shape[1])
        out = np.zeros(len(xy), dtype=bool)
        out[ok] = mask[ij[ok, 0], ij[ok, 1]]
        return out

    def box(self, mask: NDArray[np.bool_]) -> tuple[float, float, float, float]:
        """Map box of the true cells of ``mask``."""
        i, j = np.nonzero(mask)
        s = self.size
        return (
            float((self.lo[0] + i.min()) * s),
            float((self.lo[1] + j.min()) * s),
            float((self.lo[0] + i.max() + 1) * s),
            float((self.lo[1] + j.max() + 1) * s),
        )


def _components(mask: NDArray[np.bool_]) -> list[NDArray[np.bool_]]:
    """8-connected components of a 2-D mask, in the order of their first cell."""
    from scipy import ndimage

    lab, n = ndimage.label(mask, structure=np.ones((3, 3), dtype=int))
    return [lab == k for k in range(1, n + 1)]


def _state(merged: Sequence[MergedPlane], pieces: Sequence[PlanePiece]) -> dict[str, Any]:
    """The block's plane points as flat arrays: ids, xyz, label (block plane), fit mask."""
    ids = [np.zeros(0, np.int64)]
    pts = [np.zeros((0, 3))]
    lab = [np.zeros(0, np.int64)]
    fit = [np.zeros(0, bool)]
    for k, m in enumerate(merged):
        if m.ids is None:
            raise ValueError("the second pass needs the point ids of every plane piece")
        ids.append(m.ids)
        pts.append(m.points)
        lab.append(np.full(len(m.ids), k, dtype=np.int64))
        for p in m.pieces:
            f = pieces[p].fit
            fit.append(np.ones(len(pieces[p].points), bool) if f is None else f)
        if not m.pieces:
            fit.append(np.ones(len(m.ids), bool))
    return {
        "ids": np.concatenate(ids),
        "xyz": np.concatenate(pts),
        "label": np.concatenate(lab),
        "fit": np.concatenate(fit),
    }


def _window_run(
    grid: _Grid, marked: NDArray[np.bool_], buffer_cells: int, params: Any, fetch: Fetch
) -> tuple[dict[str, Any], NDArray[np.bool_]]:
    """The extraction on one window (its core: ``marked`` dilated by half a buffer, the window
    one buffer more; ``buffer_cells`` cells a buffer); returns the window's points, labels, fit
    mask, core and band flags, and the cells of its planes on ``marked`` that reach the
    window's outer quarter buffer (none: the window saw them whole)."""
    from .roof_planes import extract_roof_planes

    half = max(1, buffer_cells // 2)
    core_m = _dilate(marked, half)
    win_m = _dilate(core_m, buffer_cells)
    xyz, ids = fetch(grid.box(win_m))
    xy = xyz[:, :2]
    inwin = grid.look(win_m, xy)
    xyz, ids, xy = xyz[inwin], ids[inwin], xy[inwin]
    res = extract_roof_planes(xyz, params)
    log.info(
        "second pass: a window of %d points, %.0f x %.0f",
        len(xyz),
        grid.box(win_m)[2] - grid.box(win_m)[0],
        grid.box(win_m)[3] - grid.box(win_m)[1],
    )
    lab = res.plane_id.astype(np.int64)
    fit = res.fit_mask if res.fit_mask is not None else np.ones(len(xyz), bool)
    core = grid.look(core_m, xy)
    # band: within half a buffer of the core's border, both sides
    band = grid.look(_dilate(core_m, half) & ~core_m | core_m & _dilate(~core_m, half), xy)
    # the outer quarter of the window's buffer: a cut region (points in the marked cells)
    # that reaches it may go on beyond the window, which grows by its extent
    outer = ~grid.look(_dilate(core_m, buffer_cells - max(1, buffer_cells // 4)), xy)
    inner = np.unique(lab[grid.look(marked, xy) & (lab >= 0)])
    cut = np.intersect1d(inner, np.unique(lab[outer & (lab >= 0)]))
    grow = grid.mask(grid.of(xy[np.isin(lab, cut)])) if len(cut) else np.zeros_like(marked)
    return {"ids": ids, "xyz": xyz, "label": lab, "fit": fit, "core": core, "band": band}, grow


def _joins(blab: NDArray[np.int64], wlab: NDArray[np.int64]) -> dict[int, int]:
    """Window plane -> block plane, by the merge's test on the band points: at least
    MIN_SHARED points labelled by both, at least half of what either gave its plane in the
    band; one to one, strongest first (ties: lower ids)."""
    both = (blab >= 0) & (wlab >= 0)
    if not both.any():
        return {}
    pairs, count = np.unique(np.column_stack([wlab[both], blab[both]]), axis=0, return_counts=True)
    nw = dict(zip(*np.unique(wlab[wlab >= 0], return_counts=True)))
    nb = dict(zip(*np.unique(blab[blab >= 0], return_counts=True)))
    out: dict[int, int] = {}
    taken: set[int] = set()
    for e in np.lexsort((pairs[:, 1], pairs[:, 0], -count)):
        w, b, c = int(pairs[e, 0]), int(pairs[e, 1]), int(count[e])
        if w in out or b in taken or c < MIN_SHARED or 2 * c < min(nw[w], nb[b]):
            continue
        out[w] = b
        taken.add(b)
    return out


def _apply(state: dict[str, Any], win: dict[str, Any], next_label: int) -> int:
    """Replace the block's labels on the window's core by the window run's, joined across the
    core's border; returns the next free label."""
    order = np.argsort(state["ids"], kind="stable")
    sid = state["ids"][order]
    at = np.minimum(np.searchsorted(sid, win["ids"]), max(len(sid) - 1, 0))
    hit = (sid[at] == win["ids"]) if len(sid) else np.zeros(len(win["ids"]), bool)
    blab = np.where(hit, state["label"][order[at]] if len(sid) else -1, -1)
    band = win["band"]
    joins = _joins(np.where(band, blab, -1), np.where(band, win["label"], -1))
    core, wl = win["core"], win["label"]
    keep = ~np.isin(state["ids"], win["ids"][core])
    used = np.unique(wl[core & (wl >= 0)])
    new = {int(w): joins.get(int(w), next_label + i) for i, w in enumerate(used)}
    add = core & (wl >= 0)
    lut = np.full(int(wl.max()) + 1 if len(wl) else 0, -1, dtype=np.int64)
    lut[used] = [new[int(w)] for w in used]
    lab_add = lut[wl[add]]
    touched = set(int(b) for b in np.unique(state["label"][~keep])) | set(new.values())
    for key in ("ids", "xyz", "fit"):
        state[key] = np.concatenate([state[key][keep], win[key][add]])
    state["label"] = np.concatenate([state["label"][keep], lab_add])
    state.setdefault("touched", set()).update(touched)
    return next_label + len(used)


#: ``map(function, list of argument tuples) -> list of results``: how the windows run (in
#: turn by default; lidarblock gives one dask task to each).
MapWindows = Callable[[Callable[..., Any], list[tuple[Any, ...]]], list[Any]]

#: Grid cells per buffer (the cells of the windows' masks).
CELLS_PER_BUFFER = 4


def run_window(cells: NDArray[np.int64], size: float, params: Any, fetch: Fetch) -> dict[str, Any]:
    """One window of the second pass from its marked ``cells`` (K, 2; global indices of
    cells of ``size``), re-run larger while a cut region reaches its edge (at most
    MAX_ROUNDS runs): its points, labels, fit mask, core and band flags (``_window_run``)."""
    for _ in range(MAX_ROUNDS):
        grid = _Grid(cells, size, 2 * CELLS_PER_BUFFER + 1)
        marked = grid.mask(cells)
        win, grow = _window_run(grid, marked, CELLS_PER_BUFFER, params, fetch)
        if not grow.any() or (grow <= marked).all():
            break
        i, j = np.nonzero(marked | grow)
        cells = np.column_stack([i, j]) + grid.lo
    return win


def second_pass(
    merged: Sequence[MergedPlane],
    pieces: Sequence[PlanePiece],
    buffer: float,
    params: Any,
    fetch: Fetch,
    map_windows: MapWindows | None = None,
) -> list[MergedPlane]:
    """The block planes with the regions cut by a tile's buffer re-run whole (module
    docstring). ``merged``: :func:`core.lidar.block.merge_cut_planes` of ``pieces``;
    ``buffer``: the tiles' roof buffer (CRS unit); ``params``: the tiles'
    :class:`RoofPlaneParams`; ``fetch``: the block's non-ground points in a box;
    ``map_windows``: runs :func:`run_window` on each window (default: in turn). Planes no
    window touched are returned as they were (their ids re-ranked with the rest)."""
    edge = [k for k, m in enumerate(merged) if any(pieces[p].edge for p in m.pieces)]
    if not edge:
        return list(merged)
    state = _state(merged, pieces)
    size = buffer / CELLS_PER_BUFFER
    seed_xy = state["xyz"][np.isin(state["label"], edge), :2]
    seed_cells = np.unique(np.floor(seed_xy / size).astype(np.int64), axis=0)
    # one window per connected core (cut regions closer than a buffer share one)
    base = _Grid(seed_cells, size, CELLS_PER_BUFFER + 1)
    seeds_m = base.mask(seed_cells)
    jobs = []
    for comp in _components(_dilate(seeds_m, CELLS_PER_BUFFER // 2)):
        i, j = np.nonzero(comp & seeds_m)
        jobs.append((np.column_stack([i, j]) + base.lo, size, params, fetch))
    windows = (map_windows or (lambda f, args: [f(*a) for a in args]))(run_window, jobs)
    next_label = len(merged)
    for win in windows:
        next_label = _apply(state, win, next_label)
    return _planes(merged, state, params.min_plane_points)


def _planes(
    merged: Sequence[MergedPlane], state: dict[str, Any], min_points: int
) -> list[MergedPlane]:
    """The block planes from the state: untouched planes as they were, touched ones refitted
    (dropped below ``min_points``); ids by decreasing size (ties: lowest point id)."""
    lab, ids = state["label"], state["ids"]
    touched = state.get("touched", set())
    order = np.lexsort((ids, lab))
    lab_s = lab[order]
    starts = np.flatnonzero(np.r_[True, lab_s[1:] != lab_s[:-1]])
    groups = np.split(order, starts[1:]) if len(order) else []
    out = []
    for g in groups:
        k = int(lab[g[0]])
        if k in touched and len(g) < min_points:
            continue
        out.append((k, g))
    out.sort(key=lambda kg: (-len(kg[1]), int(ids[kg[1]].min())))
    planes = []
    for new_id, (k, g) in enumerate(out):
        if k < len(merged) and k not in touched:
            m = merged[k]
            planes.append(MergedPlane(_renumber(m.plane, new_id), m.pieces, m.points, m.ids))
            continue
        pts, fit = state["xyz"][g], state["fit"][g]
        use = pts[fit] if fit.sum() >= max(3, len(pts) // 2) else pts
        members = merged[k].pieces if k < len(merged) else ()
        planes.append(MergedPlane(fit_plane(use, plane_id=new_id), members, pts, ids[g]))
    return planes


def _renumber(plane: Any, new_id: int) -> Any:
    """The plane with id ``new_id``."""
    from dataclasses import replace

    return replace(plane, id=new_id) if plane.id != new_id else plane


def tiled_planes(
    xyz: NDArray[np.float64],
    xs: Sequence[float],
    ys: Sequence[float],
    params: Any,
    buffer: float,
    whole: bool = True,
) -> tuple[list[MergedPlane], int]:
    """The block's roof planes of an in-memory cloud (non-ground points ``xyz``, ids their
    indices) in the tiles between the edges ``xs`` x ``ys`` (each half-open, the last edge
    past the last point), with :func:`core.lidar.block.tile_planes` on a ``buffer``,
    :func:`core.lidar.block.merge_cut_planes` and, when ``whole``, :func:`second_pass`: what
    lidarblock does, without files (tests, benchmarks). Returns the planes and the number of
    pieces."""
    from .block import BandLabels, merge_cut_planes, tile_planes

    ids = np.arange(len(xyz))
    x, y = xyz[:, 0], xyz[:, 1]
    pieces: list[PlanePiece] = []
    bands: list[BandLabels] = []
    for i in range(len(xs) - 1):
        for j in range(len(ys) - 1):
            box = (xs[i], ys[j], xs[i + 1], ys[j + 1])
            core = (x >= box[0]) & (x < box[2]) & (y >= box[1]) & (y < box[3])
            near = (
                (x >= box[0] - buffer)
                & (x <= box[2] + buffer)
                & (y >= box[1] - buffer)
                & (y <= box[3] + buffer)
            )
            got, band = tile_planes(
                xyz[near], core[near], ids[near], box, buffer / 2.0, params, len(bands)
            )
            bands.append(band.shifted(len(pieces)))
            pieces += got
    merged = merge_cut_planes(pieces, bands)
    if whole:

        def fetch(box: tuple[float, float, float, float]) -> tuple[NDArray, NDArray]:
            m = (x >= box[0]) & (x < box[2]) & (y >= box[1]) & (y < box[3])
            return xyz[m], ids[m]

        merged = second_pass(merged, pieces, buffer, params, fetch)
    return merged, len(pieces)
