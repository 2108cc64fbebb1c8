"""Terrestrial laser scans in their scanner frame: LAS/LAZ, PLY, E57.

A scan is read as (N, 3) x, y, z in metres in the scanner's own frame (the scanner at the
origin: the file as the scanner software exports a single station, not registered) and an
intensity in [0, 1] (the file's intensity divided by its largest value; NaN when the file has
none). PLY: ASCII or binary (little or big endian) with a ``vertex`` element holding x, y, z
and optionally ``intensity`` or ``scalar_intensity``. E57: the first scan of the file, raw
(the scanner-frame points, its pose not applied), Cartesian or spherical, without the points
its invalid-state field marks as having no coordinates, through the optional ``pye57``
package. Every reader refuses, naming the file, an empty, truncated or corrupt file, a scan
without points, coordinates or intensities that are not finite and points beyond
:data:`MAX_SCANNER_RANGE_M` of the origin (a registered scan, not a scanner frame).

Registered scans (:func:`write_registered_scan`) are written as LAS/LAZ through laspy: a
LAS/LAZ scan chunk by chunk with every dimension and VLR kept, a PLY or E57 scan as LAS
point format 0 (1 with intensity) at 0.1 mm resolution.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable
from copy import deepcopy
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from .suffixes import SCAN_SUFFIXES
from .tables import PathLike

__all__ = ["MAX_SCANNER_RANGE_M", "SCAN_SUFFIXES", "read_scan", "write_registered_scan"]

log = logging.getLogger(__name__)
#: (N, 3) scanner-frame points (m) -> (N, 3) object-frame points (m).
Transform = Callable[[NDArray[np.float64]], NDArray[np.float64]]
_PLY_TYPES = {
    "char": "i1",
    "int8": "i1",
    "uchar": "u1",
    "uint8": "u1",
    "short": "i2",
    "int16": "i2",
    "ushort": "u2",
    "uint16": "u2",
    "int": "i4",
    "int32": "i4",
    "uint": "u4",
    "uint32": "u4",
    "float": "f4",
    "float32": "f4",
    "double": "f8",
    "float64": "f8",
}


#: A scan whose points lie farther than this from its origin (m) is not in the scanner's own
#: frame: the longest-range terrestrial scanners reach about 6 km.
MAX_SCANNER_RANGE_M = 10_000.0


def _normalise(intensity: NDArray | None, n: int) -> NDArray[np.float64]:
    if intensity is None:
        return np.full(n, np.nan)
    it = np.asarray(intensity, dtype=np.float64)
    top = float(np.nanmax(it)) if it.size else 0.0
    return it / top if top > 0 else it


def _ply_header(fh, path: Path) -> tuple[str, int, list[tuple[str, str]]]:
    """(format, vertex count, [(property, numpy type code)]) of a PLY header; the file is left
    at the first byte of the data."""
    where = str(path)
    if fh.readline(64).strip() != b"ply":
        raise InputError("not a PLY file (no 'ply' magic line)", path=where)
    fmt, count, props, in_vertex, other_before, seen = None, None, [], False, [], False
    for number in range(2, 100_000):  # header lines; a binary file without end_header stops
        line = fh.readline(4096)
        if not line:
            raise InputError("the PLY header has no end_header (truncated file?)", path=where)
        words = line.decode("ascii", "replace").split()
        if not words or words[0] in ("comment", "obj_info"):
            continue
        if words[0] == "format" and len(words) >= 2:
            fmt = words[1]
        elif words[0] == "element" and len(words) == 3:
            in_vertex = words[1] == "vertex"
            if in_vertex:
                try:
                    count = int(words[2])
                except ValueError:
                    count = -1
                if count < 0:
                    raise InputError(
                        f"header line {number}: the vertex count {words[2]!r} is "
                        "not a whole number",
                        path=where,
                    )
                seen = True
            elif not seen:
                other_before.append(words[1])
        elif words[0] == "property" and in_vertex:
            if words[1] == "list":
                raise InputError(
                    "list properties in the PLY vertex element are not supported", path=where
                )
            if len(words) != 3:
                raise InputError(
                    f"header line {number}: a property needs a type and a name", path=where
                )
            props.append((words[2], _PLY_TYPES.get(words[1], "")))
        elif words[0] == "end_header":
            break
    else:
        raise InputError("the PLY header has no end_header", path=where)
    if fmt is None:
        raise InputError("the PLY header has no format line", path=where)
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise InputError(
            f"unknown PLY format {fmt!r} (ascii, binary_little_endian or binary_big_endian)",
            path=where,
        )
    if count is None:
        raise InputError("the PLY file has no vertex element", path=where)
    if other_before:
        raise InputError("the PLY file has elements before 'vertex'", path=where)
    names = [p[0] for p in props]
    for c in ("x", "y", "z"):
        if c not in names:
            raise InputError(f"the PLY vertex element has no property {c}", path=where)
    if fmt != "ascii" and any(not t for _, t in props):
        unknown = next(n for n, t in props if not t)
        raise InputError(f"unknown PLY type of the vertex property {unknown!r}", path=where)
    if count == 0:
        raise InputError("the scan holds no points (element vertex 0)", path=where)
    return fmt, count, props


def _ply_ascii(fh, path: Path, count: int, names: list[str]) -> dict[str, NDArray]:
    """The first ``count`` data lines of an ASCII PLY as float64 columns; a short or bad line
    is named by its line in the file."""
    start = fh.tell()
    try:
        data = np.loadtxt(fh, dtype=np.float64, max_rows=count, ndmin=2, comments=None)
        ok = data.shape == (count, len(names))
    except ValueError:
        ok = False
    if not ok:  # name the first bad or missing line (the error path only: Python speed)
        fh.seek(0)
        head = fh.read(start).count(b"\n")
        held = 0
        for line in fh:
            if held == count:
                break
            words = line.split()
            try:
                good = len([float(w) for w in words]) == len(names)
            except ValueError:
                good = False
            if not good:
                raise InputError(
                    f"vertex {held + 1}: {len(words)} value(s) "
                    f"({line.decode('ascii', 'replace').strip()[:40]!r}), the "
                    f"header declares {len(names)} numbers ({', '.join(names)})",
                    path=str(path),
                    row=head + held + 1,
                )
            held += 1
        raise InputError(
            f"truncated: the file holds {held} of the {count} vertices its header declares",
            path=str(path),
        )
    return {n: data[:, i] for i, n in enumerate(names)}


def _read_ply(path: Path) -> tuple[NDArray[np.float64], NDArray | None]:
    with open(path, "rb") as fh:
        fmt, count, props = _ply_header(fh, path)
        names = [p[0] for p in props]
        if fmt == "ascii":
            cols = _ply_ascii(fh, path, count, names)
        else:
            end = "<" if fmt == "binary_little_endian" else ">"
            dtype = np.dtype([(n, end + t) for n, t in props])
            held = (os.fstat(fh.fileno()).st_size - fh.tell()) // dtype.itemsize
            if held < count:
                raise InputError(
                    f"truncated: the file holds {held} of the {count} vertices "
                    f"its header declares ({dtype.itemsize} bytes each)",
                    path=str(path),
                )
            data = np.fromfile(fh, dtype=dtype, count=count)
            cols = {n: data[n].astype(np.float64) for n in names}
    xyz = np.column_stack([cols["x"], cols["y"], cols["z"]])
    return xyz, cols.get("intensity", cols.get("scalar_intensity"))


def _first_line(exc: Exception) -> str:
    """The first line of a library's message (libE57Format's add pages of debug text)."""
    lines = str(exc).strip().splitlines()
    return lines[0] if lines else type(exc).__name__


def _read_e57(path: Path) -> tuple[NDArray[np.float64], NDArray | None]:
    """The first scan of an E57 file, raw (scanner frame): Cartesian or spherical coordinates,
    points whose invalid state says they carry no coordinates left out."""
    try:
        import pye57
    except ImportError:
        raise InputError(
            "reading E57 needs the optional package pye57 (pip install pye57); or export "
            "the scan as LAS/LAZ or PLY",
            path=str(path),
        ) from None
    try:
        e57 = pye57.E57(str(path))
    except Exception as exc:  # libE57Format raises its own types for bad bytes
        raise InputError(
            f"cannot read as E57 (truncated or corrupt file?): {_first_line(exc)}", path=str(path)
        ) from exc
    try:
        scans = int(e57.scan_count)
        if scans == 0:
            raise InputError("the E57 file holds no scans", path=str(path))
        if scans > 1:
            log.warning("%s: %d scans in the file; the first is read", path, scans)
        try:
            data = e57.read_scan_raw(0, ignore_unsupported_fields=True)
        except Exception as exc:
            raise InputError(
                f"cannot read the points of its first scan (truncated or "
                f"corrupt E57?): {_first_line(exc)}",
                path=str(path),
            ) from exc
    finally:
        e57.close()
    if "cartesianX" in data:
        xyz = np.column_stack([data["cartesianX"], data["cartesianY"], data["cartesianZ"]])
        state = data.get("cartesianInvalidState")
    elif "sphericalRange" in data:
        r, az, el = (
            np.asarray(data[k], dtype=np.float64)
            for k in ("sphericalRange", "sphericalAzimuth", "sphericalElevation")
        )
        xyz = np.column_stack(
            [r * np.cos(el) * np.cos(az), r * np.cos(el) * np.sin(az), r * np.sin(el)]
        )
        state = data.get("sphericalInvalidState")
    else:
        raise InputError(
            "the first scan has neither Cartesian nor spherical coordinates", path=str(path)
        )
    intensity = data.get("intensity")
    if state is not None:  # E57: 0 a point, 1 a direction only, 2 no return
        keep = np.asarray(state) == 0
        xyz = xyz[keep]
        intensity = None if intensity is None else np.asarray(intensity)[keep]
    return np.asarray(xyz, dtype=np.float64), intensity


def _checked(path: Path, xyz: NDArray[np.float64], intensity: NDArray | None) -> None:
    """Refuse a scan without points, with coordinates or intensities that are not finite, or
    that is not in a scanner's frame."""
    where = str(path)
    if len(xyz) == 0:
        raise InputError("the scan holds no points", path=where)
    bad = ~np.isfinite(xyz).all(axis=1)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise InputError(
            f"point {k + 1} of {len(xyz)} has coordinates that are not finite "
            f"({', '.join(f'{v:g}' for v in xyz[k])}); {int(bad.sum())} point(s) "
            "affected: remove the points without a return",
            path=where,
        )
    if intensity is not None:
        it = np.asarray(intensity, dtype=np.float64)
        bad = ~np.isfinite(it)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise InputError(
                f"point {k + 1} of {len(xyz)} has an intensity that is not "
                f"finite ({it[k]:g}); {int(bad.sum())} point(s) affected",
                path=where,
            )
    far = float(np.max(np.hypot(np.hypot(xyz[:, 0], xyz[:, 1]), xyz[:, 2])))  # no overflow
    if far > MAX_SCANNER_RANGE_M:
        raise InputError(
            f"points lie up to {far / 1000:.4g} km from the scanner's origin; a "
            f"scan in its scanner's own frame stays within "
            f"{MAX_SCANNER_RANGE_M / 1000:g} km: this one is registered or "
            "georeferenced (export the station unregistered)",
            path=where,
        )


def read_scan(path: PathLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(N, 3) scanner-frame points (m) and (N,) intensities in [0, 1] of one scan.

    Raises :class:`InputError` naming the file for a missing, empty, truncated or corrupt
    file, one without points, with coordinates or intensities that are not finite, or with
    points farther than :data:`MAX_SCANNER_RANGE_M` from the scanner (not its own frame).
    """
    p = Path(path)
    if not p.is_file():
        raise InputError("file not found", path=str(p))
    suffix = p.suffix.lower()
    if suffix not in SCAN_SUFFIXES:
        raise InputError(f"unknown scan format {suffix!r} (LAS, LAZ, PLY or E57)", path=str(p))
    if p.stat().st_size == 0:
        raise InputError("empty file (0 bytes)", path=str(p))
    if suffix in (".las", ".laz"):
        from .pointcloud import read_info, read_points

        info = read_info(p, require_crs=False)
        fields = ("x", "y", "z", "intensity") if "intensity" in info.dimensions else ("x", "y", "z")
        arrays, _ = read_points(p, fields, require_crs=False)
        xyz = np.column_stack([arrays["x"], arrays["y"], arrays["z"]]).astype(np.float64)
        intensity = arrays.get("intensity")
    elif suffix == ".ply":
        xyz, intensity = _read_ply(p)
    else:
        xyz, intensity = _read_e57(p)
    _checked(p, xyz, intensity)
    return xyz, _normalise(intensity, len(xyz))


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
                xyz = np.column_stack(
                    [np.asarray(chunk.x), np.asarray(chunk.y), np.asarray(chunk.z)]
                ).astype(np.float64)
                reg = np.asarray(transform(xyz), dtype=np.float64)
                if writer is None:
                    writer = laspy.open(
                        out,
                        mode="w",
                        header=header,
                        do_compress=compress,
                        laz_backend=_laz_backend(),
                    )
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
