"""Scan points into the common (object) frame: the adjusted station pose, and optionally the
scanner's AP corrections removed from each point.

A scan exports scanner-frame points ``d``; the pose of :mod:`.network` maps the object frame
into the scanner frame, ``d = M (X - X0)`` with ``M = R3(kappa) R2(phi) R1(omega)``, so a
point's object coordinates are ``X = M' d + X0``.

AP corrections (:mod:`.aps`): the scanner records ``obs = geo + C(geo)`` in polar form. An
exported point is turned back into its recorded polar form (face I: the file does not say
which face recorded it, and ``polar_to_cartesian`` of a face-II reading gives the same point
as a face-I one), the geometric value is found by the fixed-point iteration
``geo <- obs - C(geo)`` (the corrections change by far less than their own size between
``obs`` and ``geo``: two or three steps reach the numerical floor) and turned back into x, y, z.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..geometry.rotations import opk_to_matrix
from .aps import ap_corrections
from .polar import cartesian_to_polar, polar_to_cartesian

__all__ = ["remove_ap_corrections", "scanner_to_object"]

Array = NDArray[np.float64]


def remove_ap_corrections(
    xyz: ArrayLike,
    names: Sequence[str],
    values: ArrayLike,
    wavelength_m: float = 1.2,
    iterations: int = 3,
) -> Array:
    """(N, 3) scanner-frame points (m) as recorded -> the points without the AP corrections
    (face-I readings). Points at the origin (no return) are left as they are.

    >>> p = remove_ap_corrections([[5.002, 0.0, 0.0], [0.0, 0.0, 0.0]], ("a0",), [0.002])
    >>> np.round(p, 9).tolist()
    [[5.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
    """
    d = np.asarray(xyz, dtype=np.float64)
    names = tuple(names)
    if not names or d.shape[0] == 0:
        return d.copy()
    obs = cartesian_to_polar(d)
    geo = obs.copy()
    for _ in range(max(int(iterations), 1)):
        corr = ap_corrections(names, values, geo, wavelength_m)
        # on the vertical axis the horizontal direction has no meaning (sec(alpha) is
        # infinite there, the point's shift rho cos(alpha) d_theta is finite: 0 at the axis)
        corr[~np.isfinite(corr)] = 0.0
        geo = obs - corr
    out = polar_to_cartesian(geo)
    empty = obs[:, 0] == 0.0
    out[empty] = d[empty]
    return out


def scanner_to_object(
    xyz: ArrayLike,
    pose: ArrayLike,
    names: Sequence[str] = (),
    values: ArrayLike = (),
    wavelength_m: float = 1.2,
) -> Array:
    """(N, 3) scanner-frame points (m) of the station with ``pose`` (X0 in m, omega, phi,
    kappa in rad) -> object-frame points, after removing the APs ``names`` with ``values``
    (internal units) when given.

    >>> pose = [10.0, 20.0, 1.5, 0.0, 0.0, np.pi / 2]
    >>> np.round(scanner_to_object([[1.0, 0.0, 0.0]], pose), 9).tolist()
    [[10.0, 21.0, 1.5]]
    """
    p = np.asarray(pose, dtype=np.float64)
    d = (
        remove_ap_corrections(xyz, names, values, wavelength_m)
        if len(names)
        else (np.asarray(xyz, dtype=np.float64))
    )
    m = opk_to_matrix(p[3], p[4], p[5])
    return d @ m + p[:3]
