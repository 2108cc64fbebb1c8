"""``orthorectify``: orthophotos (and true orthophotos) of oriented frame images on a LiDAR
DSM or DTM."""

from __future__ import annotations

import contextlib
import logging
import math
import os
from collections.abc import Iterator
from concurrent.futures import Future, ThreadPoolExecutor, wait
from dataclasses import dataclass
from pathlib import Path

from .common import (
    DSM_FILTER,
    camera_param,
    compression_param,
    dsm_cell_param,
    enum_param,
    eo_param,
    images_param,
)
from .runner import JobResult, stages
from .spec import AlgorithmSpec, Fields, Param, Result, Values, options_from

log = logging.getLogger(__name__)

_D = Fields("photo.ortho_options", "OrthoOptions")
#: Name of the orthophoto of image ``<image_id>`` in the output folder.
ORTHO_NAME = "{}_ortho.tif"

SPEC = AlgorithmSpec(
    name="orthorectify",
    title="Orthorectify images on a LiDAR DSM (true orthophotos)",
    group="Orthophotos",
    group_id="orthophotos",
    summary="orthophotos of oriented frame images on a LiDAR DSM or DTM",
    description="""\
Each image is resampled onto a north-up grid of the mapping CRS through the surface: the
height of every output cell comes from the DSM (or DTM) and its image position from the
camera (lens model included) and the exterior orientation, by the rigorous chain of the
toolbox (local ENU frame reached through ECEF, so the map projection's scale and the Earth's
curvature are not neglected). The camera may be perspective or fisheye (equidistant,
equisolid-angle, orthographic, stereographic, with its Brown correction, as Calibrate camera
writes it): a fisheye maps the angle off its axis, and ground beyond its field is no data.

With True orthophoto, ground hidden from the camera (behind buildings, under trees and
overhangs) is found by tracing the ray from the camera to every cell through the DSM (as
monoplotting does) and left as no data; Orthomosaic then fills it from other images.

## Inputs
Images: image files, or folders of them (tif, tiff, jpg, png, jp2, img); each image is
matched to the row of the EO table whose image_id is its file name without extension. Every
image must have the camera's size. DSM: a raster (a layer or a file), or a LAS/LAZ cloud
rasterised at DSM cell size (highest return per cell, gaps filled). A DSM in another CRS is
resampled into the mapping CRS, heights transformed too; when PROJ cannot (a missing geoid
grid) the run stops with PROJ's reason.

## Output
One GeoTIFF per image, <image_id>_ortho.tif in the output folder: the image's bands and type,
tiled, compressed (DEFLATE by default), with overviews, the CRS and an internal mask (no data
outside the image, beyond the DSM and, for true orthophotos, where occluded). Its metadata keep the
perspective centre, which Orthomosaic uses. GSD 0 takes the images' nadir GSD (the median
over the images, 2 significant digits); the grids are aligned on multiples of the GSD. The
extent is each image's footprint on the DSM, or the extent given (xmin, ymin, xmax, ymax).
Nothing is written when an input is wrong; the files appear together when all are done.""",
    params=(
        camera_param(),
        eo_param(),
        images_param(),
        Param(
            "DSM",
            "surface",
            "DSM or DTM (raster, or LAS/LAZ)",
            file_filter=DSM_FILTER,
            help="a raster (the file of a raster layer) or a LAS/LAZ cloud",
        ),
        Param("CRS", "crs", "Mapping CRS of the EO", help="e.g. EPSG:28992"),
        Param("DSM_CRS", "crs", "DSM CRS (if the file has none)", optional=True),
        dsm_cell_param(),
        Param(
            "GSD",
            "number",
            "Output cell size (0 = image GSD)",
            _D.gsd,
            unit="CRS unit",
            minimum=0.0,
            maximum=1000.0,
        ),
        Param(
            "EXTENT",
            "numbers",
            "Extent xmin,ymin,xmax,ymax (empty = footprint)",
            count=4,
            optional=True,
            unit="CRS unit",
        ),
        enum_param("RESAMPLING", "Resampling", _D.resampling, "RESAMPLING"),
        Param(
            "TRUE_ORTHO", "boolean", "True orthophoto (occluded ground = no data)", _D.true_ortho
        ),
        Param(
            "OCCLUSION_TOLERANCE",
            "number",
            "Occlusion tolerance along the ray",
            _D.occlusion_tol_m,
            unit="CRS unit",
            minimum=0.0,
            maximum=100.0,
            advanced=True,
        ),
        compression_param(),
        Param("OUTPUT_FOLDER", "folder_out", "Output folder"),
    ),
    results=(
        Result("IMAGE_COUNT", "number", "Orthophotos written"),
        Result("GSD_USED", "number", "Cell size used"),
        Result("OCCLUDED_FRACTION", "number", "Share of cells occluded (true orthophotos)"),
    ),
    tags=("orthophoto", "orthorectification", "true orthophoto", "occlusion", "dsm", "dtm"),
    references=(
        "dos Santos, Dal Poz & Dalmolin (2010)",
        "Amhar, Jansa & Ries (1998)",
        "Habib, Kim & Kim (2007)",
    ),
)


@dataclass(frozen=True)
class OrthoFile:
    """One orthophoto written by the job."""

    image_id: str
    path: str
    width: int
    height: int
    valid_cells: int
    occluded_cells: int


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Check every input, then orthorectify the images one after the other."""
    from ..geometry.frames import parse_crs
    from ..io.atomic import OutputSet
    from ..photo.orthophoto import OrthoOptions

    mapping = parse_crs(v.crs, what="mapping CRS")
    extent = _extent(v.extent)
    camera, eo, images, row_of, infos = _read_inputs(v, mapping)
    options = options_from(OrthoOptions, SPEC, v)
    folder = Path(v.output_folder)
    targets = {f.stem: folder / ORTHO_NAME.format(f.stem) for f in images}
    inputs = {"IMAGES": [str(f) for f in images], "DSM": v.dsm, "EO": v.eo, "CAMERA": v.camera}

    load, work = stages(progress, 0.15, 0.85)
    dsm = _dsm_in(v, mapping, load, should_stop)
    poses = {f.stem: (eo.xyz[row_of[f.stem]], eo.opk[row_of[f.stem]]) for f in images}
    projectors, ground_z, gsd = _block_geometry(v, options, camera, poses, dsm, mapping)
    grids = _grids({k: p.footprint() for k, p in projectors.items()}, extent, gsd, infos, folder)
    # an image's overview levels are written (GDAL compressing them) while the next image's
    # tiles are computed; the files are renamed into place once all are whole
    written: list[OrthoFile] = []
    finishing: list[tuple[Future, str]] = []  # and the image of each
    with (
        OutputSet({k: str(p) for k, p in targets.items()}, inputs) as files,
        ThreadPoolExecutor(max_workers=1) as finisher,
    ):
        try:
            for m, f in enumerate(images):
                if f.stem not in grids:
                    continue
                sub = None if work is None else (lambda fr, m=m: work((m + fr) / len(images)))
                done, job = _write_image(
                    v,
                    f,
                    projectors[f.stem],
                    grids[f.stem],
                    ground_z[f.stem],
                    options,
                    files,
                    finisher,
                    mapping,
                    targets[f.stem],
                    sub,
                    should_stop,
                )
                written.append(done)
                if job is not None:
                    finishing.append((job, f.stem))
        finally:
            wait([job for job, _ in finishing])  # nothing is being written when set discarded
        for job, name in finishing:
            # a failure to write an image's levels fails the job: nothing renamed
            with failures_named(targets[name]):
                job.result()
        files.commit()
    return _result(written, gsd, folder, options.true_ortho)


def _block_geometry(v: Values, options, camera, poses: dict, dsm, mapping) -> tuple:
    """(the images' projectors on the DSM, their ground heights, the GSD used): the ground
    height of an image is the DSM's median in its footprint, the GSD GSD's or the block's
    rule (:func:`core.photo.ortho_block.block_gsd`); images reaching beyond the DSM warned."""
    from ..geometry.raycast import DsmTracer
    from ..photo.ortho_block import block_gsd, block_projectors, median_height

    # the skipping pyramid of the ray casting only for true orthophotos (built once)
    surface = DsmTracer.build(dsm) if options.true_ortho else dsm
    projectors = block_projectors(camera, poses, dsm, surface, mapping)
    boxes = {k: p.footprint() for k, p in projectors.items()}
    ground_z = {k: median_height(dsm, b) for k, b in boxes.items()}
    gsd = block_gsd(options, camera, projectors, ground_z, path=str(v.dsm))
    _warn_beyond(projectors, boxes, ground_z)
    return projectors, ground_z, gsd


def _result(written: list, gsd: float, folder: Path, true_ortho: bool) -> JobResult:
    """The job's result: the images written, the GSD and the share of occluded cells."""
    occluded = sum(w.occluded_cells for w in written)
    frac = occluded / max(sum(w.valid_cells for w in written) + occluded, 1)
    lines = [
        f"{len(written)} orthophoto(s) of {gsd:g} in {folder}"
        + (f"; {100 * frac:.1f} % of the cells occluded" if true_ortho else "")
    ]
    return JobResult(
        results={"IMAGE_COUNT": len(written), "GSD_USED": gsd, "OCCLUDED_FRACTION": frac},
        lines=lines,
        data=written,
    )


def _write_image(
    v: Values,
    f: Path,
    proj,
    grid,
    ground_z: float,
    options,
    files,
    finisher,
    mapping,
    target: Path,
    progress,
    should_stop,
):
    """Orthorectify image ``f`` into its temporary of ``files``: (its :class:`OrthoFile`, the
    future writing its overview levels, or None)."""
    import numpy as np

    from ..io.raster import RasterReader
    from ..io.raster_write import GeoTiffWriter
    from .common import compression_args

    name = f.stem
    nadir = proj.ground_points([proj.camera.principal_point_px], ground_z)[0]
    meta = {
        "LIDARPHOTO_IMAGE_ID": name,
        "LIDARPHOTO_SOURCE": os.path.basename(str(f)),
        "LIDARPHOTO_CENTRE": ",".join(repr(float(c)) for c in proj.xyz),
        "LIDARPHOTO_GROUND_Z": repr(float(ground_z)),
        "LIDARPHOTO_PRINCIPAL_GROUND": ",".join(repr(float(c)) for c in nadir),
        "LIDARPHOTO_TRUE_ORTHO": "yes" if options.true_ortho else "no",
    }
    valid = occluded = 0
    with RasterReader(f) as src:
        info = src.info
        photometric = "RGB" if info.bands == 3 and info.dtype == np.uint8 else None
        writer = GeoTiffWriter(
            files.path(name),
            grid.cols,
            grid.rows,
            info.bands,
            info.dtype,
            grid.geotransform,
            mapping,
            mask=True,
            tile=512,
            photometric=photometric,
            metadata=meta,
            **compression_args(v.compression),
        )
        try:
            for tile in _tiles(proj, grid, src, info, options, progress, should_stop):
                writer.write(tile.data, tile.col0, tile.row0, tile.valid)
                valid += int(np.count_nonzero(tile.valid))
                occluded += tile.occluded
        except BaseException:
            with contextlib.suppress(OSError):  # the first error is the one told
                writer.close(overviews=False)
            raise
        with failures_named(target):
            job = writer.close(finish_in=finisher)
    log.info(
        "%s: %d x %d cells of %g, %d with data%s",
        name,
        grid.cols,
        grid.rows,
        grid.cell,
        valid,
        f", {occluded} occluded" if options.true_ortho else "",
    )
    return OrthoFile(name, str(target), grid.cols, grid.rows, valid, occluded), job


def _warn_beyond(projectors: dict, boxes: dict, ground_z: dict) -> None:
    """Warn of the images whose border reaches beyond the DSM (no data there)."""
    from ..photo.ortho_block import share_beyond_dsm

    beyond = {
        k: share_beyond_dsm(p, ground_z[k]) for k, p in projectors.items() if boxes[k] is not None
    }
    beyond = {k: v for k, v in beyond.items() if v > 0}
    if beyond:
        log.warning(
            "the DSM does not cover all of %d image(s) (share of the image's border "
            "beyond it: %s): no data there",
            len(beyond),
            ", ".join(f"{k} {round(100 * v)} %" for k, v in beyond.items()),
        )


def _read_inputs(v: Values, mapping):
    """The camera, the EO (checked against the mapping CRS's area of use), the images with
    their EO rows and their size against the camera: all checked before anything is computed."""
    from ..errors import InputError
    from ..geometry.frames import check_points_in_area
    from ..geometry.projection import PROJECTIONS
    from ..io.camera import read_camera_json
    from ..io.images import list_image_files
    from ..io.orientation import read_eo_csv
    from ..io.raster import RasterReader

    camera = read_camera_json(v.camera, projections=PROJECTIONS)  # perspective or fisheye
    eo = read_eo_csv(v.eo)
    check_points_in_area(mapping, eo.xyz, what="the perspective centres", path=v.eo)
    images = list_image_files(v.images)
    row_of = {name: k for k, name in enumerate(eo.image_id)}
    missing = [f.stem for f in images if f.stem not in row_of]
    if missing:
        raise InputError(
            f"no exterior orientation for image(s) {', '.join(missing[:10])}", path=v.eo
        )
    infos = {}
    for f in images:
        with RasterReader(f) as src:
            info = infos[f.stem] = src.info
        if (info.width, info.height) != (camera.width_px, camera.height_px):
            raise InputError(
                f"the image is {info.width} x {info.height} px, the camera "
                f"{camera.name!r} {camera.width_px} x {camera.height_px} px",
                path=str(f),
            )
    return camera, eo, images, row_of, infos


def _dsm_in(v: Values, mapping, progress, should_stop):
    """The DSM (raster, or LAS/LAZ rasterised) in the mapping CRS: resampled when it is in
    another CRS, refused with PROJ's reason when it cannot be."""
    from ..errors import CrsError
    from ..geometry.surface import reproject_dsm
    from ..io.dsm import load_dsm

    dsm = load_dsm(v.dsm, v.cell_size, v.dsm_crs, progress=progress, should_stop=should_stop)
    if dsm.crs is None:
        log.warning("the DSM has no CRS: taken to be the mapping CRS %s", mapping.name)
    elif not dsm.crs.equals(mapping, ignore_axis_order=True):
        source = dsm.crs.name
        try:
            dsm = reproject_dsm(dsm, mapping, should_stop=should_stop)
        except CrsError as exc:
            raise CrsError(
                f"the DSM ({source}) cannot be brought into the mapping CRS "
                f"'{mapping.name}': {exc}",
                path=str(v.dsm),
            ) from exc
        log.warning(
            "the DSM was in '%s': resampled into '%s' (cell %g)", source, mapping.name, dsm.cell
        )
    return dsm


def _extent(values) -> tuple[float, float, float, float] | None:
    """EXTENT as (xmin, ymin, xmax, ymax), refused when empty or inverted."""
    from ..errors import InputError

    if not values:
        return None
    x0, y0, x1, y1 = (float(a) for a in values)
    if not (x1 > x0 and y1 > y0):
        raise InputError(
            f"EXTENT {x0:.10g},{y0:.10g},{x1:.10g},{y1:.10g}: give xmin,ymin,"
            "xmax,ymax with xmin < xmax and ymin < ymax"
        )
    return x0, y0, x1, y1


def _grids(boxes: dict, extent, gsd: float, infos: dict, folder: Path) -> dict:
    """The output grid of each image that sees the DSM (and the extent, when given), checked
    before anything is written: an extent outside every footprint is refused, and so are
    grids that GDAL cannot write or the output folder cannot hold (uncompressed)."""
    import shutil

    import numpy as np

    from ..errors import InputError
    from ..photo.orthophoto import ortho_grid
    from .checks import size_text

    for name, box in boxes.items():
        if box is None:
            log.warning("image %s does not overlap the DSM: no orthophoto", name)
    seen = {k: b for k, b in boxes.items() if b is not None}
    if extent is not None and seen:
        inside = {
            k: b
            for k, b in seen.items()
            if b[0] < extent[2] and extent[0] < b[2] and b[1] < extent[3] and extent[1] < b[3]
        }
        if not inside:
            lo = np.min([b[:2] for b in seen.values()], axis=0)
            hi = np.max([b[2:] for b in seen.values()], axis=0)
            raise InputError(
                "EXTENT {:.10g},{:.10g},{:.10g},{:.10g} lies outside every image's footprint "
                "on the DSM (the footprints span x {:.10g} to {:.10g}, y {:.10g} to {:.10g}): "
                "give the extent in the mapping CRS, within the footprints".format(
                    *extent, lo[0], hi[0], lo[1], hi[1]
                )
            )
        for k in sorted(set(seen) - set(inside)):
            log.warning("image %s does not see EXTENT: no orthophoto", k)
        seen = inside
    shape = {k: ortho_grid(extent or b, gsd) for k, b in seen.items()}
    need = 0.0
    for k, g in shape.items():
        cells = float(g.rows) * g.cols
        per_cell = infos[k].bands * infos[k].dtype.itemsize + 1  # the bands and the mask
        # GDAL keeps a GeoTIFF's tile offsets in one array of at most 2 GB (8 bytes a tile)
        if math.ceil(g.cols / 512) * math.ceil(g.rows / 512) * (infos[k].bands + 1) > 2**28:
            raise InputError(
                f"GSD {gsd:g}: the orthophoto of image {k} would be {g.cols} x "
                f"{g.rows} cells, beyond what a GeoTIFF can hold: give a larger "
                "GSD (0: the images' own)"
            )
        need += cells * per_cell * 4 / 3  # the overview levels add a third
    there = folder.absolute()
    while not there.is_dir() and there != there.parent:  # the folder is made when written
        there = there.parent
    free = shutil.disk_usage(there).free
    if need > free:
        big = max(shape, key=lambda k: shape[k].rows * shape[k].cols)
        g = shape[big]
        raise InputError(
            f"GSD {gsd:g}: the {len(shape)} orthophoto(s) need up to "
            f"{size_text(need)} (uncompressed; image {big}: {g.cols} x {g.rows} "
            f"cells); the output folder has {size_text(free)} free: give a larger "
            "GSD (0: the images' own) or free some space"
        )
    return shape


@contextlib.contextmanager
def failures_named(target) -> Iterator[None]:
    """An OSError of a write (a full device, the file size limit: the temporary's name)
    raised again naming the output file."""
    try:
        yield
    except OSError as exc:
        raise OSError(
            exc.errno, f"{exc.strerror or exc}; nothing was written", str(target)
        ) from exc


def _tiles(proj, grid, src, info, options, progress, should_stop):
    from ..photo.orthophoto import orthorectify_tiles

    def read(window, f):  # pixel-interleaved: OpenCV's layout, read without a copy
        return src.read(window, decimation=f, pixel_interleaved=True)

    return orthorectify_tiles(
        proj,
        grid,
        read,
        info.bands,
        info.dtype,
        options,
        progress=progress,
        should_stop=should_stop,
    )
