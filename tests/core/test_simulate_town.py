"""The synthetic town: faces, polygons, ridges and labelled points agree with each other."""

from __future__ import annotations

import numpy as np
import pytest
from lidarphoto.core.errors import InputError
from lidarphoto.core.simulation.town import (
    CLASS_BUILDING,
    CLASS_GROUND,
    CLASS_VEGETATION,
    ROOF_TYPES,
    make_town,
    sample_town,
    simulate_town,
)

FACES_PER_TYPE = {"gable": 2, "hip": 4, "pyramid": 4, "shed": 1, "flat": 1}


@pytest.fixture(scope="module")
def town():
    return make_town(n_buildings=10, n_trees=4, seed=2)


def test_roof_types_faces_and_ridges(town):
    assert [b.roof_type for b in town.buildings] == list(ROOF_TYPES) * 2
    ridges = {"gable": 1, "hip": 5, "pyramid": 4, "shed": 0, "flat": 0}
    for b in town.buildings:
        assert len(b.face_ids) == FACES_PER_TYPE[b.roof_type]
        assert len(b.ridges) == ridges[b.roof_type]
        for seg in b.ridges:  # a ridge lies on exactly two faces of its building
            on = [
                f
                for f in b.face_ids
                if np.abs(seg @ town.faces[f].normal + town.faces[f].d).max() < 1e-9
            ]
            assert len(on) == 2
    for f in town.faces:
        assert np.linalg.norm(f.normal) == pytest.approx(1.0) and f.normal[2] > 0
        assert np.abs(f.polygon @ f.normal + f.d).max() < 1e-9  # corners on the plane
        b = town.buildings[f.building_id]
        assert f.slope_deg == pytest.approx(b.slope_deg, abs=1e-9)


def test_face_areas_add_up_to_the_footprint(town):
    for b in town.buildings:
        plan = sum(town.faces[f].area * town.faces[f].normal[2] for f in b.face_ids)
        assert plan == pytest.approx(b.length * b.width, rel=1e-9)


def test_points_carry_consistent_labels(town):
    pts = sample_town(town, density=4.0, noise_sigma=0.0, seed=3)
    roof = pts.face_id >= 0
    for f in town.faces:  # noise-free roof points lie on their face
        m = pts.face_id == f.face_id
        assert m.sum() > 20
        assert np.abs(pts.xyz[m] @ f.normal + f.d).max() < 1e-9
    ground = pts.classification == CLASS_GROUND
    assert np.abs(pts.xyz[ground] @ town.terrain[:3] + town.terrain[3]).max() < 1e-9
    assert set(np.unique(pts.classification)) == {CLASS_GROUND, CLASS_VEGETATION, CLASS_BUILDING}
    assert (pts.classification[roof] == CLASS_BUILDING).all()
    assert (pts.building_id[pts.is_wall] >= 0).all() and (pts.face_id[pts.is_wall] == -1).all()
    # density: roof points per horizontal m^2
    plan = sum(f.area * f.normal[2] for f in town.faces)
    assert roof.sum() / plan == pytest.approx(4.0, rel=0.1)


def test_noise_has_the_given_sigma(town):
    pts = sample_town(town, density=4.0, noise_sigma=0.05, seed=4)
    r = np.concatenate([pts.xyz[pts.face_id == f.face_id] @ f.normal + f.d for f in town.faces])
    assert np.std(r) == pytest.approx(0.05, rel=0.05)


def test_seeds_reproduce():
    a = simulate_town(n_buildings=3, n_trees=1, density=2.0, seed=5)
    b = simulate_town(n_buildings=3, n_trees=1, density=2.0, seed=5)
    np.testing.assert_array_equal(a[1].xyz, b[1].xyz)
    c = simulate_town(n_buildings=3, n_trees=1, density=2.0, seed=6)
    assert len(c[1].xyz) != len(a[1].xyz) or not np.array_equal(c[1].xyz, a[1].xyz)


def test_bad_arguments():
    with pytest.raises(InputError):
        make_town(roof_types=("dome",))
    with pytest.raises(InputError):
        make_town(cell=10.0)
    with pytest.raises(InputError):
        sample_town(make_town(n_buildings=1, n_trees=0), density=0.0)
