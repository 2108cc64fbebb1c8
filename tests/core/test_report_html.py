"""core.quality.accuracy_html and core.quality.svg_plots: the page parses, holds the tables,
verdicts and plots."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from html.parser import HTMLParser

import numpy as np
import pytest
from lidarphoto.core.quality.accuracy import AccuracySettings, CheckPoints, assess_accuracy
from lidarphoto.core.quality.accuracy_html import render_html
from lidarphoto.core.quality.svg_plots import histogram, nice_step, qq_plot, vector_map
from scipy import stats

SVG = "{http://www.w3.org/2000/svg}"


class _Collector(HTMLParser):
    def __init__(self):
        super().__init__()
        self.tags: dict[str, int] = {}
        self.text: list[str] = []
        self.external: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.tags[tag] = self.tags.get(tag, 0) + 1
        for k, v in attrs:
            if k in ("src", "href") and v and not v.startswith("#"):
                self.external.append(v)

    def handle_data(self, data):
        self.text.append(data)


def _report(n=15, outlier=True, seed=0):
    rng = np.random.default_rng(seed)
    ref = np.column_stack(
        [500000 + rng.uniform(0, 1500, n), 7450000 + rng.uniform(0, 1500, n), rng.uniform(0, 9, n)]
    )
    meas = ref + rng.normal(0, [0.2, 0.2, 0.3], (n, 3))
    if outlier:
        meas[2, 1] += 2.5
    ids = tuple(f"CP<{k}>" if k == 0 else f"CP{k}" for k in range(n))  # one id needs escaping
    groups = tuple("NE" if k % 2 else "SW" for k in range(n))
    cp = CheckPoints(ids, meas, ref, groups, "EPSG:31983", "test & co")
    return assess_accuracy(cp, AccuracySettings(pec_scale=2000, declared_sigma_h=0.2))


def test_page_is_self_contained_and_has_every_section():
    rep = _report()
    page = render_html(rep)
    col = _Collector()
    col.feed(page)
    text = " ".join(col.text)
    assert not col.external  # nothing fetched from outside
    assert col.tags.get("svg") == 7  # vector map + 3 histograms + 3 Q-Q plots
    # info + RMSE, standards (4), project per group, (overall + 2 groups) x 2, the overall
    # statistics without the flagged point, points
    assert col.tags.get("table", 0) == 2 + 4 + 1 + 6 + 1 + 1
    assert rep.outliers.any.sum() == 1 and "For comparison: without the 1 flagged point(s)" in text
    assert f"{rep.rmse_contrast['RMSE_N']:.4f}" in text
    for word in ("ASPRS", "NSSDA", "PEC-PCD", "Project threshold", "Shapiro-Wilk", "Student t"):
        assert word in text, word
    assert "CP<0>" in text and "CP&lt;0>" not in text  # escaped in the source, intact as text
    assert "<CP<0>" not in page
    assert "INSUFFICIENT" in text  # 15 points: too few for ASPRS and NSSDA, said so
    assert f"{rep.rmse['RMSE_E']:.4f}" in text
    for k in np.flatnonzero(rep.outliers.any):
        assert rep.points.ids[k] in text


def test_every_svg_is_well_formed_xml():
    page = render_html(_report())
    svgs = re.findall(r"<svg.*?</svg>", page, re.S)
    assert len(svgs) == 7
    for s in svgs:
        root = ET.fromstring(s)
        assert root.tag == f"{SVG}svg" and root.find(f"{SVG}title") is not None


def test_vector_map_draws_one_arrow_per_nonzero_vector_and_rings_outliers():
    e = np.array([0.0, 100.0, 200.0, 50.0])
    n = np.array([0.0, 80.0, 10.0, 120.0])
    de = np.array([0.1, 0.0, -0.2, 0.05])
    dn = np.array([0.0, 0.0, 0.1, -0.05])
    flags = np.array([False, False, True, False])
    root = ET.fromstring(
        vector_map(e, n, de, dn, np.array([0.1, -0.1, 0, 0.2]), list("abcd"), flags)
    )
    polygons = root.findall(f"{SVG}polygon")
    assert len(polygons) == 3 + 1  # three non-zero vectors plus the legend's scale arrow
    rings = [c for c in root.findall(f"{SVG}circle") if c.get("fill") == "none"]
    assert len(rings) == 1 + 1  # the outlier plus its legend symbol
    # Arrow tips point the way of the discrepancy: the first arrow goes right (east).
    x0 = float(root.findall(f"{SVG}circle")[0].get("cx"))
    tip_x = float(polygons[0].get("points").split()[0].split(",")[0])
    assert tip_x > x0


def test_histogram_counts_match_numpy():
    v = np.random.default_rng(3).normal(size=40)
    root = ET.fromstring(histogram(v, title="dE", bins=6))
    bars = [r for r in root.findall(f"{SVG}rect") if r.find(f"{SVG}title") is not None]
    counts = [int(b.find(f"{SVG}title").text) for b in bars]
    assert counts == np.histogram(v, bins=6)[0].tolist()
    assert sum(counts) == 40


def test_qq_plot_points_follow_blom_scores():
    v = np.array([0.3, -0.1, 0.05, 0.2, -0.4])
    root = ET.fromstring(qq_plot(v, title="dH"))
    xs = [float(c.get("cx")) for c in root.findall(f"{SVG}circle")]
    ys = [float(c.get("cy")) for c in root.findall(f"{SVG}circle")]
    assert xs == sorted(xs) and ys == sorted(ys, reverse=True)  # sorted values, y up
    q = stats.norm.ppf((np.arange(1, 6) - 0.375) / 5.25)
    # Equal quantile steps give equal pixel steps (linear axis).
    np.testing.assert_allclose(
        np.diff(xs) / np.diff(q), (xs[-1] - xs[0]) / (q[-1] - q[0]), rtol=1e-2
    )


@pytest.mark.parametrize(("span", "step"), [(1.0, 0.2), (9.0, 2.0), (0.03, 0.01), (2400, 500)])
def test_nice_step(span, step):
    assert nice_step(span) == pytest.approx(step)
