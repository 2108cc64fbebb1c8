"""LAS/LAZ point clouds (versions 1.0-1.4) through laspy with the lazrs backend.

Reading streams laspy's ``chunk_iterator`` into preallocated arrays, so a 10-million-point
file costs the arrays asked for plus one chunk. An algorithm that writes a classified copy
reads the file once with :func:`read_cloud`, which keeps every point record as stored (the
packed bytes: 20-67 B per point) next to the arrays it asks for; :func:`write_cloud` then
writes that copy from memory, chunk by chunk into a temporary file next to the destination
(keeping every dimension, header field and VLR), and moves it into place only when it is
complete. LAZ is decoded and encoded with lazrs on every core (laspy's ``LazrsParallel``
back end) when lazrs is installed, so the whole read -> classify -> write costs one decoding,
one encoding and the algorithm, without the second decoding of a copy made from the file.

Units are never assumed: :func:`read_info` reports the horizontal unit of the cloud's CRS and
its size in metres, so that callers can interpret distance parameters in the cloud's own unit
(the Autzen files are in international feet) or convert metres explicitly.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable, Iterator, Mapping, Sequence
from copy import deepcopy
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Union

import numpy as np
import pyproj
from numpy.typing import NDArray

from ..errors import Cancelled, CrsError, InputError, stop_if_asked
from ..geometry import frames
from .atomic import atomic_path
from .cloud_units import _vertical_geokey_unit, crs_units

LOG = logging.getLogger(__name__)

PathLike = Union[str, "os.PathLike[str]"]
CrsLike = Union[str, int, pyproj.CRS, None]

#: LAS versions this module accepts (laspy reads 1.0 as 1.1: the header layouts are equal).
SUPPORTED_VERSIONS = ("1.0", "1.1", "1.2", "1.3", "1.4")
#: Extra-dimension dtypes a LAS extra-bytes VLR can describe.
EXTRA_DTYPES = ("u1", "i1", "u2", "i2", "u4", "i4", "u8", "i8", "f4", "f8")
_SCALED = ("x", "y", "z")


@dataclass(frozen=True)
class CloudInfo:
    """What the header of a LAS/LAZ file says, plus the CRS and its units.

    Attributes
    ----------
    path : str
        The file.
    point_count : int
        Number of point records.
    version : str
        LAS version, e.g. ``"1.2"``.
    point_format : int
        LAS point data record format id (0-10).
    crs : pyproj.CRS or None
        From the file's WKT VLR (preferred) or GeoTIFF keys, or the user's override. None only
        when ``require_crs=False`` and the file has none.
    horizontal_unit : str
        Unit of x and y: ``"metre"``, ``"foot"``, ``"US survey foot"``... (``"unknown"``
        without CRS).
    unit_to_metre : float
        Size of one horizontal coordinate unit in metres (1.0, 0.3048, 1200/3937; NaN when
        unknown).
    vertical_unit_to_metre : float
        Size of one z unit in metres: from the vertical part of a compound CRS, else the GeoTIFF
        VerticalUnitsGeoKey, else the horizontal unit.
    mins, maxs : NDArray[np.float64]
        (3,) bounding box of the scaled coordinates, from the header.
    dimensions : tuple[str, ...]
        Every dimension name of the point format, extra bytes included.
    has_return_numbers : bool
        False when every return number is 0 (e.g. the ISPRS samples). From the header's
        points-by-return counts in :func:`read_info`, from the data in :func:`read_points`
        when ``return_number`` is read.
    record_size : int
        Bytes of one point record (0 when unknown).
    """

    path: str
    point_count: int
    version: str
    point_format: int
    crs: pyproj.CRS | None
    horizontal_unit: str
    unit_to_metre: float
    vertical_unit_to_metre: float
    mins: NDArray[np.float64]
    maxs: NDArray[np.float64]
    dimensions: tuple[str, ...]
    has_return_numbers: bool
    record_size: int = 0

    def length_factors(self, distance_unit: str) -> tuple[float, float]:
        """Factors that turn horizontal and vertical lengths given in ``distance_unit``
        (``"crs"``: the cloud's own units; ``"metre"``) into the cloud's units.

        The one place where metres become CRS units (every LiDAR algorithm uses it).
        """
        if distance_unit == "crs":
            return 1.0, 1.0
        if distance_unit != "metre":
            raise InputError(f"DISTANCE_UNIT must be 'crs' or 'metre', got {distance_unit!r}")
        h, v = self.unit_to_metre, self.vertical_unit_to_metre
        if not (h > 0 and v > 0):
            raise CrsError(
                "lengths in metres need a cloud CRS with known units: give the CRS, or the "
                "lengths in the cloud's own unit",
                path=self.path,
            )
        return 1.0 / h, 1.0 / v


def _laz_backend() -> Any:
    """lazrs on every core when available (laspy's default order, made explicit), else None
    (laspy then takes whatever back end it has)."""
    import laspy

    available = laspy.LazBackend.detect_available()
    return laspy.LazBackend.LazrsParallel if laspy.LazBackend.LazrsParallel in available else None


def _open(path: str) -> Any:
    import laspy

    if not os.path.isfile(path):
        raise InputError("file not found", path=path)
    if os.path.getsize(path) == 0:
        raise InputError("empty file (0 bytes)", path=path)
    try:
        return laspy.open(path, laz_backend=_laz_backend())
    except Exception as exc:  # laspy/lazrs raise many types for bad bytes
        raise InputError(f"cannot read as LAS/LAZ: {exc}", path=path) from exc


def _info_from_header(path: str, header: Any, crs: CrsLike, require_crs: bool) -> CloudInfo:
    version = f"{header.version.major}.{header.version.minor}"
    if version not in SUPPORTED_VERSIONS:
        raise InputError(
            f"LAS version {version} is not supported (supported: {', '.join(SUPPORTED_VERSIONS)})",
            path=path,
        )
    count = int(header.point_count)
    if count == 0:
        raise InputError("the file holds no points", path=path)
    scales = np.asarray(header.scales, dtype=np.float64)
    offsets = np.asarray(header.offsets, dtype=np.float64)
    if not (np.isfinite(scales).all() and (scales != 0).all() and np.isfinite(offsets).all()):
        raise InputError(  # x = X * scale + offset: every coordinate would be 0, NaN or inf
            "the header's scale factors must be finite and non-zero and its offsets finite, "
            f"got scales {', '.join(f'{v:g}' for v in scales)} and offsets "
            f"{', '.join(f'{v:g}' for v in offsets)}: a corrupt header",
            path=path,
        )
    user_crs = frames.parse_crs(crs, optional=True)
    file_crs = None
    if user_crs is None:
        try:
            file_crs = header.parse_crs(prefer_wkt=True)
        except Exception as exc:  # a malformed WKT or GeoTIFF key set
            LOG.warning("%s: CRS records present but not understood (%s)", path, exc)
    use = user_crs if user_crs is not None else file_crs
    if use is None:
        if require_crs:
            raise CrsError(
                "the file has no CRS that can be read (no WKT VLR and no EPSG code in its GeoTIFF "
                "keys): give the CRS of the cloud (CRS parameter, e.g. EPSG:28992)",
                path=path,
            )
        unit, to_metre, vertical = "unknown", float("nan"), float("nan")
    else:
        try:
            unit, to_metre, vertical = crs_units(use, _vertical_geokey_unit(header))
        except CrsError as exc:
            if require_crs:
                raise CrsError(str(exc), path=path) from exc
            unit, to_metre, vertical = "unknown", float("nan"), float("nan")
    mins = np.asarray(header.mins, dtype=np.float64).copy()
    maxs = np.asarray(header.maxs, dtype=np.float64).copy()
    if use is not None:  # a CRS that cannot hold these coordinates (or a unit mix-up)
        frames.check_area_of_use(
            use, mins[:2], maxs[:2], what="the cloud (header extent)", path=path
        )
    by_return = np.asarray(header.number_of_points_by_return)
    return CloudInfo(
        path=path,
        point_count=count,
        version=version,
        point_format=int(header.point_format.id),
        crs=use,
        horizontal_unit=unit,
        unit_to_metre=to_metre,
        vertical_unit_to_metre=vertical,
        mins=mins,
        maxs=maxs,
        dimensions=tuple(header.point_format.dimension_names),
        has_return_numbers=bool(by_return.sum() > 0),
        record_size=int(header.point_format.size),
    )


def _check_record_count(path: str, header: Any) -> None:
    """An uncompressed file must hold exactly the header's number of point records.

    laspy reads as many records as the header says: extra records would be dropped silently,
    missing ones found only at the end of a long read. (A LAZ file's compressed chunks cannot
    be counted without decompressing them: its missing points are found by the reader.)
    """
    if header.are_points_compressed:
        return
    size = os.path.getsize(path)
    end = size
    if int(getattr(header, "number_of_evlrs", 0) or 0) > 0:
        start = int(getattr(header, "start_of_first_evlr", 0) or 0)
        end = start if 0 < start <= size else size
    record = int(header.point_format.size)
    held, rest = divmod(max(end - int(header.offset_to_point_data), 0), record)
    n = int(header.point_count)
    if held > n:
        raise InputError(
            f"the file holds {held} point records but its header says {n}: the header is "
            "wrong (the points beyond it would be dropped); rewrite the file with a tool that "
            "updates the header",
            path=path,
        )
    if held < n:
        raise InputError(
            f"truncated: the file holds {held} point records, the header says {n}", path=path
        )
    if held == n and rest:
        LOG.warning("%s: %d stray bytes after the last point record", path, rest)


def read_info(path: PathLike, crs: CrsLike = None, *, require_crs: bool = True) -> CloudInfo:
    """Read the header of a LAS/LAZ file, its CRS and units, without reading points.

    Parameters
    ----------
    path : str or os.PathLike
        LAS or LAZ file, version 1.0-1.4.
    crs : str, int, pyproj.CRS or None
        Overrides the file's CRS (EPSG code, ``"EPSG:xxxx"``, WKT).
    require_crs : bool
        When True (default) a cloud without a readable CRS, or with a geographic one, raises
        CrsError; when False its ``crs`` is None and its units ``"unknown"``/NaN.

    Returns
    -------
    CloudInfo

    Raises
    ------
    InputError
        Missing, empty, unreadable file, unsupported version, 0 points, scale factors or
        offsets that are not finite (names the file).
    CrsError
        No CRS and no override, or a geographic CRS.
    """
    path = os.fspath(path)
    with _open(path) as reader:
        _check_record_count(path, reader.header)
        return _info_from_header(path, reader.header, crs, require_crs)


def _check_fields(info: CloudInfo, fields: Sequence[str]) -> list[str]:
    known = {name.lower(): name for name in info.dimensions}
    out = []
    for field in fields:
        key = field.lower() if field.lower() in _SCALED else field
        if key not in _SCALED and key not in info.dimensions and key.lower() not in known:
            raise InputError(
                f"no dimension {field!r} (the file has: {', '.join(info.dimensions)})",
                path=info.path,
                column=field,
            )
        out.append(key if key in _SCALED or key in info.dimensions else known[key.lower()])
    return out


def _read_chunks(
    chunks: Iterator[Any],
    n: int,
    path: str,
    take: Callable[[Any, int], None],
    progress: Callable[[float], None] | None,
    should_stop: Callable[[], bool] | None,
) -> None:
    """Hand every chunk of a LAS reader to ``take(chunk, points_before_it)`` until ``n``
    points; decoding errors (a corrupt or truncated file) and a short count become
    InputError naming the file."""
    done = 0
    try:
        for chunk in chunks:
            stop_if_asked(should_stop, "processing the point cloud")
            m = len(chunk)
            take(chunk, done)
            done += m
            if progress is not None:
                progress(done / n)
    except (InputError, Cancelled):
        raise
    except Exception as exc:  # lazrs/laspy decoding errors: corrupt or truncated file
        raise InputError(
            f"corrupt or truncated point data after {done} of {n} points: {exc}", path=path
        ) from exc
    if done != n:
        raise InputError(f"truncated: {done} points read, the header says {n}", path=path)


def read_points(
    path: PathLike,
    fields: Sequence[str] = ("x", "y", "z"),
    crs: CrsLike = None,
    chunk_size: int = 1_000_000,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
    *,
    require_crs: bool = True,
) -> tuple[dict[str, NDArray[Any]], CloudInfo]:
    """Read chosen dimensions of every point, streaming ``chunk_size`` points at a time.

    Parameters
    ----------
    path : str or os.PathLike
        LAS or LAZ file.
    fields : sequence of str
        Dimension names: ``x``, ``y``, ``z`` (scaled, float64, in the CRS units) and any other
        dimension of the file (``classification``, ``return_number``, ``number_of_returns``,
        ``intensity``, extra bytes...) in its own dtype.
    crs, require_crs
        As in :func:`read_info`.
    chunk_size : int
        Points decoded per chunk (memory of one chunk on top of the result arrays).
    progress : callable, optional
        Receives the fraction read, after every chunk.
    should_stop : callable, optional
        Checked before every chunk; True raises Cancelled.

    Returns
    -------
    arrays : dict[str, NDArray]
        One (N,) array per field, keyed as asked.
    info : CloudInfo
        With ``has_return_numbers`` taken from the data when ``return_number`` was read.

    Raises
    ------
    InputError
        Unreadable, truncated or corrupt file, a header that counts fewer points than an
        uncompressed file holds, unknown field (names the file).
    CrsError
        As in :func:`read_info`.
    Cancelled
        When ``should_stop()`` returns True.
    """
    path = os.fspath(path)
    with _open(path) as reader:
        _check_record_count(path, reader.header)
        info = _info_from_header(path, reader.header, crs, require_crs)
        names = _check_fields(info, fields)
        n = info.point_count
        out: dict[str, NDArray[Any]] = {}

        def take(chunk: Any, done: int) -> None:
            m = len(chunk)
            if done + m > n:
                raise InputError(f"more points than the header's {n}", path=path)
            for key, name in zip(fields, names):
                values = np.asarray(chunk[name])
                if key not in out:
                    dtype = np.float64 if name in _SCALED else values.dtype
                    out[key] = np.empty(n, dtype=dtype)
                out[key][done : done + m] = values

        chunks = reader.chunk_iterator(max(int(chunk_size), 1))
        _read_chunks(chunks, n, path, take, progress, should_stop)
    if "return_number" in names:
        rn = out[fields[names.index("return_number")]]
        info = replace(info, has_return_numbers=bool(np.any(rn > 0)))
    return out, info


@dataclass(frozen=True)
class LasPoints:
    """Every point record of a LAS/LAZ file, as stored (see :func:`read_cloud`).

    Attributes
    ----------
    info : CloudInfo
        Header, CRS and units (``has_return_numbers`` from the data).
    header : laspy.LasHeader
        The source's header (writers copy it).
    chunks : list of numpy structured arrays
        The packed point records (the point format's raw dtype: integer X, Y, Z, bit fields)
        in file order, in the chunks they were decoded in (no copy into one array).
    evlrs : list
        The source's extended VLRs.
    """

    info: CloudInfo
    header: Any
    chunks: list[NDArray[Any]]
    evlrs: list[Any]

    def __len__(self) -> int:
        return sum(len(c) for c in self.chunks)

    def scaled_xyz(self) -> Any:
        """x, y, z as the records hold them (:class:`core.geometry.scaled_xyz.ScaledXYZ`:
        views of the integer X, Y, Z fields of each chunk, the header's scales and offsets),
        for algorithms that read the coordinates a block at a time instead of float64 copies
        of every point."""
        from ..geometry.scaled_xyz import ScaledXYZ

        sx, sy, sz = (float(v) for v in self.header.scales)
        ox, oy, oz = (float(v) for v in self.header.offsets)
        return ScaledXYZ(
            chunks=tuple((c["X"], c["Y"], c["Z"]) for c in self.chunks),
            scales=(sx, sy, sz),
            offsets=(ox, oy, oz),
        )

    def values(self, name: str) -> NDArray[Any]:
        """One dimension as a new (N,) array: ``x``, ``y``, ``z`` scaled to float64 in the CRS
        unit, any other (``classification``, ``return_number``, extra bytes...) in its own
        dtype."""
        import laspy

        (key,) = _check_fields(self.info, (name,))
        n = len(self)
        out = None
        done = 0
        for chunk in self.chunks:
            m = len(chunk)
            if key in _SCALED:
                axis = _SCALED.index(key)
                if out is None:
                    out = np.empty(n, dtype=np.float64)
                part = out[done : done + m]
                np.multiply(chunk[key.upper()], float(self.header.scales[axis]), out=part)
                part += float(self.header.offsets[axis])
            else:
                values = np.asarray(laspy.PackedPointRecord(chunk, self.header.point_format)[key])
                if out is None:
                    out = np.empty(n, dtype=values.dtype)
                out[done : done + m] = values
            done += m
        assert out is not None
        return out


def read_cloud(
    path: PathLike,
    crs: CrsLike = None,
    chunk_size: int = 4_000_000,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
    *,
    require_crs: bool = True,
) -> LasPoints:
    """Read every point record of a LAS/LAZ file once, to classify it and write it back.

    The records are kept as stored (the packed point format, e.g. 28 B per point for format
    1), so :func:`write_cloud` can write the copy from memory instead of decoding the file a
    second time; :meth:`LasPoints.values` gives the arrays an algorithm needs. LAZ is decoded
    by lazrs on every core.

    Parameters
    ----------
    path, crs, chunk_size, progress, should_stop, require_crs
        As in :func:`read_points` (progress and cancel are checked per chunk); the chunks
        are larger by default (lazrs decodes each on all cores: fewer ends where one core
        waits for the other).

    Returns
    -------
    LasPoints

    Raises
    ------
    InputError, CrsError, Cancelled
        As :func:`read_points`.

    Examples
    --------
    >>> from pathlib import Path
    >>> crop = Path(__file__).parents[2] / "tests" / "data" / "ahn3" / "ahn3_delft_crop60.laz"
    >>> cloud = read_cloud(crop)
    >>> len(cloud), cloud.chunks[0].dtype.itemsize, cloud.info.crs.to_epsg()
    (35231, 28, 7415)
    """
    path = os.fspath(path)
    with _open(path) as reader:
        _check_record_count(path, reader.header)
        info = _info_from_header(path, reader.header, crs, require_crs)
        header = deepcopy(reader.header)
        n = info.point_count
        chunks = []
        returns = False

        def take(chunk: Any, done: int) -> None:
            nonlocal returns
            chunks.append(chunk.array)
            returns = returns or bool(np.any(np.asarray(chunk.return_number) > 0))

        def read() -> Iterator[Any]:
            got = 0
            while got < n:
                chunk = reader.read_points(min(max(int(chunk_size), 1), n - got))
                if len(chunk) == 0:  # the file ends early: reported as truncated
                    return
                got += len(chunk)
                yield chunk

        _read_chunks(read(), n, path, take, progress, should_stop)
        evlrs = list(reader.header.evlrs or [])
    info = replace(info, has_return_numbers=returns)
    return LasPoints(info=info, header=header, chunks=chunks, evlrs=evlrs)


def _check_values(
    path: str, n: int, point_format: int, classification: Any, extra: Mapping[str, Any] | None
) -> tuple[NDArray[Any] | None, dict[str, NDArray[Any]]]:
    cls = None
    if classification is not None:
        cls = np.asarray(classification)
        if cls.shape != (n,):
            raise InputError(f"classification has shape {cls.shape}, expected ({n},)", path=path)
        top = 31 if point_format < 6 else 255
        if cls.size and (cls.min() < 0 or cls.max() > top):
            raise InputError(
                f"classification values must be 0-{top} in point format {point_format}"
            )
    arrays = {}
    for name, values in (extra or {}).items():
        arr = np.asarray(values)
        if arr.shape != (n,):
            raise InputError(f"extra dimension {name!r} has shape {arr.shape}, expected ({n},)")
        if arr.dtype.str[1:] not in EXTRA_DTYPES:
            raise InputError(
                f"extra dimension {name!r}: dtype {arr.dtype} is not one of "
                f"{', '.join(EXTRA_DTYPES)}"
            )
        arrays[name] = arr
    return cls, arrays


def write_cloud(
    src_path: PathLike,
    dst_path: PathLike,
    *,
    classification: NDArray[Any] | None = None,
    extra: Mapping[str, NDArray[Any]] | None = None,
    points: LasPoints | None = None,
    chunk_size: int = 1_000_000,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> None:
    """Write a copy of ``src_path`` with a new classification and added extra dimensions.

    Every original dimension, header field (version, point format, scales, offsets, system
    identifier, generating software, dates, global encoding) and VLR/EVLR is kept; bounds and
    counts are recomputed. LAZ or LAS is chosen by the suffix of ``dst_path`` (LAZ encoded by
    lazrs on every core). The copy is written chunk by chunk into a temporary file in the
    destination folder and moved into place only when complete
    (:func:`core.io.atomic.atomic_path`): a failure or a cancel leaves no partial output.
    Without ``extra`` the point format is unchanged and each chunk is written as read.

    Parameters
    ----------
    src_path, dst_path : str or os.PathLike
        Source LAS/LAZ and destination (``.las`` or ``.laz``; may equal the source).
    classification : (N,) integer array, optional
        Replaces the classification of every point (0-31 for point formats 0-5).
    extra : dict[str, (N,) array], optional
        Extra dimensions to add (their dtype is kept: uint8 ... float64). A name the source
        already has as an extra dimension of the same dtype is overwritten.
    points : LasPoints, optional
        The source's records already read by :func:`read_cloud`: the copy is made from them
        and the file is not decoded again. Without extra dimensions the new classification
        is written into ``points``' own records (no copy of the points is made).
    chunk_size, progress, should_stop
        As in :func:`read_points`.

    Raises
    ------
    InputError
        Bad source, bad arrays, unknown suffix, name clash with a standard dimension.
    Cancelled
        When ``should_stop()`` returns True (nothing is left behind).
    """
    src = os.fspath(src_path)
    dst = os.fspath(dst_path)
    suffix = Path(dst).suffix.lower()
    if suffix not in (".las", ".laz"):
        raise InputError("the output must end with .las or .laz", path=dst)
    folder = os.path.dirname(os.path.abspath(dst))
    if not os.path.isdir(folder):
        raise InputError("the output folder does not exist", path=dst)
    step = max(int(chunk_size), 1)
    if points is not None:
        n = len(points)
        chunks = iter(points.chunks)
        _write_records(
            src,
            dst,
            points.header,
            points.evlrs,
            n,
            chunks,
            classification,
            extra,
            progress,
            should_stop,
        )
        return
    with _open(src) as reader:
        _check_record_count(src, reader.header)
        n = int(reader.header.point_count)
        if n == 0:
            raise InputError("the file holds no points", path=src)
        chunks = (chunk.array for chunk in reader.chunk_iterator(step))
        _write_records(
            src,
            dst,
            reader.header,
            list(reader.header.evlrs or []),
            n,
            chunks,
            classification,
            extra,
            progress,
            should_stop,
        )


def _write_records(
    src: str,
    dst: str,
    src_header: Any,
    evlrs: list[Any],
    n: int,
    chunks: Any,
    classification: Any,
    extra: Mapping[str, NDArray[Any]] | None,
    progress: Callable[[float], None] | None,
    should_stop: Callable[[], bool] | None,
) -> None:
    """write_cloud's writer: raw record chunks of the source -> the temporary, then in place."""
    import laspy

    from .las_stats import HeaderStats

    cls, arrays = _check_values(src, n, int(src_header.point_format.id), classification, extra)
    header = deepcopy(src_header)
    extra_names = set(header.point_format.extra_dimension_names)
    new_params = []
    for name, arr in arrays.items():
        if name in extra_names:
            have = header.point_format.dimension_by_name(name).dtype
            if np.dtype(have) != arr.dtype:
                raise InputError(
                    f"extra dimension {name!r} exists with dtype {have}, not {arr.dtype}",
                    path=src,
                    column=name,
                )
        elif name in header.point_format.dimension_names:
            raise InputError(
                f"{name!r} is a standard dimension, not an extra one", path=src, column=name
            )
        else:
            new_params.append(laspy.ExtraBytesParams(name=name, type=arr.dtype))
    if new_params:
        header.add_extra_dims(new_params)
    same_format = not new_params
    with atomic_path(dst) as tmp:
        with laspy.open(
            tmp,
            mode="w",
            header=header,
            do_compress=dst.lower().endswith(".laz"),
            laz_backend=_laz_backend(),
        ) as writer:
            fmt = writer.header.point_format
            # laspy's header growth per chunk in one compiled pass (same header; None: laspy's)
            stats = HeaderStats.for_writer(writer) if same_format else None

            def take(raw: NDArray[Any], done: int) -> None:
                m = len(raw)
                if done + m > n:
                    raise InputError(f"more points than the header's {n}", path=src)
                if same_format:  # the chunk itself: no copy
                    out = laspy.PackedPointRecord(raw, fmt)
                else:
                    out = laspy.PackedPointRecord.zeros(m, fmt)
                    for name in raw.dtype.names or ():
                        out.array[name] = raw[name]
                if cls is not None:
                    out.classification = cls[done : done + m]
                for name, arr in arrays.items():
                    out[name] = arr[done : done + m]
                if stats is not None:
                    stats.add(out)
                    writer.point_writer.write_points(out)
                else:
                    writer.write_points(out)

            _read_chunks(iter(chunks), n, src, take, progress, should_stop)
            if stats is not None:
                stats.apply(writer.header)
            if evlrs:  # (laspy has no top-level VLRList)
                from laspy.vlrs.vlrlist import VLRList

                writer.write_evlrs(VLRList(evlrs))
    LOG.info("wrote %d points to %s", n, dst)
