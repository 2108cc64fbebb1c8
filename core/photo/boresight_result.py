"""The results of the boresight calibration (:mod:`.boresight`): the calibration with its
statistics, the residuals per observation row, the diagnosis of a parameter that cannot be
determined, and what a run of the job computed.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..errors import DiagnosedNotObservable
from ..geometry.frames import LocalFrame, MappingFrame
from ..i18n import mark as _t
from ..lsq.results import AdjustmentResult
from .boresight_blocks import _Stage
from .boresight_models import (
    pose_chain,
)
from .boresight_setup import ANGLES, ARCSEC, BoresightOptions, _Parameters
from .georeference import Trajectory
from .observations import ImageObservations
from .orientation import ExteriorOrientationTable, eo_local_to_map
from .timing import TIMING_SEPARABILITY_MIN, timing_trade

_LEVER_NAMES = ("lever_arm.x", "lever_arm.y", "lever_arm.z")

#: catalogue context of this module's ``_t("...")`` sentences (the diagnosis the report shows)
TR_CONTEXT = "Report"

__all__ = [
    "BoresightNotObservable",
    "BoresightResult",
    "BoresightRun",
    "ObservationResiduals",
    "diagnose",
    "require_timing_separable",
]

Array = NDArray[np.float64]


class BoresightNotObservable(DiagnosedNotObservable):
    """A calibration parameter cannot be determined; ``diagnosis`` explains what would fix it."""


@dataclass
class ObservationResiduals:
    """Residuals per input observation row (N rows of the observation table).

    Attributes
    ----------
    v_px : ndarray, shape (N, 2)
        Residual (adjusted - observed) of col and row, pixels; NaN for paper and unused rows.
    v_d : ndarray, shape (N,)
        Residual of d for paper rows, metres (NaN otherwise).
    w : ndarray, shape (N,)
        Largest |Baarda w| of the row's observations (NaN if untestable or unused).
    rejected : ndarray of bool, shape (N,)
        Rejected by data snooping (a line group or plane group is rejected as a whole).
    used : ndarray of bool, shape (N,)
    """

    v_px: Array
    v_d: Array
    w: Array
    rejected: NDArray[np.bool_]
    used: NDArray[np.bool_]


@dataclass
class BoresightResult:
    """Result of :func:`calibrate`.

    Attributes
    ----------
    groups : tuple of str
        Boresight groups, in the order of the rows below.
    boresight, std, std_prior : ndarray, shape (G, 3)
        (d_omega, d_phi, d_kappa) in radians and their standard deviations (a-posteriori,
        i.e. scaled by sigma0, and a-priori).
    lever_arm, lever_arm_std : ndarray, shape (3,) or None
        Metres, body frame (None when not estimated).
    interior, interior_std : ndarray, shape (3,) or None
        f, x0, y0 in millimetres (None when not estimated).
    parameter_names : list of str
        Names of the calibration parameters (boresight, lever arm, interior).
    correlation : ndarray, shape (K, K)
        Their correlation matrix.
    sigma0 : float
    redundancy : int
    chi2_passed : bool
    residuals : ObservationResiduals
    eo : ExteriorOrientationTable
        Updated exterior orientation of every image, mapping CRS.
    adjustment : AdjustmentResult
    local : LocalFrame
    warnings : list of str
    timing_offset, timing_offset_std : float or None
        Camera timing offset dt (exposure = recorded time + dt), seconds, and its a-posteriori
        standard deviation (None when not estimated).
    """

    groups: tuple[str, ...]
    boresight: Array
    std: Array
    std_prior: Array
    lever_arm: Array | None
    lever_arm_std: Array | None
    interior: Array | None
    interior_std: Array | None
    parameter_names: list[str]
    correlation: Array
    sigma0: float
    redundancy: int
    chi2_passed: bool
    residuals: ObservationResiduals
    eo: ExteriorOrientationTable
    adjustment: AdjustmentResult
    local: LocalFrame
    warnings: list[str] = field(default_factory=list)
    timing_offset: float | None = None
    timing_offset_std: float | None = None

    @property
    def boresight_deg(self) -> Array:
        """(G, 3) degrees."""
        return np.degrees(self.boresight)

    @property
    def boresight_arcsec(self) -> Array:
        """(G, 3) arc-seconds."""
        return self.boresight / ARCSEC

    @property
    def std_arcsec(self) -> Array:
        """(G, 3) a-posteriori standard deviations, arc-seconds."""
        return self.std / ARCSEC

    def table_rows(self) -> list[dict[str, object]]:
        """One row per group and angle: value in degrees and arc-seconds, std in arc-seconds."""
        rows = []
        for g, name in enumerate(self.groups):
            for k, angle in enumerate(ANGLES):
                rows.append(
                    {
                        "group": name,
                        "parameter": angle,
                        "value_deg": float(self.boresight_deg[g, k]),
                        "value_arcsec": float(self.boresight_arcsec[g, k]),
                        "std_arcsec": float(self.std_arcsec[g, k]),
                        "std_prior_arcsec": float(self.std_prior[g, k] / ARCSEC),
                    }
                )
        return rows


def _observation_residuals(res: AdjustmentResult, maps, n: int, used) -> ObservationResiduals:
    v_px = np.full((n, 2), np.nan)
    v_d = np.full(n, np.nan)
    w = np.full(n, np.nan)
    rejected = np.zeros(n, dtype=bool)
    for name, rows, kind in maps:
        table = res.residuals[name]
        g, k = rows.shape
        aw = np.abs(table.w)
        if kind == "paper":
            v_d[rows[:, 0]] = table.v[:, 0]
            w[rows[:, 0]] = aw[:, 0]
        else:
            v_px[rows.ravel()] = table.v[:, : 2 * k].reshape(-1, 2)
            ww = aw[:, : 2 * k].reshape(g, k, 2)
            with np.errstate(all="ignore"):
                w[rows.ravel()] = np.where(
                    np.isnan(ww).all(axis=2), np.nan, np.nanmax(np.nan_to_num(ww, nan=-1), axis=2)
                ).ravel()
        rejected[rows.ravel()] = np.repeat(table.rejected, k)
    return ObservationResiduals(v_px, v_d, w, rejected, np.asarray(used, dtype=bool))


def _result(
    res: AdjustmentResult,
    trajectory: Trajectory,
    frame: MappingFrame,
    local: LocalFrame,
    group_names: tuple[str, ...],
    par: _Parameters,
    st: _Stage,
    opts: BoresightOptions,
) -> BoresightResult:
    """The calibration, its statistics, the adjusted orientations in the mapping frame and
    the residuals per observation row."""
    names, n_cal, lever_at, interior_at = par.names, par.n_cal, par.lever_at, par.interior_at
    x = res.x
    bore = x[: 3 * len(group_names)].reshape(-1, 3)
    std = res.std[: 3 * len(group_names)].reshape(-1, 3)
    std_p = res.std_prior[: 3 * len(group_names)].reshape(-1, 3)
    lever = lever_std = interior = interior_std = None
    if opts.estimate_lever_arm:
        lever, lever_std = x[lever_at : lever_at + 3], res.std[lever_at : lever_at + 3]
    if opts.estimate_interior:
        interior = x[interior_at : interior_at + 3]
        interior_std = res.std[interior_at : interior_at + 3]
    corr = (
        res.correlation[:n_cal, :n_cal]
        if res.correlation is not None
        else np.full((n_cal, n_cal), np.nan)
    )
    xp = x[par.pose_idx]
    centre, r_cl, _, _ = pose_chain(xp, st.r_nl, st.spec)
    xyz_map, opk_map = eo_local_to_map(centre, np.swapaxes(r_cl, 1, 2), local)
    eo = ExteriorOrientationTable(
        trajectory.image_id,
        trajectory.time,
        trajectory.group,
        xyz_map,
        opk_map,
        frame.crs.to_wkt(),
    )
    return BoresightResult(
        groups=group_names,
        boresight=bore,
        std=std,
        std_prior=std_p,
        lever_arm=lever,
        lever_arm_std=lever_std,
        interior=interior,
        interior_std=interior_std,
        parameter_names=names[:n_cal],
        correlation=corr,
        sigma0=res.sigma0,
        redundancy=res.redundancy,
        chi2_passed=res.global_test.passed,
        residuals=_observation_residuals(res, st.maps, len(st.observations), st.used),
        eo=eo,
        adjustment=res,
        local=local,
        warnings=list(res.warnings),
        timing_offset=float(x[par.timing_at]) if par.timing_at >= 0 else None,
        timing_offset_std=float(res.std[par.timing_at]) if par.timing_at >= 0 else None,
    )


# ----------------------------------------------------------------------------- diagnosis


def diagnose(parameters: Sequence[str], groups: Sequence[str] = ()) -> list[str]:
    """Explain in words why the named parameters are not observable and what would fix it.

    Each sentence is a :class:`core.i18n.Message` (English text; the report translates it).

    >>> diagnose(["bore[NE].d_kappa"])[0].startswith("kappa of group 'NE'")
    True
    """
    out: list[str] = []
    bore: dict[str, set[str]] = {}
    kinds: set[str] = set()
    for name in parameters:
        if name.startswith("bore["):
            g, angle = name[5:].split("].", 1)
            bore.setdefault(g, set()).add(angle)
        else:
            kinds.add(name.split("[", 1)[0].split(".", 1)[0])
    for g, angles in bore.items():
        if angles == set(ANGLES):
            out.append(
                _t(
                    "the boresight of group '{group}' is not determined at all: its images have "
                    "no (or too few) measurements; measure control in them, or use one boresight "
                    "for all images (groups = single).",
                    group=g,
                )
            )
        elif angles == {"d_kappa"}:
            out.append(
                _t(
                    "kappa of group '{group}' is not observable: too few points, or all of them "
                    "near the image centre; measure points spread over the whole image (towards "
                    "the corners) on roofs facing different directions, or add LCPs or ridge "
                    "lines.",
                    group=g,
                )
            )
        else:
            out.append(
                _t(
                    "{angles} of group '{group}' cannot be separated: the points lie near the "
                    "image centre or on planes of one orientation; spread points over the image "
                    "on roofs of different slope and aspect, or add LCPs or lines.",
                    angles=", ".join(sorted(angles)),
                    group=g,
                )
            )
    if "lever_arm" in kinds:
        out.append(
            _t(
                "the lever arm cannot be separated from the INS position: it turns with the "
                "aircraft while a position error does not, so fly lines in opposite directions "
                "(horizontal components) and add height control (LCPs); its vertical component "
                "cannot be told from a vertical GNSS bias at all: measure it (total station) and "
                "keep it fixed."
            )
        )
    if "interior" in kinds:
        out.append(
            _t(
                "the interior orientation is not separable: the focal length trades with the "
                "flying height (needs control at clearly different heights or two flying "
                "heights), the principal point with the boresight omega/phi (both shift the "
                "whole image); fix them from the lab calibration."
            )
        )
    if "timing" in kinds:
        out.append(
            _t(
                "the camera timing offset cannot be separated: on one line, or on lines flown "
                "at one speed (in either direction), dt times the speed equals an along-track "
                "lever arm (and, over flat ground, a pitch boresight); fly lines at clearly "
                "different speeds, or keep the lever arm fixed, or do not estimate the timing."
            )
        )
    if "tie" in kinds:
        out.append(
            _t(
                "some tie points are not determined: measure each in at least two images, on a "
                "plane that is not seen edge-on."
            )
        )
    if "lcp" in kinds:
        out.append(_t("some LCP coordinates are not determined: give each a covariance."))
    if "control" in kinds:
        out.append(_t("some ground point coordinates are not determined: give each sx, sy, sz."))
    if "ins" in kinds and not out:
        out.append(_t("INS parameters are not determined: the INS grade sigmas must be > 0."))
    if not out:
        out.append(
            _t(
                "parameters not observable: {names}",
                names=", ".join(list(parameters)[:10]),
            )
        )
    return out


def require_timing_separable(share: float, body_velocity: Array) -> None:
    """Refuse a timing offset estimated with the lever arm when the body-frame velocity is
    (nearly) the same at every image (``share`` below :data:`TIMING_SEPARABILITY_MIN`):
    dt times that velocity is then a lever arm. Names dt and the lever-arm component along
    the velocity (``body_velocity``, the mean body-frame velocity, m/s); the rule is
    :func:`~.timing.timing_trade`'s."""
    cause = timing_trade(share, body_velocity, "timing.dt", _LEVER_NAMES, "body")
    if cause is None:
        return
    axis = "xyz"[int(np.argmax(np.abs(body_velocity)))]
    speed = float(np.linalg.norm(body_velocity))
    diagnosis: list[str] = [
        _t(
            "the camera timing offset dt cannot be separated from the lever arm's {axis} "
            "component: the velocity in the aircraft's body frame is the same at every image "
            "to {share:.1%} ({speed:.1f} m/s along body {axis}; at least {minimum:.0%} is "
            "needed), so dt times the speed equals a lever arm along {axis} (one line, or lines "
            "flown at one speed in either direction); fly lines at clearly different speeds, "
            "or keep the lever arm fixed, or do not estimate the timing.",
            axis=axis,
            share=share,
            speed=speed,
            minimum=TIMING_SEPARABILITY_MIN,
        )
    ]
    raise BoresightNotObservable(cause, diagnosis)


@dataclass
class BoresightRun:
    """What :func:`run_boresight_calibration` computed.

    Attributes
    ----------
    result : BoresightResult
    observations : ImageObservations
        The N observation rows, in file order.
    ground : ndarray, shape (N, 3)
        Ground position of each row in the mapping CRS (NaN where none can be computed).
    image_group : tuple of str, shape (N,)
        Boresight group of the image of each row ("" for unknown images).
    settings : dict of str to str
        The run's settings as text (also in the HTML).
    crs_wkt : str
        Mapping CRS (WKT).
    """

    result: BoresightResult
    observations: ImageObservations
    ground: Array
    image_group: tuple[str, ...]
    settings: dict[str, str] = field(default_factory=dict)
    crs_wkt: str = ""

    def residual_rows(self) -> list[tuple[object, ...]]:
        """Rows of the residual table (``RESIDUAL_COLUMNS``)."""
        r = self.result.residuals
        obs = self.observations
        v = np.hypot(r.v_px[:, 0], r.v_px[:, 1])
        return [
            (
                obs.image_id[k],
                obs.point_id[k],
                obs.type[k],
                obs.target_id[k],
                self.image_group[k],
                *self.ground[k],
                *obs.pixels[k],
                *r.v_px[k],
                v[k],
                r.v_d[k],
                r.w[k],
                int(r.rejected[k]),
                int(r.used[k]),
            )
            for k in range(len(obs))
        ]
