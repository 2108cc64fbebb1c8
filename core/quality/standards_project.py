"""The project threshold of Pedrosa & dos Santos (2020): the planimetric threshold and the
stereo height precision of the flight (sources: :mod:`.standards`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from .accuracy_options import PAPER_FLIGHT_GEOMETRY, PAPER_H_THRESHOLD_M
from .html_table import TR_CONTEXT  # noqa: F401 - make i18n collects the _t("...") marks
from .standards import _TOL, StandardResult, Verdict, _check_d, _rmse, _t

__all__ = [
    "project_threshold",
    "stereo_height_precision",
]


def stereo_height_precision(
    flight_height_m: float, base_m: float, focal_mm: float, pixel_um: float
) -> float:
    """Height precision of a stereo pair, Eq. 18 of Pedrosa & dos Santos (2020): sqrt(2) H^2 / (B f)
    sigma_pix.

    Parameters
    ----------
    flight_height_m, base_m : float
        Flying height above ground H and air base B (m).
    focal_mm : float
        Focal length f (mm).
    pixel_um : float
        Image measurement precision sigma_pix, taken as the pixel size (micrometres).

    Returns
    -------
    float
        dz (m).

    Examples
    --------
    >>> round(stereo_height_precision(1600, 452, 100.4, 6), 2)
    0.48
    """
    for name, value in (
        ("flying height", flight_height_m),
        ("air base", base_m),
        ("focal length", focal_mm),
        ("pixel size", pixel_um),
    ):
        if not (math.isfinite(value) and value > 0):
            raise InputError(f"the {name} must be a positive number, got {value}")
    return math.sqrt(2.0) * flight_height_m**2 / (base_m * focal_mm * 1e-3) * (pixel_um * 1e-6)


def project_threshold(
    d: NDArray[np.float64],
    *,
    h_threshold: float = PAPER_H_THRESHOLD_M,
    v_threshold: float | None = None,
    flight_geometry: Sequence[float] = PAPER_FLIGHT_GEOMETRY,
) -> StandardResult:
    """The seed paper's acceptance rule: RMSE planimetric <= 0.40 m and vertical <= dz.

    ``v_threshold`` None or 0 computes dz from ``flight_geometry`` = (H m, B m, f mm,
    sigma_pix um) with :func:`stereo_height_precision` (0.48 m for the paper's values). The
    points beyond each threshold are counted (the paper discusses them individually).

    Examples
    --------
    >>> r = project_threshold(np.full((15, 3), 0.1))
    >>> [v.status for v in r.verdicts[:2]], round(r.figures["v_threshold"], 2)
    (['pass', 'pass'], 0.48)
    """
    d = _check_d(d)
    n = len(d)
    if not (math.isfinite(h_threshold) and h_threshold > 0):
        raise InputError(f"the planimetric threshold must be positive, got {h_threshold}")
    if v_threshold:
        dz = float(v_threshold)
        how = _t("given")
    else:
        if len(flight_geometry) != 4:
            raise InputError(
                "the flight geometry needs 4 numbers: H (m), B (m), f (mm), pixel (um)"
            )
        dz = stereo_height_precision(*(float(x) for x in flight_geometry))
        h, b, f, s = flight_geometry
        how = _t(
            "Eq. 18 with H {height:g} m, B {base:g} m, f {focal:g} mm, sigma_pix {pixel:g} um",
            height=h,
            base=b,
            focal=f,
            pixel=s,
        )
    horiz = np.hypot(d[:, 0], d[:, 1])
    rms_h, rms_v = _rmse(horiz), _rmse(d[:, 2])
    n_h = int(np.sum(horiz > h_threshold + _TOL))
    n_v = int(np.sum(np.abs(d[:, 2]) > dz + _TOL))
    ok_h, ok_v = rms_h <= h_threshold + _TOL, rms_v <= dz + _TOL
    verdicts = (
        Verdict(
            _t("Planimetric RMSE"),
            "pass" if ok_h else "fail",
            _t(
                "RMSE {rmse:.3f} m {relation} {limit:.3f} m; {beyond} of {n} points beyond it",
                rmse=rms_h,
                relation="<=" if ok_h else ">",
                limit=h_threshold,
                beyond=n_h,
                n=n,
            ),
            rms_h,
            h_threshold,
        ),
        Verdict(
            _t("Vertical RMSE"),
            "pass" if ok_v else "fail",
            _t(
                "RMSE {rmse:.3f} m {relation} dz {limit:.3f} m ({how}); {beyond} of {n} points "
                "beyond it",
                rmse=rms_v,
                relation="<=" if ok_v else ">",
                limit=dz,
                how=how,
                beyond=n_v,
                n=n,
            ),
            rms_v,
            dz,
        ),
    )
    return StandardResult(
        key="project",
        title=_t("Project threshold (Pedrosa & dos Santos 2020, section 3)"),
        reference="Pedrosa & dos Santos (2020), section 3, Eq. 18 and Tables 2-5",
        n_points=n,
        verdicts=verdicts,
        figures={
            "h_threshold": float(h_threshold),
            "v_threshold": dz,
            "RMSE_HORIZONTAL": rms_h,
            "RMSE_U": rms_v,
            "points_beyond_h": float(n_h),
            "points_beyond_v": float(n_v),
        },
        notes=(
            _t(
                "The paper compares the RMSE of the check-point discrepancies with 0.40 m "
                "(twice the LiDAR standard deviation) and with dz of Eq. 18."
            ),
        ),
    )
