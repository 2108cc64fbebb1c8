"""Collinearity: projection of object points, back-projection of pixels, analytic Jacobians.

Conventions
-----------
- **Exterior orientation** (EO) of an image, always in this order:
  ``(X0, Y0, Z0, omega, phi, kappa)``: the perspective centre in object space (metres, a
  Cartesian frame such as the local ENU adjustment frame) and the omega-phi-kappa angles
  (radians). ``M = R3(kappa) R2(phi) R1(omega)`` (:func:`core.geometry.rotations.opk_to_matrix`)
  rotates object-space vectors into the camera frame.
- **Camera frame**: x right, y up, z towards the viewer; the camera looks along -z. With
  ``(u, v, w) = M (X - X0, Y - Y0, Z - Z0)`` a point is in front of the camera iff ``w < 0``.
- **Collinearity** (ideal, centred image coordinates, mm)::

      x_i = -f u / w,   y_i = -f v / w

  for a perspective camera; a fisheye camera maps the angle off the axis instead
  (:mod:`core.geometry.projection`), and "in front" then means inside its field of view

  the measured image coordinates are ``x0 + distort(x_i, y_i)`` (the inverse of the lens
  correction of :mod:`core.geometry.distortion`) and the pixel position is
  ``col = x / pixel_size + W/2``, ``row = H/2 - y / pixel_size`` (pixels as in
  :mod:`core.geometry.camera`: origin at the top-left corner of the top-left pixel, rows down).

Every function is vectorised over N points (rows). ``eo`` is (6,) for one image shared by
all points, or (N, 6) for one EO per point.
"""

from __future__ import annotations

from typing import Any, Dict, Sequence, Tuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .camera import DEFAULT_TOL_PX, Camera
from .distortion import DEFAULT_MAX_ITER, NoDistortion, as_points, inv2x2
from .projection import ideal_from_camera
from .rotations import opk_derivatives, opk_to_matrix

Array = NDArray[np.float64]

#: Names of the exterior-orientation parameters, in the order of ``eo`` and of the Jacobians.
EO_NAMES: Tuple[str, ...] = ("X0", "Y0", "Z0", "omega", "phi", "kappa")

__all__ = [
    "EO_NAMES",
    "collinearity_jacobians",
    "image_rays",
    "project",
    "project_with_status",
]


def _eo_rows(eo: ArrayLike, n: int) -> Array:
    """``eo`` as (n, 6): a single (6,) or (1, 6) EO is repeated for every point."""
    e = np.asarray(eo, dtype=np.float64)
    if e.ndim == 1:
        e = e[np.newaxis, :]
    if e.ndim != 2 or e.shape[1] != 6 or e.shape[0] not in (1, n):
        raise ValueError(f"eo must have shape (6,) or ({n}, 6), got {np.shape(eo)}")
    return np.ascontiguousarray(np.broadcast_to(e, (n, 6)))


def _to_camera_frame(points: ArrayLike, eo: ArrayLike) -> Tuple[Array, Array, Array, Array]:
    """Object points (N, 3) -> (eo (N, 6), dX (N, 3), M (N, 3, 3), q = M dX (N, 3))."""
    p = as_points(points, 3, "points")
    e = _eo_rows(eo, p.shape[0])
    d = p - e[:, :3]
    m = opk_to_matrix(e[:, 3], e[:, 4], e[:, 5])
    q = np.einsum("nij,nj->ni", m, d)
    return e, d, m, q


def _ideal(q: Array, camera: Camera) -> Tuple[Array, NDArray[np.bool_]]:
    """Ideal centred image coordinates (N, 2) mm from camera-frame vectors, and the mask of
    the vectors the camera's projection images (w < 0 for a perspective camera)."""
    ideal, valid = ideal_from_camera(q, camera.focal_mm, camera.projection)
    return ideal, valid


def project_with_status(
    points: ArrayLike,
    eo: ArrayLike,
    camera: Camera,
    *,
    tol_px: float = DEFAULT_TOL_PX,
    max_iter: int = DEFAULT_MAX_ITER,
) -> Tuple[Array, NDArray[np.bool_], NDArray[np.bool_]]:
    """Project object points to measured pixel positions, with validity masks.

    Parameters
    ----------
    points : (N, 3) array_like
        Object points, metres, in the frame of the EO.
    eo : (6,) or (N, 6) array_like
        ``(X0, Y0, Z0, omega, phi, kappa)``, metres and radians.
    camera : Camera
        Interior orientation; its lens model is applied (ideal -> measured).
    tol_px, max_iter
        Tolerance (pixels) and iteration limit of the lens inversion.

    Returns
    -------
    pixels : (N, 2) ndarray
        Measured pixel positions (col, row); NaN where ``in_front & converged`` is False.
    in_front : (N,) ndarray of bool
        True where the point is in front of the camera (``w < 0`` in the camera frame).
    converged : (N,) ndarray of bool
        True where the lens inversion succeeded; False where it failed or was not attempted
        (points not in front). Whether a pixel falls inside the frame is not checked here:
        see :meth:`core.geometry.camera.Camera.in_frame`.
    """
    _, _, _, q = _to_camera_frame(points, eo)
    ideal, in_front = _ideal(q, camera)
    pixels, converged = camera.pixel_from_ideal_with_status(ideal, tol_px=tol_px, max_iter=max_iter)
    return pixels, in_front, converged


def project(points: ArrayLike, eo: ArrayLike, camera: Camera) -> Array:
    """Project object points (N, 3) to measured pixel positions (N, 2).

    Rows are NaN for points that are not in front of the camera (``w >= 0``) or where the
    lens inversion failed; :func:`project_with_status` returns the masks.

    Examples
    --------
    >>> cam = Camera("c", focal_mm=100.0, pixel_size_mm=0.01, width_px=1000, height_px=800)
    >>> project([[10.0, 0.0, 0.0]], [0.0, 0.0, 1000.0, 0.0, 0.0, 0.0], cam).tolist()
    [[600.0, 400.0]]
    """
    return project_with_status(points, eo, camera)[0]


def image_rays(
    pixels: ArrayLike, eo: ArrayLike, camera: Camera, image_index: ArrayLike | None = None
) -> Tuple[Array, Array]:
    """Back-project measured pixel positions to rays in object space.

    Parameters
    ----------
    pixels : (N, 2) array_like
        Measured pixel positions (col, row).
    eo : (6,) or (N, 6) array_like
        ``(X0, Y0, Z0, omega, phi, kappa)``, metres and radians.
    camera : Camera
        Interior orientation; its lens correction is removed (measured -> ideal).
    image_index : (N,) array_like of int, optional
        With it, ``eo`` is (M, 6), one row per image, and pixel ``n`` lies in image
        ``image_index[n]``: the rotations are computed once per image.

    Returns
    -------
    origins : (N, 3) ndarray
        Perspective centres, metres.
    directions : (N, 3) ndarray
        Unit vectors in object space from the perspective centre towards the imaged point:
        ``M.T (x_i, y_i, -f)`` normalised.
    """
    ideal = camera.ideal_from_pixel(pixels)
    if image_index is None:
        e = _eo_rows(eo, ideal.shape[0])
        m = opk_to_matrix(e[:, 3], e[:, 4], e[:, 5])
    else:
        idx = np.asarray(image_index, dtype=np.intp)
        eo_img = np.asarray(eo, dtype=np.float64).reshape(-1, 6)
        e = eo_img[idx]
        m = opk_to_matrix(eo_img[:, 3], eo_img[:, 4], eo_img[:, 5])[idx]
    ray_c = camera.ray_from_ideal(ideal)
    # M rotates object -> camera, so its transpose takes the camera-frame ray to object space.
    d = np.einsum("nji,nj->ni", m, ray_c)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return e[:, :3].copy(), d


def collinearity_jacobians(
    points: ArrayLike,
    eo: ArrayLike,
    camera: Camera,
    wrt: Sequence[str] = ("eo", "point", "interior"),
    *,
    tol_px: float = DEFAULT_TOL_PX,
    max_iter: int = DEFAULT_MAX_ITER,
    image_index: ArrayLike | None = None,
    compiled: bool = True,
    out: Array | None = None,
) -> Dict[str, Any]:
    """Predicted measured pixels and their analytic Jacobians.

    Parameters
    ----------
    points : (N, 3) array_like
        Object points, metres.
    eo : (6,) or (N, 6) array_like
        ``(X0, Y0, Z0, omega, phi, kappa)``, metres and radians.
    camera : Camera
        Interior orientation.
    wrt : sequence of {"eo", "point", "interior"}
        Which Jacobians to compute.
    tol_px, max_iter
        Tolerance (pixels) and iteration limit of the lens inversion.
    image_index : (N,) array_like of int, optional
        With it, ``eo`` is (M, 6), one row per image, and point ``n`` is seen by image
        ``image_index[n]``: the rotations and their derivatives are computed once per image
        (a bundle adjustment has far fewer images than measurements).
    compiled : bool
        With ``image_index``, a perspective camera and numba, the geometry (camera-frame
        vectors, ideal coordinates, the EO and point Jacobians) is evaluated by the compiled
        kernels of :mod:`.collinearity_numba` in one pass over the rays, the lens model in
        numpy as here; equal to this numpy path to rounding. False: the numpy path (the
        reference; fisheye projections always take it).
    out : (N, 2, K) ndarray, K >= 9, optional
        Receives the EO Jacobian in its columns 0-5 and the point Jacobian in 6-8 (both
        computed, whatever ``wrt``); the returned ``"eo"`` and ``"point"`` are then views of
        it (a bundle's model writes its Jacobian in place, no copy of the batch).

    Returns
    -------
    dict
        ``"pixels"`` (N, 2) predicted measured (col, row); ``"in_front"``, ``"converged"``
        (N,) bool as in :func:`project_with_status`; and for each requested Jacobian, of
        the pixel coordinates (col, row):

        - ``"eo"`` (N, 2, 6): w.r.t. ``(X0, Y0, Z0, omega, phi, kappa)``, px/m and px/rad;
        - ``"point"`` (N, 2, 3): w.r.t. the object point ``(X, Y, Z)``, px/m;
        - ``"interior"`` (N, 2, 3 + P): w.r.t. :attr:`Camera.interior_params`
          ``(focal_mm, x0_mm, y0_mm, lens coefficients...)``, px per unit; the names are
          in ``"interior_names"``.

        Rows of invalid points are NaN.

    Notes
    -----
    With ``i`` the ideal and ``m`` the measured centred coordinates, ``m = D^-1(i)`` where
    ``D(m) = m + d(m)``. By the implicit-function theorem ``dm/di = G = (I + dd/dm)^-1``
    and ``dm/dtheta = -G dd/dtheta`` for a lens coefficient theta, both at ``m``. The pixel
    is ``S (x0 + m) + c`` with ``S = diag(1/ps, -1/ps)`` (rows grow downwards).
    """
    wanted = tuple(wrt)
    unknown = sorted(set(wanted) - {"eo", "point", "interior"})
    if unknown:
        raise ValueError(f"wrt: unknown Jacobian(s) {unknown}; use 'eo', 'point', 'interior'")

    if image_index is not None and compiled and camera.projection == "perspective":
        fast = _compiled_jacobians(points, eo, image_index, camera, wanted, tol_px, max_iter, out)
        if fast is not None:
            return fast
    if out is not None:
        wanted = tuple(dict.fromkeys((*wanted, "eo", "point")))
    if image_index is None:
        e, d, rot, q = _to_camera_frame(points, eo)
        per_image = None
    else:
        p = as_points(points, 3, "points")
        per_image = np.asarray(image_index, dtype=np.intp)
        eo_img = np.asarray(eo, dtype=np.float64).reshape(-1, 6)
        e = eo_img[per_image]
        d = p - e[:, :3]
        rot = opk_to_matrix(eo_img[:, 3], eo_img[:, 4], eo_img[:, 5])[per_image]
        q = np.einsum("nij,nj->ni", rot, d)
    f = camera.focal_mm
    ps = camera.pixel_size_mm
    if "eo" in wanted or "point" in wanted:
        ideal, in_front, a = ideal_from_camera(q, f, camera.projection, jacobian=True)
    else:
        ideal, in_front = _ideal(q, camera)
    measured, converged = camera.measured_from_ideal(ideal, tol_px=tol_px, max_iter=max_iter)
    pixels = camera.image_to_pixel(measured + np.array([camera.x0_mm, camera.y0_mm]))
    res: Dict[str, Any] = {"pixels": pixels, "in_front": in_front, "converged": converged}

    # S G: d pixel / d ideal, (N, 2, 2); the lens Jacobian is taken at the measured point.
    sg = inv2x2(np.eye(2) + camera.distortion.jacobian_xy(measured))
    sg[:, 0, :] /= ps
    sg[:, 1, :] /= -ps

    if "eo" in wanted or "point" in wanted:
        dpx_dq = sg @ a
        dpx_dpoint = dpx_dq @ rot
        if "point" in wanted:
            res["point"] = dpx_dpoint
        if "eo" in wanted:
            if per_image is None:
                dm = opk_derivatives(e[:, 3], e[:, 4], e[:, 5])  # (N, 3 angles, 3, 3)
                dq_dangles = np.einsum("nkij,nj->nik", dm, d)
            else:
                # one angle at a time: the (N, 3, 3, 3) gather would dominate the memory
                dm_img = opk_derivatives(eo_img[:, 3], eo_img[:, 4], eo_img[:, 5])
                dq_dangles = np.empty((d.shape[0], 3, 3))
                for k in range(3):
                    dq_dangles[:, :, k] = np.einsum("nij,nj->ni", dm_img[per_image, k], d)
            res["eo"] = np.concatenate([-dpx_dpoint, dpx_dq @ dq_dangles], axis=2)

    if "interior" in wanted:
        res["interior"] = _interior_jacobian(camera, sg, ideal, measured)
        res["interior_names"] = camera.interior_names

    valid = in_front & converged
    for key in ("eo", "point", "interior"):
        if key in res:
            res[key][~valid] = np.nan
    if out is not None:
        out[:, :, :6] = res["eo"]
        out[:, :, 6:9] = res["point"]
        res["eo"], res["point"] = out[:, :, :6], out[:, :, 6:9]
    return res


def _interior_jacobian(camera: Camera, sg: Array, ideal: Array, measured: Array) -> Array:
    """d pixel / d :attr:`Camera.interior_params` (N, 2, 3 + P) from ``S G`` (N, 2, 2)
    px/mm, the ideal and the measured centred coordinates (N, 2) mm."""
    n = ideal.shape[0]
    f = camera.focal_mm
    ps = camera.pixel_size_mm
    n_ap = camera.distortion.n_params
    jac = np.empty((n, 2, 3 + n_ap))
    # every projection's ideal point (r = f g(theta)) is linear in f, so di/df = i / f.
    jac[:, :, 0] = np.einsum("nij,nj->ni", sg, ideal / f)
    jac[:, 0, 1], jac[:, 1, 1] = 1.0 / ps, 0.0
    jac[:, 0, 2], jac[:, 1, 2] = 0.0, -1.0 / ps
    if n_ap:
        jac[:, :, 3:] = -sg @ camera.distortion.jacobian_params(measured)
    return jac


def _compiled_jacobians(
    points: ArrayLike,
    eo: ArrayLike,
    image_index: ArrayLike,
    camera: Camera,
    wanted: Tuple[str, ...],
    tol_px: float,
    max_iter: int,
    into: Array | None = None,
) -> Dict[str, Any] | None:
    """:func:`collinearity_jacobians` of a perspective camera with ``image_index``: the
    geometry compiled (:mod:`.collinearity_numba`), the lens model in numpy; None without
    numba."""
    from .collinearity_numba import perspective_ideal, perspective_jacobians

    p = as_points(points, 3, "points")
    per_image = np.asarray(image_index, dtype=np.intp)
    eo_img = np.asarray(eo, dtype=np.float64).reshape(-1, 6)
    rot = opk_to_matrix(eo_img[:, 3], eo_img[:, 4], eo_img[:, 5])
    f = camera.focal_mm
    ps = camera.pixel_size_mm
    got = perspective_ideal(p, eo_img, rot, per_image, f)
    if got is None:
        return None
    ideal, in_front = got
    measured, converged = camera.measured_from_ideal(ideal, tol_px=tol_px, max_iter=max_iter)
    pixels = camera.image_to_pixel(measured + np.array([camera.x0_mm, camera.y0_mm]))
    out: Dict[str, Any] = {"pixels": pixels, "in_front": in_front, "converged": converged}
    n = pixels.shape[0]
    if isinstance(camera.distortion, NoDistortion):
        # G = I: S alone, one (1, 2, 2) for every ray (as the numpy path's rows, exactly)
        sg = np.array([[[1.0 / ps, 0.0], [0.0, 1.0 / -ps]]])
    else:
        sg = inv2x2(np.eye(2) + camera.distortion.jacobian_xy(measured))
        sg[:, 0, :] /= ps
        sg[:, 1, :] /= -ps
    valid = in_front & converged
    if "eo" in wanted or "point" in wanted or into is not None:
        drot = opk_derivatives(eo_img[:, 3], eo_img[:, 4], eo_img[:, 5])
        jac = perspective_jacobians(p, eo_img, rot, drot, per_image, f, sg, valid, into)
        if jac is None:
            return None
        if "eo" in wanted or into is not None:
            out["eo"] = jac[:, :, :6]
        if "point" in wanted or into is not None:
            out["point"] = jac[:, :, 6:9]
    if "interior" in wanted:
        full = np.broadcast_to(sg, (n, 2, 2))
        out["interior"] = _interior_jacobian(camera, full, ideal, measured)
        out["interior"][~valid] = np.nan
        out["interior_names"] = camera.interior_names
    return out
