"""Self-contained HTML summary of a bundle adjustment (inline CSS and SVG).

Sections: settings; the model comparison (when several AP families ran: the layout of Table 1
of Lima, Debiasi & Menezes, with sigma0 and the AP counts); the adjustment (sigma0, redundancy,
global chi-square test, outlier method and rejections); the interior orientation and APs of
every camera with sigmas, t-tests and the selection's decisions; the correlation heat map of
the interior parameters (|r| above the limit framed); per-image RMS of the residuals; the
check points; the image-space residual vectors per camera (averaged per cell, to show
systematic patterns) and the residual histograms; warnings.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from .. import __version__
from .html_table import escape as _e
from .html_table import table as _table
from .svg_plots import correlation_heatmap, histogram, image_vector_field

if TYPE_CHECKING:
    from ..photo.bundle import BundleResult

__all__ = ["render_bundle_html"]

_CSS = """
body{font-family:sans-serif;margin:24px;color:#222;max-width:1150px}
h1{font-size:22px}h2{font-size:18px;border-bottom:1px solid #aaa;margin-top:26px}
table{border-collapse:collapse;margin:8px 0 16px 0;font-size:13px}
th,td{border:1px solid #bbb;padding:3px 7px;text-align:right}
th{background:#eee}td.t,th.t{text-align:left}
.pass{background:#d8f0d8}.fail{background:#f7d4d4}.best{background:#d8e8f8}
.drop{color:#777}.plots svg{margin:4px;border:1px solid #ddd}.note{font-size:12px;color:#444}
"""


def _n(x: object, fmt: str = ".3f") -> str:
    try:
        v = float(x)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return _e(x)
    return "&ndash;" if not math.isfinite(v) else format(v, fmt)


def _comparison(rows: Sequence[Mapping[str, object]], best: str) -> str:
    head = ["rank", "AP model", "check points", "mean horizontal (m)", "std horizontal (m)",
            "RMSE_HORIZONTAL (m)", "RMSE_U (m)", "RMSE_3D (m)", "sigma0", "APs",
            "APs kept", "significant", "rejected"]  # fmt: skip
    out, css = [], []
    for r in rows:
        if "error" in r and r.get("error"):
            out.append(["&ndash;", _e(r["model"]), f'not observable: {_e(r["error"])}'] +
                       [""] * 10)  # fmt: skip
            css.append("fail")
            continue
        out.append([
            _e(r.get("rank")), _e(r["model"]), _e(r["n_check"]), _n(r["mean_planimetric"]),
            _n(r["std_planimetric"]), _n(r["rms_planimetric"]), _n(r["rms_h"]),
            _n(r["rms_3d"]), _n(r["sigma0"]), _e(r["n_ap"]), _e(r["n_ap_kept"]),
            _e(r["n_significant"]), _e(r["rejected"]),
        ])  # fmt: skip
        css.append("best" if r["model"] == best else "")
    return _table(head, out, css)


def _adjustment(res: BundleResult) -> str:
    a = res.adjustment
    t = a.global_test
    rows = [
        ["converged", "yes" if a.converged else "NO", f"after {a.iterations} iterations"],
        ["sigma0 a posteriori", _n(a.sigma0, ".4f"), f"a priori {a.sigma0_prior:g}"],
        ["redundancy", _e(a.redundancy), f"{a.n_observations} observation rows, "
         f"{len(a.x)} parameters, {a.n_constraints} constraint rows"],
        ["global chi-square test", "passed" if t.passed else "FAILED",
         f"statistic {t.statistic:.1f}, accepted [{t.lower:.1f}, {t.upper:.1f}], "
         f"p = {t.p_value:.3g}" if t.dof > 0 else "no redundancy"],
        ["outliers", _e(int(res.rejected.sum())), _e(a.outlier_method)],
        ["condition number (reduced system)", _n(a.condition_number, ".3g"), ""],
    ]  # fmt: skip
    return _table(["", "value", "details"], rows, ["", "", "", "pass" if t.passed else "fail"])


def _interior(res: BundleResult, alpha_text: str) -> str:
    rows, css = [], []
    for p in res.interior:
        if p.status == "estimated":
            sig = "yes" if p.significant else "no"
        else:
            sig = "&ndash;"
        rows.append([
            _e(p.camera), _e(p.name), _n(p.value, ".6g"), _n(p.std, ".3g"), _n(p.t, ".2f"),
            sig, _e(p.status), _e(p.reason),
        ])  # fmt: skip
        css.append("drop" if p.status == "dropped" else "")
    head = ["camera", "parameter", "value", "std", "t", f"significant ({alpha_text})",
            "status", "reason"]  # fmt: skip
    return _table(head, rows, css)


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
        "<!DOCTYPE html><html><head><meta charset='utf-8'>",
        f"<title>Bundle adjustment: {_e(best)}</title><style>{_CSS}</style></head><body>",
        f"<h1>Bundle adjustment with self-calibration ({_e(best)})</h1>",
        f'<p class="note">lidarphoto {_e(__version__)}; mapping CRS and units in the '
        "settings; image residuals in pixels (adjusted minus measured).</p>",
        "<h2>Settings</h2>",
        _table(["setting", "value"], [[_e(k), _e(v)] for k, v in settings.items()]),
    ]
    if len(comparison) > 1:
        parts += [
            "<h2>AP models compared (check-point discrepancies)</h2>",
            '<p class="note">Planimetric discrepancy = horizontal distance between the '
            "intersected and the surveyed check point; ranked by the 3D RMS (sigma0 without "
            "check points). The outputs are those of the best model (highlighted).</p>",
            _comparison(comparison, best),
        ]
    parts += ["<h2>Adjustment</h2>", _adjustment(res)]
    parts += ["<h2>Interior orientation and additional parameters</h2>",
              _interior(res, alpha_text)]  # fmt: skip
    if res.dropped:
        parts.append(
            "<p>Dropped by the selection, in order: "
            + "; ".join(f"{_e(c)} {_e(n)} ({_e(w)})" for c, n, w in res.dropped)
            + "</p>"
        )
    if res.flagged_correlations:
        parts.append(
            f"<p>|correlation| above {max_correlation:g} in the final adjustment: "
            + "; ".join(f"{_e(c)} {_e(a)} / {_e(b)}: {r:+.3f}"
                        for c, a, b, r in res.flagged_correlations)
            + "</p>"
        )
    plots = []
    for cam, (names, corr) in res.interior_correlation.items():
        if len(names) > 1:
            plots.append(correlation_heatmap(names, corr, title=f"Correlations: {cam}",
                                             flag=max_correlation))  # fmt: skip
    if plots:
        parts += ['<div class="plots">', *plots, "</div>"]
    if res.mount is not None:
        m = res.mount
        rows = [[_e(n), _n(v, ".4f"), _n(s, ".4f")] for n, v, s in zip(
            ("lever dx (m)", "lever dy (m)", "lever dz (m)"), m["lever_arm_m"],
            m["lever_arm_std_m"])]  # fmt: skip
        rows += [[_e(n), _n(np.degrees(v), ".5f"), _n(np.degrees(s), ".5f")] for n, v, s in zip(
            ("boresight d_omega (deg)", "boresight d_phi (deg)", "boresight d_kappa (deg)"),
            m["boresight_rad"], m["boresight_std_rad"])]  # fmt: skip
        parts += ["<h2>Lever arm and boresight corrections (camera axes)</h2>",
                  _table(["parameter", "value", "std"], rows)]  # fmt: skip
    # per image
    rows = []
    for k, im in enumerate(res.eo.image_id):
        rc, rr = res.image_rms[im]
        n_used = int(np.sum(res.used & (np.array(res.observations.image_id) == im)))
        rows.append([_e(im), _e(res.image_camera[k]), _e(n_used), _n(rc), _n(rr),
                     *(_n(v, ".3f") for v in res.eo_sigma[k, :3]),
                     *(_n(np.degrees(v) * 3600, ".1f") for v in res.eo_sigma[k, 3:])])  # fmt: skip
    parts += [
        "<h2>Images</h2>",
        _table(["image", "camera", "points used", "RMS col (px)", "RMS row (px)",
                "sigma X (m)", "sigma Y (m)", "sigma Z (m)", 'sigma omega (")', 'sigma phi (")',
                'sigma kappa (")'], rows),
    ]
    c = res.check
    if len(c.point_id):
        st = c.statistics()
        d = c.discrepancy
        rows = [[_e(p), *(_n(v) for v in dd), _n(math.hypot(dd[0], dd[1])),
                 *(_n(v) for v in s), _e(n)]
                for p, dd, s, n in zip(c.point_id, d, c.sigma, c.n_images)]  # fmt: skip
        parts += [
            "<h2>Check points (not in the adjustment)</h2>",
            f"<p>Horizontal discrepancy: mean {_n(st['mean_planimetric'])} m, standard "
            f"deviation {_n(st['std_planimetric'])} m, RMSE_HORIZONTAL "
            f"{_n(st['rms_planimetric'])} m; RMSE_E / RMSE_N / RMSE_U {_n(st['rms_e'])} / "
            f"{_n(st['rms_n'])} / {_n(st['rms_h'])} m; RMSE_3D {_n(st['rms_3d'])} m. "
            "Intersected with the adjusted orientations; their sigmas carry the image noise "
            "only.</p>",
            _table(["point", "dE (m)", "dN (m)", "dU (m)", "dHorizontal (m)", "sigma E (m)",
                    "sigma N (m)", "sigma H (m)", "images"], rows),
        ]
    plots = []
    obs = res.observations
    cams = np.array(res.image_camera)
    img_index = {im: k for k, im in enumerate(res.eo.image_id)}
    cam_of_obs = cams[[img_index[i] for i in obs.image_id]] if len(obs) else np.array([])
    for name, cam in res.cameras.items():
        sel = res.used & (cam_of_obs == name)
        if sel.any():
            plots.append(image_vector_field(
                obs.pixels[sel, 0], obs.pixels[sel, 1], res.v_px[sel, 0], res.v_px[sel, 1],
                cam.width_px, cam.height_px, title=f"Image residuals: {name}"))  # fmt: skip
    used_v = res.v_px[res.used]
    if used_v.size:
        plots.append(histogram(used_v[:, 0], title="v col", xlabel="residual (px)"))
        plots.append(histogram(used_v[:, 1], title="v row", xlabel="residual (px)"))
    if plots:
        parts += ["<h2>Residuals</h2>", '<div class="plots">', *plots, "</div>"]
    if res.rejected.any():
        rej = np.flatnonzero(res.rejected)[:200]
        rows = [[_e(obs.image_id[i]), _e(obs.point_id[i]), _n(res.v_px[i, 0], ".2f"),
                 _n(res.v_px[i, 1], ".2f"), _n(res.w[i, 0], ".2f"), _n(res.w[i, 1], ".2f")]
                for i in rej]  # fmt: skip
        parts += [f"<h2>Rejected measurements ({int(res.rejected.sum())})</h2>",
                  _table(["image", "point", "v col", "v row", "w col", "w row"], rows)]  # fmt: skip
    if res.warnings:
        parts += ["<h2>Warnings</h2><ul>",
                  *(f"<li>{_e(w)}</li>" for w in res.warnings), "</ul>"]  # fmt: skip
    parts.append("</body></html>")
    return "\n".join(parts)
