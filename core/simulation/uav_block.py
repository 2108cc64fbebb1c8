"""A simulated UAV photogrammetric block in the configuration of Lima, Debiasi & Menezes, with the
truth, for the bundle adjustment and the products made from it.

Their block (section 2): a SenseFly Swinglet CAM with a Canon IXUS 120 IS, 15 images in four
strips, 188 m above ground, 70 % forward and 60 % side overlap, a ground sample distance of
6 cm, 21 GNSS-surveyed points of which 5 were check points (UTM zone 23 S, Seropedica, RJ).
The simulator flies that block over a gently undulating terrain and returns what a bundle
adjustment reads (the nominal camera, image measurements, control and check points, direct
georeferencing orientations) and the truth (true camera with an inserted AP family, true
orientations, true point coordinates).

The camera's true interior orientation differs from the nominal one (principal distance and
principal point) and carries the distortion of one AP family (``ap_model``) with coefficients
scaled so that the correction reaches ``ap_scale_px`` pixels in the image corner; ``"real"``
inserts a Brown-Conrady lens typical of a compact camera (barrel k1, k2, decentring p1, p2).

Geometry (flight, terrain, points) follows ``seed``; measurement noise follows ``noise_seed``
(default ``seed``), so Monte Carlo draws keep the block.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Union

import numpy as np
from numpy.typing import NDArray

from ..geometry.ap_models import AP_FAMILIES, make_ap_model
from ..geometry.camera import Camera
from ..geometry.collinearity import project_with_status
from ..geometry.distortion import BrownConrady, DistortionModel
from ..geometry.frames import LocalFrame, MappingFrame
from ..geometry.rotations import matrix_to_opk, opk_to_matrix
from ..io.atomic import folder_files, write_text_atomic
from ..io.camera import write_camera_json
from ..io.ground_points import write_ground_points_csv
from ..io.observations import write_observations_csv
from ..photo.bundle_setup import GroundPoints
from ..photo.observations import ImageObservations
from ..photo.orientation import ExteriorOrientationTable, eo_local_to_map

Array = NDArray[np.float64]

__all__ = ["UavBlock", "UavBlockConfig", "canon_ixus_120", "simulate_uav_block"]


def canon_ixus_120() -> Camera:
    """Nominal Canon IXUS 120 IS: 1/2.3" sensor, 4000 x 3000 px of 1.54 um, f = 5.0 mm.

    At 188 m this gives the 5.8 cm ground sample distance of the paper's block.
    """
    return Camera(
        "Canon IXUS 120 IS", focal_mm=5.0, pixel_size_mm=0.00154, width_px=4000, height_px=3000
    )


@dataclass(frozen=True)
class UavBlockConfig:
    """The block (defaults: the configuration of Lima, Debiasi & Menezes).

    Attributes
    ----------
    crs : str
        Mapping CRS (SIRGAS 2000 / UTM zone 23S).
    centre : (float, float)
        Block centre, easting and northing.
    ground_height_m : float
        Mean ellipsoidal height of the terrain.
    relief_m : float
        Amplitude of the terrain undulation.
    camera : Camera
        The nominal camera (what the user knows).
    true_focal_mm, true_x0_mm, true_y0_mm : float
        The camera's true interior orientation.
    flying_height_m : float
        Above the mean terrain.
    forward_overlap, side_overlap : float
    strips : tuple of int
        Images per strip (serpentine, the image's top towards the flight direction).
    heading_deg : float
        Direction of the first strip, clockwise from grid north.
    n_control, n_check : int
        GNSS-surveyed points (well distributed over the block).
    control_sigma_m : (float, float)
        Survey standard deviation horizontal, vertical.
    n_tie : int
        Tie points drawn over the block (those seen in two or more images are kept).
    sigma_px : float
        Image measurement noise.
    position_jitter_m, attitude_jitter_deg : float
        Deviation of the true poses from the flight plan (1 sigma).
    dg_position_sigma_m, dg_attitude_sigma_deg : float
        Errors of the direct-georeferencing orientations (1 sigma).
    margin_px : float
        Measurements closer to the image border are not made.
    """

    crs: str = "EPSG:31983"
    centre: tuple[float, float] = (634500.0, 7482300.0)
    ground_height_m: float = 25.0
    relief_m: float = 6.0
    camera: Camera = field(default_factory=canon_ixus_120)
    true_focal_mm: float = 5.03
    true_x0_mm: float = 0.012
    true_y0_mm: float = -0.009
    flying_height_m: float = 188.0
    forward_overlap: float = 0.70
    side_overlap: float = 0.60
    strips: tuple[int, ...] = (4, 4, 4, 3)
    heading_deg: float = 90.0
    n_control: int = 16
    n_check: int = 5
    control_sigma_m: tuple[float, float] = (0.01, 0.015)
    n_tie: int = 1200
    sigma_px: float = 0.5
    position_jitter_m: float = 3.0
    attitude_jitter_deg: float = 2.0
    dg_position_sigma_m: float = 5.0
    dg_attitude_sigma_deg: float = 1.0
    margin_px: float = 20.0


@dataclass(frozen=True)
class UavBlock:
    """A simulated block: bundle inputs and truth (mapping CRS throughout).

    Attributes
    ----------
    config : UavBlockConfig
    mapping : MappingFrame
    camera : Camera
        Nominal camera (the bundle's input).
    true_camera : Camera
        True interior orientation with the inserted lens model.
    ap_model : str
        Inserted family (a key of AP_FAMILIES, or "real").
    true_ap : dict of str to float
        Its true coefficients.
    eo_true, eo_dg : ExteriorOrientationTable
        True orientations and the direct-georeferencing ones (with errors).
    eo_sigma : ndarray, shape (M, 6)
        Standard deviations of the direct-georeferencing orientations (m and rad).
    observations : ImageObservations
    ground : GroundPoints
        Surveyed control and check points (with survey noise).
    ground_true : ndarray, shape (G, 3)
        Their true coordinates.
    tie_id : tuple of str
    tie_true : ndarray, shape (T, 3)
        True coordinates of the tie points kept.
    """

    config: UavBlockConfig
    mapping: MappingFrame
    camera: Camera
    true_camera: Camera
    ap_model: str
    true_ap: dict[str, float]
    eo_true: ExteriorOrientationTable
    eo_dg: ExteriorOrientationTable
    eo_sigma: Array
    observations: ImageObservations
    ground: GroundPoints
    ground_true: Array
    tie_id: tuple[str, ...]
    tie_true: Array

    def terrain(self, e: Array, n: Array) -> Array:
        """Ellipsoidal height (m) of the simulated terrain at easting/northing arrays (the
        surface the points lie on; for orthophotos and DSMs of the block)."""
        return _terrain(
            self.config, np.asarray(e, dtype=np.float64), np.asarray(n, dtype=np.float64)
        )

    def write(self, folder: Union[str, Path], eo: str = "dg") -> dict[str, Path]:
        """Write the bundle inputs (camera, observations, ground points, EO with sigmas) and
        the truth (JSON); ``eo`` is ``"dg"`` (the direct-georeferencing start) or ``"true"``.
        Returns the paths by name."""
        from ..io.orientation import write_eo_csv_with_sigmas

        csv = ("observations", "ground_points", "eo")
        paths = folder_files(folder, "camera.json", *(f"{k}.csv" for k in csv), "truth.json")
        write_camera_json(paths["camera"], self.camera)
        write_observations_csv(paths["observations"], self.observations)
        write_ground_points_csv(paths["ground_points"], self.ground)
        table = self.eo_dg if eo == "dg" else self.eo_true
        write_eo_csv_with_sigmas(paths["eo"], table, self.eo_sigma)
        truth = {
            "ap_model": self.ap_model,
            "true_camera": self.true_camera.to_dict(),
            "true_ap": self.true_ap,
            "eo_true": {
                i: [*map(float, x), *map(float, np.degrees(o))]
                for i, x, o in zip(self.eo_true.image_id, self.eo_true.xyz, self.eo_true.opk)
            },
            "ground_true": {
                p: list(map(float, x)) for p, x in zip(self.ground.point_id, self.ground_true)
            },
        }
        write_text_atomic(paths["truth"], json.dumps(truth, indent=1))
        return paths


def _terrain(cfg: UavBlockConfig, e: Array, n: Array) -> Array:
    """Ellipsoidal height of the terrain at map coordinates (smooth, a few metres of relief)."""
    u = (e - cfg.centre[0]) / 120.0
    v = (n - cfg.centre[1]) / 150.0
    return cfg.ground_height_m + cfg.relief_m * (
        0.6 * np.sin(u + 0.3) * np.cos(0.7 * v) + 0.4 * np.cos(1.3 * v - 0.5 * u)
    )


def _true_ap(family: str, cam: Camera, scale_px: float, rng) -> dict[str, float]:
    """Coefficients of the family giving a correction of about ``scale_px`` in the corner."""
    w = cam.width_px * cam.pixel_size_mm
    h = cam.height_px * cam.pixel_size_mm
    if family == "real":
        # A compact camera's barrel distortion: about 30 px radial at the corner, 2 px
        # decentring (coefficients for millimetre coordinates, correction convention).
        return {"k1": 8.0e-4, "k2": -1.0e-5, "k3": 0.0, "p1": 6.0e-5, "p2": -4.0e-5}
    model = make_ap_model(family, w, h, cam.focal_mm)
    grid = np.stack(
        np.meshgrid(np.linspace(-w / 2, w / 2, 9), np.linspace(-h / 2, h / 2, 7)), -1
    ).reshape(-1, 2)
    basis = model.jacobian_params(grid)  # (n, 2, P) mm per unit
    peak = np.abs(basis).max(axis=(0, 1))
    p = model.n_params
    signs = rng.choice([-1.0, 1.0], p)
    mags = rng.uniform(0.5, 1.0, p)
    coef = signs * mags / peak
    total = np.abs(np.einsum("nap,p->na", basis, coef)).max()
    coef *= scale_px * cam.pixel_size_mm / total
    return dict(zip(model.param_names, coef.tolist()))


def _true_camera(
    cfg: UavBlockConfig, ap_model: str, ap_scale_px: float, rng: np.random.Generator
) -> tuple[dict[str, float], Camera]:
    """The inserted AP coefficients and the true camera (interior orientation and lens)."""
    nominal = cfg.camera
    true_ap = {} if ap_model == "none" else _true_ap(ap_model, nominal, ap_scale_px, rng)
    w_mm = nominal.width_px * nominal.pixel_size_mm
    h_mm = nominal.height_px * nominal.pixel_size_mm
    lens: DistortionModel
    if ap_model == "real":
        lens = BrownConrady(**true_ap)
    elif ap_model == "none":
        lens = nominal.distortion
    else:
        lens = make_ap_model(ap_model, w_mm, h_mm, nominal.focal_mm, **true_ap)
    true_cam = replace(
        nominal,
        focal_mm=cfg.true_focal_mm,
        x0_mm=cfg.true_x0_mm,
        y0_mm=cfg.true_y0_mm,
        distortion=lens,
    )
    return true_ap, true_cam


@dataclass(frozen=True)
class _Plan:
    """The flight plan on the map: strips across the heading, images along it (metres)."""

    fwd: Array  # unit vector of the heading (east, north)
    right: Array  # unit vector to the right of it
    centre: Array  # the block's centre (easting, northing)
    along: float  # an image's ground footprint along the heading (the image top)
    across: float  # and across it
    base: float  # distance between exposures in a strip
    spacing: float  # distance between strips
    xy: Array  # (M, 2) planned exposure positions
    headings: list[float]  # radians, clockwise from north
    names: list[str]
    strips: list[str]


def _flight_plan(cfg: UavBlockConfig) -> _Plan:
    """Exposures of the strips (alternating direction) from the overlaps and the GSD."""
    nominal = cfg.camera
    gsd = cfg.flying_height_m * nominal.pixel_size_mm / nominal.focal_mm
    along = nominal.height_px * gsd  # the image top looks forward
    across = nominal.width_px * gsd
    base = (1.0 - cfg.forward_overlap) * along
    spacing = (1.0 - cfg.side_overlap) * across
    hd = math.radians(cfg.heading_deg)
    fwd = np.array([math.sin(hd), math.cos(hd)])
    right = np.array([fwd[1], -fwd[0]])
    centre = np.array(cfg.centre)
    n_strips = len(cfg.strips)
    plan_xy, headings, names, strips = [], [], [], []
    for s, count in enumerate(cfg.strips):
        offset = (s - (n_strips - 1) / 2) * spacing
        sign = 1.0 if s % 2 == 0 else -1.0
        for k in range(count):
            t = (k - (count - 1) / 2) * base * sign
            plan_xy.append(centre + offset * right + t * fwd)
            headings.append(hd if sign > 0 else hd + math.pi)
            names.append(f"IMG_{s + 1:02d}{k + 1:02d}")
            strips.append(f"strip {s + 1}")
    return _Plan(
        fwd, right, centre, along, across, base, spacing, np.array(plan_xy), headings, names, strips
    )


def _true_poses(
    cfg: UavBlockConfig,
    plan: _Plan,
    mapping: MappingFrame,
    local: LocalFrame,
    rng: np.random.Generator,
) -> tuple[Array, Array, ExteriorOrientationTable]:
    """The plan plus jitter, camera looking down with the image top forward: (centres in the
    local frame (M, 3), local EO rows (M, 6), the true EO table on the map)."""
    M = plan.xy.shape[0]
    z_plan = float(_terrain(cfg, plan.centre[:1], plan.centre[1:])[0])
    xyz_map = np.column_stack(
        [
            plan.xy + rng.normal(0, cfg.position_jitter_m, (M, 2)),
            np.full(M, z_plan + cfg.flying_height_m) + rng.normal(0, cfg.position_jitter_m, M),
        ]
    )
    centres = local.map_to_enu(xyz_map)
    jitter = np.radians(rng.normal(0, cfg.attitude_jitter_deg, (M, 3)))
    # camera -> local: kappa turns the image top to the heading (heading clockwise from north)
    kappa = -np.array(plan.headings) + jitter[:, 2]
    M_true = opk_to_matrix(jitter[:, 0], jitter[:, 1], kappa)
    eo_local = np.column_stack([centres, *matrix_to_opk(M_true)])
    eo_xyz, eo_opk = eo_local_to_map(centres, M_true, local)
    times = np.arange(M, dtype=float) * 3.0
    eo_true = ExteriorOrientationTable(
        tuple(plan.names), times, tuple(plan.strips), eo_xyz, eo_opk, mapping.crs.to_wkt()
    )
    return centres, eo_local, eo_true


def _direct_georeferencing(
    cfg: UavBlockConfig, eo_true: ExteriorOrientationTable, nrng: np.random.Generator
) -> tuple[ExteriorOrientationTable, Array]:
    """The truth with GNSS/INS errors, and the sigmas (M, 6; m and rad)."""
    M = len(eo_true)
    dg_xyz = eo_true.xyz + nrng.normal(0, cfg.dg_position_sigma_m, (M, 3))
    dg_opk = eo_true.opk + np.radians(nrng.normal(0, cfg.dg_attitude_sigma_deg, (M, 3)))
    eo_dg = replace(eo_true, xyz=dg_xyz, opk=dg_opk)
    eo_sigma = np.tile(
        [cfg.dg_position_sigma_m] * 3 + [math.radians(cfg.dg_attitude_sigma_deg)] * 3, (M, 1)
    )
    return eo_dg, eo_sigma


def _surveyed_points(
    cfg: UavBlockConfig,
    plan: _Plan,
    ext: tuple[float, float],
    rng: np.random.Generator,
    nrng: np.random.Generator,
) -> tuple[Array, GroundPoints]:
    """A jittered grid of control points over the block's extent (along, across; metres),
    check points spread among them: (true coordinates, the surveyed points with noise)."""
    ext_along, ext_across = ext
    n_gcp = cfg.n_control + cfg.n_check
    cols = math.ceil(math.sqrt(n_gcp * ext_along / ext_across))
    rows_ = math.ceil(n_gcp / cols)
    gu, gv = np.meshgrid(np.linspace(-0.42, 0.42, cols), np.linspace(-0.42, 0.42, rows_))
    cells = np.column_stack([gu.ravel(), gv.ravel()])[:n_gcp]
    cells = cells + rng.uniform(-0.04, 0.04, cells.shape)
    gxy = (
        plan.centre
        + (cells[:, :1] * ext_along) * plan.fwd
        + (cells[:, 1:] * ext_across) * (plan.right)
    )
    gcp_true = np.column_stack([gxy, _terrain(cfg, gxy[:, 0], gxy[:, 1])])
    order = rng.permutation(n_gcp)
    check_set = set(order[: cfg.n_check].tolist())
    gids = tuple(f"GCP{k + 1:02d}" for k in range(n_gcp))
    roles = tuple("check" if k in check_set else "control" for k in range(n_gcp))
    sig = np.array([cfg.control_sigma_m[0]] * 2 + [cfg.control_sigma_m[1]])
    gcp_meas = gcp_true + nrng.normal(0, 1, gcp_true.shape) * sig
    return gcp_true, GroundPoints(gids, gcp_meas, np.tile(sig, (n_gcp, 1)), roles)


def _project_all(
    cfg: UavBlockConfig,
    plan: _Plan,
    true_cam: Camera,
    centres: Array,
    eo_local: Array,
    pts_local: Array,
) -> tuple[NDArray[np.intp], NDArray[np.intp], Array]:
    """(image, point, pixel) of every point in front of a camera and inside its frame; only
    the points near each image's footprint are projected (large blocks)."""
    rec_img, rec_pt, rec_px = [], [], []
    reach = (
        0.75 * math.hypot(plan.along, plan.across)
        + 3.0 * cfg.position_jitter_m
        + (cfg.flying_height_m * math.tan(math.radians(4.0 * cfg.attitude_jitter_deg)))
    )
    order = np.argsort(pts_local[:, 0])
    xs = pts_local[order, 0]
    for k in range(len(centres)):
        lo, hi = np.searchsorted(xs, [centres[k, 0] - reach, centres[k, 0] + reach])
        cand = order[lo:hi]
        cand = cand[np.abs(pts_local[cand, 1] - centres[k, 1]) <= reach]
        px, front, conv = project_with_status(pts_local[cand], eo_local[k], true_cam)
        ok = front & conv & true_cam.in_frame(px, cfg.margin_px)
        idx = np.flatnonzero(ok)
        rec_img += [k] * idx.size
        rec_pt.append(cand[idx])
        rec_px.append(px[idx])
    return np.array(rec_img, dtype=np.intp), np.concatenate(rec_pt), np.vstack(rec_px)


def _measurements(
    cfg: UavBlockConfig,
    names: list[str],
    all_ids: list[str],
    ground: GroundPoints,
    img: NDArray[np.intp],
    pt: NDArray[np.intp],
    px: Array,
    nrng: np.random.Generator,
) -> tuple[ImageObservations, NDArray[np.intp]]:
    """The image observations (points seen twice or more, targets also once but for a check
    point), with pixel noise; and the indices of the tie points kept (into the tie list)."""
    n_gcp, roles = len(ground), ground.role
    counts = np.bincount(pt, minlength=len(all_ids))
    keep = counts[pt] >= 2
    keep |= pt < n_gcp  # targets are kept even when seen once (a control point may be)
    img, pt, px = img[keep], pt[keep], px[keep]
    # a check point seen once cannot be intersected: drop its single measurement
    once = (np.bincount(pt, minlength=len(all_ids)) < 2)[pt] & np.isin(
        pt, [k for k in range(n_gcp) if roles[k] == "check"]
    )
    img, pt, px = img[~once], pt[~once], px[~once]
    px = px + nrng.normal(0, cfg.sigma_px, px.shape)
    n = img.size
    obs = ImageObservations(
        tuple(names[i] for i in img),
        tuple(all_ids[p] for p in pt),
        px,
        np.full(n, cfg.sigma_px),
        tuple("check" if p < n_gcp and roles[p] == "check" else "tie" for p in pt),
        ("",) * n,
    )
    seen = np.bincount(pt, minlength=len(all_ids)) >= 2
    return obs, np.flatnonzero(seen[n_gcp:])


def simulate_uav_block(
    ap_model: str = "none",
    seed: int = 0,
    noise_seed: int | None = None,
    ap_scale_px: float = 6.0,
    config: UavBlockConfig | None = None,
    **changes,
) -> UavBlock:
    """Simulate the UAV block of Lima, Debiasi & Menezes with an inserted AP family.

    Parameters
    ----------
    ap_model : str
        A key of :data:`~lidarphoto.core.geometry.ap_models.AP_FAMILIES` (``none``: no
        distortion), or ``"real"`` (a Brown-Conrady compact-camera lens).
    seed : int
        Geometry (flight, terrain, points, inserted coefficients).
    noise_seed : int, optional
        Measurement and survey noise (default ``seed``).
    ap_scale_px : float
        Size of the inserted correction in the image corner, pixels.
    config : UavBlockConfig, optional
        The block; ``changes`` replace its fields.

    Returns
    -------
    UavBlock

    Examples
    --------
    >>> blk = simulate_uav_block("bauer", seed=1, n_tie=300)
    >>> len(blk.eo_true), len(blk.ground), blk.ap_model
    (15, 21, 'bauer')
    >>> bool(abs(blk.terrain(blk.ground_true[:1, 0], blk.ground_true[:1, 1])[0]
    ...          - blk.ground_true[0, 2]) < 1e-9)
    True
    """
    cfg = replace(config or UavBlockConfig(), **changes)
    if ap_model not in AP_FAMILIES and ap_model != "real":
        raise ValueError(f"unknown AP model {ap_model!r}")
    rng = np.random.default_rng(seed)
    nrng = np.random.default_rng(seed if noise_seed is None else noise_seed)
    mapping = MappingFrame.from_user_input(cfg.crs)
    # the random draws come in a fixed order (rng: geometry, nrng: noise): keep it
    true_ap, true_cam = _true_camera(cfg, ap_model, ap_scale_px, rng)
    plan = _flight_plan(cfg)
    local = LocalFrame.at_map_point(mapping, np.array([*plan.centre, cfg.ground_height_m]))
    centres, eo_local, eo_true = _true_poses(cfg, plan, mapping, local, rng)
    eo_dg, eo_sigma = _direct_georeferencing(cfg, eo_true, nrng)
    # the block's ground extent (the union of the footprints, shrunk a little)
    ext_along = (max(cfg.strips) - 1) * plan.base + 0.8 * plan.along
    ext_across = (len(cfg.strips) - 1) * plan.spacing + 0.8 * plan.across
    gcp_true, ground = _surveyed_points(cfg, plan, (ext_along, ext_across), rng, nrng)
    u = rng.uniform(-0.5, 0.5, (cfg.n_tie, 2)) * [ext_along, ext_across]
    xy = plan.centre + u[:, :1] * plan.fwd + u[:, 1:] * plan.right
    tie_map = np.column_stack([xy, _terrain(cfg, xy[:, 0], xy[:, 1])])
    tie_ids = [f"T{k + 1:05d}" for k in range(cfg.n_tie)]
    all_ids = list(ground.point_id) + tie_ids
    pts_local = local.map_to_enu(np.vstack([gcp_true, tie_map]))
    img, pt, px = _project_all(cfg, plan, true_cam, centres, eo_local, pts_local)
    obs, tie_keep = _measurements(cfg, plan.names, all_ids, ground, img, pt, px, nrng)
    return UavBlock(
        config=cfg,
        mapping=mapping,
        camera=cfg.camera,
        true_camera=true_cam,
        ap_model=ap_model,
        true_ap=true_ap,
        eo_true=eo_true,
        eo_dg=eo_dg,
        eo_sigma=eo_sigma,
        observations=obs,
        ground=ground,
        ground_true=gcp_true,
        tie_id=tuple(tie_ids[k] for k in tie_keep),
        tie_true=tie_map[tie_keep],
    )
