"""Two-view verification of fisheye images for the tie points: keypoints as camera rays, the
essential matrix on them, the epipolar distance in the images' own pixels.

A fundamental matrix relates perspective images only: between fisheye images (any projection
of :mod:`core.geometry.projection`, with its lens correction) the epipolar "lines" are curves.
The keypoints of a fisheye image are therefore turned into unit rays of the camera frame
(x right, y up, the camera looks along -z) with the camera's own inverse projection
(:meth:`Camera.ideal_from_pixel`, :meth:`Camera.ray_from_ideal`); two rays of one ground point
satisfy ``b^T E a = 0`` with the essential matrix ``E``.

- **Hypothesis**: OpenCV's essential-matrix RANSAC (MAGSAC++ or RANSAC, the five-point
  solver; Nister 2004) on the normalised coordinates ``(u, v) / -w`` of the rays less than
  :data:`MAX_RANSAC_ANGLE_DEG` off the axis (an identity camera matrix); its threshold is
  the RANSAC threshold in pixels times the median local scale (normalised units per pixel)
  of those matches, so that it stands for the same pixel distance where most matches are.
- **Refinement** (:func:`fit_essential`): the hypothesis is polished by least squares
  (rotation and baseline direction, 5 parameters; :func:`refine_essential`) on the
  distances below of its inliers; the RANSAC is run a second time on those inliers and
  polished the same way, and the matrix with the lower truncated cost (MSAC: the squared
  distances, at most the threshold's square) is kept. Over near-flat ground the essential
  matrix is weakly determined (a plane has two) and the first RANSAC's may sit in the other
  valley: measured on two simulated equidistant images, 0.48 px median epipolar distance
  after its refinement where the second RANSAC, refined, gives 0.137 px and the true matrix
  0.131 px.
- **Distance** (:func:`ray_epipolar_px`): the first-order distance, in full-resolution pixels
  of each image, of a keypoint to the epipolar curve of its partner: ``|b^T E a|`` divided by
  the gradient of ``b^T E a`` with respect to the pixel position (its Jacobian from the
  camera model, central differences of a quarter pixel); the mean of the two images, as
  :func:`core.photo.tie_points.epipolar_distances` gives for lines. The inliers are the
  matches within the threshold by this distance: the rays beyond the hypothesis' field
  (up to the projection's own, 90 degrees and more) are tested too.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..geometry.camera import Camera
from ..geometry.rotations import opk_to_matrix, skew

Array = NDArray[np.float64]

__all__ = [
    "MAX_RANSAC_ANGLE_DEG",
    "KeypointRays",
    "essential_from_rays",
    "fit_essential",
    "keypoint_rays",
    "ray_epipolar_px",
    "refine_essential",
]

#: Rays further off the axis (degrees) take no part in the essential-matrix hypothesis: their
#: normalised coordinates grow without bound towards 90 degrees.
MAX_RANSAC_ANGLE_DEG = 75.0
#: Step of the central differences of the rays' Jacobian, pixels.
_STEP_PX = 0.25


@dataclass(frozen=True)
class KeypointRays:
    """Camera-frame rays of one image's keypoints.

    Attributes
    ----------
    rays : (N, 3) float64
        Unit directions (camera frame; NaN where the pixel lies outside the projection).
    jac : (N, 3, 2) float64
        ``d ray / d (col, row)`` per pixel.
    norm_scale : (N,) float64
        Largest normalised-coordinate change of one pixel ((u, v) / -w per pixel; NaN
        beyond 90 degrees).
    """

    rays: Array
    jac: Array
    norm_scale: Array


def _unit_rays(camera: Camera, px: Array) -> Array:
    r = camera.ray_from_ideal(camera.ideal_from_pixel(px))
    with np.errstate(invalid="ignore", divide="ignore"):
        return r / np.linalg.norm(r, axis=1, keepdims=True)


def _normalised(r: Array) -> Array:
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(r[:, 2:] < 0, r[:, :2] / -r[:, 2:], np.nan)


def keypoint_rays(camera: Camera, pixels: Array) -> KeypointRays:
    """The rays of keypoints (full-resolution pixels, project convention) of ``camera``.

    >>> cam = Camera("f", focal_mm=2.0, pixel_size_mm=0.01, width_px=400, height_px=300,
    ...              projection="equidistant")
    >>> kr = keypoint_rays(cam, np.array([[200.0, 150.0], [300.0, 150.0]]))
    >>> kr.rays.round(6).tolist()   # the axis, and 100 px * 0.01 mm / 2 mm = 0.5 rad off it
    [[0.0, 0.0, -1.0], [0.479426, 0.0, -0.877583]]
    >>> round(float(kr.norm_scale[0]), 7)   # 1 / f_px on the axis
    0.005
    """
    px = np.asarray(pixels, np.float64).reshape(-1, 2)
    n = px.shape[0]
    h = _STEP_PX
    steps = np.array([[0.0, 0.0], [h, 0.0], [-h, 0.0], [0.0, h], [0.0, -h]])
    allr = _unit_rays(camera, (px[None, :, :] + steps[:, None, :]).reshape(-1, 2)).reshape(5, n, 3)
    jac = np.stack([(allr[1] - allr[2]) / (2 * h), (allr[3] - allr[4]) / (2 * h)], axis=2)
    norm = [_normalised(r) for r in allr]
    jn = np.stack([(norm[1] - norm[2]) / (2 * h), (norm[3] - norm[4]) / (2 * h)], axis=2)
    with np.errstate(invalid="ignore"):
        scale = np.linalg.norm(jn, ord=2, axis=(1, 2)) if n else np.zeros(0)
    return KeypointRays(allr[0], jac, scale)


def ray_epipolar_px(
    e: Array, ra: KeypointRays, ia: NDArray[np.intp], rb: KeypointRays, ib: NDArray[np.intp]
) -> Array:
    """Distance of the matches ``ia``, ``ib`` to their epipolar curves (``b^T E a = 0``),
    full-resolution pixels, the mean of the two images (module docstring); NaN for a ray
    outside its projection.

    >>> cam = Camera("f", focal_mm=2.0, pixel_size_mm=0.01, width_px=400, height_px=300,
    ...              projection="equisolid")
    >>> e = np.array([[0, 0, 0], [0, 0, -1], [0, 1, 0.0]])  # a sideways shift (x)
    >>> ka = keypoint_rays(cam, np.array([[200.0, 150.0]]))
    >>> kb = keypoint_rays(cam, np.array([[240.0, 150.5]]))  # 0.5 px off row 150 in b
    >>> i = np.zeros(1, np.intp)
    >>> float(ray_epipolar_px(e, ka, i, kb, i)[0].round(4))  # and 0.5076 px off its curve in a
    0.5038
    """
    return np.abs(_signed_px(e, ra.rays[ia], ra.jac[ia], rb.rays[ib], rb.jac[ib]))


def essential_from_rays(
    ra: KeypointRays,
    ia: NDArray[np.intp],
    rb: KeypointRays,
    ib: NDArray[np.intp],
    threshold_px: float,
    method: str,
) -> Array | None:
    """The essential matrix (3, 3) of the rays' frame (``b^T E a = 0``) from the matches,
    or None when fewer than 8 lie within :data:`MAX_RANSAC_ANGLE_DEG` of both axes or the
    RANSAC fails. ``method``: ``"magsac"`` or ``"ransac"``; a fixed seed (OpenCV's)."""
    import cv2

    lim = -np.cos(np.radians(MAX_RANSAC_ANGLE_DEG))
    a, b = ra.rays[ia], rb.rays[ib]
    use = np.flatnonzero((a[:, 2] < lim) & (b[:, 2] < lim))
    if use.size < 8:
        return None
    na, nb = _normalised(a[use]), _normalised(b[use])
    scale = float(np.median(np.concatenate([ra.norm_scale[ia[use]], rb.norm_scale[ib[use]]])))
    cv_method = cv2.USAC_MAGSAC if method == "magsac" else cv2.RANSAC
    cv2.setRNGSeed(12345)
    try:
        em, _ = cv2.findEssentialMat(
            na, nb, np.eye(3), cv_method, 0.999, float(threshold_px) * scale, 10000
        )
    except cv2.error:
        return None
    if em is None or em.ndim != 2 or em.shape[1] != 3 or em.shape[0] < 3:
        return None
    em = em[:3]  # the best of several stacked solutions (3k, 3)
    # homogeneous normalised points are D ray / -w with D = diag(1, 1, -1)
    d = np.diag([1.0, 1.0, -1.0])
    return np.asarray(d @ em @ d, np.float64)


def _signed_px(e: Array, a: Array, ja: Array, b: Array, jb: Array) -> Array:
    """Signed first-order epipolar distance (pixels, mean of the two images) of rays ``a``,
    ``b`` (N, 3) whose Jacobians by the pixel are ``ja``, ``jb`` (N, 3, 2)."""
    ea = a @ e.T  # E a: the epipolar plane's normal in b
    eb = b @ e  # E^T b: in a
    c = np.sum(b * ea, axis=1)
    ga = np.einsum("nk,nkj->nj", eb, ja)
    gb = np.einsum("nk,nkj->nj", ea, jb)
    with np.errstate(divide="ignore", invalid="ignore"):
        return 0.5 * c * (1.0 / np.hypot(ga[:, 0], ga[:, 1]) + 1.0 / np.hypot(gb[:, 0], gb[:, 1]))


def refine_essential(
    e: Array, ra: KeypointRays, ia: NDArray[np.intp], rb: KeypointRays, ib: NDArray[np.intp]
) -> Array:
    """``e`` refined by least squares on the epipolar distances (pixels) of the matches
    ``ia``, ``ib`` (its inliers): ``E = [t]x R``, R turned by three small angles, the unit
    baseline t by two; ``e`` itself when fewer than 8
    finite matches are given or the fit does not lower the sum of squares.

    >>> from lidarphoto.core.geometry.projection import ideal_from_camera
    >>> rng = np.random.default_rng(0)
    >>> cam = Camera("f", focal_mm=2.0, pixel_size_mm=0.01, width_px=400, height_px=300,
    ...              projection="equisolid")
    >>> x = np.column_stack([rng.uniform(-40, 40, (60, 2)), rng.uniform(-60, -40, 60)])
    >>> r, t = opk_to_matrix(0.05, -0.03, 0.2), np.array([10.0, 2.0, 0.5])
    >>> def rays(q):  # camera-frame points -> the keypoints' rays
    ...     return keypoint_rays(cam, cam.pixel_from_ideal(ideal_from_camera(q, 2.0,
    ...                                                                  "equisolid")[0]))
    >>> ka, kb, k = rays(x), rays((x - t) @ r.T), np.arange(60)
    >>> e_true = skew(r @ -t) @ r                # b^T [R (0 - t)]x R a = 0
    >>> noisy = e_true + 0.3 * rng.standard_normal((3, 3))
    >>> bool(np.median(ray_epipolar_px(noisy, ka, k, kb, k)) > 0.5)
    True
    >>> bool(np.max(ray_epipolar_px(refine_essential(noisy, ka, k, kb, k), ka, k, kb, k)) < 1e-6)
    True
    """
    from scipy.optimize import least_squares

    a, ja, b, jb = ra.rays[ia], ra.jac[ia], rb.rays[ib], rb.jac[ib]
    ok = np.all(np.isfinite(a), axis=1) & np.all(np.isfinite(b), axis=1)
    a, ja, b, jb = a[ok], ja[ok], b[ok], jb[ok]
    if a.shape[0] < 8:
        return e
    u, _, vt = np.linalg.svd(e)
    u = u * np.sign(np.linalg.det(u))
    vt = vt * np.sign(np.linalg.det(vt))
    r0 = u @ np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]) @ vt
    t0 = u[:, 2]  # [t0]x r0 = -e (its scale and sign do not matter)
    b1 = np.cross(t0, [1.0, 0.0, 0.0] if abs(t0[0]) < 0.9 else [0.0, 1.0, 0.0])
    b1 /= np.linalg.norm(b1)
    b2 = np.cross(t0, b1)

    def model(p: Array) -> Array:
        t = t0 + p[3] * b1 + p[4] * b2
        return skew(t / np.linalg.norm(t)) @ opk_to_matrix(p[0], p[1], p[2]) @ r0

    def residual(p: Array) -> Array:
        return _signed_px(model(p), a, ja, b, jb)

    start = residual(np.zeros(5))
    if not np.all(np.isfinite(start)):
        return e
    fit = least_squares(residual, np.zeros(5), method="lm", x_scale=1e-3)
    if not np.isfinite(fit.cost) or 2.0 * fit.cost >= float(start @ start):
        return e
    return np.asarray(model(fit.x), np.float64)


def fit_essential(
    ra: KeypointRays,
    ia: NDArray[np.intp],
    rb: KeypointRays,
    ib: NDArray[np.intp],
    threshold_px: float,
    method: str,
) -> Array | None:
    """The essential matrix of the matches ``ia``, ``ib`` (module docstring, "Refinement"):
    RANSAC, least squares on its inliers, RANSAC again on them, least squares; the matrix of
    the lowest truncated cost; None when the first RANSAC fails."""
    e = essential_from_rays(ra, ia, rb, ib, threshold_px, method)
    if e is None:
        return None
    thr = float(threshold_px)

    def inliers(m: Array) -> NDArray[np.bool_]:
        with np.errstate(invalid="ignore"):
            return ray_epipolar_px(m, ra, ia, rb, ib) <= thr

    def cost(m: Array) -> float:
        d = ray_epipolar_px(m, ra, ia, rb, ib)
        return float(np.sum(np.minimum(np.where(np.isfinite(d), d, thr) ** 2, thr * thr)))

    keep = inliers(e)
    candidates = [refine_essential(e, ra, ia[keep], rb, ib[keep])]
    again = essential_from_rays(ra, ia[keep], rb, ib[keep], threshold_px, method)
    if again is not None:
        keep2 = inliers(again)
        candidates.append(refine_essential(again, ra, ia[keep2], rb, ib[keep2]))
    best = min(candidates, key=cost)
    keep = inliers(best)
    return refine_essential(best, ra, ia[keep], rb, ib[keep])
