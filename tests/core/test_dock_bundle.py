"""The picking dock's rows as a bundle block (core.photo.dock_bundle).

Truth: hand-made rows whose conversion is known exactly; and a simulated flight (6 images,
LCPs at the true roof corners, 0.5 px Gaussian noise on every pixel) whose rows, converted,
give a block the bundle adjustment solves back to the true orientations from a start 10 m
and 1 degree off.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from lidarphoto.core.geometry.camera import Camera
from lidarphoto.core.geometry.frames import MappingFrame
from lidarphoto.core.lidar.control import ControlPoint
from lidarphoto.core.photo.bundle import bundle_adjust
from lidarphoto.core.photo.bundle_setup import BundleOptions
from lidarphoto.core.photo.dock_bundle import (
    MIN_CONTROL_SIGMA_M,
    dock_bundle_inputs,
    residuals_by_row,
)
from lidarphoto.core.photo.georeference import direct_georeference
from lidarphoto.core.photo.mount import Mount
from lidarphoto.core.photo.observations import ImageObservations
from lidarphoto.core.simulation.flight import FlightConfig, simulate_flight

CRS = "EPSG:28992"


def _lcp(i: int, xyz, cov) -> ControlPoint:
    return ControlPoint(i, np.array(xyz, float), np.array(cov, float), (1, 2, 3), 30.0, 1.0,
                        np.zeros(3))  # fmt: skip


def test_rows_become_ties_control_and_check_points():
    """Each rule of the module docstring on rows of every type: kept rows in order, LCP rows
    renamed C<id>/K<id> with the LCP's coordinates and sqrt(diag(cov)) (zero floored),
    left-out rows counted by reason."""
    cov = np.array([[4e-4, 1e-4, 0.0], [1e-4, 9e-4, 0.0], [0.0, 0.0, 2.5e-3]])
    lcps = [_lcp(3, [1.0, 2.0, 3.0], cov), _lcp(5, [4.0, 5.0, 6.0], np.zeros((3, 3)))]
    rows = [  # image, point, type, target
        ("a", "T1", "tie", "9"),
        ("b", "T1", "tie", "9"),
        ("c", "T1", "tie", "9"),  # image c is not open
        ("a", "T2", "tie", "9"),  # T2 then is in one open image only
        ("c", "T2", "tie", "9"),
        ("a", "C3", "lcp", "3"),
        ("b", "lcp-b", "lcp", "3"),  # another id: the LCP's name wins
        ("a", "K5", "check", "5"),
        ("b", "K5", "check", "5"),
        ("a", "C7", "lcp", "7"),  # no such LCP in the dock
        ("a", "R1_1", "line", "1"),
        ("b", "P1", "paper", "9"),
    ]
    obs = ImageObservations.from_arrays(
        [r[0] for r in rows], [r[1] for r in rows], np.arange(24.0).reshape(12, 2) + 10, 0.5,
        [r[2] for r in rows], [r[3] for r in rows],
    )  # fmt: skip
    b = dock_bundle_inputs(obs, lcps, ["3", "5"], images=["a", "b"])
    kept = b.observations
    assert kept.point_id == ("T1", "T1", "C3", "C3", "K5", "K5")
    assert kept.type == ("tie", "tie", "lcp", "lcp", "check", "check")
    np.testing.assert_array_equal(kept.pixels, obs.pixels[[0, 1, 5, 6, 7, 8]])
    assert b.images == ("a", "b")
    assert b.ground.point_id == ("C3", "K5") and b.ground.role == ("control", "check")
    np.testing.assert_array_equal(b.ground.xyz, [[1, 2, 3], [4, 5, 6]])
    np.testing.assert_allclose(b.ground.sigma[0], [0.02, 0.03, 0.05])
    np.testing.assert_array_equal(b.ground.sigma[1], [MIN_CONTROL_SIGMA_M] * 3)
    assert b.left_out == {
        "row(s) of images not open": 2,
        "lcp row(s) naming no control point of the dock": 1,
        "line row(s)": 1,
        "paper row(s)": 1,
        "tie point(s) measured in one image only": 1,
    }


@pytest.fixture(scope="module")
def flight():
    cam = Camera("test frame", focal_mm=50.0, pixel_size_mm=0.012, width_px=3000, height_px=2000)
    cfg = FlightConfig(camera=cam, flying_height_m=800.0, n_buildings=9, n_planes=24,
                       town_size_m=400.0, n_check=2, types=("tie", "line", "lcp", "check"),
                       ties_per_plane=2, plane_source="exact")  # fmt: skip
    sim = simulate_flight(cfg, seed=5, exact=True)
    group = sim.truth.groups[0]
    mount = Mount(sim.truth.lever_arm, sim.mount.nominal, sim.truth.boresight[group])
    frame = MappingFrame.from_user_input(CRS)
    eo = direct_georeference(sim.truth.trajectory, mount, frame)
    o = sim.observations
    rng = np.random.default_rng(1)
    noisy = replace(o, pixels=o.pixels + rng.normal(0, 0.5, o.pixels.shape))
    return sim, cam, frame, eo, noisy


def test_converted_rows_adjust_to_the_true_orientations(flight):
    """The converted block from a start 10 m and 1 deg off: every orientation within 4 of
    its sigmas of the truth, height and kappa far inside the start error; check points kept
    out and within 4 sigma; each kept row gets its residual back by row index."""
    sim, cam, frame, eo, noisy = flight
    lcps = sim.lcps + sim.check_lcps
    b = dock_bundle_inputs(noisy, lcps, [str(c.id) for c in lcps])
    assert set(b.observations.type) == {"tie", "lcp", "check"}
    assert b.left_out == {"line row(s)": int(noisy.mask("line").sum())}
    assert b.ground.role.count("check") == 2
    rng = np.random.default_rng(15)
    start = replace(eo, xyz=eo.xyz + rng.choice([-10.0, 10.0], eo.xyz.shape),
                    opk=eo.opk + np.radians(rng.choice([-1.0, 1.0], eo.opk.shape)))  # fmt: skip
    opts = BundleOptions(ap_model="none", estimate_interior=False)
    res = bundle_adjust([cam], b.observations, b.ground, frame, start, options=opts)
    s = res.eo_sigma
    dopk = (res.eo.opk - eo.opk + np.pi) % (2 * np.pi) - np.pi
    assert np.all(np.abs(res.eo.xyz - eo.xyz) < 4 * s[:, :3])
    assert np.all(np.abs(dopk) < 4 * s[:, 3:])
    assert np.all(s[:, 2] < 3.0) and np.all(np.degrees(s[:, 5]) < 0.2)
    c = res.check
    assert len(c.point_id) == 2
    assert np.all(np.abs(c.measured - c.reference) < 4 * c.sigma + 4 * 0.05)
    by_row = residuals_by_row(res, noisy)
    kinds = np.array(noisy.type)
    assert set(by_row) <= set(np.flatnonzero(kinds != "line").tolist())
    assert len(by_row) >= int(np.sum(res.used & (np.array(res.obs_role) != "check")))
    k = next(iter(by_row))
    j = next(
        i for i in range(len(res.observations))
        if (res.observations.image_id[i], res.observations.point_id[i])
        == (noisy.image_id[k], noisy.point_id[k])
    )  # fmt: skip
    np.testing.assert_array_equal(by_row[k], res.v_px[j])


def test_session_keeps_the_bundle_residuals_on_their_rows(flight):
    """The picking session shows the bundle's residual on each adjusted row; after a row is
    deleted the residuals follow their rows (new indices), and a resection run earlier is
    forgotten."""
    from lidarphoto.core.photo.observation_list import ObservationList
    from lidarphoto.core.photo.picking_session import PickingSession

    sim, cam, frame, eo, noisy = flight
    lcps = sim.lcps + sim.check_lcps
    b = dock_bundle_inputs(noisy, lcps, [str(c.id) for c in lcps])
    opts = BundleOptions(ap_model="none", estimate_interior=False)
    res = bundle_adjust([cam], b.observations, b.ground, frame, eo, options=opts)
    session = PickingSession(ObservationList(ObservationList.rows_of(noisy)))
    session.set_resection([("x", "C1", "lcp", "1", 0, 0, 0, 9.0, 9.0, 9.0, 0, False, True)])
    session.set_bundle(res)
    assert session.resection_rows == []
    shown = session.shown_residuals()
    expected = residuals_by_row(res, noisy)
    assert shown.keys() == expected.keys() and len(shown) > 100
    first = min(shown)
    session.observations.delete(first)
    after = session.shown_residuals()
    assert len(after) == len(shown) - 1
    for k, v in shown.items():
        if k > first:
            np.testing.assert_array_equal(after[k - 1], v)
    session.set_bundle(None)
    assert session.shown_residuals() == {}


def test_control_rows_are_tie_points_of_the_dock_block_and_get_their_residuals(flight):
    """Rows of type control (located surveyed points) in the dock: adjusted as tie points
    named by their point_id (the dock has no ground point table), their own rows unchanged,
    the bundle's residuals given back to them."""
    sim, cam, frame, eo, noisy = flight
    lcps = sim.lcps + sim.check_lcps
    ids = sorted({t for t, k in zip(noisy.target_id, noisy.type) if k == "lcp"}, key=int)
    surveyed = set(ids[: len(ids) - 3])  # three LCPs stay control (the datum)
    half = {k for k, (t, kind) in enumerate(zip(noisy.target_id, noisy.type))
            if kind == "lcp" and t in surveyed}  # fmt: skip
    kinds = tuple("control" if k in half else t for k, t in enumerate(noisy.type))
    target = tuple("" if k in half else t for k, t in enumerate(noisy.target_id))
    point = tuple(f"GCP{noisy.target_id[k]}" if k in half else p
                  for k, p in enumerate(noisy.point_id))  # fmt: skip
    rows = replace(noisy, type=kinds, target_id=target, point_id=point)
    b = dock_bundle_inputs(rows, lcps, [str(c.id) for c in lcps])
    as_tie = {rows.point_id[k] for k in half}
    assert not as_tie & set(b.ground.point_id)
    kept = {(i, p): t for i, p, t in zip(b.observations.image_id, b.observations.point_id,
                                         b.observations.type)}  # fmt: skip
    seen_twice = [k for k in half if sum(rows.point_id[j] == rows.point_id[k] for j in half) > 1]
    assert seen_twice
    assert all(kept[(rows.image_id[k], rows.point_id[k])] == "tie" for k in seen_twice)
    opts = BundleOptions(ap_model="none", estimate_interior=False)
    res = bundle_adjust([cam], b.observations, b.ground, frame, eo, options=opts)
    by_row = residuals_by_row(res, rows)
    assert set(seen_twice) <= set(by_row)
    assert rows.type == kinds  # the dock's own rows are not changed
