"""Plan map of an adjusted block for the reports (inline SVG): image overlap, footprints,
perspective centres, control, check and tie points.

Footprints are the frame's corners cast from the adjusted orientation onto the horizontal plane
at the median height of the object points (mapping-CRS grid coordinates, metres); the overlap
is the number of footprints that cover each cell of a grid over the block. Images whose corner
rays do not all point down (oblique above the horizon, terrestrial or close-range views) get
no footprint and do not count in the overlap.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..geometry.collinearity import image_rays
from .html_table import TR_CONTEXT  # noqa: F401 - the context of _tr (make i18n)
from .html_table import t as _tr
from .svg_plots import _FONT, _fmt, _Frame, _nice_floor, _svg

__all__ = ["BlockMap", "block_map_svg", "footprints", "overlap_counts"]

# Sequential palette for 1, 2, 3, 4 and 5+ covering images (light to dark blue).
_OVERLAP_COLOURS = ("#eff3ff", "#bdd7e7", "#6baed6", "#3182bd", "#08519c")


@dataclass(frozen=True)
class BlockMap:
    """What the map shows, in mapping-CRS grid coordinates (metres)."""

    centres: NDArray[np.float64]  # (M, 2) perspective centres E, N
    footprints: list[NDArray[np.float64]]  # (4, 2) corner polygons, one per image with one
    control: NDArray[np.float64]  # (C, 2)
    check: NDArray[np.float64]  # (K, 2)
    tie: NDArray[np.float64]  # (T, 2)


def footprints(
    cameras: list[Any], eo: NDArray[np.float64], height: float
) -> list[NDArray[np.float64] | None]:
    """Frame corners of each image (camera per image, EO rows ``X0, Y0, Z0, omega, phi,
    kappa`` in metres and radians) on the plane ``Z = height``: (4, 2) E, N per image, or
    None where a corner ray does not point down to the plane.

    >>> from core.geometry.camera import Camera
    >>> cam = Camera("c", 10.0, 0.01, 1000, 800)
    >>> fp = footprints([cam], np.array([[0.0, 0.0, 100.0, 0.0, 0.0, 0.0]]), 0.0)[0]
    >>> np.abs(fp).max(axis=0).round(6).tolist()  # 5 x 4 mm at 1:10,000
    [50.0, 40.0]
    """
    out: list[NDArray[np.float64] | None] = []
    for cam, row in zip(cameras, np.asarray(eo, dtype=np.float64)):
        w, h = cam.width_px, cam.height_px
        corners = np.array([[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]])
        origin, direction = image_rays(corners, row, cam)
        down = direction[:, 2] < -1e-3
        if not down.all() or origin[0, 2] <= height:
            out.append(None)
            continue
        s = (height - origin[:, 2]) / direction[:, 2]
        out.append(origin[:, :2] + s[:, None] * direction[:, :2])
    return out


def overlap_counts(
    polygons: list[NDArray[np.float64]], e: NDArray[np.float64], n: NDArray[np.float64]
) -> NDArray[np.int64]:
    """How many of the convex polygons (each (V, 2), either orientation) contain each point
    ``(e, n)`` (arrays of one shape); the count has that shape.

    >>> sq = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]])
    >>> overlap_counts([sq, sq + 1.0], np.array([0.5, 1.5, 2.5]), np.array([0.5, 1.5, 2.5]))
    array([1, 2, 1])
    """
    count = np.zeros(np.shape(e), dtype=np.int64)
    for poly in polygons:
        nxt = np.roll(poly, -1, axis=0)
        # the point is inside a convex polygon when it lies on the same side of every edge
        cross = np.stack(
            [(b[0] - a[0]) * (n - a[1]) - (b[1] - a[1]) * (e - a[0]) for a, b in zip(poly, nxt)]
        )
        count += (np.all(cross >= 0, axis=0) | np.all(cross <= 0, axis=0)).astype(np.int64)
    return count


def block_map_svg(
    block: BlockMap, *, title: str, width: int = 640, height: int = 520, cells: int = 80
) -> str:
    """The map: overlap cells coloured by the number of covering footprints, footprint
    outlines, centres as black triangles, control as red triangles, check points as blue
    circles and tie points as grey dots; equal scales, a legend and a ground scale bar.

    >>> bm = BlockMap(np.array([[0.0, 0.0], [60.0, 0.0]]),
    ...               [np.array([[-50.0, -40], [50, -40], [50, 40], [-50, 40]]),
    ...                np.array([[10.0, -40], [110, -40], [110, 40], [10, 40]])],
    ...               np.array([[0.0, 10.0]]), np.array([[30.0, 0.0]]), np.zeros((0, 2)))
    >>> s = block_map_svg(bm, title="map")
    >>> s.count('fill="#bdd7e7"') > 0 and s.count("<polygon") >= 5
    True
    """
    pts = [block.centres, block.control, block.check, block.tie, *block.footprints]
    every = np.vstack([p for p in pts if len(p)])
    e0, n0 = every.min(axis=0)
    span = np.ptp(every, axis=0)
    left, top, right, bottom = 64, 28, 150, 44
    pw, ph = width - left - right, height - top - bottom
    pad = 0.05 * max(float(span.max()), 1.0)
    xs, ys = float(span[0]) + 2 * pad, float(span[1]) + 2 * pad
    if xs / ys < pw / ph:
        xs = ys * pw / ph
    else:
        ys = xs * ph / pw
    cx, cy = float(span[0]) / 2, float(span[1]) / 2
    fr = _Frame(cx - xs / 2, cx + xs / 2, cy - ys / 2, cy + ys / 2, left, top, pw, ph)
    body = fr.axes(f"E - {e0:.1f} (m)", f"N - {n0:.1f} (m)")

    def xy(p: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        return fr.px(p[:, 0] - e0), fr.py(p[:, 1] - n0)

    if block.footprints:
        step = xs / cells
        ge, gn = np.meshgrid(
            np.arange(cx - xs / 2 + step / 2, cx + xs / 2, step) + e0,
            np.arange(cy - ys / 2 + step / 2, cy + ys / 2, step) + n0,
        )
        count = np.minimum(overlap_counts(block.footprints, ge, gn), len(_OVERLAP_COLOURS))
        size = step * pw / xs
        # one rectangle per run of equal counts along a row keeps the page small
        for i in range(count.shape[0]):
            row = count[i]
            starts = np.flatnonzero(np.diff(row, prepend=-1) != 0)
            ends = np.append(starts[1:], row.size)
            y = float(fr.py(gn[i, 0] - n0))
            for a, b in zip(starts, ends):
                if row[a] == 0:
                    continue
                x = float(fr.px(ge[i, a] - e0))
                body.append(
                    f'<rect x="{x - size / 2:.1f}" y="{y - size / 2:.1f}" '
                    f'width="{size * (b - a) + 0.3:.1f}" height="{size + 0.3:.1f}" '
                    f'fill="{_OVERLAP_COLOURS[row[a] - 1]}"/>'
                )
        for poly in block.footprints:
            px, py = xy(poly)
            ring = " ".join(f"{x:.1f},{y:.1f}" for x, y in zip(px, py))
            body.append(
                f'<polygon points="{ring}" fill="none" stroke="#6b6b6b" stroke-width="0.6"/>'
            )
    for p, shape in (
        (block.tie, "tie"),
        (block.centres, "centre"),
        (block.control, "control"),
        (block.check, "check"),
    ):
        if not len(p):
            continue
        px, py = xy(p)
        for x, y in zip(px, py):
            body.append(_marker(shape, float(x), float(y)))
    lx = width - right + 14
    ly = top + 20
    entries = [
        ("centre", _tr("perspective centre")),
        ("control", _tr("control point")),
        ("check", _tr("check point")),
        ("tie", _tr("tie point")),
    ]
    for j, (shape, text) in enumerate(entries):
        y = ly + 16 * j
        body.append(
            _marker(shape, lx + 6, y - 4) + f'<text x="{lx + 16}" y="{y:.1f}" {_FONT}>{text}</text>'
        )
    if block.footprints:
        body.append(f'<text x="{lx}" y="{ly + 76}" {_FONT}>' + _tr("images covering") + "</text>")
        for j, colour in enumerate(_OVERLAP_COLOURS):
            y = ly + 84 + 16 * j
            label = f"{j + 1}+" if j == len(_OVERLAP_COLOURS) - 1 else str(j + 1)
            body.append(
                f'<rect x="{lx}" y="{y}" width="14" height="14" fill="{colour}" stroke="#000"/>'
                f'<text x="{lx + 20}" y="{y + 11}" {_FONT}>{label}</text>'
            )
    bar = _nice_floor(110.0 * xs / pw)
    by = height - bottom - 10
    body.append(
        f'<line x1="{lx}" y1="{by}" x2="{lx + bar * pw / xs:.1f}" y2="{by}" stroke="#000" '
        f'stroke-width="3"/><text x="{lx}" y="{by + 16}" {_FONT}>'
        + _tr("{} m on the ground").format(_fmt(bar))
        + "</text>"
    )
    return _svg(width, height, title, body, "block-map")


def _marker(shape: str, x: float, y: float) -> str:
    if shape == "tie":
        return f'<circle cx="{x:.1f}" cy="{y:.1f}" r="1.2" fill="#999"/>'
    if shape == "check":
        return f'<circle cx="{x:.1f}" cy="{y:.1f}" r="4" fill="#2166ac" stroke="#000"/>'
    colour, r = ("#000", 4.0) if shape == "centre" else ("#d7301f", 6.0)
    return (
        f'<polygon points="{x:.1f},{y - r:.1f} {x - r:.1f},{y + r * 0.7:.1f} '
        f'{x + r:.1f},{y + r * 0.7:.1f}" fill="{colour}" stroke="#000"/>'
    )
