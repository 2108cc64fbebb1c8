"""CSV tables of terrestrial laser scanner networks (docs/formats.md, "TLS tables").

Observations, one row per station, target and face, in polar form::

    station_id,target_id,range,hz_deg,vt_deg[,s_range,s_hz,s_vt]

range and s_range in metres; the angles in degrees (columns ``hz_deg, vt_deg``), gon
(``hz_gon, vt_gon``) or in the unit given by the caller (``hz, vt``); ``vt`` is the elevation
above the scanner's horizontal plane (a value beyond +-90 degrees is a face-II reading);
s_hz and s_vt in arc-seconds. Or in scanner-frame Cartesian form (the target centres of a
target fit)::

    station_id,target_id,x,y,z[,s_x,s_y,s_z][,cov_xy,cov_xz,cov_yz]

metres (covariances m^2), converted to polar form with the covariance propagated. Missing
sigma columns take the caller's defaults. A range (or a centre's distance from the scanner)
must be > 0 and within :data:`~.scans.MAX_SCANNER_RANGE_M`.

Control (optional): ``target_id,X,Y,Z[,s_X,s_Y,s_Z]`` (object frame, metres; a sigma of 0
holds the coordinate fixed; no sigma columns: fixed).

The writers of a calibration's tables take ``comments``: lines written first as ``# text``
(the warnings of a doubtful calibration the user accepted; the readers skip them).

Stations (optional): ``station_id[,X,Y,Z][,omega_deg,phi_deg,kappa_deg][,levelled]``:
approximate positions (m) and angles (degrees), the compensator's omega, phi of a levelled
station, and ``levelled`` (1/0, true/false; empty: the run's default).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..errors import InputError
from ..tls.aps import ARCSEC
from ..tls.calibration import TlsCalibration
from ..tls.network import ControlTarget, StationInfo, TlsObservations
from ..tls.polar import polar_covariance
from .scans import MAX_SCANNER_RANGE_M
from .tables import (
    PathLike,
    Table,
    find_column,
    float_column,
    number,
    read_table,
    refuse_rows,
    sigma_column,
    text_column,
    unique_ids,
    write_csv_atomic,
)

__all__ = [
    "ANGLE_UNITS",
    "AP_COLUMNS",
    "RESIDUAL_COLUMNS",
    "STATION_COLUMNS",
    "TARGET_COLUMNS",
    "read_tls_control_csv",
    "read_tls_observations_csv",
    "read_tls_stations_csv",
    "write_tls_aps_csv",
    "write_tls_control_csv",
    "write_tls_observations_csv",
    "write_tls_residuals_csv",
    "write_tls_stations_csv",
    "write_tls_targets_csv",
]

#: Radians per unit of the angle columns.
ANGLE_UNITS = {"degrees": math.pi / 180.0, "gon": math.pi / 200.0, "radians": 1.0}
_FULL_CIRCLE = {"degrees": 360.0, "gon": 400.0, "radians": 2 * math.pi}

STATION_COLUMNS = (
    "station_id",
    "X",
    "Y",
    "Z",
    "omega_deg",
    "phi_deg",
    "kappa_deg",
    "s_X",
    "s_Y",
    "s_Z",
    "s_omega_arcsec",
    "s_phi_arcsec",
    "s_kappa_arcsec",
    "levelled",
    "targets",
)
AP_COLUMNS = (
    "name",
    "formula",
    "cause",
    "unit",
    "value",
    "std",
    "std_prior",
    "t",
    "significant",
)
TARGET_COLUMNS = ("target_id", "X", "Y", "Z", "s_X", "s_Y", "s_Z", "kind", "stations")
RESIDUAL_COLUMNS = (
    "station_id",
    "target_id",
    "face",
    "v_range_mm",
    "v_hz_arcsec",
    "v_vt_arcsec",
    "w_range",
    "w_hz",
    "w_vt",
    "rejected",
    "row",
)


def _ids(table: Table, aliases: Sequence[str], what: str) -> tuple[str, ...]:
    return text_column(table, find_column(table, aliases, what=what))


def _optional(table: Table, aliases: Sequence[str], default: float) -> np.ndarray:
    values = sigma_column(table, aliases, default)
    return np.full(len(table), float(default)) if values is None else values


def _angle(table: Table, stem: str, unit: str) -> tuple[np.ndarray, str]:
    """An angle column in radians: ``<stem>_deg``, ``<stem>_gon`` or ``<stem>`` in ``unit``."""
    names = ((stem + "_deg", "degrees"), (stem + "_gon", "gon"), (stem + "_rad", "radians"))
    found = [
        (col, u)
        for name, u in (*names, (stem, unit))
        if (col := find_column(table, (name,), required=False)) is not None
    ]
    if not found:
        raise InputError(
            f"no column for the {'horizontal direction' if stem == 'hz' else 'vertical angle'} "
            f"(accepted names: {stem}_deg, {stem}_gon, {stem}_rad, {stem}; found: "
            f"{', '.join(table.columns)})",
            path=table.path,
        )
    col, u = found[0]
    values = float_column(table, col)
    full = _FULL_CIRCLE[u]
    # A horizontal direction is within one turn and an elevation within half a turn (face
    # II: three quarters): a value beyond that is in another unit (gon read as degrees).
    limit = full if stem == "hz" else 0.75 * full
    refuse_rows(
        table,
        np.abs(values) > limit,
        col,
        lambda k: (
            f"{values[k]:g} is beyond {limit:g} {u}: the angles are not in {u} (gon read "
            "as degrees?). Name the column hz_deg/vt_deg or hz_gon/vt_gon, or choose the angle unit"
        ),
    )
    return values * ANGLE_UNITS[u], u


def _check_ranges(t: Table, rho: np.ndarray, what: str, col: int | None) -> None:
    """Distances from the scanner (m) that are > 0 and within a scanner's reach."""
    refuse_rows(
        t, rho <= 0, col, lambda k: f"{what} is {rho[k]:g} m from the scanner: it must be > 0"
    )
    refuse_rows(
        t,
        rho > MAX_SCANNER_RANGE_M,
        col,
        lambda k: (
            f"{what} is {rho[k]:g} m from the scanner, beyond the {MAX_SCANNER_RANGE_M:g} "
            "m a terrestrial scanner reaches: another unit, or coordinates that are not in the "
            "scanner's frame"
        ),
    )


def read_tls_observations_csv(
    path: PathLike,
    angle_unit: str = "degrees",
    default_sigmas: Sequence[float] = (0.002, 10.0, 10.0),
) -> TlsObservations:
    """Read an observation table (polar or scanner-frame x, y, z; see the module text).

    Parameters
    ----------
    angle_unit : {"degrees", "gon", "radians"}
        Unit of angle columns named ``hz`` and ``vt`` (``hz_deg``, ``hz_gon`` say their own).
    default_sigmas : (float, float, float)
        Range (m) and horizontal, vertical (arc-seconds) sigmas for rows without them; in
        the x, y, z form: the range sigma is used for each coordinate.
    """
    if angle_unit not in ANGLE_UNITS:
        raise InputError(f"angle unit must be one of {', '.join(ANGLE_UNITS)}, got {angle_unit!r}")
    t = read_table(path)
    station = _ids(t, ("station_id", "station", "scan", "setup"), "the station id")
    target = _ids(t, ("target_id", "target", "point_id", "id"), "the target id")
    rows = np.asarray(t.line_numbers, dtype=np.int64)
    s_r, s_h, s_v = (float(x) for x in default_sigmas)
    xcol = find_column(t, ("x",), required=False)
    rcol = find_column(t, ("range", "distance", "rho", "slope_distance"), required=False)
    if rcol is None and xcol is not None:
        xyz = np.column_stack(
            [float_column(t, find_column(t, (c,), what=c)) for c in ("x", "y", "z")]
        )
        sig = np.column_stack([_optional(t, (f"s_{c}", f"sigma_{c}"), s_r) for c in "xyz"])
        cov = np.einsum("ni,ij->nij", sig**2, np.eye(3))
        for (i, j), name in (((0, 1), "cov_xy"), ((0, 2), "cov_xz"), ((1, 2), "cov_yz")):
            col = find_column(t, (name,), required=False)
            if col is not None:  # the full covariance of a target fit (extracttlstargets)
                c = float_column(t, col, allow_empty=True)
                cov[:, i, j] = cov[:, j, i] = np.nan_to_num(c)
        for k in range(len(t)):
            if np.linalg.eigvalsh(cov[k])[0] <= 0:
                raise InputError(
                    "the covariance of (x, y, z) is not positive definite",
                    path=t.path,
                    row=int(rows[k]),
                )
        # hypot: no overflow for a coordinate of 1e300
        _check_ranges(t, np.hypot(np.hypot(xyz[:, 0], xyz[:, 1]), xyz[:, 2]), "the point", None)
        polar, pcov = polar_covariance(xyz, cov)
    else:
        if rcol is None:
            raise InputError(
                "no column for the range (accepted names: range, distance, rho) nor for "
                f"scanner-frame x, y, z (found: {', '.join(t.columns)})",
                path=t.path,
            )
        rng = float_column(t, rcol)
        _check_ranges(t, rng, "the range", rcol)
        hz, _ = _angle(t, "hz", angle_unit)
        vt, _ = _angle(t, "vt", angle_unit)
        polar = np.column_stack([rng, hz, vt])
        sr = _optional(t, ("s_range", "sigma_range", "s_rho"), s_r)
        sh = _optional(t, ("s_hz", "sigma_hz"), s_h) * ARCSEC
        sv = _optional(t, ("s_vt", "sigma_vt"), s_v) * ARCSEC
        pcov = np.einsum("ni,ij->nij", np.column_stack([sr, sh, sv]) ** 2, np.eye(3))
    return TlsObservations(station, target, polar, pcov, rows, str(path))


def read_tls_control_csv(path: PathLike) -> list[ControlTarget]:
    """Read control targets ``target_id,X,Y,Z[,s_X,s_Y,s_Z]`` (m; sigma 0 or absent: fixed)."""
    t = read_table(path)
    ids = unique_ids(
        t, find_column(t, ("target_id", "target", "id", "point_id"), what="the target id")
    )
    xyz = np.column_stack(
        [float_column(t, find_column(t, (c.lower(),), what=c)) for c in ("X", "Y", "Z")]
    )
    sig = np.column_stack([_optional(t, (f"s_{c}", f"sigma_{c}"), 0.0) for c in "xyz"])
    return [ControlTarget(i, xyz[k], sig[k], t.line_numbers[k]) for k, i in enumerate(ids)]


def _flag(cell: str, t: Table, k: int, col: int) -> bool | None:
    c = cell.strip().lower()
    if not c:
        return None
    if c in ("1", "true", "yes", "y"):
        return True
    if c in ("0", "false", "no", "n"):
        return False
    raise InputError(
        f"'{cell}' is not a yes/no value (1/0, true/false)",
        path=t.path,
        row=t.line_numbers[k],
        column=t.columns[col],
    )


def read_tls_stations_csv(path: PathLike) -> list[StationInfo]:
    """Read the stations table (see the module text); every column but the id is optional,
    and an empty cell means unknown."""
    t = read_table(path)
    ids = unique_ids(
        t, find_column(t, ("station_id", "station", "scan", "setup", "id"), what="the station id")
    )

    def group(names: Sequence[str], scale: float) -> np.ndarray | None:
        cols = [find_column(t, (n,), required=False) for n in names]
        if all(c is None for c in cols):
            return None
        if any(c is None for c in cols):
            raise InputError(f"give all of {', '.join(names)} or none", path=t.path)
        given = [c for c in cols if c is not None]  # all of them
        return np.column_stack([float_column(t, c, allow_empty=True) for c in given]) * scale

    xyz = group(("x", "y", "z"), 1.0)
    opk = group(("omega_deg", "phi_deg", "kappa_deg"), math.pi / 180.0)
    lcol = find_column(t, ("levelled", "leveled", "compensator"), required=False)
    out = []
    for k, sid in enumerate(ids):
        p = None if xyz is None or np.isnan(xyz[k]).any() else xyz[k]
        a = None if opk is None or np.isnan(opk[k]).any() else opk[k]
        lev = None if lcol is None else _flag(t.rows[k][lcol], t, k, lcol)
        out.append(StationInfo(sid, p, a, lev, t.line_numbers[k]))
    return out


def write_tls_stations_csv(
    path: PathLike, cal: TlsCalibration, comments: Sequence[str] = ()
) -> None:
    """Adjusted station poses with a-posteriori sigmas (:data:`STATION_COLUMNS`)."""
    obs = cal.observations
    counts = {
        s: len({t for st, t in zip(obs.station, obs.target) if st == s}) for s in cal.stations
    }
    rows = []
    for k, s in enumerate(cal.stations):
        p, sd = cal.pose[k], cal.pose_std[k]
        rows.append(
            (
                s,
                *map(number, p[:3]),
                *map(number, np.degrees(p[3:])),
                *map(number, sd[:3]),
                *map(number, sd[3:] / ARCSEC),
                int(cal.levelled[k]),
                counts[s],
            )
        )
    write_csv_atomic(path, STATION_COLUMNS, rows, comments)


def write_tls_aps_csv(path: PathLike, cal: TlsCalibration, comments: Sequence[str] = ()) -> None:
    """The additional parameters in report units (:data:`AP_COLUMNS`)."""
    rows = [
        (
            a["name"],
            a["formula"],
            a["cause"],
            a["unit"],
            number(a["value"]),
            number(a["std"]),
            number(a["std_prior"]),
            number(a["t"]),
            int(a["significant"]),
        )
        for a in cal.ap_report()
    ]
    write_csv_atomic(path, AP_COLUMNS, rows, comments)


def write_tls_targets_csv(
    path: PathLike, cal: TlsCalibration, comments: Sequence[str] = ()
) -> None:
    """Adjusted target coordinates with sigmas (:data:`TARGET_COLUMNS`)."""
    obs = cal.observations
    seen: dict[str, set[str]] = {}
    for s, t in zip(obs.station, obs.target):
        seen.setdefault(t, set()).add(s)
    rows = [
        (
            t,
            *map(number, cal.target_xyz[k]),
            *map(number, cal.target_std[k]),
            cal.target_kind[k],
            len(seen.get(t, ())),
        )
        for k, t in enumerate(cal.targets)
    ]
    write_csv_atomic(path, TARGET_COLUMNS, rows, comments)


def write_tls_residuals_csv(
    path: PathLike, cal: TlsCalibration, comments: Sequence[str] = ()
) -> None:
    """Residuals (adjusted minus observed) per component, Baarda's w and the rejection flag
    (:data:`RESIDUAL_COLUMNS`); ``row`` is the observation's row in its file."""
    obs = cal.observations
    face = obs.face_two
    v, w = cal.residuals, cal.w
    rows = [
        (
            obs.station[k],
            obs.target[k],
            "II" if face[k] else "I",
            number(v[k, 0] * 1000.0),
            number(v[k, 1] / ARCSEC),
            number(v[k, 2] / ARCSEC),
            *map(number, w[k]),
            int(cal.rejected[k]),
            int(obs.rows[k]),
        )
        for k in range(len(obs))
    ]
    write_csv_atomic(path, RESIDUAL_COLUMNS, rows, comments)


def write_tls_observations_csv(
    path: PathLike, obs: TlsObservations, angle_unit: str = "degrees"
) -> None:
    """An observation table in polar form (``hz_deg, vt_deg`` or ``hz_gon, vt_gon``), the
    sigmas from the diagonal of each covariance (m, arc-seconds)."""
    suffix = {"degrees": "deg", "gon": "gon", "radians": "rad"}[angle_unit]
    scale = 1.0 / ANGLE_UNITS[angle_unit]
    sig = np.sqrt(np.einsum("nii->ni", obs.cov))
    rows = [
        (
            obs.station[k],
            obs.target[k],
            number(obs.polar[k, 0]),
            number(obs.polar[k, 1] * scale),
            number(obs.polar[k, 2] * scale),
            number(sig[k, 0]),
            number(sig[k, 1] / ARCSEC),
            number(sig[k, 2] / ARCSEC),
        )
        for k in range(len(obs))
    ]
    columns = (
        "station_id",
        "target_id",
        "range",
        f"hz_{suffix}",
        f"vt_{suffix}",
        "s_range",
        "s_hz",
        "s_vt",
    )
    write_csv_atomic(path, columns, rows)


def write_tls_control_csv(path: PathLike, control: Sequence[ControlTarget]) -> None:
    """A control table ``target_id,X,Y,Z,s_X,s_Y,s_Z`` (m)."""
    rows = [(c.id, *map(number, c.xyz), *map(number, c.sigma)) for c in control]
    write_csv_atomic(path, ("target_id", "X", "Y", "Z", "s_X", "s_Y", "s_Z"), rows)
