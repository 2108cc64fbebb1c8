"""Additional-parameter (AP) families of self-calibrating aerotriangulation, as lens models.

Five families, registered into the lens-model registry of :mod:`.distortion` (so a camera JSON
may carry any of them and every projection, resection and bundle adjustment uses them):

=============  ==============================  ============================================
model          parameters                      source
=============  ==============================  ============================================
``lens_k1k2``  k1, k2                          radial symmetric distortion (Murai et al.
                                               1984; Lima, Debiasi & Menezes, their Eqs.
                                               9-10)
``bauer``      a1 .. a3 (constant ``r0_mm``)   Bauer & Mueller (1972)
``jacobsen``   a1 .. a4 (constant ``r0_mm``)   Jacobsen's simple set (Jacobsen 1980)
``ebner``      b1 .. b12 (constant ``b_mm``)   Ebner (1976): orthogonal on a 3 x 3 grid
``brown``      a1 .. a14 (constant ``c_mm``)   Brown (1976), 14-term set of Murai et al.
                                               (1984)
=============  ==============================  ============================================

As every lens model of the project they are *corrections added* to the measured image
coordinates centred on the principal point, ``x_ideal = x + dx(x, y)``, in millimetres (x
right, y up); the coefficients are defined for millimetre coordinates. All five are linear in
their parameters with polynomial basis functions, so they share one implementation
(:class:`PolynomialAP`): a table of terms ``coefficient * x**i * y**j`` per parameter and
axis, from which the correction and both Jacobians follow exactly. docs/ap_models.md gives
each form with the reason for it (the extracted text of Lima, Debiasi & Menezes garbles
several of them) and how the constants are chosen (:func:`ap_constants`).
"""

from __future__ import annotations

from typing import ClassVar, Dict, List, Tuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .ap_families import AP_FAMILIES
from .distortion import DistortionModel, as_points, register_model

Array = NDArray[np.float64]

#: A term of a basis function: (parameter number, axis 0 = dx / 1 = dy, coefficient, i, j)
#: meaning ``coefficient * x**i * y**j``.
Term = Tuple[int, int, float, int, int]

__all__ = [
    "AP_FAMILIES",
    "Bauer",
    "Brown14",
    "Ebner",
    "Jacobsen",
    "LensK1K2",
    "PolynomialAP",
    "ap_constants",
    "make_ap_model",
]


class PolynomialAP(DistortionModel):
    """A lens model linear in its parameters with polynomial basis functions.

    Subclasses implement :meth:`terms`; the correction is ``sum_k p_k B_k(x, y)``.
    """

    def terms(self) -> List[Term]:
        """The basis functions as a list of :data:`Term` (constants already applied)."""
        raise NotImplementedError

    def _tables(
        self,
    ) -> tuple[NDArray[np.intp], NDArray[np.intp], Array, NDArray[np.intp], NDArray[np.intp]]:
        cached = getattr(self, "_term_table", None)
        if cached is None:
            t = self.terms()
            cached = (
                np.array([a[0] for a in t], dtype=np.intp),
                np.array([a[1] for a in t], dtype=np.intp),
                np.array([a[2] for a in t], dtype=np.float64),
                np.array([a[3] for a in t], dtype=np.intp),
                np.array([a[4] for a in t], dtype=np.intp),
            )
            self._term_table = cached
        return cached

    @staticmethod
    def _powers(v: Array, top: int) -> Array:
        out = np.ones((top + 1, v.size))
        for k in range(1, top + 1):
            out[k] = out[k - 1] * v
        return out

    def jacobian_params(self, xy: ArrayLike) -> Array:
        """``d correction / d params`` (N, 2, P): the basis functions, mm per unit."""
        m = as_points(xy, 2, "xy")
        par, axis, coef, i, j = self._tables()
        top = int(max(i.max(initial=0), j.max(initial=0)))
        px, py = self._powers(m[:, 0], top), self._powers(m[:, 1], top)
        out = np.zeros((m.shape[0], 2, self.n_params))
        vals = coef[:, None] * px[i] * py[j]  # (T, N)
        for t in range(par.size):
            out[:, axis[t], par[t]] += vals[t]
        return out

    def correction(self, xy: ArrayLike) -> Array:
        """Correction (N, 2) mm at measured centred ``xy`` (N, 2) mm."""
        return np.einsum("nap,p->na", self.jacobian_params(xy), self._params)

    def jacobian_xy(self, xy: ArrayLike) -> Array:
        """``d correction / d (x, y)`` (N, 2, 2), dimensionless."""
        m = as_points(xy, 2, "xy")
        par, axis, coef, i, j = self._tables()
        top = int(max(i.max(initial=0), j.max(initial=0)))
        px, py = self._powers(m[:, 0], top), self._powers(m[:, 1], top)
        p = self._params[par] * coef
        out = np.zeros((m.shape[0], 2, 2))
        # d/dx of x^i y^j = i x^(i-1) y^j (zero when i = 0)
        dx = (p * i)[:, None] * px[np.maximum(i - 1, 0)] * py[j]
        dy = (p * j)[:, None] * px[i] * py[np.maximum(j - 1, 0)]
        for t in range(par.size):
            out[:, axis[t], 0] += dx[t]
            out[:, axis[t], 1] += dy[t]
        return out


def _radial(par: int, c0: float) -> List[Term]:
    """``a (x, y) (r^2 - c0)``: x^3 + x y^2 - c0 x and x^2 y + y^3 - c0 y."""
    return [
        (par, 0, 1.0, 3, 0),
        (par, 0, 1.0, 1, 2),
        (par, 0, -c0, 1, 0),
        (par, 1, 1.0, 2, 1),
        (par, 1, 1.0, 0, 3),
        (par, 1, -c0, 0, 1),
    ]


@register_model
class LensK1K2(PolynomialAP):
    """Radial symmetric distortion with two coefficients (k3 = 0).

    ``dx = x (k1 r^2 + k2 r^4)``, ``dy = y (k1 r^2 + k2 r^4)``; k1 in mm^-2, k2 in mm^-4.

    >>> LensK1K2(k1=-1e-3).correction([[2.0, 0.0]]).tolist()
    [[-0.008, 0.0]]
    """

    model: ClassVar[str] = "lens_k1k2"
    param_names: ClassVar[Tuple[str, ...]] = ("k1", "k2")

    def __init__(self, k1: float = 0.0, k2: float = 0.0) -> None:
        super().__init__(k1=k1, k2=k2)

    def terms(self) -> List[Term]:
        """x r^2, y r^2 (k1); x r^4, y r^4 (k2) expanded."""
        out = _radial(0, 0.0)[:2] + _radial(0, 0.0)[3:5]
        # r^4 = x^4 + 2 x^2 y^2 + y^4
        for axis, (a, b) in ((0, (1, 0)), (1, (0, 1))):
            out += [
                (1, axis, 1.0, 4 + a, b),
                (1, axis, 2.0, 2 + a, 2 + b),
                (1, axis, 1.0, a, 4 + b),
            ]
        return out


@register_model
class Bauer(PolynomialAP):
    """Bauer's three parameters: radial distortion, affinity and shear (Bauer & Mueller 1972).

    ``dx = a1 x (r^2 - r0^2) + a2 x``, ``dy = a1 y (r^2 - r0^2) - a2 y + a3 x``.

    >>> Bauer(a2=1e-4, r0_mm=2.0).correction([[1.0, 1.0]]).tolist()
    [[0.0001, -0.0001]]
    """

    model: ClassVar[str] = "bauer"
    param_names: ClassVar[Tuple[str, ...]] = ("a1", "a2", "a3")
    constant_names: ClassVar[Tuple[str, ...]] = ("r0_mm",)

    def __init__(self, a1: float = 0.0, a2: float = 0.0, a3: float = 0.0, *, r0_mm: float) -> None:
        super().__init__(a1=a1, a2=a2, a3=a3, r0_mm=r0_mm)

    def terms(self) -> List[Term]:
        """The three basis functions, expanded."""
        r02 = self._constants["r0_mm"] ** 2
        return _radial(0, r02) + [(1, 0, 1.0, 1, 0), (1, 1, -1.0, 0, 1), (2, 1, 1.0, 1, 0)]


@register_model
class Jacobsen(PolynomialAP):
    """Jacobsen's simple four-parameter set.

    ``dx = a1 x (r^2 - r0^2) + a2 x + a3 y``,
    ``dy = a1 y (r^2 - r0^2) - a2 y + a3 x + a4 x^2``.

    >>> Jacobsen(a4=1e-4, r0_mm=2.0).correction([[2.0, 0.0]]).tolist()
    [[0.0, 0.0004]]
    """

    model: ClassVar[str] = "jacobsen"
    param_names: ClassVar[Tuple[str, ...]] = ("a1", "a2", "a3", "a4")
    constant_names: ClassVar[Tuple[str, ...]] = ("r0_mm",)

    def __init__(
        self,
        a1: float = 0.0,
        a2: float = 0.0,
        a3: float = 0.0,
        a4: float = 0.0,
        *,
        r0_mm: float,
    ) -> None:
        super().__init__(a1=a1, a2=a2, a3=a3, a4=a4, r0_mm=r0_mm)

    def terms(self) -> List[Term]:
        """The four basis functions, expanded."""
        r02 = self._constants["r0_mm"] ** 2
        return _radial(0, r02) + [
            (1, 0, 1.0, 1, 0),
            (1, 1, -1.0, 0, 1),
            (2, 0, 1.0, 0, 1),
            (2, 1, 1.0, 1, 0),
            (3, 1, 1.0, 2, 0),
        ]


@register_model
class Ebner(PolynomialAP):
    """Ebner's twelve parameters, orthogonal on a 3 x 3 grid of spacing ``b`` (Ebner 1976).

    With ``q(u) = u^2 - 2 b^2 / 3``::

        dx = b1 x + b2 y - b3 (2 x^2 - 4 b^2/3) + b4 x y + b5 q(y) + b7 x q(y)
             + b9 y q(x) + b11 q(x) q(y)
        dy = -b1 y + b2 x + b3 x y - b4 (2 y^2 - 4 b^2/3) + b6 q(x) + b8 y q(x)
             + b10 x q(y) + b12 q(x) q(y)

    >>> Ebner(b1=1e-4, b_mm=3.0).correction([[1.0, 2.0]]).tolist()
    [[0.0001, -0.0002]]
    """

    model: ClassVar[str] = "ebner"
    param_names: ClassVar[Tuple[str, ...]] = tuple(f"b{k}" for k in range(1, 13))
    constant_names: ClassVar[Tuple[str, ...]] = ("b_mm",)

    def terms(self) -> List[Term]:
        """The twelve basis functions, expanded with ``q(u) = u^2 - 2 b^2 / 3``."""
        c = 2.0 * self._constants["b_mm"] ** 2 / 3.0
        t: List[Term] = [
            (0, 0, 1.0, 1, 0),
            (0, 1, -1.0, 0, 1),  # b1
            (1, 0, 1.0, 0, 1),
            (1, 1, 1.0, 1, 0),  # b2
            (2, 0, -2.0, 2, 0),
            (2, 0, 2.0 * c, 0, 0),
            (2, 1, 1.0, 1, 1),  # b3
            (3, 0, 1.0, 1, 1),
            (3, 1, -2.0, 0, 2),
            (3, 1, 2.0 * c, 0, 0),  # b4
            (4, 0, 1.0, 0, 2),
            (4, 0, -c, 0, 0),  # b5: q(y)
            (5, 1, 1.0, 2, 0),
            (5, 1, -c, 0, 0),  # b6: q(x)
            (6, 0, 1.0, 1, 2),
            (6, 0, -c, 1, 0),  # b7: x q(y)
            (7, 1, 1.0, 2, 1),
            (7, 1, -c, 0, 1),  # b8: y q(x)
            (8, 0, 1.0, 2, 1),
            (8, 0, -c, 0, 1),  # b9: y q(x)
            (9, 1, 1.0, 1, 2),
            (9, 1, -c, 1, 0),  # b10: x q(y)
        ]
        # b11 (dx), b12 (dy): q(x) q(y) = x^2 y^2 - c x^2 - c y^2 + c^2
        for par, axis in ((10, 0), (11, 1)):
            t += [
                (par, axis, 1.0, 2, 2),
                (par, axis, -c, 2, 0),
                (par, axis, -c, 0, 2),
                (par, axis, c * c, 0, 0),
            ]
        return t


@register_model
class Brown14(PolynomialAP):
    """Brown's (1976) polynomial set in the 14-term form of Murai et al. (1984)::

        dx = a1 x + a2 y + a3 x y + a4 y^2 + a5 x^2 y + a6 x y^2 + a7 x^2 y^2
             + a13 (x / c) x^2 y^2 + a14 x (x^2 + y^2)
        dy = a8 x y + a9 x^2 + a10 x^2 y + a11 x y^2 + a12 x^2 y^2
             + a13 (y / c) x^2 y^2 + a14 y (x^2 + y^2)

    ``c`` is the (nominal, constant) principal distance in mm.

    >>> Brown14(a3=1e-4, c_mm=5.0).correction([[1.0, 2.0]]).tolist()
    [[0.0002, 0.0]]
    """

    model: ClassVar[str] = "brown"
    param_names: ClassVar[Tuple[str, ...]] = tuple(f"a{k}" for k in range(1, 15))
    constant_names: ClassVar[Tuple[str, ...]] = ("c_mm",)

    def terms(self) -> List[Term]:
        """The fourteen basis functions, expanded."""
        ic = 1.0 / self._constants["c_mm"]
        return [
            (0, 0, 1.0, 1, 0),
            (1, 0, 1.0, 0, 1),
            (2, 0, 1.0, 1, 1),
            (3, 0, 1.0, 0, 2),
            (4, 0, 1.0, 2, 1),
            (5, 0, 1.0, 1, 2),
            (6, 0, 1.0, 2, 2),
            (7, 1, 1.0, 1, 1),
            (8, 1, 1.0, 2, 0),
            (9, 1, 1.0, 2, 1),
            (10, 1, 1.0, 1, 2),
            (11, 1, 1.0, 2, 2),
            (12, 0, ic, 3, 2),
            (12, 1, ic, 2, 3),
            (13, 0, 1.0, 3, 0),
            (13, 0, 1.0, 1, 2),
            (13, 1, 1.0, 2, 1),
            (13, 1, 1.0, 0, 3),
        ]


def ap_constants(width_mm: float, height_mm: float, focal_mm: float) -> Dict[str, float]:
    """The fixed constants of the families for an image format (see docs/ap_models.md).

    - ``r0_mm``: the radius at which Bauer's and Jacobsen's radial term is orthogonal to a
      change of principal distance over the uniformly covered format,
      ``r0^2 = E[r^4] / E[r^2]``;
    - ``b_mm``: Ebner's grid spacing, ``b^2 = (W^2 + H^2) / 16`` (for a square of side 2B,
      ``b = B / sqrt(2)``, where ``q(u) = u^2 - 2 b^2/3`` has zero mean over the format);
    - ``c_mm``: the principal distance.

    >>> sorted(ap_constants(6.0, 6.0, 5.0))
    ['b_mm', 'c_mm', 'r0_mm']
    """
    w2, h2 = width_mm**2, height_mm**2
    er2 = (w2 + h2) / 12.0
    er4 = w2 * w2 / 80.0 + 2.0 * (w2 / 12.0) * (h2 / 12.0) + h2 * h2 / 80.0
    return {
        "r0_mm": float(np.sqrt(er4 / er2)),
        "b_mm": float(np.sqrt((w2 + h2) / 16.0)),
        "c_mm": float(focal_mm),
    }


def make_ap_model(
    family: str, width_mm: float, height_mm: float, focal_mm: float, **params: float
) -> DistortionModel:
    """A lens model of the AP family ``family`` (a key of :data:`AP_FAMILIES`), with the
    constants of :func:`ap_constants` and the given coefficients (others zero).

    >>> make_ap_model("bauer", 6.0, 4.0, 5.0).param_names
    ('a1', 'a2', 'a3')
    """
    from .distortion import DISTORTION_MODELS

    if family not in AP_FAMILIES:
        raise ValueError(f"unknown AP family {family!r} (known: {', '.join(AP_FAMILIES)})")
    cls = DISTORTION_MODELS[AP_FAMILIES[family]]
    consts = ap_constants(width_mm, height_mm, focal_mm)
    values = {k: consts[k] for k in cls.constant_names}
    values.update(params)
    return cls(**values)
