"""A synthetic town with known geometry, and airborne-LiDAR-like points sampled from it.

The town (``make_town``) is pure geometry: a sloping terrain plane, rectangular buildings with
gable, hip, pyramid, shed or flat roofs (each roof face a known plane with its polygon, the
ridge and hip lines, the footprint), vertical walls, and trees (ellipsoidal crowns). Sampling
(``sample_town``) draws points at a given horizontal density with isotropic Gaussian noise and
labels each with its LAS class (2 ground, 5 high vegetation, 6 building), roof face id and
building id. Geometry and sampling take separate seeds, so the same town can be re-sampled
with fresh noise (Monte Carlo) and a flight simulator can replace ``sample_town`` while
keeping the truth.

Coordinates: a projected CRS in metres (any, e.g. RD New near Delft by default); x east,
y north, z up. Planes follow docs/conventions.md: ``n . p + d = 0``, unit n with c >= 0.

Roof model. A roof is the lower envelope of its face planes over the footprint: face f rises
from its eave edge (outward horizontal direction ``o_f`` in the building frame, at distance
``h_f`` from the centre) with slope s, ``z_f(u, v) = z_eave + tan(s) (h_f - o_f . (u, v))``,
and the roof height is ``min_f z_f``. Gable: the two long sides; hip: all four sides;
pyramid: four sides of a square; shed: one long side (slope across the width); flat: one
horizontal face at the eave height.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError

__all__ = [
    "CLASS_BUILDING",
    "CLASS_GROUND",
    "CLASS_VEGETATION",
    "ROOF_TYPES",
    "Building",
    "RoofFace",
    "Town",
    "TownPoints",
    "Tree",
    "make_town",
    "sample_town",
    "simulate_town",
]

Array = NDArray[np.float64]

ROOF_TYPES: tuple[str, ...] = ("gable", "hip", "pyramid", "shed", "flat")
CLASS_GROUND = 2
CLASS_VEGETATION = 5
CLASS_BUILDING = 6


@dataclass(frozen=True)
class RoofFace:
    """One planar roof face.

    Attributes
    ----------
    face_id : int
        Unique in the town (0, 1, ...), as in ``TownPoints.face_id``.
    building_id : int
        Building the face belongs to.
    roof_type : str
        One of ``ROOF_TYPES``.
    normal : ndarray, shape (3,)
        Unit normal, c > 0.
    d : float
        ``normal . p + d = 0``, metres.
    polygon : ndarray, shape (M, 3)
        Corner points of the face (counter-clockwise seen from above, not closed), metres.
    """

    face_id: int
    building_id: int
    roof_type: str
    normal: Array
    d: float
    polygon: Array

    @property
    def params(self) -> Array:
        """(a, b, c, d), shape (4,)."""
        return np.append(self.normal, self.d)

    @property
    def area(self) -> float:
        """Area of the (sloping) face, m^2."""
        xy = self.polygon[:, :2] - self.polygon[0, :2]  # centred: map coordinates lose digits
        plan = 0.5 * abs(
            float(np.dot(xy[:, 0], np.roll(xy[:, 1], -1)) - np.dot(xy[:, 1], np.roll(xy[:, 0], -1)))
        )
        return plan / float(self.normal[2])

    @property
    def slope_deg(self) -> float:
        """Angle to the horizontal, degrees."""
        return math.degrees(math.acos(min(1.0, float(self.normal[2]))))


@dataclass(frozen=True)
class Building:
    """A rectangular building.

    Attributes
    ----------
    building_id : int
    roof_type : str
    centre : ndarray, shape (2,)
        Footprint centre (x, y), metres.
    length, width : float
        Footprint sides along the building's u and v axes, metres (length >= width).
    rotation_rad : float
        Angle of the u axis from grid east, counter-clockwise.
    base_z, eave_z : float
        Terrain height at the centre and eave height (top of the walls), metres.
    slope_deg : float
        Roof slope (0 for flat roofs).
    footprint : ndarray, shape (4, 3)
        Footprint corners at eave height, counter-clockwise.
    ridges : ndarray, shape (R, 2, 3)
        Ridge and hip lines (segments where two faces meet).
    face_ids : tuple of int
    """

    building_id: int
    roof_type: str
    centre: Array
    length: float
    width: float
    rotation_rad: float
    base_z: float
    eave_z: float
    slope_deg: float
    footprint: Array
    ridges: Array
    face_ids: tuple[int, ...]

    def to_local(self, xy: Array) -> Array:
        """Map (N, 2) -> building frame (u along the length, v across), (N, 2)."""
        c, s = math.cos(self.rotation_rad), math.sin(self.rotation_rad)
        q = np.asarray(xy, dtype=np.float64) - self.centre
        return np.column_stack([c * q[:, 0] + s * q[:, 1], -s * q[:, 0] + c * q[:, 1]])

    def inside(self, xy: Array) -> NDArray[np.bool_]:
        """Whether (N, 2) map points fall inside the footprint, (N,)."""
        uv = self.to_local(xy)
        return (np.abs(uv[:, 0]) <= self.length / 2) & (np.abs(uv[:, 1]) <= self.width / 2)


@dataclass(frozen=True)
class Tree:
    """A tree: ellipsoidal crown of horizontal radius ``crown_radius`` between ``crown_base``
    and ``top`` (heights, metres) above the ground point ``position`` (3,)."""

    position: Array
    crown_radius: float
    crown_base: float
    top: float


@dataclass(frozen=True)
class Town:
    """The truth: terrain plane, buildings, roof faces and trees.

    ``terrain`` is (a, b, c, d) of the terrain plane; ``extent`` is (xmin, ymin, xmax, ymax).
    """

    buildings: tuple[Building, ...]
    faces: tuple[RoofFace, ...]
    trees: tuple[Tree, ...]
    terrain: Array
    extent: tuple[float, float, float, float]

    def terrain_z(self, xy: Array) -> Array:
        """Terrain height at map points (N, 2), (N,)."""
        a, b, c, d = self.terrain
        xy = np.asarray(xy, dtype=np.float64)
        return -(a * xy[:, 0] + b * xy[:, 1] + d) / c

    def roof_z(self, building: Building, xy: Array) -> tuple[Array, NDArray[np.int64]]:
        """Roof height and face id at map points (N, 2) of ``building``: ((N,), (N,))."""
        xy = np.asarray(xy, dtype=np.float64)
        faces = [self.faces[f] for f in building.face_ids]
        z = np.stack(
            [-(f.normal[0] * xy[:, 0] + f.normal[1] * xy[:, 1] + f.d) / f.normal[2] for f in faces]
        )
        k = np.argmin(z, axis=0)
        return z[k, np.arange(len(xy))], np.asarray(building.face_ids)[k]


@dataclass(frozen=True)
class TownPoints:
    """Sampled points with their truth labels.

    Attributes
    ----------
    xyz : ndarray, shape (N, 3)
        Noisy points, metres.
    classification : ndarray, shape (N,), uint8
        LAS class: 2 ground, 5 high vegetation, 6 building (roofs and walls).
    face_id : ndarray, shape (N,), int32
        Roof face of the point, -1 for anything else.
    building_id : ndarray, shape (N,), int32
        Building of the point (roof or wall), -1 otherwise.
    is_wall : ndarray, shape (N,), bool
    """

    xyz: Array
    classification: NDArray[np.uint8]
    face_id: NDArray[np.int32]
    building_id: NDArray[np.int32]
    is_wall: NDArray[np.bool_]


def _clip(poly: Array, g: Array, h: float) -> Array:
    """Keep the part of a convex polygon (M, 2) where g . p <= h (Sutherland-Hodgman)."""
    out = []
    m = len(poly)
    for i in range(m):
        p, q = poly[i], poly[(i + 1) % m]
        fp, fq = float(g @ p) - h, float(g @ q) - h
        if fp <= 0:
            out.append(p)
        if fp * fq < 0:
            out.append(p + (q - p) * (fp / (fp - fq)))
    return np.array(out).reshape(-1, 2)


def _faces_of(roof_type: str, length: float, width: float) -> list[tuple[Array, float]]:
    """Outward directions o_f (building frame) and eave distances h_f of the roof faces."""
    sides = {
        "u+": (np.array([1.0, 0.0]), length / 2),
        "u-": (np.array([-1.0, 0.0]), length / 2),
        "v+": (np.array([0.0, 1.0]), width / 2),
        "v-": (np.array([0.0, -1.0]), width / 2),
    }
    names = {
        "gable": ("v+", "v-"),
        "hip": ("v+", "u+", "v-", "u-"),
        "pyramid": ("v+", "u+", "v-", "u-"),
        "shed": ("v-",),
        "flat": ("v-",),
    }[roof_type]
    return [sides[n] for n in names]


def _build(
    building_id: int,
    first_face: int,
    roof_type: str,
    centre: Array,
    length: float,
    width: float,
    rotation: float,
    base_z: float,
    wall_height: float,
    slope_deg: float,
) -> tuple[Building, list[RoofFace]]:
    eave_z = base_z + wall_height
    t = math.tan(math.radians(slope_deg))
    rot = np.array(
        [[math.cos(rotation), -math.sin(rotation)], [math.sin(rotation), math.cos(rotation)]]
    )
    rect = np.array(
        [
            [-length / 2, -width / 2],
            [length / 2, -width / 2],
            [length / 2, width / 2],
            [-length / 2, width / 2],
        ]
    )
    specs = _faces_of(roof_type, length, width)
    if roof_type == "shed":
        # one face across the whole width: its eave is the v- side, it rises towards v+
        specs = [(np.array([0.0, -1.0]), width / 2)]
    faces = []
    polys_local = []
    for k, (o, h) in enumerate(specs):
        # z_k(p) = eave + t (h - o.p); face k is the lowest where z_k <= z_j for all j:
        # t (h_k - h_j) - t (o_k - o_j).p <= 0  <=>  (o_j - o_k).p <= h_j - h_k
        poly = rect.copy()
        for j, (oj, hj) in enumerate(specs):
            if j != k:
                poly = _clip(poly, oj - o, hj - h)
        polys_local.append(poly)
        o_map = rot @ o
        # plane: t o_map . (xy - c) + z - (eave + t h) = 0
        raw = np.array([t * o_map[0], t * o_map[1], 1.0])
        norm = float(np.linalg.norm(raw))
        normal = raw / norm
        d = (-(eave_z + t * h) - t * float(o_map @ centre)) / norm
        xy = poly @ rot.T + centre
        z = -(normal[0] * xy[:, 0] + normal[1] * xy[:, 1] + d) / normal[2]
        faces.append(
            RoofFace(first_face + k, building_id, roof_type, normal, d, np.column_stack([xy, z]))
        )
    # ridges: polygon edges that are not on the footprint boundary
    ridges: list[Array] = []
    for face, poly in zip(faces, polys_local):
        m = len(poly)
        for i in range(m):
            p, q = poly[i], poly[(i + 1) % m]
            mid = (p + q) / 2
            on_boundary = (abs(abs(mid[0]) - length / 2) < 1e-9) or (
                abs(abs(mid[1]) - width / 2) < 1e-9
            )
            if not on_boundary and np.linalg.norm(q - p) > 1e-9:
                seg = face.polygon[[i, (i + 1) % m]]
                if not any(np.allclose(seg[::-1], r) or np.allclose(seg, r) for r in ridges):
                    ridges.append(seg)
    footprint = np.column_stack([rect @ rot.T + centre, np.full(4, eave_z)])
    building = Building(
        building_id,
        roof_type,
        np.asarray(centre, dtype=np.float64),
        length,
        width,
        rotation,
        base_z,
        eave_z,
        slope_deg if roof_type != "flat" else 0.0,
        footprint,
        np.array(ridges).reshape(-1, 2, 3),
        tuple(f.face_id for f in faces),
    )
    return building, faces


def make_town(
    *,
    n_buildings: int = 10,
    roof_types: Sequence[str] = ROOF_TYPES,
    n_trees: int = 8,
    origin: tuple[float, float] = (85000.0, 447000.0),
    cell: float = 30.0,
    terrain_height: float = 2.0,
    terrain_slope_deg: float = 3.0,
    terrain_aspect_deg: float = 210.0,
    seed: int = 0,
) -> Town:
    """Lay out a town on a grid of square cells: buildings first, then trees, cyclic roof types.

    Parameters
    ----------
    n_buildings : int
        Number of buildings; roof types cycle through ``roof_types``.
    roof_types : sequence of str
        Subset of ``ROOF_TYPES``.
    n_trees : int
        Trees, in the cells after the buildings (one per cell, random crown sizes).
    origin : (float, float)
        Lower-left corner of the grid, metres in the projected CRS.
    cell : float
        Cell side, metres (>= 25: buildings are up to 18 m long, trees up to 4 m in radius).
    terrain_height, terrain_slope_deg, terrain_aspect_deg : float
        Terrain plane: height at the origin (m), slope (degrees) and downslope direction
        (degrees clockwise from grid north).
    seed : int
        Seed of the layout (sizes, rotations, slopes, tree shapes).

    Returns
    -------
    Town

    Examples
    --------
    >>> town = make_town(n_buildings=5, n_trees=0)
    >>> [b.roof_type for b in town.buildings], len(town.faces)
    (['gable', 'hip', 'pyramid', 'shed', 'flat'], 12)
    """
    bad = [r for r in roof_types if r not in ROOF_TYPES]
    if bad or not roof_types:
        raise InputError(f"roof types must be among {', '.join(ROOF_TYPES)}, got {bad}")
    if n_buildings < 0 or n_trees < 0 or cell < 25.0:
        raise InputError("n_buildings and n_trees must be >= 0 and cell >= 25 m")
    rng = np.random.default_rng(seed)
    n_cells = n_buildings + n_trees
    cols = max(1, math.ceil(math.sqrt(max(n_cells, 1))))
    rows = max(1, math.ceil(n_cells / cols))
    ox, oy = origin
    s = math.tan(math.radians(terrain_slope_deg))
    asp = math.radians(terrain_aspect_deg)
    # z = h0 - s * (downslope unit . (xy - origin))
    down = np.array([math.sin(asp), math.cos(asp)])
    raw = np.array([s * down[0], s * down[1], 1.0])
    norm = float(np.linalg.norm(raw))
    terrain = np.append(raw / norm, (-terrain_height - s * float(down @ np.array(origin))) / norm)
    extent = (ox, oy, ox + cols * cell, oy + rows * cell)

    def ground(xy: Array) -> float:
        a, b, c, d = terrain
        return float(-(a * xy[0] + b * xy[1] + d) / c)

    buildings: list[Building] = []
    faces: list[RoofFace] = []
    trees: list[Tree] = []
    for i in range(n_cells):
        centre = np.array([ox + (i % cols + 0.5) * cell, oy + (i // cols + 0.5) * cell])
        centre = centre + rng.uniform(-1.5, 1.5, 2)
        if i < n_buildings:
            roof_type = roof_types[i % len(roof_types)]
            length = float(rng.uniform(11.0, 17.0))
            width = float(rng.uniform(7.0, 10.0))
            if roof_type == "pyramid":
                length = width
            slope = (
                float(rng.uniform(25.0, 45.0))
                if roof_type != "shed"
                else float(rng.uniform(10.0, 25.0))
            )
            if roof_type == "flat":
                slope = 0.0
            building, new_faces = _build(
                i,
                len(faces),
                roof_type,
                centre,
                length,
                width,
                float(rng.uniform(0.0, math.pi)),
                ground(centre),
                float(rng.uniform(4.0, 9.0)),
                slope,
            )
            buildings.append(building)
            faces.extend(new_faces)
        else:
            radius = float(rng.uniform(2.5, 4.0))
            base = float(rng.uniform(2.0, 4.0))
            top = base + float(rng.uniform(5.0, 9.0))
            trees.append(Tree(np.array([*centre, ground(centre)]), radius, base, top))
    return Town(tuple(buildings), tuple(faces), tuple(trees), terrain, extent)


def sample_town(
    town: Town,
    *,
    density: float = 8.0,
    noise_sigma: float = 0.03,
    wall_density: float = 1.0,
    ground_under_trees: float = 0.4,
    seed: int = 0,
) -> TownPoints:
    """Sample airborne-LiDAR-like points from a town.

    Horizontal positions are uniform (Poisson) at ``density``; each position returns the top
    surface: a roof, a tree crown (a random depth inside the crown, plus with probability
    ``ground_under_trees`` a ground return beneath), or the terrain. Walls get ``wall_density``
    points per m^2 of wall (oblique views). Every coordinate then gets N(0, noise_sigma^2).

    Parameters
    ----------
    town : Town
    density : float
        Points per m^2 of horizontal area.
    noise_sigma : float
        Standard deviation of the noise on x, y and z, metres.
    wall_density : float
        Points per m^2 of vertical wall.
    ground_under_trees : float
        Probability of an extra ground return below a crown hit, in [0, 1].
    seed : int
        Seed of the sampling and the noise.

    Returns
    -------
    TownPoints
    """
    if not (density > 0 and noise_sigma >= 0 and wall_density >= 0):
        raise InputError("density must be > 0, noise_sigma and wall_density >= 0")
    rng = np.random.default_rng(seed)
    xmin, ymin, xmax, ymax = town.extent
    n = int(rng.poisson(density * (xmax - xmin) * (ymax - ymin)))
    xy = np.column_stack([rng.uniform(xmin, xmax, n), rng.uniform(ymin, ymax, n)])
    z = town.terrain_z(xy)
    cls = np.full(n, CLASS_GROUND, dtype=np.uint8)
    face = np.full(n, -1, dtype=np.int32)
    bid = np.full(n, -1, dtype=np.int32)
    for b in town.buildings:
        inside = b.inside(xy)
        z[inside], face[inside] = town.roof_z(b, xy[inside])
        cls[inside] = CLASS_BUILDING
        bid[inside] = b.building_id
    extra = []
    for tree in town.trees:
        r2 = ((xy - tree.position[:2]) ** 2).sum(axis=1) / tree.crown_radius**2
        hit = np.flatnonzero(r2 < 1.0)
        half = (tree.top - tree.crown_base) / 2
        mid = tree.position[2] + tree.crown_base + half
        span = half * np.sqrt(1.0 - r2[hit])
        under = hit[rng.random(len(hit)) < ground_under_trees]
        extra.append(np.column_stack([xy[under], z[under]]))
        z[hit] = mid + span * rng.uniform(-1.0, 1.0, len(hit))
        cls[hit] = CLASS_VEGETATION
    pts = [np.column_stack([xy, z])]
    labels = [(cls, face, bid, np.zeros(n, dtype=bool))]
    for e in extra:
        pts.append(e)
        labels.append(_labels(len(e), CLASS_GROUND, -1, False))
    for b in town.buildings:
        w = _sample_walls(town, b, wall_density, rng)
        pts.append(w)
        labels.append(_labels(len(w), CLASS_BUILDING, b.building_id, True))
    xyz = np.concatenate(pts)
    xyz = xyz + rng.normal(0.0, noise_sigma, xyz.shape) if noise_sigma > 0 else xyz
    return TownPoints(
        xyz,
        np.concatenate([lab[0] for lab in labels]),
        np.concatenate([lab[1] for lab in labels]),
        np.concatenate([lab[2] for lab in labels]),
        np.concatenate([lab[3] for lab in labels]),
    )


def _labels(n: int, cls: int, building: int, wall: bool):
    return (
        np.full(n, cls, dtype=np.uint8),
        np.full(n, -1, dtype=np.int32),
        np.full(n, building, dtype=np.int32),
        np.full(n, wall, dtype=bool),
    )


def _sample_walls(town: Town, b: Building, wall_density: float, rng) -> Array:
    """Points on the four walls, from the terrain up to the roof edge above them (N, 3)."""
    corners = b.footprint[:, :2]
    out = []
    for i in range(4):
        p, q = corners[i], corners[(i + 1) % 4]
        length = float(np.linalg.norm(q - p))
        top_mid = float(town.roof_z(b, ((p + q) / 2)[None])[0][0])
        m = int(rng.poisson(wall_density * length * max(top_mid - b.base_z, 1.0)))
        xy = p + rng.uniform(0.0, 1.0, m)[:, None] * (q - p)
        top, _ = town.roof_z(b, xy)
        bottom = town.terrain_z(xy)
        out.append(np.column_stack([xy, bottom + rng.random(m) * (top - bottom)]))
    return np.concatenate(out) if out else np.empty((0, 3))


def simulate_town(
    *,
    n_buildings: int = 10,
    n_trees: int = 8,
    density: float = 8.0,
    noise_sigma: float = 0.03,
    seed: int = 0,
    **town_kwargs,
) -> tuple[Town, TownPoints]:
    """``make_town`` and ``sample_town`` in one call (geometry seed = ``seed``, sampling seed =
    ``seed + 1``).

    >>> town, pts = simulate_town(n_buildings=5, n_trees=2, density=2.0, seed=3)
    >>> sorted(set(pts.classification.tolist()))
    [2, 5, 6]
    """
    town = make_town(n_buildings=n_buildings, n_trees=n_trees, seed=seed, **town_kwargs)
    return town, sample_town(town, density=density, noise_sigma=noise_sigma, seed=seed + 1)
