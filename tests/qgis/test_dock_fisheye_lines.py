"""Image lines measured through a fisheye camera in the picking dock, in real QGIS (QTest clicks).

Data: the equisolid block of test_dock_fisheye (f 3 mm, 2000 x 1500 px, 150 m up), one of
its frames repainted with a grey step along the exact image of its most curved long line
(1000 -> 1400 across, blurred as 0.5 + 0.5 tanh(d / 0.7 px), d the signed distance from the
line's exact image: 4,001 projected points of the 3-D segment), so that the line's curve is an
edge of the image. Truth: that exact image.
"""

# ruff: noqa: F811 - the fixtures are imported from test_dock_fisheye
from __future__ import annotations

import numpy as np
from lidarphoto.core.photo.picking import CHORD_TOL_PX
from osgeo import gdal
from qgis.PyQt.QtWidgets import QGraphicsItem, QGraphicsPathItem
from scipy.spatial import cKDTree
from test_dock_fisheye import FISHEYE, _distance, fisheye_block, fisheye_layers  # noqa: F401
from test_dock_lines import _click
from test_image_dock import _dock

#: the step's blur (pixels) and grey values
BLUR_PX, DARK, BRIGHT = 0.7, 1000.0, 1400.0


def _curved_line(block, image):
    """The long line whose image bows most off its chord within the frame: (id, exact image
    (M, 2), bow px)."""
    scene, best = block["scene"], None
    lines = {lid: (a, e) for lid, a, e in block["lines"]}
    t = np.linspace(0.0, 1.0, 4001)
    for lid in block["long"]:
        a, e = lines[lid]
        exact = scene.project(image, a[None] + t[:, None] * (e - a)[None])
        if not (np.isfinite(exact).all() and FISHEYE.in_frame(exact, 60.0).all()):
            continue
        bow = float(_distance(exact, exact[[0, -1]]).max())
        if best is None or bow > best[2]:
            best = (lid, exact, bow)
    assert best is not None
    return best


def _paint_edge(path, exact):
    """A frame with the blurred step along the curve ``exact`` (a band of 12 px each side;
    the side is that of the curve's local normal)."""
    w, h = FISHEYE.width_px, FISHEYE.height_px
    img = np.full((h, w), DARK)
    tree = cKDTree(exact)
    lo = np.floor(exact.min(axis=0)).astype(int) - 14
    hi = np.ceil(exact.max(axis=0)).astype(int) + 14
    cols, rows = np.meshgrid(np.arange(max(lo[0], 0), min(hi[0], w)),
                             np.arange(max(lo[1], 0), min(hi[1], h)))  # fmt: skip
    centres = np.column_stack([cols.ravel() + 0.5, rows.ravel() + 0.5])
    dist, k = tree.query(centres)
    near = dist < 12.0
    k = np.clip(k[near], 1, len(exact) - 2)
    tangent = exact[k + 1] - exact[k - 1]
    normal = np.column_stack([-tangent[:, 1], tangent[:, 0]])
    normal /= np.hypot(*normal.T)[:, None]
    d = np.einsum("ij,ij->i", centres[near] - exact[k], normal)
    grey = DARK + (BRIGHT - DARK) * (0.5 + 0.5 * np.tanh(d / BLUR_PX))
    img[rows.ravel()[near], cols.ravel()[near]] = grey
    ds = gdal.GetDriverByName("GTiff").Create(str(path), w, h, 1, gdal.GDT_UInt16, ["TILED=YES"])
    ds.GetRasterBand(1).WriteArray(np.round(img).astype(np.uint16))
    ds = None


def _prediction_paths(dock) -> list[np.ndarray]:
    out = []
    for item in dock.viewer.overlays.groups["predictions"].childItems():
        # (the click's marker is a path too, drawn in screen pixels)
        marker = bool(item.flags() & QGraphicsItem.GraphicsItemFlag.ItemIgnoresTransformations)
        if isinstance(item, QGraphicsPathItem) and not marker:
            p = item.path()
            out.append(np.array([[p.elementAt(i).x, p.elementAt(i).y]
                                 for i in range(p.elementCount())]))  # fmt: skip
    return out


def test_fisheye_image_line_clicked_on_the_curve_and_refined(
    qgis_parent, qgis_app, fisheye_block, fisheye_layers, tmp_path
):
    """Line mode with the equisolid camera, real clicks at 100 %, the Resection tab's
    refinement on: a first click 1.5 px off the curve (a quarter along it) starts an image
    line (no refusal), drawn as the LiDAR line's curve (many vertices, within CHORD_TOL_PX of
    the exact image, bowing off the chord); the second click 1.5 px off at three quarters
    ends it: two line rows of that LiDAR line, each refined onto the curved edge across its
    tangent. Measured: the clicks (pixel centres) 1.5-1.8 px off the curve, the rows 0.004 and
    0.007 px off it (refined across the end points' chord instead: 0.027 px); undo removes
    both."""
    b = dict(fisheye_block)
    image = b["sim"].trajectory.image_id[1]
    lid, exact, bow = _curved_line(b, image)
    assert bow > 5.0, bow
    k = list(b["sim"].trajectory.image_id).index(image)
    painted = tmp_path / f"{image}.tif"
    _paint_edge(painted, exact)
    b["images"] = [painted if n == k else p for n, p in enumerate(b["images"])]
    dock = _dock(qgis_parent, qgis_app, b, fisheye_layers, tmp_path)
    dock.show_image(image)
    dock.viewer.type_combo.setCurrentText("line")
    dock.resection_panel.refine_check.setChecked(True)

    def off_curve(frac):
        j = int(frac * (len(exact) - 1))
        t = exact[j + 1] - exact[j - 1]
        n = np.array([-t[1], t[0]]) / np.hypot(*t)
        return exact[j] + 1.5 * n

    first = _click(dock, off_curve(0.25))
    half = dock.session.half_line
    assert half is not None and half.target.target_id == lid, dock.messages[-2:]
    assert dock.store.rows == []
    drawn = _prediction_paths(dock)
    assert len(drawn) == 1 and len(drawn[0]) >= 10
    assert _distance(drawn[0], exact).max() <= CHORD_TOL_PX
    assert _distance(exact, drawn[0][[0, -1]]).max() > 5.0  # a curve, not the chord
    second = _click(dock, off_curve(0.75))
    rows = dock.store.rows
    assert len(rows) == 2 and dock.session.half_line is None, dock.messages[-2:]
    assert {(o.type, o.target_id, o.image_id) for o in rows} == {("line", lid, image)}
    clicked = np.array([first, second])
    stored = np.array([[o.col, o.row] for o in rows])
    before, after = _distance(clicked, exact), _distance(stored, exact)
    assert (before > 0.9).all(), before
    assert (after < 0.02).all(), after
    print(
        f"\nline {lid} in {image}: its image bows {bow:.1f} px off the chord, drawn with "
        f"{len(drawn[0])} vertices; clicks {np.round(before, 2)} px off the curve, refined "
        f"rows {np.round(after, 3)} px"
    )
    assert dock.session.undo() and dock.store.rows == []
    dock.close()
