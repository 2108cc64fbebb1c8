"""Bundle adjustment with self-calibration: exterior orientation of every image, object
points, interior orientation and additional parameters (APs) per camera, in one adjustment.

Model
-----
Every image measurement (col, row) of a point is a Gauss-Markov observation of the
collinearity equations (:mod:`core.geometry.collinearity`) with the camera's lens model: the
families of additional parameters of :mod:`core.geometry.ap_models` (Bauer, Jacobsen, Ebner,
Brown, the radial k1 k2 model) or the physical Brown-Conrady model, as corrections added to the
measured coordinates. Unknowns, in the local east-north-up adjustment frame of
docs/conventions.md:

- per image: ``X0, Y0, Z0, omega, phi, kappa``;
- per camera: ``f, x0, y0`` (when the interior orientation is estimated) and the free APs of
  the chosen family;
- per object point: ``X, Y, Z`` (eliminated from the normal equations by the Schur complement:
  the reduced camera system, :mod:`core.lsq.schur`);
- optionally a common lever-arm and boresight correction between the observed (GNSS/INS) and
  the photogrammetric orientation.

Observations besides the image points: control points (their coordinates with sigmas, carried
into the adjustment frame with their full covariance), observed exterior orientations
(GNSS/INS positions and attitudes with sigmas). Check points never enter the adjustment: their
rays are intersected afterwards with the adjusted orientations and compared with their
surveyed coordinates.

Datum: from the control points and/or the observed orientations (``datum="control"``), or a
free network: inner constraints on the tie points (``"inner"``, the minimum-trace datum of
the approximate coordinates) or the minimal constraints that hold the first image's
orientation and one coordinate of a second centre (``"minimal"``).

Approximate values: the exterior orientations given (e.g. direct georeferencing, a few degrees
and metres off), or, with none, a space resection of the images that see four or more control
points followed by alternating forward intersection of the tie points and resection of the
images that see them (growth), until every image is oriented.

Statistics and selection: sigma0, the global chi-square test, standard deviations and
correlations; for every AP its t-test (value over its a-posteriori standard deviation against
Student's t with the redundancy as degrees of freedom) and correlations above a limit with the
other interior parameters. Automatic selection drops, one at a time, the least significant
insignificant AP, or the less significant AP of a too-correlated pair, re-adjusts, and reports
what it dropped and why. Outliers: robust reweighting (Huber or Cauchy) before Baarda's data
snooping, both on the image measurements only (control points and observed orientations are
tested, their w reported, but never removed: their misfits mostly reflect an imperfect
model); a tie point left with one ray by a rejection is set aside with it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Callable

import numpy as np
from numpy.typing import NDArray
from scipy import stats

from ..errors import AdjustmentError, InputError, NotObservableError, stop_if_asked
from ..geometry.ap_models import AP_FAMILIES, make_ap_model
from ..geometry.camera import Camera
from ..geometry.collinearity import collinearity_jacobians, image_rays
from ..geometry.frames import LocalFrame, MappingFrame
from ..geometry.rotations import matrix_to_opk, opk_derivatives, opk_to_matrix
from ..i18n import mark as _t
from ..lsq.adjustment import adjust
from ..lsq.model import AdjustmentOptions, Constraint, GaussMarkovBlock
from ..lsq.results import AdjustmentResult
from .intersection import meet_rays
from .observations import ImageObservations
from .orientation import ExteriorOrientationTable, eo_local_to_map, eo_map_to_local

#: catalogue context of this module's ``_t("...")`` sentences (``make i18n``): the reports'
TR_CONTEXT = "Report"

Array = NDArray[np.float64]

ROLES = ("control", "check")
DATUMS = ("control", "inner", "minimal")
EO_PARAM_NAMES = ("X0", "Y0", "Z0", "omega", "phi", "kappa")
#: Default standard deviation of a control point coordinate without one in its file, metres.
DEFAULT_CONTROL_SIGMA_M = 0.02
# Fewest control/intersected points for a space resection of an image during the growth.
_MIN_RESECTION_POINTS = 6
# Control points this far (in flying heights, at least 5 km) from every image centre mean a
# wrong CRS.
_FAR_FACTOR = 50.0


# ----------------------------------------------------------------------------- inputs


@dataclass(frozen=True)
class GroundPoints:
    """Surveyed object points: control points (in the adjustment) and check points (kept out).

    Attributes
    ----------
    point_id : tuple of str, shape (N,)
    xyz : ndarray, shape (N, 3)
        Easting, northing, height in the mapping CRS, metres.
    sigma : ndarray, shape (N, 3)
        Standard deviations of the three coordinates, metres (> 0; used for control points).
    role : tuple of str, shape (N,)
        ``control`` or ``check``.
    rows : tuple of int
        Row of each point in its file (for error messages), or ().
    source : str
        The file.
    """

    point_id: tuple[str, ...]
    xyz: Array
    sigma: Array
    role: tuple[str, ...]
    rows: tuple[int, ...] = ()
    source: str = ""

    def __post_init__(self) -> None:
        n = len(self.point_id)
        xyz = np.asarray(self.xyz, dtype=np.float64).reshape(-1, 3)
        sig = np.broadcast_to(np.asarray(self.sigma, dtype=np.float64), (n, 3)).copy()
        object.__setattr__(self, "xyz", xyz)
        object.__setattr__(self, "sigma", sig)
        object.__setattr__(self, "point_id", tuple(str(p) for p in self.point_id))
        object.__setattr__(self, "role", tuple(str(r).strip().lower() for r in self.role))
        object.__setattr__(self, "rows", tuple(self.rows))
        if xyz.shape[0] != n or len(self.role) != n or (self.rows and len(self.rows) != n):
            raise InputError("ground points: all fields must have the same length")
        for i, r in enumerate(self.role):
            if r not in ROLES:
                raise InputError(f"role '{r}' is not one of {', '.join(ROLES)}", **self.where(i))
        if not np.isfinite(xyz).all():
            i = int(np.flatnonzero(~np.isfinite(xyz).all(axis=1))[0])
            raise InputError("coordinates must be finite", **self.where(i))
        if not (np.isfinite(sig).all() and (sig > 0).all()):
            i = int(np.flatnonzero(~(np.isfinite(sig) & (sig > 0)).all(axis=1))[0])
            raise InputError("sigmas must be finite and > 0", **self.where(i))
        seen: dict[str, int] = {}
        for i, p in enumerate(self.point_id):
            if p in seen:
                raise InputError(f"point '{p}' appears twice", **self.where(i))
            seen[p] = i

    def __len__(self) -> int:
        return len(self.point_id)

    def where(self, i: int) -> dict:
        """``path``/``row`` keywords of :class:`InputError` for point ``i``."""
        return {"path": self.source or None, "row": self.rows[i] if self.rows else None}

    @classmethod
    def empty(cls) -> GroundPoints:
        return cls((), np.zeros((0, 3)), np.zeros((0, 3)), ())


@dataclass(frozen=True)
class BundleOptions:
    """Options of :func:`bundle_adjust`.

    Attributes
    ----------
    ap_model : str
        AP family for every camera: a key of
        :data:`~lidarphoto.core.geometry.ap_models.AP_FAMILIES` (``none`` holds the camera's
        lens model fixed).
    estimate_interior : bool
        Estimate the principal distance and the principal point of every camera.
    ap_selection : bool
        Drop insignificant or too-correlated APs one at a time and re-adjust.
    ap_alpha : float
        Two-sided significance level of the AP t-test.
    max_correlation : float
        |correlation| above which a pair of interior parameters is flagged (and, with
        selection, the less significant AP of the pair dropped).
    robust : str
        ``none``, ``huber`` or ``cauchy``: reweighting before data snooping.
    snooping : bool
        Baarda data snooping.
    snooping_alpha : float
        Significance level per observation of data snooping.
    datum : str
        ``control`` (control points and/or observed orientations), ``inner`` (free network,
        inner constraints on the tie points) or ``minimal`` (free network, seven parameters
        held).
    estimate_mount : bool
        With observed orientations: estimate a common lever-arm correction (camera axes,
        metres) and boresight correction (about the camera axes) between the observed and
        the adjusted orientations, signed as in DESIGN.md: ``X_pc = X_obs + R_c^m da``,
        ``R_c^m = R_obs dR`` (a boresight calibration's dR).
    max_iterations : int
        Iterations of each adjustment.
    covariance : bool
        Compute the covariance (sigmas, t-tests, w-tests); needed by the AP selection and
        data snooping (off only for speed measurements).
    """

    ap_model: str = "none"
    estimate_interior: bool = True
    ap_selection: bool = True
    ap_alpha: float = 0.05
    max_correlation: float = 0.9
    robust: str = "huber"
    snooping: bool = True
    snooping_alpha: float = 0.001
    datum: str = "control"
    estimate_mount: bool = False
    max_iterations: int = 60
    covariance: bool = True

    def __post_init__(self) -> None:
        if self.ap_model not in AP_FAMILIES:
            raise InputError(
                f"AP model '{self.ap_model}' is not one of {', '.join(AP_FAMILIES)}"
            )
        if self.datum not in DATUMS:
            raise InputError(f"datum '{self.datum}' is not one of {', '.join(DATUMS)}")
        if not 0 < self.ap_alpha < 1 or not 0 < self.max_correlation <= 1:
            raise InputError("ap_alpha must be in (0, 1) and max_correlation in (0, 1]")


# ----------------------------------------------------------------------------- results


@dataclass
class InteriorEstimate:
    """One interior parameter of one camera (a row of the AP table).

    ``status``: ``estimated``, ``dropped`` (by the selection, ``reason`` says why) or
    ``fixed`` (not estimated in this run).
    """

    camera: str
    name: str
    value: float
    std: float
    t: float
    significant: bool
    status: str
    reason: str = ""
    is_ap: bool = True


@dataclass
class CheckPointResult:
    """Check points intersected with the adjusted orientations, against their survey.

    ``measured`` and ``reference`` are in the mapping CRS; ``sigma`` (metres) propagates the
    image measurement noise of the intersection only (the orientations are held).
    """

    point_id: tuple[str, ...]
    measured: Array
    reference: Array
    sigma: Array
    n_images: NDArray[np.int64]

    @property
    def discrepancy(self) -> Array:
        """measured - reference (N, 3), metres."""
        return self.measured - self.reference

    def statistics(self) -> dict[str, float]:
        """Mean, standard deviation and RMS of the planimetric discrepancy (as in the tables
        of Lima, Debiasi & Menezes), and the RMS of E, N, H and 3D (metres)."""
        d = self.discrepancy
        n = d.shape[0]
        out = {"n": float(n)}
        if n == 0:
            return {**out, **{k: math.nan for k in (
                "mean_planimetric", "std_planimetric", "rms_planimetric", "rms_e", "rms_n",
                "rms_h", "rms_3d")}}  # fmt: skip
        hz = np.hypot(d[:, 0], d[:, 1])
        out["mean_planimetric"] = float(hz.mean())
        out["std_planimetric"] = float(hz.std(ddof=1)) if n > 1 else math.nan
        out["rms_planimetric"] = float(np.sqrt(np.mean(hz**2)))
        out["rms_e"], out["rms_n"], out["rms_h"] = (float(v) for v in np.sqrt(np.mean(d**2, 0)))
        out["rms_3d"] = float(np.sqrt(np.mean(np.sum(d**2, axis=1))))
        return out


@dataclass
class BundleResult:
    """Everything a bundle adjustment determined (frames and units in the attribute notes).

    Attributes
    ----------
    ap_model : str
    cameras : dict of str to Camera
        Adjusted cameras (interior orientation and APs).
    interior : list of InteriorEstimate
        f, x0, y0 and the APs of every camera, with sigmas, t and status.
    interior_correlation : dict of str to (names, ndarray)
        Correlation matrix of the estimated interior parameters of each camera.
    flagged_correlations : list of (camera, name, name, r)
        Pairs of interior parameters with |r| above the limit (final adjustment).
    dropped : list of (camera, name, reason)
        APs removed by the selection, in order.
    eo : ExteriorOrientationTable
        Adjusted orientations in the mapping CRS.
    eo_sigma : ndarray, shape (M, 6)
        Their standard deviations: metres and radians (omega-phi-kappa of the grid frame).
    image_camera : tuple of str, shape (M,)
    point_id, point_role : tuple of str, shape (P,)
        Object points (``tie``, ``control``, ``check``).
    point_xyz, point_sigma : ndarray, shape (P, 3)
        Mapping CRS and standard deviations (metres); check points: intersected.
    point_images : ndarray of int, shape (P,)
    observations : ImageObservations
        The image measurements, in the order of the residual arrays.
    obs_role : tuple of str
        ``tie``, ``control`` or ``check`` per measurement.
    v_px, w : ndarray, shape (N, 2)
        Residuals (adjusted minus observed, pixels) and Baarda's w per coordinate (NaN for
        check-point rows and untestable rows).
    redundancy : ndarray, shape (N, 2)
    rejected, used : ndarray of bool, shape (N,)
        Rejected by the robust stage or data snooping; used in the adjustment.
    image_rms : dict of str to (float, float)
        RMS of the residuals (col, row) of the measurements used, per image, pixels.
    check : CheckPointResult
    mount : dict or None
        Estimated lever arm (m, camera axes) and boresight (rad) with sigmas.
    adjustment : AdjustmentResult
        The final adjustment (sigma0, global test, warnings, rejections ...).
    local : LocalFrame
    warnings : list of str
    """

    ap_model: str
    cameras: dict[str, Camera]
    interior: list[InteriorEstimate]
    interior_correlation: dict[str, tuple[list[str], Array]]
    flagged_correlations: list[tuple[str, str, str, float]]
    dropped: list[tuple[str, str, str]]
    eo: ExteriorOrientationTable
    eo_sigma: Array
    image_camera: tuple[str, ...]
    point_id: tuple[str, ...]
    point_role: tuple[str, ...]
    point_xyz: Array
    point_sigma: Array
    point_images: NDArray[np.int64]
    observations: ImageObservations
    obs_role: tuple[str, ...]
    v_px: Array
    w: Array
    redundancy: Array
    rejected: NDArray[np.bool_]
    used: NDArray[np.bool_]
    image_rms: dict[str, tuple[float, float]]
    check: CheckPointResult
    mount: dict | None
    adjustment: AdjustmentResult
    local: LocalFrame
    warnings: list[str] = field(default_factory=list)

    @property
    def sigma0(self) -> float:
        return self.adjustment.sigma0

    @property
    def n_significant(self) -> int:
        """APs kept and significant in the final adjustment."""
        return sum(1 for p in self.interior if p.is_ap and p.status == "estimated" and
                   p.significant)  # fmt: skip

    def summary_row(self) -> dict[str, object]:
        """One row of the model comparison (the layout of Table 1 of Lima, Debiasi &
        Menezes, with sigma0 and the AP counts)."""
        st = self.check.statistics()
        aps = [p for p in self.interior if p.is_ap]
        return {
            "model": self.ap_model,
            "n_check": int(st["n"]),
            "mean_planimetric": st["mean_planimetric"],
            "std_planimetric": st["std_planimetric"],
            "rms_planimetric": st["rms_planimetric"],
            "rms_h": st["rms_h"],
            "rms_3d": st["rms_3d"],
            "sigma0": self.sigma0,
            "n_ap": len(aps),
            "n_ap_kept": sum(1 for p in aps if p.status == "estimated"),
            "n_significant": self.n_significant,
            "rejected": int(self.rejected.sum()),
        }


# ----------------------------------------------------------------------------- validation


def _fail(message: str, obs: ImageObservations, i: int) -> InputError:
    return InputError(message, **obs.where(int(i)))


def _check_observations(
    obs: ImageObservations,
    images: Sequence[str],
    eo_rows: Sequence[int] | None,
    eo_source: str,
    ground: GroundPoints,
    free: bool,
) -> None:
    """Refuse duplicated rows, unknown images, images without and points with one
    measurement, check rows that name no check point and control rows that name no ground
    point."""
    n = len(obs)
    if n == 0:
        raise InputError("the observation table has no rows", path=obs.source or None)
    img_names, img = np.unique(np.array(obs.image_id), return_inverse=True)
    pt_names, pt = np.unique(np.array(obs.point_id), return_inverse=True)
    img, pt = np.asarray(img).ravel(), np.asarray(pt).ravel()
    unknown = ~np.isin(img_names, np.array(images))
    if unknown.any():
        i = int(np.flatnonzero(unknown[img])[0])
        raise _fail(f"image '{obs.image_id[i]}' is not in the exterior orientation table", obs, i)
    key = img.astype(np.int64) * pt_names.size + pt
    order = np.argsort(key, kind="stable")
    dup = np.flatnonzero(key[order][1:] == key[order][:-1])
    if dup.size:
        j, i = int(order[dup[0]]), int(order[dup[0] + 1])
        row_j = obs.rows[j] if obs.rows else j
        raise _fail(
            f"point '{obs.point_id[i]}' is measured twice in image '{obs.image_id[i]}' (also "
            f"row {row_j})",
            obs, i,
        )  # fmt: skip
    seen = set(img_names.tolist())
    for k, im in enumerate(images):
        if im not in seen:
            row = eo_rows[k] if eo_rows else None
            raise InputError(
                f"image '{im}' has no observations: it cannot be oriented (remove it from the "
                "exterior orientation table or measure points in it)",
                path=eo_source or None,
                row=row,
            )
    roles = dict(zip(ground.point_id, ground.role))
    obs.require_control_known(
        roles, f"the ground point table{f' {ground.source}' if ground.source else ''} (give "
        "GROUND_POINTS with that point_id)",
    )  # fmt: skip
    for i, (p, t) in enumerate(zip(obs.point_id, obs.type)):
        if t == "check" and roles.get(p) != "check":
            raise _fail(
                f"row of type check names point '{p}', which is not a check point of the "
                "ground point table",
                obs, i,
            )  # fmt: skip
    counts = np.bincount(pt, minlength=pt_names.size)
    first_i = np.full(pt_names.size, n)
    np.minimum.at(first_i, pt, np.arange(n))
    for k in np.flatnonzero(counts < 2):
        p = str(pt_names[k])
        role = roles.get(p)
        if role == "control" and not free:
            continue
        what = "check point" if role == "check" else "tie point"
        raise _fail(
            f"{what} '{p}' is measured in one image only: it needs two or more (a control "
            "point may be measured once)",
            obs, int(first_i[k]),
        )  # fmt: skip


def _components(img: NDArray[np.intp], pts: NDArray[np.intp], n_img: int, n_pts: int):
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    graph = coo_matrix(
        (np.ones(img.size), (img, n_img + pts)), shape=(n_img + n_pts, n_img + n_pts)
    )
    return connected_components(graph, directed=False)


# ----------------------------------------------------------------------------- the problem


@dataclass
class _Setup:
    """Everything fixed for a block: indices, approximations, frames."""

    local: LocalFrame
    images: tuple[str, ...]
    image_cam: NDArray[np.intp]  # (M,) camera number
    cam_names: tuple[str, ...]
    cameras: list[Camera]  # with the AP family's lens model, initial values
    eo0: Array  # (M, 6) local
    points: tuple[str, ...]  # adjusted points (tie + control)
    roles: tuple[str, ...]
    xyz0: Array  # (P, 3) local
    obs_img: NDArray[np.intp]  # (N,) image number of every measurement
    obs_pt: NDArray[np.intp]  # (N,) adjusted point number, -1 for check rows
    obs_check: NDArray[np.intp]  # (N,) check point number, -1 otherwise
    check_ids: tuple[str, ...]
    check_ref_local: Array
    control_pt: NDArray[np.intp]  # adjusted point numbers of the control points
    control_cov: Array  # (C, 3, 3) local
    control_local: Array  # (C, 3)
    eo_obs: Array | None  # (M, 6) local observed orientations
    eo_obs_cov: Array | None  # (M, 6, 6)


def _local_frame(mapping: MappingFrame, ground: GroundPoints, eo: ExteriorOrientationTable | None):
    if len(ground):
        centre = ground.xyz.mean(axis=0)
    else:
        centre = eo.xyz.mean(axis=0)  # type: ignore[union-attr]
    return LocalFrame.at_map_point(mapping, centre)


def _eo_to_local(eo: ExteriorOrientationTable, local: LocalFrame) -> Array:
    centres, m = eo_map_to_local(eo.xyz, eo.opk, local)
    om, ph, ka = matrix_to_opk(m)
    return np.column_stack([centres, om, ph, ka])


def _eo_cov_to_local(eo: ExteriorOrientationTable, sigma: Array, local: LocalFrame) -> Array:
    """Covariance (M, 6, 6) in the local frame of orientations with map-frame sigmas (M, 6)."""
    jac = np.zeros((len(eo), 6, 6))
    steps = np.array([0.01, 0.01, 0.01, 1e-6, 1e-6, 1e-6])
    values = np.concatenate([eo.xyz, eo.opk], axis=1)
    for k in range(6):
        plus, minus = values.copy(), values.copy()
        plus[:, k] += steps[k]
        minus[:, k] -= steps[k]
        tp = replace(eo, xyz=plus[:, :3], opk=plus[:, 3:])
        tm = replace(eo, xyz=minus[:, :3], opk=minus[:, 3:])
        d = _eo_to_local(tp, local) - _eo_to_local(tm, local)
        d[:, 3:] = (d[:, 3:] + np.pi) % (2 * np.pi) - np.pi
        jac[:, :, k] = d / (2 * steps[k])
    cov_map = np.zeros((len(eo), 6, 6))
    cov_map[:, np.arange(6), np.arange(6)] = sigma**2
    return jac @ cov_map @ np.swapaxes(jac, 1, 2)


def _camera_for_family(cam: Camera, family: str) -> Camera:
    if family == "none":
        return cam
    target = AP_FAMILIES[family]
    if cam.distortion.model == target:
        return cam
    w = cam.width_px * cam.pixel_size_mm
    h = cam.height_px * cam.pixel_size_mm
    return replace(cam, distortion=make_ap_model(family, w, h, cam.focal_mm))


def _prepare(
    cameras: Sequence[Camera],
    image_camera: Mapping[str, str],
    obs: ImageObservations,
    ground: GroundPoints,
    mapping: MappingFrame,
    eo: ExteriorOrientationTable | None,
    eo_sigma: Array | None,
    options: BundleOptions,
    eo_rows: Sequence[int] | None,
    eo_source: str,
    should_stop: Callable[[], bool] | None,
    warnings: list[str],
) -> _Setup:
    cam_names = tuple(c.name for c in cameras)
    if len(set(cam_names)) != len(cam_names):
        raise InputError(f"two cameras share the name(s) {sorted(set(cam_names))}")
    images = tuple(eo.image_id) if eo is not None else tuple(dict.fromkeys(obs.image_id))
    _check_observations(obs, images, eo_rows, eo_source, ground, options.datum != "control")
    image_cam = np.zeros(len(images), dtype=np.intp)
    for k, im in enumerate(images):
        name = image_camera.get(im)
        if name is None:
            if len(cameras) == 1:
                continue
            raise InputError(
                f"image '{im}' has no camera: with several cameras give a camera column in "
                "the exterior orientation or observation table"
            )
        if name not in cam_names:
            raise InputError(
                f"image '{im}' names camera '{name}', which is not one of {', '.join(cam_names)}"
            )
        image_cam[k] = cam_names.index(name)
    roles = dict(zip(ground.point_id, ground.role))
    gidx = {p: i for i, p in enumerate(ground.point_id)}
    observed = set(obs.point_id)
    unobserved = [p for p in ground.point_id if p not in observed]
    if unobserved:
        warnings.append(
            _t(
                "{n} ground point(s) are not measured in any image and were not used: {ids}",
                n=len(unobserved),
                ids=", ".join(unobserved[:20]) + (" ..." if len(unobserved) > 20 else ""),
            )
        )
    free = options.datum != "control"
    adjusted: list[str] = []
    check_ids: list[str] = []
    for p in dict.fromkeys(obs.point_id):
        if roles.get(p) == "check":
            check_ids.append(p)
        else:
            adjusted.append(p)
    pnum = {p: i for i, p in enumerate(adjusted)}
    cnum = {p: i for i, p in enumerate(check_ids)}
    img_num = {im: k for k, im in enumerate(images)}
    obs_img = np.array([img_num[i] for i in obs.image_id], dtype=np.intp)
    obs_pt = np.array([pnum.get(p, -1) for p in obs.point_id], dtype=np.intp)
    obs_check = np.array([cnum.get(p, -1) for p in obs.point_id], dtype=np.intp)
    point_roles = tuple(
        "control" if (roles.get(p) == "control" and not free) else "tie" for p in adjusted
    )
    # the block must hang together through its adjusted points
    used = obs_pt >= 0
    ncomp, label = _components(obs_img[used], obs_pt[used], len(images), len(adjusted))
    if ncomp > 1:
        img_label = label[: len(images)]
        main = np.bincount(img_label).argmax()
        apart = [images[k] for k in np.flatnonzero(img_label != main)]
        raise InputError(
            f"the block falls into {ncomp} unconnected parts (no tie or control point links "
            f"them): images {', '.join(apart[:30])}{' ...' if len(apart) > 30 else ''} are "
            "not connected to the rest; adjust the parts separately or measure tie points "
            "between them",
            path=obs.source or None,
        )
    if eo is None and len(ground) == 0:
        raise InputError(
            "without approximate exterior orientations the bundle needs control points to "
            "orient the first images (give an EO table or ground points)"
        )
    # control points in another CRS: coordinates like degrees, or far from every image
    if len(ground):
        g = ground.xyz
        if (np.abs(g[:, 0]) <= 180).all() and (np.abs(g[:, 1]) <= 90).all():
            raise InputError(
                "the ground point coordinates look like degrees of longitude/latitude; they "
                f"must be in the mapping CRS ({mapping.crs.name}), easting and northing in "
                "metres",
                path=ground.source or None,
            )
        if eo is not None:
            height = max(float(np.median(np.abs(eo.xyz[:, 2] - np.median(g[:, 2])))), 100.0)
            far = max(_FAR_FACTOR * height, 5000.0)
            dist = np.min(
                np.hypot(g[:, None, 0] - eo.xyz[None, :, 0], g[:, None, 1] - eo.xyz[None, :, 1]),
                axis=1,
            )
            bad = np.flatnonzero(dist > far)
            if bad.size:
                i = int(bad[0])
                raise InputError(
                    f"ground point '{ground.point_id[i]}' lies {dist[i] / 1000:.1f} km from the "
                    f"nearest image centre: are the ground points in the mapping CRS "
                    f"({mapping.crs.name}) as the exterior orientations are?",
                    **ground.where(i),
                )
    local = _local_frame(mapping, ground, eo)
    ctrl_mask = [roles.get(p) == "control" and not free for p in adjusted]
    control_pt = np.flatnonzero(ctrl_mask).astype(np.intp)
    ctrl_g = np.array([gidx[adjusted[i]] for i in control_pt], dtype=np.intp)
    control_local = local.map_to_enu(ground.xyz[ctrl_g]) if ctrl_g.size else np.zeros((0, 3))
    control_cov = _cov_map_to_local(ground.xyz[ctrl_g], ground.sigma[ctrl_g], local)
    chk_g = np.array([gidx[p] for p in check_ids], dtype=np.intp)
    check_local = local.map_to_enu(ground.xyz[chk_g]) if chk_g.size else np.zeros((0, 3))
    cams = [_camera_for_family(c, options.ap_model) for c in cameras]
    eo_obs = eo_obs_cov = None
    if eo is not None:
        eo0 = _eo_to_local(eo, local)
        if eo_sigma is not None:
            eo_obs = eo0.copy()
            eo_obs_cov = _eo_cov_to_local(eo, eo_sigma, local)
    else:
        eo0 = _grow(cams, image_cam, obs, obs_img, obs_pt, control_pt, control_local,
                    len(images), len(adjusted), images, should_stop)  # fmt: skip
    if options.datum == "control" and control_pt.size < 3 and eo_obs is None:
        raise InputError(
            f"the datum needs three or more control points measured in the images or observed "
            f"exterior orientations; there are {control_pt.size} control points and no EO "
            "sigmas (or choose a free-network datum: inner or minimal)"
        )
    if eo_obs is None:
        # without observed orientations an image needs three points (six equations for its
        # six unknowns) to be oriented at all
        per_image = np.bincount(obs_img[obs_pt >= 0], minlength=len(images))
        few = np.flatnonzero(per_image < 3)
        if few.size:
            names = ", ".join(f"{images[k]} ({per_image[k]})" for k in few[:20])
            raise InputError(
                f"{few.size} image(s) have fewer than three measured points and cannot be "
                f"oriented without observed exterior orientations: {names}",
                path=obs.source or None,
            )
    xyz0 = _approximate_points(cams, image_cam, eo0, obs, obs_img, obs_pt, len(adjusted))
    if control_pt.size:
        xyz0[control_pt] = control_local
    bad = np.flatnonzero(~np.isfinite(xyz0).all(axis=1))
    if bad.size:
        p = adjusted[int(bad[0])]
        i = int(np.flatnonzero(obs_pt == bad[0])[0])
        raise _fail(
            f"point '{p}' cannot be intersected from the approximate orientations (its rays "
            "are parallel or miss each other); check its measurements",
            obs, i,
        )  # fmt: skip
    return _Setup(
        local=local, images=images, image_cam=image_cam, cam_names=cam_names, cameras=cams,
        eo0=eo0, points=tuple(adjusted), roles=point_roles, xyz0=xyz0, obs_img=obs_img,
        obs_pt=obs_pt, obs_check=obs_check, check_ids=tuple(check_ids),
        check_ref_local=check_local, control_pt=control_pt, control_cov=control_cov,
        control_local=control_local, eo_obs=eo_obs, eo_obs_cov=eo_obs_cov,
    )  # fmt: skip


def _cov_map_to_local(xyz: Array, sigma: Array, local: LocalFrame) -> Array:
    """(N, 3, 3) covariance in the local frame of map coordinates with sigmas (N, 3)."""
    jac = local.map_to_enu_jacobian(xyz)[1]
    return jac @ (sigma[:, :, None] ** 2 * np.eye(3)) @ np.swapaxes(jac, 1, 2)


def _cov_local_to_map(xyz_local: Array, cov: Array, local: LocalFrame) -> Array:
    jac = local.enu_to_map_jacobian(xyz_local)[1]
    return jac @ cov @ np.swapaxes(jac, 1, 2)


def _rays(cams, image_cam, eo, obs, obs_img, rows):
    origins = np.zeros((rows.size, 3))
    dirs = np.zeros((rows.size, 3))
    for c, cam in enumerate(cams):
        sel = np.flatnonzero(image_cam[obs_img[rows]] == c)
        if sel.size:
            o, d = image_rays(obs.pixels[rows[sel]], eo[obs_img[rows[sel]]], cam)
            origins[sel], dirs[sel] = o, d
    return origins, dirs


def _approximate_points(cams, image_cam, eo, obs, obs_img, obs_pt, n_points) -> Array:
    rows = np.flatnonzero(obs_pt >= 0)
    o, d = _rays(cams, image_cam, eo, obs, obs_img, rows)
    return meet_rays(o, d, obs_pt[rows], n_points)[0]


def _grow(cams, image_cam, obs, obs_img, obs_pt, control_pt, control_local, n_img, n_pts,
          images, should_stop) -> Array:  # fmt: skip
    """Orientations from resections of the images that see control, then growth."""
    import cv2

    from .resection import space_resection

    eo = np.full((n_img, 6), np.nan)
    known = np.full((n_pts, 3), np.nan)
    known[control_pt] = control_local
    for _ in range(n_img + 1):
        stop_if_asked(should_stop, "orienting the images")
        progress = False
        for k in range(n_img):
            if np.isfinite(eo[k]).all():
                continue
            rows = np.flatnonzero((obs_img == k) & (obs_pt >= 0))
            rows = rows[np.isfinite(known[obs_pt[rows]]).all(axis=1)]
            if rows.size < _MIN_RESECTION_POINTS and not (
                rows.size >= 4 and np.isin(obs_pt[rows], control_pt).all()
            ):
                continue
            try:
                res = space_resection(
                    obs.pixels[rows], known[obs_pt[rows]], cams[image_cam[k]],
                    sigma_px=1.0, options=AdjustmentOptions(snooping=True, max_iterations=30),
                )  # fmt: skip
            except (AdjustmentError, InputError, np.linalg.LinAlgError, cv2.error):
                continue  # a failed start is retried when more points are known
            if np.all(np.abs(res.rms_px) < 50.0):
                eo[k] = res.eo
                progress = True
        oriented = np.isfinite(eo).all(axis=1)
        if oriented.all():
            break
        rows = np.flatnonzero((obs_pt >= 0) & oriented[obs_img])
        if rows.size:
            o, d = _rays(cams, image_cam, np.nan_to_num(eo), obs, obs_img, rows)
            xyz = meet_rays(o, d, obs_pt[rows], n_pts)[0]
            new = np.isfinite(xyz).all(axis=1) & ~np.isfinite(known).all(axis=1)
            if new.any():
                known[new] = xyz[new]
                progress = True
        if not progress:
            break
    missing = [images[k] for k in np.flatnonzero(~np.isfinite(eo).all(axis=1))]
    if missing:
        raise InputError(
            f"without approximate exterior orientations, {len(missing)} image(s) could not be "
            f"oriented by resection from control points and intersected tie points: "
            f"{', '.join(missing[:20])}{' ...' if len(missing) > 20 else ''} (give an EO table "
            "or more control/tie points)"
        )
    return eo


# ----------------------------------------------------------------------------- the adjustment


@dataclass
class _Layout:
    """Parameter layout of one adjustment run."""

    names: list[str]
    x0: Array
    eo: NDArray[np.intp]  # (M, 6)
    interior: list[NDArray[np.intp]]  # per camera, indices of its free interior parameters
    free: list[NDArray[np.intp]]  # per camera, positions within Camera.interior_params
    mount: NDArray[np.intp] | None  # (6,)
    points: NDArray[np.intp]  # (P, 3)


def _layout(setup: _Setup, free: list[NDArray[np.intp]], cams: list[Camera], eo: Array,
            xyz: Array, mount: Array | None) -> _Layout:  # fmt: skip
    names: list[str] = []
    values: list[Array] = []
    M = len(setup.images)
    for im in setup.images:
        names += [f"{im} {p}" for p in EO_PARAM_NAMES]
    values.append(eo.ravel())
    idx_eo = np.arange(6 * M).reshape(M, 6)
    start = 6 * M
    interior = []
    for c, cam in enumerate(cams):
        inames = cam.interior_names
        f = free[c]
        names += [f"{cam.name} {inames[j]}" for j in f]
        values.append(cam.interior_params[f])
        interior.append(np.arange(start, start + f.size))
        start += f.size
    idx_mount = None
    if mount is not None:
        names += ["lever dx_c", "lever dy_c", "lever dz_c", "boresight d_omega",
                  "boresight d_phi", "boresight d_kappa"]  # fmt: skip
        values.append(mount)
        idx_mount = np.arange(start, start + 6)
        start += 6
    P = len(setup.points)
    names += [f"{p} {c}" for p in setup.points for c in "XYZ"]
    values.append(xyz.ravel())
    idx_pts = np.arange(start, start + 3 * P).reshape(P, 3)
    return _Layout(names, np.concatenate(values), idx_eo, interior, free, idx_mount, idx_pts)


class _ImageModel:
    """Collinearity of the measurements of one camera: x_local = [eo(6), point(3), interior].

    ``img`` is the image of each group: the rotations are computed once per image.
    """

    def __init__(self, cam: Camera, free: NDArray[np.intp], img: NDArray[np.intp]) -> None:
        self.cam = cam
        self.free = free
        _, self.first, self.inv = np.unique(img, return_index=True, return_inverse=True)
        self.inv = np.asarray(self.inv).ravel()

    def __call__(self, xl: Array) -> tuple[Array, Array]:
        cam = self.cam
        wrt = ("eo", "point", "interior") if self.free.size else ("eo", "point")
        if self.free.size:
            full = cam.interior_params
            full[self.free] = xl[0, 9:]
            cam = cam.with_interior(full)
        out = collinearity_jacobians(xl[:, 6:9], xl[self.first, :6], cam, wrt=wrt,
                                     image_index=self.inv)  # fmt: skip
        parts = [out["eo"], out["point"]]
        if self.free.size:
            parts.append(out["interior"][:, :, self.free])
        return out["pixels"], np.concatenate(parts, axis=2)


class _IdentityModel:
    def __call__(self, xl: Array) -> tuple[Array, Array]:
        g, k = xl.shape
        return xl.copy(), np.broadcast_to(np.eye(k), (g, k, k)).copy()


def _dopk_dm(m: Array) -> Array:
    """d (omega, phi, kappa) / d M (entries row-major), (N, 3, 9), for matrix_to_opk."""
    n = m.shape[0]
    out = np.zeros((n, 3, 9))
    m21, m22 = m[:, 2, 1], m[:, 2, 2]
    den = m21**2 + m22**2
    out[:, 0, 7] = -m22 / den  # omega = atan2(-m21, m22)
    out[:, 0, 8] = m21 / den
    a, b0, b1 = m[:, 2, 0], m[:, 0, 0], m[:, 1, 0]
    h = np.hypot(b0, b1)
    r2 = a**2 + h**2
    out[:, 1, 6] = h / r2  # phi = atan2(a, h)
    out[:, 1, 0] = -a * b0 / (h * r2)
    out[:, 1, 3] = -a * b1 / (h * r2)
    c, d = m[:, 1, 0], m[:, 0, 0]
    den2 = c**2 + d**2
    out[:, 2, 3] = -d / den2  # kappa = atan2(-m10, m00)
    out[:, 2, 0] = c / den2
    return out


class _ObservedEOModel:
    """Observed orientation (GNSS/INS with the nominal mount) against the adjusted one, in
    the conventions of DESIGN.md (``X_pc = X_obs + R_c^m da``, ``R_c^m = R_obs dR``):
    ``X_obs = X0 - M' da``, ``M_obs = dR M`` with ``da`` the lever-arm correction in camera
    axes and ``dR`` the boresight correction about the camera axes (what a boresight
    calibration estimates). x_local = [eo(6), da(3), bore(3)]."""

    def __init__(self, observed: Array) -> None:
        self.observed = observed

    def __call__(self, xl: Array) -> tuple[Array, Array]:
        from ..geometry.rotations import boresight_matrix, rx, ry, rz, skew

        g = xl.shape[0]
        eo, da, bo = xl[:, :6], xl[:, 6:9], xl[:, 9:12]
        M = opk_to_matrix(eo[:, 3], eo[:, 4], eo[:, 5])
        dM = opk_derivatives(eo[:, 3], eo[:, 4], eo[:, 5])  # (g, 3, 3, 3)
        dR = boresight_matrix(bo[:, 0], bo[:, 1], bo[:, 2])
        Mobs = dR @ M
        f = np.zeros((g, 6))
        J = np.zeros((g, 6, 12))
        f[:, :3] = eo[:, :3] - np.einsum("gji,gj->gi", M, da)
        J[:, :3, :3] = np.eye(3)
        J[:, :3, 3:6] = -np.einsum("gkji,gj->gik", dM, da)
        J[:, :3, 6:9] = -np.swapaxes(M, 1, 2)
        om, ph, ka = matrix_to_opk(Mobs)
        f[:, 3:] = np.column_stack([om, ph, ka])
        # keep the predicted angles on the branch of the observed ones
        f[:, 3:] = self.observed[:, 3:] + (f[:, 3:] - self.observed[:, 3:] + np.pi) % (
            2 * np.pi
        ) - np.pi
        dop = _dopk_dm(Mobs)  # (g, 3, 9)
        for k in range(3):
            dMobs = dR @ dM[:, k]
            J[:, 3:, 3 + k] = np.einsum("gaj,gj->ga", dop, dMobs.reshape(g, 9))
        # dR = Rx(a) Ry(b) Rz(c): d Rx(a)/da = Rx(a) [e_x]x, and likewise
        ra, rb, rc = rx(bo[:, 0]), ry(bo[:, 1]), rz(bo[:, 2])
        gen = [skew(e) for e in np.eye(3)]
        d_dR = (ra @ gen[0] @ rb @ rc, ra @ rb @ gen[1] @ rc, ra @ rb @ rc @ gen[2])
        for k in range(3):
            dMobs = d_dR[k] @ M
            J[:, 3:, 9 + k] = np.einsum("gaj,gj->ga", dop, dMobs.reshape(g, 9))
        return f, J


def _blocks(setup: _Setup, lay: _Layout, cams: list[Camera], obs: ImageObservations,
            keep: NDArray[np.bool_]) -> tuple[list, list, list[str]]:  # fmt: skip
    """Observation blocks; returns them, the measurement rows and the names of the
    image-point blocks."""
    blocks = []
    rows_of = []
    names = []
    for c, cam in enumerate(cams):
        rows = np.flatnonzero(keep & (setup.obs_pt >= 0) & (setup.image_cam[setup.obs_img] == c))
        if rows.size == 0:
            continue
        img, pt = setup.obs_img[rows], setup.obs_pt[rows]
        idx = np.concatenate(
            [lay.eo[img], lay.points[pt], np.broadcast_to(lay.interior[c], (rows.size,
                                                                             lay.interior[c].size))],
            axis=1,
        )
        labels = [f"{obs.image_id[r]} / {obs.point_id[r]}" for r in rows]
        blocks.append(
            GaussMarkovBlock(
                name=f"image points {cam.name}",
                observed=obs.pixels[rows],
                sigma=np.repeat(obs.sigma_px[rows, None], 2, axis=1),
                param_index=idx,
                model=_ImageModel(cam, lay.free[c], img),
                labels=labels,
                row_names=("col", "row"),
            )
        )
        rows_of.append(rows)
        names.append(blocks[-1].name)
    if setup.control_pt.size:
        blocks.append(
            GaussMarkovBlock(
                name="control points",
                observed=setup.control_local,
                sigma=setup.control_cov,
                param_index=lay.points[setup.control_pt],
                model=_IdentityModel(),
                labels=[setup.points[i] for i in setup.control_pt],
                row_names=("E", "N", "U"),
            )
        )
    if setup.eo_obs is not None:
        if lay.mount is not None:
            idx = np.concatenate(
                [lay.eo, np.broadcast_to(lay.mount, (len(setup.images), 6))], axis=1
            )
            model = _ObservedEOModel(setup.eo_obs)
        else:
            idx = lay.eo
            model = _IdentityModel()
        blocks.append(
            GaussMarkovBlock(
                name="observed orientation",
                observed=setup.eo_obs,
                sigma=setup.eo_obs_cov,
                param_index=idx,
                model=model,
                labels=list(setup.images),
                row_names=EO_PARAM_NAMES,
            )
        )
    return blocks, rows_of, names


def _datum_constraints(setup: _Setup, lay: _Layout, datum: str, xyz0: Array, eo0: Array):
    if datum == "control":
        return []
    if datum == "inner":
        tie = np.arange(len(setup.points))
        P0 = xyz0[tie]
        cen = P0.mean(axis=0)
        q = P0 - cen
        scale = max(float(np.sqrt(np.mean(np.sum(q * q, axis=1)))), 1e-9)
        G = np.zeros((7, tie.size, 3))
        G[0, :, 0] = G[1, :, 1] = G[2, :, 2] = 1.0
        # rotations about E, N, U: the columns of -[q]x, scaled to metres at the network size
        G[3, :, 1], G[3, :, 2] = -q[:, 2] / scale, q[:, 1] / scale
        G[4, :, 0], G[4, :, 2] = q[:, 2] / scale, -q[:, 0] / scale
        G[5, :, 0], G[5, :, 1] = -q[:, 1] / scale, q[:, 0] / scale
        G[6] = q / scale
        Gm = G.reshape(7, -1)
        base = P0.ravel()

        def inner(xl: Array, Gm=Gm, base=base) -> tuple[Array, Array]:
            return (Gm @ (xl[0] - base))[None], Gm[None]

        return [Constraint("inner constraints", lay.points[tie].ravel()[None], inner)]
    # minimal: the first image's orientation and the largest coordinate of the baseline to
    # the farthest centre, held at their approximate values
    far = int(np.argmax(np.linalg.norm(eo0[:, :3] - eo0[0, :3], axis=1)))
    axis = int(np.argmax(np.abs(eo0[far, :3] - eo0[0, :3])))
    held = np.concatenate([lay.eo[0], [lay.eo[far, axis]]])
    vals = np.concatenate([eo0[0], [eo0[far, axis]]])

    def minimal(xl: Array, vals=vals) -> tuple[Array, Array]:
        return (xl[0] - vals)[None], np.eye(7)[None]

    return [Constraint("minimal constraints", held[None], minimal)]


@dataclass
class _Run:
    result: AdjustmentResult
    lay: _Layout
    cams: list[Camera]
    blocks_rows: list[NDArray[np.intp]]  # measurement rows of each image-point block
    block_names: list[str]
    keep: NDArray[np.bool_]


def _run(setup: _Setup, obs: ImageObservations, cams: list[Camera], free: list,
         options: BundleOptions, keep: NDArray[np.bool_], robust: str, snooping: bool,
         eo: Array, xyz: Array, mount: Array | None, should_stop, progress) -> _Run:  # fmt: skip
    lay = _layout(setup, free, cams, eo, xyz, mount)
    blocks, rows_of, bnames = _blocks(setup, lay, cams, obs, keep)
    cons = _datum_constraints(setup, lay, options.datum, setup.xyz0, setup.eo0)
    opts = AdjustmentOptions(
        robust_blocks=bnames,
        snooping_blocks=bnames,
        max_iterations=options.max_iterations,
        snooping=snooping,
        snooping_alpha=options.snooping_alpha,
        robust=robust,
        eliminate=lay.points,
        max_rejections=max(50, len(obs) // 20),
        # a millionth of each parameter's precision: far below anything reported, and the
        # linear convergence of large-residual blocks reaches it in a few iterations
        tolerance=1e-6,
        compute_covariance=options.covariance,
    )
    result = adjust(lay.x0, lay.names, blocks, cons, opts, progress=progress,
                    should_stop=should_stop)  # fmt: skip
    return _Run(result, lay, cams, rows_of, bnames, keep)


def _cams_from(run: _Run) -> list[Camera]:
    out = []
    for c, cam in enumerate(run.cams):
        full = cam.interior_params
        full[run.lay.free[c]] = run.result.x[run.lay.interior[c]]
        out.append(cam.with_interior(full))
    return out


def _interior_table(run: _Run, options: BundleOptions, dropped: dict) -> tuple[
        list[InteriorEstimate], dict, list]:  # fmt: skip
    res = run.result
    r = max(res.redundancy, 1)
    tcrit = float(stats.t.ppf(1 - options.ap_alpha / 2, r))
    table: list[InteriorEstimate] = []
    corr_out: dict[str, tuple[list[str], Array]] = {}
    flagged: list[tuple[str, str, str, float]] = []
    cams = _cams_from(run)
    for c, cam in enumerate(cams):
        names = cam.interior_names
        idx = run.lay.interior[c]
        free = list(run.lay.free[c])
        for j, nm in enumerate(names):
            is_ap = j >= 3
            if j in free:
                k = free.index(j)
                val, sd = float(res.x[idx[k]]), float(res.std[idx[k]])
                t = abs(val) / sd if sd > 0 else math.inf
                table.append(InteriorEstimate(cam.name, nm, val, sd, t, bool(t > tcrit),
                                              "estimated", "", is_ap))  # fmt: skip
            elif is_ap and (cam.name, nm) in dropped:
                why = dropped[(cam.name, nm)]
                table.append(InteriorEstimate(cam.name, nm, 0.0, math.nan, math.nan, False,
                                              "dropped", why, is_ap))  # fmt: skip
            elif is_ap and options.ap_model == "none":
                continue
            else:
                value = float(cam.interior_params[j])
                table.append(InteriorEstimate(cam.name, nm, value, math.nan, math.nan, False,
                                              "fixed", "", is_ap))  # fmt: skip
        if idx.size:
            corr = res.correlation_of(idx)
            nm = [names[j] for j in free]
            corr_out[cam.name] = (nm, corr)
            iu = np.triu_indices(idx.size, 1)
            for a, b in zip(*iu):
                if abs(corr[a, b]) > options.max_correlation:
                    flagged.append((cam.name, nm[a], nm[b], float(corr[a, b])))
    return table, corr_out, flagged


def _drop_candidate(run: _Run, options: BundleOptions) -> tuple[int, int, str] | None:
    """(camera, interior position, reason) of the AP to drop next, or None: the least
    significant insignificant AP of any camera first; only when every AP is significant, the
    AP of the most correlated pair (a t-value and a correlation are never compared)."""
    res = run.result
    r = max(res.redundancy, 1)
    tcrit = float(stats.t.ppf(1 - options.ap_alpha / 2, r))
    per_camera = []
    for c, cam in enumerate(run.cams):
        idx = run.lay.interior[c]
        if idx.size:
            with np.errstate(divide="ignore", invalid="ignore"):
                t = np.abs(res.x[idx]) / res.std[idx]
            per_camera.append((c, cam, idx, run.lay.free[c], t))
    insignificant = [
        (float(t[k]), c, int(free[k]),
         _t("insignificant (t = {t:.2f} <= {critical:.2f}, alpha {alpha:g})", t=t[k],
            critical=tcrit, alpha=options.ap_alpha))
        for c, _cam, idx, free, t in per_camera
        for k in range(idx.size)
        if free[k] >= 3 and t[k] <= tcrit
    ]  # fmt: skip
    if insignificant:
        _, c, k, why = min(insignificant, key=lambda q: q[0])
        return c, k, why
    correlated = []
    for c, cam, idx, free, t in per_camera:
        corr = res.correlation_of(idx)
        names = cam.interior_names
        for a in range(idx.size):
            for b in range(a + 1, idx.size):
                pick = [k for k in (a, b) if free[k] >= 3]
                if not abs(corr[a, b]) > options.max_correlation or not pick:
                    continue
                # drop the AP of the pair (the less significant one when both are APs)
                k = min(pick, key=lambda q: t[q])
                other = b if k == a else a
                why = _t("|correlation| {r:.3f} > {limit:g} with {other}", r=abs(corr[a, b]),
                         limit=options.max_correlation, other=names[free[other]])  # fmt: skip
                correlated.append((abs(float(corr[a, b])), c, int(free[k]), why))
    if correlated:
        _, c, k, why = max(correlated, key=lambda q: q[0])
        return c, k, why
    return None


def _check_points(setup: _Setup, obs: ImageObservations, cams: list[Camera], eo: Array,
                  sigma0: float) -> CheckPointResult:  # fmt: skip
    """Forward intersection of the check points (Gauss-Newton on the collinearity)."""
    n = len(setup.check_ids)
    rows = np.flatnonzero(setup.obs_check >= 0)
    if n == 0:
        z = np.zeros((0, 3))
        return CheckPointResult((), z, z, z, np.zeros(0, dtype=np.int64))
    pt = setup.obs_check[rows]
    o, d = _rays(cams, setup.image_cam, eo, obs, setup.obs_img, rows)
    xyz, counts = meet_rays(o, d, pt, n)
    cov = np.full((n, 3, 3), np.nan)
    for _ in range(10):
        N = np.zeros((n, 3, 3))
        b = np.zeros((n, 3))
        for c, cam in enumerate(cams):
            sel = np.flatnonzero(setup.image_cam[setup.obs_img[rows]] == c)
            if not sel.size:
                continue
            r = rows[sel]
            out = collinearity_jacobians(xyz[pt[sel]], eo[setup.obs_img[r]], cam, wrt=("point",))
            J = out["point"] / obs.sigma_px[r, None, None]
            e = (obs.pixels[r] - out["pixels"]) / obs.sigma_px[r, None]
            JtJ = np.swapaxes(J, 1, 2) @ J
            Jte = np.einsum("nki,nk->ni", J, e)
            for i in range(3):
                b[:, i] += np.bincount(pt[sel], weights=Jte[:, i], minlength=n)
                for j in range(3):
                    N[:, i, j] += np.bincount(pt[sel], weights=JtJ[:, i, j], minlength=n)
        ok = np.isfinite(N).all(axis=(1, 2)) & (np.abs(np.linalg.det(N)) > 0)
        step = np.zeros((n, 3))
        step[ok] = np.linalg.solve(N[ok], b[ok][:, :, None])[:, :, 0]
        xyz = xyz + step
        cov[ok] = np.linalg.inv(N[ok])
        if np.nanmax(np.abs(step), initial=0.0) < 1e-7:
            break
    s0 = sigma0 if np.isfinite(sigma0) else 1.0
    cov_map = _cov_local_to_map(xyz, s0**2 * cov, setup.local)
    meas = setup.local.enu_to_map(xyz)
    ref = setup.local.enu_to_map(setup.check_ref_local)
    sig = np.sqrt(np.clip(np.einsum("nii->ni", cov_map), 0, None))
    return CheckPointResult(setup.check_ids, meas, ref, sig, counts.astype(np.int64))


def _eo_map_sigma(eo_local: Array, cov: Array, local: LocalFrame) -> tuple[Array, Array, Array]:
    """Mapping-frame EO (xyz, opk) and their sigmas (M, 6) by numerical propagation."""

    def to_map(e: Array) -> Array:
        xyz, opk = eo_local_to_map(e[:, :3], opk_to_matrix(e[:, 3], e[:, 4], e[:, 5]), local)
        return np.concatenate([xyz, opk], axis=1)

    base = to_map(eo_local)
    jac = np.zeros((eo_local.shape[0], 6, 6))
    steps = np.array([0.01, 0.01, 0.01, 1e-6, 1e-6, 1e-6])
    for k in range(6):
        p, m = eo_local.copy(), eo_local.copy()
        p[:, k] += steps[k]
        m[:, k] -= steps[k]
        dv = to_map(p) - to_map(m)
        dv[:, 3:] = (dv[:, 3:] + np.pi) % (2 * np.pi) - np.pi
        jac[:, :, k] = dv / (2 * steps[k])
    cm = jac @ cov @ np.swapaxes(jac, 1, 2)
    return base[:, :3], base[:, 3:], np.sqrt(np.clip(np.einsum("nii->ni", cm), 0, None))


def _finish(setup: _Setup, obs: ImageObservations, run: _Run, options: BundleOptions,
            dropped: dict, dropped_list: list, eo_table: ExteriorOrientationTable | None,
            warnings: list[str]) -> BundleResult:  # fmt: skip
    res = run.result
    lay = run.lay
    cams = _cams_from(run)
    x = res.x
    eo_local = x[lay.eo]
    M = len(setup.images)
    eo_cov = np.stack([res.covariance_of(lay.eo[k]) for k in range(M)])
    xyz_map, opk_map, eo_sig = _eo_map_sigma(eo_local, eo_cov, setup.local)
    time = eo_table.time if eo_table is not None else np.full(M, np.nan)
    group = eo_table.group if eo_table is not None else ("",) * M
    eo_out = ExteriorOrientationTable(setup.images, time, group, xyz_map, opk_map,
                                      setup.local.mapping.crs.to_wkt())  # fmt: skip
    pts_local = x[lay.points]
    blocks_q = res.cofactor_blocks
    P = len(setup.points)
    if blocks_q is not None:
        pcov = blocks_q.Q_eliminated * res.sigma0**2
    else:
        pcov = np.full((P, 3, 3), np.nan)
    pcov_map = _cov_local_to_map(pts_local, pcov, setup.local) if P else np.zeros((0, 3, 3))
    check = _check_points(setup, obs, cams, eo_local, res.sigma0)
    n_obs = len(obs)
    v = np.full((n_obs, 2), np.nan)
    w = np.full((n_obs, 2), np.nan)
    red = np.full((n_obs, 2), np.nan)
    rejected = np.zeros(n_obs, dtype=bool)
    used = np.zeros(n_obs, dtype=bool)
    for name, rows in zip(run.block_names, run.blocks_rows):
        table = res.residuals[name]
        v[rows], w[rows], red[rows] = table.v, table.w, table.redundancy_numbers
        rejected[rows] = table.rejected
        used[rows] = ~table.rejected
    # measurements left out before the final run (not kept) are rejected as well
    gone = (setup.obs_pt >= 0) & ~run.keep
    rejected[gone] = True
    # check-point rows: residuals of the intersection (not tested)
    chk = np.flatnonzero(setup.obs_check >= 0)
    if chk.size:
        xyz_chk = setup.local.map_to_enu(check.measured)
        for c, cam in enumerate(cams):
            sel = chk[setup.image_cam[setup.obs_img[chk]] == c]
            if sel.size:
                pred = collinearity_jacobians(xyz_chk[setup.obs_check[sel]],
                                              eo_local[setup.obs_img[sel]], cam, wrt=())
                v[sel] = pred["pixels"] - obs.pixels[sel]
    cnt = np.bincount(setup.obs_img[used], minlength=M)
    sq = [np.bincount(setup.obs_img[used], weights=v[used, j] ** 2, minlength=M) for j in (0, 1)]
    with np.errstate(invalid="ignore", divide="ignore"):
        r_img = np.sqrt(np.column_stack(sq) / cnt[:, None])
    rms = {im: (float(r_img[k, 0]), float(r_img[k, 1])) for k, im in enumerate(setup.images)}
    table, corr, flagged = _interior_table(run, options, dropped)
    mount = None
    if lay.mount is not None:
        mount = {
            "lever_arm_m": x[lay.mount[:3]].copy(),
            "lever_arm_std_m": res.std[lay.mount[:3]].copy(),
            "boresight_rad": x[lay.mount[3:]].copy(),
            "boresight_std_rad": res.std[lay.mount[3:]].copy(),
        }
    roles = setup.roles + ("check",) * len(setup.check_ids)
    pid = setup.points + setup.check_ids
    pxyz = np.vstack([setup.local.enu_to_map(pts_local) if P else np.zeros((0, 3)),
                      check.measured])  # fmt: skip
    psig = np.vstack([np.sqrt(np.clip(np.einsum("nii->ni", pcov_map), 0, None)), check.sigma])
    nimg = np.concatenate([
        np.bincount(setup.obs_pt[setup.obs_pt >= 0], minlength=P),
        check.n_images,
    ]).astype(np.int64)  # fmt: skip
    role_arr = np.array(setup.roles + ("check",), dtype=object)
    obs_role = tuple(role_arr[np.where(setup.obs_check >= 0, len(setup.roles), setup.obs_pt)])
    return BundleResult(
        ap_model=options.ap_model,
        cameras={c.name: c for c in cams},
        interior=table,
        interior_correlation=corr,
        flagged_correlations=flagged,
        dropped=list(dropped_list),
        eo=eo_out,
        eo_sigma=eo_sig,
        image_camera=tuple(setup.cam_names[c] for c in setup.image_cam),
        point_id=pid,
        point_role=roles,
        point_xyz=pxyz,
        point_sigma=psig,
        point_images=nimg,
        observations=obs,
        obs_role=obs_role,
        v_px=v,
        w=w,
        redundancy=red,
        rejected=rejected,
        used=used,
        image_rms=rms,
        check=check,
        mount=mount,
        adjustment=res,
        local=setup.local,
        warnings=warnings + list(res.warnings),
    )


def bundle_adjust(
    cameras: Sequence[Camera],
    observations: ImageObservations,
    ground: GroundPoints,
    mapping: MappingFrame,
    eo: ExteriorOrientationTable | None = None,
    eo_sigma: Array | None = None,
    image_camera: Mapping[str, str] | None = None,
    options: BundleOptions | None = None,
    eo_rows: Sequence[int] | None = None,
    eo_source: str = "",
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> BundleResult:
    """Bundle adjustment with self-calibration (see the module docstring).

    Parameters
    ----------
    cameras : sequence of Camera
        One or more cameras (unique names).
    observations : ImageObservations
        Image measurements (pixels); a point is a tie point unless ``ground`` names it (rows
        of type ``control`` must name a ground point).
    ground : GroundPoints
        Control and check points in the mapping CRS.
    mapping : MappingFrame
        The mapping CRS of the ground points and orientations.
    eo : ExteriorOrientationTable, optional
        Approximate or observed orientations (mapping CRS, omega-phi-kappa of the grid
        frame); without it the images are oriented by resection from control and growth.
    eo_sigma : ndarray, shape (M, 6), optional
        Standard deviations of the observed orientations (m, m, m, rad, rad, rad) in the
        mapping frame; they make ``eo`` observations instead of approximate values.
    image_camera : mapping of str to str, optional
        Camera name of each image (needed with several cameras).
    options : BundleOptions, optional
    eo_rows, eo_source : for error messages naming rows of the EO file.

    Returns
    -------
    BundleResult

    Raises
    ------
    InputError
        Inconsistent tables (the message names file and row): duplicated measurements,
        unknown images, images without and points with one measurement, an unconnected block,
        control points in another CRS, too few control points for the datum.
    NotObservableError
        Naming the parameters the block cannot determine.
    """
    for cam in cameras:
        cam.require_perspective("the bundle adjustment")
    opts = options if options is not None else BundleOptions()
    if opts.robust not in ("none", "huber", "cauchy"):
        raise InputError(f"robust must be none, huber or cauchy, got {opts.robust!r}")
    warnings: list[str] = []
    if eo is not None and eo_sigma is not None:
        eo_sigma = np.asarray(eo_sigma, dtype=np.float64)
        if eo_sigma.shape != (len(eo), 6) or not (np.isfinite(eo_sigma).all() and
                                                  (eo_sigma > 0).all()):  # fmt: skip
            raise InputError("the EO sigmas must be finite and > 0 for every image",
                             path=eo_source or None)  # fmt: skip
    if opts.estimate_mount and eo_sigma is None:
        raise InputError("estimating the lever arm and boresight needs observed orientations "
                         "(EO with sigma columns)")  # fmt: skip
    setup = _prepare(cameras, dict(image_camera or {}), observations, ground, mapping, eo,
                     eo_sigma, opts, eo_rows, eo_source, should_stop, warnings)  # fmt: skip
    cams = list(setup.cameras)
    free = []
    for cam in cams:
        f = []
        if opts.estimate_interior:
            f += [0, 1, 2]
        if opts.ap_model != "none":
            f += list(range(3, 3 + cam.distortion.n_params))
        free.append(np.array(f, dtype=np.intp))
    mount = np.zeros(6) if opts.estimate_mount else None
    keep = np.ones(len(observations), dtype=bool)
    report = progress if progress is not None else (lambda f: None)
    # 1. the full model, robust + snooping, from the approximate values
    run = _run(setup, observations, cams, free, opts, keep, opts.robust, opts.snooping,
               setup.eo0, setup.xyz0, mount, should_stop, None)  # fmt: skip
    report(0.4)
    dropped: dict[tuple[str, str], str] = {}
    dropped_list: list[tuple[str, str, str]] = []
    if opts.ap_selection and opts.ap_model != "none":
        # observations rejected by the first run stay out while APs are selected
        keep = keep.copy()
        for rows, name in zip(run.blocks_rows, run.block_names):
            keep[rows[run.result.residuals[name].rejected]] = False
        current = run
        changed = False
        for _ in range(sum(f.size for f in free)):
            stop_if_asked(should_stop, "selecting additional parameters")
            cand = _drop_candidate(current, opts)
            if cand is None:
                break
            c, pos, reason = cand
            name = cams[c].interior_names[pos]
            dropped[(cams[c].name, name)] = reason
            dropped_list.append((cams[c].name, name, reason))
            # a dropped AP is held at zero
            full = _cams_from(current)[c].interior_params
            full[pos] = 0.0
            new_cams = _cams_from(current)
            new_cams[c] = new_cams[c].with_interior(full)
            free = [f if k != c else f[f != pos] for k, f in enumerate(free)]
            x = current.result.x
            mnt = x[current.lay.mount] if current.lay.mount is not None else None
            current = _run(setup, observations, new_cams, free, opts, keep, "none", False,
                           x[current.lay.eo], x[current.lay.points], mnt, should_stop,
                           None)  # fmt: skip
            cams = new_cams
            changed = True
        if changed:
            x = current.result.x
            mnt = x[current.lay.mount] if current.lay.mount is not None else None
            keep = np.ones(len(observations), dtype=bool)
            run = _run(setup, observations, cams, free, opts, keep, opts.robust, opts.snooping,
                       x[current.lay.eo], x[current.lay.points], mnt, should_stop,
                       None)  # fmt: skip
    report(0.9)
    out = _finish(setup, observations, run, opts, dropped, dropped_list, eo, warnings)
    report(1.0)
    return out


def compare_ap_models(
    models: Sequence[str],
    run_one: Callable[[str], BundleResult],
) -> tuple[list[dict[str, object]], dict[str, BundleResult]]:
    """Run the bundle once per AP family and tabulate the comparison (Table 1 of Lima,
    Debiasi & Menezes: mean, standard deviation and RMS of the planimetric check-point
    discrepancies, with sigma0 and the AP counts), sorted by check-point RMS.

    ``run_one(model)`` runs the bundle with that family. Families whose adjustment fails
    (not observable) are listed with the reason instead of numbers.
    """
    rows: list[dict[str, object]] = []
    results: dict[str, BundleResult] = {}
    for m in models:
        try:
            res = run_one(m)
        except NotObservableError as exc:
            rows.append({"model": m, "error": str(exc)})
            continue
        results[m] = res
        rows.append(res.summary_row())

    def key(r: dict) -> tuple:
        v = r.get("rms_3d", math.nan)  # 3D: the check points are surveyed in 3D
        s = r.get("sigma0", math.nan)
        return (0 if "error" not in r else 1, v if isinstance(v, float) and math.isfinite(v)
                else math.inf, s if isinstance(s, float) else math.inf)  # fmt: skip

    rows.sort(key=key)
    for rank, r in enumerate(rows, 1):
        r["rank"] = rank if "error" not in r else None
    return rows, results
