"""Automatic location of ground control points in oriented images from control chips
(the chip-to-image matching of Gruen 1985 least-squares matching, as in automated GCP
measurement chains).

A control chip is a north-up grey image of the ground around a surveyed point, rectified onto
the horizontal plane ``Z = Z_point`` of the mapping CRS, with a geotransform that places the
point at its X, Y (file format: :mod:`core.io.chips`). For each point and image:

1. **Prediction**: the point is projected with the image's EO and camera (local ENU frame,
   lens model included). Outside the frame (less than half a template from its border):
   ``outside image``.
2. **Search window**: the EO covariance (sigmas of X, Y, Z, omega, phi, kappa; correlations
   ignored) is propagated to the pixel with the numerical Jacobian of the projection; the
   search ellipse is ``k`` (``search_sigmas``, default 3) times that 2 x 2 covariance, the
   window its bounding box, at least ``min_search_px`` (default 5) and at most
   ``max_search_px`` (default 150) pixels half-width. Without EO sigmas the half-width is
   ``default_search_px`` (default 25 px) in both directions.
3. **Chip geometry -> image geometry**: the chip plane maps to the image by a homography
   (lens distortion added); over a template (tens of pixels) it is affine to far below
   0.001 px for a frame camera, so its linearisation at the point, the 2 x 2 Jacobian ``J``
   of chip pixels -> image pixels (central differences of the exact projection of chip
   pixels +-5 px from the point), is used. The chip template (the adaptive size of
   :mod:`core.photo.template_matching`) is warped into image geometry with ``J`` (bicubic)
   for the NCC search; least-squares matching then works from the chip's own pixels with
   ``J`` as the start of its affine, so no image is resampled before LSM and LSM's 6 affine
   parameters absorb what the EO got wrong in scale, rotation and tilt. A fisheye camera
   (:mod:`core.geometry.projection`) goes through the same steps with its own projection;
   its image of the ground curves over a template (0.06-0.24 px off the affine 10 chip
   pixels from the point, 35-50 degrees off the axis of a 1 mm fisheye at 15 m), so the
   mean over the template of the exact projection of its pixels minus their affine image
   is taken off the match (:func:`_curvature_shift`): noise-free matches 0.002-0.017 px from
   the truth, 0.01-0.05 px without it (tests/core/test_locate_fisheye.py).
4. **NCC** in the search window (peak below ``min_ncc``, default 0.6: ``low correlation
   (NCC)``; peak on the window's border: ``NCC peak on the search border``; outside the search
   ellipse: ``outside the search ellipse``), then **LSM** from the NCC position
   (:mod:`core.photo.least_squares_matching`; its reasons: no texture, left the search
   window, not converged, moved too far, low correlation, sigma too large).
5. **Transfer**: when ``transfer`` is on, each point's best chip match (smallest sigma) is
   the master; in every other image where the chip match failed for a reason other than the
   point being outside it, a patch of the master image around the match is matched by NCC +
   LSM (image to image, start affine ``J_i J_master^-1``). Its sigma adds the master's,
   propagated through the affine. Through a fisheye camera the master-to-image map curves
   over the patch like the chip-to-image one, and the same correction is taken off
   (:func:`_transfer_curvature_shift`): a transfer into an image 50 degrees off the axis
   0.02-0.04 px from the truth, 0.16-0.26 px without it (tests/core/test_locate_fisheye.py).

Every (point, image) pair whose projection is inside the image gets a row in the report with
its status and reason; a point outside every image, or whose chip has no texture, gets one
row saying so. Nothing is guessed: a rejected pair gives no observation.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError, stop_if_asked
from ..geometry.camera import Camera
from ..geometry.collinearity import project_with_status
from ..geometry.frames import LocalFrame, MappingFrame
from ..geometry.rotations import matrix_to_opk
from ..i18n import mark as _t
from .least_squares_matching import affine_start, lsm_in_image
from .matching_options import LocateOptions
from .observations import ImageObservations
from .orientation import ExteriorOrientationTable, eo_map_to_local
from .template_matching import choose_template_size, ncc_search

#: catalogue context of this module's ``_t("...")`` sentences (``make i18n``): the reports'
TR_CONTEXT = "Report"

Array = NDArray[np.float64]

__all__ = [
    "ControlChip",
    "LocateOptions",
    "LocatedPair",
    "LocationResult",
    "locate_control_points",
]


@dataclass(frozen=True)
class ControlChip:
    """A control chip (module docstring).

    point_id : the control point's id (the chip file's stem).
    grey : (rows, cols) float grey values (NaN: no data).
    geotransform : GDAL order (x0, dx, 0, y0, 0, dy), north up, mapping CRS.
    xyz : (3,) the surveyed point, mapping CRS.
    """

    point_id: str
    grey: Array
    geotransform: tuple[float, ...]
    xyz: Array

    def __post_init__(self) -> None:
        gt = tuple(float(v) for v in self.geotransform)
        if len(gt) != 6 or gt[2] != 0 or gt[4] != 0 or gt[1] <= 0 or gt[5] >= 0:
            raise InputError(f"chip {self.point_id}: not a north-up raster (geotransform {gt})")
        object.__setattr__(self, "geotransform", gt)
        object.__setattr__(self, "grey", np.asarray(self.grey, dtype=np.float64))
        object.__setattr__(self, "xyz", np.asarray(self.xyz, dtype=np.float64).reshape(3))

    @property
    def point_array(self) -> tuple[float, float]:
        """(col, row) array coordinates of the point in the chip (pixel centres at integers)."""
        gt = self.geotransform
        return ((self.xyz[0] - gt[0]) / gt[1] - 0.5, (self.xyz[1] - gt[3]) / gt[5] - 0.5)

    def array_to_map(self, cr: Array) -> Array:
        """(N, 2) chip array (col, row) -> (N, 3) map points on the plane Z = Z_point."""
        gt = self.geotransform
        cr = np.asarray(cr, dtype=np.float64).reshape(-1, 2)
        x = gt[0] + (cr[:, 0] + 0.5) * gt[1]
        y = gt[3] + (cr[:, 1] + 0.5) * gt[5]
        return np.column_stack([x, y, np.full(len(cr), self.xyz[2])])


@dataclass(frozen=True)
class LocatedPair:
    """One (point, image) row of the report. Pixels: corner convention (observation CSV).

    status : "ok" or "rejected" (or "outside" for a point outside every image).
    reason : why it was rejected ("" when ok).
    source : "chip" or "transfer from <image>".
    """

    point_id: str
    image_id: str
    status: str
    reason: str
    source: str = "chip"
    col: float = math.nan
    row: float = math.nan
    sigma_col: float = math.nan
    sigma_row: float = math.nan
    sigma0: float = math.nan
    ncc: float = math.nan
    lsm_correlation: float = math.nan
    template_px: int = 0
    predicted_col: float = math.nan
    predicted_row: float = math.nan
    search_px: tuple[float, float] = (math.nan, math.nan)
    iterations: int = 0
    chip_patch: Array | None = None
    image_patch: Array | None = None


@dataclass(frozen=True)
class LocationResult:
    """All report rows and the accepted observations (type ``control``, point_id = control
    id)."""

    pairs: tuple[LocatedPair, ...]
    observations: ImageObservations

    def counts(self) -> dict[str, int]:
        """Number of report rows per status."""
        out: dict[str, int] = {}
        for p in self.pairs:
            out[p.status] = out.get(p.status, 0) + 1
        return out


#: Reads an image window: (image_id, col0, row0, width, height) -> (height, width) grey
#: float array, NaN outside the image.
WindowReader = Callable[[str, int, int, int, int], Array]


def _window(read: WindowReader, image_id: str, centre: Array, half: tuple[int, int]) -> tuple:
    c0 = math.floor(centre[0]) - half[0]
    r0 = math.floor(centre[1]) - half[1]
    win = read(image_id, c0, r0, 2 * half[0] + 1, 2 * half[1] + 1)
    return np.asarray(win, dtype=np.float64), np.array([c0, r0], dtype=np.float64)


def _pixel_jacobian(points_local: Array, eo6: Array, camera: Camera) -> Array:
    """(N, 2, 6) d pixel / d EO by central differences (metres and radians)."""
    steps = np.array([0.01, 0.01, 0.01, 1e-6, 1e-6, 1e-6])
    jac = np.zeros((len(points_local), 2, 6))
    for j in range(6):
        d = np.zeros(6)
        d[j] = steps[j]
        plus = project_with_status(points_local, eo6 + d, camera)[0]
        minus = project_with_status(points_local, eo6 - d, camera)[0]
        jac[:, :, j] = (plus - minus) / (2 * steps[j])
    return jac


def locate_control_points(
    chips: Sequence[ControlChip],
    eo: ExteriorOrientationTable,
    camera: Camera,
    read_window: WindowReader,
    eo_sigmas: Array | None = None,
    options: LocateOptions | None = None,
    *,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> LocationResult:
    """Locate every chip's point in every image (module docstring).

    Parameters
    ----------
    chips : control chips (mapping CRS of ``eo``).
    eo : orientations of the images, mapping CRS.
    camera : the camera of every image.
    read_window : image window reader (see :data:`WindowReader`); pixels outside the image NaN.
    eo_sigmas : (N, 6) sigmas of X, Y, Z (m) and omega, phi, kappa (rad) per image, or None.
    options : LocateOptions

    Returns
    -------
    LocationResult
    """
    import cv2

    opt = options or LocateOptions()
    mapping = MappingFrame.from_user_input(eo.crs_wkt)
    if not chips:
        raise InputError("no control chips given")
    all_xyz = np.array([c.xyz for c in chips])
    local = LocalFrame.at_map_point(mapping, all_xyz.mean(axis=0))
    centres, m_local = eo_map_to_local(eo.xyz, eo.opk, local)
    om, ph, ka = matrix_to_opk(m_local)
    eo_local = np.column_stack([centres, om, ph, ka])
    pairs: list[LocatedPair] = []
    obs_rows: list[tuple[str, str, float, float, float]] = []
    for p_n, chip in enumerate(chips):
        stop_if_asked(should_stop, "locating control points")
        if progress is not None:
            progress(p_n / len(chips))
        pid = chip.point_id
        pc = chip.point_array
        size = choose_template_size(chip.grey, pc, opt.texture)
        if not size.ok or not np.isfinite(chip.grey).all():
            why = size.reason if not size.ok else _t("chip has no-data pixels")
            pairs.append(
                LocatedPair(
                    pid, "", "rejected", _t("chip refused: {why}", why=why), template_px=size.size
                )
            )
            continue
        h = size.size // 2
        ci, ri = int(np.rint(pc[0])), int(np.rint(pc[1]))
        template = chip.grey[ri - h : ri + h + 1, ci - h : ci + h + 1]
        ref = (pc[0] - (ci - h), pc[1] - (ri - h))
        pts_local, pix, jac_chip, inside, inside_margin = _chip_in_images(
            chip, pc, h, local, eo_local, camera
        )
        if not inside.any():
            pairs.append(
                LocatedPair(pid, "", "outside", _t("outside every image"), template_px=size.size)
            )
            continue
        results: dict[int, LocatedPair] = {}
        for i in np.flatnonzero(inside).tolist():
            iid = eo.image_id[i]
            pred = pix[i, 0]
            base: dict[str, Any]  # LocatedPair's fields
            base = {
                "template_px": size.size,
                "predicted_col": float(pred[0]),
                "predicted_row": float(pred[1]),
            }
            if not inside_margin[i]:
                results[i] = LocatedPair(
                    pid, iid, "rejected", _t("template partly outside the image"), **base
                )
                continue
            half_f, cov_search = _search_ellipse(opt, eo_sigmas, i, pts_local, eo_local, camera)
            base["search_px"] = (float(half_f[0]), float(half_f[1]))
            jac = jac_chip[i]
            m = _match(
                chip_template=template,
                ref=ref,
                jac=jac,
                image_id=iid,
                pred_corner=pred,
                half_search=half_f,
                read=read_window,
                opt=opt,
                cv2=cv2,
            )
            if not camera.is_perspective and np.isfinite(m.col):
                shift = _curvature_shift(chip, pc, h, local, eo_local[i], camera, jac, pred)
                m.col, m.row = m.col - shift[0], m.row - shift[1]
            results[i] = _finish(pid, iid, m, pred, cov_search, base, "chip")
        if opt.transfer:
            curved = None if camera.is_perspective else (chip, pc, local, eo_local, camera)
            _transfer_failed(results, jac_chip, pix, eo, read_window, size.size, opt, cv2, curved)
        for i in sorted(results):
            r = results[i]
            pairs.append(r)
            if r.status == "ok":
                s = max(math.hypot(r.sigma_col, r.sigma_row) / math.sqrt(2), opt.sigma_floor_px)
                obs_rows.append((r.image_id, pid, r.col, r.row, s))
    if progress is not None:
        progress(1.0)
    if obs_rows:
        img, pid_, c, rr, sig = zip(*obs_rows)
        obs = ImageObservations.from_arrays(
            img, pid_, np.column_stack([c, rr]), sig, ["control"] * len(img), [""] * len(img)
        )
    else:
        obs = ImageObservations.from_arrays([], [], np.zeros((0, 2)), np.zeros(0), [], [])
    return LocationResult(tuple(pairs), obs)


def _chip_in_images(
    chip: ControlChip, pc, h: int, local: LocalFrame, eo_local: Array, camera: Camera
):
    """The chip's point and 4 chip pixels +-5 px around it in every image at once: (their
    local coordinates (5, 3), their pixels (n_img, 5, 2), the image-per-chip-pixel Jacobians
    (n_img, 2, 2), the images the point falls in, those that also hold the whole template of
    half-size ``h`` chip pixels)."""
    offsets = np.array([[0, 0], [5, 0], [-5, 0], [0, 5], [0, -5]], dtype=float)
    pts_local = local.map_to_enu(chip.array_to_map(np.asarray(pc) + offsets))
    n_img = len(eo_local)
    pix = np.full((n_img, 5, 2), np.nan)
    front = np.zeros(n_img, dtype=bool)
    for i in range(n_img):
        px, inf, conv = project_with_status(pts_local, eo_local[i], camera)
        pix[i] = px
        front[i] = bool(inf.all() and conv.all())
    jac_chip = np.stack(
        [(pix[:, 1] - pix[:, 2]) / 10.0, (pix[:, 3] - pix[:, 4]) / 10.0], axis=2
    )  # (n_img, 2 image, 2 chip)
    reach = np.abs(jac_chip).sum(axis=2).max(axis=1) * h if n_img else np.zeros(0)
    inside = front & camera.in_frame(pix[:, 0], margin_px=0.0)
    inside &= np.isfinite(reach)
    inside_margin = inside & (pix[:, 0, 0] - reach >= 0) & (pix[:, 0, 1] - reach >= 0)
    inside_margin &= pix[:, 0, 0] + reach <= camera.width_px
    inside_margin &= pix[:, 0, 1] + reach <= camera.height_px
    return pts_local, pix, jac_chip, inside, inside_margin


def _curvature_shift(
    chip: ControlChip, pc, h: int, local: LocalFrame, eo6: Array, camera: Camera, jac, pred
) -> Array:
    """What the affine of least-squares matching puts into the point's position where the
    chip's image is curved (a fisheye camera): the mean, over the template's pixels, of the
    exact projection of each chip pixel minus its affine image ``pred + J u`` (u its offset
    from the point, chip pixels), pixels (2,). The affine that fits the curved image best
    over a symmetric template is offset from the tangent one by about that mean."""
    pc = np.asarray(pc, dtype=np.float64)
    u = _patch_offsets(h, np.rint(pc) - pc)  # about the template's centre pixel
    pts = local.map_to_enu(chip.array_to_map(pc + u))
    px = project_with_status(pts, eo6, camera)[0]
    return _finite_mean(px - (np.asarray(pred, dtype=np.float64) + u @ np.asarray(jac).T))


def _patch_offsets(h: int, centre: Array) -> Array:
    """(n, 2) offsets of a (2h + 1)^2 patch's pixels from a point at ``centre`` from the
    patch's centre pixel (pixels, col row)."""
    k = np.arange(-h, h + 1, dtype=np.float64)
    uu, vv = np.meshgrid(k, k)
    return np.column_stack([uu.ravel(), vv.ravel()]) + centre


def _finite_mean(resid: Array) -> Array:
    """Mean of the finite rows of ``resid`` (n, 2); zeros when none is finite."""
    good = np.isfinite(resid).all(axis=1)
    return resid[good].mean(axis=0) if good.any() else np.zeros(2)


def _transfer_curvature_shift(
    chip: ControlChip,
    pc,
    local: LocalFrame,
    eo_master: Array,
    eo_i: Array,
    camera: Camera,
    jac_master: Array,
    pred_master: Array,
    m_array: Array,
    ci: int,
    ri: int,
    h: int,
    jac: Array,
) -> Array:
    """:func:`_curvature_shift` of a transfer: the mean, over the master image's patch
    (centre pixel ``ci, ri``, half side ``h``, array coordinates), of the exact image in image
    i of each patch pixel (its ray to the chip's plane, found by Newton steps on the chip's
    pixels from the master's projection of them) minus its affine image ``T(0) + J u`` (u its
    offset from the master's match ``m_array``, ``J`` the transfer's start affine), pixels (2,).
    Through a fisheye camera the master-to-image map curves over the patch like the
    chip-to-image one, and the affine of least-squares matching is offset by that mean."""
    m_array = np.asarray(m_array, dtype=np.float64)
    u = _patch_offsets(h, np.array([ci, ri]) - m_array)
    u = np.vstack([np.zeros((1, 2)), u])  # the match itself first: T(0)
    target = m_array + 0.5 + u  # master pixels, corner convention
    jinv = np.linalg.inv(jac_master)
    c = np.asarray(pc, dtype=np.float64) + (target - pred_master) @ jinv.T  # chip pixels
    for _ in range(8):  # the chip-to-master map is nearly affine: a few fixed-slope steps
        px = project_with_status(local.map_to_enu(chip.array_to_map(c)), eo_master, camera)[0]
        step = (target - px) @ jinv.T
        c = c + np.where(np.isfinite(step), step, 0.0)
        if not np.nanmax(np.abs(step)) > 1e-9:
            break
    exact = project_with_status(local.map_to_enu(chip.array_to_map(c)), eo_i, camera)[0]
    if not np.isfinite(exact[0]).all():
        return np.zeros(2)
    return _finite_mean(exact[1:] - (exact[0] + u[1:] @ np.asarray(jac).T))


def _search_ellipse(
    opt: LocateOptions,
    eo_sigmas: Array | None,
    i: int,
    pts_local: Array,
    eo_local: Array,
    camera: Camera,
) -> tuple[Array, Array]:
    """The search half-sizes (col, row pixels) in image ``i`` and the search covariance
    (pixels^2): from the EO sigmas propagated to the image when given, else the defaults."""
    if eo_sigmas is not None:
        jeo = _pixel_jacobian(pts_local[:1], eo_local[i], camera)[0]
        cov = jeo @ np.diag(np.asarray(eo_sigmas[i], float) ** 2) @ jeo.T
        half_f = opt.search_sigmas * np.sqrt(np.diag(cov))
        cov_search = cov * opt.search_sigmas**2
    else:
        half_f = np.full(2, opt.default_search_px)
        cov_search = np.diag(half_f**2)
    half_f = np.clip(half_f, opt.min_search_px, opt.max_search_px)
    cov_search = cov_search + np.diag(np.full(2, opt.min_search_px**2))
    return half_f, cov_search


def _transfer_failed(
    results: dict,
    jac_chip: Array,
    pix: Array,
    eo: ExteriorOrientationTable,
    read_window: WindowReader,
    size_px: int,
    opt: LocateOptions,
    cv2,
    curved: tuple | None = None,
) -> None:
    """Transfer: the images where the chip failed (not for being outside the image) matched
    again from the best located image (smallest sigma); ``results`` updated in place.
    ``curved``: (chip, its point's array coordinates, local frame, local EO, camera) of a
    fisheye camera, whose transferred matches are corrected like the chip's
    (:func:`_transfer_curvature_shift`); None for a perspective one."""
    good = [i for i, r in results.items() if r.status == "ok"]
    if good:
        master = min(good, key=lambda i: max(results[i].sigma_col, results[i].sigma_row))
        mres = results[master]
        for i, r in list(results.items()):
            if r.status == "ok" or "outside the image" in r.reason:
                continue
            t = _transfer(
                mres,
                master,
                i,
                jac_chip,
                pix,
                eo.image_id,
                read_window,
                size_px,
                opt,
                cv2,
                r,
                curved,
            )
            if t is not None:
                results[i] = t


@dataclass
class _Match:
    reason: str = ""
    col: float = math.nan  # image array coordinates
    row: float = math.nan
    cov: Array | None = None
    sigma0: float = math.nan
    ncc: float = math.nan
    corr: float = math.nan
    iterations: int = 0
    chip_patch: Array | None = None
    image_patch: Array | None = None


def _match(
    chip_template, ref, jac, image_id, pred_corner, half_search, read, opt, cv2, ncc_template=None
) -> _Match:
    """NCC (template warped into image geometry) then LSM of the template in the image."""
    m, n = chip_template.shape
    # image-geometry template of side s' centred on the point
    reach = np.abs(jac).sum(axis=1) * (max(m, n) // 2)
    hs = math.ceil(float(reach.min()))  # inside the warped chip in both directions
    hs = max(hs, 3)
    side = 2 * hs + 1
    jinv = np.linalg.inv(jac)
    # dst (x, y) in patch array coords -> template array coords: ref + Jinv ((x, y) - hs)
    warp = np.hstack([jinv, (np.asarray(ref) - jinv @ np.array([hs, hs]))[:, None]])
    tmpl_img = cv2.warpAffine(
        np.ascontiguousarray(chip_template, dtype=np.float32),
        warp.astype(np.float64),
        (side, side),
        flags=cv2.INTER_CUBIC | cv2.WARP_INVERSE_MAP,
        borderMode=cv2.BORDER_REPLICATE,
    )
    if ncc_template is not None:
        tmpl_img = ncc_template
        side = tmpl_img.shape[0]
        hs = side // 2
    pred = np.asarray(pred_corner, float) - 0.5  # array coordinates
    lsm_margin = int(np.ceil(np.abs(jac).sum(axis=1).max() * max(m, n) / 2 + 6))
    half = (
        math.ceil(half_search[0]) + max(hs, lsm_margin) + 2,
        math.ceil(half_search[1]) + max(hs, lsm_margin) + 2,
    )
    win, origin = _window(read, image_id, pred, half)
    if np.isnan(win).any():
        # Only the part inside the image is searched; the NaNs are filled for NCC so that
        # no peak can form there, and LSM flags a patch that reaches them.
        valid = ~np.isnan(win)
        if valid.sum() < side * side:
            return _Match(_t("search window outside the image"))
    pred_w = pred - origin
    ncc_win = np.where(np.isnan(win), np.nanmean(win), win)
    # restrict NCC to the search box (plus the template)
    c_lo = int(np.rint(pred_w[0])) - math.ceil(half_search[0]) - hs
    r_lo = int(np.rint(pred_w[1])) - math.ceil(half_search[1]) - hs
    c_hi = int(np.rint(pred_w[0])) + math.ceil(half_search[0]) + hs + 1
    r_hi = int(np.rint(pred_w[1])) + math.ceil(half_search[1]) + hs + 1
    c_lo, r_lo = max(c_lo, 0), max(r_lo, 0)
    sub = ncc_win[r_lo:r_hi, c_lo:c_hi]
    if sub.shape[0] < side or sub.shape[1] < side:
        return _Match(_t("search window outside the image"))
    nm = ncc_search(tmpl_img, sub)
    out = _Match(ncc=nm.peak)
    if nm.peak < opt.min_ncc:
        out.reason = _t(
            "low correlation (NCC {ncc:.2f} < {minimum:.2f})", ncc=nm.peak, minimum=opt.min_ncc
        )
        return out
    if nm.on_border:
        out.reason = _t("NCC peak on the search border")
        return out
    start_w = np.array([nm.col + c_lo, nm.row + r_lo])
    res = lsm_in_image(
        chip_template[None],
        np.where(np.isnan(win), np.nan, win),
        affine_start(start_w[None], jac[None]),
        reference=ref,
        options=opt.lsm,
    )
    # lsm_in_image treats NaN as outside: it pads with NaN and flags patches touching them.
    pos = res.position[0] + origin
    out.col, out.row = float(pos[0]), float(pos[1])
    out.cov = res.cov_px[0]
    out.sigma0 = float(res.sigma0[0])
    out.corr = float(res.correlation[0])
    out.iterations = int(res.iterations[0])
    out.chip_patch = np.asarray(tmpl_img, dtype=np.float64)
    cc, rr = int(np.rint(pos[0] - origin[0])), int(np.rint(pos[1] - origin[1]))
    out.image_patch = ncc_win[max(rr - hs, 0) : rr + hs + 1, max(cc - hs, 0) : cc + hs + 1]
    if not res.ok[0]:
        out.reason = _t("LSM: {reason}", reason=res.reasons()[0])
    return out


def _finish(pid, iid, r: _Match, pred, cov_search, base, source) -> LocatedPair:
    """Report row of a match; checks that it lies in the search ellipse."""
    reason = r.reason
    col, row = r.col + 0.5, r.row + 0.5  # corner convention
    if not reason and np.isfinite(col):
        d = np.array([col, row]) - pred
        if float(d @ np.linalg.solve(cov_search, d)) > 1.0:
            reason = _t("outside the search ellipse")
    sig = np.sqrt(np.diag(r.cov)) if r.cov is not None else np.full(2, np.nan)
    return LocatedPair(
        pid,
        iid,
        "rejected" if reason else "ok",
        reason,
        source,
        col,
        row,
        float(sig[0]),
        float(sig[1]),
        r.sigma0,
        r.ncc,
        r.corr,
        iterations=r.iterations,
        chip_patch=r.chip_patch,
        image_patch=r.image_patch,
        **base,
    )


def _transfer(
    mres: LocatedPair,
    master: int,
    i: int,
    jac_chip,
    pix,
    image_ids,
    read,
    size: int,
    opt,
    cv2,
    old: LocatedPair,
    curved: tuple | None = None,
) -> LocatedPair | None:
    """Image-to-image LSM from the master image's patch around its match into image i
    (``curved``: see :func:`_transfer_failed`)."""
    h = size // 2
    mc, mr = mres.col - 0.5, mres.row - 0.5
    ci, ri = int(np.rint(mc)), int(np.rint(mr))
    win = np.asarray(read(image_ids[master], ci - h, ri - h, size, size), dtype=np.float64)
    if np.isnan(win).any():
        return None
    ref = (mc - (ci - h), mr - (ri - h))
    # master image -> image i: J_i J_m^-1; predicted position shifted by the master's offset
    jac = jac_chip[i] @ np.linalg.inv(jac_chip[master])
    shift = np.array([mres.col, mres.row]) - pix[master, 0]
    pred = pix[i, 0] + jac @ shift
    half_f = np.array(old.search_px, dtype=float)
    if not np.isfinite(half_f).all():
        half_f = np.full(2, opt.default_search_px)
    r = _match(win, ref, jac, image_ids[i], pred, half_f, read, opt, cv2)
    if curved is not None and np.isfinite(r.col):
        chip, pc, local, eo_local, camera = curved
        shift = _transfer_curvature_shift(
            chip, pc, local, eo_local[master], eo_local[i], camera, jac_chip[master],
            pix[master, 0], np.array([mc, mr]), ci, ri, h, jac,
        )  # fmt: skip
        r.col, r.row = r.col - shift[0], r.row - shift[1]
    cov_search = np.diag(half_f**2) + np.diag(np.full(2, opt.min_search_px**2))
    base = {
        "template_px": size,
        "predicted_col": old.predicted_col,
        "predicted_row": old.predicted_row,
        "search_px": old.search_px,
    }
    if r.cov is not None:
        m_cov = np.diag([mres.sigma_col**2, mres.sigma_row**2])
        r.cov = r.cov + jac @ m_cov @ jac.T
    out = _finish(
        old.point_id,
        old.image_id,
        r,
        pred,
        cov_search * 4.0,
        base,
        _t("transfer from {image}", image=image_ids[master]),
    )
    if out.status != "ok":
        reason = _t(
            "{reason}; transfer from {image}: {transfer_reason}",
            reason=old.reason,
            image=image_ids[master],
            transfer_reason=out.reason,
        )
        return LocatedPair(**{**out.__dict__, "reason": reason})
    return out
