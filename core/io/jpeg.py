"""JPEG files checked whole before they are decoded: GDAL (as QGIS ships it) and OpenCV
only warn about a JPEG cut short and grey out the missing part."""

from __future__ import annotations

import os
from typing import Union

import numpy as np

from ..errors import InputError

PathLike = Union[str, "os.PathLike[str]"]

__all__ = ["JPEG_SUFFIXES", "check_jpeg_whole"]

JPEG_SUFFIXES = (".jpg", ".jpeg")


def check_jpeg_whole(path: PathLike) -> None:
    """Refuse (InputError) a JPEG whose image data does not end (no end-of-image marker
    after its first scan: a copy or a download cut short). The header segments are skipped
    by their lengths (an EXIF thumbnail holds a whole JPEG of its own); data after the end
    (a motion photo's video) is allowed."""
    raw = np.fromfile(os.fspath(path), dtype=np.uint8)
    if raw.size < 4 or raw[0] != 0xFF or raw[1] != 0xD8:
        raise InputError("not a JPEG file (no start-of-image marker)", path=os.fspath(path))
    k = 2
    while k + 4 <= raw.size and raw[k] == 0xFF and raw[k + 1] != 0xDA:  # up to the first scan
        if raw[k + 1] == 0xFF:  # fill byte
            k += 1
            continue
        k += 2 + (int(raw[k + 2]) << 8 | int(raw[k + 3]))
    # in the entropy-coded data an 0xFF byte is followed by 0x00 (or a restart marker): an
    # 0xFF 0xD9 pair is the end of the image
    tail = raw[k:]
    end = np.flatnonzero((tail[:-1] == 0xFF) & (tail[1:] == 0xD9)) if tail.size > 1 else ()
    if k + 4 > raw.size or len(end) == 0:
        raise InputError(
            f"truncated JPEG: its image data stop at byte {raw.size} without the "
            "end-of-image marker (a copy or a download cut short?)",
            path=os.fspath(path),
        )
