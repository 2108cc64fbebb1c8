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

Timing offset (``BoresightOptions.estimate_timing``): a constant dt (s) between the recorded
exposure time and the true one, one more calibration unknown entering the INS position priors
(:class:`.boresight_blocks._TimedPosition`). It is separable from the lever arm only when the
along-track velocity varies in the body frame (lines at different speeds): a single line, or
lines flown at one speed (either direction), leave ``dt * speed`` = along-track lever arm. The
set-up is refused before the adjustment when the lever arm is estimated with dt and the
body-frame velocity varies by less than :data:`.timing.TIMING_SEPARABILITY_MIN` of
the speed (:func:`.timing.timing_separability`): attitude noise makes that trade-off
only nearly singular, below what the observability check's condition limit catches. The
velocity is the trajectory's own (``Trajectory.velocity_ned``) when it has one, else
differenced from neighbouring exposures.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Callable, Union

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError, NotObservableError
from ..geometry.camera import Camera
from ..geometry.frames import MappingFrame
from ..geometry.rotations import rph_to_matrix
from ..lsq.adjustment import adjust
from ..lsq.model import AdjustmentOptions
from .boresight_blocks import (
    _ins_blocks,
    _line_blocks,
    _paper_blocks,
    _point_blocks,
    _Stage,
    _tie_blocks,
)
from .boresight_models import (
    PoseSpec,
)
from .boresight_result import (
    BoresightNotObservable,
    BoresightResult,
    _result,
    diagnose,
    require_timing_separable,
)
from .boresight_setup import (
    BoresightOptions,
    SurveyedPoints,
    _grade,
    _index,
    _KnownPoint,
    _parameters,
    _surveyed_points,
    _trajectory_llh,
    exposure_velocity,
    group_labels,
    local_frame_for,
    timing_separability,
    transform_planes,
)
from .georeference import Trajectory
from .mount import Mount
from .observations import ImageObservations

__all__ = [
    "calibrate",
]

Array = NDArray[np.float64]


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
    opts = options if options is not None else BoresightOptions()
    frame = crs if isinstance(crs, MappingFrame) else MappingFrame.from_user_input(crs)
    grade = _grade(opts.ins_grade)
    if not opts.roof_roughness_m > 0:
        raise InputError("roof_roughness_m must be > 0")
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
    par = _parameters(trajectory, camera, mount, opts, group_names, gidx, ins_pos, spec)

    # ---- observations in use
    kinds, used, img, surveyed = _rows_in_use(observations, trajectory, opts, ground_points)
    st = _Stage(
        observations,
        kinds,
        used,
        img,
        par.pose_idx,
        r_nl,
        spec,
        local,
        list(par.names),
        np.array(par.x0),
    )
    velocity = _velocity(trajectory, ins_pos, r_nl, opts)
    st.blocks += _ins_blocks(
        trajectory, grade, opts, r_nl, ins_pos, par.ins_at, par.timing_at, velocity
    )
    plane_by_id = {str(p.id): k for k, p in enumerate(planes)}
    p_params, p_cov, _ = transform_planes(list(planes), local)
    _tie_blocks(st, planes, plane_by_id, p_params, p_cov, opts.roof_roughness_m)
    _line_blocks(st, lines, opts.line_segment_sigmas_px)
    _point_blocks(st, lcps, surveyed)

    # ---- 4. the single-image model of Pedrosa & dos Santos (2020)
    cloud = (lidar_points, lidar_plane_ids)
    _paper_blocks(st, planes, plane_by_id, p_params, p_cov, cloud, opts)

    if len(st.blocks) == 2:
        raise InputError("no image observations of the types in use: nothing to calibrate")

    aopts = AdjustmentOptions(
        snooping=opts.snooping,
        snooping_alpha=opts.snooping_alpha,
        snooping_per_group=opts.snooping_per_group,
        max_iterations=opts.max_iterations,
    )
    try:
        res = adjust(
            st.x_init,
            st.names,
            st.blocks,
            options=aopts,
            progress=progress,
            should_stop=should_stop,
        )
    except NotObservableError as exc:
        raise BoresightNotObservable(exc, diagnose(exc.parameters, group_names)) from exc
    return _result(res, trajectory, frame, local, group_names, par, st, opts)


def _rows_in_use(
    observations: ImageObservations,
    trajectory: Trajectory,
    opts: BoresightOptions,
    ground_points: SurveyedPoints | None,
):
    """The observations in use: (types, used mask, image index per row (-1 where unused),
    the surveyed points of ``control`` rows); the rows of check points are not used."""
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
    return kinds, used, img, surveyed


def _velocity(
    trajectory: Trajectory, ins_pos: Array, r_nl: Array, opts: BoresightOptions
) -> Array | None:
    """The exposures' velocities (local frame, m/s) for the timing offset, None without it;
    with the lever arm estimated too, refused where the two cannot be separated."""
    velocity = None
    if opts.estimate_timing:
        velocity = exposure_velocity(trajectory, ins_pos, r_nl)
        if opts.estimate_lever_arm:
            r_bl = r_nl @ rph_to_matrix(*trajectory.rph.T)
            require_timing_separable(*timing_separability(velocity, r_bl))
    return velocity
