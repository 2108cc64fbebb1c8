"""Camera-calibration files: target images in, the residual table and the report out.

Residual CSV (one row per detected target point used by the adjustment)::

    image,point_id,col,row,v_col,v_row,w_col,w_row

``image`` the view's file name, ``point_id`` the target point's id (see
:mod:`core.photo.calibration_targets`), ``col, row`` the detected position in pixels (origin
at the top-left corner of the top-left pixel, rows down), ``v_col, v_row`` the residuals
(adjusted minus detected, pixels) and ``w_col, w_row`` Baarda's standardised residuals
(dimensionless; empty where not computable).

Report JSON: the calibrated camera (the camera-file format of :mod:`core.io.camera`), the
a-posteriori sigmas, the correlation matrix of the interior parameters, the t-test of every
lens coefficient, sigma0, the RMS and the per-view RMS and points, the pose of each view in
the target frame and the initial values (keys documented in docs/conventions.md).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Union, cast

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from .atomic import write_text_atomic
from .tables import number, write_csv_atomic

RESIDUAL_COLUMNS = ("image", "point_id", "col", "row", "v_col", "v_row", "w_col", "w_row")


def read_image_grey(path: Union[str, Path]) -> NDArray[np.uint8]:
    """Read an image file as 8-bit grey (OpenCV); InputError naming the file if unreadable."""
    import cv2

    img = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)
    if img is None:
        raise InputError(
            "cannot read this image (not an image format OpenCV reads)", path=str(path)
        )
    return cast(NDArray[np.uint8], img)  # IMREAD_GRAYSCALE: always 8 bit


def write_residuals_csv(path: Union[str, Path], result: Any) -> None:
    """Write the residual table of a :class:`core.photo.camera_calibration.CalibrationResult`."""
    rows = (
        (img, pid, number(c), number(r), number(vc), number(vr), number(wc), number(wr))
        for img, pid, c, r, vc, vr, wc, wr in result.residuals
    )
    write_csv_atomic(path, RESIDUAL_COLUMNS, rows)


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(float(x)) else None


def report_dict(result: Any, extra: dict | None = None) -> dict[str, Any]:
    """The report of a calibration as a JSON-ready dict (see the module docstring)."""
    names = result.parameter_names
    corr = [[_finite(c) for c in row] for row in np.asarray(result.correlation)]
    views = [
        {
            "image": n,
            "points": int(p),
            "rms_px": float(r),
            "eo": dict(zip(("X0", "Y0", "Z0", "omega", "phi", "kappa"), map(float, e))),
            "eo_sigma": dict(zip(("X0", "Y0", "Z0", "omega", "phi", "kappa"), map(_finite, s))),
        }
        for n, p, r, e, s in zip(
            result.view_names, result.view_points, result.view_rms_px, result.eo, result.eo_sigma
        )
    ]
    cam = result.camera
    out = {
        "camera": cam.to_dict(),
        "focal_px": cam.focal_px,
        "principal_point_px": list(cam.principal_point_px),
        "sigmas": {k: _finite(v) for k, v in result.sigmas.items()},
        "sigmas_px": {
            k: _finite(result.sigmas[k] / cam.pixel_size_mm)
            for k in ("focal_mm", "x0_mm", "y0_mm")
            if k in result.sigmas
        },
        "parameters": names,
        "correlation": corr,
        "t_values": result.t_values,
        "significant": result.significant,
        "t_critical": result.t_critical,
        "sigma0": result.sigma0,
        "sigma_px_prior": result.sigma_px,
        "sigma_px_posterior": result.sigma0 * result.sigma_px,
        "global_test_passed": bool(result.adjustment.global_test.passed),
        "redundancy": result.redundancy,
        "points": result.n_points,
        "rms_px": result.rms_px,
        "iterations": result.iterations,
        "condition_number": _finite(result.condition_number),
        "initial": result.initial,
        "views": views,
        "warnings": list(result.warnings),
    }
    if extra:
        out.update(extra)
    return out


def write_report_json(path: Union[str, Path], result: Any, extra: dict | None = None) -> None:
    """Write :func:`report_dict` to ``path`` (atomically)."""
    write_text_atomic(
        path, json.dumps(report_dict(result, extra), indent=2, allow_nan=False) + "\n"
    )
