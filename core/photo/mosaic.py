"""Orthomosaics: several orthophotos of one grid into one, each cell from the image that sees it
best, with optional feathering along the seamlines.

Choice of the image (per cell, among the orthophotos that have data there):

- ``nadir``: the smallest off-nadir angle, ``tan = d_h / (Z_c - z_ref)`` with ``d_h`` the
  horizontal distance from the cell to the perspective centre (X_c, Y_c, Z_c) and ``z_ref``
  the mean ground height of the block (from the orthophotos' metadata). The seamlines are then
  those of a Voronoi diagram of the nadir points, bent around the no-data of each orthophoto;
- ``centre``: the smallest distance to where the image's principal ray meets the ground (for
  orthophotos without the perspective centre in their metadata, to the raster's centre).

True orthophotos have no data where the ground is occluded: the next best image that sees the
cell fills it (occlusion-aware mosaicking).

Feathering over ``feather_px`` cells: each image k gets the weight ``clip(0.5 + s_k /
feather, 0, 1)`` where it has data, ``s_k`` being the signed distance (cells, positive inside)
to the border of the region where k was chosen; weights are normalised. Across a seamline
between two images the weights go linearly from 1 to 0 over ``feather_px`` cells, centred
on the seamline; along a border with no data the image keeps its full weight.

Orthophotos must share the CRS and the cell size and be aligned on multiples of it (as
:func:`core.photo.orthophoto.ortho_grid` makes them).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..geometry.grid import Grid
from .ortho_options import MOSAIC_METHODS as METHODS
from .ortho_options import MosaicOptions
from .orthophoto import ordered_map, tile_windows

#: read(k, (col0, row0, cols, rows)) -> (data (bands, rows, cols), valid (rows, cols)) of
#: orthophoto k in its own pixels
ReadSource = Callable[[int, tuple[int, int, int, int]], tuple[NDArray, NDArray[np.bool_]]]

__all__ = ["METHODS", "MosaicOptions", "MosaicSource", "MosaicTile", "mosaic_grid", "mosaic_tiles"]


@dataclass(frozen=True)
class MosaicSource:
    """One orthophoto of a mosaic.

    Attributes
    ----------
    name : str
    grid : Grid
        Its raster (mapping CRS).
    centre : (X, Y, Z) or None
        The perspective centre (metadata LIDARPHOTO_CENTRE of :mod:`core.jobs.orthorectify`).
    ground_z : float or None
        Median ground height of its footprint (LIDARPHOTO_GROUND_Z).
    principal_ground : (x, y) or None
        Where the principal ray meets that height (LIDARPHOTO_PRINCIPAL_GROUND).
    """

    name: str
    grid: Grid
    centre: tuple[float, float, float] | None = None
    ground_z: float | None = None
    principal_ground: tuple[float, float] | None = None


@dataclass(frozen=True)
class MosaicTile:
    """One tile of the mosaic: ``data`` (bands, rows, cols), ``valid`` (rows, cols) and
    ``label`` (rows, cols) int16: the index of the chosen orthophoto, -1 for no data."""

    row0: int
    col0: int
    data: NDArray
    valid: NDArray[np.bool_]
    label: NDArray[np.int16]


def _offset(src: Grid, grid: Grid) -> tuple[int, int]:
    """(col, row) of the source's first cell in ``grid``; InputError unless aligned."""
    fc = (src.x0 - grid.x0) / grid.cell
    fr = (grid.y_top - src.y_top) / grid.cell
    if abs(fc - round(fc)) > 1e-6 or abs(fr - round(fr)) > 1e-6:
        raise InputError(
            "the orthophotos are not aligned on one grid (cells shifted by "
            f"{fc - round(fc):.3f}, {fr - round(fr):.3f} of a cell): make them "
            "with the same GSD"
        )
    return round(fc), round(fr)


def mosaic_method(method: str, sources: Sequence[MosaicSource]) -> str:
    """The method of :data:`METHODS` the mosaic can use: ``nadir`` needs every orthophoto's
    perspective centre, else every cell takes the nearest image centre (``centre``): a nadir
    angle and a distance are not comparable scores, so one rule holds for all cells.

    >>> g = Grid(0.0, 1.0, 1.0, 1, 1)
    >>> mosaic_method("nadir", [MosaicSource("a", g, None, None, None)])
    'centre'
    """
    if method == "nadir" and any(s.centre is None for s in sources):
        return "centre"
    return method


def mosaic_grid(sources: Sequence[MosaicSource]) -> Grid:
    """The grid covering every orthophoto (they must share the cell and be aligned)."""
    if not sources:
        raise InputError("no orthophoto to mosaic")
    cell = sources[0].grid.cell
    for s in sources:
        if not math.isclose(s.grid.cell, cell, rel_tol=1e-9):
            raise InputError(
                f"orthophoto {s.name} has cells of {s.grid.cell:g}, "
                f"{sources[0].name} of {cell:g}: make them with one GSD"
            )
    x0 = min(s.grid.x0 for s in sources)
    y_top = max(s.grid.y_top for s in sources)
    x1 = max(s.grid.x0 + s.grid.cols * cell for s in sources)
    y1 = min(s.grid.y_top - s.grid.rows * cell for s in sources)
    grid = Grid(x0, y_top, cell, round((y_top - y1) / cell), round((x1 - x0) / cell))
    for s in sources:
        _offset(s.grid, grid)
    return grid


def _scores(src: MosaicSource, xs: NDArray, ys: NDArray, method: str, z_ref: float) -> NDArray:
    """(rows, cols) score of a source at cell centres ys x xs: lower is better. ``nadir``
    needs every source's centre (a tangent and a distance do not compare)."""
    if method == "nadir":
        if src.centre is None:
            raise InputError(
                f"orthophoto '{src.name}' has no perspective centre: use the method centre"
            )
        cx, cy, cz = src.centre
        height = max(cz - z_ref, 1e-6)
        return np.hypot(xs[None, :] - cx, ys[:, None] - cy) / height
    if src.principal_ground is not None and all(map(math.isfinite, src.principal_ground)):
        px, py = src.principal_ground
    else:
        g = src.grid
        px, py = g.x0 + g.cols * g.cell / 2, g.y_top - g.rows * g.cell / 2
    return np.hypot(xs[None, :] - px, ys[:, None] - py)


def _signed_distance(mask: NDArray[np.bool_]) -> NDArray[np.float32]:
    """Distance (cells) from each cell centre to the border of ``mask``: positive inside."""
    import cv2

    m = mask.astype(np.uint8)
    inside = cv2.distanceTransform(m, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
    outside = cv2.distanceTransform(1 - m, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
    # the border lies half a cell from the centres of the cells on either side of it
    return np.where(mask, inside - 0.5, 0.5 - outside).astype(np.float32)


def _tile(
    sources: Sequence[MosaicSource],
    offsets: list[tuple[int, int]],
    grid: Grid,
    win: tuple[int, int, int, int],
    read: ReadSource,
    bands: int,
    dtype: np.dtype,
    opt: MosaicOptions,
    z_ref: float,
) -> MosaicTile:
    row0, col0, rows, cols = win
    margin = math.ceil(opt.feather_px / 2) + 1 if opt.feather_px > 0 else 0
    er0, ec0 = max(row0 - margin, 0), max(col0 - margin, 0)
    er1, ec1 = min(row0 + rows + margin, grid.rows), min(col0 + cols + margin, grid.cols)
    h, w = er1 - er0, ec1 - ec0
    xs = grid.x0 + (ec0 + np.arange(w) + 0.5) * grid.cell
    ys = grid.y_top - (er0 + np.arange(h) + 0.5) * grid.cell
    best = np.full((h, w), np.inf)
    label = np.full((h, w), -1, np.int16)
    present: dict[int, tuple[NDArray, NDArray[np.bool_]]] = {}
    for k, (src, (oc, orow)) in enumerate(zip(sources, offsets)):
        # the overlap of the extended window and the source, in mosaic cells
        r_a, r_b = max(er0, orow), min(er1, orow + src.grid.rows)
        c_a, c_b = max(ec0, oc), min(ec1, oc + src.grid.cols)
        if r_a >= r_b or c_a >= c_b:
            continue
        data, valid = read(k, (c_a - oc, r_a - orow, c_b - c_a, r_b - r_a))
        if not valid.any():
            continue
        full_d = np.zeros((bands, h, w), dtype)
        full_v = np.zeros((h, w), bool)
        full_d[:, r_a - er0 : r_b - er0, c_a - ec0 : c_b - ec0] = data
        full_v[r_a - er0 : r_b - er0, c_a - ec0 : c_b - ec0] = valid
        score = np.where(full_v, _scores(src, xs, ys, opt.method, z_ref), np.inf)
        better = score < best
        best[better] = score[better]
        label[better] = k
        present[k] = (full_d, full_v)
    valid = label >= 0
    out = np.zeros((bands, h, w), dtype)
    if present and opt.feather_px > 0:
        acc = np.zeros((bands, h, w))
        wsum = np.zeros((h, w))
        for k, (d, v) in present.items():
            wk = np.clip(0.5 + _signed_distance(label == k) / opt.feather_px, 0.0, 1.0)
            wk = np.where(v, wk, 0.0)
            acc += wk * d
            wsum += wk
        with np.errstate(invalid="ignore", divide="ignore"):
            blend = acc / wsum
        if np.dtype(dtype).kind in "ui":
            info = np.iinfo(dtype)
            blend = np.clip(np.rint(blend), info.min, info.max)
        out = np.where(valid[None], np.nan_to_num(blend), 0).astype(dtype)
    else:
        for k, (d, _) in present.items():
            sel = label == k
            out[:, sel] = d[:, sel]
    cr, cc = row0 - er0, col0 - ec0
    return MosaicTile(
        row0,
        col0,
        np.ascontiguousarray(out[:, cr : cr + rows, cc : cc + cols]),
        valid[cr : cr + rows, cc : cc + cols],
        label[cr : cr + rows, cc : cc + cols],
    )


def mosaic_tiles(
    sources: Sequence[MosaicSource],
    grid: Grid,
    read: ReadSource,
    bands: int,
    dtype: np.dtype | type,
    options: MosaicOptions | None = None,
    *,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> Iterator[MosaicTile]:
    """The mosaic of ``sources`` on ``grid`` (:func:`mosaic_grid`), tile after tile.

    Parameters
    ----------
    sources : sequence of MosaicSource
    grid : Grid
    read : callable
        ``read(k, (col0, row0, cols, rows))`` -> (data (bands, rows, cols), valid (rows,
        cols)) of orthophoto k in its own pixels; called from several threads.
    bands, dtype
        Of the orthophotos (all the same).
    options : MosaicOptions
    progress, should_stop
        Fraction of tiles done; cancellation (checked per tile).
    """
    opt = options or MosaicOptions()
    offsets = [_offset(s.grid, grid) for s in sources]
    zs = [s.ground_z for s in sources if s.ground_z is not None and math.isfinite(s.ground_z)]
    z_ref = float(np.mean(zs)) if zs else 0.0
    windows = tile_windows(grid, opt.tile_px)
    kind = np.dtype(dtype)

    def one(win: tuple[int, int, int, int]) -> MosaicTile:
        return _tile(sources, offsets, grid, win, read, bands, kind, opt, z_ref)

    yield from ordered_map(one, windows, opt.workers, progress, should_stop, "mosaicking")
