"""Accuracy grades of INS/GNSS solutions: the sigmas of the position and attitude priors."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import InputError
from .ins_grades import INS_GRADES, InsGrade


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
