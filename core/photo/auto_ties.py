"""Tie tracks associated with LiDAR roof planes (issue 32, step 2).

Each tie track (rows of type ``tie`` sharing a ``point_id``, measured in >= 2 images, e.g. the
output of :func:`core.photo.tie_points.tie_points`) is intersected with the current exterior
orientation (least-squares meeting point of its rays, :func:`.intersection.meet_rays`, in the
local ENU frame of :class:`.picking.PickingScene`) and kept as a point-to-plane tie of the plane
it lies on. A track is refused, with one reason each (:data:`REASONS`), when:

* ``one image``: fewer than two rays, or rays too parallel to fix a point;
* ``rays apart``: its rays miss the meeting point by more than the gate (a wrong match);
* ``no roof plane``: the point's (x, y) is inside no plane outline (ground, trees);
* ``wall``: the plane is steeper than ``max_roof_slope_deg`` (facades, walls);
* ``plane border``: nearer than ``border_m`` to the outline (eaves, ridges: two planes or
  a wall could hold it);
* ``off the plane``: more than the gate from the plane (a tree crown or a chimney over the
  roof, a point of the neighbouring roof seen through a wrong orientation);
* ``ambiguous``: two planes within the gate;
* ``not on the DSM``: a DSM is given and its height at (x, y) is more than the gate from the
  point (the LiDAR saw something else there).

The gate (metres) comes from the pose uncertainty (the caller derives it: angle sigma times
range, times a number of sigmas). The planes' outlines (mapping CRS, :attr:`Plane.outline`)
are needed; a plane without one holds no tie. Kept rows get ``target_id`` = the plane id, so
:func:`core.photo.boresight.calibrate` treats them with the plane's covariance as its
point-to-plane model does.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..geometry.camera import Camera
from ..geometry.planes import Plane
from ..geometry.surface import Dsm
from .intersection import meet_rays
from .observations import ImageObservations
from .orientation import ExteriorOrientationTable
from .picking import PickingScene, points_in_polygons

__all__ = ["REASONS", "TieAssociation", "associate_ties", "find_ties", "outlines_from_points"]

Array = NDArray[np.float64]

#: Reasons for refusing a track, in the order they are checked.
REASONS = (
    "one image",
    "rays apart",
    "no roof plane",
    "wall",
    "plane border",
    "off the plane",
    "ambiguous",
    "not on the DSM",
)


@dataclass(frozen=True)
class TieAssociation:
    """Result of :func:`associate_ties`.

    observations: the kept tie rows, ``target_id`` = plane id.
    reasons: refused tracks per reason of :data:`REASONS` (all keys present).
    tracks: number of tracks looked at.
    plane_of: point_id -> plane id of every kept track.
    xyz: point_id -> its intersection (mapping CRS, metres) for every track with >= 2 rays.
    """

    observations: ImageObservations
    reasons: dict[str, int]
    tracks: int
    plane_of: dict[str, int]
    xyz: dict[str, Array]

    @property
    def associated(self) -> int:
        return len(self.plane_of)


def outlines_from_points(
    planes: Sequence[Plane], xyz: ArrayLike, plane_ids: ArrayLike
) -> list[Plane]:
    """The planes with an outline: the convex hull (x, y) of their LiDAR points (mapping CRS),
    its heights on the plane; planes with fewer than 3 points (or an outline already) are
    returned unchanged."""
    from scipy.spatial import ConvexHull, QhullError

    pts = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
    ids = np.asarray(plane_ids).reshape(-1)
    if ids.shape[0] != pts.shape[0]:
        raise InputError(f"{pts.shape[0]} points but {ids.shape[0]} plane ids")
    out = []
    for p in planes:
        own = pts[ids == p.id]
        if len(p.outline) >= 3 or len(own) < 3 or abs(p.normal[2]) < 1e-6:
            out.append(p)
            continue
        try:
            ring = own[ConvexHull(own[:, :2]).vertices, :2]
        except QhullError:  # collinear points: no area
            out.append(p)
            continue
        z = p.centroid[2] - ((ring - p.centroid[:2]) @ p.normal[:2]) / p.normal[2]
        out.append(p.with_outline(np.column_stack([ring, z])))
    return out


def find_ties(
    images: Sequence[tuple[str, ArrayLike]],
    camera: Camera,
    eo: ExteriorOrientationTable,
    height_m: float,
    options=None,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
):
    """Tie tracks between the images already in memory (issue 32, step 1): the chain of
    :func:`.tie_points.tie_points` (features, pairs from the ground footprints of the
    approximate orientation ``eo`` at ``height_m`` (mapping CRS, metres), matching, tracks,
    least-squares refinement), each image converted to 8-bit grey once.

    Returns the :class:`.tie_points.TiePointResult`; its ``observations()`` are rows of type
    ``tie`` (pixels, per docs/conventions.md), ready for :func:`associate_ties`.
    ``options`` is a :class:`.tie_options.TiePointOptions` (default: its defaults, refinement
    on, pairs from the footprints). Images without a row in ``eo`` are refused by name.
    """
    from .tie_options import TiePointOptions
    from .tie_pairs import footprints
    from .tie_points import detect_features, tie_points

    opt = options or TiePointOptions()
    row = {iid: k for k, iid in enumerate(eo.image_id)}
    missing = [iid for iid, _ in images if iid not in row]
    if missing:
        raise InputError(f"image(s) without an exterior orientation: {', '.join(missing[:5])}")
    ids = [iid for iid, _ in images]
    fps = footprints(camera, eo.xyz, eo.opk, float(height_m))
    footprint = [fps[row[iid]] for iid in ids]
    greys = [_grey8(img) for _, img in images]
    for iid, g in zip(ids, greys):
        if g.shape != (camera.height_px, camera.width_px):
            raise InputError(
                f"image {iid} is {g.shape[1]} x {g.shape[0]} px, the camera "
                f"{camera.width_px} x {camera.height_px} px"
            )

    def load(k: int):
        return detect_features(greys[k], ids[k], opt)

    return tie_points(
        ids,
        load,
        opt,
        footprint,
        progress=progress,
        should_stop=should_stop,
        load_image=lambda k: greys[k],
    )


def _grey8(image: ArrayLike) -> NDArray[np.uint8]:
    """8-bit grey of a grey or RGB(A) image (luminance of the first three bands); other than
    8-bit images are stretched from their minimum to their maximum (features need contrast
    only)."""
    a = np.asarray(image)
    eight = a.dtype == np.uint8
    if a.ndim == 3:
        a = a[..., :3].astype(np.float32) @ np.array([0.299, 0.587, 0.114], np.float32)
    if a.ndim != 2:
        raise InputError(f"image must be (H, W) or (H, W, 3), got shape {a.shape}")
    if a.dtype == np.uint8:
        return a
    if not eight:
        lo, hi = float(np.min(a)), float(np.max(a))
        a = (a - lo) * (255.0 / (hi - lo if hi > lo else 1.0))
    return np.clip(np.rint(a), 0, 255).astype(np.uint8)


def _segment_distance(xy: Array, ring: Array) -> float:
    """Smallest distance (CRS unit) from the point ``xy`` (2,) to the closed ring (M, 2)."""
    a, b = ring, np.roll(ring, -1, axis=0)
    d = b - a
    t = np.clip(
        np.einsum("ij,ij->i", xy - a, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-12), 0.0, 1.0
    )
    return float(np.min(np.linalg.norm(a + t[:, None] * d - xy, axis=1)))


def _meet(
    scene: PickingScene, ties: ImageObservations, names: list[str], sigmas: float
) -> tuple[Array, NDArray[np.intp], Array, Array]:
    """Meeting points (T, 3, local frame), ray counts (T,), the largest ray miss beyond
    ``sigmas`` times its own precision (T,) m, and each point's covariance (T, 3, 3) m^2
    from the pixels' sigmas (the rays' perpendicular precision at their range)."""
    index = {n: k for k, n in enumerate(names)}
    point_of = np.array([index[p] for p in ties.point_id], dtype=np.intp)
    origins = np.empty((len(ties), 3))
    dirs = np.empty((len(ties), 3))
    image = np.array(ties.image_id)
    for iid in dict.fromkeys(ties.image_id):
        rows = np.flatnonzero(image == iid)
        origins[rows], dirs[rows] = scene.rays(iid, ties.pixels[rows])
    xyz, counts = meet_rays(origins, dirs, point_of, len(names))
    rel = xyz[point_of] - origins
    miss = np.linalg.norm(rel - np.einsum("ij,ij->i", rel, dirs)[:, None] * dirs, axis=1)
    rng = np.linalg.norm(np.nan_to_num(rel), axis=1)
    perp = np.maximum(
        ties.sigma_px * scene.camera.pixel_size_mm / scene.camera.focal_mm * rng, 1e-6
    )
    worst = np.zeros(len(names))
    np.maximum.at(worst, point_of, np.maximum(np.nan_to_num(miss, nan=np.inf) - sigmas * perp, 0))
    proj = np.eye(3) - dirs[:, :, None] * dirs[:, None, :]
    normal = np.zeros((len(names), 3, 3))
    np.add.at(normal, point_of, proj / perp[:, None, None] ** 2)
    ok = np.isfinite(xyz).all(axis=1) & (counts >= 2)
    cov = np.full((len(names), 3, 3), np.nan)
    cov[ok] = np.linalg.inv(normal[ok])
    return xyz, counts, worst, cov


def associate_ties(
    ties: ImageObservations,
    eo: ExteriorOrientationTable,
    camera: Camera,
    planes: Sequence[Plane],
    gate_m: float,
    *,
    border_m: float = 0.3,
    max_roof_slope_deg: float = 65.0,
    dsm: Dsm | None = None,
    sigmas: float = 3.0,
) -> TieAssociation:
    """Associate tie tracks with roof planes (module docstring).

    Parameters
    ----------
    ties : ImageObservations
        Tie measurements (rows of other types are ignored), pixels.
    eo : ExteriorOrientationTable
        Current orientation of the images (mapping CRS).
    camera : Camera
    planes : sequence of Plane
        LiDAR roof planes with outlines, mapping CRS.
    gate_m : float
        Largest distance of a track's point from its plane and of its rays from the point, m.
    border_m : float
        Smallest distance of an accepted point from its plane's outline, m.
    max_roof_slope_deg : float
        Planes steeper than this are walls: no tie, degrees.
    dsm : Dsm, optional
        LiDAR DSM (mapping CRS): a point more than the gate from it is refused.
    sigmas : float
        The gate of each track grows by this many of its own standard deviations: of each ray
        (its pixel sigma at its range) for the ray misses, of the intersected point along the
        plane normal (a short base fixes heights poorly) for the distance to the plane.

    Returns
    -------
    TieAssociation
    """
    if not gate_m > 0 or not border_m >= 0:
        raise InputError(f"gate_m must be > 0 and border_m >= 0, got {gate_m!r}, {border_m!r}")
    ties = ties.subset(ties.mask("tie"))
    reasons = dict.fromkeys(REASONS, 0)
    names = list(dict.fromkeys(ties.point_id))
    empty = ties.subset(np.zeros(len(ties), bool))
    if not names:
        return TieAssociation(empty, reasons, 0, {}, {})
    scene = PickingScene(eo, camera)
    local, counts, miss, cov = _meet(scene, ties, names, sigmas)
    ok = np.isfinite(local).all(axis=1) & (counts >= 2)
    xyz = np.full_like(local, np.nan)
    xyz[ok] = scene.local.enu_to_map(local[ok])
    rings = [p.outline[:, :2] if len(p.outline) >= 3 else np.empty((0, 2)) for p in planes]
    plane_of: dict[str, int] = {}
    points: dict[str, Array] = {}
    for k, name in enumerate(names):
        if not ok[k]:
            reasons["one image"] += 1
            continue
        points[name] = xyz[k]
        # the point's own precision (local ENU ~ map axes within the convergence, enough here)
        reason, pid = _judge(
            xyz[k],
            miss[k],
            cov[k],
            planes,
            rings,
            gate_m,
            border_m,
            max_roof_slope_deg,
            dsm,
            sigmas,
        )
        if reason:
            reasons[reason] += 1
        else:
            plane_of[name] = pid
    keep = np.array([p in plane_of for p in ties.point_id], bool)
    kept = ties.subset(keep)
    kept = ImageObservations(
        kept.image_id,
        kept.point_id,
        kept.pixels,
        kept.sigma_px,
        kept.type,
        tuple(str(plane_of[p]) for p in kept.point_id),
        kept.rows,
        kept.source,
        kept.camera,
    )
    return TieAssociation(kept, reasons, len(names), plane_of, points)


def _judge(
    xyz: Array,
    miss: float,
    cov: Array,
    planes: Sequence[Plane],
    rings: list[Array],
    gate_m: float,
    border_m: float,
    max_slope: float,
    dsm: Dsm | None,
    sigmas: float,
) -> tuple[str, int]:
    """(reason of refusal or "", plane id) of one intersected track (``miss``: its worst ray
    miss beyond the ray's own precision, ``cov`` the point's covariance)."""
    if not miss <= gate_m:
        return "rays apart", -1
    inside = points_in_polygons(xyz[:2], rings)
    if inside.size == 0:
        return "no roof plane", -1

    def gate(n: Array) -> float:
        return float(np.hypot(gate_m, sigmas * np.sqrt(max(float(n @ cov @ n), 0.0))))

    near = [
        int(k) for k in inside if abs(float(planes[k].distance(xyz)[0])) <= gate(planes[k].normal)
    ]
    if len(near) > 1:
        return "ambiguous", -1
    pick = near[0] if near else int(inside[0])
    plane = planes[pick]
    if plane.slope_deg > max_slope:
        return "wall", -1
    if _segment_distance(xyz[:2], rings[pick]) < border_m:
        return "plane border", -1
    if not near:
        return "off the plane", -1
    if dsm is not None:
        h = float(dsm.height_at(np.array([xyz[0]]), np.array([xyz[1]]))[0])
        if not abs(h - xyz[2]) <= gate(np.array([0.0, 0.0, 1.0])):
            return "not on the DSM", -1
    return "", int(plane.id)
