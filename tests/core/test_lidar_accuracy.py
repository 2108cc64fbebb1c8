"""LiDAR product accuracy (ASPRS Ed. 2): swath overlap difference, within-swath precision and
NVA/VVA against synthetic truth and independent computations."""

from __future__ import annotations

import json
import math

import laspy
import numpy as np
import pytest
from lidarphoto.core.jobs import lidar_accuracy
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.quality.lidar_accuracy import CheckPointSet, LidarCloud, assess_lidar
from lidarphoto.core.quality.lidar_accuracy_options import LidarAccuracyOptions
from lidarphoto.core.quality.lidar_swaths import CellGrid, identify_swaths, swath_cells
from lidarphoto.core.quality.lidar_vertical import CheckHeights, ground_tin_heights

OFFSET = 0.05  # m, swath B above the truth
ROLL = 0.001  # rad: swath B's height error grows by 1 mm per metre across its track
NOISE = 0.015  # m, ranging noise per return
VEG = (10.0, 20.0, 25.0, 35.0)  # x0, x1, y0, y1 of a tree patch in the overlap
BUILDING = (50.5, 60.5, 24.5, 35.5)  # a flat roof 6 m up, edges not on cell borders


def _ground(x, y):
    return 5.0 + 0.02 * x + 0.01 * y


def _inside(x, y, box):
    return (x >= box[0]) & (x < box[1]) & (y >= box[2]) & (y < box[3])


def _swath(rng, y0, y1, t0, reverse, density=8.0):
    """Returns of one swath over x 0-80 m, y0-y1, flying along +x (or -x) at 50 m/s."""
    n = int(80 * (y1 - y0) * density)
    x = rng.uniform(0, 80, n)
    y = rng.uniform(y0, y1, n)
    z = _ground(x, y)
    cls = np.full(n, 2, np.uint8)
    nret = np.ones(n, np.uint8)
    roof = _inside(x, y, BUILDING)
    z[roof] += 6.0
    cls[roof] = 6
    tree = _inside(x, y, VEG)
    canopy = tree & (rng.uniform(size=n) < 0.5)
    z[canopy] += rng.uniform(2.0, 10.0, int(canopy.sum()))
    cls[canopy] = 5
    nret[tree] = 2
    t = t0 + ((80 - x) if reverse else x) / 50.0
    return x, y, z + rng.normal(0, NOISE, n), cls, nret, t


def _survey(seed=1):
    rng = np.random.default_rng(seed)
    a = _swath(rng, 0.0, 40.0, 1000.0, False)
    b = list(_swath(rng, 20.0, 60.0, 2000.0, True))
    b[2] = b[2] + OFFSET + ROLL * (b[1] - 40.0)  # B flies -x: its track centre is y = 40
    cols = [np.concatenate([p, q]) for p, q in zip(a, b)]
    ids = np.r_[np.full(a[0].size, 11), np.full(b[0].size, 12)]
    x, y, z, cls, nret, t = cols
    return LidarCloud(x, y, z, cls, nret, ids, t, "synthetic")


def test_overlap_difference_recovers_offset_and_roll():
    cloud = _survey()
    rep = assess_lidar(cloud, LidarAccuracyOptions())
    assert rep.swath_method == "point_source_id"
    (pair,) = rep.pairs
    assert (pair.swath_a, pair.swath_b) == (11, 12)
    # dz = A - B = -(OFFSET + ROLL (y - 40)); the tilt plane is centred on the cells' mean
    c0, gx, gy = pair.tilt
    se = pair.tilt_se
    ym = pair.y.mean()
    assert abs(c0 + OFFSET + ROLL * (ym - 40.0)) < 4 * se[0]
    assert abs(gy + ROLL) < 4 * se[2]
    assert abs(gx) < 4 * se[1]
    # swath 11 flies +x: its left is +y, so the cross-track slope is gy
    assert pair.cross_track_slope == pytest.approx(gy, abs=2e-6)  # heading from x(t), y(t)
    # the sampling error is what the noise predicts: each cell height has sigma ~ NOISE/sqrt(n)
    assert se[0] < 3 * NOISE * math.sqrt(2 / 8) / math.sqrt(pair.n)
    # within-swath precision: the pooled plane residual rms estimates the noise
    for p in rep.precision:
        dof = p.cells * 5
        assert abs(p.rms - NOISE) < 4 * NOISE / math.sqrt(2 * dof)


def test_vegetation_and_building_edges_are_not_smooth():
    cloud = _survey()
    o = LidarAccuracyOptions()
    grid = CellGrid.covering(cloud.x, cloud.y, o.cell_size)
    cells = swath_cells(cloud.x, cloud.y, cloud.z, cloud.point_source_id, grid, o,
                        cloud.classification, cloud.number_of_returns)  # fmt: skip
    cx, cy = grid.centres(cells.cell)
    half = o.cell_size / 2
    in_tree = ((cx + half > VEG[0]) & (cx - half < VEG[1]) & (cy + half > VEG[2])
               & (cy - half < VEG[3]))  # fmt: skip
    x0, x1, y0, y1 = BUILDING
    on_edge = (((np.abs(cx - x0) < half) | (np.abs(cx - x1) < half)) & (cy > y0) & (cy < y1)) | (
        ((np.abs(cy - y0) < half) | (np.abs(cy - y1) < half)) & (cx > x0) & (cx < x1)
    )
    assert in_tree.sum() > 100 and on_edge.sum() > 50  # the planted features are there
    assert not np.any(cells.smooth & in_tree)
    assert not np.any(cells.smooth & on_edge)
    assert cells.rejected["vegetation class"] + cells.rejected["multiple returns"] > 100
    # a step in a cell tilts its plane (slope) or leaves large residuals (rough)
    assert cells.rejected["slope"] + cells.rejected["rough"] >= on_edge.sum() * 0.9
    # the flat roof's interior is hard and smooth
    roof = _inside(cx, cy, (x0 + 2, x1 - 2, y0 + 2, y1 - 2)) & (cells.n >= o.min_points)
    assert roof.sum() > 50 and np.mean(cells.smooth[roof]) > 0.9


def test_rmsdz_matches_an_independent_fit_on_the_same_cells():
    cloud = _survey(seed=3)
    o = LidarAccuracyOptions()
    rep = assess_lidar(cloud, o)
    (pair,) = rep.pairs
    pick = np.arange(0, pair.n, 37)  # a sample of the common smooth cells
    half = o.cell_size / 2
    dz = []
    for k in pick:
        h = []
        for s in (11, 12):
            m = ((cloud.point_source_id == s) & (np.abs(cloud.x - pair.x[k]) < half)
                 & (np.abs(cloud.y - pair.y[k]) < half))  # fmt: skip
            a = np.column_stack([np.ones(m.sum()), cloud.x[m] - pair.x[k], cloud.y[m] - pair.y[k]])
            h.append(np.linalg.lstsq(a, cloud.z[m], rcond=None)[0][0])
        dz.append(h[0] - h[1])
    np.testing.assert_allclose(pair.dz[pick], dz, atol=1e-9)


def test_same_figures_whatever_the_point_order():
    cloud = _survey(seed=4)
    perm = np.random.default_rng(9).permutation(cloud.x.size)
    shuffled = LidarCloud(*(getattr(cloud, f)[perm] for f in ("x", "y", "z", "classification",
                          "number_of_returns", "point_source_id", "gps_time")))  # fmt: skip
    a = assess_lidar(cloud, LidarAccuracyOptions())
    b = assess_lidar(shuffled, LidarAccuracyOptions())
    assert np.array_equal(a.pairs[0].dz, b.pairs[0].dz)
    assert a.overall == b.overall


def test_swaths_from_gps_time_gaps():
    cloud = _survey()
    labels, method = identify_swaths(None, cloud.gps_time, "auto", 10.0)
    assert method == "gps_time"
    assert np.array_equal(labels, (cloud.point_source_id == 12).astype(int))
    labels, method = identify_swaths(np.full(cloud.x.size, 7), cloud.gps_time)
    assert method == "gps_time"  # one id only: the GPS time tells the swaths apart


def _checkpoints(n_open, n_veg, seed=5):
    rng = np.random.default_rng(seed)
    xy = rng.uniform(5, 55, (n_open + n_veg, 2))
    err = rng.normal(0, 0.05, n_open + n_veg)
    h = _ground(xy[:, 0], xy[:, 1]) + err  # surveyed height = truth + planted error
    groups = ("open",) * n_open + ("forest",) * n_veg
    ids = tuple(f"cp{i}" for i in range(len(h)))
    return CheckPointSet(ids, np.column_stack([xy, h]), groups, "synthetic"), err


def test_nva_vva_exact_against_independent_computation():
    rng = np.random.default_rng(6)
    gx, gy = rng.uniform(0, 80, 4000), rng.uniform(0, 80, 4000)
    ground = np.column_stack([gx, gy, _ground(gx, gy)])  # a planar TIN: exact at any point
    cps, err = _checkpoints(35, 9)
    heights = ground_tin_heights(ground, cps.xyz[:, :2], radius=10.0)
    np.testing.assert_allclose(heights.lidar_h, _ground(cps.xyz[:, 0], cps.xyz[:, 1]), atol=1e-9)
    cloud = LidarCloud(gx, gy, ground[:, 2], np.full(gx.size, 2), None, np.zeros(gx.size), None)
    o = LidarAccuracyOptions(survey_sigma_v=0.02, v_class_cm=10.0)
    f = assess_lidar(cloud, o, cps).vertical
    dz = -err  # LiDAR (truth) - check (truth + err)
    nva, vva = dz[:35], dz[35:]
    rmse1 = math.sqrt(sum(d * d for d in nva) / 35)
    assert f.nva_n == 35 and f.vva_n == 9
    assert abs(f.nva_rmse_v1 - rmse1) < 1e-6
    assert abs(f.nva_rmse_v - math.sqrt(rmse1**2 + 0.02**2)) < 1e-6
    assert abs(f.nva_95 - 1.96 * math.sqrt(rmse1**2 + 0.02**2)) < 1e-6
    assert abs(f.vva_rmse - math.sqrt(sum(d * d for d in vva) / 9)) < 1e-6
    s = sorted(abs(d) for d in vva)  # 95th percentile, linear between order statistics
    rank = 0.95 * (len(s) - 1)
    lo = int(rank)
    p95 = s[lo] + (rank - lo) * (s[lo + 1] - s[lo])
    assert abs(f.vva_p95 - p95) < 1e-6


def test_tin_is_not_the_nearest_return():
    g = np.array([[0, 0, 0.0], [1, 0, 1.0], [0, 1, 0.0], [1, 1, 1.0]])
    h = ground_tin_heights(g, np.array([[0.3, 0.5]]), radius=5)
    assert h.lidar_h[0] == pytest.approx(0.3, abs=1e-12)  # nearest return would say 0


def test_counts_below_the_minimum_are_reported():
    rng = np.random.default_rng(7)
    gx, gy = rng.uniform(0, 80, 3000), rng.uniform(0, 80, 3000)
    cloud = LidarCloud(gx, gy, _ground(gx, gy), np.full(gx.size, 2), None, np.zeros(gx.size))
    cps, _ = _checkpoints(12, 2)
    rep = assess_lidar(cloud, LidarAccuracyOptions(v_class_cm=10.0), cps)
    status = {v.name: v.status for v in rep.verdicts}
    assert status["NVA check-point count"] == "insufficient"
    assert status["NVA class 10-cm"] == "insufficient"
    assert status["VVA (reported, no pass/fail in Ed. 2)"] == "insufficient"


def _write_las(path, cloud):
    header = laspy.LasHeader(point_format=1, version="1.2")
    header.scales = [0.001, 0.001, 0.001]
    header.offsets = [0.0, 0.0, 0.0]
    las = laspy.LasData(header)
    las.x, las.y, las.z = cloud.x, cloud.y, cloud.z
    las.classification = cloud.classification
    las.number_of_returns = cloud.number_of_returns
    las.return_number = np.ones(cloud.x.size, np.uint8)
    las.point_source_id = cloud.point_source_id
    las.gps_time = cloud.gps_time
    las.write(str(path))


def test_job_writes_report_json_raster_and_checkpoint_table(tmp_path):
    cloud = _survey(seed=8)
    _write_las(tmp_path / "survey.las", cloud)
    cps, _ = _checkpoints(30, 5)
    lines = ["id,e,n,h,group"] + [f"{i},{float(p[0])!r},{float(p[1])!r},{float(p[2])!r},{g}"
                                  for i, p, g in zip(cps.ids, cps.xyz, cps.groups)]  # fmt: skip
    (tmp_path / "cp.csv").write_text("\n".join(lines) + "\n")
    seen = []
    res = run_job(lidar_accuracy, {
        "INPUT": [str(tmp_path)], "CHECKPOINTS": str(tmp_path / "cp.csv"), "V_CLASS_CM": 10,
        "OUTPUT_HTML": str(tmp_path / "r.html"), "OUTPUT_JSON": str(tmp_path / "r.json"),
        "OUTPUT_RASTER": str(tmp_path / "dz.tif"),
        "OUTPUT_CHECKPOINTS": str(tmp_path / "cp_lidar.csv"),
    }, progress=seen.append)  # fmt: skip
    assert seen[-1] == pytest.approx(1.0)
    d = json.loads((tmp_path / "r.json").read_text())
    from lidarphoto.core.quality.lidar_accuracy import LIDAR_JSON_TOP_KEYS

    assert tuple(d) == LIDAR_JSON_TOP_KEYS
    assert d["swath_method"] == "point_source_id" and d["raster_bands"] == ["11-12"]
    assert d["pairs"][0]["rmsdz"] == res.results["RMSDZ"]
    # the millimetre LAS scale leaves the ground within 0.5 mm: the check points' planted errors
    assert d["vertical"]["nva_n"] == 30 and d["vertical"]["vva_n"] == 5
    from lidarphoto.core.io.raster import read_geotiff

    dz, _gt, _ = read_geotiff(tmp_path / "dz.tif")
    assert np.count_nonzero(np.isfinite(dz)) == d["pairs"][0]["n"]
    assert "swath-to-swath RMSDz" in (tmp_path / "r.html").read_text()
    text = (tmp_path / "cp_lidar.csv").read_text().splitlines()
    assert text[0] == "id,e,n,h,e_ref,n_ref,h_ref,group" and len(text) == 36


def test_job_stops_when_asked(tmp_path):
    from lidarphoto.core.errors import Cancelled

    cloud = _survey(seed=2)
    _write_las(tmp_path / "s.las", cloud)
    with pytest.raises(Cancelled):
        run_job(lidar_accuracy, {"INPUT": [str(tmp_path / "s.las")],
                                 "OUTPUT_HTML": str(tmp_path / "r.html")},
                should_stop=lambda: True)  # fmt: skip
    assert not (tmp_path / "r.html").exists()


def test_pair_count_below_minimum_is_insufficient():
    cloud = _survey()
    rep = assess_lidar(cloud, LidarAccuracyOptions(min_pair_cells=10**6, v_class_cm=10.0))
    st = {v.name: v.status for v in rep.verdicts}
    assert st["swaths 11-12: swath-to-swath RMSDz"] == "insufficient"


def test_heights_outside_the_tin_are_listed():
    g = np.array([[0, 0, 0.0], [1, 0, 1.0], [0, 1, 0.0]])
    h = ground_tin_heights(g, np.array([[5.0, 5.0]]), radius=100)
    assert np.isnan(h.lidar_h[0]) and isinstance(h, CheckHeights)


def test_tin_heights_match_scipy_linear_interpolation():
    from scipy.interpolate import LinearNDInterpolator

    rng = np.random.default_rng(10)
    g = np.column_stack([rng.uniform(0, 30, 2000), rng.uniform(0, 30, 2000),
                         rng.normal(0, 1, 2000)])  # fmt: skip
    q = np.vstack([rng.uniform(2, 28, (40, 2)), [[-5.0, -5.0]]])
    h = ground_tin_heights(g, q, radius=100.0)
    ref = LinearNDInterpolator(g[:, :2], g[:, 2])(q)
    np.testing.assert_allclose(h.lidar_h[:-1], ref[:-1], atol=1e-9)
    assert np.isnan(h.lidar_h[-1]) and np.isnan(ref[-1])


def test_ahn3_overlap_difference_matches_an_independent_computation():
    """Three AHN3 flight lines (tests/data/ahn3_swaths): every pair's dz on its smooth cells,
    and so RMSDz and max |dz|, recomputed from the raw returns of laspy with numpy lstsq."""
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "data" / "ahn3_swaths" / "ahn3_delft_swaths30.laz"
    las = laspy.read(str(path))
    x, y, z = (np.asarray(las[k], dtype=float) for k in ("x", "y", "z"))
    ids = np.asarray(las.point_source_id)
    # the GPS-time gaps find the same three flight lines (one label per id, one id per label)
    labels, method = identify_swaths(None, np.asarray(las.gps_time), "gps_time", 10.0)
    pairs = set(zip(labels.tolist(), ids.tolist()))
    assert method == "gps_time" and len(pairs) == 3 == len({a for a, _ in pairs})
    res = run_job(lidar_accuracy, {"INPUT": [str(path)]})
    rep = res.data
    assert rep.swath_method == "point_source_id"
    assert [(p.swath_a, p.swath_b) for p in rep.pairs] == [(44266, 57138), (44266, 57139),
                                                           (57138, 57139)]  # fmt: skip
    half = rep.options.cell_size / 2
    for p in rep.pairs:
        assert p.n > 100
        dz = []
        for cx, cy in zip(p.x, p.y):
            # a cell holds its west and north edges (rows counted from the top)
            cell = (x >= cx - half) & (x < cx + half) & (y > cy - half) & (y <= cy + half)
            h = []
            for s in (p.swath_a, p.swath_b):
                m = cell & (ids == s)
                a = np.column_stack([np.ones(m.sum()), x[m] - cx, y[m] - cy])
                h.append(np.linalg.lstsq(a, z[m], rcond=None)[0][0])
            dz.append(h[0] - h[1])
        dz = np.asarray(dz)
        st = p.stats()
        assert st["rmsdz"] == pytest.approx(float(np.sqrt(np.mean(dz**2))), abs=1e-9)
        assert st["max_abs"] == pytest.approx(float(np.max(np.abs(dz))), abs=1e-9)
        assert st["rmsdz"] < 0.05  # AHN3's stated systematic and stochastic errors: 5 cm each


def test_checkpoint_table_feeds_the_accuracy_report(tmp_path):
    """OUTPUT_CHECKPOINTS read by accuracyreport: its ASPRS RMSE_U is our NVA RMSE (all points
    non-vegetated), its horizontal discrepancies zero."""
    from lidarphoto.core.jobs import accuracy_report

    cloud = _survey(seed=8)
    _write_las(tmp_path / "survey.las", cloud)
    cps, _ = _checkpoints(30, 0, seed=12)
    rows = [f"{i},{float(p[0])!r},{float(p[1])!r},{float(p[2])!r},open"
            for i, p in zip(cps.ids, cps.xyz)]  # fmt: skip
    (tmp_path / "cp.csv").write_text("id,e,n,h,group\n" + "\n".join(rows) + "\n")
    ours = run_job(lidar_accuracy, {
        "INPUT": [str(tmp_path / "survey.las")], "CHECKPOINTS": str(tmp_path / "cp.csv"),
        "OUTPUT_HTML": str(tmp_path / "r.html"), "OUTPUT_CHECKPOINTS": str(tmp_path / "t.csv"),
    })  # fmt: skip
    theirs = run_job(accuracy_report, {"INPUT": str(tmp_path / "t.csv"),
                                       "OUTPUT_HTML": str(tmp_path / "a.html")})  # fmt: skip
    assert ours.data.vertical.nva_n == 30
    assert theirs.results["RMSE_U"] == pytest.approx(ours.results["NVA_RMSE"], abs=1e-9)
    assert theirs.results["RMSE_HORIZONTAL"] == 0.0


def test_bad_inputs_are_named(tmp_path):
    from lidarphoto.core.errors import InputError

    (tmp_path / "empty").mkdir()
    with pytest.raises(InputError, match="INPUT holds no LAS/LAZ"):
        run_job(lidar_accuracy, {"INPUT": [str(tmp_path / "empty")],
                                 "OUTPUT_HTML": str(tmp_path / "r.html")})  # fmt: skip
    _write_las(tmp_path / "s.las", _survey(seed=2))
    with pytest.raises(InputError, match="OUTPUT_CHECKPOINTS needs"):
        run_job(lidar_accuracy, {"INPUT": [str(tmp_path / "s.las")],
                                 "OUTPUT_CHECKPOINTS": str(tmp_path / "c.csv"),
                                 "OUTPUT_HTML": str(tmp_path / "r.html")})  # fmt: skip
    with pytest.raises(InputError, match="HARD_CLASSES"):
        run_job(lidar_accuracy, {"INPUT": [str(tmp_path / "s.las")], "HARD_CLASSES": "2,x",
                                 "OUTPUT_HTML": str(tmp_path / "r.html")})  # fmt: skip
    assert not (tmp_path / "r.html").exists()


def test_tiled_run_equals_the_single_process(tmp_path):
    """TILE_SIZE on a local dask cluster (threads): the same cells, the same dz to the bit,
    the same NVA; the flight directions from merged tile sums agree to 1e-9 rad."""
    cloud = _survey(seed=13)
    # two files, split across the overlap: cells on the seam need both
    half = cloud.x < 37.3
    for name, m in (("a.las", half), ("b.las", ~half)):
        part = LidarCloud(*(getattr(cloud, f)[m] for f in ("x", "y", "z", "classification",
                          "number_of_returns", "point_source_id", "gps_time")))  # fmt: skip
        _write_las(tmp_path / name, part)
    cps, _ = _checkpoints(30, 5, seed=14)
    rows = [f"{i},{float(p[0])!r},{float(p[1])!r},{float(p[2])!r},{g}"
            for i, p, g in zip(cps.ids, cps.xyz, cps.groups)]  # fmt: skip
    (tmp_path / "cp.csv").write_text("id,e,n,h,group\n" + "\n".join(rows) + "\n")
    base = {
        "INPUT": [str(tmp_path / "a.las"), str(tmp_path / "b.las")],
        "CHECKPOINTS": str(tmp_path / "cp.csv"),
        "OUTPUT_HTML": str(tmp_path / "r.html"),
    }
    one = run_job(lidar_accuracy, base).data
    tiled = run_job(lidar_accuracy, {**base, "TILE_SIZE": 17.0, "WORKERS": 2,
                                     "LOCAL_CLUSTER": "threads"}).data  # fmt: skip
    assert one.swath_counts == tiled.swath_counts
    assert np.array_equal(one.cells.cell, tiled.cells.cell)
    assert np.array_equal(one.cells.smooth, tiled.cells.smooth)
    assert one.cells.rejected == tiled.cells.rejected
    for a, b in zip(one.pairs, tiled.pairs, strict=True):
        assert np.array_equal(a.dz, b.dz)
        assert a.cross_track_slope == pytest.approx(b.cross_track_slope, abs=1e-9)
    assert one.overall == tiled.overall
    assert tiled.vertical.nva_rmse_v == pytest.approx(one.vertical.nva_rmse_v, abs=1e-12)
    assert tiled.vertical.nva_n == one.vertical.nva_n


def test_html_map_is_bounded_on_large_surveys(monkeypatch):
    from lidarphoto.core.quality import lidar_accuracy_html

    rep = assess_lidar(_survey(), LidarAccuracyOptions())
    full = lidar_accuracy_html.render_html(rep).count("<rect")
    monkeypatch.setattr(lidar_accuracy_html, "MAP_MAX_CELLS", 100)
    small = lidar_accuracy_html.render_html(rep).count("<rect")
    assert small < full and small - (full - rep.pairs[0].n) <= 100


def test_tiled_run_stops_when_asked(tmp_path):
    from lidarphoto.core.errors import Cancelled

    _write_las(tmp_path / "s.las", _survey(seed=2))
    with pytest.raises(Cancelled):
        run_job(lidar_accuracy, {"INPUT": [str(tmp_path / "s.las")], "TILE_SIZE": 20.0,
                                 "WORKERS": 1, "LOCAL_CLUSTER": "threads",
                                 "OUTPUT_HTML": str(tmp_path / "r.html")},
                should_stop=lambda: True)  # fmt: skip
    assert not (tmp_path / "r.html").exists()
