"""Self-contained HTML summary of a bundle adjustment (inline CSS and SVG).

Sections: settings; the model comparison (when several AP families ran: the layout of Table 1
of Lima, Debiasi & Menezes, with sigma0 and the AP counts); the adjustment (sigma0, redundancy,
global chi-square test, outlier method and rejections); the interior orientation and APs of
every camera with sigmas, t-tests and the selection's decisions; the correlation heat map of
the interior parameters (|r| above the limit framed); the lever arm and boresight corrections
and the camera timing offset (ms, with its correlations) when estimated; per-image RMS of the
residuals; the check points; the image-space residual vectors per camera (averaged per cell, to show
systematic patterns) and the residual histograms; warnings.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from .. import __version__
from .block_map import BlockMap, block_map_svg, footprints
from .html_table import TR_CONTEXT, html_lang, rejections_explained, report_css, t  # noqa: F401 - TR_CONTEXT: make i18n
from .html_table import escape as _e
from .html_table import table as _table
from .lens_plots import lens_distortion_field, lens_radial_profile
from .svg_plots import correlation_heatmap, histogram, image_vector_field

if TYPE_CHECKING:
    from ..photo.bundle_result import BundleResult

__all__ = ["render_bundle_html"]

_CSS = report_css(
    1150,
    (
        ".best{background:#d8e8f8}\n"
        ".drop{color:#777}.plots svg{margin:4px;border:1px solid #ddd}"
        ".note{font-size:12px;color:#444}"
    ),
)


def _timing(res: BundleResult) -> list[str]:
    """The camera timing offset dt in ms with its sigma and its correlations (none when it
    was not estimated)."""
    tm = res.timing
    if tm is None:
        return []
    rows = [["dt", _n(1e3 * tm["dt_s"], ".2f"), _n(1e3 * tm["dt_std_s"], ".2f")]]
    corr = [[_e(n), _n(r, "+.3f")] for n, r in tm["correlation"].items()]
    return [
        f"<h2>{t('Camera timing offset (exposure = recorded time + dt)')}</h2>",
        _table([t("parameter"), t("value (ms)"), t("sigma (ms)")], rows),
        *([_table([t("correlated with dt"), "r"], corr)] if corr else []),
    ]


def _n(x: object, fmt: str = ".3f") -> str:
    try:
        v = float(x)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return _e(x)
    return "&ndash;" if not math.isfinite(v) else format(v, fmt)


def _comparison(rows: Sequence[Mapping[str, object]], best: str) -> str:
    head = [
        t("rank"),
        t("AP model"),
        t("check points"),
        t("mean horizontal (m)"),
        t("std horizontal (m)"),
        "RMSE_HORIZONTAL (m)",
        "RMSE_U (m)",
        "RMSE_3D (m)",
        "sigma0",
        t("APs"),
        t("APs kept"),
        t("significant"),
        t("rejected"),
    ]
    out, css = [], []
    for r in rows:
        if "error" in r and r.get("error"):
            out.append(
                ["&ndash;", _e(r["model"]), t("not observable: {}").format(_e(r["error"]))]
                + [""] * 10
            )
            css.append("fail")
            continue
        out.append(
            [
                _e(r.get("rank")),
                _e(r["model"]),
                _e(r["n_check"]),
                _n(r["mean_planimetric"]),
                _n(r["std_planimetric"]),
                _n(r["rms_planimetric"]),
                _n(r["rms_h"]),
                _n(r["rms_3d"]),
                _n(r["sigma0"]),
                _e(r["n_ap"]),
                _e(r["n_ap_kept"]),
                _e(r["n_significant"]),
                _e(r["rejected"]),
            ]
        )
        css.append("best" if r["model"] == best else "")
    return _table(head, out, css)


def _adjustment(res: BundleResult) -> str:
    from ..lsq.results import unexplained_rejections
    from ..photo.bundle_setup import BundleOptions

    a = res.adjustment
    gt = a.global_test
    # the robust stage and snooping set aside more than their false alarms explain: the test
    # of the rest says nothing about the model
    doubt = unexplained_rejections(a, BundleOptions.snooping_alpha) if gt.passed else None
    verdict = t("passed") if gt.passed else t("FAILED")
    if doubt is not None:
        verdict = t("passed, but only after more rejections than false alarms explain")
    rows = [
        [
            t("converged"),
            t("yes") if a.converged else t("NO"),
            t("after {} iterations").format(a.iterations),
        ],
        [
            t("sigma0 a posteriori"),
            _n(a.sigma0, ".4f"),
            t("a priori {}").format(f"{a.sigma0_prior:g}"),
        ],
        [
            t("redundancy"),
            _e(a.redundancy),
            t("{} observation rows, {} parameters, {} constraint rows").format(
                a.n_observations, len(a.x), a.n_constraints
            ),
        ],
        [
            t("global chi-square test"),
            verdict,
            t("statistic {}, accepted [{}, {}], p = {}").format(
                f"{gt.statistic:.1f}", f"{gt.lower:.1f}", f"{gt.upper:.1f}", f"{gt.p_value:.3g}"
            )
            if gt.dof > 0
            else t("no redundancy"),
        ],
        [t("outliers"), _e(int(res.rejected.sum())), _e(t(a.outlier_method))],
        *(
            [
                [
                    t("rejections explained by false alarms"),
                    _e(doubt.rejected),
                    rejections_explained(doubt),
                ]
            ]
            if doubt is not None
            else []
        ),
        [t("condition number (reduced system)"), _n(a.condition_number, ".3g"), ""],
    ]
    good = gt.passed and doubt is None
    return _table(
        ["", t("value"), t("details")],
        rows,
        ["", "", "", "pass" if good else "fail", "", "" if doubt is None else "fail"],
    )


def _interior(res: BundleResult, alpha_text: str) -> str:
    rows, css = [], []
    words = {"estimated": t("estimated"), "dropped": t("dropped"), "fixed": t("fixed")}
    for p in res.interior:
        if p.status == "estimated":
            sig = t("yes") if p.significant else t("no")
        else:
            sig = "&ndash;"
        rows.append(
            [
                _e(p.camera),
                _e(p.name),
                _n(p.value, ".6g"),
                _n(p.std, ".3g"),
                _n(p.t, ".2f"),
                sig,
                _e(words.get(p.status, p.status)),
                _e(t(p.reason)),
            ]
        )
        css.append("drop" if p.status == "dropped" else "")
    head = [
        t("camera"),
        t("parameter"),
        t("value"),
        t("std"),
        "t",
        t("significant ({})").format(alpha_text),
        t("status"),
        t("reason"),
    ]
    return _table(head, rows, css)


def _block_map(res: BundleResult) -> list[str]:
    """The plan map of the block: overlap, footprints, centres, control, check and tie points."""
    xyz = np.asarray(res.point_xyz, dtype=np.float64)
    role = np.asarray(res.point_role)
    if len(res.eo) == 0 or xyz.shape[0] == 0:
        return []
    ground = xyz[role != "check"] if np.any(role != "check") else xyz
    cams = [res.cameras[c] for c in res.image_camera]
    eo = np.column_stack([res.eo.xyz, res.eo.opk])
    prints = [p for p in footprints(cams, eo, float(np.median(ground[:, 2]))) if p is not None]
    tie = xyz[role == "tie", :2]
    # a deterministic thinning: every k-th tie point, at most about 3,000 dots
    tie = tie[:: max(1, len(tie) // 3000)]
    bm = BlockMap(
        np.asarray(res.eo.xyz)[:, :2],
        prints,
        xyz[role == "control", :2],
        xyz[role == "check", :2],
        tie,
    )
    svg = block_map_svg(bm, title=t("Image overlap, control and check points"))
    return [f"<h2>{t('Block map')}</h2>", '<div class="plots">', svg, "</div>"]


def _lens_plots(res: BundleResult) -> list[str]:
    """The adjusted lens correction of every camera with a lens model, as plots."""
    plots = []
    for name, cam in res.cameras.items():
        if cam.distortion.n_params:
            plots.append(lens_distortion_field(cam, title=t("Lens correction: {}").format(name)))
            plots.append(lens_radial_profile(cam, title=t("Radial profile: {}").format(name)))
    if not plots:
        return []
    return [f"<h2>{t('Lens distortion')}</h2>", '<div class="plots">', *plots, "</div>"]


def render_bundle_html(
    results: Mapping[str, BundleResult],
    best: str,
    settings: Mapping[str, str],
    comparison: Sequence[Mapping[str, object]] = (),
    max_correlation: float = 0.9,
    alpha_text: str = "alpha 0.05",
) -> str:
    """The HTML page as a string: the result of model ``best`` in full, and the comparison of
    every model that ran."""
    res = results[best]
    parts = [
        f"<!DOCTYPE html><html lang='{html_lang()}'><head><meta charset='utf-8'>",
        "<title>" + t("Bundle adjustment: {}").format(_e(best)) + "</title>"
        f"<style>{_CSS}</style></head><body>",
        "<h1>" + t("Bundle adjustment with self-calibration ({})").format(_e(best)) + "</h1>",
        f'<p class="note">lidarphoto {_e(__version__)}; '
        + t(
            "mapping CRS and units in the settings; image residuals in pixels (adjusted minus "
            "measured)."
        )
        + "</p>",
        f"<h2>{t('Settings')}</h2>",
        _table([t("setting"), t("value")], [[_e(k), _e(v)] for k, v in settings.items()]),
    ]
    if len(comparison) > 1:
        parts += [
            f"<h2>{t('AP models compared (check-point discrepancies)')}</h2>",
            '<p class="note">'
            + t(
                "Planimetric discrepancy = horizontal distance between the intersected and the "
                "surveyed check point; ranked by the 3D RMS (sigma0 without check points). The "
                "outputs are those of the best model (highlighted)."
            )
            + "</p>",
            _comparison(comparison, best),
        ]
    parts += [f"<h2>{t('Adjustment')}</h2>", _adjustment(res)]
    parts += _block_map(res)
    parts += [
        f"<h2>{t('Interior orientation and additional parameters')}</h2>",
        _interior(res, alpha_text),
    ]
    parts += _selection(res, max_correlation)
    parts += _lens_plots(res)
    parts += _mount(res)
    parts += _timing(res)
    parts += _images(res)
    parts += _check_points(res)
    parts += _residuals(res)
    parts += _scale_bars(res)
    if res.warnings:
        parts += [
            f"<h2>{t('Warnings')}</h2><ul>",
            *(f"<li>{_e(t(w))}</li>" for w in res.warnings),
            "</ul>",
        ]
    parts.append("</body></html>")
    return _in_unit("\n".join(parts), res.length_unit)


def _selection(res: BundleResult, max_correlation: float) -> list[str]:
    """The APs the selection dropped, the correlations flagged and the interior
    correlation heat maps."""
    parts: list[str] = []
    if res.dropped:
        parts.append(
            "<p>"
            + t("Dropped by the selection, in order: ")
            + "; ".join(f"{_e(c)} {_e(n)} ({_e(t(w))})" for c, n, w in res.dropped)
            + "</p>"
        )
    if res.flagged_correlations:
        parts.append(
            "<p>"
            + t("|correlation| above {} in the final adjustment: ").format(f"{max_correlation:g}")
            + "; ".join(
                f"{_e(c)} {_e(a)} / {_e(b)}: {r:+.3f}" for c, a, b, r in res.flagged_correlations
            )
            + "</p>"
        )
    plots = []
    for cam, (names, corr) in res.interior_correlation.items():
        if len(names) > 1:
            plots.append(
                correlation_heatmap(
                    names, corr, title=t("Correlations: {}").format(cam), flag=max_correlation
                )
            )
    if plots:
        parts += ['<div class="plots">', *plots, "</div>"]
    return parts


def _mount(res: BundleResult) -> list[str]:
    """The lever arm and boresight corrections' section (when estimated)."""
    parts: list[str] = []
    if res.mount is not None:
        m = res.mount
        rows = [
            [_e(n), _n(v, ".4f"), _n(s, ".4f")]
            for n, v, s in zip(
                (t("lever dx (m)"), t("lever dy (m)"), t("lever dz (m)")),
                m["lever_arm_m"],
                m["lever_arm_std_m"],
            )
        ]
        rows += [
            [_e(n), _n(np.degrees(v), ".5f"), _n(np.degrees(s), ".5f")]
            for n, v, s in zip(
                (
                    t("boresight d_omega (deg)"),
                    t("boresight d_phi (deg)"),
                    t("boresight d_kappa (deg)"),
                ),
                m["boresight_rad"],
                m["boresight_std_rad"],
            )
        ]
        parts += [
            f"<h2>{t('Lever arm and boresight corrections (camera axes)')}</h2>",
            _table([t("parameter"), t("value"), t("std")], rows),
        ]
    return parts


def _images(res: BundleResult) -> list[str]:
    """The images' section: points used, residual RMS and orientation sigmas."""
    parts: list[str] = []
    # per image
    rows = []
    for k, im in enumerate(res.eo.image_id):
        rc, rr = res.image_rms[im]
        n_used = int(np.sum(res.used & (np.array(res.observations.image_id) == im)))
        rows.append(
            [
                _e(im),
                _e(res.image_camera[k]),
                _e(n_used),
                _n(rc),
                _n(rr),
                *(_n(v, ".3f") for v in res.eo_sigma[k, :3]),
                *(_n(np.degrees(v) * 3600, ".1f") for v in res.eo_sigma[k, 3:]),
            ]
        )
    parts += [
        f"<h2>{t('Images')}</h2>",
        _table(
            [
                t("image"),
                t("camera"),
                t("points used"),
                t("RMS col (px)"),
                t("RMS row (px)"),
                "sigma X (m)",
                "sigma Y (m)",
                "sigma Z (m)",
                'sigma omega (")',
                'sigma phi (")',
                'sigma kappa (")',
            ],
            rows,
        ),
    ]
    return parts


def _check_points(res: BundleResult) -> list[str]:
    """The check points' section: discrepancies, their statistics and sigmas."""
    parts: list[str] = []
    c = res.check
    if len(c.point_id):
        st = c.statistics()
        d = c.discrepancy
        rows = [
            [_e(p), *(_n(v) for v in dd), _n(math.hypot(dd[0], dd[1])), *(_n(v) for v in s), _e(n)]
            for p, dd, s, n in zip(c.point_id, d, c.sigma, c.n_images)
        ]
        parts += [
            f"<h2>{t('Check points (not in the adjustment)')}</h2>",
            "<p>"
            + t(
                "Horizontal discrepancy: mean {} m, standard deviation {} m, RMSE_HORIZONTAL "
                "{} m; RMSE_E / RMSE_N / RMSE_U {} / {} / {} m; RMSE_3D {} m. Intersected with "
                "the adjusted orientations; their sigmas carry the image noise only."
            ).format(
                _n(st["mean_planimetric"]),
                _n(st["std_planimetric"]),
                _n(st["rms_planimetric"]),
                _n(st["rms_e"]),
                _n(st["rms_n"]),
                _n(st["rms_h"]),
                _n(st["rms_3d"]),
            )
            + "</p>",
            _table(
                [
                    t("point"),
                    "dE (m)",
                    "dN (m)",
                    "dU (m)",
                    "dHorizontal (m)",
                    "sigma E (m)",
                    "sigma N (m)",
                    "sigma H (m)",
                    t("images"),
                ],
                rows,
            ),
        ]
    return parts


def _residuals(res: BundleResult) -> list[str]:
    """The residuals' section (vector fields per camera, histograms) and the rejected
    measurements."""
    parts: list[str] = []
    plots = []
    obs = res.observations
    cams = np.array(res.image_camera)
    img_index = {im: k for k, im in enumerate(res.eo.image_id)}
    cam_of_obs = cams[[img_index[i] for i in obs.image_id]] if len(obs) else np.array([])
    for name, camera in res.cameras.items():
        sel = res.used & (cam_of_obs == name)
        if sel.any():
            plots.append(
                image_vector_field(
                    obs.pixels[sel, 0],
                    obs.pixels[sel, 1],
                    res.v_px[sel, 0],
                    res.v_px[sel, 1],
                    camera.width_px,
                    camera.height_px,
                    title=t("Image residuals: {}").format(name),
                )
            )
    used_v = res.v_px[res.used]
    if used_v.size:
        plots.append(histogram(used_v[:, 0], title=t("v col"), xlabel=t("residual (px)")))
        plots.append(histogram(used_v[:, 1], title=t("v row"), xlabel=t("residual (px)")))
    if plots:
        parts += [f"<h2>{t('Residuals')}</h2>", '<div class="plots">', *plots, "</div>"]
    if res.rejected.any():
        rej = np.flatnonzero(res.rejected)[:200]
        rows = [
            [
                _e(obs.image_id[i]),
                _e(obs.point_id[i]),
                _n(res.v_px[i, 0], ".2f"),
                _n(res.v_px[i, 1], ".2f"),
                _n(res.w[i, 0], ".2f"),
                _n(res.w[i, 1], ".2f"),
            ]
            for i in rej
        ]
        title = t("Rejected measurements ({})").format(int(res.rejected.sum()))
        parts += [
            f"<h2>{title}</h2>",
            _table([t("image"), t("point"), t("v col"), t("v row"), t("w col"), t("w row")], rows),
        ]
    return parts


def _in_unit(page: str, unit: str) -> str:
    """The page with its lengths labelled in ``unit`` (every length of the report but the
    lever arm, which the core keeps in metres, is in the frame's unit)."""
    if unit == "m":
        return page
    page = re.sub(r"(?<!lever d[xyz] )\(m\)", f"({unit})", page)
    return re.sub(r"(\d|&ndash;|\u2013) m(?=[;,.]| RMSE|<)", rf"\1 {unit}", page)


def _scale_bars(res: BundleResult) -> list[str]:
    """The scale bars' section: measured and adjusted distances, residuals, w-tests."""
    b = res.scale_bars
    if b is None:
        return []
    rows = [
        [
            _e(f"{pa} - {pb}"),
            _n(d, ".6g"),
            _n(s, ".3g"),
            _n(a, ".6g"),
            _n(sa, ".3g"),
            _n(v, ".3g"),
            _n(w, ".2f"),
            _n(r, ".2f"),
            _e(t("rejected") if rej else ""),
        ]
        for pa, pb, d, s, a, sa, v, w, r, rej in zip(
            b.bars.point_a,
            b.bars.point_b,
            b.bars.distance,
            b.bars.sigma,
            b.adjusted,
            b.sigma,
            b.v,
            b.w,
            b.redundancy,
            b.rejected,
        )
    ]
    return [
        f"<h2>{t('Scale bars')}</h2>",
        _table(
            [
                t("bar"),
                t("distance (m)"),
                t("sigma (m)"),
                t("adjusted (m)"),
                t("adjusted sigma (m)"),
                t("v (m)"),
                "w",
                t("redundancy"),
                t("status"),
            ],
            rows,
        ),
    ]
