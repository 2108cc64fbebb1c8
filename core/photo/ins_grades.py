"""Accuracy grades of INS/GNSS solutions (:mod:`.ins`), in a module that imports numpy only
when a grade's sigmas are read, so that the command line's help lists the grades without it
(tests/core/test_startup.py)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import NDArray

    Array = NDArray[np.float64]


@dataclass(frozen=True)
class InsGrade:
    """Accuracy of an INS/GNSS solution (post-processed, 1 sigma / RMS).

    Attributes
    ----------
    name : str
    sigma_horizontal_m, sigma_vertical_m : float
        Position, metres.
    sigma_roll_pitch_deg, sigma_heading_deg : float
        Attitude, degrees.
    source : str
        Where the numbers come from.
    """

    name: str
    sigma_horizontal_m: float
    sigma_vertical_m: float
    sigma_roll_pitch_deg: float
    sigma_heading_deg: float
    source: str = "user"

    @property
    def sigma_position(self) -> Array:
        """(E, N, U) sigmas, metres."""
        import numpy as np  # here: the help lists the grades without numpy

        h, v = self.sigma_horizontal_m, self.sigma_vertical_m
        return np.array([h, h, v])

    @property
    def sigma_attitude(self) -> Array:
        """(roll, pitch, heading) sigmas, radians."""
        import numpy as np

        rp, hd = self.sigma_roll_pitch_deg, self.sigma_heading_deg
        return np.radians([rp, rp, hd])


#: Named INS grades. Only grades whose accuracies can be cited are listed; anything else is a
#: custom :class:`InsGrade`.
INS_GRADES: dict[str, InsGrade] = {
    "pos_av_310": InsGrade(
        "Applanix POS AV 310",
        0.02,
        0.05,
        0.015,
        0.035,
        "Pedrosa & dos Santos (2020), section 3: post-processed absolute accuracy (RMS) "
        "quoted from Applanix",
    ),
}
