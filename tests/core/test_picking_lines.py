"""core.photo.picking_session: image lines measured in the picking dock (two clicks linked to
a LiDAR line) and the resection the dock runs on them.

Truth: a noise-free simulated flight (core.simulate_flight) and the EO of its true trajectory
and mount; the image lines are measured on the LiDAR lines' projections with 0.3 px noise."""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.geometry.frames import MappingFrame
from lidarphoto.core.io.camera import write_camera_json
from lidarphoto.core.io.control import write_lines_csv
from lidarphoto.core.io.observations import write_observations_csv
from lidarphoto.core.jobs import resection
from lidarphoto.core.jobs.resection import residual_rows
from lidarphoto.core.jobs.runner import run_job
from lidarphoto.core.photo.control_features import (
    ControlFeature,
    ControlSet,
    lines_with_end_sigmas,
)
from lidarphoto.core.photo.georeference import direct_georeference
from lidarphoto.core.photo.mount import Mount
from lidarphoto.core.photo.picking_session import (
    MIN_LINE_PX,
    PickingSession,
    residual_summary,
)
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


@pytest.fixture(scope="module")
def session_and_truth():
    sim = simulate_flight(CONFIG, seed=5, exact=True)
    group = sim.truth.groups[0]
    mount = Mount(sim.truth.lever_arm, sim.mount.nominal, sim.truth.boresight[group])
    eo = direct_georeference(sim.truth.trajectory, mount, MappingFrame.from_user_input(sim.crs))
    lines = [ControlFeature(str(ln.id), np.array([ln.start, ln.end]), {}) for ln in sim.lines]
    lcps = [ControlFeature(str(c.id), c.xyz[None], {}) for c in sim.lcps]
    return sim, eo, ControlSet.from_features([], lines, lcps)


def _session(sim, eo, control) -> PickingSession:
    s = PickingSession()
    s.control = control
    s.set_orientation(sim.camera, eo, sim.crs)
    return s


def _inside(sim, px) -> np.ndarray:
    w, h = sim.camera.width_px, sim.camera.height_px
    p = np.reshape(px, (-1, 2))
    return (
        np.isfinite(p).all(axis=1)
        & (p[:, 0] > 5)
        & (p[:, 0] < w - 5)
        & (p[:, 1] > 5)
        & (p[:, 1] < h - 5)
    )


def _visible_lines(sim, proj) -> list[int]:
    """Lines whose points at 15 % and 85 % of their projection are in the image, 40 px long."""
    a = proj.line_starts + 0.15 * (proj.line_ends - proj.line_starts)
    b = proj.line_starts + 0.85 * (proj.line_ends - proj.line_starts)
    ok = _inside(sim, a) & _inside(sim, b) & (np.hypot(*(b - a).T) > 40)
    return np.flatnonzero(ok).tolist()


def test_two_clicks_make_one_undoable_line_linked_to_the_lidar_line(session_and_truth):
    sim, eo, control = session_and_truth
    s = _session(sim, eo, control)
    img, other = eo.image_id[0], eo.image_id[1]
    proj = s.project(img)
    i = _visible_lines(sim, proj)[0]
    a = proj.line_starts[i] + 0.2 * (proj.line_ends[i] - proj.line_starts[i])
    b = proj.line_starts[i] + 0.8 * (proj.line_ends[i] - proj.line_starts[i])
    # the first click, 2 px off the line, links the nearest projected LiDAR line
    normal = np.array([-(b - a)[1], (b - a)[0]]) / np.hypot(*(b - a))
    target = s.targets_at(img, a + 2 * normal, "line", 5.0, proj)
    assert [t.index for t in target] == [i] and target[0].target_id == control.line_ids[i]
    half = s.start_line(img, a + 2 * normal, target[0], proj)
    # its predicted position: the LiDAR line projected with the current camera and EO
    np.testing.assert_array_equal(half.predicted, [proj.line_starts[i], proj.line_ends[i]])
    assert s.observations.rows == [] and s.half_line is half
    # the second click in another image, or less than MIN_LINE_PX away: nothing added
    assert s.finish_line(other, b) == -1
    assert s.finish_line(img, half.start + [0.5 * MIN_LINE_PX, 0.0]) == -1
    assert s.observations.rows == [] and s.half_line is half
    assert s.finish_line(img, b) == 0 and s.half_line is None
    rows = s.observations.rows
    assert [(o.image_id, o.type, o.target_id) for o in rows] == [
        (img, "line", control.line_ids[i])
    ] * 2
    assert (rows[0].col, rows[0].row) == tuple(half.start) and (rows[1].col, rows[1].row) == tuple(
        b
    )
    assert len({o.point_id for o in rows}) == 2
    assert all(o.point_id.startswith(f"R{control.line_ids[i]}_") for o in rows)
    # one undo removes both ends, one redo brings both back
    assert s.undo() and s.observations.rows == []
    assert s.redo() and s.observations.rows == rows
    # a second line on the same LiDAR line: new point ids; Esc (cancel) drops a half line
    s.start_line(img, a, target[0], proj)
    assert s.finish_line(img, b) == 2
    assert len({o.point_id for o in s.observations.rows}) == 4
    s.start_line(img, a, target[0])
    assert s.cancel_line() and s.half_line is None and not s.cancel_line()
    with pytest.raises(ValueError):
        s.start_line(img, a, s.targets_at(img, proj.lcps[np.isfinite(proj.lcps).all(1)][0],
                                          "lcp", 5.0, proj)[0])  # fmt: skip


def test_lines_measured_in_the_session_resect_the_image(session_and_truth, tmp_path):
    """The rows the dock writes are read by the resection job; lines only, it recovers the
    image's true pose within 4 of its reported sigmas (0.3 px noise on the end points), and
    the residuals come back to the rows."""
    sim, eo, control = session_and_truth
    s = _session(sim, eo, control)
    img = eo.image_id[2]
    proj = s.project(img)
    visible = _visible_lines(sim, proj)
    assert len(visible) >= 6
    rng = np.random.default_rng(17)
    for i in visible:
        t = s.targets_at(img, proj.line_starts[i] + 0.5 * (proj.line_ends[i] - proj.line_starts[i]),
                         "line", 1.0, proj)  # fmt: skip
        if not t or t[0].index != i:  # (lines crossing at the middle: another is as near)
            continue
        d = proj.line_ends[i] - proj.line_starts[i]
        ends = proj.line_starts[i] + np.outer([0.15, 0.85], d) + rng.normal(0, 0.3, (2, 2))
        s.start_line(img, ends[0], t[0], proj)
        assert s.finish_line(img, ends[1]) >= 0
    n_lines = len({o.target_id for o in s.observations.rows})
    assert n_lines >= 6
    obs_csv = tmp_path / "obs.csv"
    write_observations_csv(obs_csv, s.observations.to_observations())
    _planes, lines, _lcps = control.for_calibration()
    write_lines_csv(tmp_path / "lines.csv", lines_with_end_sigmas(lines))
    write_camera_json(tmp_path / "camera.json", sim.camera)
    result = run_job(resection, {
        "CAMERA": str(tmp_path / "camera.json"), "OBSERVATIONS": str(obs_csv),
        "CONTROL_LINES": str(tmp_path / "lines.csv"), "CRS": sim.crs, "IMAGES": img,
        "OUTPUT_EO": str(tmp_path / "eo.csv"),
    })  # fmt: skip
    (run,) = result.data
    assert run.image.data.n_lines == n_lines and run.image.data.n_points == 0
    k = list(eo.image_id).index(img)
    std = run.result.std
    assert np.all(np.abs(run.result.xyz - eo.xyz[k]) < 4 * std[:3] + 1e-6), (
        run.result.xyz - eo.xyz[k],
        std[:3],
    )
    dopk = (run.result.opk - eo.opk[k] + np.pi) % (2 * np.pi) - np.pi
    assert np.all(np.abs(dopk) < 4 * std[3:] + 1e-9), (dopk, std[3:])
    # the tolerance is not vacuous: 12 lines with 5 cm control give about 1 m and 0.04 deg
    assert np.all(std[:3] < 2.0) and np.all(std[3:] < 1e-3)
    # the residuals back to the session's rows, summarised per line
    rows = residual_rows(run, s.observations.to_observations(), sim.camera)
    s.set_resection(rows)
    res = s.resection_residuals()
    assert sorted(res) == list(range(len(s.observations.rows)))
    summary = residual_summary(rows)
    assert len(summary) == n_lines and {g[0] for g in summary} == {"line"}
    assert all(g[2] == 2 and g[4] < 5 * 0.3 for g in summary)
    shown = s.shown_residuals()
    assert shown.keys() == res.keys()
