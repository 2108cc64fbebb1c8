"""``tlscalibration``: register terrestrial laser scanner stations and calibrate the scanner.

Outputs: the adjusted station poses with sigmas, the additional parameters (APs) with sigmas
and significance, the target coordinates, the residuals per component (docs/formats.md,
"TLS tables"), an HTML report with the correlation matrix and, optionally, the scans written
into the common frame (:data:`REGISTERED_NAME` in OUTPUT_FOLDER).
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

from ..i18n import joined as _joined
from ..i18n import mark as _t
from ..io.suffixes import SCAN_SUFFIXES
from .common import csv_out, doubt_params, html_out, settle_doubts, table_param
from .runner import JobResult
from .spec import AlgorithmSpec, Fields, Param, Ref, Result, Values, options_from

log = logging.getLogger(__name__)
TR_CONTEXT = "Report"

_D = Fields("tls.options", "CalibrationOptions")


def _arcsec(radians: float) -> float:
    from ..tls.ap_table import ARCSEC

    return radians / ARCSEC


ANGLE_UNITS = ("degrees", "gon", "radians")
DATUMS = ("inner", "reference")
#: Name of station ``<station_id>``'s registered scan in OUTPUT_FOLDER (its suffix: .laz for
#: a LAZ scan, .las for the others).
REGISTERED_NAME = "{}_registered{}"

SPEC = AlgorithmSpec(
    name="tlscalibration",
    title="TLS registration and self-calibration",
    group="Laser scanning",
    group_id="laserscanning",
    summary="register laser scanner stations on targets and estimate the scanner's "
    "systematic errors",
    description="""\
One least-squares adjustment of all stations and targets (Carvalho, Correa & dos Santos,
Eq. 1): each station's position and omega, phi, kappa, the targets' coordinates and the
scanner's additional parameters (APs) in polar form (Eqs. 2-5): the paper's set a0 (range
offset), b1 sec(alpha) (collimation), b2 tan(alpha) (trunnion axis), c0 (vertical index), or
Lichti's (2007) extended set (range scale and cyclic terms, circle eccentricities, encoder
errors). AP set none: registration only.

Observations (CSV): station_id,target_id,range,hz_deg,vt_deg[,s_range,s_hz,s_vt] (metres,
degrees, elevation angle; a vertical angle beyond +-90 deg is a face-II reading; sigmas in m
and arc-seconds), or hz_gon/vt_gon, or hz/vt in ANGLE UNIT; or scanner-frame target centres
station_id,target_id,x,y,z[,s_x,s_y,s_z]. Rows without sigmas take DEFAULT SIGMAS.

Control (optional): target_id,X,Y,Z[,s_X,s_Y,s_Z] (sigma 0 or none: fixed); it defines the
datum. Without control the datum is inner constraints on the targets (free network) or the
reference station. Stations (optional): station_id, approximate X,Y,Z and omega_deg,
phi_deg,kappa_deg, levelled (1/0). A levelled station's omega and phi are compensator
observations with TILT SIGMA; others are free.

The report gives sigma0 and the global test, Baarda's data snooping, each AP's t-test, the
correlation matrix of APs and station parameters with the strongly correlated pairs named and
the network design that separates them (Lichti 2010: targets over the full vertical range,
two faces, stations tilted by 90 degrees). SELECT APS removes correlated and insignificant
terms one by one. A parameter the network cannot determine is an error that says why.

Registered clouds (optional): SCANS are the stations' scans (LAS/LAZ, PLY, E57; points in
the scanner frame; the station id is the file name without its suffix, as in Extract TLS
targets). Each is written to OUTPUT_FOLDER as <station_id>_registered.laz (LAZ scans) or
.las (the others) with its points in the common frame, X = M' d + X0 with the adjusted
pose: the control's frame; without control the reference station's (its pose in the stations
table, else the origin unrotated), held exactly (DATUM reference) or on average over the
targets (inner constraints). With APs estimated and APPLY APS on,
each point's recorded polar coordinates are corrected by the estimated APs before the
pose is applied, taken as face-I readings (elevation within +-90 deg): turn it off for
scans that mix both faces (a panoramic scanner's second half-turn), which then get the
rigid pose only. LAS/LAZ scans are streamed in chunks (every dimension and VLR kept);
PLY/E57 scans are read whole. All files appear together or none (a bad scan: none).

## Checks of the result
The run fails (nothing is written but the HTML report, which says why) when the adjustment
did not converge, when its global test fails with sigma0 above MAX SIGMA0, or when data
snooping rejected more observations than its false alarms explain (the upper tail of their
binomial count below 0.001: a model that does not fit the data, e.g. APs missing, or many
blunders; the global test of the observations left then proves nothing). With ACCEPT
DOUBTFUL the outputs are written and each table starts with a warning (comment lines
beginning with #).""",
    params=(
        table_param("OBSERVATIONS", "Observations (CSV)"),
        table_param("CONTROL", "Control targets (CSV)", optional=True),
        table_param(
            "STATIONS",
            "Stations (CSV)",
            optional=True,
            help="approximate poses, compensator tilts, levelled flags; when given, every "
            "observed station must be in it",
        ),
        Param(
            "ANGLE_UNIT",
            "enum",
            "Angle unit of hz/vt columns",
            "degrees",
            options=ANGLE_UNITS,
            help="only for columns named hz and vt; hz_deg/hz_gon say their own unit",
        ),
        Param(
            "DEFAULT_SIGMAS",
            "numbers",
            "Default sigmas: range, horizontal, vertical",
            (2.0, 10.0, 10.0),
            count=3,
            unit="mm, arcsec, arcsec",
            minimum=1e-6,
            maximum=1e6,
            help="for rows without s_range, s_hz, s_vt (or s_x, s_y, s_z: the range sigma)",
            advanced=True,
        ),
        Param(
            "AP_SET",
            "enum",
            "Additional parameters",
            _D.ap_set,
            options=Ref("tls.ap_table", "AP_SETS", convert=tuple),
            labels=(
                "none (registration only)",
                "paper: a0, b1, b2, c0",
                "extended (Lichti 2007): a0-a3, b1-b6, c0-c3",
            ),
        ),
        Param(
            "AP_TERMS",
            "string",
            "AP terms (overrides the set)",
            "",
            optional=True,
            help="comma-separated, e.g. a0,b1,b2,c0,a1",
            advanced=True,
        ),
        Param(
            "SELECT_APS",
            "boolean",
            "Select the APs by significance and correlation",
            _D.select_aps,
            advanced=True,
        ),
        Param(
            "LEVELLED",
            "boolean",
            "Stations levelled by the compensator",
            _D.levelled,
            help="default for stations whose table does not say",
        ),
        Param(
            "TILT_SIGMA",
            "number",
            "Compensator sigma",
            Ref("tls.options", "CalibrationOptions", "tilt_sigma_rad", convert=_arcsec),
            unit="arcsec",
            minimum=0.01,
            maximum=36000.0,
            advanced=True,
        ),
        Param(
            "DATUM",
            "enum",
            "Datum without control",
            _D.datum,
            options=DATUMS,
            labels=(
                "inner constraints on the targets (free network)",
                "reference station held at its pose",
            ),
            advanced=True,
        ),
        Param(
            "REFERENCE_STATION",
            "string",
            "Reference station",
            "",
            optional=True,
            advanced=True,
            help="default: the first station of the stations table with a "
            "position, else the first observed",
        ),
        Param(
            "CYCLIC_WAVELENGTH",
            "number",
            "Wavelength of the cyclic range terms",
            _D.cyclic_wavelength_m,
            unit="m",
            minimum=0.01,
            maximum=1000.0,
            advanced=True,
        ),
        Param("SNOOPING", "boolean", "Data snooping (Baarda)", _D.snooping, advanced=True),
        Param(
            "CORRELATION_LIMIT",
            "number",
            "Strong correlation at |r| >=",
            _D.correlation_limit,
            minimum=0.1,
            maximum=1.0,
            advanced=True,
        ),
        *doubt_params(
            "a failed global test with sigma0 above this fails the run (wrong sigmas, a model "
            "that does not fit, or blunders data snooping did not catch)",
            "no convergence, global test beyond MAX_SIGMA0 or more rejections than data "
            "snooping's false alarms explain: write the outputs anyway, each table with a "
            "warning at its top",
        ),
        Param(
            "SCANS",
            "files",
            "Scans to register (LAS/LAZ, PLY, E57; one station per file)",
            optional=True,
            suffixes=SCAN_SUFFIXES,
            help="the file name without its suffix is the station id",
        ),
        Param(
            "APPLY_APS",
            "boolean",
            "Correct the scan points by the estimated APs",
            True,
            help="face-I readings; off: the rigid pose only",
            advanced=True,
        ),
        csv_out("OUTPUT_STATIONS", "Station poses (CSV)", optional=False),
        csv_out("OUTPUT_APS", "Additional parameters (CSV)", optional=False),
        csv_out("OUTPUT_TARGETS", "Target coordinates (CSV)"),
        csv_out("OUTPUT_RESIDUALS", "Residuals (CSV)", on_demand=True, advanced=True),
        html_out("OUTPUT_HTML", "Report (HTML)", optional=False),
        Param(
            "OUTPUT_FOLDER",
            "folder_out",
            "Registered scans (folder)",
            optional=True,
            create_by_default=False,
            help="needs SCANS",
        ),
    ),
    results=(
        Result("SIGMA0", "number", "Sigma0 a-posteriori"),
        Result("REGISTERED", "number", "Registered scans written"),
        Result("REJECTED", "number", "Observations rejected"),
        Result("APS", "string", "Additional parameters estimated"),
    ),
    tags=(
        "tls",
        "terrestrial laser scanner",
        "self-calibration",
        "registration",
        "additional parameters",
        "targets",
    ),
    references=("Carvalho, Correa & dos Santos", "Lichti (2007)", "Lichti (2010)", "Baarda (1968)"),
)


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read the tables, adjust, check the result, write the outputs."""
    from ..lsq.results import rejection_test
    from ..quality.tls_html import render_tls_html
    from ..tls.aps import ARCSEC
    from ..tls.calibration import calibrate
    from ..tls.network import check_distance_consistency
    from ..tls.options import CalibrationOptions

    scans = _check_scans(v)
    obs, control, stations = _read_inputs(v, scans)
    median = check_distance_consistency(obs, path=v.observations)
    aps = v.ap_terms.strip() if v.ap_terms else v.ap_set
    options = options_from(
        CalibrationOptions,
        SPEC,
        v,
        ap_set=aps,
        tilt_sigma_rad=v.tilt_sigma * ARCSEC,
        reference_station=v.reference_station or None,
    )
    cal = calibrate(obs, control, stations, options, progress=progress, should_stop=should_stop)
    settings = _settings(v, obs, control, aps, options, median)
    rejections = rejection_test(cal.adjustment, options.snooping_alpha) if v.snooping else None
    doubts = doubts_about(cal, v.max_sigma0, rejections)
    warning = settle_doubts(
        "TLS calibration",
        doubts,
        v.accept_doubtful,
        out,
        lambda: render_tls_html(cal, settings, doubts, accepted=False, rejections=rejections),
    )
    _write_outputs(out, cal, settings, doubts, rejections, warning)
    registered = _write_registered(v, scans, cal, out, should_stop) if scans else []
    return JobResult(
        results={
            "SIGMA0": cal.sigma0,
            "REJECTED": int(cal.rejected.sum()),
            "APS": ",".join(cal.ap_names),
            "REGISTERED": len(registered),
        },
        lines=_summary_lines(cal, rejections, registered, warning),
        data=cal,
    )


def _read_inputs(v: Values, scans: list) -> tuple:
    """The observations, control and stations tables, checked against each other (every
    scan, and every listed station, has observations; every observed station is listed)."""
    from ..errors import InputError
    from ..io.tls import read_tls_control_csv, read_tls_observations_csv, read_tls_stations_csv

    s_range_mm, s_hz, s_vt = v.default_sigmas
    obs = read_tls_observations_csv(v.observations, v.angle_unit, (s_range_mm / 1000.0, s_hz, s_vt))
    control = read_tls_control_csv(v.control) if v.control else []
    stations = read_tls_stations_csv(v.stations) if v.stations else []
    if scans:
        observed = set(obs.station)
        for f in scans:
            if f.stem not in observed:
                raise InputError(
                    f"SCANS: the scan's station '{f.stem}' (its file name) has "
                    f"no observations in {v.observations}",
                    path=str(f),
                )
    if stations:
        listed = {s.id for s in stations}
        for k, s in enumerate(obs.station):
            if s not in listed:
                raise InputError(
                    f"station '{s}' is not in the stations table {v.stations}", **obs.where(k)
                )
        observed = set(obs.station)
        for s in stations:
            if s.id not in observed:
                raise InputError(
                    f"station '{s.id}' has no observations in {v.observations}",
                    path=v.stations,
                    row=s.row or None,
                )
    for c in control:
        if c.id not in set(obs.target):
            log.warning("control target '%s' (%s, row %d) is not observed", c.id, v.control, c.row)
    return obs, control, stations


def _settings(v: Values, obs, control, aps: str, options, median: float) -> dict:
    """The settings shown in the report."""
    return {
        "observations": f"{v.observations} ({len(obs)} rows, {len(obs.stations())} stations, "
        f"{len(obs.targets())} targets, {int(obs.face_two.sum())} in face II)",
        "control": f"{v.control} ({len(control)} targets)" if v.control else "none",
        "stations table": v.stations or "none",
        "additional parameters": f"{aps}" + (" with automatic selection" if v.select_aps else ""),
        "levelled by default": f'{v.levelled} (compensator sigma {v.tilt_sigma:g}")',
        "datum without control": v.datum,
        "data snooping": f"Baarda, alpha = {options.snooping_alpha:g} per observation"
        if v.snooping
        else "off",
        "distance consistency between stations": "n/a"
        if not math.isfinite(median)
        else f"{median * 1e6:.0f} ppm (median)",
    }


def _write_outputs(out, cal, settings: dict, doubts: list, rejections, warning: list) -> None:
    """The requested tables and report of the accepted calibration."""
    from ..io.atomic import write_text_atomic
    from ..io.tls import (
        write_tls_aps_csv,
        write_tls_residuals_csv,
        write_tls_stations_csv,
        write_tls_targets_csv,
    )
    from ..quality.tls_html import render_tls_html

    if out.requested("OUTPUT_STATIONS"):
        write_tls_stations_csv(out.path("OUTPUT_STATIONS"), cal, warning)
    if out.requested("OUTPUT_APS"):
        write_tls_aps_csv(out.path("OUTPUT_APS"), cal, warning)
    if out.requested("OUTPUT_TARGETS"):
        write_tls_targets_csv(out.path("OUTPUT_TARGETS"), cal, warning)
    if out.requested("OUTPUT_RESIDUALS"):
        write_tls_residuals_csv(out.path("OUTPUT_RESIDUALS"), cal, warning)
    if out.requested("OUTPUT_HTML"):
        page = render_tls_html(cal, settings, doubts, accepted=True, rejections=rejections)
        write_text_atomic(out.path("OUTPUT_HTML"), page)


def _summary_lines(cal, rejections, registered: list, warning: list) -> list[str]:
    """The log's summary: the APs, the selection, strong correlations, the registered scans
    and the adjustment's figures."""
    lines = [*warning, f"{'AP':4} {'value':>10} {'sigma':>9} unit    t"]
    for a in cal.ap_report():
        lines.append(
            f"{a['name']:4} {a['value']:10.3f} {a['std']:9.3f} {a['unit']:7} "
            f"{a['t']:.1f}{'' if a['significant'] else ' (not significant)'}"
        )
    for s in cal.selection:
        lines.append(f"removed {s.removed}: {s.reason}")
    for a, b, r in cal.strong_pairs[:5]:
        lines.append(f"strong correlation {a} / {b}: {r:+.3f}")
    for path, n in registered:
        lines.append(f"registered scan {path}: {n} points")
    test = "passed" if cal.chi2_passed else "failed"
    if cal.chi2_passed and rejections is not None and not rejections.passed:
        test += (
            f" only after rejecting more observations than false alarms explain (at most "
            f"{rejections.bound})"
        )
    lines.append(
        f"sigma0 {cal.sigma0:.3f}, redundancy {cal.adjustment.redundancy}, global "
        f"test {test}, {int(cal.rejected.sum())} observations rejected"
    )
    return lines


def doubts_about(cal, max_sigma0: float, rejections) -> list:
    """Why the calibration's numbers cannot be trusted (empty when they can): no convergence,
    a global test failed with sigma0 above ``max_sigma0``, more rejections than data
    snooping's false alarms explain (``rejections``: :class:`~core.lsq.results.RejectionTest`,
    None without snooping), estimates that are not finite."""
    import numpy as np

    out = []
    adj = cal.adjustment
    if not adj.converged:
        out.append(_t("the adjustment did not converge after {n} iterations", n=adj.iterations))
    if not cal.chi2_passed and cal.sigma0 > max_sigma0:
        out.append(
            _t(
                "the global test failed with sigma0 = {sigma0:.3g} > MAX_SIGMA0 {maximum:g}: "
                "the observations are {sigma0:.3g} times less precise than their sigmas say "
                "(wrong sigmas, a model that does not fit, or undetected blunders)",
                sigma0=cal.sigma0,
                maximum=max_sigma0,
            )
        )
    if rejections is not None and not rejections.passed:
        out.append(rejections.message())
    bad = [n for n, x in zip(adj.names, adj.x) if not np.isfinite(x)]
    if bad:
        out.append(_t("not a finite number: {items}", items=_joined(bad[:10])))
    return out


def _check_scans(v: Values) -> list[Path]:
    """The scan files (folders expanded), checked before anything is computed."""
    from ..errors import InputError
    from .extract_tls_targets import _scan_files

    if not v.scans:
        if v.output_folder:
            raise InputError("OUTPUT_FOLDER (registered scans) needs SCANS")
        return []
    if not v.output_folder:
        raise InputError("SCANS are given but no OUTPUT_FOLDER to write them registered to")
    files = _scan_files(v.scans)
    for f in files:
        if not f.is_file():
            raise InputError("file not found", path=str(f))
    return files


def _write_registered(v: Values, scans, cal, out, should_stop) -> list[tuple[str, int]]:
    """Every scan in the common frame, written together (all or none); (path, points)."""
    from functools import partial

    from ..io.atomic import OutputSet
    from ..io.scans import write_registered_scan
    from ..tls.registration import scanner_to_object

    folder = Path(v.output_folder)
    targets = {}
    for f in scans:
        suffix = ".laz" if f.suffix.lower() == ".laz" else ".las"
        targets[f.stem] = folder / REGISTERED_NAME.format(f.stem, suffix)
    inputs = {
        "SCANS": [str(f) for f in scans],
        "OBSERVATIONS": v.observations,
        "CONTROL": v.control,
        "STATIONS": v.stations,
    }
    # outputs of this run are inputs too here: no scan may overwrite a table just written
    inputs.update(
        {
            k: str(out.target(k))
            for k in (
                "OUTPUT_STATIONS",
                "OUTPUT_APS",
                "OUTPUT_TARGETS",
                "OUTPUT_RESIDUALS",
                "OUTPUT_HTML",
            )
            if out.requested(k)
        }
    )
    at = {s: k for k, s in enumerate(cal.stations)}
    names = cal.ap_names if v.apply_aps else ()
    written = []
    with OutputSet({k: str(p) for k, p in targets.items()}, inputs) as files:
        for f in scans:
            transform = partial(
                scanner_to_object,
                pose=cal.pose[at[f.stem]],
                names=names,
                values=cal.ap,
                wavelength_m=cal.options.cyclic_wavelength_m,
            )
            n = write_registered_scan(f, files.path(f.stem), transform, should_stop=should_stop)
            log.info("%s: %d points registered to %s", f.name, n, targets[f.stem])
            written.append((str(targets[f.stem]), n))
        files.commit()
    return written
