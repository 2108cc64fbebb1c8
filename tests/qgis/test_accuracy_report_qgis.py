"""lidarphoto:accuracyreport in real QGIS: processing.run (CSV, memory and GeoPackage layers),
mixed CRSs, qgis_process, and the HTML report of 15 simulated check points as in Pedrosa & dos
Santos (2020).

The statistics themselves are tested in tests/core; here the wiring, with expectations from
the simulation's known bias and sigma or from numpy on the same numbers.
"""

from __future__ import annotations

import json
import math
import random
import re
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import processing
import pytest
from qgis.core import (
    QgsFeature,
    QgsGeometry,
    QgsPoint,
    QgsProcessingException,
    QgsVectorLayer,
    QgsWkbTypes,
)
from qgis_helpers import CRS, QGIS_PROCESS

ALG = "lidarphoto:accuracyreport"
HEADER = "id,e,n,h,e_ref,n_ref,h_ref,group\n"
# Simulation in the spirit of Pedrosa & dos Santos (2020) (section 3): 15 check points, 8 flown
# north-east and 7 south-west, a known bias and sigma per component (m).
BIAS = np.array([0.05, -0.04, 0.08])
SIGMA = np.array([0.20, 0.20, 0.25])


def simulate_checkpoints(seed: int = 2020, n: int = 15):
    """Reference positions spread over 2 x 2 km in UTM 23S, measured = reference + bias + noise."""
    rng = np.random.default_rng(seed)
    ref = np.column_stack(
        [
            500000.0 + rng.uniform(0, 2000, n),
            7450000.0 + rng.uniform(0, 2000, n),
            780.0 + rng.uniform(0, 60, n),
        ]
    )
    meas = ref + BIAS + rng.normal(0.0, SIGMA, (n, 3))
    ids = [f"LCP{k + 1:02d}" for k in range(n)]
    groups = ["NE" if k < 8 else "SW" for k in range(n)]
    return ids, meas, ref, groups


def _write_csv(path: Path, seed: int = 2020) -> Path:
    ids, meas, ref, groups = simulate_checkpoints(seed)
    rows = [
        f"{i},{m[0]:.4f},{m[1]:.4f},{m[2]:.4f},{r[0]:.4f},{r[1]:.4f},{r[2]:.4f},{g}\n"
        for i, m, r, g in zip(ids, meas, ref, groups)
    ]
    path.write_text(HEADER + "".join(rows), encoding="utf-8")
    return path


def _rounded_discrepancies(seed: int = 2020) -> np.ndarray:
    _, meas, ref, _ = simulate_checkpoints(seed)
    return np.round(meas, 4) - np.round(ref, 4)


def _memory_layer(name, crs, ids, xyz, groups=None, z_field=False):
    geom = "Point" if z_field else "PointZ"
    fields = "&field=pid:string&field=grp:string" + ("&field=h:double" if z_field else "")
    layer = QgsVectorLayer(f"{geom}?crs={crs}{fields}", name, "memory")
    feats = []
    for k, (i, p) in enumerate(zip(ids, xyz)):
        f = QgsFeature(layer.fields())
        point = QgsPoint(float(p[0]), float(p[1])) if z_field else QgsPoint(*map(float, p))
        f.setGeometry(QgsGeometry(point))
        attrs = [i, groups[k] if groups else ""]
        f.setAttributes([*attrs, float(p[2])] if z_field else attrs)
        feats.append(f)
    assert layer.dataProvider().addFeatures(feats)
    return layer


class _Html(HTMLParser):
    def __init__(self):
        super().__init__()
        self.tags: dict[str, int] = {}
        self.text: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.tags[tag] = self.tags.get(tag, 0) + 1

    def handle_data(self, data):
        self.text.append(data)


def _run(params: dict) -> dict:
    return processing.run(ALG, {"OUTPUT": "TEMPORARY_OUTPUT", **params})


def test_algorithm_is_registered_with_the_documented_api(provider):
    alg = provider.algorithm("accuracyreport")
    assert alg.id() == ALG and alg.groupId() == "accuracy"
    names = {p.name() for p in alg.parameterDefinitions()}
    assert {"INPUT", "MEASURED", "REFERENCE", "MEASURED_ID", "REFERENCE_ID", "GROUP_FIELD"} <= names
    assert {"OUTPUT", "OUTPUT_HTML", "OUTPUT_JSON", "STANDARDS", "REPROJECT"} <= names
    outputs = {o.name() for o in alg.outputDefinitions()}
    assert {"RMSE_E", "RMSE_N", "RMSE_U", "RMSE_HORIZONTAL", "RMSE_3D"} <= outputs
    assert {"RMSE_H", "RMSE_HORIZ"} <= outputs  # former names, kept for one release


def test_csv_run_layer_and_report(provider, tmp_path):
    table = _write_csv(tmp_path / "cp.csv")
    html, js = tmp_path / "report.html", tmp_path / "report.json"
    r = _run({"INPUT": str(table), "CRS": CRS, "OUTPUT_HTML": str(html), "OUTPUT_JSON": str(js)})
    d = _rounded_discrepancies()
    rmse = np.sqrt(np.mean(d**2, axis=0))
    assert r["RMSE_E"] == pytest.approx(rmse[0], abs=1e-9)
    assert r["RMSE_N"] == pytest.approx(rmse[1], abs=1e-9)
    assert r["RMSE_U"] == r["RMSE_H"] == pytest.approx(rmse[2], abs=1e-9)
    assert (
        r["RMSE_HORIZONTAL"]
        == r["RMSE_HORIZ"]
        == pytest.approx(math.hypot(rmse[0], rmse[1]), abs=1e-9)
    )
    assert r["RMSE_3D"] == pytest.approx(np.linalg.norm(rmse), abs=1e-9)
    layer = r["OUTPUT"]
    assert layer.isValid() and layer.featureCount() == 15
    assert QgsWkbTypes.hasZ(layer.wkbType()) and layer.crs().authid() == CRS
    names = [f.name() for f in layer.fields()]
    assert names == ["id", "group", "dE", "dN", "dU", "dHorizontal", "d3D", "outlier"]
    ids, _, ref, groups = simulate_checkpoints()
    for f in layer.getFeatures():
        k = ids.index(f["id"])
        p = f.geometry().constGet()
        assert (p.x(), p.y(), p.z()) == pytest.approx(tuple(np.round(ref[k], 4)), abs=1e-6)
        assert f["group"] == groups[k]
        assert f["dU"] == pytest.approx(d[k, 2], abs=1e-9)
        assert f["dHorizontal"] == pytest.approx(math.hypot(d[k, 0], d[k, 1]), abs=1e-9)
    # The HTML report opens: tables, verdicts and inline SVG plots.
    parser = _Html()
    parser.feed(html.read_text(encoding="utf-8"))
    text = " ".join(parser.text)
    assert parser.tags.get("table", 0) >= 10 and parser.tags.get("svg") == 7
    assert parser.tags.get("polygon", 0) >= 15  # an arrow head per check point
    for word in ("ASPRS", "NSSDA", "PEC-PCD", "Project threshold", "Group NE", "Group SW"):
        assert word in text
    data = json.loads(js.read_text(encoding="utf-8"))
    assert data["rmse"]["RMSE_3D"] == pytest.approx(r["RMSE_3D"])


def test_two_layers_memory_and_geopackage(provider, tmp_path):
    # The reference comes from a GeoPackage (the check-point layer of a CSV run: PointZ at
    # the reference positions, field "id"); the measured points from a memory layer in a
    # shuffled order with a height field instead of geometry Z.
    table = _write_csv(tmp_path / "cp.csv")
    gpkg = tmp_path / "reference.gpkg"
    base = processing.run(ALG, {"INPUT": str(table), "CRS": CRS, "OUTPUT": str(gpkg)})
    ids, meas, _, groups = simulate_checkpoints()
    order = list(range(15))
    random.Random(1).shuffle(order)
    measured = _memory_layer(
        "measured",
        CRS,
        [ids[k] for k in order],
        np.round(meas[order], 4),
        [groups[k] for k in order],
        z_field=True,
    )
    r = _run(
        {
            "MEASURED": measured,
            "MEASURED_ID": "pid",
            "MEASURED_Z_FIELD": "h",
            "REFERENCE": str(gpkg),
            "REFERENCE_ID": "id",
            "GROUP_FIELD": "grp",
        }
    )
    for key in ("RMSE_E", "RMSE_N", "RMSE_U", "RMSE_HORIZONTAL", "RMSE_3D"):
        assert r[key] == pytest.approx(base[key], abs=1e-6), key
    assert {f["group"] for f in r["OUTPUT"].getFeatures()} == {"NE", "SW"}


def test_mixed_crs_refused_unless_reprojected(provider):
    from pyproj import Transformer

    ids, meas, ref, _ = simulate_checkpoints()
    to_geo = Transformer.from_crs(CRS, "EPSG:4674", always_xy=True)  # SIRGAS 2000 geographic
    lon, lat = to_geo.transform(ref[:, 0], ref[:, 1])
    measured = _memory_layer("m", CRS, ids, meas)
    reference = _memory_layer("r", "EPSG:4674", ids, np.column_stack([lon, lat, ref[:, 2]]))
    params = {"MEASURED": measured, "MEASURED_ID": "pid", "REFERENCE": reference}
    params["REFERENCE_ID"] = "pid"
    with pytest.raises(QgsProcessingException, match=r"CRS|reproject"):
        _run(params)
    r = _run({**params, "REPROJECT": True})
    d = meas - ref
    rmse = np.sqrt(np.mean(d**2, axis=0))
    # Reprojected by QGIS and back: millimetre agreement with the UTM numbers.
    assert r["RMSE_E"] == pytest.approx(rmse[0], abs=1e-3)
    assert r["RMSE_N"] == pytest.approx(rmse[1], abs=1e-3)
    assert r["RMSE_U"] == pytest.approx(rmse[2], abs=1e-9)


def test_bad_layers_give_clear_errors(provider):
    ids, meas, ref, _ = simulate_checkpoints()
    measured = _memory_layer("m", CRS, ids, meas)
    reference = _memory_layer("r", CRS, ids[:-2], ref[:-2])
    params = {"MEASURED": measured, "MEASURED_ID": "pid", "REFERENCE": reference}
    with pytest.raises(QgsProcessingException, match=r"LCP14.*LCP15"):
        _run({**params, "REFERENCE_ID": "pid"})
    dup = _memory_layer("r", CRS, [*ids[:-1], ids[0]], ref)
    with pytest.raises(QgsProcessingException, match=r"duplicate id.*LCP01"):
        _run({**params, "REFERENCE": dup, "REFERENCE_ID": "pid"})
    with pytest.raises(QgsProcessingException, match="either"):
        _run({})


def _qgis_process(args: list[str], env: dict[str, str]) -> subprocess.CompletedProcess:
    return subprocess.run(
        [QGIS_PROCESS, *args], env=env, capture_output=True, text=True, timeout=300
    )


def test_qgis_process_runs_the_report(qp_env, tmp_path):
    table = _write_csv(tmp_path / "cp.csv")
    html, gpkg = tmp_path / "r.html", tmp_path / "cp.gpkg"
    r = _qgis_process(
        [
            "--json",
            "run",
            ALG,
            "--",
            f"INPUT={table}",
            f"CRS={CRS}",
            "PEC_SCALE=2000",
            "PEC_CLASS=1",
            f"OUTPUT={gpkg}",
            f"OUTPUT_HTML={html}",
        ],
        qp_env,
    )
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    results = json.loads(r.stdout)["results"]
    d = _rounded_discrepancies()
    assert results["RMSE_U"] == pytest.approx(np.sqrt(np.mean(d[:, 2] ** 2)), abs=1e-9)
    assert "<svg" in html.read_text(encoding="utf-8")
    layer = QgsVectorLayer(str(gpkg), "cp", "ogr")
    assert layer.isValid() and layer.featureCount() == 15


def test_report_of_simulated_checkpoints(provider, tmp_path):
    """One report from the simulated check points; its figures are printed for the record."""
    table = _write_csv(tmp_path / "cp.csv")
    js = tmp_path / "sim.json"
    r = _run(
        {
            "INPUT": str(table),
            "CRS": CRS,
            "OUTPUT_HTML": str(tmp_path / "sim.html"),
            "OUTPUT_JSON": str(js),
            "DECLARED_SIGMA_H": 0.2,
            "DECLARED_SIGMA_V": 0.25,
            "PEC_SCALE": 2000,
        }
    )
    data = json.loads(js.read_text(encoding="utf-8"))
    comps = data["overall"]["components"]
    # Known simulation: |mean - bias| within 4 standard errors, RMSE within its
    # non-central chi-square 99.9 % band (n RMSE^2 / sigma^2 ~ ncx2(n, n bias^2 / sigma^2)).
    from scipy import stats

    for k, c in enumerate("ENU"):
        assert abs(comps[c]["mean"] - BIAS[k]) < 4 * SIGMA[k] / math.sqrt(15)
        dist = stats.ncx2(15, 15 * BIAS[k] ** 2 / SIGMA[k] ** 2)
        lo, hi = (SIGMA[k] * math.sqrt(dist.ppf(q) / 15) for q in (0.0005, 0.9995))
        assert lo < comps[c]["rmse"] < hi
    project = next(s for s in data["standards"] if s["key"] == "project")
    assert project["figures"]["v_threshold"] == pytest.approx(0.4787, abs=1e-4)
    lines = [f"simulated check points: {data['n_points']} (NE 8, SW 7)"]
    lines += [f"{k} = {v:.3f} m" for k, v in data["rmse"].items()]
    for c in "ENU":
        x = comps[c]
        lines.append(
            f"d{c}: mean {x['mean']:+.3f} std {x['std']:.3f} min {x['minimum']:+.3f} "
            f"max {x['maximum']:+.3f}; S-W W {x['normality']['statistic']:.3f} "
            f"p {x['normality']['p_value']:.3f}; t {x['bias']['t']:+.3f} "
            f"(crit {x['bias']['critical']:.3f}, p {x['bias']['p_value']:.3f}); "
            f"chi2 {x['precision']['chi2']:.2f} (crit {x['precision']['critical']:.2f})"
        )
    for s in data["standards"]:
        for v in s["verdicts"]:
            lines.append(f"{s['key']}: {v['name']}: {v['status']} - {v['reason']}")
    for g, s in data["group_thresholds"].items():
        for v in s["verdicts"]:
            lines.append(f"project[{g}]: {v['name']}: {v['status']} - {v['reason']}")
    print("\n".join(lines))
    assert re.search(r"RMSE_HORIZONTAL = \d", "\n".join(lines))
    assert r["RMSE_HORIZONTAL"] == pytest.approx(data["rmse"]["RMSE_HORIZONTAL"])


def test_a_first_run_form_shows_what_it_needs(provider):
    """The inputs, the standards and the outputs; the thresholds, sigmas, outlier rules and
    field names under Advanced (28 basic fields before)."""
    alg = provider.algorithm("accuracyreport")
    basic = [d.name() for d in alg.parameterDefinitions() if not d.flags() & d.FlagAdvanced]
    assert basic == [
        "INPUT",
        "MEASURED",
        "REFERENCE",
        "GROUP_FIELD",
        "CRS",
        "STANDARDS",
        "OUTPUT",
        "OUTPUT_HTML",
        "OUTPUT_JSON",
    ]
