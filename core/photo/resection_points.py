"""Space resection from control points only (:func:`space_resection`): the light call for
start poses and matched points; :func:`core.photo.resection.resect` is the full resection
(points and lines, diagnosis). Object coordinates in a Cartesian frame (docs/conventions.md),
the pose ``(X0, Y0, Z0, omega, phi, kappa)`` in that frame (metres, radians)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..geometry.camera import Camera
from ..lsq.adjustment import adjust
from ..lsq.model import AdjustmentOptions
from ..lsq.results import AdjustmentResult
from .pose_start import initial_pose_pnp
from .resection_model import point_block

Array = NDArray[np.float64]

EO_NAMES = ("X0", "Y0", "Z0", "omega", "phi", "kappa")


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
    """Least-squares resection from control points only, with Baarda data snooping by default.

    The points-only case of :func:`resect`'s model (the same collinearity block,
    :func:`.resection_model.point_block`, errorless points), kept as the light call for
    code that orients many images from matched points: one start (OpenCV's solvePnP, or
    ``eo0``), the engine's :class:`~lidarphoto.core.lsq.model.AdjustmentOptions` as given,
    no observability diagnosis, a plain :class:`ResectionResult`. Use it for start poses
    (the bundle adjustment's image-by-image orientation) and for points from image matching
    (control chips). Use :func:`resect` for a user's resection: lines as well as points,
    point sigmas and covariances, the interior orientation, the start chosen among several
    candidates, the global test with the source's critical value and the diagnosis of what
    the observations cannot determine (the ``resection`` algorithm runs it).

    Parameters
    ----------
    pixels : (N, 2) measured (col, row) pixels.
    points : (N, 3) object coordinates, metres, Cartesian frame.
    camera : interior orientation (held fixed).
    eo0 : initial pose; solvePnP when None.
    sigma_px : a priori standard deviation of an image coordinate, pixels.
    options : the adjustment's options; data snooping with the engine's defaults when None.
    labels : the points' names in the residual table (their indices when None).
    """
    px = np.asarray(pixels, dtype=np.float64)
    pts = np.asarray(points, dtype=np.float64)
    if px.ndim != 2 or px.shape[1] != 2 or pts.shape != (px.shape[0], 3):
        raise InputError(f"need (N, 2) pixels and (N, 3) points, got {px.shape} and {pts.shape}")
    if px.shape[0] < 4:
        raise InputError(f"a resection needs at least 4 points, got {px.shape[0]}")
    x0 = initial_pose_pnp(px, pts, camera) if eo0 is None else np.asarray(eo0, dtype=float)
    n = px.shape[0]
    block = point_block(
        "image points",
        camera,
        px,
        np.full(n, float(sigma_px)),
        pts,
        None,
        np.tile(np.arange(6), (n, 1)),
        labels if labels is not None else [str(i) for i in range(n)],
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
