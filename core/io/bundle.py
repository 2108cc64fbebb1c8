"""Tables written by the bundle adjustment (CSV, header row).

Object points (``OUTPUT_POINTS``)::

    point_id, role (tie | control | check), X, Y, Z (mapping CRS, m),
    sigma_X, sigma_Y, sigma_Z (m; check points: from their intersection), n_images

Residuals (``OUTPUT_RESIDUALS``), one row per image measurement::

    image_id, point_id, role, col, row (measured, px), sigma_px, v_col, v_row (adjusted minus
    measured, px), v_px (length), w_col, w_row (Baarda's standardised residuals; empty when not
    testable or for check points), redundancy_col, redundancy_row, rejected (1 when set aside
    by the robust stage or data snooping), used (1 when in the final adjustment)

Check points (``OUTPUT_CHECK_CSV``): the table the accuracy report reads
(:mod:`core.io.checkpoints`): ``id, e, n, h`` (intersected), ``e_ref, n_ref, h_ref``
(surveyed), ``group`` (the AP model; with several models the id is ``point [model]`` so
that the ids stay unique), plus ``sigma_e, sigma_n, sigma_h`` (m) and
``n_images``.

Model comparison (``OUTPUT_COMPARISON``), one row per AP model, best first::

    rank, model, n_check, mean_horizontal, std_horizontal, rmse_horizontal, rmse_u, rmse_3d
    (m; the names of docs/formats.md "Accuracy figures", u = up = height), sigma0, n_ap,
    n_ap_kept, n_significant, rejected, error
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Union

import numpy as np

from ..photo.bundle_result import BundleResult
from .tables import number, write_csv_atomic

__all__ = [
    "CHECK_COLUMNS",
    "COMPARISON_COLUMNS",
    "POINT_COLUMNS",
    "RESIDUAL_COLUMNS",
    "write_bundle_points",
    "write_bundle_residuals",
    "write_check_points",
    "write_comparison",
]

POINT_COLUMNS = ("point_id", "role", "X", "Y", "Z", "sigma_X", "sigma_Y", "sigma_Z", "n_images")
RESIDUAL_COLUMNS = (
    "image_id",
    "point_id",
    "role",
    "col",
    "row",
    "sigma_px",
    "v_col",
    "v_row",
    "v_px",
    "w_col",
    "w_row",
    "redundancy_col",
    "redundancy_row",
    "rejected",
    "used",
)
CHECK_COLUMNS = (
    "id",
    "e",
    "n",
    "h",
    "e_ref",
    "n_ref",
    "h_ref",
    "group",
    "sigma_e",
    "sigma_n",
    "sigma_h",
    "n_images",
)
COMPARISON_COLUMNS = (
    "rank",
    "model",
    "n_check",
    "mean_horizontal",
    "std_horizontal",
    "rmse_horizontal",
    "rmse_u",
    "rmse_3d",
    "sigma0",
    "n_ap",
    "n_ap_kept",
    "n_significant",
    "rejected",
    "error",
)
#: The key of :func:`core.photo.bundle.compare_ap_models`'s rows each column is written from.
_COMPARISON_KEYS = {
    "mean_horizontal": "mean_planimetric",
    "std_horizontal": "std_planimetric",
    "rmse_horizontal": "rms_planimetric",
    "rmse_u": "rms_h",
    "rmse_3d": "rms_3d",
}


def write_bundle_points(path: Union[str, Path], res: BundleResult) -> None:
    """The object points with their sigmas (format in the module docstring)."""
    parts = zip(res.point_id, res.point_role, res.point_xyz, res.point_sigma, res.point_images)
    rows = (
        (p, r, *(number(v) for v in x), *(number(v) for v in s), int(n)) for p, r, x, s, n in parts
    )
    write_csv_atomic(path, POINT_COLUMNS, rows)


def write_bundle_residuals(path: Union[str, Path], res: BundleResult) -> None:
    """Every image measurement with its residual and test (format in the module docstring)."""
    obs = res.observations
    vlen = np.hypot(res.v_px[:, 0], res.v_px[:, 1])
    rows = (
        (
            i,
            p,
            role,
            number(px[0]),
            number(px[1]),
            number(s),
            number(v[0]),
            number(v[1]),
            number(vl),
            number(w[0]),
            number(w[1]),
            number(r[0]),
            number(r[1]),
            int(rej),
            int(u),
        )
        for i, p, role, px, s, v, vl, w, r, rej, u in zip(
            obs.image_id,
            obs.point_id,
            res.obs_role,
            obs.pixels,
            obs.sigma_px,
            res.v_px,
            vlen,
            res.w,
            res.redundancy,
            res.rejected,
            res.used,
        )
    )
    write_csv_atomic(path, RESIDUAL_COLUMNS, rows)


def check_rows(res: BundleResult, tag: bool = False) -> list[tuple[str, ...]]:
    """The check-point rows of one result (group = its AP model; with ``tag`` the id carries
    the model too, ``GCP02 [bauer]``, so that several models' rows stay unique)."""
    c = res.check
    return [
        (
            f"{p} [{res.ap_model}]" if tag else p,
            *(number(v) for v in m),
            *(number(v) for v in r),
            res.ap_model,
            *(number(v) for v in s),
            str(int(n)),
        )
        for p, m, r, s, n in zip(c.point_id, c.measured, c.reference, c.sigma, c.n_images)
    ]


def write_check_points(path: Union[str, Path], results: Iterable[BundleResult]) -> None:
    """The check points of one or several results (one group per AP model; the ids carry the
    model when there are several)."""
    results = list(results)
    rows = [row for res in results for row in check_rows(res, tag=len(results) > 1)]
    write_csv_atomic(path, CHECK_COLUMNS, rows)


def write_comparison(path: Union[str, Path], rows: Sequence[dict]) -> None:
    """The model comparison table (rows of :func:`core.photo.bundle.compare_ap_models`)."""

    def cell(r: dict, k: str) -> str:
        v = r.get(_COMPARISON_KEYS.get(k, k), "")
        if isinstance(v, float):
            return number(v)
        return "" if v is None else str(v)

    write_csv_atomic(
        path, COMPARISON_COLUMNS, ([cell(r, k) for k in COMPARISON_COLUMNS] for r in rows)
    )
