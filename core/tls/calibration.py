"""Simultaneous registration and self-calibration of a terrestrial laser scanner.

Model
-----
Every observation of target i from station j (one group of three rows) is, with
``d = M_j (X_i - X0_j)`` (:mod:`.network`) and its geometric polar form (:mod:`.polar`)::

    rho_obs   = |d| + d_rho(p)                               (Carvalho, Correa & dos
    theta_obs = theta_I(d) + d_theta(p)                       Santos, Eqs. 1-5; Lichti 2007)
    alpha_obs = alpha_I(d) + d_alpha(p)

with the instrument angles ``theta_I, alpha_I`` of the observation's face and the AP
corrections of :mod:`.aps`. Unknowns: the APs (shared by all stations: one instrument), the
six pose parameters of each station, and the coordinates of every target that is not held
fixed. Weighted observations besides the polar ones: the compensator's omega and phi of a
levelled station (``tilt_sigma_rad``), control coordinates with their sigmas. The datum is
the control when there is any; otherwise the reference station is held at its given pose
(position and kappa, and omega and phi when it is not levelled), and the network's scale
comes from the ranges.

The adjustment is :func:`core.lsq.adjustment.adjust` (Gauss-Markov, Levenberg-Marquardt,
Baarda data snooping of whole observations): sigma0, the global chi-square test, the
standard deviations and correlations of every parameter, residuals with redundancy numbers
and w-tests. A parameter the network cannot determine raises :class:`TlsNotObservable`,
whose ``diagnosis`` says which network design would determine it.

Correlations (Lichti 2010): the correlations between the APs and the station parameters are
reported with the pairs above a limit and why they arise (:func:`explain_pair`). With
``select_aps`` the APs are chosen by backward elimination: a pair of APs correlated beyond
the limit loses its less significant member, then the least significant AP below the
Student-t critical value goes, until every AP left is significant.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..errors import DiagnosedNotObservable, InputError, NotObservableError
from ..geometry.rotations import opk_derivatives, opk_to_matrix
from ..lsq.adjustment import adjust
from ..lsq.model import AdjustmentOptions, Constraint, GaussMarkovBlock, prior_block
from ..lsq.results import AdjustmentResult
from .aps import AP_TERMS, ap_basis, ap_terms
from .diagnosis import diagnose
from .network import (
    ControlTarget,
    StationInfo,
    TlsObservations,
    check_network,
    register_stations,
)
from .options import CalibrationOptions
from .polar import cartesian_to_polar, instrument_angles, polar_jacobian, wrap_angle

__all__ = [
    "POSE_NAMES",
    "CalibrationOptions",
    "SelectionStep",
    "TlsCalibration",
    "TlsNotObservable",
    "calibrate",
    "predict",
]

log = logging.getLogger(__name__)
Array = NDArray[np.float64]
POSE_NAMES = ("X", "Y", "Z", "omega", "phi", "kappa")


class TlsNotObservable(DiagnosedNotObservable):
    """A parameter the network cannot determine; ``diagnosis`` says what would fix it."""


@dataclass(frozen=True)
class SelectionStep:
    """One step of the automatic AP selection: which term went and why."""

    removed: str
    reason: str
    remaining: tuple[str, ...]


@dataclass
class TlsCalibration:
    """Result of :func:`calibrate`.

    Attributes
    ----------
    adjustment : AdjustmentResult
        The engine's full result (every parameter, residual tables, statistics).
    observations : TlsObservations
    ap_names : tuple of str
    ap : ndarray (K,)
        AP values in internal units (m, 1, rad).
    ap_std, ap_std_prior : ndarray (K,)
        A-posteriori (scaled by sigma0) and a-priori standard deviations.
    ap_t : ndarray (K,)
        ``|ap| / ap_std``.
    ap_significant : ndarray of bool (K,)
    t_critical : float
        Student-t critical value of the AP test.
    stations : list of str
    pose, pose_std : ndarray (S, 6)
        X0 (m) and omega, phi, kappa (rad) and their a-posteriori standard deviations.
    levelled : ndarray of bool (S,)
    datum_fixed : list of str
        Parameter names held by the datum constraints (empty with control).
    targets : list of str
    target_xyz, target_std : ndarray (T, 3)
    target_kind : list of str
        ``"fixed"``, ``"control"`` (weighted) or ``"free"``.
    residuals : ndarray (N, 3)
        Adjusted minus observed: range (m), horizontal and vertical angle (rad).
    w : ndarray (N, 3)
        Baarda's standardised residuals.
    rejected : ndarray of bool (N,)
    calib_names : list of str
        AP and station parameter names, the rows of ``calib_correlation``.
    calib_correlation : ndarray
    strong_pairs : list of (str, str, float)
        Pairs with ``|r| >= correlation_limit`` involving an AP (or, without APs, any pair),
        strongest first.
    selection : list of SelectionStep
    options : CalibrationOptions
    """

    adjustment: AdjustmentResult
    observations: TlsObservations
    ap_names: tuple[str, ...]
    ap: Array
    ap_std: Array
    ap_std_prior: Array
    ap_t: Array
    ap_significant: NDArray[np.bool_]
    t_critical: float
    stations: list[str]
    pose: Array
    pose_std: Array
    levelled: NDArray[np.bool_]
    datum_fixed: list[str]
    targets: list[str]
    target_xyz: Array
    target_std: Array
    target_kind: list[str]
    residuals: Array
    w: Array
    rejected: NDArray[np.bool_]
    calib_names: list[str]
    calib_correlation: Array
    strong_pairs: list[tuple[str, str, float]]
    selection: list[SelectionStep] = field(default_factory=list)
    options: CalibrationOptions = field(default_factory=CalibrationOptions)

    @property
    def sigma0(self) -> float:
        return float(self.adjustment.sigma0)

    @property
    def chi2_passed(self) -> bool:
        return bool(self.adjustment.global_test.passed)

    def ap_report(self) -> list[dict]:
        """One dict per AP: name, formula, cause, unit, value, std, std_prior, t, significant
        (values in the report unit)."""
        out = []
        for k, name in enumerate(self.ap_names):
            term = AP_TERMS[name]
            s = term.report_scale
            out.append(
                {
                    "name": name,
                    "formula": term.formula,
                    "cause": term.cause,
                    "unit": term.report_unit,
                    "value": float(self.ap[k] * s),
                    "std": float(self.ap_std[k] * s),
                    "std_prior": float(self.ap_std_prior[k] * s),
                    "t": float(self.ap_t[k]),
                    "significant": bool(self.ap_significant[k]),
                }
            )
        return out


# ----------------------------------------------------------------------------- the model


class _PolarModel:
    """Observation model of one block: ``model(x_local) -> (f, J)`` (see the module text).

    ``x_local`` columns: the K APs, the station's six pose parameters, then (free targets)
    the target's X, Y, Z. With ``fixed_xyz`` the target coordinates are constants.
    """

    def __init__(
        self,
        names: tuple[str, ...],
        face_two: NDArray[np.bool_],
        observed: Array,
        wavelength_m: float,
        fixed_xyz: Array | None = None,
    ) -> None:
        self.names = names
        self.k = len(names)
        self.face_two = face_two
        self.observed = observed
        self.wavelength = wavelength_m
        self.fixed_xyz = fixed_xyz

    def __call__(self, xl: Array) -> tuple[Array, Array]:
        k = self.k
        g = xl.shape[0]
        ap = xl[:, :k]
        pose = xl[:, k : k + 6]
        xyz = self.fixed_xyz if self.fixed_xyz is not None else xl[:, k + 6 : k + 9]
        m = opk_to_matrix(pose[:, 3], pose[:, 4], pose[:, 5])
        dm = opk_derivatives(pose[:, 3], pose[:, 4], pose[:, 5])  # (G, 3, 3, 3)
        diff = xyz - pose[:, :3]
        d = np.einsum("gij,gj->gi", m, diff)
        geo = cartesian_to_polar(d)
        jd = polar_jacobian(d)
        theta, alpha, sign = instrument_angles(geo[:, 1], geo[:, 2], self.face_two)
        inst = np.stack([geo[:, 0], theta, alpha], axis=-1)
        f = inst.copy()
        # d(inst)/d(geo) = diag(1, 1, sign); corrections add (I + dC/d inst).
        a = np.zeros((g, 3, 3))
        a[:, 0, 0] = a[:, 1, 1] = a[:, 2, 2] = 1.0
        j = np.zeros((g, 3, xl.shape[1]))
        if k:
            basis, dbasis, comp = ap_basis(self.names, inst, self.wavelength)
            for q in range(k):
                c = comp[q]
                f[:, c] += ap[:, q] * basis[:, q]
                a[:, c, :] += ap[:, q, None] * dbasis[:, q, :]
                j[:, c, q] = basis[:, q]
        a[:, :, 2] *= sign[:, None]
        a = a @ jd  # d f / d d
        am = a @ m
        j[:, :, k : k + 3] = -am
        for r in range(3):
            j[:, :, k + 3 + r] = np.einsum("gij,gj->gi", a, np.einsum("gij,gj->gi", dm[:, r], diff))
        if self.fixed_xyz is None:
            j[:, :, k + 6 : k + 9] = am
        # Angles compared with the observation modulo 2 pi.
        for c in (1, 2):
            f[:, c] = self.observed[:, c] + wrap_angle(f[:, c] - self.observed[:, c])
        return f, j


class _DatumConstraint:
    """Hard constraints ``x[idx] = values`` (one group)."""

    def __init__(self, values: Array) -> None:
        self.values = values

    def __call__(self, xl: Array) -> tuple[Array, Array]:
        n = self.values.size
        return xl - self.values[None, :], np.eye(n)[None, :, :].repeat(xl.shape[0], axis=0)


class _InnerConstraint:
    """Minimum (inner) constraints ``G' (x - x0) = 0`` on target coordinates (one group):
    no mean translation and no mean rotation of the targets with respect to ``x0``."""

    def __init__(self, x0: Array, rotations: tuple[int, ...]) -> None:
        self.x0 = x0.copy()
        p = x0.reshape(-1, 3)
        c = p - p.mean(axis=0)
        rows = []
        for axis in range(3):
            g = np.zeros_like(p)
            g[:, axis] = 1.0
            rows.append(g.ravel())
        for axis in rotations:
            e = np.zeros(3)
            e[axis] = 1.0
            rows.append(np.cross(e, c).ravel())  # the displacement of a small rotation
        g = np.array(rows)
        self.g = g / np.linalg.norm(g, axis=1, keepdims=True)

    def __call__(self, xl: Array) -> tuple[Array, Array]:
        h = (xl - self.x0[None, :]) @ self.g.T
        return h, np.broadcast_to(self.g, (xl.shape[0], *self.g.shape)).copy()


def predict(
    names: tuple[str, ...],
    ap: Sequence[float],
    pose: Array,
    xyz: Array,
    face_two: NDArray[np.bool_] | None = None,
    wavelength_m: float = 1.2,
) -> Array:
    """What the scanner records: (N, 3) (rho, theta, alpha) of points ``xyz`` (N, 3) seen from
    stations ``pose`` (N, 6) with APs ``ap`` (the model of :func:`calibrate`, for simulations).

    >>> p = predict(("a0",), [0.002], np.zeros((1, 6)), np.array([[3.0, 4.0, 0.0]]))
    >>> np.round(p, 6).tolist()
    [[5.002, 0.927295, 0.0]]
    """
    pose = np.asarray(pose, dtype=np.float64)
    xyz = np.asarray(xyz, dtype=np.float64)
    n = xyz.shape[0]
    face = np.zeros(n, dtype=bool) if face_two is None else np.asarray(face_two, dtype=bool)
    model = _PolarModel(tuple(names), face, np.zeros((n, 3)), wavelength_m)
    xl = np.hstack([np.tile(np.asarray(ap, dtype=np.float64), (n, 1)), pose, xyz])
    f, _ = model(xl)
    f[:, 1] = wrap_angle(f[:, 1])
    return f


# ----------------------------------------------------------------------------- the solver


@dataclass
class _Layout:
    aps: tuple[str, ...]
    stations: list[str]
    free_targets: list[str]
    fixed_targets: dict[str, Array]
    names: list[str]
    x0: Array
    blocks: list
    constraints: list
    obs_of_block: dict[str, NDArray[np.intp]]
    levelled: NDArray[np.bool_]
    datum_fixed: list[str]


def _build(
    obs: TlsObservations,
    control: Sequence[ControlTarget],
    infos: dict[str, StationInfo],
    opts: CalibrationOptions,
    aps: tuple[str, ...],
    poses: dict[str, Array],
    targets: dict[str, Array],
    reference: str | None,
    ap_start: dict[str, float],
) -> _Layout:
    stations = obs.stations()
    fixed = {c.id: np.asarray(c.xyz, dtype=np.float64) for c in control if c.fixed}
    weighted = [c for c in control if not c.fixed and c.id in targets]
    observed_targets = obs.targets()
    free = [t for t in observed_targets if t not in fixed]
    free += [c.id for c in weighted if c.id not in set(free)]
    k = len(aps)
    names = list(aps)
    x0 = [ap_start.get(a, 0.0) for a in aps]
    s_at = {}
    for s in stations:
        s_at[s] = len(names)
        names += [f"{s}.{p}" for p in POSE_NAMES]
        x0 += list(poses[s])
    t_at = {}
    for t in free:
        t_at[t] = len(names)
        names += [f"{t}.{c}" for c in ("X", "Y", "Z")]
        x0 += list(targets[t])
    x0a = np.array(x0, dtype=np.float64)
    face = obs.face_two
    blocks, obs_of_block = [], {}
    sidx = np.array([s_at[s] for s in obs.station])
    is_fixed = np.array([t in fixed for t in obs.target])
    ap_idx = np.arange(k)
    for label, sel in (("polar", ~is_fixed), ("polar to fixed targets", is_fixed)):
        rows = np.flatnonzero(sel)
        if rows.size == 0:
            continue
        cols = [np.tile(ap_idx, (rows.size, 1)), sidx[rows, None] + np.arange(6)]
        fixed_xyz = None
        if label == "polar":
            tidx = np.array([t_at[obs.target[i]] for i in rows])
            cols.append(tidx[:, None] + np.arange(3))
        else:
            fixed_xyz = np.array([fixed[obs.target[i]] for i in rows])
        index = np.hstack(cols).astype(np.intp)
        observed = obs.polar[rows]
        model = _PolarModel(aps, face[rows], observed, opts.cyclic_wavelength_m, fixed_xyz)
        blocks.append(
            GaussMarkovBlock(
                name=label,
                observed=observed,
                sigma=obs.cov[rows],
                param_index=index,
                model=model,
                labels=[
                    f"{obs.station[i]} / {obs.target[i]}" + (" (face II)" if face[i] else "")
                    for i in rows
                ],
                row_names=("range", "horizontal", "vertical"),
            )
        )
        obs_of_block[label] = rows
    levelled = np.array(
        [
            opts.levelled
            if infos.get(s) is None or infos[s].levelled is None
            else bool(infos[s].levelled)
            for s in stations
        ]
    )
    lev = [s for s, lv in zip(stations, levelled) if lv]
    if lev:
        idx, val = [], []
        for s in lev:
            info = infos.get(s)
            given = info.opk if info is not None and info.opk is not None else np.zeros(3)
            idx += [s_at[s] + 3, s_at[s] + 4]
            val += [float(given[0]), float(given[1])]
            x0a[s_at[s] + 3], x0a[s_at[s] + 4] = given[0], given[1]
        blocks.append(
            prior_block(
                "compensator", idx, val, opts.tilt_sigma_rad, labels=[names[i] for i in idx]
            )
        )
    if weighted:
        idx, val, sig = [], [], []
        for c in weighted:
            idx += [t_at[c.id] + q for q in range(3)]
            val += list(np.asarray(c.xyz, dtype=np.float64))
            sig += list(np.asarray(c.sigma, dtype=np.float64))
        blocks.append(prior_block("control", idx, val, sig, labels=[names[i] for i in idx]))
    constraints: list[Constraint] = []
    datum_fixed: list[str] = []
    if reference is not None and opts.datum == "inner" and free:
        d_idx = np.array([t_at[t] + q for t in free for q in range(3)], dtype=np.intp)
        rotations = (2,) if levelled.any() else (0, 1, 2)
        constraints.append(
            Constraint(
                "datum (inner constraints)", d_idx[None, :], _InnerConstraint(x0a[d_idx], rotations)
            )
        )
        datum_fixed = []
    elif reference is not None:
        base = s_at[reference]
        comps = [0, 1, 2, 5] if levelled[stations.index(reference)] else [0, 1, 2, 3, 4, 5]
        d_idx = np.array([base + c for c in comps], dtype=np.intp)
        values = x0a[d_idx].copy()
        constraints.append(Constraint("datum", d_idx[None, :], _DatumConstraint(values)))
        datum_fixed = [names[i] for i in d_idx]
    return _Layout(
        aps,
        stations,
        free,
        fixed,
        names,
        x0a,
        blocks,
        constraints,
        obs_of_block,
        levelled,
        datum_fixed,
    )


def _run(
    lay: _Layout,
    opts: CalibrationOptions,
    snooping: bool,
    has_control: bool,
    progress=None,
    should_stop=None,
) -> AdjustmentResult:
    aopts = AdjustmentOptions(
        snooping=snooping,
        snooping_alpha=opts.snooping_alpha,
        max_iterations=opts.max_iterations,
    )
    try:
        return adjust(
            lay.x0,
            lay.names,
            lay.blocks,
            lay.constraints,
            options=aopts,
            progress=progress,
            should_stop=should_stop,
        )
    except NotObservableError as exc:
        raise TlsNotObservable(exc, diagnose(exc.parameters, has_control)) from exc


def _ap_stats(res: AdjustmentResult, k: int, alpha: float) -> tuple[Array, float]:
    from scipy import stats  # here: scipy.stats takes seconds to import (QGIS start-up)

    std = res.std[:k]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.abs(res.x[:k]) / std
    dof = max(res.redundancy, 1)
    return t, float(stats.t.ppf(1 - alpha / 2, dof))


def _calib_correlation(res: AdjustmentResult, lay: _Layout) -> tuple[list[str], Array]:
    n_cal = len(lay.aps) + 6 * len(lay.stations)
    names = res.names[:n_cal]
    corr = (
        res.correlation[:n_cal, :n_cal]
        if res.correlation is not None
        else np.full((n_cal, n_cal), np.nan)
    )
    return names, corr


def _strong_pairs(
    names: list[str], corr: Array, limit: float, with_aps: bool
) -> list[tuple[str, str, float]]:
    out = []
    n = len(names)
    for i in range(n):
        for j in range(i + 1, n):
            r = corr[i, j]
            if not np.isfinite(r) or abs(r) < limit:
                continue
            if with_aps and names[i] not in AP_TERMS and names[j] not in AP_TERMS:
                continue
            out.append((names[i], names[j], float(r)))
    out.sort(key=lambda p: -abs(p[2]))
    return out


def _select(
    obs, control, infos, opts, aps, poses, targets, reference, has_control, should_stop
) -> tuple[tuple[str, ...], list[SelectionStep]]:
    """Backward elimination of APs by correlation and significance."""
    steps: list[SelectionStep] = []
    current = list(aps)
    while current:
        lay = _build(obs, control, infos, opts, tuple(current), poses, targets, reference, {})
        try:
            res = _run(lay, opts, False, has_control, should_stop=should_stop)
        except TlsNotObservable as exc:
            named = [p for p in exc.parameters if p in current]
            if not named:
                raise
            drop = named[-1]  # the later (less physical) term of the table
            current.remove(drop)
            steps.append(
                SelectionStep(
                    drop, f"not determinable with the others ({', '.join(named)})", tuple(current)
                )
            )
            continue
        k = len(current)
        t, tcrit = _ap_stats(res, k, opts.significance_alpha)
        corr = res.correlation[:k, :k] if res.correlation is not None else np.eye(k)
        worst = None
        for i in range(k):
            for j in range(i + 1, k):
                r = abs(corr[i, j])
                if (
                    np.isfinite(r)
                    and r >= opts.correlation_limit
                    and (worst is None or r > worst[2])
                ):
                    worst = (i, j, r)
        if worst is not None:
            i, j, r = worst
            drop_i = i if t[i] < t[j] else j
            keep_i = j if drop_i == i else i
            drop = current[drop_i]
            reason = (
                f"correlated with {current[keep_i]} (r = {corr[i, j]:+.3f}) and less "
                f"significant (t = {t[drop_i]:.2f} vs {t[keep_i]:.2f})"
            )
        else:
            low = int(np.nanargmin(t))
            if t[low] >= tcrit:
                break
            drop = current[low]
            reason = f"not significant (t = {t[low]:.2f} < {tcrit:.2f})"
        current.remove(drop)
        steps.append(SelectionStep(drop, reason, tuple(current)))
    return tuple(current), steps


#: A levelled station whose registration finds it tilted beyond this (radians) from its
#: compensator reading is not levelled (a wrong flag, or control that is not z up).
MAX_LEVEL_DISAGREEMENT_RAD = np.radians(1.0)


def _check_levelled(
    obs: TlsObservations,
    infos: dict[str, StationInfo],
    levelled_ids: list[str],
    poses: dict[str, Array],
    has_control: bool,
) -> None:
    """Refuse a station flagged levelled whose approximate registration is tilted: the
    compensator observations would pull it to a wrong orientation."""
    for s in levelled_ids:
        info = infos.get(s)
        given = info.opk[:2] if info is not None and info.opk is not None else np.zeros(2)
        tilt = np.abs(wrap_angle(poses[s][3:5] - given))
        if tilt.max() > MAX_LEVEL_DISAGREEMENT_RAD:
            k = obs.station.index(s)
            raise InputError(
                f"station '{s}' is taken as levelled (compensator omega, phi = "
                f"{np.degrees(given[0]):.4f}, {np.degrees(given[1]):.4f} deg) but its targets "
                f"place it at omega, phi = {np.degrees(poses[s][3]):.2f}, "
                f"{np.degrees(poses[s][4]):.2f} deg: mark it levelled = 0 in the stations "
                "table (a tilted or rotated scanner)"
                + (", or check that the control is in a frame with z up" if has_control else ""),
                **obs.where(k),
            )


def calibrate(
    obs: TlsObservations,
    control: Sequence[ControlTarget] = (),
    stations: Sequence[StationInfo] = (),
    options: CalibrationOptions | None = None,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> TlsCalibration:
    """Register the stations and estimate the scanner's APs in one adjustment.

    Parameters
    ----------
    obs : TlsObservations
        Polar observations (range, horizontal, vertical) with covariances.
    control : sequence of ControlTarget
        Targets with known coordinates (sigma 0: fixed); the datum when given.
    stations : sequence of StationInfo
        Approximate poses, the compensator's tilts, levelled flags, the reference station.
    options : CalibrationOptions, optional
    progress, should_stop : callable, optional
        Progress fraction and cancellation (checked once per iteration).

    Returns
    -------
    TlsCalibration

    Raises
    ------
    InputError
        The network cannot be used (:func:`~.network.check_network`), a station cannot be
        connected, an unknown AP, a control or station id that is not observed.
    TlsNotObservable
        A parameter is not determined (with the diagnosis).
    """
    opts = options if options is not None else CalibrationOptions()
    if opts.datum not in ("inner", "reference"):
        raise InputError(f"datum must be 'inner' or 'reference', got {opts.datum!r}")
    aps = ap_terms(opts.ap_set)
    control = list(control)
    check_network(obs, control)
    observed = set(obs.targets())
    known_stations = set(obs.stations())
    for st in stations:
        if st.id not in known_stations:
            raise InputError(f"station '{st.id}' has no observations", row=st.row or None)
    control = [c for c in control if c.id in observed]
    infos = {s.id: s for s in stations}
    has_control = bool(control)
    reference = opts.reference_station
    if reference is not None and reference not in known_stations:
        raise InputError(f"the reference station '{reference}' has no observations")

    def is_levelled(sid: str) -> bool:
        info = infos.get(sid)
        return opts.levelled if info is None or info.levelled is None else bool(info.levelled)

    levelled_ids = [s for s in obs.stations() if is_levelled(s)]
    if reference is None and not has_control and levelled_ids:
        # The approximate frame is that of the reference station: a levelled one keeps z up,
        # so that the compensator readings of the others can be checked against it.
        placed = [st.id for st in stations if st.xyz is not None and is_levelled(st.id)]
        reference = placed[0] if placed else levelled_ids[0]
    poses, targets, ref = register_stations(obs, control, stations, reference)
    if has_control:
        ref = None
    _check_levelled(obs, infos, levelled_ids, poses, has_control)
    steps: list[SelectionStep] = []
    if opts.select_aps and aps:
        aps, steps = _select(
            obs, control, infos, opts, aps, poses, targets, ref, has_control, should_stop
        )
    lay = _build(obs, control, infos, opts, aps, poses, targets, ref, {})
    res = _run(lay, opts, opts.snooping, has_control, progress, should_stop)
    k = len(aps)
    t, tcrit = _ap_stats(res, k, opts.significance_alpha)
    s_count = len(lay.stations)
    pose = res.x[k : k + 6 * s_count].reshape(-1, 6)
    pose_std = res.std[k : k + 6 * s_count].reshape(-1, 6)
    for q in lay.datum_fixed:  # held by the datum: exactly known
        pose_std[lay.stations.index(q.rsplit(".", 1)[0]), POSE_NAMES.index(q.rsplit(".", 1)[1])] = 0
    tlist = obs.targets() + [t for t in lay.free_targets if t not in set(obs.targets())]
    txyz = np.zeros((len(tlist), 3))
    tstd = np.zeros((len(tlist), 3))
    kinds = []
    weighted = {c.id for c in control if not c.fixed}
    base = k + 6 * s_count
    for i, tid in enumerate(tlist):
        if tid in lay.fixed_targets:
            txyz[i] = lay.fixed_targets[tid]
            kinds.append("fixed")
            continue
        at = base + 3 * lay.free_targets.index(tid)
        txyz[i] = res.x[at : at + 3]
        tstd[i] = res.std[at : at + 3]
        kinds.append("control" if tid in weighted else "free")
    n = len(obs)
    v = np.full((n, 3), np.nan)
    w = np.full((n, 3), np.nan)
    rej = np.zeros(n, dtype=bool)
    for label, rows in lay.obs_of_block.items():
        table = res.residuals[label]
        v[rows] = table.v
        w[rows] = table.w
        rej[rows] = table.rejected
    cnames, ccorr = _calib_correlation(res, lay)
    pairs = _strong_pairs(cnames, ccorr, opts.correlation_limit, with_aps=bool(k))
    return TlsCalibration(
        adjustment=res,
        observations=obs,
        ap_names=aps,
        ap=res.x[:k].copy(),
        ap_std=res.std[:k].copy(),
        ap_std_prior=res.std_prior[:k].copy(),
        ap_t=t,
        ap_significant=t >= tcrit,
        t_critical=tcrit,
        stations=lay.stations,
        pose=pose,
        pose_std=pose_std,
        levelled=lay.levelled,
        datum_fixed=lay.datum_fixed,
        targets=tlist,
        target_xyz=txyz,
        target_std=tstd,
        target_kind=kinds,
        residuals=v,
        w=w,
        rejected=rej,
        calib_names=cnames,
        calib_correlation=ccorr,
        strong_pairs=pairs,
        selection=steps,
        options=opts,
    )
