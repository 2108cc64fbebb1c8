"""Synthetic single-image resection scenes with known orientation (tests and benchmarks).

A frame camera over a block of roofs: control points (roof corners and ground points) and 3D
lines (ridges and eaves in the block's two street directions, hips, ground lines), all in a
local Cartesian frame (metres). :meth:`ResectionScene.observe` draws the measurements: the
image points with pixel noise, the two end points of each image line at random positions
along its projection (not the projections of the 3D line's end points: the image and the 3D
line share only the line), and the control with the noise of its covariance.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..geometry.camera import Camera
from ..geometry.collinearity import project
from ..photo.resection import ResectionData

Array = NDArray[np.float64]

__all__ = ["ResectionScene", "make_scene"]


@dataclass(frozen=True)
class ResectionScene:
    """The truth of a synthetic image: camera, orientation, control points and 3D lines.

    ``line_cov`` is the covariance of each line's (P1, P2) across the line (the LiDAR line
    precision), ``point_cov`` that of the control points; both may be zero (errorless).
    """

    camera: Camera
    eo: Array
    xyz: Array
    point_cov: Array
    p1: Array
    p2: Array
    line_cov: Array

    def with_eo(self, eo) -> ResectionScene:
        return replace(self, eo=np.asarray(eo, dtype=np.float64))

    def observe(
        self,
        rng: np.random.Generator | None = None,
        sigma_px: float = 0.5,
        points: bool = True,
        lines: bool = True,
        noisy_control: bool = True,
        vertices: int = 2,
    ) -> ResectionData:
        """One draw of the measurements (noise-free with ``rng`` None)."""
        cam, eo = self.camera, self.eo
        noise = (
            (lambda shape: rng.normal(0.0, sigma_px, shape))
            if rng is not None
            else (lambda shape: np.zeros(shape))
        )
        kw: dict = {}
        if points:
            px = project(self.xyz, eo, cam) + noise((len(self.xyz), 2))
            xyz = self.xyz.copy()
            if rng is not None and noisy_control:
                xyz += _draw(rng, self.point_cov)
            kw.update(
                point_ids=tuple(f"P{i}" for i in range(len(xyz))),
                pixels=px,
                sigma_px=sigma_px,
                xyz=xyz,
                xyz_cov=self.point_cov,
            )
        if lines:
            # the first and last point in the outer quarters of the line, the rest between
            t = np.broadcast_to(np.linspace(0.1, 0.9, vertices), (len(self.p1), vertices))
            if rng is not None:
                t = np.sort(rng.uniform(0.25, 0.75, (len(self.p1), vertices)), axis=1)
                t[:, 0] = rng.uniform(0.02, 0.25, len(self.p1))
                t[:, -1] = rng.uniform(0.75, 0.98, len(self.p1))
            pix = []
            for k in range(len(self.p1)):
                on = self.p1[k] + t[k][:, None] * (self.p2[k] - self.p1[k])
                pix.append(project(on, eo, cam) + noise((vertices, 2)))
            p12 = np.hstack([self.p1, self.p2])
            if rng is not None and noisy_control:
                p12 = p12 + _draw(rng, self.line_cov)
            kw.update(
                line_ids=tuple(f"L{i}" for i in range(len(self.p1))),
                line_pixels=tuple(pix),
                line_sigma_px=(sigma_px,) * len(pix),
                line_p1=p12[:, :3],
                line_p2=p12[:, 3:],
                line_cov=self.line_cov,
            )
        return ResectionData(**kw)


def write_scene_files(
    folder,
    scene: ResectionScene,
    data: ResectionData,
    crs: str = "EPSG:32632",
    origin_map=(500000.0, 5500000.0, 100.0),
    image_id: str = "img1",
) -> dict:
    """Write one image's observations and control as the resection job's files, placing the
    scene's local frame (ENU) at ``origin_map`` of the mapping CRS ``crs``.

    Files: ``camera.json``, ``observations.csv`` (control points as ``lcp`` rows, line points
    as ``line`` rows), ``control_points.csv`` (point_id,X,Y,Z,sx,sy,sz),
    ``control_lines.csv`` (id,x1..z2,sigma_start,sigma_end) and ``eo_true.csv`` (the true
    orientation in the mapping CRS). Returns the paths by name and the ``local`` frame.
    """

    from ..geometry.frames import LocalFrame, MappingFrame
    from ..geometry.rotations import opk_to_matrix
    from ..io.atomic import folder_files
    from ..io.camera import write_camera_json
    from ..io.observations import write_observations_csv
    from ..io.orientation import write_eo_csv
    from ..io.tables import write_csv_atomic
    from ..photo.observations import ImageObservations
    from ..photo.orientation import ExteriorOrientationTable, eo_local_to_map

    mapping = MappingFrame.from_user_input(crs)
    local = LocalFrame.at_map_point(mapping, np.asarray(origin_map, dtype=np.float64))
    csv = ("observations", "control_points", "control_lines", "eo_true")
    paths = folder_files(folder, "camera.json", *(f"{k}.csv" for k in csv))
    write_camera_json(paths["camera"], scene.camera)
    rows: dict[str, list[Any]]  # the observation table's columns
    rows = {
        "image_id": [],
        "point_id": [],
        "pixels": [],
        "sigma_px": [],
        "type": [],
        "target_id": [],
    }

    def add(pid, px, sig, kind, target):
        rows["image_id"].append(image_id)
        rows["point_id"].append(pid)
        rows["pixels"].append(px)
        rows["sigma_px"].append(sig)
        rows["type"].append(kind)
        rows["target_id"].append(target)

    for pid, px, sig in zip(data.point_ids, data.pixels, data.sigma_px):
        add(pid, px, sig, "lcp", pid)
    for lid, pxs, sigs in zip(data.line_ids, data.line_pixels, data.line_sigma_px):
        for j, (px, sig) in enumerate(zip(pxs, sigs)):
            add(f"{lid}_{j + 1}", px, sig, "line", lid)
    write_observations_csv(
        paths["observations"],
        ImageObservations.from_arrays(
            rows["image_id"],
            rows["point_id"],
            np.array(rows["pixels"]).reshape(-1, 2),
            rows["sigma_px"],
            rows["type"],
            rows["target_id"],
        ),
    )
    xyz = local.enu_to_map(data.xyz) if data.n_points else np.empty((0, 3))
    sig = np.sqrt(np.clip(np.diagonal(data.xyz_cov, axis1=1, axis2=2), 0, None))
    write_csv_atomic(
        paths["control_points"],
        ("point_id", "X", "Y", "Z", "sx", "sy", "sz"),
        [
            (i, *map(repr, map(float, p)), *map(repr, map(float, s)))
            for i, p, s in zip(data.point_ids, xyz, sig)
        ],
    )
    p1 = local.enu_to_map(data.line_p1) if data.n_lines else np.empty((0, 3))
    p2 = local.enu_to_map(data.line_p2) if data.n_lines else np.empty((0, 3))
    # the 3D sigma of each end: sqrt of the trace of its 3 x 3 covariance
    s3 = np.sqrt(np.clip(np.trace(data.line_cov[:, :3, :3], axis1=1, axis2=2), 0, None))
    s3b = np.sqrt(np.clip(np.trace(data.line_cov[:, 3:, 3:], axis1=1, axis2=2), 0, None))
    write_csv_atomic(
        paths["control_lines"],
        ("id", "x1", "y1", "z1", "x2", "y2", "z2", "sigma_start", "sigma_end"),
        [
            (
                i,
                *map(repr, map(float, a)),
                *map(repr, map(float, b)),
                repr(float(u)),
                repr(float(w)),
            )
            for i, a, b, u, w in zip(data.line_ids, p1, p2, s3, s3b)
        ],
    )
    m = opk_to_matrix(*scene.eo[3:])[None]
    exyz, eopk = eo_local_to_map(scene.eo[None, :3], m, local)
    write_eo_csv(
        paths["eo_true"],
        ExteriorOrientationTable(
            (image_id,), np.array([np.nan]), ("",), exyz, eopk, mapping.crs.to_wkt()
        ),
    )
    return {**paths, "local": local}


def _draw(rng: np.random.Generator, cov: Array) -> Array:
    """One sample of N(0, cov) per row of a (G, n, n) stack (semi-definite allowed)."""
    w, v = np.linalg.eigh(cov)
    z = rng.normal(size=w.shape) * np.sqrt(np.clip(w, 0.0, None))
    return np.einsum("gij,gj->gi", v, z)


def _cross_cov(u: Array, sigma: float) -> Array:
    """(P1, P2) covariance of a line with independent noise ``sigma`` across it at each end."""
    g = len(u)
    perp = sigma**2 * (np.eye(3) - np.einsum("li,lj->lij", u, u))
    cov = np.zeros((g, 6, 6))
    cov[:, :3, :3] = perp
    cov[:, 3:, 3:] = perp
    return cov


def make_scene(
    seed: int = 0,
    *,
    camera: Camera | None = None,
    height_m: float = 800.0,
    eo: Array | None = None,
    n_points: int = 12,
    n_lines: int = 24,
    relief_m: float = 15.0,
    line_sigma_m: float = 0.05,
    point_sigma_m: float = 0.0,
    street_azimuth_deg: float = 25.0,
) -> ResectionScene:
    """A block of roofs under a camera (module docstring).

    Parameters
    ----------
    seed : int
        Geometry seed.
    camera : Camera, optional
        Default: 100 mm, 10 um pixels, 6000 x 4000 px.
    height_m : float
        Flying height above the ground.
    eo : (6,) array_like, optional
        Default: near nadir at ``height_m``, kappa 0.6 rad.
    n_points, n_lines : int
    relief_m : float
        Heights of roofs above the ground range up to this.
    line_sigma_m, point_sigma_m : float
        Precision of the control (across each line at its ends; each point coordinate).
    street_azimuth_deg : float
        Direction of the streets (the roofs' ridges and eaves follow it and its normal).
    """
    rng = np.random.default_rng(seed)
    cam = camera or Camera(
        "sim", focal_mm=100.0, pixel_size_mm=0.010, width_px=6000, height_px=4000
    )
    e = np.array([12.0, -7.0, height_m, 0.015, -0.02, 0.6]) if eo is None else np.asarray(eo)
    # ground footprint half-sizes (with a margin inside the frame)
    half = 0.42 * np.array([cam.width_px, cam.height_px]) * cam.pixel_size_mm / cam.focal_mm
    half = half * height_m
    ca, sa = np.cos(np.radians(street_azimuth_deg)), np.sin(np.radians(street_azimuth_deg))
    streets = np.array([[ca, sa, 0.0], [-sa, ca, 0.0]])

    def inside(n: int) -> Array:
        xy = rng.uniform(-1, 1, (n, 2)) * half
        # rotate the footprint with kappa so that everything stays in the image
        k = e[5]
        rot = np.array([[np.cos(k), np.sin(k)], [-np.sin(k), np.cos(k)]])
        return xy @ rot + e[:2]

    xyz = np.column_stack([inside(n_points), rng.uniform(0, relief_m, n_points)])
    mids = np.column_stack([inside(n_lines), rng.uniform(0, relief_m, n_lines)])
    kind = rng.integers(0, 4, n_lines)  # 0/1 the two street directions, 2 hips, 3 ground
    d = streets[kind % 2].copy()
    hip = kind == 2
    d[hip] = (streets[0] + streets[1] * rng.choice([-1, 1], hip.sum())[:, None]) / np.sqrt(2)
    d[hip, 2] = rng.uniform(-0.6, 0.6, hip.sum())
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    mids[kind == 3, 2] = rng.uniform(-1.0, 1.0, (kind == 3).sum())
    length = rng.uniform(8.0, 30.0, n_lines)
    p1 = mids - 0.5 * length[:, None] * d
    p2 = mids + 0.5 * length[:, None] * d
    line_cov = _cross_cov(d, line_sigma_m)
    point_cov = np.broadcast_to(point_sigma_m**2 * np.eye(3), (n_points, 3, 3)).copy()
    return ResectionScene(cam, e.astype(np.float64), xyz, point_cov, p1, p2, line_cov)
