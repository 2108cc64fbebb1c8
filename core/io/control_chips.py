"""Files of the control chips (docs/formats.md, "Control chips").

Ground-photo table (CSV, header row; names case-insensitive, aliases in parentheses)::

    point_id (id, point)              text: the point_id of the ground-point table
    plate_photo (plate)               the photo with the control plate; a path relative to the
                                      table's folder, or absolute
    free_photo (photo, chip_photo)    the photo without the plate, from the same spot; optional
                                      (column missing or cell empty)
    photo_azimuth_deg (photo_azimuth) approximate grid azimuth of the photos' "up" direction,
                                      degrees clockwise from grid north, within +-45; optional
                                      (empty: the job's PHOTO_AZIMUTH)
    plate_azimuth_deg (plate_azimuth) grid azimuth of a side of the plate, degrees; optional
                                      (empty: the job's PLATE_AZIMUTH)

Without a table, photos are found by name: ``<point_id><plate suffix>.<ext>`` and
``<point_id><free suffix>.<ext>`` in the folders (or among the files) given.

Chip: ``<point_id>.tif``, a single-band float32 north-up GeoTIFF in the mapping CRS of the
ground points, nodata -9999: the grey level of the photo (0.299 R + 0.587 G + 0.114 B for a
colour photo) rectified onto the plane Z = Z_point; the geotransform puts the surveyed point at
its X, Y (the chip's centre, pixel (size/2, size/2)). Metadata: LIDARPHOTO_POINT_ID,
LIDARPHOTO_POINT (X,Y,Z), LIDARPHOTO_PLANE_Z, LIDARPHOTO_SOURCE (plate or free photo),
LIDARPHOTO_GSD.

Report: ``control_chips.csv`` (one row per point, columns :data:`REPORT_COLUMNS`) and
``control_chips.json`` (the same plus the eight corners, their sigmas and the orientations).
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Union

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from .suffixes import PHOTO_SUFFIXES
from .tables import find_column, float_column, read_table, text_column, write_csv_atomic

PathLike = Union[str, "os.PathLike[str]"]

__all__ = [
    "CHIP_NODATA",
    "REPORT_COLUMNS",
    "PhotoPair",
    "find_photo_pairs",
    "read_grey_photo",
    "read_photo_table",
    "write_chip",
    "write_report_csv",
    "write_report_json",
]

CHIP_NODATA = -9999.0
REPORT_COLUMNS = (
    "point_id",
    "status",
    "reason",
    "X",
    "Y",
    "Z",
    "plate_photo",
    "free_photo",
    "source",
    "corners_found",
    "corner_sigma_max_px",
    "edge_rms_max_px",
    "resection_sigma0",
    "sigma_X0",
    "sigma_Y0",
    "sigma_Z0",
    "sigma_omega_deg",
    "sigma_phi_deg",
    "sigma_kappa_deg",
    "azimuth_misfit_deg",
    "sift_matches",
    "sift_inliers",
    "free_sigma0",
    "valid_fraction",
    "chip",
)


@dataclass(frozen=True)
class PhotoPair:
    """The photos of one point and its optional azimuths (NaN: the job's default)."""

    point_id: str
    plate_photo: str
    free_photo: str | None
    photo_azimuth_deg: float = math.nan
    plate_azimuth_deg: float = math.nan


def read_photo_table(path: PathLike) -> dict[str, PhotoPair]:
    """The ground-photo table (module docstring); paths resolved against its folder."""
    table = read_table(path)
    base = Path(path).resolve().parent
    ids = text_column(table, find_column(table, ("point_id", "id", "point"), what="point_id"))
    plate = text_column(table, find_column(table, ("plate_photo", "plate"), what="plate_photo"))
    fi = find_column(table, ("free_photo", "photo", "chip_photo"), required=False)
    free = text_column(table, fi, nonempty=False) if fi is not None else ("",) * len(ids)
    out: dict[str, PhotoPair] = {}

    def angles(aliases: tuple[str, ...]) -> NDArray[np.float64]:
        k = find_column(table, aliases, required=False)
        if k is None:
            return np.full(len(ids), np.nan)
        return float_column(table, k, allow_empty=True)

    pa = angles(("photo_azimuth_deg", "photo_azimuth"))
    qa = angles(("plate_azimuth_deg", "plate_azimuth"))
    for k, pid in enumerate(ids):
        row = table.line_numbers[k]
        if pid in out:
            raise InputError(f"point {pid} twice", path=str(path), row=row)
        pp = (base / plate[k]).resolve()
        if not pp.is_file():
            raise InputError(
                f"plate photo not found: {pp}", path=str(path), row=row, column="plate_photo"
            )
        fp = None
        if free[k]:
            fpath = (base / free[k]).resolve()
            if not fpath.is_file():
                raise InputError(
                    f"plate-free photo not found: {fpath}",
                    path=str(path),
                    row=row,
                    column="free_photo",
                )
            fp = str(fpath)
        out[pid] = PhotoPair(pid, str(pp), fp, float(pa[k]), float(qa[k]))
    return out


def find_photo_pairs(
    paths: Sequence[PathLike], point_ids: Sequence[str], plate_suffix: str, free_suffix: str
) -> dict[str, PhotoPair]:
    """Photos by name among files and folders: ``<id><plate_suffix>.<ext>`` and
    ``<id><free_suffix>.<ext>``; points without a plate photo are left out."""
    if not plate_suffix or plate_suffix == free_suffix:
        raise InputError(
            "the plate and plate-free suffixes must differ and the plate suffix "
            f"cannot be empty (got {plate_suffix!r}, {free_suffix!r})"
        )
    files: dict[str, Path] = {}
    for raw in paths:
        p = Path(raw)
        if p.is_dir():
            found = [
                f for f in sorted(p.iterdir()) if f.is_file() and f.suffix.lower() in PHOTO_SUFFIXES
            ]
        elif p.is_file():
            found = [p]
        else:
            raise InputError("file or folder not found", path=str(p))
        for f in found:
            if f.stem in files and files[f.stem] != f:
                raise InputError(f"two photos are named {f.stem}: {files[f.stem]} and {f}")
            files[f.stem] = f
    out = {}
    for pid in point_ids:
        plate = files.get(pid + plate_suffix)
        if plate is None:
            continue
        free = files.get(pid + free_suffix)
        out[pid] = PhotoPair(pid, str(plate), str(free) if free else None)
    return out


def read_grey_photo(path: PathLike, width: int, height: int) -> NDArray[np.float32]:
    """The photo as grey levels (rows, cols) float32; refuses another size than the camera's."""
    from .raster import RasterReader

    with RasterReader(path) as src:
        info = src.info
        if (info.width, info.height) != (width, height):
            raise InputError(
                f"the photo is {info.width} x {info.height} px, the camera {width} x {height} px",
                path=str(path),
            )
        data = src.read().astype(np.float32)
    if data.shape[0] >= 3:
        return (0.299 * data[0] + 0.587 * data[1] + 0.114 * data[2]).astype(np.float32)
    return data[0]


def write_chip(
    path: PathLike,
    chip: NDArray[np.float32],
    geotransform: Sequence[float],
    crs: object,
    metadata: dict[str, str],
) -> None:
    """Write one chip (module docstring) to ``path`` (a temporary name of an OutputSet)."""
    from .raster_write import GeoTiffWriter

    data = np.where(np.isfinite(chip), chip, CHIP_NODATA).astype(np.float32)
    rows, cols = data.shape
    with GeoTiffWriter(
        os.fspath(path),
        cols,
        rows,
        1,
        np.float32,
        tuple(geotransform),
        crs,
        nodata=CHIP_NODATA,
        metadata=metadata,
    ) as w:
        w.write(data[None] if data.ndim == 2 else data)


def write_report_csv(path: PathLike, rows: Sequence[dict]) -> None:
    """One row per point, columns :data:`REPORT_COLUMNS` (empty where not measured)."""

    def cell(v: object) -> object:
        if v is None:
            return ""
        return v  # floats: write_csv_atomic writes them in full (tables.number)

    write_csv_atomic(path, REPORT_COLUMNS, ([cell(r.get(c)) for c in REPORT_COLUMNS] for r in rows))


def write_report_json(path: PathLike, rows: Sequence[dict]) -> None:
    """The full report (JSON list of objects; NaN written as null)."""
    from .atomic import write_text_atomic

    def clean(v: object) -> object:
        if isinstance(v, float) and not math.isfinite(v):
            return None
        if isinstance(v, dict):
            return {k: clean(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [clean(x) for x in v]
        return v

    write_text_atomic(path, json.dumps(clean(list(rows)), indent=1) + "\n")
