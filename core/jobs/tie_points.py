"""``tiepoints``: automatic tie points of a block of images (SIFT or ORB, ratio test, mutual
check, fundamental-matrix RANSAC, tracks, least-squares refinement by default), written as the
image-observation CSV."""

from __future__ import annotations

import logging

from ..io.suffixes import IMAGE_SUFFIXES
from .common import CSV_FILTER, CSV_OUT
from .runner import JobResult
from .spec import AlgorithmSpec, Fields, Param, Ref, Result, Values, options_from

log = logging.getLogger(__name__)

_D = Fields("photo.tie_options", "TiePointOptions")
#: Columns of the pair table (OUTPUT_PAIRS).
PAIR_COLUMNS = (
    "image_a",
    "image_b",
    "overlap",
    "features_a",
    "features_b",
    "ratio_matches",
    "mutual_matches",
    "inliers",
    "epipolar_median_px",
    "status",
)

SPEC = AlgorithmSpec(
    name="tiepoints",
    title="Automatic tie points",
    group="Aerotriangulation",
    group_id="aerotriangulation",
    summary="tie points of overlapping images by feature matching, for the bundle adjustment",
    description="""\
Finds tie points in a block of images without an operator. Features: SIFT (Lowe 2004) or
ORB (Rublee et al. 2011, faster, less precise), detected once per image, on the image reduced
by the smallest integer factor that brings its longer side to at most Detection size (0: full
resolution; reductions by 2, 4 and 8 are made while decoding JPEGs); the keypoints are
scaled back to full-resolution pixels. SIFT keeps the Features per image of the largest
scales (Keypoints kept) among the extrema above its Contrast threshold.

Pairs: with an exterior orientation and a camera, the pairs whose ground footprints (image
corners met with the plane at Mean terrain height; a fisheye image: the convex hull of 64
points a side of its border, a ray that misses the plane cut at 10 flying heights) overlap
by at least Minimum overlap of the smaller footprint; without them, each image with the
next Window images in file-name order (sequential), or all pairs. An image the EO table
lacks is paired with every image.

Matching: nearest neighbours in descriptor space (FLANN k-d trees for SIFT, Muja & Lowe 2009;
brute force for ORB), Lowe's ratio test, a mutual check, then RANSAC on the fundamental
matrix (Fischler & Bolles 1981; MAGSAC++ by default) with a threshold on the distance to the
epipolar line in full-resolution pixels. SIFT descriptors are compared as RootSIFT
(Arandjelovic & Zisserman 2012) and, after the fundamental matrix, matched again along the
epipolar lines (guided matching); both are on by default. Pairs with fewer than Minimum
inliers are dropped (the pair table gives the reason). Tracks: the matches of all pairs are
merged (connected components; keypoints of one image at one position, SIFT's orientations of
one extremum, count as one); a track holding two different points of one image is dropped,
as are tracks seen in fewer than Minimum track length images.

Fisheye images (a CAMERA with a fisheye projection, Brown correction included; needed for
them, with or without EO): the fundamental matrix holds between perspective images only, so
the keypoints become the camera's rays and the RANSAC (the threshold in the same pixels) runs
on the essential matrix of the rays within 75 degrees of the axis (Nister 2004), refined by
least squares on the distances to the epipolar curves in pixels; the guided matching follows
those curves. Simulated blocks of the four fisheye projections (corners 62-65 degrees off
the axis): refined measurements 0.021-0.033 px from the truth in the median; the fundamental
matrix on the raw pixels keeps 77-85 % of the matches, 37-52 % of those beyond 400 px from
the centre.

Refinement (on by default; unticked, the keypoints are written as detected): least-squares
matching (Gruen 1985, 6 affine + 2 radiometric parameters) of every measurement of a track
against a 21 x 21 px template around its measurement in the track's first image (kept
fixed), in the full-resolution grey images (each read a second time, one at a time),
starting from the local affine between the two images; a match the least-squares matching
calls another point (moved more than 3 px, correlation below 0.7) is dropped, as is one it
refuses for another reason (left its window, no convergence); a measurement it cannot try
(template at the image border, no start affine) keeps the keypoint.

Output: the image-observation CSV (type tie, point ids tp000001 ..., target_id empty), read
directly by Bundle adjustment. sigma_px: the value given, or 0.5 px times the detection
reduction factor; refined measurements: the least-squares sigma (at least 0.02 px); the
track's first-image measurement: the median of its track's refined sigmas.""",
    params=(
        Param(
            "IMAGES",
            "files",
            "Images (files or folders)",
            suffixes=IMAGE_SUFFIXES,
            help="image files, or folders whose images are all taken; the image id is the "
            "file name without extension",
        ),
        Param(
            "EO",
            "table",
            "Exterior orientation (CSV) for pair selection",
            optional=True,
            file_filter=CSV_FILTER,
            help="with CAMERA: pairs from ground footprints",
        ),
        Param(
            "CAMERA",
            "file",
            "Camera (JSON)",
            optional=True,
            file_filter="JSON files (*.json)",
            help="perspective or fisheye; with EO: pairs from ground footprints; a "
            "fisheye camera is needed for fisheye images (their matches are verified on "
            "the camera's rays)",
        ),
        Param(
            "CRS",
            "crs",
            "Mapping CRS of the EO",
            optional=True,
            help="the EO is checked against its area of use",
        ),
        Param(
            "HEIGHT",
            "number",
            "Mean terrain height",
            0.0,
            unit="m",
            minimum=-1000.0,
            maximum=9000.0,
            help="the plane the footprints are computed on (EO heights)",
        ),
        Param(
            "DETECTOR",
            "enum",
            "Detector",
            _D.detector,
            options=Ref("photo.tie_options", "DETECTORS"),
            labels=("SIFT (Lowe 2004)", "ORB (fast)"),
        ),
        Param(
            "MAX_FEATURES",
            "integer",
            "Features per image",
            _D.max_features,
            minimum=100,
            maximum=100000,
            advanced=True,
            help="SIFT keypoints kept per image (Keypoints kept); 6 kite images, all pairs: "
            "16,384 (default) 3,664 tracks seen in 3 images, COLMAP at its 8,192 "
            "3,662-3,730, for about half its CPU; 4,000: 1,190 (bench/matching.md)",
        ),
        Param(
            "KEEP",
            "enum",
            "Keypoints kept (SIFT)",
            _D.keep,
            options=Ref("photo.tie_options", "KEEP_MODES"),
            labels=("largest scales (COLMAP's rule)", "strongest response (OpenCV's)"),
            advanced=True,
            help="which Features per image SIFT keeps when it finds more: the largest "
            "scales (COLMAP's rule) or the strongest response (OpenCV's). Two kite "
            "images, 8,192 features: 3,313 verified matches against 2,436 (+36 %); "
            "simulated block, 1,500 features: 3-6 % fewer matches, keypoints 0.15 against "
            "0.12 px from the truth before the refinement, the same 0.021 px after it: with "
            "REFINE off, the strongest response is the precise choice (bench/matching.md)",
        ),
        Param(
            "CONTRAST",
            "number",
            "SIFT contrast threshold",
            _D.contrast,
            minimum=0.001,
            maximum=0.5,
            advanced=True,
            help="OpenCV's contrastThreshold (grey levels / 255 over 3 layers per "
            "octave): lower finds weaker extrema, so that low-contrast images fill "
            "Features per image; 6 kite images at 8,192 features (strongest kept): "
            "OpenCV's 0.04 finds 5,116 per image, 0.02 fills the budget, "
            "verified matches 5,954 -> 9,874; 0.01 (default) gives the same within 0.4 % "
            "and fills it at half the detection size",
        ),
        Param(
            "ROOT_SIFT",
            "boolean",
            "RootSIFT descriptors (Arandjelovic & Zisserman 2012)",
            _D.root_sift,
            advanced=True,
            help="SIFT descriptors L1-normalised and square-rooted before matching (the "
            "Hellinger kernel; on by default, as in COLMAP); 6 kite images at 8,192 "
            "features: 5,954 -> 6,118 verified matches (+3 %) for +7 % CPU",
        ),
        Param(
            "GUIDED",
            "boolean",
            "Guided matching along the epipolar lines",
            _D.guided,
            advanced=True,
            help="after the fundamental matrix, every keypoint is matched again among "
            "its 8 nearest descriptors within the RANSAC threshold of its epipolar "
            "line (on by default); 6 kite images, 16,384 features: 27,075 -> 28,427 "
            "verified matches (+5 %), 3-image tracks 3,582 -> 3,876 (+8 %), CPU +6 %; "
            "simulated block: +1.7 % matches, refined 0.0212 -> 0.0213 px median, the same "
            "2 wrong tracks of 4,400",
        ),
        Param(
            "MAX_DIMENSION",
            "integer",
            "Detection size (longer side, 0 = full resolution)",
            _D.max_dimension_px,
            unit="pixels",
            minimum=0,
            maximum=100000,
            advanced=True,
            help="the image is reduced by the smallest integer factor that brings its "
            "longer side to at most this (2,000 by default: images of 2,001-4,000 px at half "
            "size); 6 kite images (2,136 px), 16,384 features: half size 3,980 tracks seen "
            "in 3 images against 3,917 at full size, for 5.0 s of detection instead of 13.3 s",
        ),
        Param(
            "RATIO",
            "number",
            "Ratio test (best / second best)",
            _D.ratio,
            minimum=0.3,
            maximum=1.0,
            advanced=True,
        ),
        Param(
            "RANSAC_THRESHOLD",
            "number",
            "RANSAC threshold (epipolar distance)",
            _D.ransac_px,
            unit="pixels",
            minimum=0.05,
            maximum=100.0,
            advanced=True,
        ),
        Param(
            "RANSAC_METHOD",
            "enum",
            "RANSAC method",
            _D.ransac_method,
            options=Ref("photo.tie_options", "RANSAC_METHODS"),
            labels=("MAGSAC++", "RANSAC"),
            advanced=True,
        ),
        Param(
            "MIN_INLIERS",
            "integer",
            "Minimum inliers per pair",
            _D.min_inliers,
            minimum=8,
            maximum=100000,
            advanced=True,
        ),
        Param(
            "MIN_TRACK_LENGTH",
            "integer",
            "Minimum track length",
            _D.min_track_length,
            unit="images",
            minimum=2,
            maximum=1000,
            advanced=True,
        ),
        Param(
            "PAIR_MODE",
            "enum",
            "Pairs",
            _D.pair_mode,
            options=Ref("photo.tie_options", "PAIR_MODES"),
            labels=(
                "footprints with EO, else sequential",
                "footprints (EO + camera)",
                "all pairs",
                "sequential window",
            ),
        ),
        Param(
            "WINDOW",
            "integer",
            "Sequential window",
            _D.window,
            unit="images",
            minimum=1,
            maximum=1000,
            advanced=True,
        ),
        Param(
            "MIN_OVERLAP",
            "number",
            "Minimum footprint overlap",
            _D.min_overlap,
            minimum=0.0,
            maximum=1.0,
            help="share of the smaller footprint",
            advanced=True,
        ),
        Param(
            "REFINE",
            "boolean",
            "Least-squares refinement (Gruen 1985)",
            _D.refine,
            help="on (default): every measurement is moved to its least-squares match "
            "with the track's first image; off: the keypoints as detected. Median "
            "error against the truth, on / off: simulated block 0.021 / 0.075 px (95th "
            "percentile 0.06 / 0.36 px); graffiti wall, a change of viewpoint, 0.34 / "
            "0.75 px; boat (zoom, rotation) 0.27 / 0.38 px. On costs a second "
            "full-resolution read of every image and +25 to +40 % CPU time (see "
            "bench/matching.md)",
        ),
        Param(
            "SIGMA",
            "number",
            "sigma_px written (0 = 0.5 px x reduction)",
            _D.sigma_px,
            unit="pixels",
            minimum=0.0,
            maximum=100.0,
            advanced=True,
        ),
        Param(
            "OUTPUT_OBSERVATIONS", "file_out", "Tie points (observation CSV)", file_filter=CSV_OUT
        ),
        Param(
            "OUTPUT_PAIRS",
            "file_out",
            "Pair table (CSV)",
            optional=True,
            create_by_default=False,
            file_filter=CSV_OUT,
        ),
    ),
    results=(
        Result("TRACK_COUNT", "number", "Tie points (tracks)"),
        Result("MEASUREMENT_COUNT", "number", "Image measurements"),
        Result("PAIRS_TRIED", "number", "Image pairs tried"),
        Result("PAIRS_KEPT", "number", "Image pairs kept"),
    ),
    tags=(
        "tie points",
        "sift",
        "orb",
        "matching",
        "ransac",
        "fundamental matrix",
        "tracks",
        "least-squares matching",
    ),
    references=(
        "Lowe (2004)",
        "Fischler & Bolles (1981)",
        "Rublee et al. (2011)",
        "Muja & Lowe (2009)",
        "Barath et al. (2020)",
        "Gruen (1985)",
        "Arandjelovic & Zisserman (2012)",
        "Nister (2004)",
    ),
)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the images one by one (features only are kept), match, write the tables."""
    from ..errors import InputError
    from ..io.images import decode_factor, image_size, list_image_files, read_gray
    from ..io.observations import write_observations_csv
    from ..photo.tie_options import TiePointOptions
    from ..photo.tie_points import detect_features, reduction_factor, tie_points

    options = options_from(TiePointOptions, SPEC, v)
    files = list_image_files(v.images, ("IMAGES", "identical images have no parallax"))
    if len(files) < 2:
        raise InputError("tie points need at least two images")
    ids = [f.stem for f in files]
    camera, footprint = _footprints(v, ids, options)
    sizes = [image_size(f) for f in files]  # every header read before any work
    _check_sizes(files, sizes, camera)

    def load(k: int):
        need = reduction_factor(*sizes[k], options.max_dimension_px)
        dec = decode_factor(need)
        gray = read_gray(files[k], dec)
        return detect_features(gray, ids[k], options, factor=dec, size_px=sizes[k])

    res = tie_points(
        ids,
        load,
        options,
        footprint,
        progress=progress,
        should_stop=should_stop,
        load_image=lambda k: read_gray(files[k], 1),
        camera=camera,
    )
    s = _checked_summary(res, ids)
    write_observations_csv(out.path("OUTPUT_OBSERVATIONS"), res.observations())
    if out.requested("OUTPUT_PAIRS"):
        _write_pairs(out.path("OUTPUT_PAIRS"), res, ids)
    lines = _summary_lines(res, s)
    for line in lines:
        log.info("%s", line)
    return JobResult(
        results={
            "TRACK_COUNT": s["tracks"],
            "MEASUREMENT_COUNT": s["measurements"],
            "PAIRS_TRIED": s["pairs_tried"],
            "PAIRS_KEPT": s["pairs_kept"],
        },
        lines=lines,
        data=res,
    )


def _check_sizes(files, sizes, camera) -> None:
    """Every image the size of the camera (when one is given), else the file is named."""
    from ..errors import InputError

    if camera is None:
        return
    for f, (w, h) in zip(files, sizes):
        if (w, h) != (camera.width_px, camera.height_px):
            raise InputError(
                f"the image is {w} x {h} px, the camera {camera.name!r} "
                f"{camera.width_px} x {camera.height_px} px",
                path=str(f),
            )


def _checked_summary(res, ids: list[str]) -> dict:
    """The result's summary; copies of an image (pairs without parallax) and a run with no
    tie point are refused with the reason."""
    from ..errors import InputError

    flat = [p for p in res.pairs if p.status.startswith("no parallax")]
    if flat:
        raise InputError(
            "IMAGES: "
            + "; ".join(f"{ids[p.i]} and {ids[p.j]} show {p.status}" for p in flat[:5])
            + ": the same view twice (a copy of an image?); remove the copies"
        )
    s = res.summary()
    if s["tracks"] == 0:
        raise InputError(
            f"no tie point found: {s['pairs_kept']} of {s['pairs_tried']} pairs "
            f"matched; dropped pairs: {s['dropped_pairs'] or 'none'}"
        )
    return s


def _footprints(v: Values, ids: list[str], options) -> tuple:
    """(camera or None, the ground footprint of each image or None): the footprints with EO
    and CAMERA; refused for EO without CAMERA or footprint pairs without both. The camera
    may be perspective or fisheye (any projection of the registry)."""
    from ..errors import InputError
    from ..geometry.projection import PROJECTIONS
    from ..io.camera import read_camera_json
    from ..io.orientation import read_eo_csv
    from ..photo.tie_pairs import footprints

    if v.eo and not v.camera:
        raise InputError(
            "give both the exterior orientation and the camera (footprint pairs) or neither"
        )
    camera = read_camera_json(v.camera, projections=PROJECTIONS) if v.camera else None
    if not v.eo:
        if options.pair_mode == "footprints":
            raise InputError("footprint pairs need EO and CAMERA")
        return camera, None
    eo = read_eo_csv(v.eo)
    _check_eo_coordinates(eo, v.crs, v.eo, v.height)
    row = {name: k for k, name in enumerate(eo.image_id)}
    fps = footprints(camera, eo.xyz, eo.opk, v.height)
    footprint = [fps[row[i]] if i in row else None for i in ids]
    missing = [i for i in ids if i not in row]
    if len(missing) == len(ids):
        raise InputError(
            "no image has a row in the exterior orientation (image_id = "
            "file name without extension)",
            path=v.eo,
        )
    if missing:
        log.warning(
            "%d image(s) without exterior orientation, paired with every image: %s",
            len(missing),
            ", ".join(missing[:10]),
        )
    return camera, footprint


def _write_pairs(path: str, res, ids: list[str]) -> None:
    """OUTPUT_PAIRS: one row per image pair tried."""
    from ..io.tables import write_csv_atomic

    rows = (
        (
            ids[p.i],
            ids[p.j],
            f"{p.overlap:.4g}",
            res.features[p.i],
            res.features[p.j],
            p.n_ratio,
            p.n_mutual,
            p.n_inliers,
            f"{np_median(p.residual_px):.4g}" if p.residual_px.size else "",
            p.status,
        )
        for p in res.pairs
    )
    write_csv_atomic(path, PAIR_COLUMNS, rows)


def _summary_lines(res, s: dict) -> list[str]:
    """The log's summary of the matching (``s``: its summary), the refinement and what was
    dropped."""
    lines = [
        f"{s['images']} images, {sum(res.features)} features; pairs: {s['pairs_kept']} of "
        f"{s['pairs_tried']} kept (inliers per pair: median {s['inliers_median']:g}, min "
        f"{s['inliers_min']}, max {s['inliers_max']}; epipolar distance median "
        f"{s['epipolar_median_px']:.2f} px, 95 % {s['epipolar_p95_px']:.2f} px)",
        f"{s['tracks']} tracks, {s['measurements']} measurements; tracks by length "
        + ", ".join(f"{k}: {n}" for k, n in s["tracks_by_length"].items())
        + f"; {s['rejected_inconsistent']} tracks dropped (two points in one image)",
    ]
    rf = res.refinement
    if rf is not None:

        def text(d):
            return ", ".join(f"{k}: {n}" for k, n in d.items()) or "none"

        lines.append(
            f"least-squares refinement: {rf.refined} measurements refined (median "
            f"shift {rf.shift_median_px:.3f} px), kept at the keypoint: "
            f"{text(rf.kept)}; dropped: {text(rf.dropped)}; "
            f"{rf.tracks_dropped} tracks dropped (too short)"
        )
    if s["dropped_pairs"]:
        dropped = ", ".join(f"{k}: {n}" for k, n in s["dropped_pairs"].items())
        lines.append("dropped pairs: " + dropped)
    if s["images_without_tie"]:
        lines.append(
            f"{len(s['images_without_tie'])} image(s) without tie points (no "
            f"overlap matched): {', '.join(s['images_without_tie'][:20])}"
        )
    return lines


def _check_eo_coordinates(eo, crs: str | None, path: str, height: float) -> None:
    """The perspective centres against the CRS's area of use; without a CRS, refused when
    X, Y look like degrees (within +-180, +-90 and less than a unit apart) while the flying
    height is metres: the footprints would all overlap, every pair would be tried."""
    import numpy as np

    from ..errors import CrsError
    from ..geometry.frames import check_area_of_use, parse_crs

    lo, hi = eo.xyz.min(axis=0), eo.xyz.max(axis=0)
    if crs:
        check_area_of_use(
            parse_crs(crs, what="CRS"), lo, hi, what="the perspective centres", path=path
        )
        return
    spread = float(np.max(hi[:2] - lo[:2]))
    above = float(np.median(np.abs(eo.xyz[:, 2] - height)))
    if (
        abs(lo[0]) <= 180
        and abs(hi[0]) <= 180
        and abs(lo[1]) <= 90
        and abs(hi[1]) <= 90
        and spread < 1.0
        and above > 10.0 * max(spread, 1e-9)
    ):
        raise CrsError(
            f"the perspective centres (x {lo[0]:.10g} to {hi[0]:.10g}, y "
            f"{lo[1]:.10g} to {hi[1]:.10g}) look like longitude and latitude in "
            f"degrees, {above:.4g} units below them the ground: footprint pairs "
            "need X, Y in a projected CRS, in the unit of Z (give CRS to check "
            "it)",
            path=path,
        )


def np_median(values) -> float:
    """Median of an array (NaN when empty)."""
    import numpy as np

    return float(np.median(values)) if len(values) else float("nan")
