"""The ``resection`` algorithm (core/jobs/resection.py) from files, against simulated truth and
IGN's Borea orientation: the command line and run_job, its outputs and its errors."""

from __future__ import annotations

import csv
import math
from dataclasses import replace

import numpy as np
import pytest
from lidarphoto.core.cli import main as cli_main
from lidarphoto.core.errors import InputError, NotObservableError
from lidarphoto.core.io.camera import write_camera_json
from lidarphoto.core.io.orientation import read_eo_csv
from lidarphoto.core.io.resection import RESECTION_EO_COLUMNS, RESIDUAL_COLUMNS
from lidarphoto.core.jobs import resection
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.photo.resection import resect
from lidarphoto.core.simulation.resection import make_scene, write_scene_files
from test_borea_resection import _altitude_to_ellipsoidal, _camera, _measurements, _opk

CRS = "EPSG:32632"


def _rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def _angle(a):
    return (np.asarray(a) + 180.0) % 360.0 - 180.0


@pytest.fixture(scope="module")
def scene_files(tmp_path_factory):
    scene = make_scene(51, point_sigma_m=0.03)
    data = scene.observe(np.random.default_rng(7))
    return scene, data, write_scene_files(tmp_path_factory.mktemp("scene"), scene, data, CRS)


def _values(files, out, **extra):
    v = {"CAMERA": str(files["camera"]), "OBSERVATIONS": str(files["observations"]),
         "CONTROL_POINTS": str(files["control_points"]),
         "CONTROL_LINES": str(files["control_lines"]), "CRS": CRS,
         "OUTPUT_EO": str(out / "eo.csv"), "OUTPUT_RESIDUALS": str(out / "res.csv"),
         "OUTPUT_HTML": str(out / "summary.html")}  # fmt: skip
    v.update(extra)
    return {k: val for k, val in v.items() if val is not None}


def _check_against_truth(files, eo_path, k=4.0):
    """The resected EO in the mapping CRS within k sigma (its own columns) of the truth."""
    truth = read_eo_csv(files["eo_true"])
    got = read_eo_csv(eo_path)
    rows = _rows(eo_path)
    sig = np.array([[float(r[c]) for c in RESECTION_EO_COLUMNS[9:15]] for r in rows])
    d_xyz = got.xyz[0] - truth.xyz[0]
    d_opk = _angle(np.degrees(got.opk[0] - truth.opk[0]))
    assert np.all(np.abs(d_xyz) < k * sig[0, :3]), (d_xyz, sig[0, :3])
    assert np.all(np.abs(d_opk) < k * sig[0, 3:]), (d_opk, sig[0, 3:])
    return rows[0], sig[0]


def test_cli_points_and_lines_recover_the_truth(scene_files, tmp_path, capsys):
    """From the command line, no approximate values: the EO CSV (read back by the EO reader)
    holds the truth within 4 of its sigmas; sigma0 near 1, the chi-square test passed; one
    residual row per measured pixel; the HTML names the global test."""
    scene, data, files = scene_files
    args = ["resection"]
    for k, val in _values(files, tmp_path).items():
        args += [f"--{k.lower().replace('_', '-')}", val]
    assert cli_main(args) == 0
    row, sig = _check_against_truth(files, tmp_path / "eo.csv")
    assert list(_rows(tmp_path / "eo.csv")[0].keys()) == list(RESECTION_EO_COLUMNS)
    assert 0.7 < float(row["sigma0"]) < 1.3
    assert row["chi2_passed"] == "1"
    assert int(row["points"]) == data.n_points and int(row["lines"]) == data.n_lines
    assert int(row["redundancy"]) == 2 * data.n_points + 2 * data.n_lines - 6
    # the sigmas are those of the core resection of the same data in the scene's frame (its
    # origin on the UTM central meridian: no grid convergence between the two frames); 5 %:
    # the segment table carries each end's 3D sigma, read as isotropic, where the scene's
    # covariance is across the line only
    core = resect(data, scene.camera)
    np.testing.assert_allclose(sig[:3], core.std[:3], rtol=0.05)
    np.testing.assert_allclose(sig[3:], np.degrees(core.std[3:]), rtol=0.05)
    res = _rows(tmp_path / "res.csv")
    assert list(res[0].keys()) == list(RESIDUAL_COLUMNS)
    assert len(res) == data.n_points + sum(len(v) for v in data.line_pixels)
    dist = np.array([float(r["distance_px"]) for r in res if r["type"] == "line"])
    assert np.sqrt(np.mean(dist**2)) < 1.0  # 0.5 px noise across the lines
    html = (tmp_path / "summary.html").read_text()
    assert "chi" in html.lower() and "img1" in html
    assert "img1" in capsys.readouterr().out


@pytest.mark.parametrize("model", ["coplanarity", "equivalent_planes"])
def test_lines_only_from_the_line_table(scene_files, tmp_path, model):
    """Only LINE_OBSERVATIONS and CONTROL_LINES (the point rows of the same file are left
    out): the truth within 4 sigma with both line models."""
    _, data, files = scene_files
    v = _values(files, tmp_path, OBSERVATIONS=None, CONTROL_POINTS=None,
                LINE_OBSERVATIONS=str(files["observations"]), MODEL=model)  # fmt: skip
    result = run_job(resection, v)
    assert result.results["IMAGE_COUNT"] == 1
    row, _ = _check_against_truth(files, tmp_path / "eo.csv")
    assert int(row["points"]) == 0 and int(row["lines"]) == data.n_lines
    assert row["model"] == model


def test_line_absent_from_the_control_is_named(scene_files, tmp_path):
    _, _data, files = scene_files
    lines = _rows(files["control_lines"])
    gone = lines[3]["id"]
    with open(tmp_path / "lines.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(lines[0].keys()))
        w.writeheader()
        w.writerows([r for r in lines if r["id"] != gone])
    v = _values(files, tmp_path, CONTROL_LINES=str(tmp_path / "lines.csv"))
    with pytest.raises(InputError, match=f"line '{gone}'.*not in"):
        run_job(resection, v)
    assert not (tmp_path / "eo.csv").exists()


def test_all_lines_parallel_is_refused_by_the_job(tmp_path):
    """Lines only, all in one direction: the error names X0 and Y0 as not determinable (the
    position along the lines) and no output is written."""
    scene = make_scene(53, n_points=0, n_lines=10)
    u = np.array([math.cos(0.4), math.sin(0.4), 0.0])
    p2 = scene.p1 + 20.0 * u
    scene = replace(scene, p2=p2)
    data = scene.observe(None, points=False)
    files = write_scene_files(tmp_path / "in", scene, data, CRS)
    v = _values(files, tmp_path, OBSERVATIONS=None, CONTROL_POINTS=None,
                LINE_OBSERVATIONS=str(files["observations"]))  # fmt: skip
    with pytest.raises(NotObservableError) as err:
        run_job(resection, v)
    assert err.value.parameters == ["X0", "Y0"]
    assert "parallel" in str(err.value) and "img1" in str(err.value)
    assert not (tmp_path / "eo.csv").exists()


def test_approximate_eo_weighted_as_observations(scene_files, tmp_path):
    """APPROX_EO (the truth moved by 100 m and 10 degrees) with loose APPROX_EO_SIGMAS: six
    more redundant observations, the same solution within the precision."""
    _, _data, files = scene_files
    truth = read_eo_csv(files["eo_true"])
    rows = _rows(files["eo_true"])
    r = rows[0]
    r["X"] = repr(float(r["X"]) + 100.0)
    r["kappa_deg"] = repr(float(r["kappa_deg"]) + 10.0)
    with open(tmp_path / "approx.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(r.keys()))
        w.writeheader()
        w.writerow(r)
    free = tmp_path / "free"
    free.mkdir()
    run_job(resection, _values(files, free))
    run_job(resection, _values(files, tmp_path, APPROX_EO=str(tmp_path / "approx.csv"),
                               APPROX_EO_SIGMAS="500,500,500,45,45,45"))  # fmt: skip
    a, b = _rows(free / "eo.csv")[0], _rows(tmp_path / "eo.csv")[0]
    assert int(b["redundancy"]) == int(a["redundancy"]) + 6
    for c, s in zip(RESECTION_EO_COLUMNS[3:9], RESECTION_EO_COLUMNS[9:15]):
        assert abs(float(a[c]) - float(b[c])) < 0.05 * float(a[s]), c
    assert read_eo_csv(tmp_path / "eo.csv").image_id == truth.image_id


def test_borea_real_images_through_the_algorithm(tmp_path):
    """IGN's Borea block (real UltraCam Eagle images, tests/data/borea): the six images
    resected by the algorithm from their tie-point measurements (as lcp rows) and IGN's
    ground coordinates of the tie points (Lambert-93, ellipsoidal heights), in one run; IGN's
    centre altitudes made ellipsoidal heights with the RAF20 geoid. Each centre within 5
    sigma + 8 cm of IGN's, its height after IGN's map-scale effect on the flying height
    (test_borea_resection.py), the angles within 5 sigma + 2e-5 rad; at most 5 % of the
    points rejected."""
    from pyproj import Proj, Transformer

    camera, opk, meas = _camera(), _opk(), _measurements()
    write_camera_json(tmp_path / "camera.json", camera)
    obs, ctrl = [], {}
    for image, (px, pts) in meas.items():
        xyz = pts  # IGN's ground coordinates of the tie points: ellipsoidal heights
        for p, x in zip(px, xyz):
            pid = f"{x[0]:.3f}_{x[1]:.3f}_{x[2]:.3f}"  # the same ground point in every image
            ctrl[pid] = x
            obs.append((image, pid, repr(float(p[0])), repr(float(p[1])), "0.5", "lcp", pid))
    with open(tmp_path / "obs.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(("image_id", "point_id", "col", "row", "sigma_px", "type", "target_id"))
        w.writerows(obs)
    with open(tmp_path / "ctrl.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(("point_id", "X", "Y", "Z"))
        w.writerows((k, *map(repr, map(float, v))) for k, v in ctrl.items())
    result = run_job(resection, {"CAMERA": str(tmp_path / "camera.json"),
                                 "OBSERVATIONS": str(tmp_path / "obs.csv"),
                                 "CONTROL_POINTS": str(tmp_path / "ctrl.csv"),
                                 "CRS": "EPSG:2154", "OUTPUT_EO": str(tmp_path / "eo.csv")})
    assert result.results["IMAGE_COUNT"] == len(meas) == 6
    to_geo = Transformer.from_crs("EPSG:2154", "EPSG:4171", always_xy=True)
    for r in _rows(tmp_path / "eo.csv"):
        ign = opk[r["image_id"]]
        centre = _altitude_to_ellipsoidal(ign[None, :3])[0]
        xyz = np.array([float(r[c]) for c in ("X", "Y", "Z")])
        ang = np.array([float(r[c]) for c in ("omega_deg", "phi_deg", "kappa_deg")])
        sig = np.array([float(r[c]) for c in RESECTION_EO_COLUMNS[9:15]])
        n = len(meas[r["image_id"]][0])
        ground = np.mean(meas[r["image_id"]][1], axis=0)
        k = Proj("EPSG:2154").get_factors(*to_geo.transform(*ground[:2])).meridional_scale
        scale_dz = (centre[2] - ground[2]) * (1.0 / k - 1.0)
        d = xyz - centre
        assert np.all(np.abs(d[:2]) < 5 * sig[:2] + 0.08), (r["image_id"], d, sig)
        assert abs(d[2] - scale_dz) < 5 * sig[2] + 0.05, (r["image_id"], d[2], scale_dz)
        assert np.all(np.abs(np.radians(_angle(ang - ign[3:]))) < 5 * np.radians(sig[3:]) + 2e-5)
        assert int(r["rejected"]) < 0.05 * n
        assert 0.2 < float(r["sigma0"]) < 2.0


def test_zero_length_image_line_names_image_and_line(scene_files, tmp_path):
    """Both points of one image line 0.5 px apart: refused, naming the image and the line."""
    _, data, files = scene_files
    rows = _rows(files["observations"])
    target = data.line_ids[2]
    first = next(r for r in rows if r["type"] == "line" and r["target_id"] == target)
    for r in rows:
        if r["type"] == "line" and r["target_id"] == target and r is not first:
            r["col"] = repr(float(first["col"]) + 0.5)
            r["row"] = first["row"]
    with open(tmp_path / "obs.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    v = _values(files, tmp_path, OBSERVATIONS=str(tmp_path / "obs.csv"))
    with pytest.raises(InputError, match=f"image img1: image line {target} has zero length"):
        run_job(resection, v)
    assert not (tmp_path / "eo.csv").exists()


def test_control_rows_join_the_control_points_by_point_id(scene_files, tmp_path):
    """The point rows as locatecontrolpoints writes them (type control, point_id = the
    control point's id, empty target): the same orientation as the lcp rows; a control row
    naming no control point is refused with its file and row."""
    from lidarphoto.core.io.observations import read_observations_csv, write_observations_csv

    _, _data, files = scene_files
    obs = read_observations_csv(files["observations"])
    lcp = obs.mask("lcp")
    assert lcp.sum() >= 4
    kinds = tuple("control" if m else t for m, t in zip(lcp, obs.type))
    pid = tuple(g if m else p for m, p, g in zip(lcp, obs.point_id, obs.target_id))
    target = tuple("" if m else g for m, g in zip(lcp, obs.target_id))
    control = replace(obs, type=kinds, point_id=pid, target_id=target, rows=(), source="")
    write_observations_csv(tmp_path / "control.csv", control)
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    run_job(resection, _values(files, tmp_path / "a"))
    run_job(resection, _values(files, tmp_path / "b", OBSERVATIONS=str(tmp_path / "control.csv")))
    a, b = _rows(tmp_path / "a" / "eo.csv")[0], _rows(tmp_path / "b" / "eo.csv")[0]
    assert int(b["points"]) == int(lcp.sum())
    for c in ("X", "Y", "Z", "omega_deg", "phi_deg", "kappa_deg", "sigma0"):
        assert float(b[c]) == pytest.approx(float(a[c]), rel=1e-9, abs=1e-9), c
    k = int(np.flatnonzero(lcp)[1])
    bad = replace(control, point_id=control.point_id[:k] + ("NOPE",) + control.point_id[k + 1:])
    write_observations_csv(tmp_path / "bad.csv", bad)
    with pytest.raises(InputError, match=r"NOPE.*CONTROL_POINTS") as err:
        run_job(resection, _values(files, tmp_path, OBSERVATIONS=str(tmp_path / "bad.csv")))
    assert f"row {k + 2}" in str(err.value) and "bad.csv" in str(err.value)
