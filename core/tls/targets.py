"""Targets in terrestrial laser scans: spheres of known radius and planar checkerboards.

Every fit works in the scanner frame of its scan (:mod:`.polar`) and returns the target
centre with its 3 x 3 covariance, the observation the self-calibration takes.

Spheres
-------
RANSAC (Fischler & Bolles 1981) on four-point spheres (algebraic solution of
``|p|^2 + D.p + E = 0``), hypotheses whose radius is far from the known one discarded, the
inliers scored with the known radius. Then a least-squares fit (:mod:`core.lsq`) of the
radial misfits ``|p_i - c| - R``, each weighted with its point's variance along the sphere
normal from the scanner's noise (range along the beam, angles across it): the Gauss-Helmert
equivalent weight at the approximate centre. It gives the centre ``c`` (and, optionally, ``R``)
with its a-posteriori covariance. Outliers beyond 3.5 sigma of the refined sphere are dropped
and the fit repeated once; the inlier count and RMS reported are those of the points fitted.

Checkerboards
-------------
A planar target with a 2 x 2 pattern of black and white squares. RANSAC plane, then the
intensity of the inliers is modelled as ``m + a tanh(u'/s) tanh(v'/s)`` where ``(u', v')`` are
the in-plane coordinates rotated by beta about the centre ``(u0, v0)`` and ``s`` the blur of
the laser footprint (about half the point spacing); a Gauss-Markov adjustment gives
``(u0, v0, beta, m, a)``. The 3D centre is the plane point of ``(u0, v0)``; its covariance
combines the in-plane covariance with the plane's offset variance along the normal.

Detection and correspondence
----------------------------
:func:`detect_spheres` votes for centres ``p - R n`` (``n`` the local normal turned toward
the scanner) in a voxel grid and verifies each peak with :func:`fit_sphere`.
:func:`detect_checkerboards` scores seeds of high local intensity contrast against the
checker pattern and verifies them with :func:`fit_checkerboard`. In :mod:`.correspondence`,
``match_targets`` finds the same targets in two scans from their distances alone (rigid bodies
keep them), and ``label_targets`` gives the targets of all scans common ids, optionally those
of control points.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import AdjustmentError, InputError, stop_if_asked
from ..lsq.adjustment import adjust
from ..lsq.model import AdjustmentOptions, GaussMarkovBlock

__all__ = [
    "TargetFit",
    "beam_covariance",
    "detect_checkerboards",
    "detect_spheres",
    "fit_checkerboard",
    "fit_sphere",
]

log = logging.getLogger(__name__)
Array = NDArray[np.float64]


@dataclass(frozen=True)
class TargetFit:
    """A target fitted in one scan (scanner frame).

    Attributes
    ----------
    kind : str
        ``"sphere"`` or ``"checkerboard"``.
    centre : ndarray (3,)
        Metres, scanner frame.
    cov : ndarray (3, 3)
        A-posteriori covariance of the centre (m^2).
    n_points, n_inliers : int
        Points given and points used in the final fit.
    rms : float
        RMS of the geometric residuals of the inliers (m): distance to the sphere, or to the
        plane of a checkerboard.
    sigma0 : float
        A-posteriori standard deviation of unit weight of the final fit.
    size : float
        Sphere radius (m; the known one unless estimated) or the board's half size.
    normal : ndarray (3,)
        Board normal toward the scanner (checkerboard), or the unit vector from the centre
        to the scanner (sphere).
    """

    kind: str
    centre: Array
    cov: Array
    n_points: int
    n_inliers: int
    rms: float
    sigma0: float
    size: float
    normal: Array

    @property
    def sigma(self) -> Array:
        """Standard deviations of the centre's x, y, z (m)."""
        return np.sqrt(np.clip(np.diag(self.cov), 0.0, None))


def beam_covariance(points: ArrayLike, sigma_range_m: float, sigma_angle_rad: float) -> Array:
    """(N, 3, 3) covariance of scan points: ``sigma_range`` along the beam (from the scanner at
    the origin), ``range * sigma_angle`` across it.

    >>> c = beam_covariance([[10.0, 0.0, 0.0]], 0.001, 1e-4)[0]
    >>> np.round(np.sqrt(np.diag(c)), 6).tolist()
    [0.001, 0.001, 0.001]
    """
    p = np.asarray(points, dtype=np.float64)
    r = np.linalg.norm(p, axis=1)
    u = p / np.maximum(r, 1e-12)[:, None]
    along = np.einsum("ni,nj->nij", u, u)
    across = np.eye(3)[None] - along
    return sigma_range_m**2 * along + (r * sigma_angle_rad)[:, None, None] ** 2 * across


# ----------------------------------------------------------------------------- spheres


def _spheres_from_quads(p: Array) -> tuple[Array, Array]:
    """Centres (B, 3) and radii (B,) of spheres through B quadruples (B, 4, 3); NaN when the
    four points are (nearly) coplanar."""
    a = np.concatenate([p, np.ones((*p.shape[:2], 1))], axis=-1)  # (B, 4, 4): [x y z 1]
    b = -np.sum(p * p, axis=-1)
    det = np.linalg.det(a)
    scale = np.abs(p - p.mean(axis=1, keepdims=True)).max(axis=(1, 2)) ** 3 + 1e-300
    ok = np.abs(det) > 1e-9 * scale
    sol = np.full((p.shape[0], 4), np.nan)
    if ok.any():
        sol[ok] = np.linalg.solve(a[ok], b[ok][..., None])[..., 0]
    c = -0.5 * sol[:, :3]
    r2 = np.sum(c * c, axis=1) - sol[:, 3]
    r = np.sqrt(np.where(r2 > 0, r2, np.nan))
    return c, r


def _ransac_sphere(
    p: Array, radius: float | None, threshold: float, rng: np.random.Generator, iterations: int
) -> tuple[Array, float, NDArray[np.bool_]]:
    n = p.shape[0]
    idx = rng.integers(0, n, size=(iterations, 4))
    distinct = (np.diff(np.sort(idx, axis=1), axis=1) > 0).all(axis=1)
    c, r = _spheres_from_quads(p[idx[distinct]])
    good = np.isfinite(r)
    if radius is not None:
        good &= np.abs(r - radius) < max(3 * threshold, 0.1 * radius)
    c, r = c[good], r[good]
    if c.shape[0] == 0:
        raise InputError("no sphere found among the points")
    rr = np.full(c.shape[0], radius) if radius is not None else r
    best, best_count = 0, -1
    for lo in range(0, c.shape[0], 64):  # (64, N) distances at a time
        d = np.abs(
            np.linalg.norm(p[None, :, :] - c[lo : lo + 64, None, :], axis=2)
            - rr[lo : lo + 64, None]
        )
        counts = (d < threshold).sum(axis=1)
        q = int(np.argmax(counts))
        if counts[q] > best_count:
            best, best_count = lo + q, int(counts[q])
    inl = np.abs(np.linalg.norm(p - c[best], axis=1) - rr[best]) < threshold
    return c[best], float(rr[best]), inl


class _SphereModel:
    """Radial misfit ``f = |p - c| - R`` of fixed points ``p``, parameters c (and R)."""

    def __init__(self, points: Array, free_radius: bool, radius: float) -> None:
        self.p = points
        self.free_radius = free_radius
        self.radius = radius

    def __call__(self, xl: Array) -> tuple[Array, Array]:
        d = self.p - xl[:, :3]
        dist = np.linalg.norm(d, axis=1)
        u = d / dist[:, None]
        r = xl[:, 3] if self.free_radius else self.radius
        j = -u[:, None, :]
        if self.free_radius:
            j = np.concatenate([j, -np.ones((len(u), 1, 1))], axis=2)
        return (dist - r)[:, None], j


def _sphere_lsq(
    p: Array, cov: Array, centre: Array, radius: float, free_radius: bool
) -> tuple[Array, Array, float, float]:
    """Sphere fit by least squares of the radial misfits, each weighted with its point's
    variance along the sphere normal (the Gauss-Helmert equivalent weight ``1 / u'Su`` at the
    approximate centre): centre, its covariance, radius, sigma0."""
    k = 4 if free_radius else 3
    x0 = np.r_[centre, radius] if free_radius else centre.copy()
    names = ["cx", "cy", "cz", "R"][:k]
    u = (p - centre) / np.linalg.norm(p - centre, axis=1)[:, None]
    sigma = np.sqrt(np.einsum("ni,nij,nj->n", u, cov, u))
    block = GaussMarkovBlock(
        name="sphere",
        observed=np.zeros((p.shape[0], 1)),
        sigma=sigma[:, None],
        param_index=np.tile(np.arange(k), (p.shape[0], 1)),
        model=_SphereModel(p, free_radius, radius),
    )
    res = adjust(x0, names, [block], options=AdjustmentOptions(max_iterations=30))
    if not res.converged:
        raise AdjustmentError("the sphere fit did not converge")
    r = float(res.x[3]) if free_radius else radius
    assert res.covariance is not None  # computed: no parameter block is eliminated
    return res.x[:3].copy(), res.covariance[:3, :3].copy(), r, float(res.sigma0)


def fit_sphere(
    points: ArrayLike,
    radius: float | None,
    sigma_range_m: float = 0.001,
    sigma_angle_rad: float = 20e-6,
    *,
    threshold: float | None = None,
    iterations: int = 400,
    min_points: int = 20,
    estimate_radius: bool = False,
    rng: np.random.Generator | int | None = 0,
) -> TargetFit:
    """Fit a sphere (known ``radius``, or free with ``radius=None``) to scan points.

    Parameters
    ----------
    points : ndarray (N, 3)
        Points in the scanner frame (the scanner at the origin), metres; outliers allowed.
    radius : float or None
        Known radius of the target sphere (m); None: estimated.
    sigma_range_m, sigma_angle_rad : float
        Noise of a scan point (range, and each angle), for the weights and the RANSAC
        threshold.
    threshold : float, optional
        RANSAC inlier distance (m); default 3 times the largest point sigma.
    iterations : int
        RANSAC hypotheses.
    min_points : int
        Fewer inliers fail the fit.
    estimate_radius : bool
        Estimate the radius as well even when one is given (checks a known radius).
    rng : Generator or int
        Random source of RANSAC.

    Returns
    -------
    TargetFit

    Raises
    ------
    InputError
        Too few points or inliers, no sphere among the points.
    """
    p = np.asarray(points, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3 or p.shape[0] < max(min_points, 4):
        raise InputError(
            f"a sphere fit needs at least {max(min_points, 4)} points, got "
            f"{p.shape[0] if p.ndim == 2 else 0}"
        )
    rng = np.random.default_rng(rng)
    cov = beam_covariance(p, sigma_range_m, sigma_angle_rad)
    point_sigma = float(np.sqrt(np.max(np.linalg.eigvalsh(cov)[:, -1])))
    thr = threshold if threshold is not None else 3.0 * point_sigma
    c, r, inl = _ransac_sphere(p, radius, thr, rng, iterations)
    free = radius is None or estimate_radius
    for _ in range(2):
        if inl.sum() < min_points:
            raise InputError(
                f"only {int(inl.sum())} points on the sphere (at least {min_points} needed)"
            )
        c, ccov, r, s0 = _sphere_lsq(p[inl], cov[inl], c, r, free)
        fitted = inl  # the set the centre, radius and covariance come from
        d = np.linalg.norm(p - c, axis=1) - r
        # Normalised distance with each point's sigma along the sphere normal.
        u = (p - c) / np.linalg.norm(p - c, axis=1)[:, None]
        sn = np.sqrt(np.einsum("ni,nij,nj->n", u, cov, u))
        new = np.abs(d) < 3.5 * max(s0, 1.0) * sn
        if np.array_equal(new, inl):
            break
        inl = new
    rms = float(np.sqrt(np.mean(d[fitted] ** 2)))
    towards = -c / max(float(np.linalg.norm(c)), 1e-12)
    return TargetFit("sphere", c, ccov, p.shape[0], int(fitted.sum()), rms, s0, r, towards)


# ----------------------------------------------------------------------------- checkerboards


def _ransac_plane(
    p: Array, threshold: float, rng: np.random.Generator, iterations: int
) -> NDArray[np.bool_]:
    n = p.shape[0]
    idx = np.array([rng.choice(n, 3, replace=False) for _ in range(iterations)])
    a, b, c = p[idx[:, 0]], p[idx[:, 1]], p[idx[:, 2]]
    nrm = np.cross(b - a, c - a)
    ln = np.linalg.norm(nrm, axis=1)
    ok = ln > 1e-12
    nrm = nrm[ok] / ln[ok, None]
    off = -np.sum(nrm * a[ok], axis=1)
    best, best_count = None, -1
    for q in range(nrm.shape[0]):
        inl = np.abs(p @ nrm[q] + off[q]) < threshold
        count = int(inl.sum())
        if count > best_count:
            best, best_count = inl, count
    if best is None:
        raise InputError("no plane found among the points")
    return best


class _CheckerModel:
    """``I = m + a tanh(u'/s) tanh(v'/s)``, parameters (u0, v0, beta, m, a)."""

    def __init__(self, uv: Array, blur: float) -> None:
        self.uv = uv
        self.s = blur

    def __call__(self, xl: Array) -> tuple[Array, Array]:
        u0, v0, beta, m, a = (xl[:, i] for i in range(5))
        du, dv = self.uv[:, 0] - u0, self.uv[:, 1] - v0
        cb, sb = np.cos(beta), np.sin(beta)
        up = du * cb + dv * sb
        vp = -du * sb + dv * cb
        tu, tv = np.tanh(up / self.s), np.tanh(vp / self.s)
        f = m + a * tu * tv
        fu = a * (1 - tu * tu) / self.s * tv
        fv = a * tu * (1 - tv * tv) / self.s
        j = np.zeros((len(f), 1, 5))
        j[:, 0, 0] = fu * -cb + fv * sb
        j[:, 0, 1] = fu * -sb + fv * -cb
        j[:, 0, 2] = fu * vp + fv * -up
        j[:, 0, 3] = 1.0
        j[:, 0, 4] = tu * tv
        return f[:, None], j


def _checker_start(uv: Array, b: Array, half: float) -> tuple[float, float, float, float]:
    """Coarse search of the centre and angle maximising |sum b sign(u') sign(v')|."""
    c0 = np.median(uv, axis=0)
    offs = np.linspace(-0.5 * half, 0.5 * half, 11)
    betas = np.radians(np.arange(0.0, 90.0, 5.0))
    best = (-1.0, 0.0, 0.0, 0.0, 1.0)
    for bt in betas:
        cb, sb = math.cos(bt), math.sin(bt)
        for ox in offs:
            du = uv[:, 0] - (c0[0] + ox)
            for oy in offs:
                dv = uv[:, 1] - (c0[1] + oy)
                up = du * cb + dv * sb
                vp = -du * sb + dv * cb
                near = (np.abs(up) < half) & (np.abs(vp) < half)
                if near.sum() < 8:
                    continue
                s = float(np.mean(b[near] * np.sign(up[near]) * np.sign(vp[near])))
                if abs(s) > best[0]:
                    best = (abs(s), c0[0] + ox, c0[1] + oy, bt, math.copysign(1.0, s))
    return best[1], best[2], best[3], best[4] * best[0]


def fit_checkerboard(
    points: ArrayLike,
    intensity: ArrayLike,
    half_size: float,
    sigma_range_m: float = 0.001,
    sigma_angle_rad: float = 20e-6,
    *,
    blur: float | None = None,
    iterations: int = 300,
    min_points: int = 30,
    min_contrast: float = 0.5,
    rng: np.random.Generator | int | None = 0,
) -> TargetFit:
    """Fit a 2 x 2 checkerboard target to scan points with intensities.

    Parameters
    ----------
    points : ndarray (N, 3)
        Scanner frame, metres; points off the board plane are rejected by RANSAC.
    intensity : ndarray (N,)
        Return intensity, any scale.
    half_size : float
        Distance from the centre to the outer edge of the pattern (m): the fit uses the
        points within it.
    sigma_range_m, sigma_angle_rad : float
        Point noise (plane RANSAC threshold, plane offset weight).
    blur : float, optional
        Width ``s`` of the intensity transition (m); default half the median point spacing.
    min_contrast : float
        Smallest accepted score of the checker pattern (mean of ``b sign(u') sign(v')`` over
        the board, 1 for a perfect pattern).

    Returns
    -------
    TargetFit

    Raises
    ------
    InputError
        Too few points, no plane, no checker pattern.
    """
    p = np.asarray(points, dtype=np.float64)
    it = np.asarray(intensity, dtype=np.float64)
    if p.shape[0] < min_points:
        raise InputError(f"a checkerboard fit needs at least {min_points} points, got {p.shape[0]}")
    rng = np.random.default_rng(rng)
    rmax = float(np.max(np.linalg.norm(p, axis=1)))
    point_sigma = math.hypot(sigma_range_m, rmax * sigma_angle_rad)
    inl = _ransac_plane(p, 3.0 * point_sigma, rng, iterations)
    q, iq = p[inl], it[inl]
    centroid = q.mean(axis=0)
    _, _, vt = np.linalg.svd(q - centroid, full_matrices=False)
    normal = vt[2] if np.dot(vt[2], -centroid) > 0 else -vt[2]
    e1 = vt[0]
    e2 = np.cross(normal, e1)
    uv = np.column_stack([(q - centroid) @ e1, (q - centroid) @ e2])
    dist = (q - centroid) @ normal
    thr = _otsu(iq)
    b = np.where(iq > thr, 1.0, -1.0)
    u0, v0, beta, score = _checker_start(uv, b, half_size)
    if abs(score) < min_contrast:
        raise InputError(
            f"no checker pattern in the points (score {abs(score):.2f} < {min_contrast:g})"
        )
    lo, hi = np.percentile(iq, [10, 90])
    spacing = _median_spacing(uv)
    s_blur = blur if blur is not None else max(0.5 * spacing, 1e-4)
    for _ in range(2):
        du, dv = uv[:, 0] - u0, uv[:, 1] - v0
        up = du * math.cos(beta) + dv * math.sin(beta)
        vp = -du * math.sin(beta) + dv * math.cos(beta)
        use = (np.abs(up) < 0.9 * half_size) & (np.abs(vp) < 0.9 * half_size)
        if use.sum() < min_points:
            raise InputError(
                f"only {int(use.sum())} points on the board (at least {min_points} needed)"
            )
        within = np.abs(iq[use] - np.where(b[use] > 0, hi, lo))
        sig_i = max(1.4826 * float(np.median(within)), 1e-6 * max(abs(hi - lo), 1e-12))
        model = _CheckerModel(uv[use], s_blur)
        x0 = np.array([u0, v0, beta, 0.5 * (hi + lo), math.copysign(0.5 * (hi - lo), score)])
        block = GaussMarkovBlock(
            name="checkerboard",
            observed=iq[use, None],
            sigma=np.full((int(use.sum()), 1), sig_i),
            param_index=np.tile(np.arange(5), (int(use.sum()), 1)),
            model=model,
        )
        res = adjust(
            x0,
            ["u0", "v0", "beta", "m", "a"],
            [block],
            options=AdjustmentOptions(max_iterations=40),
        )
        if not res.converged:
            raise AdjustmentError("the checkerboard fit did not converge")
        u_new, v_new, beta = float(res.x[0]), float(res.x[1]), float(res.x[2])
        moved = math.hypot(u_new - u0, v_new - v0)
        u0, v0 = u_new, v_new
        if moved < 0.05 * s_blur:
            break
    assert res.covariance is not None  # computed: no parameter block is eliminated
    c2 = res.covariance[:2, :2]
    centre = centroid + u0 * e1 + v0 * e2
    plane_var = float(np.var(dist) / max(len(dist) - 3, 1))
    basis = np.column_stack([e1, e2, normal])
    local = np.zeros((3, 3))
    local[:2, :2] = c2
    local[2, 2] = plane_var
    cov = basis @ local @ basis.T
    rms = float(np.sqrt(np.mean(dist**2)))
    return TargetFit(
        "checkerboard",
        centre,
        cov,
        p.shape[0],
        int(use.sum()),
        rms,
        float(res.sigma0),
        half_size,
        normal,
    )


def _otsu(values: Array, bins: int = 128) -> float:
    """Otsu's threshold of a bimodal sample."""
    hist, edges = np.histogram(values, bins=bins)
    mids = 0.5 * (edges[1:] + edges[:-1])
    w = np.cumsum(hist).astype(np.float64)
    total = w[-1]
    mu = np.cumsum(hist * mids)
    with np.errstate(divide="ignore", invalid="ignore"):
        between = (mu[-1] * w - mu * total) ** 2 / (w * (total - w))
    between[~np.isfinite(between)] = -1
    return float(mids[int(np.argmax(between))])


def _median_spacing(uv: Array) -> float:
    from scipy.spatial import cKDTree

    if len(uv) < 2:
        return 0.0
    d, _ = cKDTree(uv).query(uv, k=2)
    return float(np.median(d[:, 1]))


# ----------------------------------------------------------------------------- detection


def _normals(p: Array, k: int = 12) -> tuple[Array, Array]:
    """Unit normals toward the scanner (origin) and surface variation by k-NN PCA."""
    from scipy.spatial import cKDTree

    k = min(k, len(p))
    _, nb = cKDTree(p).query(p, k=k)
    q = p[nb] - p[nb].mean(axis=1, keepdims=True)
    cov = np.einsum("nki,nkj->nij", q, q) / k
    w, v = np.linalg.eigh(cov)
    n = v[:, :, 0]
    flip = np.sum(n * p, axis=1) > 0
    n[flip] *= -1
    variation = w[:, 0] / np.maximum(w.sum(axis=1), 1e-300)
    return n, variation


def detect_spheres(
    points: ArrayLike,
    radius: float,
    sigma_range_m: float = 0.001,
    sigma_angle_rad: float = 20e-6,
    *,
    min_points: int = 30,
    max_rms_factor: float = 3.0,
    voxel: float | None = None,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> list[TargetFit]:
    """Find spheres of a known radius in a scan (scanner frame).

    Each point votes for the centre ``p - R n`` (its normal ``n`` turned toward the scanner);
    the voxels (``R/2``) with most votes are verified by :func:`fit_sphere` on the points
    within ``1.5 R`` of the voted centre: a sphere is kept when it has ``min_points`` inliers,
    its RMS is below ``max_rms_factor`` times the point noise, a freely estimated radius is
    within 10 % of ``radius``, and it is not a duplicate of a sphere already found.

    Returns
    -------
    list of TargetFit
        Ordered by their direction from the scanner (horizontal angle).
    """
    from scipy.spatial import cKDTree

    p = np.asarray(points, dtype=np.float64)
    if p.shape[0] < min_points:
        return []
    step = voxel if voxel is not None else radius / 4.0
    # Thin the cloud for the vote: one point per voxel of R/4.
    keys = np.floor(p / step).astype(np.int64)
    _, first = np.unique(keys, axis=0, return_index=True)
    sub = p[np.sort(first)]
    if sub.shape[0] < 12:
        return []
    n, _ = _normals(sub)
    votes = sub - radius * n
    cell = radius / 2.0
    vk = np.floor(votes / cell).astype(np.int64)
    _, inv, counts = np.unique(vk, axis=0, return_inverse=True, return_counts=True)
    inv = inv.ravel()
    order = np.argsort(-counts)
    tree = cKDTree(p)
    found: list[TargetFit] = []
    point_sigma = math.hypot(
        sigma_range_m, float(np.median(np.linalg.norm(p, axis=1))) * sigma_angle_rad
    )
    # A visible hemisphere fills about 2 pi R^2 / step^2 voxels of the thinned cloud (about
    # 100); a wall's offset plane puts about (cell / step)^2 = 4 votes in a cell.
    min_votes = max(12, int(0.2 * 2 * math.pi * (radius / step) ** 2))
    for rank, q in enumerate(order):
        stop_if_asked(should_stop, "detecting spheres")
        if counts[q] < min_votes:
            break
        centre = votes[inv == q].mean(axis=0)
        if any(np.linalg.norm(f.centre - centre) < radius for f in found):
            continue
        near = tree.query_ball_point(centre, 1.5 * radius)
        if len(near) < min_points:
            continue
        try:
            fit = fit_sphere(
                p[near],
                radius,
                sigma_range_m,
                sigma_angle_rad,
                min_points=min_points,
                estimate_radius=True,
            )
        except (InputError, AdjustmentError):
            continue
        if abs(fit.size - radius) > 0.1 * radius or fit.rms > max_rms_factor * point_sigma:
            continue
        if not _sphere_support(p[near], fit, point_sigma):
            continue
        if any(np.linalg.norm(f.centre - fit.centre) < radius for f in found):
            continue
        # Refit with the known radius (the estimated one only checked the candidate).
        try:
            fit = fit_sphere(p[near], radius, sigma_range_m, sigma_angle_rad, min_points=min_points)
        except (InputError, AdjustmentError):
            continue
        found.append(fit)
        if progress is not None:
            progress(min(1.0, (rank + 1) / max(len(order), 1)))
    found.sort(key=lambda f: math.atan2(f.centre[1], f.centre[0]))
    return found


def _sphere_support(p: Array, fit: TargetFit, point_sigma: float) -> bool:
    """A real sphere target fills its visible cap: the inliers cover at least a cap of 30
    degrees and hold at least a third of the points the cap would hold at their spacing."""
    d = np.abs(np.linalg.norm(p - fit.centre, axis=1) - fit.size)
    inl = p[d < 3 * max(point_sigma, fit.rms)]
    if inl.shape[0] < 10:
        return False
    u = (inl - fit.centre) / np.linalg.norm(inl - fit.centre, axis=1)[:, None]
    spread = float(np.linalg.norm(u.mean(axis=0)))
    if spread > math.cos(math.radians(30.0)):
        return False
    spacing = _median_spacing(inl)
    if spacing <= 0:
        return False
    expected = math.pi * fit.size**2 / spacing**2
    return inl.shape[0] >= expected / 3.0


def detect_checkerboards(
    points: ArrayLike,
    intensity: ArrayLike,
    half_size: float,
    sigma_range_m: float = 0.001,
    sigma_angle_rad: float = 20e-6,
    *,
    min_points: int = 30,
    min_contrast: float = 0.6,
    progress: Callable[[float], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> list[TargetFit]:
    """Find 2 x 2 checkerboard targets of a known half size in a scan (scanner frame).

    Seeds: points whose neighbourhood within ``half_size`` is planar and has a bimodal
    intensity (both classes of a global Otsu threshold present in at least a quarter each);
    their neighbourhoods are scored against the checker pattern (:func:`fit_checkerboard`),
    the best-scoring fits kept, duplicates (closer than ``half_size``) removed.
    """
    from scipy.spatial import cKDTree

    p = np.asarray(points, dtype=np.float64)
    it = np.asarray(intensity, dtype=np.float64)
    if p.shape[0] < min_points:
        return []
    tree = cKDTree(p)
    thr = _otsu(it)
    white = it > thr
    step = half_size / 2.0
    keys = np.floor(p / step).astype(np.int64)
    _, first = np.unique(keys, axis=0, return_index=True)
    seeds = np.sort(first)
    share = np.empty(seeds.size)
    for k, s in enumerate(seeds):
        nb = tree.query_ball_point(p[s], 0.7 * half_size)
        share[k] = np.mean(white[nb]) if len(nb) >= min_points else 0.0
    cand = seeds[(share > 0.25) & (share < 0.75)]

    def fit_near(centre: np.ndarray) -> TargetFit | None:
        """The checkerboard fitted to the points within 1.2 half sizes of ``centre`` (m,
        scanner frame), or None where none fits."""
        nb = tree.query_ball_point(centre, 1.2 * half_size)
        try:
            return fit_checkerboard(
                p[nb],
                it[nb],
                half_size,
                sigma_range_m,
                sigma_angle_rad,
                min_points=min_points,
                min_contrast=min_contrast,
            )
        except (InputError, AdjustmentError):
            return None

    found: list[TargetFit] = []
    for k, s in enumerate(cand):
        stop_if_asked(should_stop, "detecting checkerboards")
        if any(np.linalg.norm(f.centre - p[s]) < 0.7 * half_size for f in found):
            continue
        fit = fit_near(p[s])
        if fit is None or np.linalg.norm(fit.centre - p[s]) > half_size:
            continue
        # Refit centred on the found centre (the seed may sit off-centre).
        fit = fit_near(fit.centre)
        if fit is None:
            continue
        if any(np.linalg.norm(f.centre - fit.centre) < half_size for f in found):
            continue
        found.append(fit)
        if progress is not None:
            progress((k + 1) / max(cand.size, 1))
    found.sort(key=lambda f: math.atan2(f.centre[1], f.centre[0]))
    return found
