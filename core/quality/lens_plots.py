"""Lens distortion plots for the calibration and bundle reports (inline SVG).

Both plots show the lens model's correction ``d`` (measured -> ideal, see
:class:`core.geometry.distortion.DistortionModel`), converted to pixels: a vector field over
the frame, and the radial profile (the component of ``d`` along the radius, and the rest,
tangential to it) against the distance from the principal point. Image rows grow downwards on
the page as in the image.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from .html_table import TR_CONTEXT  # noqa: F401 - the context of _tr (make i18n)
from .html_table import t as _tr
from .svg_plots import _FONT, _arrows, _fmt, _Frame, _nice_floor, _svg

__all__ = ["lens_correction_px", "lens_distortion_field", "lens_radial_profile"]


def lens_correction_px(camera: Any, cols_rows: NDArray[np.float64]) -> NDArray[np.float64]:
    """The lens correction (N, 2) in pixels (d col, d row) at measured pixel positions (N, 2).

    >>> from core.geometry.camera import Camera
    >>> from core.geometry.distortion import BrownConrady
    >>> cam = Camera("c", 10.0, 0.01, 1000, 800, distortion=BrownConrady(k1=1e-4))
    >>> d = lens_correction_px(cam, np.array([[1000.0, 400.0]]))  # 5 mm right of the centre
    >>> [round(float(v), 6) + 0.0 for v in d[0]]  # 1e-4 * 5^3 mm = 0.0125 mm = 1.25 px, out
    [1.25, 0.0]
    """
    centred = camera.pixel_to_image(cols_rows) - np.array([camera.x0_mm, camera.y0_mm])
    d_mm = camera.distortion.correction(centred)
    # y up in mm, rows down in pixels
    return np.column_stack([d_mm[:, 0], -d_mm[:, 1]]) / camera.pixel_size_mm


def lens_distortion_field(
    camera: Any, *, title: str, cells: tuple[int, int] = (12, 9), width: int = 480
) -> str:
    """The correction as arrows at the centres of a grid of cells over the frame, with the
    arrow scale and the largest correction on the frame's corners written under the plot.

    >>> from core.geometry.camera import Camera
    >>> from core.geometry.distortion import BrownConrady
    >>> cam = Camera("c", 10.0, 0.01, 1000, 800, distortion=BrownConrady(k1=1e-4))
    >>> lens_distortion_field(cam, title="lens").count("<polygon") > 90
    True
    """
    w_px, h_px = camera.width_px, camera.height_px
    height = round(width * h_px / w_px) + 60
    left, top = 10, 28
    pw, ph = width - 2 * left, height - top - 32
    nx, ny = cells
    gx, gy = np.meshgrid((np.arange(nx) + 0.5) / nx, (np.arange(ny) + 0.5) / ny)
    cr = np.column_stack([gx.ravel() * w_px, gy.ravel() * h_px])
    d = lens_correction_px(camera, cr)
    corners = np.array([[0.0, 0.0], [w_px, 0.0], [0.0, h_px], [w_px, h_px]], dtype=float)
    corner = float(np.max(np.hypot(*lens_correction_px(camera, corners).T)))
    length = np.hypot(d[:, 0], d[:, 1])
    biggest = float(length.max()) if length.size else 0.0
    cw, chh = pw / nx, ph / ny
    scale = 0.45 * min(cw, chh) / biggest if biggest > 0 else 0.0
    cx = left + cr[:, 0] / w_px * pw
    cy = top + cr[:, 1] / h_px * ph
    ppx, ppy = camera.principal_point_px
    body = [
        f'<rect x="{left}" y="{top}" width="{pw}" height="{ph}" fill="white" stroke="#444"/>',
        f'<circle cx="{left + ppx / w_px * pw:.1f}" cy="{top + ppy / h_px * ph:.1f}" r="3" '
        'fill="none" stroke="#2166ac"/>',
        _arrows(cx, cy, cx + d[:, 0] * scale, cy + d[:, 1] * scale, "#b2182b"),
    ]
    ref = _nice_floor(biggest) if biggest > 0 else 0.0
    body.append(
        f'<text x="{width / 2:.1f}" y="{height - 10}" text-anchor="middle" {_FONT}>'
        + _tr(
            "correction (measured to ideal); {} px = {} px on screen; {} px at the corners"
        ).format(_fmt(ref), f"{ref * scale:.0f}", _fmt(corner))
        + "</text>"
    )
    return _svg(width, height, title, body, "lens-field")


def lens_radial_profile(camera: Any, *, title: str, samples: int = 60) -> str:
    """Radial and tangential parts of the correction (px) against the distance from the
    principal point (px), out to the farthest corner of the frame, sampled along the frame's
    diagonal towards that corner.

    >>> from core.geometry.camera import Camera
    >>> from core.geometry.distortion import BrownConrady
    >>> cam = Camera("c", 10.0, 0.01, 1000, 800, distortion=BrownConrady(k1=1e-4))
    >>> "<polyline" in lens_radial_profile(cam, title="radial")
    True
    """
    ppx, ppy = camera.principal_point_px
    corners = np.array(
        [
            [0.0, 0.0],
            [camera.width_px, 0.0],
            [0.0, camera.height_px],
            [camera.width_px, camera.height_px],
        ]
    )
    far = corners[np.argmax(np.hypot(corners[:, 0] - ppx, corners[:, 1] - ppy))]
    s = np.linspace(0.0, 1.0, samples)
    cr = np.column_stack([ppx + s * (far[0] - ppx), ppy + s * (far[1] - ppy)])
    d = lens_correction_px(camera, cr)
    radius = np.hypot(cr[:, 0] - ppx, cr[:, 1] - ppy)
    u = np.array([far[0] - ppx, far[1] - ppy]) / max(float(radius[-1]), 1e-12)
    radial = d @ u
    tangential = d[:, 0] * -u[1] + d[:, 1] * u[0]
    lo = float(min(radial.min(), tangential.min(), 0.0))
    hi = float(max(radial.max(), tangential.max(), 0.0))
    width, height = 480, 300
    frame = _Frame(0.0, float(radius[-1]), lo, hi, 60, 28, width - 80, height - 80)
    body = frame.axes(_tr("distance from the principal point (px)"), _tr("correction (px)"))
    for values, colour in ((radial, "#b2182b"), (tangential, "#2166ac")):
        pts = " ".join(f"{x:.1f},{y:.1f}" for x, y in zip(frame.px(radius), frame.py(values)))
        body.append(f'<polyline points="{pts}" fill="none" stroke="{colour}" stroke-width="1.5"/>')
    body.append(
        f'<text x="{width - 20}" y="40" text-anchor="end" {_FONT} fill="#b2182b">'
        + _tr("radial")
        + f'</text><text x="{width - 20}" y="54" text-anchor="end" {_FONT} fill="#2166ac">'
        + _tr("tangential")
        + "</text>"
    )
    return _svg(width, height, title, body, "lens-profile")
