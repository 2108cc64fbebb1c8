"""A LiDAR block processed tile by tile: the buffer rule, planes cut by tile borders merged,
LiDAR control points and lines deduplicated (no file access: core/jobs/lidar_block.py reads
and writes).

Buffer rule (:func:`ground_buffer`): SMRF and PMF decide a cell from the lowest-point grid
through openings (an erosion then a dilation) with windows up to radius ``R`` (SMRF's
max_window, half PMF's window width), so a cell depends on cells up to ``2 R`` away; the
low-outlier test looks ``low_outlier_radius`` further, the final test interpolates the DTM
one cell away and its slope one more cell. Hence a buffer of
``2 R + low_outlier_radius + 3 cells``. Tile grids are aligned with the whole cloud's (cells
on multiples of the cell size), so on a tile's core the openings, and the ground cells, are
those of a run on the whole cloud. What is not local is the pull-push filling of the DTM
under objects (:func:`lidarphoto.core.geometry.grid.fill_holes`): its pyramid starts at the
grid's corner, which is the tile's, so under and next to buildings the filled DTM differs by
millimetres to centimetres and a point whose height is that close to the tolerance can change
class. Measured on a simulated town in 60 m tiles: 99.99 % of the points agree (9 of 75 256
differ, each where the two DTMs differ by more than 1 mm; tests/core/test_lidar_block.py).
CSF, whose cloth couples every cell, and a slope estimated from the cloud (SMRF slope 0) have
no finite buffer and are refused for blocks.

Roof planes (:func:`tile_planes`, :func:`merge_cut_planes`) are extracted on each tile's core
plus a buffer of :func:`roof_buffer`, sized from the neighbourhood the extraction uses: a core
point's label depends on its K neighbours' local RANSAC, on its G neighbours' local planes and
on the reassignment, which reaches REASSIGN_PASSES + 1 rings of G neighbours; the buffer holds
three times that, and at least the band plus a seed voxel plus a K patch, so the half next to
the core (the overlap band) is labelled as in a whole-file run. A point's local plane does not
depend on the points a tile holds beyond its neighbours, nor a seed on those beyond its voxel
(RANSAC triplet tables picked by its coordinates, seed voxels on map coordinates sized by the
local spacing, ties by coordinates: :mod:`core.lidar.roof_planes`); what a tile
cannot see is the rest of a region cut by its buffer (its refit), hence the band. Each tile
keeps the planes of its core points (pieces) and reports the labels it gives to the points of
the band on both sides of its border. A plane cut by a border is found by both tiles; two pieces
are merged when the tiles' own region growing put the same points into them: at least half of
the band points that either tile gives to its piece are given to the other piece by the other
tile. That is the growing's own test (a tile grows its region across the border into its buffer
exactly as the whole-file run does), neither looser nor tighter: two roofs that the growing
keeps apart get different labels in the band and are not fused, whatever their normals. The
merged plane is refitted with :func:`lidarphoto.core.geometry.planes.fit_plane` (covariance
included) from the points its tiles fitted (the regions' interiors, the whole-file rule).
A region that reaches the outer edge of a tile's buffer (a piece flagged ``edge``) was seen in
part only; :func:`core.lidar.block_cut.second_pass` re-runs it whole after the merge.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..geometry.planes import Plane, fit_plane
from .control import ControlLine, ControlPoint


def ground_buffer(params: Any) -> float:
    """Buffer (horizontal unit of the parameters) a tile needs for the ground filter.

    >>> from lidarphoto.core.lidar.ground_filter import SmrfParams
    >>> ground_buffer(SmrfParams())  # 2 x 18 + 5 + 3 x 1
    44.0
    """
    method = getattr(params, "method", "")
    if method == "csf":
        raise InputError(
            "the cloth filter (CSF) couples the whole cloud: no tile buffer "
            "makes tiles agree; use SMRF or PMF for a block"
        )
    if method == "smrf" and params.slope == 0:
        raise InputError(
            "SMRF slope 0 (estimated from the cloud) differs from tile to tile: "
            "give the terrain slope for a block",
            column="slope",
        )
    # SMRF's max_window is a radius, PMF's a window width
    radius = params.max_window if method == "smrf" else params.max_window / 2.0
    low = params.low_outlier_radius if params.low_outlier_height > 0 else 0.0
    return float(2.0 * radius + low + 3.0 * params.cell_size)


def roof_buffer(k_neighbours: int, spacing: float) -> float:
    """Buffer for the roof planes (CRS unit): three times the reach of a core point's label,
    the radius of its ``k_neighbours`` patch plus REASSIGN_PASSES + 1 radii of a
    GROW_NEIGHBOURS patch, at the mean point ``spacing`` (each radius that of a disc holding
    that many points): the label of a point of the band (half the buffer) has all it depends
    on, and the region's plane half a buffer more of its points. With twice the reach, one
    plane of the AHN3 crop 2 in 2 x 2 tiles came 0.61 degrees off (its fit at the border
    differed by 29 of 740 points); with 1.5x more buffer every plane matched. At least the band
    plus a seed voxel (SEED_VOXEL spacings, up to sqrt(2) more by its rounding to a power of
    two) plus a K patch: a voxel that reaches into the band has all its points, and their
    local planes, in the tile, so the band's seeds are the whole file's.

    >>> round(roof_buffer(20, 0.5), 3)
    19.82
    """
    from .roof_planes import REASSIGN_PASSES
    from .roof_planes_local import GROW_NEIGHBOURS
    from .roof_planes_regions import SEED_VOXEL

    def radius(n: int) -> float:
        return math.sqrt(n / math.pi) * spacing

    reach = radius(k_neighbours) + (REASSIGN_PASSES + 1) * radius(
        min(GROW_NEIGHBOURS, k_neighbours)
    )
    seeds = 1.5 * reach + math.sqrt(2.0) * SEED_VOXEL * spacing + radius(k_neighbours)
    return float(max(3.0 * reach, seeds))


#: A piece is ``edge`` when its tile's region has points this many bands (half buffers)
#: outside the tile's box: in the buffer's outer eighth, where it may go on beyond the tile.
EDGE = 1.75

#: Least band points two pieces share to be merged (fewer: a corner or a ridge touch).
MIN_SHARED = 3


@dataclass(frozen=True)
class PlanePiece:
    """A plane found in one tile: the tile, the plane, its core points (N, 3), which of them
    are its region's interior (N,: RoofPlaneResult.fit_mask), their point ids (N,) and
    ``edge``: the tile's region came within an eighth of a buffer of the outer edge of the tile's
    points (the tile saw part of it only: :func:`core.lidar.block_cut.second_pass`)."""

    tile: int
    plane: Plane
    points: NDArray[np.float64]
    fit: NDArray[np.bool_] | None = None
    ids: NDArray[np.int64] | None = None
    edge: bool = False


@dataclass(frozen=True)
class BandLabels:
    """The labels a tile gives to the points of the band along its border: point ``ids``
    (M,), ``core`` (M,) True for its own points, ``piece`` (M,) the index of the piece (into
    the block's list of pieces) or -1 (no plane, or a plane without core points)."""

    tile: int
    ids: NDArray[np.int64]
    core: NDArray[np.bool_]
    piece: NDArray[np.int64]

    def shifted(self, offset: int) -> BandLabels:
        """The same labels with piece indices counted from ``offset`` (the block's list)."""
        return BandLabels(
            self.tile, self.ids, self.core, np.where(self.piece >= 0, self.piece + offset, -1)
        )


@dataclass(frozen=True)
class MergedPlane:
    """A block plane: refitted from the points of its ``pieces`` (indices into the input)."""

    plane: Plane
    pieces: tuple[int, ...]
    points: NDArray[np.float64]
    ids: NDArray[np.int64] | None = None


def tile_planes(
    xyz: NDArray[np.float64],
    core: NDArray[np.bool_],
    ids: NDArray[np.int64],
    box: Sequence[float],
    band: float,
    params: Any,
    tile: int,
) -> tuple[list[PlanePiece], BandLabels]:
    """Roof planes of one tile: the extraction on its points ``xyz`` (core and buffer, the
    tile's own points flagged by ``core``), the pieces (its planes that hold core points) and
    the labels of the points within ``band`` of the border of ``box`` (xmin, ymin, xmax,
    ymax), both sides. ``params``: :class:`RoofPlaneParams`. A piece of one or two points is
    the end of a plane the neighbour holds: the merge joins it there (dropping it lost those
    points of the plane and tilted small planes fitted with all their points by 0.5 degrees
    on AHN3)."""
    from .roof_planes import extract_roof_planes

    xyz = np.asarray(xyz, dtype=np.float64)
    label = np.full(len(xyz), -1, dtype=np.int64)
    fit: NDArray[np.bool_] | None = np.zeros(len(xyz), dtype=bool)
    pieces: list[PlanePiece] = []
    planes: tuple[Plane, ...] = ()
    if len(xyz) >= params.min_plane_points:
        res = extract_roof_planes(xyz, params)
        label, fit, planes = res.plane_id.astype(np.int64), res.fit_mask, res.planes
    piece_of = np.full(len(planes) + 1, -1, dtype=np.int64)  # plane id + 1 -> piece
    core_label = np.where(core, label, -1)
    sizes = np.bincount(core_label + 1, minlength=len(piece_of))[1:]
    x, y = xyz[:, 0], xyz[:, 1]
    inner = np.minimum(np.minimum(x - box[0], box[2] - x), np.minimum(y - box[1], box[3] - y))
    # distance outside the box (the buffer side), 0 inside; the buffer is two bands: a plane
    # with points in its outer eighth may reach beyond the tile's points
    far = np.maximum(np.maximum(box[0] - x, x - box[2]), np.maximum(box[1] - y, y - box[3]))
    outer = np.hypot(
        np.maximum(np.maximum(box[0] - x, x - box[2]), 0.0),
        np.maximum(np.maximum(box[1] - y, y - box[3]), 0.0),
    )
    at_edge = np.zeros(len(planes) + 1, dtype=bool)
    at_edge[np.unique(label[far >= EDGE * band]) + 1] = True
    for pid in np.flatnonzero(sizes > 0):  # a plane only in the buffer: the neighbour's
        m = core_label == pid
        piece_of[pid + 1] = len(pieces)
        assert fit is not None  # the fit mask comes with every plane found
        pieces.append(PlanePiece(tile, planes[pid], xyz[m], fit[m], ids[m], bool(at_edge[pid + 1])))
    inband = np.where(core, inner < band, outer < band)
    return pieces, BandLabels(tile, ids[inband], core[inband], piece_of[label[inband] + 1])


def _shared(bands: Sequence[BandLabels], n: int) -> tuple[NDArray, NDArray, Any]:
    """Band points two tiles both labelled: a tile's label of a point of its buffer against
    the label of the tile that owns it. Returns the pairs of pieces (i < j) labelled on the
    same points, their counts, and ``over(piece, tile)``: the points of the piece that ``tile``
    labelled too (with any label; arrays in, arrays out)."""
    ids = np.concatenate([b.ids for b in bands])
    core = np.concatenate([b.core for b in bands])
    piece = np.concatenate([b.piece for b in bands])
    tile = np.concatenate([np.full(len(b.ids), b.tile, np.int64) for b in bands])
    n_tiles = int(tile.max()) + 1 if len(tile) else 1
    o = np.flatnonzero(core)[np.argsort(ids[core], kind="stable")]
    u = np.flatnonzero(~core)
    at = np.searchsorted(ids[o], ids[u])
    ok = at < len(o)
    ok[ok] = ids[o[at[ok]]] == ids[u[ok]]
    u, c = u[ok], o[at[ok]]  # the same point: in one tile's buffer, in another's core
    pu, pc = piece[u], piece[c]
    # sparse (piece, other tile) counts: a dense table would be pieces x tiles
    seen, seen_count = np.unique(
        np.concatenate([(pu * n_tiles + tile[c])[pu >= 0], (pc * n_tiles + tile[u])[pc >= 0]]),
        return_counts=True,
    )

    def over(p: NDArray, t: NDArray) -> NDArray:
        key = p * n_tiles + t
        at = np.minimum(np.searchsorted(seen, key), max(len(seen) - 1, 0))
        hit = (seen[at] == key) if len(seen) else np.zeros(len(key), bool)
        return np.where(hit, seen_count[at] if len(seen) else 0, 0)

    both = (pu >= 0) & (pc >= 0)
    lo, hi = np.minimum(pu[both], pc[both]), np.maximum(pu[both], pc[both])
    key, count = np.unique(lo * n + hi, return_counts=True)
    return np.column_stack([key // n, key % n]), count, over


def _refit(pieces: Sequence[PlanePiece], members: Sequence[int], new_id: int) -> Plane:
    """The plane of merged pieces from the points their tiles fitted (all of them when fewer
    than half were: the rule of a single run, roof_planes._final_planes)."""
    pts = np.concatenate([pieces[k].points for k in members])
    fit = [f for f in (pieces[k].fit for k in members) if f is not None]
    if len(fit) == len(members):  # every piece has its fit mask
        mask = np.concatenate(fit)
        if mask.sum() >= max(3, len(pts) // 2):
            pts = pts[mask]
    return fit_plane(pts, plane_id=new_id)


def merge_cut_planes(
    pieces: Sequence[PlanePiece], bands: Sequence[BandLabels]
) -> list[MergedPlane]:
    """Merge the pieces of planes cut by tile borders and refit each merged plane.

    Two pieces of different tiles are joined when the band points (``bands``: each tile's
    labels along its border, piece indices into ``pieces``) that the two tiles both labelled
    hold at least :data:`MIN_SHARED` points given to one piece by one tile and to the other by
    the other, and these are at least half of the band points that either tile gave to its
    piece; joins are transitive (a plane over four tiles), strongest first, never putting two
    pieces of one tile into one plane. Merged planes get ids 0.. by decreasing point count
    (ties: first piece).

    Examples
    --------
    >>> from lidarphoto.core.lidar.roof_planes import RoofPlaneParams
    >>> rng = np.random.default_rng(0)
    >>> xy = rng.uniform(0, 20, (4000, 2))
    >>> pts = np.column_stack([xy, 5 + 0.5 * xy[:, 0] + rng.normal(0, 0.02, 4000)])
    >>> ids = np.arange(4000)
    >>> pieces, bands = [], []
    >>> for t, box in enumerate([(0, 0, 10, 20), (10, 0, 20, 20)]):
    ...     near = (xy[:, 0] > box[0] - 3) & (xy[:, 0] < box[2] + 3)
    ...     core = (xy[near, 0] >= box[0]) & (xy[near, 0] < box[2])
    ...     got, band = tile_planes(pts[near], core, ids[near], box, 1.5, RoofPlaneParams(), t)
    ...     bands.append(band.shifted(len(pieces)))
    ...     pieces += got
    >>> merged = merge_cut_planes(pieces, bands)
    >>> len(pieces), len(merged), merged[0].plane.n_points <= 4000, merged[0].pieces
    (2, 1, True, (0, 1))
    """
    n = len(pieces)
    if n == 0:
        return []
    tiles = np.array([p.tile for p in pieces], dtype=np.int64)
    groups: dict[int, list[int]] = {k: [k] for k in range(n)}
    if bands:
        pairs, count, over = _shared(bands, n)
        a, b = pairs[:, 0], pairs[:, 1]
        least = np.minimum(over(a, tiles[b]), over(b, tiles[a]))
        join = (tiles[a] != tiles[b]) & (count >= MIN_SHARED) & (2 * count >= least)
        a, b, count = a[join], b[join], count[join]
        # strongest joins first; a join that would put two pieces of one tile into one plane
        # is refused: that tile saw both and kept them apart (a neighbour seeing less of
        # them, e.g. two flat roofs cut by its border, must not fuse them)
        root = np.arange(n)
        for e in np.lexsort((b, a, -count)):
            ra, rb = int(root[a[e]]), int(root[b[e]])
            if ra == rb or set(tiles[groups[ra]]) & set(tiles[groups[rb]]):
                continue
            ra, rb = min(ra, rb), max(ra, rb)
            groups[ra] += groups.pop(rb)
            root[groups[ra]] = ra
    # a piece of fewer than 3 points that joined no other is no plane
    merged = [
        (sorted(members), sum(len(pieces[k].points) for k in members))
        for members in groups.values()
    ]
    merged = [m for m in merged if m[1] >= 3]
    merged.sort(key=lambda m: (-m[1], m[0][0]))
    out = []
    for new_id, (members, _) in enumerate(merged):
        pts = np.concatenate([pieces[k].points for k in members])
        ids = [i for i in (pieces[k].ids for k in members) if i is not None]
        out.append(
            MergedPlane(
                _refit(pieces, members, new_id),
                tuple(members),
                pts,
                None if len(ids) < len(members) else np.concatenate(ids),
            )
        )
    return out


def dedupe_points(points: Sequence[ControlPoint], radius: float) -> list[ControlPoint]:
    """One LCP per plane triple and per location: of the LCPs that tiles found for the same
    plane triple, or within ``radius`` of each other, the most precise (smallest trace of the
    covariance) is kept; ids renumbered 0.. in the order kept."""
    order = sorted(points, key=lambda p: float(np.trace(p.covariance)))
    kept: list[ControlPoint] = []
    triples: set[tuple[int, ...]] = set()
    for p in order:
        key = tuple(sorted(p.plane_ids))
        if key in triples:
            continue
        if any(float(np.linalg.norm(p.xyz - q.xyz)) < radius for q in kept):
            continue
        triples.add(key)
        kept.append(p)
    kept.sort(key=lambda p: tuple(p.xyz.tolist()))
    from dataclasses import replace

    return [replace(p, id=k) for k, p in enumerate(kept)]


def dedupe_lines(lines: Sequence[ControlLine]) -> list[ControlLine]:
    """One line per plane pair: the longest of those the tiles found (the tile that saw most
    of the common boundary); ids renumbered 0.. by plane pair."""
    best: dict[tuple[int, ...], ControlLine] = {}
    for ln in lines:
        key = tuple(sorted(ln.plane_ids))
        if key not in best or ln.length > best[key].length:
            best[key] = ln
    from dataclasses import replace

    return [replace(best[k], id=n) for n, k in enumerate(sorted(best))]
