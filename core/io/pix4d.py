"""Pix4D's calibrated camera parameters (``<project>_calibrated_camera_parameters.txt``) ->
the project's cameras and EO.

The file (Pix4D, "What does the Output Params Folder contain")
---------------------------------------------------------------
A header of text lines (``fileName imageWidth imageHeight``, ``camera matrix K [3x3]``,
``radial distortion [3x1]``, ``tangential distortion [2x1]``, ``camera position t [3x1]``,
``camera rotation R [3x3]``, ``camera model m = K [R|-Rt] X``), then per image: its name,
width and height (px); the 3 x 3 matrix K (``fx 0 cx / 0 fy cy / 0 0 1``, px); the radial
coefficients ``R1 R2 R3``; the tangential ``T1 T2``; the camera position ``t`` (m) and the
rotation ``R`` (3 x 3, world -> camera), both relative to ``<project>_offset.xyz`` (three
numbers, the offset added to every coordinate to get the output CRS's).

The model
---------
``m = K [R | -R t] X`` on ``X`` = the output coordinates minus the offset: the camera frame is
x right, y down, z forward (the camera looks along +z; ``R``'s third row is the viewing
direction, as the files of nadir images show). The distortion is applied to the normalised
point ``(x, y) = (X_c / Z_c, Y_c / Z_c)`` before K::

    x_d = x (1 + R1 r^2 + R2 r^4 + R3 r^6) + 2 T1 x y + T2 (r^2 + 2 x^2)
    y_d = y (1 + R1 r^2 + R2 r^4 + R3 r^6) + 2 T2 x y + T1 (r^2 + 2 y^2)

That is :class:`~core.geometry.forward_lens.OpenCVLens` with ``k1..k3 = R1..R3``, ``p1 = T1``,
``p2 = T2`` (``scale_mm = fx * pixel size``, ``aspect = fy / fx``). **Assumed, not
established**: Pix4D's article on the internal parameters writes this formula for a camera
frame with y *up* and its equations are pictures in the pages found; this module reads it in
the y-down frame of ``K`` (tangential coefficients unchanged). The pixel origin is
PIXEL_ORIGIN (default ``corner``: K's pixel coordinates start at the image's top-left
corner, the project's convention, as Pix4D's own Inpho camera file beside K says: it puts
the sensor centre at K's (W/2, H/2), tests/data/pix4d; ``centre``: the first pixel's centre
is (0, 0)). Both are stated in docs/formats.md. A nonzero skew in K is refused by name.

Images with the same size, K and coefficients share one camera (``pix4d_1``, ``pix4d_2``..,
in the order of their first image). The offset is added to the centres; in a CRS (the
``<project>_wkt.prj`` beside the file, or CRS) the coordinates are easting, northing and
height as Pix4D writes them, else LOCAL.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Dict, List, Tuple

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..geometry.camera import Camera
from ..geometry.distortion import DistortionModel, NoDistortion
from ..geometry.forward_lens import OpenCVLens
from ..geometry.rotations import nearest_rotation
from ..photo.bundle_setup import GroundPoints
from ..photo.observations import ImageObservations
from .colmap_block import ColmapBlock, ColmapFrame, oriented
from .colmap_names import PIX4D_PIXEL_ORIGINS

Array = NDArray[np.float64]

__all__ = [
    "PIXEL_ORIGINS",
    "Pix4dImage",
    "block_from_pix4d",
    "camera_from_pix4d",
    "companion_files",
    "read_offset",
    "read_pix4d",
]

PIXEL_ORIGINS = PIX4D_PIXEL_ORIGINS
#: A rotation matrix is orthonormalised when within this of a rotation (the files' digits).
_ROTATION_TOL = 1e-5
#: The numbers of an image's block after its name line: K (9), radial (3), tangential (2),
#: position (3), rotation (9), on 1 + 3 + 1 + 1 + 1 + 3 lines.
_LINES = (
    (3, "K"),
    (3, "K"),
    (3, "K"),
    (3, "radial distortion"),
    (2, "tangential distortion"),
    (3, "camera position t"),
    (3, "R"),
    (3, "R"),
    (3, "R"),
)


@dataclass(frozen=True)
class Pix4dImage:
    """One image of the file: name, size (px), K (3, 3; px), radial (R1 R2 R3), tangential
    (T1 T2), position (3,; m, relative to the offset) and rotation (3, 3; world -> camera,
    camera x right, y down, z forward)."""

    name: str
    width: int
    height: int
    k: Array
    radial: Tuple[float, float, float]
    tangential: Tuple[float, float]
    position: Array
    rotation: Array


def _floats(tokens: List[str], n: int, what: str, src: str, row: int) -> List[float]:
    if len(tokens) != n:
        raise InputError(f"{what}: expected {n} numbers, got {len(tokens)}", path=src, row=row)
    try:
        vals = [float(t) for t in tokens]
    except ValueError:
        raise InputError(
            f"{what}: not a number in {' '.join(tokens)!r}", path=src, row=row
        ) from None
    if not all(np.isfinite(vals)):
        raise InputError(f"{what}: not finite", path=src, row=row)
    return vals


def _is_name_line(tokens: List[str]) -> bool:
    """``name width height``: two integers after a name that is not a number."""
    if len(tokens) < 3 or not (tokens[-1].isdigit() and tokens[-2].isdigit()):
        return False
    try:
        float(tokens[0])
    except ValueError:
        return True
    return False


def _numeric(tokens: List[str]) -> bool:
    """Every token a number (a line of an image block, never of the header)."""
    try:
        [float(t) for t in tokens]
    except ValueError:
        return False
    return True


def _rotation(m: Array, name: str, src: str, row: int) -> Array:
    """:func:`~..geometry.rotations.nearest_rotation` of an image's R, refused with its row."""
    try:
        return nearest_rotation(m, _ROTATION_TOL)
    except ValueError as exc:
        raise InputError(
            f"image {name!r}: R is not a rotation ({exc})", path=src, row=row
        ) from None


def read_pix4d(path: str | Path) -> Tuple[Pix4dImage, ...]:
    """Read a ``..._calibrated_camera_parameters.txt`` (see the module docstring).

    Raises
    ------
    InputError
        An unreadable file, no image, a truncated or malformed block (file and row named), a
        K with skew or a non-positive focal length, an R that is not a rotation, a repeated
        image name.
    """
    src = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8-sig", errors="replace")
    except OSError as exc:
        raise InputError(f"cannot read the Pix4D camera file: {exc}", path=src) from exc
    lines = [(i + 1, ln.split()) for i, ln in enumerate(text.splitlines()) if ln.strip()]
    images: List[Pix4dImage] = []
    seen: Dict[str, int] = {}
    j = 0
    while j < len(lines):
        row, tokens = lines[j]
        if not _is_name_line(tokens):
            if images or _numeric(tokens):  # the header is text; then only image blocks
                raise InputError(
                    f"expected 'name width height', got {' '.join(tokens)!r}", path=src, row=row
                )
            j += 1
            continue
        name, width, height = " ".join(tokens[:-2]), int(tokens[-2]), int(tokens[-1])
        if name in seen:
            raise InputError(
                f"image {name!r} repeated (first at row {seen[name]})", path=src, row=row
            )
        seen[name] = row
        if j + len(_LINES) >= len(lines):
            raise InputError(
                f"image {name!r}: the block is truncated (expected {len(_LINES)} "
                "lines of numbers after its name)",
                path=src,
                row=row,
            )
        vals: List[float] = []
        for (n, what), (r, tok) in zip(_LINES, lines[j + 1 : j + 1 + len(_LINES)]):
            vals += _floats(tok, n, f"image {name!r}, {what}", src, r)
        k = np.array(vals[:9]).reshape(3, 3)
        if width <= 0 or height <= 0:
            raise InputError(f"image {name!r}: size {width} x {height}", path=src, row=row)
        if (
            not (k[0, 0] > 0 and k[1, 1] > 0)
            or np.any(k[[1, 2, 2], [0, 0, 1]] != 0)
            or k[2, 2] != 1
        ):
            raise InputError(
                f"image {name!r}: K must be [fx 0 cx; 0 fy cy; 0 0 1] with fx, "
                f"fy > 0, got {k.ravel().tolist()}",
                path=src,
                row=row + 1,
            )
        if k[0, 1] != 0:
            raise InputError(
                f"image {name!r}: K has a skew ({k[0, 1]}): no camera of the project represents it",
                path=src,
                row=row + 1,
            )
        rot = _rotation(np.array(vals[17:26]).reshape(3, 3), name, src, lines[j + 7][0])
        images.append(
            Pix4dImage(
                name,
                width,
                height,
                k,
                (vals[9], vals[10], vals[11]),
                (vals[12], vals[13]),
                np.array(vals[14:17]),
                rot,
            )
        )
        j += 1 + len(_LINES)
    if not images:
        raise InputError(
            "no image block ('name width height' and its numbers) in the file: "
            "is it a Pix4D calibrated_camera_parameters.txt?",
            path=src,
        )
    return tuple(images)


def read_offset(path: str | Path) -> Array:
    """The three numbers of a ``<project>_offset.xyz`` (m)."""
    src = str(path)
    try:
        tokens = Path(path).read_text(encoding="utf-8-sig").split()
    except OSError as exc:
        raise InputError(f"cannot read the Pix4D offset file: {exc}", path=src) from exc
    return np.array(_floats(tokens, 3, "offset X Y Z", src, 1))


#: The suffix of the file PIX4Dmapper writes for other software; its companions share the stem.
CAMERA_FILE_SUFFIX = "_calibrated_camera_parameters.txt"


def companion_files(
    path: str | Path, offset_path: str | Path | None = None, crs: str = ""
) -> Tuple[Array, str, List[str]]:
    """The offset (m) and the CRS of a calibrated_camera_parameters.txt, from the files Pix4D
    writes beside it (``<project>_offset.xyz``, ``<project>_wkt.prj``) unless given, and notes
    saying where each came from. A given offset file that does not exist is refused; a missing
    companion gives offset 0 0 0 or no CRS (``""``)."""
    src = Path(path)
    name = src.name
    stem = name[: -len(CAMERA_FILE_SUFFIX)] if name.endswith(CAMERA_FILE_SUFFIX) else src.stem
    notes: List[str] = []
    found = Path(offset_path) if offset_path else src.with_name(f"{stem}_offset.xyz")
    if found.is_file():
        offset = read_offset(found)
    elif offset_path:
        raise InputError("OFFSET: the file does not exist", path=str(found))
    else:
        offset = np.zeros(3)
        notes.append(f"no offset file {found.name} beside INPUT: offset 0 0 0")
    prj = src.with_name(f"{stem}_wkt.prj")
    if not crs and prj.is_file():
        crs = prj.read_text(encoding="utf-8-sig").strip()
        notes.append(f"CRS from {prj.name}")
    return offset, crs, notes


def camera_from_pix4d(
    img: Pix4dImage, pixel_size_mm: float, name: str, pixel_origin: str = PIXEL_ORIGINS[0]
) -> Camera:
    """The project's camera of an image's K and coefficients (see the module docstring)."""
    if pixel_origin not in PIXEL_ORIGINS:
        raise InputError(
            f"PIXEL_ORIGIN: expected one of {', '.join(PIXEL_ORIGINS)}, got {pixel_origin!r}"
        )
    ps = float(pixel_size_mm)
    fx, fy = float(img.k[0, 0]), float(img.k[1, 1])
    shift = 0.5 if pixel_origin == "centre" else 0.0  # K's pixel -> the project's
    cx, cy = float(img.k[0, 2]) + shift, float(img.k[1, 2]) + shift
    f_mm = fx * ps
    r1, r2, r3 = img.radial
    t1, t2 = img.tangential
    lens: DistortionModel
    if fx == fy and not any((r1, r2, r3, t1, t2)):
        lens = NoDistortion()
    else:
        lens = OpenCVLens(k1=r1, k2=r2, k3=r3, p1=t1, p2=t2, scale_mm=f_mm, aspect=fy / fx)
    x0 = (cx - 0.5 * img.width) * ps
    y0 = (0.5 * img.height - cy) * ps
    return Camera(name, f_mm, ps, img.width, img.height, x0, y0, lens, "perspective")


def _camera_key(img: Pix4dImage) -> Tuple[float, ...]:
    return (img.width, img.height, *img.k.ravel().tolist(), *img.radial, *img.tangential)


def block_from_pix4d(
    images: Tuple[Pix4dImage, ...],
    offset: Array,
    crs: str,
    pixel_size_mm: float,
    pixel_origin: str = PIXEL_ORIGINS[0],
) -> ColmapBlock:
    """Convert the images (see the module docstring): the offset added, in ``crs`` (the
    output CRS Pix4D wrote them in: easting, northing, height) or LOCAL (``crs`` empty)."""
    if pixel_origin not in PIXEL_ORIGINS:
        raise InputError(
            f"PIXEL_ORIGIN: expected one of {', '.join(PIXEL_ORIGINS)}, got {pixel_origin!r}"
        )
    if not images:
        raise InputError("no image to import")
    off = np.asarray(offset, dtype=np.float64).reshape(3)
    frame = (
        ColmapFrame("crs", crs.strip(), translation=off)
        if crs.strip()
        else ColmapFrame("local", translation=off)
    )
    names: Dict[Tuple[float, ...], str] = {}
    cams: List[Camera] = []
    for img in images:
        key = _camera_key(img)
        if key not in names:
            names[key] = f"pix4d_{len(names) + 1}"
            cams.append(camera_from_pix4d(img, pixel_size_mm, names[key], pixel_origin))
    r = np.array([img.rotation for img in images])
    t = -np.einsum("nij,nj->ni", r, np.array([img.position for img in images]))
    eo, _ = oriented(frame, [img.name for img in images], r, t, np.zeros((0, 3)))
    obs = ImageObservations((), (), np.zeros((0, 2)), np.zeros(0), (), ())
    ground = GroundPoints((), np.zeros((0, 3)), np.zeros((0, 3)), ())
    return ColmapBlock(tuple(cams), eo, tuple(names[_camera_key(i)] for i in images), obs, ground)
