"""core.quality.accuracy: statistics against independent computations, tests, outliers,
inputs, job."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from lidarphoto.core.errors import Cancelled, CrsError, InputError
from lidarphoto.core.io.checkpoints import read_checkpoint_table, read_point_table
from lidarphoto.core.jobs import accuracy_report
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.quality.accuracy import (
    AccuracySettings,
    CheckPoints,
    assess_accuracy,
    join_points,
    point_set,
)
from lidarphoto.core.quality.accuracy_json import report_to_dict
from lidarphoto.core.quality.accuracy_statistics import (
    bias_test,
    component_statistics,
    normality_test,
    precision_test,
    screen_outliers,
)
from scipy import stats

HEADER = "id,e,n,h,e_ref,n_ref,h_ref,group\n"


def _simulate(n=15, bias=(0.05, -0.05, 0.10), sigma=(0.2, 0.2, 0.3), seed=0):
    rng = np.random.default_rng(seed)
    ref = np.column_stack(
        [
            500000 + rng.uniform(0, 2000, n),
            7450000 + rng.uniform(0, 2000, n),
            600 + rng.uniform(0, 50, n),
        ]
    )
    meas = ref + np.asarray(bias) + rng.normal(0.0, sigma, (n, 3))
    ids = tuple(f"P{k + 1}" for k in range(n))
    groups = tuple("NE" if k < n // 2 + 1 else "SW" for k in range(n))
    return CheckPoints(ids, meas, ref, groups, "EPSG:31983", "simulated")


def _write_table(path: Path, cp: CheckPoints) -> Path:
    rows = [
        f"{i},{m[0]:.4f},{m[1]:.4f},{m[2]:.4f},{r[0]:.4f},{r[1]:.4f},{r[2]:.4f},{g}\n"
        for i, m, r, g in zip(cp.ids, cp.measured, cp.reference, cp.groups)
    ]
    path.write_text(HEADER + "".join(rows), encoding="utf-8")
    return path


# ----------------------------------------------------------------------------- statistics


def test_statistics_by_hand_on_a_known_answer():
    # Two points: dE = +-0.3, dN = -+0.4, dH = 0 and 1 -> every figure by hand.
    ref = np.zeros((2, 3))
    meas = np.array([[0.3, -0.4, 0.0], [-0.3, 0.4, 1.0]])
    r = assess_accuracy(CheckPoints(("a", "b"), meas, ref, ("", "")))
    c = r.overall.components
    assert c["E"].mean == pytest.approx(0.0, abs=1e-15)
    assert c["E"].std == pytest.approx(math.sqrt(2 * 0.09 / 1))
    assert c["E"].rmse == pytest.approx(0.3)
    assert c["N"].rmse == pytest.approx(0.4)
    assert c["U"].rmse == pytest.approx(math.sqrt(0.5))
    assert c["U"].mean == pytest.approx(0.5)
    assert (c["U"].minimum, c["U"].maximum) == (0.0, 1.0)
    assert c["HORIZONTAL"].rmse == pytest.approx(0.5)  # 3-4-5
    assert c["HORIZONTAL"].minimum == pytest.approx(0.5)
    assert c["3D"].rmse == pytest.approx(math.sqrt(0.25 + 0.5))
    assert r.rmse["RMSE_HORIZONTAL"] == pytest.approx(0.5)


def test_statistics_agree_with_numpy_on_simulated_points():
    cp = _simulate(n=40, seed=3)
    d = cp.measured - cp.reference
    r = assess_accuracy(cp)
    for k, name in enumerate("ENU"):
        c = r.overall.components[name]
        assert c.n == 40
        assert c.mean == pytest.approx(np.mean(d[:, k]), abs=1e-12)
        assert c.std == pytest.approx(np.std(d[:, k], ddof=1), abs=1e-12)
        assert c.rmse == pytest.approx(np.sqrt(np.mean(d[:, k] ** 2)), abs=1e-12)
        assert c.minimum == np.min(d[:, k]) and c.maximum == np.max(d[:, k])
    h = np.sqrt(d[:, 0] ** 2 + d[:, 1] ** 2)
    horizontal = math.hypot(r.rmse["RMSE_E"], r.rmse["RMSE_N"])
    assert r.rmse["RMSE_HORIZONTAL"] == pytest.approx(horizontal)
    assert r.overall.components["HORIZONTAL"].maximum == pytest.approx(h.max())
    assert r.rmse["RMSE_3D"] == pytest.approx(np.sqrt(np.mean(np.sum(d**2, axis=1))))


def test_rmse_of_simulation_within_the_noncentral_chi_square_bounds():
    # n RMSE^2 / sigma^2 follows a non-central chi-square(n, n bias^2 / sigma^2): the sample
    # RMSE must fall in its 99.9 % interval for each component.
    bias, sigma, n = np.array([0.05, -0.05, 0.10]), np.array([0.2, 0.2, 0.3]), 15
    r = assess_accuracy(_simulate(n=n, bias=bias, sigma=sigma, seed=11))
    for k, name in enumerate("ENU"):
        dist = stats.ncx2(n, n * bias[k] ** 2 / sigma[k] ** 2)
        lo, hi = (sigma[k] * math.sqrt(dist.ppf(q) / n) for q in (0.0005, 0.9995))
        assert lo < r.overall.components[name].rmse < hi, name


def test_group_statistics_are_those_of_the_subsets():
    cp = _simulate(n=15)
    r = assess_accuracy(cp)
    assert list(r.groups) == ["NE", "SW"]
    d = cp.discrepancies
    for g in ("NE", "SW"):
        mask = np.array(cp.groups) == g
        assert r.groups[g].n == mask.sum()
        assert r.groups[g].components["U"].rmse == pytest.approx(np.sqrt(np.mean(d[mask, 2] ** 2)))
    assert set(r.group_thresholds) == {"NE", "SW"}


# ----------------------------------------------------------------------------- tests


def test_shapiro_wilk_reproduces_the_published_example():
    # Shapiro & Wilk (1965), Biometrika 52, 591-611, worked example: weights (lb) of 11 men,
    # W = 0.79, below the 1 % point; independent check with the 1965 table coefficients
    # a_i for n = 11 (0.5601, 0.3315, 0.2260, 0.1429, 0.0695).
    x = np.array([148, 154, 158, 160, 161, 162, 166, 170, 182, 195, 236], dtype=float)
    a = np.array([0.5601, 0.3315, 0.2260, 0.1429, 0.0695])
    xs = np.sort(x)
    b = np.sum(a * (xs[::-1][:5] - xs[:5]))
    w_table = b**2 / np.sum((x - x.mean()) ** 2)
    t = normality_test(x, 0.05)
    assert round(w_table, 2) == 0.79
    assert t.statistic == pytest.approx(w_table, abs=2e-3)
    assert t.normal is False and t.p_value < 0.01


def test_shapiro_wilk_accepts_normal_samples_at_the_nominal_rate():
    rng = np.random.default_rng(5)
    accepted = [normality_test(rng.normal(size=15)).normal for _ in range(400)]
    # Binomial(400, 0.95): mean 380, sd 4.4 -> 5 sd band.
    assert 358 <= sum(accepted) <= 400


def test_too_few_points_are_reported_not_tested():
    assert normality_test(np.array([0.1, 0.2])).normal is None
    assert bias_test(np.array([0.1])).biased is None
    c = component_statistics(np.array([0.1]), "E")
    assert math.isnan(c.std) and c.normality.normal is None


def test_student_t_against_scipy_and_the_paper_critical_value():
    rng = np.random.default_rng(1)
    x = rng.normal(0.05, 0.2, 15)
    b = bias_test(x, 0.05)
    ref = stats.ttest_1samp(x, 0.0)
    t_hand = x.mean() / (x.std(ddof=1) / math.sqrt(15))
    assert b.t == pytest.approx(t_hand) and b.t == pytest.approx(ref.statistic)
    assert b.p_value == pytest.approx(ref.pvalue)
    # Pedrosa & dos Santos (2020), Table 4: 14 dof
    assert b.critical == pytest.approx(2.145, abs=5e-4)
    assert b.biased == (abs(t_hand) > b.critical)


def test_student_t_detects_a_bias_of_three_standard_errors():
    # bias 0.3 with sigma 0.2 and n 15: t is about 5.8, far beyond 2.145.
    b = bias_test(np.random.default_rng(2).normal(0.3, 0.2, 15))
    assert b.biased is True


def test_chi_square_by_hand_and_table():
    x = np.array(
        [0.12, -0.31, 0.25, 0.05, -0.18, 0.4, -0.02, 0.11, -0.27, 0.2, 0.0, -0.09, 0.3, 0.14, -0.22]
    )
    p = precision_test(x, 0.15, 0.05)
    chi2_hand = 14 * x.var(ddof=1) / 0.15**2
    assert p.chi2 == pytest.approx(chi2_hand)
    assert p.critical == pytest.approx(23.685, abs=1e-3)  # chi-square table, 14 dof, 0.95
    assert p.p_value == pytest.approx(1 - stats.chi2.cdf(chi2_hand, 14))
    assert p.accepted == (chi2_hand <= 23.685)
    assert precision_test(x, 1.0).accepted is True
    assert precision_test(x, 0.05).accepted is False
    with pytest.raises(InputError):
        precision_test(x, 0.0)


def test_declared_precision_enters_the_component_tests():
    r = assess_accuracy(
        _simulate(n=15, sigma=(0.2, 0.2, 0.3)),
        AccuracySettings(declared_sigma_h=0.05, declared_sigma_v=1.0),
    )
    c = r.overall.components
    assert c["E"].precision.accepted is False and c["U"].precision.accepted is True
    assert c["HORIZONTAL"].precision is None


# ----------------------------------------------------------------------------- outliers


def test_robust_outlier_rule_by_hand():
    d = np.zeros((15, 3))
    d[:, 0] = np.linspace(-0.2, 0.2, 15)
    d[:, 1] = np.linspace(0.1, -0.1, 15)
    d[:, 2] = np.linspace(-0.3, 0.3, 15)
    d[6, 2] = 2.0  # gross error in height
    scr = screen_outliers(d, "robust")
    med = np.median(d[:, 2])
    mad = np.median(np.abs(d[:, 2] - med))
    assert scr.scores[6, 2] == pytest.approx(0.6745 * (2.0 - med) / mad)
    assert scr.any.nonzero()[0].tolist() == [6]
    assert scr.flags[6].tolist() == [False, False, True]


def test_three_sigma_rule_by_hand_and_none():
    d = np.zeros((15, 3))
    d[:, 0] = np.linspace(-0.2, 0.2, 15)
    d[3, 0] = 3.0
    scr = screen_outliers(d, "three_sigma")
    z = (d[:, 0] - d[:, 0].mean()) / d[:, 0].std(ddof=1)
    np.testing.assert_allclose(scr.scores[:, 0], z)
    assert scr.any.nonzero()[0].tolist() == [3]
    assert not screen_outliers(d, "none").any.any()
    with pytest.raises(InputError):
        screen_outliers(d, "grubbs")


def test_flagged_points_are_kept_unless_excluded():
    cp = _simulate(n=15)
    meas = cp.measured.copy()
    meas[4, 0] += 3.0
    cp = CheckPoints(cp.ids, meas, cp.reference, cp.groups, cp.crs, "x")
    kept = assess_accuracy(cp)
    assert kept.outliers.any[4] and kept.used.all() and kept.overall.n == 15
    dropped = assess_accuracy(cp, AccuracySettings(exclude_outliers=True))
    assert not dropped.used[4] and dropped.overall.n == 15 - dropped.outliers.any.sum()
    assert dropped.rmse["RMSE_E"] < kept.rmse["RMSE_E"]
    assert "P5" in report_to_dict(dropped)["outliers"]["flagged_ids"]


# ----------------------------------------------------------------------------- inputs


def test_read_checkpoint_table(tmp_path):
    cp = _simulate(n=6)
    back = read_checkpoint_table(_write_table(tmp_path / "cp.csv", cp))
    assert back.ids == cp.ids and back.groups == cp.groups
    np.testing.assert_allclose(back.measured, cp.measured, atol=1e-4)
    np.testing.assert_allclose(back.reference, cp.reference, atol=1e-4)


def test_table_errors_name_file_row_and_column(tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text(HEADER + "a,1,2,3,1,2,3,G\nb,1,x,3,1,2,3,G\n", encoding="utf-8")
    with pytest.raises(InputError) as err:
        read_checkpoint_table(p)
    assert err.value.row == 3 and err.value.column == "n" and str(p) in str(err.value)
    p.write_text(HEADER + "a,1,2,3,1,2,3,G\na,1,2,3,1,2,3,G\n", encoding="utf-8")
    with pytest.raises(InputError, match="'a' \\(row 2 and row 3\\)"):
        read_checkpoint_table(p)
    p.write_text(HEADER + "a,1,2,nan,1,2,3,G\n", encoding="utf-8")
    with pytest.raises(InputError) as err:
        read_checkpoint_table(p)
    assert err.value.column == "h" and err.value.row == 2
    p.write_text("id,e,n,h\na,1,2,3\n", encoding="utf-8")
    with pytest.raises(InputError, match="e_ref"):
        read_checkpoint_table(p)


def test_two_tables_joined_by_id_in_any_order(tmp_path):
    m = tmp_path / "m.csv"
    r = tmp_path / "r.csv"
    m.write_text("id,e,n,h,group\nA,10.1,20,5,g1\nB,30,40.2,6,g2\n", encoding="utf-8")
    r.write_text("name,x,y,z\nB,30,40,6.5\nA,10,20,5\n", encoding="utf-8")
    cp = join_points(read_point_table(m), read_point_table(r))
    assert cp.ids == ("A", "B") and cp.groups == ("g1", "g2")
    np.testing.assert_allclose(cp.discrepancies, [[0.1, 0, 0], [0, 0.2, -0.5]], atol=1e-12)


def test_unmatched_ids_are_all_named():
    m = point_set(["A", "B", "C"], np.zeros((3, 3)), source="meas")
    r = point_set(["A", "D"], np.zeros((2, 3)), source="ref")
    with pytest.raises(InputError) as err:
        join_points(m, r)
    text = str(err.value)
    assert "'B'" in text and "'C'" in text and "'D'" in text
    assert "meas" in text and "ref" in text


def test_duplicate_ids_and_nans_in_layers_are_named():
    with pytest.raises(InputError, match="'A' \\(feature 4 and feature 9\\)"):
        point_set(["A", "B", "A"], np.zeros((3, 3)), locations=[4, 5, 9], source="lyr")
    xyz = np.zeros((2, 3))
    xyz[1, 2] = np.nan
    with pytest.raises(InputError) as err:
        point_set(["A", "B"], xyz, locations=[7, 8], source="lyr")
    assert "feature 8" in str(err.value) and "'B'" in str(err.value)
    assert err.value.column == "H"
    with pytest.raises(InputError, match="empty id"):
        point_set(["A", None], np.zeros((2, 3)))


def test_mixed_crs_is_refused_and_equal_crs_in_other_spelling_accepted():
    from pyproj import CRS

    a = point_set(["A"], np.zeros((1, 3)), crs="EPSG:31983")
    b = point_set(["A"], np.zeros((1, 3)), crs="EPSG:31982")
    with pytest.raises(CrsError, match="31982"):
        join_points(a, b)
    c = point_set(["A"], np.zeros((1, 3)), crs=CRS.from_epsg(31983).to_wkt())
    assert len(join_points(a, c)) == 1


# ----------------------------------------------------------------------------- job


def test_run_writes_html_and_json_with_every_figure(tmp_path):
    cp = _simulate(n=15)
    table = _write_table(tmp_path / "cp.csv", cp)
    html, js = tmp_path / "out" / "r.html", tmp_path / "out" / "r.json"
    r = run_job(
        accuracy_report,
        {"INPUT": str(table), "CRS": "EPSG:31983", "OUTPUT_HTML": html, "OUTPUT_JSON": js},
    ).data
    data = json.loads(js.read_text(encoding="utf-8"))
    for key, value in r.rmse.items():
        assert data["rmse"][key] == pytest.approx(value)
    assert data["n_points"] == 15 and len(data["points"]) == 15
    assert {s["key"] for s in data["standards"]} == {"asprs", "nssda", "pec", "project"}
    assert data["overall"]["components"]["E"]["normality"]["statistic"] == pytest.approx(
        r.overall.components["E"].normality.statistic
    )
    assert html.read_text(encoding="utf-8").startswith("<!DOCTYPE html>")
    assert not list((tmp_path / "out").glob(".*"))


def test_bad_input_leaves_no_output(tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text(HEADER + "a,1,2,3,1,2,3,G\nb,1,x,3,1,2,3,G\n", encoding="utf-8")
    with pytest.raises(InputError):
        run_job(accuracy_report, {"INPUT": str(p), "OUTPUT_HTML": tmp_path / "r.html"})
    assert not (tmp_path / "r.html").exists()
    with pytest.raises(InputError, match="either"):
        run_job(accuracy_report, {"INPUT": str(p), "MEASURED": str(p), "REFERENCE": str(p)})


def test_cancel_and_progress():
    seen = []
    with pytest.raises(Cancelled):
        assess_accuracy(_simulate(), should_stop=lambda: True)
    assess_accuracy(_simulate(), progress=seen.append)
    assert seen == sorted(seen) and seen[-1] <= 1.0


def test_settings_are_validated():
    with pytest.raises(InputError):
        assess_accuracy(_simulate(), AccuracySettings(alpha=0.7))
    with pytest.raises(InputError):
        assess_accuracy(_simulate(), AccuracySettings(standards=("iso",)))
    with pytest.raises(InputError):
        assess_accuracy(_simulate(), AccuracySettings(survey_sigma_h=-1.0))


def test_command_line_with_one_table_and_with_two(tmp_path, capsys):
    from lidarphoto.core.cli import main

    cp = _simulate(n=15)
    table = _write_table(tmp_path / "cp.csv", cp)
    html = tmp_path / "r.html"
    assert main(["accuracyreport", "--input", str(table), "--output-html", str(html)]) == 0
    out = capsys.readouterr().out
    rmse = np.sqrt(np.mean(np.round(cp.discrepancies, 4) ** 2, axis=0))
    assert f"RMSE_U {rmse[2]:.4f}" in out and html.exists()
    m, r = tmp_path / "m.csv", tmp_path / "r.csv"
    m.write_text("pid,e,n,h\nA,10.1,20,5\nB,30,40.2,6\nC,1,1,1\n", encoding="utf-8")
    r.write_text("id,e,n,elev\nB,30,40,6.5\nA,10,20,5\nC,1,1,1\n", encoding="utf-8")
    args = ["accuracyreport", "--measured", str(m), "--reference", str(r)]
    args += ["--measured-id", "pid", "--reference-z-field", "elev", "--standards", "project,1"]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert f"RMSE_E {math.sqrt(0.01 / 3):.4f}" in out and "nssda:" in out and "asprs:" not in out
    assert main(["accuracyreport", "--input", str(table), "--pec-class", "F"]) == 2
    assert "PEC_CLASS" in capsys.readouterr().err
