"""Forward lens models: distortion ideal -> measured (OpenCV, COLMAP), in the lens registry.

The registry's models (:mod:`core.geometry.distortion`) are corrections evaluated at the
measured point. OpenCV and COLMAP define the other direction: a *forward* map ``F`` from the
ideal (undistorted) point to the measured one. A :class:`ForwardDistortionModel` holds ``F``
exactly and derives the registry's interface from it:

- ``distort(i) = F(i)``, a direct evaluation;
- ``correction(m) = F^-1(m) - m``, by Newton's method (to rounding level);
- ``jacobian_xy(m) = J_F^-1 - I`` and ``jacobian_params(m) = -J_F^-1 dF/dp`` at ``i = F^-1(m)``
  (the implicit function theorem),

so that every algorithm of the project (bundle self-calibration, resection, orthophotos) uses a
forward model through the same interface as the others.

Normalisation and axes
----------------------
OpenCV's coefficients act on coordinates normalised by the focal length, with y *down*:
``(a, b) = (x_ideal / s, -y_ideal / s)`` where ``x_ideal, y_ideal`` are the registry's ideal
centred coordinates (mm, y up) and ``s`` is the constant ``scale_mm`` (the focal length, mm,
at the time the model was made). The coefficients are therefore OpenCV's and COLMAP's own,
unchanged. With the measured point ``(x_d, y_d)`` in OpenCV's normalised coordinates::

    x_m = s * x_d,    y_m = -aspect * s * y_d        (mm, centred, y up)

``aspect`` (constant) is ``fy / fx`` of a COLMAP or OpenCV camera, so a camera with
non-square focal lengths is represented exactly (the registry's cameras have one focal
length and square pixels). ``scale_mm`` stays fixed when a bundle adjustment changes the
focal length: the model then acts on coordinates normalised by ``s`` rather than by ``f``,
and :func:`opencv_coefficients` rescales the coefficients exactly (``k_n (f/s)^(2n)``,
``p (f/s)``) for export.
"""

from __future__ import annotations

from abc import abstractmethod
from typing import ClassVar, Tuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from .distortion import (
    DEFAULT_MAX_ITER,
    DEFAULT_TOL_MM,
    DistortionModel,
    as_points,
    inv2x2,
    register_model,
)

Array = NDArray[np.float64]

__all__ = [
    "ForwardDistortionModel",
    "MetashapeLens",
    "OpenCVFisheyeLens",
    "OpenCVFullLens",
    "OpenCVLens",
    "ThinPrismFisheyeLens",
    "opencv_coefficients",
]

#: Newton iterations of the inversion measured -> ideal.
_NEWTON_ITER = 30


class ForwardDistortionModel(DistortionModel):
    """A lens model defined by its forward map ideal -> measured (centred mm, y up).

    Subclasses implement :meth:`forward`, :meth:`forward_jacobian_xy` and
    :meth:`forward_jacobian_params`; the correction and its Jacobians follow exactly.
    """

    direction: ClassVar[str] = "forward"

    @abstractmethod
    def forward(self, xy: ArrayLike) -> Array:
        """Ideal centred coordinates (N, 2) mm -> measured centred coordinates (N, 2) mm."""

    @abstractmethod
    def forward_jacobian_xy(self, xy: ArrayLike) -> Array:
        """``d measured / d ideal`` (N, 2, 2) at ideal ``xy`` (N, 2) mm."""

    @abstractmethod
    def forward_jacobian_params(self, xy: ArrayLike) -> Array:
        """``d measured / d params`` (N, 2, P) mm per unit, at ideal ``xy`` (N, 2) mm."""

    # ------------------------------------------------------------------ inversion
    def _start(self, m: Array) -> Array:
        """Starting ideal point of the Newton inversion for measured ``m`` (N, 2) mm."""
        return m.copy()

    def ideal_with_status(self, xy: ArrayLike) -> Tuple[Array, NDArray[np.bool_]]:
        """Measured centred (N, 2) mm -> ideal centred (N, 2) mm by Newton, and a mask (N,).

        Rows that do not converge, or whose root lies beyond a fold of the forward map
        (``det J_F <= 0``), are NaN and False.
        """
        m = as_points(xy, 2, "xy")
        i = self._start(m)
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            for _ in range(_NEWTON_ITER):
                resid = self.forward(i) - m
                step = np.einsum("nij,nj->ni", inv2x2(self.forward_jacobian_xy(i)), resid)
                i = i - step
                if np.all(~np.isfinite(step) | (np.abs(step) <= 1e-15 * (1.0 + np.abs(i)))):
                    break
            final = self.forward(i) - m
            jac = self.forward_jacobian_xy(i)
            det = jac[:, 0, 0] * jac[:, 1, 1] - jac[:, 0, 1] * jac[:, 1, 0]
            scale = 1.0 + np.hypot(m[:, 0], m[:, 1])
            ok = np.all(np.isfinite(i), axis=1) & (det > 0.0)
            ok &= np.hypot(final[:, 0], final[:, 1]) <= 1e-10 * scale
        i[~ok] = np.nan
        return i, ok

    def undistort(self, xy: ArrayLike) -> Array:
        """Measured centred (N, 2) mm -> ideal (N, 2) mm, ``F^-1`` (NaN where it has no root)."""
        return self.ideal_with_status(xy)[0]

    def correction(self, xy: ArrayLike) -> Array:
        """``F^-1(m) - m`` (N, 2) mm at measured centred ``xy`` (N, 2) mm."""
        m = as_points(xy, 2, "xy")
        return self.ideal_with_status(m)[0] - m

    def jacobian_xy(self, xy: ArrayLike) -> Array:
        """``d correction / d xy`` = ``J_F(i)^-1 - I`` (N, 2, 2)."""
        i = self.undistort(xy)
        return inv2x2(self.forward_jacobian_xy(i)) - np.eye(2)

    def jacobian_params(self, xy: ArrayLike) -> Array:
        """``d correction / d params`` = ``-J_F(i)^-1 dF/dp`` (N, 2, P) mm per unit."""
        i = self.undistort(xy)
        inv = inv2x2(self.forward_jacobian_xy(i))
        return -np.einsum("nij,njp->nip", inv, self.forward_jacobian_params(i))

    def distort_with_status(
        self,
        xy: ArrayLike,
        *,
        tol_mm: float = DEFAULT_TOL_MM,
        max_iter: int = DEFAULT_MAX_ITER,
    ) -> Tuple[Array, NDArray[np.bool_]]:
        """Ideal (N, 2) mm -> measured (N, 2) mm, the direct forward map (no iteration).

        ``converged`` is False (and the row NaN) where the result is not finite or the point
        lies beyond a fold of the model (``det J_F <= 0``: there two ideal points give one
        measured point, so the model cannot be inverted). ``tol_mm`` and ``max_iter`` are
        accepted for the common interface and unused.
        """
        i = as_points(xy, 2, "xy")
        with np.errstate(over="ignore", invalid="ignore"):
            m = self.forward(i)
            jac = self.forward_jacobian_xy(i)
            det = jac[:, 0, 0] * jac[:, 1, 1] - jac[:, 0, 1] * jac[:, 1, 0]
            ok = np.all(np.isfinite(m), axis=1) & (det > 0.0)
        m[~ok] = np.nan
        return m, ok


class _NormalisedLens(ForwardDistortionModel):
    """Common part of the OpenCV-style models: normalisation by ``scale_mm``, y down, aspect."""

    constant_names: ClassVar[Tuple[str, ...]] = ("scale_mm", "aspect")

    def __init__(self, **values: float) -> None:
        super().__init__(**values)
        for key in self.constant_names:
            if not self._constants[key] > 0.0:
                raise InputError(
                    f"{self.model} constant '{key}' must be positive, got {self._constants[key]}"
                )

    def _start(self, m: Array) -> Array:
        """The measured point with the aspect divided out: Newton then starts within the
        lens's own (small) distortion of the root."""
        return m / np.array([1.0, self._constants["aspect"]])

    def _normalised(self, xy: ArrayLike) -> Tuple[Array, Array, float, float]:
        i = as_points(xy, 2, "xy")
        s = self._constants["scale_mm"]
        return i[:, 0] / s, -i[:, 1] / s, s, self._constants["aspect"]

    @abstractmethod
    def _distort_normalised(self, a: Array, b: Array) -> Tuple[Array, Array, Array, Array]:
        """``(x_d, y_d, J (N,2,2) d(x_d,y_d)/d(a,b), dP (N,2,P))`` in normalised coordinates."""

    def forward(self, xy: ArrayLike) -> Array:
        """Ideal centred (N, 2) mm -> measured centred (N, 2) mm."""
        a, b, s, asp = self._normalised(xy)
        xd, yd, _, _ = self._distort_normalised(a, b)
        return np.column_stack([s * xd, -asp * s * yd])

    def forward_jacobian_xy(self, xy: ArrayLike) -> Array:
        """``d measured / d ideal`` (N, 2, 2), dimensionless."""
        a, b, _, asp = self._normalised(xy)
        _, _, j, _ = self._distort_normalised(a, b)
        # a = x / s, b = -y / s; m_x = s x_d, m_y = -asp s y_d
        out = np.empty_like(j)
        out[:, 0, 0] = j[:, 0, 0]
        out[:, 0, 1] = -j[:, 0, 1]
        out[:, 1, 0] = -asp * j[:, 1, 0]
        out[:, 1, 1] = asp * j[:, 1, 1]
        return out

    def forward_jacobian_params(self, xy: ArrayLike) -> Array:
        """``d measured / d params`` (N, 2, P), mm per unit of each coefficient."""
        a, b, s, asp = self._normalised(xy)
        _, _, _, dp = self._distort_normalised(a, b)
        dp[:, 0, :] *= s
        dp[:, 1, :] *= -asp * s
        return dp


@register_model
class OpenCVFullLens(_NormalisedLens):
    """OpenCV's rational radial-tangential model (COLMAP's FULL_OPENCV), forward.

    In OpenCV's normalised coordinates ``(a, b)`` (y down, see the module docstring),
    ``r2 = a^2 + b^2`` and ``c = (1 + k1 r2 + k2 r2^2 + k3 r2^3) / (1 + k4 r2 + k5 r2^2 +
    k6 r2^3)``::

        x_d = a c + 2 p1 a b + p2 (r2 + 2 a^2)
        y_d = b c + p1 (r2 + 2 b^2) + 2 p2 a b

    Coefficients are dimensionless (OpenCV's and COLMAP's values, in COLMAP's order).

    >>> lens = OpenCVFullLens(k1=-0.1, scale_mm=10.0, aspect=1.0)
    >>> (lens.distort([[5.0, 0.0]]).round(12) + 0.0).tolist()     # 5 (1 - 0.1 * 0.25)
    [[4.875, 0.0]]
    """

    model: ClassVar[str] = "opencv_full"
    param_names: ClassVar[Tuple[str, ...]] = ("k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6")

    def _coefficients(self) -> Tuple[float, ...]:
        v = dict(zip(self.param_names, self._params.tolist()))
        return tuple(v.get(n, 0.0) for n in OpenCVFullLens.param_names)

    def _distort_normalised(self, a: Array, b: Array) -> Tuple[Array, Array, Array, Array]:
        k1, k2, p1, p2, k3, k4, k5, k6 = self._coefficients()
        r2 = a * a + b * b
        r4, r6 = r2 * r2, r2 * r2 * r2
        num = 1.0 + k1 * r2 + k2 * r4 + k3 * r6
        den = 1.0 + k4 * r2 + k5 * r4 + k6 * r6
        c = num / den
        dnum = k1 + 2.0 * k2 * r2 + 3.0 * k3 * r4
        dden = k4 + 2.0 * k5 * r2 + 3.0 * k6 * r4
        dc = (dnum * den - num * dden) / (den * den)  # d c / d r2
        xd = a * c + 2.0 * p1 * a * b + p2 * (r2 + 2.0 * a * a)
        yd = b * c + p1 * (r2 + 2.0 * b * b) + 2.0 * p2 * a * b
        j = np.empty((a.shape[0], 2, 2))
        j[:, 0, 0] = c + 2.0 * a * a * dc + 2.0 * p1 * b + 6.0 * p2 * a
        j[:, 0, 1] = 2.0 * a * b * dc + 2.0 * p1 * a + 2.0 * p2 * b
        j[:, 1, 0] = 2.0 * a * b * dc + 2.0 * p1 * a + 2.0 * p2 * b
        j[:, 1, 1] = c + 2.0 * b * b * dc + 6.0 * p1 * b + 2.0 * p2 * a
        full = np.empty((a.shape[0], 2, 8))
        for col, rn in ((0, r2), (1, r4), (4, r6)):
            full[:, 0, col], full[:, 1, col] = a * rn / den, b * rn / den
        for col, rn in ((5, r2), (6, r4), (7, r6)):
            g = -num * rn / (den * den)
            full[:, 0, col], full[:, 1, col] = a * g, b * g
        full[:, 0, 2], full[:, 1, 2] = 2.0 * a * b, r2 + 2.0 * b * b
        full[:, 0, 3], full[:, 1, 3] = r2 + 2.0 * a * a, 2.0 * a * b
        keep = [OpenCVFullLens.param_names.index(n) for n in self.param_names]
        return xd, yd, j, full[:, :, keep]


@register_model
class OpenCVLens(OpenCVFullLens):
    """OpenCV's radial-tangential model k1, k2, p1, p2, k3 (COLMAP's SIMPLE_RADIAL, RADIAL,
    OPENCV), forward; the formulas of :class:`OpenCVFullLens` with k4 = k5 = k6 = 0.

    >>> OpenCVLens(p1=0.01, scale_mm=10.0, aspect=1.0).distort([[0.0, -5.0]]).round(12).tolist()
    [[0.0, -5.075]]
    """

    model: ClassVar[str] = "opencv"
    param_names: ClassVar[Tuple[str, ...]] = ("k1", "k2", "p1", "p2", "k3")


@register_model
class OpenCVFisheyeLens(_NormalisedLens):
    """OpenCV's fisheye model (COLMAP's OPENCV_FISHEYE, RADIAL_FISHEYE, SIMPLE_RADIAL_FISHEYE),
    forward, for a camera with the ``equidistant`` projection.

    The equidistant projection gives the ideal point at ``f theta`` from the principal point,
    so ``(a, b)`` normalised by ``s = f`` has length ``theta``; OpenCV's distorted angle is
    ``theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8)`` along the
    same direction: ``(x_d, y_d) = (a, b) theta_d / theta``.

    >>> lens = OpenCVFisheyeLens(k1=0.1, scale_mm=10.0, aspect=1.0)
    >>> (lens.distort([[5.0, 0.0]]).round(12) + 0.0).tolist()     # 5 (1 + 0.1 * 0.25)
    [[5.125, 0.0]]
    """

    model: ClassVar[str] = "opencv_fisheye"
    param_names: ClassVar[Tuple[str, ...]] = ("k1", "k2", "k3", "k4")

    def _distort_normalised(self, a: Array, b: Array) -> Tuple[Array, Array, Array, Array]:
        k1, k2, k3, k4 = self._params.tolist()
        t2 = a * a + b * b
        g = 1.0 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4)))
        dg = k1 + t2 * (2.0 * k2 + t2 * (3.0 * k3 + 4.0 * k4 * t2))  # d g / d t2
        j = np.empty((a.shape[0], 2, 2))
        j[:, 0, 0] = g + 2.0 * a * a * dg
        j[:, 0, 1] = 2.0 * a * b * dg
        j[:, 1, 0] = 2.0 * a * b * dg
        j[:, 1, 1] = g + 2.0 * b * b * dg
        dp = np.empty((a.shape[0], 2, 4))
        for col in range(4):
            tn = t2 ** (col + 1)
            dp[:, 0, col], dp[:, 1, col] = a * tn, b * tn
        return a * g, b * g, j, dp


@register_model
class ThinPrismFisheyeLens(_NormalisedLens):
    """COLMAP's THIN_PRISM_FISHEYE, forward, for a camera with the ``equidistant`` projection.

    On the equidistant normalised coordinates ``(a, b)`` (length ``theta``, y down),
    ``r2 = a^2 + b^2`` and ``c = k1 r2 + k2 r2^2 + k3 r2^3 + k4 r2^4``::

        x_d = a (1 + c) + 2 p1 a b + p2 (r2 + 2 a^2) + sx1 r2
        y_d = b (1 + c) + p1 (r2 + 2 b^2) + 2 p2 a b + sy1 r2

    >>> lens = ThinPrismFisheyeLens(sx1=0.01, scale_mm=10.0, aspect=1.0)
    >>> (lens.distort([[0.0, 5.0]]).round(12) + 0.0).tolist()    # x: 10 * 0.01 * 0.25
    [[0.025, 5.0]]
    """

    model: ClassVar[str] = "thin_prism_fisheye"
    param_names: ClassVar[Tuple[str, ...]] = ("k1", "k2", "p1", "p2", "k3", "k4", "sx1", "sy1")

    def _distort_normalised(self, a: Array, b: Array) -> Tuple[Array, Array, Array, Array]:
        k1, k2, p1, p2, k3, k4, sx1, sy1 = self._params.tolist()
        r2 = a * a + b * b
        c = r2 * (k1 + r2 * (k2 + r2 * (k3 + r2 * k4)))
        dc = k1 + r2 * (2.0 * k2 + r2 * (3.0 * k3 + 4.0 * k4 * r2))  # d c / d r2
        xd = a * (1.0 + c) + 2.0 * p1 * a * b + p2 * (r2 + 2.0 * a * a) + sx1 * r2
        yd = b * (1.0 + c) + p1 * (r2 + 2.0 * b * b) + 2.0 * p2 * a * b + sy1 * r2
        j = np.empty((a.shape[0], 2, 2))
        j[:, 0, 0] = 1.0 + c + 2.0 * a * a * dc + 2.0 * p1 * b + 6.0 * p2 * a + 2.0 * sx1 * a
        j[:, 0, 1] = 2.0 * a * b * dc + 2.0 * p1 * a + 2.0 * p2 * b + 2.0 * sx1 * b
        j[:, 1, 0] = 2.0 * a * b * dc + 2.0 * p1 * a + 2.0 * p2 * b + 2.0 * sy1 * a
        j[:, 1, 1] = 1.0 + c + 2.0 * b * b * dc + 6.0 * p1 * b + 2.0 * p2 * a + 2.0 * sy1 * b
        dp = np.zeros((a.shape[0], 2, 8))
        for col, n in ((0, 1), (1, 2), (4, 3), (5, 4)):
            rn = r2**n
            dp[:, 0, col], dp[:, 1, col] = a * rn, b * rn
        dp[:, 0, 2], dp[:, 1, 2] = 2.0 * a * b, r2 + 2.0 * b * b
        dp[:, 0, 3], dp[:, 1, 3] = r2 + 2.0 * a * a, 2.0 * a * b
        dp[:, 0, 6] = r2
        dp[:, 1, 7] = r2
        return xd, yd, j, dp


@register_model
class MetashapeLens(_NormalisedLens):
    """Agisoft Metashape's frame / fisheye model, forward (Metashape Professional manual,
    appendix "Camera models"); with the ``equidistant`` projection for its fisheye.

    On the normalised ideal coordinates ``(a, b)`` (y down; the fisheye's have length theta),
    ``r2 = a^2 + b^2`` and ``c = 1 + k1 r2 + k2 r2^2 + k3 r2^3 + k4 r2^4``::

        x' = a c + p1 (r2 + 2 a^2) + 2 p2 a b      (p1, p2 swapped w.r.t. OpenCV)
        y' = b c + p2 (r2 + 2 b^2) + 2 p1 a b
        u - w/2 - cx = x' (f + b1) + y' b2,   v - h/2 - cy = y' f   (px)

    b1 (affinity) and b2 (non-orthogonality) are Metashape's pixels; the constant
    ``focal_px`` is f (px) when the model was made, ``scale_mm`` the same f in mm, so the
    measured point is ``(s (x' (1 + b1/F) + y' b2/F), -s y')`` mm (``aspect`` stays 1).

    >>> lens = MetashapeLens(p1=0.01, scale_mm=10.0, aspect=1.0, focal_px=2000.0)
    >>> (lens.distort([[5.0, 0.0]]).round(12) + 0.0).tolist()   # x: 5 + 10 * 0.01 * 0.75
    [[5.075, 0.0]]
    """

    model: ClassVar[str] = "metashape"
    param_names: ClassVar[Tuple[str, ...]] = ("k1", "k2", "k3", "k4", "p1", "p2", "b1", "b2")
    constant_names: ClassVar[Tuple[str, ...]] = ("scale_mm", "aspect", "focal_px")

    def _distort_normalised(self, a: Array, b: Array) -> Tuple[Array, Array, Array, Array]:
        k1, k2, k3, k4, p1, p2, b1, b2 = self._params.tolist()
        big_f = self._constants["focal_px"]
        r2 = a * a + b * b
        c = 1.0 + r2 * (k1 + r2 * (k2 + r2 * (k3 + r2 * k4)))
        dc = k1 + r2 * (2.0 * k2 + r2 * (3.0 * k3 + 4.0 * k4 * r2))  # d c / d r2
        xp = a * c + p1 * (r2 + 2.0 * a * a) + 2.0 * p2 * a * b
        yp = b * c + p2 * (r2 + 2.0 * b * b) + 2.0 * p1 * a * b
        jb = np.empty((a.shape[0], 2, 2))  # d(x', y') / d(a, b)
        jb[:, 0, 0] = c + 2.0 * a * a * dc + 6.0 * p1 * a + 2.0 * p2 * b
        jb[:, 0, 1] = 2.0 * a * b * dc + 2.0 * p1 * b + 2.0 * p2 * a
        jb[:, 1, 0] = 2.0 * a * b * dc + 2.0 * p2 * a + 2.0 * p1 * b
        jb[:, 1, 1] = c + 2.0 * b * b * dc + 6.0 * p2 * b + 2.0 * p1 * a
        dp = np.zeros((a.shape[0], 2, 8))
        for col in range(4):
            rn = r2 ** (col + 1)
            dp[:, 0, col], dp[:, 1, col] = a * rn, b * rn
        dp[:, 0, 4], dp[:, 1, 4] = r2 + 2.0 * a * a, 2.0 * a * b
        dp[:, 0, 5], dp[:, 1, 5] = 2.0 * a * b, r2 + 2.0 * b * b
        # the affine part: x_d = (1 + b1/F) x' + (b2/F) y', y_d = y' (y down, in units of s)
        ex, ey = 1.0 + b1 / big_f, b2 / big_f
        xd = ex * xp + ey * yp
        j = jb.copy()
        j[:, 0, :] = ex * jb[:, 0, :] + ey * jb[:, 1, :]
        dp[:, 0, :6] = ex * dp[:, 0, :6] + ey * dp[:, 1, :6]
        dp[:, 0, 6], dp[:, 0, 7] = xp / big_f, yp / big_f
        return xd, yp, j, dp


def opencv_coefficients(lens: DistortionModel, focal_mm: float) -> dict[str, float]:
    """The lens's coefficients normalised by ``focal_mm`` (OpenCV's and COLMAP's), exactly.

    A model made with ``scale_mm = s`` acts on ``x / s``; on ``x / f`` the same map has
    ``k_n (f/s)^(2n)`` (radial, also the fisheye's and the rational denominator's) and
    ``p (f/s)`` (tangential).
    """
    if not isinstance(lens, _NormalisedLens) or isinstance(lens, MetashapeLens):
        raise TypeError(f"{lens.model} is not an OpenCV forward model")
    ratio = focal_mm / lens.constants["scale_mm"]
    power = {"k1": 2, "k2": 4, "k3": 6, "k4": 2, "k5": 4, "k6": 6, "p1": 1, "p2": 1}
    if isinstance(lens, OpenCVFisheyeLens):
        power = {"k1": 2, "k2": 4, "k3": 6, "k4": 8}
    elif isinstance(lens, ThinPrismFisheyeLens):
        power = {"k1": 2, "k2": 4, "k3": 6, "k4": 8, "p1": 1, "p2": 1, "sx1": 1, "sy1": 1}
    return {n: float(v) * ratio ** power[n] for n, v in zip(lens.param_names, lens.params.tolist())}
