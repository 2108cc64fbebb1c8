"""Small inline-SVG plots for self-contained HTML reports (no plotting dependency).

Each function returns one ``<svg>`` element as text, sized in CSS pixels, with a ``<title>``
for accessibility. Coordinates are drawn with y up (map-like); text is HTML-escaped.
"""

from __future__ import annotations

import html
import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray
from scipy import stats

from .html_table import TR_CONTEXT  # noqa: F401 - the context of _tr (make i18n)
from .html_table import t as _tr  # (many plots use ``t`` for other things)

__all__ = [
    "correlation_heatmap",
    "histogram",
    "image_vector_field",
    "nice_step",
    "qq_plot",
    "vector_map",
]

_FONT = 'font-family="sans-serif" font-size="11"'
_NEG, _POS, _MID = (33, 102, 172), (178, 24, 43), (240, 240, 240)


def nice_step(span: float, target: int = 5) -> float:
    """A 1-2-5 step giving about ``target`` intervals over ``span``.

    Examples
    --------
    >>> nice_step(1.0), nice_step(37.0), nice_step(0.0)
    (0.2, 10.0, 1.0)
    """
    if not (math.isfinite(span) and span > 0):
        return 1.0
    raw = span / max(target, 1)
    base = 10.0 ** math.floor(math.log10(raw))
    for m in (1.0, 2.0, 5.0, 10.0):
        if raw <= m * base * 1.0000001:
            return m * base
    return 10.0 * base


def _nice_floor(limit: float) -> float:
    """The largest 1-2-5 number not above ``limit`` (> 0)."""
    base = 10.0 ** math.floor(math.log10(limit))
    return max(m * base for m in (1.0, 2.0, 5.0) if m * base <= limit * 1.0000001)


def _fmt(v: float) -> str:
    if v == 0 or not math.isfinite(v):
        return "0" if v == 0 else "nan"
    if abs(v) >= 1000:
        return f"{v:.0f}"
    if abs(v) < 0.001:
        return f"{v:.2g}"
    return f"{v:.4g}"


def _esc(text: str) -> str:
    return html.escape(str(text), quote=True)


def _tick(
    x1: float, y1: float, x2: float, y2: float, tx: float, ty: float, anchor: str, label: str
) -> str:
    """A grid line from (x1, y1) to (x2, y2) and its tick label anchored at (tx, ty) (px)."""
    return (
        f'<line x1="{x1:.1f}" y1="{y1:.1f}" x2="{x2:.1f}" y2="{y2:.1f}" stroke="#ddd"/>'
        f'<text x="{tx:.1f}" y="{ty:.1f}" text-anchor="{anchor}" {_FONT}>{label}</text>'
    )


class _Frame:
    """Linear mapping of a data window onto a pixel box (y up)."""

    def __init__(self, x0, x1, y0, y1, left, top, width, height):
        self.x0, self.x1 = (x0, x1) if x1 > x0 else (x0 - 0.5, x0 + 0.5)
        self.y0, self.y1 = (y0, y1) if y1 > y0 else (y0 - 0.5, y0 + 0.5)
        self.left, self.top, self.width, self.height = left, top, width, height

    def px(self, x):
        return self.left + (np.asarray(x, float) - self.x0) / (self.x1 - self.x0) * self.width

    def py(self, y):
        return self.top + (self.y1 - np.asarray(y, float)) / (self.y1 - self.y0) * self.height

    def axes(self, xlabel: str, ylabel: str) -> list[str]:
        out = [
            f'<rect x="{self.left:.1f}" y="{self.top:.1f}" width="{self.width:.1f}" '
            f'height="{self.height:.1f}" fill="white" stroke="#444"/>'
        ]
        for axis in ("x", "y"):
            lo, hi = (self.x0, self.x1) if axis == "x" else (self.y0, self.y1)
            step = nice_step(hi - lo)
            ticks = np.arange(math.ceil(lo / step) * step, hi + step * 1e-9, step)
            for t in ticks:
                t = 0.0 if abs(t) < step * 1e-9 else float(t)
                if axis == "x":
                    x = float(self.px(t))
                    b = self.top + self.height
                    out.append(_tick(x, self.top, x, b, x, b + 14, "middle", _fmt(t)))
                else:
                    y = float(self.py(t))
                    r = self.left + self.width
                    out.append(_tick(self.left, y, r, y, self.left - 4, y + 4, "end", _fmt(t)))
        cx = self.left + self.width / 2
        cy = self.top + self.height / 2
        out.append(
            f'<text x="{cx:.1f}" y="{self.top + self.height + 30:.1f}" text-anchor="middle" '
            f"{_FONT}>{_esc(xlabel)}</text>"
            f'<text x="{self.left - 44:.1f}" y="{cy:.1f}" text-anchor="middle" {_FONT} '
            f'transform="rotate(-90 {self.left - 44:.1f} {cy:.1f})">{_esc(ylabel)}</text>'
        )
        return out


def _svg(width: int, height: int, title: str, body: list[str], css_class: str) -> str:
    return (
        f'<svg xmlns="http://www.w3.org/2000/svg" class="{css_class}" width="{width}" '
        f'height="{height}" viewBox="0 0 {width} {height}" role="img">'
        f"<title>{_esc(title)}</title>"
        f'<text x="{width / 2:.1f}" y="16" text-anchor="middle" font-family="sans-serif" '
        f'font-size="13" font-weight="bold">{_esc(title)}</text>' + "".join(body) + "</svg>"
    )


def _diverging(values: NDArray[np.float64], limit: float) -> list[str]:
    t = np.clip(values / limit, -1.0, 1.0) if limit > 0 else np.zeros_like(values)
    mid = np.array(_MID, float)
    end = np.where(t[:, None] < 0, np.array(_NEG, float), np.array(_POS, float))
    rgb = mid + (end - mid) * np.abs(t)[:, None]
    return [f"rgb({r:.0f},{g:.0f},{b:.0f})" for r, g, b in rgb]


def vector_map(
    e: NDArray[np.float64],
    n: NDArray[np.float64],
    de: NDArray[np.float64],
    dn: NDArray[np.float64],
    dh: NDArray[np.float64] | None = None,
    labels: Sequence[str] | None = None,
    flags: NDArray[np.bool_] | None = None,
    *,
    title: str | None = None,
    width: int = 640,
    height: int = 520,
) -> str:
    """Map-like scatter of the points with their horizontal discrepancy vectors.

    Points at (E, N) (metres, shown relative to the lower-left point so labels stay short),
    equal scales on both axes; arrows (dE, dN) exaggerated so that the longest is about 12 %
    of the map, with a scale arrow stating the exaggeration; dots coloured by dU (blue
    negative, red positive); flagged outliers ringed.

    Examples
    --------
    >>> s = vector_map(np.array([0.0, 100]), np.array([0.0, 50]), np.array([0.1, -0.2]),
    ...                np.array([0.0, 0.1]))
    >>> s.startswith("<svg") and s.count("<polygon") >= 2
    True
    """
    e, n, de, dn = (np.asarray(v, dtype=np.float64).ravel() for v in (e, n, de, dn))
    dh = None if dh is None else np.asarray(dh, dtype=np.float64).ravel()
    e0, n0 = float(e.min()), float(n.min())
    x, y = e - e0, n - n0
    span = max(float(np.ptp(x)), float(np.ptp(y)), 1.0)
    pad = 0.12 * span
    left, top, right, bottom = 64, 28, 150, 44
    pw, ph = width - left - right, height - top - bottom
    # Equal scales: widen the shorter data side to the plot's aspect ratio.
    xs, ys = float(np.ptp(x)) + 2 * pad, float(np.ptp(y)) + 2 * pad
    ratio = pw / ph
    if xs / ys < ratio:
        xs = ys * ratio
    else:
        ys = xs / ratio
    cx, cy = (x.min() + x.max()) / 2, (y.min() + y.max()) / 2
    fr = _Frame(cx - xs / 2, cx + xs / 2, cy - ys / 2, cy + ys / 2, left, top, pw, ph)
    if title is None:
        title = _tr("Horizontal discrepancy vectors")
    body = fr.axes(f"E - {e0:.1f} (m)", f"N - {n0:.1f} (m)")
    length = np.hypot(de, dn)
    dmax = float(length.max()) if length.size else 0.0
    exaggeration = 0.12 * xs / dmax if dmax > 0 else 1.0
    px, py = fr.px(x), fr.py(y)
    qx, qy = fr.px(x + de * exaggeration), fr.py(y + dn * exaggeration)
    body.append(_arrows(px, py, qx, qy, "#222"))
    colours = (
        _diverging(dh, float(np.max(np.abs(dh))) if dh is not None and dh.size else 0.0)
        if (dh is not None)
        else ["#888"] * len(x)
    )
    for k in range(len(x)):
        tip = "" if labels is None else _esc(labels[k])
        body.append(
            f'<circle cx="{px[k]:.1f}" cy="{py[k]:.1f}" r="4" fill="{colours[k]}" stroke="#000">'
            f"<title>{tip}</title></circle>"
        )
        if flags is not None and bool(flags[k]):
            body.append(
                f'<circle cx="{px[k]:.1f}" cy="{py[k]:.1f}" r="9" fill="none" stroke="#d00" '
                'stroke-width="2"/>'
            )
        if labels is not None:
            body.append(
                f'<text x="{px[k] + 6:.1f}" y="{py[k] - 6:.1f}" {_FONT} fill="#333">{tip}</text>'
            )
    # Legend: scale arrow, map scale bar, colour scale.
    lx = width - right + 14
    vec = nice_step(dmax, 2) if dmax > 0 else 1.0
    arrow_px = vec * exaggeration * pw / xs
    ly = top + 24
    body.append(
        _arrows(np.array([lx]), np.array([ly]), np.array([lx + arrow_px]), np.array([ly]), "#222")
    )
    body.append(
        f'<text x="{lx:.1f}" y="{ly + 16:.1f}" {_FONT}>'
        + _tr("{} m discrepancy").format(_fmt(vec))
        + f'</text><text x="{lx:.1f}" y="{ly + 30:.1f}" {_FONT}>'
        + _tr("(vectors x {})").format(f"{exaggeration:,.0f}")
        + "</text>"
    )
    # Longest 1-2-5 ground distance that fits the legend (about 110 px).
    bar = _nice_floor(110.0 * xs / pw)
    bar_px = bar * pw / xs
    by = ly + 60
    body.append(
        f'<line x1="{lx:.1f}" y1="{by:.1f}" x2="{lx + bar_px:.1f}" y2="{by:.1f}" '
        'stroke="#000" stroke-width="3"/>'
        f'<text x="{lx:.1f}" y="{by + 16:.1f}" {_FONT}>'
        + _tr("{} m on the ground").format(_fmt(bar))
        + "</text>"
    )
    if dh is not None and dh.size:
        lim = float(np.max(np.abs(dh)))
        gy = by + 40
        for j, v in enumerate(np.linspace(lim, -lim, 5)):
            (col,) = _diverging(np.array([v]), lim)
            body.append(
                f'<rect x="{lx:.1f}" y="{gy + 16 * j:.1f}" width="14" height="14" fill="{col}" '
                f'stroke="#000"/><text x="{lx + 20:.1f}" y="{gy + 16 * j + 11:.1f}" {_FONT}>'
                f"dU {_fmt(float(v))} m</text>"
            )
    if flags is not None and np.any(flags):
        oy = height - bottom - 6
        body.append(
            f'<circle cx="{lx + 7:.1f}" cy="{oy - 4:.1f}" r="7" fill="none" stroke="#d00" '
            f'stroke-width="2"/><text x="{lx + 20:.1f}" y="{oy:.1f}" {_FONT}>'
            + _tr("outlier")
            + "</text>"
        )
    return _svg(width, height, title, body, "vector-map")


def _arrows(x0, y0, x1, y1, colour: str) -> str:
    """Lines with filled triangular heads (pixel coordinates), one path per arrow."""
    dx, dy = x1 - x0, y1 - y0
    length = np.hypot(dx, dy)
    ok = length > 0.5
    ux = np.where(ok, dx / np.where(ok, length, 1), 0)
    uy = np.where(ok, dy / np.where(ok, length, 1), 0)
    head = np.minimum(8.0, 0.4 * length)
    bx, by = x1 - ux * head, y1 - uy * head
    lx, ly = bx - uy * head * 0.45, by + ux * head * 0.45
    rx, ry = bx + uy * head * 0.45, by - ux * head * 0.45
    parts = []
    for k in np.flatnonzero(ok):
        parts.append(
            f'<line x1="{x0[k]:.1f}" y1="{y0[k]:.1f}" x2="{bx[k]:.1f}" y2="{by[k]:.1f}" '
            f'stroke="{colour}" stroke-width="1.5"/>'
            f'<polygon points="{x1[k]:.1f},{y1[k]:.1f} {lx[k]:.1f},{ly[k]:.1f} '
            f'{rx[k]:.1f},{ry[k]:.1f}" fill="{colour}"/>'
        )
    return "".join(parts)


def histogram(
    values: NDArray[np.float64],
    *,
    title: str,
    xlabel: str | None = None,
    bins: int | None = None,
    width: int = 360,
    height: int = 260,
) -> str:
    """Histogram of one component with the fitted normal density scaled to the counts.

    ``bins`` defaults to Sturges' rule. Examples
    --------
    >>> histogram(np.array([0.1, 0.2, 0.2, 0.3]), title="dE").count("<rect") >= 3
    True
    """
    v = np.asarray(values, dtype=np.float64).ravel()
    v = v[np.isfinite(v)]
    left, top, right, bottom = 56, 28, 12, 44
    pw, ph = width - left - right, height - top - bottom
    if v.size == 0:
        return _svg(width, height, title, [], "histogram")
    k = bins or max(1, math.ceil(math.log2(v.size) + 1))
    lo, hi = float(v.min()), float(v.max())
    if hi == lo:
        lo, hi = lo - 0.5, hi + 0.5
    counts, edges = np.histogram(v, bins=k, range=(lo, hi))
    xs = np.linspace(lo, hi, 80)
    dens = np.zeros_like(xs)
    if v.size > 1 and v.std(ddof=1) > 0:
        dens = stats.norm.pdf(xs, v.mean(), v.std(ddof=1)) * v.size * (edges[1] - edges[0])
    fr = _Frame(lo, hi, 0.0, max(float(counts.max()), float(dens.max())) * 1.15, left, top, pw, ph)
    body = fr.axes(_tr("discrepancy (m)") if xlabel is None else xlabel, _tr("count"))
    x0, x1 = fr.px(edges[:-1]), fr.px(edges[1:])
    y = fr.py(counts)
    base = float(fr.py(0.0))
    for a, b, t, c in zip(x0, x1, y, counts):
        body.append(
            f'<rect x="{a:.1f}" y="{t:.1f}" width="{max(b - a - 1, 1):.1f}" '
            f'height="{base - t:.1f}" fill="#6a9fd0" stroke="#2b5d8a">'
            f"<title>{int(c)}</title></rect>"
        )
    if dens.any():
        pts = " ".join(f"{a:.1f},{b:.1f}" for a, b in zip(fr.px(xs), fr.py(dens)))
        body.append(f'<polyline points="{pts}" fill="none" stroke="#c33" stroke-width="1.5"/>')
    return _svg(width, height, title, body, "histogram")


def qq_plot(
    values: NDArray[np.float64],
    *,
    title: str,
    width: int = 300,
    height: int = 280,
) -> str:
    """Normal Q-Q plot: sorted values against Blom's normal scores ``(i - 3/8) / (n + 1/4)``.

    The line is ``mean + s q`` (what a normal sample would follow).

    Examples
    --------
    >>> qq_plot(np.array([0.1, -0.2, 0.05]), title="dH").count("<circle")
    3
    """
    v = np.sort(np.asarray(values, dtype=np.float64).ravel())
    v = v[np.isfinite(v)]
    left, top, right, bottom = 56, 28, 12, 44
    pw, ph = width - left - right, height - top - bottom
    if v.size == 0:
        return _svg(width, height, title, [], "qq-plot")
    n = v.size
    q = stats.norm.ppf((np.arange(1, n + 1) - 0.375) / (n + 0.25))
    qlo, qhi = float(q.min()) - 0.3, float(q.max()) + 0.3
    lo, hi = float(v.min()), float(v.max())
    pad = 0.1 * (hi - lo) if hi > lo else 0.5
    fr = _Frame(qlo, qhi, lo - pad, hi + pad, left, top, pw, ph)
    body = fr.axes(_tr("normal quantile"), _tr("discrepancy (m)"))
    if n > 1:
        m, s = float(v.mean()), float(v.std(ddof=1))
        a, b = qlo, qhi
        if s > 0:  # keep the line inside the plot box (no clipPath: not every viewer has it)
            a = max(qlo, (fr.y0 - m) / s)
            b = min(qhi, (fr.y1 - m) / s)
        if b > a:
            body.append(
                f'<line x1="{fr.px(a):.1f}" y1="{fr.py(m + s * a):.1f}" '
                f'x2="{fr.px(b):.1f}" y2="{fr.py(m + s * b):.1f}" stroke="#c33" '
                'stroke-width="1.5"/>'
            )
    for a, b in zip(fr.px(q), fr.py(v)):
        body.append(f'<circle cx="{a:.1f}" cy="{b:.1f}" r="3" fill="#2b5d8a"/>')
    return _svg(width, height, title, body, "qq-plot")


def correlation_heatmap(
    names: Sequence[str],
    corr: NDArray[np.float64],
    *,
    title: str,
    flag: float = 0.9,
    cell: int = 22,
) -> str:
    """Correlation matrix as coloured cells (blue -1 .. white 0 .. red +1), with the value in
    each cell and a bold frame where |r| exceeds ``flag``.

    Examples
    --------
    >>> correlation_heatmap(["a", "b"], np.array([[1.0, 0.95], [0.95, 1.0]]),
    ...                     title="r").count("<rect") >= 4
    True
    """
    c = np.asarray(corr, dtype=np.float64)
    k = len(names)
    left = 14 + 7 * max((len(n) for n in names), default=1)
    top = 28 + left
    width = max(left + k * cell + 12, 8 * len(title) + 20)
    height = top + k * cell + 12
    colours = _diverging(np.nan_to_num(c.ravel()), 1.0)
    body = []
    for i in range(k):
        y = top + i * cell
        body.append(
            f'<text x="{left - 4}" y="{y + cell * 0.7:.1f}" text-anchor="end" {_FONT}>'
            f"{_esc(names[i])}</text>"
        )
        x = left + i * cell + cell * 0.6
        body.append(
            f'<text x="{x:.1f}" y="{top - 4}" {_FONT} transform="rotate(-90 {x:.1f} {top - 4})">'
            f"{_esc(names[i])}</text>"
        )
        for j in range(k):
            r = c[i, j]
            strong = i != j and np.isfinite(r) and abs(r) > flag
            stroke = 'stroke="#000" stroke-width="2"' if strong else 'stroke="#fff"'
            body.append(
                f'<rect x="{left + j * cell}" y="{y}" width="{cell}" height="{cell}" '
                f'fill="{colours[i * k + j]}" {stroke}><title>{_esc(names[i])} / '
                f"{_esc(names[j])}: {r:.3f}</title></rect>"
            )
            if k <= 20 and np.isfinite(r):
                body.append(
                    f'<text x="{left + j * cell + cell / 2:.1f}" y="{y + cell * 0.65:.1f}" '
                    f'text-anchor="middle" font-family="sans-serif" font-size="8">'
                    f"{r:.1f}</text>"
                )
    return _svg(width, height, title, body, "heatmap")


def image_vector_field(
    col: NDArray[np.float64],
    row: NDArray[np.float64],
    dcol: NDArray[np.float64],
    drow: NDArray[np.float64],
    width_px: int,
    height_px: int,
    *,
    title: str,
    cells: tuple[int, int] = (12, 9),
    width: int = 480,
) -> str:
    """Image-space residual vectors averaged in a grid of cells over the frame (all images of
    a camera together), so that systematic patterns (radial, affine, decentring) show; the
    arrow scale is written under the plot.

    Examples
    --------
    >>> s = image_vector_field(np.array([10.0, 90.0]), np.array([10.0, 60.0]),
    ...                        np.array([0.5, -0.5]), np.array([0.2, 0.1]), 100, 80, title="v")
    >>> s.count("<polygon") == 2
    True
    """
    height = round(width * height_px / width_px) + 60
    left, top = 10, 28
    pw = width - 2 * left
    ph = height - top - 32
    nx, ny = cells
    ix = np.clip((np.asarray(col) / width_px * nx).astype(int), 0, nx - 1)
    iy = np.clip((np.asarray(row) / height_px * ny).astype(int), 0, ny - 1)
    key = iy * nx + ix
    n = np.bincount(key, minlength=nx * ny)
    with np.errstate(invalid="ignore", divide="ignore"):
        mx = np.bincount(key, weights=dcol, minlength=nx * ny) / n
        my = np.bincount(key, weights=drow, minlength=nx * ny) / n
    ok = n > 0
    length = np.hypot(mx[ok], my[ok])
    biggest = float(length.max()) if length.size else 0.0
    cw, chh = pw / nx, ph / ny
    scale = 0.45 * min(cw, chh) / biggest if biggest > 0 else 0.0
    body = [f'<rect x="{left}" y="{top}" width="{pw}" height="{ph}" fill="white" stroke="#444"/>']
    for gx in range(1, nx):
        x = left + gx * cw
        body.append(f'<line x1="{x:.1f}" y1="{top}" x2="{x:.1f}" y2="{top + ph}" stroke="#eee"/>')
    for gy in range(1, ny):
        y = top + gy * chh
        body.append(f'<line x1="{left}" y1="{y:.1f}" x2="{left + pw}" y2="{y:.1f}" stroke="#eee"/>')
    k = np.flatnonzero(ok)
    cx = left + (k % nx + 0.5) * cw
    cy = top + (k // nx + 0.5) * chh
    # rows grow downwards in the image and on the page
    body.append(_arrows(cx, cy, cx + mx[ok] * scale, cy + my[ok] * scale, "#b2182b"))
    ref = _nice_floor(biggest) if biggest > 0 else 0.0
    body.append(
        f'<text x="{width / 2:.1f}" y="{height - 10}" text-anchor="middle" {_FONT}>'
        + _tr("mean residual per cell; {} px = {} px on screen; largest {} px").format(
            _fmt(ref), f"{ref * scale:.0f}", _fmt(biggest)
        )
        + "</text>"
    )
    return _svg(width, height, title, body, "image-vectors")
