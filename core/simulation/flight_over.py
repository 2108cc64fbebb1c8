"""A calibration flight over real LiDAR control (:func:`simulate_flight_over`): a small-format
camera flown over given planes, lines and LCPs (the demo's real roofs), with the truth; the
helpers are :mod:`.flight`'s.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Union

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..geometry.camera import Camera
from ..geometry.collinearity import project
from ..geometry.planes import Plane
from ..geometry.rotations import matrix_to_opk
from ..io.atomic import folder_files, write_text_atomic
from ..io.camera import write_camera_json
from ..io.observations import write_observations_csv
from ..io.tables import write_csv_atomic
from ..io.trajectory import write_trajectory_csv
from ..lidar.control import ControlLine, ControlPoint
from ..photo.georeference import Trajectory
from ..photo.mount import Mount
from ..photo.observations import ImageObservations
from .flight import (
    FlightPlan,
    FlightTruth,
    _ins_measurements,
    _plan_basics,
    _Records,
    _seen_twice,
    _true_flight,
    _true_poses,
    _truth,
)

__all__ = [
    "ControlFlightConfig",
    "ControlFlightSimulation",
    "simulate_flight_over",
    "small_format_camera",
]

Array = NDArray[np.float64]


# ----------------------------------------------------------------------------- over real control


def small_format_camera() -> Camera:
    """A 24 Mpx small-format survey camera: f = 35 mm, 4.5 um pixels, 6000 x 4000 px."""
    return Camera(
        "small format 35 mm", focal_mm=35.0, pixel_size_mm=0.0045, width_px=6000, height_px=4000
    )


@dataclass(frozen=True)
class ControlFlightConfig(FlightPlan):
    """A calibration flight over existing LiDAR control (real planes, lines and LCPs).

    Attributes are those of :class:`FlightConfig` where they share a name (a small-format
    camera low over a city block by default); ``centre`` is the block centre (mapping CRS)
    and ``flying_height_m`` is above the lowest LiDAR point. ``n_check`` roof points (on the
    planes) are made check points: measured in every image that sees them, never adjusted.
    """

    # the defaults that differ from FlightPlan's (the fields keep FlightPlan's order)
    camera: Camera = field(default_factory=small_format_camera)
    centre: tuple[float, float] = (84940.0, 447595.0)
    flying_height_m: float = 130.0
    heading_deg: float = 0.0
    images_per_line: int = 5
    forward_overlap: float = 0.8
    side_overlap: float = 0.6
    lever_arm_m: tuple[float, float, float] = (0.10, -0.05, -0.20)
    true_boresight_deg: tuple[tuple[float, float, float], ...] = ((0.12, -0.25, 0.40),)
    types: tuple[str, ...] = ("tie", "line", "lcp", "check")
    ties_per_plane: int = 2
    line_points_per_image: int = 2
    n_check: int = 15
    sigma_px: float = 0.5
    margin_px: float = 50.0


@dataclass(frozen=True)
class ControlFlightSimulation:
    """Trajectory, mount and image observations over given control, with the truth.

    ``check_points`` maps each check point id (``K<k>``, the ``target_id`` of its ``check``
    rows) to its true position (mapping CRS).
    """

    config: ControlFlightConfig
    trajectory: Trajectory
    camera: Camera
    mount: Mount
    observations: ImageObservations
    truth: FlightTruth
    check_points: dict[str, Array]

    def write(self, folder: Union[str, Path]) -> dict[str, Path]:
        """Write trajectory.csv, camera.json, observations.csv, check_points.csv (id, e, n, h:
        the truth) and truth.json; returns their paths by name."""
        csv = ("trajectory", "observations", "check_points")
        paths = folder_files(folder, "camera.json", *(f"{k}.csv" for k in csv), "truth.json")
        write_trajectory_csv(paths["trajectory"], self.trajectory)
        write_camera_json(paths["camera"], self.camera)
        write_observations_csv(paths["observations"], self.observations)
        write_csv_atomic(
            paths["check_points"],
            ("id", "e", "n", "h"),
            [(k, *(repr(float(v)) for v in p)) for k, p in self.check_points.items()],
        )
        write_text_atomic(
            paths["truth"], json.dumps(_truth(self.config, self.truth, self.mount), indent=2)
        )
        return paths


def simulate_flight_over(
    planes: list[Plane],
    lines: list[ControlLine],
    lcps: list[ControlPoint],
    lidar_points: Array,
    lidar_plane_ids: NDArray[np.integer],
    config: ControlFlightConfig | None = None,
    seed: int = 0,
) -> ControlFlightSimulation:
    """Simulate a calibration flight over real LiDAR control (e.g. from a real tile).

    The given planes, lines and LCPs are taken as the true roof geometry (the LiDAR fit is the
    truth here, so the simulation isolates the image and INS side). Tie and check points are
    LiDAR points of a plane moved onto it (so they lie where the roof really is), line points
    are spread along each line's clipped segment, LCPs are measured where they are. Visibility
    is the image frame only (no occlusion).

    Parameters
    ----------
    planes, lines, lcps : sequences of Plane, ControlLine, ControlPoint
        Mapping CRS.
    lidar_points : ndarray, shape (M, 3)
        Points of the planes (mapping CRS) with their ``lidar_plane_ids`` (M,) (-1: none).
    config : ControlFlightConfig, optional
    seed : int
        Seed of every random choice and noise.

    Returns
    -------
    ControlFlightSimulation
    """
    cfg = config if config is not None else ControlFlightConfig()
    rng = np.random.default_rng(seed)
    frame, grade, nominal = _plan_basics(cfg)
    cam = cfg.camera
    pts = np.asarray(lidar_points, dtype=np.float64).reshape(-1, 3)
    pid = np.asarray(lidar_plane_ids).astype(np.int64)
    if not planes or pts.shape[0] != pid.shape[0]:
        raise InputError("simulate_flight_over needs planes and their LiDAR points")

    # ---- flight lines (as simulate_flight), true attitude and poses via ECEF
    h0 = float(pts[:, 2].min()) + cfg.flying_height_m
    traj_true, bore_of, llh = _true_flight(cfg, cam, h0, frame, rng, seconds_per_image=2.0)
    ids, groups, enh = traj_true.image_id, traj_true.group, traj_true.position
    time, rph_true, n = traj_true.time, traj_true.rph, len(traj_true)
    lever = np.array(cfg.lever_arm_m, dtype=np.float64)
    local, centre_l, r_cl = _true_poses(traj_true, bore_of, lever, nominal, frame)
    eo_true = np.hstack([centre_l, np.column_stack(matrix_to_opk(np.swapaxes(r_cl, 1, 2)))])

    # ---- true ground points: (map xyz, type, target id, point id)
    plane_of = {int(p.id): p for p in planes}

    def on_plane(k_points: int, exclude: set[int]) -> tuple[Array, list[str]]:
        out, tgt = [], []
        for p in planes:
            idx = np.flatnonzero(pid == int(p.id))
            idx = np.setdiff1d(idx, list(exclude))
            if idx.size == 0:
                continue
            take = rng.choice(idx, min(k_points, idx.size), replace=False)
            exclude.update(take.tolist())
            q = pts[take]
            out.append(q - np.outer(q @ p.normal + p.d, p.normal))  # onto the plane
            tgt += [str(p.id)] * len(take)
        return (np.vstack(out) if out else np.empty((0, 3))), tgt

    used: set[int] = set()
    targets: list[tuple[Array, str, list[str], list[str]]] = []
    check_points: dict[str, Array] = {}
    if "check" in cfg.types and cfg.n_check > 0:
        cand = np.flatnonzero(np.isin(pid, list(plane_of)))
        take = rng.choice(cand, min(cfg.n_check, cand.size), replace=False)
        used.update(take.tolist())
        q = pts[take]
        nrm = np.array([plane_of[int(i)].normal for i in pid[take]])
        dd = np.array([plane_of[int(i)].d for i in pid[take]])
        q = q - nrm * (np.einsum("ij,ij->i", q, nrm) + dd)[:, None]
        check_points = {f"K{k}": q[k] for k in range(len(q))}
        targets.append((q, "check", list(check_points), list(check_points)))
    if "tie" in cfg.types:
        q, tgt = on_plane(cfg.ties_per_plane, used)
        targets.append((q, "tie", tgt, [f"T{k}" for k in range(len(q))]))
    if "lcp" in cfg.types and lcps:
        q = np.array([c.xyz for c in lcps], dtype=np.float64)
        targets.append((q, "lcp", [str(c.id) for c in lcps], [f"C{c.id}" for c in lcps]))
    rec = _Records()
    local_targets = [(local.map_to_enu(q), kind, t, p) for q, kind, t, p in targets if len(q)]
    per_line = cfg.line_points_per_image
    for i in range(n):
        for q, kind, tgt, pnames in local_targets:
            px = project(q, eo_true[i], cam)
            rec.add(ids[i], px, np.flatnonzero(cam.in_frame(px, cfg.margin_px)), pnames, kind, tgt)
        if "line" in cfg.types and lines:
            t = rng.uniform(0.1, 0.9, (len(lines), per_line))
            a = np.array([ln.start for ln in lines])
            b = np.array([ln.end for ln in lines])
            q = a[:, None] + t[:, :, None] * (b - a)[:, None]
            px = project(local.map_to_enu(q.reshape(-1, 3)), eo_true[i], cam)
            m = len(px)
            rec.add(
                ids[i],
                px,
                np.flatnonzero(cam.in_frame(px, cfg.margin_px)),
                [f"R{lines[j // per_line].id}_{i}_{j % per_line}" for j in range(m)],
                "line",
                [str(lines[j // per_line].id) for j in range(m)],
            )
    pixels = np.array(rec.px).reshape(-1, 2)
    kinds = np.array(rec.type)
    keep = _seen_twice(kinds, rec.point)
    pixels = pixels[keep] + rng.normal(0, cfg.sigma_px, (int(keep.sum()), 2))
    obs = ImageObservations.from_arrays(
        [v for v, k in zip(rec.image, keep) if k],
        [v for v, k in zip(rec.point, keep) if k],
        pixels,
        np.full(len(pixels), cfg.sigma_px),
        list(kinds[keep]),
        [v for v, k in zip(rec.target, keep) if k],
    )

    # ---- INS measurements: the truth plus the grade's noise
    enh_meas, rph_meas = _ins_measurements(local, llh, enh, rph_true, grade, rng)
    traj = Trajectory(tuple(ids), time, tuple(groups), enh_meas, False, rph_meas)
    mount = Mount(lever, nominal, np.radians(cfg.initial_boresight_deg))
    truth = FlightTruth(
        tuple(groups), bore_of, lever, traj_true, check_points, np.empty(0, dtype=np.int64)
    )
    return ControlFlightSimulation(cfg, traj, cam, mount, obs, truth, check_points)
