"""Overlays of the picking view: LiDAR planes, lines and control points, observations, their
residual vectors and tie-point predictions, drawn in image pixels (scene units of
:class:`ImageView`) with cosmetic pens so that their width does not change with the zoom.

Each kind lives under its own parent item, toggled with :meth:`Overlays.set_visible`.
Positions come already projected (``core.picking.PickingScene``); NaN vertices (behind the
camera) are skipped.

A click must not redraw what did not change (an image may hold a thousand observations, each
a few graphics items): the observations and the residuals are *synchronised*
(:meth:`Overlays.set_observations` keeps the items of the markers that are still wanted and
only adds and removes the difference), and a change of the map selection restyles only the
planes and control points whose highlight changed (:meth:`Overlays.set_highlighted`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Hashable, Sequence

import numpy as np
from qgis.PyQt import sip
from qgis.PyQt.QtCore import QPointF, Qt, QTimer
from qgis.PyQt.QtGui import QBrush, QColor, QFont, QPainterPath, QPen, QPolygonF
from qgis.PyQt.QtWidgets import QGraphicsItem, QGraphicsPathItem, QGraphicsSimpleTextItem

__all__ = ["GROUPS", "Overlays"]

#: overlay groups, drawing order bottom to top
GROUPS = ("planes", "lines", "lcps", "residuals", "observations", "predictions")
_Z = {name: 1.0 + k for k, name in enumerate(GROUPS)}
COLOURS = {
    "planes": QColor(0, 200, 255),
    "highlight": QColor(255, 212, 0),
    "lines": QColor(255, 90, 200),
    "lcps": QColor(255, 60, 60),
    "residuals": QColor(255, 140, 0),
    "observations": QColor(60, 255, 60),
    "selected": QColor(255, 255, 255),
    "predictions": QColor(255, 255, 0),
}
_IGNORES_TRANSFORMATIONS = QGraphicsItem.GraphicsItemFlag.ItemIgnoresTransformations
#: Screen area of one label (a point id of 3-5 characters, 8 pt bold), px^2.
LABEL_SCREEN_PX2 = 400.0
#: Labels are drawn while, spread over the image, they would cover at most this share of it
#: on screen (at fit zoom a block's thousand labels would hide the image they name).
LABEL_COVER = 0.15


def labels_fit(count: int, image_px2: float, zoom: float) -> bool:
    """Whether ``count`` labels over an image of ``image_px2`` image pixels, seen at ``zoom``
    (screen px per image px), cover at most :data:`LABEL_COVER` of it on screen.

    >>> labels_fit(1336, 6000 * 4000, 0.13), labels_fit(1336, 6000 * 4000, 0.5)
    (False, True)
    """
    if count <= 0 or image_px2 <= 0:
        return True
    return count * LABEL_SCREEN_PX2 <= LABEL_COVER * image_px2 * zoom * zoom


def _pen(colour: QColor, width: float = 1.5, style=Qt.PenStyle.SolidLine) -> QPen:
    pen = QPen(colour, width, style)
    pen.setCosmetic(True)  # constant screen width at every zoom
    return pen


def _marker(shape: str, size: float) -> QPainterPath:
    """A marker path in screen pixels (drawn with ItemIgnoresTransformations)."""
    path = QPainterPath()
    s = size
    if shape == "cross":
        path.moveTo(-s, 0)
        path.lineTo(s, 0)
        path.moveTo(0, -s)
        path.lineTo(0, s)
    elif shape == "x":
        path.moveTo(-s, -s)
        path.lineTo(s, s)
        path.moveTo(-s, s)
        path.lineTo(s, -s)
    elif shape == "square":
        path.addRect(-s, -s, 2 * s, 2 * s)
    else:  # circle
        path.addEllipse(QPointF(0, 0), s, s)
    return path


def _finite_rows(a: np.ndarray) -> np.ndarray:
    """(N,) rows of an (N, k) array with only finite values."""
    return np.isfinite(a).all(axis=1) if a.size else np.zeros(len(a), dtype=bool)


class Overlays:
    """The overlay items of one QGraphicsScene, under one parent item per group."""

    def __init__(self, scene) -> None:
        self.scene = scene
        self.groups: dict[str, QGraphicsPathItem] = {}
        self.visible = {name: True for name in GROUPS}
        self.counts = {name: 0 for name in GROUPS}
        #: vertices of the LiDAR lines drawn (2 a line through a perspective camera)
        self.line_vertices = 0
        #: (shape, size) -> marker path; (colour name, width, style) -> pen
        self._paths: dict[tuple[str, float], QPainterPath] = {}
        self._pens: dict[tuple[str, float, object], QPen] = {}
        self._font = QFont()
        self._font.setPointSizeF(8.0)
        self._font.setBold(True)
        self._brushes = {name: QBrush(c) for name, c in COLOURS.items()}
        #: synchronised groups: key -> (key, items...)
        self._synced: dict[str, dict[Hashable, tuple]] = {}
        #: the selected observation: (row, its marker items) or None
        self._selected: tuple | None = None
        #: planes and LCPs by id: [(items..., hot)] for restyling the highlight
        self._by_id: dict[str, dict[str, list[list]]] = {"planes": {}, "lcps": {}}
        #: the labels (but the selected one's), drawn only while :func:`labels_fit`
        self._labels: list[QGraphicsSimpleTextItem] = []
        self.labels_shown = True
        self._zoom = 1.0
        self._recount = QTimer()
        self._recount.setSingleShot(True)
        self._recount.timeout.connect(self.update_labels)
        for name in GROUPS:
            self._new_group(name)

    def set_zoom(self, zoom: float) -> None:
        """The view's zoom changed (screen px per image px): labels follow :func:`labels_fit`."""
        self._zoom = float(zoom)
        self.update_labels()

    def update_labels(self) -> None:
        """Show or hide the labels by how many there are at this zoom (the image is the middle
        quarter of the scene rectangle, see ImageView)."""
        self._labels = [i for i in self._labels if not sip.isdeleted(i) and i.scene() is not None]
        rect = self.scene.sceneRect()
        shown = labels_fit(len(self._labels), rect.width() * rect.height() / 4, self._zoom)
        if shown != self.labels_shown:
            self.labels_shown = shown
            for item in self._labels:
                item.setVisible(shown)

    def _new_group(self, name: str) -> QGraphicsPathItem:
        group = QGraphicsPathItem()  # a parent without contents of its own
        group.setFlag(QGraphicsItem.GraphicsItemFlag.ItemHasNoContents, True)
        group.setZValue(_Z[name])
        group.setVisible(self.visible[name])
        self.scene.addItem(group)
        self.groups[name] = group
        self._synced[name] = {}
        if name == "observations":
            self._selected = None
        if name in self._by_id:
            self._by_id[name] = {}
        return group

    def clear(self, name: str) -> QGraphicsPathItem:
        """Empty one group (a fresh parent: removing the old one removes its children)."""
        old = self.groups.get(name)
        if old is not None:
            self.scene.removeItem(old)
        self.counts[name] = 0
        self._recount.start(0)
        return self._new_group(name)

    def clear_all(self) -> None:
        for name in GROUPS:
            self.clear(name)

    def set_visible(self, name: str, on: bool) -> None:
        self.visible[name] = bool(on)
        self.groups[name].setVisible(bool(on))

    # -- builders -----------------------------------------------------------------------------
    def _path(self, shape: str, size: float) -> QPainterPath:
        key = (shape, float(size))
        if key not in self._paths:
            self._paths[key] = _marker(shape, size)
        return self._paths[key]

    def _pen_of(self, colour: str, width: float, style=Qt.PenStyle.SolidLine) -> QPen:
        key = (colour, float(width), style)
        if key not in self._pens:
            self._pens[key] = _pen(COLOURS[colour], width, style)
        return self._pens[key]

    # (an item is set up before it joins its parent in the scene: each change of an item in a
    # scene notifies the scene, about a third of the cost of making it)
    def _label(self, parent, text: str, x: float, y: float, colour: str):
        item = QGraphicsSimpleTextItem(text)
        item.setBrush(self._brushes[colour])
        item.setFont(self._font)
        item.setFlag(_IGNORES_TRANSFORMATIONS, True)
        item.setPos(x, y)
        if colour != "selected":  # the selected point keeps its label at every zoom
            item.setVisible(self.labels_shown)
            self._labels.append(item)
            self._recount.start(0)  # once after this batch of items
        item.setParentItem(parent)
        return item

    def _add_marker(self, parent, x, y, shape, size, colour, width=1.5) -> QGraphicsPathItem:
        item = QGraphicsPathItem(self._path(shape, size))
        item.setPen(self._pen_of(colour, width))
        item.setFlag(_IGNORES_TRANSFORMATIONS, True)
        item.setPos(x, y)
        item.setParentItem(parent)
        return item

    def _sync(
        self, name: str, keys: list, make: Callable[[QGraphicsItem, Hashable], tuple]
    ) -> None:
        """Make the group show one bundle of items per key: bundles whose key is still wanted
        stay as they are, the others are removed, the missing ones made by ``make``.

        A bundle is ``(key, *items)``; the table keeps the key object it was made with, so a
        synchronisation leaves no new long-lived objects behind for what did not change
        (what would bring Python's full garbage collections, tens of ms, sooner).
        """
        parent, old = self.groups[name], self._synced[name]
        new: dict[Hashable, tuple] = {}
        for base in keys:
            key = base
            if key in new:  # the same marker twice (two rows at one place): number it
                n = 1
                while (base, n) in new:
                    n += 1
                key = (base, n)
            bundle = old.pop(key, None)
            if bundle is None:
                bundle = (key, *make(parent, base))
            new[bundle[0]] = bundle
        scene = self.scene
        for bundle in old.values():
            for item in bundle[1:]:
                scene.removeItem(item)
        self._synced[name] = new
        self._recount.start(0)  # fewer labels may fit again
        self.counts[name] = len(keys)

    # -- the control --------------------------------------------------------------------------
    def _plane_style(self, items, hot: bool) -> None:
        path_item, label = items
        colour = "highlight" if hot else "planes"
        path_item.setPen(self._pen_of(colour, 3.0 if hot else 1.5))
        if hot:
            fill = QColor(COLOURS[colour])
            fill.setAlpha(50)
            path_item.setBrush(QBrush(fill))
        else:
            path_item.setBrush(QBrush(Qt.BrushStyle.NoBrush))
        label.setBrush(self._brushes[colour])

    def _lcp_style(self, items, hot: bool) -> None:
        marker, label = items
        colour = "highlight" if hot else "lcps"
        marker.setPath(self._path("square", 9 if hot else 6))
        marker.setPen(self._pen_of(colour, 2.0))
        label.setBrush(self._brushes[colour])

    def set_planes(
        self, rings: Sequence[np.ndarray], ids: Sequence[str], highlighted: set[str] = frozenset()
    ) -> None:
        """Plane outlines (each (M, 2) pixels) with their ids at the ring centre."""
        group = self.clear("planes")
        by_id = self._by_id["planes"]
        for ring, pid in zip(rings, ids):
            r = np.asarray(ring, dtype=np.float64).reshape(-1, 2)
            if len(r) < 3 or not np.isfinite(r).all():
                continue
            path = QPainterPath()
            path.addPolygon(QPolygonF([QPointF(x, y) for x, y in r.tolist()]))
            path.closeSubpath()
            item = QGraphicsPathItem(path)
            cx, cy = r.mean(axis=0).tolist()
            items = (item, self._label(group, str(pid), cx, cy, "planes"))
            hot = str(pid) in highlighted
            self._plane_style(items, hot)
            item.setParentItem(group)
            by_id.setdefault(str(pid), []).append([*items, hot])
            self.counts["planes"] += 1

    def set_lines(self, polylines: Sequence[np.ndarray], ids: Sequence[str]) -> None:
        """LiDAR lines as polylines (each (K, 2) pixels: the two end points through a
        perspective camera, the densified curve through a fisheye one); a NaN row breaks a
        polyline (a stretch outside the projection's field), a line without two finite
        vertices in a run is not drawn. ``line_vertices`` counts the vertices drawn."""
        group = self.clear("lines")
        self.line_vertices = 0
        pen = self._pen_of("lines", 2.0, Qt.PenStyle.DashLine)
        for poly, lid in zip(polylines, ids):
            p = np.reshape(poly, (-1, 2))
            ok = _finite_rows(p)
            # runs of finite vertices: a run starts where the vertex before it is not finite
            starts = ok & ~np.r_[False, ok[:-1]]
            path, drawn = QPainterPath(), []
            for (x, y), good, first in zip(p.tolist(), ok.tolist(), starts.tolist()):
                if not good:
                    continue
                if first:
                    path.moveTo(x, y)
                else:
                    path.lineTo(x, y)
                drawn.append((x, y))
            if len(drawn) - int(starts.sum()) < 1:  # no segment at all
                continue
            item = QGraphicsPathItem(path)
            item.setPen(pen)
            item.setParentItem(group)
            mx, my = drawn[len(drawn) // 2] if len(drawn) > 2 else np.mean(drawn, axis=0)
            self._label(group, f"L{lid}", float(mx), float(my), "lines")
            self.counts["lines"] += 1
            self.line_vertices += len(drawn)

    def set_lcps(self, pixels: np.ndarray, ids: Sequence[str], highlighted=frozenset()) -> None:
        """LiDAR control points (P, 2) pixels."""
        group = self.clear("lcps")
        by_id = self._by_id["lcps"]
        p = np.reshape(pixels, (-1, 2))
        ok = _finite_rows(p)
        ids = [i for i, good in zip(ids, ok.tolist()) if good]
        for (x, y), cid in zip(p[ok].tolist(), ids):
            marker = QGraphicsPathItem()
            marker.setFlag(_IGNORES_TRANSFORMATIONS, True)
            marker.setPos(x, y)
            items = (marker, self._label(group, f"C{cid}", x + 2, y + 2, "lcps"))
            hot = str(cid) in highlighted
            self._lcp_style(items, hot)
            marker.setParentItem(group)
            by_id.setdefault(str(cid), []).append([*items, hot])
            self.counts["lcps"] += 1

    def set_highlighted(self, planes: set[str], lcps: set[str]) -> int:
        """Highlight the planes and LCPs with these ids (those selected on the map), restyling
        only the ones whose state changes; returns how many were restyled."""
        changed = 0
        for kind, hot_ids, style in (
            ("planes", planes, self._plane_style),
            ("lcps", lcps, self._lcp_style),
        ):
            for tid, entries in self._by_id[kind].items():
                hot = tid in hot_ids
                for entry in entries:
                    if entry[2] != hot:
                        style(entry[:2], hot)
                        entry[2] = hot
                        changed += 1
        return changed

    def highlighted(self, kind: str) -> set[str]:
        """Ids drawn highlighted (``kind`` "planes" or "lcps")."""
        return {t for t, entries in self._by_id[kind].items() if any(e[2] for e in entries)}

    # -- measurements -------------------------------------------------------------------------
    def _observation(self, parent, o) -> tuple:
        x, y = float(o.col), float(o.row)
        return (
            self._add_marker(parent, x, y, "cross", 7, "observations", 2.0),
            self._add_marker(parent, x, y, "circle", 7, "observations", 1.0),
            self._label(parent, str(o.point_id), x, y, "observations"),
        )

    def set_observations(self, rows: Sequence, selected: int = -1) -> None:
        """Measured points of the current image: ``rows`` are observation rows (``col``,
        ``row``, ``point_id``; immutable and hashable, as
        :class:`~lidarphoto.core.photo.observation_list.Observation`); ``rows[selected]`` is
        drawn larger, in white, on top. Only the markers of rows that changed are redrawn."""
        ok = [o for o in rows if math.isfinite(o.col) and math.isfinite(o.row)]
        self._sync("observations", ok, self._observation)
        sel = rows[selected] if 0 <= selected < len(rows) else None
        if sel is not None and not (math.isfinite(sel.col) and math.isfinite(sel.row)):
            sel = None
        if self._selected is not None and self._selected[0] == sel:
            return
        if self._selected is not None:
            for item in self._selected[1:]:
                if item.scene() is not None:
                    self.scene.removeItem(item)
            self._selected = None
        if sel is not None:
            parent, x, y = self.groups["observations"], float(sel.col), float(sel.row)
            items = (
                self._add_marker(parent, x, y, "cross", 10, "selected", 2.0),
                self._add_marker(parent, x, y, "circle", 10, "selected", 1.0),
                self._label(parent, str(sel.point_id), x, y, "selected"),
            )
            for item in items:
                item.setZValue(1.0)  # over the unselected markers
            self._selected = (sel, *items)

    def _residual(self, parent, key) -> tuple:
        x, y, dx, dy = key
        path = QPainterPath(QPointF(x, y))
        path.lineTo(x + dx, y + dy)
        item = QGraphicsPathItem(path)
        item.setPen(self._pen_of("residuals", 2.0))
        item.setParentItem(parent)
        return (item,)

    def set_residuals(self, pixels: np.ndarray, v: np.ndarray, scale: float) -> None:
        """Residual vectors: a segment from each point along ``v`` (N, 2) px times ``scale``.
        Only the vectors that changed are redrawn."""
        p, d = np.reshape(pixels, (-1, 2)), np.reshape(v, (-1, 2)) * float(scale)
        ok = _finite_rows(p) & _finite_rows(d)
        keys = [(*a, *b) for a, b in zip(p[ok].tolist(), d[ok].tolist())]
        self._sync("residuals", keys, self._residual)

    def set_predictions(self, pixels: np.ndarray, labels: Sequence[str]) -> None:
        """Predicted tie-point positions waiting for confirmation."""
        group = self.clear("predictions")
        p = np.reshape(pixels, (-1, 2))
        ok = _finite_rows(p)
        labels = [t for t, good in zip(labels, ok.tolist()) if good]
        for (x, y), text in zip(p[ok].tolist(), labels):
            self._add_marker(group, x, y, "x", 9, "predictions", 2.0)
            self._add_marker(group, x, y, "circle", 14, "predictions", 1.0)
            self._label(group, text + "?", x, y, "predictions")
            self.counts["predictions"] += 1

    def add_line_prediction(self, start: np.ndarray, predicted: np.ndarray, label: str) -> None:
        """An image line being measured: its first click and the linked LiDAR line's
        predicted position (its projected end points (2, 2) through a perspective camera,
        the curve it images as (K, 2) through a fisheye one; a NaN row breaks it), drawn
        solid over the dashed LiDAR lines (in the predictions group: the next
        :meth:`set_predictions` clears it)."""
        group = self.groups["predictions"]
        a = np.reshape(predicted, (-1, 2))
        ok = _finite_rows(a)
        path, drawn, pen_down = QPainterPath(), [], False
        for (x, y), good in zip(a.tolist(), ok.tolist()):
            if not good:
                pen_down = False
                continue
            if pen_down:
                path.lineTo(x, y)
            else:
                path.moveTo(x, y)
                pen_down = True
            drawn.append((x, y))
        if len(drawn) >= 2:
            item = QGraphicsPathItem(path)
            item.setPen(self._pen_of("predictions", 2.5))
            item.setParentItem(group)
            mx, my = drawn[len(drawn) // 2] if len(drawn) > 2 else np.mean(drawn, axis=0)
            self._label(group, label + "?", float(mx), float(my), "predictions")
        x, y = np.reshape(start, 2).tolist()
        self._add_marker(group, x, y, "circle", 10, "predictions", 2.0)
        self.counts["predictions"] += 1
