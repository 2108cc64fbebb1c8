"""Short self-contained HTML summary of space resections (inline CSS).

Sections: settings; one row per image (orientation, sigma0, test); then per image the
exterior orientation with a-posteriori and a-priori standard deviations, the refined interior
orientation, the global test as the source reports it (statistic against the one-sided
critical value) and two-sided, the correlation matrix of the six parameters, residual
statistics of points, lines and check points, and the observations rejected by data snooping.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from .. import __version__
from .html_table import TR_CONTEXT, html_lang, report_css, t  # noqa: F401 - TR_CONTEXT: make i18n
from .html_table import escape as _e
from .html_table import table as _table

__all__ = ["render_resection_html"]

_NAMES = ("X", "Y", "Z", "omega", "phi", "kappa")
_CSS = report_css(1100, ".note{font-size:12px;color:#444}", h3="h3{font-size:15px;margin-top:18px}")


def _n(x: float | None, digits: int = 3) -> str:
    if x is None or not math.isfinite(float(x)):
        return "&ndash;"
    return f"{float(x):.{digits}f}"


def _rms(x: np.ndarray) -> float:
    x = np.asarray(x, dtype=np.float64)
    x = x[np.isfinite(x)]
    return float(np.sqrt(np.mean(x**2))) if x.size else math.nan


def render_resection_html(
    runs: Sequence, residuals: Sequence[Sequence[object]], settings: Mapping[str, str]
) -> str:
    """The HTML page as a string.

    Parameters
    ----------
    runs : sequence of :class:`core.jobs.resection.ImageRun`
    residuals : sequence of rows
        The residual table (columns of :data:`core.io.resection.RESIDUAL_COLUMNS`).
    settings : mapping of str to str
        Shown as given.

    Examples
    --------
    >>> page = render_resection_html([], [], {"camera": "c"})
    >>> page.startswith("<!DOCTYPE html>") and "Space resection" in page
    True
    """
    parts = [
        "<!DOCTYPE html>",
        f'<html lang="{html_lang()}"><head><meta charset="utf-8">',
        f"<title>{t('Space resection')}</title>",
        f"<style>{_CSS}</style></head><body>",
        f"<h1>{t('Space resection')}</h1>",
        f'<p class="note">lidarphoto {_e(__version__)}. '
        + t(
            "Position in the mapping CRS, omega-phi-kappa relative to the grid frame at the "
            "perspective centre; standard deviations a-posteriori (scaled by sigma0) unless "
            "labelled a-priori. Global test: v'Pv / sigma0_prior^2 against the chi-square "
            "critical value (one-sided 5 %, as dos Santos et al. 2010 report it) and the "
            "two-sided acceptance range."
        )
        + "</p>",
        f"<h2>{t('Settings')}</h2>",
        _table([t("setting"), t("value")], [[_e(k), _e(v)] for k, v in settings.items()]),
        f"<h2>{t('Images')}</h2>",
    ]
    rows, css = [], []
    for r in runs:
        res = r.result.result
        deg = np.degrees(r.result.opk)
        rows.append(
            [
                _e(r.image_id),
                *(_n(x, 3) for x in r.result.xyz),
                *(_n(a, 5) for a in deg),
                str(r.image.data.n_points),
                str(r.image.data.n_lines),
                _n(res.sigma0, 3),
                _verdict(res),
            ]
        )
        css.append("pass" if res.chi2_passed and _doubt(res) is None else "fail")
    parts.append(
        _table(
            [
                t("image"),
                "X (m)",
                "Y (m)",
                "Z (m)",
                "omega (deg)",
                "phi (deg)",
                "kappa (deg)",
                t("points"),
                t("lines"),
                "sigma0",
                t("test"),
            ],
            rows,
            css,
        )
    )
    by_image: dict[str, list] = {}
    for row in residuals:
        by_image.setdefault(str(row[0]), []).append(row)
    for r in runs:
        parts += _image(r, by_image.get(r.image_id, []))
    parts.append("</body></html>")
    return "\n".join(parts)


def _image(r, residuals: list) -> list[str]:
    res = r.result.result
    out = ["<h2>" + t("Image {}").format(_e(r.image_id)) + "</h2>"]
    out.append(
        '<p class="note">'
        + t(
            "Start: {}; line model: {}; {} iterations; {} control points, {} lines, {} check "
            "points, {} rows without control ignored."
        ).format(
            _e(res.start),
            _e(res.model),
            res.iterations,
            r.image.data.n_points,
            r.image.data.n_lines,
            len(r.image.check_rows),
            r.image.ignored,
        )
        + "</p>"
    )
    std = r.result.std
    prior = _prior_std(r)
    values = [*r.result.xyz, *np.degrees(r.result.opk)]
    units = ["m"] * 3 + ["deg"] * 3
    rows = []
    for k, name in enumerate(_NAMES):
        scale = 1.0 if k < 3 else math.degrees(1.0)
        rows.append(
            [
                name,
                _n(values[k], 4 if k < 3 else 6),
                units[k],
                _n(std[k] * scale, 5),
                _n(prior[k] * scale, 5),
                _n(std[k] * 3600 * scale, 2) if k >= 3 else "",
            ]
        )
    out.append(
        _table(
            [t("parameter"), t("value"), t("unit"), t("std"), t("std a-priori"), t("std (arcsec)")],
            rows,
        )
    )
    if res.interior is not None:
        out.append(f"<h3>{t('Interior orientation (refined)')}</h3>")
        out.append(
            _table(
                [t("parameter"), t("value (mm)"), t("std (mm)")],
                [
                    [n, _n(v, 5), _n(s, 5)]
                    for n, v, s in zip(("focal", "x0", "y0"), res.interior, res.interior_std)
                ],
            )
        )
    gt = res.chi2
    verdict = _verdict(res)
    out.append(f"<h3>{t('Global test')}</h3>")
    out.append(
        _table(
            [t("quantity"), t("value")],
            [
                [t("observations (condition rows)"), str(res.adjustment.n_observations)],
                [t("redundancy"), str(res.redundancy)],
                [t("sigma0 a-posteriori"), _n(res.sigma0, 4)],
                [t("chi-square statistic v'Pv / sigma0_prior^2"), _n(gt.statistic, 3)],
                [t("critical value, one-sided 5 % (as the source)"), _n(res.chi2_critical, 3)],
                [t("two-sided acceptance range"), f"{_n(gt.lower, 3)} .. {_n(gt.upper, 3)}"],
                [t("verdict (one-sided)"), verdict],
                [
                    t("condition number (scaled normal matrix)"),
                    f"{res.adjustment.condition_number:.3g}",
                ],
            ],
            ["", "", "", "", "", "pass" if res.chi2_passed and _doubt(res) is None else "fail"],
        )
    )
    out.append(f"<h3>{t('Correlation of the six parameters')}</h3>")
    corr = res.correlation
    out.append(
        _table(
            ["", *_NAMES],
            [[name, *(_n(corr[i, j], 2) for j in range(6))] for i, name in enumerate(_NAMES)],
        )
    )
    used = [row for row in residuals if row[12]]
    pts = [row for row in used if row[2] != "line"]
    lns = [row for row in used if row[2] == "line"]
    chk = [row for row in residuals if not row[12]]
    rows = [
        [
            t("control points: RMS |v| (px)"),
            str(len(pts)),
            _n(_rms(np.array([row[9] for row in pts])), 3),
        ],
        [
            t("line points: RMS distance from the projected line (px)"),
            str(len(lns)),
            _n(_rms(np.array([row[9] for row in lns])), 3),
        ],
        [
            t("check points: RMS |projected - measured| (px)"),
            str(len(chk)),
            _n(_rms(np.array([row[9] for row in chk])), 3),
        ],
    ]
    out.append(f"<h3>{t('Residuals')}</h3>")
    out.append(_table([t("what"), t("count"), t("value")], rows))
    rejected = [(b.block, b.label, b.row_name, b.w) for b in res.adjustment.rejected]
    if rejected:
        out.append(f"<h3>{t('Rejected by data snooping')}</h3>")
        out.append(
            _table(
                [t("block"), "id", t("row"), "w"],
                [[_e(b), _e(lab), _e(rn), _n(w, 2)] for b, lab, rn, w in rejected],
            )
        )
    if res.warnings:
        out.append('<p class="note">' + "<br>".join(_e(t(w)) for w in res.warnings) + "</p>")
    return out


def _prior_std(r) -> np.ndarray:
    """A-priori standard deviations in the mapping frame (scaled from the a-posteriori ones)."""
    res = r.result.result
    s0 = res.sigma0
    if not (math.isfinite(s0) and s0 > 0):
        return np.full(6, math.nan)
    return r.result.std / s0 * res.adjustment.sigma0_prior


def _doubt(res):
    """The failed rejection test of a resection (:func:`core.lsq.results.unexplained_rejections`
    at the snooping alpha of the job's options), None when it passed or was not needed."""
    from ..lsq.results import unexplained_rejections
    from ..photo.resection import ResectionOptions

    if not res.chi2_passed:
        return None
    return unexplained_rejections(res.adjustment, ResectionOptions.snooping_alpha)


def _verdict(res) -> str:
    """The image's global test: passed, FAILED, or passed only after unexplained rejections."""
    if not res.chi2_passed:
        return t("FAILED")
    if _doubt(res) is not None:
        return t("passed, but only after more rejections than false alarms explain")
    return t("passed")
