"""Scale bars and measured distances between object points, as observations of a bundle
adjustment (:mod:`.bundle`).

A bar ``k`` between points ``a`` and ``b`` observes ``d_k = |X_a - X_b|`` with standard
deviation ``sigma_k``; its Jacobian is ``[u', -u']`` with the unit vector
``u = (X_a - X_b) / d``. Distances are given in the unit of the frame of the ground points
(metres in a mapping CRS, which the local ENU adjustment frame keeps as true lengths; m or mm
in a local engineering frame) and converted to the adjustment frame's metres. With a free
network the bars carry the scale: the inner constraints drop their scale row and the minimal
constraints hold six parameters instead of seven (:mod:`.bundle_model`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..lsq.model import GaussMarkovBlock
from ..lsq.results import AdjustmentResult

Array = NDArray[np.float64]

#: Name of the scale bars' observation block (key of the adjustment's residual tables).
BLOCK_NAME = "scale bars"


@dataclass(frozen=True)
class ScaleBars:
    """Measured distances between pairs of object points.

    Attributes
    ----------
    point_a, point_b : tuple of str, shape (B,)
        The end points (point ids of the observation table).
    distance, sigma : ndarray, shape (B,)
        Measured distance and its standard deviation, frame units (> 0).
    rows : tuple of int
        Row of each bar in its file (for error messages), or ().
    source : str
        The file the bars come from.
    """

    point_a: tuple[str, ...]
    point_b: tuple[str, ...]
    distance: Array
    sigma: Array
    rows: tuple[int, ...] = ()
    source: str = ""

    def __len__(self) -> int:
        return len(self.point_a)

    def where(self, k: int) -> dict:
        """``path`` and ``row`` of bar ``k`` for an :class:`InputError`."""
        return {"path": self.source or None, "row": self.rows[k] if self.rows else None}

    @property
    def labels(self) -> list[str]:
        return [f"{a} - {b}" for a, b in zip(self.point_a, self.point_b)]


@dataclass(frozen=True)
class BarSetup:
    """The bars of one block: adjusted point numbers of their ends, metres."""

    bars: ScaleBars
    a: NDArray[np.intp]
    b: NDArray[np.intp]
    distance_m: Array
    sigma_m: Array
    metres: float  # length of one frame unit, metres


def setup_bars(
    bars: ScaleBars, points: Sequence[str], check_ids: Sequence[str], metres: float
) -> BarSetup:
    """Number the bars' end points among the adjusted ``points``; refuse a bar on a point
    that is not adjusted (unknown, or a check point), naming its row.

    >>> bars = ScaleBars(("A",), ("B",), np.array([1000.0]), np.array([0.01]))
    >>> s = setup_bars(bars, ["A", "B"], [], 1e-3)
    >>> float(s.distance_m[0]), s.a.tolist(), s.b.tolist()
    (1.0, [0], [1])
    """
    num = {p: i for i, p in enumerate(points)}
    checks = set(check_ids)
    ends = []
    for k, pair in enumerate(zip(bars.point_a, bars.point_b)):
        for p in pair:
            if p in checks:
                raise InputError(
                    f"scale bar {bars.labels[k]}: point '{p}' is a check point, which the "
                    "adjustment keeps out; a bar needs adjusted (tie or control) points",
                    **bars.where(k),
                )
            if p not in num:
                raise InputError(
                    f"scale bar {bars.labels[k]}: point '{p}' is not measured in any image",
                    **bars.where(k),
                )
        ends.append((num[pair[0]], num[pair[1]]))
    ab = np.array(ends, dtype=np.intp).reshape(-1, 2)
    return BarSetup(bars, ab[:, 0], ab[:, 1], bars.distance * metres, bars.sigma * metres, metres)


class DistanceModel:
    """``d = |X_a - X_b|`` of groups ``x_local = [X_a(3), X_b(3)]``, its Jacobian ``[u', -u']``."""

    def __call__(self, xl: Array) -> tuple[Array, Array]:
        diff = xl[:, :3] - xl[:, 3:6]
        d = np.linalg.norm(diff, axis=1)
        u = diff / np.where(d > 0, d, 1.0)[:, None]
        return d[:, None], np.concatenate([u, -u], axis=1)[:, None, :]


def bar_block(bars: BarSetup, point_index: NDArray[np.intp]) -> GaussMarkovBlock:
    """The observation block of the bars; ``point_index`` (P, 3) the points' parameters."""
    return GaussMarkovBlock(
        name=BLOCK_NAME,
        observed=bars.distance_m[:, None],
        sigma=bars.sigma_m[:, None],
        param_index=np.concatenate([point_index[bars.a], point_index[bars.b]], axis=1),
        model=DistanceModel(),
        labels=bars.bars.labels,
        row_names=("distance",),
    )


@dataclass(frozen=True)
class BarResult:
    """The bars after the adjustment, frame units.

    Attributes
    ----------
    bars : ScaleBars
    adjusted, sigma : ndarray, shape (B,)
        Adjusted distance and its standard deviation (from the points' covariance).
    v : ndarray, shape (B,)
        Residual, adjusted minus observed.
    w, redundancy : ndarray, shape (B,)
        Baarda's w-test and the redundancy number (NaN when not computed).
    rejected : ndarray of bool, shape (B,)
        Rejected by data snooping.
    """

    bars: ScaleBars
    adjusted: Array
    sigma: Array
    v: Array
    w: Array
    redundancy: Array
    rejected: NDArray[np.bool_]


def bar_result(bars: BarSetup, res: AdjustmentResult, point_index: NDArray[np.intp]) -> BarResult:
    """The adjusted distances with their sigmas, residuals and tests of one adjustment."""
    x = res.x
    n = len(bars.a)
    adjusted = np.zeros(n)
    sigma = np.full(n, np.nan)
    for k in range(n):
        ia, ib = point_index[bars.a[k]], point_index[bars.b[k]]
        diff = x[ia] - x[ib]
        d = float(np.linalg.norm(diff))
        adjusted[k] = d
        u = np.concatenate([diff, -diff]) / d
        cov = res.covariance_of(np.concatenate([ia, ib]))
        sigma[k] = math.sqrt(max(float(u @ cov @ u), 0.0))
    table = res.residuals[BLOCK_NAME]
    s = bars.metres
    return BarResult(
        bars.bars,
        adjusted / s,
        sigma / s,
        np.asarray(table.v)[:, 0] / s,
        np.asarray(table.w)[:, 0],
        np.asarray(table.redundancy_numbers)[:, 0],
        np.asarray(table.rejected, dtype=bool),
    )
