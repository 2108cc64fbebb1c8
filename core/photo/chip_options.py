"""The options of the control chips (:mod:`.control_chips`) and the control plate's geometry
(:mod:`.control_plate`), in a module that imports numpy only when the plate's corners are
computed, so that the command line's help reads their defaults without it
(tests/core/test_startup.py)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..errors import InputError

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import NDArray

    Array = NDArray[np.float64]


@dataclass(frozen=True)
class ChipOptions:
    """Options of :func:`~.control_chips.make_chip` (units in the names)."""

    gsd_m: float = 0.15
    size_px: int = 41
    corner_sigma_px: float = 0.0
    max_sigma0: float = 3.0
    sift_ratio: float = 0.75
    ransac_px: float = 2.0
    min_matches: int = 30
    sift_features: int = 8000
    match_sigma_px: float = 0.5
    min_valid: float = 1.0
    from_plate_photo: bool = False

    def __post_init__(self) -> None:
        if not (math.isfinite(self.gsd_m) and self.gsd_m > 0):
            raise InputError(f"GSD must be > 0 m, got {self.gsd_m!r}")
        if int(self.size_px) != self.size_px or self.size_px < 3:
            raise InputError(f"chip size must be a whole number >= 3 px, got {self.size_px!r}")
        if not 0.0 < self.sift_ratio < 1.0:
            raise InputError(f"SIFT ratio must be in (0, 1), got {self.sift_ratio!r}")
        if not 0.0 < self.min_valid <= 1.0:
            raise InputError(f"min_valid must be in (0, 1], got {self.min_valid!r}")


@dataclass(frozen=True)
class PlateGeometry:
    """The control plate (module docstring): sides in metres, height above the surveyed
    point in metres, grid azimuth of a side in degrees.

    >>> PlateGeometry(0.6, 0.3).corners().round(3)[:2].tolist()
    [[-0.3, 0.3, 0.0], [-0.3, -0.3, 0.0]]
    """

    outer_m: float = 0.6
    inner_m: float = 0.3
    height_m: float = 0.0
    azimuth_deg: float = 0.0

    def __post_init__(self) -> None:
        for name in ("outer_m", "inner_m", "height_m", "azimuth_deg"):
            value = getattr(self, name)
            if not math.isfinite(float(value)):
                raise InputError(f"plate {name} must be finite, got {value!r}")
        if not 0.0 < self.inner_m < self.outer_m:
            raise InputError(
                f"plate: need 0 < inner side ({self.inner_m:g} m) < outer side ({self.outer_m:g} m)"
            )

    def corners(self) -> Array:
        """(8, 3) corners relative to the surveyed point (east, north, up; metres)."""
        import numpy as np  # here: the help reads the plate's defaults without numpy

        a = math.radians(self.azimuth_deg)
        e1 = np.array([math.sin(a), math.cos(a)])  # along the azimuth
        e2 = np.array([-math.cos(a), math.sin(a)])  # a quarter turn counter-clockwise
        signs = np.array([[1, 1], [-1, 1], [-1, -1], [1, -1]], dtype=float)
        out = np.zeros((8, 3))
        for k, side in enumerate((self.outer_m, self.inner_m)):
            h = side / 2.0
            # rotate so that the first corner lies in the direction azimuth - 45 degrees...
            xy = h * (signs[:, :1] * e1 + signs[:, 1:] * e2)
            # ...which with signs (1, 1) is e1 + e2: azimuth - 45 degrees
            out[4 * k : 4 * k + 4, :2] = xy
        out[:, 2] = self.height_m
        return out
