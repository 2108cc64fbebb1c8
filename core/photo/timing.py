"""The camera timing offset shared by the boresight calibration and the bundle adjustment:
the velocity of each exposure (given, or differenced from neighbouring exposures of a flight
line), its conversion into the adjustment frame, and how far the offset is separable from a
lever arm.

Sign convention (as ``importtrajectory``'s TIME_OFFSET): exposure time = recorded time + dt;
the position recorded for an exposure is then ``X(t_rec) ~ X(t_exp) - v dt``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError, NotObservableError

Array = NDArray[np.float64]

#: Frames of :class:`ExposureVelocities`: ``ned`` local level at each image (true north,
#: east, down), ``map`` the mapping CRS's axes (d easting / dt, d northing / dt, d height / dt).
VELOCITY_FRAMES = ("ned", "map")

#: Smallest share of the body-frame (or camera-frame) velocity that a lever arm cannot mimic
#: (:func:`timing_separability`) with which the timing offset and the lever arm are
#: estimated together: below it dt's sigma would be more than 20 times the one with the lever
#: arm known (speeds differing by less than about 10 %, or one line).
TIMING_SEPARABILITY_MIN = 0.05


@dataclass(frozen=True)
class ExposureVelocities:
    """The velocity of every exposure (M, 3), m/s, in ``frame`` (:data:`VELOCITY_FRAMES`)."""

    values: Array
    frame: str = "ned"

    def __post_init__(self) -> None:
        if self.frame not in VELOCITY_FRAMES:
            raise InputError(f"velocity frame '{self.frame}' is not one of ned, map")
        object.__setattr__(self, "values", np.asarray(self.values, dtype=np.float64))


def local_velocity(vel: ExposureVelocities, xyz_map: Array, local) -> Array:
    """(M, 3) velocities in the ENU adjustment frame of ``local`` (a LocalFrame or an
    EngineeringLocal) at the exposures ``xyz_map`` (mapping CRS): a ``ned`` velocity is
    rotated rigorously (``R_n^l`` at each image), a ``map`` one goes through the Jacobian of
    the map -> ENU transformation (the grid's scale included)."""
    v = vel.values
    if vel.frame == "map":
        jac = local.map_to_enu_jacobian(xyz_map)[1]
        return np.einsum("nij,nj->ni", jac, v)
    if not hasattr(local, "ned_to_local"):
        raise InputError(
            "velocities v_north, v_east, v_up need a mapping CRS; in a local "
            "engineering frame give vx, vy, vz along its axes"
        )
    llh = local.mapping.map_to_geodetic(xyz_map)
    return np.einsum("nij,nj->ni", local.ned_to_local(llh), v)


def difference_velocity(
    time: Array, group: Sequence[str], position: Array, what: str = "estimate_timing"
) -> Array:
    """(N, 3) velocity of each exposure by finite differences of the neighbouring exposures'
    ``position`` (N, 3; any Cartesian frame, m) within each flight line (``group``; empty = one
    line), in time order: central inside, one-sided at the ends. Over the few seconds between
    exposures a straight line is flown at near constant speed, so the difference is the
    velocity to well below what dt resolves, but the positions' noise enters it. A line with
    fewer than two distinct times is refused, naming it (``what`` names the caller)."""
    t = np.asarray(time, dtype=np.float64)
    vel = np.zeros_like(np.asarray(position, dtype=np.float64))
    lines = np.array([g if g else "" for g in group])
    for g in dict.fromkeys(lines.tolist()):
        sel = np.flatnonzero(lines == g)
        sel = sel[np.argsort(t[sel], kind="stable")]
        if sel.size < 2 or not np.isfinite(t[sel]).all() or np.any(np.diff(t[sel]) <= 0):
            raise InputError(
                f"{what}: flight line '{g}' needs >= 2 images with distinct times (the "
                "velocity is differenced from neighbouring exposures; or give the velocities: "
                "v_north, v_east, v_up)"
            )
        vel[sel] = np.gradient(position[sel], t[sel], axis=0)
    return vel


def timing_separability(velocity: Array, r_bl: Array) -> tuple[float, Array]:
    """How far the timing offset dt is separable from the lever arm, from the geometry alone.

    dt shifts every camera centre by ``v_i dt`` (adjustment frame); a lever arm ``a`` by
    ``R_b^l(i) a`` (``r_bl``: body, or camera, axes -> the adjustment frame). The lever arm
    best mimicking dt is ``a = u dt`` with ``u`` the mean of the body-frame velocities
    ``b_i = R_b^l(i)' v_i`` (the rotations are orthonormal), and what it leaves is ``b_i - u``.
    Returns the share ``rms|b - u| / rms|b|`` (0: dt and the lever arm are one unknown; dt's
    variance grows by about 1 / share^2 when the lever arm is estimated) and ``u`` (3,), m/s
    in the body frame.

    >>> r = np.broadcast_to(np.eye(3), (4, 3, 3))
    >>> round(timing_separability(np.array([[60.0, 0, 0]] * 2 + [[30.0, 0, 0]] * 2), r)[0], 3)
    0.316
    """
    b = np.einsum("nji,nj->ni", r_bl, velocity)
    u = b.mean(axis=0)
    rms_b = float(np.sqrt(np.mean(np.sum(b * b, axis=1))))
    share = float(np.sqrt(np.mean(np.sum((b - u) ** 2, axis=1)))) / rms_b if rms_b > 0 else 0.0
    return share, u


def timing_trade(
    share: float, body_velocity: Array, dt_name: str, lever_names: Sequence[str], axes: str
) -> NotObservableError | None:
    """The error of a timing offset estimated with a lever arm when the body-frame velocity
    is (nearly) one (``share`` below :data:`TIMING_SEPARABILITY_MIN`), naming dt
    (``dt_name``) and the lever-arm component along the velocity (``lever_names``, x y z of
    ``axes``, e.g. "body"); None when they separate."""
    if share >= TIMING_SEPARABILITY_MIN:
        return None
    k = int(np.argmax(np.abs(body_velocity)))
    return NotObservableError(
        f"Not observable: {dt_name} and {lever_names[k]} cannot be separated (the {axes}-frame "
        f"velocity varies by {share:.1%} of the speed at the images, less than the "
        f"{TIMING_SEPARABILITY_MIN:.0%} needed: dt times the speed is a lever arm along "
        f"{axes} {'xyz'[k]}; fly lines at clearly different speeds, keep the lever arm fixed "
        "or do not estimate the timing)",
        parameters=[dt_name, lever_names[k]],
        condition_number=math.inf if share == 0 else 1.0 / share**2,
    )
