"""Control plates in ground photos: the plate's eight corners found automatically, and the
resection of the photo from them (Berveglieri & Tommaselli 2014, after Tommaselli &
Berveglieri 2014).

The plate
---------
A square plate with two concentric square edges: an outer square of side ``outer_m`` and an
inner square of side ``inner_m`` (e.g. a black square frame with a white square inside, or the
reverse: only the two edges matter, either polarity). Its centre lies vertically above the
surveyed point, at ``height_m`` above it (0: the plate lies at the point's height); the plate is
levelled; one pair of its sides points along the grid azimuth ``azimuth_deg`` (clockwise from
grid north; a true or magnetic reading must be corrected by the meridian convergence and the
declination). A square is the same after a quarter turn, so the azimuth counts modulo 90
degrees.

Corner order (:meth:`PlateGeometry.corners`): the outer corners then the inner ones, each four
counter-clockwise seen from above, the first in the direction ``azimuth_deg - 45``.

Detection (:func:`detect_plate`)
--------------------------------
1. **Candidates** (OpenCV): the grey photo thresholded (Otsu, adaptive and the levels 32, 64,
   ..., 224 of the photo stretched to 0-255 between its 0.5 and 99.5 percentiles; both polarities),
   contours with their holes, each polygon approximated (Douglas-Peucker) and kept when it has
   four vertices, is convex and larger than ``min_area_px``. A plate is a pair of candidates,
   one inside the other, with about the same centre (within 15 % of the outer side), whose
   inner corners the homography of the outer corners onto the square (+-1, +-1) takes to
   (+-r, +-r), r = inner/outer, within 0.12 (perspective keeps this; a blob merged with the
   plate's edge or a random pair of ground shapes does not; for a fisheye camera the test is
   made on the camera's ray plane of step 3, where the plate is a perspective image again),
   and whose frame is at least half as wide as expected and 5 px wide (one edge found at two
   thresholds is not a plate). Pairs sharing a centre (found in several binarisations) are
   one plate: the best fitting is kept.
2. **Edges** at sub-pixel precision: across each of the eight sides of the candidate pair, grey
   profiles sampled every 0.25 px (bilinear on the photo smoothed with a Gaussian of 1 px) on
   normals spaced 1 px along the side's middle 80 % (bicubic; for a fisheye camera along the
   side's curved image, the straight segment of the ray plane mapped to pixels, each normal
   to the curve), the edge point is the centroid of the squared gradient magnitude (less the
   profile's median) within 1.5 px of its peak (the peak itself snaps to the pixel grid).
   Texture of the ground next to the outer edge pulls its points by up to about a tenth of a
   pixel (tests/core/test_control_chips.py; up to 0.3 px for a plate of 100 px,
   bench/control_chips.md).
3. **Lines**: the edge points are turned into rays of the camera (its public back-projection
   :func:`core.geometry.collinearity.image_rays`, so that any central camera model, fisheye
   included, gives straight lines) and expressed on the plane z = -1 of the camera frame,
   where a straight object edge is a straight line whatever the lens. A total-least-squares
   line is fitted to each side (points beyond 3 robust sigmas dropped, once).
4. **Corners**: adjacent lines intersected, projected back to pixels with the camera
   (:func:`core.geometry.collinearity.project`); each corner gets the standard deviation
   propagated from the two lines' fits (offset and direction), to pixels by the focal length
   (perspective) or by the projection's Jacobian at the corner (fisheye, whose scale varies
   across the image).

Reasons when no plate is returned: ``plate not found`` (no quadrilateral at all), ``only one
square`` (quadrilaterals, but none with its inner/outer partner), ``ambiguous`` (several
distinct plates), ``edge fit failed`` (an edge with too few points).

Correspondence and resection (:func:`resect_plate`): a square's corners match the plate's in
four ways (quarter turns). Each is resected from OpenCV's PnP start; the one whose photo
"up" direction (the camera's y axis on the ground) is nearest the given approximate photo
azimuth is kept (the quarter turns differ by 90 degrees, so a reading within +-45 degrees
decides), then the project's rigorous resection (:func:`core.photo.resection.resect`) with
data snooping gives the orientation, sigma0 and the sigmas. Both take any central projection
of the camera: the PnP start from the corners' normalised rays, the resection with the
projection's own Jacobian (a nadir fisheye, as in the source, included).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..geometry.camera import Camera
from ..geometry.collinearity import collinearity_jacobians, image_rays, project_with_status
from ..geometry.rotations import opk_to_matrix
from ..i18n import mark as _t
from .chip_options import PlateGeometry

#: catalogue context of this module's ``_t("...")`` sentences (``make i18n``): the reports'
TR_CONTEXT = "Report"

Array = NDArray[np.float64]

__all__ = [
    "PlateDetection",
    "PlateGeometry",
    "PlateResection",
    "detect_plate",
    "fit_line_tls",
    "photo_azimuth",
    "pixels_from_plane",
    "plane_from_pixels",
    "plane_to_pixel_jacobian",
    "resect_plate",
]

#: The camera at the origin looking along -z: object frame = camera frame.
_IDENTITY_EO = np.zeros(6)
#: Sampling step along the edge normals, pixels.
PROFILE_STEP_PX = 0.25
#: Half width of the window of the gradient centroid, pixels.
EDGE_WINDOW_PX = 1.5
#: Narrowest frame (half the difference of the sides) taken as a plate's, pixels.
MIN_FRAME_PX = 5.0
#: Fraction of each side (its middle) sampled for edge points.
SIDE_FRACTION = 0.8


@dataclass(frozen=True)
class PlateDetection:
    """The plate found in a photo.

    Attributes
    ----------
    found : bool
    reason : str
        Why no plate was returned ("" when found).
    corners_px : (8, 2) ndarray
        Outer then inner corners (col, row), each four counter-clockwise as seen from above
        (and on the screen), the inner corner k on the diagonal of the outer corner k;
        NaN when not found.
    sigma_px : (8,) ndarray
        Standard deviation of each corner (root mean square of col and row), pixels,
        propagated from the line fits.
    edge_rms_px : (8,) ndarray
        RMS distance of the edge points from their fitted line, pixels (sides: outer 0-3,
        inner 4-7; side k from corner k to k + 1).
    edge_points : (8,) int ndarray
        Edge points used per side.
    candidates : int
        Distinct plate candidates (pairs) found.
    """

    found: bool
    reason: str = ""
    corners_px: Array = field(default_factory=lambda: np.full((8, 2), np.nan))
    sigma_px: Array = field(default_factory=lambda: np.full(8, np.nan))
    edge_rms_px: Array = field(default_factory=lambda: np.full(8, np.nan))
    edge_points: NDArray[np.int64] = field(default_factory=lambda: np.zeros(8, np.int64))
    candidates: int = 0


# ------------------------------------------------------------------ camera plane <-> pixels
def plane_from_pixels(pixels: ArrayLike, camera: Camera) -> Array:
    """Measured pixels (N, 2) -> the rays' points on the plane z = -1 of the camera frame.

    Straight object lines are straight there for every central camera (the camera's own
    back-projection removes its lens model).

    >>> cam = Camera("c", focal_mm=10.0, pixel_size_mm=0.01, width_px=1000, height_px=800)
    >>> plane_from_pixels([[600.0, 400.0]], cam).tolist()
    [[0.1, 0.0]]
    """
    _, d = image_rays(pixels, _IDENTITY_EO, camera)
    with np.errstate(divide="ignore", invalid="ignore"):
        uv = d[:, :2] / -d[:, 2:3]
    # a fisheye's rays at or beyond 90 degrees off the axis do not meet the plane
    uv[~(d[:, 2] < 0)] = np.nan
    return uv


def plane_to_pixel_jacobian(uv: ArrayLike, camera: Camera) -> Array:
    """``d pixel / d (u, v)`` (N, 2, 2) of :func:`pixels_from_plane` (pixels per plane unit),
    from the camera's own projection Jacobian (the lens model included).

    >>> cam = Camera("c", focal_mm=10.0, pixel_size_mm=0.01, width_px=1000, height_px=800)
    >>> plane_to_pixel_jacobian([[0.1, 0.0]], cam).round(9).tolist()
    [[[1000.0, 0.0], [0.0, -1000.0]]]
    """
    p = np.asarray(uv, dtype=np.float64).reshape(-1, 2)
    xyz = np.column_stack([p, -np.ones(len(p))])
    return collinearity_jacobians(xyz, _IDENTITY_EO, camera, wrt=("point",))["point"][:, :, :2]


def pixels_from_plane(uv: ArrayLike, camera: Camera) -> Array:
    """Points (N, 2) of the plane z = -1 of the camera frame -> measured pixels (NaN where
    the camera cannot image them).

    >>> cam = Camera("c", focal_mm=10.0, pixel_size_mm=0.01, width_px=1000, height_px=800)
    >>> pixels_from_plane([[0.1, 0.0]], cam).tolist()
    [[600.0, 400.0]]
    """
    p = np.asarray(uv, dtype=np.float64).reshape(-1, 2)
    xyz = np.column_stack([p, -np.ones(len(p))])
    return project_with_status(xyz, _IDENTITY_EO, camera)[0]


# ------------------------------------------------------------------ lines
def fit_line_tls(points: ArrayLike) -> tuple[Array, float, Array, float, float]:
    """Total-least-squares line through (N, 2) points.

    Returns
    -------
    normal : (2,) unit normal n, the line being ``n . x = d``
    d : float
    centroid : (2,)
    rms : float
        RMS orthogonal distance of the points (with N - 2 degrees of freedom).
    spread : float
        ``sqrt(sum t^2)`` of the points' positions t along the line from the centroid.

    >>> n, d, c, rms, _ = fit_line_tls([[0, 1], [1, 1], [2, 1.0]])
    >>> (abs(n).round(9).tolist(), round(abs(d), 9), round(rms, 9))
    ([0.0, 1.0], 1.0, 0.0)
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    c = p.mean(axis=0)
    q = p - c
    _, _, vt = np.linalg.svd(q, full_matrices=False)
    direction, normal = vt[0], vt[1]
    r = q @ normal
    t = q @ direction
    dof = max(len(p) - 2, 1)
    return (
        normal,
        float(normal @ c),
        c,
        float(math.sqrt(float(r @ r) / dof)),
        float(math.sqrt(float(t @ t))),
    )


def _fit_side(points: Array) -> tuple[Array, float, Array, float, float, int] | None:
    """TLS fit, points beyond 3 robust sigmas dropped once; None with fewer than 5 points."""
    if len(points) < 5:
        return None
    n, d, c, rms, spread = fit_line_tls(points)
    r = points @ n - d
    mad = 1.4826 * float(np.median(np.abs(r - np.median(r))))
    keep = np.abs(r) <= max(3.0 * mad, 1e-12)
    if 5 <= keep.sum() < len(points):
        points = points[keep]
        n, d, c, rms, spread = fit_line_tls(points)
    return n, d, c, rms, spread, len(points)


def _intersect(l1, l2) -> tuple[Array, Array]:
    """Intersection of two fitted lines and its 2 x 2 covariance (plane units)."""
    n1, d1, c1, s1, sp1, m1 = l1
    n2, d2, c2, s2, sp2, m2 = l2
    a = np.vstack([n1, n2])
    x = np.linalg.solve(a, np.array([d1, d2]))
    var = []
    for n, c, s, sp, m in ((n1, c1, s1, sp1, m1), (n2, c2, s2, sp2, m2)):
        t = float(np.array([n[1], -n[0]]) @ (x - c))  # along the line from its centroid
        # offset of the line at its centroid and its rotation, both from the TLS residuals
        var.append(s * s / m + (t * s / max(sp, 1e-300)) ** 2)
    ai = np.linalg.inv(a)
    return x, ai @ np.diag(var) @ ai.T


# ------------------------------------------------------------------ candidates
def _quads(grey_u8: NDArray[np.uint8], min_area_px: float) -> list[Array]:
    """Convex quadrilaterals (4, 2) of the contours of several binarisations (pixels,
    corner-origin convention)."""
    import cv2

    h, w = grey_u8.shape
    blur = cv2.GaussianBlur(grey_u8, (5, 5), 0)
    _, otsu = cv2.threshold(blur, 0, 255, cv2.THRESH_BINARY + cv2.THRESH_OTSU)
    block = max(15, (min(h, w) // 16) | 1)
    adaptive = cv2.adaptiveThreshold(
        blur, 255, cv2.ADAPTIVE_THRESH_MEAN_C, cv2.THRESH_BINARY, block, 0
    )
    # fixed levels too: a plate edge against a ground of similar mean grey is separated only
    # by a level between the plate's grey and the nearest ground grey
    levels = [cv2.threshold(blur, t, 255, cv2.THRESH_BINARY)[1] for t in range(32, 255, 32)]
    out = []
    for base in (otsu, adaptive, *levels):
        for binary in (base, 255 - base):
            contours, _ = cv2.findContours(binary, cv2.RETR_LIST, cv2.CHAIN_APPROX_SIMPLE)
            for cnt in contours:
                if cv2.contourArea(cnt) < min_area_px:
                    continue
                peri = cv2.arcLength(cnt, True)
                poly = cv2.approxPolyDP(cnt, 0.03 * peri, True)
                if len(poly) != 4 or not cv2.isContourConvex(poly):
                    continue
                # contour pixels are pixel indices: their centres are at +0.5 in our convention
                out.append(poly.reshape(4, 2).astype(np.float64) + 0.5)
    return out


def _area(q: Array) -> float:
    x, y = q[:, 0], q[:, 1]
    return 0.5 * float(x @ np.roll(y, -1) - y @ np.roll(x, -1))


def _inside(point: Array, quad: Array) -> bool:
    """Point inside a convex quadrilateral (either orientation)."""
    signs = []
    for k in range(4):
        a, b = quad[k], quad[(k + 1) % 4]
        signs.append((b[0] - a[0]) * (point[1] - a[1]) - (b[1] - a[1]) * (point[0] - a[0]))
    s = np.sign(signs)
    return bool(np.all(s >= 0) or np.all(s <= 0))


def _screen_ccw(q: Array) -> Array:
    """The quadrilateral ordered counter-clockwise as seen on the screen (a negative shoelace
    area in (col, row), rows growing down): counter-clockwise seen from above for a camera
    looking down, the order of :meth:`PlateGeometry.corners`."""
    return q if _area(q) < 0 else q[::-1].copy()


def _pairs(
    quads: list[Array], ratio: float, tol: float = 0.12, to_plane=None
) -> list[tuple[Array, Array]]:
    """Nested, concentric quadrilaterals that are a plate: the homography taking the outer
    corners to the square (+-1, +-1) takes the inner ones to (+-ratio, +-ratio) within
    ``tol`` (half-sides). One pair per plate (the best fitting of those sharing a centre).
    ``to_plane`` (pixels -> the camera's ray plane) applies the test there: a fisheye image
    of the plate is not a perspective one, its ray plane is."""
    import cv2

    square = np.array([[1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0], [1.0, -1.0]])
    area_ratio = ratio * ratio
    scored: list[tuple[float, Array, Array]] = []
    areas = [abs(_area(q)) for q in quads]
    centres = [q.mean(axis=0) for q in quads]
    for i, outer in enumerate(quads):
        side = math.sqrt(areas[i])
        for j, inner in enumerate(quads):
            if i == j or not 0.0 < areas[j] < areas[i]:
                continue
            if not area_ratio / 2.0 <= areas[j] / areas[i] <= area_ratio * 2.0:
                continue
            if np.hypot(*(centres[i] - centres[j])) > 0.15 * side:
                continue
            # two edges, not one edge found at two thresholds (a blurred edge spreads its
            # contours over a few pixels): a frame at least half as wide as the plate's and
            # MIN_FRAME_PX wide (the edge profiles of its two sides must not overlap)
            gap = side - math.sqrt(areas[j])
            if gap < max(2.0 * MIN_FRAME_PX, 0.5 * (1.0 - ratio) * side):
                continue
            if not all(_inside(p, outer) for p in inner):
                continue
            o = _screen_ccw(outer)
            n = _screen_ccw(inner)
            # inner corner k on the diagonal of outer corner k: the nearest in direction
            c = o.mean(axis=0)
            ang_o = np.arctan2(*(o - c).T[::-1])
            ang_n = np.arctan2(*(n - c).T[::-1])
            diff = np.abs(np.angle(np.exp(1j * (ang_n[None, :] - ang_o[:, None]))))
            order = diff.argmin(axis=1)
            if len(set(order.tolist())) != 4:
                continue
            n = n[order]
            ho, hn = (o, n) if to_plane is None else (to_plane(o), to_plane(n))
            if not (np.isfinite(ho).all() and np.isfinite(hn).all()):
                continue
            h = cv2.getPerspectiveTransform(ho.astype(np.float32), square.astype(np.float32))
            m = cv2.perspectiveTransform(hn.reshape(-1, 1, 2), h).reshape(4, 2)
            err = float(np.abs(m - ratio * square).max())
            if err <= tol:
                scored.append((err, o, n))
    scored.sort(key=lambda t: t[0])
    found: list[tuple[Array, Array]] = []
    for _, o, n in scored:
        c, side = o.mean(axis=0), math.sqrt(abs(_area(o)))
        if all(np.hypot(*(fo.mean(axis=0) - c)) > 0.15 * side for fo, _ in found):
            found.append((o, n))
    return found


# ------------------------------------------------------------------ sub-pixel edges
def _edge_points(
    smooth: NDArray[np.float32], a: Array, b: Array, camera: Camera | None = None
) -> Array:
    """Sub-pixel edge points (M, 2) across the side a -> b (pixels).

    With a (fisheye) ``camera`` the side is followed along its image, the straight segment
    of the camera's ray plane mapped to pixels (curved in the photo), each profile normal to
    the curve; without one, along the straight segment a -> b.
    """
    import cv2

    length = float(np.hypot(*(b - a)))
    if length < 8:
        return np.empty((0, 2))
    u = (b - a) / length
    m = int(length * SIDE_FRACTION)
    t = (np.arange(m) + 0.5) / m
    t = (1 - SIDE_FRACTION) / 2 + SIDE_FRACTION * t
    if camera is None:
        nrm = np.array([-u[1], u[0]])[None, :]
        base = a + t[:, None] * (b - a)
    else:
        ua, ub = plane_from_pixels(np.vstack([a, b]), camera)
        uv = ua + t[:, None] * (ub - ua)
        base = pixels_from_plane(uv, camera)
        tangent = np.einsum("nij,j->ni", plane_to_pixel_jacobian(uv, camera), ub - ua)
        tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
        nrm = np.column_stack([-tangent[:, 1], tangent[:, 0]])
        good = np.isfinite(base).all(axis=1) & np.isfinite(nrm).all(axis=1)
        base, nrm = base[good], nrm[good]
        if not len(base):
            return np.empty((0, 2))
    reach = max(3.0, 0.02 * length) + EDGE_WINDOW_PX
    s = np.arange(-reach, reach + 1e-9, PROFILE_STEP_PX)
    pts = base[:, None, :] + s[None, :, None] * nrm[:, None, :]
    # our pixel centres are at +0.5, OpenCV's at 0
    mx = (pts[..., 0] - 0.5).astype(np.float32)
    my = (pts[..., 1] - 0.5).astype(np.float32)
    prof = cv2.remap(
        smooth, mx, my, cv2.INTER_CUBIC, borderMode=cv2.BORDER_CONSTANT, borderValue=(np.nan,)
    ).astype(np.float64)
    grad = np.abs(np.gradient(prof, PROFILE_STEP_PX, axis=1))
    ok = np.isfinite(grad).all(axis=1)
    grad = np.nan_to_num(grad)
    k = grad.argmax(axis=1)
    inner = (k > 0) & (k < len(s) - 1) & ok
    rows = np.arange(len(k))
    peak = grad[rows, k]
    # the centroid of the squared gradient within EDGE_WINDOW_PX of its peak, above the
    # profile's median gradient (the ground's texture): the peak itself snaps towards the pixel
    # grid (an interpolated profile), the centroid much less
    near = np.abs(s[None, :] - s[k][:, None]) <= EDGE_WINDOW_PX
    above = np.clip(grad - np.median(grad, axis=1, keepdims=True), 0, None)
    wgt = np.where(near, above * above, 0.0)
    total = wgt.sum(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        off = (wgt * s[None, :]).sum(axis=1) / total
    # keep the profiles whose peak is clear of the noise (above half the median peak) and
    # whose window lies inside the profile
    strong = peak > 0.5 * np.median(peak[inner]) if inner.any() else inner
    clear = (s[k] - EDGE_WINDOW_PX >= s[0]) & (s[k] + EDGE_WINDOW_PX <= s[-1])
    use = inner & strong & clear & (total > 0)
    return (base + off[:, None] * nrm)[use]


def detect_plate(
    grey: ArrayLike,
    camera: Camera,
    plate: PlateGeometry,
    min_area_px: float = 400.0,
) -> PlateDetection:
    """Find the plate's eight corners at sub-pixel precision (module docstring).

    Parameters
    ----------
    grey : (rows, cols) array_like
        The photo's grey levels (any range).
    camera : Camera
        Its interior orientation (the lens model straightens the edges).
    plate : PlateGeometry
        Only the ratio of the sides is used here.
    min_area_px : float
        Smallest area of the inner square, pixels.

    Returns
    -------
    PlateDetection
    """
    import cv2

    img = np.asarray(grey, dtype=np.float32)
    if img.ndim != 2:
        raise InputError(f"detect_plate needs a single-band image, got shape {img.shape}")
    lo, hi = np.nanpercentile(img, [0.5, 99.5])
    scale = 255.0 / max(float(hi - lo), 1e-6)
    u8 = np.clip((img - lo) * scale, 0, 255).astype(np.uint8)
    quads = _quads(u8, min_area_px)
    if not quads:
        return PlateDetection(False, _t("plate not found: no quadrilateral in the photo"))
    pairs = _pairs(
        quads,
        plate.inner_m / plate.outer_m,
        to_plane=None if camera.is_perspective else (lambda q: plane_from_pixels(q, camera)),
    )
    if not pairs:
        return PlateDetection(
            False,
            _t(
                "only one square: {n} quadrilateral(s), none with a "
                "nested square of the plate's inner/outer ratio",
                n=len(quads),
            ),
        )
    if len(pairs) > 1:
        return PlateDetection(
            False,
            _t("ambiguous: {n} plate-like pairs of squares", n=len(pairs)),
            candidates=len(pairs),
        )
    outer, inner = pairs[0]
    smooth = cast(NDArray[np.float32], cv2.GaussianBlur(img, (0, 0), 1.0))  # depth kept
    lines = []
    rms = np.full(8, np.nan)
    count = np.zeros(8, np.int64)
    f_px = camera.focal_px
    for k, quad in enumerate((outer, inner)):
        for i in range(4):
            pts = _edge_points(
                smooth, quad[i], quad[(i + 1) % 4], None if camera.is_perspective else camera
            )
            uv = plane_from_pixels(pts, camera) if len(pts) else pts
            uv = uv[np.isfinite(uv).all(axis=1)] if len(uv) else uv
            fit = _fit_side(uv)
            if fit is None:
                return PlateDetection(
                    False,
                    _t(
                        "edge fit failed: side {side} has {n} edge points",
                        side=4 * k + i,
                        n=len(uv),
                    ),
                    candidates=1,
                )
            lines.append(fit)
            if camera.is_perspective:
                rms[4 * k + i] = fit[3] * f_px
            else:
                # a fisheye's scale changes across the image: the plane's distance across
                # the line in pixels, at the side's centroid
                jac = plane_to_pixel_jacobian(fit[2][None], camera)[0]
                rms[4 * k + i] = fit[3] * float(np.linalg.norm(jac @ fit[0]))
            count[4 * k + i] = fit[5]
    corners_uv = np.empty((8, 2))
    sig = np.empty(8)
    for k in range(2):
        for i in range(4):
            # corner i lies between side i - 1 (ending at it) and side i (starting at it)
            x, cov = _intersect(lines[4 * k + (i - 1) % 4], lines[4 * k + i])
            corners_uv[4 * k + i] = x
            if camera.is_perspective:
                sig[4 * k + i] = math.sqrt(max(float(np.trace(cov)) / 2.0, 0.0)) * f_px
            else:
                jac = plane_to_pixel_jacobian(x[None], camera)[0]
                var = float(np.trace(jac @ cov @ jac.T)) / 2.0
                sig[4 * k + i] = math.sqrt(max(var, 0.0))
    px = pixels_from_plane(corners_uv, camera)
    if not np.isfinite(px).all():
        return PlateDetection(
            False, _t("edge fit failed: a corner falls outside the camera's field"), candidates=1
        )
    return PlateDetection(True, "", px, sig, rms, count, 1)


# ------------------------------------------------------------------ resection
def photo_azimuth(eo: ArrayLike) -> float:
    """Grid azimuth (degrees, 0-360) of the photo's "up" direction (the camera's y axis) on
    the ground, for a camera looking down.

    >>> round(photo_azimuth([0, 0, 2, 0, 0, math.radians(30)]), 6)
    330.0
    """
    e = np.asarray(eo, dtype=np.float64)
    m = opk_to_matrix(e[3], e[4], e[5])
    up = m[1]  # camera y axis in object coordinates (M rotates object -> camera)
    return math.degrees(math.atan2(up[0], up[1])) % 360.0


@dataclass(frozen=True)
class PlateResection:
    """Orientation of a plate photo in the point's local frame (east, north, up relative to
    the surveyed point, metres; omega, phi, kappa in radians).

    ``turn`` is the quarter turn of the correspondence chosen (image corner k = plate corner
    (k + turn) mod 4) and ``azimuth_misfit_deg`` the difference between the photo azimuth it
    implies and the one given."""

    eo: Array
    std: Array
    sigma0: float
    redundancy: int
    residuals_px: Array
    rejected: NDArray[np.bool_]
    turn: int
    azimuth_misfit_deg: float
    result: object  # the SpaceResection


def resect_plate(
    detection: PlateDetection,
    camera: Camera,
    plate: PlateGeometry,
    photo_azimuth_deg: float = 0.0,
    sigma_px: float | None = None,
) -> PlateResection:
    """Resect the photo from the eight corners (module docstring).

    ``sigma_px``: a-priori sigma of a corner (default: each corner's propagated sigma, at
    least 0.02 px).
    """
    from .pose_start import initial_pose_pnp
    from .resection import ResectionData, ResectionOptions, resect

    if not detection.found:
        raise InputError("resect_plate needs a detected plate")
    obj = plate.corners()
    px = detection.corners_px
    best = None
    for turn in range(4):
        order = np.r_[(np.arange(4) + turn) % 4, 4 + (np.arange(4) + turn) % 4]
        try:
            eo0 = initial_pose_pnp(px, obj[order], camera)
        except Exception:
            continue
        if not np.isfinite(eo0).all() or eo0[2] <= plate.height_m:
            continue
        mis = (photo_azimuth(eo0) - photo_azimuth_deg + 180.0) % 360.0 - 180.0
        if best is None or abs(mis) < abs(best[2]):
            best = (turn, eo0, mis, order)
    if best is None:
        raise InputError("no pose fits the plate's corners")
    turn, eo0, mis, order = best
    sig = np.maximum(detection.sigma_px, 0.02) if sigma_px is None else np.full(8, float(sigma_px))
    data = ResectionData(
        point_ids=tuple(f"corner{k}" for k in range(8)), pixels=px, sigma_px=sig, xyz=obj[order]
    )
    res = resect(data, camera, ResectionOptions(snooping=True), eo0=eo0)
    return PlateResection(
        res.eo.copy(),
        res.std.copy(),
        float(res.sigma0),
        int(res.redundancy),
        res.point_v.copy(),
        res.point_rejected.copy(),
        turn,
        float(mis),
        res,
    )
