"""COLMAP sparse models: text (``cameras.txt``, ``images.txt``, ``points3D.txt``) and binary
(``cameras.bin``, ``images.bin``, ``points3D.bin``), read and written as COLMAP stores them.

This module holds COLMAP's own content (its camera models and parameters, world-to-camera
quaternions and translations, tracks); :mod:`core.io.colmap_block` converts it to and from
the project's cameras, orientations and observations. Layout (colmap.github.io/format.html):

- cameras: ``CAMERA_ID MODEL WIDTH HEIGHT PARAMS...``; binary: uint64 count, then per camera
  int32 id, int32 model id, uint64 width, uint64 height, float64 params;
- images: two lines per image, ``IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME`` and
  ``X Y POINT3D_ID ...`` (-1: no 3D point); binary: uint64 count, then uint32 id, 4 + 3
  float64, uint32 camera id, the name ending with a NUL byte, uint64 count, (float64 x,
  float64 y, int64 point id) each;
- points3D: ``POINT3D_ID X Y Z R G B ERROR (IMAGE_ID POINT2D_IDX)...``; binary: uint64
  count, then uint64 id, 3 float64, 3 uint8, float64 error, uint64 track length, (int32
  image id, int32 point2D index) each.

All binary values are little-endian. Pixel positions use the project's convention (the
centre of the first pixel is (0.5, 0.5)), which is COLMAP's as well.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Dict, List, Tuple, Union

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from .atomic import write_text_atomic
from .colmap_names import COLMAP_MODELS, DEFAULT_PIXEL_SIZE_MM

__all__ = [
    "COLMAP_MODELS",
    "DEFAULT_PIXEL_SIZE_MM",
    "ColmapCamera",
    "ColmapImage",
    "ColmapModel",
    "ColmapPoint",
    "read_colmap_model",
    "write_colmap_text",
]

Array = NDArray[np.float64]

_MODEL_IDS = {name: k for k, (name, _) in COLMAP_MODELS.items()}


@dataclass(frozen=True)
class ColmapCamera:
    """A COLMAP camera: its model name, image size (px) and parameters (COLMAP's order)."""

    camera_id: int
    model: str
    width: int
    height: int
    params: Tuple[float, ...]


@dataclass(frozen=True)
class ColmapImage:
    """A registered image: world-to-camera ``qvec`` (qw, qx, qy, qz), ``tvec`` (COLMAP's
    camera frame: x right, y down, z forward), its keypoints ``xy`` (N, 2) px and their 3D
    point ids (N,) (-1: none)."""

    image_id: int
    qvec: Tuple[float, ...]
    tvec: Tuple[float, ...]
    camera_id: int
    name: str
    xy: Array
    point3d_id: NDArray[np.int64]


@dataclass(frozen=True)
class ColmapPoint:
    """A 3D point (model frame), its colour, mean reprojection error (px) and track
    ((image id, point2D index), ...)."""

    point_id: int
    xyz: Tuple[float, float, float]
    rgb: Tuple[int, int, int]
    error: float
    track: Tuple[Tuple[int, int], ...]


@dataclass(frozen=True)
class ColmapModel:
    """A COLMAP sparse model, by id; ``source`` is the folder it was read from."""

    cameras: Dict[int, ColmapCamera]
    images: Dict[int, ColmapImage]
    points: Dict[int, ColmapPoint]
    source: str = ""


# ---------------------------------------------------------------------- text
def _lines(path: Path) -> List[Tuple[int, str]]:
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read COLMAP file: {exc}", path=str(path)) from exc
    return [(k + 1, ln.strip()) for k, ln in enumerate(text.splitlines())]


def _check_camera(cam_id: int, model: str, params: Tuple[float, ...], path: str, row: int) -> None:
    if model not in _MODEL_IDS:
        raise InputError(
            f"camera {cam_id}: unknown COLMAP camera model {model!r} "
            f"(known: {', '.join(_MODEL_IDS)})",
            path=path,
            row=row,
        )
    want = len(COLMAP_MODELS[_MODEL_IDS[model]][1])
    if len(params) != want:
        raise InputError(
            f"camera {cam_id}: model {model} has {want} parameters, got {len(params)}",
            path=path,
            row=row,
        )
    if not all(np.isfinite(params)):
        raise InputError(f"camera {cam_id}: a parameter is not finite", path=path, row=row)


def _read_cameras_txt(path: Path) -> Dict[int, ColmapCamera]:
    out: Dict[int, ColmapCamera] = {}
    for row, line in _lines(path):
        if not line or line.startswith("#"):
            continue
        tok = line.split()
        try:
            cam_id, model, width, height = int(tok[0]), tok[1], int(tok[2]), int(tok[3])
            params = tuple(float(v) for v in tok[4:])
        except (ValueError, IndexError):
            raise InputError(
                "expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS...", path=str(path), row=row
            ) from None
        _check_camera(cam_id, model, params, str(path), row)
        out[cam_id] = ColmapCamera(cam_id, model, width, height, params)
    return out


def _read_images_txt(path: Path) -> Dict[int, ColmapImage]:
    out: Dict[int, ColmapImage] = {}
    lines = [(r, ln) for r, ln in _lines(path) if not ln.startswith("#")]
    # the keypoint line may be empty: pairs are taken by position, not by content
    while lines and not lines[-1][1]:
        lines.pop()
    k = 0
    while k < len(lines):
        row, head = lines[k]
        if not head:
            k += 1
            continue
        points = lines[k + 1][1] if k + 1 < len(lines) else ""
        k += 2
        tok = head.split(maxsplit=9)
        try:
            image_id = int(tok[0])
            q = tuple(float(v) for v in tok[1:5])
            t = tuple(float(v) for v in tok[5:8])
            cam_id, name = int(tok[8]), tok[9]
            vals = points.split()
            if len(vals) % 3:
                raise ValueError
            xy = np.array(
                [[float(a), float(b)] for a, b in zip(vals[0::3], vals[1::3])], dtype=np.float64
            ).reshape(-1, 2)
            pid = np.array([int(v) for v in vals[2::3]], dtype=np.int64)
        except (ValueError, IndexError):
            raise InputError(
                "expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME, then a line of "
                "X Y POINT3D_ID triples",
                path=str(path),
                row=row,
            ) from None
        out[image_id] = ColmapImage(image_id, q, t, cam_id, name, xy, pid)
    return out


def _read_points_txt(path: Path) -> Dict[int, ColmapPoint]:
    out: Dict[int, ColmapPoint] = {}
    for row, line in _lines(path):
        if not line or line.startswith("#"):
            continue
        tok = line.split()
        try:
            pid = int(tok[0])
            xyz = (float(tok[1]), float(tok[2]), float(tok[3]))
            rgb = (int(tok[4]), int(tok[5]), int(tok[6]))
            err = float(tok[7])
            rest = [int(v) for v in tok[8:]]
            if len(rest) % 2:
                raise ValueError
        except (ValueError, IndexError):
            raise InputError(
                "expected POINT3D_ID X Y Z R G B ERROR (IMAGE_ID POINT2D_IDX)...",
                path=str(path),
                row=row,
            ) from None
        track = tuple(zip(rest[0::2], rest[1::2]))
        out[pid] = ColmapPoint(pid, xyz, rgb, err, track)
    return out


# ---------------------------------------------------------------------- binary
class _Reader:
    def __init__(self, path: Path) -> None:
        self.path = path
        try:
            self.data = path.read_bytes()
        except OSError as exc:
            raise InputError(f"cannot read COLMAP file: {exc}", path=str(path)) from exc
        self.pos = 0

    def take(self, fmt: str) -> Tuple[Any, ...]:
        size = struct.calcsize("<" + fmt)
        if self.pos + size > len(self.data):
            raise InputError(
                f"the file ends at byte {len(self.data)} inside a record (truncated?)",
                path=str(self.path),
            )
        vals = struct.unpack_from("<" + fmt, self.data, self.pos)
        self.pos += size
        return vals

    def name(self) -> str:
        end = self.data.find(b"\0", self.pos)
        if end < 0:
            raise InputError("an image name has no end (truncated?)", path=str(self.path))
        text = self.data[self.pos : end].decode("utf-8", errors="replace")
        self.pos = end + 1
        return text

    def done(self) -> None:
        if self.pos != len(self.data):
            raise InputError(
                f"{len(self.data) - self.pos} bytes after the last record", path=str(self.path)
            )


def _read_cameras_bin(path: Path) -> Dict[int, ColmapCamera]:
    r = _Reader(path)
    out: Dict[int, ColmapCamera] = {}
    (count,) = r.take("Q")
    for _ in range(int(count)):
        cam_id, model_id, width, height = r.take("iiQQ")
        if model_id not in COLMAP_MODELS:
            raise InputError(
                f"camera {cam_id}: unknown COLMAP camera model id {model_id}", path=str(path)
            )
        name, names = COLMAP_MODELS[model_id]
        params = tuple(float(v) for v in r.take("d" * len(names)))
        _check_camera(int(cam_id), name, params, str(path), 0)
        out[int(cam_id)] = ColmapCamera(int(cam_id), name, int(width), int(height), params)
    r.done()
    return out


def _read_images_bin(path: Path) -> Dict[int, ColmapImage]:
    r = _Reader(path)
    out: Dict[int, ColmapImage] = {}
    (count,) = r.take("Q")
    for _ in range(int(count)):
        vals = r.take("I7dI")
        name = r.name()
        (n2,) = r.take("Q")
        flat = r.take("ddq" * int(n2))
        arr = np.array(flat, dtype=np.float64).reshape(-1, 3)
        pid = np.array(flat[2::3], dtype=np.int64)
        image_id = int(vals[0])
        q = tuple(float(v) for v in vals[1:5])
        t = tuple(float(v) for v in vals[5:8])
        out[image_id] = ColmapImage(image_id, q, t, int(vals[8]), name, arr[:, :2].copy(), pid)
    r.done()
    return out


def _read_points_bin(path: Path) -> Dict[int, ColmapPoint]:
    r = _Reader(path)
    out: Dict[int, ColmapPoint] = {}
    (count,) = r.take("Q")
    for _ in range(int(count)):
        pid, x, y, z, cr, cg, cb, err, n = r.take("Q3d3BdQ")
        flat = r.take("ii" * int(n))
        track = tuple(zip(flat[0::2], flat[1::2]))
        out[int(pid)] = ColmapPoint(int(pid), (x, y, z), (cr, cg, cb), float(err), track)
    r.done()
    return out


def read_colmap_model(folder: Union[str, Path]) -> ColmapModel:
    """Read a COLMAP sparse model folder: the text files if ``cameras.txt`` is there, else
    the binary ones. ``points3D`` is optional (an empty dict without it).

    Raises
    ------
    InputError
        A missing cameras or images file, an unknown camera model, a wrong parameter count,
        a malformed or truncated record, an image whose camera is not in the model;
        naming the file (and the row for text).
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(
            "not a folder (give the COLMAP model folder, e.g. sparse/0)", path=str(folder)
        )
    if (folder / "cameras.txt").is_file():
        readers = (_read_cameras_txt, _read_images_txt, _read_points_txt)
        ext = ".txt"
    elif (folder / "cameras.bin").is_file():
        readers = (_read_cameras_bin, _read_images_bin, _read_points_bin)
        ext = ".bin"
    else:
        raise InputError("no cameras.txt or cameras.bin in this folder", path=str(folder))
    if not (folder / f"images{ext}").is_file():
        raise InputError(f"images{ext} is missing", path=str(folder))
    cameras = readers[0](folder / f"cameras{ext}")
    images = readers[1](folder / f"images{ext}")
    pts_path = folder / f"points3D{ext}"
    points = readers[2](pts_path) if pts_path.is_file() else {}
    for img in images.values():
        if img.camera_id not in cameras:
            raise InputError(
                f"image {img.name!r}: camera {img.camera_id} is not in cameras{ext}",
                path=str(folder / f"images{ext}"),
            )
    return ColmapModel(cameras, images, points, str(folder))


def write_colmap_text(folder: Union[str, Path], model: ColmapModel) -> None:
    """Write ``cameras.txt``, ``images.txt`` and ``points3D.txt`` into ``folder`` (atomically
    each), with full precision (``repr``)."""
    folder = Path(folder)
    cams = ["# CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]"]
    for c in model.cameras.values():
        cams.append(
            " ".join(
                [
                    str(c.camera_id),
                    c.model,
                    str(c.width),
                    str(c.height),
                    *(repr(float(v)) for v in c.params),
                ]
            )
        )
    imgs = [
        "# IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME",
        "# POINTS2D[] as (X, Y, POINT3D_ID)",
    ]
    for im in model.images.values():
        imgs.append(
            " ".join(
                [
                    str(im.image_id),
                    *(repr(float(v)) for v in (*im.qvec, *im.tvec)),
                    str(im.camera_id),
                    im.name,
                ]
            )
        )
        pairs = zip(im.xy.tolist(), im.point3d_id.tolist())
        imgs.append(" ".join(f"{x!r} {y!r} {int(p)}" for (x, y), p in pairs))
    pts = ["# POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)"]
    for p in model.points.values():
        pts.append(
            " ".join(
                [
                    str(p.point_id),
                    *(repr(float(v)) for v in p.xyz),
                    *(str(int(v)) for v in p.rgb),
                    repr(float(p.error)),
                    *(f"{i} {j}" for i, j in p.track),
                ]
            )
        )
    folder.mkdir(parents=True, exist_ok=True)
    for name, lines in (("cameras.txt", cams), ("images.txt", imgs), ("points3D.txt", pts)):
        write_text_atomic(folder / name, "\n".join(lines) + "\n")
