"""Space resection: the exterior orientation of one image from control points and straight
lines, by least squares.

:func:`space_resection` resects from points only (collinearity, start from OpenCV's solvePnP);
:func:`resect` from any mix of control points and image lines matched to 3D lines (the
coplanarity model or the equivalent-planes model of Tommaselli & Tozzi 1996 used by dos
Santos, Dal Poz & Dalmolin 2010), without an approximate orientation, with the global test,
covariance and correlation of the six parameters, data snooping of points and lines and the
diagnosis of what the observations cannot determine.

Object coordinates must be in a Cartesian frame (the local ENU adjustment frame, see
docs/conventions.md); the pose comes back in that frame as ``(X0, Y0, Z0, omega, phi,
kappa)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import ConvergenceError, InputError, NotObservableError, stop_if_asked
from ..geometry.camera import Camera
from ..geometry.lines import camera_vectors, coplanarity, image_vectors, parametrisation
from ..i18n import mark as _t
from ..lsq.adjustment import adjust
from ..lsq.model import AdjustmentOptions, GaussMarkovBlock, prior_block
from ..lsq.results import AdjustmentResult, ChiSquareTest
from .pose_start import initial_pose_pnp, pose_candidates  # noqa: F401 - initial_pose_pnp: the old address
from .resection_model import (
    EquivalentPlanes,
    LineConditions,
    equivalent_planes_block,
    line_block,
    observed_line_parameters,
    point_block,
)
from .resection_options import MODELS, PARAMETRISATIONS, ResectionOptions  # noqa: F401 - MODELS: the old address
from .resection_points import (  # noqa: F401 - the old address of these names
    EO_NAMES,
    ResectionResult,
    space_resection,
)

#: catalogue context of this module's ``_t("...")`` sentences (``make i18n``): the reports'
TR_CONTEXT = "Report"

Array = NDArray[np.float64]


# ============================================================================ points and lines

#: Names of the interior orientation parameters refined with ``estimate_interior``.
IO_NAMES = ("focal_mm", "x0_mm", "y0_mm")
#: Along-line standard deviation given to the end points of a 3D line (metres): where a line
#: ends along itself does not enter the conditions, only its direction and position across;
#: this keeps the covariance of (P1, P2) regular without changing the solution.
ALONG_LINE_SIGMA_M = 1.0
#: Smallest length of an image line (pixels) and of a 3D line (metres).
MIN_IMAGE_LINE_PX = 1.0
MIN_LINE_LENGTH_M = 1e-3
#: Convergence tolerance of the adjustment, in standard deviations of the parameters (the
#: engine stops when a step is below it, or below its square root, 1e-3 sigma, when the cost
#: no longer decreases: the strong correlation of position and attitude leaves steps of 1e-4
#: to 1e-3 sigma at the rounding floor of the cost). A step that stalls above that with lines
#: makes the engine re-solve the Gauss-Helmert residuals at the current parameters (the cost
#: of lines is non-linear in the 3D points) and go on from the consistent cost.
RESECTION_TOLERANCE = 1e-6
#: Largest angle (degrees) between 3D lines still counted as parallel by the diagnosis.
PARALLEL_DEG = 1.0


@dataclass(frozen=True)
class ResectionData:
    """The observations of one image and their control, in a Cartesian object frame.

    Attributes
    ----------
    point_ids : tuple of str, shape (N,)
    pixels : ndarray, shape (N, 2)
        Measured (col, row) of the control points, pixels.
    sigma_px : ndarray, shape (N,)
        Their standard deviation (each of col and row), pixels.
    xyz : ndarray, shape (N, 3)
        Object coordinates, metres.
    xyz_cov : ndarray, shape (N, 3, 3)
        Their covariance, m^2 (all zero: errorless control).
    line_ids : tuple of str, shape (L,)
    line_pixels : tuple of ndarray, each (K_i, 2)
        Pixels measured on each image line (K_i >= 2: its end points, or more points on it).
    line_sigma_px : tuple of ndarray, each (K_i,)
    line_p1, line_p2 : ndarray, shape (L, 3)
        Two points of each matched 3D line (e.g. its end points), metres.
    line_cov : ndarray, shape (L, 6, 6)
        Covariance of (P1, P2), m^2 (all zero: errorless); only its part across the line
        matters.
    """

    point_ids: tuple[str, ...] = ()
    pixels: Array = field(default_factory=lambda: np.empty((0, 2)))
    sigma_px: Array = field(default_factory=lambda: np.empty(0))
    xyz: Array = field(default_factory=lambda: np.empty((0, 3)))
    xyz_cov: Array = field(default_factory=lambda: np.empty((0, 3, 3)))
    line_ids: tuple[str, ...] = ()
    line_pixels: tuple[Array, ...] = ()
    line_sigma_px: tuple[Array, ...] = ()
    line_p1: Array = field(default_factory=lambda: np.empty((0, 3)))
    line_p2: Array = field(default_factory=lambda: np.empty((0, 3)))
    line_cov: Array = field(default_factory=lambda: np.empty((0, 6, 6)))

    def __post_init__(self) -> None:
        n = len(self.point_ids)
        set_ = object.__setattr__
        set_(self, "point_ids", tuple(map(str, self.point_ids)))
        set_(self, "pixels", np.asarray(self.pixels, dtype=np.float64).reshape(n, 2))
        set_(
            self,
            "sigma_px",
            np.broadcast_to(np.asarray(self.sigma_px, dtype=np.float64), (n,)).copy(),
        )
        set_(self, "xyz", np.asarray(self.xyz, dtype=np.float64).reshape(n, 3))
        cov = np.asarray(self.xyz_cov, dtype=np.float64)
        set_(
            self,
            "xyz_cov",
            np.broadcast_to(cov, (n, 3, 3)).copy() if cov.size else np.zeros((n, 3, 3)),
        )
        m = len(self.line_ids)
        set_(self, "line_ids", tuple(map(str, self.line_ids)))
        lp = tuple(np.asarray(v, dtype=np.float64).reshape(-1, 2) for v in self.line_pixels)
        set_(self, "line_pixels", lp)
        sig = self.line_sigma_px
        if len(sig) != len(lp):
            raise InputError("line_sigma_px needs one entry per image line")
        set_(
            self,
            "line_sigma_px",
            tuple(
                np.broadcast_to(np.asarray(s, dtype=np.float64), (len(v),)).copy()
                for s, v in zip(sig, lp)
            ),
        )
        set_(self, "line_p1", np.asarray(self.line_p1, dtype=np.float64).reshape(m, 3))
        set_(self, "line_p2", np.asarray(self.line_p2, dtype=np.float64).reshape(m, 3))
        lc = np.asarray(self.line_cov, dtype=np.float64)
        set_(
            self,
            "line_cov",
            np.broadcast_to(lc, (m, 6, 6)).copy() if lc.size else np.zeros((m, 6, 6)),
        )
        if len(lp) != m:
            raise InputError(f"{len(lp)} image lines for {m} line ids")
        for name, arr in (
            ("pixels", self.pixels),
            ("xyz", self.xyz),
            ("sigma_px", self.sigma_px),
            ("line_p1", self.line_p1),
            ("line_p2", self.line_p2),
        ):
            if not np.isfinite(arr).all():
                raise InputError(f"resection: {name} must be finite")
        if (self.sigma_px <= 0).any() or any((s <= 0).any() for s in self.line_sigma_px):
            raise InputError("resection: sigma_px must be > 0")
        for i, v in zip(self.line_ids, lp):
            if len(v) < 2:
                raise InputError(f"image line {i}: needs at least 2 points, got {len(v)}")
            span = float(np.linalg.norm(v - v[0], axis=1).max())
            if span < MIN_IMAGE_LINE_PX:
                raise InputError(
                    f"image line {i} has zero length ({span:.3g} px between its points): "
                    "measure its two ends apart"
                )
        length = np.linalg.norm(self.line_p2 - self.line_p1, axis=1)
        for i, ln in zip(self.line_ids, length):
            if not ln >= MIN_LINE_LENGTH_M:
                raise InputError(
                    f"3D line {i} has zero length ({ln:.3g} m): its two points coincide"
                )

    @property
    def n_points(self) -> int:
        return len(self.point_ids)

    @property
    def n_lines(self) -> int:
        return len(self.line_ids)


@dataclass(frozen=True)
class SpaceResection:
    """The orientation of one image from points and lines, with its statistics.

    Attributes
    ----------
    eo : ndarray, shape (6,)
        ``(X0, Y0, Z0, omega, phi, kappa)``, metres and radians, the data's frame.
    covariance, covariance_prior : ndarray, shape (6, 6)
        A-posteriori (``sigma0^2 Qxx``) and a-priori (``Qxx``) covariance of ``eo``.
    correlation : ndarray, shape (6, 6)
    interior, interior_std : ndarray, shape (3,) or None
        Refined ``(focal_mm, x0_mm, y0_mm)`` and their a-posteriori standard deviations.
    sigma0 : float
        A-posteriori standard deviation of unit weight (NaN without redundancy).
    redundancy : int
    chi2 : ChiSquareTest
        Two-sided global test (the engine's).
    chi2_critical : float
        The source's one-sided critical value ``chi2(1 - alpha, redundancy)``; the test
        passes when ``chi2.statistic <= chi2_critical``.
    point_v : ndarray, shape (N, 2)
        Residuals of the measured pixels of the control points (adjusted minus measured).
    point_w : ndarray, shape (N,)
        Largest |Baarda w| of each point's observations.
    point_rejected : ndarray of bool, shape (N,)
    line_v : tuple of ndarray, each (K_i, 2)
        Residuals of the pixels measured on each line (coplanarity model; NaN otherwise).
    line_distance_px : tuple of ndarray, each (K_i,)
        Signed distance of each measured line point from the 3D line projected with ``eo``
        (pixels; the control as given).
    line_ab_v : ndarray, shape (L, 2)
        Residuals of ``(a, b)`` of each line (equivalent-planes model; NaN otherwise): ``a``
        dimensionless, ``b`` mm.
    line_w : ndarray, shape (L,)
        Largest |w| of each line's observations.
    line_rejected : ndarray of bool, shape (L,)
    start : str
        How the start pose was found.
    start_eo : ndarray, shape (6,)
    model : str
    iterations : int
    adjustment : AdjustmentResult
        Every statistic of the adjustment.
    warnings : tuple of str
    """

    eo: Array
    covariance: Array
    covariance_prior: Array
    correlation: Array
    interior: Array | None
    interior_std: Array | None
    sigma0: float
    redundancy: int
    chi2: ChiSquareTest
    chi2_critical: float
    point_v: Array
    point_w: Array
    point_rejected: NDArray[np.bool_]
    line_v: tuple[Array, ...]
    line_distance_px: tuple[Array, ...]
    line_ab_v: Array
    line_w: Array
    line_rejected: NDArray[np.bool_]
    start: str
    start_eo: Array
    model: str
    iterations: int
    adjustment: AdjustmentResult
    warnings: tuple[str, ...] = ()

    @property
    def std(self) -> Array:
        """A-posteriori standard deviations of ``eo`` (metres, radians)."""
        return np.sqrt(np.clip(np.diag(self.covariance), 0.0, None))

    @property
    def std_prior(self) -> Array:
        """A-priori standard deviations of ``eo`` (from the observations' sigmas)."""
        return np.sqrt(np.clip(np.diag(self.covariance_prior), 0.0, None))

    @property
    def chi2_passed(self) -> bool:
        """The source's test: ``statistic <= chi2(1 - alpha, redundancy)`` (True without
        redundancy)."""
        return not (self.redundancy > 0) or self.chi2.statistic <= self.chi2_critical


def _line_cov(data: ResectionData) -> tuple[Array, NDArray[np.bool_]]:
    """(P1, P2) covariances made regular along the lines; which lines have one at all."""
    cov = data.line_cov.copy()
    has = np.abs(cov).reshape(len(cov), -1).max(axis=1) > 0 if len(cov) else np.zeros(0, bool)
    if has.any():
        u = data.line_p2 - data.line_p1
        u /= np.linalg.norm(u, axis=1, keepdims=True)
        along = ALONG_LINE_SIGMA_M**2 * np.einsum("li,lj->lij", u, u)
        cov[:, :3, :3] += along
        cov[:, 3:, 3:] += along
        low = np.linalg.eigvalsh(cov[has])[:, 0]
        bad = np.flatnonzero(low <= 1e-18)
        if bad.size:
            i = data.line_ids[int(np.flatnonzero(has)[bad[0]])]
            raise InputError(
                f"3D line {i}: its covariance leaves the line's position across itself "
                "undetermined (singular); give a full covariance or none (errorless)"
            )
    return cov, has


def _parallel_diagnosis(data: ResectionData) -> None:
    """All lines parallel and fewer than 2 points: the position along them is free."""
    if data.n_lines < 2 or data.n_points >= 2:
        return
    u = data.line_p2 - data.line_p1
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    cosines = np.abs(u @ u[0])
    if cosines.min() < math.cos(math.radians(PARALLEL_DEG)):
        return
    d = u[0] * np.sign(u[0][np.argmax(np.abs(u[0]))])
    names = [n for n, c in zip(EO_NAMES[:3], d) if abs(c) > 0.1]
    raise NotObservableError(
        f"Not observable: all {data.n_lines} lines are parallel (direction "
        f"{d[0]:.3f}, {d[1]:.3f}, {d[2]:.3f} in the object frame) and there "
        f"{'is 1 control point' if data.n_points == 1 else 'are no control points'}: the "
        f"position along them ({', '.join(names)}) is not determined; measure lines in "
        "another direction or control points",
        parameters=names,
    )


def _conditions_count(data: ResectionData, model: str) -> int:
    lines = sum(len(v) for v in data.line_pixels) if model == "coplanarity" else 2 * data.n_lines
    return 2 * data.n_points + lines


class _Problem:
    """The blocks of one resection (shared by the start-pose ranking and the adjustment)."""

    def __init__(self, data: ResectionData, camera: Camera, options: ResectionOptions) -> None:
        self.data, self.camera, self.options = data, camera, options
        self.n = 9 if options.estimate_interior else 6
        self.names = list(EO_NAMES) + (list(IO_NAMES) if options.estimate_interior else [])
        self.blocks: list = []
        #: (block name, indices into the data) of every block, for the results
        self.members: list[tuple[str, str, NDArray[np.int64]]] = []
        if data.n_points:
            has = np.abs(data.xyz_cov).reshape(data.n_points, -1).max(axis=1) > 0
            for flag, name in ((False, "control points"), (True, "control points (weighted)")):
                idx = np.flatnonzero(has == flag)
                if idx.size:
                    self.blocks.append(
                        point_block(
                            name,
                            camera,
                            data.pixels[idx],
                            data.sigma_px[idx],
                            data.xyz[idx],
                            data.xyz_cov[idx] if flag else None,
                            self._index(idx.size),
                            [data.point_ids[i] for i in idx],
                        )
                    )
                    self.members.append(("point", name, idx))
        if data.n_lines:
            cov, has = _line_cov(data)
            ks = np.array([len(v) for v in data.line_pixels])
            for k in np.unique(ks):
                for flag in (False, True):
                    idx = np.flatnonzero((ks == k) & (has == flag))
                    if not idx.size:
                        continue
                    px = np.stack([data.line_pixels[i] for i in idx])
                    sig = np.stack([data.line_sigma_px[i] for i in idx])
                    labels = [data.line_ids[i] for i in idx]
                    line_cov = cov[idx] if flag else None
                    name = f"lines ({k} points{', weighted' if flag else ''})"
                    if options.model == "coplanarity":
                        cond = LineConditions(
                            camera,
                            "coplanarity",
                            int(k),
                            bool(flag),
                            data.line_p1[idx],
                            data.line_p2[idx],
                        )
                        self.blocks.append(
                            line_block(name, cond, px, sig, line_cov, self._index(idx.size), labels)
                        )
                    else:
                        kind = parametrisation(image_vectors(px, camera)[0])
                        if options.parametrisation != "auto":
                            kind[:] = PARAMETRISATIONS.index(options.parametrisation) - 1
                        ab, ab_cov = observed_line_parameters(camera, px, sig, kind)
                        eqp = EquivalentPlanes(
                            camera, bool(flag), data.line_p1[idx], data.line_p2[idx], kind
                        )
                        self.blocks.append(
                            equivalent_planes_block(
                                name, eqp, ab, ab_cov, line_cov, self._index(idx.size), labels
                            )
                        )
                    self.members.append(("line", name, idx))

    def _index(self, g: int) -> Array:
        return np.tile(np.arange(self.n), (g, 1))

    def x0(self, eo: Array) -> Array:
        io: Array | list[float]  # the interior orientation's start, when estimated
        io = self.camera.interior_params[:3] if self.options.estimate_interior else []
        return np.concatenate([eo, io])

    def cost(self, eo: Array) -> float:
        """Weighted misclosure ``sum w' (B S B')^-1 w`` at the observations (inf if undefined)."""
        x = self.x0(eo)
        total = 0.0
        for blk in self.blocks:
            obs = np.asarray(blk.observed, dtype=np.float64)
            xl = x[np.asarray(blk.param_index)]
            s = np.asarray(blk.sigma, dtype=np.float64)
            if s.ndim == 2:
                s = np.einsum("gi,ij->gij", s**2, np.eye(s.shape[1]))
            with np.errstate(all="ignore"):
                if isinstance(blk, GaussMarkovBlock):
                    f, _ = blk.model(xl)
                    w, bmat = f - obs, -np.broadcast_to(np.eye(obs.shape[1]), s.shape)
                else:
                    w, _, bmat = blk.condition(xl, obs)
                pe = bmat @ s @ np.swapaxes(bmat, 1, 2)
                if not (np.isfinite(w).all() and np.isfinite(pe).all()):
                    return math.inf
                try:
                    sol = np.linalg.solve(pe, w[..., None])[..., 0]
                except np.linalg.LinAlgError:
                    return math.inf
            total += float(np.sum(w * sol))
        return total if math.isfinite(total) else math.inf


def _start_pose(
    problem: _Problem, data: ResectionData, camera: Camera, eo0: ArrayLike | None
) -> tuple[Array, str]:
    """The start pose and how it was found: ``eo0`` when given, else the candidate of
    :func:`.pose_start.pose_candidates` that fits the rigorous model best."""
    if eo0 is not None:
        return np.asarray(eo0, dtype=np.float64).reshape(6).copy(), "given"
    cands = pose_candidates(
        camera, data.pixels, data.xyz, list(data.line_pixels), data.line_p1, data.line_p2
    )
    if not cands:
        raise ConvergenceError(
            "no start pose puts the control in front of the camera: check that the "
            "image ids, the point and line ids and the camera match"
        )
    costs = [problem.cost(c.eo) for c in cands]
    best = int(np.argmin(costs))
    return cands[best].eo.copy(), cands[best].method


def _residuals(
    problem: _Problem, adj: AdjustmentResult, data: ResectionData, model: str
) -> tuple[Array, Array, NDArray[np.bool_], list[Array], Array, Array, NDArray[np.bool_]]:
    """The adjustment's residuals, largest |w| and rejections per control point and per line
    (the line's image points for coplanarity, its (a, b) for equivalent planes)."""
    point_v = np.full((data.n_points, 2), np.nan)
    point_w = np.full(data.n_points, np.nan)
    point_rej = np.zeros(data.n_points, bool)
    line_v = [np.full((len(v), 2), np.nan) for v in data.line_pixels]
    line_ab_v = np.full((data.n_lines, 2), np.nan)
    line_w = np.full(data.n_lines, np.nan)
    line_rej = np.zeros(data.n_lines, bool)
    for kind, name, idx in problem.members:
        table = adj.residuals[name]
        wmax = (
            np.nanmax(np.abs(table.w), axis=1)
            if np.isfinite(table.w).any()
            else (np.full(len(idx), np.nan))
        )
        if kind == "point":
            point_v[idx] = table.v[:, :2]
            point_w[idx] = wmax
            point_rej[idx] = table.rejected
        else:
            k = len(data.line_pixels[idx[0]])
            for j, i in enumerate(idx):
                if model == "coplanarity":
                    line_v[i] = table.v[j, : 2 * k].reshape(k, 2)
                else:
                    line_ab_v[i] = table.v[j, :2]
            line_w[idx] = wmax
            line_rej[idx] = table.rejected
    return point_v, point_w, point_rej, line_v, line_ab_v, line_w, line_rej


def resect(
    data: ResectionData,
    camera: Camera,
    options: ResectionOptions | None = None,
    eo0: ArrayLike | None = None,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> SpaceResection:
    """Exterior orientation of one image from control points and straight lines.

    The full resection (what the ``resection`` algorithm and the dock run); for a quick
    points-only pose from matched points, see :func:`space_resection`.

    Every observation enters one rigorous Gauss-Helmert adjustment (:mod:`.resection_model`):
    points by collinearity, lines by the coplanarity model (default) or the equivalent-planes
    model of Tommaselli & Tozzi (1996) in both its parametrisations, with the image points'
    sigmas and the control's covariances propagated; optionally the focal length and the
    principal point too. Points take any central projection of the camera (perspective or a
    fisheye of :mod:`core.geometry.projection`, with that projection's own Jacobian); lines
    need a perspective camera. Without ``eo0`` the start pose comes from
    :func:`.pose_start.pose_candidates` (no approximate orientation needed): the candidate
    that fits the rigorous model best.

    Parameters
    ----------
    data : ResectionData
        Observations and control, in a Cartesian object frame (e.g. the local ENU frame).
    camera : Camera
        Interior orientation (lens correction applied, held fixed); any projection for
        points, perspective for lines.
    options : ResectionOptions, optional
    eo0 : (6,) array_like, optional
        Start pose ``(X0, Y0, Z0, omega, phi, kappa)``; weighted as observations when
        ``options.eo_prior_sigma`` is given.
    progress, should_stop
        Fraction done; cancellation (:class:`core.errors.Cancelled`).

    Returns
    -------
    SpaceResection

    Raises
    ------
    InputError
        Too few observations for the unknowns, image or 3D lines of zero length, lines with
        a fisheye camera.
    NotObservableError
        The observations cannot determine the orientation (e.g. all lines parallel), or the
        interior orientation; names the parameters.
    ConvergenceError
        The adjustment did not converge (no numbers are returned).

    Examples
    --------
    Four lines and two points seen by a nadir camera 1000 m up, noise-free:

    >>> from lidarphoto.core.geometry.collinearity import project
    >>> cam = Camera("c", focal_mm=100.0, pixel_size_mm=0.01, width_px=4000, height_px=4000)
    >>> eo = np.array([10.0, -20.0, 1000.0, 0.01, -0.02, 0.6])
    >>> p1 = np.array([[-50, -50, 5], [40, -60, 12], [-60, 30, 0], [30, 50, 8]], float)
    >>> p2 = p1 + [[60, 0, 0], [0, 50, 0], [40, 40, 0], [30, -20, 2]]
    >>> pts = np.array([[0.0, 0.0, 3.0], [70.0, 80.0, 10.0]])
    >>> lines = tuple(project(np.vstack([a, b]), eo, cam) for a, b in zip(p1, p2))
    >>> data = ResectionData(("a", "b"), project(pts, eo, cam), 0.5, pts, None,
    ...                      ("1", "2", "3", "4"), lines, (0.5,) * 4, p1, p2, None)
    >>> res = resect(data, cam)
    >>> bool(np.allclose(res.eo, eo, atol=1e-6)), res.redundancy
    (True, 6)
    """
    if data.n_lines:
        # a straight object line is straight only in a perspective image: the line models
        # (coplanarity in the image plane, equivalent planes) hold for that projection only
        camera.require_perspective("the resection from straight lines (use control points)")

    opts = options if options is not None else ResectionOptions()
    n_unknown = 9 if opts.estimate_interior else 6
    m = _conditions_count(data, opts.model)
    # what fixes the pose: 2 per point and 2 per line, however many points a line has
    determined = 2 * data.n_points + 2 * data.n_lines
    if determined < n_unknown:
        raise InputError(
            f"{data.n_points} control point(s) and {data.n_lines} line(s) give {determined} "
            f"conditions for {n_unknown} unknowns"
            + (" (exterior and interior orientation)" if opts.estimate_interior else "")
            + ": measure more points or lines (a point gives 2 conditions, a line 2)"
        )
    _parallel_diagnosis(data)
    problem = _Problem(data, camera, opts)
    start_eo, start = _start_pose(problem, data, camera, eo0)
    stop_if_asked(should_stop, "starting the resection")
    blocks = list(problem.blocks)
    if opts.eo_prior_sigma is not None and eo0 is not None:
        blocks.append(
            prior_block("approximate orientation", np.arange(6), start_eo, opts.eo_prior_sigma)
        )
    aopts = AdjustmentOptions(
        max_iterations=opts.max_iterations,
        tolerance=RESECTION_TOLERANCE,
        damping=opts.damping,
        alpha=opts.alpha,
        snooping=opts.snooping,
        snooping_alpha=opts.snooping_alpha,
        max_rejections=max(0, (m - n_unknown) // 2),
    )
    adj = _adjust(problem, start_eo, blocks, aopts, opts, progress, should_stop)
    return _result(adj, problem, data, camera, opts, start, start_eo)


def _adjust(
    problem: _Problem,
    start_eo: Array,
    blocks: list,
    aopts: AdjustmentOptions,
    opts: ResectionOptions,
    progress: Callable[[float], None] | None,
    should_stop: Callable[[], bool] | None,
):
    """The resection's adjustment from ``start_eo``; a non-observable interior orientation
    named with what would determine it."""
    try:
        return adjust(
            problem.x0(start_eo),
            problem.names,
            blocks,
            options=aopts,
            progress=progress,
            should_stop=should_stop,
        )
    except NotObservableError as exc:
        if opts.estimate_interior and set(exc.parameters) & set(IO_NAMES):
            raise NotObservableError(
                f"{exc} -- the interior orientation cannot be refined from this image: it "
                "needs control at clearly different depths or an oblique view; resect with "
                "the interior orientation fixed",
                parameters=exc.parameters,
                null_vectors=exc.null_vectors,
                condition_number=exc.condition_number,
            ) from None
        raise


def _result(
    adj,
    problem: _Problem,
    data: ResectionData,
    camera: Camera,
    opts: ResectionOptions,
    start: str,
    start_eo: Array,
) -> SpaceResection:
    """The resection of a finished adjustment (ConvergenceError when it did not converge):
    the pose (angles wrapped to [-pi, pi)), its covariances, the residuals, the line
    distances and the global test."""
    from scipy import stats

    if not adj.converged:
        why = "; ".join(adj.warnings) or f"{adj.iterations} iterations"
        raise ConvergenceError(
            f"the resection did not converge ({why}) from the start pose "
            f"({start}); no orientation was computed"
        )
    x = adj.x
    eo = x[:6].copy()
    eo[3:] = (eo[3:] + np.pi) % (2 * np.pi) - np.pi
    cov = adj.covariance if adj.covariance is not None else np.full((len(x), len(x)), np.nan)
    cov_p = adj.covariance_prior if adj.covariance_prior is not None else cov
    corr = adj.correlation if adj.correlation is not None else np.full_like(cov, np.nan)
    point_v, point_w, point_rej, line_v, line_ab_v, line_w, line_rej = _residuals(
        problem, adj, data, opts.model
    )
    interior = interior_std = None
    if opts.estimate_interior:
        interior = x[6:9].copy()
        interior_std = adj.std[6:9].copy()
    cam_final = (
        camera.with_interior(np.concatenate([interior, camera.distortion.params]))
        if (interior is not None)
        else camera
    )
    dist = line_distances(data, eo, cam_final)
    r = adj.redundancy
    crit = float(stats.chi2.ppf(1 - opts.alpha, r)) if r > 0 else math.nan
    warnings = list(adj.warnings)
    if start != "given" and r == 0:
        warnings.append(_t("no redundancy: the orientation cannot be checked"))
    return SpaceResection(
        eo=eo,
        covariance=cov[:6, :6].copy(),
        covariance_prior=cov_p[:6, :6].copy(),
        correlation=corr[:6, :6].copy(),
        interior=interior,
        interior_std=interior_std,
        sigma0=float(adj.sigma0),
        redundancy=int(r),
        chi2=adj.global_test,
        chi2_critical=crit,
        point_v=point_v,
        point_w=point_w,
        point_rejected=point_rej,
        line_v=tuple(line_v),
        line_distance_px=dist,
        line_ab_v=line_ab_v,
        line_w=line_w,
        line_rejected=line_rej,
        start=start,
        start_eo=start_eo,
        model=opts.model,
        iterations=adj.iterations,
        adjustment=adj,
        warnings=tuple(warnings),
    )


def line_distances(data: ResectionData, eo: ArrayLike, camera: Camera) -> tuple[Array, ...]:
    """Signed distance (pixels) of every measured line point from its 3D line projected with
    ``eo`` (in the ideal image, lens correction removed).

    Returns
    -------
    tuple of ndarray, each (K_i,)
    """
    if not data.n_lines:
        return ()
    e = np.asarray(eo, dtype=np.float64).reshape(6)
    counts = np.array([len(v) for v in data.line_pixels])
    which = np.repeat(np.arange(data.n_lines), counts)
    p, _, _ = image_vectors(np.vstack(data.line_pixels), camera)
    a = camera_vectors(data.line_p1, e)[0][which]
    b = camera_vectors(data.line_p2, e)[0][which]
    d = coplanarity(p[:, None, :], a, b)[0][:, 0] / camera.pixel_size_mm
    return tuple(np.split(d, np.cumsum(counts)[:-1]))


# ============================================================================ control sets
