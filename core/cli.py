"""Command line ``lidarphoto`` (also ``python -m lidarphoto``): the processing algorithms
without QGIS, for batch work.

Subcommands carry the algorithm ids of the QGIS toolbox (``lidarphoto:trajectorytoeo`` ->
``lidarphoto trajectorytoeo``) and options carry its parameter names, lower-cased with dashes
(``LEVER_ARM`` -> ``--lever-arm``), with the same value formats. Outputs that only QGIS can
make (layers) are written as the CSV outputs instead.
"""

from __future__ import annotations

import argparse
import logging
import sys
from collections.abc import Sequence

from . import __version__
from .errors import LidarPhotoError


def _add_trajectory_to_eo(sub: argparse._SubParsersAction) -> None:
    from .photo.georeference import MOUNT_CHOICES

    p = sub.add_parser(
        "trajectorytoeo",
        help="INS/GNSS trajectory + camera mount -> exterior orientation per image",
        description=(
            "Direct georeferencing. Reads a trajectory CSV (image_id, time, easting, northing, "
            "height or latitude, longitude, height, and roll, pitch, heading in degrees) and "
            "writes the exterior orientation (X Y Z in the mapping CRS, omega phi kappa in "
            "degrees relative to the grid frame at each image)."
        ),
    )
    p.add_argument("--input", required=True, help="trajectory CSV file")
    p.add_argument("--crs", required=True, help="mapping CRS (projected), e.g. EPSG:31983 or WKT")
    p.add_argument("--lever-arm", default="0,0,0", help="x,y,z in metres, body frame")
    p.add_argument(
        "--mount",
        default=MOUNT_CHOICES[0],
        help=f"nominal mount: {', '.join(MOUNT_CHOICES)} (or its index)",
    )
    p.add_argument("--mount-matrix", default="", help="9 numbers, R_c^b row-major (custom mount)")
    p.add_argument("--boresight", default="0,0,0", help="domega,dphi,dkappa in degrees")
    p.add_argument("--output-csv", default=None, help="EO CSV to write (default: stdout)")
    p.set_defaults(run=_run_trajectory_to_eo)


def _run_trajectory_to_eo(args: argparse.Namespace) -> int:
    from .photo.georeference import run_trajectory_to_eo

    table = run_trajectory_to_eo(
        args.input,
        args.crs,
        lever_arm=args.lever_arm,
        mount=args.mount,
        mount_matrix=args.mount_matrix,
        boresight=args.boresight,
        output_csv=args.output_csv,
    )
    if args.output_csv:
        print(f"{len(table)} images -> {args.output_csv}")
    else:
        import tempfile
        from pathlib import Path

        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "eo.csv"
            table.to_csv(path)
            sys.stdout.write(path.read_text(encoding="utf-8"))
    return 0


def _add_ground_filter(sub: argparse._SubParsersAction) -> None:
    from .lidar.ground_filter import GroundFilterParams

    d = GroundFilterParams()
    p = sub.add_parser(
        "groundfilter",
        help="progressive morphological ground filter of a LAS/LAZ cloud",
        description=(
            "Classifies ground (class 2) with the Progressive Morphological Filter and writes "
            "a copy of the cloud with the extra dimension height_above_ground, and optionally "
            "the DTM as GeoTIFF. Lengths are in the cloud's CRS unit unless --distance-unit "
            "metres."
        ),
    )
    p.add_argument("--input", required=True, help="LAS/LAZ file")
    p.add_argument("--crs", default=None, help="overrides the file's CRS (EPSG:xxxx or WKT)")
    p.add_argument("--distance-unit", default="crs", help="crs (cloud CRS units) | metres")
    for name, text in (
        ("cell_size", "cell size (horizontal)"),
        ("max_window", "maximum window size (horizontal)"),
        ("slope", "terrain slope, rise/run"),
        ("initial_distance", "initial elevation threshold (vertical)"),
        ("max_distance", "maximum elevation threshold (vertical)"),
        ("window_base", "window growth base b (cells)"),
        ("ground_threshold", "final height tolerance (vertical)"),
        ("slope_scalar", "tolerance added per unit of slope (vertical)"),
        ("low_outlier_height", "low outlier depth (vertical, 0 = off)"),
        ("low_outlier_radius", "low outlier radius (horizontal)"),
    ):
        default = getattr(d, name)
        p.add_argument(f"--{name.replace('_', '-')}", type=float, default=default, help=text)
    p.add_argument("--growth", default="linear", help="linear | exponential")
    p.add_argument("--window-shape", default="square", help="square | disk")
    p.add_argument("--last-returns-only", default="true", help="true | false")
    p.add_argument("--non-ground-class", default="keep", help="keep | 1")
    p.add_argument("--output-cloud", required=True, help="classified LAS/LAZ to write")
    p.add_argument("--output-dtm", default=None, help="DTM GeoTIFF to write (optional)")
    p.set_defaults(run=_run_ground_filter)


def _run_ground_filter(args: argparse.Namespace) -> int:
    from .errors import InputError
    from .lidar.ground_filter import GroundFilterParams, run_ground_filter, write_geotiff

    def choice(value: str, options: Sequence[str], name: str) -> int:
        v = value.strip().lower()
        if v.isdigit() and int(v) < len(options):
            return int(v)
        for i, opt in enumerate(options):
            if v in opt.split("|"):
                return i
        raise InputError(f"--{name}: expected one of {', '.join(options)}, got {value!r}")

    unit = ("crs", "metre")[choice(args.distance_unit, ("crs", "metre|metres|m"), "distance-unit")]
    growth = choice(args.growth, ("linear", "exponential"), "growth")
    shape = choice(args.window_shape, ("square", "disk"), "window-shape")
    last = choice(args.last_returns_only, ("false|no|0", "true|yes|1"), "last-returns-only")
    params = GroundFilterParams(
        cell_size=args.cell_size,
        max_window=args.max_window,
        slope=args.slope,
        initial_distance=args.initial_distance,
        max_distance=args.max_distance,
        growth=("linear", "exponential")[growth],
        window_base=args.window_base,
        window_shape=("square", "disk")[shape],
        ground_threshold=args.ground_threshold,
        slope_scalar=args.slope_scalar,
        low_outlier_height=args.low_outlier_height,
        low_outlier_radius=args.low_outlier_radius,
        last_returns_only=last == 1,
        distance_unit=unit,
    )
    keep = choice(args.non_ground_class, ("keep", "1|unclassified"), "non-ground-class")
    non_ground = (None, 1)[keep]
    run = run_ground_filter(
        args.input, args.output_cloud, params, crs=args.crs, non_ground_class=non_ground
    )
    if args.output_dtm:
        r = run.result
        write_geotiff(args.output_dtm, r.dtm, r.geotransform, r.nodata, run.crs_wkt or None)
    print(
        f"{run.point_count} points, {run.ground_count} ground, {run.low_outlier_count} low "
        f"outliers; distances in {run.unit} -> {args.output_cloud}"
    )
    return 0


def _add_create_lcps(sub: argparse._SubParsersAction) -> None:
    from .lidar.control import ControlOptions

    d = ControlOptions()
    p = sub.add_parser(
        "createlcps",
        help="LiDAR control points and lines from intersecting roof planes",
        description=(
            "Intersects the roof planes of a plane table (from extractroofplanes): three planes "
            "at a corner give a control point, two adjacent planes a ridge/hip/valley line, each "
            "with its covariance. Lengths are in the cloud's CRS unit unless --distance-unit "
            "metres."
        ),
    )
    p.add_argument("--planes", required=True, help="plane table CSV")
    p.add_argument("--cloud", required=True, help="LAS/LAZ with the plane_id dimension")
    p.add_argument("--crs", default=None, help="CRS of the cloud when the file has none")
    p.add_argument("--distance-unit", default="crs", help="crs (cloud CRS unit) | metres")
    p.add_argument("--delta", type=float, default=d.delta, help="adjacency distance")
    p.add_argument("--min-boundary", type=float, default=d.min_boundary, help="common boundary")
    p.add_argument("--min-angle", type=float, default=d.min_angle_deg, help="degrees")
    p.add_argument("--max-condition", type=float, default=d.max_condition)
    p.add_argument("--max-support", type=float, default=d.max_support_distance)
    p.add_argument("--triples", default="", help='plane ids "1,2,3; 4,5,6" (default: automatic)')
    p.add_argument("--pairs", default="", help='plane ids "1,2; 2,3" (default: automatic)')
    p.add_argument("--points-csv", default=None, help="LCP table to write")
    p.add_argument("--lines-csv", default=None, help="line table to write")
    p.add_argument("--graph-csv", default=None, help="plane adjacency graph to write")
    p.set_defaults(run=_run_create_lcps)


def _run_create_lcps(args: argparse.Namespace) -> int:
    from .lidar.control import ControlOptions, run_create_lcps

    options = ControlOptions(
        delta=args.delta,
        min_boundary=args.min_boundary,
        min_angle_deg=args.min_angle,
        max_condition=args.max_condition,
        max_support_distance=args.max_support,
    )
    result, info = run_create_lcps(
        args.planes, args.cloud, crs=args.crs, options=options, triples=args.triples,
        pairs=args.pairs, points_csv=args.points_csv, lines_csv=args.lines_csv,
        graph_csv=args.graph_csv, distance_unit=args.distance_unit,
    )  # fmt: skip
    for r in result.rejected:
        logging.getLogger(__name__).info("planes %s: %s", r.plane_ids, r.reason)
    print(
        f"{len(result.points)} control points, {len(result.lines)} lines, "
        f"{int(result.adjacency.adjacent.sum())} adjacent plane pairs ({info.horizontal_unit})"
    )
    return 0


def _add_accuracy_report(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "accuracyreport",
        help="check points against ASPRS Ed. 2, NSSDA, PEC-PCD and the project threshold",
        description=(
            "Positional accuracy report. INPUT is a CSV with id, e, n, h, e_ref, n_ref, h_ref "
            "[, group]; or MEASURED and REFERENCE point tables (id, e, n, h [, group]) joined "
            "by id. Writes a self-contained HTML report and a JSON of every figure. Enumerations "
            "take names or indices as in QGIS."
        ),
    )
    p.add_argument("--input", default=None, help="check-point CSV (one table)")
    for what in ("measured", "reference"):
        p.add_argument(f"--{what}", default=None, help=f"{what} point table (CSV)")
        p.add_argument(f"--{what}-id", default="", help="id column (default: id)")
        p.add_argument(f"--{what}-z-field", default="", help="height column (default: h)")
    p.add_argument("--group-field", default="", help="group column (default: group)")
    p.add_argument("--crs", default="", help="CRS of the coordinates (reported only)")
    p.add_argument("--reproject", action="store_true", help="QGIS only: tables carry no CRS")
    p.add_argument("--alpha", type=float, default=0.05, help="significance level")
    for name in ("declared-sigma-h", "declared-sigma-v", "survey-sigma-h", "survey-sigma-v"):
        p.add_argument(f"--{name}", type=float, default=0.0, help="metres (h: per axis)")
    p.add_argument("--outlier-rule", default="robust", help="robust, three_sigma or none")
    p.add_argument("--exclude-outliers", action="store_true", help="drop flagged points")
    p.add_argument("--standards", default="asprs,nssda,pec,project", help="comma list")
    p.add_argument("--asprs-h-class-cm", type=float, default=0.0, help="0 = tightest met")
    p.add_argument("--asprs-v-class-cm", type=float, default=0.0, help="0 = tightest met")
    p.add_argument("--pec-scale", type=float, default=1000.0, help="scale denominator")
    p.add_argument("--pec-equidistance", type=float, default=0.0, help="m, 0 = series value")
    p.add_argument("--pec-class", default="A", help="declared class A, B, C or D")
    p.add_argument("--project-h-threshold", type=float, default=0.40, help="metres")
    p.add_argument("--project-v-threshold", type=float, default=0.0, help="m, 0 = Eq. 18")
    p.add_argument("--flight-geometry", default="1600,452,100.4,6", help="H m,B m,f mm,px um")
    p.add_argument("--output-html", default=None, help="HTML report to write")
    p.add_argument("--output-json", default=None, help="JSON of every figure to write")
    p.set_defaults(run=_run_accuracy_report)


def _run_accuracy_report(args: argparse.Namespace) -> int:
    from .errors import InputError
    from .quality.accuracy import (
        OUTLIER_RULES,
        STANDARD_KEYS,
        AccuracySettings,
        run_accuracy_report,
    )
    from .quality.standards import PEC_CLASSES

    def choice(value: str, options: tuple[str, ...], what: str) -> str:
        v = value.strip()
        if v.isdigit() and int(v) < len(options):
            return options[int(v)]
        if v.lower() in [o.lower() for o in options]:
            return next(o for o in options if o.lower() == v.lower())
        raise InputError(f"{what}: '{value}' is not one of {', '.join(options)}")

    if args.reproject:
        raise InputError("REPROJECT needs QGIS (point tables carry no CRS)")
    try:
        geometry = tuple(float(v) for v in args.flight_geometry.split(","))
    except ValueError:
        raise InputError(f"FLIGHT_GEOMETRY: '{args.flight_geometry}' is not 4 numbers") from None
    settings = AccuracySettings(
        alpha=args.alpha,
        declared_sigma_h=args.declared_sigma_h,
        declared_sigma_v=args.declared_sigma_v,
        survey_sigma_h=args.survey_sigma_h,
        survey_sigma_v=args.survey_sigma_v,
        outlier_rule=choice(args.outlier_rule, OUTLIER_RULES, "OUTLIER_RULE"),
        exclude_outliers=args.exclude_outliers,
        standards=tuple(
            choice(v, STANDARD_KEYS, "STANDARDS") for v in args.standards.split(",") if v.strip()
        ),
        asprs_h_class_cm=args.asprs_h_class_cm,
        asprs_v_class_cm=args.asprs_v_class_cm,
        pec_scale=args.pec_scale,
        pec_equidistance=args.pec_equidistance,
        pec_class=choice(args.pec_class, PEC_CLASSES, "PEC_CLASS"),
        project_h_threshold=args.project_h_threshold,
        project_v_threshold=args.project_v_threshold,
        flight_geometry=geometry,
    )
    report = run_accuracy_report(
        input_table=args.input,
        measured_table=args.measured,
        reference_table=args.reference,
        measured_id=args.measured_id or None,
        reference_id=args.reference_id or None,
        measured_z=args.measured_z_field or None,
        reference_z=args.reference_z_field or None,
        group_field=args.group_field or None,
        crs=args.crs or None,
        settings=settings,
        output_html=args.output_html,
        output_json=args.output_json,
    )
    for key, value in report.rmse.items():
        print(f"{key} {value:.4f}")
    for res in report.standards:
        for v in res.verdicts:
            print(f"{res.key}: {v.name}: {v.status} ({v.reason})")
    return 0


def _add_extract_roof_planes(sub: argparse._SubParsersAction) -> None:
    from .lidar.roof_planes import RoofPlaneParams

    d = RoofPlaneParams()
    p = sub.add_parser(
        "extractroofplanes",
        help="roof planes with their precision from a classified LAS/LAZ cloud",
        description=(
            "Local RANSAC on the K nearest neighbours, region growing, Pathak plane fits with "
            "covariance. Writes the plane table CSV and optionally the cloud with the extra "
            "dimension plane_id. Lengths are in the cloud's CRS unit unless --distance-unit "
            "metres."
        ),
    )
    p.add_argument("--input", required=True, help="LAS/LAZ file")
    p.add_argument("--crs", default=None, help="overrides the file's CRS (EPSG:xxxx or WKT)")
    p.add_argument("--distance-unit", default="crs", help="crs (cloud CRS units) | metres")
    p.add_argument("--points", default="non_ground", help="non_ground | classes | all")
    p.add_argument("--classes", default="6", help="classes for --points classes, e.g. 6 or 1,6")
    for name, field, kind, text in (
        ("k-neighbours", "k_neighbours", int, "neighbours K of the local RANSAC"),
        ("epsilon", "epsilon", float, "point-to-plane tolerance (length)"),
        ("min-support", "min_support", int, "minimum support of a local plane (points)"),
        ("ransac-iterations", "ransac_iterations", int, "RANSAC triplets per point"),
        ("min-slope", "min_slope_deg", float, "minimum slope alpha, degrees"),
        ("max-slope", "max_slope_deg", float, "maximum slope beta, degrees"),
        ("angle-tolerance", "angle_tolerance_deg", float, "normal angle tolerance, degrees"),
        ("min-plane-points", "min_plane_points", int, "minimum points per plane"),
        ("outline-cell", "outline_cell", float, "outline raster cell (length, 0 = auto)"),
        ("seed", "seed", int, "random seed"),
    ):
        p.add_argument(
            f"--{name}",
            dest=name.replace("-", "_"),
            type=kind,
            default=getattr(d, field),
            help=text,
        )
    p.add_argument("--output-csv", required=True, help="plane table CSV to write")
    p.add_argument("--output-cloud", default=None, help="LAS/LAZ with plane_id (optional)")
    p.set_defaults(run=_run_extract_roof_planes)


def _run_extract_roof_planes(args: argparse.Namespace) -> int:
    from .errors import InputError
    from .lidar.roof_planes import RoofPlaneParams, run_extract_roof_planes

    units = {
        "crs": "crs",
        "0": "crs",
        "metre": "metre",
        "metres": "metre",
        "m": "metre",
        "1": "metre",
    }.get(args.distance_unit.strip().lower())
    points = ("non_ground", "classes", "all")
    sel = args.points.strip().lower().replace("-", "_")
    sel = points[int(sel)] if sel.isdigit() and int(sel) < 3 else sel
    if units is None or sel not in points:
        raise InputError("--distance-unit must be crs|metres and --points non_ground|classes|all")
    params = RoofPlaneParams(
        k_neighbours=args.k_neighbours,
        epsilon=args.epsilon,
        min_support=args.min_support,
        ransac_iterations=args.ransac_iterations,
        min_slope_deg=args.min_slope,
        max_slope_deg=args.max_slope,
        angle_tolerance_deg=args.angle_tolerance,
        min_plane_points=args.min_plane_points,
        outline_cell=args.outline_cell,
        seed=args.seed,
    )
    run = run_extract_roof_planes(
        args.input,
        params=params,
        units=units,
        selection=sel,
        classes=args.classes,
        crs=args.crs,
        output_csv=args.output_csv,
        output_cloud=args.output_cloud,
    )
    print(f"{run.result.message}; lengths in {run.unit} -> {args.output_csv}")
    return 0


def _add_boresight_calibration(sub: argparse._SubParsersAction) -> None:
    from .photo.georeference import MOUNT_CHOICES

    p = sub.add_parser(
        "boresightcalibration",
        help="boresight (and lever arm, interior) from LiDAR roof planes, lines and LCPs",
        description=(
            "Adjusts the camera-INS misalignment per group of images from image observations "
            "on LiDAR roof planes (tie), lines (line), control points (lcp) and paper 000's "
            "single-image model (paper). Writes the results table, the updated exterior "
            "orientations, the residual table and an HTML summary. Enumerations take names or "
            "indices as in QGIS."
        ),
    )
    p.add_argument("--camera", required=True, help="camera JSON")
    p.add_argument("--trajectory", required=True, help="trajectory CSV")
    p.add_argument("--crs", required=True, help="mapping CRS (projected), EPSG:xxxx or WKT")
    p.add_argument("--lever-arm", default="0,0,0", help="x,y,z in metres, body frame")
    p.add_argument("--mount", default=MOUNT_CHOICES[0], help=f"{', '.join(MOUNT_CHOICES)}")
    p.add_argument("--mount-matrix", default="", help="9 numbers, R_c^b row-major (custom)")
    p.add_argument("--boresight", default="0,0,0", help="initial domega,dphi,dkappa, degrees")
    p.add_argument("--observations", required=True, help="image observation CSV")
    p.add_argument("--planes", default=None, help="plane table CSV")
    p.add_argument("--lines", default=None, help="line table CSV")
    p.add_argument("--lcps", default=None, help="LCP table CSV")
    p.add_argument("--cloud", default=None, help="LAS/LAZ with plane_id (paper mode only)")
    p.add_argument("--grouping", default="group", help="single | group | direction")
    p.add_argument("--control-types", default="tie,line,lcp,paper", help="comma list")
    p.add_argument("--estimate-lever-arm", action="store_true", help="estimate the lever arm")
    p.add_argument("--estimate-interior", action="store_true", help="estimate f, x0, y0")
    p.add_argument("--ins-grade", default="pos_av_310", help="pos_av_310 | custom")
    p.add_argument(
        "--ins-sigmas", default="0.02,0.05,0.015,0.035", help="custom: h m, v m, rp deg, hd deg"
    )
    p.add_argument("--snooping", default="true", help="Baarda data snooping: true | false")
    p.add_argument("--output-table", default=None, help="results CSV (one row per group)")
    p.add_argument("--residuals-csv", default=None, help="residual table CSV")
    p.add_argument("--output-eo", default=None, help="updated exterior orientation CSV")
    p.add_argument("--output-html", default=None, help="HTML summary")
    p.set_defaults(run=_run_boresight_calibration)


def _run_boresight_calibration(args: argparse.Namespace) -> int:
    from .errors import InputError
    from .jobs.boresight_calibration import run_boresight_calibration

    snoop = args.snooping.strip().lower()
    if snoop not in ("true", "false", "yes", "no", "1", "0"):
        raise InputError(f"--snooping: expected true or false, got {args.snooping!r}")
    run = run_boresight_calibration(
        args.camera, args.trajectory, args.crs, args.observations, lever_arm=args.lever_arm,
        mount=args.mount, mount_matrix=args.mount_matrix, boresight=args.boresight,
        planes=args.planes, lines=args.lines, lcps=args.lcps, cloud=args.cloud,
        grouping=args.grouping, estimate_lever_arm=args.estimate_lever_arm,
        estimate_interior=args.estimate_interior, ins_grade=args.ins_grade,
        ins_sigmas=args.ins_sigmas, control_types=args.control_types,
        snooping=snoop in ("true", "yes", "1"), output_table=args.output_table,
        output_eo=args.output_eo, output_html=args.output_html,
        residuals_csv=args.residuals_csv,
    )  # fmt: skip
    res = run.result
    print(f"{'group':8} {'angle':8} {'deg':>12} {'arcsec':>10} {'sigma':>8}")
    for row in res.table_rows():
        print(
            f"{row['group']:8} {row['parameter']:8} {row['value_deg']:12.6f} "
            f"{row['value_arcsec']:10.1f} {row['std_arcsec']:8.1f}"
        )
    test = "passed" if res.chi2_passed else "failed"
    print(f"sigma0 {res.sigma0:.3f}, redundancy {res.redundancy}, global test {test}, "
          f"{int(res.residuals.rejected.sum())} observations rejected")  # fmt: skip
    return 0


def _add_monoplot(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "monoplot",
        help="3D points and lines from one oriented image and a LiDAR DSM",
        description=(
            "Intersects the rays of image observations with a DSM (raster, or LAS/LAZ "
            "rasterised at --cell-size): direct (Dal Poz, DDA traversal) or Makarovic's "
            "iteration; tie/paper rows on roof planes with --planes. Writes the point table "
            "(X Y Z, sigmas, covariance, status) and the line table (WKT)."
        ),
    )
    for name, text in (
        ("observations", "image-observation CSV"),
        ("camera", "camera JSON"),
        ("eo", "exterior orientation CSV"),
        ("dsm", "DSM raster or LAS/LAZ"),
    ):
        p.add_argument(f"--{name}", required=True, help=text)
    p.add_argument("--crs", required=True, help="mapping CRS of the EO, e.g. EPSG:28992")
    p.add_argument("--dsm-crs", default=None, help="CRS of the DSM when its file has none")
    p.add_argument("--method", default="dal_poz", help="dal_poz | makarovic (or 0 | 1)")
    p.add_argument("--cell-size", type=float, default=0.5, help="DSM cell for LAS/LAZ")
    p.add_argument("--sigma-dsm", type=float, default=0.10, help="DSM height sigma, m")
    p.add_argument("--line-step", type=float, default=0.0, help="px between line points")
    p.add_argument("--min-incidence", type=float, default=5.0, help="degrees (grazing)")
    p.add_argument("--eo-sigmas", default="0.05,0.05,0.08,0.005,0.005,0.008",
                   help="X,Y,Z m and omega,phi,kappa deg")  # fmt: skip
    p.add_argument("--planes", default=None, help="roof plane table CSV")
    p.add_argument("--output-csv", default=None, help="point table CSV to write")
    p.add_argument("--lines-csv", default=None, help="line table CSV to write")
    p.add_argument("--output-dsm", default=None, help="DSM GeoTIFF to write (LAS/LAZ input)")
    p.set_defaults(run=_run_monoplot)


def _run_monoplot(args: argparse.Namespace) -> int:
    from .errors import InputError
    from .photo.monoplot import METHODS, run_monoplot

    method = args.method.strip().lower()
    method = METHODS[int(method)] if method.isdigit() and int(method) < len(METHODS) else method
    if method not in METHODS:
        raise InputError(f"--method: expected one of {', '.join(METHODS)}, got {args.method!r}")
    res = run_monoplot(
        args.observations, args.camera, args.eo, args.dsm, args.crs, dsm_crs=args.dsm_crs,
        cell_size=args.cell_size, method=method, sigma_dsm=args.sigma_dsm,
        eo_sigmas=args.eo_sigmas, planes=args.planes, line_step_px=args.line_step,
        min_incidence_deg=args.min_incidence, output_csv=args.output_csv,
        lines_csv=args.lines_csv, output_dsm=args.output_dsm,
    )  # fmt: skip
    print(f"{len(res.rows)} rays, {len(res.lines)} lines: {res.status_counts()}")
    return 0


_ALGORITHMS = (
    _add_trajectory_to_eo,
    _add_ground_filter,
    _add_create_lcps,
    _add_accuracy_report,
    _add_extract_roof_planes,
    _add_boresight_calibration,
    _add_monoplot,
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="lidarphoto", description=__doc__.split("\n\n")[0])
    parser.add_argument("--version", action="version", version=f"lidarphoto {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress to stderr")
    sub = parser.add_subparsers(dest="algorithm", metavar="ALGORITHM", required=True)
    for add in _ALGORITHMS:
        add(sub)
    return parser


def parameter_names(algorithm: str) -> list[str]:
    """The processing-style parameter names (``LEVER_ARM``) a subcommand accepts."""
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return [
        a.dest.upper()
        for a in sub.choices[algorithm]._actions
        if a.option_strings and a.dest != "help"
    ]


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    try:
        return int(args.run(args))
    except LidarPhotoError as exc:
        print(f"lidarphoto {args.algorithm}: error: {exc}", file=sys.stderr)
        return 2
