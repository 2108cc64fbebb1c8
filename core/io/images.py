"""Camera images for feature matching: grey, optionally decoded at a reduced size.

Images are read by OpenCV (JPEG, PNG, TIFF, ...) as stored in the file: the EXIF orientation
tag is ignored, so pixel positions refer to the raster as written (as GDAL and the picking
dock read it). A reduction by 2, 4 or 8 is done while decoding (JPEG's scaled inverse DCT:
much faster than decoding the full image); each reduced pixel ``k`` covers the full-resolution
pixels ``f k .. f (k + 1)``. The full size is read from the file's header (GDAL/rasterio).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Union

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from .jpeg import check_jpeg_whole
from .suffixes import IMAGE_SUFFIXES

__all__ = [
    "IMAGE_SUFFIXES",
    "check_distinct_files",
    "check_jpeg_whole",
    "decode_factor",
    "image_size",
    "list_image_files",
    "read_gray",
]

PathLike = Union[str, "os.PathLike[str]"]


def list_image_files(paths, twice: tuple[str, str] | None = None) -> list[Path]:
    """The image files named, folders expanded (their files with :data:`IMAGE_SUFFIXES`,
    sorted by name); InputError for a missing path, an empty folder or two images with the
    same name (the image id is the file name without extension). With ``twice`` (parameter
    name, what a duplicate would do), a file named twice, or a copy of another, is refused
    (:func:`check_distinct_files`); otherwise it is taken once."""
    out: list[Path] = []
    for raw in paths:
        p = Path(raw)
        if p.is_dir():
            found = sorted(
                f
                for f in p.iterdir()
                if f.is_file() and f.suffix.lower() in IMAGE_SUFFIXES and not f.name.startswith(".")
            )
            if not found:
                raise InputError(
                    "no image in this folder (" + ", ".join(IMAGE_SUFFIXES) + ")", path=str(p)
                )
            out += found
        elif p.is_file():
            out.append(p)
        else:
            raise InputError("file or folder not found", path=str(p))
    if twice is not None:
        check_distinct_files(out, *twice)
    seen: dict[str, Path] = {}
    for f in out:
        if f.stem in seen and seen[f.stem] != f:
            raise InputError(f"two images are named {f.stem}: {seen[f.stem]} and {f}")
        seen[f.stem] = f
    return list(seen.values())


def check_distinct_files(files, param: str, why: str) -> None:
    """Refuse (InputError naming ``param``) a file given twice: the same file under two
    spellings (a link, a folder and a file in it) or the same content under two names (a
    copy; only files of equal size are hashed). ``why`` says what a duplicate would do."""
    import hashlib

    by_real: dict[str, Path] = {}
    by_size: dict[int, list[Path]] = {}
    for f in map(Path, files):
        real = os.path.realpath(f)
        if real in by_real:
            again = "given twice" if by_real[real] == f else f"{by_real[real]} again"
            raise InputError(f"{param}: {f} is {again}: {why}; give it once")
        by_real[real] = f
        by_size.setdefault(f.stat().st_size, []).append(f)

    def digest(f: Path) -> str:
        h = hashlib.sha256()
        with open(f, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
        return h.hexdigest()

    for same in (g for g in by_size.values() if len(g) > 1):
        seen: dict[str, Path] = {}
        for f in same:
            first = seen.setdefault(digest(f), f)
            if first is not f:
                raise InputError(
                    f"{param}: {f} has the same content as {first} (a copy): {why}; give it once"
                )


def image_size(path: PathLike) -> tuple[int, int]:
    """(width, height) of an image from its header (nothing decoded); InputError if the
    file is missing or not an image."""
    from .raster import RasterReader

    with RasterReader(os.fspath(path)) as src:
        return int(src.info.width), int(src.info.height)


def decode_factor(factor: int) -> int:
    """The largest of 8, 4, 2, 1 dividing ``factor``: the part of a reduction done while
    decoding (the rest is a box average of the decoded image).

    >>> [decode_factor(f) for f in (1, 2, 3, 4, 6, 12, 16)]
    [1, 2, 1, 4, 2, 4, 8]
    """
    return next(f for f in (8, 4, 2, 1) if factor % f == 0)


def read_gray(path: PathLike, factor: int = 1) -> NDArray[np.uint8]:
    """Read an image as 8-bit grey, reduced by ``factor`` (1, 2, 4 or 8) while decoding.

    Raises
    ------
    InputError
        The file does not exist or cannot be decoded (named).
    """
    import cv2

    p = os.fspath(path)
    if not Path(p).is_file():
        raise InputError("image file not found", path=p)
    flags = {
        1: cv2.IMREAD_GRAYSCALE,
        2: cv2.IMREAD_REDUCED_GRAYSCALE_2,
        4: cv2.IMREAD_REDUCED_GRAYSCALE_4,
        8: cv2.IMREAD_REDUCED_GRAYSCALE_8,
    }
    if factor not in flags:
        raise ValueError(f"decoding reduces by 1, 2, 4 or 8, not {factor}")
    # ANYDEPTH: without it OpenCV divides 16-bit values by 256, and a 12-bit frame keeps
    # 4 of its bits (edges of 150 DN in 16 bits become 0.6 DN)
    img = cv2.imread(p, flags[factor] | cv2.IMREAD_ANYDEPTH | cv2.IMREAD_IGNORE_ORIENTATION)
    if img is None:
        raise InputError("cannot read the image (not an image file, or damaged)", path=p)
    if Path(p).suffix.lower() in (".jpg", ".jpeg"):  # OpenCV greys out a cut JPEG's rest
        check_jpeg_whole(p)
    if img.dtype != np.uint8:  # 16-bit or float: stretched to 8 bits (features need contrast)
        img = cv2.normalize(img, None, 0, 255, cv2.NORM_MINMAX).astype(np.uint8)
    return img
