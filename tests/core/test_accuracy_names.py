"""One naming scheme for the accuracy figures (docs/formats.md, "Accuracy figures"): every
RMSE_* / ACCURACY_* key the JSON report holds is documented, a name means the same number
wherever it appears, RMSE_H survives only as the deprecated alias of RMSE_U, and the bundle
comparison table uses the same names."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from lidarphoto.core.quality.accuracy import AccuracySettings, CheckPoints, assess_accuracy
from lidarphoto.core.quality.accuracy_json import report_to_dict

ROOT = Path(__file__).resolve().parents[2]
SIGMA = (0.03, 0.04, 0.05)  # m, per axis


def small_report(survey=(0.0, 0.0)):
    """40 simulated check points (ASPRS needs 30), all standards."""
    rng = np.random.default_rng(22)
    n = 40
    ref = np.column_stack([500000 + rng.uniform(0, 2000, n), 7450000 + rng.uniform(0, 2000, n),
                           600 + rng.uniform(0, 50, n)])  # fmt: skip
    meas = ref + rng.normal(0.0, SIGMA, (n, 3))
    cp = CheckPoints(tuple(f"P{k}" for k in range(n)), meas, ref, ("",) * n, "EPSG:31983")
    settings = AccuracySettings(survey_sigma_h=survey[0], survey_sigma_v=survey[1],
                                outlier_rule="none")  # fmt: skip
    return assess_accuracy(cp, settings)


def _documented() -> set[str]:
    text = (ROOT / "docs" / "formats.md").read_text(encoding="utf-8")
    section = text.split("## Accuracy figures")[1].split("\n## ")[0]
    table = [line for line in section.splitlines() if line.startswith("| `")]
    names = set()
    for line in table:
        names |= set(re.findall(r"`([A-Za-z0-9_]+)`", line.split("|")[1]))
    # the suffixes of the NSSDA radius
    names |= {f"ACCURACY_HORIZONTAL_95_{s}" for s in ("CASE1", "CASE2", "EXACT")}
    return names


def _figure_keys(obj, path=""):
    """(path, key, value) of every key that looks like an accuracy figure, anywhere."""
    if isinstance(obj, dict):
        for k, v in obj.items():
            if re.fullmatch(r"(RMSE|RMS|ACCURACY|Accuracy)_\w+|d[A-Z]\w*", k):
                yield f"{path}.{k}", k, v
            yield from _figure_keys(v, f"{path}.{k}")
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            yield from _figure_keys(v, f"{path}[{i}]")


def test_every_figure_in_the_json_is_documented_and_means_one_thing():
    report = small_report()
    data = json.loads(json.dumps(report_to_dict(report)))
    documented = _documented()
    deprecated = {"RMSE_H", "RMSE_HORIZ"}
    values: dict[str, list[tuple[str, float]]] = {}
    for path, key, value in _figure_keys(data):
        if key in deprecated:
            assert path in (".rmse.RMSE_H", ".rmse.RMSE_HORIZ"), path  # the alias only
            continue
        assert key in documented, path
        if not path.startswith(".points") and isinstance(value, float):
            values.setdefault(key, []).append((path, value))
    # without survey error and outlier exclusion, a name has one value everywhere
    for key, seen in values.items():
        if key.startswith("RMSE_") and "contrast" not in seen[0][0]:
            first = seen[0][1]
            for path, v in seen:
                if "contrast" not in path:
                    assert v == pytest.approx(first, rel=1e-12), (key, path)
    assert {"RMSE_E", "RMSE_N", "RMSE_U", "RMSE_HORIZONTAL", "RMSE_3D"} <= set(values)


def test_rmse_h_is_only_the_deprecated_alias_of_the_height():
    report = small_report(survey=(0.02, 0.03))
    data = report_to_dict(report)
    rmse = data["rmse"]
    d = report.points.discrepancies
    assert rmse["RMSE_U"] == pytest.approx(np.sqrt(np.mean(d[:, 2] ** 2)))
    assert rmse["RMSE_H"] == rmse["RMSE_U"]  # the alias: the height, as before
    assert rmse["RMSE_HORIZ"] == rmse["RMSE_HORIZONTAL"]
    assert set(data["deprecated_keys"]) == {"rmse.RMSE_H", "rmse.RMSE_HORIZ"}
    asprs = next(s for s in data["standards"] if s["key"] == "asprs")["figures"]
    assert "RMSE_H" not in asprs  # ASPRS's horizontal RMSE has its own name now
    h_total = np.hypot(rmse["RMSE_HORIZONTAL"], np.sqrt(2) * 0.02)
    assert asprs["RMSE_HORIZONTAL_TOTAL"] == pytest.approx(h_total)
    assert asprs["RMSE_U_TOTAL"] == pytest.approx(np.hypot(rmse["RMSE_U"], 0.03))
    assert asprs["RMSE_HORIZONTAL"] == pytest.approx(rmse["RMSE_HORIZONTAL"])
    point = data["points"][0]
    assert {"dE", "dN", "dU", "dHorizontal", "d3D"} <= set(point) and "dH" not in point


def test_the_bundle_comparison_uses_the_same_names(tmp_path):
    from lidarphoto.core.io.bundle import COMPARISON_COLUMNS, write_comparison

    row = {"rank": 1, "model": "bauer", "n_check": 3, "mean_planimetric": 0.01,
           "std_planimetric": 0.02, "rms_planimetric": 0.03, "rms_h": 0.04, "rms_3d": 0.05,
           "sigma0": 1.0, "n_ap": 3, "n_ap_kept": 3, "n_significant": 1, "rejected": 0}  # fmt: skip
    write_comparison(tmp_path / "c.csv", [row])
    header, values = (tmp_path / "c.csv").read_text(encoding="utf-8").splitlines()[:2]
    got = dict(zip(header.split(","), values.split(",")))
    assert tuple(header.split(",")) == COMPARISON_COLUMNS
    assert (got["rmse_horizontal"], got["rmse_u"], got["rmse_3d"]) == ("0.03", "0.04", "0.05")
