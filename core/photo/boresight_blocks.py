"""The observation blocks of the boresight calibration (:mod:`.boresight`), one stage per kind
of control: INS priors, plane-constrained tie points, points on LiDAR lines, LCPs and surveyed
points, and the single-image model of Pedrosa & dos Santos (2020).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from ..errors import InputError
from ..geometry.frames import NED_TO_ENU, LocalFrame
from ..lidar.control import LINE_PARAMETERS
from ..lsq.model import GaussHelmertBlock, GaussMarkovBlock, prior_block
from .boresight_models import (
    PoseSpec,
    camera_ray,
    collinearity,
    coplanarity,
    paper_plane,
)
from .boresight_setup import BoresightOptions, _index, _KnownPoint, transform_lcps, transform_lines
from .georeference import Trajectory
from .ins import InsGrade
from .observations import ImageObservations

Array = NDArray[np.float64]


class _Identity:
    """Gauss-Markov model ``f(x) = x`` for groups of c parameters observed together."""

    def __call__(self, x_local: Array) -> tuple[Array, Array]:
        g, c = x_local.shape
        return x_local.copy(), np.broadcast_to(np.eye(c), (g, c, c)).copy()


class _TimedPosition:
    """Gauss-Markov model of the INS position at the recorded time with a timing offset:
    ``p_ins = p - v dt`` (p the position at exposure, v (G, 3) m/s, dt s; first order)."""

    def __init__(self, velocity: Array) -> None:
        self.velocity = velocity

    def __call__(self, x_local: Array) -> tuple[Array, Array]:
        g = x_local.shape[0]
        f = x_local[:, :3] - self.velocity * x_local[:, 3:4]
        jac = np.zeros((g, 3, 4))
        jac[:, :, :3] = np.eye(3)
        jac[:, :, 3] = -self.velocity
        return f, jac


def _regular(cov: Array) -> Array:
    """Covariances made positive definite: a plane's (a, b, c, d) has rank 3 (unit normal), a
    line's (X0, u) rank 4 or 5; the engine factors them, so their null directions (and rounding
    below) get a variance of 1e-12 of the largest one (effect on ``B S B'``: 1e-9 relative)."""
    val, vec = np.linalg.eigh(0.5 * (cov + np.swapaxes(cov, 1, 2)))
    floor = 1e-12 * val[:, -1:]
    val = np.maximum(val, floor)
    out = (vec * val[:, None, :]) @ np.swapaxes(vec, 1, 2)
    return 0.5 * (out + np.swapaxes(out, 1, 2))


def _block_diag(jac: Array, k: int) -> Array:
    """(L * k, P) rows -> (L, k, k * P) block-diagonal Jacobians of grouped conditions."""
    p = jac.shape[-1]
    lk = jac.shape[0] // k
    out = np.zeros((lk, k, k, p))
    ar = np.arange(k)
    out[:, ar, ar, :] = jac.reshape(lk, k, p)
    return out.reshape(lk, k, k * p)


@dataclass
class _Stage:
    """What the stages of :func:`~.boresight.calibrate` share: the observation rows in use and
    the pose parameters of their images, and the parameters, blocks and residual maps built
    so far (each stage appends its own)."""

    observations: ImageObservations
    kinds: NDArray  # (N,) type of each row
    used: NDArray[np.bool_]  # (N,)
    img: NDArray[np.intp]  # (N,) image number of each row used, -1 otherwise
    pose_idx: NDArray[np.intp]  # (images, spec.size)
    r_nl: Array  # (images, 3, 3) NED at each image -> the adjustment frame
    spec: PoseSpec
    local: LocalFrame
    names: list[str]
    x_init: Array
    blocks: list[GaussMarkovBlock | GaussHelmertBlock] = field(default_factory=list)
    # (block name, obs rows (G, k), kind) for the residual table
    maps: list[tuple[str, Array, str]] = field(default_factory=list)

    def rows(self, kind: str) -> NDArray[np.intp]:
        """The rows of one observation type in use."""
        return np.arange(len(self.observations))[self.used & (self.kinds == kind)]

    def init_pose(self, rows: Array) -> Array:
        """Initial pose parameters of the images of ``rows``."""
        return self.x_init[self.pose_idx[self.img[rows]]]


def _ins_blocks(
    trajectory: Trajectory,
    grade: InsGrade,
    opts: BoresightOptions,
    r_nl: Array,
    ins_pos: Array,
    ins_at: int,
    timing_at: int = -1,
    velocity: Array | None = None,
) -> list[GaussMarkovBlock]:
    """The INS positions and attitudes as priors with the grade's sigmas (tiny ones unless
    ``ins_as_parameters``: then the poses are held at the INS)."""
    n_img = len(trajectory)
    scale = 1.0 if opts.ins_as_parameters else 1e-6
    enu_i = r_nl @ NED_TO_ENU.T  # ENU at each image -> the adjustment frame
    cov_pos = enu_i @ np.diag((scale * grade.sigma_position) ** 2) @ np.swapaxes(enu_i, 1, 2)
    pos_idx = ins_at + 6 * np.arange(n_img)[:, None] + np.arange(3)
    model: _Identity | _TimedPosition = _Identity()
    if timing_at >= 0 and velocity is not None:
        pos_idx = np.hstack([pos_idx, np.full((n_img, 1), timing_at)])
        model = _TimedPosition(velocity)
    position = GaussMarkovBlock(
        "ins position",
        ins_pos,
        0.5 * (cov_pos + np.swapaxes(cov_pos, 1, 2)),
        pos_idx,
        model,
        labels=[f"ins[{i}] position" for i in trajectory.image_id],
        row_names=("E", "N", "U"),
    )
    att_idx = (ins_at + 6 * np.arange(n_img)[:, None] + np.arange(3, 6)).ravel()
    attitude = prior_block(
        "ins attitude",
        att_idx,
        trajectory.rph.ravel(),
        np.tile(scale * grade.sigma_attitude, n_img),
    )
    return [position, attitude]


def _tie_blocks(
    st: _Stage,
    planes: Sequence,
    plane_by_id: Mapping[str, int],
    p_params: Array,
    p_cov: Array,
    roughness_m: float,
) -> None:
    """1. Plane-constrained tie points: their coordinates unknowns, their image points, and
    per plane the condition that its tie points lie on it."""
    observations = st.observations
    tie_rows = st.rows("tie")
    if not tie_rows.size:
        return
    pid = [observations.point_id[r] for r in tie_rows]
    tie_names = list(dict.fromkeys(pid))
    tie_of = {t: k for k, t in enumerate(tie_names)}
    tk = np.array([tie_of[t] for t in pid])
    plane_of_tie = np.full(len(tie_names), -1)
    for r, k in zip(tie_rows, tk):
        pl = _index([observations.target_id[r]], plane_by_id, "plane", np.array([r]))[0]
        if plane_of_tie[k] not in (-1, pl):
            raise InputError(f"observation {r + 2}: tie point '{tie_names[k]}' on two planes")
        plane_of_tie[k] = pl
    # initial coordinates: the first ray of each tie point cut with its plane
    first = np.unique(tk, return_index=True)[1]
    fr = tie_rows[first]
    centre, ray, *_ = camera_ray(
        st.init_pose(fr), observations.pixels[fr], st.r_nl[st.img[fr]], st.spec
    )
    pl = p_params[plane_of_tie]
    t = -(np.einsum("ti,ti->t", pl[:, :3], centre) + pl[:, 3]) / np.einsum(
        "ti,ti->t", pl[:, :3], ray
    )
    tie_at = len(st.names)
    for name in tie_names:
        st.names += [f"tie[{name}].{a}" for a in "XYZ"]
    st.x_init = np.concatenate([st.x_init, (centre + t[:, None] * ray).ravel()])
    tie_idx = tie_at + 3 * np.arange(len(tie_names))[:, None] + np.arange(3)
    st.blocks.append(
        _collinearity_block(
            "tie image points",
            tie_rows,
            tk,
            tie_idx,
            observations,
            st.img,
            st.pose_idx,
            st.r_nl,
            st.spec,
        )
    )
    st.maps.append(("tie image points", tie_rows[:, None], "gm"))
    counts = np.bincount(plane_of_tie, minlength=len(planes))
    for k in np.unique(counts[counts > 0]):
        sel = np.flatnonzero(counts == k)
        members = np.array([np.flatnonzero(plane_of_tie == p) for p in sel]).reshape(-1, k)
        st.blocks.append(
            _tie_plane_block(
                f"tie planes k={k}",
                k,
                sel,
                members,
                tie_idx,
                p_params,
                p_cov,
                roughness_m,
                [str(planes[p].id) for p in sel],
            )
        )


def _segments(st: _Stage, line_rows: NDArray[np.intp], lk: NDArray[np.intp], sigmas) -> Array:
    """The nuisance unknowns of the lines' segments (one line in one image): their offset and
    tilt across the line (pixels) appended to the stage's parameters with their priors
    (``sigmas``, :class:`~.boresight_options.BoresightOptions.line_segment_sigmas_px`); returns
    (N, 3) per row of ``line_rows``: the offset's and the tilt's parameter index and the
    row's position along its segment, -1 .. 1 from its middle (0 for fewer than 3 points)."""
    pix = st.observations.pixels[line_rows]
    key = st.img[line_rows].astype(np.int64) * (int(lk.max()) + 1) + lk
    _, seg = np.unique(key, return_inverse=True)
    seg = seg.ravel()
    tau = np.zeros(len(line_rows))
    for s in range(int(seg.max()) + 1):
        at = np.flatnonzero(seg == s)
        if at.size < 3:
            continue
        d = pix[at] - pix[at].mean(axis=0)
        t = d @ np.linalg.svd(d, full_matrices=False)[2][0]
        half = float(np.max(np.abs(t)))
        tau[at] = t / half if half > 0 else 0.0
    base, n_seg = len(st.names), int(seg.max()) + 1
    for s in range(n_seg):
        r = line_rows[np.flatnonzero(seg == s)[0]]
        tag = f"{st.observations.image_id[r]}:L{st.observations.target_id[r]}"
        st.names += [f"segment {tag} offset", f"segment {tag} tilt"]
    st.x_init = np.concatenate([st.x_init, np.zeros(2 * n_seg)])
    idx = base + 2 * np.arange(n_seg)
    for j, what in enumerate(("offsets", "tilts")):
        st.blocks.append(prior_block(f"line segment {what}", idx + j, 0.0, float(sigmas[j])))
    return np.column_stack([base + 2 * seg, base + 2 * seg + 1, tau])


def _line_blocks(st: _Stage, lines: Sequence, segment_sigmas=(0.0, 0.0)) -> None:
    """2. Points on LiDAR lines: per line, the rays of its points meet it (with the nuisance
    offset and tilt of each segment when ``segment_sigmas`` are > 0: :func:`_segments`)."""
    observations = st.observations
    line_rows = st.rows("line")
    if not line_rows.size:
        return
    line_by_id = {str(ln.id): k for k, ln in enumerate(lines)}
    lk = _index([observations.target_id[r] for r in line_rows], line_by_id, "line", line_rows)
    lx0, lu, lcov = transform_lines(list(lines), st.local)
    nuis = None
    if min(segment_sigmas) > 0:
        nuis = np.zeros((len(observations), 3))
        nuis[line_rows] = _segments(st, line_rows, lk, segment_sigmas)
    counts = np.bincount(lk, minlength=len(lines))
    for k in np.unique(counts[counts > 0]):
        sel = np.flatnonzero(counts == k)
        members = np.array([line_rows[lk == s] for s in sel]).reshape(-1, k)
        name = f"line points k={k}"
        st.blocks.append(
            _line_block(
                name,
                k,
                sel,
                members,
                lx0,
                lu,
                lcov,
                observations,
                st.img,
                st.pose_idx,
                st.r_nl,
                st.spec,
                [str(lines[s].id) for s in sel],
                None if nuis is None else nuis[members],
            )
        )
        st.maps.append((name, members, "line"))


def _point_blocks(st: _Stage, lcps: Sequence, surveyed: Sequence[_KnownPoint]) -> None:
    """3. LCPs and surveyed ground points: the point an unknown with its prior."""
    observations = st.observations
    for kind, what, keys, known in (
        ("lcp", "LCP", observations.target_id, lcps),
        ("control", "ground point", observations.point_id, surveyed),
    ):
        k_rows = st.rows(kind)
        if not k_rows.size:
            continue
        by_id = {str(p.id): k for k, p in enumerate(known)}
        ck = _index([keys[r] for r in k_rows], by_id, what, k_rows)
        used_pts = np.unique(ck)
        remap = {c: k for k, c in enumerate(used_pts)}
        cxyz, ccov = transform_lcps([known[c] for c in used_pts], st.local)
        pts_at = len(st.names)
        for c in used_pts:
            st.names += [f"{kind}[{known[c].id}].{a}" for a in "XYZ"]
        st.x_init = np.concatenate([st.x_init, cxyz.ravel()])
        pts_idx = pts_at + 3 * np.arange(len(used_pts))[:, None] + np.arange(3)
        st.blocks.append(
            _collinearity_block(
                f"{kind} image points",
                k_rows,
                np.array([remap[c] for c in ck]),
                pts_idx,
                observations,
                st.img,
                st.pose_idx,
                st.r_nl,
                st.spec,
            )
        )
        st.maps.append((f"{kind} image points", k_rows[:, None], "gm"))
        st.blocks.append(
            GaussMarkovBlock(
                f"{kind} coordinates",
                cxyz,
                ccov,
                pts_idx,
                _Identity(),
                labels=[f"{kind} {known[c].id}" for c in used_pts],
                row_names=("X", "Y", "Z"),
            )
        )


def _collinearity_block(
    name, rows, point_k, point_idx, obs, img, pose_idx, r_nl, spec
) -> GaussMarkovBlock:
    """Collinearity of measurements of unknown points (tie points, LCPs)."""
    p = spec.size
    rn = r_nl[img[rows]]

    def model(x_local: Array) -> tuple[Array, Array]:
        px, j_pose, j_point = collinearity(x_local[:, :p], x_local[:, p:], rn, spec)
        return px, np.concatenate([j_pose, j_point], axis=2)

    return GaussMarkovBlock(
        name,
        obs.pixels[rows],
        np.repeat(obs.sigma_px[rows][:, None], 2, axis=1),
        np.hstack([pose_idx[img[rows]], point_idx[point_k]]),
        model,
        labels=[f"{obs.image_id[r]} / {obs.point_id[r]}" for r in rows],
        row_names=("col", "row"),
    )


def _tie_plane_block(name, k, sel, members, tie_idx, p_params, p_cov, rough, plane_names):
    """Gauss-Helmert: the k tie points of a plane lie on it, n . X_j + d - e_j = 0."""
    lk = len(sel)
    obs = np.hstack([p_params[sel], np.zeros((lk, k))])
    cov = np.zeros((lk, 4 + k, 4 + k))
    cov[:, :4, :4] = _regular(p_cov[sel])
    cov[:, np.arange(4, 4 + k), np.arange(4, 4 + k)] = rough**2
    ar = np.arange(k)

    def condition(x_local: Array, l_hat: Array) -> tuple[Array, Array, Array]:
        xyz = x_local.reshape(-1, k, 3)
        n, d = l_hat[:, :3], l_hat[:, 3]
        g = np.einsum("gkj,gj->gk", xyz, n) + d[:, None] - l_hat[:, 4:]
        a = _block_diag(np.repeat(n, k, axis=0), k)
        b = np.zeros((xyz.shape[0], k, 4 + k))
        b[:, :, :3] = xyz
        b[:, :, 3] = 1.0
        b[:, ar, 4 + ar] = -1.0
        return g, a, b

    return GaussHelmertBlock(
        name,
        obs,
        cov,
        tie_idx[members].reshape(lk, 3 * k),
        condition,
        labels=[f"plane {p}" for p in plane_names],
        row_names=("a", "b", "c", "d", *[f"e{j}" for j in range(k)]),
    )


def _distinct_index(full: NDArray[np.intp]) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """(G, m) parameter indices with repeats -> ((G, u) the distinct indices of each group,
    padded with its first index where a group has fewer than u, (G, m) the column of each
    entry among them). The padding's Jacobian columns are left zero by the model (repeated
    indices add up in the adjustment), so the group's equations are unchanged; only the
    columns that are all zero are gone (a line seen in n images has 3 + 6 n parameters, not
    9 per measurement)."""
    g, m = full.shape
    found = [np.unique(row, return_inverse=True) for row in full]
    u = max((len(vals) for vals, _ in found), default=0)
    index = np.empty((g, u), dtype=np.intp)
    cols = np.empty((g, m), dtype=np.intp)
    for i, (vals, inv) in enumerate(found):
        index[i, : len(vals)] = vals
        index[i, len(vals) :] = vals[0]
        cols[i] = inv.ravel()
    return index, cols


def _line_block(
    name, k, sel, members, lx0, lu, lcov, obs, img, pose_idx, r_nl, spec, line_names, nuis=None
):
    """Gauss-Helmert: every measured ray of a line is coplanar with it (the group's parameters
    are the distinct pose parameters of its measurements: :func:`_distinct_index`). With
    ``nuis`` ((lines, k, 3): each measurement's segment offset and tilt parameter and its
    position along the segment, :func:`_segments`), the condition is that of the pixel moved
    across the projected line by the segment's offset + position * tilt (pixels): ``g -
    (a + tau b) |dg/dpx|`` (``g / |dg/dpx|`` is the pixel's distance from the projected line;
    the change of ``|dg/dpx|`` with the pose, a second-order term, is left out of the
    Jacobians)."""
    lk = len(sel)
    p = spec.size
    flat = members.ravel()
    full = pose_idx[img[flat]].reshape(lk, k * p)
    if nuis is not None:
        full = np.hstack([full, nuis[:, :, :2].astype(np.intp).reshape(lk, 2 * k)])
    index, cols = _distinct_index(full)
    at = (
        np.arange(lk)[:, None, None],
        np.arange(k)[None, :, None],
        cols[:, : k * p].reshape(lk, k, p),
    )
    o = 2 * k + 6
    observed = np.hstack([obs.pixels[flat].reshape(lk, 2 * k), lx0[sel], lu[sel]])
    cov = np.zeros((lk, o, o))
    s2 = np.repeat(obs.sigma_px[members] ** 2, 2, axis=1)
    cov[:, np.arange(2 * k), np.arange(2 * k)] = s2
    cov[:, 2 * k :, 2 * k :] = _regular(lcov[sel])
    rn = r_nl[img[flat]]
    ar = np.arange(k)
    pose_cols = cols[:, : k * p]
    if nuis is not None:
        seg_cols = cols[:, k * p :].reshape(lk, k, 2)
        at_seg = (np.arange(lk)[:, None, None], np.arange(k)[None, :, None], seg_cols)
        tau = nuis[:, :, 2]

    def condition(x_local: Array, l_hat: Array) -> tuple[Array, Array, Array]:
        xp = np.take_along_axis(x_local, pose_cols, axis=1).reshape(-1, p)
        px = l_hat[:, : 2 * k].reshape(-1, 2)
        x0 = np.repeat(l_hat[:, 2 * k : 2 * k + 3], k, axis=0)
        u = np.repeat(l_hat[:, 2 * k + 3 :], k, axis=0)
        g, j_pose, j_px, j_pt, j_dir = coplanarity(xp, px, x0, u, rn, spec)
        n = l_hat.shape[0]
        b = np.zeros((n, k, o))
        jp = j_px.reshape(n, k, 2)
        b[:, ar, 2 * ar] = jp[:, :, 0]
        b[:, ar, 2 * ar + 1] = jp[:, :, 1]
        b[:, :, 2 * k : 2 * k + 3] = j_pt.reshape(n, k, 3)
        b[:, :, 2 * k + 3 :] = j_dir.reshape(n, k, 3)
        a = np.zeros((n, k, index.shape[1]))
        a[at] = j_pose.reshape(n, k, p)  # the p parameters of one measurement are distinct
        g = g.reshape(n, k)
        if nuis is not None:
            rate = np.hypot(jp[:, :, 0], jp[:, :, 1])
            ab = np.take_along_axis(x_local, seg_cols.reshape(n, 2 * k), axis=1).reshape(n, k, 2)
            g = g - (ab[:, :, 0] + tau * ab[:, :, 1]) * rate
            a[at_seg] = np.stack([-rate, -tau * rate], axis=2)
        return g, a, b

    return GaussHelmertBlock(
        name,
        observed,
        cov,
        index,
        condition,
        labels=[f"line {s}" for s in line_names],
        row_names=(
            *[f"{c}{j}" for j in range(k) for c in ("col", "row")],
            *LINE_PARAMETERS,
        ),
    )


def _paper_blocks(
    st: _Stage,
    planes: Sequence,
    plane_by_id: Mapping[str, int],
    p_params: Array,
    p_cov: Array,
    cloud: tuple[Array | None, NDArray | None],
    opts: BoresightOptions,
) -> None:
    """4. Eq. 15 of Pedrosa & dos Santos (2020) with d observed, for the ``paper`` rows; z
    from the LiDAR points near the picked point (``cloud``: the points (M, 3) in the mapping
    CRS and their plane ids (M,))."""
    rows = st.rows("paper")
    if not rows.size:
        return
    lidar_points, lidar_plane_ids = cloud
    if lidar_points is None or lidar_plane_ids is None:
        raise InputError("paper-mode observations need the LiDAR points and their plane ids")
    obs, img, spec, local = st.observations, st.img, st.spec, st.local
    pk = _index([obs.target_id[r] for r in rows], plane_by_id, "plane", rows)
    xp0 = st.init_pose(rows)
    rn = st.r_nl[img[rows]]
    centre, ray, *_ = camera_ray(xp0, obs.pixels[rows], rn, spec)
    pl = p_params[pk]
    t = -(np.einsum("ti,ti->t", pl[:, :3], centre) + pl[:, 3]) / np.einsum(
        "ti,ti->t", pl[:, :3], ray
    )
    picked = centre + t[:, None] * ray
    ids = np.asarray(lidar_plane_ids)
    z = np.empty(rows.size)
    kn = max(1, int(opts.paper_z_neighbours))
    for p in np.unique(pk):
        on = np.flatnonzero(ids == planes[p].id)
        if on.size == 0:
            raise InputError(f"paper mode: no LiDAR points carry plane id {planes[p].id}")
        pts = local.map_to_enu(np.asarray(lidar_points, dtype=np.float64)[on])
        sel = np.flatnonzero(pk == p)
        _, nn = cKDTree(pts[:, :2]).query(picked[sel, :2], k=min(kn, on.size))
        nn = np.asarray(nn).reshape(sel.size, -1)
        z[sel] = pts[nn, 2].mean(axis=1)
    if opts.paper_sigma == "eq17":
        # Eq. 17 as printed, with the centroid in the mapping CRS (as the paper computed it)
        cent = np.array([planes[p].centroid for p in pk])
        npts = np.array([max(planes[p].n_points, 1) for p in pk], dtype=np.float64)
        sigma = np.linalg.norm(cent, axis=1) + opts.lidar_sigma_m**2 / npts
    elif opts.paper_sigma == "propagated":
        xh = np.hstack([picked, np.ones((rows.size, 1))])
        sigma = np.sqrt(np.einsum("ti,tij,tj->t", xh, p_cov[pk], xh))
    else:
        raise InputError(f"paper_sigma '{opts.paper_sigma}' is unknown: eq17 or propagated")
    normal = pl[:, :3]
    px = obs.pixels[rows]

    def model(x_local: Array) -> tuple[Array, Array]:
        d, j = paper_plane(x_local, px, normal, z, rn, spec)
        return d[:, None], j

    st.blocks.append(
        GaussMarkovBlock(
            "paper planes",
            pl[:, 3:4],
            sigma[:, None],
            st.pose_idx[img[rows]],
            model,
            labels=[f"{obs.image_id[r]} / {obs.point_id[r]}" for r in rows],
            row_names=("d",),
        )
    )
    st.maps.append(("paper planes", rows[:, None], "paper"))
