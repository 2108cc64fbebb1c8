"""Camera calibration from views of a planar target: a self-calibrating bundle adjustment.

Model
-----
Every detected target point (col, row) in view ``j`` is a Gauss-Markov observation of the
collinearity equations (:func:`core.geometry.collinearity.collinearity_jacobians`) of the
camera's projection (perspective, or a fisheye projection of :mod:`core.geometry.projection`)
with the Brown-Conrady lens correction added (:class:`core.geometry.distortion.BrownConrady`:
``ideal = measured + d(measured)``), or, with ``lens_model="opencv"``, OpenCV's forward
distortion (:class:`core.geometry.forward_lens.OpenCVLens`: ``measured = F(ideal)``; the
coefficients act on coordinates normalised by the start focal length and are rescaled exactly
for OpenCV, see :func:`core.geometry.forward_lens.opencv_coefficients`). Unknowns:

- the interior orientation ``f, x0, y0`` (mm) and the lens coefficients ``k1 k2 k3 p1 p2``
  (any subset may be held at zero);
- one exterior orientation ``X0 Y0 Z0 omega phi kappa`` per view, in the target's frame;
- with a *free* field, the coordinates of the target points as well.

Datum: a *fixed* field (its nominal coordinates taken as exact) defines position, orientation
and scale. A *free* field is given the minimal datum of seven conditions: the origin point
and a second point along the first row (X axis) are held at their nominal coordinates (six:
position, two rotations and the scale from their nominal distance, i.e. the printed square
size), and a third point off that line is held in the plane ``Z = 0`` (the rotation about
the first row). The interior orientation does not depend on the datum; the free field
absorbs a target that is not flat or not printed to scale (the scale then rests on one
distance).

Initial values: the perspective projection from OpenCV's ``calibrateCamera`` (Zhang's
homography method); a fisheye projection from a search of the focal length that makes each
view's back-projected rays closest to those of a plane seen by a central camera (the DLT of
``ray ~ H (X, Y, 1)``, valid beyond 90 degrees off the axis; a wrong focal length bends the
grid's lines), the poses from those ``H``. The lens coefficients start at zero.

Statistics: sigma0 and the global test, standard deviations, the correlation matrix of the
interior orientation, per-view RMS residuals (``sqrt(sum(vcol^2 + vrow^2) / points)``,
OpenCV's definition of the reprojection error), Baarda's standardised residuals, and the
significance of every lens coefficient (Student's t-test of the value over its standard
deviation, the redundancy as the degrees of freedom).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy import stats

from ..errors import AdjustmentError, ConvergenceError, InputError, NotObservableError
from ..geometry.camera import Camera
from ..geometry.collinearity import collinearity_jacobians
from ..geometry.distortion import BrownConrady
from ..geometry.forward_lens import OpenCVLens
from ..geometry.projection import PROJECTIONS, ray_from_ideal
from ..geometry.rotations import matrix_to_opk
from ..i18n import mark as _t
from ..lsq.adjustment import adjust
from ..lsq.model import AdjustmentOptions, GaussMarkovBlock
from ..lsq.results import AdjustmentResult
from .calibration_options import (
    FIELD_MODES,
    INTERIOR_NAMES,
    LENS_NAMES,
    CalibrationOptions,
)
from .calibration_targets import Detection, TargetField

#: catalogue context of this module's ``_t("...")`` sentences (``make i18n``): the reports'
TR_CONTEXT = "Report"

Array = NDArray[np.float64]

# Points a view needs for its own pose (6 unknowns) with some redundancy.
MIN_POINTS_PER_VIEW = 6


@dataclass
class CalibrationResult:
    """Estimates and statistics of a camera calibration.

    Attributes
    ----------
    camera : Camera
        The calibrated camera (the chosen lens model and projection).
    sigmas : dict of str to float
        A-posteriori standard deviations of the estimated interior parameters (mm, per mm^n).
    parameter_names : list of str
        Names of the estimated interior parameters (rows of ``correlation``).
    correlation : ndarray (p, p)
        Their correlation matrix.
    t_values, significant : dict of str to float / bool
        t-test of every estimated lens coefficient.
    t_critical : float
    sigma0 : float
        A-posteriori standard deviation of unit weight (a-priori 1: the observations'
        sigma is ``sigma_px``, so ``sigma0 * sigma_px`` is the a-posteriori point sigma, px).
    sigma0_prior, redundancy, n_points, iterations, condition_number
    rms_px : float
        Reprojection RMS over all points (OpenCV's definition, see the module docstring).
    view_names : list of str
    view_rms_px : ndarray (V,)
    view_points : ndarray (V,) of int
    eo : ndarray (V, 6)
        Pose of each view in the target frame: X0 Y0 Z0 (m), omega phi kappa (rad).
    eo_sigma : ndarray (V, 6)
    residuals : list of tuple
        ``(view, point_id, col, row, v_col, v_row, w_col, w_row)`` per observation, pixels.
    field_xyz : ndarray (M, 3)
        Target coordinates after the adjustment (the nominal ones for a fixed field).
    field_ids : ndarray (M,)
    initial : dict
        Initial values (focal_px, principal point) and how they were found.
    adjustment : AdjustmentResult
    warnings : list of str
    sigma_px : float
        The a-priori sigma of a detected point, pixels.
    projection : str
    """

    camera: Camera
    sigmas: dict[str, float]
    parameter_names: list[str]
    correlation: Array
    t_values: dict[str, float]
    significant: dict[str, bool]
    t_critical: float
    sigma0: float
    sigma0_prior: float
    redundancy: int
    n_points: int
    iterations: int
    condition_number: float
    rms_px: float
    view_names: list[str]
    view_rms_px: Array
    view_points: NDArray[np.int64]
    eo: Array
    eo_sigma: Array
    residuals: list[tuple]
    field_xyz: Array
    field_ids: NDArray[np.int64]
    initial: dict
    adjustment: AdjustmentResult
    warnings: list[str] = field(default_factory=list)
    sigma_px: float = 0.0
    projection: str = "perspective"


# ----------------------------------------------------------------------------- initial values
def _cv_pose_to_eo(rvec: Array, tvec: Array) -> Array:
    """OpenCV pose (rotation vector or matrix; camera x right, y down, z forward) -> EO in
    the target frame (the project's camera: x right, y up, looking along -z)."""
    import cv2

    r = np.asarray(rvec, dtype=np.float64)
    r_cv = r if r.shape == (3, 3) else cv2.Rodrigues(r.reshape(3))[0]
    m = np.diag([1.0, -1.0, -1.0]) @ r_cv
    centre = -r_cv.T @ np.asarray(tvec, dtype=np.float64).reshape(3)
    om, ph, ka = matrix_to_opk(m)
    return np.array([*centre, float(om), float(ph), float(ka)])


def _rays_cv(px: Array, f_px: float, pp: Array, projection: str) -> Array:
    """Pixels -> unit rays in OpenCV's camera frame (x right, y down, z forward) with the given
    focal length and principal point and no lens correction; NaN outside the projection."""
    xy = np.column_stack([px[:, 0] - pp[0], pp[1] - px[:, 1]])  # y up, pixels
    ray = ray_from_ideal(xy, f_px, projection)  # the project's frame, looking along -z
    ray = ray * np.array([1.0, -1.0, -1.0])
    return ray / np.linalg.norm(ray, axis=1, keepdims=True)


def _plane_pose(xy: Array, rays: Array) -> tuple[Array, Array, float]:
    """Pose of a plane (points ``xy`` (N, 2) in Z = 0) seen along unit ``rays`` (N, 3):
    the DLT of ``ray ~ H (X, Y, 1)`` (valid for rays beyond 90 degrees off the axis, unlike
    a homography of image points), ``H = [r1 r2 t]``. Returns R, t (OpenCV frame) and the RMS
    angle (rad) between the rays and ``H x``."""
    c = xy.mean(axis=0)
    s = math.sqrt(2.0) / max(float(np.mean(np.linalg.norm(xy - c, axis=1))), 1e-12)
    t_norm = np.array([[s, 0, -s * c[0]], [0, s, -s * c[1]], [0, 0, 1.0]])
    x = np.column_stack([xy, np.ones(len(xy))]) @ t_norm.T
    zero = np.zeros_like(x)
    rx, ry, rz = rays[:, :1], rays[:, 1:2], rays[:, 2:3]
    # rows of ray x (H x) = 0: two independent per point
    a = np.vstack([np.hstack([zero, -rz * x, ry * x]), np.hstack([rz * x, zero, -rx * x])])
    h = np.linalg.svd(a)[2][-1].reshape(3, 3) @ t_norm
    hx = np.column_stack([xy, np.ones(len(xy))]) @ h.T
    if np.sum(np.sum(hx * rays, axis=1) > 0) < 0.5 * len(xy):
        h, hx = -h, -hx
    cosang = np.sum(hx * rays, axis=1) / np.linalg.norm(hx, axis=1)
    misfit = float(np.sqrt(np.mean(np.arccos(np.clip(cosang, -1.0, 1.0)) ** 2)))
    lam = 2.0 / (np.linalg.norm(h[:, 0]) + np.linalg.norm(h[:, 1]))
    r1, r2 = lam * h[:, 0], lam * h[:, 1]
    u, _, vt = np.linalg.svd(np.column_stack([r1, r2, np.cross(r1, r2)]))
    rot = u @ vt
    if np.linalg.det(rot) < 0:
        rot = u @ np.diag([1.0, 1.0, -1.0]) @ vt
    return rot, lam * h[:, 2], misfit


def _best_focal(
    views: list[tuple[Array, Array]], size: tuple[int, int], projection: str, relative: bool = False
) -> tuple[float, float]:
    """Focal length (px) whose back-projected rays make every view closest to a plane seen by
    a central camera (a wrong focal length bends the grid's lines), and the summed squares
    of the views' RMS misfit angles (rad^2) there; the principal point at the centre. With
    ``relative``, each misfit over the RMS angle of the view's rays from their mean (a long
    focal length narrows the rays and their misfit alike: projections then compare)."""
    w, h = size
    pp = np.array([0.5 * w, 0.5 * h])

    def misfit(f_px: float) -> float:
        total = 0.0
        for xyz, px in views:
            rays = _rays_cv(px, f_px, pp, projection)
            ok = np.isfinite(rays).all(axis=1)
            if ok.sum() < len(px):  # a point outside the projection: f too small
                return np.inf
            m = _plane_pose(xyz[:, :2], rays)[2]
            if relative:
                mean = rays.mean(axis=0) / np.linalg.norm(rays.mean(axis=0))
                m /= math.sqrt(float(np.mean(np.arccos(np.clip(rays @ mean, -1, 1)) ** 2)))
            total += m**2
        return total

    diag = math.hypot(w, h)
    grid = np.geomspace(0.05 * diag, 2.0 * diag, 60)
    costs = np.array([misfit(f) for f in grid])
    if not np.isfinite(costs).any():
        raise InputError(
            f"no focal length puts every target point inside the {projection} "
            "projection's image (a wider projection may fit)"
        )
    k = int(np.argmin(costs))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
    for _ in range(40):  # golden-section refinement within the bracket
        a = hi - 0.618 * (hi - lo)
        b = lo + 0.618 * (hi - lo)
        if misfit(a) < misfit(b):
            hi = b
        else:
            lo = a
    f_px = 0.5 * (lo + hi)
    return f_px, misfit(f_px)


def _init_fisheye(views: list[tuple[Array, Array]], size: tuple[int, int], projection: str):
    """The focal length of :func:`_best_focal` and the views' poses from it."""
    f_px = _best_focal(views, size, projection)[0]
    pp = np.array([0.5 * size[0], 0.5 * size[1]])
    eos = []
    for xyz, px in views:
        rot, t, _ = _plane_pose(xyz[:, :2], _rays_cv(px, f_px, pp, projection))
        eos.append(_cv_pose_to_eo(rot, t))
    return f_px, pp, np.array(eos)


#: A fisheye projection must fit the views this many times better than the perspective one
#: (:func:`fisheye_evidence`; real fisheye lenses, their distortion unmodelled: 2 to 3).
FISHEYE_FIT_RATIO = 1.5
#: ... and see the target this far off the axis, degrees (a rectilinear lens of 30 degrees
#: off the axis in the corners is wide already; a fisheye reaches 80 to 100).
FISHEYE_OFF_AXIS_DEG = 55.0


def fisheye_evidence(views: list[tuple[Array, Array]], size: tuple[int, int]) -> str:
    """The sentence saying that views taken as perspective look like a fisheye lens ("" when
    they do not): the target's straight lines fit the best fisheye projection better than a
    perspective one (:func:`_best_focal`'s relative misfit, principal point at the centre) by
    :data:`FISHEYE_FIT_RATIO`, the target seen :data:`FISHEYE_OFF_AXIS_DEG` or more off the
    axis through it; names the projection to try."""
    import warnings

    def rms(p: str) -> tuple[float, float]:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)  # degenerate views
                f, cost = _best_focal(views, size, p, relative=True)
        except InputError:  # no focal length fits the points inside that projection
            return math.nan, math.inf
        return f, math.sqrt(cost / len(views))

    fits = {p: rms(p) for p in PROJECTIONS}
    persp = fits["perspective"][1]
    best = min(PROJECTIONS[1:], key=lambda p: fits[p][1])
    f_px, mis = fits[best]
    pp = np.array([0.5 * size[0], 0.5 * size[1]])
    off = (
        max(
            float(np.nanmax(np.arccos(np.clip(_rays_cv(px, f_px, pp, best)[:, 2], -1, 1))))
            for _, px in views
        )
        if math.isfinite(mis)
        else 0.0
    )
    if not (mis * FISHEYE_FIT_RATIO < persp and off >= math.radians(FISHEYE_OFF_AXIS_DEG)):
        return ""
    return (
        f"the views look like a fisheye lens: the target's straight lines fit the {best} "
        f"projection (f {f_px:.0f} px) {persp / mis:.2g} times better than the perspective "
        f"one (RMS misfit {100 * mis:.2g} % against {100 * persp:.2g} % of the rays' "
        f"spread) and the target is seen up to about {math.degrees(off):.0f} degrees off the "
        f"axis (a field of view of about {2 * math.degrees(off):.0f} degrees): try PROJECTION "
        f"{best}"
    )


def _init_perspective(views: list[tuple[Array, Array]], size: tuple[int, int]):
    import cv2

    obj = [xyz.astype(np.float32) for xyz, _ in views]
    img = [(px - 0.5).astype(np.float32) for _, px in views]  # OpenCV pixel centres
    # OpenCV takes None for the camera matrix and distortion to estimate; its stubs do not
    _, k, _, rvecs, tvecs = cv2.calibrateCamera(obj, img, size, None, None)  # type: ignore[call-overload]
    f_px = 0.5 * (k[0, 0] + k[1, 1])
    pp = np.array([k[0, 2] + 0.5, k[1, 2] + 0.5])
    eos = np.array([_cv_pose_to_eo(r, t) for r, t in zip(rvecs, tvecs)])
    return f_px, pp, eos


# ----------------------------------------------------------------------------- model
class _ViewModel:
    """Collinearity of one block of observations: x_local = [eo (6), interior (p), point (3)?]."""

    def __init__(
        self, base: Camera, free: NDArray[np.intp], view: NDArray[np.intp], const_xyz: Array | None
    ) -> None:
        self.base = base
        self.free = free
        self.const_xyz = const_xyz
        _, self.first, inv = np.unique(view, return_index=True, return_inverse=True)
        self.inv = np.asarray(inv).ravel()

    def __call__(self, xl: Array) -> tuple[Array, Array]:
        p = self.free.size
        full = self.base.interior_params
        full[self.free] = xl[0, 6 : 6 + p]
        cam = self.base.with_interior(full)
        xyz = self.const_xyz if self.const_xyz is not None else xl[:, 6 + p : 9 + p]
        wrt = ("eo", "interior") if self.const_xyz is not None else ("eo", "interior", "point")
        out = collinearity_jacobians(xyz, xl[self.first, :6], cam, wrt=wrt, image_index=self.inv)
        parts = [out["eo"], out["interior"][:, :, self.free]]
        if self.const_xyz is None:
            parts.append(out["point"])
        return out["pixels"], np.concatenate(parts, axis=2)


def _flat(detections: Sequence[Detection], fld: TargetField):
    lookup = {int(i): k for k, i in enumerate(fld.ids)}
    views, pts, pxs, names = [], [], [], []
    for det in detections:
        known = np.array([int(i) in lookup for i in det.ids], dtype=bool)
        if known.sum() < MIN_POINTS_PER_VIEW:
            continue
        names.append(det.image)
        j = len(names) - 1
        views.append(np.full(int(known.sum()), j))
        pts.append(np.array([lookup[int(i)] for i in det.ids[known]], dtype=np.intp))
        pxs.append(det.pixels[known])
    if not names:
        raise InputError(f"no view has the {MIN_POINTS_PER_VIEW} target points a pose needs")
    return np.concatenate(views), np.concatenate(pts), np.concatenate(pxs), names


def _adjust_explained(
    x0v, pnames, blocks, constraints, aopts, progress, should_stop, perspective_views, size
) -> AdjustmentResult:
    """``adjust`` with its failures explained for a camera calibration: which views are
    missing, and (``perspective_views`` given) whether the views look like a fisheye lens."""

    def fisheye() -> str:  # why a perspective calibration may fail
        text = fisheye_evidence(perspective_views, size) if perspective_views else ""
        return f"; {text}" if text else ""

    try:
        res = adjust(
            x0v, pnames, blocks, constraints, aopts, progress=progress, should_stop=should_stop
        )
    except NotObservableError as exc:
        raise NotObservableError(
            f"camera calibration: {exc}. The views cannot determine these parameters: use "
            "more views, tilted in different directions (not all parallel to the target), "
            "with the target filling the image corners, or estimate fewer lens parameters"
            + fisheye(),
            parameters=exc.parameters,
        ) from exc
    except AdjustmentError as exc:
        raise type(exc)(f"camera calibration: {exc}{fisheye()}") from exc
    if not res.converged:
        raise ConvergenceError(
            f"camera calibration did not converge in {res.iterations} iterations{fisheye()}"
        )
    return res


def _residuals_by_point(res: AdjustmentResult, blocks, is_free: NDArray[np.bool_], px: Array):
    """(v, w): the residuals (px) and w-tests of every measured point in the input order."""
    v_all = np.zeros_like(px)
    w_all = np.full_like(px, np.nan)
    for b in blocks:
        sel = ~is_free if b.name == "fixed points" else is_free
        tab = res.residuals[b.name]
        v_all[sel] = tab.v
        w_all[sel] = tab.w
    return v_all, w_all


def _initial_camera(
    per_view: list[tuple[Array, Array]],
    opts: CalibrationOptions,
    name: str,
    width_px: int,
    height_px: int,
    pixel_size_mm: float,
) -> tuple[Camera, Array, dict]:
    """The start camera (no distortion), the start orientations (V, 6) and how they were
    found (focal length and principal point in pixels, the method)."""
    if opts.projection == "perspective":
        f_px, pp, eo0 = _init_perspective(per_view, (width_px, height_px))
        how = "OpenCV calibrateCamera (Zhang)"
    else:
        f_px, pp, eo0 = _init_fisheye(per_view, (width_px, height_px), opts.projection)
        how = "focal-length search: plane DLT of the back-projected rays (Z = 0 target)"
    ps = float(pixel_size_mm)
    base = Camera(
        name,
        f_px * ps,
        ps,
        width_px,
        height_px,
        x0_mm=(pp[0] - 0.5 * width_px) * ps,
        y0_mm=(0.5 * height_px - pp[1]) * ps,
        distortion=(
            OpenCVLens(scale_mm=f_px * ps, aspect=1.0)
            if opts.lens_model == "opencv"
            else BrownConrady()
        ),
        projection=opts.projection,
    )
    initial = {
        "focal_px": float(f_px),
        "ppx_px": float(pp[0]),
        "ppy_px": float(pp[1]),
        "method": how,
    }
    return base, eo0, initial


@dataclass(frozen=True)
class _Unknowns:
    """The parameter vector: [interior (n_io), eo (6 per view), free points (3 each)]."""

    free_io: NDArray[np.intp]  # the interior parameters adjusted (indices into the camera's)
    io_names: list[str]
    names: list[str]  # of every parameter
    x0: Array  # start values
    point_index: dict[int, int]  # field point -> index of its X among the parameters
    datum: list[int]  # the free field's datum points (empty for a fixed field)

    @property
    def n_io(self) -> int:
        return int(self.free_io.size)


def _unknowns(
    fld: TargetField,
    pt: NDArray[np.intp],
    view_names: list[str],
    base: Camera,
    eo0: Array,
    opts: CalibrationOptions,
) -> _Unknowns:
    """The parameters adjusted and their start values (a free field: its points but two of
    the datum)."""
    lens = base.distortion.param_names  # the model's own order
    free_io = np.array(
        [0, 1, 2] + [3 + i for i, p in enumerate(lens) if p in opts.lens_parameters],
        dtype=np.intp,
    )
    io_names = [base.interior_names[i] for i in free_io]
    n_io, n_views = free_io.size, len(view_names)
    x0 = [base.interior_params[free_io], eo0.ravel()]
    pnames = list(io_names)
    pnames += [f"{n}:{p}" for n in view_names for p in ("X0", "Y0", "Z0", "omega", "phi", "kappa")]
    seen = np.unique(pt)
    datum: list[int] = []
    if opts.field == "free":
        datum = [int(np.flatnonzero(fld.ids == d)[0]) for d in fld.datum]
        if not np.isin(datum, seen).all():
            raise InputError(
                "a free target field needs its datum points (origin, end of the "
                "first row, start of the last row) seen in some view"
            )
        fixed_pts = set(datum[:2])
        free_pts = [int(k) for k in seen if int(k) not in fixed_pts]
    else:
        free_pts = []
    point_index = {k: n_io + 6 * n_views + 3 * i for i, k in enumerate(free_pts)}
    for k in free_pts:
        x0.append(fld.xyz[k])
        pnames += [f"point {int(fld.ids[k])}:{c}" for c in "XYZ"]
    x0v = np.concatenate([np.asarray(a, dtype=np.float64).ravel() for a in x0])
    return _Unknowns(free_io, io_names, pnames, x0v, point_index, datum)


def _blocks(
    fld: TargetField,
    view: NDArray[np.intp],
    pt: NDArray[np.intp],
    px: Array,
    view_names: list[str],
    base: Camera,
    unk: _Unknowns,
    sigma: float,
) -> tuple[list[GaussMarkovBlock], NDArray[np.bool_]]:
    """The observation blocks (points of a fixed field, free points) and which observations
    are of free points."""
    n_io, point_index = unk.n_io, unk.point_index
    eo_idx = n_io + 6 * view[:, None] + np.arange(6)[None, :]
    io_idx = np.broadcast_to(np.arange(n_io), (view.size, n_io))
    is_free = np.array([int(k) in point_index for k in pt], dtype=bool)
    blocks = []
    labels = [f"{view_names[v]} / {int(fld.ids[k])}" for v, k in zip(view, pt)]
    for sel, free in ((~is_free, False), (is_free, True)):
        if not sel.any():
            continue
        idx = [eo_idx[sel], io_idx[sel]]
        if free:
            idx.append(
                np.array([point_index[int(k)] for k in pt[sel]])[:, None] + np.arange(3)[None, :]
            )
        blocks.append(
            GaussMarkovBlock(
                name="free points" if free else "fixed points",
                observed=px[sel],
                sigma=sigma,
                param_index=np.concatenate(idx, axis=1),
                model=_ViewModel(base, unk.free_io, view[sel], None if free else fld.xyz[pt[sel]]),
                labels=[labels[i] for i in np.flatnonzero(sel)],
                row_names=("col", "row"),
            )
        )
    return blocks, is_free


def _datum_constraints(unk: _Unknowns, free_field: bool) -> list:
    """A free field's third datum point held in Z = 0 (none for a fixed field)."""
    if not free_field:
        return []
    from ..lsq.model import Constraint

    zc = unk.point_index[unk.datum[2]] + 2

    def plane(xl: Array) -> tuple[Array, Array]:
        return xl.copy(), np.ones((xl.shape[0], 1, 1))

    return [Constraint("datum: third point in Z = 0", [[zc]], plane)]


def calibrate_camera(
    fld: TargetField,
    detections: Sequence[Detection],
    width_px: int,
    height_px: int,
    pixel_size_mm: float,
    options: CalibrationOptions | None = None,
    name: str = "camera",
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> CalibrationResult:
    """Calibrate a camera from detections of a planar target (see the module docstring).

    Parameters
    ----------
    fld : TargetField
        The target's points (ids, nominal coordinates in metres).
    detections : sequence of Detection
        Per view, the ids and pixel positions (project convention) found; views with fewer
        than :data:`MIN_POINTS_PER_VIEW` known points are left out (named in the warnings).
    width_px, height_px : int
        Image size.
    pixel_size_mm : float
        Pixel pitch; it only scales the millimetre values (the calibration is in pixels).
    options : CalibrationOptions
    name : str
        Name of the calibrated camera.

    Raises
    ------
    InputError
        Too few usable views or points, inconsistent detections.
    NotObservableError
        A parameter the views cannot determine (e.g. the focal length and the decentring from
        views all parallel to the target, or too few views); the message names it.
    """
    opts = options or CalibrationOptions()
    view, pt, px, names = _flat(detections, fld)
    skipped = [d.image for d in detections if d.image not in names]
    warnings: list[str]  # Messages: English text that keeps its template for translation
    warnings = [
        _t(
            "view {view!r} left out: fewer than {minimum} target points",
            view=s,
            minimum=MIN_POINTS_PER_VIEW,
        )
        for s in skipped
    ]
    n_views = len(names)
    if n_views < 2:
        raise NotObservableError(
            f"camera calibration needs at least 2 views of the target (3 or more, tilted in "
            f"different directions, to determine f, x0, y0 and the decentring); got {n_views}",
            parameters=["focal_mm", "x0_mm", "y0_mm"],
        )
    per_view = [(fld.xyz[pt[view == j]], px[view == j]) for j in range(n_views)]
    base, eo0, initial = _initial_camera(per_view, opts, name, width_px, height_px, pixel_size_mm)
    unk = _unknowns(fld, pt, names, base, eo0, opts)
    io_names, n_io, point_index = unk.io_names, unk.n_io, unk.point_index
    sigma = opts.sigma_px
    blocks, is_free = _blocks(fld, view, pt, px, names, base, unk, sigma)
    aopts = AdjustmentOptions(max_iterations=opts.max_iterations)
    constraints = _datum_constraints(unk, opts.field == "free")
    res = _adjust_explained(
        unk.x0,
        unk.names,
        blocks,
        constraints,
        aopts,
        progress,
        should_stop,
        per_view if opts.projection == "perspective" else None,
        (width_px, height_px),
    )
    full = base.interior_params
    full[unk.free_io] = res.x[:n_io]
    cam = base.with_interior(full)
    std = res.std
    sigmas = {n: float(std[i]) for i, n in enumerate(io_names)}
    corr = res.correlation_of(np.arange(n_io))
    tcrit = float(stats.t.ppf(1 - opts.alpha / 2, max(res.redundancy, 1)))
    t_values = {
        n: abs(float(res.x[i])) / float(std[i]) for i, n in enumerate(io_names) if n in LENS_NAMES
    }
    significant = {n: bool(t > tcrit) for n, t in t_values.items()}
    v_all, w_all = _residuals_by_point(res, blocks, is_free, px)
    d2 = np.sum(v_all**2, axis=1)
    view_rms = np.array([math.sqrt(float(np.mean(d2[view == j]))) for j in range(n_views)])
    view_pts = np.bincount(view, minlength=n_views).astype(np.int64)
    eo = res.x[n_io : n_io + 6 * n_views].reshape(n_views, 6)
    eo_sigma = std[n_io : n_io + 6 * n_views].reshape(n_views, 6)
    xyz = fld.xyz.copy()
    for k, i in point_index.items():
        xyz[k] = res.x[i : i + 3]
    rows = [
        (names[v], int(fld.ids[k]), float(c), float(r), float(a), float(b), float(wc), float(wr))
        for v, k, (c, r), (a, b), (wc, wr) in zip(view, pt, px, v_all, w_all)
    ]
    for n, sig in significant.items():
        if not sig:
            warnings.append(
                _t(
                    "{parameter} is not significant (t = {t:.2f} < {critical:.2f}): "
                    "consider holding it at zero",
                    parameter=n,
                    t=t_values[n],
                    critical=tcrit,
                )
            )
    warnings += list(res.warnings)
    return CalibrationResult(
        camera=cam,
        sigmas=sigmas,
        parameter_names=io_names,
        correlation=corr,
        t_values=t_values,
        significant=significant,
        t_critical=tcrit,
        sigma0=res.sigma0,
        sigma0_prior=1.0,
        redundancy=res.redundancy,
        n_points=int(view.size),
        iterations=res.iterations,
        condition_number=res.condition_number,
        rms_px=math.sqrt(float(np.mean(d2))),
        view_names=names,
        view_rms_px=view_rms,
        view_points=view_pts,
        eo=eo,
        eo_sigma=eo_sigma,
        residuals=rows,
        field_xyz=xyz,
        field_ids=fld.ids.copy(),
        initial=initial,
        adjustment=res,
        warnings=warnings,
        sigma_px=sigma,
        projection=opts.projection,
    )


def simulate_views(
    camera: Camera,
    fld: TargetField,
    eos: Array,
    noise_px: float = 0.0,
    seed: int = 0,
) -> list[Detection]:
    """Project a target field into views with known EO (N, 6) and add Gaussian pixel noise.

    Points outside the image or outside the projection are left out. For tests and benches.

    >>> from .calibration_targets import TargetSpec, target_field
    >>> cam = Camera("c", 4.0, 0.004, 1000, 800)
    >>> fld = target_field(TargetSpec("chessboard", 4, 3, 0.1))
    >>> det = simulate_views(cam, fld, np.array([[0.15, 0.1, 1.0, 0.0, 0.0, 0.0]]))
    >>> det[0].pixels[0].round(6).tolist()
    [350.0, 500.0]
    """
    from ..geometry.collinearity import project

    rng = np.random.default_rng(seed)
    out = []
    for j, e in enumerate(np.asarray(eos, dtype=np.float64).reshape(-1, 6)):
        p = project(fld.xyz, e, camera)
        ok = np.isfinite(p).all(axis=1) & camera.in_frame(np.nan_to_num(p, nan=-1.0))
        p = p[ok] + rng.normal(0.0, noise_px, size=(int(ok.sum()), 2)) if noise_px else p[ok]
        out.append(Detection(f"view{j:02d}", fld.ids[ok].copy(), p))
    return out


def look_at_eo(centre: Array, target: Array, roll_rad: float = 0.0) -> Array:
    """EO (6,) of a camera at ``centre`` looking at ``target`` (object frame, Z up-ish), the
    image x axis kept horizontal, then rolled by ``roll_rad`` about the viewing axis."""
    c = np.asarray(centre, dtype=np.float64)
    back = c - np.asarray(target, dtype=np.float64)
    zc = back / np.linalg.norm(back)  # camera z points back, towards the viewer
    up = np.array([0.0, 1.0, 0.0]) if abs(zc[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    xc = np.cross(up, zc)
    xc /= np.linalg.norm(xc)
    yc = np.cross(zc, xc)
    m = np.vstack([xc, yc, zc])  # rows: camera axes in object coordinates -> object to camera
    cr, sr = math.cos(roll_rad), math.sin(roll_rad)
    m = np.array([[cr, sr, 0.0], [-sr, cr, 0.0], [0.0, 0.0, 1.0]]) @ m
    om, ph, ka = matrix_to_opk(m)
    return np.array([*c, float(om), float(ph), float(ka)])


__all__ = [
    "FIELD_MODES",
    "INTERIOR_NAMES",
    "LENS_NAMES",
    "CalibrationOptions",
    "CalibrationResult",
    "calibrate_camera",
    "look_at_eo",
    "simulate_views",
]
