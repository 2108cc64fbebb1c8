"""Lens models: corrections added to measured, centred image coordinates.

Conventions
-----------
Every model in this family is a *correction* ``d`` that is ADDED to a measured image
coordinate, centred on the principal point, to give the ideal (distortion-free) one::

    x_bar = x_meas - x0,  y_bar = y_meas - y0          (millimetres, image frame)
    x_ideal = x_bar + dx(x_bar, y_bar)
    y_ideal = y_bar + dy(x_bar, y_bar)

The image frame has x to the right and y up (see :mod:`core.geometry.camera`); every length here is
in millimetres and every model coefficient is defined for millimetre coordinates (so
Brown-Conrady's ``k1`` is in mm^-2, ``k2`` in mm^-4, ``p1``/``p2`` in mm^-1).

Undistortion (measured -> ideal) is therefore a direct evaluation. Distortion
(ideal -> measured, needed for projection) solves ``m + d(m) = i`` for ``m`` by Newton's
method, vectorised over all points; points for which it fails (no solution: far outside
the calibrated field, or a root on the far side of a fold of the model) are flagged, never
returned silently.

Adding a model
--------------
Subclass :class:`DistortionModel`, set ``model`` (the name used in files) and
``param_names`` (the adjustable coefficients, in the order of ``params``), optionally
``constant_names`` (fixed values that are stored but never adjusted, e.g. a reference
radius ``r0_mm``), implement :meth:`~DistortionModel.correction`,
:meth:`~DistortionModel.jacobian_xy` and :meth:`~DistortionModel.jacobian_params`, and
decorate the class with :func:`register_model`. Nothing else has to change.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from typing import Any, ClassVar, Dict, Tuple, Type, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError, LidarPhotoError

Array = NDArray[np.float64]

#: Default stopping tolerance of the Newton inversion, in millimetres: 1e-6 px for a 1 µm
#: pixel, i.e. finer than 1e-6 px for every real sensor. :class:`core.geometry.camera.Camera` passes
#: its own tolerance of 1e-6 px converted with its pixel size.
DEFAULT_TOL_MM = 1e-9
DEFAULT_MAX_ITER = 50

__all__ = [
    "DEFAULT_MAX_ITER",
    "DEFAULT_TOL_MM",
    "DISTORTION_MODELS",
    "BrownConrady",
    "DistortionInversionError",
    "DistortionModel",
    "NoDistortion",
    "as_points",
    "distortion_from_dict",
    "inv2x2",
    "register_model",
]


class DistortionInversionError(LidarPhotoError):
    """The ideal -> measured inversion of a lens model failed for some points.

    ``converged`` is the (N,) boolean mask of the points that did converge.
    """

    def __init__(self, message: str, converged: NDArray[np.bool_]) -> None:
        self.converged = converged
        super().__init__(message)


def as_points(values: ArrayLike, dim: int, name: str = "points") -> Array:
    """Return ``values`` as a C-contiguous float64 array of shape (N, dim).

    A single point of shape (dim,) is accepted and returned as (1, dim).

    >>> as_points([1, 2], 2).shape
    (1, 2)
    """
    a = np.asarray(values, dtype=np.float64)
    if a.ndim == 1 and a.shape[0] == dim:
        a = a[np.newaxis, :]
    if a.ndim != 2 or a.shape[1] != dim:
        raise ValueError(f"{name} must have shape (N, {dim}), got {np.shape(values)}")
    return np.ascontiguousarray(a)


def inv2x2(a: Array) -> Array:
    """Inverse of a stack of 2x2 matrices (..., 2, 2), by the adjugate.

    Written out because ``np.linalg.solve`` changed its broadcasting rules for stacked
    right-hand sides between numpy 1.x and 2.x; singular matrices give inf/nan, which the
    callers treat as a failure.
    """
    det = a[..., 0, 0] * a[..., 1, 1] - a[..., 0, 1] * a[..., 1, 0]
    out = np.empty_like(a)
    with np.errstate(divide="ignore", invalid="ignore"):
        out[..., 0, 0] = a[..., 1, 1] / det
        out[..., 1, 1] = a[..., 0, 0] / det
        out[..., 0, 1] = -a[..., 0, 1] / det
        out[..., 1, 0] = -a[..., 1, 0] / det
    return out


_M = TypeVar("_M", bound="DistortionModel")


class DistortionModel(ABC):
    """Base class of the lens-model family (immutable).

    Class attributes
    ----------------
    model : str
        Name used in files (``{"model": ...}``) and in :data:`DISTORTION_MODELS`.
    param_names : tuple of str
        Adjustable coefficients, in the order of :attr:`params`.
    constant_names : tuple of str
        Fixed values of the model that are stored but never adjusted.
    """

    model: ClassVar[str] = ""
    param_names: ClassVar[Tuple[str, ...]] = ()
    constant_names: ClassVar[Tuple[str, ...]] = ()

    def __init__(self, **values: float) -> None:
        known = set(self.param_names) | set(self.constant_names)
        unknown = sorted(set(values) - known)
        if unknown:
            raise TypeError(
                f"{type(self).__name__}: unknown parameter(s) {unknown}; "
                f"expected {list(self.param_names) + list(self.constant_names)}"
            )
        missing = [c for c in self.constant_names if c not in values]
        if missing:
            raise TypeError(f"{type(self).__name__}: missing constant(s) {missing}")
        checked: Dict[str, float] = {}
        for key, value in values.items():
            if isinstance(value, bool):
                raise InputError(f"{self.model} coefficient '{key}' must be a number, got {value}")
            try:
                number = float(value)
            except (TypeError, ValueError):
                raise InputError(
                    f"{self.model} coefficient '{key}' must be a number, got {value!r}"
                ) from None
            if not np.isfinite(number):
                raise InputError(f"{self.model} coefficient '{key}' must be finite, got {number}")
            checked[key] = number
        params = np.array([checked.get(n, 0.0) for n in self.param_names], dtype=np.float64)
        params.setflags(write=False)
        self._params: Array = params
        self._constants: Dict[str, float] = {c: checked[c] for c in self.constant_names}

    # ------------------------------------------------------------------ parameters
    @property
    def params(self) -> Array:
        """Adjustable coefficients (P,), in the order of :attr:`param_names` (a copy)."""
        return self._params.copy()

    @property
    def n_params(self) -> int:
        """Number P of adjustable coefficients."""
        return len(self.param_names)

    @property
    def constants(self) -> Dict[str, float]:
        """Fixed (never adjusted) values of the model, by name (a copy)."""
        return dict(self._constants)

    def with_params(self: _M, params: ArrayLike) -> _M:
        """Copy of this model with new coefficients (P,), constants unchanged."""
        p = np.asarray(params, dtype=np.float64).reshape(-1)
        if p.shape[0] != self.n_params:
            raise ValueError(f"{self.model}: expected {self.n_params} parameters, got {p.shape[0]}")
        return type(self)(**self._constants, **dict(zip(self.param_names, p.tolist())))

    # ------------------------------------------------------------------ the model
    @abstractmethod
    def correction(self, xy: ArrayLike) -> Array:
        """Correction ``d`` (N, 2) in mm at measured, centred image coordinates ``xy`` (N, 2) mm."""

    @abstractmethod
    def jacobian_xy(self, xy: ArrayLike) -> Array:
        """``d correction / d xy`` at ``xy`` (N, 2) mm.

        Shape (N, 2, 2) with ``[n, i, j] = d d_i / d xy_j``, dimensionless.
        """

    @abstractmethod
    def jacobian_params(self, xy: ArrayLike) -> Array:
        """``d correction / d params`` at ``xy`` (N, 2) mm.

        Shape (N, 2, P), in mm per unit of each coefficient.
        """

    def undistort(self, xy: ArrayLike) -> Array:
        """Measured centred coordinates (N, 2) mm -> ideal centred coordinates (N, 2) mm."""
        m = as_points(xy, 2, "xy")
        return m + self.correction(m)

    def distort_with_status(
        self,
        xy: ArrayLike,
        *,
        tol_mm: float = DEFAULT_TOL_MM,
        max_iter: int = DEFAULT_MAX_ITER,
    ) -> Tuple[Array, NDArray[np.bool_]]:
        """Ideal centred coordinates -> measured centred coordinates, by Newton's method.

        Solves ``m + d(m) = i`` for every row.

        Parameters
        ----------
        xy : (N, 2) array_like
            Ideal, centred image coordinates ``i`` in mm.
        tol_mm : float
            A row has converged when ``|m + d(m) - i| <= tol_mm`` (Euclidean, mm).
        max_iter : int
            Newton iterations at most.

        Returns
        -------
        measured : (N, 2) ndarray
            Measured, centred coordinates ``m`` in mm; NaN where the inversion failed.
        converged : (N,) ndarray of bool
            False where Newton did not reach ``tol_mm`` in ``max_iter`` iterations, or where
            the root it found is not on the physical branch of the model: an eigenvalue of
            ``I + dd/dm`` without positive real part (the root lies beyond a fold, where the
            model turns the image inside out), or a measured point on the opposite side of
            the principal point from the ideal one.
        """
        # Diverging rows may overflow; they are caught by the finiteness and residual
        # checks and flagged, so the floating-point warnings would only be noise.
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            target = as_points(xy, 2, "xy")
            eye = np.eye(2)
            # The first-order inverse m = i - d(i) starts Newton within its quadratic basin
            # for any correction that is small compared with the radius.
            m = target - self.correction(target)
            active = np.all(np.isfinite(m), axis=1)
            done = np.zeros(target.shape[0], dtype=bool)
            for _ in range(max_iter):
                idx = np.flatnonzero(active & ~done)
                if idx.size == 0:
                    break
                mi = m[idx]
                resid = mi + self.correction(mi) - target[idx]
                reached = np.hypot(resid[:, 0], resid[:, 1]) <= tol_mm
                # Rows that meet the tolerance still take this step: it costs nothing and
                # squares the residual (Newton), so results are at rounding level, which is
                # what finite-difference checks of the projection need.
                step = np.einsum("nij,nj->ni", inv2x2(eye + self.jacobian_xy(mi)), resid)
                m[idx] = mi - step
                done[idx[reached]] = True
                bad = ~np.all(np.isfinite(m[idx]), axis=1)
                active[idx[bad]] = False
            m[~active] = np.nan
            jac = eye + self.jacobian_xy(m)
            det = jac[:, 0, 0] * jac[:, 1, 1] - jac[:, 0, 1] * jac[:, 1, 0]
            trace = jac[:, 0, 0] + jac[:, 1, 1]
            final = m + self.correction(m) - target
            ok = done & active & (np.hypot(final[:, 0], final[:, 1]) <= tol_mm)
            # The physical root lies on the branch connected to the identity: there both
            # eigenvalues of I + dd/dm have positive real part (det > 0 alone is not
            # enough: past a radial fold both flip sign), and the point stays on the same
            # side of the principal point.
            same_side = np.einsum("ni,ni->n", m, target) > 0.0
            tiny = np.hypot(target[:, 0], target[:, 1]) <= tol_mm
            ok &= (det > 0.0) & (trace > 0.0) & (same_side | tiny)
        m[~ok] = np.nan
        return m, ok

    def distort(
        self,
        xy: ArrayLike,
        *,
        tol_mm: float = DEFAULT_TOL_MM,
        max_iter: int = DEFAULT_MAX_ITER,
    ) -> Array:
        """Ideal centred coordinates (N, 2) mm -> measured centred coordinates (N, 2) mm.

        Same as :meth:`distort_with_status` but raises :class:`DistortionInversionError` if any
        point fails.
        """
        m, ok = self.distort_with_status(xy, tol_mm=tol_mm, max_iter=max_iter)
        if not np.all(ok):
            bad = np.flatnonzero(~ok)
            first = as_points(xy, 2, "xy")[bad[0]]
            raise DistortionInversionError(
                f"{self.model}: inverting the lens model failed for {bad.size} of {ok.size} "
                f"point(s) (first: ideal x={first[0]:.6g} mm, y={first[1]:.6g} mm); they "
                "lie outside the region where the model is invertible, e.g. far outside "
                "the calibrated field",
                ok,
            )
        return m

    # ------------------------------------------------------------------ files
    def to_dict(self) -> Dict[str, Any]:
        """``{"model": name, <param>: value, ..., <constant>: value, ...}``."""
        out: Dict[str, Any] = {"model": self.model}
        out.update(zip(self.param_names, self._params.tolist()))
        out.update(self._constants)
        return out

    @classmethod
    def from_dict(cls: Type[_M], data: Mapping[str, Any], source: str | None = None) -> _M:
        """Build the model from :meth:`to_dict` output.

        Missing coefficients are 0; missing constants, unknown keys and non-numeric values
        raise :class:`InputError` naming ``source`` (a file) and the key.
        """
        return _from_dict_checked(cls, data, source)

    # ------------------------------------------------------------------ value semantics
    def _key(self) -> Tuple[Any, ...]:
        return (self.model, tuple(self._params.tolist()), tuple(sorted(self._constants.items())))

    def __eq__(self, other: object) -> bool:
        """Compare model class, coefficients and constants exactly."""
        if not isinstance(other, DistortionModel):
            return NotImplemented
        return type(self) is type(other) and self._key() == other._key()

    def __hash__(self) -> int:
        """Hash consistent with :meth:`__eq__` (models are immutable)."""
        return hash(self._key())

    def __repr__(self) -> str:
        """``ClassName(name=value, ...)``."""
        items = list(zip(self.param_names, self._params.tolist())) + list(self._constants.items())
        return f"{type(self).__name__}({', '.join(f'{k}={v!r}' for k, v in items)})"


#: Registry of the lens models by their file name (``"model"`` key).
DISTORTION_MODELS: Dict[str, Type[DistortionModel]] = {}


def register_model(cls: Type[_M]) -> Type[_M]:
    """Class decorator adding a :class:`DistortionModel` subclass to :data:`DISTORTION_MODELS`."""
    if not cls.model:
        raise TypeError(f"{cls.__name__} has no model name")
    if cls.model in DISTORTION_MODELS and DISTORTION_MODELS[cls.model] is not cls:
        raise TypeError(f"lens model name '{cls.model}' is already registered")
    DISTORTION_MODELS[cls.model] = cls
    return cls


def _from_dict_checked(
    cls: Type[_M], data: Mapping[str, Any], source: str | None, prefix: str = "distortion"
) -> _M:
    known = set(cls.param_names) | set(cls.constant_names) | {"model"}
    for key in data:
        if key not in known:
            raise InputError(
                f"key '{prefix}.{key}': unknown coefficient for lens model '{cls.model}' "
                f"(expected {sorted(known - {'model'})})",
                path=source,
            )
    values: Dict[str, float] = {}
    for key in (*cls.param_names, *cls.constant_names):
        if key not in data:
            if key in cls.constant_names:
                raise InputError(f"key '{prefix}.{key}' is missing", path=source)
            continue
        value = data[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(f"key '{prefix}.{key}': must be a number, got {value!r}", path=source)
        if not np.isfinite(value):
            raise InputError(f"key '{prefix}.{key}': must be finite, got {value}", path=source)
        values[key] = float(value)
    return cls(**values)


def distortion_from_dict(
    data: Any, source: str | None = None, prefix: str = "distortion"
) -> DistortionModel:
    """Build a registered lens model from a dict with a ``"model"`` key.

    Parameters
    ----------
    data : mapping
        E.g. ``{"model": "brown_conrady", "k1": -5e-5}``; ``{"model": "none"}`` or an
        empty mapping gives :class:`NoDistortion`.
    source : str, optional
        File the dict came from, named in every :class:`InputError`.
    prefix : str
        Key path of ``data`` in that file, used in error messages.

    >>> distortion_from_dict({"model": "brown_conrady", "k1": -5e-5}).params.tolist()
    [-5e-05, 0.0, 0.0, 0.0, 0.0]
    """
    if not isinstance(data, Mapping):
        raise InputError(f"key '{prefix}': must be an object, got {data!r}", path=source)
    name = data.get("model", "none" if not data else None)
    if name is None:
        raise InputError(f"key '{prefix}.model' is missing", path=source)
    if not isinstance(name, str) or name not in DISTORTION_MODELS:
        raise InputError(
            f"key '{prefix}.model': unknown lens model {name!r} "
            f"(known: {', '.join(sorted(DISTORTION_MODELS))})",
            path=source,
        )
    return _from_dict_checked(DISTORTION_MODELS[name], data, source, prefix)


@register_model
class NoDistortion(DistortionModel):
    """The identity lens model: measured == ideal (P = 0)."""

    model: ClassVar[str] = "none"
    param_names: ClassVar[Tuple[str, ...]] = ()

    def __init__(self) -> None:
        super().__init__()

    def correction(self, xy: ArrayLike) -> Array:
        """Zero correction (N, 2)."""
        return np.zeros_like(as_points(xy, 2, "xy"))

    def jacobian_xy(self, xy: ArrayLike) -> Array:
        """Zeros (N, 2, 2)."""
        return np.zeros((as_points(xy, 2, "xy").shape[0], 2, 2))

    def jacobian_params(self, xy: ArrayLike) -> Array:
        """Empty (N, 2, 0)."""
        return np.zeros((as_points(xy, 2, "xy").shape[0], 2, 0))

    def distort_with_status(
        self, xy: ArrayLike, *, tol_mm: float = DEFAULT_TOL_MM, max_iter: int = DEFAULT_MAX_ITER
    ) -> Tuple[Array, NDArray[np.bool_]]:
        """Identity (copy of ``xy``), all points converged."""
        m = as_points(xy, 2, "xy").copy()
        ok = np.all(np.isfinite(m), axis=1)
        m[~ok] = np.nan
        return m, ok


@register_model
class BrownConrady(DistortionModel):
    """Brown-Conrady radial (k1, k2, k3) and decentring (p1, p2) correction, in mm.

    With ``x, y`` the measured coordinates centred on the principal point (mm) and
    ``r2 = x**2 + y**2``::

        dx = x (k1 r2 + k2 r2**2 + k3 r2**3) + p1 (r2 + 2 x**2) + 2 p2 x y
        dy = y (k1 r2 + k2 r2**2 + k3 r2**3) + 2 p1 x y + p2 (r2 + 2 y**2)

    and ``ideal = measured + d``. Units: k1 mm^-2, k2 mm^-4, k3 mm^-6, p1 and p2 mm^-1.
    These are not OpenCV's coefficients: OpenCV maps ideal -> distorted in coordinates
    normalised by the focal length, with y down and p1/p2 swapped (see the tests).

    >>> BrownConrady(k1=-5e-5).correction([[10.0, 0.0]])
    array([[-0.05,  0.  ]])
    """

    model: ClassVar[str] = "brown_conrady"
    param_names: ClassVar[Tuple[str, ...]] = ("k1", "k2", "k3", "p1", "p2")

    def __init__(
        self,
        k1: float = 0.0,
        k2: float = 0.0,
        k3: float = 0.0,
        p1: float = 0.0,
        p2: float = 0.0,
    ) -> None:
        super().__init__(k1=k1, k2=k2, k3=k3, p1=p1, p2=p2)

    def _terms(self, xy: ArrayLike) -> Tuple[Array, Array, Array, Array, Array]:
        m = as_points(xy, 2, "xy")
        x, y = m[:, 0], m[:, 1]
        k1, k2, k3 = self._params[:3]
        r2 = x * x + y * y
        radial = r2 * (k1 + r2 * (k2 + r2 * k3))
        # d radial / d r2, for the chain rule d r2 / dx = 2 x.
        radial_r2 = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2)
        return x, y, r2, radial, radial_r2

    def correction(self, xy: ArrayLike) -> Array:
        """Correction (N, 2) mm at measured centred ``xy`` (N, 2) mm."""
        x, y, r2, radial, _ = self._terms(xy)
        p1, p2 = self._params[3:]
        out = np.empty((x.shape[0], 2))
        out[:, 0] = x * radial + p1 * (r2 + 2.0 * x * x) + 2.0 * p2 * x * y
        out[:, 1] = y * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * y * y)
        return out

    def jacobian_xy(self, xy: ArrayLike) -> Array:
        """``d correction / d (x, y)``, (N, 2, 2), dimensionless."""
        x, y, _, radial, radial_r2 = self._terms(xy)
        p1, p2 = self._params[3:]
        out = np.empty((x.shape[0], 2, 2))
        # The off-diagonal terms are equal: the correction is the gradient of a potential.
        cross = 2.0 * x * y * radial_r2 + 2.0 * p1 * y + 2.0 * p2 * x
        out[:, 0, 0] = radial + 2.0 * x * x * radial_r2 + 6.0 * p1 * x + 2.0 * p2 * y
        out[:, 0, 1] = cross
        out[:, 1, 0] = cross
        out[:, 1, 1] = radial + 2.0 * y * y * radial_r2 + 2.0 * p1 * x + 6.0 * p2 * y
        return out

    def jacobian_params(self, xy: ArrayLike) -> Array:
        """``d correction / d (k1, k2, k3, p1, p2)``, (N, 2, 5), mm per unit of each."""
        x, y, r2, _, _ = self._terms(xy)
        r4 = r2 * r2
        out = np.empty((x.shape[0], 2, 5))
        out[:, 0, 0], out[:, 1, 0] = x * r2, y * r2
        out[:, 0, 1], out[:, 1, 1] = x * r4, y * r4
        out[:, 0, 2], out[:, 1, 2] = x * r4 * r2, y * r4 * r2
        out[:, 0, 3], out[:, 1, 3] = r2 + 2.0 * x * x, 2.0 * x * y
        out[:, 0, 4], out[:, 1, 4] = 2.0 * x * y, r2 + 2.0 * y * y
        return out
