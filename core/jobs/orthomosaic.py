"""``orthomosaic``: orthophotos into one mosaic, each cell from the image that sees it best."""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

from ..io.suffixes import IMAGE_SUFFIXES
from .common import compression_param, csv_out, enum_param
from .runner import JobResult, stages
from .spec import AlgorithmSpec, Fields, Param, Result, Values, options_from

log = logging.getLogger(__name__)

_D = Fields("photo.ortho_options", "MosaicOptions")
#: Largest seamline raster kept in memory (cells); bigger mosaics are traced at a coarser step.
MAX_LABEL_CELLS = 64_000_000

#: Columns of the seamline table (docs/formats.md, "Seamline CSV").
SEAMLINE_COLUMNS = ("image_id", "cells", "area", "wkt")

SPEC = AlgorithmSpec(
    name="orthomosaic",
    title="Orthomosaic (seamlines, feathering, occlusion-aware)",
    group="Orthophotos",
    group_id="orthophotos",
    summary="orthophotos into one mosaic, each cell from the image that sees it best",
    description="""\
Every cell of the mosaic takes the orthophoto that sees it most nadir (the smallest angle
between the vertical and the ray to the camera's perspective centre, kept in the metadata of
the orthophotos Orthorectify writes) or, with method centre, the one whose image centre is
nearest. Only orthophotos with data at the cell compete: with true orthophotos, ground
occluded in one image is filled from another that sees it.

Feathering blends the images across the seamlines over the given width (cells), linearly,
centred on the seamline; 0 leaves hard seams.

## Inputs
Orthophotos: GeoTIFFs of one CRS and cell size, aligned on multiples of it (Orthorectify
with one GSD makes them so, from perspective or fisheye images alike), or folders of them.

## Outputs
The mosaic (GeoTIFF: tiled, compressed, overviews, internal mask), and the seamline polygons:
the region each image fills, as a layer and as a CSV (image_id, cells, area, WKT
MultiPolygon in the mosaic's CRS).""",
    params=(
        Param("ORTHOPHOTOS", "files", "Orthophotos (files or folders)", suffixes=IMAGE_SUFFIXES),
        enum_param(
            "METHOD",
            "Image chosen per cell",
            _D.method,
            "MOSAIC_METHODS",
            labels=("most nadir view", "nearest image centre"),
        ),
        Param(
            "FEATHER",
            "number",
            "Feathering width across seamlines (0 = none)",
            _D.feather_px,
            unit="cells",
            minimum=0.0,
            maximum=1000.0,
        ),
        compression_param(),
        Param("OUTPUT", "raster_out", "Orthomosaic"),
        Param(
            "OUTPUT_SEAMLINES",
            "sink",
            "Seamlines (region of each image)",
            geometry="polygon",
            optional=True,
        ),
        csv_out("SEAMLINES_CSV", "Seamline table (CSV)", on_demand=True),
    ),
    results=(
        Result("SOURCE_COUNT", "number", "Orthophotos mosaicked"),
        Result("COVERED_FRACTION", "number", "Share of the mosaic's cells with data"),
    ),
    tags=("orthomosaic", "mosaic", "seamline", "feathering", "true orthophoto"),
    references=("Amhar, Jansa & Ries (1998)",),
)


@dataclass(frozen=True)
class Seamline:
    """The region of the mosaic one orthophoto fills."""

    image_id: str
    cells: int
    area: float
    wkt: str


@dataclass(frozen=True)
class MosaicResult:
    """What the job made: the seamline regions and the mosaic's CRS (WKT)."""

    seamlines: list[Seamline]
    crs_wkt: str
    path: str


def _floats(text: str | None, n: int) -> tuple[float, ...] | None:
    if not text:
        return None
    try:
        vals = tuple(float(t) for t in text.split(","))
    except ValueError:
        return None
    return vals if len(vals) == n and all(map(math.isfinite, vals)) else None


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the orthophotos' grids and metadata, mosaic tile by tile, trace the seamlines."""
    import numpy as np

    from ..io.images import list_image_files
    from ..io.raster import RasterReader, polygonize
    from ..io.tables import write_csv_atomic
    from ..photo.mosaic import MosaicOptions, mosaic_grid, mosaic_method

    files = list_image_files(v.orthophotos, ("ORTHOPHOTOS", "one image would count twice"))
    readers = [RasterReader(f) for f in files]
    try:
        crs, sources = _sources(files, readers)
        method = mosaic_method(v.method, sources)
        if method != v.method:
            log.warning(
                "some orthophotos have no perspective centre in their metadata (not "
                "made by orthorectify): every cell takes the nearest image centre"
            )
        grid = mosaic_grid(sources)
        options = options_from(MosaicOptions, SPEC, v, method=method)
        # seamlines are traced on a raster of the chosen image (coarser for huge mosaics)
        step = max(1, math.ceil(math.sqrt(grid.rows * grid.cols / MAX_LABEL_CELLS)))
        mosaic, seams = stages(progress, 0.9, 0.1)
        covered, labels = _write_mosaic(
            v, out, readers, sources, grid, crs, options, step, mosaic, should_stop
        )
    finally:
        for r in readers:
            r.close()
    gt_lab = (grid.x0, grid.cell * step, 0.0, grid.y_top, 0.0, -grid.cell * step)
    regions = polygonize(labels, gt_lab)
    counts = np.bincount(labels[labels >= 0].ravel(), minlength=len(sources)) * step * step
    seamlines = [
        Seamline(sources[k].name, int(counts[k]), float(counts[k]) * grid.cell**2, wkt)
        for k, wkt in regions.items()
    ]
    if seams is not None:
        seams(1.0)
    if out.requested("SEAMLINES_CSV"):
        rows = [(s.image_id, s.cells, repr(s.area), s.wkt) for s in seamlines]
        write_csv_atomic(out.path("SEAMLINES_CSV"), SEAMLINE_COLUMNS, rows)
    frac = covered / max(grid.rows * grid.cols, 1)
    return JobResult(
        results={"SOURCE_COUNT": len(sources), "COVERED_FRACTION": frac},
        lines=[
            f"mosaic of {len(sources)} orthophoto(s): {grid.cols} x {grid.rows} cells of "
            f"{grid.cell:g}, {100 * frac:.1f} % with data; {len(seamlines)} seamline "
            f"region(s)" + (f" (traced every {step} cells)" if step > 1 else "")
        ],
        data=MosaicResult(seamlines, crs.to_wkt() if crs else "", str(out.target("OUTPUT"))),
    )


def _sources(files: list, readers: list) -> tuple:
    """(the CRS, one :class:`MosaicSource` per orthophoto from its grid and metadata), each
    checked: north-up with square cells, the bands, type and CRS of the first."""
    import pyproj

    from ..errors import InputError
    from ..geometry.grid import Grid
    from ..photo.mosaic import MosaicSource

    first = readers[0].info
    crs = pyproj.CRS.from_wkt(first.crs_wkt) if first.crs_wkt else None
    sources = []
    for f, r in zip(files, readers):
        info = r.info
        gt = info.geotransform
        if gt is None or gt[2] or gt[4] or not math.isclose(gt[1], -gt[5], rel_tol=1e-9):
            raise InputError("not a north-up raster with square cells", path=str(f))
        if (info.bands, info.dtype) != (first.bands, first.dtype):
            raise InputError(
                f"{info.bands} band(s) of {info.dtype}, the first orthophoto "
                f"{first.bands} of {first.dtype}",
                path=str(f),
            )
        other = pyproj.CRS.from_wkt(info.crs_wkt) if info.crs_wkt else None
        if (other is None) != (crs is None) or (
            other is not None and not other.equals(crs, ignore_axis_order=True)
        ):
            raise InputError(
                f"CRS '{other.name if other else 'none'}' differs from the "
                f"first orthophoto's '{crs.name if crs else 'none'}'",
                path=str(f),
            )
        meta = info.metadata
        centre = _floats(meta.get("LIDARPHOTO_CENTRE"), 3)
        ground = _floats(meta.get("LIDARPHOTO_GROUND_Z"), 1)
        pg = _floats(meta.get("LIDARPHOTO_PRINCIPAL_GROUND"), 2)
        name = meta.get("LIDARPHOTO_IMAGE_ID") or f.stem
        sources.append(
            MosaicSource(
                name,
                Grid(gt[0], gt[3], gt[1], info.height, info.width),
                centre,
                ground[0] if ground else None,
                pg,
            )
        )
    return crs, sources


def _write_mosaic(
    v: Values, out, readers, sources, grid, crs, options, step: int, progress, should_stop
) -> tuple:
    """Write OUTPUT tile by tile: (the cells with data, the raster of the chosen image's index
    every ``step`` cells, -1 where none)."""
    import numpy as np

    from ..io.raster_write import GeoTiffWriter
    from ..photo.mosaic import mosaic_tiles
    from .common import compression_args
    from .orthorectify import failures_named

    first = readers[0].info

    def read(k: int, win: tuple[int, int, int, int]):
        return readers[k].read(win), readers[k].read_mask(win)

    labels = np.full((-(-grid.rows // step), -(-grid.cols // step)), -1, np.int16)
    photometric = "RGB" if first.bands == 3 and first.dtype == np.uint8 else None
    covered = 0
    meta_out = {"LIDARPHOTO_SOURCES": ",".join(s.name for s in sources)}
    with (
        failures_named(out.target("OUTPUT")),
        GeoTiffWriter(
            out.path("OUTPUT"),
            grid.cols,
            grid.rows,
            first.bands,
            first.dtype,
            grid.geotransform,
            crs,
            mask=True,
            tile=512,
            photometric=photometric,
            metadata=meta_out,
            **compression_args(v.compression),
        ) as writer,
    ):
        for tile in mosaic_tiles(
            sources,
            grid,
            read,
            first.bands,
            first.dtype,
            options,
            progress=progress,
            should_stop=should_stop,
        ):
            writer.write(tile.data, tile.col0, tile.row0, tile.valid)
            covered += int(np.count_nonzero(tile.valid))
            r_first = (-tile.row0) % step
            c_first = (-tile.col0) % step
            sub = tile.label[r_first::step, c_first::step]
            lr, lc = (tile.row0 + r_first) // step, (tile.col0 + c_first) // step
            labels[lr : lr + sub.shape[0], lc : lc + sub.shape[1]] = sub
    return covered, labels
