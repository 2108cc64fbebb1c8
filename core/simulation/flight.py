"""Flight simulator: complete boresight-calibration inputs over a synthetic town, with the truth.

A town (:func:`core.simulation.town.make_town`) is flown in straight lines (optionally in
opposite directions) with a frame camera; the true camera poses come from the rigorous ECEF
direct georeferencing of :func:`core.photo.georeference.georeference_ecef` (independent of the
calibration's own chain) with a true boresight per group and a true lever arm. The simulator
returns what the calibration reads, in the mapping CRS:

- the INS trajectory with noise of a named grade (:data:`core.photo.ins.INS_GRADES`);
- the camera, the mount with the *initial* boresight;
- roof planes fitted (``fit_plane``) to LiDAR points sampled on the true faces with noise
  (or the true planes with the covariance of such a fit: ``plane_source="exact"``);
- ridge/hip lines from two fitted planes and LCPs from three (``lidar_control``'s
  intersections, with their propagated covariances);
- image observations of every control type with pixel noise and optional blunders, and check
  points (LCPs measured in the images but not adjusted).

Geometry (town layout) and noise take separate seeds, so Monte-Carlo draws keep the geometry.
``exact=True`` gives noise-free observations of the truth with the same covariances (used to
evaluate the Cramer-Rao bound at the truth).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Union

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..geometry.camera import Camera
from ..geometry.collinearity import project
from ..geometry.frames import MappingFrame
from ..geometry.planes import Plane, fit_plane
from ..geometry.rotations import matrix_to_opk
from ..io.atomic import folder_files, write_text_atomic
from ..io.camera import write_camera_json
from ..io.control import write_lcps_csv, write_lines_csv
from ..io.ground_points import write_ground_points_csv
from ..io.observations import write_observations_csv
from ..io.planes import write_planes_csv
from ..io.tables import write_csv_atomic
from ..io.trajectory import write_trajectory_csv
from ..lidar.control import ControlLine, ControlPoint, intersect_three_planes, intersect_two_planes
from ..photo.boresight import calibrate
from ..photo.boresight_result import BoresightResult
from ..photo.boresight_setup import BoresightOptions, local_frame_for
from ..photo.bundle_setup import GroundPoints
from ..photo.georeference import Trajectory, georeference_ecef
from ..photo.ins import INS_GRADES, InsGrade
from ..photo.mount import MOUNT_PRESETS, Mount
from ..photo.observations import ImageObservations
from .flight_roofs import _face_points, _roof_corners, _roof_lines, _roof_samples
from .town import Town, make_town

__all__ = [
    "FlightConfig",
    "FlightSimulation",
    "FlightTruth",
    "paper_config",
    "simulate_flight",
    "surveyed_control",
    "ultracam_xp",
]

Array = NDArray[np.float64]


def ultracam_xp() -> Camera:
    """UltraCam XP panchromatic frame as in Pedrosa & dos Santos (2020): f = 100.4 mm, 6 um, 17310 x
    11310 px.

    11310 px is the side along track with the ``image_top_forward`` mount (the image height).
    """
    return Camera(
        "UltraCam XP", focal_mm=100.4, pixel_size_mm=0.006, width_px=17310, height_px=11310
    )


@dataclass(frozen=True)
class FlightPlan:
    """What every simulated flight has: CRS, block, camera, lines, mount, INS (attributes as in
    :class:`FlightConfig`)."""

    crs: str = "EPSG:28992"
    centre: tuple[float, float] = (85500.0, 447500.0)
    camera: Camera = field(default_factory=ultracam_xp)
    flying_height_m: float = 1600.0
    forward_overlap: float = 0.6
    side_overlap: float = 0.3
    images_per_line: int = 3
    n_lines: int = 2
    heading_deg: float = 45.0
    opposite: bool = True
    mount: str = "image_top_forward"
    true_boresight_deg: tuple[tuple[float, float, float], ...] = ((0.07, -0.13, 0.005),)
    initial_boresight_deg: tuple[float, float, float] = (0.0, 0.0, 0.0)
    lever_arm_m: tuple[float, float, float] = (0.15, -0.05, -0.60)
    ins_grade: Union[str, InsGrade] = "pos_av_310"
    attitude_jitter_deg: float = 1.0


@dataclass(frozen=True)
class FlightConfig(FlightPlan):
    """A simulated calibration flight over a simulated town.

    Attributes
    ----------
    crs : str
        Mapping CRS (projected, metres).
    centre : (float, float)
        Block centre, easting and northing in ``crs``.
    camera : Camera
    flying_height_m : float
        Above the terrain at the centre.
    forward_overlap, side_overlap : float
    images_per_line, n_lines : int
    heading_deg : float
        Grid azimuth of the first line; with ``opposite`` every other line is flown back.
    mount : str
        Nominal mount preset (``core.photo.mount.MOUNT_PRESETS``).
    true_boresight_deg : tuple of (float, float, float)
        One row for all lines, or one per line (d_omega, d_phi, d_kappa), degrees.
    initial_boresight_deg : (float, float, float)
        What the calibration starts from (the mount's boresight).
    lever_arm_m : (float, float, float)
    ins_grade : str or InsGrade
    attitude_jitter_deg : float
        Spread of the true roll, pitch and crab angle about level flight.
    n_buildings, roof_types, town_size_m, town_seed : town layout
    n_planes : int or None
        Keep the first n roof faces (None: all).
    lidar_density, lidar_noise_m : float
        Roof points per m^2 and their noise (x, y, z), metres.
    plane_source : {"fit", "exact"}
    types : tuple of str
        Observation types to make: tie, line, lcp, paper, check.
    ties_per_plane, line_points_per_image : int
    n_check : int
        LCPs used as check points (the rest are control).
    sigma_px : float
        Pixel noise, pixels.
    roof_roughness_m : float
        True departure of tie points from their plane, metres.
    n_blunders : int
        Tie/LCP measurements given a gross error of ``blunder_px`` pixels.
    margin_px : float
        Points closer than this to the image border are not measured.
    """

    n_buildings: int = 23
    roof_types: tuple[str, ...] = ("gable", "hip", "pyramid")
    town_size_m: float = 900.0
    town_seed: int = 7
    n_planes: int | None = 76
    lidar_density: float = 5.0
    lidar_noise_m: float = 0.05
    plane_source: str = "fit"
    types: tuple[str, ...] = ("tie", "line", "lcp", "paper", "check")
    ties_per_plane: int = 1
    line_points_per_image: int = 2
    n_check: int = 15
    sigma_px: float = 0.5
    roof_roughness_m: float = 0.0
    n_blunders: int = 0
    blunder_px: float = 25.0
    margin_px: float = 50.0


def paper_config(**changes) -> FlightConfig:
    """The configuration of Pedrosa & dos Santos (2020), section 3: UltraCam XP, 1600 m, 60 %/30 %
    overlap, 6 images in two opposite directions (3 NE, 3 SW), 76 roof planes, 15 check points,
    Applanix POS AV 310. Plane-constrained tie points and paper-mode points are made."""
    base = FlightConfig(types=("tie", "paper", "check"))
    return replace(base, **changes)


@dataclass(frozen=True)
class FlightTruth:
    """The truth of a simulation.

    Attributes
    ----------
    groups : tuple of str
        Group of each flight line's images (the trajectory's group column).
    boresight : dict of str to ndarray (3,)
        True boresight per group, radians.
    lever_arm : ndarray, shape (3,)
    trajectory : Trajectory
        Noise-free INS poses.
    check_points : dict of str to ndarray (3,)
        True check-point coordinates (mapping CRS) by LCP id.
    blunders : ndarray of int
        Observation rows given a gross error.
    """

    groups: tuple[str, ...]
    boresight: dict[str, Array]
    lever_arm: Array
    trajectory: Trajectory
    check_points: dict[str, Array]
    blunders: NDArray[np.int64]


@dataclass(frozen=True)
class FlightSimulation:
    """Inputs of :func:`core.photo.boresight.calibrate` plus the truth (mapping CRS throughout)."""

    config: FlightConfig
    crs: str
    trajectory: Trajectory
    camera: Camera
    mount: Mount
    planes: list[Plane]
    lines: list[ControlLine]
    lcps: list[ControlPoint]
    check_lcps: list[ControlPoint]
    observations: ImageObservations
    lidar_points: Array
    lidar_plane_ids: NDArray[np.int64]
    town: Town
    truth: FlightTruth

    def calibrate(self, options: BoresightOptions | None = None) -> BoresightResult:
        """Boresight calibration of this simulation with every control it made."""
        return calibrate(
            self.trajectory,
            self.camera,
            self.mount,
            self.crs,
            self.observations,
            self.planes,
            self.lines,
            self.lcps,
            self.lidar_points,
            self.lidar_plane_ids,
            options=options,
        )

    def true_boresight(self, groups: tuple[str, ...]) -> Array:
        """(G, 3) true boresight in the order of a result's groups, radians."""
        return np.array([self.truth.boresight[g] for g in groups])

    def write(self, folder: Union[str, Path]) -> dict[str, Path]:
        """Write every input as the project's files; returns their paths by name."""
        csv = ("trajectory", "planes", "lines", "lcps", "observations", "lidar_roof_points")
        paths = folder_files(folder, "camera.json", *(f"{k}.csv" for k in csv), "truth.json")
        write_trajectory_csv(paths["trajectory"], self.trajectory)
        write_camera_json(paths["camera"], self.camera)
        write_planes_csv(paths["planes"], self.planes)
        write_lines_csv(paths["lines"], self.lines)
        write_lcps_csv(paths["lcps"], self.lcps + self.check_lcps)
        write_observations_csv(paths["observations"], self.observations)
        write_csv_atomic(
            paths["lidar_roof_points"],
            ("x", "y", "z", "plane_id"),
            [
                (*(repr(float(v)) for v in p), int(i))
                for p, i in zip(self.lidar_points, self.lidar_plane_ids)
            ],
        )
        truth = _truth(self.config, self.truth, self.mount)
        truth["check_points"] = {k: v.tolist() for k, v in self.truth.check_points.items()}
        write_text_atomic(paths["truth"], json.dumps(truth, indent=2))
        return paths


# ----------------------------------------------------------------------------- helpers


def _plan_basics(cfg: FlightPlan) -> tuple[MappingFrame, InsGrade, Array]:
    """The mapping frame, the INS grade and the nominal mount of a flight plan."""
    if cfg.mount not in MOUNT_PRESETS:
        raise InputError(f"mount '{cfg.mount}' is not a preset")
    grade = cfg.ins_grade
    grade = grade if isinstance(grade, InsGrade) else INS_GRADES[str(grade)]
    return MappingFrame.from_user_input(cfg.crs), grade, MOUNT_PRESETS[cfg.mount]


# ----------------------------------------------------------------------------- main


def _true_flight(cfg, cam, h0: float, frame, rng, seconds_per_image: float):
    """Flight lines over ``cfg.centre`` at height ``h0`` (grid azimuth ``cfg.heading_deg``,
    overlaps from the camera footprint), true attitudes with jitter, and the true boresight of
    each group. Returns (true trajectory, {group: boresight (3,) rad}, geodetic (N, 3))."""
    along_axis = 1 if cfg.mount in ("image_top_forward", "image_bottom_forward") else 0
    size_px = (cam.width_px, cam.height_px)
    scale = cfg.flying_height_m / cam.focal_mm
    base = (1 - cfg.forward_overlap) * size_px[along_axis] * cam.pixel_size_mm * scale
    spacing = (1 - cfg.side_overlap) * size_px[1 - along_axis] * cam.pixel_size_mm * scale
    az = math.radians(cfg.heading_deg)
    fwd = np.array([math.sin(az), math.cos(az)])
    right = np.array([math.cos(az), -math.sin(az)])
    names = _direction_names(cfg)
    pos, head, groups = [], [], []
    ids: list[str] = []
    m = cfg.images_per_line
    for line in range(cfg.n_lines):
        back = cfg.opposite and line % 2 == 1
        off = (line - (cfg.n_lines - 1) / 2) * spacing
        for k in range(m - 1, -1, -1) if back else range(m):
            pos.append(np.array(cfg.centre) + (k - (m - 1) / 2) * base * fwd + off * right)
            head.append(az + (math.pi if back else 0.0))
            groups.append(names[line])
            ids.append(f"L{line + 1}_{len(ids) + 1:03d}")
    n = len(ids)
    enh = np.column_stack([np.array(pos), np.full(n, h0)])
    llh = frame.map_to_geodetic(enh)
    theta = frame.grid_north_azimuth(llh)
    jit = math.radians(cfg.attitude_jitter_deg)
    rph_true = np.column_stack(
        [
            rng.normal(0, jit, n),
            rng.normal(0, jit, n),
            np.angle(np.exp(1j * (np.array(head) - theta + rng.normal(0, jit, n)))),
        ]
    )
    time = np.arange(n, dtype=np.float64) * seconds_per_image
    traj_true = Trajectory(tuple(ids), time, tuple(groups), enh, False, rph_true)
    rows = np.radians(np.array(cfg.true_boresight_deg, dtype=np.float64).reshape(-1, 3))
    if rows.shape[0] not in (1, cfg.n_lines):
        raise InputError("true_boresight_deg needs one row or one per line")
    bore_of = {names[k]: rows[min(k, rows.shape[0] - 1)] for k in range(cfg.n_lines)}
    return traj_true, bore_of, llh


def _control(
    town: Town, kept: list[int], lidar_noisy: Array, lid: NDArray, exact: bool, plane_source: str
) -> tuple[list[Plane], list[ControlLine], list[Array], list[ControlPoint], list[Array]]:
    """The LiDAR control of the kept faces: the planes fitted to their noisy points (or the
    true ones with the fit's covariance), the ridge/hip lines of two planes and the LCPs of
    three, with their true segments and corners."""
    kept_set = set(kept)
    planes = []
    for f in kept:
        fit = fit_plane(lidar_noisy[lid == f], plane_id=f)
        if exact or plane_source == "exact":
            face = town.faces[f]
            c = fit.centroid - (fit.centroid @ face.normal + face.d) * face.normal
            fit = Plane(
                f,
                face.normal.copy(),
                float(-face.normal @ c),
                c,
                fit.n_points,
                fit.rms,
                fit.sigma_d,
                fit.covariance,
                fit.slope_deg,
                fit.aspect_deg,
            )
        planes.append(fit)
    plane_of = {p.id: p for p in planes}

    # ---- lines and LCPs from the (fitted) planes
    lines: list[ControlLine] = []
    line_truth = []
    for seg, fa, fb in _roof_lines(town, kept_set):
        pa, pb = plane_of[fa], plane_of[fb]
        x0, u, cov = intersect_two_planes(
            pa.normal[None],
            np.array([pa.d]),
            pa.covariance[None],
            pb.normal[None],
            np.array([pb.d]),
            pb.covariance[None],
            seg.mean(axis=0)[None],
        )
        if not np.isfinite(x0).all():
            continue
        kind = "ridge" if abs(seg[0, 2] - seg[1, 2]) < 1e-6 else "hip"
        dih = math.degrees(math.acos(min(1.0, abs(float(pa.normal @ pb.normal)))))
        lines.append(
            ControlLine(len(lines), (fa, fb), kind, seg[0], seg[1], x0[0], u[0], cov[0], dih)
        )
        line_truth.append(seg)
    corners = _roof_corners(town, kept_set)
    all_lcps: list[ControlPoint] = []
    lcp_truth = []
    for k, (p, tri) in enumerate(corners):
        ps = [plane_of[f] for f in tri]
        x, c, cond = intersect_three_planes(
            np.array([q.normal for q in ps])[None],
            np.array([[q.d for q in ps]]),
            np.array([q.covariance for q in ps])[None],
        )
        if not np.isfinite(x).all():
            continue
        xyz = p.copy() if exact else x[0]
        plane_ids = (int(tri[0]), int(tri[1]), int(tri[2]))
        all_lcps.append(ControlPoint(k, xyz, c[0], plane_ids, 0.0, float(cond[0]), np.zeros(3)))
        lcp_truth.append(p)
    return planes, lines, line_truth, all_lcps, lcp_truth


def _observations(
    cfg: FlightConfig,
    town: Town,
    kept: list[int],
    local,
    eo_true: Array,
    ids,
    cam: Camera,
    lines: list[ControlLine],
    line_truth: list[Array],
    control_truth: list[Array],
    control_lcps: list[ControlPoint],
    check_lcps: list[ControlPoint],
    check_truth: dict[str, Array],
    exact: bool,
    rng: np.random.Generator,
) -> tuple[ImageObservations, NDArray[np.int64]]:
    """The image measurements of every control type in every image (pixel noise and
    blunders unless ``exact``) and the rows made blunders."""
    n = len(eo_true)
    targets: list[tuple[Array, str, list[str], list[str]]] = []
    if "tie" in cfg.types:
        p = _face_points(town, kept, cfg.ties_per_plane, rng)
        fids = np.repeat(kept, cfg.ties_per_plane)
        if cfg.roof_roughness_m > 0 and not exact:
            nrm = np.array([town.faces[f].normal for f in fids])
            p = p + nrm * rng.normal(0, cfg.roof_roughness_m, (len(p), 1))
        targets.append((p, "tie", [str(f) for f in fids], [f"T{k}" for k in range(len(p))]))
    if "lcp" in cfg.types and control_truth:
        targets.append(
            (
                np.array(control_truth),
                "lcp",
                [str(c.id) for c in control_lcps],
                [f"C{c.id}" for c in control_lcps],
            )
        )
    if "check" in cfg.types and check_lcps:
        targets.append(
            (
                np.array([check_truth[str(c.id)] for c in check_lcps]),
                "check",
                [str(c.id) for c in check_lcps],
                [f"K{c.id}" for c in check_lcps],
            )
        )
    rec = _Records()
    local_targets = [(local.map_to_enu(pts), kind, tgt, pid) for pts, kind, tgt, pid in targets]
    per_line = cfg.line_points_per_image
    for i in range(n):
        for pts, kind, tgt, pid in local_targets:
            px = project(pts, eo_true[i], cam)
            rec.add(ids[i], px, np.flatnonzero(cam.in_frame(px, cfg.margin_px)), pid, kind, tgt)
        if "paper" in cfg.types:
            p = local.map_to_enu(_face_points(town, kept, 1, rng))
            px = project(p, eo_true[i], cam)
            rec.add(
                ids[i],
                px,
                np.flatnonzero(cam.in_frame(px, cfg.margin_px)),
                [f"P{i}_{f}" for f in kept],
                "paper",
                [str(f) for f in kept],
            )
        if "line" in cfg.types and lines:
            t = rng.uniform(0.1, 0.9, (len(lines), per_line))
            seg = np.array(line_truth)
            p = seg[:, None, 0] + t[:, :, None] * (seg[:, None, 1] - seg[:, None, 0])
            px = project(local.map_to_enu(p.reshape(-1, 3)), eo_true[i], cam)
            m = len(px)
            rec.add(
                ids[i],
                px,
                np.flatnonzero(cam.in_frame(px, cfg.margin_px)),
                [f"R{j // per_line}_{j % per_line}" for j in range(m)],
                "line",
                [str(lines[j // per_line].id) for j in range(m)],
            )
    rec_point, rec_target, rec_image = rec.point, rec.target, rec.image
    pixels = np.array(rec.px).reshape(-1, 2)
    kinds = np.array(rec.type)
    # tie points seen in fewer than two images carry no information: drop them
    if "tie" in cfg.types:
        keep_rows = _seen_twice(kinds, rec_point)
        pixels = pixels[keep_rows]
        kinds = kinds[keep_rows]
        rec_image, rec_point, rec_target = (
            [v for v, k in zip(values, keep_rows) if k]
            for values in (rec_image, rec_point, rec_target)
        )
    blunders = np.empty(0, dtype=np.int64)
    if not exact:
        pixels = pixels + rng.normal(0, cfg.sigma_px, pixels.shape)
        if cfg.n_blunders:
            cand = np.flatnonzero(np.isin(kinds, ("tie", "lcp")))
            blunders = np.sort(rng.choice(cand, cfg.n_blunders, replace=False))
            ang = rng.uniform(0, 2 * math.pi, blunders.size)
            pixels[blunders] += cfg.blunder_px * np.column_stack([np.cos(ang), np.sin(ang)])
    obs = ImageObservations.from_arrays(
        rec_image, rec_point, pixels, np.full(len(pixels), cfg.sigma_px), list(kinds), rec_target
    )

    return obs, blunders


def simulate_flight(config: FlightConfig, seed: int = 0, exact: bool = False) -> FlightSimulation:
    """Simulate a calibration flight (module docstring).

    Parameters
    ----------
    config : FlightConfig
    seed : int
        Seed of every noise (INS, LiDAR, pixels, blunders, point choice); the town layout uses
        ``config.town_seed``.
    exact : bool
        Noise-free INS, planes (true parameters with the fitted covariance), lines, LCPs and
        pixels; no blunders.

    Returns
    -------
    FlightSimulation
    """
    cfg = config
    rng = np.random.default_rng(seed)
    frame, grade, nominal = _plan_basics(cfg)
    cam = cfg.camera

    # ---- town
    cols = max(1, math.ceil(math.sqrt(cfg.n_buildings)))
    cell = max(25.0, cfg.town_size_m / cols)
    origin = (cfg.centre[0] - cols * cell / 2, cfg.centre[1] - cols * cell / 2)
    town = make_town(
        n_buildings=cfg.n_buildings,
        roof_types=cfg.roof_types,
        n_trees=0,
        origin=origin,
        cell=cell,
        seed=cfg.town_seed,
    )
    kept = [f.face_id for f in town.faces][: cfg.n_planes]

    # ---- flight lines (grid azimuths), true attitude and boresight
    h0 = float(town.terrain_z(np.array([cfg.centre]))[0]) + cfg.flying_height_m
    traj_true, bore_of, llh = _true_flight(cfg, cam, h0, frame, rng, seconds_per_image=10.0)
    ids, groups, enh = traj_true.image_id, traj_true.group, traj_true.position
    time, rph_true = traj_true.time, traj_true.rph
    lever = np.array(cfg.lever_arm_m, dtype=np.float64)
    local, centre_l, r_cl = _true_poses(traj_true, bore_of, lever, nominal, frame)
    m_true = np.swapaxes(r_cl, 1, 2)
    opk = np.column_stack(matrix_to_opk(m_true))
    eo_true = np.hstack([centre_l, opk])

    # ---- LiDAR roof points and planes
    lidar, lid = _roof_samples(town, cfg.lidar_density, rng)
    keep = np.isin(lid, kept)
    lidar, lid = lidar[keep], lid[keep]
    lidar_noisy = lidar + rng.normal(0, cfg.lidar_noise_m, lidar.shape)
    planes, lines, line_truth, all_lcps, lcp_truth = _control(
        town, kept, lidar_noisy, lid, exact, cfg.plane_source
    )
    order = rng.permutation(len(all_lcps))
    n_check = min(cfg.n_check, len(all_lcps)) if "check" in cfg.types else 0
    check_lcps = [all_lcps[i] for i in order[:n_check]]
    control_lcps = [all_lcps[i] for i in order[n_check:]]
    check_truth = {str(all_lcps[i].id): lcp_truth[i] for i in order[:n_check]}
    control_truth = [lcp_truth[i] for i in order[n_check:]]

    # ---- image observations: (true map point, type, target, point id)
    obs, blunders = _observations(
        cfg,
        town,
        kept,
        local,
        eo_true,
        ids,
        cam,
        lines,
        line_truth,
        control_truth,
        control_lcps,
        check_lcps,
        check_truth,
        exact,
        rng,
    )

    # ---- INS measurements
    if exact:
        enh_meas, rph_meas = enh, rph_true
    else:
        enh_meas, rph_meas = _ins_measurements(local, llh, enh, rph_true, grade, rng)
    traj = Trajectory(tuple(ids), time, tuple(groups), enh_meas, False, rph_meas)
    mount = Mount(lever, nominal, np.radians(cfg.initial_boresight_deg))
    truth = FlightTruth(tuple(groups), bore_of, lever, traj_true, check_truth, blunders)
    return FlightSimulation(
        cfg,
        cfg.crs,
        traj,
        cam,
        mount,
        planes,
        lines,
        control_lcps,
        check_lcps,
        obs,
        lidar_noisy if not exact else lidar,
        lid,
        town,
        truth,
    )


def surveyed_control(
    config: FlightConfig,
    seed: int,
    survey_sigma_m: tuple[float, float, float] = (0.02, 0.02, 0.03),
    survey_seed: int = 11,
    folder: Union[str, Path, None] = None,
) -> tuple[FlightSimulation, ImageObservations, GroundPoints, dict[str, Path]]:
    """A flight whose only control is surveyed ground points measured as ``control`` rows.

    The roof corners stand in for surveyed points: the ``lcp`` and ``check`` rows of
    ``simulate_flight(config, seed)`` (true corners, pixel noise) become ``control`` rows of
    point ``GCP<id>``, and the ground points are the true corners (from the exact simulation)
    plus Gaussian survey noise of ``survey_sigma_m`` (sx, sy, sz, which they also carry); the
    LCPs used as check points get the role ``check``. With ``folder`` the simulation's files
    are written there, the observations replaced by these rows and the ground points added
    (``paths["ground"]``).
    """
    sim = simulate_flight(config, seed=seed)
    exact = simulate_flight(config, seed=seed, exact=True)
    truth = {str(p.id): p.xyz for p in exact.lcps + exact.check_lcps}
    check_ids = {str(p.id) for p in sim.check_lcps}
    obs = sim.observations.subset(np.isin(sim.observations.type, ("lcp", "check")))
    n = len(obs)
    rows = ImageObservations(
        obs.image_id,
        tuple(f"GCP{t}" for t in obs.target_id),
        obs.pixels,
        obs.sigma_px,
        ("control",) * n,
        ("",) * n,
    )
    ids = sorted(set(obs.target_id), key=int)
    sigma = np.asarray(survey_sigma_m, dtype=np.float64)
    noise = np.random.default_rng(survey_seed).normal(0.0, sigma, (len(ids), 3))
    ground = GroundPoints(
        tuple(f"GCP{i}" for i in ids),
        np.array([truth[i] for i in ids]) + noise,
        np.tile(sigma, (len(ids), 1)),
        tuple("check" if i in check_ids else "control" for i in ids),
    )
    paths: dict[str, Path] = {}
    if folder is not None:
        paths = sim.write(folder)
        write_observations_csv(paths["observations"], rows)
        paths["ground"] = Path(folder) / "ground_points.csv"
        write_ground_points_csv(paths["ground"], ground)
    return sim, rows, ground, paths


def _direction_names(cfg: FlightConfig) -> list[str]:
    """Group name of each line: its compass direction, with a line number when repeated."""
    compass = ("N", "NE", "E", "SE", "S", "SW", "W", "NW")
    out = []
    for line in range(cfg.n_lines):
        h = cfg.heading_deg + (180.0 if cfg.opposite and line % 2 == 1 else 0.0)
        out.append(compass[round(h % 360.0 / 45.0) % 8])
    if len(set(out)) < len(out):
        out = [f"{d}{k + 1}" for k, d in enumerate(out)]
    return out


class _Records:
    """Image measurements as they are made: image, point name, pixel, type, target."""

    def __init__(self) -> None:
        self.image: list[str] = []
        self.point: list[str] = []
        self.px: list[Array] = []
        self.type: list[str] = []
        self.target: list[str] = []

    def add(self, image: str, px: Array, rows, names, kind: str, targets) -> None:
        """The rows ``rows`` of ``px`` (N, 2), measured in ``image``."""
        for j in rows:
            self.image.append(image)
            self.point.append(names[j])
            self.px.append(px[j])
            self.type.append(kind)
            self.target.append(targets[j])


def _seen_twice(kinds: NDArray, names: list[str]) -> NDArray[np.bool_]:
    """Rows to keep: tie points seen in fewer than two images carry no information."""
    names_arr = np.array(names)
    uniq, cnt = np.unique(names_arr[kinds == "tie"], return_counts=True)
    return ~((kinds == "tie") & np.isin(names_arr, uniq[cnt < 2]))


def _ins_measurements(local, llh: Array, enh: Array, rph: Array, grade: InsGrade, rng):
    """The INS solution: the true positions and attitudes plus the grade's noise."""
    n = len(enh)
    r_nl = local.ned_to_local(llh)
    enu_i = r_nl @ np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]]).T
    noise = np.einsum("nij,nj->ni", enu_i, rng.normal(0, 1, (n, 3)) * grade.sigma_position)
    enh_meas = local.enu_to_map(local.map_to_enu(enh) + noise)
    return enh_meas, rph + rng.normal(0, 1, (n, 3)) * grade.sigma_attitude


def _true_poses(traj: Trajectory, bore_of: dict, lever: Array, nominal: Array, frame):
    """The true camera poses in the local ENU frame of the flight: (frame, centres (N, 3),
    camera-to-local rotations (N, 3, 3)), each flight line with its own boresight."""
    local = local_frame_for(traj, frame)
    n = len(traj)
    centre_l = np.empty((n, 3))
    r_cl = np.empty((n, 3, 3))
    groups = np.array(traj.group)
    for g, b in bore_of.items():
        sel = groups == g
        sub = Trajectory(
            tuple(np.array(traj.image_id)[sel]),
            traj.time[sel],
            tuple(groups[sel]),
            traj.position[sel],
            False,
            traj.rph[sel],
        )
        poses = georeference_ecef(sub, Mount(lever, nominal, b), frame)
        centre_l[sel] = local.ecef_to_enu(poses.centre_ecef)
        r_cl[sel] = local.rotation @ poses.camera_to_ecef
    return local, centre_l, r_cl


def _truth(config: FlightPlan, truth: FlightTruth, mount: Mount) -> dict:
    """The truth of a flight as JSON-ready data."""
    return {
        "crs": config.crs,
        "boresight_deg": {g: np.degrees(b).tolist() for g, b in truth.boresight.items()},
        "initial_boresight_deg": np.degrees(mount.boresight).tolist(),
        "lever_arm_m": truth.lever_arm.tolist(),
        "mount": config.mount,
    }
