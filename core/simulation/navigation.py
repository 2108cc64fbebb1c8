"""A simulated INS/GNSS flight with analytic truth: position, velocity and attitude are closed
formulas of time, so a trajectory sampled at any rate can be checked at any time between its
records (tests/core/test_trajectory_import.py, bench/trajectory_import.py).

The path is a curve in the east-north-up frame tangent at the origin, 60 m/s with a slow turn
and small wiggles; the attitude has a heading through north (350 -> 10 degrees and on), a
+-20 degree roll manoeuvre and a pitch oscillation; the wander angle drifts.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..geometry.frames import MappingFrame, enu_rotation, ned_to_ecef_rotation

Array = NDArray[np.float64]

_R, _W = 1500.0, 0.04  # turn radius m, turn rate rad/s: 60 m/s


@dataclass(frozen=True)
class SimulatedFlight:
    """The flight's frame (mapping CRS), origin (lat, lon deg, h m) and start time (GPS s)."""

    frame: MappingFrame
    origin: tuple[float, float, float] = (-22.9, -47.06, 900.0)
    t0: float = 345600.0

    def _enu(self, t: Array) -> tuple[Array, Array]:
        s = np.asarray(t, dtype=np.float64) - self.t0
        e = _R * np.sin(_W * s) + 5.0 * np.sin(0.7 * s)
        n = _R * (1.0 - np.cos(_W * s)) + 3.0 * np.sin(0.5 * s)
        u = 2.0 * np.sin(0.5 * s)
        de = _R * _W * np.cos(_W * s) + 3.5 * np.cos(0.7 * s)
        dn = _R * _W * np.sin(_W * s) + 1.5 * np.cos(0.5 * s)
        du = np.cos(0.5 * s)
        return np.stack([e, n, u], axis=1), np.stack([de, dn, du], axis=1)

    def position(self, t: Array) -> tuple[Array, Array]:
        """ECEF positions (N, 3) m and velocities (N, 3) m/s at times ``t`` (s)."""
        lat0, lon0, _ = self.origin
        r = enu_rotation(lat0, lon0)  # rows e, n, u in ECEF
        origin = self.frame.geodetic_to_ecef(np.array([self.origin]))[0]
        enu, denu = self._enu(t)
        return origin + enu @ r, denu @ r

    def attitude(self, t: Array) -> Array:
        """Roll, pitch, true heading (N, 3) radians; heading in [0, 2 pi)."""
        s = np.asarray(t, dtype=np.float64) - self.t0
        roll = np.radians(20.0) * np.sin(2.0 * np.pi * s / 15.0)
        pitch = np.radians(2.0 + np.sin(0.4 * s))
        heading = np.radians(350.0 + 2.0 * s + 3.0 * np.sin(0.3 * s))
        return np.stack([roll, pitch, np.mod(heading, 2 * np.pi)], axis=1)

    def wander(self, t: Array) -> Array:
        """The wander angle of the solution (radians): a slow swing through zero."""
        return -0.2 + 0.5 * np.sin(0.02 * (np.asarray(t, dtype=np.float64) - self.t0))

    def records(self, t: Array) -> dict[str, Array]:
        """What a navigation file holds at ``t``: llh (deg, m), NED velocity, rph."""
        xyz, v = self.position(t)
        llh = self.frame.ecef_to_geodetic(xyz)
        r_n_e = ned_to_ecef_rotation(llh[:, 0], llh[:, 1])
        v_ned = np.einsum("kji,kj->ki", r_n_e, v)
        return {
            "time": np.asarray(t, dtype=np.float64),
            "llh": llh,
            "v_ned": v_ned,
            "rph": self.attitude(t),
            "wander": self.wander(t),
        }
