"""North-up raster grids: cell geometry, point-to-cell indexing, interpolation, hole filling.

A :class:`Grid` cell (row, col) covers ``x0 + col c .. x0 + (col + 1) c`` in x and
``y_top - (row + 1) c .. y_top - row c`` in y; values live at the cell centres.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError


@dataclass(frozen=True)
class Grid:
    """A north-up raster: cell (row, col) covers x0 + col c .. and y_top - row c ...

    ``geotransform`` is in GDAL order (x of the top-left corner, c, 0, y of the top-left
    corner, 0, -c).
    """

    x0: float
    y_top: float
    cell: float
    rows: int
    cols: int

    @property
    def geotransform(self) -> tuple[float, float, float, float, float, float]:
        return (self.x0, self.cell, 0.0, self.y_top, 0.0, -self.cell)

    @classmethod
    def covering(
        cls,
        mins: Sequence[float] | NDArray[np.float64],
        maxs: Sequence[float] | NDArray[np.float64],
        cell: float,
    ) -> Grid:
        """The grid of ``cell`` aligned on multiples of ``cell`` that covers the box."""
        x0 = math.floor(mins[0] / cell) * cell
        y_top = (math.floor(maxs[1] / cell) + 1) * cell
        cols = math.floor((maxs[0] - x0) / cell) + 1
        rows = math.floor((y_top - mins[1]) / cell) + 1
        return cls(x0, y_top, cell, rows, cols)

    def flat_index(self, x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.int64]:
        """(N,) flat cell index row * cols + col of each point (clipped to the grid)."""
        col = ((x - self.x0) * (1.0 / self.cell)).astype(np.int64)
        row = ((self.y_top - y) * (1.0 / self.cell)).astype(np.int64)
        np.clip(col, 0, self.cols - 1, out=col)
        np.clip(row, 0, self.rows - 1, out=row)
        row *= self.cols
        row += col
        return row

    def bilinear(
        self, surface: NDArray[np.float32], x: NDArray[np.float64], y: NDArray[np.float64]
    ) -> NDArray[np.float32]:
        """(N,) bilinear interpolation of a (rows, cols) surface given at the cell centres."""
        fc = ((x - self.x0) * (1.0 / self.cell) - 0.5).astype(np.float32)
        fr = ((self.y_top - y) * (1.0 / self.cell) - 0.5).astype(np.float32)
        np.clip(fc, 0, self.cols - 1, out=fc)
        np.clip(fr, 0, self.rows - 1, out=fr)
        c0 = np.minimum(fc.astype(np.int64), max(self.cols - 2, 0))
        r0 = np.minimum(fr.astype(np.int64), max(self.rows - 2, 0))
        fc -= c0
        fr -= r0
        flat = surface.ravel()
        i00 = r0 * self.cols + c0
        dc = 1 if self.cols > 1 else 0
        dr = self.cols if self.rows > 1 else 0
        top = flat[i00] * (1 - fc) + flat[i00 + dc] * fc
        bottom = flat[i00 + dr] * (1 - fc) + flat[i00 + dr + dc] * fc
        return top * (1 - fr) + bottom * fr


_Float = TypeVar("_Float", np.float32, np.float64)


def fill_nearest(surface: NDArray[_Float], valid: NDArray[np.bool_]) -> NDArray[_Float]:
    from scipy import ndimage

    if valid.all():
        return surface
    _, (ri, ci) = ndimage.distance_transform_edt(~valid, return_indices=True)
    return surface[ri, ci]


def fill_holes(surface: NDArray[np.float32], valid: NDArray[np.bool_]) -> NDArray[np.float32]:
    """Fill the cells where ``valid`` is False by pull-push interpolation.

    Pull: weighted 2x2 averages build a pyramid until a level has no hole. Push: from the
    coarsest level down, holes take the bilinear up-sampling of the level above. The result
    is smooth across holes and exact on valid cells.

    Parameters
    ----------
    surface : (rows, cols) float32
    valid : (rows, cols) bool, at least one True

    Returns
    -------
    (rows, cols) float32

    Examples
    --------
    >>> s = np.array([[1, 0, 3]], np.float32)
    >>> fill_holes(s, s > 0).tolist()
    [[1.0, 1.5, 3.0]]
    """
    import cv2

    if valid.all():
        return surface.astype(np.float32, copy=True)
    if not valid.any():
        raise InputError("no valid cell to interpolate from")
    values = np.where(valid, surface, 0).astype(np.float32)
    weights = valid.astype(np.float32)
    levels = []
    while True:
        levels.append((values, weights))
        if weights.min() > 0 or max(values.shape) == 1:
            break
        r, c = values.shape
        pr, pc = r % 2, c % 2
        if pr or pc:
            values = np.pad(values, ((0, pr), (0, pc)))
            weights = np.pad(weights, ((0, pr), (0, pc)))
        values = values.reshape(values.shape[0] // 2, 2, values.shape[1] // 2, 2).sum(axis=(1, 3))
        weights = weights.reshape(weights.shape[0] // 2, 2, weights.shape[1] // 2, 2).sum(
            axis=(1, 3)
        )
    values, weights = levels[-1]
    est: NDArray[np.floating] = values / np.maximum(weights, 1e-30)
    if weights.min() <= 0:  # a 1-cell-wide top level with holes: nearest fill
        est = fill_nearest(est.astype(np.float32), weights > 0)
    for values, weights in reversed(levels[:-1]):
        r, c = values.shape
        up = cv2.resize(
            est.astype(np.float32),
            (2 * est.shape[1], 2 * est.shape[0]),
            interpolation=cv2.INTER_LINEAR,
        )[:r, :c]
        est = np.where(weights > 0, values / np.maximum(weights, 1e-30), up)
    out = np.where(valid, surface, est)
    return out.astype(np.float32)
