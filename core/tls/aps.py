"""Additional parameters (APs) of a terrestrial laser scanner: systematic errors in polar form.

Each recorded observation is the geometric one plus a correction that is linear in the APs
(Carvalho, Correa & dos Santos, Eqs. 2-5; Lichti 2007)::

    rho_obs   = rho   + d_rho(rho, theta, alpha)
    theta_obs = theta + d_theta(rho, theta, alpha)
    alpha_obs = alpha + d_alpha(rho, theta, alpha)

with ``d = sum_k p_k f_k`` over the chosen terms, evaluated at the angles the instrument
records (face II included, :func:`~lidarphoto.core.tls.polar.instrument_angles`). Terms:

==== ========== =============================== =====================================
name component f_k                             physical cause
==== ========== =============================== =====================================
a0   range      1                               rangefinder offset
a1   range      rho                             range scale (frequency) error
a2   range      sin(4 pi rho / U)               cyclic error of the phase measurement
a3   range      cos(4 pi rho / U)               (U: modulation wavelength)
b1   horizontal sec(alpha)                      collimation axis error
b2   horizontal tan(alpha)                      trunnion (horizontal) axis error
b3   horizontal sin(theta)                      horizontal circle eccentricity
b4   horizontal cos(theta)
b5   horizontal sin(2 theta)                    non-orthogonality of the horizontal
b6   horizontal cos(2 theta)                    encoder and the vertical axis
c0   vertical   1                               vertical circle index error
c1   vertical   alpha                           vertical encoder scale error
c2   vertical   sin(alpha)                      vertical circle eccentricity
c3   vertical   cos(alpha)
==== ========== =============================== =====================================

The paper's set is a0, b1, b2, c0 (its Eq. 5 writes ``d_theta = b1 sec(alpha) +
b2 tan(alpha)``). The extended set follows the physical terms of Lichti (2007); several of
them are correlated by nature (c0 with c3 near the horizon, c1 with c2 for small elevations,
a1 with the network scale without a known distance): :mod:`.calibration` reports such pairs
and can select the terms the data support.

Internal units: metres for a0, a2, a3; dimensionless for a1; radians for the angular terms.
Reports use millimetres, ppm and arc-seconds (:attr:`ApTerm.report_unit`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from .ap_table import AP_SETS, AP_TERMS, ARCSEC, HORIZONTAL, RANGE, VERTICAL, ApTerm  # noqa: F401

__all__ = [
    "AP_SETS",
    "AP_TERMS",
    "ApTerm",
    "ap_basis",
    "ap_corrections",
    "ap_terms",
]

Array = NDArray[np.float64]


def ap_terms(selection: str | tuple[str, ...] | list[str]) -> tuple[str, ...]:
    """The term names of a set name (``"paper"``) or a list (``"a0,b1,c0"``), in table order.

    >>> ap_terms("paper")
    ('a0', 'b1', 'b2', 'c0')
    >>> ap_terms("c0, a0")
    ('a0', 'c0')
    """
    if isinstance(selection, str):
        key = selection.strip().lower()
        if key in AP_SETS:
            return AP_SETS[key]
        names = [s.strip().lower() for s in key.replace(";", ",").split(",") if s.strip()]
    else:
        names = [str(s).strip().lower() for s in selection]
    unknown = [n for n in names if n not in AP_TERMS]
    if unknown:
        raise InputError(
            f"unknown additional parameter(s) {', '.join(unknown)}: choose a set "
            f"({', '.join(AP_SETS)}) or terms among {', '.join(AP_TERMS)}"
        )
    return tuple(n for n in AP_TERMS if n in names)


def ap_basis(
    names: tuple[str, ...], inst: ArrayLike, wavelength_m: float = 1.2
) -> tuple[Array, Array, NDArray[np.intp]]:
    """The functions ``f_k`` of the terms at the recorded geometry and their derivatives.

    Parameters
    ----------
    names : tuple of str
        Term names (:data:`AP_TERMS`).
    inst : ndarray, shape (N, 3)
        (rho, theta, alpha) as the instrument records them (metres, radians).
    wavelength_m : float
        Modulation wavelength U of the cyclic range terms a2, a3 (metres).

    Returns
    -------
    f : ndarray, shape (N, K)
    df : ndarray, shape (N, K, 3)
        ``d f_k / d (rho, theta, alpha)``.
    component : ndarray of int, shape (K,)
        The observation each term corrects (0 range, 1 horizontal, 2 vertical).

    >>> f, df, c = ap_basis(("b1", "c0"), [[10.0, 0.0, math.radians(60.0)]])
    >>> np.round(f, 6).tolist(), c.tolist()
    ([[2.0, 1.0]], [1, 2])
    """
    p = np.asarray(inst, dtype=np.float64)
    rho, theta, alpha = p[..., 0], p[..., 1], p[..., 2]
    n, k = p.shape[0], len(names)
    f = np.zeros((n, k))
    df = np.zeros((n, k, 3))
    ca, sa = np.cos(alpha), np.sin(alpha)
    w = 4.0 * math.pi / wavelength_m
    for j, name in enumerate(names):
        if name in ("a0", "c0"):
            f[:, j] = 1.0
        elif name == "a1":
            f[:, j] = rho
            df[:, j, 0] = 1.0
        elif name == "a2":
            f[:, j] = np.sin(w * rho)
            df[:, j, 0] = w * np.cos(w * rho)
        elif name == "a3":
            f[:, j] = np.cos(w * rho)
            df[:, j, 0] = -w * np.sin(w * rho)
        elif name == "b1":
            f[:, j] = 1.0 / ca
            df[:, j, 2] = sa / (ca * ca)
        elif name == "b2":
            f[:, j] = sa / ca
            df[:, j, 2] = 1.0 / (ca * ca)
        elif name == "b3":
            f[:, j] = np.sin(theta)
            df[:, j, 1] = np.cos(theta)
        elif name == "b4":
            f[:, j] = np.cos(theta)
            df[:, j, 1] = -np.sin(theta)
        elif name == "b5":
            f[:, j] = np.sin(2 * theta)
            df[:, j, 1] = 2 * np.cos(2 * theta)
        elif name == "b6":
            f[:, j] = np.cos(2 * theta)
            df[:, j, 1] = -2 * np.sin(2 * theta)
        elif name == "c1":
            f[:, j] = alpha
            df[:, j, 2] = 1.0
        elif name == "c2":
            f[:, j] = sa
            df[:, j, 2] = ca
        elif name == "c3":
            f[:, j] = ca
            df[:, j, 2] = -sa
        else:
            raise InputError(f"unknown additional parameter {name!r}")
    component = np.array([AP_TERMS[nm].component for nm in names], dtype=np.intp)
    return f, df, component


def ap_corrections(
    names: tuple[str, ...], values: ArrayLike, inst: ArrayLike, wavelength_m: float = 1.2
) -> Array:
    """(N, 3) corrections (d_rho, d_theta, d_alpha) of the terms with ``values`` (internal
    units) at the recorded geometry ``inst`` (N, 3).

    >>> c = ap_corrections(("a0", "b2"), [0.002, 4 * ARCSEC], [[5.0, 0.3, math.pi / 4]])
    >>> round(float(c[0, 0]), 6), round(float(c[0, 1] / ARCSEC), 6)
    (0.002, 4.0)
    """
    f, _, comp = ap_basis(names, inst, wavelength_m)
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    out = np.zeros((f.shape[0], 3))
    for j in range(len(names)):
        out[:, comp[j]] += v[j] * f[:, j]
    return out
