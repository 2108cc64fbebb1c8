"""The inputs of the boresight calibration (:mod:`.boresight`): its options, the surveyed
points it takes, the adjustment frame and the LiDAR control (planes, lines, LCPs) carried into
it, the boresight groups, and the layout of the calibration and pose parameters.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol, Union

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..geometry.camera import Camera
from ..geometry.frames import LocalFrame, MappingFrame
from .boresight_models import (
    PoseSpec,
)
from .boresight_options import BoresightOptions
from .georeference import Trajectory
from .ins import INS_GRADES, InsGrade
from .mount import Mount
from .observations import ImageObservations
from .timing import difference_velocity, timing_separability

__all__ = [
    "ARCSEC",
    "BoresightOptions",
    "SurveyedPoints",
    "group_labels",
    "local_frame_for",
    "timing_separability",
    "transform_lcps",
    "transform_lines",
    "transform_planes",
]

Array = NDArray[np.float64]
ARCSEC = math.pi / (180.0 * 3600.0)
ANGLES = ("d_omega", "d_phi", "d_kappa")
INS_NAMES = ("E", "N", "U", "roll", "pitch", "heading")


class SurveyedPoints(Protocol):
    """Surveyed ground points as :class:`core.photo.bundle_setup.GroundPoints` holds them (a
    protocol: that module depends on this one): ids, mapping-CRS coordinates (m), sigmas (m),
    roles (``control`` or ``check``)."""

    point_id: tuple[str, ...]
    xyz: Array
    sigma: Array
    role: tuple[str, ...]
    source: str


# ----------------------------------------------------------------------------- frames


def local_frame_for(trajectory: Trajectory, frame: MappingFrame) -> LocalFrame:
    """Adjustment frame tangent at the horizontal centre of the images, ellipsoidal height 0."""
    llh = _trajectory_llh(trajectory, frame)
    lat = float(np.mean(llh[:, 0]))
    lon = float(np.mean(llh[:, 1]))
    return LocalFrame(frame, (lat, lon, 0.0))


def _trajectory_llh(trajectory: Trajectory, frame: MappingFrame) -> Array:
    pos = np.asarray(trajectory.position, dtype=np.float64)
    return pos if trajectory.geodetic else frame.map_to_geodetic(pos)


def transform_planes(planes: Sequence, local: LocalFrame) -> tuple[Array, Array, Array]:
    """Planes of the mapping CRS -> (params (P, 4), covariance (P, 4, 4), centroid (P, 3)) in ENU.

    A plane ``n . p + d = 0`` through its centroid c maps, with ``p_l = T(c) + J (p - c)``, to
    ``(K n) . p_l + (c - K' T(c)) . n + d = 0`` with ``K = J^-T``, then normalised.
    """
    if not planes:
        return np.empty((0, 4)), np.empty((0, 4, 4)), np.empty((0, 3))
    c = np.array([p.centroid for p in planes], dtype=np.float64)
    pi = np.array([p.params for p in planes], dtype=np.float64)
    cov = np.array([p.covariance for p in planes], dtype=np.float64)
    tc, jac = local.map_to_enu_jacobian(c)
    kmat = np.linalg.inv(np.swapaxes(jac, 1, 2))
    lin = np.zeros((len(planes), 4, 4))
    lin[:, :3, :3] = kmat
    lin[:, 3, :3] = c - np.einsum("pi,pij->pj", tc, kmat)
    lin[:, 3, 3] = 1.0
    raw = np.einsum("pij,pj->pi", lin, pi)
    s = np.linalg.norm(raw[:, :3], axis=1)
    out = raw / s[:, None]
    nz = np.concatenate([out[:, :3], np.zeros((len(planes), 1))], axis=1)
    norm_j = (np.eye(4) - out[:, :, None] * nz[:, None, :]) / s[:, None, None]
    full = norm_j @ lin
    cov_l = full @ cov @ np.swapaxes(full, 1, 2)
    return out, 0.5 * (cov_l + np.swapaxes(cov_l, 1, 2)), tc


def transform_lines(lines: Sequence, local: LocalFrame) -> tuple[Array, Array, Array]:
    """Lines of the mapping CRS -> (X0 (L, 3), u (L, 3), covariance (L, 6, 6)) in ENU."""
    if not lines:
        return np.empty((0, 3)), np.empty((0, 3)), np.empty((0, 6, 6))
    x0 = np.array([ln.point for ln in lines], dtype=np.float64)
    u = np.array([ln.direction for ln in lines], dtype=np.float64)
    cov = np.array([ln.covariance for ln in lines], dtype=np.float64)
    tx, jac = local.map_to_enu_jacobian(x0)
    ju = np.einsum("lij,lj->li", jac, u)
    s = np.linalg.norm(ju, axis=1)
    ul = ju / s[:, None]
    full = np.zeros((len(lines), 6, 6))
    full[:, :3, :3] = jac
    full[:, 3:, 3:] = (np.eye(3) - ul[:, :, None] * ul[:, None, :]) @ jac / s[:, None, None]
    c = full @ cov @ np.swapaxes(full, 1, 2)
    return tx, ul, 0.5 * (c + np.swapaxes(c, 1, 2))


def transform_lcps(points: Sequence, local: LocalFrame) -> tuple[Array, Array]:
    """LCPs of the mapping CRS -> (xyz (L, 3), covariance (L, 3, 3)) in ENU."""
    if not points:
        return np.empty((0, 3)), np.empty((0, 3, 3))
    xyz = np.array([p.xyz for p in points], dtype=np.float64)
    cov = np.array([p.covariance for p in points], dtype=np.float64)
    tx, jac = local.map_to_enu_jacobian(xyz)
    c = jac @ cov @ np.swapaxes(jac, 1, 2)
    return tx, 0.5 * (c + np.swapaxes(c, 1, 2))


# ----------------------------------------------------------------------------- helpers


def group_labels(trajectory: Trajectory, groups: Union[str, Mapping[str, str]]) -> list[str]:
    if isinstance(groups, Mapping):
        missing = [i for i in trajectory.image_id if i not in groups]
        if missing:
            raise InputError(f"boresight groups: no group for image(s) {missing[:10]}")
        return [str(groups[i]) for i in trajectory.image_id]
    mode = str(groups).strip().lower()
    if mode == "single":
        return ["all"] * len(trajectory)
    if mode == "group":
        return [g if g else "all" for g in trajectory.group]
    if mode == "direction":
        names = ("N", "NE", "E", "SE", "S", "SW", "W", "NW")
        octant = np.round(np.degrees(trajectory.rph[:, 2]) % 360.0 / 45.0).astype(int) % 8
        return [names[k] for k in octant]
    raise InputError(f"groups '{groups}' is unknown: use single, group, direction or a mapping")


def _grade(grade: Union[str, InsGrade]) -> InsGrade:
    if isinstance(grade, InsGrade):
        return grade
    key = str(grade).strip().lower().replace(" ", "_")
    if key not in INS_GRADES:
        raise InputError(f"INS grade '{grade}' is unknown: use {', '.join(INS_GRADES)} or custom")
    return INS_GRADES[key]


@dataclass(frozen=True)
class _KnownPoint:
    """A surveyed point as :func:`transform_lcps` takes it (mapping CRS, m; m^2)."""

    id: str
    xyz: Array
    covariance: Array


def _surveyed_points(
    obs: ImageObservations, ground: SurveyedPoints | None
) -> tuple[list[_KnownPoint], NDArray[np.bool_]]:
    """The ground points of ``control`` rows (covariance diag(sx^2, sy^2, sz^2)) and the rows
    that measure a check point (N,). A control row naming no ground point is an error: a
    surveyed point must never turn into something else silently."""
    rows = np.flatnonzero(obs.mask("control"))
    if ground is None or not len(ground.point_id):
        raise InputError(
            f"{rows.size} observation row(s) of type control measure surveyed points but no "
            "ground points were given (GROUND_POINTS), or leave control out of the types used",
            **obs.where(int(rows[0])),
        )
    index = {p: k for k, p in enumerate(ground.point_id)}
    where = f" ({ground.source})" if ground.source else ""
    obs.require_control_known(index, f"the ground points{where}")
    check = np.zeros(len(obs), dtype=bool)
    check[rows] = [ground.role[index[obs.point_id[r]]] == "check" for r in rows]
    points = [
        _KnownPoint(p, ground.xyz[k], np.diag(ground.sigma[k] ** 2))
        for k, p in enumerate(ground.point_id)
        if ground.role[k] == "control"
    ]
    return points, check


def _index(ids: Sequence[str], known: Mapping[str, int], what: str, rows: Array) -> Array:
    out = np.empty(len(ids), dtype=np.intp)
    for k, (i, r) in enumerate(zip(ids, rows)):
        if i not in known:
            raise InputError(f"observation {int(r) + 2}: {what} '{i}' is not known")
        out[k] = known[i]
    return out


@dataclass
class _Parameters:
    """The calibration and pose parameters of :func:`calibrate` (names, initial values, where
    the lever arm, interior orientation and INS poses start) and each image's pose indices."""

    names: list[str]
    x0: list[float]
    n_cal: int  # the calibration parameters come first
    lever_at: int
    interior_at: int
    ins_at: int
    pose_idx: NDArray[np.intp]  # (N, spec.size)
    timing_at: int = -1


def _parameters(
    trajectory: Trajectory,
    camera: Camera,
    mount: Mount,
    opts: BoresightOptions,
    group_names: tuple[str, ...],
    gidx: NDArray[np.intp],
    ins_pos: Array,
    spec: PoseSpec,
) -> _Parameters:
    """Boresight per group, lever arm and interior orientation when estimated, then the INS
    pose of every image."""
    n_img = len(trajectory)
    names: list[str] = []
    x0: list[float] = []
    for g in group_names:
        names += [f"bore[{g}].{a}" for a in ANGLES]
        x0 += list(mount.boresight)
    lever_at = interior_at = -1
    if opts.estimate_lever_arm:
        lever_at = len(names)
        names += ["lever_arm.x", "lever_arm.y", "lever_arm.z"]
        x0 += list(mount.lever_arm)
    if opts.estimate_interior:
        interior_at = len(names)
        names += ["interior.f", "interior.x0", "interior.y0"]
        x0 += [camera.focal_mm, camera.x0_mm, camera.y0_mm]
    timing_at = -1
    if opts.estimate_timing:
        timing_at = len(names)
        names += ["timing.dt"]
        x0 += [0.0]
    n_cal = len(names)
    ins_at = len(names)
    for i in trajectory.image_id:
        names += [f"ins[{i}].{a}" for a in INS_NAMES]
    x0 += list(np.hstack([ins_pos, trajectory.rph]).ravel())
    pose_idx = np.zeros((n_img, spec.size), dtype=np.intp)
    pose_idx[:, 0:3] = 3 * gidx[:, None] + np.arange(3)
    pose_idx[:, 3:9] = ins_at + 6 * np.arange(n_img)[:, None] + np.arange(6)
    col = 9
    if opts.estimate_lever_arm:
        pose_idx[:, col : col + 3] = lever_at + np.arange(3)
        col += 3
    if opts.estimate_interior:
        pose_idx[:, col : col + 3] = interior_at + np.arange(3)
    return _Parameters(names, x0, n_cal, lever_at, interior_at, ins_at, pose_idx, timing_at)


def exposure_velocity(trajectory: Trajectory, ins_pos: Array, r_nl: Array) -> Array:
    """(N, 3) velocity of each exposure in the adjustment frame (ENU), m/s.

    The trajectory's own velocities when it has them (``Trajectory.velocity_ned``, north-east-
    down at each image, as ``importtrajectory`` interpolates them from the high-rate solution),
    rotated by ``r_nl`` (N, 3, 3: NED at each image -> the adjustment frame). Otherwise finite
    differences of the neighbouring exposures of the same flight line (trajectory group
    column; empty = one line; :func:`.timing.difference_velocity`). The attitude's rate is not
    used: the dt term of the attitude is neglected, which is second order for straight lines.
    """
    if trajectory.velocity_ned is not None:
        return np.einsum("nij,nj->ni", r_nl, np.asarray(trajectory.velocity_ned, dtype=float))
    return difference_velocity(trajectory.time, trajectory.group, ins_pos)
