"""``extracttlstargets``: target centres (spheres, checkerboards) from terrestrial laser scans,
with covariances and common ids: the observation table of ``tlscalibration``."""

from __future__ import annotations

import logging
from pathlib import Path

from ..io.suffixes import SCAN_SUFFIXES
from .common import csv_out, table_param
from .runner import JobResult, stages
from .spec import AlgorithmSpec, Param, Result, Values

log = logging.getLogger(__name__)

KINDS = ("sphere", "checkerboard")
#: Columns of the table written (docs/formats.md, "TLS tables"): the x, y, z form of the
#: observation table with the full covariance and the fit's figures.
COLUMNS = (
    "station_id",
    "target_id",
    "x",
    "y",
    "z",
    "s_x",
    "s_y",
    "s_z",
    "cov_xy",
    "cov_xz",
    "cov_yz",
    "kind",
    "n_points",
    "n_inliers",
    "rms_mm",
)

SPEC = AlgorithmSpec(
    name="extracttlstargets",
    title="Extract TLS targets from scans",
    group="Laser scanning",
    group_id="laserscanning",
    summary="sphere or checkerboard target centres with covariance from laser scans",
    description="""\
Finds the targets in each scan and writes their centres in the scanner frame with their
3 x 3 covariance: the observation table of TLS registration and self-calibration.

Scans: one station per file (LAS/LAZ, PLY, or E57 with the optional pye57 package), points
in the scanner's own frame in metres (the scanner at the origin, as exported for a single
station, not registered); the station id is the file name without its suffix.

Spheres of a known radius: every point votes for the centre along its normal, the peaks are
verified by RANSAC (Fischler & Bolles 1981) and a least-squares fit with each point's
covariance (range along the beam, angles across it). Checkerboards (2 x 2 pattern of a known
half size): RANSAC plane and a least-squares fit of the intensity pattern; their reported
sigma is 2-3 times optimistic on simulations (the centre itself within 0.5 mm).

Ids: targets are matched between scans by their mutual distances (a rigid motion keeps them),
and take the ids of CONTROL points when given (matched the same way).""",
    params=(
        Param(
            "SCANS",
            "files",
            "Scans (LAS/LAZ, PLY, E57; one station per file)",
            suffixes=SCAN_SUFFIXES,
        ),
        Param("KIND", "enum", "Target kind", "sphere", options=KINDS),
        Param("RADIUS", "number", "Sphere radius", 0.0725, unit="m", minimum=0.005, maximum=2.0),
        Param(
            "HALF_SIZE",
            "number",
            "Checkerboard half size",
            0.1,
            unit="m",
            minimum=0.01,
            maximum=2.0,
        ),
        Param(
            "SCAN_SIGMAS",
            "numbers",
            "Scan point noise: range, angle",
            (1.0, 4.0),
            count=2,
            unit="mm, arcsec",
            minimum=0.001,
            maximum=1e4,
        ),
        Param(
            "MATCH_TOLERANCE",
            "number",
            "Distance tolerance of the matching",
            0.02,
            unit="m",
            minimum=0.0001,
            maximum=10.0,
            advanced=True,
        ),
        table_param("CONTROL", "Control targets (CSV, for their ids)", optional=True),
        csv_out("OUTPUT", "Target observations (CSV)", optional=False),
    ),
    results=(Result("TARGETS", "number", "Target centres found (all scans)"),),
    tags=("tls", "terrestrial laser scanner", "targets", "spheres", "checkerboards", "ransac"),
    references=("Fischler & Bolles (1981)",),
)


def _scan_files(paths) -> list[Path]:
    from ..errors import InputError
    from ..io.scans import SCAN_SUFFIXES

    out: list[Path] = []
    for p in paths or ():
        q = Path(p)
        if q.is_dir():
            out += sorted(f for f in q.iterdir() if f.suffix.lower() in SCAN_SUFFIXES)
        else:
            out.append(q)
    if not out:
        raise InputError("SCANS: no scan files (LAS, LAZ, PLY, E57) given")
    stems = [f.stem for f in out]
    for s in stems:
        if stems.count(s) > 1:
            raise InputError(
                f"SCANS: two scans are named '{s}': the file name is the station "
                "id and must be unique"
            )
    return out


def run(v: Values, out, progress=None, should_stop=None) -> JobResult:
    """Read each scan, find its targets, label them across scans, write the table."""
    import numpy as np

    from ..errors import stop_if_asked
    from ..io.tables import write_csv_atomic
    from ..io.tls import read_tls_control_csv
    from ..tls.aps import ARCSEC
    from ..tls.correspondence import label_targets

    files = _scan_files(v.scans)
    s_range, s_angle = v.scan_sigmas[0] / 1000.0, v.scan_sigmas[1] * ARCSEC
    control = read_tls_control_csv(v.control) if v.control else []
    parts = stages(progress, *([1.0] * len(files)))
    fits = []
    for f, part in zip(files, parts):
        stop_if_asked(should_stop, f"reading {f.name}")
        fits.append(_targets_in(f, v, s_range, s_angle, part, should_stop))
    ctrl_ids = [c.id for c in control]
    ctrl_xyz = np.array([c.xyz for c in control]) if control else None
    ids = label_targets(
        [np.array([t.centre for t in fs]) for fs in fits], v.match_tolerance, ctrl_ids, ctrl_xyz
    )
    rows = _rows(files, fits, ids)
    if out.requested("OUTPUT"):
        write_csv_atomic(out.path("OUTPUT"), COLUMNS, rows)
    lines = [f"{f.name}: {len(fs)} {v.kind} targets" for f, fs in zip(files, fits)]
    return JobResult(results={"TARGETS": len(rows)}, lines=lines, data=(files, fits, ids))


def _targets_in(f: Path, v: Values, s_range: float, s_angle: float, progress, should_stop) -> list:
    """The targets of kind KIND found in scan ``f`` (scanner frame; range sigma in m, angle
    sigma in rad); InputError naming the scan when fewer than three are found."""
    import numpy as np

    from ..errors import InputError
    from ..io.scans import read_scan
    from ..tls.targets import detect_checkerboards, detect_spheres

    xyz, intensity = read_scan(f)
    if v.kind == "sphere":
        found = detect_spheres(
            xyz, v.radius, s_range, s_angle, progress=progress, should_stop=should_stop
        )
    else:
        if not np.isfinite(intensity).any():
            raise InputError(
                "checkerboards need the intensity of the points; the scan has none", path=str(f)
            )
        found = detect_checkerboards(
            xyz,
            intensity,
            v.half_size,
            s_range,
            s_angle,
            progress=progress,
            should_stop=should_stop,
        )
    log.info("%s: %d %s targets", f.name, len(found), v.kind)
    if len(found) < 3:
        raise InputError(
            f"found {len(found)} {v.kind} target(s) in the scan: at least "
            "three are needed to register it (check RADIUS / HALF_SIZE, "
            "SCAN_SIGMAS and that the points are in the scanner frame)",
            path=str(f),
        )
    return found


def _rows(files: list[Path], fits: list, ids: list) -> list[tuple]:
    """The output table's rows (COLUMNS): every target of every scan with its label."""
    rows = []
    for f, fs, names in zip(files, fits, ids):
        for t, name in zip(fs, names):
            c = t.cov
            rows.append(
                (
                    f.stem,
                    name,
                    *(repr(float(x)) for x in t.centre),
                    *(repr(float(x)) for x in t.sigma),
                    repr(float(c[0, 1])),
                    repr(float(c[0, 2])),
                    repr(float(c[1, 2])),
                    t.kind,
                    t.n_points,
                    t.n_inliers,
                    repr(float(t.rms * 1000.0)),
                )
            )
    return rows
