"""The inputs and the setup of a bundle adjustment (:mod:`.bundle`): ground points and
options, the checks of the observation table, and the fixed part of a block (indices, the
local adjustment frame, control in it, approximate orientations by resection and growth,
approximate points by intersection).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Callable, Union

import numpy as np
from numpy.typing import NDArray

from ..errors import AdjustmentError, InputError, stop_if_asked
from ..geometry.ap_models import AP_FAMILIES, make_ap_model
from ..geometry.camera import Camera
from ..geometry.collinearity import image_rays
from ..geometry.engineering import EngineeringFrame, EngineeringLocal
from ..geometry.frames import LocalFrame, MappingFrame
from ..geometry.rotations import matrix_to_opk
from ..i18n import mark as _t
from ..lsq.model import AdjustmentOptions
from .bundle_options import DATUMS, BundleOptions  # noqa: F401 - DATUMS: the old address
from .intersection import meet_rays
from .observations import ImageObservations
from .orientation import ExteriorOrientationTable, eo_map_to_local
from .scale_bars import BarSetup

#: catalogue context of this module's ``_t("...")`` sentences (``make i18n``): the reports'
TR_CONTEXT = "Report"

Array = NDArray[np.float64]
#: the frame of the user's coordinates (a mapping CRS, or a local engineering frame) and the
#: adjustment frame it gives
Frame = Union[MappingFrame, EngineeringFrame]
Local = Union[LocalFrame, EngineeringLocal]

ROLES = ("control", "check")
EO_PARAM_NAMES = ("X0", "Y0", "Z0", "omega", "phi", "kappa")
#: Default standard deviation of a control point coordinate without one in its file, metres.
DEFAULT_CONTROL_SIGMA_M = 0.02
# Fewest control/intersected points for a space resection of an image during the growth.
_MIN_RESECTION_POINTS = 6
# Control points this far (in flying heights, at least 5 km) from every image centre mean a
# wrong CRS.
_FAR_FACTOR = 50.0


@dataclass(frozen=True)
class GroundPoints:
    """Surveyed object points: control points (in the adjustment) and check points (kept out).

    Attributes
    ----------
    point_id : tuple of str, shape (N,)
    xyz : ndarray, shape (N, 3)
        Easting, northing, height in the mapping CRS, metres.
    sigma : ndarray, shape (N, 3)
        Standard deviations of the three coordinates, metres (> 0; used for control points).
    role : tuple of str, shape (N,)
        ``control`` or ``check``.
    rows : tuple of int
        Row of each point in its file (for error messages), or ().
    source : str
        The file.
    """

    point_id: tuple[str, ...]
    xyz: Array
    sigma: Array
    role: tuple[str, ...]
    rows: tuple[int, ...] = ()
    source: str = ""

    def __post_init__(self) -> None:
        n = len(self.point_id)
        xyz = np.asarray(self.xyz, dtype=np.float64).reshape(-1, 3)
        sig = np.broadcast_to(np.asarray(self.sigma, dtype=np.float64), (n, 3)).copy()
        object.__setattr__(self, "xyz", xyz)
        object.__setattr__(self, "sigma", sig)
        object.__setattr__(self, "point_id", tuple(str(p) for p in self.point_id))
        object.__setattr__(self, "role", tuple(str(r).strip().lower() for r in self.role))
        object.__setattr__(self, "rows", tuple(self.rows))
        if xyz.shape[0] != n or len(self.role) != n or (self.rows and len(self.rows) != n):
            raise InputError("ground points: all fields must have the same length")
        for i, r in enumerate(self.role):
            if r not in ROLES:
                raise InputError(f"role '{r}' is not one of {', '.join(ROLES)}", **self.where(i))
        if not np.isfinite(xyz).all():
            i = int(np.flatnonzero(~np.isfinite(xyz).all(axis=1))[0])
            raise InputError("coordinates must be finite", **self.where(i))
        if not (np.isfinite(sig).all() and (sig > 0).all()):
            i = int(np.flatnonzero(~(np.isfinite(sig) & (sig > 0)).all(axis=1))[0])
            raise InputError("sigmas must be finite and > 0", **self.where(i))
        seen: dict[str, int] = {}
        for i, p in enumerate(self.point_id):
            if p in seen:
                raise InputError(f"point '{p}' appears twice", **self.where(i))
            seen[p] = i

    def __len__(self) -> int:
        return len(self.point_id)

    def where(self, i: int) -> dict:
        """``path``/``row`` keywords of :class:`InputError` for point ``i``."""
        return {"path": self.source or None, "row": self.rows[i] if self.rows else None}

    @classmethod
    def empty(cls) -> GroundPoints:
        return cls((), np.zeros((0, 3)), np.zeros((0, 3)), ())


def _fail(message: str, obs: ImageObservations, i: int) -> InputError:
    return InputError(message, **obs.where(int(i)))


def _check_observations(
    obs: ImageObservations,
    images: Sequence[str],
    eo_rows: Sequence[int] | None,
    eo_source: str,
    ground: GroundPoints,
    free: bool,
) -> None:
    """Refuse duplicated rows, unknown images, images without and points with one
    measurement, check rows that name no check point and control rows that name no ground
    point."""
    n = len(obs)
    if n == 0:
        raise InputError("the observation table has no rows", path=obs.source or None)
    img_names, img = np.unique(np.array(obs.image_id), return_inverse=True)
    pt_names, pt = np.unique(np.array(obs.point_id), return_inverse=True)
    img, pt = np.asarray(img).ravel(), np.asarray(pt).ravel()
    unknown = ~np.isin(img_names, np.array(images))
    if unknown.any():
        i = int(np.flatnonzero(unknown[img])[0])
        raise _fail(f"image '{obs.image_id[i]}' is not in the exterior orientation table", obs, i)
    key = img.astype(np.int64) * pt_names.size + pt
    order = np.argsort(key, kind="stable")
    dup = np.flatnonzero(key[order][1:] == key[order][:-1])
    if dup.size:
        j, i = int(order[dup[0]]), int(order[dup[0] + 1])
        row_j = obs.rows[j] if obs.rows else j
        raise _fail(
            f"point '{obs.point_id[i]}' is measured twice in image '{obs.image_id[i]}' (also "
            f"row {row_j})",
            obs,
            i,
        )
    seen = set(img_names.tolist())
    for k, im in enumerate(images):
        if im not in seen:
            row = eo_rows[k] if eo_rows else None
            raise InputError(
                f"image '{im}' has no observations: it cannot be oriented (remove it from the "
                "exterior orientation table or measure points in it)",
                path=eo_source or None,
                row=row,
            )
    roles = dict(zip(ground.point_id, ground.role))
    obs.require_control_known(
        roles,
        f"the ground point table{f' {ground.source}' if ground.source else ''} (give "
        "GROUND_POINTS with that point_id)",
    )
    for i, (p, t) in enumerate(zip(obs.point_id, obs.type)):
        if t == "check" and roles.get(p) != "check":
            raise _fail(
                f"row of type check names point '{p}', which is not a check point of the "
                "ground point table",
                obs,
                i,
            )
    counts = np.bincount(pt, minlength=pt_names.size)
    first_i = np.full(pt_names.size, n)
    np.minimum.at(first_i, pt, np.arange(n))
    for k in np.flatnonzero(counts < 2):
        p = str(pt_names[k])
        role = roles.get(p)
        if role == "control" and not free:
            continue
        what = "check point" if role == "check" else "tie point"
        raise _fail(
            f"{what} '{p}' is measured in one image only: it needs two or more (a control "
            "point may be measured once)",
            obs,
            int(first_i[k]),
        )


def _components(img: NDArray[np.intp], pts: NDArray[np.intp], n_img: int, n_pts: int):
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    graph = coo_matrix(
        (np.ones(img.size), (img, n_img + pts)), shape=(n_img + n_pts, n_img + n_pts)
    )
    return connected_components(graph, directed=False)


@dataclass
class _Setup:
    """Everything fixed for a block: indices, approximations, frames."""

    local: Local
    images: tuple[str, ...]
    image_cam: NDArray[np.intp]  # (M,) camera number
    cam_names: tuple[str, ...]
    cameras: list[Camera]  # with the AP family's lens model, initial values
    eo0: Array  # (M, 6) local
    points: tuple[str, ...]  # adjusted points (tie + control)
    roles: tuple[str, ...]
    xyz0: Array  # (P, 3) local
    obs_img: NDArray[np.intp]  # (N,) image number of every measurement
    obs_pt: NDArray[np.intp]  # (N,) adjusted point number, -1 for check rows
    obs_check: NDArray[np.intp]  # (N,) check point number, -1 otherwise
    check_ids: tuple[str, ...]
    check_ref_local: Array
    control_pt: NDArray[np.intp]  # adjusted point numbers of the control points
    control_cov: Array  # (C, 3, 3) local
    control_local: Array  # (C, 3)
    eo_obs: Array | None  # (M, 6) local observed orientations
    eo_obs_cov: Array | None  # (M, 6, 6)
    bars: BarSetup | None = None  # scale bars (set after the setup, bundle.py)
    velocity: Array | None = None  # (M, 3) local, m/s: the exposures' (timing offset)


def _local_frame(
    mapping: Frame, ground: GroundPoints, eo: ExteriorOrientationTable | None
) -> Local:
    if len(ground):
        centre = ground.xyz.mean(axis=0)
    else:
        centre = eo.xyz.mean(axis=0)  # type: ignore[union-attr]
    if isinstance(mapping, EngineeringFrame):
        return EngineeringLocal(mapping, (float(centre[0]), float(centre[1]), float(centre[2])))
    return LocalFrame.at_map_point(mapping, centre)


def _eo_to_local(eo: ExteriorOrientationTable, local: Local) -> Array:
    centres, m = eo_map_to_local(eo.xyz, eo.opk, local)
    om, ph, ka = matrix_to_opk(m)
    return np.column_stack([centres, om, ph, ka])


def _eo_cov_to_local(eo: ExteriorOrientationTable, sigma: Array, local: Local) -> Array:
    """Covariance (M, 6, 6) in the local frame of orientations with map-frame sigmas (M, 6)."""
    jac = np.zeros((len(eo), 6, 6))
    steps = np.array([0.01, 0.01, 0.01, 1e-6, 1e-6, 1e-6])
    values = np.concatenate([eo.xyz, eo.opk], axis=1)
    for k in range(6):
        plus, minus = values.copy(), values.copy()
        plus[:, k] += steps[k]
        minus[:, k] -= steps[k]
        tp = replace(eo, xyz=plus[:, :3], opk=plus[:, 3:])
        tm = replace(eo, xyz=minus[:, :3], opk=minus[:, 3:])
        d = _eo_to_local(tp, local) - _eo_to_local(tm, local)
        d[:, 3:] = (d[:, 3:] + np.pi) % (2 * np.pi) - np.pi
        jac[:, :, k] = d / (2 * steps[k])
    cov_map = np.zeros((len(eo), 6, 6))
    cov_map[:, np.arange(6), np.arange(6)] = sigma**2
    return jac @ cov_map @ np.swapaxes(jac, 1, 2)


def _camera_for_family(cam: Camera, family: str) -> Camera:
    if family == "none":
        return cam
    target = AP_FAMILIES[family]
    if cam.distortion.model == target:
        return cam
    w = cam.width_px * cam.pixel_size_mm
    h = cam.height_px * cam.pixel_size_mm
    return replace(cam, distortion=make_ap_model(family, w, h, cam.focal_mm))


def _check_ground_crs(
    ground: GroundPoints, eo: ExteriorOrientationTable | None, mapping: Frame
) -> None:
    """Refuse control points in another CRS: coordinates like degrees, or far from every
    image (a local engineering frame has no CRS to confuse)."""
    if not len(ground) or isinstance(mapping, EngineeringFrame):
        return
    g = ground.xyz
    if (np.abs(g[:, 0]) <= 180).all() and (np.abs(g[:, 1]) <= 90).all():
        raise InputError(
            "the ground point coordinates look like degrees of longitude/latitude; they "
            f"must be in the mapping CRS ({mapping.crs.name}), easting and northing in "
            "metres",
            path=ground.source or None,
        )
    if eo is not None:
        height = max(float(np.median(np.abs(eo.xyz[:, 2] - np.median(g[:, 2])))), 100.0)
        far = max(_FAR_FACTOR * height, 5000.0)
        dist = np.min(
            np.hypot(g[:, None, 0] - eo.xyz[None, :, 0], g[:, None, 1] - eo.xyz[None, :, 1]),
            axis=1,
        )
        bad = np.flatnonzero(dist > far)
        if bad.size:
            i = int(bad[0])
            raise InputError(
                f"ground point '{ground.point_id[i]}' lies {dist[i] / 1000:.1f} km from the "
                f"nearest image centre: are the ground points in the mapping CRS "
                f"({mapping.crs.name}) as the exterior orientations are?",
                **ground.where(i),
            )


def _prepare(
    cameras: Sequence[Camera],
    image_camera: Mapping[str, str],
    obs: ImageObservations,
    ground: GroundPoints,
    mapping: Frame,
    eo: ExteriorOrientationTable | None,
    eo_sigma: Array | None,
    options: BundleOptions,
    eo_rows: Sequence[int] | None,
    eo_source: str,
    should_stop: Callable[[], bool] | None,
    warnings: list[str],
) -> _Setup:
    cam_names = tuple(c.name for c in cameras)
    if len(set(cam_names)) != len(cam_names):
        raise InputError(f"two cameras share the name(s) {sorted(set(cam_names))}")
    images = tuple(eo.image_id) if eo is not None else tuple(dict.fromkeys(obs.image_id))
    _check_observations(obs, images, eo_rows, eo_source, ground, options.datum != "control")
    image_cam = _image_cameras(cameras, cam_names, images, image_camera)
    roles = dict(zip(ground.point_id, ground.role))
    gidx = {p: i for i, p in enumerate(ground.point_id)}
    _warn_unobserved(ground, obs, warnings)
    free = options.datum != "control"
    adjusted: list[str] = []
    check_ids: list[str] = []
    # every measured point once, in order of first measurement: one dict look-up a
    # measurement, then the adjusted / check numbers of each distinct point by index
    first = {p: i for i, p in enumerate(dict.fromkeys(obs.point_id))}
    pt_of = np.full(len(first), -1, dtype=np.intp)
    check_of = np.full(len(first), -1, dtype=np.intp)
    for p, i in first.items():
        if roles.get(p) == "check":
            check_of[i] = len(check_ids)
            check_ids.append(p)
        else:
            pt_of[i] = len(adjusted)
            adjusted.append(p)
    img_num = {im: k for k, im in enumerate(images)}
    obs_img = np.array([img_num[i] for i in obs.image_id], dtype=np.intp)
    obs_code = np.array([first[p] for p in obs.point_id], dtype=np.intp)
    obs_pt = pt_of[obs_code]
    obs_check = check_of[obs_code]
    point_roles = tuple(
        "control" if (roles.get(p) == "control" and not free) else "tie" for p in adjusted
    )
    _check_connected(obs, obs_img, obs_pt, images, len(adjusted))
    if eo is None and len(ground) == 0:
        raise InputError(
            "without approximate exterior orientations the bundle needs control points to "
            "orient the first images (give an EO table or ground points)"
        )
    _check_ground_crs(ground, eo, mapping)
    local = _local_frame(mapping, ground, eo)
    ctrl_mask = [roles.get(p) == "control" and not free for p in adjusted]
    control_pt = np.flatnonzero(ctrl_mask).astype(np.intp)
    ctrl_g = np.array([gidx[adjusted[i]] for i in control_pt], dtype=np.intp)
    control_local = local.map_to_enu(ground.xyz[ctrl_g]) if ctrl_g.size else np.zeros((0, 3))
    control_cov = _cov_map_to_local(ground.xyz[ctrl_g], ground.sigma[ctrl_g], local)
    chk_g = np.array([gidx[p] for p in check_ids], dtype=np.intp)
    check_local = local.map_to_enu(ground.xyz[chk_g]) if chk_g.size else np.zeros((0, 3))
    cams = [_camera_for_family(c, options.ap_model) for c in cameras]
    eo_obs = eo_obs_cov = None
    if eo is not None:
        eo0 = _eo_to_local(eo, local)
        if eo_sigma is not None:
            eo_obs = eo0.copy()
            eo_obs_cov = _eo_cov_to_local(eo, eo_sigma, local)
    else:
        eo0 = _grow(
            cams,
            image_cam,
            obs,
            obs_img,
            obs_pt,
            control_pt,
            control_local,
            len(images),
            len(adjusted),
            images,
            should_stop,
        )
    if options.datum == "control" and control_pt.size < 3 and eo_obs is None:
        raise InputError(
            f"the datum needs three or more control points measured in the images or observed "
            f"exterior orientations; there are {control_pt.size} control points and no EO "
            "sigmas (or choose a free-network datum: inner or minimal)"
        )
    if eo_obs is None:
        _check_orientable(obs, obs_img, obs_pt, images)
    xyz0 = _approximate_points(cams, image_cam, eo0, obs, obs_img, obs_pt, len(adjusted))
    if control_pt.size:
        xyz0[control_pt] = control_local
    bad = np.flatnonzero(~np.isfinite(xyz0).all(axis=1))
    if bad.size:
        p = adjusted[int(bad[0])]
        i = int(np.flatnonzero(obs_pt == bad[0])[0])
        raise _fail(
            f"point '{p}' cannot be intersected from the approximate orientations (its rays "
            "are parallel or miss each other); check its measurements",
            obs,
            i,
        )
    return _Setup(
        local=local,
        images=images,
        image_cam=image_cam,
        cam_names=cam_names,
        cameras=cams,
        eo0=eo0,
        points=tuple(adjusted),
        roles=point_roles,
        xyz0=xyz0,
        obs_img=obs_img,
        obs_pt=obs_pt,
        obs_check=obs_check,
        check_ids=tuple(check_ids),
        check_ref_local=check_local,
        control_pt=control_pt,
        control_cov=control_cov,
        control_local=control_local,
        eo_obs=eo_obs,
        eo_obs_cov=eo_obs_cov,
    )


def _image_cameras(
    cameras: Sequence[Camera],
    cam_names: tuple[str, ...],
    images: tuple[str, ...],
    image_camera: Mapping[str, str],
) -> NDArray[np.intp]:
    """The camera (index into ``cameras``) of every image; InputError for an image without
    one among several cameras or naming an unknown camera."""
    image_cam = np.zeros(len(images), dtype=np.intp)
    for k, im in enumerate(images):
        name = image_camera.get(im)
        if name is None:
            if len(cameras) == 1:
                continue
            raise InputError(
                f"image '{im}' has no camera: with several cameras give a camera column in "
                "the exterior orientation or observation table"
            )
        if name not in cam_names:
            raise InputError(
                f"image '{im}' names camera '{name}', which is not one of {', '.join(cam_names)}"
            )
        image_cam[k] = cam_names.index(name)
    return image_cam


def _warn_unobserved(ground: GroundPoints, obs: ImageObservations, warnings: list[str]) -> None:
    """A warning (appended to ``warnings``) naming the ground points no image measures."""
    observed = set(obs.point_id)
    unobserved = [p for p in ground.point_id if p not in observed]
    if unobserved:
        warnings.append(
            _t(
                "{n} ground point(s) are not measured in any image and were not used: {ids}",
                n=len(unobserved),
                ids=", ".join(unobserved[:20]) + (" ..." if len(unobserved) > 20 else ""),
            )
        )


def _check_connected(
    obs: ImageObservations,
    obs_img: NDArray[np.intp],
    obs_pt: NDArray[np.intp],
    images: tuple[str, ...],
    n_points: int,
) -> None:
    """InputError naming the images apart when the block falls into unconnected parts
    (through its adjusted points)."""
    # the block must hang together through its adjusted points
    used = obs_pt >= 0
    ncomp, label = _components(obs_img[used], obs_pt[used], len(images), n_points)
    if ncomp > 1:
        img_label = label[: len(images)]
        main = np.bincount(img_label).argmax()
        apart = [images[k] for k in np.flatnonzero(img_label != main)]
        raise InputError(
            f"the block falls into {ncomp} unconnected parts (no tie or control point links "
            f"them): images {', '.join(apart[:30])}{' ...' if len(apart) > 30 else ''} are "
            "not connected to the rest; adjust the parts separately or measure tie points "
            "between them",
            path=obs.source or None,
        )


def _check_orientable(
    obs: ImageObservations,
    obs_img: NDArray[np.intp],
    obs_pt: NDArray[np.intp],
    images: tuple[str, ...],
) -> None:
    """Without observed orientations: InputError naming the images with fewer than three
    measured points (six equations for their six unknowns)."""
    # without observed orientations an image needs three points (six equations for its
    # six unknowns) to be oriented at all
    per_image = np.bincount(obs_img[obs_pt >= 0], minlength=len(images))
    few = np.flatnonzero(per_image < 3)
    if few.size:
        names = ", ".join(f"{images[k]} ({per_image[k]})" for k in few[:20])
        raise InputError(
            f"{few.size} image(s) have fewer than three measured points and cannot be "
            f"oriented without observed exterior orientations: {names}",
            path=obs.source or None,
        )


def _cov_map_to_local(xyz: Array, sigma: Array, local: Local) -> Array:
    """(N, 3, 3) covariance in the local frame of map coordinates with sigmas (N, 3)."""
    jac = local.map_to_enu_jacobian(xyz)[1]
    return jac @ (sigma[:, :, None] ** 2 * np.eye(3)) @ np.swapaxes(jac, 1, 2)


def _cov_local_to_map(xyz_local: Array, cov: Array, local: Local) -> Array:
    jac = local.enu_to_map_jacobian(xyz_local)[1]
    return jac @ cov @ np.swapaxes(jac, 1, 2)


def _rays(cams, image_cam, eo, obs, obs_img, rows):
    origins = np.zeros((rows.size, 3))
    dirs = np.zeros((rows.size, 3))
    for c, cam in enumerate(cams):
        sel = np.flatnonzero(image_cam[obs_img[rows]] == c)
        if sel.size:
            o, d = image_rays(obs.pixels[rows[sel]], eo, cam, image_index=obs_img[rows[sel]])
            origins[sel], dirs[sel] = o, d
    return origins, dirs


def _approximate_points(cams, image_cam, eo, obs, obs_img, obs_pt, n_points) -> Array:
    rows = np.flatnonzero(obs_pt >= 0)
    o, d = _rays(cams, image_cam, eo, obs, obs_img, rows)
    return meet_rays(o, d, obs_pt[rows], n_points)[0]


def _grow(
    cams,
    image_cam,
    obs,
    obs_img,
    obs_pt,
    control_pt,
    control_local,
    n_img,
    n_pts,
    images,
    should_stop,
) -> Array:
    """Orientations from resections of the images that see control, then growth."""
    import cv2

    from .resection import space_resection

    eo = np.full((n_img, 6), np.nan)
    known = np.full((n_pts, 3), np.nan)
    known[control_pt] = control_local
    for _ in range(n_img + 1):
        stop_if_asked(should_stop, "orienting the images")
        progress = False
        for k in range(n_img):
            if np.isfinite(eo[k]).all():
                continue
            rows = np.flatnonzero((obs_img == k) & (obs_pt >= 0))
            rows = rows[np.isfinite(known[obs_pt[rows]]).all(axis=1)]
            if rows.size < _MIN_RESECTION_POINTS and not (
                rows.size >= 4 and np.isin(obs_pt[rows], control_pt).all()
            ):
                continue
            try:
                res = space_resection(
                    obs.pixels[rows],
                    known[obs_pt[rows]],
                    cams[image_cam[k]],
                    sigma_px=1.0,
                    options=AdjustmentOptions(snooping=True, max_iterations=30),
                )
            except (AdjustmentError, InputError, np.linalg.LinAlgError, cv2.error):
                continue  # a failed start is retried when more points are known
            if np.all(np.abs(res.rms_px) < 50.0):
                eo[k] = res.eo
                progress = True
        oriented = np.isfinite(eo).all(axis=1)
        if oriented.all():
            break
        rows = np.flatnonzero((obs_pt >= 0) & oriented[obs_img])
        if rows.size:
            o, d = _rays(cams, image_cam, np.nan_to_num(eo), obs, obs_img, rows)
            xyz = meet_rays(o, d, obs_pt[rows], n_pts)[0]
            new = np.isfinite(xyz).all(axis=1) & ~np.isfinite(known).all(axis=1)
            if new.any():
                known[new] = xyz[new]
                progress = True
        if not progress:
            break
    missing = [images[k] for k in np.flatnonzero(~np.isfinite(eo).all(axis=1))]
    if missing:
        raise InputError(
            f"without approximate exterior orientations, {len(missing)} image(s) could not be "
            f"oriented by resection from control points and intersected tie points: "
            f"{', '.join(missing[:20])}{' ...' if len(missing) > 20 else ''} (give an EO table "
            "or more control/tie points)"
        )
    return eo
