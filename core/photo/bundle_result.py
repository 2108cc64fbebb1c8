"""The results of a bundle adjustment (:mod:`.bundle`): the interior-orientation table with its
t-tests and correlations, the check points intersected with the adjusted orientations, the
orientations and points in the mapping frame with their sigmas, and :class:`BundleResult`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy import stats

from ..geometry.camera import Camera
from ..geometry.collinearity import collinearity_jacobians
from ..geometry.engineering import EngineeringLocal
from ..geometry.rotations import opk_to_matrix
from ..i18n import mark as _t
from ..lsq.results import AdjustmentResult
from .bundle_model import _cams_from, _eliminated, _Run
from .bundle_selection import ap_decisions
from .bundle_setup import BundleOptions, Local, _cov_local_to_map, _rays, _Setup
from .intersection import meet_rays
from .observations import ImageObservations
from .orientation import ExteriorOrientationTable, eo_local_to_map
from .scale_bars import BarResult, bar_result

#: catalogue context of this module's ``_t("...")`` sentences (``make i18n``): the reports'
TR_CONTEXT = "Report"

Array = NDArray[np.float64]


@dataclass
class InteriorEstimate:
    """One interior parameter of one camera (a row of the AP table).

    ``status``: ``estimated``, ``dropped`` (by the selection, ``reason`` says why) or
    ``fixed`` (not estimated in this run); an estimated AP's ``reason`` is its significance
    decision with its statistic (:mod:`.bundle_selection`).
    """

    camera: str
    name: str
    value: float
    std: float
    t: float
    significant: bool
    status: str
    reason: str = ""
    is_ap: bool = True


@dataclass
class CheckPointResult:
    """Check points intersected with the adjusted orientations, against their survey.

    ``measured`` and ``reference`` are in the mapping CRS; ``sigma`` (metres) propagates the
    image measurement noise of the intersection only (the orientations are held).
    """

    point_id: tuple[str, ...]
    measured: Array
    reference: Array
    sigma: Array
    n_images: NDArray[np.int64]

    @property
    def discrepancy(self) -> Array:
        """measured - reference (N, 3), metres."""
        return self.measured - self.reference

    def statistics(self) -> dict[str, float]:
        """Mean, standard deviation and RMS of the planimetric discrepancy (as in the tables
        of Lima, Debiasi & Menezes), and the RMS of E, N, H and 3D (metres)."""
        d = self.discrepancy
        n = d.shape[0]
        out = {"n": float(n)}
        if n == 0:
            return {
                **out,
                **{
                    k: math.nan
                    for k in (
                        "mean_planimetric",
                        "std_planimetric",
                        "rms_planimetric",
                        "rms_e",
                        "rms_n",
                        "rms_h",
                        "rms_3d",
                    )
                },
            }
        hz = np.hypot(d[:, 0], d[:, 1])
        out["mean_planimetric"] = float(hz.mean())
        out["std_planimetric"] = float(hz.std(ddof=1)) if n > 1 else math.nan
        out["rms_planimetric"] = float(np.sqrt(np.mean(hz**2)))
        out["rms_e"], out["rms_n"], out["rms_h"] = (float(v) for v in np.sqrt(np.mean(d**2, 0)))
        out["rms_3d"] = float(np.sqrt(np.mean(np.sum(d**2, axis=1))))
        return out


@dataclass
class BundleResult:
    """Everything a bundle adjustment determined (frames and units in the attribute notes).

    Attributes
    ----------
    ap_model : str
    cameras : dict of str to Camera
        Adjusted cameras (interior orientation and APs).
    interior : list of InteriorEstimate
        f, x0, y0 and the APs of every camera, with sigmas, t and status.
    interior_correlation : dict of str to (names, ndarray)
        Correlation matrix of the estimated interior parameters of each camera.
    flagged_correlations : list of (camera, name, name, r)
        Pairs of interior parameters with |r| above the limit (final adjustment).
    dropped : list of (camera, name, reason)
        APs removed by the selection, in order.
    eo : ExteriorOrientationTable
        Adjusted orientations in the mapping CRS.
    eo_sigma : ndarray, shape (M, 6)
        Their standard deviations: metres and radians (omega-phi-kappa of the grid frame).
    image_camera : tuple of str, shape (M,)
    point_id, point_role : tuple of str, shape (P,)
        Object points (``tie``, ``control``, ``check``).
    point_xyz, point_sigma : ndarray, shape (P, 3)
        Mapping CRS and standard deviations (metres); check points: intersected.
    point_images : ndarray of int, shape (P,)
    observations : ImageObservations
        The image measurements, in the order of the residual arrays.
    obs_role : tuple of str
        ``tie``, ``control`` or ``check`` per measurement.
    v_px, w : ndarray, shape (N, 2)
        Residuals (adjusted minus observed, pixels) and Baarda's w per coordinate (NaN for
        check-point rows and untestable rows).
    redundancy : ndarray, shape (N, 2)
    rejected, used : ndarray of bool, shape (N,)
        Rejected by the robust stage or data snooping; used in the adjustment.
    image_rms : dict of str to (float, float)
        RMS of the residuals (col, row) of the measurements used, per image, pixels.
    check : CheckPointResult
    mount : dict or None
        Estimated lever arm (m, camera axes) and boresight (rad) with sigmas.
    adjustment : AdjustmentResult
        The final adjustment (sigma0, global test, warnings, rejections ...).
    local : LocalFrame or EngineeringLocal
    warnings : list of str
    scale_bars : BarResult or None
        The scale bars' adjusted distances, residuals and tests (frame units).
    timing : dict or None
        The camera timing offset when estimated: ``dt_s`` and ``dt_std_s`` (seconds, exposure
        = recorded time + dt) and ``correlation`` (parameter name -> its correlation with dt:
        the lever arm and boresight corrections, the interior orientation and APs, and the
        exterior-orientation parameter most correlated with dt).
    """

    ap_model: str
    cameras: dict[str, Camera]
    interior: list[InteriorEstimate]
    interior_correlation: dict[str, tuple[list[str], Array]]
    flagged_correlations: list[tuple[str, str, str, float]]
    dropped: list[tuple[str, str, str]]
    eo: ExteriorOrientationTable
    eo_sigma: Array
    image_camera: tuple[str, ...]
    point_id: tuple[str, ...]
    point_role: tuple[str, ...]
    point_xyz: Array
    point_sigma: Array
    point_images: NDArray[np.int64]
    observations: ImageObservations
    obs_role: tuple[str, ...]
    v_px: Array
    w: Array
    redundancy: Array
    rejected: NDArray[np.bool_]
    used: NDArray[np.bool_]
    image_rms: dict[str, tuple[float, float]]
    check: CheckPointResult
    mount: dict | None
    adjustment: AdjustmentResult
    local: Local
    warnings: list[str] = field(default_factory=list)
    scale_bars: BarResult | None = None
    timing: dict | None = None

    @property
    def sigma0(self) -> float:
        return self.adjustment.sigma0

    @property
    def length_unit(self) -> str:
        """The length unit of the frame: ``m``, or the unit of an engineering frame."""
        return str(getattr(self.local.mapping, "unit", "m"))

    @property
    def n_significant(self) -> int:
        """APs kept and significant in the final adjustment."""
        return sum(
            1 for p in self.interior if p.is_ap and p.status == "estimated" and p.significant
        )

    def summary_row(self) -> dict[str, object]:
        """One row of the model comparison (the layout of Table 1 of Lima, Debiasi &
        Menezes, with sigma0 and the AP counts)."""
        st = self.check.statistics()
        aps = [p for p in self.interior if p.is_ap]
        return {
            "model": self.ap_model,
            "n_check": int(st["n"]),
            "mean_planimetric": st["mean_planimetric"],
            "std_planimetric": st["std_planimetric"],
            "rms_planimetric": st["rms_planimetric"],
            "rms_h": st["rms_h"],
            "rms_3d": st["rms_3d"],
            "sigma0": self.sigma0,
            "n_ap": len(aps),
            "n_ap_kept": sum(1 for p in aps if p.status == "estimated"),
            "n_significant": self.n_significant,
            "rejected": int(self.rejected.sum()),
        }


def _interior_table(
    run: _Run, options: BundleOptions, dropped: dict
) -> tuple[list[InteriorEstimate], dict, list]:
    res = run.result
    r = max(res.redundancy, 1)
    tcrit = float(stats.t.ppf(1 - options.ap_alpha / 2, r))
    table: list[InteriorEstimate] = []
    corr_out: dict[str, tuple[list[str], Array]] = {}
    flagged: list[tuple[str, str, str, float]] = []
    cams = _cams_from(run)
    decided = {
        (d.camera, d.position): d.reason
        for d in ap_decisions(
            res, run.lay.interior, run.lay.free, run.cams, options.ap_alpha, options.max_correlation
        )
    }
    for c, cam in enumerate(cams):
        names = cam.interior_names
        idx = run.lay.interior[c]
        free = list(run.lay.free[c])
        for j, nm in enumerate(names):
            is_ap = j >= 3
            if j in free:
                k = free.index(j)
                val, sd = float(res.x[idx[k]]), float(res.std[idx[k]])
                t = abs(val) / sd if sd > 0 else math.inf
                table.append(
                    InteriorEstimate(
                        cam.name,
                        nm,
                        val,
                        sd,
                        t,
                        bool(t > tcrit),
                        "estimated",
                        decided.get((c, j), ""),
                        is_ap,
                    )
                )
            elif is_ap and (cam.name, nm) in dropped:
                why = dropped[(cam.name, nm)]
                table.append(
                    InteriorEstimate(
                        cam.name, nm, 0.0, math.nan, math.nan, False, "dropped", why, is_ap
                    )
                )
            elif is_ap and options.ap_model == "none":
                continue
            else:
                value = float(cam.interior_params[j])
                table.append(
                    InteriorEstimate(
                        cam.name, nm, value, math.nan, math.nan, False, "fixed", "", is_ap
                    )
                )
        if idx.size:
            corr = res.correlation_of(idx)
            nm = [names[j] for j in free]
            corr_out[cam.name] = (nm, corr)
            iu = np.triu_indices(idx.size, 1)
            for a, b in zip(*iu):
                if abs(corr[a, b]) > options.max_correlation:
                    flagged.append((cam.name, nm[a], nm[b], float(corr[a, b])))
    return table, corr_out, flagged


def _check_points(
    setup: _Setup, obs: ImageObservations, cams: list[Camera], eo: Array, sigma0: float
) -> CheckPointResult:
    """Forward intersection of the check points (Gauss-Newton on the collinearity)."""
    n = len(setup.check_ids)
    rows = np.flatnonzero(setup.obs_check >= 0)
    if n == 0:
        z = np.zeros((0, 3))
        return CheckPointResult((), z, z, z, np.zeros(0, dtype=np.int64))
    pt = setup.obs_check[rows]
    o, d = _rays(cams, setup.image_cam, eo, obs, setup.obs_img, rows)
    xyz, counts = meet_rays(o, d, pt, n)
    cov = np.full((n, 3, 3), np.nan)
    for _ in range(10):
        N = np.zeros((n, 3, 3))
        b = np.zeros((n, 3))
        for c, cam in enumerate(cams):
            sel = np.flatnonzero(setup.image_cam[setup.obs_img[rows]] == c)
            if not sel.size:
                continue
            r = rows[sel]
            out = collinearity_jacobians(xyz[pt[sel]], eo[setup.obs_img[r]], cam, wrt=("point",))
            J = out["point"] / obs.sigma_px[r, None, None]
            e = (obs.pixels[r] - out["pixels"]) / obs.sigma_px[r, None]
            JtJ = np.swapaxes(J, 1, 2) @ J
            Jte = np.einsum("nki,nk->ni", J, e)
            for i in range(3):
                b[:, i] += np.bincount(pt[sel], weights=Jte[:, i], minlength=n)
                for j in range(3):
                    N[:, i, j] += np.bincount(pt[sel], weights=JtJ[:, i, j], minlength=n)
        ok = np.isfinite(N).all(axis=(1, 2)) & (np.abs(np.linalg.det(N)) > 0)
        step = np.zeros((n, 3))
        step[ok] = np.linalg.solve(N[ok], b[ok][:, :, None])[:, :, 0]
        xyz = xyz + step
        cov[ok] = np.linalg.inv(N[ok])
        if np.nanmax(np.abs(step), initial=0.0) < 1e-7:
            break
    s0 = sigma0 if np.isfinite(sigma0) else 1.0
    cov_map = _cov_local_to_map(xyz, s0**2 * cov, setup.local)
    meas = setup.local.enu_to_map(xyz)
    ref = setup.local.enu_to_map(setup.check_ref_local)
    sig = np.sqrt(np.clip(np.einsum("nii->ni", cov_map), 0, None))
    return CheckPointResult(setup.check_ids, meas, ref, sig, counts.astype(np.int64))


def _eo_map_sigma(eo_local: Array, cov: Array, local: Local) -> tuple[Array, Array, Array]:
    """Mapping-frame EO (xyz, opk) and their sigmas (M, 6) by numerical propagation."""

    def to_map(e: Array) -> Array:
        xyz, opk = eo_local_to_map(e[:, :3], opk_to_matrix(e[:, 3], e[:, 4], e[:, 5]), local)
        return np.concatenate([xyz, opk], axis=1)

    base = to_map(eo_local)
    jac = np.zeros((eo_local.shape[0], 6, 6))
    steps = np.array([0.01, 0.01, 0.01, 1e-6, 1e-6, 1e-6])
    for k in range(6):
        p, m = eo_local.copy(), eo_local.copy()
        p[:, k] += steps[k]
        m[:, k] -= steps[k]
        dv = to_map(p) - to_map(m)
        dv[:, 3:] = (dv[:, 3:] + np.pi) % (2 * np.pi) - np.pi
        jac[:, :, k] = dv / (2 * steps[k])
    cm = jac @ cov @ np.swapaxes(jac, 1, 2)
    return base[:, :3], base[:, 3:], np.sqrt(np.clip(np.einsum("nii->ni", cm), 0, None))


def _finish(
    setup: _Setup,
    obs: ImageObservations,
    run: _Run,
    options: BundleOptions,
    dropped: dict,
    dropped_list: list,
    eo_table: ExteriorOrientationTable | None,
    warnings: list[str],
) -> BundleResult:
    res = run.result
    lay = run.lay
    cams = _cams_from(run)
    x = res.x
    eo_local = x[lay.eo]
    M = len(setup.images)
    eo_cov = np.stack([res.covariance_of(lay.eo[k]) for k in range(M)])
    xyz_map, opk_map, eo_sig = _eo_map_sigma(eo_local, eo_cov, setup.local)
    time = eo_table.time if eo_table is not None else np.full(M, np.nan)
    group = eo_table.group if eo_table is not None else ("",) * M
    eo_out = ExteriorOrientationTable(
        setup.images, time, group, xyz_map, opk_map, _wkt(setup.local)
    )
    pts_local = x[lay.points]
    blocks_q = res.cofactor_blocks
    P = len(setup.points)
    pcov = np.full((P, 3, 3), np.nan)
    if blocks_q is not None:
        elim = _eliminated(setup)
        pcov[elim] = blocks_q.Q_eliminated * res.sigma0**2
        for i in np.flatnonzero(~elim):  # the scale bars' ends, in the reduced system
            pcov[i] = res.covariance_of(lay.points[i])
    elif res.cofactor is not None:  # nothing eliminated
        pcov = np.stack([res.covariance_of(lay.points[i]) for i in range(P)]) if P else pcov
    pcov_map = _cov_local_to_map(pts_local, pcov, setup.local) if P else np.zeros((0, 3, 3))
    check = _check_points(setup, obs, cams, eo_local, res.sigma0)
    n_obs = len(obs)
    v = np.full((n_obs, 2), np.nan)
    w = np.full((n_obs, 2), np.nan)
    red = np.full((n_obs, 2), np.nan)
    rejected = np.zeros(n_obs, dtype=bool)
    used = np.zeros(n_obs, dtype=bool)
    for name, rows in zip(run.block_names, run.blocks_rows):
        table = res.residuals[name]
        v[rows], w[rows], red[rows] = table.v, table.w, table.redundancy_numbers
        rejected[rows] = table.rejected
        used[rows] = ~table.rejected
    # measurements left out before the final run (not kept) are rejected as well
    gone = (setup.obs_pt >= 0) & ~run.keep
    rejected[gone] = True
    # check-point rows: residuals of the intersection (not tested)
    chk = np.flatnonzero(setup.obs_check >= 0)
    if chk.size:
        xyz_chk = setup.local.map_to_enu(check.measured)
        for c, cam in enumerate(cams):
            sel = chk[setup.image_cam[setup.obs_img[chk]] == c]
            if sel.size:
                pred = collinearity_jacobians(
                    xyz_chk[setup.obs_check[sel]], eo_local[setup.obs_img[sel]], cam, wrt=()
                )
                v[sel] = pred["pixels"] - obs.pixels[sel]
    cnt = np.bincount(setup.obs_img[used], minlength=M)
    sq = [np.bincount(setup.obs_img[used], weights=v[used, j] ** 2, minlength=M) for j in (0, 1)]
    with np.errstate(invalid="ignore", divide="ignore"):
        r_img = np.sqrt(np.column_stack(sq) / cnt[:, None])
    rms = {im: (float(r_img[k, 0]), float(r_img[k, 1])) for k, im in enumerate(setup.images)}
    table, corr, flagged = _interior_table(run, options, dropped)
    mount = None
    if lay.mount is not None:
        mount = {
            "lever_arm_m": x[lay.mount[:3]].copy(),
            "lever_arm_std_m": res.std[lay.mount[:3]].copy(),
            "boresight_rad": x[lay.mount[3:]].copy(),
            "boresight_std_rad": res.std[lay.mount[3:]].copy(),
        }
    roles = setup.roles + ("check",) * len(setup.check_ids)
    pid = setup.points + setup.check_ids
    pxyz = np.vstack([setup.local.enu_to_map(pts_local) if P else np.zeros((0, 3)), check.measured])
    psig = np.vstack([np.sqrt(np.clip(np.einsum("nii->ni", pcov_map), 0, None)), check.sigma])
    nimg = np.concatenate(
        [
            np.bincount(setup.obs_pt[setup.obs_pt >= 0], minlength=P),
            check.n_images,
        ]
    ).astype(np.int64)
    role_arr = np.array(setup.roles + ("check",), dtype=object)
    obs_role = tuple(role_arr[np.where(setup.obs_check >= 0, len(setup.roles), setup.obs_pt)])
    timing = _timing(run)
    if timing is not None:
        warnings = warnings + _timing_warnings(timing, options.max_correlation)
    return BundleResult(
        ap_model=options.ap_model,
        cameras={c.name: c for c in cams},
        interior=table,
        interior_correlation=corr,
        flagged_correlations=flagged,
        dropped=list(dropped_list),
        eo=eo_out,
        eo_sigma=eo_sig,
        image_camera=tuple(setup.cam_names[c] for c in setup.image_cam),
        point_id=pid,
        point_role=roles,
        point_xyz=pxyz,
        point_sigma=psig,
        point_images=nimg,
        observations=obs,
        obs_role=obs_role,
        v_px=v,
        w=w,
        redundancy=red,
        rejected=rejected,
        used=used,
        image_rms=rms,
        check=check,
        mount=mount,
        adjustment=res,
        local=setup.local,
        warnings=warnings + list(res.warnings),
        scale_bars=bar_result(setup.bars, res, lay.points) if setup.bars is not None else None,
        timing=timing,
    )


def _timing_warnings(timing: dict, limit: float) -> list[str]:
    """A warning naming the parameters whose |correlation| with dt is above ``limit``."""
    high = [(n, r) for n, r in timing["correlation"].items() if abs(r) > limit]
    if not high:
        return []
    return [
        _t(
            "the camera timing offset dt is correlated with {names}: its sigma ({sigma:.2f} ms) "
            "carries that trade-off (strips at different speeds, or held interior orientation "
            "and lever arm, separate them better)",
            names=", ".join(f"{n} ({r:+.3f})" for n, r in high),
            sigma=1e3 * timing["dt_std_s"],
        )
    ]


def _timing(run: _Run) -> dict | None:
    """dt (s), its sigma and its correlations (see :class:`BundleResult`), or None."""
    lay, res = run.lay, run.result
    if lay.timing < 0:
        return None
    others = [
        *(lay.mount if lay.mount is not None else ()),
        *np.concatenate(
            [np.asarray(i, dtype=np.intp) for i in lay.interior] or [np.zeros(0, np.intp)]
        ),
    ]
    corr: dict[str, float] = {}
    if res.cofactor is not None or res.cofactor_blocks is not None:
        eo = lay.eo.ravel()
        # pair by pair: the whole (1 + 6M)-square block is not needed (for a large block
        # it would be solved from the band factor column by column)
        r_eo = np.array([res.correlation_of([lay.timing, e])[0, 1] for e in eo])
        k = int(np.argmax(np.abs(r_eo)))
        idx = np.r_[lay.timing, np.asarray(others, dtype=np.intp)]
        r = res.correlation_of(idx)[0, 1:]
        corr = {lay.names[i]: float(v) for i, v in zip(others, r)}
        corr[lay.names[eo[k]]] = float(r_eo[k])
    return {
        "dt_s": float(res.x[lay.timing]),
        "dt_std_s": float(res.std[lay.timing]),
        "correlation": corr,
    }


def _wkt(local: Local) -> str:
    """The WKT of the tables written in the frame of ``local`` (empty: no CRS)."""
    return "" if isinstance(local, EngineeringLocal) else local.mapping.crs.to_wkt()
