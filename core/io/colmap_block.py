"""COLMAP models <-> the project's cameras, exterior orientations, observations and points.

Cameras
-------
COLMAP's intrinsics are in pixels and its distortion acts on ideal coordinates normalised by
the focal length (a forward model). A COLMAP camera becomes a :class:`Camera` with the stated
pixel size (COLMAP has none; it only scales millimetres, never the projection):
``focal_mm = fx * pixel_size_mm``, the principal point from ``(cx, cy)`` (COLMAP's pixel
convention is the project's: the first pixel's centre is (0.5, 0.5)), and the lens a forward
model of :mod:`core.geometry.forward_lens` with COLMAP's own coefficients, ``scale_mm =
focal_mm`` and ``aspect = fy / fx``:

===========================  =============================================  ===============
COLMAP                       lens model (coefficients)                      projection
===========================  =============================================  ===============
SIMPLE_PINHOLE               none                                           perspective
PINHOLE                      none (fx = fy) or ``opencv`` (zeros, aspect)   perspective
SIMPLE_RADIAL, RADIAL        ``opencv`` (k1 = k; k1, k2)                    perspective
OPENCV                       ``opencv`` (k1, k2, p1, p2)                    perspective
FULL_OPENCV                  ``opencv_full`` (k1, k2, p1, p2, k3..k6)       perspective
OPENCV_FISHEYE               ``opencv_fisheye`` (k1..k4)                    equidistant
SIMPLE_RADIAL_FISHEYE,       ``opencv_fisheye`` (k1 = k; k1, k2)            equidistant
RADIAL_FISHEYE
THIN_PRISM_FISHEYE           ``thin_prism_fisheye`` (k1 k2 p1 p2 k3 k4      equidistant
                             sx1 sy1)
===========================  =============================================  ===============

FOV and RAD_TAN_THIN_PRISM_FISHEYE are refused by name. Every mapping
is exact (the formulas are the same, not fitted).

Orientations
------------
COLMAP stores world-to-camera ``R(q), t`` with its camera frame x right, y down, z forward;
the project's camera frame is x right, y up, z backward (docs/conventions.md, "Images"), so
``M = diag(1, -1, -1) R(q)`` and the centre is ``C = -R(q)^T t``. A similarity ``X' = s R X +
T`` (the model's frame to the stated one) gives ``C' = s R C + T`` and ``M' = M R^T``. In
ECEF, ``M`` is turned to the grid frame at each centre (grid east, grid north, up) and the
centres and points are transformed into the mapping CRS.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Dict, List, Mapping, Sequence, Tuple, TypeVar

import numpy as np
from numpy.typing import NDArray

from ..errors import CrsError, InputError
from ..geometry.camera import Camera
from ..geometry.distortion import DistortionModel, NoDistortion
from ..geometry.forward_lens import (
    OpenCVFisheyeLens,
    OpenCVFullLens,
    OpenCVLens,
    ThinPrismFisheyeLens,
    opencv_coefficients,
)
from ..geometry.rotations import matrix_to_opk, opk_to_matrix
from ..photo.bundle_setup import DEFAULT_CONTROL_SIGMA_M, GroundPoints
from ..photo.observations import DEFAULT_SIGMA_PX, ImageObservations
from ..photo.orientation import ExteriorOrientationTable
from .colmap import ColmapCamera, ColmapImage, ColmapModel, ColmapPoint

Array = NDArray[np.float64]
K = TypeVar("K")
C = TypeVar("C")

__all__ = [
    "ColmapBlock",
    "ColmapFrame",
    "block_from_colmap",
    "camera_from_colmap",
    "camera_to_colmap",
    "colmap_from_block",
    "frame_from_text",
    "named_cameras",
    "quaternion_to_matrix",
    "tie_block",
    "to_frame",
]

#: The project's camera frame from COLMAP's (y and z flipped).
_FLIP = np.diag([1.0, -1.0, -1.0])
_REFUSED = ("FOV", "RAD_TAN_THIN_PRISM_FISHEYE")


@dataclass(frozen=True)
class ColmapFrame:
    """The frame of a COLMAP model's coordinates (COLMAP stores none).

    kind: ``"local"`` (as they are, no CRS), ``"crs"`` (the coordinates are easting,
    northing, height of ``crs``) or ``"ecef"`` (Earth-centred, converted to ``crs``).
    scale, rotation (3, 3), translation (3,): a similarity applied first, model -> frame.
    """

    kind: str
    crs: str = ""
    scale: float = 1.0
    rotation: Array = field(default_factory=lambda: np.eye(3))
    translation: Array = field(default_factory=lambda: np.zeros(3))


def quaternion_to_matrix(q: Sequence[float]) -> Array:
    """Rotation matrix (3, 3) of a Hamilton quaternion (qw, qx, qy, qz), normalised first.

    >>> quaternion_to_matrix([0.0, 0.0, 0.0, 1.0]).round(12).tolist()[0]
    [-1.0, 0.0, 0.0]
    """
    w, x, y, z = np.asarray(q, dtype=np.float64) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def matrix_to_quaternion(r: Array) -> Tuple[float, float, float, float]:
    """Quaternion (qw >= 0, qx, qy, qz) of a rotation matrix (Shepperd's method)."""
    m = np.asarray(r, dtype=np.float64)
    tr = np.trace(m)
    cands = [1.0 + tr, 1.0 + 2 * m[0, 0] - tr, 1.0 + 2 * m[1, 1] - tr, 1.0 + 2 * m[2, 2] - tr]
    k = int(np.argmax(cands))
    s = 2.0 * np.sqrt(cands[k])
    if k == 0:
        q = [s / 4, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
    elif k == 1:
        q = [(m[2, 1] - m[1, 2]) / s, s / 4, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s]
    elif k == 2:
        q = [(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, s / 4, (m[1, 2] + m[2, 1]) / s]
    else:
        q = [(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, s / 4]
    if q[0] < 0:
        q = [-v for v in q]
    return (float(q[0]), float(q[1]), float(q[2]), float(q[3]))


def frame_from_text(frame: str, crs: str = "", similarity: str = "") -> ColmapFrame:
    """The frame stated by the user: ``LOCAL``, ``ECEF`` (with ``crs``, the mapping CRS to
    convert to) or a CRS (``EPSG:32723``, WKT); ``similarity`` is empty or eight numbers
    ``s qw qx qy qz tx ty tz`` (model -> frame: ``X' = s R(q) X + t``).

    Raises
    ------
    CrsError
        No frame given (a COLMAP model has none), or ECEF without a mapping CRS.
    """
    text = (frame or "").strip()
    if not text:
        raise CrsError(
            "FRAME: a COLMAP model has no coordinate reference system; state its frame "
            "(LOCAL, ECEF with a mapping CRS, or the CRS its coordinates are in, e.g. EPSG:32723)"
        )
    scale, rot, trans = 1.0, np.eye(3), np.zeros(3)
    if similarity.strip():
        try:
            vals = [float(v) for v in similarity.replace(",", " ").split()]
        except ValueError:
            vals = []
        if len(vals) != 8 or not all(np.isfinite(vals)) or vals[0] <= 0 or not any(vals[1:5]):
            raise InputError(
                f"SIMILARITY: expected eight numbers 's qw qx qy qz tx ty tz' with s > 0, "
                f"got {similarity!r}"
            )
        scale, rot, trans = vals[0], quaternion_to_matrix(vals[1:5]), np.array(vals[5:])
    kind = text.lower()
    if kind == "ecef" and not crs.strip():
        raise CrsError("FRAME ECEF: give the mapping CRS to convert the model to (CRS)")
    if kind in ("local", "ecef"):
        return ColmapFrame(kind, crs.strip(), scale, rot, trans)
    return ColmapFrame("crs", text, scale, rot, trans)


# ---------------------------------------------------------------------- cameras
def camera_from_colmap(cam: ColmapCamera, pixel_size_mm: float, name: str) -> Camera:
    """The project's camera of a COLMAP camera (exact; see the module docstring).

    Raises
    ------
    InputError
        For a COLMAP model the project does not represent (FOV, thin-prism fisheyes).
    """
    if cam.model in _REFUSED:
        raise InputError(
            f"camera {cam.camera_id}: COLMAP camera model {cam.model} is not supported "
            "(no lens model of the project represents it exactly)"
        )
    from .colmap import COLMAP_MODELS

    names = dict(COLMAP_MODELS.values())[cam.model]
    p = dict(zip(names, cam.params))
    fx = p.get("fx", p.get("f", 0.0))
    fy = p.get("fy", fx)
    if not (fx > 0 and fy > 0):
        raise InputError(f"camera {cam.camera_id}: the focal length must be positive, got {fx}")
    ps = float(pixel_size_mm)
    f_mm = fx * ps
    common = {"scale_mm": f_mm, "aspect": fy / fx}
    projection = "perspective"
    lens: DistortionModel
    if cam.model in ("SIMPLE_PINHOLE", "PINHOLE") and fx == fy:
        lens = NoDistortion()
    elif cam.model in ("SIMPLE_PINHOLE", "PINHOLE"):
        lens = OpenCVLens(**common)
    elif cam.model == "SIMPLE_RADIAL":
        lens = OpenCVLens(k1=p["k"], **common)
    elif cam.model in ("RADIAL", "OPENCV"):
        lens = OpenCVLens(**{k: p.get(k, 0.0) for k in ("k1", "k2", "p1", "p2")}, **common)
    elif cam.model == "FULL_OPENCV":
        lens = OpenCVFullLens(**{k: p[k] for k in OpenCVFullLens.param_names}, **common)
    elif cam.model == "THIN_PRISM_FISHEYE":
        projection = "equidistant"
        lens = ThinPrismFisheyeLens(**{k: p[k] for k in ThinPrismFisheyeLens.param_names}, **common)
    else:  # the fisheyes: OPENCV_FISHEYE, SIMPLE_RADIAL_FISHEYE, RADIAL_FISHEYE
        projection = "equidistant"
        coef = {"k1": p.get("k", 0.0)} if "k" in p else {}
        coef.update({k: p[k] for k in ("k1", "k2", "k3", "k4") if k in p})
        lens = OpenCVFisheyeLens(**coef, **common)
    x0 = (p["cx"] - 0.5 * cam.width) * ps
    y0 = (0.5 * cam.height - p["cy"]) * ps
    return Camera(name, f_mm, ps, cam.width, cam.height, x0, y0, lens, projection)


def camera_to_colmap(camera: Camera, camera_id: int) -> ColmapCamera:
    """The COLMAP camera of a project camera, exactly; refuses a correction lens model.

    Raises
    ------
    InputError
        For a lens model that is a correction (measured -> ideal: no COLMAP model holds it
        exactly) or a fisheye projection other than equidistant with ``opencv_fisheye``.
    """
    lens = camera.distortion
    f_px = camera.focal_px
    cx, cy = camera.principal_point_px
    fisheye = camera.projection == "equidistant"
    if camera.projection not in ("perspective", "equidistant"):
        raise InputError(
            f"camera {camera.name!r}: the {camera.projection} projection has no COLMAP camera model"
        )
    if isinstance(lens, NoDistortion):
        if fisheye:
            return ColmapCamera(
                camera_id,
                "OPENCV_FISHEYE",
                camera.width_px,
                camera.height_px,
                (f_px, f_px, cx, cy, 0.0, 0.0, 0.0, 0.0),
            )
        return ColmapCamera(
            camera_id, "SIMPLE_PINHOLE", camera.width_px, camera.height_px, (f_px, cx, cy)
        )
    fisheye_lens = isinstance(lens, (OpenCVFisheyeLens, ThinPrismFisheyeLens))
    if fisheye_lens != fisheye or not isinstance(
        lens, (OpenCVLens, OpenCVFullLens, OpenCVFisheyeLens, ThinPrismFisheyeLens)
    ):
        raise InputError(
            f"camera {camera.name!r}: lens model {lens.model!r} with the {camera.projection} "
            "projection has no exact COLMAP camera model (a correction model cannot be "
            "written as COLMAP's forward distortion)"
        )
    c = opencv_coefficients(lens, camera.focal_mm)
    fy = lens.constants["aspect"] * f_px
    names: Tuple[str, ...]
    if isinstance(lens, OpenCVFisheyeLens):
        model, names = "OPENCV_FISHEYE", ("k1", "k2", "k3", "k4")
    elif isinstance(lens, ThinPrismFisheyeLens):
        model, names = "THIN_PRISM_FISHEYE", ThinPrismFisheyeLens.param_names
    elif type(lens) is OpenCVLens and c["k3"] == 0.0:
        model, names = "OPENCV", ("k1", "k2", "p1", "p2")
    else:
        model, names = "FULL_OPENCV", OpenCVFullLens.param_names
    params = (f_px, fy, cx, cy, *(c.get(n, 0.0) for n in names))
    return ColmapCamera(camera_id, model, camera.width_px, camera.height_px, params)


# ---------------------------------------------------------------------- the block
@dataclass(frozen=True)
class ColmapBlock:
    """A COLMAP model in the project's terms.

    cameras: one per COLMAP camera; eo: the registered images (``image_id`` = COLMAP's image
    name) in the stated frame (``crs_wkt`` empty for LOCAL); camera: the camera name per
    image; observations: the tracked keypoints (type ``tie``, ``point_id`` = COLMAP's point
    id); points: the 3D points (role ``check``: triangulated tie points, never control).
    """

    cameras: Tuple[Camera, ...]
    eo: ExteriorOrientationTable
    camera: Tuple[str, ...]
    observations: ImageObservations
    points: GroundPoints


def to_frame(frame: ColmapFrame, xyz: Array, m: Array) -> Tuple[Array, Array, str]:
    """Model-frame centres/points (N, 3) and rotations M (K, 3, 3) -> the frame's (and its WKT).

    Shared with the OpenSfM import (its topocentric frame is an ECEF similarity).

    ``m`` applies to the first K rows of ``xyz`` (the image centres)."""
    x = frame.scale * xyz @ frame.rotation.T + frame.translation
    mm = m @ frame.rotation.T
    if frame.kind == "local":
        return x, mm, ""
    from ..geometry.frames import MappingFrame, enu_rotation, grid_rotation

    try:
        mapping = MappingFrame.from_user_input(frame.crs)
    except Exception as exc:
        raise CrsError(f"CRS {frame.crs!r}: {exc}") from exc
    if frame.kind == "crs":
        return x, mm, mapping.crs.to_wkt()
    llh = mapping.ecef_to_geodetic(x[: m.shape[0]])
    r_eg = grid_rotation(mapping.grid_north_azimuth(llh)) @ enu_rotation(llh[:, 0], llh[:, 1])
    return mapping.ecef_to_map(x), mm @ np.swapaxes(r_eg, -1, -2), mapping.crs.to_wkt()


def oriented(
    frame: ColmapFrame,
    names: Sequence[str],
    r: NDArray[np.float64],
    t: NDArray[np.float64],
    xyz: NDArray[np.float64],
) -> Tuple[ExteriorOrientationTable, NDArray[np.float64]]:
    """The EO table of images given as world -> camera rotations ``r`` (N, 3, 3) and
    translations ``t`` (N, 3) in the camera frame x right, y down, z forward (COLMAP's and
    OpenSfM's), and the points ``xyz`` (M, 3), both converted into ``frame``."""
    centres = -np.einsum("nji,nj->ni", r, t)
    allx, m, wkt = to_frame(frame, np.vstack([centres, xyz]), _FLIP @ r)
    w, ph, k = matrix_to_opk(m)
    n = len(names)
    eo = ExteriorOrientationTable(
        tuple(names), np.full(n, np.nan), ("",) * n, allx[:n], np.column_stack([w, ph, k]), wkt
    )
    return eo, allx[n:]


def block_from_colmap(model: ColmapModel, frame: ColmapFrame, pixel_size_mm: float) -> ColmapBlock:
    """Convert a COLMAP model (see the module docstring for the rules)."""
    cam_names, cams = named_cameras("colmap", model.cameras, camera_from_colmap, pixel_size_mm)
    images: List[ColmapImage] = sorted(model.images.values(), key=lambda im: im.image_id)
    if not images:
        raise InputError("the model has no registered image", path=model.source)
    names = [im.name for im in images]
    if len(set(names)) != len(names):
        raise InputError("two images have the same name", path=model.source)
    r = np.array([quaternion_to_matrix(im.qvec) for im in images])
    t = np.array([im.tvec for im in images], dtype=np.float64)
    pts: List[ColmapPoint] = sorted(model.points.values(), key=lambda p: p.point_id)
    xyz = np.array([p.xyz for p in pts], dtype=np.float64).reshape(-1, 3)
    eo, point_xyz = oriented(frame, names, r, t, xyz)
    known = set(model.points)
    rows: Dict[str, list] = {"image": [], "point": [], "px": []}
    for im in images:
        keep = np.flatnonzero(im.point3d_id >= 0)
        for j in keep:
            if int(im.point3d_id[j]) not in known and known:
                raise InputError(
                    f"image {im.name!r}: keypoint {j} names 3D point "
                    f"{int(im.point3d_id[j])}, not in points3D",
                    path=model.source,
                )
            rows["image"].append(im.name)
            rows["point"].append(str(int(im.point3d_id[j])))
            rows["px"].append(im.xy[j])
    per_image = tuple(cam_names[im.camera_id] for im in images)
    obs, ground = tie_block(
        rows["image"], rows["point"], rows["px"], [str(p.point_id) for p in pts], point_xyz
    )
    return ColmapBlock(cams, eo, per_image, obs, ground)


def named_cameras(
    prefix: str,
    cameras: Mapping[K, C],
    convert: Callable[[C, float, str], Camera],
    pixel_size_mm: float,
) -> Tuple[Dict[K, str], Tuple[Camera, ...]]:
    """The project cameras of a reconstruction's ``cameras`` (key -> its own camera record),
    each named ``<prefix>_<key>`` and made by ``convert(record, pixel_size_mm, name)``; and
    the name of each key.

    >>> named_cameras("x", {1: "a", 2: "b"}, lambda c, p, n: f"{n}={c}@{p}", 0.01)
    ({1: 'x_1', 2: 'x_2'}, ('x_1=a@0.01', 'x_2=b@0.01'))
    """
    names = {k: f"{prefix}_{k}" for k in cameras}
    return names, tuple(convert(c, pixel_size_mm, names[k]) for k, c in cameras.items())


def tie_block(
    image_ids: Sequence[str],
    point_ids: Sequence[str],
    pixels: Sequence[Sequence[float]] | Array,
    ground_ids: Sequence[str],
    ground_xyz: Array,
) -> Tuple[ImageObservations, GroundPoints]:
    """The observations and points of a reconstruction: its keypoints as ``tie`` observations
    of sigma DEFAULT_SIGMA_PX (no group), its triangulated points as ``check`` points of
    sigma DEFAULT_CONTROL_SIGMA_M (never control: :class:`ColmapBlock`).

    >>> obs, pts = tie_block(["a"], ["7"], [[1.0, 2.0]], ["7"], np.zeros((1, 3)))
    >>> obs.type, obs.pixels.tolist(), pts.role
    (('tie',), [[1.0, 2.0]], ('check',))
    """
    n_obs = len(image_ids)
    obs = ImageObservations(
        tuple(image_ids),
        tuple(point_ids),
        np.array(pixels, dtype=np.float64).reshape(-1, 2),
        np.full(n_obs, DEFAULT_SIGMA_PX),
        ("tie",) * n_obs,
        ("",) * n_obs,
    )
    ground = GroundPoints(
        tuple(ground_ids),
        ground_xyz,
        np.full((len(ground_ids), 3), DEFAULT_CONTROL_SIGMA_M),
        ("check",) * len(ground_ids),
    )
    return obs, ground


def colmap_from_block(
    cameras: Sequence[Camera],
    eo: ExteriorOrientationTable,
    camera: Sequence[str] | None = None,
    observations: ImageObservations | None = None,
    points: GroundPoints | None = None,
) -> ColmapModel:
    """A COLMAP model of the project's cameras and orientations, in the EO's own frame.

    ``camera``: the camera name of each image (None: the only camera). Observations of
    points in ``points`` become keypoints with their 3D point and tracks; others are
    written as untracked keypoints (-1).
    """
    by_name = {c.name: k + 1 for k, c in enumerate(cameras)}
    if camera is None:
        if len(cameras) != 1:
            raise InputError("several cameras: the EO must name each image's camera")
        camera = (cameras[0].name,) * len(eo)
    cols = {k + 1: camera_to_colmap(c, k + 1) for k, c in enumerate(cameras)}
    m = opk_to_matrix(eo.opk[:, 0], eo.opk[:, 1], eo.opk[:, 2])
    r = _FLIP @ m
    t = -np.einsum("nij,nj->ni", r, eo.xyz)
    point_ids = {p: k + 1 for k, p in enumerate(points.point_id)} if points is not None else {}
    tracks: Dict[int, list] = {v: [] for v in point_ids.values()}
    images: Dict[int, ColmapImage] = {}
    for k, name in enumerate(eo.image_id):
        if camera[k] not in by_name:
            raise InputError(f"image {name!r}: camera {camera[k]!r} is not in the camera file")
        xy, pid = np.zeros((0, 2)), []
        if observations is not None:
            sel = [j for j, i in enumerate(observations.image_id) if i == name]
            xy = observations.pixels[sel]
            pid = [point_ids.get(observations.point_id[j], -1) for j in sel]
            for idx, p in enumerate(pid):
                if p > 0:
                    tracks[p].append((k + 1, idx))
        images[k + 1] = ColmapImage(
            k + 1,
            matrix_to_quaternion(r[k]),
            tuple(t[k].tolist()),
            by_name[camera[k]],
            name,
            xy,
            np.array(pid, dtype=np.int64),
        )
    pts: Dict[int, ColmapPoint] = {}
    if points is not None:
        for v in point_ids.values():
            xyz = (
                float(points.xyz[v - 1, 0]),
                float(points.xyz[v - 1, 1]),
                float(points.xyz[v - 1, 2]),
            )
            pts[v] = ColmapPoint(v, xyz, (128, 128, 128), 0.0, tuple(tracks[v]))
    return ColmapModel(cols, images, pts)
