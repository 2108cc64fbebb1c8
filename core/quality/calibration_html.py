"""Short self-contained HTML report of a camera calibration (inline CSS).

Sections: the calibrated interior orientation with a-posteriori standard deviations and the
t-test of every lens coefficient; sigma0 and the global test; the correlation matrix of the
interior parameters (|r| > 0.9 marked); one row per view (points, RMS, pose); warnings.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from .. import __version__
from .html_table import TR_CONTEXT, html_lang, report_css, t  # noqa: F401 - TR_CONTEXT: make i18n
from .html_table import escape as _e
from .html_table import table as _table
from .lens_plots import lens_distortion_field, lens_radial_profile

__all__ = ["render_calibration_html"]

_CSS = report_css(
    1100, ".note{font-size:12px;color:#444}.plots svg{margin:4px;border:1px solid #ddd}"
)


def _n(x: float | None, fmt: str = ".4g") -> str:
    if x is None or not math.isfinite(float(x)):
        return "&ndash;"
    return format(float(x), fmt)


def render_calibration_html(result: Any, settings: Mapping[str, str]) -> str:
    """The HTML page of a :class:`core.photo.camera_calibration.CalibrationResult`.

    >>> from types import SimpleNamespace as S
    >>> cam = S(name="c", projection="perspective", focal_px=1000.0, pixel_size_mm=0.004,
    ...         principal_point_px=(640.0, 480.0), interior_names=("focal_mm",),
    ...         interior_params=np.array([4.0]))
    >>> r = S(camera=cam, sigmas={"focal_mm": 0.001}, t_values={}, significant={},
    ...       parameter_names=["focal_mm"], correlation=np.eye(1), sigma0=1.0, sigma_px=0.2,
    ...       redundancy=10, rms_px=0.2, n_points=20, t_critical=2.0, view_names=["a"],
    ...       view_points=np.array([20]), view_rms_px=np.array([0.2]), eo=np.zeros((1, 6)),
    ...       warnings=[], adjustment=S(global_test=S(passed=True)))
    >>> "Camera calibration" in render_calibration_html(r, {"target": "chessboard"})
    True
    """
    cam = result.camera
    ps = cam.pixel_size_mm
    cx, cy = cam.principal_point_px
    parts = [
        "<!DOCTYPE html>",
        f'<html lang="{html_lang()}"><head><meta charset="utf-8">',
        f"<title>{t('Camera calibration')}</title>",
        f"<style>{_CSS}</style></head><body>",
        "<h1>"
        + t("Camera calibration: {} ({})").format(_e(cam.name), _e(cam.projection))
        + "</h1>",
        f'<p class="note">lidarphoto {_e(__version__)}. '
        + t(
            "Standard deviations a-posteriori (scaled by sigma0). Lens coefficients: "
            "Brown-Conrady correction of measured coordinates in mm (ideal = measured + d); "
            "t = |value| / sigma against Student's t (two-sided 5 %, the redundancy as degrees "
            "of freedom)."
        )
        + "</p>",
        f"<h2>{t('Settings')}</h2>",
        _table([t("setting"), t("value")], [[_e(k), _e(v)] for k, v in settings.items()]),
        f"<h2>{t('Interior orientation')}</h2>",
        "<p>"
        + t(
            "f = {} px, principal point ({}, {}) px; RMS {} px over {} points; sigma0 {} "
            "(a-priori {} px), redundancy {}, global test {}."
        ).format(
            _n(cam.focal_px, ".3f"),
            _n(cx, ".2f"),
            _n(cy, ".2f"),
            _n(result.rms_px, ".3f"),
            result.n_points,
            _n(result.sigma0, ".3f"),
            _n(result.sigma_px, ".3g"),
            result.redundancy,
            t("passed") if result.adjustment.global_test.passed else t("FAILED"),
        )
        + "</p>",
    ]
    rows, css = [], []
    values = dict(zip(cam.interior_names, cam.interior_params))
    for name in cam.interior_names:
        sig = result.sigmas.get(name)
        tv = result.t_values.get(name)
        sig_px = _n(sig / ps, ".3f") if sig is not None and name.endswith("_mm") else ""
        verdict = (
            ""
            if tv is None
            else (t("significant") if result.significant[name] else t("not significant"))
        )
        rows.append(
            [
                _e(name),
                _n(values[name], ".6g"),
                _n(sig, ".3g") if sig else t("fixed"),
                sig_px,
                _n(tv, ".2f") if tv is not None else "",
                verdict,
            ]
        )
        css.append("" if tv is None else ("pass" if result.significant[name] else "fail"))
    parts.append(
        _table([t("parameter"), t("value"), "sigma", "sigma (px)", "t", t("test")], rows, css)
    )
    names = list(result.parameter_names)
    corr = np.asarray(result.correlation)
    crow, ccss = [], []
    for i, n in enumerate(names):
        crow.append([_e(n), *(_n(corr[i, j], ".2f") for j in range(len(names)))])
        off = np.abs(np.delete(corr[i], i))
        ccss.append("fail" if off.size and np.nanmax(off) > 0.9 else "")
    parts += [f"<h2>{t('Correlations')}</h2>", _table(["", *map(_e, names)], crow, ccss)]
    if getattr(cam, "distortion", None) is not None and cam.distortion.n_params:
        parts += [
            f"<h2>{t('Lens distortion')}</h2>",
            '<div class="plots">',
            lens_distortion_field(cam, title=t("Lens correction: {}").format(cam.name)),
            lens_radial_profile(cam, title=t("Radial profile: {}").format(cam.name)),
            "</div>",
        ]
    vrows = [
        [
            _e(v),
            str(int(p)),
            _n(r, ".3f"),
            *(_n(x, ".4f") for x in e[:3]),
            *(_n(math.degrees(a), ".3f") for a in e[3:]),
        ]
        for v, p, r, e in zip(result.view_names, result.view_points, result.view_rms_px, result.eo)
    ]
    vhead = [
        t("view"),
        t("points"),
        "RMS (px)",
        "X0",
        "Y0",
        "Z0",
        "omega (deg)",
        "phi (deg)",
        "kappa (deg)",
    ]
    parts += [f"<h2>{t('Views')}</h2>", _table(vhead, vrows)]
    if result.warnings:
        parts += [
            f"<h2>{t('Warnings')}</h2>",
            "<ul>",
            *(f"<li>{_e(t(w))}</li>" for w in result.warnings),
            "</ul>",
        ]
    parts.append("</body></html>")
    return "\n".join(parts)
