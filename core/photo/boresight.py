"""Boresight (and optionally lever-arm and interior) calibration from LiDAR roof control.

Model
-----
Everything runs in a local ENU adjustment frame tangent to the ellipsoid at the block centre
(:class:`~lidarphoto.core.geometry.frames.LocalFrame`). For image i with INS position ``p_i`` and
attitude ``R_b^n(roll, pitch, heading)`` (NED at the image's own position, rotated rigorously
into the ENU frame by ``R_n^l = LocalFrame.ned_to_local``)::

    X_pc(i) = p_i + R_n^l R_b^n a_b
    R_c^l(i) = R_n^l R_b^n R_nominal dR(bore_g(i)),     dR = Rx(dw) Ry(dp) Rz(dk)

Unknowns: the boresight ``(dw, dp, dk)`` of each group g (one set, per direction, per flight
line or per session: ``BoresightOptions.groups``), optionally the lever arm ``a_b`` and the
focal length and principal point, the tie-point coordinates, the LCP coordinates and, per
image, the INS position and attitude as nuisance parameters with weighted prior observations
(sigmas of a named INS grade, :data:`INS_GRADES`, or custom).

Control types (any mix, one adjustment; :mod:`core.photo.boresight_models` has the equations):

1. ``tie``: plane-constrained tie points (primary mode). A roof point measured in >= 2 images:
   collinearity for each measurement (Gauss-Markov) with the point as unknown, and the
   condition ``n . X + d - e = 0`` (Gauss-Helmert) with the plane's (a, b, c, d) as
   observations with their 4 x 4 covariance and ``e`` ~ N(0, roughness^2) the roof's departure
   from a plane. All tie points on one plane share one group, so a plane is never used twice.
2. ``line``: a point anywhere along a LiDAR ridge, hip or valley line: the image ray and the
   line are coplanar, ``(X0 - X_pc) . (r x u) = 0`` (Gauss-Helmert) with the pixel and the
   line's (X0, u) and 6 x 6 covariance as observations; all measurements of one line share
   one group. One image suffices.
3. ``lcp``: LiDAR control points: collinearity, the LCP an unknown point with a prior from its
   3 x 3 covariance. ``control``: surveyed ground points (``point_id`` in the ground points
   table), the same model with the diagonal covariance of their sigmas (sx^2, sy^2, sz^2);
   points of role ``check`` are left out of the adjustment, as ``check`` rows of LCPs.
4. ``paper``: the single-image model of Pedrosa & dos Santos (2020) (its Eqs. 12-17): the ray
   cut at a height z taken from the LiDAR points of the plane nearest the picked point
   (located with the *initial* orientation, once), with the plane offset d as the observation
   and sigma_d from Eq. 17 as printed (``sqrt(Cx^2 + Cy^2 + Cz^2) + sigma^2 / n`` with the
   centroid in the mapping CRS; its misprint is discussed in :mod:`core.io.planes`) or, with
   ``paper_sigma="propagated"``, the plane's propagated standard deviation. The pixel is not an
   observation there (as in the paper), so this model's sigmas ignore the image noise and its
   z depends on the initial boresight: see bench/boresight.md for what this does.

Planes, lines and LCPs are given in the mapping CRS; they are carried into the adjustment
frame with the local Jacobian of the map -> ENU transformation (scale factor, convergence and
the tilt of the vertical included), covariances propagated to first order.

The adjustment is :func:`core.lsq.adjustment.adjust` (Gauss-Markov/Gauss-Helmert, Levenberg-
Marquardt, Baarda data snooping). When a parameter is not observable, :func:`calibrate`
raises :class:`BoresightNotObservable` whose ``diagnosis`` says which flight pattern or
control would fix it.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Callable, Protocol, Union

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from ..errors import DiagnosedNotObservable, InputError, NotObservableError
from ..geometry.camera import Camera
from ..geometry.frames import NED_TO_ENU, LocalFrame, MappingFrame
from ..i18n import mark as _t
from ..lsq.adjustment import adjust
from ..lsq.model import AdjustmentOptions, GaussHelmertBlock, GaussMarkovBlock, prior_block
from ..lsq.results import AdjustmentResult
from .boresight_models import (
    PoseSpec,
    camera_ray,
    collinearity,
    coplanarity,
    paper_plane,
    pose_chain,
)
from .georeference import Trajectory
from .ins import INS_GRADES, InsGrade
from .mount import Mount
from .observations import ImageObservations
from .orientation import ExteriorOrientationTable, eo_local_to_map

#: catalogue context of this module's ``_t("...")`` sentences (the diagnosis the report shows)
TR_CONTEXT = "Report"

__all__ = [
    "ARCSEC",
    "BoresightNotObservable",
    "BoresightOptions",
    "BoresightResult",
    "ObservationResiduals",
    "SurveyedPoints",
    "calibrate",
    "diagnose",
    "local_frame_for",
    "transform_lcps",
    "transform_lines",
    "transform_planes",
]

log = logging.getLogger(__name__)
Array = NDArray[np.float64]
ARCSEC = math.pi / (180.0 * 3600.0)
ANGLES = ("d_omega", "d_phi", "d_kappa")
INS_NAMES = ("E", "N", "U", "roll", "pitch", "heading")


@dataclass(frozen=True)
class BoresightOptions:
    """Options of :func:`calibrate`.

    Attributes
    ----------
    groups : str or mapping
        ``"single"`` one boresight for all images; ``"group"`` one per value of the
        trajectory's group column (flight line, direction or session, as the user filled it);
        ``"direction"`` one per compass octant of the heading (N, NE, ...); or a mapping
        image_id -> group name.
    estimate_lever_arm, estimate_interior : bool
        Add the lever arm (3) / the focal length and principal point (3) as unknowns.
    ins_grade : str or InsGrade
        Key of :data:`INS_GRADES` or a custom grade: sigmas of the INS prior observations.
    ins_as_parameters : bool
        True: INS positions and attitudes are nuisance parameters with their priors. False: held at
        the INS values (weighted with 1e-6 times the grade's sigmas), as Pedrosa & dos Santos
        (2020).
    roof_roughness_m : float
        Standard deviation of a roof point about its plane (tiles, sag), metres (> 0).
    use_types : tuple of str
        Observation types used (``tie``, ``line``, ``lcp``, ``paper``, ``control``).
    paper_sigma : {"eq17", "propagated"}
        Standard deviation of d in paper mode (module docstring).
    lidar_sigma_m : float
        Nominal LiDAR coordinate sigma of Eq. 17, metres.
    paper_z_neighbours : int
        LiDAR points of the plane whose mean height is the paper's z.
    snooping, snooping_alpha : bool, float
        Baarda data snooping and its significance per observation.
    max_iterations : int
    """

    groups: Union[str, Mapping[str, str]] = "group"
    estimate_lever_arm: bool = False
    estimate_interior: bool = False
    ins_grade: Union[str, InsGrade] = "pos_av_310"
    ins_as_parameters: bool = True
    roof_roughness_m: float = 0.01
    use_types: tuple[str, ...] = ("tie", "line", "lcp", "paper", "control")
    paper_sigma: str = "eq17"
    lidar_sigma_m: float = 0.05
    paper_z_neighbours: int = 4
    snooping: bool = True
    snooping_alpha: float = 0.001
    max_iterations: int = 50


class SurveyedPoints(Protocol):
    """Surveyed ground points as :class:`core.photo.bundle_setup.GroundPoints` holds them (a
    protocol: that module depends on this one): ids, mapping-CRS coordinates (m), sigmas (m),
    roles (``control`` or ``check``)."""

    point_id: tuple[str, ...]
    xyz: Array
    sigma: Array
    role: tuple[str, ...]
    source: str


class BoresightNotObservable(DiagnosedNotObservable):
    """A calibration parameter cannot be determined; ``diagnosis`` explains what would fix it."""


@dataclass
class ObservationResiduals:
    """Residuals per input observation row (N rows of the observation table).

    Attributes
    ----------
    v_px : ndarray, shape (N, 2)
        Residual (adjusted - observed) of col and row, pixels; NaN for paper and unused rows.
    v_d : ndarray, shape (N,)
        Residual of d for paper rows, metres (NaN otherwise).
    w : ndarray, shape (N,)
        Largest |Baarda w| of the row's observations (NaN if untestable or unused).
    rejected : ndarray of bool, shape (N,)
        Rejected by data snooping (a line group or plane group is rejected as a whole).
    used : ndarray of bool, shape (N,)
    """

    v_px: Array
    v_d: Array
    w: Array
    rejected: NDArray[np.bool_]
    used: NDArray[np.bool_]


@dataclass
class BoresightResult:
    """Result of :func:`calibrate`.

    Attributes
    ----------
    groups : tuple of str
        Boresight groups, in the order of the rows below.
    boresight, std, std_prior : ndarray, shape (G, 3)
        (d_omega, d_phi, d_kappa) in radians and their standard deviations (a-posteriori,
        i.e. scaled by sigma0, and a-priori).
    lever_arm, lever_arm_std : ndarray, shape (3,) or None
        Metres, body frame (None when not estimated).
    interior, interior_std : ndarray, shape (3,) or None
        f, x0, y0 in millimetres (None when not estimated).
    parameter_names : list of str
        Names of the calibration parameters (boresight, lever arm, interior).
    correlation : ndarray, shape (K, K)
        Their correlation matrix.
    sigma0 : float
    redundancy : int
    chi2_passed : bool
    residuals : ObservationResiduals
    eo : ExteriorOrientationTable
        Updated exterior orientation of every image, mapping CRS.
    adjustment : AdjustmentResult
    local : LocalFrame
    warnings : list of str
    """

    groups: tuple[str, ...]
    boresight: Array
    std: Array
    std_prior: Array
    lever_arm: Array | None
    lever_arm_std: Array | None
    interior: Array | None
    interior_std: Array | None
    parameter_names: list[str]
    correlation: Array
    sigma0: float
    redundancy: int
    chi2_passed: bool
    residuals: ObservationResiduals
    eo: ExteriorOrientationTable
    adjustment: AdjustmentResult
    local: LocalFrame
    warnings: list[str] = field(default_factory=list)

    @property
    def boresight_deg(self) -> Array:
        """(G, 3) degrees."""
        return np.degrees(self.boresight)

    @property
    def boresight_arcsec(self) -> Array:
        """(G, 3) arc-seconds."""
        return self.boresight / ARCSEC

    @property
    def std_arcsec(self) -> Array:
        """(G, 3) a-posteriori standard deviations, arc-seconds."""
        return self.std / ARCSEC

    def table_rows(self) -> list[dict[str, object]]:
        """One row per group and angle: value in degrees and arc-seconds, std in arc-seconds."""
        rows = []
        for g, name in enumerate(self.groups):
            for k, angle in enumerate(ANGLES):
                rows.append(
                    {
                        "group": name,
                        "parameter": angle,
                        "value_deg": float(self.boresight_deg[g, k]),
                        "value_arcsec": float(self.boresight_arcsec[g, k]),
                        "std_arcsec": float(self.std_arcsec[g, k]),
                        "std_prior_arcsec": float(self.std_prior[g, k] / ARCSEC),
                    }
                )
        return rows


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


class _Identity:
    """Gauss-Markov model ``f(x) = x`` for groups of c parameters observed together."""

    def __call__(self, x_local: Array) -> tuple[Array, Array]:
        g, c = x_local.shape
        return x_local.copy(), np.broadcast_to(np.eye(c), (g, c, c)).copy()


def _regular(cov: Array) -> Array:
    """Covariances made positive definite: a plane's (a, b, c, d) has rank 3 (unit normal), a
    line's (X0, u) rank 4 or 5; the engine factors them, so their null directions (and rounding
    below) get a variance of 1e-12 of the largest one (effect on ``B S B'``: 1e-9 relative)."""
    val, vec = np.linalg.eigh(0.5 * (cov + np.swapaxes(cov, 1, 2)))
    floor = 1e-12 * val[:, -1:]
    val = np.maximum(val, floor)
    out = (vec * val[:, None, :]) @ np.swapaxes(vec, 1, 2)
    return 0.5 * (out + np.swapaxes(out, 1, 2))


def _block_diag(jac: Array, k: int) -> Array:
    """(L * k, P) rows -> (L, k, k * P) block-diagonal Jacobians of grouped conditions."""
    p = jac.shape[-1]
    lk = jac.shape[0] // k
    out = np.zeros((lk, k, k, p))
    ar = np.arange(k)
    out[:, ar, ar, :] = jac.reshape(lk, k, p)
    return out.reshape(lk, k, k * p)


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


# ----------------------------------------------------------------------------- main entry


def calibrate(
    trajectory: Trajectory,
    camera: Camera,
    mount: Mount,
    crs: Union[str, MappingFrame],
    observations: ImageObservations,
    planes: Sequence = (),
    lines: Sequence = (),
    lcps: Sequence = (),
    lidar_points: Array | None = None,
    lidar_plane_ids: NDArray[np.integer] | None = None,
    options: BoresightOptions | None = None,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
    ground_points: SurveyedPoints | None = None,
) -> BoresightResult:
    """Estimate the boresight per group (module docstring: model and control types).

    Parameters
    ----------
    trajectory : Trajectory
        INS/GNSS poses of the N images (positions in the mapping CRS or geodetic).
    camera : Camera
        Interior orientation (the initial values when ``estimate_interior``).
    mount : Mount
        Lever arm (metres, body frame), nominal mount and the *initial* boresight (radians).
    crs : str or MappingFrame
        Mapping CRS of the trajectory, planes, lines, LCPs and LiDAR points.
    observations : ImageObservations
        Image measurements (``core.io.observations``); rows of type ``check`` are ignored.
    planes : sequence of Plane
        Planes referenced by ``tie`` and ``paper`` rows (ids as text in ``target_id``).
    lines : sequence of ControlLine
        Lines referenced by ``line`` rows.
    lcps : sequence of ControlPoint
        LCPs referenced by ``lcp`` rows.
    lidar_points : ndarray, shape (M, 3), optional
        LiDAR points (mapping CRS) with their ``lidar_plane_ids`` (M,): needed by ``paper``
        rows (the height z of Eqs. 12-13).
    options : BoresightOptions, optional
    progress, should_stop : callables, optional
        Forwarded to the adjustment (per iteration).
    ground_points : SurveyedPoints, optional
        Surveyed points (mapping CRS, metres) referenced by the ``point_id`` of ``control``
        rows; rows of its ``check`` points are not adjusted.

    Returns
    -------
    BoresightResult

    Raises
    ------
    InputError
        Unknown images or targets, a control row naming no ground point (the row named),
        missing LiDAR points for paper mode, ...
    BoresightNotObservable
        With a diagnosis naming what would make the parameters observable.
    """
    camera.require_perspective("the boresight calibration")
    opts = options if options is not None else BoresightOptions()
    frame = crs if isinstance(crs, MappingFrame) else MappingFrame.from_user_input(crs)
    grade = _grade(opts.ins_grade)
    if not opts.roof_roughness_m > 0:
        raise InputError("roof_roughness_m must be > 0")
    n_img = len(trajectory)
    local = local_frame_for(trajectory, frame)
    llh = _trajectory_llh(trajectory, frame)
    ins_pos = local.geodetic_to_enu(llh)
    r_nl = local.ned_to_local(llh)
    labels = group_labels(trajectory, opts.groups)
    group_names = tuple(dict.fromkeys(labels))
    gidx = np.array([group_names.index(g) for g in labels])
    spec = PoseSpec(
        camera,
        mount.nominal,
        mount.lever_arm,
        opts.estimate_lever_arm,
        opts.estimate_interior,
    )

    # ---- parameters
    names: list[str] = []
    x0: list[float] = []
    for g in group_names:
        names += [f"bore[{g}].{a}" for a in ANGLES]
        x0 += list(mount.boresight)
    n_cal = len(names)
    lever_at = interior_at = -1
    if opts.estimate_lever_arm:
        lever_at = len(names)
        names += ["lever_arm.x", "lever_arm.y", "lever_arm.z"]
        x0 += list(mount.lever_arm)
    if opts.estimate_interior:
        interior_at = len(names)
        names += ["interior.f", "interior.x0", "interior.y0"]
        x0 += [camera.focal_mm, camera.x0_mm, camera.y0_mm]
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

    # ---- observations in use
    kinds = np.array(observations.type)
    used = np.isin(kinds, [t for t in opts.use_types if t != "check"])
    surveyed: list[_KnownPoint] = []
    if "control" in opts.use_types and (kinds == "control").any():
        surveyed, check = _surveyed_points(observations, ground_points)
        used &= ~check
    image_of = {iid: k for k, iid in enumerate(trajectory.image_id)}
    rows_all = np.arange(len(observations))
    img = np.full(len(observations), -1, dtype=np.intp)
    img[used] = _index(
        [observations.image_id[r] for r in rows_all[used]], image_of, "image", rows_all[used]
    )
    blocks: list[GaussMarkovBlock | GaussHelmertBlock] = []
    # (block name, obs rows (G, k), kind) for the residual table
    maps: list[tuple[str, Array, str]] = []

    # ---- INS priors
    scale = 1.0 if opts.ins_as_parameters else 1e-6
    enu_i = r_nl @ NED_TO_ENU.T  # ENU at each image -> the adjustment frame
    cov_pos = enu_i @ np.diag((scale * grade.sigma_position) ** 2) @ np.swapaxes(enu_i, 1, 2)
    blocks.append(
        GaussMarkovBlock(
            "ins position",
            ins_pos,
            0.5 * (cov_pos + np.swapaxes(cov_pos, 1, 2)),
            ins_at + 6 * np.arange(n_img)[:, None] + np.arange(3),
            _Identity(),
            labels=[f"ins[{i}] position" for i in trajectory.image_id],
            row_names=("E", "N", "U"),
        )
    )
    att_idx = (ins_at + 6 * np.arange(n_img)[:, None] + np.arange(3, 6)).ravel()
    blocks.append(
        prior_block(
            "ins attitude",
            att_idx,
            trajectory.rph.ravel(),
            np.tile(scale * grade.sigma_attitude, n_img),
        )
    )

    x_init = np.array(x0)

    def init_pose(rows: Array) -> Array:
        return x_init[pose_idx[img[rows]]]

    plane_by_id = {str(p.id): k for k, p in enumerate(planes)}
    p_params, p_cov, _ = transform_planes(list(planes), local)

    # ---- 1. plane-constrained tie points
    tie_rows = rows_all[used & (kinds == "tie")]
    if tie_rows.size:
        pid = [observations.point_id[r] for r in tie_rows]
        tie_names = list(dict.fromkeys(pid))
        tie_of = {t: k for k, t in enumerate(tie_names)}
        tk = np.array([tie_of[t] for t in pid])
        plane_of_tie = np.full(len(tie_names), -1)
        for r, k in zip(tie_rows, tk):
            pl = _index([observations.target_id[r]], plane_by_id, "plane", np.array([r]))[0]
            if plane_of_tie[k] not in (-1, pl):
                raise InputError(f"observation {r + 2}: tie point '{tie_names[k]}' on two planes")
            plane_of_tie[k] = pl
        # initial coordinates: the first ray of each tie point cut with its plane
        first = np.unique(tk, return_index=True)[1]
        fr = tie_rows[first]
        centre, ray, *_ = camera_ray(init_pose(fr), observations.pixels[fr], r_nl[img[fr]], spec)
        pl = p_params[plane_of_tie]
        t = -(np.einsum("ti,ti->t", pl[:, :3], centre) + pl[:, 3]) / np.einsum(
            "ti,ti->t", pl[:, :3], ray
        )
        tie_at = len(names)
        for name in tie_names:
            names += [f"tie[{name}].{a}" for a in "XYZ"]
        x_init = np.concatenate([x_init, (centre + t[:, None] * ray).ravel()])
        tie_idx = tie_at + 3 * np.arange(len(tie_names))[:, None] + np.arange(3)
        blocks.append(
            _collinearity_block(
                "tie image points", tie_rows, tk, tie_idx, observations, img, pose_idx, r_nl, spec
            )
        )
        maps.append(("tie image points", tie_rows[:, None], "gm"))
        counts = np.bincount(plane_of_tie, minlength=len(planes))
        for k in np.unique(counts[counts > 0]):
            sel = np.flatnonzero(counts == k)
            members = np.array([np.flatnonzero(plane_of_tie == p) for p in sel]).reshape(-1, k)
            blocks.append(
                _tie_plane_block(
                    f"tie planes k={k}",
                    k,
                    sel,
                    members,
                    tie_idx,
                    p_params,
                    p_cov,
                    opts.roof_roughness_m,
                    [str(planes[p].id) for p in sel],
                )
            )

    # ---- 2. points on LiDAR lines
    line_rows = rows_all[used & (kinds == "line")]
    if line_rows.size:
        line_by_id = {str(ln.id): k for k, ln in enumerate(lines)}
        lk = _index([observations.target_id[r] for r in line_rows], line_by_id, "line", line_rows)
        lx0, lu, lcov = transform_lines(list(lines), local)
        counts = np.bincount(lk, minlength=len(lines))
        for k in np.unique(counts[counts > 0]):
            sel = np.flatnonzero(counts == k)
            members = np.array([line_rows[lk == s] for s in sel]).reshape(-1, k)
            name = f"line points k={k}"
            blocks.append(
                _line_block(
                    name,
                    k,
                    sel,
                    members,
                    lx0,
                    lu,
                    lcov,
                    observations,
                    img,
                    pose_idx,
                    r_nl,
                    spec,
                    [str(lines[s].id) for s in sel],
                )
            )
            maps.append((name, members, "line"))

    # ---- 3. LCPs and surveyed ground points: the point an unknown with its prior
    for kind, what, keys, known in (
        ("lcp", "LCP", observations.target_id, lcps),
        ("control", "ground point", observations.point_id, surveyed),
    ):
        k_rows = rows_all[used & (kinds == kind)]
        if not k_rows.size:
            continue
        by_id = {str(p.id): k for k, p in enumerate(known)}
        ck = _index([keys[r] for r in k_rows], by_id, what, k_rows)
        used_pts = np.unique(ck)
        remap = {c: k for k, c in enumerate(used_pts)}
        cxyz, ccov = transform_lcps([known[c] for c in used_pts], local)
        pts_at = len(names)
        for c in used_pts:
            names += [f"{kind}[{known[c].id}].{a}" for a in "XYZ"]
        x_init = np.concatenate([x_init, cxyz.ravel()])
        pts_idx = pts_at + 3 * np.arange(len(used_pts))[:, None] + np.arange(3)
        blocks.append(
            _collinearity_block(
                f"{kind} image points",
                k_rows,
                np.array([remap[c] for c in ck]),
                pts_idx,
                observations,
                img,
                pose_idx,
                r_nl,
                spec,
            )
        )
        maps.append((f"{kind} image points", k_rows[:, None], "gm"))
        blocks.append(
            GaussMarkovBlock(
                f"{kind} coordinates",
                cxyz,
                ccov,
                pts_idx,
                _Identity(),
                labels=[f"{kind} {known[c].id}" for c in used_pts],
                row_names=("X", "Y", "Z"),
            )
        )

    # ---- 4. the single-image model of Pedrosa & dos Santos (2020)
    paper_rows = rows_all[used & (kinds == "paper")]
    if paper_rows.size:
        blocks.append(
            _paper_block(
                paper_rows, observations, img, pose_idx, r_nl, spec, planes, plane_by_id,
                p_params, p_cov, local, lidar_points, lidar_plane_ids, opts, x_init,
            )
        )
        maps.append(("paper planes", paper_rows[:, None], "paper"))

    if len(blocks) == 2:
        raise InputError("no image observations of the types in use: nothing to calibrate")

    aopts = AdjustmentOptions(
        snooping=opts.snooping,
        snooping_alpha=opts.snooping_alpha,
        max_iterations=opts.max_iterations,
    )
    try:
        res = adjust(
            x_init, names, blocks, options=aopts, progress=progress, should_stop=should_stop
        )
    except NotObservableError as exc:
        raise BoresightNotObservable(exc, diagnose(exc.parameters, group_names)) from exc

    # ---- results
    x = res.x
    bore = x[: 3 * len(group_names)].reshape(-1, 3)
    std = res.std[: 3 * len(group_names)].reshape(-1, 3)
    std_p = res.std_prior[: 3 * len(group_names)].reshape(-1, 3)
    lever = lever_std = interior = interior_std = None
    if opts.estimate_lever_arm:
        lever, lever_std = x[lever_at : lever_at + 3], res.std[lever_at : lever_at + 3]
    if opts.estimate_interior:
        interior = x[interior_at : interior_at + 3]
        interior_std = res.std[interior_at : interior_at + 3]
    corr = (
        res.correlation[:n_cal, :n_cal]
        if res.correlation is not None
        else np.full((n_cal, n_cal), np.nan)
    )
    xp = x[pose_idx]
    centre, r_cl, _, _ = pose_chain(xp, r_nl, spec)
    xyz_map, opk_map = eo_local_to_map(centre, np.swapaxes(r_cl, 1, 2), local)
    eo = ExteriorOrientationTable(
        trajectory.image_id,
        trajectory.time,
        trajectory.group,
        xyz_map,
        opk_map,
        frame.crs.to_wkt(),
    )
    return BoresightResult(
        groups=group_names,
        boresight=bore,
        std=std,
        std_prior=std_p,
        lever_arm=lever,
        lever_arm_std=lever_std,
        interior=interior,
        interior_std=interior_std,
        parameter_names=names[:n_cal],
        correlation=corr,
        sigma0=res.sigma0,
        redundancy=res.redundancy,
        chi2_passed=res.global_test.passed,
        residuals=_observation_residuals(res, maps, len(observations), used),
        eo=eo,
        adjustment=res,
        local=local,
        warnings=list(res.warnings),
    )


# ----------------------------------------------------------------------------- blocks


def _collinearity_block(
    name, rows, point_k, point_idx, obs, img, pose_idx, r_nl, spec
) -> GaussMarkovBlock:
    """Collinearity of measurements of unknown points (tie points, LCPs)."""
    p = spec.size
    rn = r_nl[img[rows]]

    def model(x_local: Array) -> tuple[Array, Array]:
        px, j_pose, j_point = collinearity(x_local[:, :p], x_local[:, p:], rn, spec)
        return px, np.concatenate([j_pose, j_point], axis=2)

    return GaussMarkovBlock(
        name,
        obs.pixels[rows],
        np.repeat(obs.sigma_px[rows][:, None], 2, axis=1),
        np.hstack([pose_idx[img[rows]], point_idx[point_k]]),
        model,
        labels=[f"{obs.image_id[r]} / {obs.point_id[r]}" for r in rows],
        row_names=("col", "row"),
    )


def _tie_plane_block(name, k, sel, members, tie_idx, p_params, p_cov, rough, plane_names):
    """Gauss-Helmert: the k tie points of a plane lie on it, n . X_j + d - e_j = 0."""
    lk = len(sel)
    obs = np.hstack([p_params[sel], np.zeros((lk, k))])
    cov = np.zeros((lk, 4 + k, 4 + k))
    cov[:, :4, :4] = _regular(p_cov[sel])
    cov[:, np.arange(4, 4 + k), np.arange(4, 4 + k)] = rough**2
    ar = np.arange(k)

    def condition(x_local: Array, l_hat: Array) -> tuple[Array, Array, Array]:
        xyz = x_local.reshape(-1, k, 3)
        n, d = l_hat[:, :3], l_hat[:, 3]
        g = np.einsum("gkj,gj->gk", xyz, n) + d[:, None] - l_hat[:, 4:]
        a = _block_diag(np.repeat(n, k, axis=0), k)
        b = np.zeros((xyz.shape[0], k, 4 + k))
        b[:, :, :3] = xyz
        b[:, :, 3] = 1.0
        b[:, ar, 4 + ar] = -1.0
        return g, a, b

    return GaussHelmertBlock(
        name,
        obs,
        cov,
        tie_idx[members].reshape(lk, 3 * k),
        condition,
        labels=[f"plane {p}" for p in plane_names],
        row_names=("a", "b", "c", "d", *[f"e{j}" for j in range(k)]),
    )


def _line_block(name, k, sel, members, lx0, lu, lcov, obs, img, pose_idx, r_nl, spec, line_names):
    """Gauss-Helmert: every measured ray of a line is coplanar with it."""
    lk = len(sel)
    p = spec.size
    flat = members.ravel()
    o = 2 * k + 6
    observed = np.hstack([obs.pixels[flat].reshape(lk, 2 * k), lx0[sel], lu[sel]])
    cov = np.zeros((lk, o, o))
    s2 = np.repeat(obs.sigma_px[members] ** 2, 2, axis=1)
    cov[:, np.arange(2 * k), np.arange(2 * k)] = s2
    cov[:, 2 * k :, 2 * k :] = _regular(lcov[sel])
    rn = r_nl[img[flat]]
    ar = np.arange(k)

    def condition(x_local: Array, l_hat: Array) -> tuple[Array, Array, Array]:
        xp = x_local.reshape(-1, p)
        px = l_hat[:, : 2 * k].reshape(-1, 2)
        x0 = np.repeat(l_hat[:, 2 * k : 2 * k + 3], k, axis=0)
        u = np.repeat(l_hat[:, 2 * k + 3 :], k, axis=0)
        g, j_pose, j_px, j_pt, j_dir = coplanarity(xp, px, x0, u, rn, spec)
        n = l_hat.shape[0]
        b = np.zeros((n, k, o))
        jp = j_px.reshape(n, k, 2)
        b[:, ar, 2 * ar] = jp[:, :, 0]
        b[:, ar, 2 * ar + 1] = jp[:, :, 1]
        b[:, :, 2 * k : 2 * k + 3] = j_pt.reshape(n, k, 3)
        b[:, :, 2 * k + 3 :] = j_dir.reshape(n, k, 3)
        return g.reshape(n, k), _block_diag(j_pose, k), b

    return GaussHelmertBlock(
        name,
        observed,
        cov,
        pose_idx[img[flat]].reshape(lk, k * p),
        condition,
        labels=[f"line {s}" for s in line_names],
        row_names=(
            *[f"{c}{j}" for j in range(k) for c in ("col", "row")],
            "x0",
            "y0",
            "z0",
            "ux",
            "uy",
            "uz",
        ),
    )


def _paper_block(
    rows,
    obs,
    img,
    pose_idx,
    r_nl,
    spec,
    planes,
    plane_by_id,
    p_params,
    p_cov,
    local,
    lidar_points,
    lidar_plane_ids,
    opts,
    x_init,
) -> GaussMarkovBlock:
    """Eq. 15 of Pedrosa & dos Santos (2020) with d observed; z from the LiDAR points near the
    picked point."""
    if lidar_points is None or lidar_plane_ids is None:
        raise InputError("paper-mode observations need the LiDAR points and their plane ids")
    pk = _index([obs.target_id[r] for r in rows], plane_by_id, "plane", rows)
    xp0 = x_init[pose_idx[img[rows]]]
    rn = r_nl[img[rows]]
    centre, ray, *_ = camera_ray(xp0, obs.pixels[rows], rn, spec)
    pl = p_params[pk]
    t = -(np.einsum("ti,ti->t", pl[:, :3], centre) + pl[:, 3]) / np.einsum(
        "ti,ti->t", pl[:, :3], ray
    )
    picked = centre + t[:, None] * ray
    ids = np.asarray(lidar_plane_ids)
    z = np.empty(rows.size)
    kn = max(1, int(opts.paper_z_neighbours))
    for p in np.unique(pk):
        on = np.flatnonzero(ids == planes[p].id)
        if on.size == 0:
            raise InputError(f"paper mode: no LiDAR points carry plane id {planes[p].id}")
        pts = local.map_to_enu(np.asarray(lidar_points, dtype=np.float64)[on])
        sel = np.flatnonzero(pk == p)
        _, nn = cKDTree(pts[:, :2]).query(picked[sel, :2], k=min(kn, on.size))
        nn = np.asarray(nn).reshape(sel.size, -1)
        z[sel] = pts[nn, 2].mean(axis=1)
    if opts.paper_sigma == "eq17":
        # Eq. 17 as printed, with the centroid in the mapping CRS (as the paper computed it)
        cent = np.array([planes[p].centroid for p in pk])
        npts = np.array([max(planes[p].n_points, 1) for p in pk], dtype=np.float64)
        sigma = np.linalg.norm(cent, axis=1) + opts.lidar_sigma_m**2 / npts
    elif opts.paper_sigma == "propagated":
        xh = np.hstack([picked, np.ones((rows.size, 1))])
        sigma = np.sqrt(np.einsum("ti,tij,tj->t", xh, p_cov[pk], xh))
    else:
        raise InputError(f"paper_sigma '{opts.paper_sigma}' is unknown: eq17 or propagated")
    normal = pl[:, :3]
    px = obs.pixels[rows]

    def model(x_local: Array) -> tuple[Array, Array]:
        d, j = paper_plane(x_local, px, normal, z, rn, spec)
        return d[:, None], j

    return GaussMarkovBlock(
        "paper planes",
        pl[:, 3:4],
        sigma[:, None],
        pose_idx[img[rows]],
        model,
        labels=[f"{obs.image_id[r]} / {obs.point_id[r]}" for r in rows],
        row_names=("d",),
    )


def _observation_residuals(res: AdjustmentResult, maps, n: int, used) -> ObservationResiduals:
    v_px = np.full((n, 2), np.nan)
    v_d = np.full(n, np.nan)
    w = np.full(n, np.nan)
    rejected = np.zeros(n, dtype=bool)
    for name, rows, kind in maps:
        table = res.residuals[name]
        g, k = rows.shape
        aw = np.abs(table.w)
        if kind == "paper":
            v_d[rows[:, 0]] = table.v[:, 0]
            w[rows[:, 0]] = aw[:, 0]
        else:
            v_px[rows.ravel()] = table.v[:, : 2 * k].reshape(-1, 2)
            ww = aw[:, : 2 * k].reshape(g, k, 2)
            with np.errstate(all="ignore"):
                w[rows.ravel()] = np.where(
                    np.isnan(ww).all(axis=2), np.nan, np.nanmax(np.nan_to_num(ww, nan=-1), axis=2)
                ).ravel()
        rejected[rows.ravel()] = np.repeat(table.rejected, k)
    return ObservationResiduals(v_px, v_d, w, rejected, np.asarray(used, dtype=bool))


# ----------------------------------------------------------------------------- diagnosis


def diagnose(parameters: Sequence[str], groups: Sequence[str] = ()) -> list[str]:
    """Explain in words why the named parameters are not observable and what would fix it.

    Each sentence is a :class:`core.i18n.Message` (English text; the report translates it).

    >>> diagnose(["bore[NE].d_kappa"])[0].startswith("kappa of group 'NE'")
    True
    """
    out: list[str] = []
    bore: dict[str, set[str]] = {}
    kinds: set[str] = set()
    for name in parameters:
        if name.startswith("bore["):
            g, angle = name[5:].split("].", 1)
            bore.setdefault(g, set()).add(angle)
        else:
            kinds.add(name.split("[", 1)[0].split(".", 1)[0])
    for g, angles in bore.items():
        if angles == set(ANGLES):
            out.append(
                _t(
                    "the boresight of group '{group}' is not determined at all: its images have "
                    "no (or too few) measurements; measure control in them, or use one boresight "
                    "for all images (groups = single).",
                    group=g,
                )
            )
        elif angles == {"d_kappa"}:
            out.append(
                _t(
                    "kappa of group '{group}' is not observable: too few points, or all of them "
                    "near the image centre; measure points spread over the whole image (towards "
                    "the corners) on roofs facing different directions, or add LCPs or ridge "
                    "lines.",
                    group=g,
                )
            )
        else:
            out.append(
                _t(
                    "{angles} of group '{group}' cannot be separated: the points lie near the "
                    "image centre or on planes of one orientation; spread points over the image "
                    "on roofs of different slope and aspect, or add LCPs or lines.",
                    angles=", ".join(sorted(angles)),
                    group=g,
                )
            )
    if "lever_arm" in kinds:
        out.append(
            _t(
                "the lever arm cannot be separated from the INS position: it turns with the "
                "aircraft while a position error does not, so fly lines in opposite directions "
                "(horizontal components) and add height control (LCPs); its vertical component "
                "cannot be told from a vertical GNSS bias at all: measure it (total station) and "
                "keep it fixed."
            )
        )
    if "interior" in kinds:
        out.append(
            _t(
                "the interior orientation is not separable: the focal length trades with the "
                "flying height (needs control at clearly different heights or two flying "
                "heights), the principal point with the boresight omega/phi (both shift the "
                "whole image); fix them from the lab calibration."
            )
        )
    if "tie" in kinds:
        out.append(
            _t(
                "some tie points are not determined: measure each in at least two images, on a "
                "plane that is not seen edge-on."
            )
        )
    if "lcp" in kinds:
        out.append(_t("some LCP coordinates are not determined: give each a covariance."))
    if "control" in kinds:
        out.append(_t("some ground point coordinates are not determined: give each sx, sy, sz."))
    if "ins" in kinds and not out:
        out.append(_t("INS parameters are not determined: the INS grade sigmas must be > 0."))
    if not out:
        out.append(
            _t(
                "parameters not observable: {names}",
                names=", ".join(list(parameters)[:10]),
            )
        )
    return out


@dataclass
class BoresightRun:
    """What :func:`run_boresight_calibration` computed.

    Attributes
    ----------
    result : BoresightResult
    observations : ImageObservations
        The N observation rows, in file order.
    ground : ndarray, shape (N, 3)
        Ground position of each row in the mapping CRS (NaN where none can be computed).
    image_group : tuple of str, shape (N,)
        Boresight group of the image of each row ("" for unknown images).
    settings : dict of str to str
        The run's settings as text (also in the HTML).
    crs_wkt : str
        Mapping CRS (WKT).
    """

    result: BoresightResult
    observations: ImageObservations
    ground: Array
    image_group: tuple[str, ...]
    settings: dict[str, str] = field(default_factory=dict)
    crs_wkt: str = ""

    def residual_rows(self) -> list[tuple[object, ...]]:
        """Rows of the residual table (``RESIDUAL_COLUMNS``)."""
        r = self.result.residuals
        obs = self.observations
        v = np.hypot(r.v_px[:, 0], r.v_px[:, 1])
        return [
            (
                obs.image_id[k],
                obs.point_id[k],
                obs.type[k],
                obs.target_id[k],
                self.image_group[k],
                *self.ground[k],
                *obs.pixels[k],
                *r.v_px[k],
                v[k],
                r.v_d[k],
                r.w[k],
                int(r.rejected[k]),
                int(r.used[k]),
            )
            for k in range(len(obs))
        ]
