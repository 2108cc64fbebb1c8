"""Terrestrial laser scans in their scanner frame: LAS/LAZ, PLY, E57.

A scan is read as (N, 3) x, y, z in metres in the scanner's own frame (the scanner at the
origin: the file as the scanner software exports a single station, not registered) and an
intensity in [0, 1] (the file's intensity divided by its largest value; NaN when the file has
none). PLY: ASCII or binary (little or big endian) with a ``vertex`` element holding x, y, z
and optionally ``intensity`` or ``scalar_intensity``. E57: the first scan of the file, with
its pose applied only if the user asks (we read the raw scanner-frame points), through the
optional ``pye57`` package.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from .tables import PathLike

__all__ = ["SCAN_SUFFIXES", "read_scan"]

SCAN_SUFFIXES = (".las", ".laz", ".ply", ".e57")
_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
    "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}  # fmt: skip


def _normalise(intensity: NDArray | None, n: int) -> NDArray[np.float64]:
    if intensity is None:
        return np.full(n, np.nan)
    it = np.asarray(intensity, dtype=np.float64)
    top = float(np.nanmax(it)) if it.size else 0.0
    return it / top if top > 0 else it


def _read_ply(path: Path) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    with open(path, "rb") as fh:
        if fh.readline().strip() != b"ply":
            raise InputError("not a PLY file (no 'ply' magic line)", path=str(path))
        fmt, count, props, in_vertex, other_before = None, 0, [], False, []
        while True:
            line = fh.readline()
            if not line:
                raise InputError("the PLY header has no end_header", path=str(path))
            words = line.decode("ascii", "replace").split()
            if not words or words[0] in ("comment", "obj_info"):
                continue
            if words[0] == "format":
                fmt = words[1]
            elif words[0] == "element":
                in_vertex = words[1] == "vertex"
                if in_vertex:
                    count = int(words[2])
                elif count == 0:
                    other_before.append(words[1])
            elif words[0] == "property" and in_vertex:
                if words[1] == "list":
                    raise InputError("list properties in the PLY vertex element are not "
                                     "supported", path=str(path))  # fmt: skip
                props.append((words[2], _PLY_TYPES.get(words[1], "")))
            elif words[0] == "end_header":
                break
        if other_before:
            raise InputError("the PLY file has elements before 'vertex'", path=str(path))
        names = [p[0] for p in props]
        for c in ("x", "y", "z"):
            if c not in names:
                raise InputError(f"the PLY vertex element has no property {c}", path=str(path))
        if fmt == "ascii":
            data = np.loadtxt(fh, dtype=np.float64, max_rows=count, ndmin=2)
            cols = {n: data[:, i] for i, n in enumerate(names)}
        elif fmt in ("binary_little_endian", "binary_big_endian"):
            end = "<" if fmt == "binary_little_endian" else ">"
            if any(not t for _, t in props):
                raise InputError("unknown PLY property type", path=str(path))
            dtype = np.dtype([(n, end + t) for n, t in props])
            data = np.frombuffer(fh.read(dtype.itemsize * count), dtype=dtype, count=count)
            cols = {n: data[n].astype(np.float64) for n in names}
        else:
            raise InputError(f"unknown PLY format {fmt!r}", path=str(path))
    xyz = np.column_stack([cols["x"], cols["y"], cols["z"]])
    inten = cols.get("intensity", cols.get("scalar_intensity"))
    return xyz, _normalise(inten, len(xyz))


def read_scan(path: PathLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(N, 3) scanner-frame points (m) and (N,) intensities in [0, 1] of one scan."""
    p = Path(path)
    if not p.is_file():
        raise InputError("file not found", path=str(p))
    suffix = p.suffix.lower()
    if suffix in (".las", ".laz"):
        from .pointcloud import read_info, read_points

        info = read_info(p, require_crs=False)
        fields = ("x", "y", "z", "intensity") if "intensity" in info.dimensions else ("x", "y", "z")
        arrays, _ = read_points(p, fields, require_crs=False)
        xyz = np.column_stack([arrays["x"], arrays["y"], arrays["z"]]).astype(np.float64)
        return xyz, _normalise(arrays.get("intensity"), len(xyz))
    if suffix == ".ply":
        return _read_ply(p)
    if suffix == ".e57":
        try:
            import pye57
        except ImportError:
            raise InputError(
                "reading E57 needs the optional package pye57 (pip install pye57); or export "
                "the scan as LAS/LAZ or PLY",
                path=str(p),
            ) from None
        e57 = pye57.E57(str(p))
        data = e57.read_scan_raw(0)
        xyz = np.column_stack([data["cartesianX"], data["cartesianY"], data["cartesianZ"]])
        return xyz.astype(np.float64), _normalise(data.get("intensity"), len(xyz))
    raise InputError(f"unknown scan format {suffix!r} (LAS, LAZ, PLY or E57)", path=str(p))
