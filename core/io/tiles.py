"""A LiDAR block as tiles: a folder of LAS/LAZ files, a virtual point cloud (.vpc), or one
large file cut into a grid of tiles read in chunks; buffered reads; the output VPC.

The tile index is made from headers only (or the VPC's own bounding boxes): finding a tile's
neighbours never reads points. :func:`read_buffered` then reads one tile's own points (its
*core*) and the points of its neighbours within ``buffer`` of its box, streaming each file in
chunks. A COPC file (Cloud Optimized Point Cloud: a LAZ 1.4 file whose first VLR is the
``copc`` info record and whose LAZ chunks are the nodes of an octree) is read by bounds
instead: only the octree nodes whose cube meets the tile's box plus buffer are decompressed
(:func:`copc_nodes`), and the points are then kept by the same rules as when streaming (the
half-open cell for the core, the closed buffered box), so the tile gets the same points with
the same ids either way.

Point ids: every point of the block has the id ``file offset + index in its file``, where a
file's offset is the sum of the point counts of the files before it in the index (folder and
VPC: sorted by name / in the VPC's order; one large file: offset 0). The id is stable across
runs and workers, so a re-run task gives the same points with the same ids. A COPC node's
points have ids from the node's place in the file (its chunk's byte offset): the ids of a
streamed read.

A VPC (PDAL's and QGIS's virtual point cloud) is a STAC ItemCollection (GeoJSON
FeatureCollection): each feature's ``assets`` hold the file (``href``, relative to the .vpc),
``properties`` its ``pc:count``, ``proj:bbox`` (x, y, z min then max, in the CRS) and CRS
(``proj:wkt2``, ``proj:projjson`` or ``proj:epsg``).
"""

from __future__ import annotations

import functools
import json
import math
import os
import shutil
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import Cancelled, CrsError, InputError, stop_if_asked
from ..geometry.frames import parse_crs
from .atomic import PathLike, _forget, remove_dead_temporaries, temp_folder, write_text_atomic
from .pointcloud import CloudInfo, LasPoints, read_info

#: Suffixes of the point-cloud files of a folder block.
CLOUD_SUFFIXES = (".las", ".laz")
#: Fields :func:`read_buffered` returns for every point (besides ``id`` and ``core``).
BUFFER_FIELDS = ("x", "y", "z", "return_number", "number_of_returns", "classification")
_CHUNK = 1_000_000


@dataclass(frozen=True)
class Tile:
    """One tile of a block.

    Attributes
    ----------
    name : str
        File stem (folder, VPC) or ``<stem>_<col>_<row>`` (a grid tile of one large file).
    path : str
        The LAS/LAZ file holding its points.
    box : tuple of 4 float
        (xmin, ymin, xmax, ymax), CRS unit: the file's header bounds, or the grid cell.
    count : int
        Points of the file (a grid tile: of the whole file; its own count is known once read).
    offset : int
        Id of the file's first point (module docstring).
    cell : tuple of 4 float or None
        A grid tile's half-open core [xmin, xmax) x [ymin, ymax) (the grid, on multiples of
        the tile size, has a cell past the file's maximum); None when the tile is its whole
        file.
    copc : bool
        The file is COPC: its neighbours' buffers (and a grid tile's core) are read by octree
        node, not streamed.
    """

    name: str
    path: str
    box: tuple[float, float, float, float]
    count: int
    offset: int
    cell: tuple[float, float, float, float] | None = None
    copc: bool = False


@dataclass
class BlockIndex:
    """The tiles of a block, its CRS (all tiles share it) and the tiles that could not be
    indexed (name, reason: a corrupt header, a file the VPC names that is missing)."""

    source: str
    kind: str  # "folder", "vpc" or "file"
    tiles: list[Tile]
    info: CloudInfo | None
    bad: list[tuple[str, str]] = field(default_factory=list)

    @property
    def point_count(self) -> int:
        """Points of the indexed files (each file once)."""
        return sum({t.path: t.count for t in self.tiles}.values())


def _boxes_touch(a: Sequence[float], b: Sequence[float], margin: float) -> bool:
    return not (
        a[0] - margin > b[2] or b[0] > a[2] + margin or a[1] - margin > b[3] or b[1] > a[3] + margin
    )


def neighbours(index: BlockIndex, i: int, buffer: float) -> list[int]:
    """Tiles (other than ``i``) whose box comes within ``buffer`` of tile ``i``'s box.

    >>> t = [Tile(f"t{k}", "", (100.0 * k, 0.0, 100.0 * k + 99.0, 99.0), 1, k) for k in range(4)]
    >>> neighbours(BlockIndex("", "folder", t, None), 1, 10.0)
    [0, 2]
    """
    own = index.tiles[i].cell or index.tiles[i].box
    return [
        k
        for k, t in enumerate(index.tiles)
        if k != i and _boxes_touch(own, t.cell or t.box, buffer)
    ]


def _same_crs(a: CloudInfo, b: CloudInfo) -> bool:
    if a.crs is None or b.crs is None:
        return a.crs is b.crs
    return bool(a.crs == b.crs or a.crs.equals(b.crs, ignore_axis_order=True))


def _check_crs(infos: list[tuple[str, CloudInfo]]) -> None:
    first_name, first = infos[0]
    for name, info in infos[1:]:
        if not _same_crs(first, info):
            raise CrsError(
                f"tiles in different CRSs: {first_name} is "
                f"{first.crs.name if first.crs else 'without CRS'}, {name} is "
                f"{info.crs.name if info.crs else 'without CRS'}; reproject them to one CRS first"
            )


def index_block(source: PathLike, crs: Any = None, tile_size: float = 0.0) -> BlockIndex:
    """Index a block: a folder of LAS/LAZ tiles, a ``.vpc``, or one LAS/LAZ file.

    Parameters
    ----------
    source : path
        Folder (its ``*.las``/``*.laz``, not recursive, sorted by name), ``.vpc`` or one file.
    crs : optional
        Overrides the files' CRS (all tiles get it).
    tile_size : float
        One file only: side of the grid tiles (CRS unit) it is cut into; 0 = one tile.

    Raises
    ------
    InputError
        No tile at all, a VPC that is not a STAC ItemCollection.
    CrsError
        Tiles in different CRSs (names two of them), no CRS.
    """
    path = Path(source)
    if path.is_dir():
        files = sorted(
            p
            for p in path.iterdir()
            if p.suffix.lower() in CLOUD_SUFFIXES and not p.name.startswith(".")
        )
        if not files:
            raise InputError("no .las or .laz file in the folder", path=str(path))
        return _index_files(str(path), "folder", [(p.stem, str(p), None) for p in files], crs)
    if path.suffix.lower() == ".vpc":
        return _index_vpc(path, crs)
    if path.suffix.lower() in CLOUD_SUFFIXES:
        return _index_one_file(path, crs, tile_size)
    if not path.exists():
        raise InputError("not found", path=str(path))
    raise InputError("give a folder of LAS/LAZ tiles, a .vpc or a .las/.laz file", path=str(path))


def _index_files(
    source: str, kind: str, entries: list[tuple[str, str, Any]], crs: Any
) -> BlockIndex:
    """Tiles from (name, path, VPC bbox or None) entries: headers read, CRSs compared."""
    tiles: list[Tile] = []
    bad: list[tuple[str, str]] = []
    infos: list[tuple[str, CloudInfo]] = []
    offset = 0
    for name, file, _ in entries:
        try:
            copc = is_copc(file)
            if copc:  # a truncated COPC lost its hierarchy (and its CRS, an EVLR): say so
                with open(file, "rb") as fh:
                    _copc_layout(fh, file)
            info = read_info(file, crs)
        except CrsError:
            raise
        except InputError as exc:  # reported by name, the rest goes on
            bad.append((name, str(exc)))
            continue
        infos.append((name, info))
        box = (float(info.mins[0]), float(info.mins[1]), float(info.maxs[0]), float(info.maxs[1]))
        tiles.append(Tile(name, file, box, info.point_count, offset, None, copc))
        offset += info.point_count
    if not tiles:
        raise InputError(f"no readable tile ({len(bad)} unreadable: {bad[0][1]})", path=source)
    _check_crs(infos)
    return BlockIndex(source, kind, tiles, infos[0][1], bad)


def _vpc_crs(props: dict[str, Any]) -> Any:
    for key in ("proj:wkt2", "proj:projjson", "proj:epsg"):
        if props.get(key) not in (None, ""):
            value = props[key]
            return json.dumps(value) if isinstance(value, dict) else value
    return None


def _index_vpc(path: Path, crs: Any) -> BlockIndex:
    """A VPC's tiles: files and boxes from the VPC; each existing file's header is read for
    its CRS and units (the header, never the points)."""
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot read the VPC: {exc}", path=str(path)) from exc
    features = doc.get("features") if isinstance(doc, dict) else None
    if doc.get("type") != "FeatureCollection" or not isinstance(features, list):
        raise InputError("not a virtual point cloud (a STAC FeatureCollection)", path=str(path))
    entries, bad = [], []
    crs_seen: dict[str, str] = {}
    for k, feat in enumerate(features):
        assets = feat.get("assets") or {}
        asset = assets.get("data") or next(iter(assets.values()), None)
        name = str(feat.get("id") or f"item{k}")
        if not asset or "href" not in asset:
            bad.append((name, "no asset href"))
            continue
        href = str(asset["href"])
        file = href if os.path.isabs(href) else str((path.parent / href).resolve())
        props = feat.get("properties") or {}
        crs_seen.setdefault(str(_vpc_crs(props)), name)
        if not os.path.isfile(file):
            bad.append((name, f"{href}: file not found"))
            continue
        entries.append((name, file, props.get("proj:bbox")))
    if crs is None and len(crs_seen) > 1:
        a, b = list(crs_seen.values())[:2]
        raise CrsError(f"tiles in different CRSs in the VPC: {a} and {b}", path=str(path))
    if not entries:
        raise InputError("the VPC names no existing file", path=str(path))
    index = _index_files(str(path), "vpc", entries, crs)
    index.bad = bad + index.bad
    return index


def _index_one_file(path: Path, crs: Any, tile_size: float) -> BlockIndex:
    info = read_info(path, crs)
    copc = is_copc(path)
    if copc:  # a truncated COPC fails here, by name, not in every tile task
        with open(path, "rb") as fh:
            _copc_layout(fh, str(path))
    xmin, ymin, xmax, ymax = (
        float(info.mins[0]),
        float(info.mins[1]),
        float(info.maxs[0]),
        float(info.maxs[1]),
    )
    size = tile_size if tile_size > 0 else max(xmax - xmin, ymax - ymin, 1.0) * 1.000001
    # cells on multiples of the tile size: the same grid whatever the file's extent
    x0, y0 = math.floor(xmin / size) * size, math.floor(ymin / size) * size
    cols = max(math.floor((xmax - x0) / size) + 1, 1)
    rows = max(math.floor((ymax - y0) / size) + 1, 1)
    tiles = []
    for r in range(rows):
        for c in range(cols):
            cell = (x0 + c * size, y0 + r * size, x0 + (c + 1) * size, y0 + (r + 1) * size)
            box = (max(cell[0], xmin), max(cell[1], ymin), min(cell[2], xmax), min(cell[3], ymax))
            tiles.append(
                Tile(f"{path.stem}_{c}_{r}", str(path), box, info.point_count, 0, cell, copc)
            )
    return BlockIndex(str(path), "file", tiles, info)


# ----------------------------------------------------------------------------- COPC
#: A COPC hierarchy entry (COPC 1.0 specification): voxel key (level, x, y, z), then the byte
#: offset and size of the node's LAZ chunk (or of a child hierarchy page when the point count
#: is -1) and its point count.
_ENTRY = np.dtype(
    [
        ("level", "<i4"),
        ("x", "<i4"),
        ("y", "<i4"),
        ("z", "<i4"),
        ("offset", "<u8"),
        ("size", "<i4"),
        ("count", "<i4"),
    ]
)


def is_copc(path: PathLike) -> bool:
    """True when the LAS/LAZ file is COPC: its first VLR is the ``copc`` info record (user id
    "copc", record id 1), as the COPC specification requires. Reads the header only."""
    import laspy

    try:
        with laspy.open(os.fspath(path)) as reader:
            vlrs = reader.header.vlrs
            return bool(len(vlrs)) and vlrs[0].user_id == "copc" and vlrs[0].record_id == 1
    except Exception:  # not readable as LAS/LAZ: read_info reports it
        return False


@dataclass(frozen=True)
class CopcLayout:
    """A COPC file's octree as read from its header and hierarchy pages.

    ``nodes`` (structured array, :data:`_ENTRY` fields plus ``start``, the file index of the
    node's first point: the node's chunks sorted by byte offset are the file's point order),
    the root cube (``center`` and ``halfsize``, CRS unit), the LAZ VLR and header."""

    nodes: NDArray[Any]
    center: NDArray[np.float64]
    halfsize: float
    laz_vlr: bytes
    header: Any


def _copc_layout(fh: Any, path: str) -> CopcLayout:
    """Read a COPC file's header and its whole hierarchy (every page: a few bytes per node)."""
    import laspy

    size = os.fstat(fh.fileno()).st_size
    try:
        fh.seek(0)
        header = laspy.LasHeader.read_from(fh)
        info = header.vlrs[0]
        laz = header.vlrs.get("LasZipVlr")[0]
        pages = [(int(info.hierarchy_root_offset), int(info.hierarchy_root_size))]
        center = np.asarray(info.center, dtype=np.float64).copy()
        halfsize = float(info.halfsize)
    except Exception as exc:
        raise InputError(f"corrupt COPC header: {exc}", path=path) from exc
    nodes = []
    seen: set[int] = set()
    while pages:
        at, nbytes = pages.pop()
        if at in seen:  # a page listed twice would loop or count its nodes twice
            raise InputError(f"corrupt COPC: hierarchy page at byte {at} listed twice", path=path)
        seen.add(at)
        if at + nbytes > size or nbytes % _ENTRY.itemsize:
            raise InputError(
                f"corrupt or truncated COPC: a hierarchy page (bytes {at} to "
                f"{at + nbytes}) lies past the end of the file ({size} bytes)",
                path=path,
            )
        fh.seek(at)
        page = np.frombuffer(fh.read(nbytes), dtype=_ENTRY)
        pages += [(int(e["offset"]), int(e["size"])) for e in page[page["count"] == -1]]
        nodes.append(page[page["count"] > 0])
    entries = np.concatenate(nodes) if nodes else np.zeros(0, _ENTRY)
    entries = np.sort(entries, order="offset")
    end = entries["offset"].astype(np.int64) + entries["size"]
    if len(entries) and int(end.max()) > size:
        raise InputError(
            f"corrupt or truncated COPC: its last node ends at byte {int(end.max())}"
            f", the file has {size}",
            path=path,
        )
    if int(entries["count"].sum()) != int(header.point_count):
        raise InputError(
            f"corrupt COPC: its nodes hold {int(entries['count'].sum())} points, "
            f"the header says {int(header.point_count)}",
            path=path,
        )
    out = np.zeros(len(entries), _ENTRY.descr + [("start", "<i8")])
    for name in _ENTRY.names or ():
        out[name] = entries[name]
    out["start"] = np.concatenate([[0], np.cumsum(entries["count"], dtype=np.int64)[:-1]])
    return CopcLayout(out, center, halfsize, bytes(laz.record_data), header)


def copc_nodes(layout: CopcLayout, box: Sequence[float]) -> NDArray[Any]:
    """The nodes whose cube meets ``box`` (xmin, ymin, xmax, ymax; closed) in x and y.

    A COPC writer puts every point inside its node's cube; the cube is widened by two
    coordinate steps so a point rounded onto a cube face is never missed.
    """
    n = layout.nodes
    side = 2.0 * layout.halfsize / np.exp2(n["level"])
    pad = 2.0 * float(np.max(layout.header.scales[:2]))
    lo_x = layout.center[0] - layout.halfsize + n["x"] * side
    lo_y = layout.center[1] - layout.halfsize + n["y"] * side
    hit = (
        (lo_x - pad <= box[2])
        & (lo_x + side + pad >= box[0])
        & (lo_y - pad <= box[3])
        & (lo_y + side + pad >= box[1])
    )
    return n[hit]


@functools.lru_cache(maxsize=8)
def _cached_layout(path: str, size: int, mtime_ns: int) -> CopcLayout:
    """The layout of a COPC file, parsed once per worker process for all the tiles and
    buffers it serves (size and modification time in the key: a changed file is re-read)."""
    with open(path, "rb") as fh:
        return _copc_layout(fh, path)


def _copc_read(path: str, box: Sequence[float]):
    """(header, points of the nodes meeting ``box`` in file order, their ids, points decoded)
    of a COPC file: only those nodes' chunks are read and decompressed (lazrs)."""
    import laspy
    import lazrs

    st = os.stat(path)
    layout = _cached_layout(path, st.st_size, st.st_mtime_ns)
    with open(path, "rb") as fh:
        nodes = copc_nodes(layout, box)
        header = layout.header
        fmt = header.point_format
        total = int(nodes["count"].sum())
        raw = np.zeros(total * fmt.size, np.uint8)
        if total:
            # contiguous nodes in one read (they are sorted by offset)
            data = bytearray(int(nodes["size"].sum()))
            view = memoryview(data)
            pos = 0
            at = nodes["offset"].astype(np.int64)
            new_run = np.concatenate([[True], at[1:] != at[:-1] + nodes["size"][:-1]])
            for k in np.flatnonzero(new_run):
                stop = np.flatnonzero(new_run[k + 1 :])
                last = k + 1 + int(stop[0]) if len(stop) else len(nodes)
                nbytes = int(nodes["size"][k:last].sum())
                fh.seek(int(at[k]))
                if fh.readinto(view[pos : pos + nbytes]) != nbytes:
                    raise InputError(
                        "truncated COPC: a node's chunk ends past the end of the file", path=path
                    )
                pos += nbytes
            table = [(int(c), int(b)) for c, b in zip(nodes["count"], nodes["size"])]
            try:
                lazrs.decompress_points_with_chunk_table(
                    data, layout.laz_vlr, raw, table, laspy.DecompressionSelection.all().to_lazrs()
                )
            except Exception as exc:  # lazrs: corrupt chunk bytes
                raise InputError(f"corrupt COPC point data: {exc}", path=path) from exc
    points = laspy.ScaleAwarePointRecord(raw.view(fmt.dtype()), fmt, header.scales, header.offsets)
    ids = np.repeat(
        nodes["start"] - np.cumsum(nodes["count"]) + nodes["count"], nodes["count"]
    ) + np.arange(total, dtype=np.int64)
    return header, points, ids, total


def _output_header(header: Any) -> tuple[Any, list[Any]]:
    """A copy of a source header for a plain LAS/LAZ output, and the EVLRs to write: the
    COPC records (info, extents, hierarchy) are dropped (the output is no octree), the other
    EVLRs (a LAS 1.4 file's WKT CRS may be one) kept."""
    from copy import deepcopy

    out = deepcopy(header)
    keep = [v for v in out.vlrs if v.user_id != "copc"]
    out.vlrs.clear()
    out.vlrs.extend(keep)
    evlrs = [v for v in (getattr(header, "evlrs", None) or []) if v.user_id != "copc"]
    out.evlrs = None
    return out, deepcopy(evlrs)


def _in_cell(x: NDArray[np.float64], y: NDArray[np.float64], cell) -> NDArray[np.bool_]:
    """Half-open cell membership: every point of a grid lies in exactly one cell."""
    return (x >= cell[0]) & (x < cell[2]) & (y >= cell[1]) & (y < cell[3])


@dataclass
class BufferedTile:
    """One tile's core points and its buffer.

    ``arrays`` holds :data:`BUFFER_FIELDS` plus ``id`` (int64, module docstring) and ``core``
    (bool) for every point read, core points first; ``records`` the core's packed records (to
    write the output tile); ``missing`` the neighbours whose buffer could not be read;
    ``decoded`` the points decompressed to make it (a streamed file: all its points; a COPC
    file: those of the octree nodes meeting the buffered box)."""

    tile: Tile
    arrays: dict[str, NDArray[Any]]
    records: LasPoints
    missing: list[str]
    decoded: int = 0

    @property
    def n_core(self) -> int:
        return int(self.arrays["core"].sum())


def _stream(path: str, crs: Any, should_stop: Callable[[], bool] | None):
    """(header, info, chunk record arrays with their ids) of a file, streamed."""
    from .pointcloud import _open

    with _open(path) as reader:
        info = read_info(path, crs)
        done = 0
        try:
            for chunk in reader.chunk_iterator(_CHUNK):
                stop_if_asked(should_stop, "reading the tiles")
                yield reader.header, info, chunk, done + np.arange(len(chunk), dtype=np.int64)
                done += len(chunk)
        except (InputError, Cancelled):
            raise
        except Exception as exc:  # lazrs/laspy decoding errors: corrupt or truncated file
            raise InputError(f"corrupt or truncated after {done} points: {exc}", path=path) from exc


def _query(path: str, crs: Any, box: Sequence[float], should_stop: Callable[[], bool] | None):
    """The same as :func:`_stream` for a COPC file: one part, the points of the octree nodes
    meeting ``box``, in file order (the caller keeps the points inside by its own rule)."""
    from .pointcloud import _open

    stop_if_asked(should_stop, "reading the tiles")
    with _open(path) as reader:  # the header with its EVLRs (a COPC's WKT is one)
        header = reader.header
    info = read_info(path, crs)
    _, points, ids, _ = _copc_read(path, box)
    yield header, info, points, ids


def read_buffered(
    index: BlockIndex,
    i: int,
    buffer: float,
    crs: Any = None,
    should_stop: Callable[[], bool] | None = None,
) -> BufferedTile:
    """Read tile ``i``'s core and the points of its neighbours within ``buffer`` of its box.

    Neighbours come from the index's boxes (no point is read to find them). A neighbour whose
    file cannot be read is listed in ``missing`` (its buffer is then incomplete); the tile's
    own file must be readable (InputError naming it otherwise). A COPC file is read by bounds
    (module docstring) unless all of it is needed (a whole-file tile's own file); the points
    kept, their ids and order are those of a streamed read.
    """
    tile = index.tiles[i]
    own = tile.cell or tile.box
    outer = (own[0] - buffer, own[1] - buffer, own[2] + buffer, own[3] + buffer)
    parts: list[dict[str, NDArray[Any]]] = []
    core_records: list[NDArray[Any]] = []
    header = None
    info = None
    files = [(tile.path, tile.offset, True, tile.copc and tile.cell is not None)]
    for k in neighbours(index, i, buffer):
        t = index.tiles[k]
        if t.path != tile.path and all(f[0] != t.path for f in files):
            files.append((t.path, t.offset, False, t.copc))
    missing: list[str] = []
    decoded = 0
    for path, offset, is_own, by_query in files:
        reads = (
            _query(path, crs, outer, should_stop) if by_query else _stream(path, crs, should_stop)
        )
        try:
            for head, inf, chunk, ids in reads:
                decoded += len(chunk)
                x = np.asarray(chunk.x, dtype=np.float64)
                y = np.asarray(chunk.y, dtype=np.float64)
                if is_own and tile.cell is None:
                    core = np.ones(len(x), dtype=bool)
                elif is_own:  # the grid covers the file's maximum: half-open cells
                    core = _in_cell(x, y, tile.cell)
                else:
                    core = np.zeros(len(x), dtype=bool)
                near = (x >= outer[0]) & (x <= outer[2]) & (y >= outer[1]) & (y <= outer[3])
                take = core | near
                if is_own:
                    header, info = head, inf
                    core_records.append(chunk.array[core])
                if not take.any():
                    continue
                # core points first within each chunk, then the buffer points
                order = np.concatenate([np.flatnonzero(core), np.flatnonzero(take & ~core)])
                part = {"core": core[order], "id": offset + ids[order]}
                for name in BUFFER_FIELDS:
                    part[name] = np.asarray(getattr(chunk, name))[order]
                parts.append(part)
        except InputError as exc:
            if is_own:
                raise
            missing.append(f"{Path(path).stem}: {exc}")
    if header is None or info is None:
        raise InputError("no point read", path=tile.path)
    if not parts:  # an empty cell of a large file's grid
        parts = [
            {
                "core": np.zeros(0, bool),
                "id": np.zeros(0, np.int64),
                **{k: np.zeros(0) for k in BUFFER_FIELDS},
            }
        ]
    arrays = {k: np.concatenate([p[k] for p in parts]) for k in ("core", "id", *BUFFER_FIELDS)}
    # core points first overall (their order: file order, as in the output tile)
    first = np.argsort(~arrays["core"], kind="stable")
    arrays = {k: v[first] for k, v in arrays.items()}
    out_header, evlrs = _output_header(header)
    records = LasPoints(info=info, header=out_header, chunks=core_records, evlrs=evlrs)
    return BufferedTile(tile, arrays, records, missing, decoded)


# ----------------------------------------------------------------------------- outputs
def staging_folder(target: PathLike) -> Path:
    """A new hidden folder next to ``target`` (a folder to be) where the tiles are written
    before :func:`commit_folder` moves it into place; its name carries this process's id
    (:func:`~core.io.atomic.temp_folder`), and the staging folders and temporaries a killed
    run left next to ``target`` are removed first (only those whose process is gone)."""
    dest = Path(target)
    dest.parent.mkdir(parents=True, exist_ok=True)
    remove_dead_temporaries(dest.parent)
    return temp_folder(dest)


def commit_folder(staging: PathLike, target: PathLike) -> None:
    """Replace folder ``target`` by ``staging`` (the old folder is kept aside until the new one
    is in place, then removed)."""
    dest = Path(target)
    old = None
    if dest.exists():
        if not dest.is_dir():
            raise InputError("is a file, not a folder", path=str(dest))
        old = staging_folder(dest)
        old.rmdir()
        os.replace(dest, old)
    try:
        os.replace(staging, dest)
    except OSError:
        if old is not None:
            os.replace(old, dest)
            _forget(str(old))
        raise
    _forget(str(staging))
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)
        _forget(str(old))


def write_vpc(path: PathLike, tiles: Sequence[dict[str, Any]], crs_wkt: str) -> None:
    """Write a virtual point cloud (STAC ItemCollection) of the output tiles.

    ``tiles``: dicts with ``name``, ``href`` (relative to the .vpc), ``count``, ``bbox``
    (xmin, ymin, zmin, xmax, ymax, zmax in the CRS). The WGS 84 ``bbox``/``geometry`` STAC
    requires are the CRS box transformed with pyproj.
    """
    import pyproj

    crs = parse_crs(crs_wkt) if crs_wkt else None
    to_ll = None
    if crs is not None:
        to_ll = pyproj.Transformer.from_crs(crs, "EPSG:4326", always_xy=True)
    features = []
    for t in tiles:
        b = [float(v) for v in t["bbox"]]
        ring = [(b[0], b[1]), (b[3], b[1]), (b[3], b[4]), (b[0], b[4]), (b[0], b[1])]
        if to_ll is not None:
            ll = [to_ll.transform(x, y) for x, y in ring]
        else:
            ll = ring
        lon, lat = [p[0] for p in ll], [p[1] for p in ll]
        features.append(
            {
                "type": "Feature",
                "stac_version": "1.0.0",
                "stac_extensions": [
                    "https://stac-extensions.github.io/pointcloud/v1.0.0/schema.json",
                    "https://stac-extensions.github.io/projection/v1.1.0/schema.json",
                ],
                "id": t["name"],
                "geometry": {"type": "Polygon", "coordinates": [[list(p) for p in ll]]},
                "bbox": [min(lon), min(lat), b[2], max(lon), max(lat), b[5]],
                "properties": {
                    "datetime": "0001-01-01T00:00:00Z",
                    "pc:count": int(t["count"]),
                    "pc:encoding": "?",
                    "pc:type": "lidar",
                    "proj:bbox": b,
                    "proj:wkt2": crs_wkt,
                },
                "links": [],
                "assets": {"data": {"href": t["href"], "roles": ["data"]}},
            }
        )
    text = json.dumps({"type": "FeatureCollection", "features": features}, indent=1)
    write_text_atomic(path, text + "\n")


def write_json(path: PathLike, doc: Any) -> None:
    """Write a JSON document (the block report) atomically."""
    write_text_atomic(path, json.dumps(doc, indent=1, sort_keys=False) + "\n")
