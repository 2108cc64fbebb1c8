"""Direct georeferencing: INS/GNSS trajectory + camera mount -> exterior orientation per image.

Model (docs/conventions.md)::

    X_pc = X_ins + R_b^e a_b                 (lever arm a_b in the body frame, metres)
    R_c^e = R_n^e(INS) R_b^n R_c^b           (R_b^n = Rz(heading) Ry(pitch) Rx(roll))
    R_c^b = R_nominal dR(dw, dp, dk)         (nominal mount times the boresight misalignment)

Everything is composed in the geocentric frame e of the mapping CRS's datum, so the
navigation frame of each image (NED at its own position), Earth curvature and the grid
convergence of the map projection are all rigorous. The results are reported in the mapping
frame: omega-phi-kappa of ``M = (R_c^m)^T`` with ``R_c^m = R_e^m(X_pc) R_c^e``, m being the
grid frame (grid east, grid north, up) at the perspective centre.

The trajectory table's format: :mod:`core.io.trajectory`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..geometry.frames import MappingFrame, ned_to_ecef_rotation
from ..geometry.rotations import matrix_to_opk, rph_to_matrix
from .mount import Mount
from .orientation import ExteriorOrientationTable

__all__ = ["GeoreferencedPoses", "Trajectory", "direct_georeference", "georeference_ecef"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Trajectory:
    """INS/GNSS solution at the exposure times of N images.

    position: (N, 3) easting, northing, height in the mapping CRS when ``geodetic`` is False;
    latitude, longitude (degrees) and ellipsoidal height otherwise.
    rph: (N, 3) roll, pitch, heading in radians.
    velocity_ned: (N, 3) north, east, down velocity at each exposure, m/s (local level at the
    image, true north), or None when the table has none.
    """

    image_id: tuple[str, ...]
    time: Array
    group: tuple[str, ...]
    position: Array
    geodetic: bool
    rph: Array
    velocity_ned: Array | None = None

    def __len__(self) -> int:
        return len(self.image_id)


@dataclass(frozen=True)
class GeoreferencedPoses:
    """Camera poses in the geocentric frame: centres (N, 3) metres and ``R_c^e`` (N, 3, 3)."""

    centre_ecef: Array
    camera_to_ecef: Array


def georeference_ecef(traj: Trajectory, mount: Mount, frame: MappingFrame) -> GeoreferencedPoses:
    """Apply the lever arm and mount to the trajectory, rigorously in ECEF."""
    llh = traj.position if traj.geodetic else frame.map_to_geodetic(traj.position)
    r_n_e = ned_to_ecef_rotation(llh[:, 0], llh[:, 1])
    r_b_n = rph_to_matrix(traj.rph[:, 0], traj.rph[:, 1], traj.rph[:, 2])
    r_b_e = r_n_e @ r_b_n
    centre = frame.geodetic_to_ecef(llh) + r_b_e @ mount.lever_arm
    return GeoreferencedPoses(centre, r_b_e @ mount.camera_to_body)


def direct_georeference(
    traj: Trajectory, mount: Mount, frame: MappingFrame
) -> ExteriorOrientationTable:
    """Exterior orientation of every image in the mapping frame (see the module docstring)."""
    poses = georeference_ecef(traj, mount, frame)
    llh_pc = frame.ecef_to_geodetic(poses.centre_ecef)
    xyz = frame.geodetic_to_map(llh_pc)
    # R_e^m at the perspective centre = R_n^m (R_n^e)^T, both at the centre's own position.
    r_n_e = ned_to_ecef_rotation(llh_pc[:, 0], llh_pc[:, 1])
    r_c_m = frame.ned_to_grid(llh_pc) @ np.swapaxes(r_n_e, -1, -2) @ poses.camera_to_ecef
    omega, phi, kappa = matrix_to_opk(np.swapaxes(r_c_m, -1, -2))
    return ExteriorOrientationTable(
        traj.image_id,
        traj.time,
        traj.group,
        xyz,
        np.stack([omega, phi, kappa], axis=1),
        frame.crs.to_wkt(),
    )
