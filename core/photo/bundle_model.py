"""The model of a bundle adjustment (:mod:`.bundle`): the parameter layout, the observation
blocks (image points through the collinearity equations, control points, observed
orientations with the mount), the datum constraints, and one run of the adjustment.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .. import compiled
from ..geometry.camera import Camera
from ..geometry.collinearity import collinearity_jacobians
from ..geometry.distortion import NoDistortion
from ..geometry.rotations import matrix_to_opk, opk_derivatives, opk_to_matrix
from ..lsq.adjustment import adjust
from ..lsq.model import AdjustmentOptions, Constraint, GaussMarkovBlock
from ..lsq.results import AdjustmentResult
from .bundle_setup import EO_PARAM_NAMES, BundleOptions, _Setup
from .observations import ImageObservations
from .scale_bars import BLOCK_NAME as BARS
from .scale_bars import bar_block

#: catalogue context of this module's ``_t("...")`` sentences (``make i18n``): the reports'
TR_CONTEXT = "Report"

Array = NDArray[np.float64]
#: The name of the camera timing offset (seconds) among the adjustment's parameters.
TIMING_NAME = "timing dt"
#: The names of the lever-arm correction (camera axes) among the adjustment's parameters.
LEVER_NAMES = ("lever dx_c", "lever dy_c", "lever dz_c")
# Image measurements projected at once by the collinearity model (bounds its temporaries).
_CHUNK = 65536


@dataclass
class _Layout:
    """Parameter layout of one adjustment run."""

    names: list[str]
    x0: Array
    eo: NDArray[np.intp]  # (M, 6)
    interior: list[NDArray[np.intp]]  # per camera, indices of its free interior parameters
    free: list[NDArray[np.intp]]  # per camera, positions within Camera.interior_params
    mount: NDArray[np.intp] | None  # (6,)
    points: NDArray[np.intp]  # (P, 3)
    timing: int = -1  # index of the timing offset dt (s), -1 when not estimated


def _layout(
    setup: _Setup,
    free: list[NDArray[np.intp]],
    cams: list[Camera],
    eo: Array,
    xyz: Array,
    mount: Array | None,
    timing: float | None = None,
) -> _Layout:
    names: list[str] = []
    values: list[Array] = []
    M = len(setup.images)
    for im in setup.images:
        names += [f"{im} {p}" for p in EO_PARAM_NAMES]
    values.append(eo.ravel())
    idx_eo = np.arange(6 * M).reshape(M, 6)
    start = 6 * M
    interior = []
    for c, cam in enumerate(cams):
        inames = cam.interior_names
        f = free[c]
        names += [f"{cam.name} {inames[j]}" for j in f]
        values.append(cam.interior_params[f])
        interior.append(np.arange(start, start + f.size))
        start += f.size
    idx_mount = None
    if mount is not None:
        names += [*LEVER_NAMES, "boresight d_omega", "boresight d_phi", "boresight d_kappa"]
        values.append(mount)
        idx_mount = np.arange(start, start + 6)
        start += 6
    idx_dt = -1
    if timing is not None:
        names.append(TIMING_NAME)
        values.append(np.array([timing], dtype=np.float64))
        idx_dt = start
        start += 1
    P = len(setup.points)
    names += [f"{p} {c}" for p in setup.points for c in "XYZ"]
    values.append(xyz.ravel())
    idx_pts = np.arange(start, start + 3 * P).reshape(P, 3)
    return _Layout(
        names, np.concatenate(values), idx_eo, interior, free, idx_mount, idx_pts, idx_dt
    )


class _ImageModel:
    """Collinearity of the measurements of one camera: x_local = [eo(6), point(3), interior].

    ``img`` is the image of each group: the rotations are computed once per image.
    """

    #: every call returns a new Jacobian (the adjustment may whiten it in place)
    fresh_jacobian = True

    def __init__(self, cam: Camera, free: NDArray[np.intp], img: NDArray[np.intp]) -> None:
        self.cam = cam
        self.free = free
        _, self.first, self.inv = np.unique(img, return_index=True, return_inverse=True)
        self.inv = np.asarray(self.inv).ravel()

    def __call__(self, xl: Array) -> tuple[Array, Array]:
        cam = self.cam
        wrt = ("eo", "point", "interior") if self.free.size else ("eo", "point")
        if self.free.size:
            full = cam.interior_params
            full[self.free] = xl[0, 9:]
            cam = cam.with_interior(full)
        n = xl.shape[0]
        eo = xl[self.first, :6]
        jac = np.empty((n, 2, 9 + self.free.size))
        pixels = np.empty((n, 2))
        # the compiled geometry writes the EO and point columns in place and has no per-ray
        # temporaries beyond (n, 2) ones: a camera without lens model or free interior
        # parameters is projected at once; else in chunks of groups, which bound the lens
        # model's temporaries (and the numpy path's rotations and partial derivatives: some
        # 700 bytes a ray); every row is computed alone
        fast = cam.projection == "perspective" and compiled.AVAILABLE
        whole = fast and isinstance(cam.distortion, NoDistortion) and not self.free.size
        step = max(n, 1) if whole else _CHUNK
        for s in range(0, n, step):
            sl = slice(s, min(n, s + step))
            out = collinearity_jacobians(xl[sl, 6:9], eo, cam, wrt=wrt, image_index=self.inv[sl],
                                         out=jac[sl] if fast else None)  # fmt: skip
            pixels[sl] = out["pixels"]
            if not fast:
                jac[sl, :, :6] = out["eo"]
                jac[sl, :, 6:9] = out["point"]
            if self.free.size:
                jac[sl, :, 9:] = out["interior"][:, :, self.free]
        return pixels, jac


class _IdentityModel:
    def __call__(self, xl: Array) -> tuple[Array, Array]:
        g, k = xl.shape
        return xl.copy(), np.broadcast_to(np.eye(k), (g, k, k)).copy()


def _dopk_dm(m: Array) -> Array:
    """d (omega, phi, kappa) / d M (entries row-major), (N, 3, 9), for matrix_to_opk."""
    n = m.shape[0]
    out = np.zeros((n, 3, 9))
    m21, m22 = m[:, 2, 1], m[:, 2, 2]
    den = m21**2 + m22**2
    out[:, 0, 7] = -m22 / den  # omega = atan2(-m21, m22)
    out[:, 0, 8] = m21 / den
    a, b0, b1 = m[:, 2, 0], m[:, 0, 0], m[:, 1, 0]
    h = np.hypot(b0, b1)
    r2 = a**2 + h**2
    out[:, 1, 6] = h / r2  # phi = atan2(a, h)
    out[:, 1, 0] = -a * b0 / (h * r2)
    out[:, 1, 3] = -a * b1 / (h * r2)
    c, d = m[:, 1, 0], m[:, 0, 0]
    den2 = c**2 + d**2
    out[:, 2, 3] = -d / den2  # kappa = atan2(-m10, m00)
    out[:, 2, 0] = c / den2
    return out


class _ObservedEOModel:
    """Observed orientation (GNSS/INS with the nominal mount) against the adjusted one, in
    the conventions of docs/conventions.md, "Rotations" (``X_pc = X_obs + R_c^m da``,
    ``R_c^m = R_obs dR``):
    ``X_obs = X0 - M' da``, ``M_obs = dR M`` with ``da`` the lever-arm correction in camera
    axes and ``dR`` the boresight correction about the camera axes (what a boresight
    calibration estimates). x_local = [eo(6), da(3), bore(3)] with ``mount``, then dt (s)
    with ``velocity`` (G, 3; m/s in the adjustment frame): the centre observed at the
    recorded time is ``X_obs = X0 - M' da - v dt`` (exposure = recorded time + dt; the
    attitude's change over dt is neglected, second order on straight lines)."""

    def __init__(self, observed: Array, mount: bool = True, velocity: Array | None = None) -> None:
        self.observed = observed
        self.mount = mount
        self.velocity = velocity

    def __call__(self, xl: Array) -> tuple[Array, Array]:
        f, J = self._full(xl)
        cols = list(range(6)) + (list(range(6, 12)) if self.mount else [])
        if self.velocity is not None:
            cols.append(12)
        return f, J[:, :, cols]

    def _full(self, xl: Array) -> tuple[Array, Array]:
        """The prediction and its Jacobian with respect to [eo(6), da(3), bore(3), dt]."""
        from ..geometry.rotations import boresight_matrix, rx, ry, rz, skew

        g = xl.shape[0]
        eo = xl[:, :6]
        da, bo = (xl[:, 6:9], xl[:, 9:12]) if self.mount else (np.zeros((g, 3)),) * 2
        dt = xl[:, -1] if self.velocity is not None else np.zeros(g)
        M = opk_to_matrix(eo[:, 3], eo[:, 4], eo[:, 5])
        dM = opk_derivatives(eo[:, 3], eo[:, 4], eo[:, 5])  # (g, 3, 3, 3)
        dR = boresight_matrix(bo[:, 0], bo[:, 1], bo[:, 2])
        Mobs = dR @ M
        f = np.zeros((g, 6))
        J = np.zeros((g, 6, 13))
        f[:, :3] = eo[:, :3] - np.einsum("gji,gj->gi", M, da)
        if self.velocity is not None:
            f[:, :3] -= self.velocity * dt[:, None]
            J[:, :3, 12] = -self.velocity
        J[:, :3, :3] = np.eye(3)
        J[:, :3, 3:6] = -np.einsum("gkji,gj->gik", dM, da)
        J[:, :3, 6:9] = -np.swapaxes(M, 1, 2)
        om, ph, ka = matrix_to_opk(Mobs)
        f[:, 3:] = np.column_stack([om, ph, ka])
        # keep the predicted angles on the branch of the observed ones
        f[:, 3:] = (
            self.observed[:, 3:] + (f[:, 3:] - self.observed[:, 3:] + np.pi) % (2 * np.pi) - np.pi
        )
        dop = _dopk_dm(Mobs)  # (g, 3, 9)
        for k in range(3):
            dMobs = dR @ dM[:, k]
            J[:, 3:, 3 + k] = np.einsum("gaj,gj->ga", dop, dMobs.reshape(g, 9))
        # dR = Rx(a) Ry(b) Rz(c): d Rx(a)/da = Rx(a) [e_x]x, and likewise
        ra, rb, rc = rx(bo[:, 0]), ry(bo[:, 1]), rz(bo[:, 2])
        gen = [skew(e) for e in np.eye(3)]
        d_dR = (ra @ gen[0] @ rb @ rc, ra @ rb @ gen[1] @ rc, ra @ rb @ rc @ gen[2])
        for k in range(3):
            dMobs = d_dR[k] @ M
            J[:, 3:, 9 + k] = np.einsum("gaj,gj->ga", dop, dMobs.reshape(g, 9))
        return f, J


def _blocks(
    setup: _Setup, lay: _Layout, cams: list[Camera], obs: ImageObservations, keep: NDArray[np.bool_]
) -> tuple[list, list, list[str]]:
    """Observation blocks; returns them, the measurement rows and the names of the
    image-point blocks."""
    blocks = []
    rows_of = []
    names = []
    elim = _eliminated(setup)
    # a scale bar's ends stay in the reduced system: their measurements form blocks of their
    # own (a block's point columns are eliminated in every group or in none)
    parts = [(c, cam, e) for c, cam in enumerate(cams) for e in (True, False)]
    for c, cam, e in parts:
        rows = np.flatnonzero(
            keep
            & (setup.obs_pt >= 0)
            & (setup.image_cam[setup.obs_img] == c)
            & (elim[np.maximum(setup.obs_pt, 0)] == e)
        )
        if rows.size == 0:
            continue
        img, pt = setup.obs_img[rows], setup.obs_pt[rows]
        idx = np.concatenate(
            [
                lay.eo[img],
                lay.points[pt],
                np.broadcast_to(lay.interior[c], (rows.size, lay.interior[c].size)),
            ],
            axis=1,
        )
        labels = [f"{obs.image_id[r]} / {obs.point_id[r]}" for r in rows]
        blocks.append(
            GaussMarkovBlock(
                name=f"image points {cam.name}" + ("" if e else " (scale bar ends)"),
                observed=obs.pixels[rows],
                sigma=np.repeat(obs.sigma_px[rows, None], 2, axis=1),
                param_index=idx,
                model=_ImageModel(cam, lay.free[c], img),
                labels=labels,
                row_names=("col", "row"),
            )
        )
        rows_of.append(rows)
        names.append(blocks[-1].name)
    if setup.control_pt.size:
        blocks.append(
            GaussMarkovBlock(
                name="control points",
                observed=setup.control_local,
                sigma=setup.control_cov,
                param_index=lay.points[setup.control_pt],
                model=_IdentityModel(),
                labels=[setup.points[i] for i in setup.control_pt],
                row_names=("E", "N", "U"),
            )
        )
    if setup.eo_obs is not None:
        M = len(setup.images)
        if lay.mount is not None or lay.timing >= 0:
            parts = [lay.eo]
            if lay.mount is not None:
                parts.append(np.broadcast_to(lay.mount, (M, 6)))
            if lay.timing >= 0:
                parts.append(np.full((M, 1), lay.timing, dtype=np.intp))
            idx = np.concatenate(parts, axis=1)
            velocity = setup.velocity if lay.timing >= 0 else None
            model = _ObservedEOModel(setup.eo_obs, lay.mount is not None, velocity)
        else:
            idx = lay.eo
            model = _IdentityModel()
        blocks.append(
            GaussMarkovBlock(
                name="observed orientation",
                observed=setup.eo_obs,
                sigma=setup.eo_obs_cov,
                param_index=idx,
                model=model,
                labels=list(setup.images),
                row_names=EO_PARAM_NAMES,
            )
        )
    if setup.bars is not None:
        blocks.append(bar_block(setup.bars, lay.points))
    return blocks, rows_of, names


def _datum_constraints(setup: _Setup, lay: _Layout, datum: str, xyz0: Array, eo0: Array):
    if datum == "control":
        return []
    if datum == "inner":
        tie = np.arange(len(setup.points))
        P0 = xyz0[tie]
        cen = P0.mean(axis=0)
        q = P0 - cen
        scale = max(float(np.sqrt(np.mean(np.sum(q * q, axis=1)))), 1e-9)
        G = np.zeros((7, tie.size, 3))
        G[0, :, 0] = G[1, :, 1] = G[2, :, 2] = 1.0
        # rotations about E, N, U: the columns of -[q]x, scaled to metres at the network size
        G[3, :, 1], G[3, :, 2] = -q[:, 2] / scale, q[:, 1] / scale
        G[4, :, 0], G[4, :, 2] = q[:, 2] / scale, -q[:, 0] / scale
        G[5, :, 0], G[5, :, 1] = -q[:, 1] / scale, q[:, 0] / scale
        G[6] = q / scale
        if setup.bars is not None:  # the scale bars carry the scale: no scale row
            G = G[:6]
        Gm = G.reshape(len(G), -1)
        base = P0.ravel()

        def inner(xl: Array, Gm=Gm, base=base) -> tuple[Array, Array]:
            return (Gm @ (xl[0] - base))[None], Gm[None]

        return [Constraint("inner constraints", lay.points[tie].ravel()[None], inner)]
    # minimal: the first image's orientation and the largest coordinate of the baseline to
    # the farthest centre, held at their approximate values
    far = int(np.argmax(np.linalg.norm(eo0[:, :3] - eo0[0, :3], axis=1)))
    axis = int(np.argmax(np.abs(eo0[far, :3] - eo0[0, :3])))
    held = np.concatenate([lay.eo[0], [lay.eo[far, axis]]])
    vals = np.concatenate([eo0[0], [eo0[far, axis]]])
    if setup.bars is not None:  # the scale bars carry the scale: the first image alone
        held, vals = held[:6], vals[:6]

    def minimal(xl: Array, vals=vals) -> tuple[Array, Array]:
        return (xl[0] - vals)[None], np.eye(vals.size)[None]

    return [Constraint("minimal constraints", held[None], minimal)]


@dataclass
class _Run:
    result: AdjustmentResult
    lay: _Layout
    cams: list[Camera]
    blocks_rows: list[NDArray[np.intp]]  # measurement rows of each image-point block
    block_names: list[str]
    keep: NDArray[np.bool_]


def _run(
    setup: _Setup,
    obs: ImageObservations,
    cams: list[Camera],
    free: list,
    options: BundleOptions,
    keep: NDArray[np.bool_],
    robust: str,
    snooping: bool,
    eo: Array,
    xyz: Array,
    mount: Array | None,
    should_stop,
    progress,
    timing: float | None = None,
) -> _Run:
    lay = _layout(setup, free, cams, eo, xyz, mount, timing)
    blocks, rows_of, bnames = _blocks(setup, lay, cams, obs, keep)
    cons = _datum_constraints(setup, lay, options.datum, setup.xyz0, setup.eo0)
    opts = AdjustmentOptions(
        robust_blocks=bnames,
        snooping_blocks=bnames + ([BARS] if setup.bars is not None else []),
        max_iterations=options.max_iterations,
        snooping=snooping,
        snooping_alpha=options.snooping_alpha,
        robust=robust,
        eliminate=lay.points[_eliminated(setup)] if _eliminated(setup).any() else None,
        max_rejections=max(50, len(obs) // 20),
        # a millionth of each parameter's precision: far below anything reported, and the
        # linear convergence of large-residual blocks reaches it in a few iterations
        tolerance=1e-6,
        compute_covariance=options.covariance,
    )
    result = adjust(
        lay.x0, lay.names, blocks, cons, opts, progress=progress, should_stop=should_stop
    )
    return _Run(result, lay, cams, rows_of, bnames, keep)


def _eliminated(setup: _Setup) -> NDArray[np.bool_]:
    """The points eliminated by the Schur complement: all but the scale bars' ends (a group
    may see one eliminated block only; a bar sees two points)."""
    out = np.ones(len(setup.points), dtype=bool)
    if setup.bars is not None:
        out[setup.bars.a] = out[setup.bars.b] = False
    return out


def _cams_from(run: _Run) -> list[Camera]:
    out = []
    for c, cam in enumerate(run.cams):
        full = cam.interior_params
        full[run.lay.free[c]] = run.result.x[run.lay.interior[c]]
        out.append(cam.with_interior(full))
    return out
