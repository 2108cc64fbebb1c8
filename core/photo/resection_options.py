"""The options of a space resection (:mod:`.resection`), in a module of their own that imports
no numerical library, so that the command line's help reads their defaults without the
adjustment's engine (tests/core/test_startup.py)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import InputError

#: Line models of :func:`~.resection.resect` (the first is the default).
MODELS = ("coplanarity", "equivalent_planes")
#: Equivalent-planes parametrisations: per line (the source's rule), or one for all lines.
PARAMETRISATIONS = ("auto", "horizontal", "vertical")


@dataclass(frozen=True)
class ResectionOptions:
    """Options of :func:`~.resection.resect`.

    Attributes
    ----------
    model : str
        Line model: ``"coplanarity"`` (parametrisation-free, the default) or
        ``"equivalent_planes"`` (Tommaselli & Tozzi 1996, both parametrisations).
    estimate_interior : bool
        Refine the focal length and the principal point (needs control at different depths
        or an oblique view; refused, naming the parameters, when the geometry cannot fix them).
    snooping : bool
        Baarda's data snooping (rejects whole points or lines).
    snooping_alpha : float
        Significance per observation of the data snooping.
    alpha : float
        Significance level of the global chi-square test.
    damping : bool
        Levenberg-Marquardt damping (plain Gauss-Newton when False, as in the source).
    max_iterations : int
    eo_prior_sigma : tuple of 6 floats, optional
        With a start pose, weight it as observations with these sigmas (m, m, m, rad, rad,
        rad): the source's weighted constraints on the approximate orientation.
    parametrisation : str
        Equivalent planes only: ``"auto"`` (per line by its direction, the source's rule),
        ``"horizontal"`` (``y = a x + b`` for every line) or ``"vertical"`` (``x = a* y +
        b*``), for studies of the two parametrisations.
    """

    model: str = MODELS[0]
    estimate_interior: bool = False
    snooping: bool = True
    snooping_alpha: float = 0.001
    alpha: float = 0.05
    damping: bool = True
    max_iterations: int = 50
    eo_prior_sigma: tuple[float, ...] | None = None
    parametrisation: str = "auto"

    def __post_init__(self) -> None:
        if self.model not in MODELS:
            raise InputError(f"model '{self.model}' is not one of {', '.join(MODELS)}")
        if self.parametrisation not in PARAMETRISATIONS:
            raise InputError(
                f"parametrisation '{self.parametrisation}' is not one of "
                f"{', '.join(PARAMETRISATIONS)}"
            )
        if self.eo_prior_sigma is not None:
            s = tuple(float(v) for v in self.eo_prior_sigma)
            if len(s) != 6 or not all(v > 0 and math.isfinite(v) for v in s):
                raise InputError("eo_prior_sigma needs 6 positive sigmas (m, m, m, rad x 3)")
            object.__setattr__(self, "eo_prior_sigma", s)
