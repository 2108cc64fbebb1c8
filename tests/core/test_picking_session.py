"""core.photo.picking_session: the picking dock's state without Qt.

Observations with undo/redo; control objects made from layer features (and from the tables,
which replace them by id); picking a tie point and confirming its prediction; the residuals
of a real calibration (the core job the dock runs) following their rows through edits.
Truth: a noise-free simulated flight and its own projection chain (through ECEF)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.geometry.frames import MappingFrame
from lidarphoto.core.io.control import (
    read_lcps_csv,
    read_lines_csv,
    write_lcps_csv,
    write_lines_csv,
)
from lidarphoto.core.io.planes import read_planes_csv, write_planes_csv
from lidarphoto.core.photo.control_features import (
    DEFAULT_LIDAR_SIGMA_M,
    ControlFeature,
    ControlSet,
)
from lidarphoto.core.photo.georeference import direct_georeference
from lidarphoto.core.photo.mount import Mount
from lidarphoto.core.photo.observation_list import Observation, ObservationList
from lidarphoto.core.photo.picking import PickingScene
from lidarphoto.core.photo.picking_session import PickingSession
from lidarphoto.core.simulation.flight import FlightConfig, simulate_flight

CONFIG = FlightConfig(
    n_buildings=9,
    n_planes=24,
    town_size_m=400.0,
    n_check=0,
    types=("tie", "line", "lcp"),
    ties_per_plane=2,
    plane_source="exact",
)


def _obs(k: int, image: str = "a") -> Observation:
    return Observation(image, f"T{k}", 10.0 * k + 0.5, 20.0 * k + 0.5, "tie", str(k))


# ------------------------------------------------------------------------------ observations
def test_observation_list_edits_undo_redo_and_queries():
    log = ObservationList()
    v0 = log.version
    assert log.add([]) == -1 and log.version == v0 and not log.can_undo
    assert log.add(_obs(1)) == 0
    assert log.add([_obs(2), _obs(3, "b")]) == 1  # one edit for the batch
    assert [o.point_id for o in log.rows] == ["T1", "T2", "T3"]
    log.move(1, 5.25, 6.75)
    assert (log.rows[1].col, log.rows[1].row) == (5.25, 6.75)
    assert log.rows[1].point_id == "T2" and log.rows[1].target_id == "2"
    log.delete([2, 0])
    assert [o.point_id for o in log.rows] == ["T2"]
    # undo the deletion: both rows back at their places; then the move; then the batch
    assert log.undo().text == "delete 2 point(s)"
    assert [o.point_id for o in log.rows] == ["T1", "T2", "T3"]
    log.undo()
    assert log.rows[1] == _obs(2)
    log.undo()
    assert log.rows == [_obs(1)]
    assert log.can_redo and log.redo() is not None
    assert len(log.rows) == 3
    # a new edit drops what was undone
    log.undo()
    log.add(_obs(9))
    assert not log.can_redo and log.redo() is None
    assert [o.point_id for o in log.rows] == ["T1", "T9"]
    while log.undo() is not None:
        pass
    assert log.rows == [] and not log.can_undo
    assert log.version > v0
    # queries
    log.reset([_obs(1), _obs(2, "b"), _obs(3)])
    assert not log.can_undo and log.indices_of_image("a") == [0, 2]
    assert log.image_ids() == {"a", "b"}
    assert log.next_point_id("T") == "T4" and log.next_point_id("P") == "P4"
    np.testing.assert_array_equal(log.pixels([2, 0]), [[30.5, 60.5], [10.5, 20.5]])
    assert ObservationList.rows_of(log.to_observations()) == log.rows


# ------------------------------------------------------------------------------ control
@pytest.fixture(scope="module")
def flight():
    """The simulation, its roof outlines (faces) and the EO of the true trajectory and mount."""
    sim = simulate_flight(CONFIG, seed=5, exact=True)
    group = sim.truth.groups[0]
    mount = Mount(sim.truth.lever_arm, sim.mount.nominal, sim.truth.boresight[group])
    eo = direct_georeference(sim.truth.trajectory, mount, MappingFrame.from_user_input(sim.crs))
    faces = {f.face_id: f for f in sim.town.faces}
    outlines = [faces[int(p.id)].polygon for p in sim.planes]
    return sim, eo, outlines


def _features(sim, outlines, with_attributes=False):
    """Layer features as the dock makes them: outlines, segments, points (+ table fields)."""
    planes = [
        ControlFeature(
            str(p.id),
            np.vstack([ring, ring[:1]]),  # a closed ring, as QGIS gives it
            {"a": p.normal[0], "b": p.normal[1], "c": p.normal[2], "d": p.d}
            if with_attributes
            else {},
        )
        for p, ring in zip(sim.planes, outlines)
    ]
    lines = [
        ControlFeature(
            str(ln.id),
            np.array([ln.start, ln.end]),
            {"sigma_perpendicular": 0.02, "plane_1": ln.plane_ids[0], "kind": ln.kind}
            if with_attributes
            else {},
        )
        for ln in sim.lines
    ]
    lcps = [
        ControlFeature(
            str(c.id),
            c.xyz[None],
            dict(zip(("sigma_x", "sigma_y", "sigma_z"), c.sigma)) if with_attributes else {},
        )
        for c in sim.lcps
    ]
    return planes, lines, lcps


def test_control_from_layer_features(flight):
    sim, _eo, outlines = flight
    control = ControlSet.from_features(*_features(sim, outlines))
    assert control.plane_ids == tuple(str(p.id) for p in sim.planes)
    for got, true, ring in zip(control.planes, sim.planes, outlines):
        # fitted to the (exact) outline: the simulation's plane; the ring is kept, open
        np.testing.assert_allclose(got.normal, true.normal, atol=1e-9)
        assert abs(got.distance(true.centroid[None])[0]) < 1e-6
        np.testing.assert_array_equal(got.outline, ring)
        assert got.id == true.id
    for got, true in zip(control.lines, sim.lines):
        np.testing.assert_array_equal([got.start, got.end], [true.start, true.end])
        assert got.sigma_perpendicular == pytest.approx(DEFAULT_LIDAR_SIGMA_M)
        assert got.plane_ids == (-1, -1) and got.kind == "other"
    for got, true in zip(control.lcps, sim.lcps):
        np.testing.assert_array_equal(got.xyz, true.xyz)
        np.testing.assert_allclose(got.sigma, DEFAULT_LIDAR_SIGMA_M)
    heights = np.concatenate([r[:, 2] for r in outlines])
    assert control.ground_height() == pytest.approx(heights.mean())
    # with the tables' fields: plane parameters (heights put on the plane), sigmas, plane ids
    planes, lines, lcps = _features(sim, outlines, with_attributes=True)
    flat = [replace(f, vertices=f.vertices * [1.0, 1.0, np.nan]) for f in planes]
    control = ControlSet.from_features(flat, lines, lcps)
    for got, true, ring in zip(control.planes, sim.planes, outlines):
        np.testing.assert_allclose(got.params, true.params, atol=1e-12)
        np.testing.assert_allclose(got.outline, ring, atol=1e-6)
    assert control.lines[0].sigma_perpendicular == pytest.approx(0.02)
    assert control.lines[0].plane_ids[0] == sim.lines[0].plane_ids[0]
    assert control.lines[0].kind == sim.lines[0].kind
    np.testing.assert_allclose(control.lcps[0].sigma, sim.lcps[0].sigma)
    # reprojected layer: its a,b,c,d no longer apply; no heights and no plane: skipped
    moved = ControlSet.from_features([replace(f, same_crs=False) for f in flat[:3]])
    assert moved.planes == () and moved.skipped == {"planes": 3}
    # not an integer id: kept for display and picking, left out of the calibration
    named = ControlSet.from_features([replace(planes[0], id="roof A"), planes[1]])
    assert named.plane_ids == ("roof A", str(sim.planes[1].id)) and named.planes[0].id == -1
    assert [p.id for p in named.for_calibration()[0]] == [sim.planes[1].id]


def test_tables_replace_layer_objects_and_are_what_the_calibration_reads(flight, tmp_path):
    sim, _eo, outlines = flight
    planes, lines, lcps = _features(sim, outlines)
    # the layers miss the first plane, line and LCP; the tables have everything
    layer = ControlSet.from_features(planes[1:], lines[1:], lcps[1:])
    control = layer.with_tables(sim.planes, sim.lines, sim.lcps)
    assert control.plane_ids == tuple(str(p.id) for p in sim.planes)
    for got, true, ring in zip(control.planes[1:], sim.planes[1:], outlines[1:]):
        np.testing.assert_array_equal(got.covariance, true.covariance)  # the table's
        np.testing.assert_array_equal(got.outline, ring)  # the layer's
    assert len(control.planes[0].outline) == 0  # table only: not drawn, calibrated
    for got, true in zip(control.lines, sim.lines):
        np.testing.assert_array_equal(got.covariance, true.covariance)
    assert control.lcps == tuple(sim.lcps)
    assert layer.with_tables().planes == layer.planes  # no table: the layer's objects
    # what the dock writes for the calibration job is read back as the same objects
    p, ln, c = control.for_calibration()
    write_planes_csv(tmp_path / "planes.csv", p)
    write_lines_csv(tmp_path / "lines.csv", ln)
    write_lcps_csv(tmp_path / "lcps.csv", c)
    back = read_planes_csv(tmp_path / "planes.csv")
    assert [b.id for b in back] == [q.id for q in p]
    for b, q in zip(back, p):
        np.testing.assert_array_equal(b.params, q.params)
        np.testing.assert_array_equal(b.covariance, q.covariance)
    for b, q in zip(read_lines_csv(tmp_path / "lines.csv"), ln):
        np.testing.assert_array_equal(b.covariance, q.covariance)
    for b, q in zip(read_lcps_csv(tmp_path / "lcps.csv"), c):
        np.testing.assert_array_equal(b.xyz, q.xyz)
    # objects from layers only are written and read back too (default precision)
    p, ln, c = ControlSet.from_features(planes, lines, lcps).for_calibration()
    write_planes_csv(tmp_path / "p2.csv", p)
    write_lines_csv(tmp_path / "l2.csv", ln)
    write_lcps_csv(tmp_path / "c2.csv", c)
    assert len(read_planes_csv(tmp_path / "p2.csv")) == len(sim.planes)
    assert len(read_lines_csv(tmp_path / "l2.csv")) == len(sim.lines)
    assert len(read_lcps_csv(tmp_path / "c2.csv")) == len(sim.lcps)


# ------------------------------------------------------------------------------ picking
def test_pick_tie_prediction_line_and_lcp(flight):
    sim, eo, outlines = flight
    session = PickingSession()
    session.control = ControlSet.from_features(*_features(sim, outlines))
    # no CRS anywhere: the camera and the table are kept, there is no scene to pick in
    with pytest.raises(InputError, match="CRS"):
        session.set_orientation(sim.camera, replace(eo, crs_wkt=""))
    assert session.eo is not None and session.scene is None
    assert session.has_orientation(eo.image_id[0]) and not session.oriented(eo.image_id[0])
    session.set_orientation(sim.camera, eo, sim.crs)
    assert isinstance(session.scene, PickingScene)
    obs = sim.observations  # noise-free: the true pixels
    names = np.array(obs.point_id)
    ties = [n for n in np.unique(names[np.array(obs.type) == "tie"])]
    name = next(n for n in ties if (names == n).sum() >= 2)
    a, b = np.flatnonzero(names == name)[:2]
    img_a, img_b = obs.image_id[a], obs.image_id[b]
    assert session.oriented(img_a) and not session.oriented("nowhere")
    targets = session.targets_at(img_a, obs.pixels[a], "tie", 10.0)
    assert targets and targets[0].target_id == obs.target_id[a]
    assert all(t.range_m <= u.range_m for t, u in zip(targets, targets[1:]))
    k = session.add_observation(img_a, obs.pixels[a], targets[0])
    row = session.observations.rows[k]
    assert (row.image_id, row.type, row.target_id, row.point_id) == (
        img_a, "tie", obs.target_id[a], "T1",
    )  # fmt: skip
    pending = session.pending
    assert pending is not None and pending.point_id == "T1"
    assert math.hypot(*(session.prediction(img_b) - obs.pixels[b])) < 1e-3
    # confirm at the prediction in the second image: the same point id
    k2 = session.confirm_prediction(img_b)
    second = session.observations.rows[k2]
    assert (second.image_id, second.point_id, second.target_id) == (img_b, "T1", row.target_id)
    assert session.prediction(img_b) is None
    assert session.confirm_prediction(img_b) == -1
    session.cancel_prediction()
    assert session.pending is None
    # a point on a line, a control point and a check point: the nearest within the tolerance
    proj = session.project(img_a)
    j = int(np.flatnonzero(np.isfinite(proj.lcps).all(axis=1))[0])
    near = proj.lcps[j] + [3.0, -2.0]
    lcp = session.targets_at(img_a, near, "lcp", 5.0, proj)
    assert [t.target_id for t in lcp] == [session.control.lcp_ids[j]]
    assert session.targets_at(img_a, near, "lcp", 2.0, proj) == []
    c = session.add_observation(img_a, near, lcp[0])
    assert session.observations.rows[c].point_id == f"C{lcp[0].target_id}"
    check = session.targets_at(img_a, near, "check", 5.0, proj)[0]
    assert session.observations.rows[session.add_observation(img_a, near, check)].point_id == (
        f"K{check.target_id}"
    )
    i = int(np.flatnonzero(np.isfinite(proj.line_starts).all(axis=1)
                           & np.isfinite(proj.line_ends).all(axis=1))[0])  # fmt: skip
    mid = 0.5 * (proj.line_starts[i] + proj.line_ends[i])
    line = session.targets_at(img_a, mid + 1.0, "line", 5.0)
    assert line and line[0].index == i
    r = session.add_observation(img_a, mid + 1.0, line[0])
    assert session.observations.rows[r].point_id.startswith(f"R{line[0].target_id}_")
    # hit test of the measured points; the footprint holds the image centre's ground point
    assert session.observation_at(img_a, near + 0.5, 2.0) == c
    assert session.observation_at(img_a, near + 50.0, 2.0) is None
    corners = session.footprint(img_a)
    assert corners.shape == (4, 3) and np.isfinite(corners).all()
    assert session.footprint("nowhere") is None
    assert session.targets_at(img_a, (-1e6, -1e6), "tie", 10.0) == []


# ------------------------------------------------------------------------------ calibration
def test_residuals_of_the_calibration_follow_their_rows(flight, tmp_path):
    """The dock's calibration: the core job on the observation file and the control the
    session writes; the residuals come from the result object, matched to the rows."""
    from lidarphoto.core.io.observations import write_observations_csv
    from lidarphoto.core.jobs import boresight_calibration
    from lidarphoto.core.jobs.runner import run_job

    sim, _eo, outlines = flight
    rng = np.random.default_rng(2)
    noisy = replace(
        sim.observations,
        pixels=sim.observations.pixels + rng.normal(0, 0.5, (len(sim.observations), 2)),
    )
    session = PickingSession(ObservationList(ObservationList.rows_of(noisy)))
    layer = ControlSet.from_features(*_features(sim, outlines))
    session.control = layer.with_tables(sim.planes, sim.lines, sim.lcps)
    planes, lines, lcps = session.control.for_calibration()
    write_planes_csv(tmp_path / "planes.csv", planes)
    write_lines_csv(tmp_path / "lines.csv", lines)
    write_lcps_csv(tmp_path / "lcps.csv", lcps)
    write_observations_csv(tmp_path / "obs.csv", session.observations.to_observations())
    paths = sim.write(tmp_path / "sim")  # camera and trajectory (and the tables, not used)
    jr = run_job(boresight_calibration, {
        "CAMERA": str(paths["camera"]), "TRAJECTORY": str(paths["trajectory"]),
        "CRS": sim.crs, "OBSERVATIONS": str(tmp_path / "obs.csv"),
        "LEVER_ARM": ",".join(map(repr, map(float, sim.mount.lever_arm))),
        "MOUNT": "image_top_forward", "BORESIGHT": "0,0,0",
        "PLANES": str(tmp_path / "planes.csv"), "LINES": str(tmp_path / "lines.csv"),
        "LCPS": str(tmp_path / "lcps.csv"), "CONTROL_TYPES": ["tie", "line", "lcp"],
        "OUTPUT_TABLE": str(tmp_path / "boresight.csv"), "OUTPUT_EO": str(tmp_path / "eo.csv"),
        "OUTPUT_HTML": str(tmp_path / "summary.html"),
    })  # fmt: skip
    run = jr.data
    assert session.residuals() == {} and session.boresight_summary() == []
    session.set_calibration(run)
    v = run.result.residuals.v_px
    res = session.residuals()
    finite = np.flatnonzero(np.isfinite(v).all(axis=1))
    assert sorted(res) == finite.tolist() and finite.size > 100
    for k in finite[:20]:
        np.testing.assert_array_equal(res[k], v[k])
    n, rms, vmax = session.residual_stats()
    assert n == finite.size and 0.2 < rms < 1.2 and vmax >= rms
    (group, arcsec, sigma0), *_ = session.boresight_summary()
    g = list(run.result.groups).index(group)
    np.testing.assert_array_equal(arcsec, run.result.boresight_arcsec[g])
    assert sigma0 == jr.results["SIGMA0"]
    # the truth within 3 sigma (what the dock test checks on the written table)
    true = sim.truth.boresight[group] * 180 / math.pi * 3600
    assert np.all(np.abs(arcsec - true) < 3 * run.result.std_arcsec[g] + 0.5)
    # edits: a deleted row takes its residual with it, a moved one loses it, undo restores
    log = session.observations
    first = int(finite[0])
    log.delete(first)
    after = session.residuals()
    assert len(after) == len(res) - 1
    np.testing.assert_array_equal(after[int(finite[1]) - 1], v[finite[1]])
    log.undo()
    log.move(first, log.rows[first].col + 3.0, log.rows[first].row)
    assert first not in session.residuals()
    log.undo()
    np.testing.assert_array_equal(session.residuals()[first], v[first])
    session.set_calibration(None)
    assert session.residuals() == {}


# ------------------------------------------------------------------ undo and the prediction
def _tie_pair(sim):
    """A simulated tie point seen in at least three images: (rows of it, observations)."""
    obs = sim.observations  # noise-free: the true pixels
    names = np.array(obs.point_id)
    for n in np.unique(names[np.array(obs.type) == "tie"]):
        rows = np.flatnonzero(names == n)
        if rows.size >= 3:
            return rows, obs
    raise AssertionError("no tie point in three images")


def test_undo_and_redo_restore_the_prediction_with_the_rows(flight):
    """The pending tie point goes back and forth with its rows: after undoing a tie point no
    image predicts it (Enter would add it to one image only); redo brings the prediction back;
    undoing its measurement in a second image predicts it there again."""
    sim, eo, outlines = flight
    session = PickingSession()
    session.control = ControlSet.from_features(*_features(sim, outlines))
    session.set_orientation(sim.camera, eo, sim.crs)
    log = session.observations
    rows, obs = _tie_pair(sim)
    a, b, c = rows[:3]
    img_a, img_b, img_c = obs.image_id[a], obs.image_id[b], obs.image_id[c]
    target = session.targets_at(img_a, obs.pixels[a], "tie", 10.0)[0]
    k = session.add_observation(img_a, obs.pixels[a], target)
    first = session.pending
    pred_b = session.prediction(img_b).copy()
    assert math.hypot(*(pred_b - obs.pixels[b])) < 1e-3 and session.prediction(img_c) is not None

    # undo the tie point: no row, no prediction anywhere; Enter in B adds nothing
    assert session.undo()
    assert log.rows == [] and session.pending is None
    assert session.prediction(img_b) is None and session.confirm_prediction(img_b) == -1
    assert log.rows == []
    # redo: the row and the same prediction
    assert session.redo()
    assert log.rows[k].image_id == img_a and session.pending is first
    np.testing.assert_array_equal(session.prediction(img_b), pred_b)

    # measured in B: B no longer predicted (C still); undo: the B row goes, B predicted again
    kb = session.confirm_prediction(img_b)
    assert log.rows[kb].point_id == log.rows[k].point_id and session.prediction(img_b) is None
    assert session.prediction(img_c) is not None
    session.undo()
    assert len(log.rows) == 1
    np.testing.assert_array_equal(session.prediction(img_b), pred_b)
    session.redo()
    assert len(log.rows) == 2 and session.prediction(img_b) is None
    # measured in every image it was predicted in: nothing left; undo: the last one again
    left = list(session.pending.pixels)
    for image in left:
        session.confirm_prediction(image)
    assert session.pending is None and len(log.rows) == 2 + len(left)
    session.undo()
    assert list(session.pending.pixels) == left[-1:]
    assert session.redo() and session.pending is None

    # Esc drops the prediction (not an edit); undoing the next edit restores what was pending
    # before that edit (nothing), not what Esc dropped
    for _ in left:
        session.undo()
    assert session.prediction(img_c) is not None
    session.cancel_prediction()
    assert session.pending is None
    proj = session.project(img_a)
    j = int(np.flatnonzero(np.isfinite(proj.lcps).all(axis=1))[0])
    session.add_observation(
        img_a, proj.lcps[j], session.targets_at(img_a, proj.lcps[j], "lcp", 1.0, proj)[0]
    )
    session.undo()
    assert session.pending is None and len(log.rows) == 2
    # a new tie point replaces the pending one; undoing it brings the first back
    session.redo()
    session.undo()
    session.undo()  # (the B row)
    session.redo()
    assert session.prediction(img_b) is None and session.prediction(img_c) is not None
    t2 = session.targets_at(img_a, obs.pixels[a] + [1.0, 1.0], "tie", 10.0)[0]
    before = session.pending
    session.add_observation(img_a, obs.pixels[a] + [1.0, 1.0], t2)
    assert session.pending is not before and session.pending.point_id != before.point_id
    session.undo()
    assert session.pending is before


def test_deleting_or_moving_the_tie_point_updates_its_prediction(flight):
    sim, eo, outlines = flight
    session = PickingSession()
    session.control = ControlSet.from_features(*_features(sim, outlines))
    session.set_orientation(sim.camera, eo, sim.crs)
    log = session.observations
    rows, obs = _tie_pair(sim)
    a, b = rows[:2]
    img_a, img_b = obs.image_id[a], obs.image_id[b]
    target = session.targets_at(img_a, obs.pixels[a], "tie", 10.0)[0]
    k = session.add_observation(img_a, obs.pixels[a], target)
    pending = session.pending
    # moved by (+3, -2) px: the prediction follows (the ray of the new pixel on the plane)
    session.move(k, *(obs.pixels[a] + [3.0, -2.0]))
    plane = session.control.planes[target.index]
    expected = session.scene.predict_tie(
        img_a, obs.pixels[a] + [3.0, -2.0], plane.normal, plane.centroid
    )[img_b]
    np.testing.assert_allclose(session.prediction(img_b), expected, atol=1e-9)
    assert math.hypot(*(session.prediction(img_b) - pending.pixels[img_b])) > 1.0
    session.undo()  # the move undone: the first prediction again
    assert session.pending is pending and log.rows[k].col == pytest.approx(obs.pixels[a][0])
    # deleting the only row of the point drops its prediction; undo brings both back
    session.delete(k)
    assert log.rows == [] and session.pending is None and session.prediction(img_b) is None
    session.undo()
    assert len(log.rows) == 1 and session.pending is pending
    # measured in B, then A's row deleted: B's row keeps the point, the prediction stays
    kb = session.confirm_prediction(img_b)
    rest = session.pending
    session.delete(k)
    assert [o.image_id for o in log.rows] == [img_b] and session.pending is rest
    # a moved row that is not the one predicted from leaves the prediction alone
    session.move(0, log.rows[0].col + 1.0, log.rows[0].row)
    assert session.pending is rest
    del kb


def test_index_of_rows_by_image_follows_every_edit():
    """The index behind indices_of_image (kept up to date for adds, moves and their undo)
    against a plain scan, through a random sequence of edits."""
    rng = np.random.default_rng(4)
    log = ObservationList([_obs(k, "abc"[k % 3]) for k in range(20)])
    for step in range(400):
        r = rng.uniform()
        if r < 0.35:
            n = int(rng.integers(1, 4))
            log.add([_obs(1000 + step * 4 + j, "abcd"[int(rng.integers(4))]) for j in range(n)])
        elif r < 0.5 and log.rows:
            k = int(rng.integers(len(log.rows)))
            log.move(k, float(rng.uniform(0, 100)), float(rng.uniform(0, 100)))
        elif r < 0.6 and log.rows:
            log.delete([int(i) for i in rng.integers(len(log.rows), size=2)])
        elif r < 0.85:
            log.undo()
        else:
            log.redo()
        for image in "abcde":
            assert log.indices_of_image(image) == [
                k for k, o in enumerate(log.rows) if o.image_id == image
            ], (step, image)
    assert log.image_ids() <= set("abcd")
