"""Accuracy grades of INS/GNSS solutions: the sigmas of the position and attitude priors."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError

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
        h, v = self.sigma_horizontal_m, self.sigma_vertical_m
        return np.array([h, h, v])

    @property
    def sigma_attitude(self) -> Array:
        """(roll, pitch, heading) sigmas, radians."""
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


def ins_grade(grade: str, sigmas: Sequence[float] | None = None) -> InsGrade:
    """A named grade of :data:`INS_GRADES`, or ``custom`` with four sigmas: horizontal and
    vertical position (metres), roll/pitch and heading (degrees).

    >>> ins_grade("custom", (0.1, 0.2, 0.01, 0.02)).sigma_vertical_m
    0.2
    """
    if grade == "custom":
        values = np.asarray(sigmas if sigmas is not None else (), dtype=np.float64)
        if values.shape != (4,) or not (np.isfinite(values).all() and (values > 0).all()):
            raise InputError(f"INS_SIGMAS must be four numbers > 0, got {sigmas}")
        return InsGrade("custom", *map(float, values))
    if grade not in INS_GRADES:
        raise InputError(f"INS grade '{grade}' is unknown: use {', '.join(INS_GRADES)} or custom")
    return INS_GRADES[grade]
