"""The project's cameras, orientations and points -> an OpenSfM ``reconstruction.json``
(and ``tracks.csv``), exactly: the inverse of :mod:`core.io.opensfm`'s reading.

Cameras
-------
OpenSfM normalises by ``size = max(width, height)`` from the image centre (``c_x = (cx -
width / 2) / size`` with ``cx`` the project's principal point in pixels; focal lengths
divided by ``size``); its distortion is a forward model on ``X/Z, Y/Z``. A camera is written
with the simplest OpenSfM type that holds it exactly:

=======================================  =============================  ==================
the project's camera                     OpenSfM type                   when
=======================================  =============================  ==================
perspective, no lens or ``opencv``        ``perspective`` (k1, k2)       principal point at
                                                                        the centre, fy = fx,
                                                                        k3 = p1 = p2 = 0
perspective, no lens, ``opencv`` or       ``brown`` (k1 k2 k3 p1 p2)     otherwise
``opencv_full`` with k4 = k5 = k6 = 0
equidistant, no lens or                   ``fisheye`` (k1, k2)           centred, fy = fx,
``opencv_fisheye``                                                      k3 = k4 = 0
equidistant, no lens or                   ``fisheye_opencv`` (k1..k4)    otherwise
``opencv_fisheye``
=======================================  =============================  ==================

The coefficients are renormalised to the current focal length
(:func:`core.geometry.forward_lens.opencv_coefficients`). Any other lens (the correction
models: brown_conrady and the photogrammetric families; metashape; thin_prism_fisheye;
opencv_full with a rational denominator) or projection has no exact OpenSfM camera and is
refused by name.

Shots and frame
---------------
``R = diag(1, -1, -1) M`` (world -> camera, x right, y down, z forward), written as its
axis-angle vector, and ``t = -R C``. An EO in a CRS is written topocentric: east, north, up
at ``reference_lla`` (the geodetic position of the centres' mean, on the CRS's ellipsoid),
each rotation turned from the grid frame at its centre to that frame through ECEF; an EO
without a CRS is written as it is, without ``reference_lla``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Dict, List, Sequence, Tuple

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..geometry.camera import Camera
from ..geometry.distortion import NoDistortion
from ..geometry.forward_lens import (
    OpenCVFisheyeLens,
    OpenCVFullLens,
    OpenCVLens,
    opencv_coefficients,
)
from ..geometry.rotations import opk_to_matrix
from ..photo.bundle_setup import GroundPoints
from ..photo.observations import ImageObservations
from ..photo.orientation import ExteriorOrientationTable
from .atomic import write_text_atomic

Array = NDArray[np.float64]

__all__ = ["axis_angle", "camera_to_opensfm", "opensfm_from_block", "write_opensfm"]

_FLIP = np.diag([1.0, -1.0, -1.0])


def axis_angle(r: Array) -> Tuple[float, float, float]:
    """The axis-angle vector (rad) of a rotation matrix (3, 3): the inverse of Rodrigues'."""
    from scipy.spatial.transform import Rotation

    v = Rotation.from_matrix(np.asarray(r, dtype=np.float64)).as_rotvec()
    return (float(v[0]), float(v[1]), float(v[2]))


def camera_to_opensfm(camera: Camera) -> Dict[str, Any]:
    """The OpenSfM camera (a JSON object) of a project camera, exactly (module docstring).

    Raises
    ------
    InputError
        For a lens model or projection no OpenSfM camera holds exactly, named.
    """
    lens = camera.distortion
    w, h = camera.width_px, camera.height_px
    size = float(max(w, h))
    f_px = camera.focal_px
    cx, cy = camera.principal_point_px
    c_x, c_y = (cx - 0.5 * w) / size, (cy - 0.5 * h) / size
    fisheye = camera.projection == "equidistant"
    if camera.projection not in ("perspective", "equidistant"):
        raise InputError(
            f"camera {camera.name!r}: the {camera.projection} projection has no OpenSfM camera type"
        )
    if isinstance(lens, NoDistortion):
        coef: Dict[str, float] = {}
        aspect = 1.0
    elif fisheye and type(lens) is OpenCVFisheyeLens:
        coef, aspect = opencv_coefficients(lens, camera.focal_mm), lens.constants["aspect"]
    elif not fisheye and type(lens) in (OpenCVLens, OpenCVFullLens):
        coef, aspect = opencv_coefficients(lens, camera.focal_mm), lens.constants["aspect"]
        if any(coef.get(k, 0.0) != 0.0 for k in ("k4", "k5", "k6")):
            raise InputError(
                f"camera {camera.name!r}: lens model 'opencv_full' with k4..k6 "
                "(a rational radial term) has no OpenSfM camera type"
            )
    else:
        raise InputError(
            f"camera {camera.name!r}: lens model {lens.model!r} with the {camera.projection} "
            "projection has no exact OpenSfM camera type (OpenSfM's distortion is forward; a "
            "correction model cannot be written as one)"
        )
    k = {n: float(coef.get(n, 0.0)) for n in ("k1", "k2", "k3", "k4", "p1", "p2")}
    out: Dict[str, Any] = {"width": int(w), "height": int(h)}
    centred = c_x == 0.0 and c_y == 0.0 and aspect == 1.0
    if fisheye:
        if centred and k["k3"] == 0.0 and k["k4"] == 0.0:
            out.update(projection_type="fisheye", focal=f_px / size, k1=k["k1"], k2=k["k2"])
        else:
            out.update(
                projection_type="fisheye_opencv",
                focal=f_px / size,
                aspect_ratio=aspect,
                c_x=c_x,
                c_y=c_y,
                **{n: k[n] for n in ("k1", "k2", "k3", "k4")},
            )
    elif centred and k["k3"] == 0.0 and k["p1"] == 0.0 and k["p2"] == 0.0:
        out.update(projection_type="perspective", focal=f_px / size, k1=k["k1"], k2=k["k2"])
    else:
        brown = {n: k[n] for n in ("k1", "k2", "k3", "p1", "p2")}
        out.update(
            projection_type="brown",
            focal_x=f_px / size,
            focal_y=aspect * f_px / size,
            c_x=c_x,
            c_y=c_y,
            **brown,
        )
    return out


def _topocentric(
    eo: ExteriorOrientationTable, m: Array, points: Array
) -> Tuple[Array, Array, Array, Dict[str, float] | None]:
    """Centres, rotations M and points in the EO's frame -> topocentric (or as they are)."""
    if not eo.crs_wkt:
        return eo.xyz, m, points, None
    from ..geometry.frames import MappingFrame, enu_rotation, grid_rotation

    mapping = MappingFrame.from_user_input(eo.crs_wkt)
    llh0 = mapping.map_to_geodetic(eo.xyz.mean(axis=0, keepdims=True))[0]
    x0 = mapping.geodetic_to_ecef(llh0[None, :])[0]
    e0 = enu_rotation(llh0[0], llh0[1])
    llh = mapping.map_to_geodetic(eo.xyz)
    r_eg = grid_rotation(mapping.grid_north_azimuth(llh)) @ enu_rotation(llh[:, 0], llh[:, 1])
    m_topo = m @ r_eg @ e0.T

    def enu(enh: Array) -> Array:
        if len(enh) == 0:
            return np.zeros((0, 3))
        return (mapping.map_to_ecef(enh) - x0) @ e0.T

    ref = {"latitude": float(llh0[0]), "longitude": float(llh0[1]), "altitude": float(llh0[2])}
    return enu(eo.xyz), m_topo, enu(points), ref


def opensfm_from_block(
    cameras: Sequence[Camera],
    eo: ExteriorOrientationTable,
    camera: Sequence[str] | None = None,
    observations: ImageObservations | None = None,
    points: GroundPoints | None = None,
) -> Tuple[List[Dict[str, Any]], str]:
    """The ``reconstruction.json`` content (a list of one reconstruction) and the
    ``tracks.csv`` text ("" without observations) of the project's block.

    ``camera``: each image's camera name (None: the only camera). Observations of the points
    in ``points`` (same point_id) become tracks, in OpenSfM's normalised coordinates.
    """
    by_name = {c.name: c for c in cameras}
    if camera is None:
        if len(cameras) != 1:
            raise InputError("several cameras: the EO must name each image's camera")
        camera = (cameras[0].name,) * len(eo)
    for name, cam in zip(eo.image_id, camera):
        if cam not in by_name:
            raise InputError(f"image {name!r}: camera {cam!r} is not in the camera file")
    used = sorted(set(camera))
    cams = {name: camera_to_opensfm(by_name[name]) for name in used}
    m = np.asarray(opk_to_matrix(eo.opk[:, 0], eo.opk[:, 1], eo.opk[:, 2])).reshape(-1, 3, 3)
    pxyz = points.xyz if points is not None else np.zeros((0, 3))
    centres, m_out, pts, ref = _topocentric(eo, m, pxyz)
    shots = {}
    for k, name in enumerate(eo.image_id):
        r = _FLIP @ m_out[k]
        shots[name] = {
            "camera": camera[k],
            "rotation": list(axis_angle(r)),
            "translation": (-r @ centres[k]).tolist(),
        }
    rec: Dict[str, Any] = {"cameras": cams, "shots": shots, "points": {}}
    if points is not None:
        rec["points"] = {
            pid: {"coordinates": pts[j].tolist(), "color": [128, 128, 128]}
            for j, pid in enumerate(points.point_id)
        }
    if ref is not None:
        rec["reference_lla"] = ref
    tracks = ""
    if observations is not None and points is not None:
        known, images = set(points.point_id), set(eo.image_id)
        cam_of = dict(zip(eo.image_id, camera))
        lines = ["OPENSFM_TRACKS_VERSION_v2"]
        for j, (img, pid) in enumerate(zip(observations.image_id, observations.point_id)):
            if img not in images or pid not in known:
                continue
            c = by_name[cam_of[img]]
            size = float(max(c.width_px, c.height_px))
            u, v = observations.pixels[j]
            xn = float((u - 0.5 * c.width_px) / size)
            yn = float((v - 0.5 * c.height_px) / size)
            lines.append(f"{img}\t{pid}\t{j}\t{xn!r}\t{yn!r}\t0\t128\t128\t128\t-1\t-1")
        tracks = "\n".join(lines) + "\n"
    return [rec], tracks


def write_opensfm(folder: str | Path, reconstruction: List[Dict[str, Any]], tracks: str) -> Path:
    """Write ``reconstruction.json`` (and ``tracks.csv`` when given) into ``folder``; returns
    the JSON's path."""
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "reconstruction.json"
    write_text_atomic(path, json.dumps(reconstruction, indent=1) + "\n")
    if tracks:
        write_text_atomic(out / "tracks.csv", tracks)
    return path
