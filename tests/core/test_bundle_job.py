"""The ``bundleadjustment`` job on files: every output written and readable by the project's
readers, the check-point table chaining into the accuracy report, the command line."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
from lidarphoto.core.cli import main as cli_main
from lidarphoto.core.errors import InputError
from lidarphoto.core.geometry.ap_models import AP_FAMILIES
from lidarphoto.core.io.camera import read_cameras_json
from lidarphoto.core.io.checkpoints import read_checkpoint_table
from lidarphoto.core.io.orientation import read_eo_csv_full
from lidarphoto.core.jobs import accuracy_report, bundle_adjustment
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.simulation.uav_block import simulate_uav_block


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("uav")
    blk = simulate_uav_block("bauer", seed=1, n_tie=400)
    return blk, blk.write(folder), folder


def _outputs(folder, tag):
    return {
        "OUTPUT_EO": str(folder / f"{tag}_eo.csv"),
        "OUTPUT_CAMERA": str(folder / f"{tag}_camera.json"),
        "OUTPUT_POINTS": str(folder / f"{tag}_points.csv"),
        "OUTPUT_RESIDUALS": str(folder / f"{tag}_residuals.csv"),
        "OUTPUT_CHECK_CSV": str(folder / f"{tag}_check.csv"),
        "OUTPUT_COMPARISON": str(folder / f"{tag}_comparison.csv"),
        "OUTPUT_HTML": str(folder / f"{tag}.html"),
    }


def _read(path):
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def test_all_models_compared_and_every_output_readable(files):
    blk, paths, folder = files
    outs = _outputs(folder, "all")
    res = run_job(
        bundle_adjustment,
        {
            "CAMERA": str(paths["camera"]),
            "OBSERVATIONS": str(paths["observations"]),
            "GROUND_POINTS": str(paths["ground_points"]),
            "EO": str(paths["eo"]),
            "CRS": "EPSG:31983",
            "AP_MODEL": "all",
            "ROBUST": "none",
            "SNOOPING": False,
            "AP_SELECTION": False,
            **outs,
        },
    )
    best = res.results["MODEL"]
    # Bauer's distortion was inserted: the winner can represent it (Bauer, or the richer
    # Jacobsen / Brown sets), never a radial-only model
    assert best in ("bauer", "jacobsen", "brown")
    assert res.results["CHECK_RMS"] < 0.2
    comp = _read(outs["OUTPUT_COMPARISON"])
    assert next(r["model"] for r in comp) == best and len(comp) == 7
    families = set(bundle_adjustment.SPEC.param("AP_MODEL").options) - {"all"}
    assert {r["model"] for r in comp} == families
    rms = [float(r["rmse_3d"]) for r in comp]
    assert rms == sorted(rms)
    # the report draws the winner's adjusted lens: its field and radial profile
    page = open(outs["OUTPUT_HTML"], encoding="utf-8").read()
    assert page.count('class="lens-field"') == 1 and page.count('class="lens-profile"') == 1
    assert page.count('class="block-map"') == 1
    # the orientations with sigmas read back as observed orientations
    eo = read_eo_csv_full(outs["OUTPUT_EO"], "")
    assert eo.sigma is not None and len(eo.eo) == 15
    # heights: the principal distance is estimated over flat ground (correlated, ~1 m)
    assert np.all(eo.sigma[:, :2] < 0.5) and np.all(eo.sigma[:, 2] < 2.0)
    assert np.all(np.degrees(eo.sigma[:, 3:]) < 0.05)
    assert np.abs(eo.eo.xyz - blk.eo_true.xyz).max() < 0.5
    cam = read_cameras_json(outs["OUTPUT_CAMERA"])[0]
    assert cam.distortion.model == AP_FAMILIES[best]
    data = json.loads(open(outs["OUTPUT_CAMERA"]).read())
    assert data["sigmas"]["focal_mm"] > 0 and data["_bundle"]["ap_model"] == best
    pts = _read(outs["OUTPUT_POINTS"])
    assert {r["role"] for r in pts} == {"tie", "control", "check"}
    assert all(float(r["sigma_Z"]) > 0 for r in pts if r["role"] != "check")
    resid = _read(outs["OUTPUT_RESIDUALS"])
    assert len(resid) == len(blk.observations)
    assert sum(int(r["used"]) for r in resid) == sum(r["role"] != "check" for r in resid)
    # the check table: every model as a group, readable by the accuracy report ...
    chk = read_checkpoint_table(outs["OUTPUT_CHECK_CSV"])
    assert set(chk.groups) == {r["model"] for r in comp}
    n_check = int(comp[0]["n_check"])
    assert len(chk.ids) == 7 * n_check
    # ... and the accuracy report runs on it (the model chain of the QGIS test)
    rep = run_job(
        accuracy_report,
        {"INPUT": outs["OUTPUT_CHECK_CSV"], "OUTPUT_HTML": str(folder / "acc.html")},
    )
    assert (folder / "acc.html").is_file() and rep.results
    page = open(outs["OUTPUT_HTML"], encoding="utf-8").read()
    for text in (
        "AP models compared",
        "Interior orientation and additional parameters",
        "Correlations",
        "Image residuals",
        "Check points",
        "global chi-square",
    ):
        assert text in page, text


def test_command_line_single_model(files, capsys):
    _blk, paths, folder = files
    outs = _outputs(folder, "cli")
    args = [
        "bundleadjustment",
        "--camera",
        str(paths["camera"]),
        "--observations",
        str(paths["observations"]),
        "--ground-points",
        str(paths["ground_points"]),
        "--eo",
        str(paths["eo"]),
        "--crs",
        "EPSG:31983",
        "--ap-model",
        "bauer",
        "--output-eo",
        outs["OUTPUT_EO"],
        "--output-check-csv",
        outs["OUTPUT_CHECK_CSV"],
    ]
    assert cli_main(args) == 0
    text = capsys.readouterr().out
    assert "bauer: sigma0" in text and "check points" in text
    assert len(read_checkpoint_table(outs["OUTPUT_CHECK_CSV"]).ids) >= 4


def test_bad_ground_point_table_names_row_and_column(files, tmp_path):
    _blk, paths, _folder = files
    bad = tmp_path / "gp.csv"
    lines = open(paths["ground_points"]).read().splitlines()
    lines[3] = lines[3].replace("control", "contrl")
    bad.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"gp\.csv.*row 4.*column 'role'.*contrl"):
        run_job(
            bundle_adjustment,
            {
                "CAMERA": str(paths["camera"]),
                "OBSERVATIONS": str(paths["observations"]),
                "GROUND_POINTS": str(bad),
                "EO": str(paths["eo"]),
                "CRS": "EPSG:31983",
                "OUTPUT_EO": str(tmp_path / "eo.csv"),
            },
        )


def test_eo_without_sigmas_becomes_observed_with_eo_sigmas(files, tmp_path):
    """An EO table without sigma columns (as trajectorytoeo writes it) with EO_SIGMAS: the
    orientations are observations (the settings say so and the datum needs no control)."""
    from lidarphoto.core.io.orientation import write_eo_csv

    blk, paths, _ = files
    plain = tmp_path / "eo_plain.csv"
    write_eo_csv(plain, blk.eo_dg)
    html = tmp_path / "s.html"
    checks = tmp_path / "checks.csv"
    lines = open(paths["ground_points"], encoding="utf-8").read().splitlines()
    checks.write_text("\n".join(line.replace(",control", ",check") for line in lines) + "\n")
    # a control point may be measured once, a check point not: those rows go
    from lidarphoto.core.io.observations import write_observations_csv

    obs = blk.observations
    once = {p for p in set(obs.point_id) if obs.point_id.count(p) < 2}
    obs_path = tmp_path / "obs.csv"
    write_observations_csv(obs_path, obs.subset([p not in once for p in obs.point_id]))
    res = run_job(
        bundle_adjustment,
        {
            "CAMERA": str(paths["camera"]),
            "OBSERVATIONS": str(obs_path),
            "GROUND_POINTS": str(checks),
            "EO": str(plain),
            "EO_SIGMAS": "5,5,5,1,1,1",
            "CRS": "EPSG:31983",
            "DATUM": "control",
            "ESTIMATE_INTERIOR": False,
            "ROBUST": "none",
            "SNOOPING": False,
            "OUTPUT_EO": str(tmp_path / "eo.csv"),
            "OUTPUT_HTML": str(html),
        },
    )
    assert res.data.adjustment.converged
    assert "observed (with sigmas)" in html.read_text(encoding="utf-8")
    # every surveyed point is a check point here: the datum comes from the observed
    # orientations alone (no control block, no constraints)
    adj = res.data.adjustment
    assert "observed orientation" in adj.residuals and "control points" not in adj.residuals
    assert adj.n_constraints == 0 and len(res.data.check.point_id) >= 15


def _base(paths, tmp_path, **changes):
    values = {
        "CAMERA": str(paths["camera"]),
        "OBSERVATIONS": str(paths["observations"]),
        "GROUND_POINTS": str(paths["ground_points"]),
        "EO": str(paths["eo"]),
        "CRS": "EPSG:31983",
        "OUTPUT_EO": str(tmp_path / "eo.csv"),
    }
    values.update(changes)
    return values


def test_inputs_checked_before_the_adjustment(files, tmp_path):
    """Project-wide checks hold for the bundle too: a pixel off the camera's image, ground
    points in degrees and perspective centres in another CRS, an EO sigma of zero; each
    refused naming the file (and row), nothing written."""
    from lidarphoto.core.errors import CrsError

    blk, paths, _folder = files
    # a pixel off the 4000 x 3000 image (row 5 of the table)
    obs = open(paths["observations"], encoding="utf-8").read().splitlines()
    head = obs[0].split(",")
    cells = obs[4].split(",")
    cells[head.index("col")] = str(blk.camera.width_px + 10)
    obs[4] = ",".join(cells)
    bad_obs = tmp_path / "obs_off.csv"
    bad_obs.write_text("\n".join(obs) + "\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"obs_off\.csv.*row 5.*column 'col'.*off the image"):
        run_job(bundle_adjustment, _base(paths, tmp_path, OBSERVATIONS=str(bad_obs)))
    # ground points given in geographic degrees
    gp = _read(paths["ground_points"])
    deg = tmp_path / "gp_deg.csv"
    with open(deg, "w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, fieldnames=list(gp[0]))
        w.writeheader()
        for k, r in enumerate(gp):
            w.writerow({**r, "X": f"{-43.7 + 1e-4 * k}", "Y": f"{-22.75 + 1e-4 * k}"})
    with pytest.raises(CrsError, match=r"gp_deg\.csv.*ground points.*longitude and latitude"):
        run_job(bundle_adjustment, _base(paths, tmp_path, GROUND_POINTS=str(deg)))
    # perspective centres of another CRS (SIRGAS 2000 / UTM 23S expected; given 1000 km north)
    eo = _read(paths["eo"])
    far = tmp_path / "eo_far.csv"
    with open(far, "w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, fieldnames=list(eo[0]))
        w.writeheader()
        for r in eo:
            w.writerow({**r, "Y": f"{float(r['Y']) + 9.0e6:.3f}"})
    with pytest.raises(CrsError, match=r"eo_far\.csv.*perspective centres.*outside the area"):
        run_job(bundle_adjustment, _base(paths, tmp_path, EO=str(far)))
    with pytest.raises(InputError, match=r"EO_SIGMAS \(number 4 of 6\): must be >= 0\.0001"):
        run_job(bundle_adjustment, _base(paths, tmp_path, EO_SIGMAS="5,5,5,0,1,1"))
    assert not (tmp_path / "eo.csv").exists()


def test_pixels_checked_against_each_camera_of_a_block():
    """With several cameras each row is bounded by its own image's camera."""
    from dataclasses import replace

    from lidarphoto.core.jobs.bundle_adjustment import _check_on_image
    from lidarphoto.core.photo.observations import ImageObservations

    blk = simulate_uav_block("bauer", seed=1, n_tie=50)
    small = replace(blk.camera, name="small", width_px=1000, height_px=800)
    obs = ImageObservations.from_arrays(
        ["A", "B", "B"],
        ["P1", "P1", "P2"],
        [[3500.0, 2500.0], [900.0, 700.0], [999.0, 850.0]],
        [0.5] * 3,
        ["tie"] * 3,
        [""] * 3,
    )
    obs = replace(obs, rows=(2, 3, 4), source="obs.csv")
    cams = [replace(blk.camera, name="big"), small]
    _check_on_image(obs.subset([True, True, False]), {"A": "big", "B": "small"}, cams)
    with pytest.raises(InputError, match=r"obs\.csv.*row 4.*\(999, 850\).*'small'.*1000 x 800"):
        _check_on_image(obs, {"A": "big", "B": "small"}, cams)
