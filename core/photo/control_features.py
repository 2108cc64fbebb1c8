"""LiDAR control from GIS features: roof planes, lines and control points made from the
geometries and attributes of a layer's features (plain values, no QGIS), and the set of them
the picking dock shows and the calibration uses.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..geometry.planes import Plane, fit_plane, orient_up, slope_aspect_deg
from ..lidar.control import LINE_KINDS, LINE_PARAMETERS, ControlLine, ControlPoint
from .boresight_options import BoresightOptions

Array = NDArray[np.float64]

#: Standard deviation (metres, each axis) given to a LiDAR line or control point whose layer
#: carries no precision: the LiDAR sigma of :class:`~.boresight_options.BoresightOptions`
#: (not a surveyed point's, :data:`~.bundle_setup.DEFAULT_CONTROL_SIGMA_M`).
DEFAULT_LIDAR_SIGMA_M: float = BoresightOptions.lidar_sigma_m
_PLANE_COV = tuple(f"cov_{'abcd'[i]}{'abcd'[j]}" for i, j in zip(*np.triu_indices(4)))
_LINE_COV = tuple(f"cov_{i}{j}" for i, j in zip(*np.triu_indices(6)))
_LCP_COV = tuple(f"cov_{'xyz'[i]}{'xyz'[j]}" for i, j in zip(*np.triu_indices(3)))


@dataclass(frozen=True)
class ControlFeature:
    """One feature of a roof plane, line or control point layer, as plain values.

    Attributes
    ----------
    id : str
        The target id observations name it by (the layer's ``id`` field as text).
    vertices : ndarray, shape (M, 3)
        Its vertices in the mapping CRS (a polygon's exterior ring, a line's vertices, the
        point); z is NaN when the layer has no heights.
    attributes : mapping of str to object
        Field values by lower-case name (None for NULL); the columns of the plane, line and
        LCP tables (:mod:`core.io.planes`, :mod:`core.io.control`) are used when present.
    same_crs : bool
        The layer is in the mapping CRS. When it was reprojected, its plane parameters,
        centroids and covariance elements no longer apply and are ignored (standard
        deviations are kept).
    """

    id: str
    vertices: Array
    attributes: Mapping[str, object] = field(default_factory=dict)
    same_crs: bool = True

    def number(self, name: str) -> float | None:
        """The attribute as a finite float, None when absent, NULL or not a number."""
        value = self.attributes.get(name)
        try:
            out = float(value)  # type: ignore[arg-type]
        except (TypeError, ValueError):
            return None
        return out if math.isfinite(out) else None

    def numbers(self, names: Sequence[str], geometric: bool = True) -> list[float] | None:
        """Several attributes, None unless all are numbers (and, for ``geometric`` ones,
        the layer is in the mapping CRS)."""
        if geometric and not self.same_crs:
            return None
        values = [self.number(n) for n in names]
        return None if any(v is None for v in values) else values  # type: ignore[return-value]

    @property
    def int_id(self) -> int:
        """The id as an integer (-1 when it is not one)."""
        try:
            value = float(self.id)
        except ValueError:
            return -1
        return int(value) if value.is_integer() else -1


def _symmetric(upper: Sequence[float], n: int) -> Array:
    cov = np.zeros((n, n))
    cov[np.triu_indices(n)] = upper
    return cov + np.triu(cov, 1).T


def _ids(feature: ControlFeature, names: Sequence[str]) -> tuple[int, ...]:
    return tuple(int(v) if (v := feature.number(n)) is not None else -1 for n in names)


def plane_from_feature(feature: ControlFeature) -> Plane | None:
    """The roof plane of an outline polygon, None when it has none.

    With the plane parameters ``a, b, c, d`` among the attributes (and the layer in the mapping
    CRS) the plane is theirs: missing heights of the outline are put on it, the centroid is
    ``centroid_x..z`` or the outline's mean moved onto the plane, and the covariance is
    ``cov_aa..cov_dd`` (zero when absent). Otherwise the plane is fitted to the outline's
    vertices (:func:`core.geometry.planes.fit_plane`, with its covariance), which needs three
    of them with heights. The outline is kept (not closed).

    >>> square = np.array([[0, 0, 5.0], [4, 0, 5.0], [4, 4, 7.0], [0, 4, 7.0], [0, 0, 5.0]])
    >>> p = plane_from_feature(ControlFeature("3", square))
    >>> p.id, p.outline.shape, round(p.slope_deg, 3)
    (3, (4, 3), 26.565)
    >>> flat = ControlFeature("4", square * [1, 1, np.nan], {"a": 0, "b": 0, "c": 1, "d": -2})
    >>> plane_from_feature(flat).outline[:, 2].tolist()
    [2.0, 2.0, 2.0, 2.0]
    """
    ring = np.asarray(feature.vertices, dtype=np.float64).reshape(-1, 3).copy()
    if len(ring) > 1 and np.allclose(ring[0], ring[-1], equal_nan=True):
        ring = ring[:-1]
    params = feature.numbers(("a", "b", "c", "d"))
    size = math.hypot(*params[:3]) if params else 0.0
    if params and size > 0:
        normal = np.array(params[:3]) / size
        d = params[3] / size
        if (orient_up(normal) != normal).any():
            normal, d = -normal, -d
        if np.isnan(ring[:, 2]).any() and abs(normal[2]) > 1e-9:
            ring[:, 2] = -(ring[:, :2] @ normal[:2] + d) / normal[2]
        centroid = feature.numbers(("centroid_x", "centroid_y", "centroid_z"))
        if centroid is not None:
            point = np.array(centroid)
        else:
            point = ring.mean(axis=0) if len(ring) else np.full(3, np.nan)
            point = point - (point @ normal + d) * normal
        if not np.isfinite(point).all():
            return None
        upper = feature.numbers(_PLANE_COV)
        cov = _symmetric(upper, 4) if upper is not None else np.zeros((4, 4))
        n_points, rms, sigma_d = (feature.number(n) for n in ("n_points", "rms", "sigma_d"))
        slope, aspect = slope_aspect_deg(normal)
        return Plane(
            id=feature.int_id,
            normal=normal,
            d=float(d),
            centroid=point,
            n_points=int(n_points) if n_points is not None else len(ring),
            rms=rms if rms is not None else 0.0,
            sigma_d=sigma_d if sigma_d is not None else math.sqrt(max(cov[3, 3], 0.0)),
            covariance=cov,
            slope_deg=slope,
            aspect_deg=aspect,
            outline=ring,
        )
    if len(ring) < 3 or not np.isfinite(ring).all():
        return None
    try:
        return fit_plane(ring, plane_id=feature.int_id).with_outline(ring)
    except InputError:
        return None


def line_from_feature(feature: ControlFeature) -> ControlLine | None:
    """The LiDAR line of a line feature (its first and last vertex), None without two distinct
    vertices with heights.

    ``x0..z0``, ``ux..uz`` and ``cov_00..cov_55`` (the line table's) give the line point, the
    direction and their covariance when all present (layer in the mapping CRS); otherwise the
    point is the middle of the segment and the covariance that of a point known to
    ``sigma_perpendicular`` (or :data:`DEFAULT_LIDAR_SIGMA_M`) across the line in every
    direction. ``plane_1``, ``plane_2``, ``kind`` and ``dihedral_deg`` are read when present
    (else -1, ``"other"`` and 0: unknown).

    >>> ln = line_from_feature(ControlFeature("7", np.array([[0, 0, 10.0], [8, 0, 10.0]])))
    >>> ln.id, ln.point.tolist(), ln.direction.tolist(), ln.kind, round(ln.sigma_perpendicular, 3)
    (7, [4.0, 0.0, 10.0], [1.0, 0.0, 0.0], 'other', 0.05)
    """
    v = np.asarray(feature.vertices, dtype=np.float64).reshape(-1, 3)
    if len(v) < 2 or not np.isfinite(v).all():
        return None
    start, end = v[0].copy(), v[-1].copy()
    length = float(np.linalg.norm(end - start))
    if length == 0.0:
        return None
    point, direction = 0.5 * (start + end), (end - start) / length
    line_point = feature.numbers(LINE_PARAMETERS)
    upper = feature.numbers(_LINE_COV)
    if line_point is not None and upper is not None:
        point, direction = np.array(line_point[:3]), np.array(line_point[3:])
        direction = direction / np.linalg.norm(direction)
        cov = _symmetric(upper, 6)
    else:
        sigma = feature.number("sigma_perpendicular") or DEFAULT_LIDAR_SIGMA_M
        cov = np.zeros((6, 6))
        cov[:3, :3] = sigma**2 * np.eye(3)
    kind = str(feature.attributes.get("kind") or "other")
    dihedral = feature.number("dihedral_deg")
    return ControlLine(
        id=feature.int_id,
        plane_ids=_ids(feature, ("plane_1", "plane_2")),  # type: ignore[arg-type]
        kind=kind if kind in LINE_KINDS else "other",
        start=start,
        end=end,
        point=point,
        direction=direction,
        covariance=cov,
        dihedral_deg=dihedral if dihedral is not None else 0.0,
    )


def lcp_from_feature(feature: ControlFeature) -> ControlPoint | None:
    """The LiDAR control point of a point feature, None without a height.

    The covariance is ``cov_xx..cov_zz`` (the LCP table's; layer in the mapping CRS), else
    ``sigma_x, sigma_y, sigma_z`` on the diagonal, else :data:`DEFAULT_LIDAR_SIGMA_M` on
    each axis. ``plane_1..3``, ``min_angle_deg`` and ``condition`` are read when present (else
    -1, 0 and 0: unknown).

    >>> c = lcp_from_feature(ControlFeature("2", np.array([[1.0, 2.0, 3.0]]), {"sigma_x": 0.1,
    ...     "sigma_y": 0.1, "sigma_z": 0.2}))
    >>> c.id, c.xyz.tolist(), c.sigma.round(3).tolist(), c.plane_ids
    (2, [1.0, 2.0, 3.0], [0.1, 0.1, 0.2], (-1, -1, -1))
    """
    v = np.asarray(feature.vertices, dtype=np.float64).reshape(-1, 3)
    if len(v) == 0 or not np.isfinite(v[0]).all():
        return None
    upper = feature.numbers(_LCP_COV)
    sigmas = feature.numbers(("sigma_x", "sigma_y", "sigma_z"), geometric=False)
    if upper is not None:
        cov = _symmetric(upper, 3)
    elif sigmas is not None:
        cov = np.diag(np.square(sigmas))
    else:
        cov = DEFAULT_LIDAR_SIGMA_M**2 * np.eye(3)
    angle, condition = feature.number("min_angle_deg"), feature.number("condition")
    return ControlPoint(
        id=feature.int_id,
        xyz=v[0].copy(),
        covariance=cov,
        plane_ids=_ids(feature, ("plane_1", "plane_2", "plane_3")),  # type: ignore[arg-type]
        min_angle_deg=angle if angle is not None else 0.0,
        condition=condition if condition is not None else 0.0,
        support_distance=np.full(3, np.nan),
    )


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
        out: dict[str, tuple[tuple[Any, ...], tuple[str, ...]]] = {}  # kind: (objects, ids)
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
                if kind == "planes":
                    assert isinstance(t, Plane)  # the plane table's rows
                    t = t.with_outline(objs[k].outline)
                new_objs.append(t)
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


def lines_with_end_sigmas(lines: Iterable[ControlLine]) -> list[ControlLine]:
    """The lines as the resection takes them: a line whose direction has no covariance (a
    layer feature without the line table's: its position known to ``sigma_perpendicular``,
    its direction exact) gets the covariance of its two end points each known to that sigma
    in every direction, independently; the other lines are returned as they are.

    The resection needs the end points' covariance regular across the line (or none); the
    point-and-exact-direction one makes the two ends move together. Independent ends: the
    point (their middle) has sigma**2 / 2 and the direction 2 sigma**2 / L**2 per axis, so
    :meth:`ControlLine.sigma_ends` is sigma again.

    >>> ln = line_from_feature(ControlFeature("7", np.array([[0, 0, 10.0], [8, 0, 10.0]])))
    >>> [round(s, 3) for s in lines_with_end_sigmas([ln])[0].sigma_ends]
    [0.05, 0.05]
    """
    out = []
    for ln in lines:
        cov = np.asarray(ln.covariance, dtype=np.float64)
        if np.any(cov[3:, 3:] != 0) or not np.any(cov[:3, :3] != 0):
            out.append(ln)
            continue
        s2 = ln.sigma_perpendicular**2
        new = np.zeros((6, 6))
        new[:3, :3] = 0.5 * s2 * np.eye(3)
        new[3:, 3:] = 2.0 * s2 / ln.length**2 * np.eye(3)
        mid = 0.5 * (ln.start + ln.end)
        out.append(replace(ln, point=mid, covariance=new))
    return out
