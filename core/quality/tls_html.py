"""HTML report of a terrestrial laser scanner self-calibration (one self-contained page).

Sections: the failed checks (when there are), the settings, the adjustment's statistics
(with the rejections against data snooping's false alarms), the additional parameters with
their significance, the stations, the strongly correlated pairs with the network design that
breaks them (Lichti 2010), the correlation matrix of the APs and the station parameters
(coloured by |r|), the automatic AP selection, the residuals per component and the largest
w-tests.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from .. import __version__
from ..lsq.results import RejectionTest
from ..tls.aps import ARCSEC
from ..tls.calibration import TlsCalibration
from ..tls.diagnosis import explain_pair
from .html_table import TR_CONTEXT, failed_checks, html_lang, rejections_explained, report_css, t  # noqa: F401 - TR_CONTEXT: i18n
from .html_table import escape as _e
from .html_table import table as _table

__all__ = ["render_tls_html"]

_CSS = report_css(
    1200,
    (
        ".diag{background:#fbecc4;padding:8px}\n"
        "table.corr td{padding:2px 4px;font-size:11px}"
        "table.corr th{font-size:11px;padding:2px 4px}\n"
        ".note{font-size:12px;color:#444}"
        ".alarm{background:#f7d4d4;border:2px solid #c33;padding:8px}"
    ),
)


def _design() -> str:
    """How the network design breaks the correlations (Lichti 2010), translated."""
    return t(
        "Correlations between the APs and the station parameters (Lichti 2010) come from the "
        "network design, not the instrument: the rangefinder offset a0 with the station "
        "positions when the targets lie on one side or in a narrow vertical band; the collimation "
        "error b1 with kappa when the targets are near the horizon (sec(alpha) is then about 1); "
        "the trunnion-axis error b2 and the vertical index c0 with omega and phi. They are broken "
        "by targets all around the scanner and over the full vertical range (floor and ceiling), "
        "by two-face observations, and by stations whose scanner is tilted by about 90 degrees "
        "(which turn elevations into horizontal directions). A levelled scanner's compensator "
        "observes omega and phi and helps b2 and c0."
    )


def _n(x: float, digits: int = 2) -> str:
    x = float(x)
    return f"{x:.{digits}f}" if math.isfinite(x) else "&ndash;"


def _colour(r: float) -> str:
    """White (0) to red (|r| = 1)."""
    if not math.isfinite(r):
        return "#ddd"
    a = min(abs(r), 1.0)
    g = int(255 - 200 * a)
    return f"rgb(255,{g},{g})"


def _correlation_table(names: Sequence[str], corr: np.ndarray, n_ap: int) -> str:
    """AP rows against every AP and station-parameter column; without APs, the station
    parameters against themselves."""
    rows_idx = list(range(n_ap)) if n_ap else list(range(len(names)))
    head = "".join(f"<th>{_e(n)}</th>" for n in names)
    body = []
    for i in rows_idx:
        cells = "".join(
            f'<td style="background:{_colour(corr[i, j])}">{_n(corr[i, j], 2)}</td>'
            for j in range(len(names))
        )
        body.append(f'<tr><th class="t">{_e(names[i])}</th>{cells}</tr>')
    return (
        f'<div style="overflow-x:auto"><table class="corr"><thead><tr><th></th>{head}'
        f"</tr></thead><tbody>{''.join(body)}</tbody></table></div>"
    )


def _residual_parts(cal: TlsCalibration) -> list[str]:
    """The residuals section: the RMS per component and the ten largest |w|."""
    v = cal.residuals[~cal.rejected]
    rms = np.sqrt(np.nanmean(v**2, axis=0)) if v.size else np.full(3, np.nan)
    out = [
        f"<h2>{t('Residuals')}</h2>",
        _table(
            [t("component"), "RMS", t("unit")],
            [
                (t("range"), _n(rms[0] * 1000, 3), "mm"),
                (t("horizontal direction"), _n(rms[1] / ARCSEC, 2), t("arc-seconds")),
                (t("vertical angle"), _n(rms[2] / ARCSEC, 2), t("arc-seconds")),
            ],
        ),
    ]
    w = np.nan_to_num(np.abs(cal.w), nan=0.0).max(axis=1)
    worst = np.argsort(-w)[:10]
    obs = cal.observations
    out.append(
        _table(
            [
                t("station / target"),
                t("row"),
                t("v range mm"),
                'v hz "',
                'v vt "',
                "max |w|",
                t("rejected"),
            ],
            [
                (
                    _e(f"{obs.station[k]} / {obs.target[k]}"),
                    str(int(obs.rows[k])),
                    _n(cal.residuals[k, 0] * 1000, 3),
                    _n(cal.residuals[k, 1] / ARCSEC, 2),
                    _n(cal.residuals[k, 2] / ARCSEC, 2),
                    _n(w[k], 2),
                    t("yes") if cal.rejected[k] else t("no"),
                )
                for k in worst
            ],
            ["fail" if cal.rejected[k] else "" for k in worst],
        )
    )
    return out


def _refused() -> str:
    return t(
        "The calibration FAILED its checks: no table and no registered scan were written. "
        "The numbers below show the failed adjustment, for diagnosis only."
    )


def _adjustment_parts(cal: TlsCalibration, rejections: RejectionTest | None) -> list[str]:
    """The adjustment section: sigma0, the global test (with the rejections against data
    snooping's false alarms), iterations and the datum."""
    adj = cal.adjustment
    gt = adj.global_test
    test = t("passed") if gt.passed else t("failed")
    if gt.passed and rejections is not None and not rejections.passed:
        test = t("passed, but only after more rejections than false alarms explain")
    return [
        f"<h2>{t('Adjustment')}</h2>",
        _table(
            [t("quantity"), t("value")],
            [
                (t("observations (station-target-face)"), str(len(cal.observations))),
                (t("stations / targets"), f"{len(cal.stations)} / {len(cal.targets)}"),
                (t("redundancy"), str(adj.redundancy)),
                (t("sigma0 a-posteriori"), _n(cal.sigma0, 3)),
                (
                    t("global chi-square test"),
                    f"{test} ({_n(gt.lower, 1)} &le; {_n(gt.statistic, 1)} &le; {_n(gt.upper, 1)})",
                ),
                (
                    t("iterations"),
                    f"{adj.iterations} ({t('converged') if adj.converged else t('NOT')})",
                ),
                (t("observations rejected (data snooping)"), str(int(cal.rejected.sum()))),
                *(
                    [
                        (
                            t("rejections explained by false alarms"),
                            rejections_explained(rejections),
                        )
                    ]
                    if rejections is not None
                    else []
                ),
                (
                    t("datum"),
                    ", ".join(cal.datum_fixed)
                    or (
                        t("control")
                        if any(k != "free" for k in cal.target_kind)
                        else t("inner constraints")
                    ),
                ),
            ],
            [
                "",
                "",
                "",
                "",
                "pass" if gt.passed and (rejections is None or rejections.passed) else "fail",
                "",
                "",
                "" if rejections is None or rejections.passed else "fail",
            ],
        ),
    ]


def _ap_parts(cal: TlsCalibration) -> list[str]:
    """The additional parameters' section: values, sigmas, t-tests (none without APs)."""
    out: list[str] = []
    if cal.ap_names:
        rows, css = [], []
        for a in cal.ap_report():
            d = 2 if a["unit"] != "mm" else 3
            rows.append(
                (
                    _e(a["name"]),
                    _e(a["formula"]),
                    _e(a["cause"]),
                    _n(a["value"], d),
                    _n(a["std"], d),
                    _n(a["std_prior"], d),
                    _e(a["unit"]),
                    _n(a["t"], 2),
                    t("yes") if a["significant"] else t("no"),
                )
            )
            css.append("" if a["significant"] else "fail")
        out += [
            f"<h2>{t('Additional parameters')}</h2>",
            _table(
                [
                    t("AP"),
                    t("term"),
                    t("cause"),
                    t("value"),
                    "sigma",
                    t("sigma a-priori"),
                    t("unit"),
                    "t",
                    t("significant"),
                ],
                rows,
                css,
            ),
            "<p class='note'>"
            + t(
                "t = |value| / sigma against the Student-t critical value {} (two-sided, alpha "
                "= {}). sigma is scaled by sigma0; sigma a-priori is the Cramer-Rao bound of the "
                "network for the observation sigmas given."
            ).format(_n(cal.t_critical, 2), f"{cal.options.significance_alpha:g}")
            + "</p>",
        ]
    return out


def _station_parts(cal: TlsCalibration) -> list[str]:
    """The stations' section: poses (m, deg) and their sigmas (mm, arc seconds)."""
    out: list[str] = []
    srows = []
    for k, s in enumerate(cal.stations):
        p, sd = cal.pose[k], cal.pose_std[k]
        srows.append(
            (
                _e(s),
                *(_n(x, 4) for x in p[:3]),
                *(_n(math.degrees(x), 6) for x in p[3:]),
                *(_n(x * 1000, 2) for x in sd[:3]),
                *(_n(x / ARCSEC, 2) for x in sd[3:]),
                t("yes") if cal.levelled[k] else t("no"),
            )
        )
    out += [
        f"<h2>{t('Stations')}</h2>",
        _table(
            [
                t("station"),
                "X m",
                "Y m",
                "Z m",
                "omega deg",
                "phi deg",
                "kappa deg",
                "s_X mm",
                "s_Y mm",
                "s_Z mm",
                's_omega "',
                's_phi "',
                's_kappa "',
                t("levelled"),
            ],
            srows,
        ),
    ]
    return out


def render_tls_html(
    cal: TlsCalibration,
    settings: Mapping[str, str],
    problems: Sequence[object] = (),
    accepted: bool = True,
    rejections: RejectionTest | None = None,
) -> str:
    """The report page of a calibration (str, UTF-8 HTML); ``problems``: why it failed its
    checks (written anyway when ``accepted``), ``rejections``: the test of the number of
    rejected observations against snooping's false alarms."""
    adj = cal.adjustment
    out = [
        f"<!DOCTYPE html><html lang='{html_lang()}'><head><meta charset='utf-8'>",
        f"<title>{t('TLS self-calibration')}</title>",
        f"<style>{_CSS}</style></head><body>",
        f"<h1>{t('Terrestrial laser scanner: registration and self-calibration')}</h1>",
        f"<p class='note'>lidarphoto {_e(__version__)}. "
        + t(
            "Model: Carvalho, Correa &amp; dos Santos (Eqs. 1-5), additional parameters after "
            "Lichti (2007), correlation analysis after Lichti (2010)."
        )
        + "</p>",
        *failed_checks(problems, accepted, _refused()),
        f"<h2>{t('Settings')}</h2>",
        _table([t("setting"), t("value")], [(_e(k), _e(v)) for k, v in settings.items()]),
    ]
    out += _adjustment_parts(cal, rejections)
    out += _ap_parts(cal)
    out += _station_parts(cal)
    out.append(f"<h2>{t('Correlations')}</h2>")
    if cal.strong_pairs:
        prow = [
            (_e(a), _e(b), _n(r, 3), _e(explain_pair(a, b) or ""))
            for a, b, r in cal.strong_pairs[:30]
        ]
        limit = f"{cal.options.correlation_limit:g}"
        out.append("<p>" + t("Pairs with |r| &ge; {}:").format(limit) + "</p>")
        out.append(
            _table(
                [t("parameter"), t("parameter"), "r", t("why, and the design that breaks it")], prow
            )
        )
    else:
        limit = f"{cal.options.correlation_limit:g}"
        out.append("<p>" + t("No pair involving an AP reaches |r| = {}.").format(limit) + "</p>")
    out.append(f"<p class='diag'>{_e(_design())}</p>")
    if np.isfinite(cal.calib_correlation).any():
        out.append(_correlation_table(cal.calib_names, cal.calib_correlation, len(cal.ap_names)))
    if cal.selection:
        out += [
            f"<h2>{t('Automatic AP selection')}</h2>",
            _table(
                [t("removed"), t("why"), t("remaining")],
                [
                    (_e(s.removed), _e(s.reason), _e(", ".join(s.remaining) or t("none")))
                    for s in cal.selection
                ],
            ),
        ]
    out += _residual_parts(cal)
    if adj.warnings:
        out.append(
            f"<h2>{t('Warnings')}</h2><ul>"
            + "".join(f"<li>{_e(t(x))}</li>" for x in adj.warnings)
            + "</ul>"
        )
    out.append("</body></html>")
    return "\n".join(out)
