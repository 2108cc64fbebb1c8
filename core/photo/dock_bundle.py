"""The picking dock's measurements as a bundle adjustment block (Qt-free).

The dock records one observation table (:mod:`core.io.observations`) for every purpose: tie
points on roof planes, points on LiDAR lines, LiDAR control points (LCPs), points of the
single-image plane model and check points. The bundle adjustment
(:func:`core.photo.bundle.bundle_adjust`, the job ``bundleadjustment``) needs point
measurements named by point id and a ground point table. :func:`dock_bundle_inputs` makes
them:

- ``tie`` rows are tie points (their ``point_id``; the roof plane is not used);
- ``control`` rows (surveyed points, as ``locatecontrolpoints`` writes them) are tie points
  named by their ``point_id`` too: the dock holds no ground point table, so the surveyed
  coordinates are not used here (``bundleadjustment`` with ``GROUND_POINTS`` uses them); a
  row measured in one image only is left out like a tie point. The rows themselves are
  kept and saved unchanged;
- ``lcp`` rows measure the control point ``C<target_id>``: its coordinates and the square
  roots of the diagonal of the LCP's covariance (the ground point table has no
  correlations) become a control point;
- ``check`` rows measure the check point ``K<target_id>`` at the LCP's coordinates;
- ``line`` and ``paper`` rows are left out (a point anywhere on a line, a point of one image:
  no object point of a block), as are rows of images not open, rows naming an LCP the dock
  does not have, and tie points measured in one image only (a tie point still being
  measured); :attr:`DockBundleInputs.left_out` counts them by reason.

:func:`residuals_by_row` gives the bundle's residuals back to the dock's rows.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..lidar.control import ControlPoint
from .bundle_setup import DEFAULT_CONTROL_SIGMA_M, GroundPoints
from .observations import ImageObservations
from .orientation import ExteriorOrientationTable

if TYPE_CHECKING:
    from .bundle_result import BundleResult

__all__ = [
    "DEFAULT_EO_SIGMAS",
    "MIN_CONTROL_SIGMA_M",
    "DockBundleInputs",
    "dock_bundle_inputs",
    "orientations_of",
    "residuals_by_row",
]

Array = NDArray[np.float64]

#: Standard deviations given to the dock's orientations when the Bundle tab takes them as
#: observations: X, Y, Z (m), omega, phi, kappa (degrees); a GNSS/INS of survey grade.
DEFAULT_EO_SIGMAS = (0.1, 0.1, 0.1, 0.01, 0.01, 0.01)
#: Smallest standard deviation of an LCP coordinate, metres: an LCP table may hold a zero
#: covariance (errorless), which the adjustment cannot weight.
MIN_CONTROL_SIGMA_M = 1e-4
#: Row types the dock's block adjusts as tie points named by their point_id.
_AS_TIE = ("tie", "control")


@dataclass(frozen=True)
class DockBundleInputs:
    """A bundle block made from the dock's rows.

    Attributes
    ----------
    observations : ImageObservations
        The tie, control and check measurements kept (type ``tie``, ``lcp``, ``check``).
    ground : GroundPoints
        Control (``C<id>``) and check (``K<id>``) points, mapping CRS, metres.
    images : tuple of str
        The images with kept measurements, in the order of their first row.
    left_out : dict of str to int
        Rows left out, by reason.
    """

    observations: ImageObservations
    ground: GroundPoints
    images: tuple[str, ...]
    left_out: dict[str, int] = field(default_factory=dict)

    def left_out_text(self) -> str:
        """``"12 line rows, 1 tie point in one image"`` or ``""``."""
        return ", ".join(f"{n} {why}" for why, n in self.left_out.items() if n)


def dock_bundle_inputs(
    observations: ImageObservations,
    lcps: Sequence[ControlPoint],
    lcp_ids: Sequence[str],
    images: Iterable[str] | None = None,
) -> DockBundleInputs:
    """The bundle block of the dock's rows (rules in the module docstring).

    Parameters
    ----------
    observations : ImageObservations
        The dock's rows (pixels; any types).
    lcps, lcp_ids : the dock's LiDAR control points and the target ids the rows name them by
        (mapping CRS, metres; covariance in m^2).
    images : iterable of str, optional
        The images open in the dock; None: every image of the rows.

    Examples
    --------
    >>> from lidarphoto.core.lidar.control import ControlPoint
    >>> lcp = ControlPoint(4, np.array([10.0, 20.0, 5.0]), np.diag([1e-4, 4e-4, 0.0]),
    ...                    (1, 2, 3), 30.0, 1.0, np.zeros(3))
    >>> obs = ImageObservations.from_arrays(
    ...     ["a", "b", "a", "b", "a", "a"], ["T1", "T1", "C4", "C4", "R2_1", "T2"],
    ...     np.full((6, 2), 100.0), 0.5, ["tie", "tie", "lcp", "lcp", "line", "tie"],
    ...     ["7", "7", "4", "4", "2", "8"])
    >>> b = dock_bundle_inputs(obs, [lcp], ["4"])
    >>> b.observations.point_id, b.images
    (('T1', 'T1', 'C4', 'C4'), ('a', 'b'))
    >>> gcp = ImageObservations.from_arrays(["a", "b", "a"], ["GCP1", "GCP1", "GCP2"],
    ...     np.full((3, 2), 50.0), 0.5, ["control"] * 3, [""] * 3)
    >>> g = dock_bundle_inputs(obs.concat(gcp), [lcp], ["4"])
    >>> g.observations.point_id[-2:], g.observations.type[-2:]
    (('GCP1', 'GCP1'), ('tie', 'tie'))
    >>> g.left_out["tie point(s) measured in one image only"]
    2
    >>> b.ground.point_id, b.ground.sigma.tolist(), b.ground.role
    (('C4',), [[0.01, 0.02, 0.0001]], ('control',))
    >>> b.left_out_text()
    '1 line row(s), 1 tie point(s) measured in one image only'
    """
    open_images = None if images is None else set(images)
    lcp_of = {str(i): c for i, c in zip(lcp_ids, lcps)}
    left: dict[str, int] = {}

    def leave(why: str) -> None:
        left[why] = left.get(why, 0) + 1

    keep: list[int] = []
    point_id: list[str] = []
    ground: dict[str, tuple[Array, Array, str]] = {}
    for i, (im, pid, kind, tid) in enumerate(
        zip(observations.image_id, observations.point_id, observations.type, observations.target_id)
    ):
        if open_images is not None and im not in open_images:
            leave("row(s) of images not open")
        elif kind in ("line", "paper"):
            leave(f"{kind} row(s)")
        elif kind in ("tie", "control"):
            keep.append(i)
            point_id.append(pid)
        else:  # lcp, check
            c = lcp_of.get(str(tid))
            if c is None:
                leave(f"{kind} row(s) naming no control point of the dock")
                continue
            name = ("C" if kind == "lcp" else "K") + str(tid)
            if name not in ground:
                sig = np.sqrt(np.clip(np.diag(np.asarray(c.covariance, dtype=np.float64)), 0, None))
                sig = np.where(np.isfinite(sig), sig, DEFAULT_CONTROL_SIGMA_M)
                role = "control" if kind == "lcp" else "check"
                ground[name] = (
                    np.asarray(c.xyz, dtype=np.float64),
                    np.maximum(sig, MIN_CONTROL_SIGMA_M),
                    role,
                )
            keep.append(i)
            point_id.append(name)
    # a tie point in one image only is one still being measured: no ray to intersect
    ties = [p for k, p in zip(keep, point_id) if observations.type[k] in _AS_TIE]
    images_of: dict[str, set[str]] = {}
    for k, p in zip(keep, point_id):
        if observations.type[k] in _AS_TIE:
            images_of.setdefault(p, set()).add(observations.image_id[k])
    single = {p for p in ties if len(images_of[p]) < 2}
    if single:
        left["tie point(s) measured in one image only"] = len(single)
    sel = [(k, p) for k, p in zip(keep, point_id) if p not in single]
    idx = np.array([k for k, _ in sel], dtype=np.intp)
    sub = observations.subset(idx)
    # the bundle refuses a control row naming no ground point: here they are tie points
    kinds = tuple("tie" if t == "control" else t for t in sub.type)
    kept = ImageObservations(
        sub.image_id,
        tuple(p for _, p in sel),
        sub.pixels,
        sub.sigma_px,
        kinds,
        sub.target_id,
        sub.rows,
        sub.source,
        sub.camera,
    )
    names = tuple(ground)
    gp = GroundPoints(
        names,
        np.array([ground[n][0] for n in names], dtype=np.float64).reshape(-1, 3),
        np.array([ground[n][1] for n in names], dtype=np.float64).reshape(-1, 3),
        tuple(ground[n][2] for n in names),
    )
    return DockBundleInputs(kept, gp, tuple(dict.fromkeys(kept.image_id)), left)


def residuals_by_row(result: BundleResult, observations: ImageObservations) -> dict[int, Array]:
    """The bundle's residual (v_col, v_row; adjusted minus measured, pixels) of each row of the
    dock's ``observations`` it adjusted, by row index. A residual belongs to the row of the
    same image, type and point (``C<target>``/``K<target>`` for lcp and check rows; a
    ``control`` row's point was adjusted as a tie point);
    rows left out, rejected or without a finite residual have none.
    """
    r = result.observations
    v = np.asarray(result.v_px, dtype=np.float64).reshape(-1, 2)
    by_key = {
        (im, kind, pid): v[k]
        for k, (im, kind, pid) in enumerate(zip(r.image_id, r.type, r.point_id))
        if np.isfinite(v[k]).all() and result.used[k]
    }
    out: dict[int, Array] = {}
    for i, (im, pid, kind, tid) in enumerate(
        zip(observations.image_id, observations.point_id, observations.type, observations.target_id)
    ):
        name = pid if kind in _AS_TIE else ("C" if kind == "lcp" else "K") + str(tid)
        vk = by_key.get((im, "tie" if kind == "control" else kind, name))
        if vk is not None:
            out[i] = vk.copy()
    return out


def orientations_of(
    eo: ExteriorOrientationTable, images: Sequence[str]
) -> ExteriorOrientationTable:
    """The rows of ``images`` (in that order) of an orientation table (the bundle refuses an
    image without measurements).

    >>> t = ExteriorOrientationTable(("a", "b", "c"), np.arange(3.0), ("g",) * 3,
    ...                              np.arange(9.0).reshape(3, 3), np.zeros((3, 3)), "")
    >>> s = orientations_of(t, ["c", "a"])
    >>> s.image_id, s.xyz[:, 0].tolist(), s.time.tolist()
    (('c', 'a'), [6.0, 0.0], [2.0, 0.0])
    """
    where = {im: k for k, im in enumerate(eo.image_id)}
    keep = np.array([where[i] for i in images], dtype=np.intp)
    return replace(
        eo,
        image_id=tuple(eo.image_id[k] for k in keep),
        time=np.asarray(eo.time)[keep],
        group=tuple(eo.group[k] for k in keep),
        xyz=eo.xyz[keep],
        opk=eo.opk[keep],
    )
