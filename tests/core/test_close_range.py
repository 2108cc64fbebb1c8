"""Close-range networks: a local engineering frame (no CRS, m or mm) and scale bars.

A simulated convergent network: 20 images on a ring 2 m around a 1 m target field (60
targets with 0.2 m of depth), every other image rolled by 90 degrees, 0.1 px image noise.
"""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.collinearity import project_with_status
from lidarphoto.core.geometry.engineering import EngineeringFrame
from lidarphoto.core.geometry.rotations import matrix_to_opk
from lidarphoto.core.io.scale_bars import read_scale_bars_csv
from lidarphoto.core.photo.bundle import bundle_adjust
from lidarphoto.core.photo.bundle_setup import BundleOptions, GroundPoints
from lidarphoto.core.photo.observations import ImageObservations
from lidarphoto.core.photo.orientation import ExteriorOrientationTable
from lidarphoto.core.photo.scale_bars import DistanceModel, ScaleBars

NOISE_PX = 0.1
PLAIN = {"robust": "none", "snooping": False, "ap_selection": False}


def _look_at(centre: np.ndarray, target: np.ndarray, roll: float) -> np.ndarray:
    """omega, phi, kappa of a camera at ``centre`` looking at ``target`` (camera -z)."""
    z = centre - target
    z /= np.linalg.norm(z)
    x = np.cross([0.0, 0.0, 1.0], z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    c, s = np.cos(roll), np.sin(roll)
    x, y = c * x + s * y, -s * x + c * y
    m = np.vstack([x, y, z])  # rows: the camera axes in object space = world-to-camera M
    return np.array(matrix_to_opk(m[None])).ravel()


def _network(seed: int = 7):
    """Truth (metres) and the measurements: camera, points (P, 3), EO (M, 6), observations."""
    rng = np.random.default_rng(seed)
    cam = Camera("cr", focal_mm=20.0, pixel_size_mm=0.005, width_px=4000, height_px=3000)
    pts = np.column_stack([rng.uniform(-0.5, 0.5, (60, 2)), rng.uniform(0.0, 0.2, 60)])
    eo = []
    for k in range(20):
        az = 2 * np.pi * k / 20
        el = np.radians(35.0 if k % 2 else 55.0)
        c = 2.0 * np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
        eo.append(np.r_[c, _look_at(c, np.array([0.0, 0.0, 0.1]), np.pi / 2 * (k % 2))])
    eo = np.array(eo)
    img, pid, px = [], [], []
    for k, e in enumerate(eo):
        p, front, ok = project_with_status(pts, e, cam)
        good = front & ok & cam.in_frame(p)
        for i in np.flatnonzero(good):
            img.append(f"I{k:02d}")
            pid.append(f"P{i:02d}")
            px.append(p[i] + rng.normal(0.0, NOISE_PX, 2))
    n = len(img)
    obs = ImageObservations(tuple(img), tuple(pid), np.array(px), np.full(n, NOISE_PX),
                            ("tie",) * n, ("",) * n)  # fmt: skip
    return cam, pts, eo, obs, rng


@pytest.fixture(scope="module")
def net():
    return _network()


def _eo_table(eo: np.ndarray, rng, unit: float) -> ExteriorOrientationTable:
    """Approximate orientations (5 mm, 1 degree off) in a frame of ``unit`` metres."""
    off = np.c_[rng.normal(0, 0.005, (len(eo), 3)), rng.normal(0, np.radians(1.0), (len(eo), 3))]
    approx = eo + off
    ids = tuple(f"I{k:02d}" for k in range(len(eo)))
    return ExteriorOrientationTable(ids, np.full(len(eo), np.nan), ("",) * len(eo),
                                    approx[:, :3] / unit, approx[:, 3:], "")  # fmt: skip


def _control(pts: np.ndarray, unit: float, sigma_m: float = 2e-5, seed: int = 4) -> GroundPoints:
    """Eight control points (spread around the field), surveyed with ``sigma_m`` (the
    coordinates drawn with that noise, so that the datum's uncertainty is real)."""
    idx = np.argsort(np.arctan2(pts[:, 1], pts[:, 0]))[::8][:8]
    ids = tuple(f"P{i:02d}" for i in idx)
    xyz = pts[idx] + np.random.default_rng(seed).normal(0.0, sigma_m, (len(idx), 3))
    return GroundPoints(ids, xyz / unit, np.full((len(idx), 3), sigma_m / unit),
                        ("control",) * len(idx))  # fmt: skip


def _points(res) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    return {p: (x, s) for p, x, s in zip(res.point_id, res.point_xyz, res.point_sigma)}


def test_millimetre_frame_recovers_the_truth_and_equals_the_metre_frame(net):
    """LOCAL:mm: every adjusted target within 3 sigma of the truth (sigma0 near 1), and the
    same network in a metre frame gives the same coordinates and sigmas times 1000."""
    cam, pts, eo, obs, _ = net
    out = {}
    for unit, scale in (("mm", 1e-3), ("m", 1.0)):
        rng = np.random.default_rng(3)
        out[unit] = bundle_adjust([cam], obs, _control(pts, scale), EngineeringFrame(unit),
                                  _eo_table(eo, rng, scale),
                                  options=BundleOptions(**PLAIN))  # fmt: skip
    mm, m = out["mm"], out["m"]
    assert mm.adjustment.converged and 0.9 < mm.sigma0 < 1.1
    got = _points(mm)
    tie = [i for i in range(len(pts)) if f"P{i:02d}" not in _control(pts, 1.0).point_id]
    z = np.array([(got[f"P{i:02d}"][0] - pts[i] * 1000) / got[f"P{i:02d}"][1] for i in tie])
    assert z.shape == (52, 3)
    assert np.abs(z).max() < 4.0 and (np.abs(z) < 3).mean() > 0.98
    # 156 correlated z-scores (one datum for all): their mean square near 1, not a tight chi2
    assert 0.5 < np.mean(z**2) < 1.6
    # the point precision is tens of micrometres: stated in mm, not rounded away
    assert 0.001 < np.median(mm.point_sigma) < 0.1
    assert mm.point_id == m.point_id
    np.testing.assert_allclose(mm.point_xyz, 1000 * m.point_xyz, rtol=0, atol=1e-7)
    np.testing.assert_allclose(mm.point_sigma, 1000 * m.point_sigma, rtol=1e-6)
    np.testing.assert_allclose(mm.eo.xyz, 1000 * m.eo.xyz, rtol=0, atol=1e-7)
    np.testing.assert_allclose(mm.eo.opk, m.eo.opk, rtol=0, atol=1e-11)
    assert abs(mm.sigma0 / m.sigma0 - 1) < 1e-8
    assert mm.eo.crs_wkt == ""


def _bars(pts: np.ndarray, pairs, sigma_mm, error_mm=None) -> ScaleBars:
    d = np.array([np.linalg.norm(pts[a] - pts[b]) * 1000 for a, b in pairs])
    if error_mm is not None:
        d = d + error_mm
    return ScaleBars(tuple(f"P{a:02d}" for a, _ in pairs), tuple(f"P{b:02d}" for _, b in pairs),
                     d, np.broadcast_to(np.asarray(sigma_mm, float), d.shape).copy())  # fmt: skip


def _far_pairs(pts: np.ndarray, n: int, rng) -> list[tuple[int, int]]:
    out: list[tuple[int, int]] = []
    while len(out) < n:
        a, b = (int(v) for v in rng.choice(len(pts), 2, replace=False))
        if np.linalg.norm(pts[a, :2] - pts[b, :2]) > 0.7 and {a, b}.isdisjoint(
                {p for q in out for p in q}):  # fmt: skip
            out.append((a, b))
    return out


@pytest.mark.parametrize("datum", ["inner", "minimal"])
def test_scale_bars_give_the_datum_of_a_free_network(net, datum):
    """No control: inner (or minimal) constraints without scale, three bars at 0.02 mm give
    the scale; distances between other targets (given as bars of no weight, 10 m, so that
    their propagated sigmas come out) match the truth within 3 sigma."""
    cam, pts, eo, obs, _ = net
    rng = np.random.default_rng(11)
    pairs = _far_pairs(pts, 13, rng)
    sig = np.r_[np.full(3, 0.02), np.full(10, 1e4)]
    bars = _bars(pts, pairs, sig)
    res = bundle_adjust([cam], obs, GroundPoints.empty(), EngineeringFrame("mm"),
                        _eo_table(eo, rng, 1e-3),
                        options=BundleOptions(datum=datum, **PLAIN), scale_bars=bars)  # fmt: skip
    assert res.adjustment.converged and res.adjustment.n_constraints == 6
    b = res.scale_bars
    truth = np.array([np.linalg.norm(pts[a] - pts[c]) * 1000 for a, c in pairs])
    err = b.adjusted - truth
    assert np.all(np.abs(err[3:]) < 3 * b.sigma[3:]), (err[3:], b.sigma[3:])
    # the scale comes from the bars: about 0.02 mm / sqrt(3) over about 1 m
    assert 0.003 < np.median(b.sigma[3:]) < 0.03


def test_a_bar_with_a_gross_error_is_flagged_by_data_snooping(net):
    cam, pts, eo, obs, _ = net
    rng = np.random.default_rng(5)
    pairs = _far_pairs(pts, 4, rng)
    bars = _bars(pts, pairs, 0.02, error_mm=np.array([0.0, 0.0, 0.5, 0.0]))
    res = bundle_adjust([cam], obs, _control(pts, 1e-3), EngineeringFrame("mm"),
                        _eo_table(eo, rng, 1e-3),
                        options=BundleOptions(robust="none", ap_selection=False,
                                              snooping=True),
                        scale_bars=bars)  # fmt: skip
    b = res.scale_bars
    assert b.rejected.tolist() == [False, False, True, False]
    # the rejected bar's misfit is its planted error (within a few sigma)
    assert abs(-b.v[2] - 0.5) < 0.1
    assert np.all(np.abs(b.w[[0, 1, 3]]) < 3.3)


def test_distance_model_jacobian_matches_finite_differences():
    rng = np.random.default_rng(2)
    x = rng.normal(size=(4, 6))
    _, J = DistanceModel()(x)
    h = 1e-6
    for k in range(6):
        dx = np.zeros(6)
        dx[k] = h
        num = (DistanceModel()(x + dx)[0] - DistanceModel()(x - dx)[0]) / (2 * h)
        np.testing.assert_allclose(J[:, :, k], num, atol=1e-8)


@pytest.mark.parametrize(
    ("text", "message", "row"),
    [
        ("point_a,point_b,distance,sigma\nA,B,1000,0\n", "a standard deviation must be > 0", 2),
        ("point_a,point_b,distance,sigma\nA,B,-1,0.1\n", "a distance must be > 0", 2),
        ("point_a,point_b,distance,sigma\nA,A,1000,0.1\n", "to itself", 2),
        ("point_a,point_b,distance,sigma\nA,B,1000,0.1\nB,A,1000,0.1\n", "given twice", 3),
        ("point_a,point_b,distance,sigma\nA,B,x,0.1\n", "is not a number", 2),
        ("point_a,point_b,sigma\nA,B,0.1\n", "no column for distance", None),
    ],
)
def test_bad_scale_bar_files_are_refused_with_the_row(tmp_path, text, message, row):
    p = tmp_path / "bars.csv"
    p.write_text(text)
    with pytest.raises(InputError, match=message) as info:
        read_scale_bars_csv(p)
    assert str(p) in str(info.value)
    if row is not None:
        assert f"row {row}" in str(info.value)


def test_a_bar_on_an_unknown_or_check_point_is_refused(net, tmp_path):
    cam, pts, eo, obs, _ = net
    p = tmp_path / "bars.csv"
    p.write_text("point_a,point_b,distance,sigma\nP00,P01,100,0.1\nP00,NOPE,100,0.1\n")
    bars = read_scale_bars_csv(p)
    with pytest.raises(InputError, match="'NOPE' is not measured in any image") as info:
        bundle_adjust([cam], obs, _control(pts, 1e-3), EngineeringFrame("mm"),
                      _eo_table(eo, np.random.default_rng(1), 1e-3),
                      options=BundleOptions(**PLAIN), scale_bars=bars)  # fmt: skip
    assert "row 3" in str(info.value)
    ctrl = _control(pts, 1e-3)
    k = next(i for i in range(len(pts)) if f"P{i:02d}" not in ctrl.point_id)
    p.write_text(f"point_a,point_b,distance,sigma\nP{k:02d},{ctrl.point_id[0]},100,0.1\n")
    bars = read_scale_bars_csv(p)
    ground = GroundPoints((*ctrl.point_id, f"P{k:02d}"), np.vstack([ctrl.xyz, pts[k] * 1000]),
                          0.02, ("control",) * 8 + ("check",))  # fmt: skip
    with pytest.raises(InputError, match=f"'P{k:02d}' is a check point"):
        bundle_adjust([cam], obs, ground, EngineeringFrame("mm"),
                      _eo_table(eo, np.random.default_rng(1), 1e-3),
                      options=BundleOptions(**PLAIN), scale_bars=bars)  # fmt: skip


def test_unknown_unit_is_refused():
    with pytest.raises(InputError, match="unit of a local frame"):
        EngineeringFrame("inch")


def test_command_line_local_millimetre_frame_with_scale_bars(net, tmp_path, capsys):
    """``lidarphoto bundleadjustment --frame local_mm --scale-bars ...``: a free network in
    millimetres (no CRS), scale from two bars; every output in mm, the frame named."""
    import csv

    from lidarphoto.core.cli import main
    from lidarphoto.core.io.camera import write_camera_json
    from lidarphoto.core.io.observations import write_observations_csv
    from lidarphoto.core.io.orientation import write_eo_csv

    cam, pts, eo, obs, _ = net
    rng = np.random.default_rng(8)
    write_camera_json(tmp_path / "cam.json", cam)
    write_observations_csv(tmp_path / "obs.csv", obs)
    write_eo_csv(tmp_path / "eo.csv", _eo_table(eo, rng, 1e-3))
    pairs = _far_pairs(pts, 2, rng)
    bars = _bars(pts, pairs, 0.01)
    (tmp_path / "bars.csv").write_text("point_a,point_b,distance,sigma\n" + "".join(
        f"{a},{b},{float(d)!r},{float(s)!r}\n" for a, b, d, s in zip(bars.point_a, bars.point_b,
                                                       bars.distance, bars.sigma)))  # fmt: skip
    code = main(["bundleadjustment", "--camera", str(tmp_path / "cam.json"), "--observations",
                 str(tmp_path / "obs.csv"), "--eo", str(tmp_path / "eo.csv"), "--frame",
                 "local_mm", "--datum", "inner", "--scale-bars", str(tmp_path / "bars.csv"),
                 "--ap-selection", "false", "--output-eo", str(tmp_path / "eo_out.csv"),
                 "--output-points", str(tmp_path / "points.csv"),
                 "--output-scale-bars", str(tmp_path / "bars_out.csv"),
                 "--output-html", str(tmp_path / "summary.html")])  # fmt: skip
    assert code == 0
    printed = capsys.readouterr().out
    assert "frame: local engineering frame (mm)" in printed and "scale bars (2)" in printed
    with open(tmp_path / "points.csv", newline="") as fh:
        rows = {r["point_id"]: r for r in csv.DictReader(fh)}
    # a similarity away from the truth (free network): distances in mm within 0.1 mm
    xyz = np.array([[float(rows[f"P{i:02d}"][c]) for c in "XYZ"] for i in range(len(pts))])
    d_adj = np.linalg.norm(xyz[1:] - xyz[:-1], axis=1)
    d_true = np.linalg.norm(pts[1:] - pts[:-1], axis=1) * 1000
    assert np.abs(d_adj - d_true).max() < 0.1
    with open(tmp_path / "bars_out.csv", newline="") as fh:
        out = list(csv.DictReader(fh))
    assert [r["unit"] for r in out] == ["mm", "mm"]
    page = (tmp_path / "summary.html").read_text()
    assert "local engineering frame (mm)" in page and "RMS col (px)" in page
    assert "sigma X (mm)" in page and "Scale bars" in page


def test_the_job_needs_a_crs_or_a_local_frame_and_bars_for_their_output(net, tmp_path, capsys):
    from lidarphoto.core.cli import main
    from lidarphoto.core.io.camera import write_camera_json
    from lidarphoto.core.io.observations import write_observations_csv

    cam, _, _, obs, _ = net
    write_camera_json(tmp_path / "cam.json", cam)
    write_observations_csv(tmp_path / "obs.csv", obs)
    base = ["bundleadjustment", "--camera", str(tmp_path / "cam.json"), "--observations",
            str(tmp_path / "obs.csv"), "--output-eo", str(tmp_path / "eo_out.csv")]  # fmt: skip
    assert main(base) == 2
    assert "CRS: give the mapping CRS" in capsys.readouterr().err
    assert main([*base, "--frame", "local_mm", "--output-scale-bars",
                 str(tmp_path / "bars.csv")]) == 2  # fmt: skip
    assert "OUTPUT_SCALE_BARS needs the scale bars" in capsys.readouterr().err
    assert not (tmp_path / "eo_out.csv").exists() and not (tmp_path / "bars.csv").exists()
