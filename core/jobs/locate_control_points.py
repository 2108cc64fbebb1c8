"""``locatecontrolpoints``: ground control points located in oriented images from control chips
(NCC with an adaptive template, least-squares matching, transfer between images)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..io.suffixes import CHIP_SUFFIXES
from .common import camera_param, csv_out, eo_param, html_out, images_param, table_param
from .runner import JobResult, stages
from .spec import AlgorithmSpec, Fields, Param, Result, Values, options_from

if TYPE_CHECKING:
    import numpy as np

_D = Fields("photo.matching_options", "LocateOptions")
_L = Fields("photo.matching_options", "LsmOptions")

SPEC = AlgorithmSpec(
    name="locatecontrolpoints",
    title="Locate control points in images (chips, NCC + least-squares matching)",
    group="Aerotriangulation",
    group_id="aerotriangulation",
    summary="control points measured automatically in oriented images from control chips",
    description="""\
Each control point is projected into each image with its exterior orientation; its control
chip (a north-up GeoTIFF of the ground around the point, rectified onto the plane Z = Z_point,
file name = point id) is searched there by normalised cross-correlation with an adaptive
template size (grown until the predicted least-squares precision from the texture, Förstner
1986, passes), then refined by least-squares matching (Gruen 1985: 6 affine + 2 radiometric
parameters) from the chip's pixels with the local chip-to-image affine as start. Search
window: the EO sigmas (columns sigma_X .. sigma_kappa_deg of the EO CSV) propagated to the
image, times 3; without them +-SEARCH_PX pixels. A match is rejected, with the reason, for a
chip without texture, low correlation, no convergence, a sigma above MAX_SIGMA, a match
outside the search ellipse or a template partly outside the image. With TRANSFER, images where
the chip match failed are matched from the point's best image (image-to-image LSM). The camera
may be perspective or fisheye (equidistant, equisolid-angle, orthographic, stereographic,
Brown added): the prediction and the chip-to-image affine come from its own projection.

Output: the image-observation CSV (image_id, point_id, col, row, sigma_px, type control,
empty target_id; point_id = the control point's id, also for the rows transferred from another
image), which bundleadjustment (with the control points as GROUND_POINTS), resection (with
them as CONTROL_POINTS) and boresightcalibration (with them as GROUND_POINTS) read directly;
sigma_px is the LSM sigma, at least SIGMA_FLOOR (LSM does not see the chip's own errors).
The report CSV has one row per point and image with the status and reason; the HTML report
shows the chips.""",
    params=(
        Param(
            "CHIPS",
            "files",
            "Control chips (GeoTIFF files or folders)",
            suffixes=CHIP_SUFFIXES,
            help="one GeoTIFF per point, named <point_id>.tif",
        ),
        table_param(
            "CONTROL_POINTS",
            "Control points (CSV)",
            help="point_id,X,Y,Z in the mapping CRS (the chips' CRS)",
        ),
        camera_param(),
        eo_param(help="with sigma columns: the search window follows from them"),
        images_param(help="image files (name = image_id), or folders whose images are all taken"),
        Param("CRS", "crs", "Mapping CRS of the EO and control", help="e.g. EPSG:25832"),
        Param(
            "SEARCH_PX",
            "number",
            "Search half-width without EO sigmas",
            _D.default_search_px,
            unit="pixels",
            minimum=1.0,
            maximum=1000.0,
        ),
        Param(
            "MIN_NCC",
            "number",
            "Smallest NCC peak",
            _D.min_ncc,
            minimum=0.0,
            maximum=1.0,
            advanced=True,
        ),
        Param(
            "MIN_CORRELATION",
            "number",
            "Smallest LSM correlation",
            _L.min_correlation,
            minimum=0.0,
            maximum=1.0,
            advanced=True,
        ),
        Param(
            "MAX_SIGMA",
            "number",
            "Largest LSM sigma",
            _L.max_sigma_px,
            unit="pixels",
            minimum=0.0001,
            maximum=10.0,
            advanced=True,
        ),
        Param(
            "SIGMA_FLOOR",
            "number",
            "Smallest sigma written",
            _D.sigma_floor_px,
            unit="pixels",
            minimum=0.0001,
            maximum=100.0,
            advanced=True,
        ),
        Param("TRANSFER", "boolean", "Transfer to images where the chip failed", _D.transfer),
        csv_out("OUTPUT", "Image observations (CSV)", optional=False),
        csv_out("OUTPUT_REPORT", "Report per point and image (CSV)"),
        html_out("OUTPUT_HTML", "Report with chip gallery (HTML)"),
    ),
    results=(
        Result("LOCATED", "number", "Observations written"),
        Result("REJECTED", "number", "Point-image pairs rejected"),
    ),
    tags=("control points", "gcp", "matching", "least-squares matching", "ncc", "chips"),
    references=("Gruen (1985)", "Förstner (1986)", "Immerkær (1996)", "Keys (1981)"),
)


class _Images:
    """Grey windows of the image files (NaN outside the image)."""

    def __init__(self, files: dict) -> None:
        self.files = files
        self.readers: dict = {}

    def __call__(self, image_id: str, c0: int, r0: int, w: int, h: int) -> np.ndarray:
        import numpy as np

        from ..io.raster import RasterReader

        if image_id not in self.readers:
            self.readers[image_id] = RasterReader(self.files[image_id])
        src = self.readers[image_id]
        out = np.full((h, w), np.nan)
        cs, rs = max(c0, 0), max(r0, 0)
        ce, re = min(c0 + w, src.info.width), min(r0 + h, src.info.height)
        if ce <= cs or re <= rs:
            return out
        data = src.read((cs, rs, ce - cs, re - rs)).astype(np.float64)
        grey = (
            0.299 * data[0] + 0.587 * data[1] + 0.114 * data[2] if data.shape[0] >= 3 else data[0]
        )
        out[rs - r0 : re - r0, cs - c0 : ce - c0] = grey
        return out

    def close(self) -> None:
        for r in self.readers.values():
            r.close()


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read chips, control, camera, EO and images; locate; write the outputs."""
    from ..io.atomic import write_text_atomic
    from ..io.chips import write_location_report
    from ..io.observations import write_observations_csv
    from ..photo.control_location import LocateOptions, locate_control_points
    from ..photo.least_squares_matching import LsmOptions
    from ..quality.control_location_html import render_location_html

    camera, chips, images, sub, sig = _read_inputs(v)
    opt = options_from(LocateOptions, SPEC, v, lsm=options_from(LsmOptions, SPEC, v))
    reader = _Images(images)
    compute, _ = stages(progress, 0.95, 0.05)
    try:
        res = locate_control_points(
            chips, sub, camera, reader, sig, opt, progress=compute, should_stop=should_stop
        )
    finally:
        reader.close()
    write_observations_csv(out.path("OUTPUT"), res.observations)
    if out.requested("OUTPUT_REPORT"):
        write_location_report(out.path("OUTPUT_REPORT"), res.pairs)
    if out.requested("OUTPUT_HTML"):
        settings = {
            "chips": str(len(chips)),
            "images": str(len(sub)),
            "search window": "EO sigmas x 3" if sig is not None else f"+-{v.search_px:g} px",
            "transfer": "yes" if v.transfer else "no",
        }
        write_text_atomic(out.path("OUTPUT_HTML"), render_location_html(res.pairs, settings))
    counts = res.counts()
    rejected = counts.get("rejected", 0) + counts.get("outside", 0)
    lines = [
        f"{len(res.observations)} observations of {len(chips)} points in {len(sub)} images;"
        f" {rejected} rejected"
    ]
    for p in res.pairs:
        if p.status != "ok":
            where = f" in {p.image_id}" if p.image_id else ""
            lines.append(f"  {p.point_id}{where}: {p.reason}")
    return JobResult(
        results={"LOCATED": len(res.observations), "REJECTED": rejected}, lines=lines, data=res
    )


def _read_inputs(v: Values) -> tuple:
    """(camera, the chips of the control points, the image files by id, the EO of those
    images, their EO sigmas or None), every input checked before any work."""
    from dataclasses import replace

    from ..errors import InputError
    from ..geometry.frames import check_points_in_area, parse_crs
    from ..geometry.projection import PROJECTIONS
    from ..io.camera import read_camera_json
    from ..io.chips import list_chips, read_control_chip
    from ..io.images import image_size, list_image_files
    from ..io.orientation import read_eo_csv_full
    from ..io.resection import read_point_control_csv

    crs = parse_crs(v.crs, what="CRS")
    camera = read_camera_json(v.camera, projections=PROJECTIONS)  # perspective or fisheye
    eo_file = read_eo_csv_full(v.eo, crs.to_wkt())
    eo = eo_file.eo
    check_points_in_area(crs, eo.xyz, what="the perspective centres", path=v.eo)
    control = read_point_control_csv(v.control_points)
    check_points_in_area(crs, control.xyz, what="the control points", path=v.control_points)
    chip_files = list_chips(v.chips)
    ids = list(control.ids)
    unknown = sorted(set(chip_files) - set(ids))
    if unknown:
        raise InputError(
            f"chips of unknown points (not in the control table): {', '.join(unknown[:10])}",
            path=v.control_points,
        )
    chips = [
        read_control_chip(chip_files[p], p, control.xyz[ids.index(p)], crs)
        for p in sorted(chip_files)
    ]
    images = {f.stem: f for f in list_image_files(v.images)}
    lacking = sorted(set(images) - set(eo.image_id))
    if lacking:
        raise InputError(
            f"no exterior orientation for image(s) {', '.join(lacking[:10])} "
            "(image_id = file name without extension)",
            path=v.eo,
        )
    for f in images.values():  # every header read before any work
        w, h = image_size(f)
        if (w, h) != (camera.width_px, camera.height_px):
            raise InputError(
                f"the image is {w} x {h} px, the camera {camera.name!r} "
                f"{camera.width_px} x {camera.height_px} px",
                path=str(f),
            )
    keep = [k for k, i in enumerate(eo.image_id) if i in images]
    if not keep:
        raise InputError("no image of the EO table among the images given", path=v.eo)
    sub = replace(
        eo,
        image_id=tuple(eo.image_id[k] for k in keep),
        time=eo.time[keep],
        group=tuple(eo.group[k] for k in keep),
        xyz=eo.xyz[keep],
        opk=eo.opk[keep],
    )
    sig = eo_file.sigma[keep] if eo_file.sigma is not None else None
    return camera, chips, images, sub, sig
