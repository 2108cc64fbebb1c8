"""The state of the image point picking dock, without Qt or QGIS.

:class:`PickingSession` holds what the dock shows and edits:

- the observations (:class:`ObservationList`: the rows of the observation table, with an undo
  and redo history of add, move and delete edits);
- the LiDAR control as core objects (:class:`ControlSet`: roof planes, lines and control
  points), made once from the QGIS layers' features (:class:`~.picking.ControlFeature`) and, for
  the ids they list, from the plane, line and LCP tables; the overlays, the picking and the
  calibration all use these same objects;
- the tie point waiting for its other images (:class:`TiePrediction`);
- the last boresight calibration (:class:`~.boresight.BoresightRun`) and, from it, the residual
  of each current observation row.

The dock (plugin/) draws from it and wraps the observation list in a Qt object that saves the
file after every change. Pixels follow :mod:`core.photo.picking` (col, row; the centre of the
first pixel is (0.5, 0.5)); coordinates are in the mapping CRS of the exterior orientation.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..geometry.planes import Plane
from ..lidar.control import ControlLine, ControlPoint
from .observations import DEFAULT_SIGMA_PX, ImageObservations
from .picking import (
    ControlFeature,
    PickingScene,
    lcp_from_feature,
    line_from_feature,
    nearest_point,
    nearest_segment,
    plane_from_feature,
)

if TYPE_CHECKING:
    from .boresight import BoresightRun

__all__ = [
    "PICK_TYPES",
    "AddRows",
    "ControlSet",
    "DeleteRows",
    "MoveRow",
    "Observation",
    "ObservationList",
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


# ----------------------------------------------------------------------------- observations
@dataclass(frozen=True)
class Observation:
    """One row of the observation table (:mod:`core.io.observations`): an image point in
    pixels (col, row) and what it measures."""

    image_id: str
    point_id: str
    col: float
    row: float
    type: str
    target_id: str
    sigma_px: float = DEFAULT_SIGMA_PX


@dataclass(frozen=True)
class AddRows:
    """Insert ``rows`` at index ``at``."""

    at: int
    rows: tuple[Observation, ...]
    text: str = ""

    def apply(self, rows: list[Observation]) -> None:
        rows[self.at : self.at] = self.rows

    def revert(self, rows: list[Observation]) -> None:
        del rows[self.at : self.at + len(self.rows)]


@dataclass(frozen=True)
class MoveRow:
    """Replace the row at ``index`` (``before``) by ``after`` (the same point, moved)."""

    index: int
    before: Observation
    after: Observation
    text: str = ""

    def apply(self, rows: list[Observation]) -> None:
        rows[self.index] = self.after

    def revert(self, rows: list[Observation]) -> None:
        rows[self.index] = self.before


@dataclass(frozen=True)
class DeleteRows:
    """Remove the rows ``removed`` ((index, row) pairs, ascending indices)."""

    removed: tuple[tuple[int, Observation], ...]
    text: str = ""

    def apply(self, rows: list[Observation]) -> None:
        for i, _ in reversed(self.removed):
            del rows[i]

    def revert(self, rows: list[Observation]) -> None:
        for i, row in self.removed:
            rows.insert(i, row)


Edit = Union[AddRows, MoveRow, DeleteRows]


class ObservationList:
    """The observation rows and the history of their edits (undo, redo).

    Every change is an edit object with ``apply`` and ``revert``; :meth:`push` applies one and
    records it (a new edit drops what was undone). :attr:`version` grows with every change.
    """

    def __init__(self, rows: Iterable[Observation] = ()) -> None:
        self.rows: list[Observation] = list(rows)
        self._done: list[Edit] = []
        self._undone: list[Edit] = []
        self.version = 0

    def reset(self, rows: Iterable[Observation] = ()) -> None:
        """Replace every row (a file opened); the history is cleared."""
        self.rows = list(rows)
        self._done.clear()
        self._undone.clear()
        self.version += 1

    # -- edits --------------------------------------------------------------------------------
    def push(self, edit: Edit) -> None:
        """Apply an edit and record it for undo."""
        edit.apply(self.rows)
        self._done.append(edit)
        self._undone.clear()
        self.version += 1

    def add(self, rows: Observation | Sequence[Observation], text: str = "") -> int:
        """Append one or more rows as one edit; the index of the first (-1: none given)."""
        batch = (rows,) if isinstance(rows, Observation) else tuple(rows)
        if not batch:
            return -1
        at = len(self.rows)
        self.push(AddRows(at, batch, text or f"add {batch[0].point_id}"))
        return at

    def move(self, index: int, col: float, row: float) -> None:
        """Move the point of row ``index`` to (col, row)."""
        before = self.rows[index]
        after = replace(before, col=float(col), row=float(row))
        self.push(MoveRow(index, before, after, f"move {before.point_id}"))

    def delete(self, indices: int | Iterable[int]) -> None:
        """Delete rows (one edit)."""
        idx = sorted({indices} if isinstance(indices, int) else set(indices))
        if idx:
            removed = tuple((i, self.rows[i]) for i in idx)
            self.push(DeleteRows(removed, f"delete {len(idx)} point(s)"))

    @property
    def can_undo(self) -> bool:
        return bool(self._done)

    @property
    def can_redo(self) -> bool:
        return bool(self._undone)

    def undo(self) -> Edit | None:
        """Revert the last edit; None when there is none."""
        if not self._done:
            return None
        edit = self._done.pop()
        edit.revert(self.rows)
        self._undone.append(edit)
        self.version += 1
        return edit

    def redo(self) -> Edit | None:
        """Apply again the last undone edit; None when there is none."""
        if not self._undone:
            return None
        edit = self._undone.pop()
        edit.apply(self.rows)
        self._done.append(edit)
        self.version += 1
        return edit

    # -- queries ------------------------------------------------------------------------------
    def indices_of_image(self, image_id: str) -> list[int]:
        return [k for k, o in enumerate(self.rows) if o.image_id == image_id]

    def image_ids(self) -> set[str]:
        return {o.image_id for o in self.rows}

    def pixels(self, indices: Sequence[int]) -> Array:
        """(N, 2) pixels of the given rows."""
        return np.array([[self.rows[k].col, self.rows[k].row] for k in indices]).reshape(-1, 2)

    def next_point_id(self, prefix: str) -> str:
        """A point id ``<prefix><n>`` not used yet."""
        used = {o.point_id for o in self.rows}
        n = len(self.rows) + 1
        while f"{prefix}{n}" in used:
            n += 1
        return f"{prefix}{n}"

    def to_observations(self) -> ImageObservations:
        r = self.rows
        return ImageObservations.from_arrays(
            [o.image_id for o in r],
            [o.point_id for o in r],
            np.array([[o.col, o.row] for o in r], dtype=np.float64).reshape(-1, 2),
            np.array([o.sigma_px for o in r], dtype=np.float64),
            [o.type for o in r],
            [o.target_id for o in r],
        )

    @staticmethod
    def rows_of(obs: ImageObservations) -> list[Observation]:
        """The rows of an observation table, in its order."""
        return [
            Observation(i, p, float(c), float(r), t, g, float(s))
            for i, p, (c, r), s, t, g in zip(
                obs.image_id, obs.point_id, obs.pixels, obs.sigma_px, obs.type, obs.target_id
            )
        ]


# ----------------------------------------------------------------------------- control
@dataclass(frozen=True)
class ControlSet:
    """The LiDAR control of the dock: planes, lines and control points with the target ids the
    observations name them by (parallel tuples). Mapping CRS of the exterior orientation.

    ``skipped`` counts the layer features that gave no object (e.g. an outline without heights
    and without plane parameters), by kind.
    """

    planes: tuple[Plane, ...] = ()
    plane_ids: tuple[str, ...] = ()
    lines: tuple[ControlLine, ...] = ()
    line_ids: tuple[str, ...] = ()
    lcps: tuple[ControlPoint, ...] = ()
    lcp_ids: tuple[str, ...] = ()
    skipped: dict[str, int] = field(default_factory=dict)

    @classmethod
    def from_features(
        cls,
        planes: Iterable[ControlFeature] = (),
        lines: Iterable[ControlFeature] = (),
        lcps: Iterable[ControlFeature] = (),
    ) -> ControlSet:
        """Core objects of layer features (:func:`~.picking.plane_from_feature` and the line
        and LCP ones); features without a usable geometry are counted in ``skipped``."""
        out: dict[str, tuple] = {}
        skipped: dict[str, int] = {}
        for kind, feats, make in (
            ("planes", planes, plane_from_feature),
            ("lines", lines, line_from_feature),
            ("lcps", lcps, lcp_from_feature),
        ):
            objs, ids = [], []
            for f in feats:
                obj = make(f)
                if obj is None:
                    skipped[kind] = skipped.get(kind, 0) + 1
                    continue
                objs.append(obj)
                ids.append(str(f.id))
            out[kind] = (tuple(objs), tuple(ids))
        return cls(*out["planes"], *out["lines"], *out["lcps"], skipped=skipped)

    def with_tables(
        self,
        planes: Sequence[Plane] | None = None,
        lines: Sequence[ControlLine] | None = None,
        lcps: Sequence[ControlPoint] | None = None,
    ) -> ControlSet:
        """The control with the rows of the plane, line and LCP tables (None: no table).

        A table row replaces the layer's object of the same id (its parameters and full
        covariance are the LiDAR adjustment's; a plane keeps the layer's outline); rows
        without a layer feature are added (a plane without an outline is not drawn and
        cannot be clicked, but the calibration uses it).
        """
        out = {}
        for kind, table in (("planes", planes), ("lines", lines), ("lcps", lcps)):
            objs, ids = self.items(kind)
            if table is None:
                out[kind] = (objs, ids)
                continue
            layer = {str(o.id) if o.id >= 0 else i: k for k, (o, i) in enumerate(zip(objs, ids))}
            new_objs, new_ids, used = [], [], set()
            for t in table:
                k = layer.get(str(t.id))
                if k is None:
                    new_objs.append(t)
                    new_ids.append(str(t.id))
                    continue
                used.add(k)
                new_objs.append(t.with_outline(objs[k].outline) if kind == "planes" else t)
                new_ids.append(ids[k])
            for k, (o, i) in enumerate(zip(objs, ids)):
                if k not in used:
                    new_objs.append(o)
                    new_ids.append(i)
            out[kind] = (tuple(new_objs), tuple(new_ids))
        return ControlSet(*out["planes"], *out["lines"], *out["lcps"], skipped=self.skipped)

    def items(self, kind: str) -> tuple[tuple, tuple[str, ...]]:
        """(objects, target ids) of ``"planes"``, ``"lines"`` or ``"lcps"``."""
        return {
            "planes": (self.planes, self.plane_ids),
            "lines": (self.lines, self.line_ids),
            "lcps": (self.lcps, self.lcp_ids),
        }[kind]

    def for_calibration(self) -> tuple[list[Plane], list[ControlLine], list[ControlPoint]]:
        """Planes, lines and LCPs with an integer id (the tables' key), first of each id."""
        out = []
        for kind in ("planes", "lines", "lcps"):
            seen: set[int] = set()
            keep = []
            for o in self.items(kind)[0]:
                if o.id >= 0 and o.id not in seen:
                    seen.add(o.id)
                    keep.append(o)
            out.append(keep)
        return out[0], out[1], out[2]

    # -- arrays -------------------------------------------------------------------------------
    @property
    def outlines(self) -> list[Array]:
        return [p.outline for p in self.planes]

    @property
    def normals(self) -> Array:
        return np.array([p.normal for p in self.planes], dtype=np.float64).reshape(-1, 3)

    @property
    def centroids(self) -> Array:
        return np.array([p.centroid for p in self.planes], dtype=np.float64).reshape(-1, 3)

    @property
    def line_starts(self) -> Array:
        return np.array([ln.start for ln in self.lines], dtype=np.float64).reshape(-1, 3)

    @property
    def line_ends(self) -> Array:
        return np.array([ln.end for ln in self.lines], dtype=np.float64).reshape(-1, 3)

    @property
    def lcp_xyz(self) -> Array:
        return np.array([c.xyz for c in self.lcps], dtype=np.float64).reshape(-1, 3)

    def ground_height(self) -> float:
        """Mean height of the plane outlines, else of the control points, else 0."""
        zs = [p.outline[:, 2] for p in self.planes if len(p.outline)]
        if zs:
            return float(np.nanmean(np.concatenate(zs)))
        if self.lcps:
            return float(np.nanmean(self.lcp_xyz[:, 2]))
        return 0.0


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
        self.scene: PickingScene | None = None
        self.pending: TiePrediction | None = None
        self.calibration: BoresightRun | None = None
        self._residuals: tuple[int, int, dict[int, Array]] | None = None

    # -- orientation --------------------------------------------------------------------------
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
