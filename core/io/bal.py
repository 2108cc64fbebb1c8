"""Bundle Adjustment in the Large (BAL) problem files (Agarwal et al. 2010).

Text format, whitespace separated::

    <num_cameras> <num_points> <num_observations>
    <camera_index> <point_index> <x> <y>      (num_observations lines; pixels from the image
                                              centre, x right, y up)
    <camera parameters>                       (9 per camera: Rodrigues rotation r (3),
                                              translation t (3), f, k1, k2)
    <point coordinates>                       (3 per point)

The projection model is Snavely's (:mod:`core.geometry.snavely`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Union

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError

__all__ = ["BalProblem", "read_bal"]


@dataclass(frozen=True)
class BalProblem:
    """A BAL problem: observations (N, 2) with their camera (N,) and point (N,) indices,
    cameras (C, 9) and points (P, 3)."""

    camera_index: NDArray[np.intp]
    point_index: NDArray[np.intp]
    observations: NDArray[np.float64]
    cameras: NDArray[np.float64]
    points: NDArray[np.float64]


def read_bal(path: Union[str, Path]) -> BalProblem:
    """Read a BAL text file (optionally .bz2), checking the counts and indices."""
    p = Path(path)
    try:
        if p.suffix == ".bz2":
            import bz2

            text = bz2.open(p, "rt").read()
        else:
            text = p.read_text()
    except OSError as exc:
        raise InputError(f"cannot read BAL file: {exc}", path=str(p)) from exc
    values = text.split()
    try:
        nc, npt, nobs = (int(v) for v in values[:3])
        obs = np.array(values[3 : 3 + 4 * nobs], dtype=np.float64).reshape(nobs, 4)
        start = 3 + 4 * nobs
        cams = np.array(values[start : start + 9 * nc], dtype=np.float64).reshape(nc, 9)
        start += 9 * nc
        pts = np.array(values[start : start + 3 * npt], dtype=np.float64).reshape(npt, 3)
    except (ValueError, IndexError) as exc:
        raise InputError(f"not a BAL problem ({exc})", path=str(p)) from exc
    ci = obs[:, 0].astype(np.intp)
    pi = obs[:, 1].astype(np.intp)
    if ci.min() < 0 or ci.max() >= nc or pi.min() < 0 or pi.max() >= npt:
        raise InputError("camera or point index out of range", path=str(p))
    return BalProblem(ci, pi, obs[:, 2:].copy(), cams, pts)
