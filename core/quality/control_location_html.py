"""Self-contained HTML report of control-point location with a chip gallery (inline CSS,
images embedded as PNG data URIs).

Sections: settings; counts by status; one table row per point and image (status, reason,
position, sigmas, correlations); the gallery: per located pair the chip template warped into
the image's geometry next to the image patch at the match (both contrast-stretched, enlarged
4 x, nearest neighbour, the matched point marked by the centre pixel).
"""

from __future__ import annotations

import base64
import math
from collections.abc import Mapping, Sequence

import numpy as np

from .. import __version__
from ..photo.control_location import LocatedPair
from .html_table import TR_CONTEXT, html_lang, report_css, t  # noqa: F401 - TR_CONTEXT: make i18n
from .html_table import escape as _e
from .html_table import table as _table

__all__ = ["png_data_uri", "render_location_html"]

_CSS = report_css(
    1200,
    (
        ".note{font-size:12px;color:#444}\n"
        "figure{display:inline-block;margin:6px;padding:4px;border:1px solid #ccc;font-size:12px}\n"
        "figure.fail{border-color:#c33}img{image-rendering:pixelated;margin:2px}"
    ),
)


def png_data_uri(grey: np.ndarray | None, zoom: int = 4) -> str:
    """A grey patch as ``data:image/png;base64,...`` (2-98 % stretch, zoomed, centre marked).

    >>> png_data_uri(np.arange(9.0).reshape(3, 3)).startswith("data:image/png;base64,")
    True
    """
    import cv2

    if grey is None or np.size(grey) == 0:
        return ""
    a = np.asarray(grey, dtype=np.float64)
    finite = np.isfinite(a)
    if not finite.any():
        return ""
    lo, hi = np.percentile(a[finite], [2, 98])
    u8 = np.clip((np.where(finite, a, lo) - lo) / max(hi - lo, 1e-12) * 255, 0, 255)
    u8 = np.repeat(np.repeat(u8.astype(np.uint8), zoom, axis=0), zoom, axis=1)
    rgb = np.dstack([u8, u8, u8])
    cy, cx = (a.shape[0] // 2) * zoom, (a.shape[1] // 2) * zoom
    rgb[cy : cy + zoom, cx : cx + zoom] = (0, 0, 255)  # BGR red: the matched point's pixel
    ok, buf = cv2.imencode(".png", rgb)
    return "data:image/png;base64," + base64.b64encode(buf.tobytes()).decode("ascii") if ok else ""


def _word(text: str) -> str:
    """A status or source word of a pair (``ok``, ``rejected``...) in the report's language."""
    words = {"ok": t("ok"), "rejected": t("rejected"), "outside": t("outside"), "chip": t("chip")}
    return words.get(text) or t(text)


def _n(x: float, digits: int = 3) -> str:
    return f"{x:.{digits}f}" if x is not None and math.isfinite(x) else "&ndash;"


def render_location_html(pairs: Sequence[LocatedPair], settings: Mapping[str, str]) -> str:
    """The HTML page as a string.

    >>> page = render_location_html([], {"chips": "3"})
    >>> page.startswith("<!DOCTYPE html>") and "Control point location" in page
    True
    """
    counts: dict[str, int] = {}
    for p in pairs:
        counts[p.status] = counts.get(p.status, 0) + 1
    parts = [
        "<!DOCTYPE html>",
        f'<html lang="{html_lang()}"><head><meta charset="utf-8">',
        f"<title>{t('Control point location')}</title>",
        f"<style>{_CSS}</style></head><body>",
        f"<h1>{t('Control point location')}</h1>",
        f'<p class="note">lidarphoto {_e(__version__)}. '
        + t(
            "NCC with an adaptive template, then least-squares matching (Gruen 1985: 6 affine "
            "+ 2 radiometric parameters). Pixels: corner convention (centre of the first pixel "
            "at 0.5, 0.5); sigmas a posteriori from LSM (they do not include the chip's own "
            "errors)."
        )
        + "</p>",
        f"<h2>{t('Settings')}</h2>",
        _table([t("setting"), t("value")], [[_e(k), _e(v)] for k, v in settings.items()]),
        f"<h2>{t('Summary')}</h2>",
        _table(
            [t("status"), t("pairs")], [[_e(_word(k)), str(v)] for k, v in sorted(counts.items())]
        ),
        f"<h2>{t('Points and images')}</h2>",
    ]
    rows, css = [], []
    for p in pairs:
        rows.append(
            [
                _e(p.point_id),
                _e(p.image_id),
                _e(_word(p.status)),
                _e(t(p.reason)),
                _e(_word(p.source) if p.image_id else ""),
                _n(p.col, 3),
                _n(p.row, 3),
                _n(p.sigma_col, 4),
                _n(p.sigma_row, 4),
                _n(p.ncc, 3),
                _n(p.lsm_correlation, 3),
                str(p.template_px or ""),
            ]
        )
        css.append("pass" if p.status == "ok" else "fail")
    parts.append(
        _table(
            [
                t("point"),
                t("image"),
                t("status"),
                t("reason"),
                t("source"),
                "col",
                t("row"),
                "sigma col",
                t("sigma row"),
                "NCC",
                t("LSM corr."),
                t("template px"),
            ],
            rows,
            css,
        )
    )
    parts.append(f"<h2>{t('Chip gallery')}</h2>")
    parts.append(
        '<p class="note">'
        + t("Left: the chip in the image geometry; right: the image at the match.")
        + "</p>"
    )
    for p in pairs:
        if p.chip_patch is None and p.image_patch is None:
            continue
        cls = "" if p.status == "ok" else ' class="fail"'
        cap = t("{} in {}: {}").format(_e(p.point_id), _e(p.image_id), _e(_word(p.status)))
        if p.reason:
            cap += f" ({_e(t(p.reason))})"
        parts.append(
            f'<figure{cls}><img alt="chip" src="{png_data_uri(p.chip_patch)}">'
            f'<img alt="image" src="{png_data_uri(p.image_patch)}">'
            f"<figcaption>{cap}</figcaption></figure>"
        )
    parts.append("</body></html>")
    return "\n".join(parts)
