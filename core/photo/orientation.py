"""Exterior orientation tables: perspective centre and omega-phi-kappa per image.

CSV format (header row, comma separated, one image per row)::

    image_id,time,group,X,Y,Z,omega_deg,phi_deg,kappa_deg

X, Y, Z: perspective centre in the mapping CRS (easting, northing, height; metres).
omega, phi, kappa: degrees, ``M = R3(kappa) R2(phi) R1(omega)`` rotates vectors of the grid
frame at the perspective centre (grid east, grid north, local up) into the camera frame.
``time`` may be empty (NaN) and ``group`` (flight line or direction) may be empty.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Union

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..geometry.frames import LocalFrame
from ..geometry.rotations import matrix_to_opk, opk_to_matrix
from ..io.tables import (
    find_column,
    float_column,
    read_table,
    text_column,
    unique_ids,
    write_csv_atomic,
)

EO_COLUMNS = ("image_id", "time", "group", "X", "Y", "Z", "omega_deg", "phi_deg", "kappa_deg")


@dataclass(frozen=True)
class ExteriorOrientationTable:
    """Exterior orientation of N images in the mapping CRS.

    xyz: (N, 3) perspective centres (easting, northing, height), metres.
    opk: (N, 3) omega, phi, kappa in radians relative to the grid frame at each centre.
    crs_wkt: the mapping CRS as WKT.
    """

    image_id: tuple[str, ...]
    time: NDArray[np.float64]
    group: tuple[str, ...]
    xyz: NDArray[np.float64]
    opk: NDArray[np.float64]
    crs_wkt: str

    def __len__(self) -> int:
        return len(self.image_id)

    def rotation(self) -> NDArray[np.float64]:
        """(N, 3, 3) world-to-camera matrices M."""
        return opk_to_matrix(self.opk[:, 0], self.opk[:, 1], self.opk[:, 2])

    def to_csv(self, path: Union[str, Path]) -> None:
        """Write the documented CSV atomically (never a half-written file)."""
        deg = np.degrees(self.opk)
        rows = (
            (
                image,
                "" if not np.isfinite(t) else f"{t:.6f}",
                group,
                f"{x:.4f}",
                f"{y:.4f}",
                f"{z:.4f}",
                f"{w:.10f}",
                f"{p:.10f}",
                f"{k:.10f}",
            )
            for image, t, group, (x, y, z), (w, p, k) in zip(
                self.image_id, self.time, self.group, self.xyz, deg
            )
        )
        write_csv_atomic(path, EO_COLUMNS, rows)


def read_eo_csv(path: Union[str, Path], crs_wkt: str = "") -> ExteriorOrientationTable:
    """Read a table written by :meth:`ExteriorOrientationTable.to_csv` (or made by hand)."""
    table = read_table(path)
    ids = unique_ids(table, find_column(table, ("image_id", "image", "id", "name")))
    t_col = find_column(table, ("time",), required=False)
    g_col = find_column(table, ("group",), required=False)
    xyz = np.stack(
        [float_column(table, find_column(table, (name.lower(),))) for name in ("X", "Y", "Z")],
        axis=1,
    )
    opk = np.stack(
        [
            float_column(table, find_column(table, (f"{name}_deg", name)))
            for name in ("omega", "phi", "kappa")
        ],
        axis=1,
    )
    if t_col is None:
        time = np.full(len(table), np.nan)
    else:
        time = float_column(table, t_col, allow_empty=True)
    group = text_column(table, g_col, nonempty=False) if g_col is not None else ("",) * len(ids)
    if np.any(np.abs(opk[:, 1]) > 90.0):
        row = table.line_numbers[int(np.argmax(np.abs(opk[:, 1]) > 90.0))]
        raise InputError("phi must lie within [-90, 90] degrees", path=table.path, row=row)
    return ExteriorOrientationTable(ids, time, group, xyz, np.radians(opk), crs_wkt)


def eo_map_to_local(
    xyz: NDArray[np.float64], opk: NDArray[np.float64], local: LocalFrame
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Mapping-frame EO -> (centres (N, 3) in the ENU frame, world-to-camera M (N, 3, 3) there).

    ``opk`` is relative to the grid frame at each centre (as in the EO CSV); the rotation into
    the ENU frame includes grid convergence and the tilt of the local vertical.
    """
    llh = local.mapping.map_to_geodetic(xyz)
    r_c_m = np.swapaxes(opk_to_matrix(opk[:, 0], opk[:, 1], opk[:, 2]), -1, -2)
    r_c_l = local.grid_to_local(llh) @ r_c_m
    return local.geodetic_to_enu(llh), np.swapaxes(r_c_l, -1, -2)


def eo_local_to_map(
    centres: NDArray[np.float64], m_local: NDArray[np.float64], local: LocalFrame
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Inverse of :func:`eo_map_to_local`: -> (xyz (N, 3) mapping CRS, opk (N, 3) radians)."""
    llh = local.mapping.ecef_to_geodetic(local.enu_to_ecef(centres))
    r_c_l = np.swapaxes(m_local, -1, -2)
    r_c_m = np.swapaxes(local.grid_to_local(llh), -1, -2) @ r_c_l
    omega, phi, kappa = matrix_to_opk(np.swapaxes(r_c_m, -1, -2))
    return local.mapping.geodetic_to_map(llh), np.stack([omega, phi, kappa], axis=-1)
