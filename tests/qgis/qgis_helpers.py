"""Constants and helpers shared by the QGIS tests (imported by conftest.py and the tests)."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DATA = Path(__file__).resolve().parent / "data"
PLUGIN = "lidarphoto"
ALG = "lidarphoto:trajectorytoeo"
CRS = "EPSG:31983"  # SIRGAS 2000 / UTM zone 23S (central meridian 45 W)
QGIS_PROCESS = shutil.which("qgis_process.bin") or "/usr/bin/qgis_process.bin"

TRAJECTORY_HEADER = "image_id,time,group,easting,northing,height,roll,pitch,heading\n"


def write_csv(path: Path, rows: list[str], header: str = TRAJECTORY_HEADER) -> Path:
    path.write_text(header + "".join(row + "\n" for row in rows), encoding="utf-8")
    return path


def purge_plugin_modules() -> None:
    """Forget every imported ``lidarphoto`` module (as qgis.utils does on unload)."""
    for name in [m for m in sys.modules if m == PLUGIN or m.startswith(PLUGIN + ".")]:
        del sys.modules[name]
