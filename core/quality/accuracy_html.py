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
from .html_table import TR_CONTEXT, html_lang, report_css, t  # noqa: F401 - TR_CONTEXT: make i18n
from .html_table import escape as _e
from .html_table import table as _table
from .svg_plots import histogram, qq_plot, vector_map

if TYPE_CHECKING:
    from .accuracy import AccuracyReport
    from .accuracy_statistics import GroupStatistics

__all__ = ["render_html"]


_CSS = report_css(
    1200,
    (
        ".insufficient{background:#fbecc4}\n"
        ".info{background:#e6eef8}.plots svg{margin:4px;border:1px solid #ddd}\n"
        ".note{font-size:12px;color:#444}"
    ),
    h2_top_px=28,
    h3="h3{font-size:15px}",
)


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
    head = [
        t("component"),
        "n",
        t("mean (m)"),
        t("std (m)"),
        "RMSE (m)",
        t("min (m)"),
        t("max (m)"),
    ]
    return _table(head, rows)


def _figures(test: object | None, *fields: tuple[str, int]) -> list[str]:
    """The figures ``(attribute, decimals)`` of a test's result; dashes for a test not run."""
    return [_m(getattr(test, name) if test else None, digits) for name, digits in fields]


def _decision(flag: bool | None, yes: str, no: str) -> str:
    """A test's decision: ``yes`` when ``flag`` holds, ``no`` when it is False, else not tested."""
    return _e(yes if flag else (no if flag is False else t("not tested")))


def _tests_table(g: GroupStatistics) -> str:
    rows, css = [], []
    for key in ("E", "N", "U"):
        c = g.components[key]
        sw, bt, pt = c.normality, c.bias, c.precision
        rows.append(
            [
                f"d{key}",
                *_figures(sw, ("statistic", 4), ("p_value", 4)),
                _decision(sw.normal if sw else None, t("normal"), t("not normal")),
                *_figures(bt, ("t", 3), ("critical", 3), ("p_value", 4)),
                _decision(bt.biased if bt else None, t("bias"), t("no bias")),
                *_figures(pt, ("chi2", 3), ("critical", 3)),
                _e(
                    (t("accepted") if pt.accepted else t("rejected")) + f" (sigma0 {pt.sigma0:g} m)"
                    if pt and pt.accepted is not None
                    else t("not tested")
                ),
            ]
        )
        bad = (sw and sw.normal is False) or (bt and bt.biased) or (pt and pt.accepted is False)
        css.append("fail" if bad else "pass")
    return _table(
        [
            t("component"),
            "Shapiro-Wilk W",
            "p",
            t("decision"),
            t("Student t"),
            t("t critical"),
            "p",
            t("decision"),
            t("chi-square"),
            t("chi-square critical"),
            t("decision"),
        ],
        rows,
        css,
    )


def _status(status: str) -> str:
    """A verdict's status in capitals, in the report's language."""
    words = {
        "pass": t("PASS"),
        "fail": t("FAIL"),
        "insufficient": t("INSUFFICIENT"),
        "info": t("INFO"),
    }
    return _e(words.get(status, status.upper()))


def _standard_section(res) -> str:
    rows = [
        [
            _e(t(v.name)),
            _status(v.status),
            "&ndash;"
            if v.measured is None
            else (_m(v.measured, 3) + (" " + _e(v.unit) if v.unit != "m" else " m")),
            "&ndash;"
            if v.limit is None
            else (_m(v.limit, 3) + (" " + _e(v.unit) if v.unit != "m" else " m")),
            _e(t(v.reason)),
        ]
        for v in res.verdicts
    ]
    css = [v.status for v in res.verdicts]
    notes = "".join(f'<li class="note">{_e(t(n))}</li>' for n in res.notes)
    return (
        f'<h3 class="standard" id="std-{_e(res.key)}">{_e(t(res.title))}</h3>'
        + '<p class="note">'
        + t("Source: {}. {} check points.").format(_e(res.reference), res.n_points)
        + "</p>"
        + _table([t("check"), t("status"), t("measured"), t("limit"), t("reason")], rows, css)
        + (f"<ul>{notes}</ul>" if notes else "")
    )


def _summary(report: AccuracyReport) -> str:
    """The RMSEs, and beside them those of the other choice when points were flagged."""
    if report.contrast is None:
        return _table(["RMSE", t("value (m)")], [[k, _m(v, 4)] for k, v in report.rmse.items()])
    other = report.rmse_contrast
    head = [
        "RMSE",
        t("{}, used (m)").format(_e(t(report.overall.name))),
        f"{_e(t(report.contrast.name))} (m)",
    ]
    rows = [[k, _m(v, 4), _m(other[k], 4)] for k, v in report.rmse.items()]
    return _table(head, rows)


def _plot_parts(report: AccuracyReport) -> list[str]:
    """The plots section: the vector map, then the histograms and Q-Q plots of dE, dN, dH."""
    pts, d, used = report.points, report.discrepancies, report.used
    parts: list[str] = []
    parts.append(f'<h2>{t("Plots")}</h2><div class="plots">')
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
        title = t("Histogram of {}").format(f"d{c}")
        parts.append(histogram(d[used, k], title=title, xlabel=f"d{c} (m)"))
    parts.append('</div><div class="plots">')
    for k, c in enumerate("ENH"):
        parts.append(qq_plot(d[used, k], title=t("Normal Q-Q plot of {}").format(f"d{c}")))
    parts.append("</div>")
    return parts


def render_html(report: AccuracyReport) -> str:
    """The report as one HTML document (UTF-8 text)."""
    pts = report.points
    s = report.settings
    d = report.discrepancies
    used = report.used
    flagged = np.flatnonzero(report.outliers.any)
    parts = [
        "<!DOCTYPE html>",
        f'<html lang="{html_lang()}"><head><meta charset="utf-8">',
        f"<title>{_e(t(s.title))}</title><style>{_CSS}</style></head><body>",
        f"<h1>{_e(t(s.title))}</h1>",
        _table(
            [t("item"), t("value")],
            [
                [
                    t("check points"),
                    t("{} ({} in the statistics)").format(len(pts), int(used.sum())),
                ],
                [t("source"), _e(pts.source)],
                [t("CRS"), _e(pts.crs or t("not stated"))],
                [t("sign convention"), t("d = measured &minus; reference, metres")],
                [t("significance level"), f"{s.alpha:g}"],
                [t("created"), _e(f"{report.created}, lidarphoto {__version__}")],
            ],
        ),
        f"<h2>{t('Summary')}</h2>",
        _summary(report),
        f"<h2>{t('Standards')}</h2>",
    ]
    if report.standards:
        parts.extend(_standard_section(r) for r in report.standards)
    else:
        parts.append(f"<p>{t('No standard was selected.')}</p>")
    if report.group_thresholds:
        parts.append(f"<h3>{t('Project threshold per group')}</h3>")
        rows, css = [], []
        for g, res in report.group_thresholds.items():
            for v in res.verdicts:
                rows.append([_e(g), _e(t(v.name)), _status(v.status), _e(t(v.reason))])
                css.append(v.status)
        parts.append(_table([t("group"), t("check"), t("status"), t("reason")], rows, css))
    parts.append(f"<h2>{t('Statistics')}</h2>")
    parts.append(
        f'<h3 class="group">{_e(t(report.overall.name).capitalize())} ({report.overall.n})</h3>'
    )
    parts.append(_stats_table(report.overall))
    parts.append(_tests_table(report.overall))
    if report.contrast is not None:
        parts.append(
            '<h3 class="group">'
            + t("For comparison: {} ({})").format(_e(t(report.contrast.name)), report.contrast.n)
            + "</h3>"
        )
        parts.append(_stats_table(report.contrast))
    for name, stats in report.groups.items():
        parts.append('<h3 class="group">' + t("Group {} ({})").format(_e(name), stats.n) + "</h3>")
        parts.append(_stats_table(stats))
        parts.append(_tests_table(stats))
    parts.append(f"<h2>{t('Outliers')}</h2>")
    parts.append(
        "<p>"
        + t("Rule: {}.").format(_e(report.outliers.description))
        + " "
        + (
            t("{} point(s) flagged: ").format(len(flagged))
            + ", ".join(_e(pts.ids[k]) for k in flagged)
            + (
                t("; excluded from the statistics and the standards.")
                if s.exclude_outliers
                else t("; kept in the statistics (not excluded).")
            )
            if len(flagged)
            else t("No point flagged.")
        )
        + "</p>"
    )
    parts.extend(_plot_parts(report))
    parts.append(f"<h2>{t('Check points')}</h2>")
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
                t("yes") if report.outliers.any[k] else t("no"),
                t("yes") if used[k] else t("no"),
            ]
        )
        css.append("fail" if report.outliers.any[k] else "")
    parts.append(
        _table(
            [
                "id",
                t("group"),
                "dE (m)",
                "dN (m)",
                "dU (m)",
                "dHorizontal (m)",
                "d3D (m)",
                t("outlier"),
                t("used"),
            ],
            rows,
            css,
        )
    )
    notes = (
        t(
            "Statistics: standard deviation with n &minus; 1; RMSE = sqrt(mean(d&sup2;)); "
            "Shapiro-Wilk by scipy (Royston's algorithm); Student t two-sided for a zero mean; "
            "chi-square one-sided, (n &minus; 1) s&sup2; / sigma0&sup2; against chi-square(1 "
            "&minus; alpha, n &minus; 1)."
        ),
        t(
            "Figures marked <i>uncertain</i> in the verdicts come from our reading of the "
            "standard or from secondary sources; check them against the official text before a "
            "contractual statement."
        ),
        t(
            "Status INSUFFICIENT: the standard needs more check points than were given; the "
            "figures are computed but no conformance is claimed."
        ),
    )
    parts.append(
        f'<h2>{t("Notes")}</h2><ul class="note">'
        + "".join(f"<li>{n}</li>" for n in notes)
        + "</ul>"
    )
    parts.append("</body></html>")
    return "\n".join(parts)
