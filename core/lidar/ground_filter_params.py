"""The parameters of the ground filters (:mod:`.ground_filter`): PMF (``GroundFilterParams``),
SMRF (``SmrfParams``, and the published defaults) and CSF (``CsfParams``), each with its checks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Union

from ..errors import InputError

METHODS = ("smrf", "pmf", "csf")
GROWTH_CHOICES = ("linear", "exponential")
WINDOW_SHAPES = ("square", "disk")


@dataclass(frozen=True)
class LowOutlierParams:
    """What every method shares: the low-outlier pre-filter and the return filter.

    Attributes
    ----------
    low_outlier_height : float
        Depth below the local ground level that makes a point a low outlier (vertical unit);
        0 disables the pre-filter. Default 1.0.
    low_outlier_radius : float
        Half-size of the neighbourhood the point is compared with (horizontal unit).
        Default 5.0.
    last_returns_only : bool
        Only last/single returns can be ground when the file has return numbers. Default True.
    """

    low_outlier_height: float = 1.0
    low_outlier_radius: float = 5.0
    last_returns_only: bool = True

    def _check_common(self) -> None:
        for name in ("low_outlier_height", "low_outlier_radius"):
            value = getattr(self, name)
            if not (value >= 0 and math.isfinite(value)):
                raise InputError(f"{name} must be >= 0", column=name)


@dataclass(frozen=True)
class GroundFilterParams(LowOutlierParams):
    """Parameters of the PMF (units: see the module docstring).

    Attributes
    ----------
    cell_size : float
        Side of a grid cell (horizontal unit). Default 1.0.
    max_window : float
        Largest opening window (horizontal unit): about the size of the largest building.
        Default 20.0.
    slope : float
        Terrain slope (rise/run, dimensionless) that the elevation thresholds allow. Default 0.2.
    initial_distance : float
        ``dh0``, elevation threshold of the first opening (vertical unit). Default 0.3.
    max_distance : float
        Cap of the elevation thresholds (vertical unit). Default 2.5.
    growth : str
        ``"linear"`` (w_k = 2 k b + 1) or ``"exponential"`` (w_k = 2 b^k + 1). Default linear.
    window_base : float
        ``b`` of the window series (cells). Default 1.
    window_shape : str
        ``"square"`` or ``"disk"`` opening window. Default square.
    ground_threshold : float
        Final height above the DTM accepted as ground (vertical unit). Default 0.3.
    slope_scalar : float
        Added to ``ground_threshold`` per unit of local DTM slope (vertical unit). Default 1.0.
    low_outlier_height, low_outlier_radius, last_returns_only
        As in :class:`LowOutlierParams`.
    """

    cell_size: float = 1.0
    max_window: float = 20.0
    slope: float = 0.2
    initial_distance: float = 0.3
    max_distance: float = 2.5
    growth: str = "linear"
    window_base: float = 1.0
    window_shape: str = "square"
    ground_threshold: float = 0.3
    slope_scalar: float = 1.0
    method = "pmf"

    def validate(self) -> None:
        """Raise InputError naming the parameter when a value is out of range."""
        positive = ("cell_size", "max_window", "window_base")
        for name in positive:
            if not getattr(self, name) > 0:
                raise InputError(f"{name} must be > 0", column=name)
        non_negative = (
            "slope",
            "initial_distance",
            "max_distance",
            "ground_threshold",
            "slope_scalar",
        )
        for name in non_negative:
            value = getattr(self, name)
            if not (value >= 0 and math.isfinite(value)):
                raise InputError(f"{name} must be >= 0", column=name)
        self._check_common()
        if self.growth not in GROWTH_CHOICES:
            raise InputError(f"growth must be one of {GROWTH_CHOICES}", column="growth")
        if self.growth == "exponential" and self.window_base <= 1:
            raise InputError("window_base must be > 1 for exponential growth", column="window_base")
        if self.window_shape not in WINDOW_SHAPES:
            raise InputError(f"window_shape must be one of {WINDOW_SHAPES}", column="window_shape")
        if self.max_window < self.cell_size:
            raise InputError("max_window must be at least one cell", column="max_window")


@dataclass(frozen=True)
class SmrfParams(LowOutlierParams):
    """Parameters of SMRF (Pingel et al. 2013). The defaults are the paper's (and PDAL's,
    :data:`SMRF_PUBLISHED`) except ``threshold``, chosen on AHN3 (README).

    Attributes
    ----------
    cell_size : float
        Side of a grid cell (horizontal unit). Default 1.0 (published 1.0).
    slope : float
        Terrain slope (rise/run) allowed per unit of window radius; 0 estimates it from the
        cloud (the 90th percentile of the ground's slope after a first pass on cells twice
        as large, within 0.1-0.7; it over-estimates under vegetation on steep slopes, see
        README). Default 0.15 (published 0.15).
    max_window : float
        Largest window radius (horizontal unit). Default 18.0 (published 18.0).
    threshold : float
        Final height above the DTM accepted as ground (vertical unit). Default 0.3
        (published 0.5).
    scalar : float
        Added to ``threshold`` per unit of local DTM slope (vertical unit). Default 1.25
        (published 1.25).
    low_outlier_height, low_outlier_radius, last_returns_only
        As in :class:`LowOutlierParams`.
    """

    cell_size: float = 1.0
    slope: float = 0.15
    max_window: float = 18.0
    threshold: float = 0.3
    scalar: float = 1.25
    method = "smrf"

    def validate(self) -> None:
        """Raise InputError naming the parameter when a value is out of range."""
        for name in ("cell_size", "max_window"):
            if not getattr(self, name) > 0:
                raise InputError(f"{name} must be > 0", column=name)
        for name in ("slope", "threshold", "scalar"):
            value = getattr(self, name)
            if not (value >= 0 and math.isfinite(value)):
                raise InputError(f"{name} must be >= 0", column=name)
        self._check_common()
        if self.max_window < self.cell_size:
            raise InputError("max_window must be at least one cell", column="max_window")


#: SMRF with the defaults of Pingel et al. (2013) and PDAL's filters.smrf.
SMRF_PUBLISHED = SmrfParams(slope=0.15, max_window=18.0, threshold=0.5, scalar=1.25)


@dataclass(frozen=True)
class CsfParams(LowOutlierParams):
    """Parameters of the cloth simulation filter (Zhang et al. 2016); the defaults are those of
    the authors' package (``cloth-simulation-filter``).

    Attributes
    ----------
    resolution : float
        Distance between cloth particles (horizontal unit). Default 1.0.
    rigidness : int
        1 (steep slopes), 2 (terraces, gentle slopes) or 3 (flat terrain). Default 3.
    time_step : float
        Time step of the simulation (unit time). Default 0.65.
    threshold : float
        Largest distance from the cloth of a ground point (vertical unit). Default 0.5.
    iterations : int
        Largest number of time steps. Default 500.
    slope_smooth : bool
        Post-processing for steep slopes. Default True.
    low_outlier_height, low_outlier_radius, last_returns_only
        As in :class:`LowOutlierParams`.
    """

    resolution: float = 1.0
    rigidness: int = 3
    time_step: float = 0.65
    threshold: float = 0.5
    iterations: int = 500
    slope_smooth: bool = True
    method = "csf"

    @property
    def cell_size(self) -> float:
        """The grid of the minimum surface and of the cloth (horizontal unit)."""
        return self.resolution

    def validate(self) -> None:
        """Raise InputError naming the parameter when a value is out of range."""
        if not self.resolution > 0:
            raise InputError("resolution must be > 0", column="resolution")
        if self.rigidness not in (1, 2, 3):
            raise InputError("rigidness must be 1, 2 or 3", column="rigidness")
        if not (self.time_step > 0 and math.isfinite(self.time_step)):
            raise InputError("time_step must be > 0", column="time_step")
        if not (self.threshold >= 0 and math.isfinite(self.threshold)):
            raise InputError("threshold must be >= 0", column="threshold")
        if not self.iterations >= 1:
            raise InputError("iterations must be >= 1", column="iterations")
        self._check_common()


FilterParams = Union[GroundFilterParams, SmrfParams, CsfParams]
