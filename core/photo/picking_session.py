"""The state of the image point picking dock, without Qt or QGIS.

:class:`PickingSession` holds what the dock shows and edits:

- the observations (:class:`~.observation_list.ObservationList`: the rows of the observation
  table, with an undo and redo history of add, move and delete edits);
- the LiDAR control as core objects (:class:`~.control_features.ControlSet`: roof planes,
  lines and control points), made once from the QGIS layers' features
  (:class:`~.control_features.ControlFeature`) and, for the ids they list, from the plane,
  line and LCP tables; the overlays, the picking and the calibration all use these same
  objects;
- the tie point waiting for its other images (:class:`TiePrediction`);
- the last boresight calibration (:class:`~.boresight.BoresightRun`) and, from it, the residual
  of each current observation row.

The dock (plugin/) draws from it and wraps the observation list in a Qt object that saves the
file after every change. Pixels follow :mod:`core.photo.picking` (col, row; the centre of the
first pixel is (0.5, 0.5)); coordinates are in the mapping CRS of the exterior orientation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..geometry.camera import Camera
from .control_features import ControlSet
from .observation_list import Observation, ObservationList
from .orientation import ExteriorOrientationTable
from .picking import PickingScene, nearest_point, nearest_segment

if TYPE_CHECKING:
    from .boresight import BoresightRun

__all__ = [
    "PICK_TYPES",
    "PickTarget",
    "PickingSession",
    "ProjectedControl",
    "TiePrediction",
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
    """The control projected into one image, pixels (NaN behind the camera)."""

    image_id: str
    rings: list[Array]
    line_starts: Array
    line_ends: Array
    lcps: Array


@dataclass
class TiePrediction:
    """A tie point measured in one image, waiting for the others: its predicted pixel in each
    image that sees it (entries are removed as they are measured)."""

    point_id: str
    target_id: str
    pixels: dict[str, Array]


@dataclass(frozen=True)
class PickTarget:
    """What a click can measure: an observation type and its control object (index into the
    control list of that type, and its target id); ``range_m`` for planes."""

    kind: str
    index: int
    target_id: str
    range_m: float = math.nan


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
        self.pending: TiePrediction | None = None
        self.calibration: BoresightRun | None = None
        self._residuals: tuple[int, int, dict[int, Array]] | None = None

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
        )

    def footprint(self, image_id: str) -> Array | None:
        """(4, 3) ground corners of an image at the control's mean height, or None."""
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
        ``tol_px``. Empty when there is nothing.
        """
        c = self.control
        if kind in ("tie", "paper"):
            cands = self.scene.planes_under_pixel(  # type: ignore[union-attr]
                image_id, pixel, c.outlines, c.normals, c.centroids
            )
            return [PickTarget(kind, p.index, c.plane_ids[p.index], p.range_m) for p in cands]
        proj = projected if projected is not None else self.project(image_id)
        if kind == "line":
            k, _d = nearest_segment(pixel, proj.line_starts, proj.line_ends, tol_px)
            return [PickTarget(kind, k, c.line_ids[k])] if k >= 0 else []
        k, _d = nearest_point(pixel, proj.lcps, tol_px)
        return [PickTarget(kind, k, c.lcp_ids[k])] if k >= 0 else []

    def add_observation(self, image_id: str, pixel: ArrayLike, target: PickTarget) -> int:
        """Add the observation of a click on ``target``; returns its row index.

        Point ids: ``T<n>``/``P<n>`` for tie and paper points, ``R<line>_<n>`` for line points,
        ``C<lcp>``/``K<lcp>`` for control and check points. A tie point becomes the pending
        :class:`TiePrediction` (its pixel in the other images that see it).
        """
        col, row = (float(v) for v in np.asarray(pixel, dtype=np.float64).reshape(2))
        obs, kind, tid = self.observations, target.kind, target.target_id
        if kind in ("tie", "paper"):
            point_id = obs.next_point_id(_PREFIX[kind])
        elif kind == "line":
            point_id = obs.next_point_id(f"R{tid}_")
        else:
            point_id = f"{_PREFIX[kind]}{tid}"
        index = obs.add(Observation(image_id, point_id, col, row, kind, tid))
        if kind == "tie":
            plane = self.control.planes[target.index]
            pred = self.scene.predict_tie(  # type: ignore[union-attr]
                image_id, (col, row), plane.normal, plane.centroid
            )
            self.pending = TiePrediction(point_id, tid, pred)
        return index

    def prediction(self, image_id: str) -> Array | None:
        """The pending tie point's predicted pixel in an image, or None."""
        if self.pending is None:
            return None
        return self.pending.pixels.get(image_id)

    def confirm_prediction(self, image_id: str, pixel: ArrayLike | None = None) -> int:
        """Measure the pending tie point in an image, at ``pixel`` or (None) at its prediction;
        returns the new row index (-1: no prediction in that image)."""
        at = self.prediction(image_id)
        if at is None or self.pending is None:
            return -1
        p = self.pending
        col, row = (float(v) for v in np.asarray(at if pixel is None else pixel).reshape(2))
        index = self.observations.add(
            Observation(image_id, p.point_id, col, row, "tie", p.target_id)
        )
        del p.pixels[image_id]
        if not p.pixels:
            self.pending = None
        return index

    def cancel_prediction(self) -> None:
        self.pending = None

    def observation_at(self, image_id: str, pixel: ArrayLike, tol_px: float) -> int | None:
        """Row index of the observation of an image nearest to ``pixel`` within ``tol_px``."""
        rows = self.observations.indices_of_image(image_id)
        if not rows:
            return None
        k, _d = nearest_point(pixel, self.observations.pixels(rows), tol_px)
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

    def boresight_summary(self) -> list[tuple[str, Array, float]]:
        """(group, (d_omega, d_phi, d_kappa) in arc-seconds, sigma0) of the last calibration."""
        if self.calibration is None:
            return []
        res = self.calibration.result
        return [(g, res.boresight_arcsec[k], float(res.sigma0)) for k, g in enumerate(res.groups)]
