"""Short self-contained HTML summary of a boresight calibration (inline CSS and SVG).

Sections: settings; the boresight per group in degrees and arc-seconds with a-posteriori and
a-priori standard deviations; lever arm, interior orientation and the camera timing offset
(ms, with its correlations) when estimated; sigma0,
redundancy and the global chi-square test; the correlation matrix of the calibration
parameters; rejected observations (Baarda data snooping); residual histograms in pixels.
When the set-up is not observable the page carries the diagnosis instead of numbers.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from .. import __version__
from .html_table import TR_CONTEXT, failed_checks, html_lang, report_css, t  # noqa: F401 - TR_CONTEXT: i18n
from .html_table import escape as _e
from .html_table import table as _table
from .svg_plots import histogram

if TYPE_CHECKING:
    from ..photo.boresight_result import BoresightRun

__all__ = ["render_boresight_html"]

ARCSEC_PER_RAD = 180.0 * 3600.0 / math.pi
_ANGLES = ("omega", "phi", "kappa")

_CSS = report_css(
    1100,
    (
        ".diag{background:#fbecc4;padding:8px}\n"
        ".plots svg{margin:4px;border:1px solid #ddd}.note{font-size:12px;color:#444}\n"
        ".alarm{background:#c62828;color:#fff;padding:8px 14px;font-size:15px}"
    ),
)


def _n(x: float | None, digits: int = 2) -> str:
    if x is None or not math.isfinite(float(x)):
        return "&ndash;"
    return f"{float(x):.{digits}f}"


def _value_table(
    head: list[str],
    names: Sequence[str],
    values: Sequence[float] | NDArray[np.float64],
    sigmas: Sequence[float] | NDArray[np.float64],
    digits: int,
) -> str:
    """A table of estimated parameters: one row a parameter, its value and sigma."""
    rows = [[a, _n(v, digits), _n(s, digits)] for a, v, s in zip(names, values, sigmas)]
    return _table(head, rows)


def _dms(rad: float) -> str:
    """Signed degrees, arc-minutes and arc-seconds, e.g. -0&deg;07'48.0"."""
    s = rad * ARCSEC_PER_RAD
    sign = "-" if s < 0 else "+"
    s = abs(s)
    d, rem = divmod(s, 3600.0)
    m, sec = divmod(rem, 60.0)
    return f"{sign}{int(d)}&deg;{int(m):02d}'{sec:04.1f}\""


def render_boresight_html(
    run: BoresightRun | None,
    settings: Mapping[str, str],
    diagnosis: Sequence[str] | None = None,
    *,
    problems: Sequence[str] = (),
    accepted: bool = False,
) -> str:
    """The HTML page as a string.

    Parameters
    ----------
    run : BoresightRun or None
        The calibration (None when it failed as not observable).
    settings : mapping of str to str
        Shown as given.
    diagnosis : sequence of str, optional
        Sentences of :class:`core.photo.boresight_result.BoresightNotObservable`; shown
        instead of results.
    problems : sequence of str
        Checks the result failed (no convergence, global test, implausible angles): shown in a
        red box at the top, saying whether the results were refused or written anyway
        (``accepted``).

    Examples
    --------
    >>> page = render_boresight_html(None, {"images": "6"}, ["kappa is not observable."])
    >>> "kappa is not observable." in page and page.startswith("<!DOCTYPE html>")
    True
    """
    parts = [
        "<!DOCTYPE html>",
        f'<html lang="{html_lang()}"><head><meta charset="utf-8">',
        f"<title>{t('Boresight calibration')}</title>",
        f"<style>{_CSS}</style></head><body>",
        f"<h1>{t('Boresight calibration')}</h1>",
        *_problems(problems, accepted),
        f'<p class="note">lidarphoto {_e(__version__)}. '
        + t(
            "Angles: d_omega, d_phi, d_kappa about the camera axes x, y, z (R_c^b = R_nominal "
            "dR); standard deviations are a-posteriori (scaled by sigma0) unless labelled "
            "a-priori."
        )
        + "</p>",
        f"<h2>{t('Settings')}</h2>",
        _table(
            [t("setting"), t("value")],
            [[_e(k), f'<span class="t">{_e(v)}</span>'] for k, v in settings.items()],
        ),
    ]
    if diagnosis:
        parts.append(f"<h2>{t('Not observable')}</h2>")
        parts.append(f'<div class="diag"><p>{t("The calibration was not computed:")}</p><ul>')
        parts += [f"<li>{_e(t(s))}</li>" for s in diagnosis]
        parts.append("</ul></div>")
    if run is not None:
        parts += _results(run)
    parts.append("</body></html>")
    return "\n".join(parts)


def _timing(res) -> list[str]:
    """The timing offset dt in milliseconds with its sigma and its correlations with the
    other calibration parameters (boresight angles, lever arm, interior)."""
    head = [t("parameter"), t("value (ms)"), t("sigma (ms)")]
    rows = [["dt", _n(1e3 * res.timing_offset, 2), _n(1e3 * res.timing_offset_std, 2)]]
    names = res.parameter_names
    at = names.index("timing.dt")
    corr = np.asarray(res.correlation)[at]
    others = [
        [_e(n.replace("bore[", "").replace("].", " ")), _n(corr[k], 3)]
        for k, n in enumerate(names)
        if k != at
    ]
    return [
        f"<h3>{t('Camera timing offset')}</h3>",
        f'<p class="note">{t("exposure = recorded time + dt")}</p>',
        _table(head, rows),
        _table([t("parameter"), t("correlation with dt")], others),
    ]


def _problems(problems: Sequence[str], accepted: bool) -> list[str]:
    return failed_checks(
        problems,
        accepted,
        t(
            "The calibration FAILED its checks: no table and no exterior orientation were "
            "written. The numbers below show the failed adjustment, for diagnosis only."
        ),
    )


def _results(run: BoresightRun) -> list[str]:
    res = run.result
    out = [f"<h2>{t('Boresight')}</h2>"]
    rows = []
    for g, name in enumerate(res.groups):
        for k, angle in enumerate(_ANGLES):
            b = float(res.boresight[g, k])
            rows.append(
                [
                    _e(name) if k == 0 else "",
                    f"d_{angle}",
                    f"{math.degrees(b):.6f}",
                    _dms(b),
                    _n(b * ARCSEC_PER_RAD, 1),
                    _n(res.std[g, k] * ARCSEC_PER_RAD, 1),
                    _n(res.std_prior[g, k] * ARCSEC_PER_RAD, 1),
                ]
            )
    out.append(
        _table(
            [
                t("group"),
                t("angle"),
                t("value (deg)"),
                t("value (d m s)"),
                t("value (arcsec)"),
                t("sigma (arcsec)"),
                t("sigma a-priori (arcsec)"),
            ],
            rows,
        )
    )
    if res.lever_arm is not None:
        out.append(f"<h3>{t('Lever arm (body frame)')}</h3>")
        head = [t("axis"), t("value (m)"), t("sigma (m)")]
        assert res.lever_arm_std is not None  # estimated with the lever arm
        out.append(_value_table(head, "xyz", res.lever_arm, res.lever_arm_std, 4))
    if res.interior is not None:
        out.append(f"<h3>{t('Interior orientation')}</h3>")
        head = [t("parameter"), t("value (mm)"), t("sigma (mm)")]
        assert res.interior_std is not None  # estimated with the interior orientation
        out.append(_value_table(head, ("f", "x0", "y0"), res.interior, res.interior_std, 5))
    if res.timing_offset is not None:
        out += _timing(res)
    gt = res.adjustment.global_test
    out.append(f"<h2>{t('Adjustment')}</h2>")
    out.append(
        _table(
            [t("figure"), t("value")],
            [
                [t("sigma0 (a-posteriori, a-priori 1)"), _n(res.sigma0, 3)],
                [t("redundancy"), str(res.redundancy)],
                [
                    t("observations / constraints"),
                    f"{res.adjustment.n_observations} / {res.adjustment.n_constraints}",
                ],
                [t("global chi-square statistic"), _n(gt.statistic, 1)],
                [
                    t("acceptance interval (alpha = {})").format(f"{gt.alpha:g}"),
                    f"[{_n(gt.lower, 1)}, {_n(gt.upper, 1)}]",
                ],
                [t("p-value"), _n(gt.p_value, 3)],
                [t("global test"), t("passed") if gt.passed else t("failed")],
                [
                    t("iterations"),
                    t("{} (converged: {})").format(
                        res.adjustment.iterations,
                        t("yes") if res.adjustment.converged else t("no"),
                    ),
                ],
                [t("outlier detection"), _e(t(res.adjustment.outlier_method))],
            ],
            [""] * 6 + ["pass" if gt.passed else "fail", "", ""],
        )
    )
    out.append(f"<h2>{t('Correlation of the calibration parameters')}</h2>")
    names = [_e(n.replace("bore[", "").replace("].", " ")) for n in res.parameter_names]
    corr = np.asarray(res.correlation)
    out.append(
        _table(["", *names], [[names[i], *(_n(v, 2) for v in corr[i])] for i in range(len(names))])
    )
    r = res.residuals
    obs = run.observations
    out.append(f"<h2>{t('Rejected observations')}</h2>")
    rej = np.flatnonzero(r.rejected)
    if rej.size:
        out.append(
            _table(
                [t("image"), t("point"), t("type"), t("target"), "|v| (px)", "w"],
                [
                    [
                        _e(obs.image_id[k]),
                        _e(obs.point_id[k]),
                        _e(obs.type[k]),
                        _e(obs.target_id[k]),
                        _n(float(np.hypot(*r.v_px[k])), 2),
                        _n(r.w[k], 1),
                    ]
                    for k in rej
                ],
            )
        )
    else:
        out.append(f"<p>{t('None.')}</p>")
    if res.warnings:
        out.append(
            f"<h2>{t('Warnings')}</h2><ul>" + "".join(f"<li>{_e(t(w))}</li>" for w in res.warnings)
        )
        out.append("</ul>")
    keep = r.used & ~r.rejected & np.isfinite(r.v_px).all(axis=1)
    if keep.any():
        rms = np.sqrt(np.mean(r.v_px[keep] ** 2, axis=0))
        out.append(f"<h2>{t('Image residuals')}</h2>")
        out.append(
            "<p>"
            + t("{} image points kept: RMS residual {} px (col), {} px (row).").format(
                int(keep.sum()), _n(rms[0], 3), _n(rms[1], 3)
            )
            + "</p>"
        )
        out.append('<div class="plots">')
        out.append(
            histogram(r.v_px[keep, 0], title=t("Residual vx"), xlabel=t("col residual (px)"))
        )
        out.append(
            histogram(r.v_px[keep, 1], title=t("Residual vy"), xlabel=t("row residual (px)"))
        )
        out.append("</div>")
    return out
