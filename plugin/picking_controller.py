"""Clicks in the picking dock's image -> observations, and what the image and the table show.

The decisions (which plane, line or control point a click measures, the point ids, the tie
point's prediction in the other images, the residuals of the last calibration) are the core
:class:`~lidarphoto.core.photo.picking_session.PickingSession`'s; this glue asks the user when
outlines overlap, selects the target on the map, and redraws the overlays and the table.

What a click redraws is what it changed: the observation markers are synchronised (only the
new, moved or removed ones are redrawn), the table is a model reset (Qt reads only the rows on
screen), and the map selection it makes restyles only the highlighted plane or control point.
The control is projected again only when the image, the orientation or the control change
(:meth:`PickingController.refresh`).

With a fisheye camera the LiDAR lines are drawn and hit as the curves they image as (the
session's polylines), and an image line's two clicks are points on that curve (two ``line``
rows, which the boresight calibration models through the projection; the resection's
straight-line model leaves them out by name). The line being measured is drawn as its
curve, and a click refined on the image's edge is refined across the curve's tangent at the
click (core.photo.line_edge refines across a straight edge: over its +-3 px of profiles a
curve of radius R bends 2 / R px on average, 0.01 px for R = 200 px).
"""

from __future__ import annotations

import bisect
import math

import numpy as np
from qgis.PyQt.QtCore import QCoreApplication, QObject, QPointF, QTimer
from qgis.PyQt.QtGui import QCursor
from qgis.PyQt.QtWidgets import QMenu

from ..core.photo.line_edge import refine_edge_point
from ..core.photo.picking_session import PickTarget, ProjectedControl

__all__ = ["HIT_SCREEN_PX", "PickingController"]

#: hit tolerance of lines, control points and observations, screen pixels
HIT_SCREEN_PX = 10.0
#: the window read around a line end refined on the image's edge, pixels
_EDGE_WINDOW_PX = 25
#: half side of the refine action's template and its NCC search radius, pixels
_REFINE_HALF_PX = 10
_REFINE_SEARCH_PX = 6
_LAYER_OF = {"tie": "planes", "paper": "planes", "lcp": "lcps", "check": "lcps"}


class PickingController(QObject):
    """Picking and drawing for one dock (its session, store, viewer, table and map links)."""

    def __init__(self, dock) -> None:
        super().__init__(dock)
        self.dock = dock
        self.session, self.store = dock.session, dock.store
        self.viewer, self.table = dock.viewer, dock.table
        self.projected: ProjectedControl | None = None
        self.selected_index = -1
        self._later = 0  # hold_markers() depth
        self._missed = False  # a marker draw was skipped meanwhile
        self._scheduled = False  # ... and is scheduled
        self.viewer.view.hit_test = self.hit_observation
        self.viewer.view.pointMoved.connect(self.moved)
        self.viewer.residual_scale.valueChanged.connect(lambda *_: self.draw_observations())
        self.table.rowSelected.connect(self.select_row)
        self.store.changed.connect(self.store_changed)

    def tr(self, text: str) -> str:
        return QCoreApplication.translate("PickingController", text)  # the context lupdate gives it

    def oriented(self) -> bool:
        return self.session.oriented(self.dock.current_image) and self.viewer.source is not None

    # -- drawing ------------------------------------------------------------------------------
    def highlighted(self) -> tuple[set[str], set[str]]:
        """Ids of the planes and LCPs selected on the map."""
        links = self.dock.loader.links
        return links.selected("planes"), links.selected("lcps")

    def refresh(self, *_args) -> None:
        """Project the control into the current image and redraw every overlay (the image,
        the orientation or the control changed)."""
        overlays = self.viewer.overlays
        self.projected = None
        if not self.oriented():
            overlays.clear_all()
            self.fill_table()
            return
        p = self.projected = self.session.project(self.dock.current_image)
        control = self.session.control
        hot_planes, hot_lcps = self.highlighted()
        overlays.set_planes(p.rings, control.plane_ids, hot_planes)
        overlays.set_lines(p.lines, control.line_ids)
        overlays.set_lcps(p.lcps, control.lcp_ids, hot_lcps)
        self.draw_observations()
        self.fill_table()

    def selection_changed(self, *_args) -> None:
        """The selection of the plane or LCP layer changed on the map: restyle the planes and
        control points whose highlight changed (nothing is projected again)."""
        if self.projected is not None:
            self.viewer.overlays.set_highlighted(*self.highlighted())

    def hold_markers(self) -> None:
        """Draw no observation markers until :meth:`release_markers` (the dock's opening:
        the image and the control are on screen first; the markers come in a turn of the
        event loop of their own)."""
        self._later += 1

    def release_markers(self) -> None:
        self._later = max(0, self._later - 1)
        if not self._later and self._missed:
            self._missed, self._scheduled = False, True
            QTimer.singleShot(0, self._draw_later)

    @property
    def markers_held(self) -> bool:
        """Markers are held, or their draw is scheduled."""
        return bool(self._later) or self._missed or self._scheduled

    def _draw_later(self) -> None:
        self._scheduled = False
        try:
            self.draw_observations()
        except RuntimeError:  # the dock was deleted meanwhile
            pass

    def draw_observations(self) -> None:
        """The observations of the current image, their residuals and the prediction (only
        what changed is redrawn)."""
        if self._later:
            self._missed = True
            return
        img, overlays, log = self.dock.current_image, self.viewer.overlays, self.store.log
        rows = log.indices_of_image(img) if self.oriented() else []
        all_rows = log.rows
        k, sel = self.selected_index, -1
        if 0 <= k < len(all_rows) and all_rows[k].image_id == img:
            sel = bisect.bisect_left(rows, k)  # (rows ascending, k among them)
        overlays.set_observations([all_rows[k] for k in rows], sel)
        res = self.session.shown_residuals()
        if res:
            drawn = [k for k in rows if k in res]
            px, v = log.pixels(drawn), np.array([res[k] for k in drawn]).reshape(-1, 2)
        else:
            px = v = np.empty((0, 2))
        overlays.set_residuals(px, v, self.viewer.residual_scale.value())
        self.draw_predictions()

    def draw_predictions(self) -> None:
        """The pending tie point's prediction in the current image (if any), and the image
        line being measured with its LiDAR line's predicted position."""
        pending = self.session.pending
        pred = self.session.prediction(self.dock.current_image) if self.oriented() else None
        self.viewer.overlays.set_predictions(
            np.reshape(pred if pred is not None else [], (-1, 2)),
            [pending.point_id] if pred is not None and pending is not None else [],
        )
        half = self.session.half_line
        if half is not None and half.image_id == self.dock.current_image and self.oriented():
            self.viewer.overlays.add_line_prediction(
                half.start,
                half.curve if half.curve is not None else half.predicted,
                f"L{half.target.target_id}",
            )

    def fill_table(self) -> None:
        log = self.store.log
        rows = log.indices_of_image(self.dock.current_image)
        self.table.fill(log.rows, rows, self.session.shown_residuals(), self.selected_index)

    def store_changed(self) -> None:
        if self.selected_index >= len(self.store.rows):
            self.selected_index = -1
        if self.oriented():
            self.draw_observations()
        else:
            self.viewer.overlays.clear("observations")
        self.fill_table()

    # -- picking ------------------------------------------------------------------------------
    def _choose(self, targets: list[PickTarget]) -> PickTarget | None:
        """The plane of a click; the user chooses when outlines overlap (None: cancelled)."""
        if len(targets) == 1:
            return targets[0]
        labels = [
            self.tr("plane {} ({:.1f} m away)").format(t.target_id, t.range_m) for t in targets
        ]
        return self.dock.choose_candidate(targets, labels)

    def choose_from_menu(self, candidates: list, labels: list[str]):
        """Let the user resolve an ambiguous plane (menu at the cursor); None: cancelled."""
        menu = QMenu(self.dock)
        actions = [menu.addAction(label) for label in labels]
        chosen = menu.exec(QCursor.pos())
        return candidates[actions.index(chosen)] if chosen in actions else None

    def pick(self, col: float, row: float) -> int:
        """A click at a pixel: add an observation of the current type; its row index, or -1
        (with a message) when nothing was added."""
        dock, session = self.dock, self.session
        img = dock.current_image
        if self.viewer.source is None:
            dock.message(self.tr("No image shown."), warning=True)
            return -1
        if not self.oriented():
            dock.message(
                self.tr(
                    "Image {} has no orientation: picking needs the camera and the "
                    "exterior orientation."
                ).format(img),
                warning=True,
            )
            return -1
        if session.prediction(img) is not None:
            return self._added(session.confirm_prediction(img, (col, row)))  # corrected
        kind = self.viewer.type_combo.currentText()
        half = session.half_line
        if kind == "line" and half is not None and half.image_id == img:
            return self._line_end(img, col, row)
        session.cancel_line()  # (another type or image since the first click)
        tol = HIT_SCREEN_PX / max(self.viewer.view.zoom, 1e-9)
        targets = session.targets_at(img, (col, row), kind, tol, self.projected)
        if not targets:
            what = {"tie": "plane", "paper": "plane", "line": "line"}.get(kind, "lcp")
            self.dock.message(
                {
                    "plane": self.tr("No roof plane under the cursor."),
                    "line": self.tr("No line within {:.0f} px.").format(HIT_SCREEN_PX),
                    "lcp": self.tr("No control point within {:.0f} px.").format(HIT_SCREEN_PX),
                }[what]
            )
            return -1
        target = self._choose(targets)
        if target is None:
            return -1
        if kind in _LAYER_OF:
            dock.loader.links.select(_LAYER_OF[kind], target.target_id)
        if kind == "line":  # the first click of an image line: its end comes next
            half = session.start_line(img, (col, row), target, self.projected)
            # across the LiDAR line's image at the click (its curve's tangent: fisheye)
            refined = self._on_edge(col, row, half.direction_at((col, row)))
            if refined is not None:
                session.start_line(img, refined, target, self.projected)
            dock.message(
                self.tr("Line on LiDAR line {}: click its other end (Esc cancels).").format(
                    target.target_id
                )
            )
            self.draw_predictions()
            return -1
        index = session.add_observation(img, (col, row), target)  # saved by _added
        point_id = self.store.rows[index].point_id
        if kind == "tie":
            n = len(session.pending.pixels) if session.pending is not None else 0
            dock.message(
                self.tr(
                    "Tie {} on plane {}: predicted in {} other image(s) "
                    "(Enter accepts, click corrects)."
                ).format(point_id, target.target_id, n)
            )
        elif kind == "paper":
            dock.message(self.tr("{} on plane {}.").format(point_id, target.target_id))
        return self._added(index)

    def _line_end(self, img: str, col: float, row: float) -> int:
        """The second click of an image line: its two end points are added (one undo)."""
        half = self.session.half_line
        tid = half.target.target_id  # type: ignore[union-attr]
        # across the line measured so far (the prediction's direction when it is short);
        # through a fisheye, across the tangent of the line's curved image at the click
        d = np.array([col, row]) - half.start  # type: ignore[union-attr]
        if self.session.lines_curved() or np.hypot(*d) < 5.0:
            d = half.direction_at((col, row))  # type: ignore[union-attr]
        refined = self._on_edge(col, row, d)
        index = self.session.finish_line(img, refined if refined is not None else (col, row))
        if index < 0:
            self.dock.message(self.tr("The line's ends must be 1 px apart or more."))
            return -1
        self.dock.message(self.tr("Image line of LiDAR line {} measured.").format(tid))
        self.draw_predictions()
        return self._added(index + 1)

    def _on_edge(self, col: float, row: float, direction) -> np.ndarray | None:
        """The click refined across the edge of ``direction`` (image pixels), when the
        Resection tab asks for it; None: not asked, or no edge near."""
        source = self.viewer.source
        if source is None or not self.dock.resection_panel.refine_check.isChecked():
            return None
        if not np.isfinite(direction).all():
            return None
        half = _EDGE_WINDOW_PX // 2
        x0, y0 = max(0, int(col) - half), max(0, int(row) - half)
        n = _EDGE_WINDOW_PX
        window = source.read_raw(x0, y0, n, n, n, n)
        if window.size == 0:
            return None
        grey = window.astype(np.float64).mean(axis=2)
        return refine_edge_point(grey, (x0, y0), (col, row), direction)

    def cancel_line(self) -> bool:
        """Drop the half-measured image line (Esc); whether there was one."""
        if not self.session.cancel_line():
            return False
        self.draw_predictions()
        return True

    def _added(self, index: int) -> int:
        if index >= 0:
            self.selected_index = index
            self.store.edited()  # saved; the markers and the table follow (store_changed)
        return index

    def accept_prediction(self) -> int:
        """Accept the predicted position of the pending tie point in the current image."""
        return self._added(self.session.confirm_prediction(self.dock.current_image))

    def cancel_prediction(self) -> None:
        self.session.cancel_prediction()
        self.draw_predictions()

    # -- editing ------------------------------------------------------------------------------
    def hit_observation(self, col: float, row: float, tol: float):
        if not self.oriented():
            return None
        return self.session.observation_at(self.dock.current_image, (col, row), tol)

    def moved(self, key, col: float, row: float) -> None:
        """A point dragged in the image (the pending prediction follows its first
        measurement: the session's move)."""
        self.selected_index = int(key)
        self.store.move(int(key), col, row)

    def refine_selected(self) -> bool:
        """Snap the selected observation to the least-squares match of the same point's
        observation in another image (the template); True when it moved. The matching is the
        core's (:func:`~lidarphoto.core.photo.least_squares_matching.match_point`)."""
        from ..core.photo.least_squares_matching import match_point
        from .image_source import ImageSource, ImageSourceError

        img, source = self.dock.current_image, self.viewer.source
        k = self.selected_index
        if (
            source is None
            or not 0 <= k < len(self.store.rows)
            or (self.store.rows[k].image_id != img)
        ):
            self.dock.message(self.tr("Select a point of the image shown first."), warning=True)
            return False
        obs = self.store.rows[k]
        others = [o for o in self.store.rows if o.point_id == obs.point_id and o.image_id != img]
        path = next(
            (
                self.dock.image_paths.get(o.image_id)
                for o in others
                if self.dock.image_paths.get(o.image_id)
            ),
            None,
        )
        if path is None:
            self.dock.message(
                self.tr("Point {} is measured in no other image: no template.").format(
                    obs.point_id
                ),
                warning=True,
            )
            return False
        tmpl = next(o for o in others if self.dock.image_paths.get(o.image_id) == path)
        half, search = _REFINE_HALF_PX, _REFINE_SEARCH_PX
        try:
            other = ImageSource(path, stretch_now=False)
        except ImageSourceError as exc:
            self.dock.message(str(exc), warning=True)
            return False
        try:
            t_win, t_xy = _grey_window(other, tmpl.col, tmpl.row, half + 3)
        finally:
            other.close()
        s_win, s_xy = _grey_window(source, obs.col, obs.row, half + search + 6)
        m = match_point(t_win, t_xy, s_win, s_xy, half, search)
        if not m.ok:
            self.dock.message(
                self.tr("Point {} not refined: {}").format(obs.point_id, m.reason), warning=True
            )
            return False
        col = obs.col + (m.col - s_xy[0])
        row = obs.row + (m.row - s_xy[1])
        self.store.move(k, col, row)
        self.dock.message(
            self.tr(
                "Point {} refined by least-squares matching on image {}: moved {:.2f} px, "
                "sigma {:.3f} px, correlation {:.2f}."
            ).format(
                obs.point_id,
                tmpl.image_id,
                math.hypot(col - obs.col, row - obs.row),
                max(m.sigma_px),
                m.correlation,
            )
        )
        return True

    def delete_selected(self) -> None:
        """Delete the selected point (its pending prediction goes with its last row)."""
        if 0 <= self.selected_index < len(self.store.rows):
            k, self.selected_index = self.selected_index, -1
            self.store.delete(k)

    def select_row(self, k: int) -> None:
        """A row chosen in the table: select its target on the map, centre the view on it."""
        self.selected_index = k
        o = self.store.rows[k]
        if o.type in _LAYER_OF:
            self.dock.loader.links.select(_LAYER_OF[o.type], o.target_id)
        self.viewer.view.centerOn(QPointF(o.col, o.row))
        self.draw_observations()


def _grey_window(source, col: float, row: float, half: int) -> tuple[np.ndarray, tuple]:
    """Grey window of ``source`` around pixel (col, row) (corner convention) and the point's
    array coordinates in it."""
    c0, r0 = math.floor(col) - half, math.floor(row) - half
    n = 2 * half + 1
    raw = source.read_raw(c0, r0, n, n, n, n)
    # read_raw clips at the border: the window starts at max(0, c0)
    c0, r0 = max(c0, 0), max(r0, 0)
    return raw.astype(np.float64).mean(axis=2), (col - 0.5 - c0, row - 0.5 - r0)
