"""Bundle adjustment with self-calibration: exterior orientation of every image, object
points, interior orientation and additional parameters (APs) per camera, in one adjustment.

Model
-----
Every image measurement (col, row) of a point is a Gauss-Markov observation of the
collinearity equations (:mod:`core.geometry.collinearity`) with the camera's lens model: the
families of additional parameters of :mod:`core.geometry.ap_models` (Bauer, Jacobsen, Ebner,
Brown, the radial k1 k2 model) or the physical Brown-Conrady model, as corrections added to the
measured coordinates. Unknowns, in the local east-north-up adjustment frame of
docs/conventions.md:

- per image: ``X0, Y0, Z0, omega, phi, kappa``;
- per camera: ``f, x0, y0`` (when the interior orientation is estimated) and the free APs of
  the chosen family;
- per object point: ``X, Y, Z`` (eliminated from the normal equations by the Schur complement:
  the reduced camera system, :mod:`core.lsq.schur`);
- optionally a common lever-arm and boresight correction between the observed (GNSS/INS) and
  the photogrammetric orientation, and a camera timing offset dt (s; exposure = recorded time
  + dt): the observed centre is the GNSS/INS position at the recorded time,
  ``X_obs = X_pc - R_c^m da - v dt``, with the exposure's velocity v (:mod:`.timing`).

Observations besides the image points: control points (their coordinates with sigmas, carried
into the adjustment frame with their full covariance), observed exterior orientations
(GNSS/INS positions and attitudes with sigmas). Check points never enter the adjustment: their
rays are intersected afterwards with the adjusted orientations and compared with their
surveyed coordinates.

Datum: from the control points and/or the observed orientations (``datum="control"``), or a
free network: inner constraints on the tie points (``"inner"``, the minimum-trace datum of
the approximate coordinates) or the minimal constraints that hold the first image's
orientation and one coordinate of a second centre (``"minimal"``).

Approximate values: the exterior orientations given (e.g. direct georeferencing, a few degrees
and metres off), or, with none, a space resection of the images that see four or more control
points followed by alternating forward intersection of the tie points and resection of the
images that see them (growth), until every image is oriented.

Statistics and selection: sigma0, the global chi-square test, standard deviations and
correlations; for every AP its t-test (value over its a-posteriori standard deviation against
Student's t with the redundancy as degrees of freedom) and correlations above a limit with the
other interior parameters. Automatic selection drops, one at a time, the least significant
AP among those insignificant alone and, tested jointly with the other insignificant APs they
correlate with, as a group (a correlation alone never drops a significant parameter:
:mod:`.bundle_selection`), re-adjusts, and reports every decision with its statistic.
Outliers: robust reweighting (Huber or Cauchy) before Baarda's data snooping, both on the
image measurements only (control points and observed orientations are tested, their w
reported, but never removed: their misfits mostly reflect an imperfect model); a tie point
left with one ray by a rejection is set aside with it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Callable

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError, NotObservableError, stop_if_asked
from ..geometry.camera import Camera
from ..geometry.engineering import EngineeringFrame, EngineeringLocal
from ..geometry.frames import MappingFrame
from ..geometry.rotations import opk_to_matrix
from ..lsq.adjustment import small_pages
from .bundle_model import LEVER_NAMES, TIMING_NAME, _cams_from, _Run, _run
from .bundle_options import ROBUSTS
from .bundle_result import BundleResult, _finish
from .bundle_selection import ap_decisions, drop_candidate
from .bundle_setup import BundleOptions, GroundPoints, _prepare
from .observations import ImageObservations
from .orientation import ExteriorOrientationTable
from .scale_bars import ScaleBars, setup_bars
from .timing import (
    ExposureVelocities,
    difference_velocity,
    local_velocity,
    timing_separability,
    timing_trade,
)

#: catalogue context of this module's ``_t("...")`` sentences (``make i18n``): the reports'
TR_CONTEXT = "Report"

Array = NDArray[np.float64]


def _drop_candidate(run: _Run, options: BundleOptions) -> tuple[int, int, str] | None:
    """(camera, interior position, reason) of the AP to drop next, or None: the least
    significant of the APs that are insignificant alone and, with the other insignificant APs
    they correlate with, jointly (:mod:`.bundle_selection`); a correlation alone never drops
    a parameter."""
    decisions = ap_decisions(
        run.result,
        run.lay.interior,
        run.lay.free,
        run.cams,
        options.ap_alpha,
        options.max_correlation,
    )
    d = drop_candidate(decisions)
    return None if d is None else (d.camera, d.position, d.reason)


@small_pages()
def bundle_adjust(
    cameras: Sequence[Camera],
    observations: ImageObservations,
    ground: GroundPoints,
    mapping: MappingFrame | EngineeringFrame,
    eo: ExteriorOrientationTable | None = None,
    eo_sigma: Array | None = None,
    image_camera: Mapping[str, str] | None = None,
    options: BundleOptions | None = None,
    eo_rows: Sequence[int] | None = None,
    eo_source: str = "",
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
    scale_bars: ScaleBars | None = None,
    velocity: ExposureVelocities | None = None,
) -> BundleResult:
    """Bundle adjustment with self-calibration (see the module docstring).

    Parameters
    ----------
    cameras : sequence of Camera
        One or more cameras (unique names).
    observations : ImageObservations
        Image measurements (pixels); a point is a tie point unless ``ground`` names it (rows
        of type ``control`` must name a ground point).
    ground : GroundPoints
        Control and check points in the mapping CRS.
    mapping : MappingFrame or EngineeringFrame
        The mapping CRS of the ground points and orientations, or a local engineering
        frame (no CRS, m or mm).
    eo : ExteriorOrientationTable, optional
        Approximate or observed orientations (mapping CRS, omega-phi-kappa of the grid
        frame); without it the images are oriented by resection from control and growth.
    eo_sigma : ndarray, shape (M, 6), optional
        Standard deviations of the observed orientations (m, m, m, rad, rad, rad) in the
        mapping frame; they make ``eo`` observations instead of approximate values.
    image_camera : mapping of str to str, optional
        Camera name of each image (needed with several cameras).
    options : BundleOptions, optional
    eo_rows, eo_source : for error messages naming rows of the EO file.
    scale_bars : ScaleBars, optional
        Measured distances between adjusted points (frame units), observations with their
        sigmas; with a free-network datum they give its scale (:mod:`.scale_bars`).
    velocity : ExposureVelocities, optional
        The velocity of every exposure of ``eo`` (m/s) for the timing offset
        (``options.estimate_timing``); without it the velocities are differenced from the
        observed centres of each group of ``eo`` by its time column.

    Returns
    -------
    BundleResult

    Raises
    ------
    InputError
        Inconsistent tables (the message names file and row): duplicated measurements,
        unknown images, images without and points with one measurement, an unconnected block,
        control points in another CRS, too few control points for the datum.
    NotObservableError
        Naming the parameters the block cannot determine.
    """
    opts = options if options is not None else BundleOptions()
    eo_sigma = _check_options(opts, eo, eo_sigma, eo_source)
    warnings: list[str] = []
    setup = _prepare(
        cameras,
        dict(image_camera or {}),
        observations,
        ground,
        mapping,
        eo,
        eo_sigma,
        opts,
        eo_rows,
        eo_source,
        should_stop,
        warnings,
    )
    if scale_bars is not None and len(scale_bars):
        metres = setup.local.mapping.metres if isinstance(setup.local, EngineeringLocal) else 1.0
        setup.bars = setup_bars(scale_bars, setup.points, setup.check_ids, metres)
    if opts.estimate_timing:
        assert eo is not None  # observed orientations: above
        setup.velocity = _exposure_velocity(setup, eo, velocity, eo_source, opts.estimate_mount)
    dt0 = 0.0 if opts.estimate_timing else None
    cams = list(setup.cameras)
    free = _free_interior(cams, opts)
    mount = np.zeros(6) if opts.estimate_mount else None
    keep = np.ones(len(observations), dtype=bool)
    report = progress if progress is not None else (lambda f: None)
    # 1. the full model, robust + snooping, from the approximate values
    start = (setup.eo0, setup.xyz0, mount, dt0)
    run = _run_at(start, setup, observations, cams, free, opts, keep, True, should_stop)
    report(0.4)
    dropped: dict[tuple[str, str], str] = {}
    dropped_list: list[tuple[str, str, str]] = []
    if opts.ap_selection and opts.ap_model != "none":
        run = _select_aps(
            setup, observations, run, cams, free, opts, keep, should_stop, dropped, dropped_list
        )
    report(0.9)
    out = _finish(setup, observations, run, opts, dropped, dropped_list, eo, warnings)
    report(1.0)
    return out


def _check_options(
    opts: BundleOptions, eo: ExteriorOrientationTable | None, eo_sigma: Array | None, eo_source: str
) -> Array | None:
    """The options and the EO sigmas checked against each other (InputError naming what is
    wrong); the sigmas as a float64 array (m, m, m, rad, rad, rad) or None."""
    if opts.robust not in ROBUSTS:
        choices = f"{', '.join(ROBUSTS[:-1])} or {ROBUSTS[-1]}"
        raise InputError(f"robust must be {choices}, got {opts.robust!r}")
    if eo is not None and eo_sigma is not None:
        eo_sigma = np.asarray(eo_sigma, dtype=np.float64)
        if eo_sigma.shape != (len(eo), 6) or not (
            np.isfinite(eo_sigma).all() and (eo_sigma > 0).all()
        ):
            raise InputError(
                "the EO sigmas must be finite and > 0 for every image", path=eo_source or None
            )
    if opts.estimate_mount and eo_sigma is None:
        raise InputError(
            "estimating the lever arm and boresight needs observed orientations "
            "(EO with sigma columns)"
        )
    if opts.estimate_timing and eo_sigma is None:
        raise InputError(
            "estimating the camera timing offset needs observed orientations "
            "(EO with sigma columns, or EO_SIGMAS)"
        )
    return eo_sigma


def _free_interior(cams: Sequence[Camera], opts: BundleOptions) -> list[NDArray[np.intp]]:
    """Per camera, the indices of its interior parameters the adjustment estimates (the
    principal distance and point with ``estimate_interior``, the APs unless ``ap_model`` is
    none)."""
    free = []
    for cam in cams:
        f = []
        if opts.estimate_interior:
            f += [0, 1, 2]
        if opts.ap_model != "none":
            f += list(range(3, 3 + cam.distortion.n_params))
        free.append(np.array(f, dtype=np.intp))
    return free


def _select_aps(
    setup,
    observations: ImageObservations,
    run: _Run,
    cams: list[Camera],
    free: list[NDArray[np.intp]],
    opts: BundleOptions,
    keep: NDArray[np.bool_],
    should_stop: Callable[[], bool] | None,
    dropped: dict[tuple[str, str], str],
    dropped_list: list[tuple[str, str, str]],
) -> _Run:
    """The AP selection loop (:mod:`.bundle_selection`): from the first run, drop one AP at a
    time (held at zero; the observations that run rejected stay out) while one is not
    significant, then the full model, robust + snooping, again with what is left; ``dropped``
    and ``dropped_list`` filled with each dropped AP and its reason. The run to report."""
    # observations rejected by the first run stay out while APs are selected
    keep = keep.copy()
    for rows, name in zip(run.blocks_rows, run.block_names):
        keep[rows[run.result.residuals[name].rejected]] = False
    current = run
    changed = False
    for _ in range(sum(f.size for f in free)):
        stop_if_asked(should_stop, "selecting additional parameters")
        cand = _drop_candidate(current, opts)
        if cand is None:
            break
        c, pos, reason = cand
        name = cams[c].interior_names[pos]
        dropped[(cams[c].name, name)] = reason
        dropped_list.append((cams[c].name, name, reason))
        # a dropped AP is held at zero
        full = _cams_from(current)[c].interior_params
        full[pos] = 0.0
        new_cams = _cams_from(current)
        new_cams[c] = new_cams[c].with_interior(full)
        free = [f if k != c else f[f != pos] for k, f in enumerate(free)]
        start = _start_of(current)
        current = _run_at(
            start, setup, observations, new_cams, free, opts, keep, False, should_stop
        )
        cams = new_cams
        changed = True
    if changed:
        keep = np.ones(len(observations), dtype=bool)
        start = _start_of(current)
        run = _run_at(start, setup, observations, cams, free, opts, keep, True, should_stop)
    return run


_Start = tuple[Array, Array, "Array | None", "float | None"]


def _start_of(run: _Run) -> _Start:
    """The solution of ``run`` as the start of the next: orientations (m, rad), object points
    (frame units), mount corrections and timing offset (s; None where not estimated)."""
    x = run.result.x
    mnt = x[run.lay.mount] if run.lay.mount is not None else None
    dt = float(x[run.lay.timing]) if run.lay.timing >= 0 else None
    return x[run.lay.eo], x[run.lay.points], mnt, dt


def _run_at(
    start: _Start,
    setup,
    observations: ImageObservations,
    cams: list[Camera],
    free: list[NDArray[np.intp]],
    opts: BundleOptions,
    keep: NDArray[np.bool_],
    full: bool,
    should_stop: Callable[[], bool] | None,
) -> _Run:
    """One adjustment (:func:`.bundle_model._run`) from ``start`` (:func:`_start_of`): the
    full model (``opts.robust`` and ``opts.snooping``) when ``full``, else plain least squares
    without data snooping (the AP-selection runs)."""
    eo, xyz, mount, dt = start
    robust, snooping = (opts.robust, opts.snooping) if full else ("none", False)
    return _run(
        setup, observations, cams, free, opts, keep, robust, snooping, eo, xyz, mount,
        should_stop, None, dt,
    )  # fmt: skip


def _exposure_velocity(
    setup,
    eo: ExteriorOrientationTable,
    velocity: ExposureVelocities | None,
    source: str,
    with_lever_arm: bool,
) -> Array:
    """(M, 3) velocities of the exposures in the adjustment frame, m/s: the EO table's, or
    differenced from the observed centres of each group by the EO's time; with the lever arm
    estimated, a camera-frame velocity that is one at every image is refused, naming dt and
    the lever-arm component it trades with."""
    vel = _velocity_local(setup, eo, velocity, source)
    if with_lever_arm:
        r_cl = np.swapaxes(opk_to_matrix(*setup.eo_obs[:, 3:].T), 1, 2)
        trade = timing_trade(*timing_separability(vel, r_cl), TIMING_NAME, LEVER_NAMES, "camera")
        if trade is not None:
            raise trade
    return vel


def _velocity_local(
    setup, eo: ExteriorOrientationTable, velocity: ExposureVelocities | None, source: str
) -> Array:
    if velocity is not None:
        if velocity.values.shape != (len(eo), 3) or not np.isfinite(velocity.values).all():
            raise InputError(
                "the exposure velocities must be finite, three per image", path=source or None
            )
        return local_velocity(velocity, eo.xyz, setup.local)
    if not np.isfinite(eo.time).all():
        raise InputError(
            "estimating the camera timing offset needs the velocity of every "
            "exposure: velocity columns (v_north, v_east, v_up or vx, vy, vz) or "
            "a time for every image (differenced within each group)",
            path=source or None,
        )
    return difference_velocity(eo.time, eo.group, setup.eo_obs[:, :3], "the timing offset")


def compare_ap_models(
    models: Sequence[str],
    run_one: Callable[[str], BundleResult],
) -> tuple[list[dict[str, object]], dict[str, BundleResult]]:
    """Run the bundle once per AP family and tabulate the comparison (Table 1 of Lima,
    Debiasi & Menezes: mean, standard deviation and RMS of the planimetric check-point
    discrepancies, with sigma0 and the AP counts), sorted by check-point RMS.

    ``run_one(model)`` runs the bundle with that family. Families whose adjustment fails
    (not observable) are listed with the reason instead of numbers.
    """
    rows: list[dict[str, object]] = []
    results: dict[str, BundleResult] = {}
    for m in models:
        try:
            res = run_one(m)
        except NotObservableError as exc:
            rows.append({"model": m, "error": str(exc)})
            continue
        results[m] = res
        rows.append(res.summary_row())

    def key(r: dict) -> tuple:
        v = r.get("rms_3d", math.nan)  # 3D: the check points are surveyed in 3D
        s = r.get("sigma0", math.nan)
        return (
            0 if "error" not in r else 1,
            v if isinstance(v, float) and math.isfinite(v) else math.inf,
            s if isinstance(s, float) else math.inf,
        )

    rows.sort(key=key)
    for rank, r in enumerate(rows, 1):
        r["rank"] = rank if "error" not in r else None
    return rows, results
