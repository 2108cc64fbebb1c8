"""Terrestrial laser scanner networks with known truth: the cube of Carvalho, Correa & dos
Santos, a room with levelled and tilted stations, and observations with a scanner's noise.

The observations are computed here from the geometry with their own formulas (rotation of
Eq. 1, polar form of Eqs. 2-4, the AP corrections written out term by term), independently of
the adjustment's model in :mod:`core.tls.calibration`, so that a test comparing the two can
fail.

Scanner class of the noisy simulations (:data:`SCANNER_CLASSES`): the standard deviations of a
*target centre* observation, i.e. after a target fit, of a high-end scanner (range 1.2 mm,
angles 8 arc-seconds: the order of the datasheet accuracy of a Leica ScanStation P40-class
instrument), and of a mid-range phase scanner (range 2 mm, angles 19 arc-seconds: the order of
a FARO Focus-class datasheet).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from ..geometry.rotations import opk_to_matrix
from ..tls.ap_table import ARCSEC
from ..tls.network import ControlTarget, StationInfo, TlsObservations

__all__ = [
    "PAPER_APS",
    "SCANNER_CLASSES",
    "TlsTruth",
    "observe",
    "paper_cube",
    "room_network",
]

Array = NDArray[np.float64]

#: name -> (sigma range m, sigma horizontal rad, sigma vertical rad) of a target centre.
SCANNER_CLASSES = {
    "high_end": (0.0012, 8.0 * ARCSEC, 8.0 * ARCSEC),
    "mid_range": (0.0020, 19.0 * ARCSEC, 19.0 * ARCSEC),
}

#: The paper's inserted APs (its Table 1): b1 5", b2 4", c0 3". The extracted text lost the
#: value of a0 (its cell is empty); 2 mm is our choice, stated wherever it is used.
PAPER_APS = {"a0": 0.002, "b1": 5.0 * ARCSEC, "b2": 4.0 * ARCSEC, "c0": 3.0 * ARCSEC}


@dataclass(frozen=True)
class TlsTruth:
    """A simulated network.

    Attributes
    ----------
    target_ids : tuple of str
    target_xyz : ndarray (T, 3)
        Object frame, metres.
    station_ids : tuple of str
    poses : ndarray (S, 6)
        X0 (m), omega, phi, kappa (rad) with ``d = R3(k) R2(p) R1(w) (X - X0)``.
    levelled : ndarray of bool (S,)
        The compensator levelled the station (omega, phi read with ``tilt_sigma``).
    aps : dict of str to float
        Inserted APs, internal units (m, 1, rad).
    wavelength_m : float
        Modulation wavelength of the cyclic terms.
    min_elevation_rad : float
        Targets below this elevation are hidden (tripod, scanner body).
    """

    target_ids: tuple[str, ...]
    target_xyz: Array
    station_ids: tuple[str, ...]
    poses: Array
    levelled: NDArray[np.bool_]
    aps: dict[str, float] = field(default_factory=dict)
    wavelength_m: float = 1.2
    min_elevation_rad: float = -math.pi / 2

    def control(self, ids=None, sigma: float = 0.0) -> list[ControlTarget]:
        """Targets as control with ``sigma`` (0: fixed), all or those of ``ids``."""
        keep = self.target_ids if ids is None else ids
        at = {t: i for i, t in enumerate(self.target_ids)}
        return [
            ControlTarget(t, self.target_xyz[at[t]].copy(), np.full(3, float(sigma))) for t in keep
        ]

    def station_info(self, with_pose: bool = False) -> list[StationInfo]:
        """Station table: levelled flags (compensator readings = true tilts), and the true
        poses as approximate values when ``with_pose``."""
        out = []
        for s, p, lv in zip(self.station_ids, self.poses, self.levelled):
            opk = p[3:].copy() if (with_pose or lv) else None
            out.append(StationInfo(s, p[:3].copy() if with_pose else None, opk, bool(lv)))
        return out


def _corrections(aps: dict[str, float], rho: Array, theta: Array, alpha: Array, u: float):
    """The AP corrections written out (independent of core.tls.aps)."""
    g = aps.get
    d_rho = (
        g("a0", 0.0)
        + g("a1", 0.0) * rho
        + g("a2", 0.0) * np.sin(4 * math.pi * rho / u)
        + g("a3", 0.0) * np.cos(4 * math.pi * rho / u)
    )
    d_theta = (
        g("b1", 0.0) / np.cos(alpha)
        + g("b2", 0.0) * np.tan(alpha)
        + g("b3", 0.0) * np.sin(theta)
        + g("b4", 0.0) * np.cos(theta)
        + g("b5", 0.0) * np.sin(2 * theta)
        + g("b6", 0.0) * np.cos(2 * theta)
    )
    d_alpha = (
        g("c0", 0.0)
        + g("c1", 0.0) * alpha
        + g("c2", 0.0) * np.sin(alpha)
        + g("c3", 0.0) * np.cos(alpha)
    )
    return d_rho, d_theta, d_alpha


def observe(
    truth: TlsTruth,
    sigma_range_m: float = 0.0,
    sigma_hz_rad: float = 0.0,
    sigma_vt_rad: float | None = None,
    rng: np.random.Generator | int | None = None,
    two_faces: bool = False,
    exact: bool = False,
    blunders: int = 0,
    blunder_size: tuple[float, float] = (0.02, 60 * ARCSEC),
) -> tuple[TlsObservations, NDArray[np.intp]]:
    """Polar observations of every visible target from every station.

    Parameters
    ----------
    truth : TlsTruth
    sigma_range_m, sigma_hz_rad, sigma_vt_rad : float
        Noise of a target-centre observation (``sigma_vt_rad`` defaults to ``sigma_hz_rad``);
        also the covariance the observations carry. Zero noise gets a nominal covariance of
        1 mm and 5 arc-seconds.
    rng : Generator or int, optional
        Noise source (a seed or a Generator).
    two_faces : bool
        Also observe every target in face II (``theta + pi``, ``pi - alpha``).
    exact : bool
        No noise (the covariance is still the stated one): the truth itself.
    blunders : int
        Number of observations that get a gross error (range ``blunder_size[0]`` metres and
        ``blunder_size[1]`` radians on both angles, random signs).

    Returns
    -------
    obs : TlsObservations
    blunder_rows : ndarray of int
        Indices of the observations with a gross error.
    """
    rng = np.random.default_rng(rng)
    s_r = sigma_range_m if sigma_range_m > 0 else 0.001
    s_h = sigma_hz_rad if sigma_hz_rad > 0 else 5 * ARCSEC
    s_v = sigma_vt_rad if sigma_vt_rad is not None else sigma_hz_rad
    s_v = s_v if s_v > 0 else s_h
    noisy = not exact and sigma_range_m > 0
    st_ids, tg_ids, polar = [], [], []
    for sid, pose in zip(truth.station_ids, truth.poses):
        # Eq. 1: d = R3(kappa) R2(phi) R1(omega) (X - X0)
        m = opk_to_matrix(pose[3], pose[4], pose[5])
        d = (truth.target_xyz - pose[:3]) @ m.T
        h = np.sqrt(d[:, 0] ** 2 + d[:, 1] ** 2)
        rho = np.sqrt(h**2 + d[:, 2] ** 2)
        theta = np.arctan2(d[:, 1], d[:, 0])
        alpha = np.arctan2(d[:, 2], h)
        seen = (alpha > truth.min_elevation_rad) & (np.abs(alpha) < math.radians(85.0))
        seen &= rho > 0.5
        faces = (False, True) if two_faces else (False,)
        for face in faces:
            t = theta + math.pi if face else theta
            a = math.pi - alpha if face else alpha
            dr, dt, da = _corrections(truth.aps, rho, t, a, truth.wavelength_m)
            obs = np.stack([rho + dr, t + dt, a + da], axis=-1)[seen]
            polar.append(obs)
            st_ids += [sid] * int(seen.sum())
            tg_ids += [tid for tid, v in zip(truth.target_ids, seen) if v]
    p = np.vstack(polar)
    n = p.shape[0]
    if noisy:
        p = p + rng.normal(size=(n, 3)) * [s_r, s_h, s_v]
    bad = np.zeros(0, dtype=np.intp)
    if blunders:
        bad = np.sort(rng.choice(n, size=min(blunders, n), replace=False)).astype(np.intp)
        signs = rng.choice([-1.0, 1.0], size=(bad.size, 3))
        p[bad] += signs * [blunder_size[0], blunder_size[1], blunder_size[1]]
    p[:, 1] = (p[:, 1] + math.pi) % (2 * math.pi) - math.pi
    cov = np.zeros((n, 3, 3))
    cov[:, 0, 0], cov[:, 1, 1], cov[:, 2, 2] = s_r**2, s_h**2, s_v**2
    return TlsObservations(tuple(st_ids), tuple(tg_ids), p, cov, np.arange(2, n + 2)), bad


def _face_grid(nu: int, nv: int, side: float, margin: float) -> Array:
    u = np.linspace(margin, side - margin, nu)
    v = np.linspace(margin, side - margin, nv)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    return np.column_stack([uu.ravel(), vv.ravel()])


def paper_cube(
    side: float = 10.0,
    z_min: float = -5.0,
    grid: tuple[int, int] = (6, 4),
    aps: dict[str, float] | None = None,
) -> TlsTruth:
    """The simulated network of Carvalho, Correa & dos Santos (their Section 2, Table 1).

    144 targets, 24 on each face of a cube of ``side`` metres (a ``grid`` of 6 x 4 per face
    1 m inside its edges: the figure with the layout is missing from the text, so this is our
    choice), x and y in [0, side], z in [z_min, z_min + side]; three stations at (5, 2, 0),
    (2, 5, 0) and (8, 8, 0) with (omega, phi, kappa) = (30", 30", 40 deg), (10", 20", 20 deg)
    and (12", 25", 10 deg). The table prints the columns as kappa, phi, omega with the 40 deg in
    the last one; the text says kappa is the large rotation in the XY plane and omega, phi
    start at zero (levelled), so we read the columns as omega, phi, kappa. APs: b1 = 5",
    b2 = 4", c0 = 3" and a0 = 2 mm (:data:`PAPER_APS`; the text lost the value of a0). The
    stations are not levelled in the paper's adjustment (six free EOPs each).

    >>> t = paper_cube()
    >>> t.target_xyz.shape, t.station_ids
    ((144, 3), ('1', '2', '3'))
    """
    g = _face_grid(grid[0], grid[1], side, 1.0)
    z0 = z_min
    faces = []
    zero, top = np.zeros(len(g)), np.full(len(g), side)
    faces.append(np.column_stack([g[:, 0], g[:, 1], zero + z0]))  # floor
    faces.append(np.column_stack([g[:, 0], g[:, 1], top + z0]))  # ceiling
    faces.append(np.column_stack([g[:, 0], zero, g[:, 1] + z0]))  # wall y = 0
    faces.append(np.column_stack([g[:, 0], top, g[:, 1] + z0]))  # wall y = side
    faces.append(np.column_stack([zero, g[:, 0], g[:, 1] + z0]))  # wall x = 0
    faces.append(np.column_stack([top, g[:, 0], g[:, 1] + z0]))  # wall x = side
    xyz = np.vstack(faces)
    ids = tuple(f"T{i + 1:03d}" for i in range(len(xyz)))
    a = ARCSEC
    poses = np.array(
        [
            [5.0, 2.0, 0.0, 30 * a, 30 * a, math.radians(40.0)],
            [2.0, 5.0, 0.0, 10 * a, 20 * a, math.radians(20.0)],
            [8.0, 8.0, 0.0, 12 * a, 25 * a, math.radians(10.0)],
        ]
    )
    return TlsTruth(
        ids,
        xyz,
        ("1", "2", "3"),
        poses,
        np.zeros(3, dtype=bool),
        dict(PAPER_APS if aps is None else aps),
    )


def room_network(
    size: tuple[float, float, float] = (12.0, 8.0, 3.5),
    levelled_stations: int = 4,
    tilted: bool = True,
    aps: dict[str, float] | None = None,
    scanner_height: float = 1.5,
    spacing: float = 1.5,
    min_elevation_deg: float = -60.0,
    seed: int = 7,
) -> TlsTruth:
    """A room-sized calibration field in the spirit of Lichti (2007, 2010).

    Targets on the four walls (every ``spacing`` metres at 0.5 m, half the height and 0.5 m
    below the ceiling), on the ceiling and on the floor (grids), so that they cover the full
    horizontal circle and a wide vertical range. ``levelled_stations`` stations on the
    tripod at ``scanner_height`` (compensator on, small tilts), spread over the room with
    random headings; with ``tilted``, two more stations at the room's centre whose scanners
    are rolled by +90 and -90 degrees about their x axis (compensator off), which turns the
    vertical range of the targets into horizontal directions and back (Lichti 2010's remedy
    for the correlations of the APs with the station parameters). Targets below
    ``min_elevation_deg`` are hidden from a station (tripod, scanner body).

    >>> t = room_network()
    >>> len(t.station_ids), t.levelled.tolist()
    (6, [True, True, True, True, False, False])
    """
    lx, ly, lz = size
    rng = np.random.default_rng(seed)
    pts = []
    heights = (0.5, lz / 2, lz - 0.5)
    for axis, length, other in ((0, lx, ly), (1, ly, lx)):
        along = np.arange(spacing / 2, length, spacing)
        for fixed in (0.0, other):
            for z in heights:
                p = np.zeros((along.size, 3))
                p[:, axis] = along
                p[:, 1 - axis] = fixed
                p[:, 2] = z
                pts.append(p)
    gx = np.arange(spacing, lx, 2 * spacing)
    gy = np.arange(spacing, ly, 2 * spacing)
    xx, yy = np.meshgrid(gx, gy, indexing="ij")
    for z in (0.0, lz):
        pts.append(np.column_stack([xx.ravel(), yy.ravel(), np.full(xx.size, z)]))
    xyz = np.vstack(pts)
    # A little scatter off the regular grid (targets are never placed perfectly).
    xyz[:, :2] += (
        rng.uniform(-0.1, 0.1, size=(len(xyz), 2)) * ((xyz[:, 2] == 0) | (xyz[:, 2] == lz))[:, None]
    )
    ids = tuple(f"R{i + 1:03d}" for i in range(len(xyz)))
    cx, cy = lx / 2, ly / 2
    spots = [(0.3, 0.3), (0.7, 0.3), (0.7, 0.7), (0.3, 0.7), (0.5, 0.5), (0.2, 0.5), (0.8, 0.5)]
    poses = []
    levelled = []
    for q in range(levelled_stations):
        fx, fy = spots[q % len(spots)]
        tilt = rng.normal(0.0, 20 * ARCSEC, size=2)
        poses.append(
            [fx * lx, fy * ly, scanner_height, tilt[0], tilt[1], rng.uniform(-math.pi, math.pi)]
        )
        levelled.append(True)
    if tilted:
        for roll in (math.pi / 2, -math.pi / 2):
            poses.append(
                [
                    cx,
                    cy,
                    scanner_height,
                    roll,
                    rng.normal(0.0, 0.01),
                    rng.uniform(-math.pi, math.pi),
                ]
            )
            levelled.append(False)
    ids_s = tuple(f"S{q + 1}" for q in range(len(poses)))
    return TlsTruth(
        ids,
        xyz,
        ids_s,
        np.array(poses),
        np.array(levelled),
        dict(PAPER_APS if aps is None else aps),
        min_elevation_rad=math.radians(min_elevation_deg),
    )


def with_aps(truth: TlsTruth, aps: dict[str, float]) -> TlsTruth:
    """The same network with other inserted APs."""
    return replace(truth, aps=dict(aps))


# ----------------------------------------------------------------------------- scans

#: Return intensities of the simulated materials (0-1).
WALL_INTENSITY, SPHERE_INTENSITY, BLACK, WHITE = 0.35, 0.8, 0.08, 0.92


@dataclass(frozen=True)
class ScanScene:
    """A box-shaped room with sphere and checkerboard targets (object frame, metres).

    Attributes
    ----------
    room : tuple of float
        (lx, ly, lz): the room is [0, lx] x [0, ly] x [0, lz].
    sphere_ids, sphere_xyz, radius
        Sphere targets: ids, centres (S, 3) and their common radius.
    board_ids, board_xyz, board_normal, board_up, half_size
        Checkerboards: ids, centres (B, 3), unit normals into the room (B, 3), a unit
        in-plane direction of one pattern axis (B, 3), and the half size of the 2 x 2 pattern.
    """

    room: tuple[float, float, float]
    sphere_ids: tuple[str, ...] = ()
    sphere_xyz: Array = field(default_factory=lambda: np.zeros((0, 3)))
    radius: float = 0.0725
    board_ids: tuple[str, ...] = ()
    board_xyz: Array = field(default_factory=lambda: np.zeros((0, 3)))
    board_normal: Array = field(default_factory=lambda: np.zeros((0, 3)))
    board_up: Array = field(default_factory=lambda: np.zeros((0, 3)))
    half_size: float = 0.1


@dataclass(frozen=True)
class SimulatedScan:
    """One station's scan: points in the scanner frame as the scanner records them.

    ``label`` is the index of the sphere (0..S-1) or of the board (S..S+B-1) a point hit,
    -1 for the room and -2 for an outlier.
    """

    station_id: str
    xyz: Array
    intensity: Array
    label: NDArray[np.int64]


def scene_from_network(
    truth: TlsTruth,
    kind: str = "sphere",
    radius: float = 0.0725,
    half_size: float = 0.1,
    room: tuple[float, float, float] | None = None,
    seed: int = 3,
) -> tuple[ScanScene, TlsTruth]:
    """Targets of a room network as spheres (centres moved ``1.5 radius`` off their wall into
    the room, as on a bracket) or checkerboards (on the walls, ceiling and floor, turned at
    random about their normal); returns the scene and the network with the target centres."""
    lx, ly, lz = (
        room if room is not None else tuple(float(v) for v in np.max(truth.target_xyz, axis=0))
    )
    p = truth.target_xyz.copy()
    normal = np.zeros_like(p)
    for axis, top in ((0, lx), (1, ly), (2, lz)):
        normal[np.isclose(p[:, axis], 0.0), axis] = 1.0
        normal[np.isclose(p[:, axis], top), axis] = -1.0
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-12)
    if kind == "sphere":
        centres = p + 1.5 * radius * normal
        scene = ScanScene((lx, ly, lz), truth.target_ids, centres, radius)
    else:
        rng = np.random.default_rng(seed)
        centres = p + 0.002 * normal  # the board's thickness off its wall
        ups = []
        for n in normal:
            a = np.array([0.0, 0.0, 1.0]) if abs(n[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
            e1 = np.cross(n, a)
            e1 /= np.linalg.norm(e1)
            e2 = np.cross(n, e1)
            ang = rng.uniform(0, math.pi / 2)
            ups.append(math.cos(ang) * e1 + math.sin(ang) * e2)
        scene = ScanScene(
            (lx, ly, lz),
            board_ids=truth.target_ids,
            board_xyz=centres,
            board_normal=normal,
            board_up=np.array(ups),
            half_size=half_size,
        )
    return scene, replace(truth, target_xyz=centres)


def _hits(
    scene: ScanScene, m: Array, x0: Array, u: Array
) -> tuple[Array, Array, NDArray[np.int64]]:
    """Nearest hit along unit rays ``u`` (N, 3) of the scanner frame: range, intensity and
    label (the target index, -1 for a wall); the scene is moved into the scanner frame."""
    n = u.shape[0]
    best = np.full(n, np.inf)
    inten = np.full(n, WALL_INTENSITY)
    label = np.full(n, -1, dtype=np.int64)
    lx, ly, lz = scene.room
    for axis, top in ((0, lx), (1, ly), (2, lz)):
        for value in (0.0, top):
            nrm = m[:, axis]  # the object axis in the scanner frame
            dist = value - x0[axis]
            den = u @ nrm
            with np.errstate(divide="ignore", invalid="ignore"):
                t = dist / den
            ok = (t > 1e-6) & (t < best)
            best = np.where(ok, t, best)
    c = (scene.sphere_xyz - x0) @ m.T
    r = scene.radius
    for k in range(c.shape[0]):
        b = u @ c[k]
        disc = b * b - (c[k] @ c[k] - r * r)
        with np.errstate(invalid="ignore"):
            t = b - np.sqrt(disc)
        ok = (disc > 0) & (t > 1e-6) & (t < best)
        best = np.where(ok, t, best)
        inten = np.where(ok, SPHERE_INTENSITY, inten)
        label = np.where(ok, k, label)
    s = c.shape[0]
    bc = (scene.board_xyz - x0) @ m.T
    bn = scene.board_normal @ m.T
    bu = scene.board_up @ m.T
    for k in range(bc.shape[0]):
        den = u @ bn[k]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (bc[k] @ bn[k]) / den
        q = u * t[:, None] - bc[k]
        e1 = bu[k]
        e2 = np.cross(bn[k], e1)
        a1, a2 = q @ e1, q @ e2
        h = scene.half_size
        ok = (t > 1e-6) & (t < best) & (np.abs(a1) < h) & (np.abs(a2) < h)
        best = np.where(ok, t, best)
        white = np.sign(a1) * np.sign(a2) > 0
        inten = np.where(ok, np.where(white, WHITE, BLACK), inten)
        label = np.where(ok, s + k, label)
    return best, inten, label


def simulate_scan(
    scene: ScanScene,
    truth: TlsTruth,
    station: int,
    spacing_m: float = 0.003,
    sigma_range_m: float = 0.001,
    sigma_angle_rad: float = 20e-6,
    sigma_intensity: float = 0.03,
    outlier_fraction: float = 0.0,
    hide_below: float | None = None,
    rng: np.random.Generator | int | None = None,
    window: float = 1.6,
) -> SimulatedScan:
    """Scan the targets of ``scene`` from station ``station`` of ``truth`` (its pose and APs).

    Like a scanner's fine scan of each target: a grid of directions spaced ``spacing_m`` at
    the target's distance, over ``window`` times its angular radius; each ray meets the nearest
    surface (room, spheres, boards). The recorded polar observation is the true one plus the
    APs of ``truth`` plus noise, turned into scanner-frame x, y, z as a scanner exports it.

    Parameters
    ----------
    outlier_fraction : float
        Share of the points replaced by outliers: a range anywhere from 0.3 m before to
        0.3 m after the true hit along the same beam (mixed pixels, dust), random intensity.
    hide_below : float, optional
        Partial coverage: sphere points lower than ``hide_below * radius`` under the sphere
        centre (object z) are hidden, as by a bracket or stand.
    """
    rng = np.random.default_rng(rng)
    pose = truth.poses[station]
    m = opk_to_matrix(pose[3], pose[4], pose[5])
    x0 = pose[:3]
    centres = (
        np.vstack([scene.sphere_xyz, scene.board_xyz])
        if len(scene.board_xyz)
        else (scene.sphere_xyz)
    )
    sizes = np.r_[
        np.full(len(scene.sphere_xyz), scene.radius),
        np.full(len(scene.board_xyz), scene.half_size * math.sqrt(2)),
    ]
    d = (centres - x0) @ m.T
    rho_c = np.linalg.norm(d, axis=1)
    theta_c = np.arctan2(d[:, 1], d[:, 0])
    alpha_c = np.arctan2(d[:, 2], np.hypot(d[:, 0], d[:, 1]))
    rays = []
    for k in range(len(centres)):
        if rho_c[k] < 0.5 or abs(alpha_c[k]) > math.radians(80.0):
            continue
        if alpha_c[k] < truth.min_elevation_rad:
            continue
        ang = window * math.asin(min(sizes[k] / rho_c[k], 0.99))
        step_rad = spacing_m / rho_c[k]
        na = max(math.ceil(2 * ang / step_rad), 3)
        nt = max(math.ceil(2 * ang / (step_rad * max(math.cos(alpha_c[k]), 0.1))), 3)
        tt = theta_c[k] + np.linspace(-ang, ang, nt) / max(math.cos(alpha_c[k]), 0.1)
        aa = alpha_c[k] + np.linspace(-ang, ang, na)
        t2, a2 = np.meshgrid(tt, aa, indexing="ij")
        rays.append(np.column_stack([t2.ravel(), a2.ravel()]))
    if not rays:
        return SimulatedScan(
            truth.station_ids[station], np.zeros((0, 3)), np.zeros(0), np.zeros(0, dtype=np.int64)
        )
    ta = np.vstack(rays)
    u = np.column_stack(
        [np.cos(ta[:, 1]) * np.cos(ta[:, 0]), np.cos(ta[:, 1]) * np.sin(ta[:, 0]), np.sin(ta[:, 1])]
    )
    rho, inten, label = _hits(scene, m, x0, u)
    keep = np.isfinite(rho)
    if hide_below is not None and len(scene.sphere_xyz):
        obj = (u * rho[:, None]) @ m + x0
        sph = (label >= 0) & (label < len(scene.sphere_xyz))
        low = np.zeros_like(keep)
        low[sph] = obj[sph, 2] < scene.sphere_xyz[label[sph], 2] - hide_below * scene.radius
        keep &= ~low
    ta, rho, inten, label = ta[keep], rho[keep], inten[keep], label[keep]
    n = rho.size
    dr, dt, da = _corrections(truth.aps, rho, ta[:, 0], ta[:, 1], truth.wavelength_m)
    r_obs = rho + dr + rng.normal(0.0, sigma_range_m, n)
    t_obs = ta[:, 0] + dt + rng.normal(0.0, sigma_angle_rad, n)
    a_obs = ta[:, 1] + da + rng.normal(0.0, sigma_angle_rad, n)
    inten = inten + rng.normal(0.0, sigma_intensity, n)
    if outlier_fraction > 0:
        bad = rng.random(n) < outlier_fraction
        r_obs[bad] = rho[bad] + rng.uniform(-0.3, 0.3, int(bad.sum()))
        inten[bad] = rng.uniform(0.0, 1.0, int(bad.sum()))
        label[bad] = -2
    ca = np.cos(a_obs)
    xyz = np.column_stack(
        [r_obs * ca * np.cos(t_obs), r_obs * ca * np.sin(t_obs), r_obs * np.sin(a_obs)]
    )
    return SimulatedScan(truth.station_ids[station], xyz, inten, label)
