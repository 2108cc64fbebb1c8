"""Self-contained HTML page of an accuracy report (inline CSS and SVG, no external file).

Sections: summary, standards' verdicts, statistics and tests per group, outliers, plots
(discrepancy vectors, histograms, normal Q-Q plots), the list of points and the notes on
the sources of the standards' figures.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from .. import __version__
from .html_table import escape as _e
from .html_table import table as _table
from .svg_plots import histogram, qq_plot, vector_map

if TYPE_CHECKING:
    from .accuracy import AccuracyReport, GroupStatistics

__all__ = ["render_html"]

_CSS = """
body{font-family:sans-serif;margin:24px;color:#222;max-width:1200px}
h1{font-size:22px}h2{font-size:18px;border-bottom:1px solid #aaa;margin-top:28px}
h3{font-size:15px}
table{border-collapse:collapse;margin:8px 0 16px 0;font-size:13px}
th,td{border:1px solid #bbb;padding:3px 7px;text-align:right}
th{background:#eee}td.t,th.t{text-align:left}
.pass{background:#d8f0d8}.fail{background:#f7d4d4}.insufficient{background:#fbecc4}
.info{background:#e6eef8}.plots svg{margin:4px;border:1px solid #ddd}
.note{font-size:12px;color:#444}
"""


def _m(x: float | None, digits: int = 3) -> str:
    if x is None or not math.isfinite(float(x)):
        return "&ndash;"
    return f"{float(x):.{digits}f}"


def _stats_table(g: GroupStatistics) -> str:
    rows = []
    for key, label in (
        ("E", "dE"),
        ("N", "dN"),
        ("U", "dU"),
        ("HORIZONTAL", "dHorizontal"),
        ("3D", "d3D"),
    ):
        c = g.components[key]
        rows.append(
            [label, str(c.n), _m(c.mean), _m(c.std), _m(c.rmse), _m(c.minimum), _m(c.maximum)]
        )
    return _table(["component", "n", "mean (m)", "std (m)", "RMSE (m)", "min (m)", "max (m)"], rows)


def _tests_table(g: GroupStatistics) -> str:
    rows, css = [], []
    for key in ("E", "N", "U"):
        c = g.components[key]
        sw, bt, pt = c.normality, c.bias, c.precision
        rows.append(
            [
                f"d{key}",
                _m(sw.statistic, 4) if sw else "&ndash;",
                _m(sw.p_value, 4) if sw else "&ndash;",
                _e(
                    "normal"
                    if sw and sw.normal
                    else ("not normal" if sw and sw.normal is False else "not tested")
                ),
                _m(bt.t, 3) if bt else "&ndash;",
                _m(bt.critical, 3) if bt else "&ndash;",
                _m(bt.p_value, 4) if bt else "&ndash;",
                _e(
                    "bias"
                    if bt and bt.biased
                    else ("no bias" if bt and bt.biased is False else "not tested")
                ),
                _m(pt.chi2, 3) if pt else "&ndash;",
                _m(pt.critical, 3) if pt else "&ndash;",
                _e(
                    ("accepted" if pt.accepted else "rejected") + f" (sigma0 {pt.sigma0:g} m)"
                    if pt and pt.accepted is not None
                    else "not tested"
                ),
            ]
        )
        bad = (sw and sw.normal is False) or (bt and bt.biased) or (pt and pt.accepted is False)
        css.append("fail" if bad else "pass")
    return _table(
        [
            "component",
            "Shapiro-Wilk W",
            "p",
            "decision",
            "Student t",
            "t critical",
            "p",
            "decision",
            "chi-square",
            "chi-square critical",
            "decision",
        ],
        rows,
        css,
    )


def _standard_section(res) -> str:
    rows = [
        [
            _e(v.name),
            _e(v.status.upper()),
            "&ndash;"
            if v.measured is None
            else (_m(v.measured, 3) + (" " + _e(v.unit) if v.unit != "m" else " m")),
            "&ndash;"
            if v.limit is None
            else (_m(v.limit, 3) + (" " + _e(v.unit) if v.unit != "m" else " m")),
            _e(v.reason),
        ]
        for v in res.verdicts
    ]
    css = [v.status for v in res.verdicts]
    notes = "".join(f'<li class="note">{_e(n)}</li>' for n in res.notes)
    return (
        f'<h3 class="standard" id="std-{_e(res.key)}">{_e(res.title)}</h3>'
        f'<p class="note">Source: {_e(res.reference)}. {res.n_points} check points.</p>'
        + _table(["check", "status", "measured", "limit", "reason"], rows, css)
        + (f"<ul>{notes}</ul>" if notes else "")
    )


def _summary(report: AccuracyReport) -> str:
    """The RMSEs, and beside them those of the other choice when points were flagged."""
    if report.contrast is None:
        return _table(["RMSE", "value (m)"], [[k, _m(v, 4)] for k, v in report.rmse.items()])
    other = report.rmse_contrast
    head = [
        "RMSE",
        f"{_e(report.overall.name)}, used (m)",
        f"{_e(report.contrast.name)} (m)",
    ]
    rows = [[k, _m(v, 4), _m(other[k], 4)] for k, v in report.rmse.items()]
    return _table(head, rows)


def render_html(report: AccuracyReport) -> str:
    """The report as one HTML document (UTF-8 text)."""
    pts = report.points
    s = report.settings
    d = report.discrepancies
    used = report.used
    flagged = np.flatnonzero(report.outliers.any)
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>{_e(s.title)}</title><style>{_CSS}</style></head><body>",
        f"<h1>{_e(s.title)}</h1>",
        _table(
            ["item", "value"],
            [
                ["check points", f"{len(pts)} ({int(used.sum())} in the statistics)"],
                ["source", _e(pts.source)],
                ["CRS", _e(pts.crs or "not stated")],
                ["sign convention", "d = measured &minus; reference, metres"],
                ["significance level", f"{s.alpha:g}"],
                ["created", _e(f"{report.created}, lidarphoto {__version__}")],
            ],
        ),
        "<h2>Summary</h2>",
        _summary(report),
        "<h2>Standards</h2>",
    ]
    if report.standards:
        parts.extend(_standard_section(r) for r in report.standards)
    else:
        parts.append("<p>No standard was selected.</p>")
    if report.group_thresholds:
        parts.append("<h3>Project threshold per group</h3>")
        rows, css = [], []
        for g, res in report.group_thresholds.items():
            for v in res.verdicts:
                rows.append([_e(g), _e(v.name), _e(v.status.upper()), _e(v.reason)])
                css.append(v.status)
        parts.append(_table(["group", "check", "status", "reason"], rows, css))
    parts.append("<h2>Statistics</h2>")
    parts.append(f'<h3 class="group">{_e(report.overall.name.capitalize())} '
                 f"({report.overall.n})</h3>")  # fmt: skip
    parts.append(_stats_table(report.overall))
    parts.append(_tests_table(report.overall))
    if report.contrast is not None:
        parts.append(f'<h3 class="group">For comparison: {_e(report.contrast.name)} '
                     f"({report.contrast.n})</h3>")  # fmt: skip
        parts.append(_stats_table(report.contrast))
    for name, g in report.groups.items():
        parts.append(f'<h3 class="group">Group {_e(name)} ({g.n})</h3>')
        parts.append(_stats_table(g))
        parts.append(_tests_table(g))
    parts.append("<h2>Outliers</h2>")
    parts.append(
        f"<p>Rule: {_e(report.outliers.description)}. "
        + (
            f"{len(flagged)} point(s) flagged: "
            + ", ".join(_e(pts.ids[k]) for k in flagged)
            + (
                "; excluded from the statistics and the standards."
                if s.exclude_outliers
                else "; kept in the statistics (not excluded)."
            )
            if len(flagged)
            else "No point flagged."
        )
        + "</p>"
    )
    parts.append('<h2>Plots</h2><div class="plots">')
    labels = list(pts.ids)
    parts.append(
        vector_map(
            pts.reference[:, 0],
            pts.reference[:, 1],
            d[:, 0],
            d[:, 1],
            d[:, 2],
            labels,
            report.outliers.any,
        )
    )
    parts.append('</div><div class="plots">')
    for k, c in enumerate("ENH"):
        parts.append(histogram(d[used, k], title=f"Histogram of d{c}", xlabel=f"d{c} (m)"))
    parts.append('</div><div class="plots">')
    for k, c in enumerate("ENH"):
        parts.append(qq_plot(d[used, k], title=f"Normal Q-Q plot of d{c}"))
    parts.append("</div>")
    parts.append("<h2>Check points</h2>")
    rows, css = [], []
    for k in range(len(pts)):
        rows.append(
            [
                _e(pts.ids[k]),
                _e(pts.groups[k]),
                _m(d[k, 0]),
                _m(d[k, 1]),
                _m(d[k, 2]),
                _m(report.horizontal[k]),
                _m(report.d3[k]),
                "yes" if report.outliers.any[k] else "no",
                "yes" if used[k] else "no",
            ]
        )
        css.append("fail" if report.outliers.any[k] else "")
    parts.append(
        _table(
            [
                "id",
                "group",
                "dE (m)",
                "dN (m)",
                "dU (m)",
                "dHorizontal (m)",
                "d3D (m)",
                "outlier",
                "used",
            ],
            rows,
            css,
        )
    )
    parts.append(
        '<h2>Notes</h2><ul class="note">'
        "<li>Statistics: standard deviation with n &minus; 1; RMSE = sqrt(mean(d&sup2;)); "
        "Shapiro-Wilk by scipy (Royston's algorithm); Student t two-sided for a zero mean; "
        "chi-square one-sided, (n &minus; 1) s&sup2; / sigma0&sup2; against chi-square(1 &minus; "
        "alpha, n &minus; 1).</li>"
        "<li>Figures marked <i>uncertain</i> in the verdicts come from our reading of the "
        "standard or from secondary sources; check them against the official text before a "
        "contractual statement.</li>"
        "<li>Status INSUFFICIENT: the standard needs more check points than were given; the "
        "figures are computed but no conformance is claimed.</li></ul>"
    )
    parts.append("</body></html>")
    return "\n".join(parts)
