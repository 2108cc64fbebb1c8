"""Variance components of the automatic line points (issue 32): the points of one LiDAR line
in one image (a segment) share an error (the image edge against the LiDAR line as seen from
that image: shading, the edge's blur, the line's own error along it) that the per-point sigma
of the segment's straight fit cannot carry. :func:`~.boresight.calibrate` gives each segment an
offset and a tilt across the line as nuisance unknowns with priors
(``BoresightOptions.line_segment_sigmas_px``); this module estimates the three variances (the
points' scale, the offsets' and the tilts' sigma) from an adjustment's residuals.

Each component c is re-estimated as ``s_c^2 * sum(v' P v)_c / sum(r)_c`` (Foerstner's form of
Helmert's variance component estimation: the weighted residuals of the component against its
redundancy numbers), with ``v' P v = w^2 r`` row by row (Baarda's w at the a-priori unit weight,
diagonal weights). Iterated over the automatic calibration's rounds, the estimate converges to
the variances that make each component's share of the redundancy fit as well as its sigmas say.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .boresight_result import BoresightResult

__all__ = ["LineVariances", "line_variances"]

#: a component is re-estimated only with at least this much redundancy (else kept)
MIN_REDUNDANCY = 5.0


@dataclass(frozen=True)
class LineVariances:
    """Estimated factor on the line points' sigma_px (``scale``), the segments' offset and
    tilt sigmas (pixels), and each component's redundancy (``r``: points, offsets, tilts)."""

    scale: float
    offset_px: float
    tilt_px: float
    r: tuple[float, float, float]


def _ratio(tables, names, cols=None) -> tuple[float, float]:
    """(sum w^2 r, sum r) over the kept rows of the named blocks (``cols(table)``: the columns
    to take, all by default)."""
    num = den = 0.0
    for name in names:
        t = tables[name]
        sl = slice(None) if cols is None else cols(t)
        w, r = t.w[:, sl], t.redundancy_numbers[:, sl]
        ok = ~t.rejected[:, None] & np.isfinite(w) & np.isfinite(r)
        num += float(np.sum(np.where(ok, w * w * r, 0.0)))
        den += float(np.sum(np.where(ok, r, 0.0)))
    return num, den


def line_variances(result: BoresightResult, sigmas: tuple[float, float]) -> LineVariances:
    """The variance components after ``result`` (a calibration with the segment nuisances at
    ``sigmas`` (offset, tilt) px): a component with too little redundancy keeps its value."""
    tables = result.adjustment.residuals
    lines = [n for n in tables if n.startswith("line points k=")]

    def pixels(t):
        return slice(0, len(t.row_names) - 6)

    out = []
    for names, cols, old in (
        (lines, pixels, 1.0),
        (["line segment offsets"], None, sigmas[0]),
        (["line segment tilts"], None, sigmas[1]),
    ):
        names = [n for n in names if n in tables]
        num, den = _ratio(tables, names, cols)
        factor = np.sqrt(num / den) if den >= MIN_REDUNDANCY and num > 0 else 1.0
        out.append((float(old * factor), den))
    return LineVariances(out[0][0], out[1][0], out[2][0], (out[0][1], out[1][1], out[2][1]))
