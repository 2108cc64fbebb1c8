"""Space resection: the exterior orientation of one image from image points with known
object coordinates, by least squares on the collinearity equations.

Object points must be in a Cartesian frame (the local ENU adjustment frame, see
docs/conventions.md); the pose comes back in that frame as ``(X0, Y0, Z0, omega, phi,
kappa)``. The initial pose, when not given, comes from OpenCV's solvePnP.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..geometry.camera import Camera
from ..geometry.collinearity import collinearity_jacobians
from ..geometry.rotations import matrix_to_opk
from ..lsq.adjustment import adjust
from ..lsq.model import AdjustmentOptions, GaussMarkovBlock
from ..lsq.results import AdjustmentResult

Array = NDArray[np.float64]

EO_NAMES = ("X0", "Y0", "Z0", "omega", "phi", "kappa")
# OpenCV's camera looks along +z with y down; ours looks along -z with y up.
_CV_FLIP = np.diag([1.0, -1.0, -1.0])


@dataclass(frozen=True)
class ResectionResult:
    """Estimated pose (6,), its covariance (6, 6) and the per-point residuals (N, 2) in pixels.

    ``rms_px`` is the root mean square of the residuals of the points kept (col, row);
    ``rejected`` indexes the points removed by data snooping.
    """

    eo: Array
    covariance: Array
    residuals_px: Array
    rms_px: Array
    rejected: NDArray[np.int64]
    adjustment: AdjustmentResult

    @property
    def std(self) -> Array:
        return np.sqrt(np.diag(self.covariance))


def initial_pose_pnp(pixels: ArrayLike, points: ArrayLike, camera: Camera) -> Array:
    """Pose from OpenCV's solvePnP (SQPnP, then its iterative refinement); lens removed first.

    Returns ``(X0, Y0, Z0, omega, phi, kappa)`` in the frame of ``points``.
    """
    px = np.asarray(pixels, dtype=np.float64)
    pts = np.asarray(points, dtype=np.float64)
    ideal = camera.ideal_from_pixel(px)  # centred, corrected, mm
    ps = camera.pixel_size_mm
    # OpenCV puts the centre of the first pixel at (0, 0), we put it at (0.5, 0.5).
    cx = camera.width_px / 2 + camera.x0_mm / ps - 0.5
    cy = camera.height_px / 2 - camera.y0_mm / ps - 0.5
    cv_px = np.column_stack([cx + ideal[:, 0] / ps, cy - ideal[:, 1] / ps])
    k = np.array([[camera.focal_px, 0.0, cx], [0.0, camera.focal_px, cy], [0.0, 0.0, 1.0]])
    centre = pts.mean(axis=0)  # keeps OpenCV's float arithmetic away from large coordinates
    obj = np.ascontiguousarray(pts - centre)
    img = np.ascontiguousarray(cv_px)
    ok, rvec, tvec = cv2.solvePnP(obj, img, k, None, flags=cv2.SOLVEPNP_SQPNP)
    if not ok:
        raise InputError("OpenCV could not find an initial pose for the resection")
    ok, rvec, tvec = cv2.solvePnP(obj, img, k, None, rvec, tvec, True, cv2.SOLVEPNP_ITERATIVE)
    r_cv = cv2.Rodrigues(rvec)[0]
    m = _CV_FLIP @ r_cv
    x0 = -r_cv.T @ tvec.ravel() + centre
    omega, phi, kappa = matrix_to_opk(m)
    return np.array([*x0, omega, phi, kappa])


def space_resection(
    pixels: ArrayLike,
    points: ArrayLike,
    camera: Camera,
    eo0: ArrayLike | None = None,
    sigma_px: float = 1.0,
    options: AdjustmentOptions | None = None,
    labels: list[str] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> ResectionResult:
    """Least-squares resection with Baarda data snooping by default.

    Parameters
    ----------
    pixels : (N, 2) measured (col, row) pixels.
    points : (N, 3) object coordinates, metres, Cartesian frame.
    camera : interior orientation (held fixed).
    eo0 : initial pose; solvePnP when None.
    sigma_px : a priori standard deviation of an image coordinate, pixels.
    """
    px = np.asarray(pixels, dtype=np.float64)
    pts = np.asarray(points, dtype=np.float64)
    if px.ndim != 2 or px.shape[1] != 2 or pts.shape != (px.shape[0], 3):
        raise InputError(f"need (N, 2) pixels and (N, 3) points, got {px.shape} and {pts.shape}")
    if px.shape[0] < 4:
        raise InputError(f"a resection needs at least 4 points, got {px.shape[0]}")
    x0 = initial_pose_pnp(px, pts, camera) if eo0 is None else np.asarray(eo0, dtype=float)
    n = px.shape[0]

    def model(x_local: Array) -> tuple[Array, Array]:
        out = collinearity_jacobians(pts, x_local, camera, wrt=("eo",))
        return out["pixels"], out["eo"]

    block = GaussMarkovBlock(
        name="image points",
        observed=px,
        sigma=np.full((n, 2), float(sigma_px)),
        param_index=np.tile(np.arange(6), (n, 1)),
        model=model,
        labels=labels if labels is not None else [str(i) for i in range(n)],
        row_names=("col", "row"),
    )
    opts = options if options is not None else AdjustmentOptions(snooping=True)
    result = adjust(x0, list(EO_NAMES), [block], options=opts, should_stop=should_stop)
    table = result.residuals["image points"]
    kept = ~table.rejected
    rms = np.sqrt(np.mean(table.v[kept] ** 2, axis=0))
    return ResectionResult(
        eo=result.x.copy(),
        covariance=result.covariance,
        residuals_px=table.v,
        rms_px=rms,
        rejected=np.flatnonzero(table.rejected),
        adjustment=result,
    )
