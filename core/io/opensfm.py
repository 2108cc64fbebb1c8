"""OpenSfM / ODM reconstructions (``reconstruction.json``) -> the project's cameras, EO, points.

The file
--------
``reconstruction.json`` is a list of reconstructions, each with ``cameras`` (id -> intrinsics),
``shots`` (image name -> camera id, ``rotation`` axis-angle and ``translation``, world ->
camera), ``points`` (id -> ``coordinates``) and, in ODM's, ``reference_lla`` (the origin of
the topocentric frame; ODM also writes ``reference_lla.json`` beside it). The image
observations are in ``tracks.csv`` beside the file (image, track id, feature id, x, y, ...;
read when present).

Cameras
-------
OpenSfM normalises image coordinates by ``size = max(width, height)`` with the origin at the
image centre: ``x_n = (u - width / 2) / size`` where ``u`` is the project's pixel coordinate
(the first pixel's centre at 0.5; OpenSfM's at 0, hence its ``u + 0.5``). Its focal lengths
and principal points are normalised the same way and its distortion acts on ``X/Z, Y/Z``
(x right, y down, z forward): a forward model, mapped exactly onto
:mod:`core.geometry.forward_lens` with OpenSfM's own coefficients (``scale_mm = focal_mm``,
``aspect = focal_y / focal_x``):

==============  ============================================  ===========
OpenSfM         lens model (coefficients)                     projection
==============  ============================================  ===========
perspective     ``opencv`` (k1, k2)                           perspective
simple_radial   ``opencv`` (k1), with focal_x/y, c_x, c_y     perspective
radial          ``opencv`` (k1, k2), with focal_x/y, c_x, c_y perspective
brown           ``opencv`` (k1, k2, k3, p1, p2)               perspective
fisheye         ``opencv_fisheye`` (k1, k2)                   equidistant
fisheye_opencv  ``opencv_fisheye`` (k1..k4, aspect_ratio)     equidistant
==============  ============================================  ===========

OpenSfM's Brown tangential terms are OpenCV's (``x += 2 p1 x y + p2 (r2 + 2 x^2)``, ``y +=
p1 (r2 + 2 y^2) + 2 p2 x y``, as in OpenSfM's ``camera_distortions_functions.h``).
Spherical (equirectangular), dual, fisheye62/624 are refused by name.

Orientations and frame
----------------------
As COLMAP's: ``M = diag(1, -1, -1) R`` with ``R`` the rotation of the axis-angle vector and
the centre ``C = -R^T t``. The coordinates are topocentric (east, north, up at
``reference_lla``, on WGS84). With a mapping CRS they are taken to ECEF (``X = X0 + E^T x``,
``E`` the ENU rotation at the origin) and into the CRS with each rotation turned to the grid
frame at its centre (:func:`core.io.colmap_block.to_frame`); without one they stay LOCAL.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Dict, List, Mapping, Tuple

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..geometry.camera import Camera
from ..geometry.distortion import DistortionModel
from ..geometry.forward_lens import OpenCVFisheyeLens, OpenCVLens
from .colmap_block import ColmapBlock, ColmapFrame, named_cameras, oriented, tie_block

Array = NDArray[np.float64]

__all__ = [
    "OPENSFM_MODELS",
    "OpenSfmCamera",
    "OpenSfmReconstruction",
    "OpenSfmShot",
    "block_from_opensfm",
    "camera_from_opensfm",
    "read_opensfm",
    "rotation_from_axis_angle",
]

#: Supported projection types and their keys (besides width, height).
OPENSFM_MODELS: Dict[str, Tuple[str, ...]] = {
    "perspective": ("focal", "k1", "k2"),
    "simple_radial": ("focal_x", "focal_y", "c_x", "c_y", "k1"),
    "radial": ("focal_x", "focal_y", "c_x", "c_y", "k1", "k2"),
    "brown": ("focal_x", "focal_y", "c_x", "c_y", "k1", "k2", "k3", "p1", "p2"),
    "fisheye": ("focal", "k1", "k2"),
    "fisheye_opencv": ("focal", "aspect_ratio", "c_x", "c_y", "k1", "k2", "k3", "k4"),
}
_REFUSED = ("spherical", "equirectangular", "dual", "fisheye62", "fisheye624")


@dataclass(frozen=True)
class OpenSfmCamera:
    """One camera: its id, projection type, size (px) and normalised parameters."""

    camera_id: str
    projection_type: str
    width: int
    height: int
    params: Mapping[str, float]


@dataclass(frozen=True)
class OpenSfmShot:
    """One shot: image name, camera id, axis-angle rotation and translation (world -> camera)."""

    name: str
    camera: str
    rotation: Tuple[float, float, float]
    translation: Tuple[float, float, float]


@dataclass(frozen=True)
class OpenSfmReconstruction:
    """One reconstruction of a ``reconstruction.json`` and the tracks of its shots.

    points: id -> topocentric xyz (m); reference_lla: (lat, lon deg, h m) or None;
    tracks: (image, point id, x_n, y_n) rows in normalised image coordinates.
    """

    cameras: Dict[str, OpenSfmCamera]
    shots: Dict[str, OpenSfmShot]
    points: Dict[str, Tuple[float, float, float]]
    reference_lla: Tuple[float, float, float] | None
    tracks: Tuple[Tuple[str, str, float, float], ...]
    source: str


def rotation_from_axis_angle(v: Any) -> Array:
    """Rotation matrix (3, 3) of an axis-angle vector (rad), Rodrigues' formula."""
    w = np.asarray(v, dtype=np.float64)
    th = float(np.linalg.norm(w))
    k = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    if th < 1e-12:  # second order: exact to rounding for such angles
        return np.eye(3) + k + 0.5 * k @ k
    k /= th
    return np.eye(3) + np.sin(th) * k + (1.0 - np.cos(th)) * k @ k


# ---------------------------------------------------------------------- reading
def _number(obj: Mapping[str, Any], key: str, what: str, path: str) -> float:
    if key not in obj:
        raise InputError(f"{what}: key '{key}' is missing", path=path)
    try:
        val = float(obj[key])
    except (TypeError, ValueError):
        val = float("nan")
    if not np.isfinite(val):
        raise InputError(f"{what}: key '{key}' is not a finite number: {obj[key]!r}", path=path)
    return val


def _vector(obj: Mapping[str, Any], key: str, what: str, path: str) -> Tuple[float, float, float]:
    val = obj.get(key)
    try:
        arr = np.asarray(val, dtype=np.float64)
    except (TypeError, ValueError):
        arr = np.zeros(0)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise InputError(f"{what}: key '{key}' must be three numbers, got {val!r}", path=path)
    return (float(arr[0]), float(arr[1]), float(arr[2]))


def _read_camera(cid: str, obj: Any, path: str) -> OpenSfmCamera:
    what = f"camera {cid!r}"
    if not isinstance(obj, dict):
        raise InputError(f"{what}: expected an object", path=path)
    kind = str(obj.get("projection_type", "perspective"))
    if kind in _REFUSED:
        raise InputError(
            f"{what}: OpenSfM projection type '{kind}' is not supported (no "
            "camera model of the project represents it)",
            path=path,
        )
    if kind not in OPENSFM_MODELS:
        raise InputError(f"{what}: unknown OpenSfM projection type '{kind}'", path=path)
    w, h = (_number(obj, k, what, path) for k in ("width", "height"))
    if not (w >= 1 and h >= 1 and w == int(w) and h == int(h)):
        raise InputError(f"{what}: width and height must be positive integers", path=path)
    params = {k: _number(obj, k, what, path) for k in OPENSFM_MODELS[kind]}
    return OpenSfmCamera(cid, kind, int(w), int(h), params)


def _read_tracks(path: Path, shots: Mapping[str, Any], points: Mapping[str, Any]) -> list:
    rows = []
    for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        if not line.strip() or line.startswith("OPENSFM_TRACKS_VERSION"):
            continue
        f = line.split("\t")
        try:
            x, y = float(f[3]), float(f[4])
        except (IndexError, ValueError):
            raise InputError(
                "expected image, track, feature, x, y separated by tabs", path=str(path), row=n
            ) from None
        if f[0] in shots and f[1] in points:
            rows.append((f[0], f[1], x, y))
    return rows


def read_opensfm(path: str | Path, index: int = 0) -> OpenSfmReconstruction:
    """Read reconstruction ``index`` of a ``reconstruction.json`` (a file or its folder), its
    ``reference_lla`` (in the file or ``reference_lla.json`` beside) and ``tracks.csv``.

    Raises
    ------
    InputError
        Naming the file and the camera, shot or key at fault.
    """
    p = Path(path)
    if p.is_dir():
        p = p / "reconstruction.json"
    src = str(p)
    try:
        data = json.loads(p.read_text(encoding="utf-8"))
    except OSError as exc:
        msg = f"cannot read the reconstruction: {exc.strerror or exc}"
        raise InputError(msg, path=src) from exc
    except ValueError as exc:
        raise InputError(f"not a JSON file: {exc}", path=src) from exc
    if not isinstance(data, list) or not data:
        raise InputError("expected a list of reconstructions", path=src)
    if not 0 <= index < len(data) or not isinstance(data[index], dict):
        raise InputError(
            f"reconstruction {index} does not exist (the file has {len(data)})", path=src
        )
    rec = data[index]
    for key in ("cameras", "shots"):
        if not isinstance(rec.get(key), dict):
            raise InputError(f"reconstruction {index}: key '{key}' is missing", path=src)
    cams = {str(k): _read_camera(str(k), v, src) for k, v in rec["cameras"].items()}
    shots = {}
    for name, s in rec["shots"].items():
        what = f"shot {name!r}"
        if not isinstance(s, dict) or "camera" not in s:
            raise InputError(f"{what}: key 'camera' is missing", path=src)
        if str(s["camera"]) not in cams:
            raise InputError(f"{what}: camera {s['camera']!r} is not in cameras", path=src)
        shots[str(name)] = OpenSfmShot(
            str(name),
            str(s["camera"]),
            _vector(s, "rotation", what, src),
            _vector(s, "translation", what, src),
        )
    points = {
        str(k): _vector(v if isinstance(v, dict) else {}, "coordinates", f"point {k!r}", src)
        for k, v in (rec.get("points") or {}).items()
    }
    ref = rec.get("reference_lla")
    ref_file = p.parent / "reference_lla.json"
    if ref is None and ref_file.is_file():
        try:
            ref = json.loads(ref_file.read_text(encoding="utf-8"))
        except ValueError as exc:
            raise InputError(f"not a JSON file: {exc}", path=str(ref_file)) from exc
        src_ref = str(ref_file)
    else:
        src_ref = src
    lla: Tuple[float, float, float] | None = None
    if ref is not None:
        obj = ref if isinstance(ref, dict) else {}
        lat, lon, alt = (
            _number(obj, k, "reference_lla", src_ref) for k in ("latitude", "longitude", "altitude")
        )
        lla = (lat, lon, alt)
    tracks_file = p.parent / "tracks.csv"
    tracks = _read_tracks(tracks_file, shots, points) if tracks_file.is_file() else []
    return OpenSfmReconstruction(cams, shots, points, lla, tuple(tracks), src)


# ---------------------------------------------------------------------- conversion
def camera_from_opensfm(cam: OpenSfmCamera, pixel_size_mm: float, name: str) -> Camera:
    """The project's camera of an OpenSfM camera (exact; see the module docstring)."""
    p, size, ps = dict(cam.params), float(max(cam.width, cam.height)), float(pixel_size_mm)
    fx = p.get("focal", p.get("focal_x", 0.0))
    fy = p.get("focal_y", fx * p.get("aspect_ratio", 1.0))
    if not (fx > 0 and fy > 0):
        raise InputError(f"camera {cam.camera_id!r}: the focal length must be positive, got {fx}")
    f_mm = fx * size * ps
    common = {"scale_mm": f_mm, "aspect": fy / fx}
    coef = {k: p[k] for k in ("k1", "k2", "k3", "k4", "p1", "p2") if k in p}
    lens: DistortionModel
    projection = "perspective"
    if cam.projection_type.startswith("fisheye"):
        projection = "equidistant"
        lens = OpenCVFisheyeLens(**coef, **common)
    else:
        lens = OpenCVLens(**coef, **common)
    x0 = p.get("c_x", 0.0) * size * ps
    y0 = -p.get("c_y", 0.0) * size * ps
    return Camera(name, f_mm, ps, cam.width, cam.height, x0, y0, lens, projection)


def topocentric_frame(reference_lla: Tuple[float, float, float] | None, crs: str) -> ColmapFrame:
    """The frame of OpenSfM's coordinates: LOCAL (``crs`` empty) or topocentric at
    ``reference_lla`` as an ECEF similarity, converted to the mapping ``crs``."""
    if not crs.strip():
        return ColmapFrame("local")
    if reference_lla is None:
        raise InputError(
            "CRS given but the reconstruction has no reference_lla (nor a "
            "reference_lla.json beside it): its frame is unknown; leave CRS empty "
            "for LOCAL"
        )
    from ..geometry.frames import MappingFrame, enu_rotation

    try:
        mapping = MappingFrame.from_user_input(crs)
    except Exception as exc:
        from ..errors import CrsError

        raise CrsError(f"CRS {crs!r}: {exc}") from exc
    lat, lon, h = reference_lla
    x0 = mapping.geodetic_to_ecef(np.array([[lat, lon, h]]))[0]
    # enu = E (X - X0)  <=>  X = E^T enu + X0
    return ColmapFrame("ecef", crs.strip(), 1.0, enu_rotation(lat, lon).T, x0)


def block_from_opensfm(rec: OpenSfmReconstruction, crs: str, pixel_size_mm: float) -> ColmapBlock:
    """Convert one reconstruction (see the module docstring): LOCAL, or into ``crs``."""
    frame = topocentric_frame(rec.reference_lla, crs)
    cam_names, cams = named_cameras("opensfm", rec.cameras, camera_from_opensfm, pixel_size_mm)
    shots: List[OpenSfmShot] = sorted(rec.shots.values(), key=lambda s: s.name)
    if not shots:
        raise InputError("the reconstruction has no shot", path=rec.source)
    r = np.array([rotation_from_axis_angle(s.rotation) for s in shots])
    t = np.array([s.translation for s in shots], dtype=np.float64)
    pids = sorted(rec.points)
    xyz = np.array([rec.points[k] for k in pids], dtype=np.float64).reshape(-1, 3)
    eo, point_xyz = oriented(frame, [s.name for s in shots], r, t, xyz)
    px = np.empty((len(rec.tracks), 2))
    for j, (img, _, xn, yn) in enumerate(rec.tracks):
        c = rec.cameras[rec.shots[img].camera]
        size = max(c.width, c.height)
        px[j] = (xn * size + 0.5 * c.width, yn * size + 0.5 * c.height)
    obs, ground = tie_block(
        [r_[0] for r_ in rec.tracks], [r_[1] for r_ in rec.tracks], px, pids, point_xyz
    )
    return ColmapBlock(cams, eo, tuple(cam_names[s.camera] for s in shots), obs, ground)
