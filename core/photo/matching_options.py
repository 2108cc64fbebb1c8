"""The options of least-squares matching (:mod:`.least_squares_matching`) and of control
location (:mod:`.control_location`), kept apart from their numba kernels so that the
algorithm's spec reads its defaults without importing them (core/jobs/locate_control_points.py).
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class TextureOptions:
    """Parameters of the adaptive template size (:mod:`.template_matching`'s docstring)."""

    min_size: int = 15
    max_size: int = 51
    step: int = 6
    target_sigma_px: float = 0.02
    min_isotropy: float = 0.05
    noise_floor: float = 0.02
    min_contrast: float = 1e-6


@dataclass(frozen=True)
class LsmOptions:
    """Convergence and acceptance thresholds (:mod:`.least_squares_matching`); pixels unless
    stated."""

    max_iterations: int = 30
    shift_tol_px: float = 0.001
    max_shift_px: float = 3.0
    min_correlation: float = 0.7
    max_sigma_px: float = 0.2
    interpolation: str = "bicubic"
    backend: str = "auto"


@dataclass(frozen=True)
class LocateOptions:
    """Options of :func:`~.control_location.locate_control_points` (its module docstring
    for each)."""

    search_sigmas: float = 3.0
    default_search_px: float = 25.0
    min_search_px: float = 5.0
    max_search_px: float = 150.0
    min_ncc: float = 0.6
    transfer: bool = True
    sigma_floor_px: float = 0.1
    texture: TextureOptions = field(default_factory=TextureOptions)
    lsm: LsmOptions = field(default_factory=LsmOptions)
