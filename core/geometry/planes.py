"""Planes fitted to points with their precision, and the plane table (CSV).

Convention (docs/conventions.md, "Planes"): a plane is ``n . p + d = 0`` with the unit
normal ``n = (a, b, c)`` pointing up (``c >= 0``), ``p`` in the cloud's projected CRS (all lengths
in the CRS's unit: metres, or international feet for e.g. Autzen).

Fit: the weighted eigen method of Pathak et al. (2010), computed on centred coordinates. With
weights ``w_i`` (relative: point i has a residual variance ``sigma0^2 / w_i``) the plane minimising
``sum w_i (n . p_i + d)^2`` passes through the weighted centroid ``m`` and its normal is the
eigenvector of the smallest eigenvalue ``l3`` of the weighted scatter matrix ``S = sum w_i (p_i -
m)(p_i - m)^T`` (eigenpairs ``l1 >= l2 >= l3``, ``v1, v2, v3``). The raw moment matrix of ``[x y z
1]`` used by Pedrosa & dos Santos (2020, Eq. 5) is never formed: with map coordinates of 1e5-1e6 m
its smallest eigenvalue drowns in rounding.

Precision (first-order propagation of a noise along the normal, equal to Pathak's closed form
from the Hessian of the weighted sum of squares; checked by Monte Carlo in
tests/core/test_planes.py)::

    sigma0^2 = sum w_i r_i^2 / (n - 3)                      a-posteriori variance factor
    C_nn     = sigma0^2 (v1 v1^T / (l1 - l3) + v2 v2^T / (l2 - l3))
    var(s)   = sigma0^2 / sum w_i                            offset of the plane at m
    d = -n . m  =>  C_nd = -C_nn m,  var(d) = m^T C_nn m + sigma0^2 / sum w_i

``sigma_d = sqrt(var(d))`` is Khoshelham's (2016) standard deviation of d, used by Pedrosa & dos
Santos (2020) Eq. (17) (printed there as ``sqrt(Cx^2 + Cy^2 + Cz^2) + sigma^2 / n``, a misprint of
the same propagation with an isotropic normal variance). ``d`` is the distance of the CRS origin to
the plane, so with map coordinates sigma_d is dominated by the lever ``m`` and is strongly
correlated with the normal: use the full covariance (the plane table keeps all of it) when
propagating, e.g. to plane intersections.

The plane table (CSV) is :mod:`core.io.planes`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from .sym3 import eigh_sym3

__all__ = ["Plane", "fit_plane", "fit_planes", "label_moments", "orient_up", "slope_aspect_deg"]

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Plane:
    """A plane ``n . p + d = 0`` fitted to points, with its precision.

    Attributes
    ----------
    id : int
        Plane id (as in the cloud's ``plane_id`` dimension; -1 for a plane not yet numbered).
    normal : ndarray, shape (3,)
        Unit normal (a, b, c), ``c >= 0`` (up for roofs).
    d : float
        Offset, CRS unit: ``n . p + d = 0``.
    centroid : ndarray, shape (3,)
        Weighted centroid of the points, CRS unit.
    n_points : int
        Number of points fitted.
    rms : float
        Weighted root mean square of the point-to-plane residuals, CRS unit.
    sigma_d : float
        Standard deviation of d (Khoshelham 2016), CRS unit: ``sqrt(covariance[3, 3])``.
    covariance : ndarray, shape (4, 4)
        Covariance of (a, b, c, d), scaled by the a-posteriori variance factor. Rank 3: the
        normal's length is fixed, so ``covariance @ (a, b, c, 0) = 0``.
    slope_deg : float
        Angle between the plane and the horizontal, degrees in [0, 90].
    aspect_deg : float
        Direction of steepest descent, degrees clockwise from grid north in [0, 360).
    outline : ndarray, shape (M, 3)
        Outline polygon (not closed: the first vertex is not repeated), CRS unit; empty when
        unknown (e.g. read back from a plane table).
    """

    id: int
    normal: Array
    d: float
    centroid: Array
    n_points: int
    rms: float
    sigma_d: float
    covariance: Array
    slope_deg: float
    aspect_deg: float
    outline: Array = field(default_factory=lambda: np.empty((0, 3)))

    @property
    def params(self) -> Array:
        """(a, b, c, d), shape (4,)."""
        return np.append(self.normal, self.d)

    def distance(self, points: ArrayLike) -> Array:
        """Signed distances of points (N, 3) to the plane, CRS unit, positive above (N,).

        >>> p = fit_plane([[0, 0, 1], [1, 0, 1], [0, 1, 1], [1, 1, 1.0]])
        >>> p.distance([[5.0, 5.0, 3.0]]).round(6).tolist()
        [2.0]
        """
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        # relative to the centroid: map coordinates of 1e6 would lose digits in n.p + d
        return (pts - self.centroid) @ self.normal

    def with_id(self, new_id: int) -> Plane:
        """The same plane with another id."""
        return replace(self, id=int(new_id))

    def with_outline(self, outline: ArrayLike) -> Plane:
        """The same plane with an outline polygon (M, 3)."""
        return replace(self, outline=np.asarray(outline, dtype=np.float64).reshape(-1, 3))


def orient_up(normal: Array) -> Array:
    """Flip a unit normal (3,) so that c >= 0 (for c == 0: b >= 0, then a >= 0)."""
    for comp in normal[::-1]:
        if comp != 0.0:
            return normal if comp > 0.0 else -normal
    return normal


def slope_aspect_deg(normal: Array) -> tuple[float, float]:
    """Slope (degrees from horizontal) and aspect (degrees clockwise from grid north of the
    downslope direction) of an upward unit normal (3,).

    The downslope direction of ``z = -(a x + b y + d) / c`` is ``(a, b)``.

    >>> [round(v, 6) for v in slope_aspect_deg(np.array([0.5, 0.0, math.sqrt(0.75)]))]
    [30.0, 90.0]
    """
    a, b, c = (float(v) for v in normal)
    slope = math.degrees(math.atan2(math.hypot(a, b), abs(c)))
    aspect = math.degrees(math.atan2(a, b)) % 360.0
    return slope, aspect


def fit_plane(points: ArrayLike, weights: ArrayLike | None = None, *, plane_id: int = -1) -> Plane:
    """Weighted least-squares plane (Pathak et al. 2010) with its covariance.

    The same arithmetic as :func:`fit_planes` (sums in point order by ``np.bincount``, the
    3 x 3 eigen-problem by :func:`core.geometry.sym3.eigh_sym3`, no BLAS or LAPACK): the same
    bits on any thread count or numpy; with unit weights, those of :func:`fit_planes` given
    the same points as one label.

    Parameters
    ----------
    points : array_like, shape (N, 3)
        Points in a projected CRS (any unit; the results are in the same unit), N >= 3.
    weights : array_like, shape (N,), optional
        Relative weights (inverse variances up to a common factor), all > 0. Default: 1.
    plane_id : int
        Id stored in the result.

    Returns
    -------
    Plane
        Normal up (c >= 0), d, centroid, rms, sigma_d and the 4x4 covariance of (a, b, c, d),
        scaled by the a-posteriori variance factor ``sum w r^2 / (N - 3)`` (with N = 3 the
        covariance is zero: no redundancy).

    Raises
    ------
    InputError
        Fewer than 3 points, non-finite values, bad weights, or (near) collinear points.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> xy = rng.uniform(0, 10, (200, 2))
    >>> z = 2.0 + 0.5 * xy[:, 0]
    >>> p = fit_plane(np.column_stack([xy, z]))
    >>> round(p.slope_deg, 6), round(p.aspect_deg, 6), round(p.rms, 9)
    (26.565051, 270.0, 0.0)
    """
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise InputError(f"points must have shape (N, 3), got {pts.shape}")
    n = len(pts)
    if n < 3:
        raise InputError(f"a plane needs at least 3 points, got {n}")
    if not np.isfinite(pts).all():
        raise InputError("points contain NaN or infinite coordinates")
    w = None
    if weights is not None:
        w = np.asarray(weights, dtype=np.float64).reshape(-1)
        if w.shape != (n,):
            raise InputError(f"weights must have shape ({n},), got {w.shape}")
        if not (np.isfinite(w).all() and (w > 0).all()):
            raise InputError("weights must be finite and > 0")
    plane = _fit_labels(pts, np.zeros(n, dtype=np.int64), 1, w)[0]
    if plane is None:
        raise InputError("the points are collinear or coincident: no unique plane")
    return plane.with_id(plane_id)


def label_moments(
    q: NDArray[np.float64],
    lab: NDArray[np.int64],
    nl: int,
    weights: NDArray[np.float64] | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Point counts (L,), centroids (L, 3) and scatter matrices (L, 3, 3) of the points ``q``
    (N, 3) of each label ``lab`` (N,) in 0..L-1, in two passes (centroid first: no
    cancellation), summed in point order (``np.bincount``: no BLAS). With ``weights`` (N,):
    the weight sums, weighted centroids and weighted scatter matrices (unit weights give the
    unweighted moments bit for bit).

    >>> c, m, s = label_moments(np.array([[0., 0, 0], [2, 0, 0], [5, 5, 5]]),
    ...                         np.array([0, 0, 1]), 2)
    >>> c.tolist(), m[0].tolist(), float(s[0, 0, 0]), float(s[1].sum())
    ([2.0, 1.0], [1.0, 0.0, 0.0], 2.0, 0.0)
    """

    def weighted(values: NDArray[np.float64]) -> NDArray[np.float64]:
        return values if weights is None else weights * values

    if weights is None:
        counts = np.bincount(lab, minlength=nl).astype(np.float64)
    else:
        counts = np.bincount(lab, weights, minlength=nl).astype(np.float64, copy=False)
    # weighted bincounts are float64 already (copy=False: no copy; the stubs say integers)
    mean = np.column_stack(
        [np.bincount(lab, weighted(q[:, c]), minlength=nl) for c in range(3)]
    ).astype(np.float64, copy=False)
    mean /= np.where(counts > 0, counts, 1.0)[:, None]
    dev = q - mean[lab]
    scatter = np.empty((nl, 3, 3))
    for a in range(3):
        for b in range(a, 3):
            scatter[:, a, b] = scatter[:, b, a] = np.bincount(
                lab, weighted(dev[:, a] * dev[:, b]), minlength=nl
            )
    return counts, mean, scatter


def fit_planes(
    points: ArrayLike, labels: ArrayLike, n_planes: int | None = None
) -> list[Plane | None]:
    """:func:`fit_plane` (unit weights) of every label at once: plane ``l`` is fitted to the
    points with ``labels == l`` (ids 0..L-1; -1 = no plane).

    The same estimator and covariance as :func:`fit_plane`, with the moments of all planes
    summed in one pass over the points (coordinates centred on the first point's floor, so
    map coordinates keep their digits). Repeatable: every sum runs in point order
    (``np.bincount``), the eigen-problems by fixed Jacobi rotations
    (:func:`core.geometry.sym3.eigh_sym3`) and every small product written out, so no BLAS
    or LAPACK call is made and the planes are the same bits for any thread count, BLAS build
    or numpy version. A label with fewer than 3 points, or collinear ones, gives None.

    Parameters
    ----------
    points : array_like, shape (N, 3)
    labels : array_like of int, shape (N,)
    n_planes : int, optional
        L (default: the largest label + 1).

    Returns
    -------
    list of Plane or None, length L (ids = labels)

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> xy = rng.uniform(0, 10, (400, 2))
    >>> z = np.where(xy[:, 0] < 5, 0.2 * xy[:, 0], 3.0 - 0.4 * xy[:, 1])
    >>> labels = (xy[:, 0] >= 5).astype(int)
    >>> planes = fit_planes(np.column_stack([xy, z]), labels)
    >>> [round(p.slope_deg, 4) for p in planes], [p.n_points for p in planes]
    ([11.3099, 21.8014], [175, 225])
    """
    pts = np.asarray(points, dtype=np.float64)
    lab = np.asarray(labels, dtype=np.int64).reshape(-1)
    if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) != len(lab):
        raise InputError("points must have shape (N, 3) and labels (N,)")
    nl = int(lab.max()) + 1 if n_planes is None and len(lab) else int(n_planes or 0)
    m = (lab >= 0) & (lab < nl)
    if not m.any():
        return [None] * nl
    return _fit_labels(pts[m], lab[m], nl, None)


def _dot3(u: Array, v: Array) -> Array:
    """Row-wise dot products of (..., 3) arrays, summed in the order 0, 1, 2 (no BLAS)."""
    return u[..., 0] * v[..., 0] + u[..., 1] * v[..., 1] + u[..., 2] * v[..., 2]


def _fit_labels(pts: Array, lab: NDArray[np.int64], nl: int, w: Array | None) -> list[Plane | None]:
    """The planes of labels 0..nl-1 (``lab`` (N,) all in range) of ``pts`` (N, 3) with
    relative weights ``w`` (N,) or unit weights (None); None for a label with fewer than 3
    points or collinear ones. Fixed-order sums and Jacobi eigen-problems only."""
    origin = np.floor(pts[0])
    q = pts - origin
    counts = np.bincount(lab, minlength=nl)
    wsum, mean, scatter = label_moments(q, lab, nl, w)
    lam, vec = eigh_sym3(scatter)  # ascending
    extent = lam[:, 2]
    ok = (counts >= 3) & (extent > 0) & (lam[:, 1] > 1e-12 * extent)
    normal = vec[:, :, 0].copy()
    # orient_up, vectorised: the last non-zero component positive
    sign = np.where(
        normal[:, 2] != 0,
        np.sign(normal[:, 2]),
        np.where(normal[:, 1] != 0, np.sign(normal[:, 1]), np.sign(normal[:, 0])),
    )
    normal *= np.where(sign < 0, -1.0, 1.0)[:, None]
    r = _dot3(q - mean[lab], normal[lab])
    wrr = np.bincount(lab, r * r if w is None else w * (r * r), minlength=nl)
    centroid = origin + mean
    with np.errstate(divide="ignore", invalid="ignore"):  # labels not ok are dropped below
        sigma0_sq = np.where(counts > 3, wrr / np.maximum(counts - 3, 1), 0.0)
        cov = _covariances(lam, vec, centroid, sigma0_sq, wsum)
        rms = np.sqrt(wrr / wsum)
    d = -_dot3(normal, centroid)
    out: list[Plane | None] = []
    for pid in range(nl):
        if not ok[pid]:
            out.append(None)
            continue
        slope, aspect = slope_aspect_deg(normal[pid])
        out.append(
            Plane(
                id=pid,
                normal=normal[pid].copy(),
                d=float(d[pid]),
                centroid=centroid[pid].copy(),
                n_points=int(counts[pid]),
                rms=float(rms[pid]),
                sigma_d=math.sqrt(max(cov[pid, 3, 3], 0.0)),
                covariance=cov[pid].copy(),
                slope_deg=slope,
                aspect_deg=aspect,
            )
        )
    return out


def _covariances(lam: Array, vec: Array, centroid: Array, sigma0_sq: Array, wsum: Array) -> Array:
    """Covariances (L, 4, 4) of (a, b, c, d) from the eigenpairs (``lam`` (L, 3) ascending,
    ``vec`` (L, 3, 3) in columns) of the scatter matrices, the centroids (L, 3, CRS unit),
    the variance factors (L,) and the weight sums (L,): tilts of the normal towards v_k are
    resisted by the spread along v_k (l_k - l3); the offset along n by the total weight. Every
    product written out (no BLAS)."""
    v1, v2 = vec[:, :, 1], vec[:, :, 2]
    g1 = (lam[:, 1] - lam[:, 0])[:, None, None]
    g2 = (lam[:, 2] - lam[:, 0])[:, None, None]
    c_nn = sigma0_sq[:, None, None] * (
        v2[:, :, None] * v2[:, None, :] / g2 + v1[:, :, None] * v1[:, None, :] / g1
    )
    t = _dot3(c_nn, centroid[:, None, :])  # (L, 3): C_nn m
    cov = np.empty((len(lam), 4, 4))
    cov[:, :3, :3] = c_nn
    cov[:, :3, 3] = -t
    cov[:, 3, :3] = -t
    cov[:, 3, 3] = _dot3(centroid, t) + sigma0_sq / wsum
    return cov
