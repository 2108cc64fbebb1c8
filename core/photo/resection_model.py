"""The observation blocks of a single-image resection: control points (collinearity) and image
lines matched to 3D lines (coplanarity or equivalent planes), for :func:`.resection.resect`.

Parameters of the adjustment: the exterior orientation ``(X0, Y0, Z0, omega, phi, kappa)``
(metres, radians, a Cartesian object frame) and, when refined, ``(focal_mm, x0_mm, y0_mm)``.

Blocks (Gauss-Helmert conditions, see :mod:`core.lsq.adjustment`):

- **points**: ``pixel(x, P) - pixel_observed = 0``; observations ``(col, row)`` and, when
  the control point has a covariance, ``(X, Y, Z)`` too (Gauss-Markov when it has none).
- **lines, coplanarity** (:func:`core.geometry.lines.coplanarity`): one condition per image
  point measured on the line, its distance from the projected 3D line (mm) is zero;
  observations the K image points ``(col, row)`` and, with a covariance, the two 3D points
  ``(P1, P2)`` of the line.
- **lines, equivalent planes** (:func:`core.geometry.lines.equivalent_planes_model`): two
  conditions per line, ``(a, b)`` of the measured image line minus ``(a, b)`` predicted from
  the 3D line, as the source's parametric model: ``(a, b)`` are the observations, their
  covariance propagated once from the image points; with a covariance of the 3D line its two
  points are observed too (Gauss-Helmert). Keeping ``(a, b)`` as the observations keeps the
  conditions linear in them (the ratios of pixel differences would not be, and the
  adjustment's step control needs that near the solution).

Lines are grouped into blocks of equal shape (number of image points, with or without a 3D
covariance); each line is one group, so data snooping rejects whole lines.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..geometry.camera import Camera
from ..geometry.collinearity import collinearity_jacobians
from ..geometry.lines import (
    VERTICAL,
    camera_vectors,
    coplanarity,
    equivalent_planes_image,
    equivalent_planes_model,
    image_vectors,
)
from ..lsq.model import GaussHelmertBlock, GaussMarkovBlock

Array = NDArray[np.float64]

__all__ = [
    "EquivalentPlanes",
    "LineConditions",
    "PointConditions",
    "equivalent_planes_block",
    "line_block",
    "observed_line_parameters",
    "point_block",
]


def _camera_at(camera: Camera, x_local: Array) -> Camera:
    """The camera with the adjusted interior orientation (the same in every group)."""
    if x_local.shape[1] <= 6:
        return camera
    return camera.with_interior(np.concatenate([x_local[0, 6:9], camera.distortion.params]))


@dataclass
class PointConditions:
    """Collinearity of control points (module docstring); ``xyz`` is used when the block
    does not observe the points (Gauss-Markov)."""

    camera: Camera
    xyz: Array  # (G, 3)

    def model(self, x_local: Array) -> tuple[Array, Array]:
        """Gauss-Markov: predicted pixels (G, 2) and d/dx (G, 2, k)."""
        out = self._jac(x_local, self.xyz, want_point=False)
        return out[0], out[1]

    def condition(self, x_local: Array, l_hat: Array) -> tuple[Array, Array, Array]:
        """Gauss-Helmert: ``pixel(x, P) - pixel``; observations (col, row, X, Y, Z)."""
        f, a, dp = self._jac(x_local, l_hat[:, 2:5], want_point=True)
        g = f - l_hat[:, :2]
        b = np.zeros((g.shape[0], 2, 5))
        b[:, 0, 0] = b[:, 1, 1] = -1.0
        b[:, :, 2:] = dp
        return g, a, b

    def _jac(self, x_local: Array, xyz: Array, want_point: bool):
        cam = _camera_at(self.camera, x_local)
        interior = x_local.shape[1] > 6
        wrt = ["eo"] + (["point"] if want_point else []) + (["interior"] if interior else [])
        out = collinearity_jacobians(xyz, x_local[:, :6], cam, wrt=wrt)
        a = out["eo"] if not interior else np.concatenate([out["eo"], out["interior"][:, :, :3]], 2)
        return out["pixels"], a, out.get("point")


@dataclass
class LineConditions:
    """Coplanarity conditions of one block: K image points per line, two 3D points per line
    (module docstring). ``p1``, ``p2`` are used when the block does not observe the 3D points.
    """

    camera: Camera
    model_name: str  # "coplanarity"
    k: int
    observes_line: bool
    p1: Array  # (G, 3)
    p2: Array  # (G, 3)

    def condition(self, x_local: Array, l_hat: Array) -> tuple[Array, Array, Array]:
        """Conditions (G, c), d/dx (G, c, k_x) and d/dl (G, c, o)."""
        g_count, k = l_hat.shape[0], self.k
        interior = x_local.shape[1] > 6
        io = x_local[0, 6:9] if interior else None
        px = l_hat[:, : 2 * k].reshape(g_count, k, 2)
        p, dp_dpx, dp_dio = image_vectors(px, self.camera, io)
        if self.observes_line:
            p1, p2 = l_hat[:, 2 * k : 2 * k + 3], l_hat[:, 2 * k + 3 : 2 * k + 6]
        else:
            p1, p2 = self.p1, self.p2
        eo = x_local[:, :6]
        a, da_deo, m = camera_vectors(p1, eo)
        b, db_deo, _ = camera_vectors(p2, eo)
        nx = x_local.shape[1]
        o = l_hat.shape[1]
        if self.model_name == "coplanarity":
            d, dd_dp, dd_da, dd_db = coplanarity(p, a, b)
            g = d
            c = k
            jac_x = np.zeros((g_count, c, nx))
            jac_x[:, :, :6] = dd_da @ da_deo + dd_db @ db_deo
            if interior:
                jac_x[:, :, 6:9] = np.einsum("gkc,gkcj->gkj", dd_dp, dp_dio)
            jac_l = np.zeros((g_count, c, o))
            per_vertex = np.einsum("gkc,gkcj->gkj", dd_dp, dp_dpx)  # (G, K, 2)
            for j in range(k):
                jac_l[:, j, 2 * j : 2 * j + 2] = per_vertex[:, j]
            if self.observes_line:
                jac_l[:, :, 2 * k : 2 * k + 3] = dd_da @ m
                jac_l[:, :, 2 * k + 3 : 2 * k + 6] = dd_db @ m
            return g, jac_x, jac_l
        raise ValueError(f"LineConditions: unknown model {self.model_name!r}")


@dataclass
class EquivalentPlanes:
    """The equivalent-planes conditions of one block of lines: observations ``(a, b)`` of the
    measured image lines (in the ideal image of the camera's own principal point) and, when the
    3D lines are observed, their two points ``(P1, P2)``.

    With the principal point refined by ``(dx0, dy0)`` the measured line, expressed in the new
    ideal image, is ``y = a x + (b + a dx0 - dy0)`` (horizontal) or ``x = a* y + (b* + a* dy0 -
    dx0)`` (vertical): the conditions compare ``b`` with ``b_model - a_model dx0 + dy0`` (and the
    vertical counterpart), which keeps them linear in the observations (the lens correction
    stays the one at the camera's principal point, a second-order effect).
    """

    camera: Camera
    observes_line: bool
    p1: Array  # (G, 3)
    p2: Array  # (G, 3)
    kind: NDArray[np.int8]  # (G,)

    def condition(self, x_local: Array, l_hat: Array) -> tuple[Array, Array, Array]:
        """Conditions ``(a, b) - model`` (G, 2), d/dx (G, 2, k_x) and d/dl (G, 2, o)."""
        g_count, nx, o = l_hat.shape[0], x_local.shape[1], l_hat.shape[1]
        interior = nx > 6
        if self.observes_line:
            p1, p2 = l_hat[:, 2:5], l_hat[:, 5:8]
        else:
            p1, p2 = self.p1, self.p2
        eo = x_local[:, :6]
        a, da_deo, m = camera_vectors(p1, eo)
        b, db_deo, _ = camera_vectors(p2, eo)
        focal = float(x_local[0, 6]) if interior else self.camera.focal_mm
        ab, dab_da, dab_db, dab_df = equivalent_planes_model(a, b, focal, self.kind)
        dab_deo = dab_da @ da_deo + dab_db @ db_deo  # (G, 2, 6)
        model = ab.copy()
        dmodel_dx = np.zeros((g_count, 2, nx))
        dmodel_dx[:, :, :6] = dab_deo
        dmodel_dl = np.zeros((g_count, 2, o))
        if self.observes_line:
            dmodel_dl[:, :, 2:5] = dab_da @ m
            dmodel_dl[:, :, 5:8] = dab_db @ m
        if interior:
            vert = np.asarray(self.kind) == VERTICAL
            shift = x_local[0, 7:9] - np.array([self.camera.x0_mm, self.camera.y0_mm])
            # horizontal: b - a dx0 + dy0; vertical: b* - a* dy0 + dx0
            own = np.where(vert, shift[1], shift[0])  # multiplies -a
            other = np.where(vert, shift[0], shift[1])  # added
            model[:, 1] += -ab[:, 0] * own + other
            dmodel_dx[:, 1, :6] -= own[:, None] * dab_deo[:, 0]
            if self.observes_line:
                dmodel_dl[:, 1, 2:] -= own[:, None] * dmodel_dl[:, 0, 2:]
            dmodel_dx[:, :, 6] = dab_df
            dmodel_dx[:, 1, 7] = np.where(vert, 1.0, -ab[:, 0])
            dmodel_dx[:, 1, 8] = np.where(vert, -ab[:, 0], 1.0)
        g = l_hat[:, :2] - model
        jac_l = -dmodel_dl
        jac_l[:, 0, 0] = jac_l[:, 1, 1] = 1.0
        return g, -dmodel_dx, jac_l


def observed_line_parameters(
    camera: Camera, pixels: Array, sigma_px: Array, kind: NDArray[np.int8]
) -> tuple[Array, Array]:
    """``(a, b)`` of measured image lines and their covariance, propagated from the points.

    Parameters
    ----------
    pixels : (G, K, 2)
        Points measured on each line, pixels.
    sigma_px : (G, K)
        Their standard deviations.
    kind : (G,)
        HORIZONTAL or VERTICAL.

    Returns
    -------
    ab : (G, 2)
        ``a`` (dimensionless) and ``b`` (mm), in the ideal image.
    cov : (G, 2, 2)
    """
    p, dp_dpx, _ = image_vectors(pixels, camera)
    ab, j_img = equivalent_planes_image(p, kind)
    jac = np.einsum("gikc,gkcj->gikj", j_img, dp_dpx).reshape(len(ab), 2, -1)
    s2 = np.repeat(sigma_px, 2, axis=1) ** 2
    cov = np.einsum("gik,gk,gjk->gij", jac, s2, jac)
    return ab, cov


def point_block(
    name: str,
    camera: Camera,
    pixels: Array,
    sigma_px: Array,
    xyz: Array,
    cov: Array | None,
    param_index: Array,
    labels: list[str],
) -> GaussMarkovBlock | GaussHelmertBlock:
    """Control points as a Gauss-Markov block (``cov`` None: errorless) or a Gauss-Helmert
    block observing ``(col, row, X, Y, Z)`` with the points' 3 x 3 covariances."""
    g = pixels.shape[0]
    cond = PointConditions(camera, xyz)
    if cov is None:
        return GaussMarkovBlock(
            name=name,
            observed=pixels,
            sigma=np.repeat(sigma_px[:, None], 2, axis=1),
            param_index=param_index,
            model=cond.model,
            labels=labels,
            row_names=("col", "row"),
        )
    s = np.zeros((g, 5, 5))
    s[:, 0, 0] = s[:, 1, 1] = sigma_px**2
    s[:, 2:, 2:] = cov
    return GaussHelmertBlock(
        name=name,
        observed=np.column_stack([pixels, xyz]),
        sigma=s,
        param_index=param_index,
        condition=cond.condition,
        labels=labels,
        row_names=("col", "row", "X", "Y", "Z"),
    )


def _lines_block(
    name: str,
    conditions: LineConditions | EquivalentPlanes,
    s: Array,
    observed: Array,
    rows: list[str],
    cov: Array | None,
    param_index: Array,
    labels: list[str],
) -> GaussHelmertBlock:
    """The Gauss-Helmert block of image lines (``observed``, their covariance in ``s``); with
    ``cov`` (G, 6, 6) the 3D line's end points P1, P2 are observations too, after them."""
    if cov is not None:
        n = observed.shape[1]
        s[:, n:, n:] = cov
        observed = np.column_stack([observed, conditions.p1, conditions.p2])
        rows = [*rows, "X1", "Y1", "Z1", "X2", "Y2", "Z2"]
    return GaussHelmertBlock(
        name=name,
        observed=observed,
        sigma=s,
        param_index=param_index,
        condition=conditions.condition,
        labels=labels,
        row_names=tuple(rows),
    )


def equivalent_planes_block(
    name: str,
    conditions: EquivalentPlanes,
    ab: Array,
    ab_cov: Array,
    cov: Array | None,
    param_index: Array,
    labels: list[str],
) -> GaussHelmertBlock:
    """Lines as ``(a, b)`` (G, 2) with covariance (G, 2, 2); ``cov`` (G, 6, 6) of (P1, P2) when
    the 3D lines are observed (``conditions.observes_line``)."""
    g = ab.shape[0]
    o = 2 + (6 if cov is not None else 0)
    s = np.zeros((g, o, o))
    s[:, :2, :2] = ab_cov
    observed = ab
    rows = ["a", "b"]
    return _lines_block(name, conditions, s, observed, rows, cov, param_index, labels)


def line_block(
    name: str,
    conditions: LineConditions,
    pixels: Array,
    sigma_px: Array,
    cov: Array | None,
    param_index: Array,
    labels: list[str],
) -> GaussHelmertBlock:
    """Lines with K image points each: ``pixels`` (G, K, 2), ``sigma_px`` (G, K); ``cov``
    (G, 6, 6) of (P1, P2) when the 3D lines are observed (``conditions.observes_line``)."""
    g, k = pixels.shape[:2]
    o = 2 * k + (6 if cov is not None else 0)
    s = np.zeros((g, o, o))
    idx = np.arange(2 * k)
    s[:, idx, idx] = np.repeat(sigma_px, 2, axis=1) ** 2
    observed = pixels.reshape(g, 2 * k)
    rows = [f"{axis}{j + 1}" for j in range(k) for axis in ("col", "row")]
    return _lines_block(name, conditions, s, observed, rows, cov, param_index, labels)
