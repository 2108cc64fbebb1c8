"""The LiDAR product accuracy check of ASPRS Ed. 2 (2023) in one call: swaths, smooth cells,
swath overlap differences, within-swath precision, and the NVA/VVA of check points, with the
standard's verdicts and their reasons (:mod:`.lidar_swaths`, :mod:`.lidar_vertical`; the
thresholds and what is our reading: :mod:`.lidar_accuracy_options`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError, stop_if_asked
from .lidar_accuracy_options import (
    NVA_MIN_CHECKPOINTS,
    SWATH_MAX_FACTOR,
    SWATH_RMSDZ_FACTOR,
    VVA_FACTOR,
    VVA_MIN_CHECKPOINTS,
    WITHIN_SWATH_FACTOR,
    LidarAccuracyOptions,
)
from .lidar_swaths import (
    CellGrid,
    PairDifference,
    SwathCells,
    SwathPrecision,
    difference_stats,
    identify_swaths,
    overlap_differences,
    relative_limits,
    swath_cells,
    swath_headings,
    within_swath_precision,
)
from .lidar_vertical import VerticalFigures, ground_tin_heights, vertical_figures
from .standards import _TOL, Verdict

__all__ = ["LIDAR_JSON_TOP_KEYS", "LidarAccuracyReport", "LidarCloud", "assess_lidar"]

#: The top-level keys of the JSON (docs/formats.md "LiDAR accuracy"); the last two only when
#: check points were given.
LIDAR_JSON_TOP_KEYS = (
    "standard",
    "source",
    "swath_method",
    "swaths",
    "grid",
    "cells",
    "pairs",
    "overall",
    "within_swath",
    "limits",
    "raster_bands",
    "verdicts",
    "notes",
    "options",
    "vertical",
    "check_points",
)


@dataclass(frozen=True)
class LidarCloud:
    """The returns the check needs, (N,) arrays; the optional ones None when absent."""

    x: NDArray[np.float64]
    y: NDArray[np.float64]
    z: NDArray[np.float64]
    classification: NDArray | None = None
    number_of_returns: NDArray | None = None
    point_source_id: NDArray | None = None
    gps_time: NDArray | None = None
    source: str = ""


@dataclass(frozen=True)
class CheckPointSet:
    """Surveyed check points: ids, (N, 3) e, n, h and a land-cover group each."""

    ids: tuple[str, ...]
    xyz: NDArray[np.float64]
    groups: tuple[str, ...]
    source: str = ""


@dataclass(frozen=True)
class LidarAccuracyReport:
    """Everything the HTML and JSON report show."""

    options: LidarAccuracyOptions
    swath_method: str
    swath_counts: dict[int, int]
    grid: CellGrid
    cells: SwathCells
    pairs: list[PairDifference]
    precision: list[SwathPrecision]
    overall: dict[str, float]
    verdicts: tuple[Verdict, ...]
    vertical: VerticalFigures | None = None
    checkpoints: CheckPointSet | None = None
    notes: tuple[str, ...] = field(default_factory=tuple)
    source: str = ""


def _cm(v: float) -> str:
    return "n/a" if not math.isfinite(v) else f"{100 * v:.2f} cm"


def _limit_verdict(name: str, value: float, limit: float, enough: bool, what: str) -> Verdict:
    if not math.isfinite(value):
        return Verdict(name, "insufficient", f"{what}: no value", None, limit)
    ok = value <= limit + _TOL
    status = ("pass" if ok else "fail") if enough else "insufficient"
    reason = f"{what} = {_cm(value)} {'<=' if ok else '>'} {_cm(limit)}"
    return Verdict(name, status, reason, value, limit)


def _class_met(value: float, factor: float) -> str:
    return f"meets a vertical class of at least {100 * value / factor:.2f} cm (x {factor:g})"


def _shares(dz: NDArray, limits: dict[str, float]) -> dict[str, float]:
    a = np.abs(dz)
    if a.size == 0:
        return {}
    return {
        "share_over_rmsdz_limit": float(np.mean(a > limits["swath_rmsdz"] + _TOL)),
        "share_over_max_limit": float(np.mean(a > limits["swath_max"] + _TOL)),
    }


def _relative_verdicts(
    pairs: list[PairDifference],
    overall: dict[str, float],
    precision: list[SwathPrecision],
    o: LidarAccuracyOptions,
    cells: SwathCells,
) -> list[Verdict]:
    out: list[Verdict] = []
    c = o.v_class_cm
    lim = relative_limits(c) if c > 0 else None
    named = [(f"swaths {p.swath_a}-{p.swath_b}", p.stats()) for p in pairs]
    named.append(("all swath pairs", overall))
    for name, st in named:
        enough = st["n"] >= o.min_pair_cells
        few = "" if enough else f"; only {st['n']} of {o.min_pair_cells} smooth cells"
        if lim is None:
            for what, key, factor in (
                ("RMSDz", "rmsdz", SWATH_RMSDZ_FACTOR),
                ("max |dz|", "max_abs", SWATH_MAX_FACTOR),
            ):
                v = st[key]
                out.append(
                    Verdict(
                        f"{name}: {what}",
                        "info" if enough else "insufficient",
                        f"{what} = {_cm(v)} on {st['n']} cells: {_class_met(v, factor)}{few}",
                        v,
                        None,
                    )
                )
            continue
        out.append(
            _limit_verdict(
                f"{name}: swath-to-swath RMSDz",
                st["rmsdz"],
                lim["swath_rmsdz"],
                enough,
                f"RMSDz on {st['n']} cells",
            )
        )
        out.append(
            _limit_verdict(
                f"{name}: swath-to-swath max difference",
                st["max_abs"],
                lim["swath_max"],
                enough,
                f"max |dz| on {st['n']} cells",
            )
        )
    for p in precision:
        name = f"swath {p.swath}: within-swath precision (Max Diff)"
        enough = p.cells >= o.min_pair_cells
        if lim is None:
            out.append(
                Verdict(
                    name,
                    "info" if enough else "insufficient",
                    f"largest cell range {_cm(p.range_max)} on {p.cells} cells "
                    f"(95th percentile {_cm(p.range_p95)}): "
                    f"{_class_met(p.range_max, WITHIN_SWATH_FACTOR)}",
                    p.range_max,
                    None,
                )
            )
        else:
            verdict = _limit_verdict(
                name,
                p.range_max,
                lim["within_swath_max"],
                enough,
                f"largest cell range on {p.cells} cells",
            )
            m = (cells.swath == p.swath) & cells.smooth
            share = (
                float(np.mean(cells.range[m] <= lim["within_swath_max"] + _TOL)) if p.cells else 0.0
            )
            out.append(
                replace(
                    verdict,
                    reason=f"{verdict.reason}; {share:.1%} of the cells "
                    f"within it, 95th percentile {_cm(p.range_p95)}",
                )
            )
    return out


def _vertical_verdicts(f: VerticalFigures, o: LidarAccuracyOptions) -> list[Verdict]:
    out = []
    enough = f.nva_n >= NVA_MIN_CHECKPOINTS
    out.append(
        Verdict(
            "NVA check-point count",
            "pass" if enough else "insufficient",
            f"{f.nva_n} non-vegetated check points; Ed. 2 requires at least {NVA_MIN_CHECKPOINTS}",
            float(f.nva_n),
            float(NVA_MIN_CHECKPOINTS),
            unit="points",
        )
    )
    if o.v_class_cm > 0:
        out.append(
            _limit_verdict(
                f"NVA class {o.v_class_cm:g}-cm",
                f.nva_rmse_v,
                o.v_class_cm / 100.0,
                enough,
                "RMSE_V",
            )
        )
    else:
        out.append(
            Verdict(
                "NVA class",
                "info" if enough else "insufficient",
                f"RMSE_V = {_cm(f.nva_rmse_v)}: meets any class of at least that",
                f.nva_rmse_v,
                None,
            )
        )
    vva_enough = f.vva_n >= VVA_MIN_CHECKPOINTS
    guide = (
        f"; the class's VVA guidance is {VVA_FACTOR:g} x {o.v_class_cm:g} cm"
        if o.v_class_cm > 0
        else ""
    )
    out.append(
        Verdict(
            "VVA (reported, no pass/fail in Ed. 2)",
            "info" if vva_enough else "insufficient",
            f"{f.vva_n} vegetated check points (at least {VVA_MIN_CHECKPOINTS}): "
            f"RMSE {_cm(f.vva_rmse)}, 95th percentile of |dz| {_cm(f.vva_p95)}"
            f"{guide}",
            f.vva_rmse,
            None,
        )
    )
    return out


def _swaths(cloud: LidarCloud, o: LidarAccuracyOptions) -> tuple[NDArray[np.int64], str]:
    return identify_swaths(cloud.point_source_id, cloud.gps_time, o.swath_source, o.gps_gap_s)


def assess_lidar(
    cloud: LidarCloud,
    options: LidarAccuracyOptions,
    checkpoints: CheckPointSet | None = None,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
    grid: CellGrid | None = None,
) -> LidarAccuracyReport:
    """Swath overlap differences, within-swath precision and (with check points) NVA/VVA.

    ``grid``: the cells (default: covering the points). Raises InputError for an empty cloud
    or a cell size that is not positive.
    """
    o = options
    if cloud.x.size == 0:
        raise InputError("the cloud has no points", path=cloud.source or None)
    swath, method = _swaths(cloud, o)
    names, counts = np.unique(swath, return_counts=True)
    grid = grid or CellGrid.covering(cloud.x, cloud.y, o.cell_size)
    stop_if_asked(should_stop, "fitting the cells")
    cells = swath_cells(
        cloud.x, cloud.y, cloud.z, swath, grid, o, cloud.classification, cloud.number_of_returns
    )
    if progress is not None:
        progress(0.6)
    headings = (
        swath_headings(swath, cloud.x, cloud.y, cloud.gps_time)
        if cloud.gps_time is not None
        else {}
    )
    ground = None
    if checkpoints is not None and len(checkpoints.ids):
        cls = cloud.classification
        keep = np.ones(cloud.x.size, bool) if cls is None else np.isin(cls, o.ground_classes)
        ground = np.column_stack([cloud.x[keep], cloud.y[keep], cloud.z[keep]])
    stop_if_asked(should_stop, "comparing the swaths")
    report = report_from_cells(
        cells,
        grid,
        o,
        method,
        {int(s): int(n) for s, n in zip(names, counts)},
        headings,
        checkpoints,
        ground,
        cloud.source,
    )
    if progress is not None:
        progress(1.0)
    return report


def report_from_cells(
    cells: SwathCells,
    grid: CellGrid,
    options: LidarAccuracyOptions,
    method: str,
    swath_counts: dict[int, int],
    headings: dict[int, float],
    checkpoints: CheckPointSet | None = None,
    ground_xyz: NDArray | None = None,
    source: str = "",
) -> LidarAccuracyReport:
    """The report from the swaths' cells (one process or joined tiles) and, with check
    points, the ground returns near them (N, 3)."""
    o = options
    pairs = overlap_differences(cells, grid, headings)
    precision = within_swath_precision(cells)
    all_dz = np.concatenate([p.dz for p in pairs]) if pairs else np.zeros(0)
    all_dn = np.concatenate([p.dn for p in pairs]) if pairs else np.zeros(0)
    overall = difference_stats(all_dz, all_dn)
    if o.v_class_cm > 0:
        overall.update(_shares(all_dz, relative_limits(o.v_class_cm)))
    verdicts = _relative_verdicts(pairs, overall, precision, o, cells)
    notes = [f"swaths from {method.replace('_', ' ')}: {len(swath_counts)} swaths"]
    if len(swath_counts) < 2:
        notes.append("one swath only: no overlap difference")
    vertical = None
    if checkpoints is not None and len(checkpoints.ids) and ground_xyz is not None:
        heights = ground_tin_heights(ground_xyz, checkpoints.xyz[:, :2], o.tin_radius)
        vertical = vertical_figures(
            checkpoints.ids, checkpoints.xyz[:, 2], checkpoints.groups, heights, o
        )
        verdicts += _vertical_verdicts(vertical, o)
        if vertical.outside:
            notes.append(
                f"{len(vertical.outside)} check point(s) outside the ground TIN, not "
                f"assessed: {', '.join(vertical.outside)}"
            )
    return LidarAccuracyReport(
        options=o,
        swath_method=method,
        swath_counts=swath_counts,
        grid=grid,
        cells=cells,
        pairs=pairs,
        precision=precision,
        overall=overall,
        verdicts=tuple(verdicts),
        vertical=vertical,
        checkpoints=checkpoints,
        notes=tuple(notes),
        source=source,
    )


def pair_rows(report: LidarAccuracyReport) -> list[dict[str, Any]]:
    """One dict per swath pair (and one for all pairs) of the figures the report prints."""
    rows: list[dict[str, Any]] = []
    lim = relative_limits(report.options.v_class_cm) if report.options.v_class_cm > 0 else None
    for p in report.pairs:
        st: dict[str, object] = {"swath_a": p.swath_a, "swath_b": p.swath_b, **p.stats()}
        if lim:
            st.update(_shares(p.dz, lim))
        st["tilt"] = None if p.tilt is None else dict(zip(("c0", "gx", "gy"), p.tilt))
        st["tilt_se"] = None if p.tilt_se is None else dict(zip(("c0", "gx", "gy"), p.tilt_se))
        st["cross_track_slope"] = p.cross_track_slope
        rows.append(st)
    return rows


def _finite(v: object) -> object:
    if isinstance(v, float) and not math.isfinite(v):
        return None
    if isinstance(v, dict):
        return {k: _finite(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_finite(x) for x in v]
    return v


def report_dict(report: LidarAccuracyReport, raster_bands: Sequence[str] = ()) -> dict:
    """Every figure of the report as JSON-ready data (NaN as null; metres)."""
    o = report.options
    rejected = report.cells.rejected
    d: dict[str, object] = {
        "standard": "ASPRS Positional Accuracy Standards, Edition 2, Version 1.0 (2023)",
        "source": report.source,
        "swath_method": report.swath_method,
        "swaths": {str(k): v for k, v in report.swath_counts.items()},
        "grid": {
            "x0": report.grid.x0,
            "y_top": report.grid.y_top,
            "cell": report.grid.cell,
            "cols": report.grid.cols,
            "rows": report.grid.rows,
        },
        "cells": {
            "fitted": int(report.cells.n.size),
            "smooth": int(np.count_nonzero(report.cells.smooth)),
            "rejected": dict(rejected),
        },
        "pairs": pair_rows(report),
        "overall": report.overall,
        "within_swath": [p.__dict__ for p in report.precision],
        "limits": relative_limits(o.v_class_cm) if o.v_class_cm > 0 else None,
        "raster_bands": list(raster_bands),
        "verdicts": [v.__dict__ for v in report.verdicts],
        "notes": list(report.notes),
        "options": {k: (list(v) if isinstance(v, tuple) else v) for k, v in o.__dict__.items()},
    }
    f = report.vertical
    if f is not None and report.checkpoints is not None:
        d["vertical"] = {
            k: getattr(f, k)
            for k in (
                "nva_n",
                "nva_mean",
                "nva_std",
                "nva_rmse_v1",
                "nva_rmse_v",
                "nva_95",
                "vva_n",
                "vva_rmse",
                "vva_p95",
            )
        }
        d["check_points"] = [
            {
                "id": i,
                "e": float(p[0]),
                "n": float(p[1]),
                "h": float(p[2]),
                "group": g,
                "vegetated": bool(v),
                "lidar_h": float(p[2] + dz),
                "dz": float(dz),
            }
            for i, p, g, v, dz in zip(
                report.checkpoints.ids,
                report.checkpoints.xyz,
                report.checkpoints.groups,
                f.vegetated,
                f.dz,
            )
        ]
    return {k: _finite(x) for k, x in d.items()}  # _finite(d), keeping the dict type
