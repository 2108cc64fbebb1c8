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

Trajectory CSV format (header row; names are case-insensitive, aliases in parentheses)::

    image_id (id, image, name, photo)      text, unique
    time (gps_time, t)                     optional, seconds
    group (line, strip, flight_line)       optional, flight line or direction
    easting (e, x), northing (n, y), height (h, z, alt)         in the mapping CRS, or
    latitude (lat), longitude (lon, long), height (h, z, alt)   degrees on the CRS's datum
    roll, pitch, heading (yaw)             degrees; body x forward, y right, z down;
                                           heading clockwise from true north
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Union

import numpy as np
from numpy.typing import NDArray

from ..errors import Cancelled, InputError
from ..geometry.frames import MappingFrame, ned_to_ecef_rotation
from ..geometry.rotations import (
    MOUNT_PRESETS,
    boresight_matrix,
    is_rotation,
    matrix_to_opk,
    rph_to_matrix,
)
from ..io.tables import find_column, float_column, read_table, text_column, unique_ids
from .orientation import ExteriorOrientationTable

__all__ = [
    "MOUNT_CHOICES",
    "ExteriorOrientationTable",
    "Mount",
    "Trajectory",
    "direct_georeference",
    "read_trajectory_csv",
    "run_trajectory_to_eo",
]

log = logging.getLogger(__name__)

MOUNT_CHOICES = (*MOUNT_PRESETS.keys(), "custom")

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Trajectory:
    """INS/GNSS solution at the exposure times of N images.

    position: (N, 3) easting, northing, height in the mapping CRS when ``geodetic`` is False;
    latitude, longitude (degrees) and ellipsoidal height otherwise.
    rph: (N, 3) roll, pitch, heading in radians.
    """

    image_id: tuple[str, ...]
    time: Array
    group: tuple[str, ...]
    position: Array
    geodetic: bool
    rph: Array

    def __len__(self) -> int:
        return len(self.image_id)


@dataclass(frozen=True)
class Mount:
    """Camera mounting: lever arm (body frame, metres) and camera-to-body rotation.

    boresight: (d_omega, d_phi, d_kappa) in radians about the camera axes.
    """

    lever_arm: Array
    nominal: Array
    boresight: Array

    def __post_init__(self) -> None:
        for name, shape in (("lever_arm", (3,)), ("nominal", (3, 3)), ("boresight", (3,))):
            value = getattr(self, name)
            arr = np.asarray(value, dtype=np.float64)
            if arr.shape != shape or not np.all(np.isfinite(arr)):
                raise InputError(f"mount {name} must be {shape} finite numbers, got {value!r}")
            object.__setattr__(self, name, arr)
        if not is_rotation(self.nominal, atol=1e-6):
            raise InputError(
                "the custom mount matrix is not a rotation (orthonormal, determinant +1): "
                f"{np.round(self.nominal, 6).tolist()}"
            )

    @property
    def camera_to_body(self) -> Array:
        """``R_c^b = R_nominal dR``."""
        return self.nominal @ boresight_matrix(*self.boresight)

    @classmethod
    def from_user(
        cls,
        lever_arm: Union[str, Sequence[float]] = "0,0,0",
        mount: str = "image_top_forward",
        mount_matrix: Union[str, Sequence[float]] = "",
        boresight_deg: Union[str, Sequence[float]] = "0,0,0",
    ) -> Mount:
        """Build from the algorithm's parameters (strings as typed by a user, or numbers)."""
        arm = parse_numbers(lever_arm, 3, "LEVER_ARM")
        bore = np.radians(parse_numbers(boresight_deg, 3, "BORESIGHT"))
        name = str(mount).strip().lower()
        if name.isdigit() and int(name) < len(MOUNT_CHOICES):
            name = MOUNT_CHOICES[int(name)]
        if name == "custom":
            nominal = parse_numbers(mount_matrix, 9, "MOUNT_MATRIX").reshape(3, 3)
        elif name in MOUNT_PRESETS:
            nominal = MOUNT_PRESETS[name]
        else:
            raise InputError(
                f"MOUNT '{mount}' is unknown; choose one of {', '.join(MOUNT_CHOICES)}"
            )
        return cls(arm, nominal, bore)


def parse_numbers(value: Union[str, Sequence[float]], count: int, name: str) -> Array:
    """Parse ``"a,b,c"`` (commas, semicolons or spaces) or a sequence into ``count`` floats."""
    if isinstance(value, str):
        parts = [p for p in value.replace(";", ",").replace(" ", ",").split(",") if p]
    else:
        parts = list(value)
    try:
        numbers = np.array([float(p) for p in parts], dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be {count} numbers, got '{value}'") from None
    if numbers.shape != (count,) or not np.all(np.isfinite(numbers)):
        raise InputError(f"{name} must be {count} finite numbers, got '{value}'")
    return numbers


def read_trajectory_csv(path: Union[str, Path]) -> Trajectory:
    """Read the trajectory table (format in the module docstring)."""
    table = read_table(path)
    ids = unique_ids(table, find_column(table, ("image_id", "id", "image", "name", "photo")))
    t_col = find_column(table, ("time", "gps_time", "t"), required=False)
    time = (
        float_column(table, t_col, allow_empty=True)
        if t_col is not None
        else np.full(len(ids), np.nan)
    )
    g_col = find_column(table, ("group", "line", "strip", "flight_line"), required=False)
    group = text_column(table, g_col, nonempty=False) if g_col is not None else ("",) * len(ids)
    lat_col = find_column(table, ("latitude", "lat"), required=False)
    e_col = find_column(table, ("easting", "e", "x"), required=False)
    if (lat_col is None) == (e_col is None):
        raise InputError(
            "give either easting/northing/height or latitude/longitude/height columns "
            f"(found: {', '.join(table.columns)})",
            path=table.path,
        )
    h_col = find_column(table, ("height", "h", "z", "alt", "altitude"), what="height")
    if lat_col is not None:
        lon_col = find_column(table, ("longitude", "lon", "long"), what="longitude")
        position = np.stack([float_column(table, c) for c in (lat_col, lon_col, h_col)], axis=1)
        _check_range(table, lat_col, position[:, 0], 90.0)
        _check_range(table, lon_col, position[:, 1], 180.0)
    else:
        n_col = find_column(table, ("northing", "n", "y"), what="northing")
        position = np.stack([float_column(table, c) for c in (e_col, n_col, h_col)], axis=1)
    cols = [find_column(table, names) for names in (("roll",), ("pitch",), ("heading", "yaw"))]
    rph_deg = np.stack([float_column(table, c) for c in cols], axis=1)
    _check_range(table, cols[0], rph_deg[:, 0], 180.0)
    _check_range(table, cols[1], rph_deg[:, 1], 90.0)
    _check_range(table, cols[2], rph_deg[:, 2], 360.0)
    return Trajectory(ids, time, group, position, lat_col is not None, np.radians(rph_deg))


def _check_range(table, column: int, values: Array, limit: float) -> None:
    bad = np.flatnonzero(np.abs(values) > limit)
    if bad.size:
        raise InputError(
            f"{values[bad[0]]} is outside [-{limit:g}, {limit:g}] degrees",
            path=table.path,
            row=table.line_numbers[bad[0]],
            column=table.columns[column],
        )


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


def run_trajectory_to_eo(
    input_csv: Union[str, Path],
    crs: str,
    lever_arm: Union[str, Sequence[float]] = "0,0,0",
    mount: str = "image_top_forward",
    mount_matrix: Union[str, Sequence[float]] = "",
    boresight: Union[str, Sequence[float]] = "0,0,0",
    output_csv: Union[str, Path] | None = None,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> ExteriorOrientationTable:
    """The ``trajectorytoeo`` job: read, georeference, optionally write the EO CSV.

    ``boresight`` is in degrees (d_omega, d_phi, d_kappa); ``lever_arm`` in metres (body
    frame). Every input is validated before anything is written.
    """
    frame = MappingFrame.from_user_input(crs)
    mount_ = Mount.from_user(lever_arm, mount, mount_matrix, boresight)
    traj = read_trajectory_csv(input_csv)
    log.info("read %d images from %s", len(traj), input_csv)
    if should_stop is not None and should_stop():
        raise Cancelled("cancelled before georeferencing")
    if progress is not None:
        progress(0.3)
    table = direct_georeference(traj, mount_, frame)
    if progress is not None:
        progress(0.8)
    if output_csv:
        table.to_csv(output_csv)
        log.info("wrote %s", output_csv)
    if progress is not None:
        progress(1.0)
    return table
