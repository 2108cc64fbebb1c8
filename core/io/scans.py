"""Terrestrial laser scans in their scanner frame: LAS/LAZ, PLY, E57.

A scan is read as (N, 3) x, y, z in metres in the scanner's own frame (the scanner at the
origin: the file as the scanner software exports a single station, not registered) and an
intensity in [0, 1] (the file's intensity divided by its largest value; NaN when the file has
none). PLY: ASCII or binary (little or big endian) with a ``vertex`` element holding x, y, z
and optionally ``intensity`` or ``scalar_intensity``. E57: the first scan of the file, with
its pose applied only if the user asks (we read the raw scanner-frame points), through the
optional ``pye57`` package.

Registered scans (:func:`write_registered_scan`) are written as LAS/LAZ through laspy: a
LAS/LAZ scan chunk by chunk with every dimension and VLR kept, a PLY or E57 scan as LAS
point format 0 (1 with intensity) at 0.1 mm resolution.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from copy import deepcopy
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from .tables import PathLike

__all__ = ["SCAN_SUFFIXES", "read_scan", "write_registered_scan"]

SCAN_SUFFIXES = (".las", ".laz", ".ply", ".e57")
#: (N, 3) scanner-frame points (m) -> (N, 3) object-frame points (m).
Transform = Callable[[NDArray[np.float64]], NDArray[np.float64]]
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


def _new_offsets(transform: Transform) -> NDArray[np.float64]:
    """Offsets of the registered file: where the scanner's origin goes, rounded to a metre (the
    scan lies within a few km of it: inside the int32 range even at 0.1 mm)."""
    origin = np.asarray(transform(np.zeros((1, 3))), dtype=np.float64)[0]
    return np.round(origin) if np.all(np.isfinite(origin)) else np.zeros(3)


def write_registered_scan(
    src: PathLike,
    dst: PathLike,
    transform: Transform,
    *,
    chunk_size: int = 1_000_000,
    should_stop: Callable[[], bool] | None = None,
) -> int:
    """Write scan ``src`` to ``dst`` (.las or .laz) with its points mapped by ``transform``
    ((N, 3) scanner-frame metres -> (N, 3) object-frame metres); the number of points.

    LAS/LAZ sources are streamed in chunks of ``chunk_size`` points, keeping every dimension,
    the point format, the scales and the VLRs; the offsets become the registered position of
    the scanner's origin in whole metres. PLY and E57 scans are read whole and written as
    point format 0 (1 with intensity, scaled to 0-65535) with scales of 0.1 mm. ``dst`` is
    written directly: the caller makes it atomic (a temporary of
    :class:`~core.io.atomic.OutputSet`).
    """
    import laspy

    from ..errors import stop_if_asked
    from .pointcloud import _check_record_count, _laz_backend, _open

    p, out = Path(src), os.fspath(dst)
    compress = out.lower().endswith(".laz")
    suffix = p.suffix.lower()
    if suffix not in (".las", ".laz"):
        xyz, intensity = read_scan(p)
        reg = np.asarray(transform(xyz), dtype=np.float64)
        has_i = bool(np.isfinite(intensity).any())
        header = laspy.LasHeader(point_format=1 if has_i else 0, version="1.2")
        header.scales = np.full(3, 0.0001)
        header.offsets = _new_offsets(transform)
        las = laspy.LasData(header)
        las.x, las.y, las.z = reg[:, 0], reg[:, 1], reg[:, 2]
        if has_i:
            las.intensity = np.round(np.nan_to_num(intensity) * 65535).astype(np.uint16)
        las.write(out, do_compress=compress, laz_backend=_laz_backend())
        return len(reg)
    if not p.is_file():
        raise InputError("file not found", path=str(p))
    n = 0
    with _open(str(p)) as reader:
        _check_record_count(str(p), reader.header)
        header = deepcopy(reader.header)
        header.offsets = _new_offsets(transform)
        writer = None
        try:
            for chunk in reader.chunk_iterator(max(int(chunk_size), 1)):
                stop_if_asked(should_stop, f"registering {p.name}")
                xyz = np.column_stack([np.asarray(chunk.x), np.asarray(chunk.y),
                                       np.asarray(chunk.z)]).astype(np.float64)  # fmt: skip
                reg = np.asarray(transform(xyz), dtype=np.float64)
                if writer is None:
                    writer = laspy.open(out, mode="w", header=header, do_compress=compress,
                                        laz_backend=_laz_backend())  # fmt: skip
                rec = laspy.ScaleAwarePointRecord.zeros(len(reg), header=writer.header)
                for name in chunk.point_format.dimension_names:
                    if name not in ("X", "Y", "Z"):
                        rec[name] = chunk[name]
                rec.x, rec.y, rec.z = reg[:, 0], reg[:, 1], reg[:, 2]
                writer.write_points(rec)
                n += len(reg)
        finally:
            if writer is not None:
                writer.close()
    if n == 0:
        raise InputError("the scan holds no points", path=str(p))
    return n
