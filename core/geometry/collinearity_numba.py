"""The perspective collinearity equations and their Jacobians compiled with numba.

:func:`core.geometry.collinearity.collinearity_jacobians` evaluates a bundle's rays in numpy
as batched small products (rotation per ray, ``d ideal / d q``, ``S G``, the angle
derivatives), each a temporary of the whole batch. The two kernels here do the geometric
part in one pass over the rays, reading the image's rotation and its derivatives in place:
:func:`perspective_ideal` the ideal image coordinates, :func:`perspective_jacobians` the
pixel Jacobians with respect to the exterior orientation and the object point, given the
lens part ``S G`` (d pixel / d ideal) that the caller takes from the camera's lens model in
numpy. The results equal the numpy path's to rounding (other order of additions).

Frames and units as in :mod:`.collinearity`: ``q = M (X - X0)`` in the camera frame (m),
ideal coordinates ``x_i = -f u / w``, ``y_i = -f v / w`` (mm), a point is imaged iff
``w < 0``. numba is optional: both functions return None without it.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]
Index = NDArray[np.intp]

__all__ = ["perspective_ideal", "perspective_jacobians"]


def _ideal_kernel(points, eo, rot, img, f, ideal, valid):  # pragma: no cover - compiled
    for n in range(points.shape[0]):
        i = img[n]
        d0 = points[n, 0] - eo[i, 0]
        d1 = points[n, 1] - eo[i, 1]
        d2 = points[n, 2] - eo[i, 2]
        u = rot[i, 0, 0] * d0 + rot[i, 0, 1] * d1 + rot[i, 0, 2] * d2
        v = rot[i, 1, 0] * d0 + rot[i, 1, 1] * d1 + rot[i, 1, 2] * d2
        w = rot[i, 2, 0] * d0 + rot[i, 2, 1] * d1 + rot[i, 2, 2] * d2
        if w < 0.0:
            valid[n] = True
            ideal[n, 0] = -f * u / w
            ideal[n, 1] = -f * v / w
        else:
            valid[n] = False
            ideal[n, 0] = np.nan
            ideal[n, 1] = np.nan


def _jac_kernel(points, eo, rot, drot, img, f, sg, per_ray, ok, jac):  # pragma: no cover
    a = np.empty((2, 3))  # d ideal / d q
    b = np.empty((2, 3))  # d pixel / d q = S G a
    dq = np.empty((3, 3))  # d q / d angles
    d = np.empty(3)
    for n in range(points.shape[0]):
        if not ok[n]:
            for r in range(2):
                for c in range(9):
                    jac[n, r, c] = np.nan
            continue
        i = img[n]
        for k in range(3):
            d[k] = points[n, k] - eo[i, k]
        u = rot[i, 0, 0] * d[0] + rot[i, 0, 1] * d[1] + rot[i, 0, 2] * d[2]
        v = rot[i, 1, 0] * d[0] + rot[i, 1, 1] * d[1] + rot[i, 1, 2] * d[2]
        w = rot[i, 2, 0] * d[0] + rot[i, 2, 1] * d[1] + rot[i, 2, 2] * d[2]
        a[0, 0] = -f / w
        a[0, 1] = 0.0
        a[0, 2] = f * u / (w * w)
        a[1, 0] = 0.0
        a[1, 1] = -f / w
        a[1, 2] = f * v / (w * w)
        s = n if per_ray else 0
        for r in range(2):
            for c in range(3):
                b[r, c] = sg[s, r, 0] * a[0, c] + sg[s, r, 1] * a[1, c]
        for k in range(3):  # angle k: dq[:, k] = dM_k d
            for r in range(3):
                dk = drot[i, k, r]
                dq[r, k] = dk[0] * d[0] + dk[1] * d[1] + dk[2] * d[2]
        for r in range(2):
            for c in range(3):
                p = b[r, 0] * rot[i, 0, c] + b[r, 1] * rot[i, 1, c] + b[r, 2] * rot[i, 2, c]
                jac[n, r, c] = -p
                jac[n, r, 6 + c] = p
                jac[n, r, 3 + c] = b[r, 0] * dq[0, c] + b[r, 1] * dq[1, c] + b[r, 2] * dq[2, c]


def perspective_ideal(
    points: Array, eo_img: Array, rot: Array, image_index: Index, focal_mm: float
) -> tuple[Array, NDArray[np.bool_]] | None:
    """Ideal centred image coordinates (N, 2) mm of object points (N, 3) m seen by images
    ``image_index`` (N,) with EOs ``eo_img`` (M, 6) and rotations ``rot`` (M, 3, 3) (object
    -> camera), and the mask of the points in front (w < 0; NaN rows elsewhere); None
    without numba."""
    from ..compiled import compiled_kernel  # numba imported here: this module stays light

    kernel = compiled_kernel(_ideal_kernel)
    if kernel is None:
        return None
    n = points.shape[0]
    ideal = np.empty((n, 2))
    valid = np.empty(n, dtype=np.bool_)
    kernel(
        np.ascontiguousarray(points, dtype=np.float64),
        np.ascontiguousarray(eo_img, dtype=np.float64),
        np.ascontiguousarray(rot, dtype=np.float64),
        np.ascontiguousarray(image_index, dtype=np.intp),
        float(focal_mm),
        ideal,
        valid,
    )
    return ideal, valid


def perspective_jacobians(
    points: Array,
    eo_img: Array,
    rot: Array,
    drot: Array,
    image_index: Index,
    focal_mm: float,
    sg: Array,
    ok: NDArray[np.bool_],
    out: Array | None = None,
) -> Array | None:
    """d pixel / d (X0, Y0, Z0, omega, phi, kappa, X, Y, Z), (N, 2, 9) px/m and px/rad.

    ``drot`` (M, 3, 3, 3): d M / d (omega, phi, kappa) per image
    (:func:`core.geometry.rotations.opk_derivatives`); ``sg`` d pixel / d ideal (px/mm),
    (N, 2, 2) per ray or (1, 2, 2) for all (a camera without lens distortion); rows where
    ``ok`` is False are NaN. ``out`` (N, 2, K >= 9): written in its first 9 columns and
    returned (else a new array). None without numba.
    """
    from ..compiled import compiled_kernel  # numba imported here: this module stays light

    kernel = compiled_kernel(_jac_kernel)
    if kernel is None:
        return None
    n = points.shape[0]
    sg = np.ascontiguousarray(sg, dtype=np.float64).reshape(-1, 2, 2)
    if sg.shape[0] not in (1, n):
        raise ValueError(f"sg must have 1 or {n} rows, got {sg.shape[0]}")
    jac = np.empty((n, 2, 9)) if out is None else out
    if jac.shape[0] != n or jac.shape[1] != 2 or jac.shape[2] < 9 or jac.dtype != np.float64:
        raise ValueError(f"out must be a float64 array of shape ({n}, 2, >= 9), got {jac.shape}")
    kernel(
        np.ascontiguousarray(points, dtype=np.float64),
        np.ascontiguousarray(eo_img, dtype=np.float64),
        np.ascontiguousarray(rot, dtype=np.float64),
        np.ascontiguousarray(drot, dtype=np.float64),
        np.ascontiguousarray(image_index, dtype=np.intp),
        float(focal_mm),
        sg,
        sg.shape[0] > 1,
        np.ascontiguousarray(ok, dtype=np.bool_),
        jac,
    )
    return jac
