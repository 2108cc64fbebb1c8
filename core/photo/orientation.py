"""Exterior orientation tables: perspective centre and omega-phi-kappa per image.

omega, phi, kappa are relative to the grid frame at each perspective centre (grid east, grid
north, local up); the table's file format: :mod:`core.io.orientation`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..geometry.engineering import EngineeringLocal
from ..geometry.frames import LocalFrame
from ..geometry.rotations import matrix_to_opk, opk_to_matrix


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


def eo_map_to_local(
    xyz: NDArray[np.float64], opk: NDArray[np.float64], local: LocalFrame | EngineeringLocal
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Mapping-frame EO -> (centres (N, 3) in the ENU frame, world-to-camera M (N, 3, 3) there).

    ``opk`` is relative to the grid frame at each centre (as in the EO CSV); the rotation into
    the ENU frame includes grid convergence and the tilt of the local vertical.
    """
    if isinstance(local, EngineeringLocal):  # an engineering frame: no grid, same axes
        return local.map_to_enu(xyz), opk_to_matrix(opk[:, 0], opk[:, 1], opk[:, 2])
    llh = local.mapping.map_to_geodetic(xyz)
    r_c_m = np.swapaxes(opk_to_matrix(opk[:, 0], opk[:, 1], opk[:, 2]), -1, -2)
    r_c_l = local.grid_to_local(llh) @ r_c_m
    return local.geodetic_to_enu(llh), np.swapaxes(r_c_l, -1, -2)


def eo_local_to_map(
    centres: NDArray[np.float64], m_local: NDArray[np.float64], local: LocalFrame | EngineeringLocal
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Inverse of :func:`eo_map_to_local`: -> (xyz (N, 3) mapping CRS, opk (N, 3) radians)."""
    if isinstance(local, EngineeringLocal):
        omega, phi, kappa = matrix_to_opk(m_local)
        return local.enu_to_map(centres), np.stack([omega, phi, kappa], axis=-1)
    llh = local.mapping.ecef_to_geodetic(local.enu_to_ecef(centres))
    r_c_l = np.swapaxes(m_local, -1, -2)
    r_c_m = np.swapaxes(local.grid_to_local(llh), -1, -2) @ r_c_l
    omega, phi, kappa = matrix_to_opk(np.swapaxes(r_c_m, -1, -2))
    return local.mapping.geodetic_to_map(llh), np.stack([omega, phi, kappa], axis=-1)
