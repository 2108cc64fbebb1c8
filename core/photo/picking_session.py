"""The state of the image point picking dock, without Qt or QGIS.

:class:`PickingSession` holds what the dock shows and edits:

- the observations (:class:`~.observation_list.ObservationList`: the rows of the observation
  table, with an undo and redo history of add, move and delete edits);
- the LiDAR control as core objects (:class:`~.control_features.ControlSet`: roof planes,
  lines and control points), made once from the QGIS layers' features
  (:class:`~.control_features.ControlFeature`) and, for the ids they list, from the plane,
  line and LCP tables; the overlays, the picking and the calibration all use these same
  objects;
- the tie point waiting for its other images (:class:`TiePrediction`), kept with the
  observations (their attached value): undo and redo restore it together with the rows, and
  deleting the last row of that point drops it;
- the last boresight calibration (:class:`~.boresight.BoresightRun`) and, from it, the residual
  of each current observation row.

The dock (plugin/) draws from it and wraps the observation list in a Qt object that saves the
file after every change. Pixels follow :mod:`core.photo.picking` (col, row; the centre of the
first pixel is (0.5, 0.5)); coordinates are in the mapping CRS of the exterior orientation.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..geometry.camera import Camera
from .control_features import ControlSet
from .observation_list import Observation, ObservationList
from .orientation import ExteriorOrientationTable
from .picking import PickingScene, nearest_point, nearest_polyline, polyline_tangent

if TYPE_CHECKING:
    from .boresight_result import BoresightRun
    from .bundle_result import BundleResult

__all__ = [
    "PICK_TYPES",
    "HalfLine",
    "PickTarget",
    "PickingSession",
    "ProjectedControl",
    "TiePrediction",
    "residual_summary",
]

Array = NDArray[np.float64]
#: observation types the dock measures, in the order of its type selector
PICK_TYPES = ("tie", "paper", "line", "lcp", "check")
_PREFIX = {"tie": "T", "paper": "P", "line": "R", "lcp": "C", "check": "K"}
#: the control list each observation type targets
_CONTROL_OF = {"tie": "planes", "paper": "planes", "line": "lines", "lcp": "lcps", "check": "lcps"}


# ----------------------------------------------------------------------------- picking
@dataclass(frozen=True)
class ProjectedControl:
    """The control projected into one image, pixels (NaN behind the camera).

    ``line_starts`` and ``line_ends`` are the LiDAR lines' projected end points; ``lines``
    the lines as drawn and hit: one polyline (K_i, 2) each, the two end points for a
    perspective camera, densified along the curved image for a fisheye one
    (:meth:`~.picking.PickingScene.project_segments`; ``rings`` likewise).
    """

    image_id: str
    rings: list[Array]
    line_starts: Array
    line_ends: Array
    lcps: Array
    lines: list[Array]


@dataclass(frozen=True, eq=False)
class TiePrediction:
    """A tie point measured in one image, waiting for the others: its predicted pixel in each
    image that sees it and is not measured yet.

    Immutable (the undo history keeps references): :meth:`without` gives the prediction once
    an image is measured. ``image_id`` is the image it was measured in, ``normal`` and
    ``point`` its plane (mapping CRS), so that moving that measurement moves the prediction.
    """

    point_id: str
    target_id: str
    pixels: Mapping[str, Array]
    image_id: str = ""
    normal: Array | None = None
    point: Array | None = None

    def without(self, image_id: str) -> TiePrediction | None:
        """The prediction left once ``image_id`` is measured (None: no image left)."""
        rest = {k: v for k, v in self.pixels.items() if k != image_id}
        return replace(self, pixels=rest) if rest else None


@dataclass(frozen=True)
class PickTarget:
    """What a click can measure: an observation type and its control object (index into the
    control list of that type, and its target id); ``range_m`` for planes."""

    kind: str
    index: int
    target_id: str
    range_m: float = math.nan


@dataclass(frozen=True, eq=False)
class HalfLine:
    """An image line being measured: its first click (``start``, pixels) in ``image_id`` and
    the LiDAR line it is linked to (``target``); ``predicted`` (2, 2) the LiDAR line's end
    points projected into that image with the current camera and EO (pixels, NaN behind);
    ``curve`` (K, 2) the line as drawn (:attr:`ProjectedControl.lines`: the two end points
    through a perspective camera, the curve it images as through a fisheye one)."""

    image_id: str
    target: PickTarget
    start: Array
    predicted: Array
    curve: Array | None = None

    def direction_at(self, pixel: ArrayLike) -> Array:
        """The direction of the LiDAR line's image at ``pixel`` (unit (2,), NaN when it has
        no edge): the tangent of its curve at the nearest point (:func:`.picking.polyline_tangent`),
        the chord of its end points without a curve."""
        curve = self.curve if self.curve is not None else self.predicted
        return polyline_tangent(pixel, curve)


#: shortest image line the dock stores, pixels (the resection refuses shorter ones)
MIN_LINE_PX = 1.0


class PickingSession:
    """The dock's state: observations, control, orientation, pending tie point, calibration.

    Parameters
    ----------
    observations : ObservationList, optional
        The list to work on (the dock's autosaved store shares it).
    """

    def __init__(self, observations: ObservationList | None = None) -> None:
        self.observations = observations if observations is not None else ObservationList()
        self.control = ControlSet()
        self.camera: Camera | None = None
        self.eo: ExteriorOrientationTable | None = None
        self.scene: PickingScene | None = None
        self.calibration: BoresightRun | None = None
        self._residuals: tuple[int, int, dict[int, Array]] | None = None
        #: the image line waiting for its second click (not an edit: Esc drops it)
        self.half_line: HalfLine | None = None
        #: residual rows of the last resection (:func:`core.jobs.resection.residual_rows`)
        self.resection_rows: list[tuple] = []
        #: the last bundle adjustment of the Bundle tab (:mod:`.dock_bundle`)
        self.bundle: BundleResult | None = None
        self._bundle_residuals: tuple[int, dict[int, Array]] | None = None

    @property
    def pending(self) -> TiePrediction | None:
        """The tie point waiting for its other images (the observations' attached value)."""
        return self.observations.attached

    @pending.setter
    def pending(self, value: TiePrediction | None) -> None:
        self.observations.attached = value

    # -- orientation --------------------------------------------------------------------------
    def set_orientation(
        self,
        camera: Camera | None,
        eo: ExteriorOrientationTable | None,
        crs: str = "",
    ) -> None:
        """The camera and the exterior orientation (mapping CRS ``crs``, EPSG code or WKT);
        the picking scene is made when both are given.

        Raises
        ------
        InputError
            No CRS, or an empty table (camera and table are kept, the scene is None).
        """
        self.camera, self.eo, self.scene = camera, eo, None
        if camera is not None and eo is not None:
            self.scene = PickingScene(eo, camera, crs)

    def has_orientation(self, image_id: str) -> bool:
        """The exterior orientation table lists the image (with or without a camera)."""
        return self.eo is not None and image_id in self.eo.image_id

    def oriented(self, image_id: str) -> bool:
        """The image has an exterior orientation (and a camera)."""
        return self.scene is not None and self.scene.has_image(image_id)

    def project(self, image_id: str) -> ProjectedControl:
        """The control in an oriented image."""
        sg, c = self.scene, self.control
        if sg is None:
            raise ValueError("no orientation")
        return ProjectedControl(
            image_id,
            sg.project_rings(image_id, c.outlines),
            sg.project(image_id, c.line_starts),
            sg.project(image_id, c.line_ends),
            sg.project(image_id, c.lcp_xyz),
            sg.project_segments(image_id, c.line_starts, c.line_ends),
        )

    def lines_curved(self) -> bool:
        """Whether the LiDAR lines image as curves (a fisheye camera).

        Through a fisheye lens an image line is measured as points on the curve the LiDAR
        line images as (each click a ``line`` row): the boresight calibration models every
        such point through the projection (its ray meets the line), while the resection's
        straight image-line model holds for perspective cameras only and leaves those rows
        out by name (plugin/resection_task.py).
        """
        cam = self.camera
        return cam is not None and not cam.is_perspective

    def footprint(self, image_id: str) -> Array | None:
        """Ground footprint of an image at the control's mean height (mapping CRS; 4 corners,
        or a fisheye's (4 K, 3) outline: :meth:`.picking.PickingScene.footprint`), or None."""
        if not self.oriented(image_id):
            return None
        return self.scene.footprint(image_id, self.control.ground_height())  # type: ignore[union-attr]

    # -- picking ------------------------------------------------------------------------------
    def targets_at(
        self,
        image_id: str,
        pixel: ArrayLike,
        kind: str,
        tol_px: float,
        projected: ProjectedControl | None = None,
    ) -> list[PickTarget]:
        """What a click at ``pixel`` of an oriented image measures as ``kind``.

        tie, paper: every plane whose outline holds the pixel, nearest to the camera first;
        line: the nearest line within ``tol_px``; lcp, check: the nearest control point within
        ``tol_px``. Empty when there is nothing. ``projected``: the control already projected
        into that image (:meth:`project`), so that it is not projected again. Lines are hit
        along their drawn polylines (the curved images of a fisheye camera).
        """
        c = self.control
        if projected is not None and projected.image_id != image_id:
            projected = None
        if kind in ("tie", "paper"):
            rings = projected.rings if projected is not None else None
            cands = self.scene.planes_under_pixel(  # type: ignore[union-attr]
                image_id, pixel, c.outlines, c.normals, c.centroids, rings
            )
            return [PickTarget(kind, p.index, c.plane_ids[p.index], p.range_m) for p in cands]
        proj = projected if projected is not None else self.project(image_id)
        if kind == "line":
            k, _d = nearest_polyline(pixel, proj.lines, tol_px)
            return [PickTarget(kind, k, c.line_ids[k])] if k >= 0 else []
        k, _d = nearest_point(pixel, proj.lcps, tol_px)
        return [PickTarget(kind, k, c.lcp_ids[k])] if k >= 0 else []

    def add_observation(self, image_id: str, pixel: ArrayLike, target: PickTarget) -> int:
        """Add the observation of a click on ``target``; returns its row index.

        Point ids: ``T<n>``/``P<n>`` for tie and paper points, ``R<line>_<n>`` for line points,
        ``C<lcp>``/``K<lcp>`` for control and check points. A tie point becomes the pending
        :class:`TiePrediction` (its pixel in the other images that see it), in the same
        undoable step as its row.
        """
        col, row = (float(v) for v in np.asarray(pixel, dtype=np.float64).reshape(2))
        obs, kind, tid = self.observations, target.kind, target.target_id
        if kind in ("tie", "paper"):
            point_id = obs.next_point_id(_PREFIX[kind])
        elif kind == "line":
            point_id = obs.next_point_id(f"R{tid}_")
        else:
            point_id = f"{_PREFIX[kind]}{tid}"
        new = Observation(image_id, point_id, col, row, kind, tid)
        if kind != "tie":
            return obs.add(new)
        plane = self.control.planes[target.index]
        pending = self._predict(point_id, tid, image_id, (col, row), plane.normal, plane.centroid)
        return obs.add(new, attached=pending)

    def start_line(
        self,
        image_id: str,
        pixel: ArrayLike,
        target: PickTarget,
        projected: ProjectedControl | None = None,
    ) -> HalfLine:
        """The first click of an image line on the LiDAR line ``target`` (kind ``line``): kept
        as :attr:`half_line` until :meth:`finish_line` or :meth:`cancel_line`. Through a
        fisheye camera the two clicks are points on the line's curved image
        (:meth:`lines_curved`), and the half line holds that curve."""
        if target.kind != "line":
            raise ValueError(f"an image line is linked to a LiDAR line, not a {target.kind}")
        if projected is None or projected.image_id != image_id:
            projected = self.project(image_id)
        k = target.index
        predicted = np.array([projected.line_starts[k], projected.line_ends[k]], dtype=float)
        curve = np.asarray(projected.lines[k], dtype=np.float64).reshape(-1, 2)
        start = np.array(pixel, dtype=np.float64).reshape(2)
        self.half_line = HalfLine(image_id, target, start, predicted, curve)
        return self.half_line

    def finish_line(self, image_id: str, pixel: ArrayLike) -> int:
        """The second click: the image line's two end points as two ``line`` rows of the
        linked LiDAR line's id, added in one undoable step; the index of the first row.

        -1 (nothing added, the half line kept) when no line is started in ``image_id`` or the
        two clicks are less than :data:`MIN_LINE_PX` apart.
        """
        h = self.half_line
        end = np.array(pixel, dtype=np.float64).reshape(2)
        if h is None or h.image_id != image_id:
            return -1
        if not float(np.hypot(*(end - h.start))) >= MIN_LINE_PX:
            return -1
        obs, tid = self.observations, h.target.target_id
        first = obs.next_point_id(f"R{tid}_")
        used = {o.point_id for o in obs.rows} | {first}
        n = int(first.rsplit("_", 1)[1]) + 1
        while f"R{tid}_{n}" in used:
            n += 1
        rows = [
            Observation(image_id, pid, float(p[0]), float(p[1]), "line", tid)
            for pid, p in ((first, h.start), (f"R{tid}_{n}", end))
        ]
        self.half_line = None
        return obs.add(rows, text=f"add line {first}, R{tid}_{n}")

    def cancel_line(self) -> bool:
        """Drop the half-measured image line; whether there was one."""
        had, self.half_line = self.half_line is not None, None
        return had

    def _predict(
        self,
        point_id: str,
        target_id: str,
        image_id: str,
        pixel: ArrayLike,
        normal: ArrayLike,
        point: ArrayLike,
        only: Iterable[str] | None = None,
    ) -> TiePrediction | None:
        """The prediction of a tie point measured at ``pixel`` of ``image_id`` on a plane (in
        the images ``only``, when given); None when no other image sees it."""
        pred = self.scene.predict_tie(image_id, pixel, normal, point)  # type: ignore[union-attr]
        if only is not None:
            keep = set(only)
            pred = {k: v for k, v in pred.items() if k in keep}
        if not pred:
            return None
        n = np.array(normal, dtype=np.float64).reshape(3)
        p = np.array(point, dtype=np.float64).reshape(3)
        return TiePrediction(point_id, target_id, pred, image_id, n, p)

    def prediction(self, image_id: str) -> Array | None:
        """The pending tie point's predicted pixel in an image, or None."""
        if self.pending is None:
            return None
        return self.pending.pixels.get(image_id)

    def confirm_prediction(self, image_id: str, pixel: ArrayLike | None = None) -> int:
        """Measure the pending tie point in an image, at ``pixel`` or (None) at its prediction;
        returns the new row index (-1: no prediction in that image). Undoing it brings the
        prediction in that image back."""
        at = self.prediction(image_id)
        p = self.pending
        if at is None or p is None:
            return -1
        col, row = (float(v) for v in np.asarray(at if pixel is None else pixel).reshape(2))
        return self.observations.add(
            Observation(image_id, p.point_id, col, row, "tie", p.target_id),
            attached=p.without(image_id),
        )

    def cancel_prediction(self) -> None:
        """Drop the pending tie point (not an edit: undoing the next edit brings back the
        prediction that was pending before it)."""
        self.pending = None

    def move(self, index: int, col: float, row: float) -> None:
        """Move an observation; when it is the measurement the pending tie point was predicted
        from, the prediction moves with it (in the same undoable step)."""
        obs = self.observations
        o, p = obs.rows[index], self.pending
        if (
            p is None
            or (o.point_id, o.image_id) != (p.point_id, p.image_id)
            or p.normal is None
            or self.scene is None
            or not self.scene.has_image(o.image_id)
        ):
            obs.move(index, col, row)
            return
        moved = self._predict(
            p.point_id, p.target_id, p.image_id, (col, row), p.normal, p.point, p.pixels
        )
        obs.move(index, col, row, attached=moved)

    def delete(self, indices: int | Iterable[int]) -> None:
        """Delete observations (one undoable step); deleting the last row of the pending tie
        point drops its prediction (it would otherwise be measured as a tie point without the
        image it was predicted from)."""
        obs = self.observations
        idx = {indices} if isinstance(indices, int) else set(indices)
        p = self.pending
        if p is not None and not any(
            o.point_id == p.point_id for k, o in enumerate(obs.rows) if k not in idx
        ):
            obs.delete(idx, attached=None)
        else:
            obs.delete(idx)

    def undo(self) -> bool:
        """Undo the last edit: the rows and the pending tie point as they were before it."""
        return self.observations.undo() is not None

    def redo(self) -> bool:
        """Redo the last undone edit: the rows and the pending tie point as they were after."""
        return self.observations.redo() is not None

    def observation_at(self, image_id: str, pixel: ArrayLike, tol_px: float) -> int | None:
        """Row index of the observation of an image nearest to ``pixel`` within ``tol_px``."""
        rows, px = self.observations.pixels_of_image(image_id)
        if not rows:
            return None
        k, _d = nearest_point(pixel, px, tol_px)
        return rows[k] if k >= 0 else None

    # -- calibration --------------------------------------------------------------------------
    def set_calibration(self, run: BoresightRun | None) -> None:
        """Keep a calibration result (None: forget it)."""
        self.calibration = run
        self._residuals = None

    def residuals(self) -> dict[int, Array]:
        """Residual (vx, vy) in pixels of the current rows the last calibration used, by row
        index (rows without a finite residual are left out).

        A calibration row belongs to the current row that equals it (same image, point, type,
        target, pixel and sigma; the n-th equal row to the n-th): a point moved or added since
        has none.
        """
        run = self.calibration
        if run is None:
            return {}
        key = (self.observations.version, id(run))
        if self._residuals is not None and self._residuals[:2] == key:
            return self._residuals[2]
        v = np.asarray(run.result.residuals.v_px, dtype=np.float64).reshape(-1, 2)
        where: dict[Observation, list[int]] = {}
        for k, o in enumerate(ObservationList.rows_of(run.observations)):
            where.setdefault(o, []).append(k)
        out: dict[int, Array] = {}
        for i, o in enumerate(self.observations.rows):
            ks = where.get(o)
            if ks:
                k = ks.pop(0)
                if np.isfinite(v[k]).all():
                    out[i] = v[k].copy()
        self._residuals = (*key, out)
        return out

    def residual_stats(self) -> tuple[int, float, float]:
        """(count, RMS, max) of the residual lengths of :meth:`residuals`, pixels."""
        v = np.array([math.hypot(*x) for x in self.residuals().values()])
        if v.size == 0:
            return 0, math.nan, math.nan
        return int(v.size), float(np.sqrt(np.mean(v**2))), float(v.max())

    # -- resection ----------------------------------------------------------------------------
    def set_resection(self, rows: Iterable[tuple]) -> None:
        """Keep the residual rows of a resection (:func:`core.jobs.resection.residual_rows`:
        image_id, point_id, type, target_id, vertex, col, row, vx, vy, distance_px, w,
        rejected, used); empty: forget them."""
        self.resection_rows = list(rows)

    def resection_residuals(self) -> dict[int, Array]:
        """Residual (vx, vy) in pixels of the last resection by current row index: a residual
        row belongs to the current row of the same image, point id and type."""
        if not self.resection_rows:
            return {}
        by_key = {
            (r[0], r[1], r[2]): np.array(r[7:9], dtype=np.float64) for r in self.resection_rows
        }
        out: dict[int, Array] = {}
        for i, o in enumerate(self.observations.rows):
            v = by_key.get((o.image_id, o.point_id, o.type))
            if v is not None and np.isfinite(v).all():
                out[i] = v
        return out

    def shown_residuals(self) -> dict[int, Array]:
        """The residuals the dock draws: the last calibration's, the last bundle
        adjustment's for the rows it adjusted, and the last resection's for the rows it used
        (those of the resected image)."""
        res, bundle = self.resection_residuals(), self.bundle_residuals()
        if not res and not bundle:
            return self.residuals()
        out = dict(self.residuals())
        out.update(bundle)
        out.update(res)
        return out

    # -- bundle adjustment --------------------------------------------------------------------
    def set_bundle(self, result: BundleResult | None) -> None:
        """Keep the result of a bundle adjustment of the dock's rows (None: forget it); the
        residuals of an earlier resection are forgotten (the bundle re-oriented the images)."""
        self.bundle = result
        self._bundle_residuals = None
        if result is not None:
            self.resection_rows = []

    def bundle_residuals(self) -> dict[int, Array]:
        """Residual (vx, vy) in pixels of the last bundle adjustment by current row index
        (:func:`.dock_bundle.residuals_by_row`)."""
        if self.bundle is None:
            return {}
        version = self.observations.version
        if self._bundle_residuals is None or self._bundle_residuals[0] != version:
            from .dock_bundle import residuals_by_row

            out = residuals_by_row(self.bundle, self.observations.to_observations())
            self._bundle_residuals = (version, out)
        return self._bundle_residuals[1]

    def boresight_summary(self) -> list[tuple[str, Array, float]]:
        """(group, (d_omega, d_phi, d_kappa) in arc-seconds, sigma0) of the last calibration."""
        if self.calibration is None:
            return []
        res = self.calibration.result
        return [(g, res.boresight_arcsec[k], float(res.sigma0)) for k, g in enumerate(res.groups)]


def residual_summary(rows: Iterable[tuple]) -> list[tuple[str, str, int, float, float, bool]]:
    """Per image line and per point of resection residual rows (see
    :meth:`PickingSession.set_resection`): (type, target_id, points, RMS and largest
    distance in pixels, rejected), in the rows' order. A line's distance is its points'
    signed distance from the projected LiDAR line, a point's the length of its residual.

    >>> rows = [("a", "R7_1", "line", "7", 1, 0, 0, 0.3, 0.4, 0.5, 0.1, False, True),
    ...         ("a", "R7_2", "line", "7", 2, 9, 0, 0, 0, -0.5, 0.1, False, True),
    ...         ("a", "C3", "lcp", "3", 0, 5, 5, 0.6, 0.8, 1.0, 0.2, False, True)]
    >>> [(t, g, n, round(rms, 3), round(mx, 3)) for t, g, n, rms, mx, _ in residual_summary(rows)]
    [('line', '7', 2, 0.5, 0.5), ('lcp', '3', 1, 1.0, 1.0)]
    """
    groups: dict[tuple[str, str, str], list[tuple]] = {}
    for r in rows:
        key = (r[0], r[2], r[3] if r[2] == "line" else r[1])
        groups.setdefault(key, []).append(r)
    out = []
    for (_img, kind, _pid), rs in groups.items():
        d = np.abs(np.array([float(r[9]) for r in rs]))
        out.append(
            (
                kind,
                str(rs[0][3]),
                len(rs),
                float(np.sqrt(np.mean(d**2))),
                float(d.max()),
                any(bool(r[11]) for r in rs),
            )
        )
    return out
