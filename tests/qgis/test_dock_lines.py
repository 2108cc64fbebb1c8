"""Image lines and the resection in the picking dock, in real QGIS (QTest clicks on the view).

Data: the simulated flight of test_image_dock (its fixtures): noise-free, the EO of the true
trajectory and mount, 16-bit frames with the roofs where the camera model puts them. Truth:
that EO; the lines are clicked on the LiDAR lines' projections, stored at the centres of the
clicked pixels (a uniform error of at most 0.5 px per coordinate, 0.29 px RMS).
"""

# ruff: noqa: F811 - the fixtures block and layers are imported from test_image_dock
from __future__ import annotations

import math

import numpy as np
from lidarphoto.core.io.observations import read_observations_csv
from lidarphoto.core.io.orientation import read_eo_csv
from qgis.PyQt.QtCore import QPoint, QPointF, Qt
from qgis.PyQt.QtTest import QTest
from test_image_dock import _dock, _wait, block, layers  # noqa: F401 - fixtures

CTRL = Qt.KeyboardModifier.ControlModifier


def _line_points(dock, image: str, margin: float = 40.0) -> list[tuple[int, np.ndarray]]:
    """(line index, (2, 2) points at 20 % and 80 % of its projection) of the LiDAR lines
    inside the image (about 30 px long in these images) whose projection is the nearest one
    to the centres of the pixels holding both points (the line a click there links)."""
    session = dock.session
    proj = session.project(image)
    w, h = dock.camera.width_px, dock.camera.height_px
    out = []
    for i, (a, b) in enumerate(zip(proj.line_starts, proj.line_ends)):
        p = np.array([a + 0.2 * (b - a), a + 0.8 * (b - a)])
        if not np.isfinite(p).all() or np.hypot(*(p[1] - p[0])) < 10:
            continue
        if (p < margin).any() or (p[:, 0] > w - margin).any() or (p[:, 1] > h - margin).any():
            continue
        near = [session.targets_at(image, q, "line", 10.0, proj) for q in np.floor(p) + 0.5]
        if all(t and t[0].index == i for t in near):
            out.append((i, p))
    return out


def _click(dock, pixel) -> tuple[float, float]:
    """A real click at 100 % on the image pixel holding ``pixel``; the pixel's centre."""
    view = dock.view
    c, r = (int(v) for v in np.floor(pixel))
    view.set_zoom(1.0, QPointF(c + 0.5, r + 0.5))
    assert view.wait_idle(60.0, build=False)
    hs, vs = view.horizontalScrollBar().value(), view.verticalScrollBar().value()
    QTest.mouseClick(
        view.viewport(),
        Qt.MouseButton.LeftButton,
        Qt.KeyboardModifier.NoModifier,
        QPoint(math.floor(c + 0.5 - hs), math.floor(r + 0.5 - vs)),
    )
    return c + 0.5, r + 0.5


def _key(dock, key, mods=Qt.KeyboardModifier.NoModifier) -> None:
    dock.view.setFocus()
    QTest.keyClick(dock.view, key, mods)


def test_two_clicks_measure_a_line_linked_to_the_lidar_line_undo_removes_both(
    qgis_parent,
    qgis_app,
    block,
    layers,
    tmp_path,
):
    """Two real clicks: two line rows with the LiDAR line's id at the clicked pixels' centres
    (saved); the predicted LiDAR line is drawn between the clicks; Esc cancels a half line;
    one Ctrl+Z removes both ends and Ctrl+Shift+Z brings them back."""
    dock = _dock(qgis_parent, qgis_app, block, layers, tmp_path)
    image = block["sim"].trajectory.image_id[1]
    dock.show_image(image)
    dock.viewer.type_combo.setCurrentText("line")
    i, (a, b) = _line_points(dock, image)[0]
    line_id = dock.session.control.line_ids[i]
    proj = dock.session.project(image)
    overlays = dock.viewer.overlays
    # a first click, then Esc: nothing stored, no prediction left
    _click(dock, a)
    assert dock.session.half_line is not None and dock.store.rows == []
    assert overlays.groups["predictions"].childItems()
    _key(dock, Qt.Key.Key_Escape)
    assert dock.session.half_line is None and not overlays.groups["predictions"].childItems()
    # the line: first click links the LiDAR line, whose predicted position is drawn
    ca = _click(dock, a)
    half = dock.session.half_line
    assert half is not None and half.target.target_id == line_id
    np.testing.assert_allclose(half.predicted, [proj.line_starts[i], proj.line_ends[i]])
    assert overlays.groups["predictions"].childItems() and dock.store.rows == []
    cb = _click(dock, b)
    rows = list(dock.store.rows)
    assert [(o.image_id, o.type, o.target_id) for o in rows] == [(image, "line", line_id)] * 2
    assert [(o.col, o.row) for o in rows] == [ca, cb]
    assert dock.session.half_line is None and not overlays.groups["predictions"].childItems()
    on_disk = read_observations_csv(tmp_path / "obs.csv")
    assert list(on_disk.type) == ["line", "line"] and set(on_disk.target_id) == {line_id}
    np.testing.assert_allclose(on_disk.pixels, [ca, cb], atol=1e-9)
    # one undo removes both ends (and the file follows), one redo restores both
    _key(dock, Qt.Key.Key_Z, CTRL)
    assert dock.store.rows == []
    lines = [t for t in (tmp_path / "obs.csv").read_text().splitlines() if t.strip()]
    assert len(lines) == 1 and lines[0].startswith("image_id")  # the header only
    _key(dock, Qt.Key.Key_Z, CTRL | Qt.KeyboardModifier.ShiftModifier)
    assert list(dock.store.rows) == rows
    dock.close()


def test_resect_from_the_dock_recovers_the_pose(
    qgis_parent,
    qgis_app,
    block,
    layers,
    tmp_path,
):
    """Lines measured in the dock (end points at the centres of the pixels holding the
    projected LiDAR lines: at most 0.5 px off), then Resect: the core job reads the saved
    rows and recovers the true pose within 4 of its reported sigmas (a-priori 0.5 px, larger
    than the 0.29 px RMS of the rounding); the dock shows the pose and a residual per line,
    and draws the residuals on the rows."""
    dock = _dock(qgis_parent, qgis_app, block, layers, tmp_path)
    image = block["sim"].trajectory.image_id[4]
    dock.show_image(image)
    dock.viewer.type_combo.setCurrentText("line")
    measured = _line_points(dock, image)
    assert len(measured) >= 6
    for _i, p in measured:
        ends = np.floor(p) + 0.5
        assert dock.pick(*ends[0]) == -1  # the first click: a half line
        assert dock.pick(*ends[1]) >= 0
    assert len(dock.store.rows) == 2 * len(measured)
    finished = []
    dock.resectionFinished.connect(finished.append)
    assert dock.run_resection()
    assert _wait(qgis_app, lambda: bool(finished), 120.0)
    assert finished == [True], dock.resection.error
    run = dock.resection.run
    assert run.image_id == image and run.image.data.n_lines == len(measured)
    truth = read_eo_csv(block["eo"])
    k = list(truth.image_id).index(image)
    std = run.result.std
    assert np.all(np.abs(run.result.xyz - truth.xyz[k]) < 4 * std[:3]), (
        run.result.xyz - truth.xyz[k],
        std[:3],
    )
    dopk = (run.result.opk - truth.opk[k] + np.pi) % (2 * np.pi) - np.pi
    assert np.all(np.abs(dopk) < 4 * std[3:]), (dopk, std[3:])
    # not a vacuous tolerance: about 20 px long lines of 5 cm control give 1.3 m and 0.1 deg
    # (the start has no approximate values: a wrong minimum would be metres and degrees off)
    assert np.all(std[:3] < 3.0) and np.all(std[3:] < 5e-3)
    # shown: the pose and one residual row per line; residuals drawn on every line point
    text = dock.resection_panel.result_label.text()
    assert image in text and text.count("<tr>") == 1 + len(measured)
    res = dock.session.shown_residuals()
    assert sorted(res) == list(range(len(dock.store.rows)))
    assert all(np.hypot(*v) < 1.5 for v in res.values())  # 3 sigma of 0.5 px
    assert (
        dock.viewer.overlays.counts["residuals"] > 0
        or dock.viewer.overlays.groups["residuals"].childItems()
    )
    dock.close()


def _distance_to_line(p, a, b) -> float:
    d = (b - a) / np.hypot(*(b - a))
    return float(abs((p - a) @ np.array([-d[1], d[0]])))


def test_line_ends_refined_on_the_image_edge(qgis_parent, qgis_app, block, layers, tmp_path):
    """With the Resection tab's refinement on, ends clicked 2 px off a roof edge (a ridge or
    hip between two roof faces painted in different greys) move onto it: their distance to
    the LiDAR line's projection (the truth, the edge being painted from it to the nearest
    pixel centre: 0.29 px RMS) drops from 2 px to a median below 0.6 px."""
    dock = _dock(qgis_parent, qgis_app, block, layers, tmp_path)
    image = block["sim"].trajectory.image_id[1]
    dock.show_image(image)
    dock.viewer.type_combo.setCurrentText("line")
    dock.resection_panel.refine_check.setChecked(True)
    proj = dock.session.project(image)
    before, after = [], []
    for i, p in _line_points(dock, image):
        a, b = proj.line_starts[i], proj.line_ends[i]
        d = (b - a) / np.hypot(*(b - a))
        off = p + 2.0 * np.array([-d[1], d[0]])
        tol = 10.0 / dock.view.zoom
        if not all(
            (t := dock.session.targets_at(image, q, "line", tol, proj)) and t[0].index == i
            for q in off
        ):
            continue
        n = len(dock.store.rows)
        assert dock.pick(*off[0]) == -1
        if dock.pick(*off[1]) < 0:
            continue  # (both ends refined onto the same point: nothing stored)
        for o, q in zip(dock.store.rows[n:], off):
            before.append(_distance_to_line(q, a, b))
            after.append(_distance_to_line(np.array([o.col, o.row]), a, b))
    before, after = np.array(before), np.array(after)
    assert len(after) >= 10 and np.allclose(before, 2.0)
    # measured: 36 ends, median 0.47 px, 31 within 1 px (one on two faces of equal grey: 2 px)
    assert np.median(after) < 0.6 and np.mean(after < 1.0) >= 0.7, np.round(after, 2)
    dock.close()
