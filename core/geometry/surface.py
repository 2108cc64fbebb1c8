"""A gridded surface model (DSM or DTM) and its surface, the polyhedron of dos Santos et al. (2010).

A DSM is a north-up grid of heights given at the cell *centres* (``Grid`` of
:mod:`core.geometry.grid`: cell (row, col) covers ``x0 + col c .. x0 + (col + 1) c`` and
``y_top - (row + 1) c .. y_top - row c``). NaN marks nodata.

The surface is the polyhedron of dos Santos et al. (2010) after Dal Poz (1991): the centres of four
neighbouring cells ``(r, c), (r, c+1), (r+1, c), (r+1, c+1)`` span a *quad*, split along its
diagonal from ``(r, c)`` to ``(r+1, c+1)`` into two triangles. With the quad's local coordinates ``u
= (x - x_c) / cell`` (east) and ``v = (y_r - y) / cell`` (south), in [0, 1]:

- triangle 0 (``u >= v``): vertices (0, 0), (1, 0), (1, 1), i.e. cells (r, c), (r, c+1),
  (r+1, c+1);
- triangle 1 (``u <= v``): vertices (0, 0), (0, 1), (1, 1), i.e. cells (r, c), (r+1, c),
  (r+1, c+1).

The surface spans the centres of the first and last rows and columns: half a cell inside
the raster's outer edge.
"""

from __future__ import annotations

import functools
import logging
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pyproj
from numpy.typing import ArrayLike, NDArray

from ..errors import CrsError, stop_if_asked
from .frames import parse_crs
from .grid import Grid

LOG = logging.getLogger(__name__)

Array = NDArray[np.float64]

__all__ = ["Dsm", "reproject_dsm", "triangle_height"]


@dataclass(frozen=True)
class Dsm:
    """A gridded surface model.

    Attributes
    ----------
    heights : (rows, cols) float32
        Heights at the cell centres, CRS unit; NaN for nodata.
    grid : Grid
        Geometry of the raster (top-left corner, square cell, size).
    crs : pyproj.CRS or None
        CRS of x, y and the heights; None when the source had none.
    source : str
        File it came from (for messages).
    """

    heights: NDArray[np.float32]
    grid: Grid
    crs: pyproj.CRS | None = None
    source: str = ""

    @property
    def cell(self) -> float:
        return self.grid.cell

    @property
    def centre_origin(self) -> tuple[float, float]:
        """(x, y) of the centre of cell (0, 0)."""
        return self.grid.x0 + 0.5 * self.grid.cell, self.grid.y_top - 0.5 * self.grid.cell

    @functools.cached_property
    def z_range(self) -> tuple[float, float]:
        """(min, max) of the valid heights (computed once: a DSM's heights are not edited)."""
        return float(np.nanmin(self.heights)), float(np.nanmax(self.heights))

    def to_grid_uv(self, x: ArrayLike, y: ArrayLike) -> tuple[Array, Array]:
        """Map x, y -> lattice coordinates (u east, v south) in cells from the centre of (0, 0)."""
        xc, yc = self.centre_origin
        inv = 1.0 / self.grid.cell
        return (np.asarray(x, float) - xc) * inv, (yc - np.asarray(y, float)) * inv

    def height_at(self, x: ArrayLike, y: ArrayLike) -> Array:
        """(N,) height of the triangulated surface at map points; NaN outside or on nodata.

        Examples
        --------
        >>> d = Dsm(np.array([[0, 1], [2, 3]], np.float32), Grid(0.0, 2.0, 1.0, 2, 2))
        >>> d.height_at([0.5, 1.0, 1.5], [1.5, 1.0, 0.5]).tolist()
        [0.0, 1.5, 3.0]
        """
        u, v = self.to_grid_uv(x, y)
        return triangle_height(self.heights, np.atleast_1d(u), np.atleast_1d(v))


def triangle_height(z: NDArray, u: ArrayLike, v: ArrayLike) -> Array:
    """Height of the surface triangulated on the grid ``z`` at grid coordinates ``(u, v)``.

    ``u`` counts columns and ``v`` rows from the centre of cell (0, 0) (cells); ``u`` and ``v``
    broadcast against each other. Each cell square is split along its (0, 0)-(1, 1) diagonal;
    NaN outside the grid (and where a corner is NaN).

    >>> triangle_height(np.array([[0.0, 1.0], [2.0, 3.0]]), [0.5, 1.0], [0.25, 1.0]).tolist()
    [1.0, 3.0]
    """
    u, v = np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64)
    rows, cols = z.shape
    inside = (u >= 0) & (v >= 0) & (u <= cols - 1) & (v <= rows - 1)
    c = np.clip(np.floor(u), 0, max(cols - 2, 0)).astype(np.int64)
    r = np.clip(np.floor(v), 0, max(rows - 2, 0)).astype(np.int64)
    fu, fv = u - c, v - r
    c1, r1 = np.minimum(c + 1, cols - 1), np.minimum(r + 1, rows - 1)
    z00 = z[r, c].astype(np.float64)
    z01 = z[r, c1].astype(np.float64)
    z10 = z[r1, c].astype(np.float64)
    z11 = z[r1, c1].astype(np.float64)
    out = np.where(
        fu >= fv,
        z00 + (z01 - z00) * fu + (z11 - z01) * fv,
        z00 + (z11 - z10) * fu + (z10 - z00) * fv,
    )
    out[~inside] = np.nan
    return out


def reproject_dsm(
    dsm: Dsm,
    crs: str | int | pyproj.CRS,
    cell: float | None = None,
    *,
    block_rows: int = 256,
    should_stop: Callable[[], bool] | None = None,
) -> Dsm:
    """The DSM resampled onto a north-up grid of another CRS, heights transformed too.

    Each target cell centre is mapped back to the source CRS, the source surface (the
    triangulated polyhedron) is sampled there and the point (x, y, height) is transformed
    to the target: vertical datum changes are applied (2D CRSs carry ellipsoidal heights,
    :func:`core.geometry.frames.as_3d`), and a transformation that needs a grid PROJ does not have
    raises :class:`CrsError` instead of silently dropping it.

    Parameters
    ----------
    dsm : Dsm
        With its CRS.
    crs : target CRS.
    cell : float, optional
        Target cell, target CRS unit (default: the source cell times the local scale
        between the two CRSs at the DSM's centre, rounded to 1 mm).
    block_rows : int
        Target rows transformed per batch (memory).
    """
    from .frames import transformer_3d

    if dsm.crs is None:
        raise CrsError("the DSM has no CRS: it cannot be reprojected", path=dsm.source or None)
    dst = parse_crs(crs)
    fwd = transformer_3d(dsm.crs, dst)
    inv = transformer_3d(dst, dsm.crs)
    g = dsm.grid
    rows, cols = dsm.heights.shape
    # the footprint: the surface's outline (cell centres of the border), densified
    k = np.linspace(0.0, 1.0, 65)
    xc, yc = dsm.centre_origin
    xs = xc + np.r_[k, np.ones_like(k), k[::-1], np.zeros_like(k)] * (cols - 1) * g.cell
    ys = yc - np.r_[np.zeros_like(k), k, np.ones_like(k), k[::-1]] * (rows - 1) * g.cell
    zmid = float(np.nanmedian(dsm.heights)) if np.isfinite(dsm.heights).any() else 0.0
    bx, by, _ = fwd.transform(xs, ys, np.full(xs.size, zmid))
    if not (np.isfinite(bx).all() and np.isfinite(by).all()):
        raise CrsError(
            f"the DSM's footprint cannot be transformed to '{dst.name}'", path=dsm.source or None
        )
    if cell is None:
        cx, cy = xc + (cols - 1) * g.cell / 2, yc - (rows - 1) * g.cell / 2
        px, py, _ = fwd.transform([cx, cx + g.cell, cx], [cy, cy, cy + g.cell], [zmid] * 3)
        scale = (
            0.5
            * (math.hypot(px[1] - px[0], py[1] - py[0]) + math.hypot(px[2] - px[0], py[2] - py[0]))
            / g.cell
        )
        cell = max(round(g.cell * scale, 3), 1e-3)
    cell = float(cell)
    out = Grid.covering(
        (bx.min() - cell / 2, by.min() - cell / 2), (bx.max() + cell / 2, by.max() + cell / 2), cell
    )
    heights = np.full((out.rows, out.cols), np.nan, np.float32)
    cols_x = out.x0 + (np.arange(out.cols) + 0.5) * cell
    for r0 in range(0, out.rows, max(int(block_rows), 1)):
        stop_if_asked(should_stop, "building the DSM")
        r1 = min(r0 + block_rows, out.rows)
        yy = out.y_top - (np.arange(r0, r1) + 0.5) * cell
        tx, ty = np.meshgrid(cols_x, yy)
        sx, sy, _ = inv.transform(tx.ravel(), ty.ravel(), np.full(tx.size, zmid))
        h = dsm.height_at(sx, sy)
        ok = np.isfinite(h)
        if ok.any():
            _, _, th = fwd.transform(sx[ok], sy[ok], h[ok])
            block = np.full(tx.size, np.nan)
            block[ok] = th
            heights[r0:r1] = block.reshape(tx.shape)
    LOG.info(
        "DSM reprojected from '%s' to '%s': %d x %d cells of %g",
        dsm.crs.name,
        dst.name,
        out.rows,
        out.cols,
        cell,
    )
    return Dsm(heights, out, dst, dsm.source)
