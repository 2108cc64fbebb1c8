"""The LiDAR accuracy report (:mod:`.lidar_accuracy`) as one self-contained HTML page: the
verdicts with their reasons, the swath pairs, the within-swath precision, the NVA/VVA check
points, histograms and a map of the overlap differences (SVG)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .. import __version__
from .html_table import escape, table
from .lidar_accuracy import LidarAccuracyReport, pair_rows
from .svg_plots import histogram

_CSS = """
body{font-family:sans-serif;margin:24px;color:#222;max-width:1200px}
h1{font-size:22px}h2{font-size:18px;border-bottom:1px solid #aaa;margin-top:28px}
table{border-collapse:collapse;margin:8px 0}td,th{border:1px solid #ccc;padding:3px 8px;
text-align:right}td.t,th.t{text-align:left}tr.pass td{background:#e6f4e6}
tr.fail td{background:#f8dede}tr.insufficient td{background:#fff3cd}
"""


def _m(v: Any, digits: int = 4) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "&ndash;"
    return f"{float(v):.{digits}f}"


def _pct(v: Any) -> str:
    return "&ndash;" if v is None else f"{100 * float(v):.2f} %"


def _pairs_table(report: LidarAccuracyReport) -> str:
    rows = []
    for r in pair_rows(report):
        tilt = r["tilt"] or {}
        rows.append(
            [
                escape(f"{r['swath_a']} - {r['swath_b']}"),
                str(r["n"]),
                _m(r["mean"]),
                _m(r["std"]),
                _m(r["rmsdz"]),
                _m(r["max_abs"]),
                _m(r["rmsd_normal"]),
                _pct(r.get("share_over_rmsdz_limit")),
                _pct(r.get("share_over_max_limit")),
                _m(1000 * tilt["gx"], 3) if tilt else "&ndash;",
                _m(1000 * tilt["gy"], 3) if tilt else "&ndash;",
                _m(None if r["cross_track_slope"] is None else 1000 * r["cross_track_slope"], 3),
            ]
        )
    o = report.overall
    rows.append(
        [
            "all pairs",
            str(o["n"]),
            _m(o["mean"]),
            _m(o["std"]),
            _m(o["rmsdz"]),
            _m(o["max_abs"]),
            _m(o["rmsd_normal"]),
            _pct(o.get("share_over_rmsdz_limit")),
            _pct(o.get("share_over_max_limit")),
            "",
            "",
            "",
        ]
    )
    head = [
        "swaths a - b",
        "cells",
        "mean dz (m)",
        "std (m)",
        "RMSDz (m)",
        "max |dz| (m)",
        "normal RMSD (m)",
        "share > 0.8 x class",
        "share > 1.6 x class",
        "tilt dz/dx (mm/m)",
        "tilt dz/dy (mm/m)",
        "cross-track (mm/m)",
    ]
    return table(head, rows)


#: Most cells the map draws (one SVG rectangle each); more are averaged in square blocks.
MAP_MAX_CELLS = 20000


def _map(report: LidarAccuracyReport, limit: float) -> str:
    """Cells of every pair coloured by dz (diverging, +-limit), north up; on a large survey
    the mean dz of blocks of f x f cells (f chosen to draw at most MAP_MAX_CELLS)."""
    g = report.grid
    rows = np.concatenate([p.cells // g.cols for p in report.pairs])
    cols = np.concatenate([p.cells % g.cols for p in report.pairs])
    dz = np.concatenate([p.dz for p in report.pairs])
    f = max(1, math.ceil(math.sqrt(dz.size / MAP_MAX_CELLS)))
    while True:  # sparse cells: grow the blocks until few enough are drawn
        bcols = -(-g.cols // f)
        blocks, inv = np.unique((rows // f) * bcols + cols // f, return_inverse=True)
        if blocks.size <= MAP_MAX_CELLS:
            break
        f += 1
    mean = np.bincount(inv, weights=dz) / np.bincount(inv)
    w = 480
    scale = w * f / max(g.cols, 1)
    h = math.ceil(g.rows * w / max(g.cols, 1))
    t = np.clip(mean / limit, -1, 1) if limit > 0 else np.zeros_like(mean)
    rects = []
    for b, v in zip(blocks, t):
        r, c = divmod(int(b), bcols)
        red = 255 if v > 0 else int(255 * (1 + v))
        blue = 255 if v < 0 else int(255 * (1 - v))
        green = int(255 * (1 - abs(v)))
        rects.append(
            f'<rect x="{c * scale:.2f}" y="{r * scale:.2f}" width="{scale:.2f}" '
            f'height="{scale:.2f}" fill="rgb({red},{green},{blue})"/>'
        )
    what = "dz of every pair" if f == 1 else f"mean dz of {f} x {f} cells, every pair"
    return (
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" '
        f'style="border:1px solid #ccc;background:#f4f4f4">{"".join(rects)}</svg>'
        f"<p>{what} (red: a above b), colour limit &plusmn;{limit:.3f} m</p>"
    )


def render_html(report: LidarAccuracyReport) -> str:
    """The report as one HTML document (UTF-8 text)."""
    o = report.options
    c = report.cells
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>LiDAR accuracy</title><style>{_CSS}</style></head><body>",
        "<h1>LiDAR product accuracy (ASPRS Positional Accuracy Standards, Ed. 2, 2023)</h1>",
        table(
            ["item", "value"],
            [
                ["cloud", escape(report.source)],
                [
                    "swaths",
                    escape(
                        f"{len(report.swath_counts)} from {report.swath_method}: "
                        + ", ".join(f"{k} ({v} returns)" for k, v in report.swath_counts.items())
                    ),
                ],
                [
                    "grid",
                    escape(
                        f"{report.grid.cols} x {report.grid.rows} cells of {report.grid.cell:g}"
                    ),
                ],
                ["cells fitted / smooth", f"{c.n.size} / {int(np.count_nonzero(c.smooth))}"],
                ["cells rejected", escape(", ".join(f"{k} {v}" for k, v in c.rejected.items()))],
                [
                    "smooth cell",
                    escape(
                        f">= {o.min_points} single returns of one swath, no class "
                        f"{o.vegetation_classes}, slope <= {o.max_slope_deg:g} deg, "
                        f"plane rms <= {o.max_residual:g} m, step to a "
                        f"neighbour <= {o.max_step:g} m"
                    ),
                ],
                ["sign convention", "dz = swath a &minus; swath b; dz = LiDAR &minus; check point"],
                ["created", escape(f"lidarphoto {__version__}")],
            ],
        ),
        "<h2>Verdicts</h2>",
        table(
            ["condition", "status", "reason"],
            [[escape(v.name), escape(v.status), escape(v.reason)] for v in report.verdicts],
            [v.status for v in report.verdicts],
        ),
        "<h2>Swath overlap difference (smooth hard cells)</h2>",
        _pairs_table(report),
    ]
    if report.pairs:
        dz = np.concatenate([p.dz for p in report.pairs])
        lim = 1.6 * o.v_class_cm / 100.0 if o.v_class_cm > 0 else float(np.max(np.abs(dz)))
        parts.append(histogram(dz, title="swath overlap dz (m)", xlabel="dz (m)"))
        parts.append(_map(report, lim))
    parts.append("<h2>Within-swath precision (smooth-surface repeatability)</h2>")
    parts.append(
        table(
            [
                "swath",
                "smooth cells",
                "residual rms (m)",
                "median Max Diff (m)",
                "95th pct Max Diff (m)",
                "max Max Diff (m)",
            ],
            [
                [
                    str(p.swath),
                    str(p.cells),
                    _m(p.rms),
                    _m(p.range_median),
                    _m(p.range_p95),
                    _m(p.range_max),
                ]
                for p in report.precision
            ],
        )
    )
    f = report.vertical
    if f is not None and report.checkpoints is not None:
        cp = report.checkpoints
        parts.append("<h2>Absolute vertical accuracy (TIN of ground returns)</h2>")
        parts.append(
            table(
                ["figure", "NVA", "VVA"],
                [
                    ["check points", str(f.nva_n), str(f.vva_n)],
                    ["mean dz (m)", _m(f.nva_mean), ""],
                    ["std (m)", _m(f.nva_std), ""],
                    ["RMSE of the dz (m)", _m(f.nva_rmse_v1), _m(f.vva_rmse)],
                    ["RMSE_V with the survey sigma (m)", _m(f.nva_rmse_v), ""],
                    ["1.96 RMSE_V (Ed. 1 / NSSDA 95 %, m)", _m(f.nva_95), ""],
                    ["95th percentile of |dz| (Ed. 1 VVA, m)", "", _m(f.vva_p95)],
                ],
            )
        )
        rows = [
            [
                escape(i),
                _m(p[0], 3),
                _m(p[1], 3),
                _m(p[2]),
                escape(g),
                "VVA" if v else "NVA",
                _m(p[2] + d),
                _m(d),
            ]
            for i, p, g, v, d in zip(cp.ids, cp.xyz, cp.groups, f.vegetated, f.dz)
        ]
        parts.append(table(["id", "e", "n", "h", "group", "class", "LiDAR h", "dz (m)"], rows))
        ok = np.isfinite(f.dz)
        if ok.sum() > 1:
            parts.append(histogram(f.dz[ok], title="check points dz (m)", xlabel="dz (m)"))
    if report.notes:
        parts.append("<h2>Notes</h2><ul>")
        parts += [f"<li>{escape(n)}</li>" for n in report.notes]
        parts.append("</ul>")
    parts.append(
        '<p>Limits (our reading of ASPRS Ed. 2 section 7, docs/formats.md "LiDAR accuracy"): '
        "within-swath Max Diff &le; 0.6, swath-to-swath RMSDz &le; 0.8 and max difference "
        "&le; 1.6 times the vertical class; NVA RMSE_V &le; the class with at least 30 check "
        "points; VVA reported only.</p></body></html>"
    )
    return "\n".join(parts)
