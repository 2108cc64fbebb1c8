"""The options of camera calibration (:mod:`.camera_calibration`): its parameter names and
choices, kept apart from the adjustment (scipy) so that the algorithm's spec reads its
defaults without importing it (core/jobs/calibrate_camera.py)."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import InputError
from ..geometry.projection import PROJECTIONS

INTERIOR_NAMES = ("focal_mm", "x0_mm", "y0_mm", "k1", "k2", "k3", "p1", "p2")
LENS_NAMES = INTERIOR_NAMES[3:]
FIELD_MODES = ("fixed", "free")


@dataclass(frozen=True)
class CalibrationOptions:
    """Options of :func:`~.camera_calibration.calibrate_camera`.

    Attributes
    ----------
    projection : str
        ``"perspective"`` or a fisheye projection (:data:`core.geometry.projection.PROJECTIONS`).
    lens_parameters : tuple of str
        Lens coefficients to estimate (the others are held at zero), of
        ``k1 k2 k3 p1 p2``.
    field : {"fixed", "free"}
        Target coordinates as given (fixed) or estimated with a minimal datum (free).
    sigma_px : float
        A-priori standard deviation of a detected point, pixels (each coordinate).
    alpha : float
        Significance level of the t-tests of the lens coefficients.
    max_iterations : int
        Of the adjustment.
    """

    projection: str = "perspective"
    lens_parameters: tuple[str, ...] = LENS_NAMES
    field: str = "fixed"
    sigma_px: float = 0.2
    alpha: float = 0.05
    max_iterations: int = 100

    def __post_init__(self) -> None:
        """Check the choices (raises :class:`InputError`)."""
        if self.projection not in PROJECTIONS:
            raise InputError(f"projection must be one of {', '.join(PROJECTIONS)}, "
                             f"got {self.projection!r}")  # fmt: skip
        bad = [p for p in self.lens_parameters if p not in LENS_NAMES]
        if bad:
            raise InputError(f"unknown lens parameter(s) {bad}: use some of {list(LENS_NAMES)}")
        if self.field not in FIELD_MODES:
            raise InputError(f"field must be fixed or free, got {self.field!r}")
        if not self.sigma_px > 0:
            raise InputError(f"sigma_px must be positive, got {self.sigma_px}")
