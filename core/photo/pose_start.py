"""Start values of a single-image resection without an approximate orientation.

From any mix of image points with known object points and image lines matched to 3D lines,
the camera pose is found by a global search over the rotation with the translation
eliminated in closed form, then refined locally:

- every correspondence gives constraints linear in the camera-frame translation ``t`` for a
  given rotation ``R`` (object -> camera, the ``M`` of omega-phi-kappa): a line with the unit
  normal ``n`` of its image interpretation plane gives ``n . (R P + t) = 0`` for two points
  ``P`` of the 3D line; a point with the unit ray ``r`` gives ``E (R P + t) = 0`` with ``E``
  two unit vectors perpendicular to ``r`` (each row a distance in metres);
- stacking them, ``A t + B vec(R) = 0`` with ``A`` independent of ``R``; eliminating ``t``
  leaves the cost ``vec(R)' K vec(R)``, ``K = B' (I - A A+) B`` (9 x 9), a quartic in the
  rotation's quaternion: the variable-projection form used, for points, by the direct
  least-squares PnP of Hesch & Roumeliotis (2011) and, for lines, by Mirzaei & Roumeliotis
  (2011);
- its minima are found by evaluating it on a fixed set of rotations covering SO(3) (about 4
  degrees apart), refining the best distinct ones by Gauss-Newton on the rotation, solving
  ``t`` and keeping the solutions with the control in front of the camera.

With four or more points, OpenCV's solvePnP (SQPnP) is tried as well. The caller picks the
candidate that fits the rigorous model best. Nothing here needs an approximate pose.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from ..errors import InputError, NotObservableError
from ..geometry.camera import Camera
from ..geometry.rotations import matrix_to_opk, opk_to_matrix, skew

Array = NDArray[np.float64]

__all__ = ["PoseCandidate", "initial_pose_pnp", "pose_candidates"]

# OpenCV's camera looks along +z with y down; ours looks along -z with y up.
_CV_FLIP = np.diag([1.0, -1.0, -1.0])

#: Rotations sampled over SO(3) (quaternions of a fixed seed): about 4 degrees apart.
_SAMPLES = 24000
_SEED = 20100417
#: Local minima refined, taken at least this far apart (radians).
_SEEDS = 12
_SEED_SEPARATION = np.radians(15.0)


@dataclass(frozen=True)
class PoseCandidate:
    """A start pose: ``eo = (X0, Y0, Z0, omega, phi, kappa)`` (metres, radians), the cost it
    was ranked by, the share of the control in front of the camera and how it was found."""

    eo: Array
    cost: float
    in_front: float
    method: str


def initial_pose_pnp(pixels: ArrayLike, points: ArrayLike, camera: Camera) -> Array:
    """Pose from OpenCV's solvePnP (SQPnP, then its iterative refinement); lens removed first.

    A perspective camera's pixels go to OpenCV with its own camera matrix; any other central
    projection (a fisheye) goes as normalised rays: each pixel's ray (the camera's
    back-projection, :meth:`Camera.ray_from_ideal`) cut with the plane one unit in front of
    the camera, with the identity camera matrix. Rays at or beyond 90 degrees off the axis
    have no such point and are left out (at least 4 must remain).

    Returns ``(X0, Y0, Z0, omega, phi, kappa)`` in the frame of ``points``.

    Examples
    --------
    >>> from lidarphoto.core.geometry.collinearity import project
    >>> cam = Camera("f", focal_mm=2.0, pixel_size_mm=0.004, width_px=1500, height_px=1500,
    ...              projection="equidistant")
    >>> pts = np.array([[-1.0, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0], [0.3, 0.2, 0.5]])
    >>> eo = np.array([0.2, -0.1, 1.5, 0.05, -0.03, 0.4])
    >>> bool(np.allclose(initial_pose_pnp(project(pts, eo, cam), pts, cam), eo, atol=1e-6))
    True
    """
    import cv2

    px = np.asarray(pixels, dtype=np.float64)
    pts = np.asarray(points, dtype=np.float64)
    ideal = camera.ideal_from_pixel(px)  # centred, corrected, mm
    if camera.is_perspective:
        ps = camera.pixel_size_mm
        # OpenCV puts the centre of the first pixel at (0, 0), we put it at (0.5, 0.5).
        cx = camera.width_px / 2 + camera.x0_mm / ps - 0.5
        cy = camera.height_px / 2 - camera.y0_mm / ps - 0.5
        cv_px = np.column_stack([cx + ideal[:, 0] / ps, cy - ideal[:, 1] / ps])
        k = np.array([[camera.focal_px, 0.0, cx], [0.0, camera.focal_px, cy], [0.0, 0.0, 1.0]])
    else:
        ray = camera.ray_from_ideal(ideal)
        front = np.isfinite(ray).all(axis=1) & (ray[:, 2] < 0)
        if front.sum() < 4:
            raise InputError(
                f"OpenCV's start pose needs 4 points less than 90 degrees off the axis of the "
                f"{camera.projection} camera, got {int(front.sum())}"
            )
        ray, pts = ray[front], pts[front]
        # OpenCV's normalised coordinates: its camera looks along +z with y down
        cv_px = np.column_stack([ray[:, 0] / -ray[:, 2], ray[:, 1] / ray[:, 2]])
        k = np.eye(3)
    centre = pts.mean(axis=0)  # keeps OpenCV's float arithmetic away from large coordinates
    obj = np.ascontiguousarray(pts - centre)
    img = np.ascontiguousarray(cv_px)
    # OpenCV takes None for no distortion; its stubs do not
    ok, rvec, tvec = cv2.solvePnP(obj, img, k, None, flags=cv2.SOLVEPNP_SQPNP)  # type: ignore[call-overload]
    if not ok:
        raise InputError("OpenCV could not find an initial pose for the resection")
    ok, rvec, tvec = cv2.solvePnP(obj, img, k, None, rvec, tvec, True, cv2.SOLVEPNP_ITERATIVE)  # type: ignore[call-overload]
    r_cv = cv2.Rodrigues(rvec)[0]
    m = _CV_FLIP @ r_cv
    x0 = -r_cv.T @ tvec.ravel() + centre
    omega, phi, kappa = matrix_to_opk(m)
    return np.array([*x0, omega, phi, kappa])


def _quat_to_matrix(q: Array) -> Array:
    """Unit quaternions (S, 4) (w, x, y, z) -> rotation matrices (S, 3, 3)."""
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    r = np.empty((q.shape[0], 3, 3))
    r[:, 0, 0] = w * w + x * x - y * y - z * z
    r[:, 0, 1] = 2 * (x * y - w * z)
    r[:, 0, 2] = 2 * (x * z + w * y)
    r[:, 1, 0] = 2 * (x * y + w * z)
    r[:, 1, 1] = w * w - x * x + y * y - z * z
    r[:, 1, 2] = 2 * (y * z - w * x)
    r[:, 2, 0] = 2 * (x * z - w * y)
    r[:, 2, 1] = 2 * (y * z + w * x)
    r[:, 2, 2] = w * w - x * x - y * y + z * z
    return r


def _samples() -> Array:
    rng = np.random.default_rng(_SEED)
    q = rng.normal(size=(_SAMPLES, 4))
    return _quat_to_matrix(q / np.linalg.norm(q, axis=1, keepdims=True))


_ROTATIONS: Array | None = None


def _vec(r: Array) -> Array:
    """Column-major vec of (..., 3, 3) matrices: ``vec(R)[i + 3 j] = R[i, j]``."""
    return np.swapaxes(r, -1, -2).reshape(*r.shape[:-2], 9)


def _perpendicular(r: Array) -> Array:
    """Two unit vectors perpendicular to each unit vector of (N, 3): (N, 2, 3)."""
    helper = np.where(np.abs(r[:, [0]]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    e1 = np.cross(r, helper)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(r, e1)
    return np.stack([e1, e2], axis=1)


def _rays(pixels: Array, camera: Camera) -> Array:
    """Unit camera-frame rays of measured pixels (the camera's own projection)."""
    v = camera.ray_from_ideal(camera.ideal_from_pixel(pixels))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _plane_normal(rays: Array) -> Array:
    """Unit normal of the plane through the origin best containing the unit rays (K, 3)."""
    if rays.shape[0] == 2:
        n = np.cross(rays[0], rays[1])
    else:
        n = np.linalg.svd(rays)[2][-1]
    norm = np.linalg.norm(n)
    return n / norm if norm > 0 else n


def _system(
    camera: Camera,
    pixels: Array,
    xyz: Array,
    line_pixels: list[Array],
    line_p1: Array,
    line_p2: Array,
) -> tuple[Array, Array, Array]:
    """Rows ``a_l`` (L, 3) of ``A`` and the object points ``P_l`` (L, 3): ``a_l.(R P_l + t)``."""
    rows, pts = [], []
    if len(pixels):
        e = _perpendicular(_rays(pixels, camera))  # (N, 2, 3)
        rows.append(e.reshape(-1, 3))
        pts.append(np.repeat(xyz, 2, axis=0))
    for k, vertices in enumerate(line_pixels):
        n = _plane_normal(_rays(vertices, camera))
        rows.append(np.vstack([n, n]))
        pts.append(np.vstack([line_p1[k], line_p2[k]]))
    a = np.vstack(rows)
    p = np.vstack(pts)
    return a, p, np.einsum("li,lj->lij", p, a).reshape(-1, 9)  # kron(P, a) per row


def _refine(k_sqrt: Array, r0: Array, iterations: int = 40) -> tuple[Array, Array]:
    """Levenberg-Marquardt on SO(3) for a batch of starts ``r0`` (S, 3, 3): min ||L vec(R)||^2
    with ``R = exp([d]x) R``; returns the rotations (S, 3, 3) and their costs (S,)."""
    r = r0.copy()
    cost = np.sum((_vec(r) @ k_sqrt.T) ** 2, axis=1)
    lam = np.full(len(r), 1e-6)
    gens = skew(np.eye(3))  # [e_k]x, (3, 3, 3)
    for _ in range(iterations):
        res = _vec(r) @ k_sqrt.T  # (S, 9)
        jac = np.einsum("ij,skj->sik", k_sqrt, _vec(gens[None] @ r[:, None]))  # (S, 9, 3)
        n = np.swapaxes(jac, 1, 2) @ jac
        g = np.einsum("sik,si->sk", jac, res)
        damp = lam[:, None, None] * (
            np.eye(3) * (np.diagonal(n, axis1=1, axis2=2)[:, None, :] + 1e-12)
        )
        step = -np.linalg.solve(n + damp, g[:, :, None])[:, :, 0]
        trial = Rotation.from_rotvec(step).as_matrix() @ r
        c = np.sum((_vec(trial) @ k_sqrt.T) ** 2, axis=1)
        better = c <= cost
        r = np.where(better[:, None, None], trial, r)
        cost = np.where(better, c, cost)
        lam = np.where(better, lam * 0.1, lam * 10.0)
        if (np.linalg.norm(step, axis=1)[better] < 1e-12).all() and (better | (lam > 1e8)).all():
            break
    u, _, vt = np.linalg.svd(r)
    d = np.linalg.det(u @ vt)
    fix = np.ones((len(r), 3))
    fix[:, 2] = d
    return (u * fix[:, None, :]) @ vt, cost


def pose_candidates(
    camera: Camera,
    pixels: ArrayLike = (),
    xyz: ArrayLike = (),
    line_pixels: list[ArrayLike] | tuple = (),
    line_p1: ArrayLike = (),
    line_p2: ArrayLike = (),
) -> list[PoseCandidate]:
    """Start poses from points and lines, best first (module docstring).

    Parameters
    ----------
    camera : Camera
        Interior orientation (lens correction removed from the pixels first).
    pixels : (N, 2) array_like
        Measured pixels (col, row) of control points.
    xyz : (N, 3) array_like
        Their object coordinates, metres, a Cartesian frame.
    line_pixels : sequence of (K_i, 2) array_like
        Pixels measured on each image line (K_i >= 2).
    line_p1, line_p2 : (L, 3) array_like
        Two points of each matched 3D line.

    Returns
    -------
    list of PoseCandidate
        Distinct poses with most of the control in front of the camera, lowest cost first.

    Raises
    ------
    InputError
        Fewer than six constraints (e.g. 2 points, or 1 point and 1 line).
    NotObservableError
        The constraints cannot fix the position (all lines parallel and no point: the position
        along them is free; the message names the direction).

    Examples
    --------
    >>> from lidarphoto.core.geometry.collinearity import project
    >>> cam = Camera("c", focal_mm=100.0, pixel_size_mm=0.01, width_px=2000, height_px=2000)
    >>> rng = np.random.default_rng(0)
    >>> pts = np.column_stack([rng.uniform(-80, 80, (8, 2)), rng.uniform(0, 20, 8)])
    >>> eo = np.array([5.0, -3.0, 1000.0, 0.02, -0.01, 2.5])
    >>> best = pose_candidates(cam, project(pts, eo, cam), pts)[0]
    >>> bool(np.allclose(best.eo, eo, atol=1e-6))
    True
    """
    global _ROTATIONS
    px = np.asarray(pixels, dtype=np.float64).reshape(-1, 2)
    pts = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
    lines = [np.asarray(v, dtype=np.float64).reshape(-1, 2) for v in line_pixels]
    p1 = np.asarray(line_p1, dtype=np.float64).reshape(-1, 3)
    p2 = np.asarray(line_p2, dtype=np.float64).reshape(-1, 3)
    if 2 * len(px) + 2 * len(lines) < 6:
        raise InputError(
            f"{len(px)} point(s) and {len(lines)} line(s) give {2 * len(px) + 2 * len(lines)} "
            "conditions: a resection needs at least 6 (e.g. 3 points, 3 lines, or 2 points and "
            "1 line)"
        )
    everything = np.vstack([pts, p1, p2])
    centre = everything.mean(axis=0)
    a, p, b = _system(camera, px, pts - centre, lines, p1 - centre, p2 - centre)
    # t is free along the null space of A: e.g. all lines parallel and no points
    sv = np.linalg.svd(a, compute_uv=False)
    if sv.size < 3 or sv[-1] < 1e-6 * sv[0]:
        direction = np.linalg.svd(a)[2][-1]
        raise NotObservableError(
            "Not observable: the position along the direction "
            f"({direction[0]:.3f}, {direction[1]:.3f}, {direction[2]:.3f}) of the camera frame "
            "is not determined by these observations (all lines parallel and no control "
            "point?); add lines in other directions or control points",
            parameters=["X0", "Y0", "Z0"],
        )
    q, _ = np.linalg.qr(a)
    proj = b - q @ (q.T @ b)
    kmat = proj.T @ proj
    w, v = np.linalg.eigh(kmat)
    k_sqrt = (v * np.sqrt(np.clip(w, 0.0, None))).T  # L with L'L = K
    if _ROTATIONS is None:
        _ROTATIONS = _samples()
    vr = _vec(_ROTATIONS)
    costs = np.sum((vr @ kmat) * vr, axis=1)
    best = np.argpartition(costs, 2000)[:2000]
    order = best[np.argsort(costs[best])]
    seeds: list[Array] = []
    for i in order:
        r = _ROTATIONS[i]
        if all(
            np.arccos(np.clip((np.trace(r @ s.T) - 1) / 2, -1, 1)) > _SEED_SEPARATION for s in seeds
        ):
            seeds.append(r)
            if len(seeds) >= _SEEDS:
                break
    a_pinv = np.linalg.pinv(a)
    out: list[PoseCandidate] = []
    refined, refined_cost = _refine(k_sqrt, np.array(seeds))
    for r, cost in zip(refined, refined_cost):
        cost = float(cost)
        t = -a_pinv @ (b @ _vec(r))
        cam_pts = (p @ r.T) + t
        front = float(np.mean(cam_pts[:, 2] < 0))
        if front < 0.5:
            continue
        c = centre - r.T @ t
        dup = any(
            np.arccos(np.clip((np.trace(r @ o_r.T) - 1) / 2, -1, 1)) < 1e-4
            for o_r in [_opk_matrix(o.eo) for o in out]
        )
        if dup:
            continue
        omega, phi, kappa = matrix_to_opk(r)
        out.append(
            PoseCandidate(np.array([*c, omega, phi, kappa]), cost, front, "global (points+lines)")
        )
    if len(px) >= 4:
        try:
            eo = initial_pose_pnp(px, pts, camera)
            m = _opk_matrix(eo)
            cam_pts = (everything - eo[:3]) @ m.T
            front = float(np.mean(cam_pts[:, 2] < 0))
            t = m @ (centre - eo[:3])
            res = a @ t + b @ _vec(m)
            out.append(PoseCandidate(eo, float(res @ res), front, "OpenCV solvePnP (SQPnP)"))
        except Exception:
            pass
    out.sort(key=lambda c: c.cost)
    return out


def _opk_matrix(eo: Array) -> Array:
    return opk_to_matrix(eo[3], eo[4], eo[5])
