"""Issue 35, "a failed check is a failure": an adjustment whose robust stage and data snooping
reject more observations than their false alarms explain does not report its global test as
plainly passed. Bundle adjustment and resection say so in their summary ("passed only after
rejecting ..."); boresight calibration, like tlscalibration, fails with the reason unless
ACCEPT_DOUBTFUL. A clean block of the same kind still passes. (calibratecamera has neither a
robust stage nor data snooping: it rejects nothing.)"""

from __future__ import annotations

import csv
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from lidarphoto.core.errors import AdjustmentError
from lidarphoto.core.jobs import boresight_calibration, bundle_adjustment, resection
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.simulation.flight import FlightConfig, simulate_flight
from lidarphoto.core.simulation.resection import make_scene, write_scene_files
from lidarphoto.core.simulation.uav_block import simulate_uav_block

FLAGGED = "global test passed only after rejecting"


def _blunder(path: Path, out: Path, share: float, kinds: tuple[str, ...], seed: int) -> int:
    """Copy the observation table ``path`` to ``out`` with ``share`` of the rows whose
    point_id starts with one of ``kinds`` (or whose type is one) moved by 8-30 px in each
    coordinate; returns how many were moved."""
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    rng = np.random.default_rng(seed)
    pick = [k for k, r in enumerate(rows) if r["point_id"].startswith(kinds) or r["type"] in kinds]
    bad = rng.choice(pick, round(share * len(pick)), replace=False)
    for k in bad:
        for c in ("col", "row"):
            step = float(rng.choice([-1.0, 1.0]) * rng.uniform(8.0, 30.0))
            rows[k][c] = repr(float(rows[k][c]) + step)
    with open(out, "w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    return len(bad)


def _test_line(lines: list[str]) -> str:
    return next(s for s in lines if ", global test " in s)


@pytest.fixture(scope="module")
def uav(tmp_path_factory):
    folder = tmp_path_factory.mktemp("uav_blunders")
    paths = simulate_uav_block("none", seed=1, n_tie=150).write(folder)
    return paths, folder


LATE = "passed, but only after more rejections than false alarms explain"


def _bundle(paths, observations) -> tuple[list[str], str]:
    html = observations.parent / f"{observations.stem}.html"
    lines = run_job(bundle_adjustment, {
        "CAMERA": str(paths["camera"]), "OBSERVATIONS": str(observations),
        "GROUND_POINTS": str(paths["ground_points"]), "EO": str(paths["eo"]),
        "CRS": "EPSG:31983", "AP_MODEL": "none", "OUTPUT_HTML": str(html),
    }).lines  # fmt: skip
    return lines, html.read_text(encoding="utf-8")


def test_bundle_with_a_tenth_of_its_ties_blundered_says_its_test_is_not_plainly_passed(uav):
    """60 of 600 tie measurements moved by 8-30 px: the robust stage and snooping reject
    them all and the rest passes the global test, which the summary qualifies (at most 6
    false alarms at alpha = 0.001 among ~700 groups); the clean block passes plainly. (With
    a fifth blundered the global test of the rest fails: "failed".)"""
    paths, folder = uav
    lines, page = _bundle(paths, paths["observations"])
    assert "global test passed," in _test_line(lines), lines
    assert LATE not in page and "rejections explained by false alarms" not in page
    n = _blunder(paths["observations"], folder / "dirty.csv", 0.1, ("T",), seed=3)
    lines, page = _bundle(paths, folder / "dirty.csv")
    line = _test_line(lines)
    assert FLAGGED in line and "global test passed," not in line, line
    assert LATE in page and "at most 6 (1.5 expected); 79 rejected" in page
    rejected = int(line.split(" of ")[0].rsplit(" ", 1)[1])
    assert rejected >= n, (rejected, n)
    assert "rejecting 79 of 698 observations (false alarms explain at most 6)" in line, line


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    sc = make_scene(51, point_sigma_m=0.03)
    data = sc.observe(np.random.default_rng(7))
    folder = tmp_path_factory.mktemp("resection_blunders")
    return write_scene_files(folder, sc, data, "EPSG:32632"), folder


def _resect(files, observations) -> tuple[str, str]:
    html = observations.parent / f"{observations.stem}.html"
    lines = run_job(resection, {
        "CAMERA": str(files["camera"]), "OBSERVATIONS": str(observations),
        "CONTROL_POINTS": str(files["control_points"]),
        "CONTROL_LINES": str(files["control_lines"]), "CRS": "EPSG:32632",
        "OUTPUT_HTML": str(html),
    }).lines  # fmt: skip
    return lines[1], html.read_text(encoding="utf-8")


def test_resection_with_a_sixth_of_its_measurements_blundered_is_not_plainly_passed(scene):
    """9 of 60 point and line measurements moved by 8-30 px: snooping rejects 9 of the 36
    point and line groups, the rest passes, and the image's row says at what price (more
    blunders and the resection no longer converges: a named error). Clean: passed."""
    files, folder = scene
    clean, page = _resect(files, files["observations"])
    assert clean.endswith(" passed") and LATE not in page, clean
    assert _blunder(files["observations"], folder / "dirty.csv", 0.15, ("lcp", "line"), 4) == 9
    row, page = _resect(files, folder / "dirty.csv")
    assert row.endswith(" passed only after rejecting 9 of 36 observations (false alarms "
                        "explain at most 3)"), row  # fmt: skip
    assert page.count(LATE) == 2  # the images' table and the image's global test


SMALL = FlightConfig(n_buildings=6, n_planes=12, town_size_m=700.0, n_check=3,
                     types=("tie", "line", "lcp", "check"))  # fmt: skip


def _boresight(sim, paths, **extra):
    raw = {"CAMERA": str(paths["camera"]), "TRAJECTORY": str(paths["trajectory"]),
           "CRS": sim.crs, "OBSERVATIONS": str(paths["observations"]),
           "LEVER_ARM": ",".join(repr(float(v)) for v in sim.mount.lever_arm),
           "PLANES": str(paths["planes"]), "LINES": str(paths["lines"]),
           "LCPS": str(paths["lcps"]), "CONTROL_TYPES": "tie,lcp", **extra}  # fmt: skip
    return run_job(boresight_calibration, raw)


@pytest.mark.parametrize("blunders", [0, 10])
def test_boresight_with_many_blunders_fails_its_checks(tmp_path, blunders):
    """Ten 30-px blunders among 86 tie and LCP groups (at most 3 false alarms): refused like
    tlscalibration, nothing written; ACCEPT_DOUBTFUL writes the table with the warning and
    the summary qualifies the global test. The same flight without blunders passes."""
    sim = simulate_flight(replace(SMALL, n_blunders=blunders, blunder_px=30.0), seed=5)
    paths = sim.write(tmp_path)
    table = tmp_path / "table.csv"
    if not blunders:
        res = _boresight(sim, paths, OUTPUT_TABLE=str(table))
        assert "global test passed," in _test_line(res.lines) and table.is_file()
        return
    before = sorted(p.name for p in tmp_path.iterdir())
    with pytest.raises(AdjustmentError) as info:
        _boresight(sim, paths, OUTPUT_TABLE=str(table))
    assert str(info.value).startswith(
        "the boresight calibration failed its checks: data snooping rejected 10 of 86 "
        "observations (11.6 %); its false alarms at alpha = 0.001 explain at most 3"
    ), info.value
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    res = _boresight(sim, paths, OUTPUT_TABLE=str(table), ACCEPT_DOUBTFUL=True)
    assert FLAGGED in _test_line(res.lines), res.lines
    assert any(s.startswith("WARNING: data snooping rejected 10 of 86") for s in res.lines)
    assert table.read_text(encoding="utf-8").startswith("# WARNING")
