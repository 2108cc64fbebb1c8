"""Observation models of boresight calibration, with analytic Jacobians (see
core/photo/boresight.py).

Every function is batched over ``G`` measurements (rows) and works in the local ENU adjustment
frame. Each measurement depends on a *pose vector* ``xp`` of its image (shape (G, P)):

    columns 0:3   boresight (d_omega, d_phi, d_kappa) of the image's group, radians
    columns 3:6   INS position (E, N, U) in the adjustment frame, metres
    columns 6:9   INS attitude (roll, pitch, heading), radians (NED at the image's position)
    columns 9:12  lever arm (x, y, z) in the body frame, metres          (only when estimated)
    last 3        focal length, principal point x0, y0, millimetres      (only when estimated)

Chain (docs/conventions.md)::

    R_b^l = R_n^l R_b^n(roll, pitch, heading),   R_b^n = Rz(h) Ry(p) Rx(r)
    X_pc  = X_ins + R_b^l a_b
    R_c^l = R_b^l R_nominal dR(bore),            dR = Rx(dw) Ry(dp) Rz(dk)

``R_n^l`` (NED at the image's own position -> the ENU frame) is a constant per image: a
position error of a metre turns it by 1.6e-7 rad, far below anything estimated here.
Derivatives of the rotations use the generators: ``d Rx(a)/da = Rx(a) [e_x]x`` and so on.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..geometry.camera import Camera
from ..geometry.collinearity import collinearity_jacobians
from ..geometry.projection import radius_derivative, theta_from_radius
from ..geometry.rotations import matrix_to_opk, rx, ry, rz, skew

Array = NDArray[np.float64]

_KX, _KY, _KZ = skew(np.eye(3))


@dataclass(frozen=True)
class PoseSpec:
    """What the pose vector contains and the constants of the chain.

    Attributes
    ----------
    camera : Camera
        Interior orientation (its f, x0, y0 are replaced by the pose vector when estimated).
    nominal : ndarray, shape (3, 3)
        ``R_nominal`` (camera -> body).
    lever_arm : ndarray, shape (3,)
        Lever arm used when it is not estimated, metres (body frame).
    estimate_lever_arm, estimate_interior : bool
    """

    camera: Camera
    nominal: Array
    lever_arm: Array
    estimate_lever_arm: bool = False
    estimate_interior: bool = False

    @property
    def size(self) -> int:
        """Length P of the pose vector."""
        return 9 + 3 * self.estimate_lever_arm + 3 * self.estimate_interior

    def camera_at(self, xp: Array) -> Camera:
        """The camera with the interior orientation of the pose vector (shared by all rows)."""
        if not self.estimate_interior or xp.shape[0] == 0:
            return self.camera
        p = self.camera.interior_params.copy()
        p[:3] = xp[0, -3:]
        return self.camera.with_interior(p)


def pose_chain(xp: Array, r_nl: Array, spec: PoseSpec) -> tuple[Array, Array, Array, Array]:
    """Perspective centre and camera rotation with their derivatives.

    Parameters
    ----------
    xp : ndarray, shape (G, P)
        Pose vectors (module docstring).
    r_nl : ndarray, shape (G, 3, 3)
        ``R_n^l`` of each row's image.
    spec : PoseSpec

    Returns
    -------
    centre : ndarray, shape (G, 3)
        ``X_pc`` in the adjustment frame, metres.
    r_cl : ndarray, shape (G, 3, 3)
        ``R_c^l`` (camera -> adjustment frame; ``M = r_cl.T``).
    d_centre : ndarray, shape (G, 3, P)
        ``d X_pc / d xp``.
    d_rot : ndarray, shape (G, P, 3, 3)
        ``d R_c^l / d xp_k`` (zero for the non-angular columns).
    """
    g, p = xp.shape
    bore, pos, rph = xp[:, 0:3], xp[:, 3:6], xp[:, 6:9]
    lever = xp[:, 9:12] if spec.estimate_lever_arm else np.broadcast_to(spec.lever_arm, (g, 3))
    rr, rp, rh = rx(rph[:, 0]), ry(rph[:, 1]), rz(rph[:, 2])
    r_bn = rh @ rp @ rr
    r_bl = r_nl @ r_bn
    bx, by, bz = rx(bore[:, 0]), ry(bore[:, 1]), rz(bore[:, 2])
    d_r = bx @ by @ bz
    t = spec.nominal @ d_r  # R_c^b
    r_cl = r_bl @ t
    centre = pos + np.einsum("gij,gj->gi", r_bl, lever)
    d_rot = np.zeros((g, p, 3, 3))
    d_centre = np.zeros((g, 3, p))
    left = r_bl @ spec.nominal
    d_rot[:, 0] = left @ (_KX @ d_r)
    d_rot[:, 1] = left @ (bx @ _KY @ by @ bz)
    d_rot[:, 2] = left @ (d_r @ _KZ)
    for j, d_bn in enumerate((r_bn @ _KX, rh @ rp @ _KY @ rr, _KZ @ r_bn)):
        d_bl = r_nl @ d_bn
        d_rot[:, 6 + j] = d_bl @ t
        d_centre[:, :, 6 + j] = np.einsum("gij,gj->gi", d_bl, lever)
    d_centre[:, :, 3:6] = np.eye(3)
    if spec.estimate_lever_arm:
        d_centre[:, :, 9:12] = r_bl
    return centre, r_cl, d_centre, d_rot


def eo_rows(centre: Array, r_cl: Array) -> Array:
    """(G, 6) exterior orientations ``(X0, Y0, Z0, omega, phi, kappa)`` in the adjustment frame."""
    omega, phi, kappa = matrix_to_opk(np.swapaxes(r_cl, -1, -2))
    return np.column_stack([centre, omega, phi, kappa])


def collinearity(
    xp: Array, points: Array, r_nl: Array, spec: PoseSpec
) -> tuple[Array, Array, Array]:
    """Predicted pixels of object points and their Jacobians.

    Parameters
    ----------
    xp : ndarray, shape (G, P)
    points : ndarray, shape (G, 3)
        Object points in the adjustment frame, metres.
    r_nl : ndarray, shape (G, 3, 3)
    spec : PoseSpec

    Returns
    -------
    pixels : ndarray, shape (G, 2)
        (col, row), pixels.
    j_pose : ndarray, shape (G, 2, P)
        d pixel / d xp.
    j_point : ndarray, shape (G, 2, 3)
        d pixel / d point, px/m.
    """
    centre, r_cl, d_centre, d_rot = pose_chain(xp, r_nl, spec)
    cam = spec.camera_at(xp)
    wrt = ("point", "interior") if spec.estimate_interior else ("point",)
    out = collinearity_jacobians(points, eo_rows(centre, r_cl), cam, wrt=wrt)
    j_point = out["point"]
    # j_point = d px/d q @ M with q = M (X - X_pc), M = R_c^l^T orthonormal.
    dpx_dq = j_point @ r_cl
    d = points - centre
    m = np.swapaxes(r_cl, -1, -2)
    dq = np.einsum("gkji,gj->gik", d_rot, d) - m @ d_centre
    j_pose = dpx_dq @ dq
    if spec.estimate_interior:
        j_pose[:, :, -3:] += out["interior"][:, :, :3]
    return out["pixels"], j_pose, j_point


def _camera_frame_ray(ideal: Array, f: float, projection: str) -> tuple[Array, Array, Array]:
    """Camera-frame rays of ideal centred image points, with their derivatives.

    Perspective: ``(x / f, y / f, -1)`` (camera-frame z of -1). Fisheye: the unit vector at the
    angle ``theta(r)`` off the axis (:func:`core.geometry.projection.ray_from_ideal`), which
    also holds beyond 90 degrees; the conditions that use the ray do not depend on its length.

    Parameters
    ----------
    ideal : ndarray, shape (G, 2)
        Ideal centred image coordinates, millimetres.
    f : float
        Principal distance, millimetres.
    projection : str
        The camera's projection (:data:`core.geometry.projection.PROJECTIONS`).

    Returns
    -------
    rc : (G, 3)
        The rays; NaN beyond a fisheye's field.
    d_ideal : (G, 3, 2)
        ``d rc / d ideal``, per millimetre.
    d_f : (G, 3)
        ``d rc / d f`` at fixed ideal coordinates, per millimetre.
    """
    g = ideal.shape[0]
    if projection == "perspective":
        rc = np.column_stack([ideal / f, -np.ones(g)])
        d_ideal = np.zeros((g, 3, 2))
        d_ideal[:, 0, 0] = d_ideal[:, 1, 1] = 1.0 / f
        d_f = np.zeros((g, 3))
        d_f[:, :2] = -ideal / f**2
        return rc, d_ideal, d_f
    r = np.hypot(ideal[:, 0], ideal[:, 1])
    theta = theta_from_radius(r / f, projection)
    # d theta / d r = 1 / (f g'(theta)); every fisheye g has g'(0) = 1
    t_r = 1.0 / (f * radius_derivative(theta, projection))
    sin, cos = np.sin(theta), np.cos(theta)
    axis = r <= 1e-12 * f
    rs = np.where(axis, 1.0, r)
    s = np.where(axis, 1.0 / f, sin / rs)  # rc_xy = s (x, y)
    # (d s / d r) / r, which tends to a finite limit on the axis: its term vanishes there
    ds_r = np.where(axis, 0.0, (cos * t_r * rs - sin) / rs**3)
    rc = np.column_stack([ideal * s[:, None], -cos])
    d_ideal = np.empty((g, 3, 2))
    d_ideal[:, :2, :] = s[:, None, None] * np.eye(2) + ds_r[:, None, None] * (
        ideal[:, :, None] * ideal[:, None, :]
    )
    d_ideal[:, 2, :] = (sin * t_r / rs)[:, None] * ideal
    d_ideal[axis, 2, :] = ideal[axis] / f**2  # sin(theta) / r -> 1 / f, theta_r -> 1 / f
    # theta depends on r / f: d theta / d f = -(r / f) d theta / d r
    t_f = -r * t_r / f
    d_f = np.column_stack([ideal * (cos * t_f / rs)[:, None], sin * t_f])
    d_f[axis, :2] = -ideal[axis] / f**2
    return rc, d_ideal, d_f


def camera_ray(
    xp: Array, pixels: Array, r_nl: Array, spec: PoseSpec
) -> tuple[Array, Array, Array, Array, Array, Array]:
    """Object-space rays of measured pixels, with derivatives.

    The camera's own projection (perspective or fisheye, :func:`_camera_frame_ray`) turns the
    ideal image point into the camera-frame ray.

    Returns
    -------
    centre : (G, 3)
        Perspective centres.
    ray : (G, 3)
        ``R_c^l rc``: for a perspective camera ``rc = (x_i / f, y_i / f, -1)`` (not unit, its
        camera-frame z is -1); for a fisheye one the unit ray.
    d_centre : (G, 3, P)
    d_ray_pose : (G, 3, P)
        d ray / d xp (interior included).
    d_ray_px : (G, 3, 2)
        d ray / d (col, row).
    r_cl : (G, 3, 3)
    """
    centre, r_cl, d_centre, d_rot = pose_chain(xp, r_nl, spec)
    cam = spec.camera_at(xp)
    f = cam.focal_mm
    ps = cam.pixel_size_mm
    measured = cam.pixel_to_image(pixels) - np.array([cam.x0_mm, cam.y0_mm])
    ideal = cam.distortion.undistort(measured)
    g = pixels.shape[0]
    rc, drc_di, drc_df = _camera_frame_ray(ideal, f, cam.projection)
    ray = np.einsum("gij,gj->gi", r_cl, rc)
    d_ray_pose = np.einsum("gkij,gj->gik", d_rot, rc)
    jd = np.eye(2) + cam.distortion.jacobian_xy(measured)  # d ideal / d measured
    drc_dm = drc_di @ jd  # d rc / d measured
    d_measured_d_px = np.array([[ps, 0.0], [0.0, -ps]])
    d_ray_px = r_cl @ (drc_dm @ d_measured_d_px)
    if spec.estimate_interior:
        drc = np.zeros((g, 3, 3))
        drc[:, :, 0] = drc_df
        drc[:, :, 1] = -drc_dm[:, :, 0]  # measured = image - x0
        drc[:, :, 2] = -drc_dm[:, :, 1]
        d_ray_pose[:, :, -3:] += r_cl @ drc
    return centre, ray, d_centre, d_ray_pose, d_ray_px, r_cl


def coplanarity(
    xp: Array, pixels: Array, line_point: Array, line_dir: Array, r_nl: Array, spec: PoseSpec
) -> tuple[Array, Array, Array, Array, Array]:
    """Condition that the image ray and a 3D line are coplanar: ``(X0 - X_pc) . (r x u) = 0``.

    Parameters
    ----------
    xp : (G, P); pixels : (G, 2); line_point, line_dir : (G, 3) X0 and u in the adjustment
    frame; r_nl : (G, 3, 3); spec : PoseSpec.

    Returns
    -------
    g : (G,)
        Misclosure, m (the ray of :func:`camera_ray`: camera-frame z of -1, or unit for a
        fisheye camera; the Gauss-Helmert solution does not depend on its scale).
    j_pose : (G, P); j_px : (G, 2); j_point : (G, 3); j_dir : (G, 3)
        Its derivatives.
    """
    centre, ray, d_centre, d_ray_pose, d_ray_px, _ = camera_ray(xp, pixels, r_nl, spec)
    a = line_point - centre
    cr = np.cross(ray, line_dir)
    g = np.einsum("gi,gi->g", a, cr)
    dg_dray = np.cross(line_dir, a)
    j_pose = np.einsum("gi,gik->gk", dg_dray, d_ray_pose) - np.einsum("gi,gik->gk", cr, d_centre)
    j_px = np.einsum("gi,gik->gk", dg_dray, d_ray_px)
    return g, j_pose, j_px, cr, np.cross(a, ray)


def paper_plane(
    xp: Array, pixels: Array, normal: Array, z: Array, r_nl: Array, spec: PoseSpec
) -> tuple[Array, Array]:
    """Paper 000's single-image model (its Eqs. 12-15) with d as the observation.

    The ray from the perspective centre is cut at the height ``z`` taken from the LiDAR
    points (Eqs. 12-13), and the plane equation gives ``d = -(a X + b Y + c z)`` (Eq. 15).

    Parameters
    ----------
    xp : (G, P); pixels : (G, 2); normal : (G, 3) plane normal (a, b, c) in the adjustment
    frame; z : (G,) height from the LiDAR points, adjustment frame; r_nl : (G, 3, 3).

    Returns
    -------
    d : (G,)
        Predicted plane offset, metres.
    j_pose : (G, 1, P)
    """
    centre, ray, d_centre, d_ray_pose, _, _ = camera_ray(xp, pixels, r_nl, spec)
    h = z - centre[:, 2]
    ratio = ray[:, :2] / ray[:, 2:3]
    xy = centre[:, :2] + h[:, None] * ratio
    d = -(np.einsum("gi,gi->g", normal[:, :2], xy) + normal[:, 2] * z)
    d_ratio = (
        d_ray_pose[:, :2, :] * ray[:, 2, None, None] - ray[:, :2, None] * d_ray_pose[:, 2:3, :]
    ) / (ray[:, 2, None, None] ** 2)
    d_xy = d_centre[:, :2, :] - ratio[:, :, None] * d_centre[:, 2:3, :] + h[:, None, None] * d_ratio
    j = -np.einsum("gi,gik->gk", normal[:, :2], d_xy)
    return d, j[:, None, :]
