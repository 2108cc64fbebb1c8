"""The accuracy report as the JSON document of docs/formats.md (:mod:`.accuracy`): plain
numbers and lists, the keys of earlier versions kept for one release.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .accuracy import AccuracyReport

__all__ = [
    "DEPRECATED_KEYS",
    "JSON_TOP_KEYS",
    "report_to_dict",
    "with_deprecated_keys",
]

#: Keys of earlier versions still written to the JSON for one release (key -> its new name).
DEPRECATED_KEYS = {
    "rmse.RMSE_H": "rmse.RMSE_U (the height RMSE; RMSE_H was also ASPRS's horizontal RMSE)",
    "rmse.RMSE_HORIZ": "rmse.RMSE_HORIZONTAL",
}


# ----------------------------------------------------------------------------- JSON


def _num(x: Any) -> Any:
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(float(x)) else None
    return x


def _obj(o: Any) -> Any:
    if o is None:
        return None
    if hasattr(o, "__dataclass_fields__"):
        return {k: _obj(getattr(o, k)) for k in o.__dataclass_fields__}
    if isinstance(o, dict):
        return {str(k): _obj(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [_obj(v) for v in o]
    if isinstance(o, np.ndarray):
        return _obj(o.tolist())
    return _num(o)


#: Top-level keys of the JSON report, in order (docs/formats.md, "Accuracy report JSON").
JSON_TOP_KEYS = (
    "title",
    "created",
    "source",
    "crs",
    "sign_convention",
    "n_points",
    "n_used",
    "settings",
    "names",
    "rmse",
    "outliers",
    "overall",
    "contrast",
    "rmse_contrast",
    "deprecated_keys",
    "groups",
    "standards",
    "group_thresholds",
    "points",
)


def with_deprecated_keys(rmse: dict[str, float]) -> dict[str, float]:
    """The RMSEs with the keys of earlier versions added (one release of overlap).

    >>> sorted(with_deprecated_keys({"RMSE_U": 1.0, "RMSE_HORIZONTAL": 2.0}).items())
    [('RMSE_H', 1.0), ('RMSE_HORIZ', 2.0), ('RMSE_HORIZONTAL', 2.0), ('RMSE_U', 1.0)]
    """
    out = dict(rmse)
    if "RMSE_U" in rmse:
        out["RMSE_H"] = rmse["RMSE_U"]
    if "RMSE_HORIZONTAL" in rmse:
        out["RMSE_HORIZ"] = rmse["RMSE_HORIZONTAL"]
    return out


def report_to_dict(report: AccuracyReport) -> dict[str, Any]:
    """Every figure of the report as JSON-ready data (NaN and infinities become null)."""
    d = report.discrepancies
    pts = report.points
    return {
        "title": report.settings.title,
        "created": report.created,
        "source": pts.source,
        "crs": pts.crs,
        "sign_convention": "d = measured - reference (metres)",
        "n_points": len(pts),
        "n_used": int(report.used.sum()),
        "settings": _obj(report.settings),
        "names": "docs/formats.md, Accuracy figures",
        "rmse": _obj(with_deprecated_keys(report.rmse)),
        "outliers": {
            "rule": report.outliers.rule,
            "description": report.outliers.description,
            "threshold": _num(report.outliers.threshold),
            "excluded": bool(report.settings.exclude_outliers),
            "flagged_ids": [pts.ids[k] for k in np.flatnonzero(report.outliers.any)],
        },
        "overall": _obj(report.overall),
        "contrast": _obj(report.contrast) if report.contrast is not None else None,
        "rmse_contrast": _obj(report.rmse_contrast),
        "deprecated_keys": {
            old: f"deprecated, removed in the next release: use {new}"
            for old, new in DEPRECATED_KEYS.items()
        },
        "groups": _obj(report.groups),
        "standards": _obj(report.standards),
        "group_thresholds": _obj(report.group_thresholds),
        "points": [
            {
                "id": pts.ids[k],
                "group": pts.groups[k],
                "measured": _obj(pts.measured[k]),
                "reference": _obj(pts.reference[k]),
                "dE": _num(d[k, 0]),
                "dN": _num(d[k, 1]),
                "dU": _num(d[k, 2]),
                "dHorizontal": _num(report.horizontal[k]),
                "d3D": _num(report.d3[k]),
                "outlier": bool(report.outliers.any[k]),
                "outlier_scores": _obj(report.outliers.scores[k]),
                "used": bool(report.used[k]),
            }
            for k in range(len(pts))
        ],
    }
