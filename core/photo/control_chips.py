"""Control chips: a ground photo of a surveyed point rectified onto the point's horizontal
plane at the aerial images' GSD, north up (Berveglieri & Tommaselli 2014).

Per point (:func:`make_chip`):

1. the plate photo's plate is detected and the photo resected from its eight corners
   (:mod:`.control_plate`), in the point's local frame (east, north, up relative to the
   surveyed point, metres, along the axes of the mapping grid; over the few metres a ground
   photo covers, the grid's scale factor and convergence change nothing that matters: a scale
   error of 4e-4 moves a point 1 m away by 0.4 mm);
2. the plate-free photo, taken from the same spot, is matched to the plate photo with SIFT
   (Lowe 2004: OpenCV's detector and descriptors, nearest-neighbour ratio test), the matches
   filtered by RANSAC on a homography between the two photos' ray planes (z = -1 of each
   camera frame: exact for a pure rotation of the camera and for a planar ground, whatever
   the lens; a homography between the fisheye photos themselves would not be, so a fisheye
   photo is registered on its rays, not on its pixels; rays at or beyond 90 degrees off the
   axis, which do not meet that plane, are left out; the RANSAC threshold is ``ransac_px``
   over the focal length in pixels, the pixel tolerance on the axis: a fisheye's ray plane
   stretches off the axis, so there it is tighter in pixels, e.g. ``ransac_px cos^2(theta)``
   radially for the equidistant projection), then the inliers' rays in the plate photo are
   intersected with the plane Z = Z_point and the plate-free photo is resected from those
   ground points with the project's resection (:func:`core.photo.resection.space_resection`,
   data snooping, any central projection), started from the plate photo's pose;
3. the chip: a north-up grid of ``size`` x ``size`` cells of ``gsd`` metres on the plane
   Z = Z_point, centred on the surveyed point, each cell the mean of ``s`` x ``s`` sub-samples
   (``s`` from the ratio of the chip GSD to the photo's ground pixel at the principal point,
   at most 8; a fisheye's pixels cover more ground off the axis, so this errs on the side of
   more sub-samples) projected into the plate-free photo with its orientation and the
   camera's own projection, fisheye included (:func:`core.geometry.collinearity.project`),
   and read bilinearly. With ``size`` cells the surveyed point is at chip pixel
   ``(size / 2, size / 2)`` (pixel corners at integers, the first pixel's centre at (0.5,
   0.5)): the geotransform puts it at its map X, Y.

When only the plate photo is given and ``from_plate_photo`` is set, step 2 is skipped and the
chip is made from the plate photo (the plate then hides the ground around the point: the
chip shows the plate).

Reasons a point gets no chip: the plate not found (with the detector's reason), the
resection's sigma0 above ``max_sigma0``, too few SIFT matches (below ``min_matches`` RANSAC
inliers), the free photo's resection failing, or the chip falling partly outside the photo
(``min_valid`` of its cells must be seen).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import ConvergenceError, InputError, NotObservableError
from ..geometry.camera import Camera
from ..geometry.collinearity import image_rays, project_with_status
from ..i18n import mark as _t
from .chip_options import ChipOptions
from .control_plate import (
    PlateDetection,
    PlateGeometry,
    PlateResection,
    detect_plate,
    plane_from_pixels,
    resect_plate,
)

#: catalogue context of this module's ``_t("...")`` sentences (``make i18n``): the reports'
TR_CONTEXT = "Report"

Array = NDArray[np.float64]

__all__ = [
    "ChipOptions",
    "ChipResult",
    "SiftRegistration",
    "chip_grid",
    "make_chip",
    "rectify_to_plane",
    "register_sift",
]

#: Most sub-samples per chip cell side.
MAX_SUBSAMPLES = 8


@dataclass(frozen=True)
class SiftRegistration:
    """SIFT matches of a moved photo to a reference photo: ``ref_px``, ``moved_px`` (M, 2)
    the RANSAC inliers; ``matches`` after the ratio test; ``homography`` (3, 3) between the
    ray planes (reference -> moved)."""

    ref_px: Array
    moved_px: Array
    matches: int
    homography: Array


@dataclass(frozen=True)
class ChipResult:
    """One point's chip and what was measured on the way (module docstring).

    ``chip`` is (size, size) float32 grey levels, NaN where no photo pixel; ``geotransform``
    GDAL order in the mapping CRS; ``free_eo`` the orientation of the photo the chip was made
    from (local frame); ``status`` "ok" or "failed" with ``reason``.
    """

    point_id: str
    status: str
    reason: str = ""
    detection: PlateDetection | None = None
    plate: PlateResection | None = None
    sift: SiftRegistration | None = None
    free_eo: Array | None = None
    free_std: Array | None = None
    free_sigma0: float = math.nan
    source: str = ""
    chip: NDArray[np.float32] | None = None
    geotransform: tuple[float, ...] = ()
    valid_fraction: float = math.nan
    subsamples: int = 0
    notes: tuple[str, ...] = field(default_factory=tuple)


def chip_grid(xy: ArrayLike, gsd_m: float, size_px: int) -> tuple[float, ...]:
    """GDAL geotransform of the chip centred on the point ``xy`` (map X, Y).

    >>> chip_grid([1000.0, 2000.0], 0.1, 5)
    (999.75, 0.1, 0.0, 2000.25, 0.0, -0.1)
    """
    x, y = (float(v) for v in np.asarray(xy, dtype=float).reshape(2))
    half = size_px * gsd_m / 2.0
    return (x - half, float(gsd_m), 0.0, y + half, 0.0, -float(gsd_m))


def _grey_f32(img: ArrayLike) -> NDArray[np.float32]:
    a = np.asarray(img, dtype=np.float32)
    if a.ndim != 2:
        raise InputError(f"need a single-band (grey) photo, got shape {a.shape}")
    return a


def register_sift(
    reference: ArrayLike,
    moved: ArrayLike,
    camera: Camera,
    ratio: float = 0.75,
    ransac_px: float = 2.0,
    features: int = 8000,
) -> SiftRegistration:
    """SIFT matches of ``moved`` to ``reference`` (same camera), ratio test, RANSAC on the
    homography of the ray planes (module docstring). Pixels in the project's convention."""
    import cv2

    def u8(a: NDArray[np.float32]) -> NDArray[np.uint8]:
        lo, hi = np.nanpercentile(a, [0.5, 99.5])
        return np.clip((a - lo) * (255.0 / max(float(hi - lo), 1e-6)), 0, 255).astype(np.uint8)

    # cv2.SIFT_create (OpenCV >= 4.4) is missing from OpenCV's stubs
    sift = cv2.SIFT_create(nfeatures=int(features))  # type: ignore[attr-defined]
    ka, da = sift.detectAndCompute(u8(_grey_f32(reference)), None)
    kb, db = sift.detectAndCompute(u8(_grey_f32(moved)), None)
    empty = SiftRegistration(np.empty((0, 2)), np.empty((0, 2)), 0, np.full((3, 3), np.nan))
    if da is None or db is None or len(ka) < 2 or len(kb) < 2:
        return empty
    knn = cv2.BFMatcher(cv2.NORM_L2).knnMatch(da, db, k=2)
    good = [m[0] for m in knn if len(m) == 2 and m[0].distance < ratio * m[1].distance]
    if len(good) < 4:
        return SiftRegistration(np.empty((0, 2)), np.empty((0, 2)), len(good), empty.homography)
    # OpenCV's keypoints put the first pixel's centre at 0, ours at 0.5
    pa = np.array([ka[m.queryIdx].pt for m in good], dtype=np.float64) + 0.5
    pb = np.array([kb[m.trainIdx].pt for m in good], dtype=np.float64) + 0.5
    ua, ub = plane_from_pixels(pa, camera), plane_from_pixels(pb, camera)
    ok = np.isfinite(ua).all(axis=1) & np.isfinite(ub).all(axis=1)
    pa, pb, ua, ub = pa[ok], pb[ok], ua[ok], ub[ok]
    if len(pa) < 4:
        return SiftRegistration(np.empty((0, 2)), np.empty((0, 2)), len(good), empty.homography)
    h, mask = cv2.findHomography(ua, ub, cv2.RANSAC, ransac_px / camera.focal_px)
    if h is None:
        return SiftRegistration(np.empty((0, 2)), np.empty((0, 2)), len(good), empty.homography)
    inl = mask.ravel().astype(bool)
    return SiftRegistration(pa[inl], pb[inl], len(good), cast(Array, h))  # 3 x 3 float64


def _on_plane(pixels: Array, eo: Array, camera: Camera, z: float) -> Array:
    """Rays of ``pixels`` intersected with the plane Z = z (NaN where they miss it)."""
    o, d = image_rays(pixels, eo, camera)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (z - o[:, 2]) / d[:, 2]
    p = o + t[:, None] * d
    p[~(t > 0)] = np.nan
    return p


def ground_pixel_m(camera: Camera, eo: ArrayLike, z: float) -> float:
    """Ground size (m) of a photo pixel at the principal point on the plane Z = z."""
    e = np.asarray(eo, dtype=np.float64)
    c = np.array(camera.principal_point_px)
    p = _on_plane(np.array([c, c + [1.0, 0.0], c + [0.0, 1.0]]), e, camera, z)
    return float(0.5 * (np.linalg.norm(p[1] - p[0]) + np.linalg.norm(p[2] - p[0])))


def rectify_to_plane(
    photo: ArrayLike,
    camera: Camera,
    eo: ArrayLike,
    geotransform: tuple[float, ...],
    size_px: int,
    origin_xy: ArrayLike = (0.0, 0.0),
    z: float = 0.0,
    subsamples: int | None = None,
) -> tuple[NDArray[np.float32], int]:
    """Resample ``photo`` onto a north-up grid on the plane Z = ``z``.

    Parameters
    ----------
    photo : (rows, cols) grey levels
    eo : (6,) orientation in a frame whose origin is ``origin_xy`` of the grid's map frame
        (the point's local frame: map X, Y minus ``origin_xy``), metres and radians.
    geotransform : GDAL order, map coordinates; ``size_px`` x ``size_px`` cells.
    subsamples : per cell side (None: from the chip GSD over the photo's ground pixel).

    Returns
    -------
    chip : (size, size) float32, NaN where a sub-sample falls outside the photo
    subsamples : int
    """
    import cv2

    img = _grey_f32(photo)
    e = np.asarray(eo, dtype=np.float64)
    x0, g, _, y0, _, _ = geotransform
    ox, oy = (float(v) for v in np.asarray(origin_xy, dtype=float).reshape(2))
    if subsamples is None:
        ratio = g / max(ground_pixel_m(camera, e, z), 1e-12)
        subsamples = int(min(MAX_SUBSAMPLES, max(1, math.ceil(ratio))))
    s = int(subsamples)
    n = int(size_px)
    f = (np.arange(n * s) + 0.5) / s  # sub-sample centres, in cells
    xs = x0 - ox + f * g
    ys = y0 - oy - f * g
    chip = np.empty((n, n), np.float32)
    rows_per_block = max(1, (1 << 20) // (n * s * s))  # about a million sub-samples a block
    for r0 in range(0, n, rows_per_block):
        r1 = min(n, r0 + rows_per_block)
        gx, gy = np.meshgrid(xs, ys[r0 * s : r1 * s])
        pts = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, z)])
        px, front, conv = project_with_status(pts, e, camera)
        good = front & conv & camera.in_frame(np.nan_to_num(px, nan=-1.0), margin_px=0.5)
        shape = gx.shape
        mx = np.where(good, px[:, 0] - 0.5, -1e6).astype(np.float32).reshape(shape)
        my = np.where(good, px[:, 1] - 0.5, -1e6).astype(np.float32).reshape(shape)
        sub = cv2.remap(
            img, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=(np.nan,)
        )
        # a cell with any sub-sample outside the photo is NaN (no partial cells)
        chip[r0:r1] = sub.reshape(r1 - r0, s, n, s).mean(axis=(1, 3))
    return chip, s


def make_chip(
    point_id: str,
    point_xyz: ArrayLike,
    plate_photo: ArrayLike,
    free_photo: ArrayLike | None,
    camera: Camera,
    plate: PlateGeometry,
    options: ChipOptions | None = None,
    photo_azimuth_deg: float = 0.0,
) -> ChipResult:
    """Detect, resect, register and rectify for one point (module docstring).

    Parameters
    ----------
    point_id : str
    point_xyz : (3,) surveyed point, mapping CRS (metres)
    plate_photo, free_photo : (rows, cols) grey photos; ``free_photo`` None: the chip comes
        from the plate photo when ``options.from_plate_photo``, else the point fails.
    camera : Camera of the ground photos
    plate : PlateGeometry
    photo_azimuth_deg : approximate grid azimuth of the photos' "up" direction (+-45 degrees)

    Returns
    -------
    ChipResult
        Status "failed" with the reason instead of raising for what the data cause.
    """
    opt = options or ChipOptions()
    p = np.asarray(point_xyz, dtype=np.float64).reshape(3)
    ref = _grey_f32(plate_photo)
    gt = chip_grid(p[:2], opt.gsd_m, opt.size_px)

    def fail(reason: str, **kw) -> ChipResult:
        return ChipResult(point_id, "failed", reason, geotransform=gt, **kw)

    det = detect_plate(ref, camera, plate)
    if not det.found:
        return fail(det.reason, detection=det)
    try:
        pr = resect_plate(
            det, camera, plate, photo_azimuth_deg, sigma_px=opt.corner_sigma_px or None
        )
    except (ConvergenceError, NotObservableError, InputError) as exc:
        return fail(_t("plate resection failed: {error}", error=str(exc)), detection=det)
    if not (pr.sigma0 <= opt.max_sigma0):
        return fail(
            _t(
                "resection sigma0 {sigma0:.3g} > {maximum:g}",
                sigma0=pr.sigma0,
                maximum=opt.max_sigma0,
            ),
            detection=det,
            plate=pr,
        )
    notes = []
    if free_photo is None:
        if not opt.from_plate_photo:
            return fail(
                _t("no plate-free photo (allow the chip from the plate photo to make it anyway)"),
                detection=det,
                plate=pr,
            )
        source_img, eo, std, s0, reg, source = ref, pr.eo, pr.std, pr.sigma0, None, "plate"
        notes.append(_t("chip from the plate photo: the plate hides the ground at the point"))
    else:
        from .resection import space_resection

        free = _grey_f32(free_photo)
        reg = register_sift(ref, free, camera, opt.sift_ratio, opt.ransac_px, opt.sift_features)
        if len(reg.ref_px) < opt.min_matches:
            return fail(
                _t(
                    "too few SIFT matches: {inliers} RANSAC inliers of {matches} "
                    "matches (< {minimum})",
                    inliers=len(reg.ref_px),
                    matches=reg.matches,
                    minimum=opt.min_matches,
                ),
                detection=det,
                plate=pr,
                sift=reg,
            )
        ground = _on_plane(reg.ref_px, pr.eo, camera, 0.0)
        ok = np.isfinite(ground).all(axis=1)
        try:
            fr = space_resection(
                reg.moved_px[ok], ground[ok], camera, eo0=pr.eo, sigma_px=opt.match_sigma_px
            )
        except (ConvergenceError, NotObservableError, InputError) as exc:
            return fail(
                _t("plate-free photo resection failed: {error}", error=str(exc)),
                detection=det,
                plate=pr,
                sift=reg,
            )
        eo, std, s0, source = fr.eo, fr.std, float(fr.adjustment.sigma0), "free"
        source_img = free
        if len(fr.rejected):
            notes.append(_t("{n} SIFT matches rejected by data snooping", n=len(fr.rejected)))
    chip, s = rectify_to_plane(source_img, camera, eo, gt, opt.size_px, origin_xy=p[:2], z=0.0)
    valid = float(np.isfinite(chip).mean())
    kw: dict[str, Any]  # ChipResult's fields
    kw = dict(
        detection=det,
        plate=pr,
        sift=reg,
        free_eo=np.asarray(eo).copy(),
        free_std=np.asarray(std).copy(),
        free_sigma0=float(s0),
        source=source,
        chip=chip,
        valid_fraction=valid,
        subsamples=s,
        notes=tuple(notes),
    )
    if valid < opt.min_valid:
        return ChipResult(
            point_id,
            "failed",
            _t(
                "the photo sees {valid:.1f} % of the chip (< {minimum:g} %)",
                valid=100 * valid,
                minimum=100 * opt.min_valid,
            ),
            geotransform=gt,
            **kw,
        )
    return ChipResult(point_id, "ok", "", geotransform=gt, **kw)
