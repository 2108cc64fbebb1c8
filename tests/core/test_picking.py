"""core.photo.picking: point-in-outline, hit tests and tie-point prediction against a simulated
flight (the simulation's own projection chain, through ECEF, is the independent truth)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.geometry.frames import MappingFrame
from lidarphoto.core.photo.georeference import direct_georeference
from lidarphoto.core.photo.mount import Mount
from lidarphoto.core.photo.picking import (
    PickingScene,
    nearest_point,
    nearest_segment,
    points_in_polygons,
)
from lidarphoto.core.simulation.flight import FlightConfig, simulate_flight

SMALL = FlightConfig(
    n_buildings=9,
    n_planes=24,
    town_size_m=600.0,
    n_check=0,
    types=("tie",),
    ties_per_plane=2,
    plane_source="exact",
)


@pytest.fixture(scope="module")
def flight():
    """An exact simulation and the EO table made from the true trajectory and true mount."""
    sim = simulate_flight(SMALL, seed=3, exact=True)
    group = sim.truth.groups[0]
    mount = Mount(sim.truth.lever_arm, sim.mount.nominal, sim.truth.boresight[group])
    frame = MappingFrame.from_user_input(sim.crs)
    eo = direct_georeference(sim.truth.trajectory, mount, frame)
    return sim, PickingScene(eo, sim.camera)


def test_points_in_polygons_convex_concave_and_invalid():
    rng = np.random.default_rng(1)
    angles = np.linspace(0, 2 * np.pi, 9)[:-1]
    octagon = np.column_stack([np.cos(angles), np.sin(angles)]) * 10 + 50
    ell = np.array([[0, 0], [4, 0], [4, 1], [1, 1], [1, 4], [0, 4]], dtype=float)
    behind = octagon.copy()
    behind[3] = np.nan
    polys = [octagon, ell, behind, np.array([[0.0, 0.0], [1.0, 1.0]])]
    # inside the octagon's inscribed circle / outside its circumscribed circle
    r = np.sqrt(rng.uniform(0, 1, 200)) * 10 * np.cos(np.pi / 8) * 0.999
    t = rng.uniform(0, 2 * np.pi, 200)
    for x, y in np.column_stack([50 + r * np.cos(t), 50 + r * np.sin(t)]):
        assert points_in_polygons((x, y), polys).tolist() == [0]
    for x, y in np.column_stack([50 + 10.01 * np.cos(t), 50 + 10.01 * np.sin(t)]):
        assert points_in_polygons((x, y), polys).tolist() == []
    assert points_in_polygons((0.5, 3.5), polys).tolist() == [1]  # the L's vertical arm
    assert points_in_polygons((3.5, 0.5), polys).tolist() == [1]
    assert points_in_polygons((2.5, 2.5), polys).tolist() == []  # the L's notch
    assert points_in_polygons((0, 0), []).tolist() == []


def test_hit_tests():
    assert nearest_point((5, 5), [[0, 0], [6, 5], [np.nan, np.nan]], 2.0) == (1, 1.0)
    assert nearest_point((5, 5), [[0, 0]], 2.0)[0] == -1
    starts, ends = np.array([[0, 0], [0, 10.0]]), np.array([[10, 0], [10, 10.0]])
    k, d = nearest_segment((5, 3), starts, ends, 4.0)
    assert (k, d) == (0, pytest.approx(3.0))
    k, d = nearest_segment((13, 14), starts, ends, 6.0)  # past the end: distance to the end
    assert (k, d) == (1, pytest.approx(5.0))
    assert nearest_segment((5, 5), starts, ends, 4.0)[0] == -1


def test_tie_prediction_matches_the_simulation(flight):
    sim, scene = flight
    obs = sim.observations
    plane = {str(p.id): p for p in sim.planes}
    names = np.array(obs.point_id)
    errors = []
    for name in np.unique(names):
        rows = np.flatnonzero(names == name)
        if rows.size < 2:
            continue
        a = rows[0]
        p = plane[obs.target_id[a]]
        pred = scene.predict_tie(obs.image_id[a], obs.pixels[a], p.normal, p.centroid)
        for b in rows[1:]:
            errors.append(np.hypot(*(pred[obs.image_id[b]] - obs.pixels[b])))
    errors = np.array(errors)
    assert errors.size >= 20
    # noise-free simulation: only the EO CSV rounding (0.1 mm, 1e-10 deg) is left
    assert errors.max() < 0.01, errors.max()


def test_planes_under_pixel_finds_the_roof(flight):
    sim, scene = flight
    obs = sim.observations
    faces = {f.face_id: f for f in sim.town.faces}
    outlines = [faces[int(p.id)].polygon for p in sim.planes]
    normals = np.array([p.normal for p in sim.planes])
    points = np.array([p.centroid for p in sim.planes])
    found = 0
    for k in range(0, len(obs), 3):
        cands = scene.planes_under_pixel(obs.image_id[k], obs.pixels[k], outlines, normals, points)
        ids = [str(sim.planes[c.index].id) for c in cands]
        assert obs.target_id[k] in ids
        found += ids[0] == obs.target_id[k]
        hit = cands[ids.index(obs.target_id[k])]
        back = scene.project(obs.image_id[k], hit.ground[None])[0]
        assert np.hypot(*(back - obs.pixels[k])) < 1e-3
    assert found >= 0.9 * len(range(0, len(obs), 3))  # the nearest roof is the visible one


def test_footprint_projects_to_the_corners(flight):
    sim, scene = flight
    image = sim.trajectory.image_id[0]
    corners = scene.footprint(image, 10.0)
    assert np.allclose(corners[:, 2], 10.0, atol=1e-6)
    w, h = sim.camera.width_px, sim.camera.height_px
    back = scene.project(image, corners)
    assert np.allclose(back, [[0, 0], [w, 0], [w, h], [0, h]], atol=1e-4)


def test_unknown_image_and_missing_crs(flight):
    sim, scene = flight
    with pytest.raises(InputError, match="no exterior orientation"):
        scene.project("nope", [[0.0, 0.0, 0.0]])
    with pytest.raises(InputError, match="CRS"):
        PickingScene(replace(scene.eo, crs_wkt=""), sim.camera)
