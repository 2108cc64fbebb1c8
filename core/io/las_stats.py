"""The header statistics laspy's writer recomputes for every chunk it writes (bounds and points
per return number), in one compiled pass over the packed records.

``laspy.LasWriter.write_points`` grows the header chunk by chunk: six strided reductions of X, Y
and Z, two of the GPS time (kept in laspy's header object, not in the file) and a sort
(``np.unique``) of the return numbers: about 0.2 s per 10 M points, on one thread, while the
encoder waits. :class:`HeaderStats` computes the same per-chunk integers in one pass and applies
them with laspy's own arithmetic (``max(header, chunk_max * scale + offset)`` per chunk, return
number 0 and numbers above the header's 15 slots not counted), so the file written is byte for
byte laspy's (tests/core/test_pointcloud.py).
Without numba, or for records laspy's writer treats specially (extra-bytes VLRs, whose
statistics it grows too), :func:`HeaderStats.for_writer` returns None: laspy's own path.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..compiled import Kernels
from ..geometry.raycast_numba import AVAILABLE

__all__ = ["HeaderStats"]


def _chunk_stats(xs, ys, zs, bits, mask, lsb, ints, counts):
    """ints <- (min X, max X, min Y, max Y, min Z, max Z); counts[v] += points with return
    number v ((bits & mask) >> lsb)."""
    n = xs.shape[0]
    if n == 0:
        return
    lo_x = hi_x = xs[0]
    lo_y = hi_y = ys[0]
    lo_z = hi_z = zs[0]
    for i in range(n):
        x, y, z = xs[i], ys[i], zs[i]
        lo_x = min(lo_x, x)
        hi_x = max(hi_x, x)
        lo_y = min(lo_y, y)
        hi_y = max(hi_y, y)
        lo_z = min(lo_z, z)
        hi_z = max(hi_z, z)
        counts[(bits[i] & mask) >> lsb] += 1
    ints[0], ints[1], ints[2], ints[3], ints[4], ints[5] = lo_x, hi_x, lo_y, hi_y, lo_z, hi_z


#: The jitted chunk statistics (compiled at its first call, cached: core/compiled.py).
_compiled = Kernels({"stats": _chunk_stats})


class HeaderStats:
    """What ``LasWriter.write_points`` grows in the header, for the chunks passed to :meth:`add`
    (written meanwhile with ``writer.point_writer.write_points``); :meth:`apply` sets it."""

    def __init__(self, writer: Any) -> None:
        h = writer.header
        self._fmt = h.point_format
        self._max_count = int(h.max_point_count())
        self._scales = [h.x_scale, h.y_scale, h.z_scale]
        self._offsets = [h.x_offset, h.y_offset, h.z_offset]
        self._mins = list(h.mins)
        self._maxs = list(h.maxs)
        self._counts = np.zeros(16, np.int64)
        self._n = int(h.point_count)

    @classmethod
    def for_writer(cls, writer: Any) -> HeaderStats | None:
        """The fast path for this laspy writer, or None (laspy's own ``write_points``)."""
        if not AVAILABLE or not hasattr(writer, "point_writer"):
            return None
        if writer.header.vlrs.get("ExtraBytesVlr"):  # laspy grows their statistics too
            return None
        import laspy

        try:  # the laspy internals used here (2.x): else laspy's own path
            view = laspy.PackedPointRecord.zeros(1, writer.header.point_format).return_number
            view.array, int(view.bit_mask), int(view.lsb)
        except (AttributeError, TypeError):
            return None
        return cls(writer)

    def add(self, points: Any) -> None:
        """Take a ``laspy.PackedPointRecord`` about to be written (checks as laspy's)."""
        import laspy

        if points.point_format != self._fmt:
            raise laspy.LaspyException("Incompatible point formats")
        m = len(points)
        if self._max_count - self._n < m:
            raise laspy.LaspyException(
                f"Cannot write {m} points: the file can hold {self._max_count}, it has {self._n}"
            )
        if m == 0:
            return
        a = points.array
        rn = points.return_number  # laspy's bit-field view: its byte array, mask, shift
        ints = np.zeros(6, np.int64)
        _compiled("stats")(
            a["X"], a["Y"], a["Z"], rn.array, int(rn.bit_mask), int(rn.lsb), ints, self._counts
        )
        for k in range(3):  # laspy's arithmetic: max(header, chunk's max * scale + offset)
            self._maxs[k] = max(
                self._maxs[k], np.int64(ints[2 * k + 1]) * self._scales[k] + self._offsets[k]
            )
            self._mins[k] = min(
                self._mins[k], np.int64(ints[2 * k]) * self._scales[k] + self._offsets[k]
            )
        self._n += m

    def apply(self, header: Any) -> None:
        """Set the writer's header to what laspy's per-chunk growth would have made."""
        header.mins = np.array(self._mins, np.float64)
        header.maxs = np.array(self._maxs, np.float64)
        by_return = header.number_of_points_by_return
        for r in range(1, min(len(by_return), 15) + 1):
            by_return[r - 1] += int(self._counts[r])
        header.point_count = self._n
