"""core.quality.standards: factors from their definitions, class limits at the boundaries,
counts."""

from __future__ import annotations

import math

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.quality.standards_asprs import asprs_2023
from lidarphoto.core.quality.standards_nssda import (
    NSSDA_HORIZONTAL_FACTOR,
    NSSDA_RADIAL_FACTOR,
    NSSDA_VERTICAL_FACTOR,
    bivariate_radius,
    nssda,
)
from lidarphoto.core.quality.standards_pec import pec_pcd, pec_pcd_limits
from lidarphoto.core.quality.standards_project import project_threshold, stereo_height_precision
from scipy import stats

EPS = 1e-6  # metres: "just inside" / "just outside" a limit


def _status(result, name):
    return next(v for v in result.verdicts if v.name == name).status


def _horizontal(r: np.ndarray) -> np.ndarray:
    """Discrepancies with horizontal length r (3-4-5 direction) and dH = 0."""
    r = np.asarray(r, dtype=float)
    return np.column_stack([0.6 * r, 0.8 * r, np.zeros_like(r)])


# ----------------------------------------------------- Pedrosa & dos Santos (2020)


def test_eq18_gives_the_paper_threshold():
    # Paper 000, Eq. 18 and Table 2: H 1600 m, B 452 m, f 100.4 mm, sigma_pix 6 um -> 0.48 m.
    dz = stereo_height_precision(1600.0, 452.0, 100.4, 6.0)
    hand = math.sqrt(2.0) * 1600.0**2 / (452.0 * 0.1004) * 6e-6
    assert dz == pytest.approx(hand, rel=1e-12)
    assert round(dz, 2) == 0.48
    with pytest.raises(InputError):
        stereo_height_precision(1600.0, 0.0, 100.4, 6.0)


def test_project_threshold_at_its_limits():
    for r, expected in ((0.40 - EPS, "pass"), (0.40 + EPS, "fail")):
        res = project_threshold(_horizontal(np.full(15, r)))
        assert _status(res, "Planimetric RMSE") == expected
    dz = stereo_height_precision(1600.0, 452.0, 100.4, 6.0)
    for h, expected in ((dz - EPS, "pass"), (dz + EPS, "fail")):
        d = np.zeros((15, 3))
        d[:, 2] = h
        assert _status(project_threshold(d), "Vertical RMSE") == expected
    res = project_threshold(np.zeros((15, 3)), h_threshold=0.3, v_threshold=0.2)
    assert res.figures["v_threshold"] == 0.2


# ----------------------------------------------------------------------------- NSSDA


def test_nssda_factors_from_their_definitions():
    k95 = math.sqrt(stats.chi2.ppf(0.95, 2))  # 95 % radius of a circular normal, in sigma
    assert k95 == pytest.approx(math.sqrt(-2.0 * math.log(0.05)))
    assert NSSDA_HORIZONTAL_FACTOR == pytest.approx(k95, abs=5e-5)
    assert NSSDA_RADIAL_FACTOR == pytest.approx(k95 / math.sqrt(2.0), abs=5e-5)
    assert NSSDA_VERTICAL_FACTOR == pytest.approx(stats.norm.ppf(0.975), abs=5e-5)


def test_exact_bivariate_radius_against_monte_carlo():
    assert bivariate_radius(0.1, 0.1) == pytest.approx(0.1 * NSSDA_HORIZONTAL_FACTOR, rel=1e-4)
    rng = np.random.default_rng(0)
    xy = rng.normal(0.0, [0.3, 0.1], (400_000, 2))
    radius = bivariate_radius(0.3, 0.1)
    coverage = np.mean(np.hypot(xy[:, 0], xy[:, 1]) <= radius)
    assert coverage == pytest.approx(0.95, abs=0.002)  # binomial sd 0.00034
    assert bivariate_radius(0.0, 0.2) == pytest.approx(0.2 * 1.959964, rel=1e-5)


def test_nssda_figures_and_conditions():
    rng = np.random.default_rng(4)
    d = rng.normal(0.0, [0.2, 0.18, 0.3], (25, 3))
    res = nssda(d, normal=[True, True, True], biased=[False, False, False])
    rx, ry, rz = np.sqrt(np.mean(d**2, axis=0))
    assert res.figures["ACCURACY_U_95"] == pytest.approx(1.9600 * rz)
    assert res.figures["ACCURACY_HORIZONTAL_95"] == pytest.approx(2.4477 * 0.5 * (rx + ry))
    assert res.figures["ACCURACY_HORIZONTAL_95_CASE1"] == pytest.approx(1.7308 * math.hypot(rx, ry))
    # Case 2 approximates the exact radius within 1 % for ratios near 1.
    exact = res.figures["ACCURACY_HORIZONTAL_95_EXACT"]
    assert res.figures["ACCURACY_HORIZONTAL_95"] == pytest.approx(exact, rel=0.01)
    assert _status(res, "Check-point count") == "pass"
    assert _status(res, "Horizontal approximation condition") == "pass"
    assert _status(res, "Horizontal accuracy (95 %)") == "info"
    bad = nssda(d * [1.0, 0.3, 1.0], normal=[True, False, None], biased=[True, False, False])
    assert _status(bad, "Horizontal approximation condition") == "fail"
    assert bad.figures["ACCURACY_HORIZONTAL_95"] == bad.figures["ACCURACY_HORIZONTAL_95_EXACT"]
    assert _status(bad, "Assumption: normal distribution (Shapiro-Wilk)") == "fail"
    assert _status(bad, "Assumption: no systematic error (Student t)") == "fail"


def test_too_few_points_are_reported_for_each_standard():
    d = np.full((15, 3), 0.01)
    n = nssda(d)
    assert _status(n, "Check-point count") == "insufficient"
    assert "15" in n.verdicts[0].reason and not n.enough_points
    assert _status(n, "Horizontal accuracy (95 %)") == "insufficient"
    assert math.isfinite(n.figures["ACCURACY_HORIZONTAL_95"])  # computed, not hidden
    a = asprs_2023(d, h_class_cm=5.0)
    assert _status(a, "Check-point count") == "insufficient"
    assert _status(a, "Horizontal class 5-cm") == "insufficient"
    assert "only 15 of 30" in next(
        v.reason for v in a.verdicts if v.name == "Horizontal class 5-cm"
    )
    p = pec_pcd(d, scale=1000)
    assert _status(p, "Check-point count") == "insufficient"
    assert _status(p, "Class A planimetric") == "pass"  # the Decreto sets no minimum
    assert asprs_2023(np.full((30, 3), 0.01)).enough_points


# ----------------------------------------------------------------------------- ASPRS


def test_asprs_includes_the_survey_error_and_3d():
    rng = np.random.default_rng(6)
    d = rng.normal(0.0, [0.03, 0.04, 0.05], (30, 3))
    res = asprs_2023(d, survey_sigma_h=0.01, survey_sigma_v=0.02)
    rx, ry, rz = np.sqrt(np.mean(d**2, axis=0))
    rmse_h = math.sqrt(rx**2 + ry**2 + 2 * 0.01**2)
    rmse_v = math.sqrt(rz**2 + 0.02**2)
    assert res.figures["RMSE_HORIZONTAL_TOTAL"] == pytest.approx(rmse_h)
    assert res.figures["RMSE_U_TOTAL"] == pytest.approx(rmse_v)
    assert res.figures["RMSE_3D_TOTAL"] == pytest.approx(math.hypot(rmse_h, rmse_v))
    # the check points' own figures carry the names they have everywhere else
    assert res.figures["RMSE_HORIZONTAL"] == pytest.approx(math.hypot(rx, ry))
    assert res.figures["RMSE_U"] == pytest.approx(rz)
    assert "RMSE_H" not in res.figures and "RMSE_V" not in res.figures


def test_asprs_class_boundaries():
    for r, expected in ((0.05 - EPS, "pass"), (0.05 + EPS, "fail")):
        res = asprs_2023(_horizontal(np.full(30, r)), h_class_cm=5.0)
        assert _status(res, "Horizontal class 5-cm") == expected
    d = np.zeros((30, 3))
    d[:, 2] = 0.10 + EPS
    assert _status(asprs_2023(d, v_class_cm=10.0), "Vertical (NVA) class 10-cm") == "fail"
    d[:, 2] = 0.10 - EPS
    assert _status(asprs_2023(d, v_class_cm=10.0), "Vertical (NVA) class 10-cm") == "pass"
    # With no target the tightest example class met is named.
    res = asprs_2023(_horizontal(np.full(30, 0.06)))
    assert "7.5-cm" in next(v.reason for v in res.verdicts if v.name == "Horizontal class")


# ----------------------------------------------------------------------------- PEC-PCD


def test_pec_limits_from_the_published_table():
    # PEC-PCD planimetric: 0.28/0.5/0.8/1.0 mm (EP 0.17/0.3/0.5/0.6 mm) at the map scale.
    lim = pec_pcd_limits(25000)
    assert [lim[c]["pec_h"] for c in "ABCD"] == pytest.approx([7.0, 12.5, 20.0, 25.0])
    assert [lim[c]["ep_h"] for c in "ABCD"] == pytest.approx([4.25, 7.5, 12.5, 15.0])
    # Altimetric, equidistance 10 m at 1:25 000: 0.27/0.50/0.60/0.75 Eq, EP 1/6, 1/3, 2/5, 1/2.
    assert [lim[c]["pec_v"] for c in "ABCD"] == pytest.approx([2.7, 5.0, 6.0, 7.5])
    assert [lim[c]["ep_v"] for c in "ABCD"] == pytest.approx([10 / 6, 10 / 3, 4.0, 5.0])
    # Decreto 89.817 art. 8: PEC = 1.6449 EP; the tables round EP (class C: 0.8 / 0.5 = 1.6).
    for c in "ABCD":
        assert lim[c]["pec_h"] / lim[c]["ep_h"] == pytest.approx(1.6449, rel=0.03)
    assert math.isnan(pec_pcd_limits(3000)["A"]["pec_v"])
    assert pec_pcd_limits(3000, 2.0)["B"]["pec_v"] == pytest.approx(1.0)
    with pytest.raises(InputError):
        pec_pcd_limits(0)


@pytest.mark.parametrize("cls", ["A", "B", "C", "D"])
def test_pec_planimetric_standard_error_boundary(cls):
    lim = pec_pcd_limits(2000)[cls]
    for r, expected in ((lim["ep_h"] - EPS, "pass"), (lim["ep_h"] + EPS, "fail")):
        res = pec_pcd(_horizontal(np.full(20, r)), scale=2000, target_class=cls)
        assert _status(res, f"Class {cls} planimetric") == expected
        assert _status(res, f"Declared class {cls} (planimetric)") == expected


@pytest.mark.parametrize("cls", ["A", "B", "C", "D"])
def test_pec_ninety_percent_rule_boundary(cls):
    # 18 of 20 points (90 %) small, 2 just beyond the PEC: passes; a third beyond: fails.
    # The RMS stays below EP so only the 90 % rule decides.
    lim = pec_pcd_limits(1000)[cls]
    small, big = 0.1 * lim["ep_h"], lim["pec_h"] + EPS
    r = np.full(20, small)
    r[:2] = big
    assert np.sqrt(np.mean(r**2)) < lim["ep_h"]
    assert _status(pec_pcd(_horizontal(r), scale=1000), f"Class {cls} planimetric") == "pass"
    r[2] = big
    assert np.sqrt(np.mean(r**2)) < lim["ep_h"]
    assert _status(pec_pcd(_horizontal(r), scale=1000), f"Class {cls} planimetric") == "fail"
    r[:3] = lim["pec_h"] - EPS  # just inside the PEC again
    assert _status(pec_pcd(_horizontal(r), scale=1000), f"Class {cls} planimetric") == "pass"


@pytest.mark.parametrize("cls", ["A", "B", "C", "D"])
def test_pec_altimetric_boundaries(cls):
    # 1:5 000 -> equidistance 2 m by default.
    lim = pec_pcd_limits(5000)[cls]
    assert lim["pec_v"] == pytest.approx({"A": 0.54, "B": 1.0, "C": 1.2, "D": 1.5}[cls])
    d = np.zeros((20, 3))
    for h, expected in ((lim["ep_v"] - EPS, "pass"), (lim["ep_v"] + EPS, "fail")):
        d[:, 2] = -h  # |dH| is what counts
        assert _status(pec_pcd(d, scale=5000), f"Class {cls} altimetric") == expected
    d[:, 2] = 0.05 * lim["ep_v"]
    d[:2, 2] = lim["pec_v"] + EPS
    assert _status(pec_pcd(d, scale=5000), f"Class {cls} altimetric") == "pass"
    d[2, 2] = lim["pec_v"] + EPS
    assert _status(pec_pcd(d, scale=5000), f"Class {cls} altimetric") == "fail"


def test_pec_rejects_unknown_class():
    with pytest.raises(InputError):
        pec_pcd(np.zeros((3, 3)), scale=1000, target_class="E")
