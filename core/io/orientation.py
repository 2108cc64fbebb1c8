"""The exterior orientation table: perspective centre and omega-phi-kappa per image.

CSV format (header row, comma separated, one image per row)::

    image_id,time,group,X,Y,Z,omega_deg,phi_deg,kappa_deg

X, Y, Z: perspective centre in the mapping CRS (easting, northing, height; metres).
omega, phi, kappa: degrees, ``M = R3(kappa) R2(phi) R1(omega)`` rotates vectors of the grid
frame at the perspective centre (grid east, grid north, local up) into the camera frame.
``time`` may be empty (NaN) and ``group`` (flight line or direction) may be empty. Lines
starting with ``#`` are comments (a calibration accepted despite failed checks says so there).

Observed orientations (GNSS/INS, for the bundle adjustment) add their standard deviations,
all six or none (the bundle adjustment writes them for its adjusted orientations too)::

    sigma_X,sigma_Y,sigma_Z            metres (aliases sx, sy, sz)
    sigma_omega_deg,sigma_phi_deg,sigma_kappa_deg    degrees (aliases s_omega_deg, ...)

and an optional ``camera`` column names the camera of each image (blocks with several
cameras). The velocity of each exposure (m/s; the bundle adjustment's camera timing offset)
may be given, three columns or none, either local level at the image (true north, as the
trajectory table and ``importtrajectory`` write it)::

    v_north, v_east, v_up (or v_down)      aliases as in :mod:`.trajectory`

or along the mapping CRS's axes (d easting / dt, d northing / dt, d height / dt)::

    vx, vy, vz                             aliases v_x, v_y, v_z

Tables without these columns are read as before.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Union

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..photo.orientation import ExteriorOrientationTable
from ..photo.timing import ExposureVelocities
from .tables import (
    Table,
    find_column,
    float_column,
    number,
    read_table,
    text_column,
    unique_ids,
    write_csv_atomic,
)

EO_COLUMNS = ("image_id", "time", "group", "X", "Y", "Z", "omega_deg", "phi_deg", "kappa_deg")
EO_SIGMA_COLUMNS = (
    "sigma_X",
    "sigma_Y",
    "sigma_Z",
    "sigma_omega_deg",
    "sigma_phi_deg",
    "sigma_kappa_deg",
)
_SIGMA_ALIASES = (
    ("sigma_x", "sx", "s_x"),
    ("sigma_y", "sy", "s_y"),
    ("sigma_z", "sz", "s_z"),
    ("sigma_omega_deg", "s_omega_deg", "sigma_omega"),
    ("sigma_phi_deg", "s_phi_deg", "sigma_phi"),
    ("sigma_kappa_deg", "s_kappa_deg", "sigma_kappa"),
)


@dataclass(frozen=True)
class EoFile:
    """An EO table with what the bundle adjustment also reads from it.

    ``sigma`` (M, 6): metres and radians, or None (approximate orientations only);
    ``camera``: camera name per image, or None; ``rows``: the file rows of the images.
    """

    eo: ExteriorOrientationTable
    sigma: NDArray[np.float64] | None
    camera: tuple[str, ...] | None
    rows: tuple[int, ...]
    path: str
    velocity: ExposureVelocities | None = None


def _eo_rows(eo: ExteriorOrientationTable) -> Iterator[tuple[str, ...]]:
    deg = np.degrees(eo.opk)
    for image, t, group, (x, y, z), (w, p, k) in zip(eo.image_id, eo.time, eo.group, eo.xyz, deg):
        yield (
            image,
            number(t),
            group,
            number(x),
            number(y),
            number(z),
            number(w),
            number(p),
            number(k),
        )


def write_eo_csv(
    path: Union[str, Path], eo: ExteriorOrientationTable, comments: Sequence[str] = ()
) -> None:
    """Write the documented CSV atomically (never a half-written file); ``comments`` become
    ``# text`` lines before the header (e.g. a warning)."""
    write_csv_atomic(path, EO_COLUMNS, _eo_rows(eo), comments)


def eo_csv_text(eo: ExteriorOrientationTable) -> str:
    """The same table as text (what the command line prints when no file is given)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(EO_COLUMNS)
    writer.writerows(_eo_rows(eo))
    return buffer.getvalue()


def read_eo_csv(path: Union[str, Path], crs_wkt: str = "") -> ExteriorOrientationTable:
    """Read a table written by :meth:`ExteriorOrientationTable.to_csv` (or made by hand)."""
    return _eo_from_table(read_table(path), crs_wkt)


def _eo_from_table(table: Table, crs_wkt: str) -> ExteriorOrientationTable:
    ids = unique_ids(table, find_column(table, ("image_id", "image", "id", "name")))
    t_col = find_column(table, ("time",), required=False)
    g_col = find_column(table, ("group",), required=False)
    xyz = np.stack(
        [float_column(table, find_column(table, (name.lower(),))) for name in ("X", "Y", "Z")],
        axis=1,
    )
    opk = np.stack(
        [
            float_column(table, find_column(table, (f"{name}_deg", name)))
            for name in ("omega", "phi", "kappa")
        ],
        axis=1,
    )
    if t_col is None:
        time = np.full(len(table), np.nan)
    else:
        time = float_column(table, t_col, allow_empty=True)
    group = text_column(table, g_col, nonempty=False) if g_col is not None else ("",) * len(ids)
    if np.any(np.abs(opk[:, 1]) > 90.0):
        row = table.line_numbers[int(np.argmax(np.abs(opk[:, 1]) > 90.0))]
        raise InputError("phi must lie within [-90, 90] degrees", path=table.path, row=row)
    return ExteriorOrientationTable(ids, time, group, xyz, np.radians(opk), crs_wkt)


def read_eo_csv_full(path: Union[str, Path], crs_wkt: str = "") -> EoFile:
    """Read the EO table with its optional sigma and camera columns (module docstring)."""
    table = read_table(path)
    eo = _eo_from_table(table, crs_wkt)
    cols = [find_column(table, a, required=False) for a in _SIGMA_ALIASES]
    sigma = None
    given = [c for c in cols if c is not None]
    if given and len(given) < 6:
        missing = [EO_SIGMA_COLUMNS[k] for k, c in enumerate(cols) if c is None]
        raise InputError(
            f"EO sigma columns must be given all six or none; missing {', '.join(missing)}",
            path=table.path,
        )
    if given:
        # all six given: ``given`` is ``cols``, in order
        values = np.column_stack([float_column(table, c, allow_empty=True) for c in given])
        empty = np.isnan(values)
        if empty.all():
            sigma = None
        else:
            bad = np.flatnonzero(empty.any(axis=1) | (values <= 0).any(axis=1))
            if bad.size:
                k = int(bad[0])
                j = int(np.flatnonzero(empty[k] | (values[k] <= 0))[0])
                raise InputError(
                    "every sigma must be a number > 0 (or leave all of them empty)",
                    path=table.path,
                    row=table.line_numbers[k],
                    column=table.columns[given[j]],
                )
            sigma = values.copy()
            sigma[:, 3:] = np.radians(sigma[:, 3:])
    c_col = find_column(table, ("camera", "camera_id", "camera_name"), required=False)
    camera = None if c_col is None else text_column(table, c_col)
    return EoFile(eo, sigma, camera, table.line_numbers, table.path, _velocity(table))


_MAP_VELOCITY = (("vx", "v_x"), ("vy", "v_y"), ("vz", "v_z"))


def _velocity(table: Table) -> ExposureVelocities | None:
    """The exposures' velocities of the module docstring, or None; a partial set, both sets
    or an implausible speed refused with the file (and row)."""
    from .trajectory import check_speeds, velocity_columns

    ned = velocity_columns(table)
    cols = [find_column(table, a, required=False) for a in _MAP_VELOCITY]
    given = [c for c in cols if c is not None]
    if not given:
        return None if ned is None else ExposureVelocities(ned, "ned")
    if ned is not None or len(given) < 3:
        raise InputError(
            "give the velocities as v_north, v_east, v_up or as vx, vy, vz (all three of one set)",
            path=table.path,
        )
    vel = np.column_stack([float_column(table, c) for c in given])
    check_speeds(table, vel, given[0])
    return ExposureVelocities(vel, "map")


def write_eo_csv_with_sigmas(
    path: Union[str, Path],
    eo: ExteriorOrientationTable,
    sigma: NDArray[np.float64],
    camera: tuple[str, ...] | None = None,
) -> None:
    """Write the EO table with its sigmas (M, 6: metres, radians) and optional cameras."""
    sig = np.asarray(sigma, dtype=np.float64).copy()
    sig[:, 3:] = np.degrees(sig[:, 3:])
    cols = EO_COLUMNS + EO_SIGMA_COLUMNS + (("camera",) if camera is not None else ())

    def rows() -> Iterator[tuple[str, ...]]:
        for k, base in enumerate(_eo_rows(eo)):
            s = tuple(number(v) for v in sig[k])
            yield base + s + ((camera[k],) if camera is not None else ())

    write_csv_atomic(path, cols, rows())
