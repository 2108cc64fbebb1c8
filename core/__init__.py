"""Qt-free, QGIS-free science core of the LiDAR Photogrammetry Toolkit.

Frames, units and sign conventions are fixed in ``docs/conventions.md``: metres and radians
inside the core, pixels (col, row) with the origin at the top-left corner of the top-left
pixel, image coordinates in millimetres, rotations world -> camera for omega-phi-kappa.
"""

from __future__ import annotations

import configparser
from pathlib import Path


def _read_version() -> str:
    meta = configparser.ConfigParser()
    meta.read(Path(__file__).resolve().parents[1] / "metadata.txt", encoding="utf-8")
    return meta.get("general", "version", fallback="0+unknown")


__version__ = _read_version()
