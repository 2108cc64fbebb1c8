"""Checks of parameter values against the data, made before the heavy work starts.

The spec (:mod:`.spec`) bounds each number to its physical range; these checks bound what
depends on the data: a cell or window size against the extent of the data, and the memory a
grid or a batch will take against what the machine has free (the error gives both figures).
Every message names the parameter, so the user knows what to change.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence

from ..errors import InputError

#: Bytes per grid cell that the ground filter holds at its peak (measured with tracemalloc on
#: 1 M and 4 M cells: 60-75 B; rounded up).
GROUND_FILTER_BYTES_PER_CELL = 80
#: Bytes per point of the ground filter besides the coordinates it reads (indices, heights,
#: flags; measured about 30 B).
GROUND_FILTER_BYTES_PER_POINT = 64
#: Bytes per cell of a DSM made from a cloud plus its ray-casting pyramid (measured 36-39 B).
DSM_BYTES_PER_CELL = 48
#: Share of the free memory a job may plan to use (the rest is for the OS, QGIS, the arrays
#: not counted).
MEMORY_SHARE = 0.8


def available_memory() -> int | None:
    """Bytes of memory the machine can give without swapping, or None when unknown.

    Linux: ``MemAvailable`` of /proc/meminfo; elsewhere the free pages of ``os.sysconf``.
    """
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (AttributeError, OSError, ValueError):
        return None


def size_text(n_bytes: float) -> str:
    """``1.6e9`` -> ``"1.6 GB"``.

    >>> size_text(1.6e9), size_text(3.2e6), size_text(512)
    ('1.6 GB', '3.2 MB', '512 B')
    """
    for unit, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n_bytes >= size:
            return f"{n_bytes / size:.1f} {unit}"
    return f"{int(n_bytes)} B"


def check_memory(need: float, what: str, fix: str, available: int | None = None) -> None:
    """Refuse (InputError) when ``need`` bytes exceed the usable share of the free memory.

    ``what`` says what takes the memory (naming the parameter), ``fix`` what to change.

    >>> try:
    ...     check_memory(1e9, "CELL_SIZE 0.01 m: a 3e4 x 3e4 grid", "use a larger cell", 4e8)
    ... except InputError as exc:
    ...     print(exc)  # doctest: +NORMALIZE_WHITESPACE
    CELL_SIZE 0.01 m: a 3e4 x 3e4 grid needs about 1.0 GB of memory; 400.0 MB is free:
    use a larger cell
    """
    free = available_memory() if available is None else available
    if free is not None and need > MEMORY_SHARE * free:
        raise InputError(
            f"{what} needs about {size_text(need)} of memory; {size_text(free)} is free: {fix}"
        )


def grid_shape(mins: Sequence[float], maxs: Sequence[float], cell: float) -> tuple[int, int]:
    """Rows and columns of the grid of ``cell`` covering the box (as ``Grid.covering``).

    >>> grid_shape((0, 0), (10, 4), 1.0)
    (6, 11)
    """
    from ..geometry.grid import Grid

    grid = Grid.covering(mins, maxs, cell)
    return grid.rows, grid.cols


def check_cell_size(
    name: str,
    cell: float,
    unit: str,
    mins: Sequence[float],
    maxs: Sequence[float],
    bytes_per_cell: float,
    extra_bytes: float = 0.0,
    available: int | None = None,
) -> tuple[int, int]:
    """Refuse a cell size larger than the data's extent, or one whose grid would not fit in
    memory; returns the grid's (rows, columns).

    ``mins``/``maxs`` are the data's box (x, y) in the unit of ``cell``; ``extra_bytes`` the
    memory the run needs besides the grid (its points).

    >>> try:
    ...     check_cell_size("CELL_SIZE", 80.0, "m", (0, 0), (60, 40), 80)
    ... except InputError as exc:
    ...     print(exc)  # doctest: +NORMALIZE_WHITESPACE
    CELL_SIZE: 80 m is larger than the data's extent (60 x 40 m): give a cell smaller than
    the extent
    >>> check_cell_size("CELL_SIZE", 1.0, "m", (0, 0), (60, 40), 80)
    (42, 61)
    """
    width, height = maxs[0] - mins[0], maxs[1] - mins[1]
    if not (math.isfinite(width) and math.isfinite(height)):
        raise InputError(f"{name}: the data's extent is not finite")
    if cell > max(width, height):
        raise InputError(
            f"{name}: {cell:g} {unit} is larger than the data's extent ({width:.4g} x "
            f"{height:.4g} {unit}): give a cell smaller than the extent"
        )
    rows, cols = grid_shape(mins, maxs, cell)
    check_memory(
        float(rows) * cols * bytes_per_cell + extra_bytes,
        f"{name} {cell:g} {unit}: a grid of {rows} x {cols} cells over {width:.4g} x "
        f"{height:.4g} {unit}",
        "give a larger cell",
        available,
    )
    return rows, cols
