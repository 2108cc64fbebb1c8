"""Coordinates as LAS point records hold them (integers with a scale and an offset per axis),
read a block at a time: what :func:`core.io.pointcloud` hands to the ground filter instead of
float64 arrays of every point.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray


@dataclass(frozen=True)
class ScaledXYZ:
    """Coordinates as LAS point records hold them: integers, ``x = X * scale + offset``
    (float64, the LAS rule), in chunks in point order. The filter reads them a block at a time
    instead of float64 x, y, z arrays of every point (240 MB at 10 M points, and the page
    faults of fresh memory).

    Attributes
    ----------
    chunks : sequence of (X, Y, Z)
        (N_k,) integer arrays each (e.g. views of the records' X, Y, Z fields).
    scales, offsets : tuple of 3 float
        Of x, y, z.
    """

    chunks: tuple[tuple[NDArray[Any], NDArray[Any], NDArray[Any]], ...]
    scales: tuple[float, float, float]
    offsets: tuple[float, float, float]

    def __len__(self) -> int:
        return sum(len(c[0]) for c in self.chunks)

    def axis(self, k: int) -> NDArray[np.float64]:
        """Coordinate ``k`` (0 x, 1 y, 2 z) of every point as one float64 array."""
        out = np.empty(len(self), dtype=np.float64)
        done = 0
        for chunk in self.chunks:
            part = out[done : done + len(chunk[k])]
            np.multiply(chunk[k], float(self.scales[k]), out=part)
            part += float(self.offsets[k])
            done += len(part)
        return out

    def bounds(
        self, integers: NDArray[np.int64] | None = None
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(3,) minima and maxima of the scaled coordinates (exactly those of :meth:`axis`:
        rounding is monotonic, so the extreme integers give the extreme coordinates);
        ``integers``: the (3, 2) extreme integers when already known."""
        if integers is None:
            nonempty = [c for c in self.chunks if len(c[0])]
            integers = np.array(
                [
                    [min(int(c[k].min()) for c in nonempty), max(int(c[k].max()) for c in nonempty)]
                    for k in range(3)
                ],
                dtype=np.int64,
            )
        ends = integers.astype(np.float64)
        ends *= np.asarray(self.scales, dtype=np.float64)[:, None]
        ends += np.asarray(self.offsets, dtype=np.float64)[:, None]
        return ends.min(axis=1), ends.max(axis=1)
