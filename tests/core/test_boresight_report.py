"""The boresightcalibration job: files in, results table, residual table, EO and HTML out."""

from __future__ import annotations

import csv
from dataclasses import replace
from html import unescape
from html.parser import HTMLParser

import numpy as np
import pytest
from lidarphoto.core import i18n
from lidarphoto.core.errors import InputError
from lidarphoto.core.geometry.frames import MappingFrame
from lidarphoto.core.io.orientation import read_eo_csv
from lidarphoto.core.jobs import boresight_calibration
from lidarphoto.core.jobs.boresight_calibration import TABLE_COLUMNS
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.photo.boresight_result import BoresightNotObservable
from lidarphoto.core.photo.boresight_setup import ARCSEC, local_frame_for
from lidarphoto.core.photo.ins import ins_grade
from lidarphoto.core.photo.intersection import forward_intersection
from lidarphoto.core.quality.boresight_html import render_boresight_html
from lidarphoto.core.simulation.flight import FlightConfig, simulate_flight
from lidarphoto.core.simulation.flight_over import ControlFlightConfig, simulate_flight_over

SMALL = FlightConfig(
    n_buildings=12,
    n_planes=30,
    town_size_m=700.0,
    n_check=3,
    types=("tie", "line", "lcp", "check"),
)


def run_boresight_calibration(camera, trajectory, crs, observations, **params):
    """The boresightcalibration job on files; returns what it computed (BoresightRun)."""
    raw = {"CAMERA": str(camera), "TRAJECTORY": str(trajectory), "CRS": crs,
           "OBSERVATIONS": str(observations)}  # fmt: skip
    raw.update({k.upper(): v for k, v in params.items()})
    return run_job(boresight_calibration, raw).data


class _Balanced(HTMLParser):
    """Counts unclosed elements (void elements excluded)."""

    VOID = frozenset(
        {
            "meta",
            "br",
            "hr",
            "img",
            "input",
            "link",
            "circle",
            "line",
            "rect",
            "polygon",
            "polyline",
            "path",
        }
    )

    def __init__(self):
        super().__init__()
        self.stack: list[str] = []
        self.errors: list[str] = []

    def handle_starttag(self, tag, attrs):
        if tag not in self.VOID:
            self.stack.append(tag)

    def handle_startendtag(self, tag, attrs):
        pass

    def handle_endtag(self, tag):
        if tag in self.VOID:
            return
        if not self.stack or self.stack[-1] != tag:
            self.errors.append(f"</{tag}> with open {self.stack[-3:]}")
        else:
            self.stack.pop()


def _lever(sim) -> str:
    return ",".join(repr(float(v)) for v in sim.mount.lever_arm)


@pytest.fixture(scope="module")
def calibrated(tmp_path_factory):
    sim = simulate_flight(SMALL, seed=3)
    folder = tmp_path_factory.mktemp("bore")
    paths = sim.write(folder)
    run = run_boresight_calibration(
        paths["camera"],
        paths["trajectory"],
        sim.crs,
        paths["observations"],
        lever_arm=_lever(sim),
        planes=paths["planes"],
        lines=paths["lines"],
        lcps=paths["lcps"],
        control_types="tie,line,lcp",
        output_table=folder / "table.csv",
        output_eo=folder / "eo.csv",
        output_html=folder / "summary.html",
        residuals_csv=folder / "residuals.csv",
    )
    return sim, run, folder


def test_table_recovers_the_truth_and_matches_the_result(calibrated):
    sim, run, folder = calibrated
    res = run.result
    err = res.boresight - sim.true_boresight(res.groups)
    assert np.all(np.abs(err) < 3.0 * res.std)
    with open(folder / "table.csv", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert tuple(rows[0]) == TABLE_COLUMNS and [r["group"] for r in rows] == list(res.groups)
    for g, row in enumerate(rows):
        for k, angle in enumerate(("omega", "phi", "kappa")):
            assert float(row[f"d_{angle}_deg"]) == pytest.approx(np.degrees(res.boresight[g, k]))
            assert float(row[f"d_{angle}_arcsec"]) == pytest.approx(res.boresight[g, k] / ARCSEC)
            assert float(row[f"std_d_{angle}_arcsec"]) == pytest.approx(res.std[g, k] / ARCSEC)
        assert int(row["images"]) == 3 and int(row["observations"]) > 20
    eo = read_eo_csv(folder / "eo.csv")
    np.testing.assert_allclose(eo.xyz, res.eo.xyz, atol=1e-3)


def test_ground_positions_lie_on_their_targets(calibrated):
    sim, run, folder = calibrated
    obs = run.observations
    kinds = np.array(obs.type)
    plane = {str(p.id): p for p in sim.planes}
    tie = np.flatnonzero(kinds == "tie")
    dist = [abs(plane[obs.target_id[r]].distance(run.ground[r][None])[0]) for r in tie]
    assert max(dist) < 0.05  # rays cut the (map) plane; the ENU/map difference is mm here
    # a tie point's rays meet near the true point: 0.5 px at ~10 cm GSD plus INS noise
    lcp = {str(c.id): c for c in sim.lcps}
    rows = np.flatnonzero(kinds == "lcp")
    gap = np.array([run.ground[r] - lcp[obs.target_id[r]].xyz for r in rows])
    assert np.abs(gap[:, 2]).max() < 1e-3 and np.hypot(gap[:, 0], gap[:, 1]).max() < 0.5
    with open(folder / "residuals.csv", encoding="utf-8") as fh:
        table = list(csv.DictReader(fh))
    assert len(table) == len(obs)
    v = np.array([float(r["v_px"]) for r in table if r["type"] == "tie"])
    assert 0.2 < np.sqrt(np.mean(v**2)) < 1.0  # 0.5 px per coordinate, partly absorbed


def test_html_has_the_figures_and_parses(calibrated):
    _, run, folder = calibrated
    page = (folder / "summary.html").read_text(encoding="utf-8")
    parser = _Balanced()
    parser.feed(page)
    assert not parser.errors and parser.stack == []
    res = run.result
    for g, name in enumerate(res.groups):
        assert f'<td class="t">{name}</td>' in page
        for k in range(3):
            assert f"{res.boresight[g, k] / ARCSEC:.1f}" in page
            assert f"{res.std[g, k] / ARCSEC:.1f}" in page
            assert f"{np.degrees(res.boresight[g, k]):.6f}" in page
    assert f"{res.sigma0:.3f}" in page and str(res.redundancy) in page
    assert ("passed" if res.chi2_passed else "failed") in page
    assert "Correlation" in page and page.count("<svg") == 2 and "Not observable" not in page


def _run_with_a_lonely_group(tmp_path, **kw):
    """A calibration whose group 'lonely' has no observations (its boresight cannot be
    determined): raises BoresightNotObservable after writing the HTML diagnosis."""
    sim = simulate_flight(SMALL, seed=2)
    lonely = sim.trajectory.image_id[0]
    traj = replace(
        sim.trajectory,
        group=tuple(
            "lonely" if i == lonely else g
            for i, g in zip(sim.trajectory.image_id, sim.trajectory.group)
        ),
    )
    keep = np.array([i != lonely for i in sim.observations.image_id])
    sim = replace(sim, trajectory=traj, observations=sim.observations.subset(keep))
    paths = sim.write(tmp_path)
    run_boresight_calibration(
        paths["camera"],
        paths["trajectory"],
        sim.crs,
        paths["observations"],
        lever_arm=_lever(sim),
        planes=paths["planes"],
        lcps=paths["lcps"],
        control_types="tie,lcp",
        output_html=tmp_path / "summary.html",
        **kw,
    )


def test_not_observable_writes_the_diagnosis_then_raises(tmp_path):
    with pytest.raises(BoresightNotObservable) as info:
        _run_with_a_lonely_group(tmp_path, output_table=tmp_path / "t.csv")
    page = unescape((tmp_path / "summary.html").read_text(encoding="utf-8"))
    assert "Not observable" in page and "group 'lonely'" in page
    assert info.value.diagnosis[0] in page
    assert not (tmp_path / "t.csv").exists()


def test_not_observable_diagnosis_in_portuguese(tmp_path):
    """The same set-up in pt_BR: the HTML shows each diagnosis sentence translated, with its
    group name, and none of the English sentences (the exception keeps the English)."""
    i18n.set_language("pt_BR")
    try:
        with pytest.raises(BoresightNotObservable) as info:
            _run_with_a_lonely_group(tmp_path)
    finally:
        i18n.set_language("en")
    page = unescape((tmp_path / "summary.html").read_text(encoding="utf-8"))
    diagnosis = info.value.diagnosis
    assert diagnosis and all(isinstance(d, i18n.Message) for d in diagnosis)
    assert "o boresight do grupo 'lonely' não é determinado de forma alguma" in page
    for d in diagnosis:
        pt = i18n.render(d, "Report", "pt_BR")
        assert pt != str(d) and pt in page and str(d) not in page
    assert "Not observable" not in page and "is not determined" not in page


def test_render_without_results_and_option_errors():
    page = render_boresight_html(None, {"grouping": "single"}, ["x is not observable."])
    assert "x is not observable." in page and "Boresight</h2>" not in page
    assert ins_grade("custom", (0.1, 0.1, 0.01, 0.02)).sigma_heading_deg == 0.02
    with pytest.raises(InputError, match="INS_SIGMAS"):
        ins_grade("custom", (0.1, 0.1, 0.01))
    with pytest.raises(InputError, match="INS grade"):
        ins_grade("tactical")


def test_flight_over_given_control_and_check_point_intersection(tmp_path):
    """Control from a town (as if from a tile); check points from the calibrated images."""
    town = simulate_flight(replace(SMALL, town_size_m=120.0, n_buildings=9), seed=1)
    centre = tuple(town.lidar_points[:, :2].mean(axis=0))
    cfg = ControlFlightConfig(crs=town.crs, centre=centre, n_check=10)
    sim = simulate_flight_over(
        town.planes, town.lines, town.lcps, town.lidar_points, town.lidar_plane_ids, cfg, seed=4
    )
    assert len(sim.check_points) == 10 and set(sim.observations.type) == {
        "tie",
        "line",
        "lcp",
        "check",
    }
    paths = sim.write(tmp_path / "flight")
    town_paths = town.write(tmp_path / "town")
    run = run_boresight_calibration(
        paths["camera"],
        paths["trajectory"],
        cfg.crs,
        paths["observations"],
        lever_arm=",".join(map(str, cfg.lever_arm_m)),
        planes=town_paths["planes"],
        lines=town_paths["lines"],
        lcps=town_paths["lcps"],
        control_types="tie,line,lcp",
    )
    res = run.result
    err = res.boresight - sim.truth.boresight["N"][None]
    assert np.all(np.abs(err) < 3.0 * res.std)
    local = local_frame_for(sim.trajectory, MappingFrame.from_user_input(cfg.crs))
    ids, xyz, nrays = forward_intersection(run.observations, res.eo, sim.camera, local)
    assert len(ids) >= 8 and nrays.min() >= 2
    d = xyz - np.array([sim.check_points[i] for i in ids])
    # 0.5 px at 1.7 cm GSD and POS AV 310 attitude noise (0.015 deg at 130 m: 3.4 cm per ray)
    assert np.sqrt(np.mean(d**2)) < 0.06
