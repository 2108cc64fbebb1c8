"""Synthetic terrains with known ground, for choosing and testing ground filters.

Each scene is one terrain class that ground filters are known to find hard (Sithole &
Vosselman 2004): steep ``slopes`` with forest and buildings on them, ``cliffs`` and a quarry,
agricultural ``terraces``, ``bridges`` (a river bridge and a road overpass with their ramps),
data ``gaps`` (lakes, occlusions), ``low_outliers`` (multipath, single and in clusters),
``high_outliers`` (birds, wires) and ``dense_buildings`` (a city block with courtyards and
narrow streets). Every scene also has some ordinary objects (trees, cars, hedges) so that no
class is only its hard part.

Points are sampled like an airborne scanner without return numbers (as the ISPRS reference
samples): horizontal positions uniform at ``density`` points per m^2, each returning the top
surface (a roof, a deck, a car, a random depth inside a tree crown, or the ground); a crown
hit also gives, with probability 0.3, a ground return beneath it; water and occluded areas
return nothing; a slope steeper than 60 degrees returns points along its face in proportion
to its height (the scanner sees it obliquely). Every coordinate gets Gaussian noise
``noise_sigma``. The truth is ``ground`` per point: terrain (ramps, embankments, cliff faces,
terrace risers included) is ground; buildings, bridge decks, vegetation, cars and outliers
are not (the ISPRS convention: bridges are objects, ramps are ground).

Coordinates: a local projected frame in metres (x east, y north, z up), origin at the
scene's lower-left corner.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError

__all__ = ["TERRAIN_CLASSES", "TerrainScene", "make_terrain"]

Array = NDArray[np.float64]

TERRAIN_CLASSES: tuple[str, ...] = (
    "slopes",
    "cliffs",
    "terraces",
    "bridges",
    "gaps",
    "low_outliers",
    "high_outliers",
    "dense_buildings",
)
#: Probability of a ground return beneath a crown hit.
GROUND_UNDER_TREES = 0.3


@dataclass(frozen=True)
class TerrainScene:
    """Points of one synthetic terrain and their truth.

    Attributes
    ----------
    name : str
        One of ``TERRAIN_CLASSES``.
    xyz : ndarray, shape (N, 3)
        Noisy points, metres.
    ground : ndarray, shape (N,), bool
        True for points on the terrain.
    kind : ndarray, shape (N,), int8
        What each point hit: 0 terrain, 1 building, 2 vegetation, 3 bridge deck, 4 car or
        hedge, 5 low outlier, 6 high outlier.
    density : float
        Points per m^2 the scene was sampled at.
    """

    name: str
    xyz: Array
    ground: NDArray[np.bool_]
    kind: NDArray[np.int8]
    density: float


TERRAIN, BUILDING, VEGETATION, DECK, SMALL, LOW, HIGH = range(7)


@dataclass(frozen=True)
class _Box:
    """A flat-topped object over a rotated rectangle (optionally with a rectangular hole):
    its top is at ``height`` above the highest ground of its footprint (``top`` absolute when
    given)."""

    cx: float
    cy: float
    length: float
    width: float
    angle: float
    height: float
    kind: int = BUILDING
    hole: float = 0.0  # side ratio of a central courtyard (0 = none)
    top: float | None = None

    def local(self, x: Array, y: Array) -> tuple[Array, Array]:
        c, s = math.cos(self.angle), math.sin(self.angle)
        dx, dy = x - self.cx, y - self.cy
        return c * dx + s * dy, -s * dx + c * dy

    def inside(self, x: Array, y: Array) -> NDArray[np.bool_]:
        u, v = self.local(x, y)
        a, b = np.abs(u) / (self.length / 2), np.abs(v) / (self.width / 2)
        m = (a <= 1) & (b <= 1)
        if self.hole > 0:
            m &= ~((a <= self.hole) & (b <= self.hole))
        return m


@dataclass(frozen=True)
class _Tree:
    x: float
    y: float
    radius: float
    base: float  # crown bottom above ground
    top: float  # crown top above ground


def _sample(
    name: str,
    size: tuple[float, float],
    density: float,
    ground_z: Callable[[Array, Array], Array],
    boxes: list[_Box],
    trees: list[_Tree],
    rng: np.random.Generator,
    noise: float,
    void: Callable[[Array, Array], np.ndarray] | None = None,
) -> tuple[list[Array], list[NDArray[np.int8]]]:
    """Top-surface sampling of a scene: (points, kinds) lists."""
    w, h = size
    n = int(rng.poisson(density * w * h))
    x = rng.uniform(0.0, w, n)
    y = rng.uniform(0.0, h, n)
    g = ground_z(x, y)
    z = g.copy()
    kind = np.full(n, TERRAIN, dtype=np.int8)
    # steep ground seen obliquely: points along faces steeper than 60 degrees
    e = 0.25
    gx = (ground_z(x + e, y) - ground_z(x - e, y)) / (2 * e)
    gy = (ground_z(x, y + e) - ground_z(x, y - e)) / (2 * e)
    steep = np.hypot(gx, gy)
    face = steep > math.tan(math.radians(60))
    extra_x, extra_y, extra_z = [], [], []
    if face.any():
        # a sample on a face stands for ~1/density m^2 of plan; the face there is steep x
        # wider: spread that many points along the fall line
        idx = np.flatnonzero(face)
        reps = np.minimum(np.round(steep[idx] / math.tan(math.radians(60))), 20).astype(int)
        src = np.repeat(idx, reps)
        t = rng.uniform(-0.5, 0.5, len(src)) / np.sqrt(density)
        ux, uy = gx[src] / steep[src], gy[src] / steep[src]
        ex, ey = x[src] + t * ux, y[src] + t * uy
        extra_x.append(ex)
        extra_y.append(ey)
        extra_z.append(ground_z(ex, ey))
    for box in boxes:
        m = box.inside(x, y)
        if not m.any():
            continue
        if box.top is not None:
            top = box.top
        else:
            # the highest ground under the footprint: sample its rectangle
            uu, vv = np.meshgrid(np.linspace(-0.5, 0.5, 9), np.linspace(-0.5, 0.5, 9))
            c, s = math.cos(box.angle), math.sin(box.angle)
            px = box.cx + c * uu.ravel() * box.length - s * vv.ravel() * box.width
            py = box.cy + s * uu.ravel() * box.length + c * vv.ravel() * box.width
            top = float(ground_z(px, py).max()) + box.height
        higher = m & (z < top)
        z[higher] = top
        kind[higher] = box.kind
    under = []
    for tree in trees:
        r2 = ((x - tree.x) ** 2 + (y - tree.y) ** 2) / tree.radius**2
        hit = np.flatnonzero(r2 < 1.0)
        if not len(hit):
            continue
        half = (tree.top - tree.base) / 2
        mid = g[hit] + tree.base + half
        depth = mid + half * np.sqrt(1.0 - r2[hit]) * rng.uniform(-1.0, 1.0, len(hit))
        higher = depth > z[hit]
        hit, depth = hit[higher], depth[higher]
        z[hit] = depth
        kind[hit] = VEGETATION
        under.append(hit[rng.random(len(hit)) < GROUND_UNDER_TREES])
    pts = [np.column_stack([x, y, z])]
    kinds = [kind]
    if under:
        u = np.concatenate(under)
        pts.append(np.column_stack([x[u], y[u], g[u]]))
        kinds.append(np.full(len(u), TERRAIN, dtype=np.int8))
    if extra_x:
        ex, ey, ez = (np.concatenate(a) for a in (extra_x, extra_y, extra_z))
        covered = np.zeros(len(ex), dtype=bool)
        for box in boxes:
            covered |= box.inside(ex, ey)
        keep = ~covered
        pts.append(np.column_stack([ex[keep], ey[keep], ez[keep]]))
        kinds.append(np.full(int(keep.sum()), TERRAIN, dtype=np.int8))
    if void is not None:
        for i, p in enumerate(pts):
            keep = ~void(p[:, 0], p[:, 1]) | (kinds[i] != TERRAIN)
            pts[i], kinds[i] = p[keep], kinds[i][keep]
    for i, p in enumerate(pts):
        pts[i] = p + rng.normal(0.0, noise, p.shape)
    return pts, kinds


def _scatter_trees(
    rng: np.random.Generator, n: int, box: tuple[float, float, float, float], big: bool = True
) -> list[_Tree]:
    x0, y0, x1, y1 = box
    out = []
    for _ in range(n):
        r = rng.uniform(2.5, 5.0) if big else rng.uniform(1.0, 2.0)
        base = rng.uniform(1.0, 4.0) if big else rng.uniform(0.2, 0.8)
        top = base + (rng.uniform(5.0, 14.0) if big else rng.uniform(1.0, 2.5))
        out.append(_Tree(rng.uniform(x0, x1), rng.uniform(y0, y1), r, base, top))
    return out


def _scatter_small(
    rng: np.random.Generator, n: int, box: tuple[float, float, float, float]
) -> list[_Box]:
    """Cars (4.5 x 1.8 m, 1.5 m) and hedges (10-25 x 1 m, 1-2 m)."""
    x0, y0, x1, y1 = box
    out = []
    for k in range(n):
        cx, cy, a = rng.uniform(x0, x1), rng.uniform(y0, y1), rng.uniform(0, math.pi)
        if k % 3:
            out.append(_Box(cx, cy, 4.5, 1.8, a, 1.5, SMALL))
        else:
            out.append(_Box(cx, cy, rng.uniform(10, 25), 1.0, a, rng.uniform(1.0, 2.0), SMALL))
    return out


def _houses(
    rng: np.random.Generator, n: int, box: tuple[float, float, float, float], big: float = 1.0
) -> list[_Box]:
    x0, y0, x1, y1 = box
    return [
        _Box(
            rng.uniform(x0, x1),
            rng.uniform(y0, y1),
            big * rng.uniform(10, 22),
            big * rng.uniform(8, 14),
            rng.uniform(0, math.pi),
            rng.uniform(4.0, 12.0),
        )
        for _ in range(n)
    ]


class _Layout(NamedTuple):
    """One terrain class's scene before sampling: the ground height function (x, y arrays ->
    z, metres), the boxes and trees standing on it, and where no return comes back (None:
    everywhere)."""

    ground: Callable[[Array, Array], Array]
    boxes: list[_Box]
    trees: list[_Tree]
    void: Callable[[Array, Array], Array] | None


def _layout_slopes(rng: np.random.Generator, L: float) -> _Layout:
    """A hillside steepening from 24 to 50 degrees under a closed forest, with houses."""
    full = (0.0, 0.0, L, L)

    # a hillside steepening from 24 to 50 degrees, with spurs; closed forest on the upper
    # part, shrubs (1-2.5 m) everywhere, houses low down and on the steep part
    def ground(x, y):
        return (
            0.45 * x
            + 0.25 * L * np.tanh((x - 0.6 * L) / (0.25 * L)) * 0.8
            + (6.0 * np.sin(y / 23.0) * np.cos(x / 31.0))
        )

    # a closed canopy: a crown every 25 m^2 (the ground seen only through it)
    trees = _scatter_trees(rng, int(0.55 * L * L / 25), (0.45 * L, 0, L, L))
    trees += _scatter_trees(rng, int(L * L / 150), full, big=False)
    boxes = _houses(rng, 6, (0.08 * L, 0.1 * L, 0.4 * L, 0.9 * L))
    boxes += _houses(rng, 3, (0.5 * L, 0.1 * L, 0.9 * L, 0.9 * L))
    boxes += _scatter_small(rng, 10, (0, 0, 0.4 * L, L))
    return _Layout(ground, boxes, trees, None)


def _layout_cliffs(rng: np.random.Generator, L: float) -> _Layout:
    """A plateau behind a curved cliff and a quarry pit."""
    full = (0.0, 0.0, L, L)

    # a plateau 12 m above the plain behind a curved cliff, a quarry pit 9 m deep
    def ground(x, y):
        edge = 0.55 * L + 10.0 * np.sin(y / 19.0)
        plateau = 12.0 / (1.0 + np.exp(-(x - edge) / 0.6))
        r = np.hypot(x - 0.25 * L, y - 0.3 * L)
        pit = -9.0 / (1.0 + np.exp(-(0.12 * L - r) / 0.5))
        return 0.02 * y + plateau + pit

    trees = _scatter_trees(rng, int(L * L / 600), full)
    boxes = _houses(rng, 4, (0.6 * L, 0.5 * L, 0.95 * L, 0.95 * L))
    boxes += _scatter_small(rng, 8, full)
    return _Layout(ground, boxes, trees, None)


def _layout_terraces(rng: np.random.Generator, L: float) -> _Layout:
    """Steps across a hillside with vines in rows on the treads."""
    full = (0.0, 0.0, L, L)

    # 2.2 m steps every 16 m across a hillside (risers 1:1), vines in rows on the treads
    def ground(x, y):
        k = x / 16.0
        step = np.floor(k) + 1.0 / (1.0 + np.exp(-((k - np.floor(k)) - 0.93) * 40.0))
        return 2.2 * step + 0.02 * x + 1.5 * np.sin(y / 40.0)

    boxes: list[_Box] = []
    for i in range(int(L / 16)):
        for j in range(3):
            boxes.append(_Box(16.0 * i + 4.0 + 3.5 * j, L / 2, 1.0, 0.8 * L, 0.0, 1.6, VEGETATION))
    trees = _scatter_trees(rng, int(L * L / 1500), full)
    boxes += _houses(rng, 3, (0.1 * L, 0.05 * L, 0.9 * L, 0.2 * L))
    return _Layout(ground, boxes, trees, None)


def _layout_bridges(rng: np.random.Generator, L: float) -> _Layout:
    """A river with a bridge on embankment ramps, a highway over a road."""
    full = (0.0, 0.0, L, L)

    # a river (no returns) in a floodplain, embankment ramps up to a bridge deck 7 m over
    # the plain; a highway on an embankment crossing a road on an overpass
    river_y = 0.35 * L

    def ramp(x, y):
        # an embankment along y at x = 0.5 L: 12 m wide on top, side slopes 1:1.5,
        # rising at 12 % to 7 m at the bridge abutments, 14 m from the river's axis
        dist = np.abs(y - river_y)
        crest = np.where(dist > 14.0, np.clip(7.0 - (dist - 14.0) * 0.12, 0.0, 7.0), 0.0)
        return np.clip(crest - (np.abs(x - 0.5 * L) - 6.0) / 1.5, 0.0, crest)

    def highway(x, y):
        # an embankment 5 m high along x at y = 0.75 L, cut by a road (x near 0.3 L)
        across = np.abs(y - 0.75 * L) < 8.0
        cut = np.abs(x - 0.3 * L) < 7.0
        side = np.clip(5.0 - (np.abs(y - 0.75 * L) - 8.0) * 0.5, 0.0, 5.0)
        return np.where(cut, 0.0, np.where(across, 5.0, side))

    def ground(x, y):
        bank = -2.0 / (1.0 + np.exp(-(12.0 - np.abs(y - river_y)) / 1.0))
        return 0.01 * x + bank + np.maximum(ramp(x, y), highway(x, y))

    def void(x, y):
        return np.abs(y - river_y) < 10.0

    boxes = [
        _Box(0.5 * L, river_y, 12.0, 28.0, 0.0, 0.0, DECK, top=7.0 + 0.005 * L),
        _Box(0.3 * L, 0.75 * L, 14.0, 16.0, 0.0, 0.0, DECK, top=5.0 + 0.003 * L),
    ]
    boxes += _scatter_small(rng, 12, full)
    trees = _scatter_trees(rng, int(L * L / 900), (0, 0.45 * L, L, 0.65 * L))
    boxes += _houses(rng, 3, (0.65 * L, 0.05 * L, 0.95 * L, 0.2 * L))
    return _Layout(ground, boxes, trees, void)


def _layout_gaps(rng: np.random.Generator, L: float) -> _Layout:
    """Rolling ground with two lakes and an occluded strip."""
    full = (0.0, 0.0, L, L)

    # rolling ground with two lakes (no returns), an occluded strip, buildings at the shore
    def ground(x, y):
        return 4.0 * np.sin(x / 37.0) + 3.0 * np.cos(y / 29.0) + 0.03 * x

    def void(x, y):
        lake1 = np.hypot((x - 0.3 * L) / 0.2, (y - 0.35 * L) / 0.15) < L
        lake2 = np.hypot((x - 0.75 * L) / 0.12, (y - 0.7 * L) / 0.2) < L
        strip = np.abs(x + 0.4 * y - 0.9 * L) < 4.0
        return lake1 | lake2 | strip

    boxes = [
        _Box(0.3 * L + 0.23 * L, 0.35 * L, 18.0, 12.0, 0.3, 9.0),
        _Box(0.75 * L - 0.17 * L, 0.7 * L + 0.1 * L, 24.0, 14.0, 1.2, 14.0),
    ]
    boxes += _houses(rng, 5, (0.05 * L, 0.65 * L, 0.45 * L, 0.95 * L))
    trees = _scatter_trees(rng, int(L * L / 800), full)
    boxes += _scatter_small(rng, 8, full)
    return _Layout(ground, boxes, trees, void)


def _layout_outliers(rng: np.random.Generator, L: float) -> _Layout:
    """Gentle ground with houses and trees (the outliers are added after sampling)."""

    def ground(x, y):
        return 2.0 * np.sin(x / 45.0) * np.cos(y / 35.0) + 0.05 * y

    boxes = _houses(rng, 10, (0.05 * L, 0.05 * L, 0.95 * L, 0.95 * L))
    trees = _scatter_trees(rng, int(L * L / 700), (0.0, 0.0, L, L))
    boxes += _scatter_small(rng, 12, (0.0, 0.0, L, L))
    return _Layout(ground, boxes, trees, None)


def _layout_dense_buildings(rng: np.random.Generator, L: float) -> _Layout:
    """A city block of large buildings with courtyards along narrow streets."""
    full = (0.0, 0.0, L, L)

    # a city block: large buildings with courtyards along narrow streets, 2 % slope
    def ground(x, y):
        return 0.02 * x + 0.01 * y

    boxes: list[_Box] = []
    street = 10.0
    x = street
    while x < L - 20:
        wx = rng.uniform(30.0, 80.0)
        y = street
        while y < L - 20:
            wy = rng.uniform(25.0, 70.0)
            ww, hh = min(wx, L - x - 2), min(wy, L - y - 2)
            hole = rng.uniform(0.35, 0.6) if min(ww, hh) > 40 else 0.0
            boxes.append(
                _Box(x + ww / 2, y + hh / 2, ww, hh, 0.0, rng.uniform(6.0, 30.0), hole=hole)
            )
            y += wy + street
        x += wx + street
    boxes += _scatter_small(rng, 25, full)
    trees = _scatter_trees(rng, int(L * L / 2500), full)
    return _Layout(ground, boxes, trees, None)


#: the layout builder of each class (the two outlier classes share one layout)
_LAYOUTS: dict[str, Callable[[np.random.Generator, float], _Layout]] = {
    "slopes": _layout_slopes,
    "cliffs": _layout_cliffs,
    "terraces": _layout_terraces,
    "bridges": _layout_bridges,
    "gaps": _layout_gaps,
    "low_outliers": _layout_outliers,
    "high_outliers": _layout_outliers,
    "dense_buildings": _layout_dense_buildings,
}


def _add_low_outliers(
    rng: np.random.Generator, xyz: Array, kind: NDArray[np.int8], L: float
) -> tuple[Array, NDArray[np.int8]]:
    """Append multipath points below the ground: singles and clusters (kind LOW)."""
    # single multipath points, one per 150 m^2, 1.5-25 m down
    singles = rng.choice(np.flatnonzero(kind == TERRAIN), int(L * L / 150), replace=False)
    low = xyz[singles].copy()
    low[:, 2] -= rng.uniform(1.5, 25.0, len(low))
    # clusters of multipath points, one per 1000 m^2: 12 points within about 1.5 m,
    # 3-8 m down
    centres = xyz[rng.choice(np.flatnonzero(kind == TERRAIN), max(int(L * L / 1000), 1))]
    cl = np.repeat(centres, 12, axis=0)
    cl[:, :2] += rng.normal(0.0, 0.5, (len(cl), 2))
    cl[:, 2] -= np.repeat(rng.uniform(3.0, 8.0, len(centres)), 12)
    cl[:, 2] += rng.normal(0.0, 0.3, len(cl))
    xyz = np.concatenate([xyz, low, cl])
    kind = np.concatenate([kind, np.full(len(low) + len(cl), LOW, dtype=np.int8)])
    return xyz, kind


def _add_high_outliers(
    rng: np.random.Generator, xyz: Array, kind: NDArray[np.int8], n: int
) -> tuple[Array, NDArray[np.int8]]:
    """Append points above the scene (kind HIGH): birds and clouds, 0.5 % of the ``n``
    sampled points; 30 % of them wires 3-12 m up."""
    m = int(0.005 * n)
    src = rng.choice(n, m, replace=False)
    high = xyz[src].copy()
    high[:, 2] += np.where(
        rng.random(m) < 0.3, rng.uniform(3.0, 12.0, m), rng.uniform(20.0, 250.0, m)
    )
    xyz = np.concatenate([xyz, high])
    kind = np.concatenate([kind, np.full(m, HIGH, dtype=np.int8)])
    return xyz, kind


def make_terrain(
    name: str,
    *,
    size: float = 160.0,
    density: float = 2.0,
    noise_sigma: float = 0.05,
    seed: int = 0,
) -> TerrainScene:
    """Sample one synthetic terrain class (module docstring) with its truth.

    Parameters
    ----------
    name : str
        One of ``TERRAIN_CLASSES``.
    size : float
        Side of the square scene, metres (>= 100).
    density : float
        Points per m^2 of horizontal area (> 0).
    noise_sigma : float
        Standard deviation of the noise on each coordinate, metres.
    seed : int
        Seed of the layout, the sampling and the noise.

    Returns
    -------
    TerrainScene

    Examples
    --------
    >>> s = make_terrain("bridges", size=120, density=1.0, seed=1)
    >>> s.xyz.shape[1], bool(s.ground.any()), bool((s.kind == DECK).any())
    (3, True, True)
    """
    if name not in TERRAIN_CLASSES:
        raise InputError(f"terrain class must be one of {', '.join(TERRAIN_CLASSES)}, got {name!r}")
    if not (size >= 100 and density > 0 and noise_sigma >= 0):
        raise InputError("size must be >= 100 m, density > 0 and noise_sigma >= 0")
    rng = np.random.default_rng([seed, TERRAIN_CLASSES.index(name)])
    L = float(size)
    ground, boxes, trees, void = _LAYOUTS[name](rng, L)
    pts, kinds = _sample(name, (L, L), density, ground, boxes, trees, rng, noise_sigma, void)
    xyz = np.concatenate(pts)
    kind = np.concatenate(kinds)
    n = len(xyz)
    if name == "low_outliers":
        xyz, kind = _add_low_outliers(rng, xyz, kind, L)
    if name == "high_outliers":
        xyz, kind = _add_high_outliers(rng, xyz, kind, n)
    order = rng.permutation(len(xyz))
    xyz, kind = xyz[order], kind[order]
    return TerrainScene(name, xyz, kind == TERRAIN, kind, float(density))
