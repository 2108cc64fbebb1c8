"""``makecontrolchips``: control chips from ground photos of surveyed points (control plate,
resection, SIFT registration, rectification)."""

from __future__ import annotations

import logging
import math

from ..io.suffixes import PHOTO_SUFFIXES
from .common import camera_param, table_param
from .runner import JobResult
from .spec import AlgorithmSpec, Fields, Param, Result, Values, options_from

log = logging.getLogger(__name__)

_C = Fields("photo.chip_options", "ChipOptions")
_P = Fields("photo.chip_options", "PlateGeometry")
#: File names of the report in the output folder.
REPORT_CSV = "control_chips.csv"
REPORT_JSON = "control_chips.json"

SPEC = AlgorithmSpec(
    name="makecontrolchips",
    title="Make control chips from ground photos",
    group="Aerotriangulation",
    group_id="aerotriangulation",
    summary="Control chips: ground photos of surveyed points rectified at the aerial GSD",
    description="""\
Control chips for the automatic location of control points in aerial images (Berveglieri &
Tommaselli 2014). For each surveyed point two ground photos taken from the same spot looking
down: one with the control plate over the point, one without it.

The ground camera may be a perspective or a fisheye camera (equidistant, equisolid,
orthographic or stereographic, with Brown distortion: the camera file of the camera
calibration), as the nadir fisheye of the source.

1. The plate (a square with an outer and an inner square edge; its centre vertically above
the point at plate height, levelled, one side along the plate azimuth) is found in the plate
photo; its eight corners are located at sub-pixel precision (edges fitted as straight lines
and intersected, the lens model removed), and the photo is resected from them (data snooping;
sigma0 and the sigmas in the report). The four quarter turns of the square are told apart by
the photo azimuth (the approximate grid azimuth of the photos' up direction, within 45
degrees).
2. The plate-free photo is matched to the plate photo by SIFT (Lowe 2004; ratio test, RANSAC
homography) and resected from the matched ground points.
3. It is rectified onto the horizontal plane Z = Z_point at the GSD, north up, centred on the
point: the chip (the plate hides the ground, hence the plate-free photo). Without a
plate-free photo, Chip from the plate photo makes it from the plate photo.

Ground points: the ground-point CSV of the bundle adjustment (point_id, X, Y, Z, role; every
point gets a chip, whatever its role) in the mapping CRS. Photos: a ground-photo table
(point_id, plate_photo, free_photo, and optional photo_azimuth_deg, plate_azimuth_deg), or
files / folders searched by name:
<point_id><plate suffix>.<ext> and <point_id><free suffix>.<ext>.

Output folder: <point_id>.tif per chip (float32 grey, nodata -9999, the geotransform puts the
point at its X, Y: the chip's centre) and the report control_chips.csv / .json (per point:
status and reason, corners found, corner sigmas, resection sigma0 and sigmas, SIFT matches and
inliers). A point that fails (plate not found, only one square, ambiguous, resection sigma0
too large, too few SIFT matches, chip partly outside the photo) gets its reason and no chip;
the others are written.""",
    params=(
        table_param(
            "POINTS",
            "Ground points (CSV)",
            help="point_id, X, Y, Z, role (the bundle adjustment's table)",
        ),
        Param("CRS", "crs", "Mapping CRS of the points", help="e.g. EPSG:31983"),
        camera_param(
            "Ground camera (JSON)", help="perspective or fisheye (as written by calibratecamera)"
        ),
        table_param(
            "PHOTO_TABLE",
            "Ground-photo table (CSV)",
            optional=True,
            help="point_id, plate_photo, free_photo; else PHOTOS are searched by name",
        ),
        Param(
            "PHOTOS",
            "files",
            "Ground photos (files or folders)",
            optional=True,
            suffixes=PHOTO_SUFFIXES,
            help="searched by name when no table is given",
        ),
        Param("PLATE_SUFFIX", "string", "Plate photo name suffix", "_plate", advanced=True),
        Param("FREE_SUFFIX", "string", "Plate-free photo name suffix", "_free", advanced=True),
        Param(
            "OUTER_SIDE",
            "number",
            "Plate outer side",
            _P.outer_m,
            unit="m",
            minimum=0.01,
            maximum=10.0,
        ),
        Param(
            "INNER_SIDE",
            "number",
            "Plate inner side",
            _P.inner_m,
            unit="m",
            minimum=0.005,
            maximum=10.0,
        ),
        Param(
            "PLATE_HEIGHT",
            "number",
            "Plate height above the point",
            _P.height_m,
            unit="m",
            minimum=-5.0,
            maximum=5.0,
            advanced=True,
        ),
        Param(
            "PLATE_AZIMUTH",
            "number",
            "Plate side azimuth (grid)",
            _P.azimuth_deg,
            unit="degrees",
            minimum=-360.0,
            maximum=360.0,
        ),
        Param(
            "PHOTO_AZIMUTH",
            "number",
            "Photo up azimuth (grid, +-45)",
            0.0,
            unit="degrees",
            minimum=-360.0,
            maximum=360.0,
            advanced=True,
        ),
        Param(
            "GSD",
            "number",
            "Chip GSD (the aerial images')",
            _C.gsd_m,
            unit="m",
            minimum=1e-4,
            maximum=100.0,
        ),
        Param(
            "CHIP_SIZE",
            "integer",
            "Chip size",
            _C.size_px,
            unit="pixels",
            minimum=3,
            maximum=4001,
            advanced=True,
        ),
        Param(
            "MAX_SIGMA0",
            "number",
            "Largest resection sigma0",
            _C.max_sigma0,
            minimum=0.0,
            maximum=1e6,
            advanced=True,
        ),
        Param(
            "CORNER_SIGMA",
            "number",
            "Corner sigma (0 = from the line fits)",
            _C.corner_sigma_px,
            unit="pixels",
            minimum=0.0,
            maximum=100.0,
            advanced=True,
        ),
        Param(
            "SIFT_RATIO",
            "number",
            "SIFT ratio test",
            _C.sift_ratio,
            minimum=0.1,
            maximum=0.99,
            advanced=True,
        ),
        Param(
            "RANSAC_THRESHOLD",
            "number",
            "RANSAC threshold",
            _C.ransac_px,
            unit="pixels",
            minimum=0.1,
            maximum=100.0,
            advanced=True,
        ),
        Param(
            "MIN_MATCHES",
            "integer",
            "Fewest SIFT inliers",
            _C.min_matches,
            minimum=6,
            maximum=100000,
            advanced=True,
        ),
        Param(
            "FROM_PLATE_PHOTO",
            "boolean",
            "Chip from the plate photo when no plate-free photo",
            _C.from_plate_photo,
        ),
        Param("OUTPUT_FOLDER", "folder_out", "Output folder"),
    ),
    results=(
        Result("CHIP_COUNT", "number", "Chips written"),
        Result("FAILED_COUNT", "number", "Points without a chip"),
    ),
    tags=(
        "control chip",
        "control plate",
        "ground photo",
        "sift",
        "rectification",
        "control points",
        "resection",
    ),
    references=(
        "Berveglieri & Tommaselli (2014)",
        "Tommaselli & Berveglieri (2014)",
        "Lowe (2004)",
        "Garrido-Jurado et al. (2014)",
    ),
)


def _report_row(pid, xyz, pair, res) -> dict:
    """The report's row (CSV columns, plus the JSON details under their own keys)."""
    row = {
        "point_id": pid,
        "status": res.status,
        "reason": res.reason,
        "X": float(xyz[0]),
        "Y": float(xyz[1]),
        "Z": float(xyz[2]),
        "plate_photo": pair.plate_photo if pair else "",
        "free_photo": (pair.free_photo or "") if pair else "",
        "source": res.source,
        "corners_found": 0,
    }
    det = res.detection
    if det is not None and det.found:
        row.update(
            corners_found=8,
            corner_sigma_max_px=float(det.sigma_px.max()),
            edge_rms_max_px=float(det.edge_rms_px.max()),
            corners_px=det.corners_px.tolist(),
            corner_sigma_px=det.sigma_px.tolist(),
            edge_rms_px=det.edge_rms_px.tolist(),
            edge_points=det.edge_points.tolist(),
        )
    pr = res.plate
    if pr is not None:
        std = pr.std
        row.update(
            resection_sigma0=pr.sigma0,
            sigma_X0=float(std[0]),
            sigma_Y0=float(std[1]),
            sigma_Z0=float(std[2]),
            sigma_omega_deg=math.degrees(std[3]),
            sigma_phi_deg=math.degrees(std[4]),
            sigma_kappa_deg=math.degrees(std[5]),
            azimuth_misfit_deg=pr.azimuth_misfit_deg,
            plate_eo=[
                float(xyz[0] + pr.eo[0]),
                float(xyz[1] + pr.eo[1]),
                float(xyz[2] + pr.eo[2]),
                *map(math.degrees, pr.eo[3:]),
            ],
            corner_residuals_px=pr.residuals_px.tolist(),
            corner_rejected=pr.rejected.tolist(),
        )
    if res.sift is not None:
        row.update(sift_matches=res.sift.matches, sift_inliers=len(res.sift.ref_px))
    if res.free_eo is not None:
        e = res.free_eo
        row.update(
            free_sigma0=res.free_sigma0,
            valid_fraction=res.valid_fraction,
            chip_eo=[
                float(xyz[0] + e[0]),
                float(xyz[1] + e[1]),
                float(xyz[2] + e[2]),
                *map(math.degrees, e[3:]),
            ],
            subsamples=res.subsamples,
            notes=list(res.notes),
        )
    return row


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the points, camera and photos, make each point's chip, write chips and report."""
    from pathlib import Path

    from ..errors import stop_if_asked
    from ..io.atomic import OutputSet
    from ..io.control_chips import write_report_csv, write_report_json
    from ..photo.control_chips import ChipOptions

    points, crs, camera, pairs = _read_inputs(v)
    options = options_from(ChipOptions, SPEC, v)
    _check_photos(pairs, camera)  # every photo checked before anything is computed
    folder = Path(v.output_folder)
    ids = [p for p in points.point_id if p in pairs]
    targets = {pid: folder / f"{pid}.tif" for pid in ids}
    targets["__csv"] = folder / REPORT_CSV
    targets["__json"] = folder / REPORT_JSON
    inputs = {
        "POINTS": v.points,
        "CAMERA": v.camera,
        "PHOTO_TABLE": v.photo_table,
        "PHOTOS": [x for p in pairs.values() for x in (p.plate_photo, p.free_photo) if x],
    }
    xyz_of = dict(zip(points.point_id, points.xyz))
    rows = []
    written = 0
    with OutputSet({k: str(p) for k, p in targets.items()}, inputs) as files:
        for k, pid in enumerate(ids):
            stop_if_asked(should_stop, "making control chips")
            row = _chip(v, pid, xyz_of[pid], pairs[pid], camera, options, crs, files)
            if row["status"] == "ok":
                row["chip"] = str(targets[pid])
                written += 1
            rows.append(row)
            if progress is not None:
                progress((k + 1) / len(ids))
        rows += _without_photo(points.point_id, pairs, xyz_of)
        write_report_csv(files.path("__csv"), rows)
        write_report_json(files.path("__json"), rows)
        files.commit()
    failed = len(rows) - written
    lines = [
        f"{written} chip(s) of {v.chip_size} x {v.chip_size} px at {v.gsd:g} m in "
        f"{folder}; {failed} point(s) without a chip"
    ]
    lines += [f"  {r['point_id']}: {r['reason']}" for r in rows if r["status"] != "ok"]
    return JobResult(
        results={"CHIP_COUNT": written, "FAILED_COUNT": failed}, lines=lines, data=rows
    )


def _without_photo(point_ids, pairs: dict, xyz_of: dict) -> list[dict]:
    """The report's rows of the points without a plate photo (no chip)."""
    return [
        {
            "point_id": pid,
            "status": "failed",
            "reason": "no plate photo",
            "X": float(xyz_of[pid][0]),
            "Y": float(xyz_of[pid][1]),
            "Z": float(xyz_of[pid][2]),
        }
        for pid in point_ids
        if pid not in pairs
    ]


def _read_inputs(v: Values) -> tuple:
    """The ground points (checked against the CRS's area of use), the CRS, the camera and the
    plate and free photos of each point, with the plate's sides checked."""
    from ..errors import InputError
    from ..geometry.frames import check_points_in_area, parse_crs
    from ..geometry.projection import PROJECTIONS
    from ..io.camera import read_camera_json
    from ..io.control_chips import find_photo_pairs, read_photo_table
    from ..io.ground_points import read_ground_points_csv

    points = read_ground_points_csv(v.points)
    crs = parse_crs(v.crs, what="mapping CRS")
    check_points_in_area(crs, points.xyz, what="the ground points", path=v.points)
    # any central projection: the plate's edges, the resection, the registration and the
    # rectification all go through the camera's own projection (a nadir fisheye, as in the
    # source)
    camera = read_camera_json(v.camera, projections=PROJECTIONS)
    if v.photo_table:
        pairs = read_photo_table(v.photo_table)
        unknown = [p for p in pairs if p not in points.point_id]
        if unknown:
            raise InputError(
                f"point(s) not in the ground points: {', '.join(unknown[:10])}", path=v.photo_table
            )
    elif v.photos:
        pairs = find_photo_pairs(v.photos, points.point_id, v.plate_suffix, v.free_suffix)
    else:
        raise InputError("give a ground-photo table (PHOTO_TABLE) or photos (PHOTOS)")
    if not pairs:
        raise InputError(
            f"no plate photo found for any point (names <point_id>{v.plate_suffix}.<ext>)"
        )
    if not v.inner_side < v.outer_side:
        raise InputError(
            f"INNER_SIDE ({v.inner_side:g} m) must be smaller than OUTER_SIDE ({v.outer_side:g} m)"
        )
    return points, crs, camera, pairs


def _check_photos(pairs: dict, camera) -> None:
    """Every photo has the camera's size."""
    from ..errors import InputError
    from ..io.raster import RasterReader

    for pair in pairs.values():
        for path in (pair.plate_photo, pair.free_photo):
            if path:
                with RasterReader(path) as src:
                    w, h = src.info.width, src.info.height
                if (w, h) != (camera.width_px, camera.height_px):
                    raise InputError(
                        f"the photo is {w} x {h} px, the camera {camera.name!r} "
                        f"{camera.width_px} x {camera.height_px} px",
                        path=path,
                    )


def _chip(v: Values, pid: str, xyz, pair, camera, options, crs, files) -> dict:
    """Make point ``pid``'s chip and write it into its temporary of ``files`` when it could
    be made: its report row (the plate's and the photo's azimuths from the pair's row, else
    the parameters)."""
    from ..io.control_chips import read_grey_photo, write_chip
    from ..photo.control_chips import ChipResult, make_chip
    from ..photo.control_plate import PlateGeometry

    plate = PlateGeometry(
        v.outer_side,
        v.inner_side,
        v.plate_height,
        v.plate_azimuth if math.isnan(pair.plate_azimuth_deg) else pair.plate_azimuth_deg,
    )
    az = v.photo_azimuth if math.isnan(pair.photo_azimuth_deg) else pair.photo_azimuth_deg
    ref = read_grey_photo(pair.plate_photo, camera.width_px, camera.height_px)
    free = (
        read_grey_photo(pair.free_photo, camera.width_px, camera.height_px)
        if pair.free_photo
        else None
    )
    res: ChipResult = make_chip(pid, xyz, ref, free, camera, plate, options, az)
    row = _report_row(pid, xyz, pair, res)
    if res.status == "ok":
        meta = {
            "LIDARPHOTO_POINT_ID": pid,
            "LIDARPHOTO_POINT": ",".join(repr(float(c)) for c in xyz),
            "LIDARPHOTO_PLANE_Z": repr(float(xyz[2])),
            "LIDARPHOTO_SOURCE": res.source,
            "LIDARPHOTO_GSD": repr(v.gsd),
        }
        write_chip(files.path(pid), res.chip, res.geotransform, crs, meta)
    else:
        log.warning("point %s: %s", pid, res.reason)
    return row
