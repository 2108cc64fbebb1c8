"""Digital surface models made from LiDAR points: the highest return per cell, gaps filled."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..geometry.grid import Grid, fill_holes

#: Classes never used for a surface: low point (7) and high noise (18).
NOISE_CLASSES = (7, 18)


def dsm_from_points(
    x: ArrayLike,
    y: ArrayLike,
    z: ArrayLike,
    cell: float,
    *,
    fill: bool = True,
    bounds: Sequence[float] | None = None,
) -> tuple[NDArray[np.float32], Grid]:
    """Highest point per cell, with the empty cells filled (pull-push interpolation).

    Parameters
    ----------
    x, y, z : (N,) array_like
        Points, CRS unit.
    cell : float
        Cell size, CRS unit, > 0.
    fill : bool
        Fill the cells without points (:func:`core.geometry.grid.fill_holes`); else NaN.
    bounds : (xmin, ymin, xmax, ymax), optional
        Area to cover (default: the points' box); the grid is aligned on multiples of ``cell``.

    Returns
    -------
    heights : (rows, cols) float32
    grid : Grid

    Examples
    --------
    >>> h, g = dsm_from_points([0.2, 0.4, 1.5], [0.5, 0.5, 0.5], [1, 3, 2], 1.0)
    >>> h.tolist(), (g.rows, g.cols)
    ([[3.0, 2.0]], (1, 2))
    """
    x, y, z = (np.asarray(a, dtype=np.float64).ravel() for a in (x, y, z))
    if not (cell > 0 and np.isfinite(cell)):
        raise InputError(f"cell size must be a positive number, got {cell!r}")
    if x.size == 0:
        raise InputError("no points to make a DSM from")
    if bounds is None:
        mins, maxs = (x.min(), y.min()), (x.max(), y.max())
    else:
        mins, maxs = (bounds[0], bounds[1]), (bounds[2], bounds[3])
    grid = Grid.covering(mins, maxs, float(cell))
    flat = grid.flat_index(x, y)
    # ufunc.at is slow on numpy < 1.25: sort by cell and reduce each run instead.
    order = np.argsort(flat, kind="stable")
    fs = flat[order]
    starts = np.flatnonzero(np.r_[True, fs[1:] != fs[:-1]])
    out = np.full(grid.rows * grid.cols, np.nan, dtype=np.float32)
    out[fs[starts]] = np.maximum.reduceat(z[order], starts).astype(np.float32)
    heights = out.reshape(grid.rows, grid.cols)
    if fill:
        valid = np.isfinite(heights)
        heights = fill_holes(np.where(valid, heights, 0).astype(np.float32), valid)
    return heights, grid
